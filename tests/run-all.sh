#!/bin/sh
# run-all.sh - run every test binary under $BUILD/tests, then the script checks
# in tests/checks/*.sh. Each cmocka binary prints its own summary; this script
# ends with one line "N passed, N failed, N skipped" counting test programs.
# With arguments (e.g. "net"), only those test directories run, no checks.
#
# A program that exits 77 was SKIPPED (e.g. tests/net without root): it is
# reported as such, never counted as passed; with ROBOELF_NO_SKIP=1 a skip
# counts as a failure (make netrig).
#
# A test program counts as passed only if it exits 0 AND its output has no
# cmocka "[  FAILED  ]" or "[  ERROR   ]" line (cmocka 1.1.5 returns 0 when a
# group setup fails) AND, for a cmocka binary, a "[  PASSED  ]" line.
# Environment given to tests: BUILD, ROBOELF_BIN (the binaries), ROBOELF_TOP,
# and PATH: only the commands of docs/commands.md (tools/cmdtable.sh), so that
# a test calling a command nobody declared fails on every machine, not only
# on a fresh one (ROBOELF_SYSPATH keeps the full one for a declared tool that
# runs helpers of its own: lintian).
set -u
BUILD=${BUILD:-build}
ROBOELF_TOP=$(cd "$(dirname "$0")/.." && pwd)
ROBOELF_BIN=$ROBOELF_TOP/$BUILD/bin
export BUILD ROBOELF_BIN ROBOELF_TOP
cd "$ROBOELF_TOP" || exit 1
sh tools/cmdtable.sh path "$ROBOELF_TOP/$BUILD/cmdpath" || exit 1
ROBOELF_SYSPATH=$PATH
PATH=$ROBOELF_TOP/$BUILD/cmdpath
export PATH ROBOELF_SYSPATH
LOGDIR=$BUILD/test-logs
mkdir -p "$LOGDIR"
passed=0; failed=0; skipped=0; failures=""
# Per-program deadline (s): a hung test fails with exit 124 instead of hanging
# the run; system tests get more, and so does the fuzz check, which builds
# its targets first (ROBOELF_TEST_TIMEOUT overrides both).
deadline() {
	case $1 in
	system/* | net/* | checks/fuzz_short.sh) echo "${ROBOELF_TEST_TIMEOUT:-600}" ;;
	*) echo "${ROBOELF_TEST_TIMEOUT:-180}" ;;
	esac
}
run() { # run NAME KIND CMD... ; KIND = cmocka | script
	name=$1; kind=$2; shift 2
	log=$LOGDIR/$(echo "$name" | tr / _).log
	echo "=== $name"
	start=$(date +%s)
	timeout --kill-after=10 "$(deadline "$name")" "$@" >"$log" 2>&1
	rc=$?
	cat "$log"
	res=ok
	if [ "$rc" -eq 77 ]; then
		res="SKIPPED ($(grep -m1 '^SKIP' "$log"))"
	elif [ "$rc" -eq 124 ] || [ "$rc" -eq 137 ]; then
		res="FAILED (timed out after $(deadline "$name") s)"
	elif [ "$rc" -ne 0 ]; then
		res="FAILED (exit $rc)"
	elif grep -qE '^\[  (FAILED|ERROR)   ?\]' "$log"; then
		res="FAILED (cmocka reported a failure)"
	elif [ "$kind" = cmocka ] && ! grep -q '^\[  PASSED  \]' "$log"; then
		res="FAILED (no cmocka summary)"
	elif grep -q '^\[  PASSED  \] 0 test' "$log"; then
		res="FAILED (no test ran)"
	fi
	if [ "$res" = ok ]; then
		passed=$((passed + 1))
	elif [ "$rc" -eq 77 ] && [ "${ROBOELF_NO_SKIP:-0}" != 1 ]; then
		skipped=$((skipped + 1))
	else
		failed=$((failed + 1)); failures="$failures $name"
	fi
	echo "=== $name: $res ($(( $(date +%s) - start )) s)"
}
dirs=${*:-unit load sim dmc system net}
for dir in $dirs; do
	for t in "$BUILD/tests/$dir"/test_*; do
		[ -x "$t" ] || continue
		run "$dir/$(basename "$t")" cmocka "$t"
	done
done
checks="tests/checks/*.sh"
[ $# -gt 0 ] && checks=""
for s in $checks; do
	[ -f "$s" ] || continue
	run "checks/$(basename "$s")" script "$(head -1 "$s" | grep -q bash && echo bash || echo sh)" "$s"
done
[ -n "$failures" ] && echo "failed:$failures"
echo "$passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
