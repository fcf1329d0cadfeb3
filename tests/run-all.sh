#!/bin/sh
# run-all.sh - run every test binary under $BUILD/tests, then the script checks
# in tests/checks/*.sh. Each cmocka binary prints its own summary; this script
# ends with one line "N passed, N failed" counting test programs.
# Environment given to tests: BUILD, ROBOELF_BIN (the binaries), ROBOELF_TOP.
set -u
BUILD=${BUILD:-build}
ROBOELF_TOP=$(cd "$(dirname "$0")/.." && pwd)
ROBOELF_BIN=$ROBOELF_TOP/$BUILD/bin
export BUILD ROBOELF_BIN ROBOELF_TOP
cd "$ROBOELF_TOP" || exit 1
passed=0; failed=0; failures=""
run() {
	name=$1; shift
	echo "=== $name"
	start=$(date +%s)
	if "$@"; then
		passed=$((passed + 1)); res=ok
	else
		failed=$((failed + 1)); failures="$failures $name"; res=FAILED
	fi
	echo "=== $name: $res ($(( $(date +%s) - start )) s)"
}
for dir in unit load sim dmc system; do
	for t in "$BUILD/tests/$dir"/test_*; do
		[ -x "$t" ] || continue
		run "$dir/$(basename "$t")" "$t"
	done
done
for s in tests/checks/*.sh; do
	[ -f "$s" ] || continue
	run "checks/$(basename "$s")" sh "$s"
done
[ -n "$failures" ] && echo "failed:$failures"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
