#!/usr/bin/python3
"""Interop test: every format plume writes, opened by the tools people use.

plume writes a feather, a shell, a simulation and a coat in each format it
has; Blender 3.4 imports them (OBJ with its default importer and the legacy
one, glTF with its own importer) and ParaView 5.11 opens them (OBJ, and the
VTK XML fields when plume writes them); the counts each tool holds afterwards
are compared with what plume reports writing: the feather's JSON dump (curve
points), the mesher's report.json, the simulation's summary.json, the coat's
report and the .glb's own accessors.

    /usr/bin/python3 tests/interop/interop.py BUILD/plume [--keep DIR]

Exit 0 when every check passes. A tool that is missing is skipped with a
message (blender, pvbatch3.11: `.ci/run` installs both); a format this plume
does not write yet is reported as not written, not as a failure.
"""
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(SOURCE, "tests"))
import glb_check  # noqa: E402  (the .glb reader of tests/cli/gltf.sh: struct + json only)
failures = 0
# simulate --fields: per face strain, stress, barb angle, material, energy densities; per vertex velocity, handles.
FACE_FIELDS = ("green_strain_barb", "pk2_stress_barb", "barb_angle", "material", "membrane_energy_density",
               "bending_energy_density")
VERTEX_FIELDS = ("velocity", "handle")


def check(ok, what):
    global failures
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures += 1


def run(*args):
    return subprocess.run(args, check=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True).stdout


def writes_glb(plume, command):
    help_text = subprocess.run([plume, command, "--help"], stdout=subprocess.PIPE, text=True).stdout
    return "glb" in help_text


# ---------------------------------------------------------------------------
# What plume wrote


def feather_curves(feather_json):
    """Points and segments of every curve in plume's JSON dump of a feather."""
    data = json.load(open(feather_json))
    lengths = []

    def add(feather):
        lengths.append(len(feather["shaft"]["width"]))
        for barb in feather["barbs"]:
            lengths.append(len(barb["arc_length"]))
            for barbule in barb.get("barbules") or []:
                lengths.append(len(barbule["arc_length"]) if "arc_length" in barbule else len(barbule["position"]) // 3)

    add(data)
    if data.get("afterfeather"):
        add(data["afterfeather"])
    return {"curves": len(lengths), "points": sum(lengths), "segments": sum(n - 1 for n in lengths)}


def glb_counts(path):
    """Counts a glTF importer should reproduce, from the file's own accessors."""
    g, _ = glb_check.load(path)
    accessors = g.get("accessors", [])
    per_mesh = []
    for mesh in g.get("meshes", []):
        c = {"vertices": 0, "triangles": 0, "segments": 0, "targets": 0}
        for p in mesh["primitives"]:
            n = accessors[p["attributes"]["POSITION"]]["count"]
            indexed = accessors[p["indices"]]["count"] if "indices" in p else n
            mode = p.get("mode", 4)
            c["vertices"] += n
            if mode == 4:
                c["triangles"] += indexed // 3
            elif mode == 1:
                c["segments"] += indexed // 2
            c["targets"] = max(c["targets"], len(p.get("targets", [])))
        per_mesh.append(c)
    nodes = [n for n in g.get("nodes", []) if "mesh" in n]
    total = {k: sum(per_mesh[n["mesh"]][k] for n in nodes) for k in ("vertices", "triangles", "segments")}
    frames = 0
    for animation in g.get("animations", []):
        for sampler in animation["samplers"]:
            frames = max(frames, accessors[sampler["input"]]["count"])
    return dict(
        total,
        objects=len(nodes),
        meshes=len({n["mesh"] for n in nodes}),
        targets=max([c["targets"] for c in per_mesh] or [0]),
        frames=frames,
    )


# ---------------------------------------------------------------------------


def main():
    args = sys.argv[1:]
    if not args or args[0].startswith("-"):
        print(__doc__)
        return 2
    plume = os.path.abspath(args[0])
    keep = args[args.index("--keep") + 1] if "--keep" in args else None
    blender = shutil.which("blender")
    pvbatch = shutil.which("pvbatch3.11") or shutil.which("pvbatch")
    if pvbatch and subprocess.run([pvbatch, "-c", "import paraview.simple"], stdout=subprocess.DEVNULL,
                                  stderr=subprocess.DEVNULL).returncode != 0:
        print("note: %s cannot import paraview.simple (apt-get install python3-paraview)" % pvbatch)
        pvbatch = None
    if not blender and not pvbatch:
        print("interop test skipped: neither blender nor pvbatch3.11 is installed (apt-get install blender paraview)")
        return 0
    if not blender:
        print("note: blender is not installed: the Blender imports are skipped (apt-get install blender)")
    if not pvbatch:
        print("note: pvbatch3.11 is not installed: the ParaView reads are skipped (apt-get install paraview)")

    out = keep or tempfile.mkdtemp(prefix="plume-interop-")
    os.makedirs(out, exist_ok=True)
    ex = os.path.join(SOURCE, "examples")
    glb = writes_glb(plume, "generate")
    formats = "obj,json" + (",glb" if glb else "")
    run(plume, "generate", os.path.join(ex, "franco-walter", "hawk.json"), "-o", out + "/feather", "--format", formats)
    mesh_args = ["--format", "obj,glb"] if writes_glb(plume, "mesh") else []
    run(plume, "mesh", os.path.join(ex, "franco-walter", "hawk.json"), "-o", out + "/mesh", *mesh_args)
    sim_args = [plume, "simulate", os.path.join(ex, "scenes", "figure1-anisotropic.json"), "-o", out + "/sim"]
    fields = "--fields" in subprocess.run([plume, "simulate", "--help"], stdout=subprocess.PIPE, text=True).stdout
    run(*(sim_args + (["--fields"] if fields else [])))
    coat_formats = "obj" + (",glb" if writes_glb(plume, "coat") else "")
    coat_report = run(plume, "coat", os.path.join(ex, "coats", "figure15-hexagonal.json"), "-o", out + "/coat",
                      "--format", coat_formats)
    if not glb:
        print("note: this plume writes no .glb: the glTF imports are skipped")
    if not fields:
        print("note: this plume has no `simulate --fields`: the VTK XML reads are skipped")

    curves = feather_curves(out + "/feather/feather.json")
    report = json.load(open(out + "/mesh/report.json"))
    summary = json.load(open(out + "/sim/summary.json"))
    frame_objs = sorted(glob.glob(out + "/sim/frames/*.obj"))
    check(len(frame_objs) == summary["frames"], "simulation: %d frame OBJ files, summary.json says %d frames"
          % (len(frame_objs), summary["frames"]))

    # The coat's OBJ: its header names the feathers, the file holds the v and l lines.
    coat_obj = out + "/coat/coat.obj"
    with open(coat_obj) as f:
        header = f.readline()
        coat_v = coat_l = 0
        for line in f:
            coat_v += line.startswith("v ")
            coat_l += line.startswith("l ")
    match = re.search(r"(\d+) feathers", header)
    check(match is not None, "coat.obj's header names its feathers: " + header.strip()[:100])
    coat_feathers = int(match.group(1)) if match else -1

    # Jobs: file, importer, expected counts, label.
    jobs = []
    for importer in ("obj", "obj-legacy"):
        jobs.append(dict(path=out + "/feather/feather.obj", importer=importer, label="hawk feather.obj",
                         expect={"vertices": curves["points"], "edges": curves["segments"]}))
        jobs.append(dict(path=out + "/mesh/mesh.obj", importer=importer, label="hawk mesh.obj",
                         expect={"vertices": report["vertex_count"], "faces": report["face_count"]}))
        coat_expect = {"vertices": coat_v, "edges": coat_l}
        if importer == "obj":  # one object per `o` (the legacy importer is asked for one object)
            coat_expect["objects"] = coat_feathers
        jobs.append(dict(path=coat_obj, importer=importer, label="coat coat.obj", expect=coat_expect))
        for frame in (frame_objs[0], frame_objs[-1]):
            jobs.append(dict(path=frame, importer=importer, label="simulation frames/" + os.path.basename(frame),
                             expect={"vertices": summary["vertices"], "faces": summary["faces"]}))
    glbs = {}
    for path, label in ((out + "/feather/feather.glb", "hawk feather.glb"), (out + "/mesh/mesh.glb", "hawk mesh.glb"),
                        (out + "/sim/sim.glb", "simulation sim.glb"), (out + "/coat/coat.glb", "coat coat.glb")):
        if os.path.exists(path):
            glbs[path] = glb_counts(path)
            c = glbs[path]
            expect = {"objects": c["objects"], "meshes": c["meshes"], "triangles": c["triangles"]}
            if c["frames"]:
                expect.update(frames=c["frames"], shape_keys=c["targets"])
            if label == "hawk mesh.glb":
                check(c["triangles"] == report["face_count"], "mesh.glb: %d triangles, report.json says %d faces"
                      % (c["triangles"], report["face_count"]))
            if label.startswith("coat"):
                # What `plume coat` printed: "N feather instances of M meshes, and the surface".
                match = re.search(r"(\d+) feather instances of (\d+) meshes, and the surface", coat_report)
                check(match is not None, "plume coat reports its instances (%s)" % coat_report.strip())
                if match:
                    expect.update(objects=int(match.group(1)) + 1, meshes=int(match.group(2)) + 1)
            jobs.append(dict(path=path, importer="gltf", label=label, expect=expect))
    if glbs:
        # Reported, not judged: whether this Blender's default glTF import works here.
        jobs.append(dict(path=next(iter(glbs)), importer="gltf-default", label="default shading", expect={}))
    if out + "/sim/sim.glb" in glbs:
        c = glbs[out + "/sim/sim.glb"]
        check(c["frames"] == summary["frames"], "sim.glb: %d animation keyframes, summary.json says %d frames"
              % (c["frames"], summary["frames"]))

    if blender:
        jobs_path, results_path = out + "/blender-jobs.json", out + "/blender-results.json"
        json.dump(jobs, open(jobs_path, "w"))
        proc = subprocess.run([blender, "-b", "--factory-startup", "--python", os.path.join(HERE, "blender_counts.py"),
                               "--", jobs_path, results_path], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              text=True)
        if not os.path.exists(results_path):
            check(False, "Blender ran the imports:\n" + proc.stdout[-3000:])
        else:
            for result in json.load(open(results_path)):
                got = result["blender"]
                if result["importer"] == "gltf-default":
                    print("note: Blender's glTF import with its default shading (Normals): " +
                          ("fails here (%s)" % [line for line in got["error"].splitlines() if "Error" in line][-1].strip()[:160]
                           if "error" in got else "works"))
                    continue
                if "error" in got:
                    check(False, "Blender %s importer, %s: %s" % (result["importer"], result["label"], got["error"]))
                    continue
                for key, want in result["expect"].items():
                    check(got[key] == want, "Blender %s importer, %s: %s %d (plume wrote %d)"
                          % (result["importer"], result["label"], key, got[key], want))

    if pvbatch:
        pv_jobs = [dict(path=out + "/feather/feather.obj", label="hawk feather.obj",
                        expect={"points": curves["points"], "line_segments": curves["segments"]}),
                   dict(path=out + "/mesh/mesh.obj", label="hawk mesh.obj",
                        expect={"points": report["vertex_count"], "polys": report["face_count"]}),
                   dict(path=coat_obj, label="coat coat.obj", expect={"points": coat_v, "line_segments": coat_l})]
        for pvd in sorted(glob.glob(out + "/sim/*.pvd")):
            pv_jobs.append(dict(path=pvd, label="simulation " + os.path.basename(pvd),
                                expect={"timesteps": summary["frames"], "points": summary["vertices"],
                                        "cells": summary["faces"], "last_points": summary["vertices"],
                                        "last_cells": summary["faces"]}))
        jobs_path, results_path = out + "/paraview-jobs.json", out + "/paraview-results.json"
        json.dump(pv_jobs, open(jobs_path, "w"))
        proc = subprocess.run([pvbatch, os.path.join(HERE, "paraview_counts.py"), jobs_path, results_path],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if not os.path.exists(results_path):
            check(False, "ParaView ran the reads:\n" + proc.stdout[-3000:])
        else:
            for result in json.load(open(results_path)):
                got = result["paraview"]
                if "error" in got:
                    check(False, "ParaView, %s: %s" % (result["label"], got["error"]))
                    continue
                for key, want in result["expect"].items():
                    check(got.get(key) == want, "ParaView %s, %s: %s %s (plume wrote %d)"
                          % (got["reader"], result["label"], key, got.get(key), want))
                if result["path"].endswith(".pvd"):
                    # The fields the issue asks for, per face and per vertex.
                    for kind, names in (("cell_arrays", FACE_FIELDS), ("point_arrays", VERTEX_FIELDS)):
                        missing = sorted(set(names) - set(got.get(kind, [])))
                        check(not missing, "ParaView, %s: %s has %s%s" % (result["label"], kind, ", ".join(names),
                                                                         " (missing %s)" % missing if missing else ""))
                if got.get("cell_arrays"):
                    print("     cell fields: " + ", ".join(got["cell_arrays"]))
                if got.get("point_arrays"):
                    print("     point fields: " + ", ".join(got["point_arrays"]))

    if not keep:
        shutil.rmtree(out)
    print("interop: %d check(s) failed" % failures if failures else "interop: every check passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
