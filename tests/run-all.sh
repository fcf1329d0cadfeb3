#!/bin/sh
# run-all.sh - run every test binary under $BUILD/tests, then the script checks
# in tests/checks/*.sh. Each cmocka binary prints its own summary; this script
# ends with one line "N passed, N failed, N skipped" counting test programs.
# With arguments (e.g. "net"), only those test directories run, no checks.
#
# Independent programs run side by side (ROBOELF_JOBS at once, default the
# number of CPUs): the unit, loader, simulator and DMC tests (in-process or
# in virtual time) and the checks that judge files. The real-time ones run
# once the others are done: the system tests and the console in tmux
# ROBOELF_RT_JOBS at once (default 2, the longest of the last run first),
# then alone, one after another, the network rig, the unit and simulator
# tests that time real waits, and the checks that time a host or install
# and drive roboelf in real time (realtime.sh, install.sh). Each
# program's log is printed whole, in the order of the list, never
# interleaved.
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
if [ "${1:-}" != --one ]; then # a child (--one) has all this from its parent
	ROBOELF_TOP=$(cd "$(dirname "$0")/.." && pwd)
	ROBOELF_BIN=$ROBOELF_TOP/$BUILD/bin
	export BUILD ROBOELF_BIN ROBOELF_TOP
	cd "$ROBOELF_TOP" || exit 1
	sh tools/cmdtable.sh path "$ROBOELF_TOP/$BUILD/cmdpath" || exit 1
	ROBOELF_SYSPATH=$PATH
	PATH=$ROBOELF_TOP/$BUILD/cmdpath
	export PATH ROBOELF_SYSPATH
fi
LOGDIR=$BUILD/test-logs
mkdir -p "$LOGDIR"
# The system tests of one run share one full calibration per configuration
# (tests/harness/sys_h.h, sys_env_calibrate()): a fresh directory each run.
if [ "${1:-}" != --one ] && [ -z "${ROBOELF_SYS_CAL_SHARE:-}" ]; then
	ROBOELF_SYS_CAL_SHARE=$ROBOELF_TOP/$LOGDIR/calibration-share
	rm -rf "$ROBOELF_SYS_CAL_SHARE" && mkdir "$ROBOELF_SYS_CAL_SHARE" || exit 1
	export ROBOELF_SYS_CAL_SHARE
fi
# Per-program deadline (s): a hung test fails with exit 124 instead of hanging
# the run; system tests get more, and so does the fuzz check, which builds
# its targets first (ROBOELF_TEST_TIMEOUT overrides both).
deadline() {
	case $1 in
	system/* | net/* | checks/fuzz_short.sh | checks/stream_suite.sh) echo "${ROBOELF_TEST_TIMEOUT:-600}" ;;
	*) echo "${ROBOELF_TEST_TIMEOUT:-180}" ;;
	esac
}
# The real-time programs: after the others. The system tests and the
# console in tmux run a few at a time (ROBOELF_RT_JOBS, default 2): each is
# one roboelf and one galil-sim mostly waiting on real time (about 6 % of one
# core, measured), so two of them on 2 cores do not delay each other's
# cycle; the rest (the network rig, the host's timing) run alone.
few() {
	case $1 in
	system/* | checks/console_tmux.sh | checks/stream_suite.sh) return 0 ;;
	*) return 1 ;;
	esac
}
alone() {
	case $1 in
	net/* | checks/realtime.sh | checks/install.sh) return 0 ;;
	# unit and simulator tests that time real waits (the relay's and the
	# link's deadlines, the clock, the real-time set-up, the ports)
	unit/test_re_relay* | unit/test_gl_link | unit/test_base_clock | unit/test_re_rt | \
		unit/test_re_io | sim/test_sim_net | sim/test_sim_relay | sim/test_sim_speed | \
		sim/test_sim_stream | sim/test_gl_link_udp) return 0 ;;
	*) return 1 ;;
	esac
}
logof() { echo "$LOGDIR/$(echo "$1" | tr / _).log"; }
# The command of NAME: a cmocka binary, or a check script in its shell.
cmdof() {
	case $1 in
	checks/*)
		s=tests/$1
		if head -1 "$s" | grep -q bash; then echo "bash $s"; else echo "sh $s"; fi ;;
	*) echo "$BUILD/tests/$1" ;;
	esac
}
# exec1 NAME: run it into its log; its verdict line into NAME's .res file
# ("ok", "SKIPPED (...)" or "FAILED (...)"; then the exit status, seconds).
exec1() {
	name=$1; log=$(logof "$name")
	start=$(date +%s)
	# Each program its own lock directory (re_lock.h): programs run side
	# by side, and a relay's pty number freed by one (galil-sim's
	# "relayfault unplug" closes it while that roboelf still holds the
	# relay's lock, as it must) is handed to another's galil-sim at once.
	locks=$(mktemp -d "${TMPDIR:-/tmp}/roboelf-locks.XXXXXX") || locks=
	# shellcheck disable=SC2046 # the command's words
	ROBOELF_LOCK_DIR=${ROBOELF_LOCK_DIR:-$locks} \
		timeout --kill-after=10 "$(deadline "$name")" $(cmdof "$name") >"$log" 2>&1
	rc=$?
	[ -n "$locks" ] && rm -rf "$locks"
	res=ok
	if [ "$rc" -eq 77 ]; then
		res="SKIPPED ($(grep -m1 '^SKIP' "$log"))"
	elif [ "$rc" -eq 124 ] || [ "$rc" -eq 137 ]; then
		res="FAILED (timed out after $(deadline "$name") s)"
	elif [ "$rc" -ne 0 ]; then
		res="FAILED (exit $rc)"
	elif grep -qE '^\[  (FAILED|ERROR)   ?\]' "$log"; then
		res="FAILED (cmocka reported a failure)"
	else
		case $name in
		checks/*) ;;
		*) grep -q '^\[  PASSED  \]' "$log" || res="FAILED (no cmocka summary)" ;;
		esac
		[ "$res" = ok ] && grep -q '^\[  PASSED  \] 0 test' "$log" && res="FAILED (no test ran)"
	fi
	printf '%s\n%s\n%s\n' "$res" "$rc" "$(( $(date +%s) - start ))" >"$log.res"
}
if [ "${1:-}" = --one ]; then # a child of the side-by-side run
	exec1 "$2"
	exit 0
fi
passed=0; failed=0; skipped=0; failures=""
# report NAME: its log and verdict, and the counts
report() {
	name=$1; log=$(logof "$name")
	echo "=== $name"
	cat "$log"
	{ read -r res; read -r rc; read -r secs; } <"$log.res"
	if [ "$res" = ok ]; then
		passed=$((passed + 1))
	elif [ "$rc" -eq 77 ] && [ "${ROBOELF_NO_SKIP:-0}" != 1 ]; then
		skipped=$((skipped + 1))
	else
		failed=$((failed + 1)); failures="$failures $name"
	fi
	echo "=== $name: $res ($secs s)"
}
list=""; once=""
dirs=${*:-unit load sim dmc system net}
for dir in $dirs; do
	for t in "$BUILD/tests/$dir"/test_*; do
		[ -x "$t" ] && list="$list $dir/$(basename "$t")"
	done
done
# Under the sanitizers (make asan: ROBOELF_SAN=1) the checks that only read
# files, or build and run programs of their own (the package, the fuzz
# targets, which make check already runs under ASan), would repeat make
# check's run exactly: they run there once. Every test program and every
# check that runs the sanitized programs runs in both.
once_only() {
	case $1 in
	commands* | contracts* | deb.sh | docs* | fuzz_short.sh | have_deps.sh | includes.sh | layers* | modtests.sh | nodisc.sh | quotes.sh | safety_trace.sh) return 0 ;;
	*) return 1 ;;
	esac
}
if [ $# -eq 0 ]; then
	for s in tests/checks/*.sh; do
		[ -f "$s" ] || continue
		if [ "${ROBOELF_SAN:-0}" = 1 ] && once_only "$(basename "$s")"; then
			once="$once $(basename "$s")"
			continue
		fi
		list="$list checks/$(basename "$s")"
	done
fi
jobs=${ROBOELF_JOBS:-$(nproc)}
rtjobs=${ROBOELF_RT_JOBS:-2}
# secsof NAME: its time in the last run (for the order), 9999 if unknown
secsof() {
	f="$(logof "$1").res"
	if [ -f "$f" ]; then sed -n 3p "$f"; else echo 9999; fi
}
pool=""; rt=""; rtfew=""
for n in $list; do
	if few "$n"; then rtfew="$rtfew $(secsof "$n"):$n"
	elif alone "$n"; then rt="$rt $n"; else pool="$pool $(secsof "$n"):$n"; fi
	rm -f "$(logof "$n").res"
done
# longest_first SECS:NAME...: the names, the longest of the last run first
# (unknown ones first, by name), so that the last to finish is a short one
longest_first() {
	printf '%s\n' "$@" | sort -t: -k1,1nr -k2,2 | cut -d: -f2-
}
# shellcheck disable=SC2086 # one entry per word
rtfew=$(longest_first $rtfew)
# shellcheck disable=SC2086 # one entry per word
pool=$(longest_first $pool)
t0=$(date +%s)
# shellcheck disable=SC2086 # one name per word
[ -n "$pool" ] && printf '%s\n' $pool | xargs -P "$jobs" -n 1 sh "$ROBOELF_TOP/tests/run-all.sh" --one
for n in $pool; do report "$n"; done
echo "=== side by side ($jobs at once): $(echo $pool | wc -w) programs in $(( $(date +%s) - t0 )) s"
t0=$(date +%s)
# shellcheck disable=SC2086 # one name per word
[ -n "$rtfew" ] && printf '%s\n' $rtfew | xargs -P "$rtjobs" -n 1 sh "$ROBOELF_TOP/tests/run-all.sh" --one
for n in $rtfew; do report "$n"; done
[ -n "$rtfew" ] && echo "=== real time, $rtjobs at once: $(echo $rtfew | wc -w) programs in $(( $(date +%s) - t0 )) s"
for n in $rt; do
	echo "=== $n (alone)"
	exec1 "$n"
	report "$n"
done
[ -n "$once" ] && echo "run once, in make check (they do not run the sanitized programs):$once"
[ -n "$failures" ] && echo "failed:$failures"
echo "$passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
