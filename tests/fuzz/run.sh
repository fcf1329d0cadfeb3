#!/bin/sh
# run.sh - run libFuzzer targets built by `make fuzz-build` (docs/fuzzing.md).
#
#   tests/fuzz/run.sh NAME...      run $FUZZ_BUILD/bin/fuzz_NAME for each NAME
#
# Environment:
#   FUZZ_BUILD    where the targets are (default build/fuzz)
#   FUZZ_SECONDS  time per target, s (default 600)
#   FUZZ_WORK     working directory for corpora and crashes (default
#                 $FUZZ_BUILD): WORK/corpus/NAME starts as a copy of
#                 tests/fuzz/corpus/NAME plus tests/fuzz/regress/NAME (inputs
#                 found earlier are kept); WORK/crash/NAME/ receives crashes.
#                 The repository's corpus is never written.
#   FUZZ_ARGS     extra libFuzzer options
# Each target replays its whole corpus (regression inputs included) first,
# then fuzzes; the dictionary tests/fuzz/NAME.dict and the libFuzzer options
# in tests/fuzz/NAME.options (one line) are used when present.
# Prints one line per target: NAME: ok|FAILED, execs, exec/s, cov, ft, and
# for a failure the reproducer path and the command that replays it. Logs go
# to WORK/log/NAME.log. Exits 1 when a target failed (crash, leak, timeout,
# sanitizer report), 0 otherwise.
set -u
cd "$(dirname "$0")/../.." || exit 1
FUZZ_BUILD=${FUZZ_BUILD:-build/fuzz}
FUZZ_SECONDS=${FUZZ_SECONDS:-600}
WORK=${FUZZ_WORK:-$FUZZ_BUILD}
failed=0
[ $# -gt 0 ] || { echo "run.sh: no target named" >&2; exit 1; }
for name in "$@"; do
	bin=$FUZZ_BUILD/bin/fuzz_$name
	corpus=$WORK/corpus/$name
	crash=$WORK/crash/$name
	log=$WORK/log/$name.log
	if [ ! -x "$bin" ]; then
		echo "$name: FAILED (no $bin: run make fuzz-build)"
		failed=1
		continue
	fi
	mkdir -p "$corpus" "$crash" "$WORK/log" || exit 1
	for d in tests/fuzz/corpus/$name tests/fuzz/regress/$name; do
		[ -d "$d" ] && cp -p "$d"/* "$corpus"/ 2>/dev/null
	done
	dict=
	[ -f "tests/fuzz/$name.dict" ] && dict=-dict=tests/fuzz/$name.dict
	opts=
	[ -f "tests/fuzz/$name.options" ] && opts=$(cat "tests/fuzz/$name.options")
	# -timeout: one input taking longer is a hang (a failure);
	# -rss_limit_mb: a memory blow-up is a failure too.
	"$bin" -max_total_time="$FUZZ_SECONDS" -timeout=20 -rss_limit_mb=2048 \
		-print_final_stats=1 -artifact_prefix="$crash/" $dict $opts \
		${FUZZ_ARGS:-} "$corpus" >"$log" 2>&1
	rc=$?
	done_line=$(grep -E '^#[0-9]+[[:space:]]+DONE' "$log" | tail -1)
	execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
	rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
	cov=$(echo "$done_line" | sed -n 's/.*cov: \([0-9]*\).*/\1/p')
	ft=$(echo "$done_line" | sed -n 's/.* ft: \([0-9]*\).*/\1/p')
	figures="${execs:-?} execs, ${rate:-?} exec/s, cov ${cov:-?}, ft ${ft:-?}, ${FUZZ_SECONDS} s"
	if [ "$rc" -eq 0 ] && [ -n "$done_line" ]; then
		echo "$name: ok ($figures)"
		continue
	fi
	failed=1
	repro=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$log" | tail -1)
	echo "$name: FAILED (exit $rc; $figures)"
	grep -E 'ERROR: |runtime error: |SUMMARY: ' "$log" | head -5 | sed 's/^/  /'
	if [ -n "$repro" ]; then
		echo "  reproducer: $repro"
		echo "  replay: $bin $repro"
	fi
	echo "  log: $log"
done
exit $failed
