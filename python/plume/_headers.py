"""Turns libplume's public headers into a cffi ``cdef``.

The binding uses cffi's ABI mode, which needs the exact C declarations of the
structs it reads and fills. Rather than keeping a second copy of them by hand
(one that drifts when a header gains a field), the declarations are taken from
include/plume/*.h themselves with a small preprocessor that knows the few
things these headers use: include guards, ``extern "C"`` guards, the
PLUME_API_BEGIN/END visibility macros, ``__attribute__`` under ``__GNUC__``,
integer ``#define`` constants, and ``static inline`` helpers (which the shared
library does not export, so they are dropped). Anything else is an error, so a
header that grows a new construct fails loudly instead of binding wrongly.
"""

from __future__ import annotations

import pathlib
import re

# Order matters: a header's types come before their users (plume.h's order).
HEADERS = (
    "core.h",
    "feather.h",
    "io.h",
    "mesh.h",
    "model.h",
    "sim.h",
    "lab.h",
    "streit_heidrich.h",
    "zhang_kanai.h",
    "render.h",
    "coat.h",
    "embed.h",
    "raytrace.h",
    "scene.h",
)


def _strip_comments(text: str) -> str:
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def _strip_inline_functions(text: str) -> str:
    out = []
    i = 0
    while True:
        match = re.compile(r"\bstatic\s+inline\b").search(text, i)
        if match is None:
            out.append(text[i:])
            return "".join(out)
        out.append(text[i : match.start()])
        brace = text.index("{", match.end())
        depth = 0
        j = brace
        while True:
            if text[j] == "{":
                depth += 1
            elif text[j] == "}":
                depth -= 1
                if depth == 0:
                    break
            j += 1
        i = j + 1


def _integer_expression(value: str) -> "int | None":
    """The value of an integer constant expression such as 64, 0x706c756du or (4ull << 30), else None."""
    text = re.sub(r"\b(0[xX][0-9a-fA-F]+|\d+)[uUlL]*\b", r"\1", value.strip())
    if not text or not re.fullmatch(r"[0-9a-fA-FxX()<>+\-*/%|&~^ ]+", text) or re.search(r"[a-wyzA-WYZ]", re.sub(
            r"0[xX][0-9a-fA-F]+", "", text)):
        return None
    try:
        result = eval(text.replace("/", "//"), {"__builtins__": {}}, {})  # digits and operators only
    except (SyntaxError, TypeError, NameError, ZeroDivisionError):
        return None
    return result if isinstance(result, int) else None


def header_text(path: pathlib.Path, constants: dict[str, str]) -> str:
    """One header, preprocessed for cffi. Fills constants with its #defines."""
    lines = []
    skipping = []  # one flag per open #if: True when that block is dropped
    for raw in _strip_comments(path.read_text()).splitlines():
        line = raw.strip()
        if line.startswith("#"):
            directive = line[1:].strip()
            if directive.startswith(("if ", "ifdef", "ifndef")):
                dropped = "__cplusplus" in directive or "__GNUC__" in directive
                skipping.append(dropped)
            elif directive.startswith("else"):
                pass  # both branches of the guards this file knows are dropped or kept alike
            elif directive.startswith("endif"):
                skipping.pop()
            elif any(skipping):
                pass
            elif directive.startswith("include"):
                pass  # the headers are concatenated in HEADERS' order
            elif directive.startswith("define"):
                parts = directive.split(None, 2)
                name = parts[1]
                value = parts[2] if len(parts) > 2 else ""
                if re.fullmatch(r"PLUME_\w+_H|PLUME_H", name) and value == "":
                    continue
                number = _integer_expression(value)
                if number is not None:
                    constants[name] = str(number)  # cffi wants plain decimal
                elif re.fullmatch(r'"[^"]*"', value):
                    constants[name] = value
                # Anything else (a function-like macro ...) is left out: a declaration that used it
                # would fail in cffi's parser with the macro's name, not bind wrongly.
            else:
                raise ValueError(f"{path}: unsupported directive #{directive}")
            continue
        if any(skipping):
            continue
        lines.append(raw)
    text = "\n".join(lines)
    text = re.sub(r"\bPLUME_API_(BEGIN|END)\b", "", text)
    text = _strip_inline_functions(text)
    for name, value in constants.items():
        if not value.startswith('"'):
            text = re.sub(rf"\b{name}\b", value, text)
    return text


def cdef(include_dir: str | pathlib.Path) -> tuple[str, dict[str, str]]:
    """The cdef text of every public header in include_dir/plume, and the #define constants."""
    folder = pathlib.Path(include_dir) / "plume"
    present = {p.name for p in folder.glob("*.h")} - {"plume.h"}
    # Headers added after this list was written come last, in name order: they build on the
    # others (a new module's header includes the ones below it).
    order = [name for name in HEADERS if name in present] + sorted(present - set(HEADERS))
    constants: dict[str, str] = {}
    parts = [header_text(folder / name, constants) for name in order]
    return "\n".join(parts), constants
