"""Simulation of scenes (docs/scene.md): a feather held by handles under gravity and loads."""

from __future__ import annotations

import json
import math
import os
from typing import Any, Optional, Sequence, Union

import numpy as np

from ._lib import Closable, Error, check, ffi, lib, new_error, text, view
from .feather import Feather, _options
from .mesh import Mesh, _report

Vec3 = Sequence[float]


def _solve_report(r: Any) -> dict:
    return {
        "converged": bool(r.converged),
        "newton_iterations": r.newton_iterations,
        "substeps": r.substeps,
        "gradient_norm": r.gradient_norm,
        "energy": r.energy,
        "max_barb_strain": r.max_barb_strain,
        "seconds_assembly": r.seconds_assembly,
        "seconds_factor": r.seconds_factor,
        "seconds_solve": r.seconds_solve,
        "seconds_contact": r.seconds_contact,
    }


def _vec(v: Vec3) -> Any:
    x, y, z = (float(c) for c in v)
    return ffi.new("plume_vec3 *", (x, y, z))[0]


class Simulation(Closable):
    """A scene (a dict or a scene file) and its running simulation.

    ``step()`` advances one time step with the scene's handles posed at the end of the step
    (a static solve for quasi-static scenes, as `plume simulate` does); ``run()`` steps to the
    scene's duration. ``positions`` is a live (N, 3) view of the current positions, valid while
    the simulation lives. ``reports`` collects one dict per step.
    """

    def __init__(self, scene: Union[dict, str, "os.PathLike[str]"], *, seed: Optional[int] = None):
        options = _options(seed, None, "growth")
        out = ffi.new("plume_scene **")
        err = new_error()
        if isinstance(scene, dict):
            status = lib.plume_scene_parse(json.dumps(scene).encode(), b"<dict>", options, out, err)
        else:
            status = lib.plume_scene_load(os.fspath(scene).encode(), options, out, err)
        check(status, err)
        self._scene = ffi.gc(out[0], lib.plume_scene_destroy)
        s = self._scene
        sim = ffi.new("plume_sim **")
        check(lib.plume_sim_create(s.mesh, ffi.addressof(s.sim), sim, err), err)
        self._sim = ffi.gc(sim[0], lib.plume_sim_destroy)
        self._keep = (self._sim, self._scene)  # what views keep alive (not self)
        self._handle_ids = []
        for h in range(s.handle_count):
            hid = lib.plume_sim_add_handle(self._sim, s.handles[h].group, err)
            if hid < 0:
                raise Error.from_c(err)
            self._handle_ids.append(hid)
        self._loads: dict[str, tuple[float, float, float]] = {}
        for i in range(s.force_count):
            f = s.forces[i]
            self.set_load(text(f.group), (f.force.x, f.force.y, f.force.z))
        self.step_count = 0
        self.reports: list[dict] = []
        self.mesh = Mesh(s.mesh, _report(s.mesh_report), owner=self, destroy=False)
        self.feather = None if s.feather == ffi.NULL else Feather(s.feather, owner=self, destroy=False)

    # -- lifetime -------------------------------------------------------------------
    def close(self) -> None:
        """Frees the simulation and its scene (views of positions keep them until dropped)."""
        self._sim = None
        self._scene = None
        self._keep = None
        self.mesh = None
        self.feather = None

    def _live(self) -> Any:
        if self._sim is None:
            raise ValueError("the simulation was closed")
        return self._sim

    # -- scene ----------------------------------------------------------------------
    @property
    def time_step(self) -> float:
        return float(self._scene.sim.time_step)

    @property
    def duration(self) -> float:
        return float(self._scene.duration)

    @property
    def quasi_static(self) -> bool:
        return bool(self._scene.quasi_static)

    @property
    def steps_total(self) -> int:
        """Steps `plume simulate` runs for this scene: ceil(duration / time_step)."""
        return int(math.ceil(self.duration / self.time_step - 1e-9))

    @property
    def handles(self) -> list[dict]:
        """The scene's handles: group, pivot and keyframes (time, translation, axis, angle)."""
        out = []
        s = self._scene
        for h in range(s.handle_count):
            handle = s.handles[h]
            keys = [
                {"time": k.time, "translation": (k.translation.x, k.translation.y, k.translation.z),
                 "axis": (k.axis.x, k.axis.y, k.axis.z), "angle": k.angle}
                for k in (handle.keyframes[i] for i in range(handle.keyframe_count))
            ]
            out.append({"group": text(handle.group), "pivot": (handle.pivot.x, handle.pivot.y, handle.pivot.z),
                        "keyframes": keys})
        return out

    @property
    def loads(self) -> dict[str, tuple[float, float, float]]:
        """Constant forces, N, per vertex group."""
        return dict(self._loads)

    def set_load(self, group: str, force: Vec3) -> None:
        """A constant force, N, shared by the group's vertices (replaces the group's load)."""
        err = new_error()
        check(lib.plume_sim_set_group_load(self._live(), group.encode(), _vec(force), err), err)
        self._loads[group] = tuple(float(c) for c in force)  # type: ignore[assignment]

    def add_handle(self, group: str) -> int:
        """Holds a vertex group where it is; returns the handle's index for set_handle."""
        err = new_error()
        hid = lib.plume_sim_add_handle(self._live(), group.encode(), err)
        if hid < 0:
            raise Error.from_c(err)
        return int(hid)

    def set_handle(self, handle: int, translation: Vec3 = (0, 0, 0), rotation: Optional[np.ndarray] = None,
                   pivot: Vec3 = (0, 0, 0)) -> None:
        """Moves a handle rigidly: rotation (3 x 3) about pivot, then translation, m."""
        r = ffi.new("plume_mat3 *")
        m = np.eye(3) if rotation is None else np.asarray(rotation, dtype=np.float64)
        for i in range(3):
            for j in range(3):
                r.m[i][j] = float(m[i, j])
        lib.plume_sim_set_handle(self._live(), handle, _vec(translation), r[0], _vec(pivot))

    def _pose_handles(self, t: float) -> None:
        s = self._scene
        translation = ffi.new("plume_vec3 *")
        rotation = ffi.new("plume_mat3 *")
        for h, hid in enumerate(self._handle_ids):
            lib.plume_scene_handle_pose(ffi.addressof(s.handles[h]), t, translation, rotation)
            lib.plume_sim_set_handle(self._sim, hid, translation[0], rotation[0], s.handles[h].pivot)

    # -- state ----------------------------------------------------------------------
    @property
    def time(self) -> float:
        return float(lib.plume_sim_time(self._live()))

    @property
    def vertex_count(self) -> int:
        return int(lib.plume_sim_vertex_count(self._live()))

    @property
    def constraint_count(self) -> int:
        return int(lib.plume_sim_constraint_count(self._live()))

    @property
    def positions(self) -> np.ndarray:
        """(N, 3) current positions, m: a live read-only view (it changes as the simulation steps)."""
        n = self.vertex_count
        return view(self._keep, lib.plume_sim_positions(self._sim), n * 3, np.float64, (n, 3))

    @property
    def velocities(self) -> np.ndarray:
        n = self.vertex_count
        return view(self._keep, lib.plume_sim_velocities(self._sim), n * 3, np.float64, (n, 3))

    def energies(self) -> dict:
        e = lib.plume_sim_energy(self._live())
        return {"membrane": e.membrane, "bending": e.bending, "compression": e.compression,
                "gravity": e.gravity, "kinetic": e.kinetic,
                "contact": e.contact, "friction": e.friction}

    def reaction(self, group: str) -> tuple[float, float, float]:
        """Force, N, a handle must apply to hold the group where it is."""
        f = ffi.new("plume_vec3 *")
        if not lib.plume_sim_group_reaction(self._live(), group.encode(), f):
            raise Error(f"unknown vertex group {group!r}", None, "spec", 3)
        return (f.x, f.y, f.z)

    # -- solving --------------------------------------------------------------------
    def step(self) -> dict:
        """One step: handles posed at the step's end time from the scene's keyframes, then an
        implicit-Euler step (or a static solve in a quasi-static scene). Returns its report."""
        sim = self._live()
        self.step_count += 1
        self._pose_handles(self.step_count * self.time_step)
        report = ffi.new("plume_solve_report *")
        err = new_error()
        status = (lib.plume_sim_solve_static if self.quasi_static else lib.plume_sim_step)(sim, report, err)
        if status != lib.PLUME_OK:
            self.step_count -= 1
            lib.plume_error_prefix(err, b"quasi-static solve" if self.quasi_static else b"simulation")
            raise Error.from_c(err)
        r = _solve_report(report[0])
        r["step"] = self.step_count
        r["time"] = self.step_count * self.time_step
        self.reports.append(r)
        return r

    def solve_static(self) -> dict:
        """The static equilibrium with the handles where they are."""
        report = ffi.new("plume_solve_report *")
        err = new_error()
        check(lib.plume_sim_solve_static(self._live(), report, err), err)
        return _solve_report(report[0])

    def run(self, steps: Optional[int] = None) -> list[dict]:
        """Runs the remaining steps of the scene's duration (or `steps` more); returns their reports."""
        count = self.steps_total - self.step_count if steps is None else steps
        return [self.step() for _ in range(count)]

    def __repr__(self) -> str:
        return f"<plume.Simulation {self.vertex_count} vertices, t = {self.time:g} s>"
