"""Rendering, coats and the lab from the binding against the CLI's results."""

import json
import os

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
    assert result["slope"] == summary["slope_pa"]  # traction.json: the shortest round-trip digits
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
    for key in ("E_vv", "E_ww", "E_vw"):  # the CLI prints the shortest digits that read back the same
        assert result[key] == expected[key], key
    assert result["slope_tilted"] == expected["slopes"]["tilted_mesoscale"]
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


def test_render_checks_shell_positions_and_vectors(source):
    feather = plume.generate({"model": "franco-walter", "segments": [{"barb_count": 3}, {"barb_count": 3}]})
    shell = plume.mesh(feather, edge_length=0.01)
    n = shell.vertex_count
    # Too few rows made the C library read past the buffer; the rest were taken or misread.
    for bad in (np.zeros((3, 3)), np.zeros((n + 5, 3)), np.zeros(3 * n), np.zeros((n, 2)), np.zeros((n, 3), bool),
                np.array([["a", "b", "c"]] * n)):
        with pytest.raises(ValueError, match=rf"shell_positions has shape .*expected shape \({n}, 3\)"):
            plume.render(width=16, height=16, spp=1, shell=shell, shell_positions=bad)
    with pytest.raises(ValueError, match="shell_positions has non-finite"):
        plume.render(width=16, height=16, spp=1, shell=shell, shell_positions=np.full((n, 3), np.nan))
    with pytest.raises(ValueError, match="shell_positions is given without shell"):
        plume.render(feather, width=16, height=16, spp=1, shell_positions=shell.vertices)
    # Any real dtype of the right shape is converted: float32 positions draw what their float64 values do.
    single = shell.vertices.astype(np.float32)
    assert np.array_equal(plume.render(width=16, height=16, spp=1, shell=shell, shell_positions=single),
                          plume.render(width=16, height=16, spp=1, shell=shell, shell_positions=single.astype(float)))
    for bad in ((1, 0), (1, 0, 0, 0), (0, 0, float("nan")), "xyz", 3.0):
        with pytest.raises(ValueError, match="view_direction is .*expected 3 finite numbers"):
            plume.render(feather, width=16, height=16, spp=1, view_direction=bad)


def test_write_png_takes_uint8_rgba_only(tmp_path):
    image = np.zeros((4, 5, 4), np.uint8)
    plume.write_png(image[:, ::-1], tmp_path / "ok.png")  # a strided view is fine
    assert (tmp_path / "ok.png").read_bytes()[:4] == b"\x89PNG"
    for bad in (np.zeros((4, 5, 4)), np.full((4, 5, 4), 300), np.zeros((4, 5, 4), np.int8)):
        with pytest.raises(TypeError, match=f"image has dtype {bad.dtype}, expected uint8"):
            plume.write_png(bad, tmp_path / "bad.png")
    for shape in ((4, 5, 3), (4, 5), (0, 5, 4)):
        with pytest.raises(ValueError, match=r"image has shape .*expected \(height, width, 4\)"):
            plume.write_png(np.zeros(shape, np.uint8), tmp_path / "bad.png")
    assert not (tmp_path / "bad.png").exists()


def test_render2d_style_and_paths(source, tmp_path):
    feather = plume.generate(source / "examples" / "franco-walter" / "filoplume.json")
    with pytest.raises(ValueError, match="style is 'dots'; allowed 'lines', 'strips'"):
        plume.render2d(feather, tmp_path / "x.png", style="dots")
    plume.render2d(feather, os.fsencode(tmp_path / "strips.svg"), width=64, height=64, style="strips")
    assert "<svg" in (tmp_path / "strips.svg").read_text()[:400]
    plume.write_png(np.zeros((16, 16, 4), np.uint8), os.fsencode(tmp_path / "b.png"))
    with pytest.raises(TypeError, match="path is int; expected a path"):
        plume.render2d(feather, 3)


def test_errors_without_a_file_name_none(source):
    feather = plume.generate(source / "examples" / "franco-walter" / "filoplume.json")
    with pytest.raises(plume.Error) as e:
        plume.render(feather, width=1)
    assert e.value.message.startswith("raytrace: ") and e.value.file is None
    with pytest.raises(plume.Error) as e:
        plume.render2d(feather, "front.png", width=1)
    assert e.value.message.startswith("render2d: ") and e.value.file is None
    with pytest.raises(plume.Error) as e:
        plume.calibrate(element_count=0)
    assert "elements is 0" in e.value.message and e.value.file is None


@pytest.mark.parametrize("message, file", [
    ("simulation: Newton did not converge", None),
    ("quasi-static solve: the step stalled", None),
    ("calibration: mesoscale, barbs at 45 deg: band phase 0.5: sample.elements is 0", None),
    ("$.segments[0]: rachis positions must increase", None),
    ("camera size is 1x800, each allowed in [16, 16384]", None),
    ("hawk.json: $.seed is -1", "hawk.json"),
    ("/tmp/my specs/hawk.json:2:7: '}' expected", "/tmp/my specs/hawk.json"),
    ("examples/coats/back-cap.obj:12: bad face", "examples/coats/back-cap.obj"),
    ("out/png: cannot write PNG: Permission denied", "out/png"),
    ("<dict>: $.model: missing", "<dict>"),
])
def test_error_file_is_a_file_or_none(message, file):
    err = plume._lib.new_error()
    err.status = 3
    err.message = message.encode()
    assert plume.Error.from_c(err).file == file


def test_error_file_without_folder_or_suffix_counts_where_passed():
    err = plume._lib.new_error()
    err.status = 1
    err.message = b"hawk: cannot read: No such file or directory"
    assert plume.Error.from_c(err).file is None and plume.Error.from_c(err, files=["hawk"]).file == "hawk"


def test_dict_coat_references_resolve_against_the_working_directory(source, monkeypatch):
    spec = json.loads((source / "examples" / "coats" / "back-cap.json").read_text())
    monkeypatch.chdir(source)
    # Relative to the working directory, not to the hidden temporary file the dict is written to.
    with pytest.raises(plume.Error) as e:
        plume.coat(spec)
    assert e.value.code == "io" and "plume-" not in e.value.message and e.value.file == "<dict>"
    assert f"$.surface.obj: {source / 'back-cap.obj'}: cannot open" in e.value.message
    assert "resolve against the working directory" in e.value.message
    monkeypatch.chdir(source / "examples" / "coats")
    from_dict, from_file = plume.coat(spec), plume.coat("back-cap.json")
    assert len(from_dict) == len(from_file) > 0
    assert all(a.equal(b) for a, b in zip(from_dict.feathers, from_file.feathers))
    # An inline key feather's references too (a blend of spec files), and the caller's dict is left as it was.
    monkeypatch.chdir(source)
    spec["surface"]["obj"] = "examples/coats/back-cap.obj"
    for key in spec["key_feathers"]:
        key["feather"] = "examples/coats/key-contour.json"
    spec["key_feathers"][0]["feather"] = {"model": "streit-heidrich", "blend": {
        "feathers": ["examples/streit-heidrich/down.json", "examples/streit-heidrich/contour.json"], "t": 0.5}}
    before = json.dumps(spec)
    assert len(plume.coat(spec)) == len(from_file)
    assert json.dumps(spec) == before
    spec["key_feathers"][0]["feather"]["blend"]["feathers"][0] = "down.json"
    with pytest.raises(plume.Error) as e:
        plume.coat(spec)
    assert e.value.file == str(source / "down.json") and "working directory" in e.value.message


def test_python_terms_in_limit_messages(source):
    with pytest.raises(plume.Error) as e:
        plume.coat(source / "examples" / "coats" / "sphere.json", max_memory=1000)
    assert e.value.code == "limit" and "the max_memory keyword" in e.value.message and "--" not in e.value.message
    feather = plume.generate(source / "examples" / "franco-walter" / "filoplume.json")
    with pytest.raises(plume.Error) as e:
        plume.mesh(feather, max_memory=1000)
    assert e.value.code == "limit" and "the max_memory keyword" in e.value.message and "--" not in e.value.message
    for bad in (0, -1, 1.5, True, 2**64):
        with pytest.raises(ValueError, match="max_memory is"):
            plume.mesh(feather, max_memory=bad)


def test_closed_forms_check_their_ranges():
    for args in ((2.0, 1e9, 1e4), (0.0, 1e9, 1e4), (1.0, 1e9, 1e4), (0.14, -1e9, 1e4), (0.14, 1e9, float("nan")),
                 (0.14, float("inf"), 1e4)):
        with pytest.raises(plume.Error) as e:
            plume.longitudinal_modulus(*args)
        assert e.value.code == "spec" and "allowed" in e.value.message, args
    for args in ((1.0, 3.9e4), (0.14, 3.9e4, -1), (0.14, 3.9e4, 0), (0.14, 0, 0.4), (float("nan"), 3.9e4)):
        with pytest.raises(plume.Error) as e:
            plume.transverse_slope_rigid(*args)
        assert e.value.code == "spec" and "allowed" in e.value.message, args
    assert np.isfinite(plume.transverse_slope_rigid(0.14, 3.9e4, 0.4))
