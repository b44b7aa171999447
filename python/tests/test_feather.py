"""Feathers from the binding against the C library's own output: `plume generate`'s feather.json,
read with Python's json module (not plume's reader), must hold the binding's arrays bit for bit."""

import gc
import json
import os

import numpy as np
import pytest

import plume

MODELS = ("franco-walter", "streit-heidrich", "zhang-kanai")


# Two presets per model (make test's time budget): the small ones, a feather with an afterfeather
# (semiplume) and one whose barbules sit between its barbs in the point pool (figure11-expansion).
PRESETS = ("franco-walter/filoplume", "franco-walter/figure6a", "streit-heidrich/contour", "streit-heidrich/semiplume",
           "zhang-kanai/figure8-contour", "zhang-kanai/figure11-expansion")


def test_presets_equal_the_cli_json(source, cli, tmp_path):
    checked = 0
    for name in PRESETS:
        spec = source / "examples" / f"{name}.json"
        out = tmp_path / spec.stem
        cli("generate", spec, "-o", out, "-f", "json")
        dump = json.loads((out / "feather.json").read_text())
        feather = plume.generate(spec)
        shaft = dump["shaft"]
        assert np.array_equal(feather.shaft_points.ravel(), np.array(shaft["position"])), spec
        assert np.array_equal(feather.shaft["tangent"].ravel(), np.array(shaft["tangent"])), spec
        assert np.array_equal(feather.shaft_widths, np.array(shaft["width"])), spec
        assert np.array_equal(feather.shaft["t"], np.array(shaft["t"])), spec
        barbs = dump["barbs"]
        assert feather.barb_count == len(barbs), spec
        offsets = feather.barb_offsets
        assert len(offsets) == len(barbs) + 1, spec
        points = np.concatenate([np.array(b["position"]) for b in barbs]) if barbs else np.zeros(0)
        assert np.array_equal(feather.barb_points.ravel(), points), spec
        assert np.array_equal(feather.barb_widths, np.concatenate([b["width"] for b in barbs])), spec
        assert np.array_equal(feather.barb_uv.ravel(), np.concatenate([b["uv"] for b in barbs])), spec
        assert np.array_equal(feather.barb_normals.ravel(), np.concatenate([b["normal"] for b in barbs]))
        last = len(barbs) - 1
        assert np.array_equal(feather.barb(last).ravel(), barbs[last]["position"]), spec
        if feather.barbule_count:
            first = dump["barbs"][feather.barbule_barbs[0]]["barbules"][0]
            start, count = feather.barbule_offsets[0], feather.barbule_counts[0]
            assert np.array_equal(feather.points[start : start + count].ravel(), first["position"]), spec
        assert np.array_equal(np.diff(offsets), [len(b["width"]) for b in barbs]), spec
        assert np.array_equal(feather.barb_sides, [0 if b["side"] == "left" else 1 for b in barbs]), spec
        assert np.array_equal(feather.barb_rachis_t, [b["rachis_t"] for b in barbs]), spec
        assert feather.barbule_count == sum(len(b["barbules"]) for b in barbs), spec
        assert (feather.afterfeather is None) == (dump["afterfeather"] is None), spec
        if feather.afterfeather is not None:
            after = dump["afterfeather"]["feather"]
            assert np.array_equal(feather.afterfeather.shaft_points.ravel(), after["shaft"]["position"]), spec
        # And plume's own reader agrees with every array, barbules included.
        assert feather.equal(plume.Feather.read_json(out / "feather.json")), spec
        checked += 1
    assert checked == len(PRESETS)


def test_binary_json_read_by_numpy(source, tmp_path):
    """Version 2 (plume simulate's feather.json + feather.bin), read with json and numpy alone."""
    from plume._lib import check, lib, new_error

    feather = plume.generate(source / "examples" / "streit-heidrich" / "semiplume.json")
    path = tmp_path / "feather.json"
    err = new_error()
    check(lib.plume_write_json_binary(feather.pointer, str(path).encode(), err), err)
    dump = json.loads(path.read_text())
    assert dump["version"] == 2 and dump["buffer"] == {"uri": "feather.bin"}
    numbers = np.fromfile(tmp_path / "feather.bin", dtype="<f8")

    def array(view):
        start = view["offset"] // 8
        return numbers[start : start + view["count"]]

    assert np.array_equal(feather.shaft_points.ravel(), array(dump["shaft"]["position"]))
    barbs = dump["barbs"]
    assert np.array_equal(feather.barb_points.ravel(), np.concatenate([array(b["position"]) for b in barbs]))
    assert np.array_equal(feather.barb_uv.ravel(), np.concatenate([array(b["uv"]) for b in barbs]))
    assert np.array_equal(feather.afterfeather.shaft_points.ravel(),
                          array(dump["afterfeather"]["feather"]["shaft"]["position"]))
    assert feather.equal(plume.Feather.read_json(path))


def test_dict_and_file_specs_give_the_same_feather(source):
    path = source / "examples" / "zhang-kanai" / "figure8-contour.json"
    spec = json.loads(path.read_text())
    assert plume.generate(spec).equal(plume.generate(path))
    assert not plume.generate(spec, seed=5).equal(plume.generate(spec, seed=6)) or spec["model"] == "zhang-kanai"


def test_seed_and_stages(source):
    spec = {"model": "franco-walter", "segments": [{"barb_count": 20}, {"barb_count": 30}]}
    assert plume.generate(spec, seed=3).equal(plume.generate(spec, seed=3))
    assert not plume.generate(spec, seed=3).equal(plume.generate(spec, seed=4))
    sh = source / "examples" / "streit-heidrich" / "contour.json"
    half = plume.generate(sh, stage=0.5)
    assert half.info["shaft_length"] < plume.generate(sh).info["shaft_length"]
    with pytest.raises(plume.Error) as e:
        plume.generate(spec, stage=0.5)
    assert e.value.code == "unsupported"


def test_arrays_outlive_their_feather_object(source):
    feather = plume.generate(source / "examples" / "franco-walter" / "blue.json")
    points, shaft, widths = feather.points, feather.shaft_points, feather.widths
    expected = points.copy(), shaft.copy(), widths.copy()
    assert not points.flags.owndata  # a view, not a copy
    assert not points.flags.writeable
    del feather
    gc.collect()
    for _ in range(20):  # churn the allocator so freed memory would be reused
        plume.generate({"model": "franco-walter"})
    assert np.array_equal(points, expected[0])
    assert np.array_equal(shaft, expected[1])
    assert np.array_equal(widths, expected[2])


def test_write_formats(source, tmp_path):
    feather = plume.generate(source / "examples" / "franco-walter" / "figure6a.json")
    written = feather.write(tmp_path / "f6a", ["json", "obj", "usda"])
    assert [p.rsplit(".", 1)[1] for p in written] == ["json", "obj", "usda"]
    assert plume.Feather.read_json(tmp_path / "f6a.json").equal(feather)
    obj = (tmp_path / "f6a.obj").read_text()
    assert obj.count("\nv ") == feather.info["shaft_sample_count"] + feather.info["point_count"]
    feather.write(tmp_path / "single.usda")
    assert (tmp_path / "single.usda").read_text().startswith("#usda")
    with pytest.raises(ValueError):
        feather.write(tmp_path / "x", ["stl"])


def test_bad_specs_raise_errors_naming_the_key(source, tmp_path):
    cases = [
        ({"model": "franco-walter", "segments": [{"barb_count": 6000}, {}]}, "$.segments[0].barb_count",
         "is 6000, allowed [0, 5000]"),
        ({"model": "franco-walte"}, "$.model", 'did you mean "franco-walter"'),
        ({"model": "zhang-kanai", "sede": 1}, "$.sede", "unknown key"),
        ({"seed": 1}, "$.model", "missing"),
    ]
    for spec, path, fragment in cases:
        with pytest.raises(plume.Error) as e:
            plume.generate(spec)
        assert e.value.path == path, e.value.message
        assert fragment in e.value.message
        assert e.value.code == "spec" and e.value.status == 3
        assert e.value.file == "<dict>"
        assert str(e.value) == e.value.message
    bad = tmp_path / "bad.json"
    bad.write_text('{"model": "franco-walter",\n "seed": }')
    with pytest.raises(plume.Error) as e:
        plume.generate(bad)
    assert e.value.code == "syntax" and e.value.message.startswith(f"{bad}:2:")
    assert e.value.file == str(bad)
    with pytest.raises(plume.Error) as e:
        plume.generate(tmp_path / "missing.json")
    assert e.value.code == "io" and "No such file" in e.value.message
    with pytest.raises(plume.Error, match="coat spec"):
        plume.generate({"model": "coat"})


def test_no_leak_over_a_thousand_feathers():
    gc.collect()
    start = plume.bytes_in_use()
    spec = {"model": "franco-walter", "segments": [{"barb_count": 3}, {"barb_count": 3}], "barb_samples": 4}
    for i in range(1000):
        with plume.generate(spec, seed=i) as feather:
            assert feather.barb_count == 12
    for i in range(1000):
        plume.generate(spec, seed=i).points  # freed by the garbage collector
    with pytest.raises(plume.Error):
        for i in range(1000):
            plume.generate({"model": "franco-walter", "calamus_fraction": 2})
    gc.collect()
    assert plume.bytes_in_use() == start


def test_ribbons_and_colours(source):
    feather = plume.generate(source / "examples" / "zhang-kanai" / "figure11-expansion.json")  # barbules in between
    r = plume.ribbons(feather)
    points = len(feather.barb_points) + len(feather.shaft)
    assert r["vertices"].shape == (2 * points, 3)
    assert len(r["quads"]) == points - feather.barb_count - 1  # one per segment, none across curves
    widths = np.linalg.norm(r["vertices"][1::2] - r["vertices"][0::2], axis=1)
    assert np.allclose(widths, np.concatenate([feather.barb_widths, feather.shaft_widths]), rtol=1e-12, atol=1e-15)
    centres = 0.5 * (r["vertices"][1::2] + r["vertices"][0::2])
    assert np.allclose(centres, np.concatenate([feather.barb_points, feather.shaft_points]), rtol=0, atol=1e-15)
    # Quads face their curve's normal (counter-clockwise seen from it).
    q = r["vertices"][r["quads"]]
    face_normal = np.cross(q[:, 1] - q[:, 0], q[:, 3] - q[:, 0])
    curve_normal = np.concatenate([feather.barb_normals, feather.shaft["normal"]])[r["quads"][:, 0] // 2]
    facing = np.einsum("ij,ij->i", face_normal, curve_normal)
    assert (facing[np.linalg.norm(face_normal, axis=1) > 0] > 0).mean() > 0.99
    assert np.array_equal(r["uv"][0::2][: len(feather.barb_uv)], feather.barb_uv)
    colours = plume.banded_colors(feather, 64, 64)
    assert colours.shape == (len(feather.barb_points), 4)
    assert ((colours >= 0) & (colours <= 1)).all() and len(np.unique(colours[:, 0])) > 3


def test_argument_checks(source, tmp_path, monkeypatch):
    spec = source / "examples" / "franco-walter" / "filoplume.json"
    feather = plume.generate(spec)
    # One format given as a string is that format, not its letters.
    assert feather.write(tmp_path / "one", "json") == [str(tmp_path / "one.json")]
    # Paths as bytes or os.PathLike, like open(); anything else is a TypeError naming the argument.
    assert plume.generate(os.fsencode(spec)).equal(feather)
    assert plume.Feather.read_json(os.fsencode(tmp_path / "one.json")).equal(feather)
    assert feather.write(os.fsencode(tmp_path / "two.obj")) == [str(tmp_path / "two.obj")]
    with pytest.raises(TypeError, match="spec is int; expected a dict or a path"):
        plume.generate(5)
    with pytest.raises(TypeError, match="path is NoneType; expected a path"):
        feather.write(None)
    # stage_kind is checked with or without a stage.
    with pytest.raises(ValueError, match="stage_kind is 'bogus', allowed 'growth' or 'unfurl'"):
        plume.generate(spec, stage_kind="bogus")
    for size in (0, -1, 1, 16385, 2.5):
        with pytest.raises(ValueError, match=r"width is .*allowed a whole number of pixels in \[2, 16384\]"):
            plume.banded_colors(feather, width=size)
        with pytest.raises(ValueError, match=r"height is .*allowed"):
            plume.banded_colors(feather, height=size)
    assert plume.banded_colors(feather, 2, 2).shape == (len(feather.barb_points), 4)
    # A path without a suffix or folder is still the message's file when the call was given it.
    monkeypatch.chdir(tmp_path)
    with pytest.raises(plume.Error) as e:
        plume.generate("hawk")
    assert e.value.code == "io" and e.value.file == "hawk"


def test_messages_name_the_python_keywords(source):
    sh = source / "examples" / "streit-heidrich" / "contour.json"
    with pytest.raises(plume.Error) as e:
        plume.generate(sh, stage=0.5, stage_kind="unfurl")
    assert e.value.code == "unsupported" and 'use stage_kind="growth"' in e.value.message
    assert "--unfurl" not in e.value.message
    with pytest.raises(plume.Error) as e:
        plume.generate(source / "examples" / "franco-walter" / "blue.json", max_memory=1000)
    assert e.value.code == "limit" and "raise it with the max_memory keyword" in e.value.message
    assert "--max-memory" not in e.value.message
    assert plume.generate(sh, max_memory=1 << 30).equal(plume.generate(sh))


def test_dict_references_resolve_against_the_working_directory(source, monkeypatch):
    spec = json.loads((source / "examples" / "streit-heidrich" / "continuum.json").read_text())
    monkeypatch.chdir(source)
    with pytest.raises(plume.Error) as e:
        plume.generate(spec)
    assert e.value.file == "down.json" and "resolve against the working directory" in e.value.message
    monkeypatch.chdir(source / "examples" / "streit-heidrich")
    assert plume.generate(spec).equal(plume.generate("continuum.json"))
