"""Feathers: generation from specs, NumPy views of their arrays, export."""

from __future__ import annotations

import json
import os
from typing import Any, Iterable, Optional, Union

import numpy as np

from ._lib import PYTHON_TERMS, Error, Handle, check, ffi, fspath, lib, memory_limit, new_error, text, view

PathLike = Union[str, "os.PathLike[str]"]
Spec = Union[dict, PathLike]

_STAGES = {"full": 0, "growth": 1, "unfurl": 2}

# plume_shaft_sample: position, tangent, normal, binormal (3 doubles each), width, t.
SHAFT_DTYPE = np.dtype(
    [("position", "<f8", 3), ("tangent", "<f8", 3), ("normal", "<f8", 3), ("binormal", "<f8", 3),
     ("width", "<f8"), ("t", "<f8")]
)


def _options(seed: Optional[int], stage: Optional[float], stage_kind: str, max_memory: Optional[int] = None) -> Any:
    # stage_kind is checked even without a stage: a misspelt kind must not pass unnoticed.
    if stage_kind not in ("growth", "unfurl"):
        raise ValueError(f"stage_kind is {stage_kind!r}, allowed 'growth' or 'unfurl'")
    options = ffi.new("plume_spec_options *")
    if seed is not None:
        options.seed = seed
        options.seed_given = True
    if stage is not None:
        options.stage_kind = _STAGES[stage_kind]
        options.stage = stage
    if max_memory is not None:
        options.max_memory = memory_limit(max_memory)
    return options


class Feather(Handle):
    """A generated feather (libplume's plume_feather).

    Arrays are read-only NumPy views into the feather's memory (no copy); each keeps
    the feather alive, so they stay valid after the Feather object itself is dropped.
    ``close()`` (or leaving a ``with`` block) frees the feather once no view refers to it
    (views hold a reference), otherwise the garbage collector frees it.

    Barb and barbule points share one pool: ``points``, ``normals``, ``widths``,
    ``arc_length`` and ``uv`` are (P, ...) arrays over it, and barb i is the rows
    ``barb_starts[i]:barb_starts[i] + barb_counts[i]``. The ragged form of the barbs alone is
    ``barb_points`` with ``barb_offsets`` (B + 1 entries): a view when the barbs lie back to
    back in the pool, a gathered copy when barbules sit between them.
    """

    _what = "feather"

    def __init__(self, pointer: Any, owner: Any = None, destroy: bool = True):
        self._ptr = ffi.gc(pointer, lib.plume_feather_destroy) if destroy else pointer
        # What views keep alive: the pointer (which frees the feather when collected) and
        # whatever the feather lives in (a coat, a scene, a parent feather). Never self: views
        # cached in self would make a reference cycle through cffi objects the GC cannot see.
        self._keep = (self._ptr, getattr(owner, "_keep", owner))
        self._info = lib.plume_feather_get_info(self._ptr)
        self._pool: Optional[dict[str, np.ndarray]] = None

    # -- lifetime -------------------------------------------------------------------
    def close(self) -> None:
        """Drops this object's reference: the feather is freed now unless views of it are alive."""
        self._pool = None
        super().close()

    # -- counts ---------------------------------------------------------------------
    @property
    def info(self) -> dict:
        """Summary counts: shaft samples, barbs per side, barbules, points, bounds, shaft length (m)."""
        i = self._info
        return {
            "shaft_sample_count": i.shaft_sample_count,
            "calamus_sample_count": i.calamus_sample_count,
            "barb_count": i.barb_count,
            "barb_count_left": i.barb_count_left,
            "barb_count_right": i.barb_count_right,
            "barbule_count": i.barbule_count,
            "point_count": i.point_count,
            "has_afterfeather": bool(i.has_afterfeather),
            "shaft_length": i.shaft_length,
            "bounds_min": (i.bounds_min.x, i.bounds_min.y, i.bounds_min.z),
            "bounds_max": (i.bounds_max.x, i.bounds_max.y, i.bounds_max.z),
        }

    @property
    def barb_count(self) -> int:
        return int(self._info.barb_count)

    @property
    def barbule_count(self) -> int:
        return int(self._info.barbule_count)

    @property
    def summary(self) -> Optional[dict]:
        """The generator's diagnostics (JSON object), or None."""
        s = lib.plume_feather_summary(self.pointer)
        return None if s == ffi.NULL else json.loads(text(s))

    # -- shaft ----------------------------------------------------------------------
    @property
    def shaft(self) -> np.ndarray:
        """The shaft samples, base first, as a structured array (fields of SHAFT_DTYPE)."""
        n = self._info.shaft_sample_count
        return view(self._keep, lib.plume_feather_shaft(self.pointer), n, SHAFT_DTYPE, (n,))

    @property
    def shaft_points(self) -> np.ndarray:
        """(S, 3) shaft centre line, m."""
        return self.shaft["position"]

    @property
    def shaft_widths(self) -> np.ndarray:
        """(S,) shaft diameter, m."""
        return self.shaft["width"]

    # -- barbs ----------------------------------------------------------------------
    def _curves(self) -> dict[str, np.ndarray]:
        if self._pool is not None:
            return self._pool
        f = self.pointer
        nb, nbb = self._info.barb_count, self._info.barbule_count
        barbs = [lib.plume_feather_barb(f, i) for i in range(nb)]
        barbules = [lib.plume_feather_barbule(f, i) for i in range(nbb)]
        curves = [b.curve for b in barbs] + [b.curve for b in barbules]
        base = None
        for c in curves:
            if c.count > 0:
                address = int(ffi.cast("uintptr_t", c.points))
                base = address if base is None else min(base, address)
        total = self._info.point_count

        def first(c: Any) -> int:
            return 0 if c.count == 0 else (int(ffi.cast("uintptr_t", c.points)) - base) // ffi.sizeof("plume_vec3")

        pool: dict[str, np.ndarray] = {}
        if base is not None:
            # The pool's parallel arrays start where the lowest curve starts in each of them.
            lowest = min((c for c in curves if c.count > 0), key=lambda c: first(c))
            pool["points"] = view(self._keep, lowest.points, total * 3, np.float64, (total, 3))
            pool["normals"] = view(self._keep, lowest.normals, total * 3, np.float64, (total, 3))
            pool["arc_length"] = view(self._keep, lowest.arc_length, total, np.float64, (total,))
            pool["widths"] = view(self._keep, lowest.widths, total, np.float64, (total,))
            pool["uv"] = view(self._keep, lowest.uv, total * 2, np.float64, (total, 2))
        else:
            pool["points"] = np.zeros((0, 3))
            pool["normals"] = np.zeros((0, 3))
            pool["arc_length"] = np.zeros(0)
            pool["widths"] = np.zeros(0)
            pool["uv"] = np.zeros((0, 2))
        pool["barb_first"] = np.array([first(b.curve) for b in barbs], dtype=np.int64)
        pool["barb_counts"] = np.array([b.curve.count for b in barbs], dtype=np.int64)
        pool["barb_side"] = np.array([b.side for b in barbs], dtype=np.int8)
        pool["barb_rachis_t"] = np.array([b.rachis_t for b in barbs], dtype=np.float64)
        pool["barb_segment"] = np.array([b.segment for b in barbs], dtype=np.int32)
        pool["barbule_first"] = np.array([first(b.curve) for b in barbules], dtype=np.int64)
        pool["barbule_counts"] = np.array([b.curve.count for b in barbules], dtype=np.int64)
        pool["barbule_barb"] = np.array([b.barb for b in barbules], dtype=np.int32)
        for a in pool.values():
            a.flags.writeable = False
        self._pool = pool
        return pool

    @property
    def points(self) -> np.ndarray:
        """(P, 3) every barb and barbule point, m (a view)."""
        return self._curves()["points"]

    @property
    def normals(self) -> np.ndarray:
        """(P, 3) unit ribbon normals of the points."""
        return self._curves()["normals"]

    @property
    def widths(self) -> np.ndarray:
        """(P,) widths of the points, m."""
        return self._curves()["widths"]

    @property
    def arc_length(self) -> np.ndarray:
        """(P,) arc length from each curve's first point, m."""
        return self._curves()["arc_length"]

    @property
    def uv(self) -> np.ndarray:
        """(P, 2) texture coordinates (s along the barb, t of its root on the shaft)."""
        return self._curves()["uv"]

    @property
    def barb_counts(self) -> np.ndarray:
        """(B,) points per barb."""
        return self._curves()["barb_counts"]

    @property
    def barb_starts(self) -> np.ndarray:
        """(B,) row of each barb's first point in the pool arrays (points, widths, ...)."""
        return self._curves()["barb_first"]

    @property
    def barb_offsets(self) -> np.ndarray:
        """(B + 1,) ragged offsets into barb_points (and barb_widths, barb_uv, barb_normals):
        barb i is rows barb_offsets[i]:barb_offsets[i + 1]."""
        return np.concatenate([[0], np.cumsum(self.barb_counts)]).astype(np.int64)

    def _barb_rows(self, name: str) -> np.ndarray:
        c = self._curves()
        first, counts = c["barb_first"], c["barb_counts"]
        if len(first) == 0:
            return c[name][:0]
        if first[0] == 0 and np.array_equal(first[1:], (first + counts)[:-1]):
            return c[name][: first[-1] + counts[-1]]  # back to back: a view
        rows = np.concatenate([np.arange(f, f + n) for f, n in zip(first, counts)])
        out = c[name][rows]  # interleaved with barbules: gathered (a copy)
        out.flags.writeable = False
        return out

    @property
    def barb_points(self) -> np.ndarray:
        """(sum of barb_counts, 3) barb points, barb after barb, m: a view of the pool when the
        barbs lie back to back in it (the generators without barbules), else a copy."""
        return self._barb_rows("points")

    @property
    def barb_widths(self) -> np.ndarray:
        return self._barb_rows("widths")

    @property
    def barb_uv(self) -> np.ndarray:
        return self._barb_rows("uv")

    @property
    def barb_normals(self) -> np.ndarray:
        return self._barb_rows("normals")

    @property
    def barb_sides(self) -> np.ndarray:
        """(B,) 0 left vane, 1 right vane."""
        return self._curves()["barb_side"]

    @property
    def barb_rachis_t(self) -> np.ndarray:
        """(B,) shaft arc-length fraction of each barb's root."""
        return self._curves()["barb_rachis_t"]

    @property
    def barb_segments(self) -> np.ndarray:
        return self._curves()["barb_segment"]

    def barb(self, i: int) -> np.ndarray:
        """(n, 3) points of barb i (a view)."""
        c = self._curves()
        if not 0 <= i < len(c["barb_first"]):
            raise IndexError(f"barb {i} of {len(c['barb_first'])}")
        f = c["barb_first"][i]
        return c["points"][f : f + c["barb_counts"][i]]

    @property
    def barbule_offsets(self) -> np.ndarray:
        return self._curves()["barbule_first"]

    @property
    def barbule_counts(self) -> np.ndarray:
        return self._curves()["barbule_counts"]

    @property
    def barbule_barbs(self) -> np.ndarray:
        return self._curves()["barbule_barb"]

    @property
    def afterfeather(self) -> Optional["Feather"]:
        """The afterfeather (owned by this feather), or None."""
        p = lib.plume_feather_afterfeather(self.pointer)
        return None if p == ffi.NULL else Feather(ffi.cast("plume_feather *", p), owner=self, destroy=False)

    # -- comparison, export ---------------------------------------------------------
    def equal(self, other: "Feather") -> bool:
        """Bit-for-bit equality of every array (plume_feather_equal)."""
        return bool(lib.plume_feather_equal(self.pointer, other.pointer))

    def clone(self) -> "Feather":
        p = lib.plume_feather_clone(self.pointer)
        if p == ffi.NULL:
            raise MemoryError("plume_feather_clone")
        return Feather(p)

    def write(self, path: PathLike, formats: Optional[Union[str, Iterable[str]]] = None) -> list[str]:
        """Writes the feather. formats: one or a list of "json", "obj", "usda"; each is written to
        path with that suffix. Without formats, path's own suffix picks one. Returns the paths written."""
        path = fspath(path, "path")
        root, suffix = os.path.splitext(path)
        if formats is None:
            formats = [suffix.lstrip(".").lower()]
            root_path = {formats[0]: path}
        else:
            formats = [formats] if isinstance(formats, str) else list(formats)  # "json" is one format, not four
            root_path = {f: f"{root}.{f}" for f in formats}
        writers = {"json": lib.plume_write_json, "obj": lib.plume_write_obj, "usda": lib.plume_write_usda}
        written = []
        for f in formats:
            if f not in writers:
                raise ValueError(f"format {f!r}; allowed: json, obj, usda")
            err = new_error()
            check(writers[f](self.pointer, os.fsencode(root_path[f]), err), err, files=(root_path[f],))
            written.append(root_path[f])
        return written

    @classmethod
    def read_json(cls, path: PathLike) -> "Feather":
        """Reads a feather JSON dump (plume generate's feather.json, or plume simulate's with its numbers in
        feather.bin): the same feather bit for bit."""
        path = fspath(path, "path")
        out = ffi.new("plume_feather **")
        err = new_error()
        check(lib.plume_read_json(os.fsencode(path), out, err), err, files=(path,))
        return cls(out[0])

    def __repr__(self) -> str:
        return f"<plume.Feather {self._info.barb_count} barbs, {self._info.point_count} points>"


def generate(spec: Spec, *, seed: Optional[int] = None, stage: Optional[float] = None,
             stage_kind: str = "growth", max_memory: Optional[int] = None) -> Feather:
    """Generates a feather from a spec: a dict (the JSON object of docs/specs) or a path to a
    JSON spec file, for every model (franco-walter, streit-heidrich, zhang-kanai).

    seed overrides the spec's seed; stage in [0, 1] builds a growth ("growth") or unfurling
    ("unfurl", Zhang–Kanai) stage. max_memory: bytes the feather may take (default 4 GiB), past
    which it fails with code "limit" before the work. A bad spec raises plume.Error naming the
    key's JSON path; a dict is named "<dict>" in messages, and its relative file references
    resolve against the working directory.
    """
    options = _options(seed, stage, stage_kind, max_memory)
    out = ffi.new("plume_feather **")
    err = new_error()
    files: tuple[str, ...] = ()
    if isinstance(spec, dict):
        if spec.get("model") == "coat":
            raise Error('<dict>: $.model: "coat" is a coat spec, not a feather: use plume.coat()', "$.model",
                        file="<dict>")
        status = lib.plume_spec_parse(json.dumps(spec).encode(), b"<dict>", options, out, err)
    else:
        path = fspath(spec, "spec", "a dict or a path (str, bytes or os.PathLike)")
        files = (path,)
        status = lib.plume_spec_generate(os.fsencode(path), options, out, err)
    try:
        check(status, err, rename=PYTHON_TERMS, files=files)
    except Error as e:
        # A dict's references (a blend's feathers, a scan image) resolve against the working directory.
        if not files and e.code == "io" and e.file not in (None, "<dict>") and not os.path.isabs(e.file):
            e.hint_relative()
        raise
    return Feather(out[0])


def _tangents(points: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Unit tangents of curves stored back to back (curve i: rows offsets[i]:offsets[i + 1]):
    central differences inside, one-sided at the ends."""
    n = len(points)
    t = np.zeros_like(points)
    if n < 2:
        return t
    starts, ends = offsets[:-1], offsets[1:] - 1
    t[1:-1] = points[2:] - points[:-2]
    t[starts] = points[np.minimum(starts + 1, n - 1)] - points[starts]
    t[ends] = points[ends] - points[np.maximum(ends - 1, 0)]
    length = np.linalg.norm(t, axis=1, keepdims=True)
    return np.divide(t, length, out=np.zeros_like(t), where=length > 0)


def ribbons(feather: Feather, *, shaft: bool = True) -> dict[str, np.ndarray]:
    """The feather's barbs (and shaft) as flat ribbons: each curve point becomes two vertices half a
    width either side of it, across the curve in the plane its normal faces (barbs are flat ribbons
    facing their normals, as plume's USD export and ray tracer treat them), and each curve segment
    a quad. Returns vertices (V, 3), quads (Q, 4) counter-clockwise seen from the normal, uv (V, 2)
    (the barb's (s, t); the shaft's (0, t)), side (V,) (0 left vane, 1 right, 2 shaft), and
    point (V,), the pool row (or -1 - shaft sample) each vertex came from."""
    curves_points = [feather.barb_points]
    curves_normals = [feather.barb_normals]
    curves_widths = [feather.barb_widths]
    curves_uv = [feather.barb_uv]
    offsets = [feather.barb_offsets]
    counts = feather.barb_counts
    sides = [np.repeat(feather.barb_sides.astype(np.int8), counts)]
    rows = [np.concatenate([np.arange(s, s + c) for s, c in zip(feather.barb_starts, counts)])
            if len(counts) else np.zeros(0, dtype=np.int64)]
    if shaft:
        sh = feather.shaft
        curves_points.append(sh["position"])
        curves_normals.append(sh["normal"])
        curves_widths.append(sh["width"])
        curves_uv.append(np.stack([np.zeros(len(sh)), sh["t"]], axis=1))
        offsets.append(np.array([0, len(sh)]) + offsets[0][-1])
        sides.append(np.full(len(sh), 2, dtype=np.int8))
        rows.append(-1 - np.arange(len(sh)))
    points = np.concatenate(curves_points)
    normals = np.concatenate(curves_normals)
    widths = np.concatenate(curves_widths)
    all_offsets = np.concatenate([offsets[0]] + [o[1:] for o in offsets[1:]])
    tangent = _tangents(points, all_offsets)
    across = np.cross(normals, tangent)
    length = np.linalg.norm(across, axis=1, keepdims=True)
    across = np.divide(across, length, out=np.zeros_like(across), where=length > 0)
    half = 0.5 * widths[:, None] * across
    vertices = np.empty((2 * len(points), 3))
    vertices[0::2] = points - half
    vertices[1::2] = points + half
    # Quads between consecutive points of one curve.
    first = np.arange(len(points) - 1)
    keep = np.ones(len(first), dtype=bool)
    keep[all_offsets[1:-1] - 1] = False  # no quad across two curves
    first = first[keep]
    quads = np.stack([2 * first, 2 * first + 2, 2 * first + 3, 2 * first + 1], axis=1)
    uv = np.repeat(np.concatenate(curves_uv), 2, axis=0)
    return {"vertices": vertices, "quads": quads, "uv": uv, "side": np.repeat(np.concatenate(sides), 2),
            "point": np.repeat(np.concatenate(rows), 2)}


def banded_colors(feather: Feather, width: int = 256, height: int = 256) -> np.ndarray:
    """(B points, 4) sRGBA colours of the barb points (barb_points' rows) from plume's own banded
    hawk texture (plume_texture_create_banded), by each point's (s, t) as Franco & Walter 4.4 map
    a texture onto the vanes."""
    # The C function answers NULL both for sizes below 2 and for memory: tell them apart here.
    for name, value in (("width", width), ("height", height)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 2 <= value <= 16384:
            raise ValueError(f"{name} is {value!r}; allowed a whole number of pixels in [2, 16384]")
    texture = ffi.gc(lib.plume_texture_create_banded(width, height), lib.plume_texture_destroy)
    if texture == ffi.NULL:
        raise MemoryError("plume_texture_create_banded")
    uv, sides = feather.barb_uv, np.repeat(feather.barb_sides, feather.barb_counts)
    out = np.empty((len(uv), 4))
    sample = lib.plume_texture_sample_vane
    for i, ((s, t), side) in enumerate(zip(uv.tolist(), sides.tolist())):
        c = sample(texture, side, s, t)
        out[i] = (c.r, c.g, c.b, c.a)
    return out
