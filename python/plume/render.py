"""Rendering: Embree ray tracing into a NumPy image, Cairo 2D pictures to files."""

from __future__ import annotations

import os
from typing import Optional, Sequence, Union

import numpy as np

from ._lib import check, ffi, fspath, lib, new_error
from .feather import Feather
from .mesh import Mesh


def _vector(value: Sequence[float], name: str, size: int = 3) -> tuple[float, ...]:
    """A vector argument as size finite floats: cffi would zero-fill a short one and reject a long
    one with a message that does not name the argument."""
    try:
        vector = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} is {value!r}; expected {size} finite numbers") from None
    if vector.shape != (size,) or not np.isfinite(vector).all():
        raise ValueError(f"{name} is {value!r}; expected {size} finite numbers")
    return tuple(float(c) for c in vector)


def render(feathers: Union[Feather, Sequence[Feather]] = (), *, width: int = 800, height: int = 800, spp: int = 16,
           shell: Optional[Mesh] = None, shell_positions: Optional[np.ndarray] = None,
           view_direction: Sequence[float] = (0.0, 0.0, 1.0), ground: bool = True, seed: int = 1,
           settings: Optional[Union[str, "os.PathLike[str]"]] = None, threads: int = 0) -> np.ndarray:
    """Ray-traces feathers (and an optional shell mesh, at shell_positions: (vertex_count, 3)
    finite floats, else its rest shape) into a (height, width, 4) uint8 RGBA image, rows top
    first, with plume_raytrace_render. settings: a camera/lights JSON file (docs/render.md) read
    before the keyword values that differ from their defaults."""
    if isinstance(feathers, Feather):
        feathers = [feathers]
    view_direction = _vector(view_direction, "view_direction")
    if shell_positions is not None and shell is None:
        raise ValueError("shell_positions is given without shell: pass the Mesh they are positions of")
    if shell_positions is not None:
        # The C library reads vertex_count positions from the buffer whatever its size: check it all here.
        pos = np.asarray(shell_positions)
        expected = (shell.vertex_count, 3)
        if pos.shape != expected or not (np.issubdtype(pos.dtype, np.floating) or np.issubdtype(pos.dtype, np.integer)):
            raise ValueError(f"shell_positions has shape {pos.shape} and dtype {pos.dtype}; expected shape {expected} "
                             "of real numbers: x, y, z of each vertex of shell, m")
        pos = np.ascontiguousarray(pos, dtype=np.float64)
        if not np.isfinite(pos).all():
            raise ValueError("shell_positions has non-finite values; expected finite positions, m")
    d = ffi.new("plume_raytrace_def *", lib.plume_raytrace_default_def())
    err = new_error()
    if settings is not None:
        settings = fspath(settings, "settings")
        check(lib.plume_raytrace_def_read(os.fsencode(settings), d, err), err, files=(settings,))
    if settings is None or width != 800:
        d.camera.width = width
    if settings is None or height != 800:
        d.camera.height = height
    if settings is None or spp != 16:
        d.spp = spp
    if settings is None or view_direction != (0.0, 0.0, 1.0):
        d.camera.view_direction = view_direction
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
            keep.append(pos)
            scene.shell_positions = ffi.cast("const plume_vec3 *", ffi.from_buffer(pos))
    image = np.zeros((d.camera.height, d.camera.width, 4), dtype=np.uint8)
    check(lib.plume_raytrace_render(scene, d, ffi.cast("uint8_t *", ffi.from_buffer(image)), ffi.NULL, err), err)
    return image


def write_png(image: np.ndarray, path: Union[str, "os.PathLike[str]"]) -> None:
    """Writes a (height, width, 4) uint8 RGBA image as a PNG, atomically."""
    path = fspath(path, "path")
    image = np.asarray(image)
    # No cast: floats in [0, 1] would become 0 and 300 would wrap to 44.
    if image.dtype != np.uint8:
        raise TypeError(f"image has dtype {image.dtype}, expected uint8 (RGBA bytes 0-255)")
    if image.ndim != 3 or image.shape[2] != 4 or 0 in image.shape:
        raise ValueError(f"image has shape {image.shape}, expected (height, width, 4) with height, width >= 1")
    image = np.ascontiguousarray(image)
    err = new_error()
    check(lib.plume_write_rgba_png(image.shape[1], image.shape[0], ffi.cast("const uint8_t *", ffi.from_buffer(image)),
                                   os.fsencode(path), err), err, files=(path,))


_FORMATS = {"png": 0, "svg": 1, "pdf": 2}


_STYLES = {"lines": 0, "strips": 1}


def render2d(feather: Feather, path: Union[str, "os.PathLike[str]"], *, width: int = 1024, height: int = 1024,
             style: str = "lines") -> None:
    """Cairo's front view of the feather to a PNG, SVG or PDF file (by path's suffix); style
    "lines" or "strips"."""
    path = fspath(path, "path")
    fmt = os.path.splitext(path)[1].lstrip(".").lower()
    if fmt not in _FORMATS:
        raise ValueError(f"{path}: format {fmt!r}; allowed png, svg, pdf")
    if not isinstance(style, str) or style not in _STYLES:
        raise ValueError(f"style is {style!r}; allowed {', '.join(map(repr, _STYLES))}")
    d = ffi.new("plume_render2d_def *", lib.plume_render2d_default_def())
    d.width, d.height = width, height
    d.style = _STYLES[style]
    err = new_error()
    check(lib.plume_render2d(feather.pointer, d, _FORMATS[fmt], os.fsencode(path), err), err, files=(path,))
