#!/usr/bin/env bash
# The shared library exports exactly the functions its public headers declare:
# internal helpers (CSC lookups, solver internals, test hooks) stay hidden, and
# every documented function is there for a program linked against libplume.so.
# Usage: exports.sh LIBPLUME_SO SOURCE_DIR
set -uo pipefail
library=$1
source_dir=$2

exported=$(nm -D --defined-only "$library" | awk '$2 ~ /^[TDBR]$/ {print $3}' | sort -u)
# Function declarations of the public headers: a name followed by "(" on a line
# that is not a typedef, a macro or a comment; static inline helpers are not exported.
declared=$(python3 - "$source_dir/include/plume" <<'EOF'
import pathlib, re, sys
names = set()
for header in sorted(pathlib.Path(sys.argv[1]).glob("*.h")):
    text = re.sub(r"/\*.*?\*/", "", header.read_text(), flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    for statement in re.split(r"[;{}]", text):
        statement = " ".join(line for line in statement.splitlines() if not line.lstrip().startswith("#"))
        if re.search(r"\btypedef\b|\bstatic\b", statement):
            continue
        match = re.search(r"\b(plume_\w+)\s*\(", statement)
        if match:
            names.add(match.group(1))
print("\n".join(sorted(names)))
EOF
)

status=0
extra=$(comm -23 <(echo "$exported") <(echo "$declared"))
missing=$(comm -13 <(echo "$exported") <(echo "$declared"))
if [ -n "$extra" ]; then
	echo "FAIL: exported but not declared in include/plume:"
	echo "$extra" | sed 's/^/  /'
	status=1
fi
if [ -n "$missing" ]; then
	echo "FAIL: declared in include/plume but not exported:"
	echo "$missing" | sed 's/^/  /'
	status=1
fi
count=$(echo "$declared" | wc -l)
if [ "$count" -lt 100 ]; then
	echo "FAIL: only $count public functions found in the headers; the parser is broken"
	status=1
fi
[ $status -eq 0 ] && echo "ok: libplume.so exports the $count functions of include/plume and nothing else"
exit $status
