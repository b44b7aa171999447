"""Loading libplume through cffi (ABI mode) and turning its errors into plume.Error."""

from __future__ import annotations

import ctypes.util
import json
import os
import pathlib
import re
import shutil
import subprocess
import tempfile
from typing import Any, Callable, Iterable, Optional, TypeVar

import cffi
import numpy as np

from . import _headers

_PACKAGE = pathlib.Path(__file__).resolve().parent


def _pkg_config(variable: str) -> Optional[str]:
    if shutil.which("pkg-config") is None:
        return None
    try:
        out = subprocess.run(
            ["pkg-config", f"--variable={variable}", "plume"], capture_output=True, text=True, check=True
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None
    return out or None


def _cdef_text() -> str:
    """The declarations: bundled at install time (setup.py), else the source tree's headers."""
    include = os.environ.get("PLUME_INCLUDE_DIR")
    if include:
        return _headers.cdef(include)[0]
    bundled = _PACKAGE / "_cdef.h"
    if bundled.exists():
        return bundled.read_text()
    source_include = _PACKAGE.parent.parent / "include"
    if (source_include / "plume" / "core.h").exists():
        return _headers.cdef(source_include)[0]
    include = _pkg_config("includedir")
    if include and (pathlib.Path(include) / "plume" / "core.h").exists():
        return _headers.cdef(include)[0]
    raise ImportError("plume: cannot find libplume's headers (set PLUME_INCLUDE_DIR to the folder holding plume/core.h)")


def _library_path() -> str:
    """libplume.so: $PLUME_LIBRARY, $PLUME_BUILD_DIR/libplume.so, the path recorded at install, pkg-config, the loader."""
    explicit = os.environ.get("PLUME_LIBRARY")
    if explicit:
        return explicit
    build = os.environ.get("PLUME_BUILD_DIR")
    if build:
        return str(pathlib.Path(build) / "libplume.so")
    recorded = _PACKAGE / "_libpath.txt"
    if recorded.exists():
        path = recorded.read_text().strip()
        if os.path.exists(path):
            return path
    libdir = _pkg_config("libdir")
    if libdir and os.path.exists(os.path.join(libdir, "libplume.so")):
        return os.path.join(libdir, "libplume.so")
    found = ctypes.util.find_library("plume")
    if found:
        return found
    raise ImportError(
        "plume: cannot find libplume.so; `make install` it (pkg-config plume), or set PLUME_BUILD_DIR to a build folder"
    )


ffi = cffi.FFI()
ffi.cdef(_cdef_text())
library_path = _library_path()
# Never unloaded: Embree's worker threads (TBB) outlive the interpreter's teardown, and
# unmapping their code under them crashes the process at exit.
lib: Any = ffi.dlopen(library_path, ffi.RTLD_NOW | getattr(ffi, "RTLD_NODELETE", 0))


class Error(Exception):
    """A failed libplume call.

    Attributes:
        message: the library's whole message (it names the file and the JSON path).
        path: the JSON path the message names ("$.segments[1].barb_count"), or None.
        file: the file (or "<dict>") the message names, or None.
        code: the status's stable name: "io", "syntax", "spec", "memory", "numeric", "unsupported".
        status: the numeric plume_status.
    """

    def __init__(self, message: str, path: Optional[str] = None, code: str = "spec", status: int = 3,
                 file: Optional[str] = None):
        super().__init__(message)
        self.message = message
        self.path = path
        self.code = code
        self.status = status
        self.file = file

    def hint_relative(self) -> None:
        """Adds to the message of a file not found from a dict spec where its relative name was looked for."""
        self.message += " (a dict spec's relative file references resolve against the working directory)"
        self.args = (self.message,)

    @classmethod
    def from_c(cls, err: Any, rename: Optional[dict[str, str]] = None, files: Iterable[str] = ()) -> "Error":
        message = ffi.string(err.message).decode("utf-8", "replace")
        for old, new in (rename or {}).items():
            message = message.replace(old, new)
        status = int(err.status)
        code = ffi.string(lib.plume_status_name(status)).decode()
        match = re.search(r"(\$[\w.\[\]\"-]*)", message)
        path = match.group(1).rstrip(":.") if match else None
        return cls(message, path, code, status, _file_of(message, files))


# A message that names a file starts with it: "PATH: ...", "PATH:LINE: ..." (OBJ) or
# "PATH:LINE:COL: ..." (JSON syntax). Others start with a context instead ("raytrace: ...",
# "calibration: ...", "simulation: ..."), so the first part counts as a file only when it is one
# the caller passed, "<dict>", or looks like a path: a folder in it or a suffix (".json").
_PREFIX = re.compile(r"((?:(?!: ).)+?)(?::\d+){0,2}: ")
_FILE_LIKE = re.compile(r"[/\\]|\.[A-Za-z][A-Za-z0-9]*$")


def _file_of(message: str, files: Iterable[str] = ()) -> Optional[str]:
    match = _PREFIX.match(message)
    if match is None:
        return None
    name = match.group(1)
    if name in files or name == "<dict>" or (not name.startswith("$") and _FILE_LIKE.search(name)):
        return name
    return None


def new_error() -> Any:
    return ffi.new("plume_error *")


# The library's messages name the CLI's options; calls that take the matching keyword name that.
PYTHON_TERMS = {
    "raise it with --max-memory": "raise it with the max_memory keyword",
    "drop --unfurl": 'use stage_kind="growth"',
}


def check(status: int, err: Any, rename: Optional[dict[str, str]] = None, files: Iterable[str] = ()) -> None:
    """Raises plume.Error when status is not PLUME_OK. rename: replacements in the message;
    files: paths the caller passed, which count as the message's file when it starts with one."""
    if status != lib.PLUME_OK:
        raise Error.from_c(err, rename, files)


def fspath(value: Any, name: str, expected: str = "a path (str, bytes or os.PathLike)") -> str:
    """A path argument (str, bytes or os.PathLike) as str; TypeError naming the argument otherwise."""
    try:
        return os.fsdecode(value)
    except TypeError:
        raise TypeError(f"{name} is {type(value).__name__}; expected {expected}") from None


def memory_limit(max_memory: Any) -> int:
    """A max_memory keyword's bytes. The C structs' 0 means the library's default (4 GiB), not
    "nothing allowed", so it is refused here with anything else that is not a count of bytes."""
    if isinstance(max_memory, bool) or not isinstance(max_memory, (int, np.integer)) or not 0 < max_memory < 2**64:
        raise ValueError(f"max_memory is {max_memory!r}; allowed a whole number of bytes in [1, 2**64)")
    return int(max_memory)


def check_spec(spec: Any, name: str, call: Callable[[bytes], int], err: Any,
               references: Optional[Callable[[dict], set[str]]] = None,
               rename: Optional[dict[str, str]] = None) -> None:
    """Calls call(path) on a spec file, or on a dict written as JSON to a temporary file
    (whose messages then name it "<dict>"), and raises plume.Error when it fails.

    The C readers resolve a spec's file references against the spec's folder, which for a dict
    would be the temporary folder: references(spec) makes a copy's relative references absolute
    against the working directory first (as open() and plume.generate's dicts resolve them) and
    returns the paths it made. rename: further replacements in the message (PYTHON_TERMS)."""
    if isinstance(spec, dict):
        made: set[str] = set()
        if references is not None:
            spec = json.loads(json.dumps(spec))  # a copy to rewrite, never the caller's dict
            made = references(spec)
        with tempfile.TemporaryDirectory(prefix="plume-") as folder:
            path = os.path.join(folder, name)
            with open(path, "w") as f:
                json.dump(spec, f)
            # A reference not rewritten resolves in the temporary folder: name it as it was written.
            names = {path: "<dict>", folder + os.sep: "", **(rename or {})}
            try:
                check(call(os.fsencode(path)), err, rename=names)
            except Error as e:
                # The file not found is one of the rewritten references (the message may name the
                # spec first: "<dict>: $.surface.obj: /cwd/cap.obj: cannot open: ...").
                if e.code == "io" and any(f"{p}: cannot" in e.message for p in made):
                    e.hint_relative()
                raise
    else:
        path = fspath(spec, "spec", "a dict or a path (str, bytes or os.PathLike)")
        check(call(os.fsencode(path)), err, rename=rename, files=(path,))


def absolute(path: Any, made: set[str]) -> Any:
    """path made absolute against the working directory when it is a relative str (recorded in made)."""
    if isinstance(path, str) and path and not os.path.isabs(path):
        path = os.path.abspath(path)
        made.add(path)
    return path


def view(owner: Any, pointer: Any, count: int, dtype: Any, shape: tuple[int, ...]) -> np.ndarray:
    """A NumPy array over count C items at pointer, without copying, that keeps owner alive.

    The buffer keeps a cdata alive whose (never called before collection) destructor closes
    over owner, so the memory cannot be freed while any view of it exists.
    """
    dtype = np.dtype(dtype)
    if count == 0 or pointer == ffi.NULL:
        return np.zeros(shape, dtype)
    keeper = ffi.gc(ffi.cast("char *", pointer), lambda _p, _owner=owner: None)
    size = int(np.prod(shape)) * dtype.itemsize
    array = np.frombuffer(ffi.buffer(keeper, size), dtype=dtype).reshape(shape)
    array.flags.writeable = False
    return array


def text(s: Any) -> str:
    return ffi.string(s).decode("utf-8", "replace")


def bytes_in_use() -> int:
    """Bytes libplume has allocated and not freed (its allocator's counter, all threads)."""
    return int(lib.plume_bytes_in_use())


_Self = TypeVar("_Self", bound="Closable")


class Closable:
    """``with`` support for the wrappers of libplume objects: leaving the block calls close()."""

    def __enter__(self: _Self) -> _Self:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def close(self) -> None:
        raise NotImplementedError


class Handle(Closable):
    """A wrapper of one libplume object: ``_ptr`` (the pointer, freed by cffi's gc when no view
    keeps it), ``_keep`` (what views keep alive) and ``_what`` (its name in messages)."""

    _what = "object"
    _ptr: Any
    _keep: Any

    def close(self) -> None:
        """Drops this object's reference: the object is freed now unless views of it are alive."""
        self._ptr = None
        self._keep = None

    @property
    def pointer(self) -> Any:
        if self._ptr is None:
            raise ValueError(f"the {self._what} was closed")
        return self._ptr
