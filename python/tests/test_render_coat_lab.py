"""Rendering, coats and the lab from the binding against the CLI's results."""

import json

import numpy as np
import pytest

import plume


def test_render_is_the_cli_render(source, cli, tmp_path):
    spec = source / "examples" / "franco-walter" / "blue.json"
    cli("render", spec, "-o", tmp_path, "--size", "96x64", "--spp", "2")
    image = plume.render(plume.generate(spec), width=96, height=64, spp=2)
    assert image.shape == (64, 96, 4) and image.dtype == np.uint8
    assert (image[..., :3] < 200).any()  # the feather is there, darker than the background
    plume.write_png(image, tmp_path / "binding.png")
    assert (tmp_path / "binding.png").read_bytes() == (tmp_path / "feather.png").read_bytes()


def test_render_errors_and_2d(source, tmp_path):
    feather = plume.generate(source / "examples" / "franco-walter" / "blue.json")
    with pytest.raises(plume.Error) as e:
        plume.render(feather, width=4, height=4)
    assert e.value.code == "spec"
    plume.render2d(feather, tmp_path / "front.svg", width=200, height=300)
    assert "<svg" in (tmp_path / "front.svg").read_text()[:400]


def test_coat_matches_plume_coat(source, cli, tmp_path):
    spec = source / "examples" / "coats" / "sphere.json"
    cli("coat", spec, "-o", tmp_path, "-f", "obj")
    objects = [line for line in (tmp_path / "coat.obj").read_text().splitlines() if line.startswith("o feather_")]
    with plume.coat(spec) as coat:
        assert len(coat) == len(objects) > 100
        assert coat.is_key.sum() >= 1
        follicles = coat.follicles
        radius = np.linalg.norm(follicles - follicles.mean(axis=0), axis=1)
        assert np.ptp(radius) < 1e-6 * radius.mean() + 1e-9  # all on the sphere
        roots = np.array([f.shaft_points[0] for f in coat.feathers[:10]])
        assert np.abs(roots - follicles[:10]).max() < 0.05 * radius.mean()
        assert coat.surface.face_count > 0
        coat.write(tmp_path / "again.obj")
        assert (tmp_path / "again.obj").read_bytes() == (tmp_path / "coat.obj").read_bytes()
    with pytest.raises(plume.Error) as e:
        plume.coat({"model": "coat", "surfce": {}})
    assert e.value.file == "<dict>" and e.value.path == "$.surfce"


def test_traction_is_the_cli_traction(source, cli, tmp_path):
    spec = source / "examples" / "lab" / "tilted-macroscale.json"
    lab = json.loads(spec.read_text())
    lab.setdefault("traction", {})["steps"] = 4
    lab["sample"]["elements"] = 200
    (tmp_path / "lab.json").write_text(json.dumps(lab))
    cli("lab", "traction", tmp_path / "lab.json", "-o", tmp_path / "out")
    result = plume.traction(lab)
    table = np.loadtxt(tmp_path / "out" / "traction.csv", delimiter=",", skiprows=1)
    assert np.array_equal(table[:, 0], result["strain"])
    assert np.array_equal(table[:, 1], result["stress"])
    assert np.array_equal(table[:, 3], result["iterations"])
    summary = json.loads((tmp_path / "out" / "traction.json").read_text())
    assert f"{result['slope']:.10g}" == f"{summary['slope_pa']:.10g}"
    assert summary["newton_iterations"] == result["newton_iterations"]
    lab["material"]["E_vw"] = -1
    with pytest.raises(plume.Error) as e:
        plume.traction(lab)
    assert e.value.path == "$.material.E_vw" and e.value.file == "<dict>"


def test_calibrate_is_the_cli_calibration(cli, tmp_path):
    done = cli("lab", "calibrate", "--phi", 0.14, "--Eb", 3.92e4, "--EB", 2.57e9, "--elements", 300,
               "--macro-elements", 200, "--phases", 1, "-o", tmp_path / "cal")
    expected = json.loads(done.stdout)
    result = plume.calibrate(barb_fraction=0.14, E_b=3.92e4, E_B=2.57e9, element_count=300, macroscale_elements=200,
                             phase_count=1)
    for key in ("E_vv", "E_ww", "E_vw"):  # the CLI prints %.6g
        assert f"{result[key]:.6g}" == f"{expected[key]:.6g}", key
    assert result["slope_tilted"] == pytest.approx(expected["slopes"]["tilted_mesoscale"], rel=1e-7)
    assert result["solve_count"] == expected["solves"]
    assert result["protocol"] == expected["protocol"]["name"] == "custom"
    for key in ("E_vv", "E_ww", "E_vw"):
        for part in ("phase", "width", "mesh", "total"):
            assert result["spread"][key][part] >= 0
            assert f"{result['spread'][key][part]:.4g}" == f"{expected['spread'][key][part]:.4g}", (key, part)
    assert result["sensitivity"] == pytest.approx(expected["sensitivity"], rel=1e-3)
    # The curves are the CLI's curves.csv, column by column (written with %.17g).
    table = np.loadtxt(tmp_path / "cal" / "curves.csv", delimiter=",", skiprows=1)
    for c, name in enumerate(("longitudinal", "transverse", "tilted_mesoscale", "tilted_macroscale")):
        strain, stress = result["curves"][name]
        assert len(strain) == 11 and np.array_equal(strain, table[:, 2 * c]), name
        assert np.array_equal(stress, table[:, 2 * c + 1]), name
    with pytest.raises(plume.Error):
        plume.calibrate(barb_fraction=1.5)


def test_mesoscale_moduli_invert_the_closed_forms():
    slope_long = plume.longitudinal_modulus(0.14, 2.57e9, 3.92e4)
    slope_trans = plume.transverse_slope_rigid(0.14, 3.92e4, 0.4)
    assert slope_long == pytest.approx(0.14 * 2.57e9 + 0.86 * 3.92e4, rel=1e-15)
    E_B, E_b = plume.mesoscale_moduli(0.14, slope_long, slope_trans, 0.4)
    assert E_B == pytest.approx(2.57e9, rel=1e-12) and E_b == pytest.approx(3.92e4, rel=1e-12)
    with pytest.raises(plume.Error) as e:
        plume.mesoscale_moduli(1.5, slope_long, slope_trans)
    assert e.value.code == "spec"


def test_study_is_the_cli_study(cli, tmp_path):
    cli("lab", "study", "conditioning", "--scale", 0.05, "-o", tmp_path)
    result = plume.study("conditioning", scale=0.05, png=str(tmp_path / "binding.png"))
    assert result["study"] == "conditioning"
    table = np.loadtxt(tmp_path / "conditioning.csv", delimiter=",", skiprows=1)
    header = (tmp_path / "conditioning.csv").read_text().splitlines()[0].split(",")
    assert list(result["table"]) == header
    for i, name in enumerate(header):
        assert np.array_equal(result["table"][name], table[:, i]), name
    assert (tmp_path / "binding.png").read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(ValueError, match="allowed"):
        plume.study("lockin")
