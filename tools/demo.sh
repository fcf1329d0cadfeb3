#!/usr/bin/env bash
# demo.sh - the whole RoboELF system on the simulator (run by `make demo`).
#
# Starts galil-sim with the default robot, checks and downloads dmc/ with
# galil-load, runs roboelf against it through the virtual relay (full
# calibration, "RoboELF Ready for Use"), then drives a scripted joystick tour
# through the simulator's control port: each axis forward and back, a brief
# invalid switch state that must not trip, and finally a potentiometer fault
# that must trip the E-stop. It ends by naming the flight recorder's trace
# of that fault (kept in $BUILD/demo/; installed: ./roboelf-demo/) and the PNG
# pages roboelf-tech show-trace drew from it, and the directory .../run-<time>
# where roboelf ran (its log, calibration file and output). roboelf's board
# keeps to the bottom of the terminal; this narration scrolls above it.
# roboelf is stopped by a SIGTERM to itself (an orderly quit), every other
# process it starts by its process group; on exit, whatever happens.
#
# INTERACTIVE=1: no script; drive the joysticks and inject faults from the
# keyboard (keys shown on start, each one says what it did); q quits
# roboelf, s or f starts it again, Q ends the demo.
set -u
set -m # each background job in its own process group, stopped as a group
BUILD=${BUILD:-build}
HERE=$(cd "$(dirname "$0")" && pwd) || exit 1
if [ -f "$HERE/../dmc/MANIFEST" ]; then
	# the source tree (tools/demo.sh, make demo): its programs and dmc/,
	# the demo's files in $BUILD/demo
	TOP=$(cd "$HERE/.." && pwd)
	cd "$TOP" || exit 1
	BIN=$(cd "${ROBOELF_BIN:-$BUILD/bin}" && pwd) || exit 1
	OUTBASE=$TOP/$BUILD/demo
else
	# installed (package roboelf-sim: /usr/share/roboelf/demo.sh): the
	# data directory holds dmc/ and config/, the programs are on PATH, the
	# demo's files go to ./roboelf-demo
	TOP=$HERE
	BIN=${ROBOELF_BIN:-$(dirname "$(command -v galil-sim || echo /usr/bin/galil-sim)")}
	OUTBASE=$PWD/roboelf-demo
fi
# ROBOELF_DEMO_CONFIG=FILE: roboelf and galil-load use FILE, and roboelf's
# log, traces and calibration file go where FILE says (the package test:
# /var/log/roboelf, /var/lib/roboelf); by default the development
# configuration, with the log and the calibration file in the run's directory
CONFIG=${ROBOELF_DEMO_CONFIG:-$TOP/config/roboelf.yaml}
TMP=$(mktemp -d /tmp/roboelf-demo.XXXXXX)
SIM_PID=""; RE_PID=""

stop() { # stop PID: SIGTERM to its process group, SIGKILL after 5 s
	local i
	kill -TERM -- "-$1" 2>/dev/null || return 0
	for i in $(seq 50); do
		kill -0 "$1" 2>/dev/null || break
		sleep 0.1
	done
	kill -KILL -- "-$1" 2>/dev/null
	wait "$1" 2>/dev/null
}
cleanup() {
	[ -n "$RE_PID" ] && stop_roboelf
	[ -n "$SIM_PID" ] && stop "$SIM_PID"
	rm -rf "$TMP"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

tty_size() { # prints "ROWS COLS" of this terminal, or "24 80"
	local size
	size=$(stty size 2>/dev/null </dev/tty)
	case "$size" in [1-9]*\ [1-9]*) echo "$size" ;; *) echo "24 80" ;; esac
}
# say TEXT: one narration line, wrapped at word boundaries to this
# terminal's width (continuation lines indented by two spaces) so that
# the terminal never cuts or wraps it by itself; a word wider than the
# terminal (a path) whole on a line of its own, so that it can be copied.
# Written in one piece, so that roboelf's board is not drawn inside it.
say() {
	local size text
	size=$(tty_size)
	text=$(printf '%s\n' "demo: $*" | awk -v w="$(( ${size#* } - 1 ))" '
	function out(s) { printf "\033[1m%s\033[0m\n", s }
	{
		line = ""
		for (i = 1; i <= NF; i++) {
			if (line != "" && length(line) + 1 + length($i) <= w) {
				line = line " " $i; continue
			}
			if (line != "") out(line)
			line = (length($i) + 2 <= w && i > 1) ? "  " $i : $i
		}
		if (line != "") out(line)
	}')
	printf '\n%s\n' "$text" >&2
}
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

# latch AXIS DIR: a key holds a joystick (both switches) until space
latch() {
	ctl "joy $1 $2" >/dev/null
	say "key $key: joystick $1 $2 LATCHED (stays pressed until space); another joystick as well is two commands: an INPUT fault"
}
# inject KEY REQUEST WHAT: a fault injected in galil-sim
inject() {
	ctl "$2" >/dev/null
	say "key $1: injected: $3"
}

say "starting galil-sim (default robot)"
"$BIN/galil-sim" --port 0 --control-port 0 --relay-link "$TMP/relay" \
	>"$TMP/sim.out" 2>"$TMP/sim.err" &
SIM_PID=$!
wait_line "$TMP/sim.out" '^galil-sim: listening' 10 || die "galil-sim did not start: $(cat "$TMP/sim.err")"
read -r _ _ _ addr _ CPORT _ RELAY <"$TMP/sim.out"
say "galil-sim at $addr, control port $CPORT, relay $RELAY"

say "checking and downloading dmc/ with galil-load"
"$BIN/galil-load" -a "$addr" --config "$CONFIG" --start "$TOP/dmc/" || die "galil-load failed"

if [ "${INTERACTIVE:-}" = 1 ]; then
	exec 3</dev/tty
	say "keys (read once roboelf is ready; anything typed before is dropped):"
	say "  a/z axis A fwd/rev, s/x B, d/c C: the joystick STAYS pressed until space"
	say "  space: every joystick neutral; i: A fwd on one channel only (invalid:"
	say "  held 0.5 s it is an INPUT fault); p pot fault B, e encoder stuck A,"
	say "  j jam C, r relay unplug; q quits roboelf (then s or f starts it again), Q ends the demo"
fi

# roboelf runs on a pseudo-terminal made by script(1), so that it shows its
# live status board here (on the bottom lines; this narration scrolls
# above it) while its output is also kept in a file to watch. It runs in
# $RUN: the calibration table and the log stay there after the demo.
# Its input is /dev/null, not that pseudo-terminal: the keys are the
# demo's, none reaches roboelf, and its board says so ("no keyboard
# here") instead of offering keys that would do nothing.
# script(1) gives its pseudo-terminal the size of its standard input, which
# is /dev/null here (the keys are the demo's): without the stty below
# roboelf would lay its board out for 80x24 whatever this terminal's size,
# in the middle of a taller one, over the narration.
start_roboelf() { # start_roboelf full|file
	local size
	size=$(tty_size)
	(cd "$RUN" && exec script -qfec "stty rows ${size% *} cols ${size#* }; \
		exec '$BIN/roboelf' -c '$CONFIG' \
		--galil '$addr' --relay '$TMP/relay' --calibration $1 $LOGOPT </dev/null" \
		"$RUN/roboelf.out" </dev/null) &
	RE_PID=$!
}
# child_of PID: PID's first child (roboelf is script's child); the kernel
# lists a process's children in /proc, so no ps is needed. The list ends
# without a newline, so read fails at its end though it read the pid:
# the pid is tested, not read's status (else roboelf was never found, and
# got its SIGTERM only with script's, 10 s later, its last words lost)
child_of() {
	local c=""
	read -r c _ <"/proc/$1/task/$1/children" 2>/dev/null
	[ -n "$c" ] && echo "$c"
}
# resize_roboelf: this terminal was resized: so is roboelf's (its board is
# redrawn for the new size on the SIGWINCH that stty makes the kernel send)
resize_roboelf() {
	local pid pts size
	[ -n "$RE_PID" ] || return 0
	pid=$(child_of "$RE_PID")
	[ -n "$pid" ] || return 0
	pts=$(readlink "/proc/$pid/fd/1" 2>/dev/null) || return 0
	size=$(tty_size)
	stty -F "$pts" rows "${size% *}" cols "${size#* }" 2>/dev/null
}
trap resize_roboelf WINCH
# stop_roboelf: SIGTERM to roboelf itself (the child of script), which
# quits in order and ends script quietly; the group only if it hangs.
stop_roboelf() {
	local pid i
	[ -n "$RE_PID" ] || return 0
	pid=$(child_of "$RE_PID")
	[ -n "$pid" ] && kill -TERM "$pid" 2>/dev/null
	for i in $(seq 100); do
		kill -0 "$RE_PID" 2>/dev/null || break
		sleep 0.1
	done
	kill -0 "$RE_PID" 2>/dev/null && stop "$RE_PID"
	wait "$RE_PID" 2>/dev/null
	RE_PID=""
}
RUN="$OUTBASE/run-$(date +%Y%m%d-%H%M%S)"
mkdir -p "$RUN" || die "cannot make $RUN"
if [ -n "${ROBOELF_DEMO_CONFIG:-}" ]; then
	LOG=$("$BIN/roboelf-tech" --print log.path -c "$CONFIG") || die "cannot read log.path of $CONFIG"
	LOGOPT=""
	KEPT="the places $CONFIG names (log: $LOG)"
	say "starting roboelf (full calibration); its log, traces and calibration file go where $CONFIG says (log: $LOG)"
else
	LOG=$RUN/roboelf.log
	LOGOPT="--log '$LOG'"
	KEPT=$RUN
	say "starting roboelf (full calibration); its log and calibration file go to $RUN"
fi
start_roboelf full
wait_line "$RUN/roboelf.out" 'RoboELF Ready for Use' 60 || die "roboelf did not become ready"

if [ "${INTERACTIVE:-}" = 1 ]; then
	# keys typed during start-up and calibration must not move the robot
	# once it is armed: drop them
	while IFS= read -r -s -n 1 -t 0.01 _ <&3; do :; done
	say "keys are read now (a/z s/x d/c joysticks, space release, i p e j r faults, q quit roboelf)"
	# bash runs a trap only between commands: a read that waits for a
	# key would hold a resize (resize_roboelf) back until the next key
	while :; do
		IFS= read -r -s -n 1 -t 0.2 key <&3
		rc=$?
		[ "$rc" -gt 128 ] && continue # no key within 0.2 s
		[ "$rc" -ne 0 ] && break      # end of input
		if [ -z "$RE_PID" ]; then
			case "$key" in
			s|f) how=file; [ "$key" = f ] && how=full
			   say "key $key: starting roboelf again (calibration: $how)"
			   start_roboelf "$how"
			   wait_line "$RUN/roboelf.out" 'RoboELF Ready for Use' 90 ||
				say "roboelf did not become ready (see its messages above; after an encoder fault the file no longer fits: f): s, f or Q"
			   # keys typed while it started are dropped
			   while IFS= read -r -s -n 1 -t 0.01 _ <&3; do :; done ;;
			Q) break ;;
			*) say "roboelf is not running: s starts it again (calibration from the file), f with a full calibration, Q ends the demo" ;;
			esac
			continue
		fi
		case "$key" in
		a) latch A fwd ;; z) latch A rev ;;
		s) latch B fwd ;; x) latch B rev ;;
		d) latch C fwd ;; c) latch C rev ;;
		" ") for ax in A B C; do ctl "joy $ax neutral" >/dev/null; done
		     say "key space: every joystick RELEASED (neutral)" ;;
		i) ctl "joy A fwd a" >/dev/null
		   say "key i: axis A fwd switch a only: LATCHED (an invalid state: held 0.5 s it is an INPUT fault; space releases)" ;;
		p) inject p "pot B offset 0.5" "potentiometer B +0.5 V" ;;
		e) inject e "enc A stuck" "encoder A stuck" ;;
		j) inject j "block C 1" "axis C jammed" ;;
		r) inject r "relayfault unplug" "relay unplugged" ;;
		q) say "key q: quitting roboelf (as its own q does)"
		   stop_roboelf
		   for ax in A B C; do ctl "joy $ax neutral" >/dev/null; done
		   for req in "pot B ok" "enc A ok" "block C 0" "relayfault ok"; do
			ctl "$req" >/dev/null
		   done
		   say "roboelf stopped (every joystick released, injected faults cleared): s starts it again (calibration from the file), f with a full calibration, Q ends the demo" ;;
		Q) break ;;
		esac
	done
	stop_roboelf
	say "the log and the calibration file are kept in $KEPT"
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
grep -q 'FAULT [A-Z]*:' "$RUN/roboelf.out" && die "a transient invalid state tripped the system"

say "injecting a potentiometer fault on axis B (offset +0.5 V): the E-stop must trip"
ctl "joy B fwd" >/dev/null
ctl "pot B offset 0.5" >/dev/null
wait_line "$RUN/roboelf.out" 'FAULT ENCODER:' 5 || die "the potentiometer fault did not trip"
[ "$(ctl relay)" = off ] || die "the relay is still on after the fault"
# the FAULT line whole from the log (roboelf.out holds it as the board
# wrapped it for the screen: its first row only would be cut)
wait_line "$LOG" ' FAULT FAULT ENCODER:' 5 || die "the fault is not in the log"
fault=$(sed -n 's/^[^ ]* FAULT \(FAULT ENCODER: [^|]*[^| ]\) |.*/\1/p' "$LOG" | head -n 1)
say "relay: $(ctl relay); $fault"

# The flight recorder: the fault's trace is written
# recorder.after_fault_s (2 s) after the fault; kept in $BUILD/demo and drawn.
say "waiting for the flight recorder's trace of the fault (written 2 s after it)"
wait_line "$LOG" 'trace: .* written' 10 || die "no trace of the fault was written"
trace=$(sed -n 's/.* trace: \(.*\) written (.*/\1/p' "$LOG" | head -n 1)
OUT=$OUTBASE
mkdir -p "$OUT" && cp "$trace" "$OUT/" || die "cannot keep the trace in $OUT"
trace="$OUT/$(basename "$trace")"
"$BIN/roboelf-tech" show-trace "$trace" >"$TMP/show.out" 2>"$TMP/show.err" ||
	die "roboelf-tech show-trace failed: $(cat "$TMP/show.err")"
# said while roboelf's board still holds the bottom of the screen: once
# it ends, its fault panel stays there, and only one short line follows,
# so that the panel's first line stays on a 24-line screen
say "the fault's trace: $trace"
say "its plots: $(sed -n 's/^wrote //p' "$TMP/show.out" | tr '\n' ' ')"
if [ "$KEPT" = "$RUN" ]; then
	say "the log, the calibration file and roboelf's output are kept in $RUN"
else
	say "the log and the calibration file are kept in $KEPT; roboelf's output in $RUN"
fi
stop_roboelf
stop "$SIM_PID"; SIM_PID=""
say "demo finished: roboelf and galil-sim stopped"
exit 0
