#!/bin/sh
# fuzz_short.sh - every libFuzzer target (tests/fuzz/fuzz_*.c) for a few
# seconds, so that `make check` (tests/run-all.sh) catches a regression:
# each target first replays its seed corpus and its regression inputs
# (tests/fuzz/regress/NAME: every crash found so far), then fuzzes for
# FUZZ_SHORT_SECONDS (default 5). Builds the targets first (make
# fuzz-build, clang from `make deps`; a missing clang is a failure, not a
# skip). Works in a temporary directory: nothing is written to the
# repository. On a crash it prints the reproducer path; the input is copied
# to $BUILD/fuzz-short-crash/ so it outlives the run. docs/fuzzing.md.
set -u
cd "$(dirname "$0")/../.." || exit 1
BUILD=${BUILD:-build}
FUZZ_BUILD=${FUZZ_BUILD:-$BUILD/fuzz}
names=$(ls tests/fuzz/fuzz_*.c 2>/dev/null | sed 's|.*/fuzz_||; s|\.c$||')
if [ -z "$names" ]; then
	echo "fuzz_short.sh: no tests/fuzz/fuzz_*.c" >&2
	exit 1
fi
if ! command -v "${FUZZ_CC:-clang}" >/dev/null; then
	echo "fuzz_short.sh: FAILED: ${FUZZ_CC:-clang} not found (make deps installs it)"
	exit 1
fi
# a make of its own: run-all.sh has no jobserver to share (make check)
unset MAKEFLAGS MFLAGS MAKELEVEL
make --no-print-directory -s -j2 BUILD="$BUILD" FUZZ_BUILD="$FUZZ_BUILD" fuzz-build ||
	{ echo "fuzz_short.sh: FAILED: make fuzz-build"; exit 1; }
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
# shellcheck disable=SC2086
FUZZ_BUILD=$FUZZ_BUILD FUZZ_WORK=$tmp FUZZ_SECONDS=${FUZZ_SHORT_SECONDS:-5} \
	tests/fuzz/run.sh $names
rc=$?
if [ "$rc" -ne 0 ]; then
	mkdir -p "$BUILD/fuzz-short-crash"
	for f in "$tmp"/crash/*/*; do
		[ -f "$f" ] || continue
		keep=$BUILD/fuzz-short-crash/$(basename "$(dirname "$f")")-$(basename "$f")
		cp "$f" "$keep" && echo "fuzz_short.sh: reproducer kept as $keep"
	done
	echo "fuzz_short.sh: FAILED"
	exit 1
fi
echo "fuzz_short.sh: every target ok"
