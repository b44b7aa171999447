#!/usr/bin/env bash
# Scenario tests of `plume mesh`: a feather spec and a guides spec meshed into
# DIR/mesh.obj, mesh.png and report.json; bad input fails clearly and writes nothing.
# Usage: mesh.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"

# A feather spec, twice: the same bytes.
"$plume" mesh "$source_dir/examples/franco-walter/hawk.json" -o "$scratch/hawk" 2>"$scratch/err.txt"
check "hawk: exit 0" test $? -eq 0
for name in mesh.obj mesh.png report.json; do
	check "hawk: $name written" test -s "$scratch/hawk/$name"
done
check "hawk: aligned fraction 1" grep -q '"aligned_fraction": 1,' "$scratch/hawk/report.json"
check "hawk: triangles only" bash -c "! grep -E '^f( [^ ]+){4,}' '$scratch/hawk/mesh.obj'"
"$plume" mesh "$source_dir/examples/franco-walter/hawk.json" -o "$scratch/hawk2" 2>/dev/null
check "hawk: deterministic obj" cmp -s "$scratch/hawk/mesh.obj" "$scratch/hawk2/mesh.obj"
check "hawk: deterministic report" cmp -s "$scratch/hawk/report.json" "$scratch/hawk2/report.json"

# --edge-length: a finer mesh has more vertices.
"$plume" mesh "$source_dir/examples/franco-walter/hawk.json" -o "$scratch/fine" --edge-length 0.0025 2>/dev/null
check "fine: exit 0" test $? -eq 0
coarse=$(grep -c '^v ' "$scratch/hawk/mesh.obj")
fine=$(grep -c '^v ' "$scratch/fine/mesh.obj")
check "fine: more vertices ($fine > 2 x $coarse)" test "$fine" -gt $((2 * coarse))
check "fine: edge length in report, shortest form" grep -q '"edge_length": 0.0025,' "$scratch/fine/report.json"

# Every vane face a junction face (the filoplume at 5 mm): no angle to report, null (it read
# 180, the pi the library holds then); a hawk's vane has one.
"$plume" mesh "$source_dir/examples/streit-heidrich/filoplume.json" -o "$scratch/filoplume" -e 0.005 2>"$scratch/err.txt"
succeeded "filoplume: exit 0"
check "filoplume: vane_min_angle_deg null, every vane face excepted" python3 -c "
import json
r = json.load(open('$scratch/filoplume/report.json'))
assert r['vane_face_count'] > 0 and r['excepted_count'] == r['vane_face_count'], r
assert r['vane_min_angle_deg'] is None, r['vane_min_angle_deg']
h = json.load(open('$scratch/hawk/report.json'))
assert h['excepted_count'] < h['vane_face_count'] and 20 <= h['vane_min_angle_deg'] < 60, h
"

# A guides spec.
"$plume" mesh "$source_dir/examples/meshes/guides.json" -o "$scratch/guides" 2>"$scratch/err.txt"
check "guides: exit 0" test $? -eq 0
check "guides: aligned fraction 1" grep -q '"aligned_fraction": 1,' "$scratch/guides/report.json"

# Guides whose first try folds (overlapping faces) are meshed by a later try: three guides at e =
# 15 mm (the hawk at e = 0.6 mm the same) failed with exit 1, "the barb guides fold over one another",
# though the tries after the first, which pass over a try that folds, mesh them.
cat >"$scratch/folds.json" <<'EOF'
{"mesh": {"edge_length": 0.015, "rachis_width_base": 0.00229, "rachis_width_tip": 0.00445},
 "boundary": [[0.0438, 0.15], [0.0249, 0.293], [-0.0267, 0.303], [-0.0412, 0.15], [-0.0259, 0.00118], [0.0177, 0.0483]],
 "rachis": {"type": "catmull-rom", "points": [[0.0, 0.0], [-0.00737, 0.075], [-0.0104, 0.15], [-0.00737, 0.225], [0.0, 0.3]]},
 "guides": [{"type": "catmull-rom", "points": [[-0.00873, 0.205], [-0.0211, 0.225]]},
            {"type": "catmull-rom", "points": [[-0.0104, 0.149], [-0.0191, 0.156], [-0.0257, 0.164]]},
            {"type": "bezier", "points": [[-0.0018, 0.0166], [0.00054, 0.0266], [0.00221, 0.0369]]}]}
EOF
"$plume" mesh "$scratch/folds.json" -o "$scratch/folds" 2>"$scratch/err.txt"
succeeded "guides whose first try folds: a later try meshes them"
check "guides whose first try folds: a vane, every face aligned" python3 -c "
import json
r = json.load(open('$scratch/folds/report.json'))
assert r['vane_face_count'] > 0 and r['aligned_fraction'] == 1, r
"

# A boundary that leaves no guide beside the band is named as the cause (it read "the feather
# needs barbs with a length in the feather plane", a feather's cause, for explicit guides).
python3 -c "
import json
d = json.load(open('$source_dir/examples/meshes/guides.json'))
d['boundary'] = [[1.0, 1.0], [1.1, 1.0], [1.1, 1.1]]
json.dump(d, open('$scratch/far.json', 'w'))"
expect_no_output "a boundary away from the rachis" 3 \
	"far.json: no vane to mesh: 4 usable barb guides on the left, 4 on the right (0 input guides left out), and no guide vertex beside the rachis band inside the boundary polygon; the boundary must enclose the rachis and reach past the band (0.0025 m wide at the base, rachis_width_base, and 0.0008 m at the tip, rachis_width_tip)" \
	"$scratch/far" "$plume" mesh "$scratch/far.json" -o "$scratch/far"

# A picture smaller than its 20-pixel margins: the margins shrink to a quarter of it, and the mesh
# fills it the right way up (at --size 32x32 the scale was negative: rows 1 to 20, turned half a turn).
"$plume" mesh "$source_dir/examples/meshes/guides.json" -o "$scratch/thumb" --format png --size 32x32 2>"$scratch/err.txt"
succeeded "a 32x32 picture"
check "a 32x32 picture: the mesh between the margins, its height filling them" python3 -c "
# The PNG decoded (8-bit RGB, the five filters): the bounds of what is drawn.
import struct, zlib
data = open('$scratch/thumb/mesh.png', 'rb').read()
at, idat = 8, b''
while at < len(data):
    length, kind = struct.unpack('>I4s', data[at:at + 8])
    if kind == b'IHDR':
        width, height, depth, colour = struct.unpack('>IIBB', data[at + 8:at + 18])
    elif kind == b'IDAT':
        idat += data[at + 8:at + 8 + length]
    at += 12 + length
assert depth == 8 and colour in (2, 6), (depth, colour)
step = 3 if colour == 2 else 4
raw, rows, previous, drawn = zlib.decompress(idat), [], bytearray(width * step), []
for y in range(height):
    kind, line = raw[y * (width * step + 1)], bytearray(raw[y * (width * step + 1) + 1:(y + 1) * (width * step + 1)])
    for i in range(len(line)):
        a = line[i - step] if i >= step else 0
        b, c = previous[i], previous[i - step] if i >= step else 0
        p = a + b - c
        predictor = [0, a, b, (a + b) // 2, a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c) else b if abs(p - b) <= abs(p - c) else c][kind]
        line[i] = (line[i] + predictor) & 255
    previous = line
    drawn += [(y, x) for x in range(width) if min(line[x * step:x * step + 3]) < 250]
rows, columns = [y for y, x in drawn], [x for y, x in drawn]
assert 6 <= min(rows) and max(rows) <= 25 and max(rows) - min(rows) >= 14, (min(rows), max(rows))
assert 6 <= min(columns) and max(columns) <= 25, (min(columns), max(columns))
"

# "samples" on a polyline did nothing (its points are the polyline): refused, naming the key.
python3 -c "
import json
d = json.load(open('$source_dir/examples/meshes/guides.json'))
d['guides'][6] = {'type': 'polyline', 'samples': 500, 'points': d['guides'][6]}
json.dump(d, open('$scratch/polyline.json', 'w'))"
expect_no_output "samples on a polyline" 3 \
	"polyline.json: \$.guides[6].samples: a polyline takes its points as they are; \"samples\" is for catmull-rom and bezier" \
	"$scratch/polyline" "$plume" mesh "$scratch/polyline.json" -o "$scratch/polyline"

# Without --size mesh.png is 1200 tall and as wide as the mesh, at most 16384 (--size's bound). A flat
# mesh (guides 0.1 m long, 1e-8 m apart) is 16384 wide: its width, 1.2e10 pixels, was cast to an int.
cat >"$scratch/flat.json" <<'EOF'
{"mesh": {"edge_length": 0.001, "rachis_width_base": 0.0002, "rachis_width_tip": 0.0002},
 "boundary": [[-0.05, -1e-9], [0.05, -1e-9], [0.05, 2e-8], [-0.05, 2e-8]],
 "rachis": {"type": "catmull-rom", "points": [[0.0, 0.0], [0.0, 1e-8]]},
 "guides": [[[0.0, 0.0], [-0.05, 0.0]], [[0.0, 1e-8], [-0.05, 1e-8]], [[0.0, 0.0], [0.05, 0.0]],
            [[0.0, 1e-8], [0.05, 1e-8]]]}
EOF
"$plume" mesh "$scratch/flat.json" -o "$scratch/flat" --format png 2>"$scratch/err.txt"
succeeded "a flat mesh's picture"
check "a flat mesh's picture is 16384 x 1200" bash -c "od -An -tu1 -j16 -N8 '$scratch/flat/mesh.png' | tr -s ' ' | grep -q '^ 0 0 64 0 0 0 4 176$'"

# Bad input: clear message, exit code, nothing written.
expect_failure "missing -o" 2 "missing -o DIR" "$plume" mesh "$source_dir/examples/meshes/guides.json"
expect_failure "bad edge length" 2 "--edge-length '-1'" "$plume" mesh "$source_dir/examples/meshes/guides.json" \
	-o "$scratch/bad" --edge-length -1
check "bad edge length: nothing written" test ! -e "$scratch/bad"
# An absurd edge length: refused, its row count to three digits (it printed 300 of them).
expect_no_output "edge length 1e-300" 3 "edge_length 1e-300 m is too small for a 0.200056 m rachis (2e+299 rows, at most 10000000)" \
	"$scratch/tiny" "$plume" mesh "$source_dir/examples/franco-walter/hawk.json" -o "$scratch/tiny" --edge-length 1e-300
check "edge length 1e-300: a short message" test "$(wc -c <"$scratch/err.txt")" -lt 300
# Small enough to need 26.9 GB: the memory estimate refuses it (exit 5).
expect_no_output "edge length 1e-5" 5 "the limit is" "$scratch/tiny" \
	"$plume" mesh "$source_dir/examples/franco-walter/hawk.json" -o "$scratch/tiny" --edge-length 1e-5
# Splines sampled past --max-memory are refused before they are sampled (exit 5, naming the spline):
# 10 KB of JSON, a guide of 500 points at 10000 samples a span, took 5 million points (200 MB).
python3 -c "
import json
d = json.load(open('$source_dir/examples/meshes/guides.json'))
d['guides'][1] = {'type': 'catmull-rom', 'samples': 10000,
                  'points': [[0.001 - 0.027 * i / 499, 0.045 + 0.03 * i / 499] for i in range(500)]}
json.dump(d, open('$scratch/samples.json', 'w'))"
expect_no_output "guides sampled past --max-memory" 5 \
	"samples.json: \$.guides[1]: the splines up to here sample into 4990114 points, about 0.319 GB at 64 B a point; the limit is 0.105 GB" \
	"$scratch/heavy" "$plume" mesh "$scratch/samples.json" -o "$scratch/heavy" --max-memory 100M
# The outputs are held to --max-memory too: a 16384x16384 mesh.png is a 1 GiB surface (it was
# drawn at --max-memory 100M, 1 GB of RSS); without png the same --size is nothing to write.
expect_no_output "a picture past --max-memory" 5 \
	"guides.json: writing png, obj (--format, --size) takes up to 1.07 GB besides the mesh's" \
	"$scratch/huge" "$plume" mesh "$source_dir/examples/meshes/guides.json" -o "$scratch/huge" \
	--size 16384x16384 --max-memory 100M
"$plume" mesh "$source_dir/examples/meshes/guides.json" -o "$scratch/huge" --format obj --size 16384x16384 \
	--max-memory 100M 2>"$scratch/err.txt"
succeeded "--size without png: nothing past --max-memory"
# --format lists what a mesh is written as, not a feather's formats.
expect_failure "format foo" 2 "unknown format 'foo' in --format: a mesh writes obj, png, glb" \
	"$plume" mesh "$source_dir/examples/meshes/guides.json" -o "$scratch/bad" --format foo
check "format foo: no svg offered" bash -c "! grep -q svg '$scratch/err.txt'"
expect_failure "format svg" 2 "unknown format 'svg' in --format: a mesh writes obj, png, glb" \
	"$plume" mesh "$source_dir/examples/meshes/guides.json" -o "$scratch/bad" --format png,svg
# An empty item is refused wherever it is ('obj,' was taken as obj; generate's list refused it).
for list in obj, ,obj obj,,png; do
	expect_failure "format '$list'" 2 "--format '$list' has an empty item; a mesh writes obj, png, glb" \
		"$plume" mesh "$source_dir/examples/meshes/guides.json" -o "$scratch/bad" --format "$list"
done
check "bad formats: nothing written" test ! -e "$scratch/bad"
"$plume" mesh "$source_dir/examples/meshes/guides.json" -o "$scratch/glb" --format glb,obj 2>"$scratch/err.txt"
succeeded "format glb,obj"
check "format glb,obj: mesh.glb, mesh.obj and report.json only" test "$(ls "$scratch/glb" | tr '\n' ' ')" = "mesh.glb mesh.obj report.json "
printf '{"guides": [[[0,0],[1,1]]], "rachis": [[0,0],[0,1]], "boundary": [[0,0],[1,0],[1,1]], "mesh": {"edge_lenght": 1}}' \
	>"$scratch/typo.json"
expect_failure "typo key" 3 "typo.json: \$.mesh" "$plume" mesh "$scratch/typo.json" -o "$scratch/typo"
check "typo key: nothing written" test ! -e "$scratch/typo"
expect_failure "missing file" 4 "nope.json" "$plume" mesh "$scratch/nope.json" -o "$scratch/nope"
check "missing file: nothing written" test ! -e "$scratch/nope"
# An edge length too coarse for a small vane (the Streit-Heidrich down, its vane 7.9 mm):
# the error names the edge length to use, and that one meshes it.
expect_no_output "coarse mesh of a small vane" 3 "no vane to mesh at edge_length 0.01 m: the vane spans 0.00785 m" \
	"$scratch/coarse" "$plume" mesh "$source_dir/examples/streit-heidrich/down.json" -o "$scratch/coarse" -e 0.01
suggested=$(sed -n 's/.*an edge_length of \([0-9.e-]*\) m or less meshes it.*/\1/p' "$scratch/err.txt")
check "coarse mesh: an edge length is suggested ($suggested)" test -n "$suggested"
"$plume" mesh "$source_dir/examples/streit-heidrich/down.json" -o "$scratch/suggested" -e "${suggested:-0}" \
	>"$scratch/out.txt" 2>"$scratch/err.txt"
succeeded "the suggested edge length meshes the down"
"$plume" help mesh >"$scratch/help.txt" 2>&1
check "help mentions guides spec" grep -q "guides spec" "$scratch/help.txt"

finish
