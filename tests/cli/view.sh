#!/usr/bin/env bash
# Scenario tests of `plume view`: the page it writes (the viewer's files copied,
# the .glb files embedded as base64 that decodes back to the same bytes, or
# listed by URL and served on 127.0.0.1), where it writes it, and its errors.
# It runs without node: a stand-in viewer folder is given with --viewer (the
# real viewer in a real browser is tests/browser/run.sh).
# Usage: view.sh PLUME_BINARY SOURCE_DIR
source "$(dirname "$0")/../cli_support.sh" "$@"

viewer=$scratch/viewer-assets
mkdir -p "$viewer"
echo '<!doctype html><script src="models.js"></script>' >"$viewer/index.html"
echo '// viewer' >"$viewer/plume-viewer.js"
echo 'MIT' >"$viewer/LICENSE.three.txt"

# Three files whose lengths cover the three base64 paddings, and a non-.glb. Each starts with
# a GLB header (the magic "glTF", version 2, its length, little-endian), which plume view checks.
in=$scratch/results
mkdir -p "$in"
glb() { # glb LENGTH FILE: a GLB header, then random bytes
	printf 'glTF\002\000\000\000' >"$2"
	printf "$(printf '\\%03o\\%03o\\%03o\\%03o' $(($1 & 255)) $(($1 >> 8 & 255)) $(($1 >> 16 & 255)) $(($1 >> 24)))" >>"$2"
	head -c $(($1 - 12)) /dev/urandom >>"$2"
}
glb 1000 "$in/b.glb"
glb 1001 "$in/a.glb"
glb 100002 "$in/c.glb"
echo 'not a model' >"$in/notes.txt"

# The base64 of the entry named $2 in models.js $1, decoded.
decoded() {
	grep -F "{\"name\": \"$2\", \"data\": \"" "$1" | sed 's/.*"data": "\([^"]*\)".*/\1/' | base64 -d
}

# --- a folder: every .glb, sorted, embedded -------------------------------------
"$plume" view "$in" --viewer "$viewer" >"$scratch/out.txt" 2>"$scratch/err.txt"
succeeded "view a folder succeeds"
page=$in/view
for f in index.html plume-viewer.js LICENSE.three.txt models.js; do
	check "view: $f written" test -s "$page/$f"
done
check "view: viewer files copied" cmp -s "$viewer/plume-viewer.js" "$page/plume-viewer.js"
check "view: only the .glb files, sorted" test "$(grep -o '"name": "[^"]*"' "$page/models.js" | tr '\n' ' ')" = \
	'"name": "a.glb" "name": "b.glb" "name": "c.glb" '
for f in a b c; do
	check "view: $f.glb decodes back to its bytes" cmp -s <(decoded "$page/models.js" $f.glb) "$in/$f.glb"
done
"$plume" view "$in///" --viewer "$viewer" >"$scratch/slash.txt" 2>&1
check "view: a trailing slash gives the same page" grep -qF "$in/view/index.html" "$scratch/slash.txt"
check "view: prints the file:// address" grep -qF "file://$(realpath "$page")/index.html" "$scratch/out.txt"
cp "$page/models.js" "$scratch/models-first.js"
"$plume" view "$in" --viewer "$viewer" >/dev/null 2>&1
check "view: again, the same bytes" cmp -s "$scratch/models-first.js" "$page/models.js"
check "view: no staging left" test -z "$(ls -A "$in" | grep plume-staging)"

# --- one file: the page beside it, or -o; the viewer from $PLUME_VIEWER_DIR -----
PLUME_VIEWER_DIR=$viewer "$plume" view "$in/b.glb" -o "$scratch/one" >/dev/null 2>"$scratch/err.txt"
succeeded "view one file with -o"
check "view one file: only it" test "$(grep -c '"name"' "$scratch/one/models.js")" -eq 1
check "view one file: its bytes" cmp -s <(decoded "$scratch/one/models.js" b.glb) "$in/b.glb"
mkdir -p "$scratch/quote"
cp "$in/a.glb" "$scratch/quote/say \"hi\".glb"
"$plume" view "$scratch/quote/say \"hi\".glb" --viewer "$viewer" >/dev/null 2>&1
check "view: a name with quotes is escaped in models.js" grep -qF '"name": "say \"hi\".glb"' "$scratch/quote/view/models.js"

# --- errors: a message, an exit code, nothing written ---------------------------
mkdir -p "$scratch/empty"
expect_no_output "no .glb in the folder" 4 "no .glb file in this folder" "$scratch/empty/view" \
	"$plume" view "$scratch/empty" --viewer "$viewer"
expect_no_output "not a .glb" 4 "not a .glb file" "$in/view-txt" \
	"$plume" view "$in/notes.txt" --viewer "$viewer" -o "$in/view-txt"
expect_no_output "missing input" 4 "$scratch/nothing.glb" "$scratch/view" \
	"$plume" view "$scratch/nothing.glb" --viewer "$viewer"
# A file named .glb that is not one: refused, alone or in a folder, nothing written.
mkdir -p "$scratch/fake"
echo 'just text' >"$scratch/fake/fake.glb"
expect_no_output "a text file named .glb" 3 "fake.glb: not a glTF binary" "$scratch/fake/view" \
	"$plume" view "$scratch/fake/fake.glb" --viewer "$viewer"
cp "$in/a.glb" "$scratch/fake/a.glb"
expect_no_output "a folder with a fake .glb" 3 "fake.glb: not a glTF binary" "$scratch/fake/view" \
	"$plume" view "$scratch/fake" --viewer "$viewer"
head -c 500 "$in/a.glb" >"$scratch/fake/cut.glb"
rm "$scratch/fake/fake.glb"
expect_no_output "a .glb cut short" 3 "cut.glb: its GLB header gives 1001 bytes, but the file has 500" \
	"$scratch/fake/view" "$plume" view "$scratch/fake/cut.glb" --viewer "$viewer"
# A folder of more than 24 .glb files: refused (exit 4) with a pointer to giving one file.
mkdir -p "$scratch/many"
for i in $(seq 25); do cp "$in/a.glb" "$scratch/many/m$i.glb"; done
expect_no_output "25 .glb files in a folder" 4 "more than 24 .glb files; give one file as INPUT" \
	"$scratch/many/view" "$plume" view "$scratch/many" --viewer "$viewer"
expect_no_output "viewer not built" 4 "no built viewer there" "$scratch/v2" \
	env PLUME_VIEWER_DIR="$scratch/empty" "$plume" view "$in" -o "$scratch/v2"
expect_no_output "--serve not a port" 2 "--serve '99999' must be a port number" "$scratch/v3" \
	"$plume" view "$in" --viewer "$viewer" -o "$scratch/v3" --serve 99999
expect_failure "no input" 2 "missing INPUT" "$plume" view
expect_failure "two inputs" 2 "unexpected argument" "$plume" view "$in" "$in"

# --- --serve: URLs in models.js; the page and the files over HTTP on 127.0.0.1 ---
# GET PORT PATH: the response (headers and body) on stdout, through bash's /dev/tcp.
get() {
	exec 3<>"/dev/tcp/127.0.0.1/$1" || return 1
	printf 'GET %s HTTP/1.0\r\nHost: localhost\r\n\r\n' "$2" >&3
	cat <&3
	exec 3<&-
}
port=$((20000 + $$ % 20000))
"$plume" view "$in" --viewer "$viewer" -o "$scratch/served" --serve "$port" >"$scratch/serve.txt" 2>&1 &
server=$!
for _ in $(seq 50); do grep -q Serving "$scratch/serve.txt" 2>/dev/null && break || sleep 0.1; done
if grep -q Serving "$scratch/serve.txt"; then
	check "serve: models.js lists URLs" grep -qF '{"name": "b.glb", "url": "/glb/1.glb"}' "$scratch/served/models.js"
	check "serve: nothing embedded" bash -c "! grep -q '\"data\"' '$scratch/served/models.js'"
	get "$port" /glb/1.glb >"$scratch/response"
	check "serve: 200 for a listed file" grep -q '^HTTP/1.1 200' "$scratch/response"
	check "serve: the file's bytes" cmp -s <(tail -c 1000 "$scratch/response") "$in/b.glb"
	get "$port" / >"$scratch/response"
	check "serve: the page" grep -q 'models.js' "$scratch/response"
	for path in /glb/3.glb /../notes.txt /notes.txt /glb/1.glbx; do
		check "serve: 404 for $path" bash -c "exec 3<>/dev/tcp/127.0.0.1/$port; printf 'GET $path HTTP/1.0\r\n\r\n' >&3; head -1 <&3 | grep -q '404'"
	done
	kill -INT "$server"
	wait "$server"
	check "serve: Ctrl-C ends it with status 0" test $? -eq 0
else
	kill "$server" 2>/dev/null
	echo "note: could not serve on 127.0.0.1:$port ($(cat "$scratch/serve.txt")); --serve checks skipped"
fi

finish
