"""Coats of feathers on a surface (Streit & Heidrich 4.4; docs/coats.md)."""

from __future__ import annotations

import os
from typing import Any, Iterable, Optional, Union

import numpy as np

from ._lib import PYTHON_TERMS, Handle, absolute, check, check_spec, ffi, fspath, lib, new_error
from .feather import Feather, _options
from .mesh import Mesh


class Coat(Handle):
    """A groomed coat: ``feathers`` (placed, world coordinates, drawing order bottom to top),
    ``follicles`` and ``follicle_normals`` (K x 3), ``is_key`` (K,), the ``surface`` mesh."""

    _what = "coat"

    def __init__(self, pointer: Any):
        self._ptr = ffi.gc(pointer, lib.plume_coat_destroy)
        self._keep = self._ptr

    def __len__(self) -> int:
        return int(lib.plume_coat_feather_count(self.pointer))

    def feather(self, index: int) -> Feather:
        if not 0 <= index < len(self):
            raise IndexError(f"feather {index} of {len(self)}")
        p = lib.plume_coat_feather(self.pointer, index)
        return Feather(ffi.cast("plume_feather *", p), owner=self, destroy=False)

    @property
    def feathers(self) -> list[Feather]:
        return [self.feather(i) for i in range(len(self))]

    def _follicles(self) -> tuple[np.ndarray, np.ndarray]:
        n = len(self)
        pos, nor = np.zeros((n, 3)), np.zeros((n, 3))
        p, q = ffi.new("plume_vec3 *"), ffi.new("plume_vec3 *")
        for i in range(n):
            lib.plume_coat_follicle(self.pointer, i, p, q)
            pos[i] = (p.x, p.y, p.z)
            nor[i] = (q.x, q.y, q.z)
        return pos, nor

    @property
    def follicles(self) -> np.ndarray:
        return self._follicles()[0]

    @property
    def follicle_normals(self) -> np.ndarray:
        return self._follicles()[1]

    @property
    def is_key(self) -> np.ndarray:
        return np.array([bool(lib.plume_coat_is_key(self.pointer, i)) for i in range(len(self))])

    @property
    def surface(self) -> Mesh:
        p = lib.plume_coat_surface(self.pointer)
        return Mesh(ffi.cast("plume_mesh *", p), owner=self, destroy=False)

    def write(self, path: Union[str, "os.PathLike[str]"], formats: Optional[Iterable[str]] = None) -> list[str]:
        """OBJ (one object per feather) and/or USD text, by formats or path's suffix."""
        path = fspath(path, "path")
        root, suffix = os.path.splitext(path)
        if formats is None:
            formats = [suffix.lstrip(".").lower()]
        else:
            formats = [formats] if isinstance(formats, str) else list(formats)  # "obj" is one format, not three
        writers = {"obj": lib.plume_coat_write_obj, "usda": lib.plume_coat_write_usda}
        written = []
        for f in formats:
            if f not in writers:
                raise ValueError(f"format {f!r}; allowed: obj, usda")
            target = path if len(formats) == 1 and suffix == "." + f else f"{root}.{f}"
            err = new_error()
            check(writers[f](self.pointer, os.fsencode(target), err), err, files=(target,))
            written.append(target)
        return written

    def __repr__(self) -> str:
        return f"<plume.Coat {len(self)} feathers>"


def _sh_references(spec: Any, made: set[str]) -> None:
    """The file references of an inline streit-heidrich spec (docs/spec-streit-heidrich.md): its
    and its afterfeather's barb_length_scan image, and the feathers it blends (files or inline)."""
    if not isinstance(spec, dict):
        return
    for params in (spec, spec.get("afterfeather")):
        scan = params.get("barb_length_scan") if isinstance(params, dict) else None
        if isinstance(scan, dict) and "image" in scan:
            scan["image"] = absolute(scan["image"], made)
    blend = spec.get("blend")
    feathers = blend.get("feathers") if isinstance(blend, dict) else None
    if isinstance(feathers, list):
        for i, feather in enumerate(feathers):
            feathers[i] = absolute(feather, made)
            _sh_references(feather, made)


def _coat_references(spec: dict) -> set[str]:
    """Makes a coat dict's relative file references (docs/coats.md: the surface OBJ, key feather
    spec files, and those of inline key feathers) absolute against the working directory."""
    made: set[str] = set()
    surface = spec.get("surface")
    if isinstance(surface, dict) and "obj" in surface:
        surface["obj"] = absolute(surface["obj"], made)
    keys = spec.get("key_feathers")
    for key in keys if isinstance(keys, list) else ():
        if isinstance(key, dict) and "feather" in key:
            key["feather"] = absolute(key["feather"], made)
            _sh_references(key["feather"], made)
    return made


def coat(spec: Union[dict, str, "os.PathLike[str]"], *, seed: Optional[int] = None,
         stage: Optional[float] = None, max_memory: Optional[int] = None) -> Coat:
    """Grooms a coat from a coat spec ("model": "coat"): a dict or a path. A spec file's file
    references (key feathers, surface OBJ) resolve against its folder, a dict's against the
    working directory; messages name a dict "<dict>". max_memory: bytes the coat may take
    (default 4 GiB), past which it fails with code "limit" before the work."""
    options = _options(seed, stage, "growth", max_memory)
    out = ffi.new("plume_coat **")
    err = new_error()
    check_spec(spec, "coat.json", lambda path: lib.plume_coat_spec_generate(path, options, out, err), err,
               references=_coat_references, rename=PYTHON_TERMS)
    return Coat(out[0])
