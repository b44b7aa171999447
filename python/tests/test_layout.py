"""The binding's struct layouts are the C compiler's: a program compiled against the headers
prints sizeof and offsetof of every struct and field the cdef declares."""

import shutil
import subprocess

import cffi
import pytest

from plume._lib import ffi


def test_every_struct_matches_the_compiler(source, tmp_path):
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    lines = ['#include <stddef.h>', '#include <stdio.h>', '#include "plume/plume.h"', "int main(void) {"]
    expected = []
    for name in ffi.list_types()[0]:  # typedef names
        try:
            t = ffi.typeof(name)
        except cffi.CDefError:  # function types (plume_alloc_fn, ...)
            continue
        if t.kind != "struct" or t.fields is None:  # opaque objects
            continue
        lines.append(f'printf("%zu\\n", sizeof({name}));')
        expected.append((f"sizeof {name}", ffi.sizeof(t)))
        for field, info in t.fields:
            lines.append(f'printf("%zu\\n", offsetof({name}, {field}));')
            expected.append((f"{name}.{field}", info.offset))
    lines += ["return 0; }"]
    (tmp_path / "layout.c").write_text("\n".join(lines))
    subprocess.run([cc, "-std=c11", "-I", str(source / "include"), "-o", str(tmp_path / "layout"),
                    str(tmp_path / "layout.c")], check=True)
    out = subprocess.run([str(tmp_path / "layout")], capture_output=True, text=True, check=True).stdout.split()
    assert len(out) == len(expected)
    wrong = [(what, want, int(got)) for (what, want), got in zip(expected, out) if want != int(got)]
    assert not wrong, f"cffi and the compiler disagree on: {wrong[:10]}"
    assert len(expected) > 300  # every public struct was seen


def test_header_preprocessor(tmp_path):
    from plume import _headers

    assert _headers._integer_expression("64") == 64
    assert _headers._integer_expression("0x706c756du") == 0x706C756D
    assert _headers._integer_expression("(4ull << 30)") == 4 << 30
    assert _headers._integer_expression("plume_v3(0, 0, 0)") is None
    header = tmp_path / "x.h"
    header.write_text('#define PLUME_N 0x10u\n#define PLUME_F(x) ((x) + 1)\ntypedef struct t { int a[PLUME_N]; } t;\n'
                      "static inline int f(int x) { if (x) { return 1; } return 0; }\nint g(void);\n")
    constants = {}
    text = _headers.header_text(header, constants)
    assert constants == {"PLUME_N": "16"}
    assert "int a[16]" in text and "inline" not in text and "int g(void);" in text
    header.write_text("#pragma once\n")
    with pytest.raises(ValueError, match="unsupported directive"):
        _headers.header_text(header, {})
