#!/bin/sh
# realtime.sh - roboelf's real-time set-up seen from outside.
#   1. As root (CI): `roboelf-tech check-host 1` reports SCHED_FIFO 50 in force
#      (read back from the kernel), wake-up figures and a verdict, exit 0.
#   2. Without the right (user 65534 via setpriv, RLIMIT_RTPRIO 0): a 5 ms
#      period is refused with exit 2 and the message naming what to do,
#      before any relay or controller is touched; at 50 ms the refusal is a
#      logged WARN and roboelf goes on (it then stops at the relay: exit 3).
# Not root: nothing can be dropped; the check says so and fails.
set -u
BIN=${ROBOELF_BIN:-build/bin}
fails=0
fail() { echo "realtime.sh: FAIL: $*"; fails=$((fails + 1)); }
if [ "$(id -u)" != 0 ]; then
	echo "realtime.sh: FAIL: needs root (CI runs as root) to compare granted and refused"
	exit 1
fi
command -v setpriv >/dev/null || { echo "realtime.sh: FAIL: setpriv (util-linux) missing"; exit 1; }
T=$(mktemp -d "${TMPDIR:-/tmp}/rt-check.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT
chmod 755 "$T"
cp "$BIN/roboelf" "$T/roboelf"
cp "$BIN/roboelf-tech" "$T/roboelf-tech"
cp config/roboelf.yaml "$T/roboelf.yaml"
mkdir "$T/w" && chmod 777 "$T/w"

# 1. granted
out=$("$T/roboelf-tech" check-host 1 -c "$T/roboelf.yaml" 2>&1); rc=$?
first=$(echo "$out" | head -1)
case "$first" in
"host check: SCHED_FIFO 50, memory locked, not pinned" | \
"host check: SCHED_FIFO 50, memory not locked (AddressSanitizer build), not pinned") ;;
*) fail "check-host first line: '$first'" ;;
esac
[ "$rc" = 0 ] || fail "check-host exit $rc, not 0: $out"
echo "$out" | grep -q "^host check: [0-9]* wake-ups, late p50 " || fail "no wake-up figures: $out"
echo "$out" | grep -q "^host check: shortest safe period on this host: .* the configured 50 ms ($T/roboelf.yaml) is safe$" ||
	fail "no verdict line: $out"
echo "$out" | sed 's/^/  /'

# 2. refused
drop() { setpriv --reuid=65534 --regid=65534 --clear-groups -- sh -c 'ulimit -r 0; exec "$@"' sh "$@"; }
err=$(cd "$T/w" && drop "$T/roboelf" -c "$T/roboelf.yaml" --period 5 --calibration file \
	--log "$T/w/r5.log" 2>&1 </dev/null); rc=$?
want="roboelf: error: a 5 ms period needs real-time scheduling, and this host gave normal scheduling (SCHED_FIFO refused: Operation not permitted), memory not locked (Cannot allocate memory), not pinned: run as root or give roboelf CAP_SYS_NICE (docs/supervisor.md, \"Real time\"), or use a period of 10 ms or more"
want2=$(echo "$want" | sed 's/memory not locked (Cannot allocate memory)/memory locked (current pages only)/')
want3=$(echo "$want" | sed 's/memory not locked (Cannot allocate memory)/memory not locked (AddressSanitizer build)/')
[ "$rc" = 2 ] || fail "5 ms without real time: exit $rc, not 2"
echo "$err" | grep -qxF -e "$want" -e "$want2" -e "$want3" || fail "5 ms without real time said: $err"
grep -q " WARN real time: normal scheduling (SCHED_FIFO refused: Operation not permitted)" "$T/w/r5.log" ||
	fail "no WARN in the log: $(cat "$T/w/r5.log")"
echo "  refused at 5 ms (exit $rc): $err"

out=$(cd "$T/w" && drop "$T/roboelf" -c "$T/roboelf.yaml" --calibration file \
	--relay "$T/w/no-relay" --log "$T/w/r50.log" 2>&1 </dev/null); rc=$?
echo "$out" | grep -q "^roboelf: note: real time: normal scheduling (SCHED_FIFO refused: Operation not permitted).*; periods under 10 ms are refused$" ||
	fail "50 ms without real time: no note: $out"
[ "$rc" = 3 ] || fail "50 ms without real time: exit $rc, not 3 (the relay is missing)"
echo "  50 ms without real time: noted, went on to the relay (exit $rc)"
[ "$fails" = 0 ] && echo "realtime.sh: ok" && exit 0
exit 1
