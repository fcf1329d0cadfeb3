#!/usr/bin/env bash
# demo.sh - the whole RoboELF system on the simulator (run by `make demo`).
#
# Starts galil-sim with the default robot, checks and downloads dmc/ with
# galil-load, runs roboelf against it through the virtual relay (full
# calibration, "RoboELF Ready for Use"), then drives a scripted joystick tour
# through the simulator's control port: each axis forward and back, a brief
# invalid switch state that must not trip, and finally a potentiometer fault
# that must trip the E-stop. Every process it starts is stopped on exit,
# whatever happens.
#
# INTERACTIVE=1: no script; drive the joysticks and inject faults from the
# keyboard (keys shown on start).
set -u
BUILD=${BUILD:-build}
BIN=${ROBOELF_BIN:-$BUILD/bin}
TOP=$(cd "$(dirname "$0")/.." && pwd)
cd "$TOP" || exit 1
TMP=$(mktemp -d /tmp/roboelf-demo.XXXXXX)
SIM_PID=""; RE_PID=""

cleanup() {
	[ -n "$RE_PID" ] && kill -TERM "$RE_PID" 2>/dev/null && wait "$RE_PID" 2>/dev/null
	[ -n "$SIM_PID" ] && kill -TERM "$SIM_PID" 2>/dev/null && wait "$SIM_PID" 2>/dev/null
	rm -rf "$TMP"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

say() { printf '\n\033[1mdemo: %s\033[0m\n' "$*" >&2; }
die() { say "FAILED: $*"; exit 1; }

# wait_line FILE PATTERN SECONDS - wait until FILE has a line matching PATTERN.
wait_line() {
	local end=$(( $(date +%s) + $3 ))
	while ! grep -q -- "$2" "$1" 2>/dev/null; do
		[ "$(date +%s)" -ge "$end" ] && return 1
		sleep 0.1
	done
}

# ctl REQUEST - one request on the simulator's control port; prints the answer.
ctl() {
	local ans
	exec 5<>"/dev/tcp/127.0.0.1/$CPORT" || die "control port $CPORT unreachable"
	printf '%s\n' "$1" >&5
	IFS= read -r -t 5 ans <&5
	exec 5>&-
	printf '%s\n' "$ans"
}

say "starting galil-sim (default robot)"
"$BIN/galil-sim" --port 0 --control-port 0 --relay-link "$TMP/relay" \
	>"$TMP/sim.out" 2>"$TMP/sim.err" &
SIM_PID=$!
wait_line "$TMP/sim.out" '^galil-sim: listening' 10 || die "galil-sim did not start: $(cat "$TMP/sim.err")"
read -r _ _ _ addr _ CPORT _ RELAY <"$TMP/sim.out"
say "galil-sim at $addr, control port $CPORT, relay $RELAY"

say "checking and downloading dmc/ with galil-load"
"$BIN/galil-load" -a "$addr" --start dmc/ || die "galil-load failed"

if [ "${INTERACTIVE:-}" = 1 ]; then
	exec 3</dev/tty
	say "keys: a/z axis A fwd/rev, s/x B, d/c C, space neutral, i invalid (one channel),"
	say "      p pot fault B, e encoder stuck A, j jam C, r relay unplug, q quit"
fi

say "starting roboelf (full calibration)"
"$BIN/roboelf" -c config/roboelf.yaml --galil "$addr" --relay "$TMP/relay" \
	--calibration full --log "$TMP/roboelf.log" </dev/null | tee "$TMP/roboelf.out" &
RE_PID=$(jobs -p | tail -n 1)
wait_line "$TMP/roboelf.out" 'RoboELF Ready for Use' 60 || die "roboelf did not become ready"

if [ "${INTERACTIVE:-}" = 1 ]; then
	while IFS= read -r -s -n 1 key <&3; do
		case "$key" in
		a) ctl "joy A fwd" ;; z) ctl "joy A rev" ;;
		s) ctl "joy B fwd" ;; x) ctl "joy B rev" ;;
		d) ctl "joy C fwd" ;; c) ctl "joy C rev" ;;
		" ") for ax in A B C; do ctl "joy $ax neutral"; done ;;
		i) ctl "joy A fwd a" ;;
		p) ctl "pot B offset 0.5" ;; e) ctl "enc A stuck" ;;
		j) ctl "block C 1" ;; r) ctl "relayfault unplug" ;;
		q) break ;;
		esac >/dev/null
	done
	exit 0
fi

tour() { # tour AXIS DIR SECONDS
	say "joystick: axis $1 $2 for $3 s"
	ctl "joy $1 $2" >/dev/null
	sleep "$3"
	ctl "joy $1 neutral" >/dev/null
	sleep 0.5
}
for ax in A B C; do
	tour "$ax" fwd 2
	tour "$ax" rev 2
done
say "joystick: axis B, only channel a closed for 0.2 s (a transient invalid state: must not trip)"
ctl "joy B fwd a" >/dev/null; sleep 0.2; ctl "joy B neutral" >/dev/null; sleep 1
grep -q '^FAULT' "$TMP/roboelf.out" && die "a transient invalid state tripped the system"

say "injecting a potentiometer fault on axis B (offset +0.5 V): the E-stop must trip"
ctl "joy B fwd" >/dev/null
ctl "pot B offset 0.5" >/dev/null
wait_line "$TMP/roboelf.out" '^FAULT ENCODER' 5 || die "the potentiometer fault did not trip"
[ "$(ctl relay)" = off ] || die "the relay is still on after the fault"
say "relay: $(ctl relay); fault line: $(grep -m1 '^FAULT' "$TMP/roboelf.out")"
sleep 2
say "demo finished: stopping roboelf and galil-sim"
exit 0
