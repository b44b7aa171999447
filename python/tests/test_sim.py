"""Meshes and simulations from the binding against `plume mesh` and `plume simulate`."""

import gc
import math
import json

import numpy as np
import pytest

import plume


def swing(source):
    return {
        "feather": str(source / "examples" / "franco-walter" / "blue.json"),
        "mesh": {"edge_length": 0.01},
        "handles": [{"group": "rachis_clamp"}],
        "gravity": [0, 0, -9.81],
        "duration": 0.055,
    }


def read_obj_vertices(path):
    return np.array([[float(x) for x in line.split()[1:4]] for line in path.read_text().splitlines()
                     if line.startswith("v ")])


def test_simulation_matches_plume_simulate(source, cli, tmp_path):
    scene = tmp_path / "swing.json"
    scene.write_text(json.dumps(swing(source)))
    cli("simulate", scene, "-o", tmp_path / "out")
    rows = (tmp_path / "out" / "stats.csv").read_text().splitlines()
    header, rows = rows[0].split(","), [r.split(",") for r in rows[1:]]
    with plume.Simulation(scene) as sim:
        assert sim.steps_total == len(rows) == 5
        reports = sim.run()
        assert len(reports) == 5 and sim.reports == reports
        for report, row in zip(reports, rows):
            stats = dict(zip(header, row))
            # The CLI's stats.csv formats: %.9g,%d,%.6e,%.12e,%.6e
            assert int(stats["newton_iterations"]) == report["newton_iterations"]
            assert stats["time"] == f"{report['time']:.9g}"
            assert stats["gradient_norm"] == f"{report['gradient_norm']:.6e}"
            assert stats["energy"] == f"{report['energy']:.12e}"
            assert stats["max_barb_strain"] == f"{report['max_barb_strain']:.6e}"
        summary = json.loads((tmp_path / "out" / "summary.json").read_text())
        assert summary["steps"] == 5
        last = read_obj_vertices(tmp_path / "out" / "frames" / "0005.obj")
        assert last.shape == sim.positions.shape
        assert np.abs(last - sim.positions).max() < 1e-9  # the OBJ's printed digits
        # The mesh the scene made is the one `plume simulate` wrote.
        rest = read_obj_vertices(tmp_path / "out" / "mesh.obj")
        assert np.abs(rest - sim.mesh.vertices).max() < 1e-9


def test_keyframed_quasi_static_scene_matches_plume_simulate(source, cli, tmp_path):
    spec = swing(source)
    spec.update(quasi_static=True, forces=[{"group": "rachis_tip", "force": [0, 0, -1e-4]}])
    spec["handles"].append({"group": "rachis_tip", "interpolation": "smooth", "keyframes": [
        {"time": 0, "translation": [0, 0, 0]},
        {"time": 0.055, "translation": [0, -0.002, -0.01], "rotation_axis": [0, 1, 0], "rotation_deg": 5}]})
    (tmp_path / "pull.json").write_text(json.dumps(spec))
    cli("simulate", tmp_path / "pull.json", "-o", tmp_path / "out")
    rows = [r.split(",") for r in (tmp_path / "out" / "stats.csv").read_text().splitlines()[1:]]
    with plume.Simulation(spec) as sim:
        assert sim.quasi_static and len(sim.handles) == 2 and len(sim.handles[1]["keyframes"]) == 2
        assert sim.loads == {"rachis_tip": (0.0, 0.0, -1e-4)}
        reports = sim.run()
        assert [int(r[1]) for r in rows] == [r["newton_iterations"] for r in reports]
        assert [r[3] for r in rows] == [f"{r['energy']:.12e}" for r in reports]
        last = read_obj_vertices(tmp_path / "out" / "frames" / f"{len(rows):04d}.obj")
        assert np.abs(last - sim.positions).max() < 1e-9
        tip = sim.mesh.groups["rachis_tip"]
        assert np.abs(sim.positions[tip] - sim.mesh.vertices[tip]).max() > 5e-3  # pulled by its handle


def test_dict_scene_handles_loads_and_static(source):
    spec = swing(source)
    spec["duration"] = 0.022
    with plume.Simulation(spec) as sim:
        assert [h["group"] for h in sim.handles] == ["rachis_clamp"]
        clamp = sim.mesh.groups["rachis_clamp"]
        tip = sim.mesh.groups["rachis_tip"]
        rest = sim.positions.copy()
        assert sim.solve_static()["converged"]
        sagged = sim.positions[tip, 2].mean()  # under gravity alone
        sim.set_load("rachis_tip", (0, 0, -1e-3))
        assert sim.loads == {"rachis_tip": (0.0, 0.0, -1e-3)}
        assert sim.solve_static()["converged"]
        assert np.array_equal(sim.positions[clamp], rest[clamp])  # held
        assert sagged < rest[tip, 2].mean()
        assert sim.positions[tip, 2].mean() < 1.5 * sagged  # the load pushes the tip further down
        # The clamp holds the weight and the load: its reaction points up.
        assert sim.reaction("rachis_clamp")[2] > 0


def wing(source, steps=3):
    """Two feathers carried at their follicles by examples/scenes/wing-draft.json's flapping arm,
    with contact: the body's bones move the feathers' clamps, and the body is an obstacle."""
    spec = json.loads((source / "examples" / "scenes" / "wing-draft.json").read_text())
    spec.pop("description")
    spec["feathers"] = spec["feathers"][:2]
    for feather in spec["feathers"]:
        feather["feather"] = str(source / "examples" / "franco-walter" / "blue.json")
    spec.update(duration=steps * spec["time_step"], frame_every=1, contact={})
    return spec


def test_scene_with_a_body_matches_plume_simulate(source, cli, tmp_path):
    # The Simulation steps the library's scene runner, as `plume simulate` does: it carries the
    # follicles' clamps with the bones and poses the body (before, it held no clamp and let the
    # feathers fall free: 12 mm off the CLI's after 4 steps of the full wing-draft scene).
    scene = tmp_path / "wing.json"
    scene.write_text(json.dumps(wing(source)))
    cli("simulate", scene, "-o", tmp_path / "out")
    rows = (tmp_path / "out" / "stats.csv").read_text().splitlines()[1:]
    with plume.Simulation(scene) as sim:
        assert sim.handles == [] and sim.steps_total == 3
        assert sim.body_positions is not None
        body0 = read_obj_vertices(tmp_path / "out" / "frames" / "body-0000.obj")
        assert np.abs(body0 - sim.body_positions).max() < 1e-9
        reports = sim.run()
        assert [r["newton_iterations"] for r in reports] == [int(row.split(",")[1]) for row in rows]
        last = read_obj_vertices(tmp_path / "out" / "frames" / "0003.obj")
        assert np.abs(last - sim.positions).max() < 1e-9
        body = read_obj_vertices(tmp_path / "out" / "frames" / "body-0003.obj")
        assert np.abs(body - sim.body_positions).max() < 1e-9
        assert np.abs(body - body0).max() > 1e-4  # the arm did move
        summary = json.loads((tmp_path / "out" / "summary.json").read_text())
        mine = sim.summary()
        for key in ("steps", "newton_iterations", "retried_steps", "feather_count", "vertex_count",
                    "contact_pairs_max", "min_distance", "intersecting_pairs", "frames_checked",
                    "first_intersecting_step"):
            assert mine[key] == summary[key], key
        assert mine["max_barb_strain"] == pytest.approx(summary["max_barb_strain"], rel=1e-9)
        assert mine["rachis_tip_deflection"] == pytest.approx(summary["rachis_tip_deflection"], rel=1e-9)


def test_scene_paths_and_memory_limit(source, tmp_path):
    scene = tmp_path / "swing.json"
    scene.write_text(json.dumps(swing(source)))
    for path in (scene, str(scene), bytes(scene)):
        with plume.Simulation(path) as sim:
            assert sim.steps_total == 5
    with pytest.raises(TypeError, match="scene is int"):
        plume.Simulation(5)
    with pytest.raises(plume.Error, match="max_memory keyword") as e:
        plume.Simulation(scene, max_memory=1000)
    assert e.value.code == "limit" and e.value.file == str(scene)


def test_bad_handles_and_loads_raise(source):
    with plume.Simulation(swing(source)) as sim:
        for bad in (1, -1, 1.0, True, "0"):
            with pytest.raises(ValueError, match="handle is"):
                sim.set_handle(bad, (0, 0, 0))
        with pytest.raises(ValueError, match="translation must be 3 finite numbers"):
            sim.set_handle(0, (math.nan, 0, 0))
        with pytest.raises(ValueError, match="translation must be 3 finite numbers"):
            sim.set_handle(0, (0, 0))
        with pytest.raises(ValueError, match="pivot must be 3 finite numbers"):
            sim.set_handle(0, pivot=(0, 0, math.inf))
        with pytest.raises(ValueError, match="rotation must be a finite 3 x 3 matrix"):
            sim.set_handle(0, rotation=np.eye(4))
        with pytest.raises(ValueError, match="rotation must be a finite 3 x 3 matrix"):
            sim.set_handle(0, rotation=np.full((3, 3), np.inf))
        with pytest.raises(ValueError, match="force must be 3 finite numbers"):
            sim.set_load("rachis_tip", (math.nan, 0, 0))
        assert sim.loads == {}
        extra = sim.add_handle("rachis_tip")
        assert extra == 1
        sim.set_handle(extra, (0, 0, 1e-3))  # the new handle is valid
        sim.step()
    for name in ("time_step", "duration", "steps_total", "step_count", "handles", "positions", "body_positions"):
        with pytest.raises(ValueError, match="the simulation was closed"):
            getattr(sim, name)


def test_positions_stay_valid_after_close(source):
    sim = plume.Simulation(swing(source))
    sim.step()
    positions = sim.positions
    copy = positions.copy()
    sim.close()
    del sim
    gc.collect()
    for _ in range(5):
        plume.mesh(plume.generate({"model": "franco-walter"}), edge_length=0.02)
    assert np.array_equal(positions, copy)


def test_scene_errors(source):
    spec = swing(source)
    spec["duration"] = -1
    with pytest.raises(plume.Error) as e:
        plume.Simulation(spec)
    assert e.value.path == "$.duration" and e.value.file == "<dict>"
    spec = swing(source)
    spec["handles"] = [{"group": "nowhere"}]
    with pytest.raises(plume.Error, match="nowhere"):
        plume.Simulation(spec)


def test_mesh_matches_plume_mesh(source, cli, tmp_path):
    spec = source / "examples" / "franco-walter" / "blue.json"
    cli("mesh", spec, "-o", tmp_path, "--edge-length", "0.005")
    feather = plume.generate(spec)
    shell = plume.mesh(feather, edge_length=0.005)
    assert np.abs(read_obj_vertices(tmp_path / "mesh.obj") - shell.vertices).max() < 1e-9
    faces = [line.split()[1:] for line in (tmp_path / "mesh.obj").read_text().splitlines() if line.startswith("f ")]
    obj_faces = np.array([[int(v.split("/")[0]) - 1 for v in f] for f in faces])
    assert np.array_equal(np.sort(obj_faces, axis=0), np.sort(shell.triangles.astype(int), axis=0))
    assert shell.triangles.max() < shell.vertex_count
    assert ((shell.barb_angles >= 0) & (shell.barb_angles < np.pi)).all()
    assert set(np.unique(shell.materials)) <= {0, 1}
    assert shell.report["aligned_fraction"] == 1.0
    # The mesher's quality floor outside junction faces (docs/meshing.md), in radians.
    assert shell.report["vane_min_angle"] >= math.radians(20.0) - 1e-12
    assert 0 <= shell.report["excepted_count"] < shell.face_count
    assert {"rachis_clamp", "rachis_tip"} <= set(shell.groups)
    assert shell.barb_edges.shape[1] == 2 and len(shell.barb_edges) > 0


def test_no_leak_over_a_thousand_meshes_and_simulations(source):
    feather = plume.generate({"model": "franco-walter", "segments": [{"barb_count": 10}, {"barb_count": 10}]})
    spec = swing(source)
    spec["duration"] = 0.011
    gc.collect()
    start = plume.bytes_in_use()
    for _ in range(1000):
        with plume.mesh(feather, edge_length=0.03) as m:
            m.triangles
    for _ in range(20):
        with plume.Simulation(spec) as sim:
            sim.step()
            sim.positions
    gc.collect()
    assert plume.bytes_in_use() == start
