"""Rendering: Embree ray tracing into a NumPy image, Cairo 2D pictures to files."""

from __future__ import annotations

import os
from typing import Optional, Sequence, Union

import numpy as np

from ._lib import check, ffi, lib, new_error
from .feather import Feather
from .mesh import Mesh


def render(feathers: Union[Feather, Sequence[Feather]] = (), *, width: int = 800, height: int = 800, spp: int = 16,
           shell: Optional[Mesh] = None, shell_positions: Optional[np.ndarray] = None,
           view_direction: Sequence[float] = (0.0, 0.0, 1.0), ground: bool = True, seed: int = 1,
           settings: Optional[Union[str, "os.PathLike[str]"]] = None, threads: int = 0) -> np.ndarray:
    """Ray-traces feathers (and an optional shell mesh at shell_positions) into a (height, width, 4)
    uint8 RGBA image, rows top first, with plume_raytrace_render. settings: a camera/lights JSON file
    (docs/render.md) read before the keyword values that differ from their defaults."""
    if isinstance(feathers, Feather):
        feathers = [feathers]
    d = ffi.new("plume_raytrace_def *", lib.plume_raytrace_default_def())
    err = new_error()
    if settings is not None:
        check(lib.plume_raytrace_def_read(os.fspath(settings).encode(), d, err), err)
    if settings is None or width != 800:
        d.camera.width = width
    if settings is None or height != 800:
        d.camera.height = height
    if settings is None or spp != 16:
        d.spp = spp
    if settings is None or tuple(view_direction) != (0.0, 0.0, 1.0):
        d.camera.view_direction = tuple(float(c) for c in view_direction)
    if settings is None or not ground:
        d.ground = ground
    d.seed = seed
    d.threads = threads
    pointers = ffi.new("const plume_feather *[]", [f.pointer for f in feathers] or [ffi.NULL])
    scene = ffi.new("plume_raytrace_scene *")
    scene.feather_count = len(feathers)
    scene.feathers = pointers
    keep = []
    if shell is not None:
        scene.shell = shell.pointer
        if shell_positions is not None:
            pos = np.ascontiguousarray(shell_positions, dtype=np.float64)
            keep.append(pos)
            scene.shell_positions = ffi.cast("const plume_vec3 *", ffi.from_buffer(pos))
    image = np.zeros((d.camera.height, d.camera.width, 4), dtype=np.uint8)
    check(lib.plume_raytrace_render(scene, d, ffi.cast("uint8_t *", ffi.from_buffer(image)), ffi.NULL, err), err)
    return image


def write_png(image: np.ndarray, path: Union[str, "os.PathLike[str]"]) -> None:
    """Writes a (height, width, 4) uint8 RGBA image as a PNG, atomically."""
    image = np.ascontiguousarray(image, dtype=np.uint8)
    if image.ndim != 3 or image.shape[2] != 4:
        raise ValueError(f"image has shape {image.shape}, expected (height, width, 4)")
    err = new_error()
    check(lib.plume_write_rgba_png(image.shape[1], image.shape[0], ffi.cast("const uint8_t *", ffi.from_buffer(image)),
                                   os.fspath(path).encode(), err), err)


_FORMATS = {"png": 0, "svg": 1, "pdf": 2}


def render2d(feather: Feather, path: Union[str, "os.PathLike[str]"], *, width: int = 1024, height: int = 1024,
             style: str = "lines") -> None:
    """Cairo's front view of the feather to a PNG, SVG or PDF file (by path's suffix)."""
    path = os.fspath(path)
    fmt = os.path.splitext(path)[1].lstrip(".").lower()
    if fmt not in _FORMATS:
        raise ValueError(f"{path}: format {fmt!r}; allowed png, svg, pdf")
    d = ffi.new("plume_render2d_def *", lib.plume_render2d_default_def())
    d.width, d.height = width, height
    d.style = {"lines": 0, "strips": 1}[style]
    err = new_error()
    check(lib.plume_render2d(feather.pointer, d, _FORMATS[fmt], path.encode(), err), err)
