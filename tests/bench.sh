#!/bin/sh
# bench.sh - make bench: performance figures of the whole system on
# galil-sim, printed as a table and written as CSV to $BUILD/bench.csv.
# Figures, not pass/fail (see tests/bench/bench_sys.c for what is measured).
#
# The Makefile's bench target has built the libraries, the binaries and the
# tests; this script compiles the bench program with the project's flags
# (the Makefile's object rule), links it, builds the LD_PRELOAD allocation
# counter, and runs it. The loops run at 50, 10 and 2 ms in both designs of
# getting the controller's record (controller.record: poll and stream,
# docs/link.md), printed side by side.
# Knobs: ROBOELF_BENCH_S (seconds of joystick use per period and design,
# default 20), ROBOELF_BENCH_REPEAT (runs of each fault, default 5),
# ROBOELF_BENCH_LONG_S (the long run: the stream design at 2 ms for this many
# seconds, no request waited for in the cycle; the target is zero overruns
# and no trip; default 600 in the part under chrt -f 50, i.e. as root or
# with an rtprio limit, and 0 elsewhere; 0 = skip; where chrt is refused, a
# value given runs it without SCHED_FIFO), ROBOELF_BENCH_HOST_S (the host
# self-test's seconds, default 10), ROBOELF_BENCH_ONLY=instr (only the user
# instructions per cycle of both designs, under valgrind's callgrind;
# ROBOELF_SYS_CAL=FILE reuses a calibration).
set -eu
BUILD=${BUILD:-build}
CC=${CC:-cc}
TOP=$(cd "$(dirname "$0")/.." && pwd)
cd "$TOP"
ROBOELF_TOP=$TOP
ROBOELF_BIN=$TOP/$BUILD/bin
export BUILD ROBOELF_TOP ROBOELF_BIN

make --no-print-directory BUILD="$BUILD" "$BUILD/obj/tests/bench/bench_sys.o"
mkdir -p "$BUILD/bench"
# shellcheck disable=SC2046
$CC -o "$BUILD/bench/bench_sys" "$BUILD/obj/tests/bench/bench_sys.o" \
	"$BUILD/lib/libharness.a" "$BUILD/lib/libre.a" "$BUILD/lib/libsuper.a" \
	$(ls "$BUILD/lib/libdmc.a" 2>/dev/null) "$BUILD/lib/libgl.a" \
	$(ls "$BUILD/lib/libbase.a" 2>/dev/null) \
	$(pkg-config --libs libserialport yaml-0.1) -lpthread -lm
$CC -O2 -Wall -Wextra -shared -fPIC -o "$BUILD/bench/alloc_count.so" \
	tests/bench/alloc_count.c -ldl

# The long run goes where SCHED_FIFO is (below); without it, only when asked.
RT=0
chrt -f 50 true 2>/dev/null && RT=1
LONG_PLAIN=0
[ "$RT" = 1 ] || LONG_PLAIN=${ROBOELF_BENCH_LONG_S:-0}

if [ -n "${ROBOELF_BENCH_ONLY:-}" ]; then
	exec "$BUILD/bench/bench_sys" --csv "$BUILD/bench.csv" \
		--seconds "${ROBOELF_BENCH_S:-20}" --only "$ROBOELF_BENCH_ONLY"
fi
"$BUILD/bench/bench_sys" --csv "$BUILD/bench.csv" \
	--seconds "${ROBOELF_BENCH_S:-20}" \
	--repeat "${ROBOELF_BENCH_REPEAT:-5}" --long "$LONG_PLAIN" \
	--alloc-lib "$TOP/$BUILD/bench/alloc_count.so" \
	--faults-bin "$TOP/$BUILD/tests/system/test_sys_faults"

# The host latency self-test (roboelf-tech check-host): this machine's wake-up
# lateness under the configured real-time set-up and the shortest safe period.
echo
echo "bench: host self-test (roboelf-tech check-host ${ROBOELF_BENCH_HOST_S:-10})"
"$BUILD/bin/roboelf-tech" check-host "${ROBOELF_BENCH_HOST_S:-10}" \
	-c config/roboelf.yaml || true

# The loops again with real-time scheduling (SCHED_FIFO 50, inherited by
# galil-sim and roboelf), where this user may use it: the 2 ms period needs
# it on an ordinary Linux (docs/supervisor.md). The fault matrix is not
# repeated (--faults-bin true). Then the long run of the stream design at
# 2 ms (ROBOELF_BENCH_LONG_S, default 600 s: ten minutes).
if [ "$RT" = 1 ]; then
	echo
	echo "bench: the loops again under real-time scheduling (chrt -f 50)"
	chrt -f 50 "$BUILD/bench/bench_sys" --csv "$BUILD/bench-rt.csv" \
		--seconds "${ROBOELF_BENCH_S:-20}" --repeat 1 \
		--long "${ROBOELF_BENCH_LONG_S:-600}" \
		--alloc-lib "$TOP/$BUILD/bench/alloc_count.so" \
		--faults-bin true
else
	echo "bench: real-time scheduling not permitted here (chrt -f 50):" \
		"no SCHED_FIFO figures"
fi
