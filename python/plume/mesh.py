"""Barb-aligned meshes of feathers (plume_mesh) as NumPy views."""

from __future__ import annotations

import os
from typing import Any, Optional, Union

import numpy as np

from ._lib import PYTHON_TERMS, Handle, check, ffi, fspath, lib, memory_limit, new_error, text, view
from .feather import Feather


class Mesh(Handle):
    """A triangle shell: ``vertices`` (rest, N x 3), ``reference`` (N x 2, the flat material
    coordinates), ``uv``, ``triangles`` (F x 3), ``barb_angles`` (F, radians from +x in the
    reference plane), ``materials`` (F; 0 vane, 1 rachis), ``barb_edges`` (E x 2) and
    ``groups`` (name -> vertex indices). Arrays are read-only views kept valid by the mesh."""

    _what = "mesh"

    def __init__(self, pointer: Any, report: Optional[dict] = None, owner: Any = None, destroy: bool = True):
        self._ptr = ffi.gc(pointer, lib.plume_mesh_destroy) if destroy else pointer
        self._keep = (self._ptr, getattr(owner, "_keep", owner))  # what views keep alive (not self)
        self.report = report or {}

    @property
    def vertex_count(self) -> int:
        return int(self.pointer.vertex_count)

    @property
    def face_count(self) -> int:
        return int(self.pointer.face_count)

    @property
    def vertices(self) -> np.ndarray:
        m = self.pointer
        return view(self._keep, m.rest, m.vertex_count * 3, np.float64, (m.vertex_count, 3))

    @property
    def reference(self) -> np.ndarray:
        m = self.pointer
        return view(self._keep, m.reference, m.vertex_count * 2, np.float64, (m.vertex_count, 2))

    @property
    def uv(self) -> np.ndarray:
        m = self.pointer
        return view(self._keep, m.uv, m.vertex_count * 2, np.float64, (m.vertex_count, 2))

    @property
    def triangles(self) -> np.ndarray:
        m = self.pointer
        return view(self._keep, m.faces, m.face_count * 3, np.intc, (m.face_count, 3))

    @property
    def barb_angles(self) -> np.ndarray:
        m = self.pointer
        return view(self._keep, m.barb_angle, m.face_count, np.float64, (m.face_count,))

    @property
    def materials(self) -> np.ndarray:
        m = self.pointer
        return view(self._keep, m.material, m.face_count, np.uint8, (m.face_count,))

    @property
    def barb_edges(self) -> np.ndarray:
        m = self.pointer
        return view(self._keep, m.barb_edges, m.barb_edge_count * 2, np.intc, (m.barb_edge_count, 2))

    @property
    def groups(self) -> dict[str, np.ndarray]:
        m = self.pointer
        out = {}
        for g in range(m.group_count):
            group = m.groups[g]
            out[text(group.name)] = view(self._keep, group.vertices, group.count, np.intc, (group.count,))
        return out

    def write_obj(self, path: Union[str, "os.PathLike[str]"], positions: Optional[np.ndarray] = None) -> None:
        """Wavefront OBJ with UVs, at positions (N x 3) or the rest shape."""
        path = fspath(path, "path")
        err = new_error()
        pos = ffi.NULL
        if positions is not None:
            positions = np.ascontiguousarray(positions, dtype=np.float64)
            if positions.shape != (self.vertex_count, 3):
                raise ValueError(f"positions has shape {positions.shape}, expected ({self.vertex_count}, 3)")
            pos = ffi.cast("const plume_vec3 *", ffi.from_buffer(positions))
        check(lib.plume_mesh_write_obj(self.pointer, pos, os.fsencode(path), err), err, files=(path,))

    def __repr__(self) -> str:
        return f"<plume.Mesh {self.vertex_count} vertices, {self.face_count} triangles>"


def _report(r: Any) -> dict:
    return {
        "min_angle": r.min_angle,
        "aligned_fraction": r.aligned_fraction,
        "guides_dropped": r.guides_dropped,
        "guide_count": (r.guide_count[0], r.guide_count[1]),
        "barbs_averaged": r.barbs_averaged,
        "vertices_trimmed": r.vertices_trimmed,
        "edge_length": r.edge_length,
        "vane_min_angle": r.vane_min_angle,
        "excepted_count": r.excepted_count,
    }


def mesh(feather: Feather, edge_length: Optional[float] = None, *, rachis_width_base: Optional[float] = None,
         rachis_width_tip: Optional[float] = None, include_calamus: bool = True,
         max_memory: Optional[int] = None) -> Mesh:
    """Meshes a feather with the barb-aligned mesher (Jouve thesis 6.2): its shaft is the rachis,
    its barbs the guides. edge_length in m (default 5e-3, thesis Table 6.1). max_memory: bytes the
    mesher may use (default 4 GiB), past which it fails with code "limit" before the work."""
    d = ffi.new("plume_mesh_def *", lib.plume_mesh_default_def())
    if edge_length is not None:
        d.edge_length = edge_length
    if rachis_width_base is not None:
        d.rachis_width_base = rachis_width_base
    if rachis_width_tip is not None:
        d.rachis_width_tip = rachis_width_tip
    d.include_calamus = include_calamus
    if max_memory is not None:
        d.max_memory = memory_limit(max_memory)
    out = ffi.new("plume_mesh **")
    report = ffi.new("plume_mesh_report *")
    err = new_error()
    check(lib.plume_mesh_from_feather(feather.pointer, d, out, report, err), err, rename=PYTHON_TERMS)
    return Mesh(out[0], _report(report[0]))
