# Shared by the scenario scripts in tests/cli/ (sourced, not run): the two
# arguments every script takes, a scratch folder removed on exit, pass/fail
# counters and the checks. Usage, at the top of a script:
#   source "$(dirname "$0")/../cli_support.sh" "$@"   # PLUME_BINARY SOURCE_DIR
# and `finish` as its last line.
set -u
plume=$1
source_dir=$2
scratch=$(mktemp -d /tmp/plume-cli-XXXXXX)
trap 'rm -rf "$scratch"' EXIT
passed=0
failed=0

check() { # check NAME CONDITION...
	local name=$1
	shift
	if "$@"; then
		passed=$((passed + 1))
	else
		failed=$((failed + 1))
		echo "FAIL: $name" >&2
	fi
}

# succeeded NAME: the command just before exited 0; when it did not, its exit
# code and $scratch/err.txt. Call it on the next line: it reads $? first, so
# NAME must hold no command substitution ("$(...)" would reset $? to 0).
succeeded() {
	local status=$? name=$1
	if [ "$status" -eq 0 ]; then
		passed=$((passed + 1))
	else
		failed=$((failed + 1))
		echo "FAIL: $name (exit $status): $(cat "$scratch/err.txt" 2>/dev/null)" >&2
	fi
}

# expect_failure NAME EXIT_CODE MESSAGE_FRAGMENT COMMAND...: the exit code and
# the message on stderr.
expect_failure() {
	local name=$1 code=$2 fragment=$3
	shift 3
	"$@" >"$scratch/out.txt" 2>"$scratch/err.txt"
	local got=$?
	check "$name: exit $code (got $got)" test "$got" -eq "$code"
	if ! grep -qF -- "$fragment" "$scratch/err.txt"; then
		failed=$((failed + 1))
		echo "FAIL: $name: stderr lacks '$fragment': $(cat "$scratch/err.txt")" >&2
	else
		passed=$((passed + 1))
	fi
}

# expect_no_output NAME EXIT_CODE MESSAGE_FRAGMENT OUTPUT_DIR COMMAND...: the
# same, and no output folder or staging folder left behind.
expect_no_output() {
	local name=$1 code=$2 fragment=$3 out=$4
	shift 4
	expect_failure "$name" "$code" "$fragment" "$@"
	check "$name: nothing written" test ! -e "$out"
	check "$name: no staging left" test -z "$(ls -A "$scratch" | grep plume-staging)"
}

finish() {
	echo "$passed passed, $failed failed"
	test "$failed" -eq 0
}
