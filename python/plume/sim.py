"""Simulation of scenes (docs/scene.md): a feather held by handles under gravity and loads."""

from __future__ import annotations

import json
import math
import os
from typing import Any, Optional, Sequence, Union

import numpy as np

from ._lib import PYTHON_TERMS, Closable, Error, check, ffi, fspath, lib, new_error, text, view
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


def _vec(v: Vec3, name: str) -> Any:
    """A finite 3-vector for the library; ValueError naming the argument otherwise."""
    a = np.asarray(v, dtype=np.float64)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be 3 finite numbers; got {v!r}")
    return ffi.new("plume_vec3 *", (float(a[0]), float(a[1]), float(a[2])))[0]


class Simulation(Closable):
    """A scene (a dict or a scene file) and its running simulation.

    ``step()`` advances one time step with the scene's handles posed at the end of the step
    (a static solve for quasi-static scenes, as `plume simulate` does); ``run()`` steps to the
    scene's duration. ``positions`` is a live (N, 3) view of the current positions, valid while
    the simulation lives. ``reports`` collects one dict per step.
    """

    def __init__(self, scene: Union[dict, str, bytes, "os.PathLike[str]"], *, seed: Optional[int] = None,
                 max_memory: Optional[int] = None):
        options = _options(seed, None, "growth", max_memory)
        out = ffi.new("plume_scene **")
        err = new_error()
        rename = PYTHON_TERMS  # the limit's message names the max_memory keyword, not --max-memory
        if isinstance(scene, dict):
            status = lib.plume_scene_parse(json.dumps(scene).encode(), b"<dict>", options, out, err)
            check(status, err, rename=rename)
        else:
            path = fspath(scene, "scene", "a dict or a path (str, bytes or os.PathLike)")
            check(lib.plume_scene_load(os.fsencode(path), options, out, err), err, rename=rename, files=(path,))
        self._scene = ffi.gc(out[0], lib.plume_scene_destroy)
        s = self._scene
        # The library's scene runner: the run `plume simulate` makes (follicle handles carried
        # by the body's bones, the body's pose and contact with it), one step at a time.
        runner = ffi.new("plume_scene_runner **")
        check(lib.plume_scene_runner_create(s, runner, err), err)
        # The runner refers to the scene: it is destroyed first (the gc keeps the scene alive).
        scene_ref = self._scene
        self._runner = ffi.gc(runner[0], lambda r: (lib.plume_scene_runner_destroy(r), scene_ref))
        self._sim = lib.plume_scene_runner_sim(self._runner)
        self._keep = (self._runner, self._scene)  # what views keep alive (not self)
        self._loads: dict[str, tuple[float, float, float]] = {}
        for i in range(s.force_count):
            f = s.forces[i]
            self._loads[text(f.group)] = (f.force.x, f.force.y, f.force.z)
        self.reports: list[dict] = []
        self.mesh = Mesh(s.mesh, _report(s.mesh_report), owner=self, destroy=False)
        self.feather = None if s.feather == ffi.NULL else Feather(s.feather, owner=self, destroy=False)

    # -- lifetime -------------------------------------------------------------------
    def close(self) -> None:
        """Frees the simulation and its scene (views of positions keep them until dropped)."""
        self._runner = None
        self._sim = None
        self._scene = None
        self._keep = None
        self.mesh = None
        self.feather = None

    def _live(self) -> Any:
        if self._sim is None:
            raise ValueError("the simulation was closed")
        return self._sim

    def _live_scene(self) -> Any:
        self._live()
        return self._scene

    # -- scene ----------------------------------------------------------------------
    @property
    def time_step(self) -> float:
        return float(self._live_scene().sim.time_step)

    @property
    def duration(self) -> float:
        return float(self._live_scene().duration)

    @property
    def quasi_static(self) -> bool:
        return bool(self._live_scene().quasi_static)

    @property
    def steps_total(self) -> int:
        """Steps `plume simulate` runs for this scene: ceil(duration / time_step), at least 1."""
        self._live()
        return int(lib.plume_scene_runner_step_count(self._runner))

    @property
    def step_count(self) -> int:
        """Steps taken so far."""
        self._live()
        return int(lib.plume_scene_runner_steps_done(self._runner))

    @property
    def handles(self) -> list[dict]:
        """The scene's handles: group, pivot and keyframes (time, translation, axis, angle)."""
        out = []
        s = self._live_scene()
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
        check(lib.plume_sim_set_group_load(self._live(), group.encode(), _vec(force, "force"), err), err)
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
        """Moves a handle rigidly: rotation (3 x 3) about pivot, then translation, m.

        A scene's own handles (indices 0 .. len(handles) - 1) go back to their keyframes at the
        next step; handles from add_handle stay where they are set."""
        sim = self._live()
        count = int(lib.plume_sim_handle_count(sim))
        if isinstance(handle, bool) or not isinstance(handle, (int, np.integer)) or not 0 <= handle < count:
            raise ValueError(f"handle is {handle!r}; allowed an index from add_handle or the scene, 0 to {count - 1}")
        m = np.eye(3) if rotation is None else np.asarray(rotation, dtype=np.float64)
        if m.shape != (3, 3) or not np.all(np.isfinite(m)):
            raise ValueError(f"rotation must be a finite 3 x 3 matrix; got shape {m.shape}")
        r = ffi.new("plume_mat3 *")
        for i in range(3):
            for j in range(3):
                r.m[i][j] = float(m[i, j])
        lib.plume_sim_set_handle(sim, int(handle), _vec(translation, "translation"), r[0], _vec(pivot, "pivot"))

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
        """One step, as `plume simulate` takes it (the library's scene runner): the scene's handles
        posed at the step's end time from their keyframes, the feathers on follicles carried by
        the body, the body posed (and contact with it), then an implicit step (or a static solve
        in a quasi-static scene). Returns its report."""
        self._live()
        report = ffi.new("plume_solve_report *")
        err = new_error()
        check(lib.plume_scene_runner_step(self._runner, report, err), err)
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

    @property
    def body_positions(self) -> Optional[np.ndarray]:
        """(M, 3) the body's vertex positions at the current time, m (None without a body): a live
        read-only view, posed at each step as `plume simulate` poses it."""
        self._live()
        body = self._scene.body
        if body == ffi.NULL:
            return None
        m = int(lib.plume_body_vertex_count(body))
        return view(self._keep, lib.plume_scene_runner_body_positions(self._runner), m * 3, np.float64, (m, 3))

    def summary(self) -> dict:
        """What the run measured so far, as summary.json's keys (docs/simulation.md)."""
        self._live()
        out = ffi.new("plume_scene_summary *")
        lib.plume_scene_runner_summary(self._runner, out)
        s = out[0]
        result = {
            "steps": s.steps, "newton_iterations": s.newton_iterations, "retried_steps": s.retried_steps,
            "wall_seconds": s.wall_seconds, "seconds_assembly": s.seconds_assembly,
            "seconds_factorization": s.seconds_factor, "seconds_solve": s.seconds_solve,
            "seconds_contact": s.seconds_contact, "max_barb_strain": s.max_barb_strain,
            "rachis_tip_deflection": s.rachis_tip_deflection, "vertex_count": s.vertex_count,
            "feather_count": s.feather_count,
        }
        if s.contact_measured:  # written only by runs that measure them, as summary.json
            result["contact_pairs_max"] = s.contact_pairs_max
            result["min_distance"] = s.min_distance if math.isfinite(s.min_distance) else None
        if s.intersections_checked:
            result["intersecting_pairs"] = s.intersecting_pairs
            result["frames_checked"] = s.frames_checked
            result["first_intersecting_step"] = s.first_intersecting_step if s.first_intersecting_step >= 0 else None
        return result

    def __repr__(self) -> str:
        return f"<plume.Simulation {self.vertex_count} vertices, t = {self.time:g} s>"
