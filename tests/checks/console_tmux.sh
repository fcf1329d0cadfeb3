#!/bin/bash
# console_tmux.sh - the operator's board in a real terminal (tmux), as an
# operator sees it: roboelf on galil-sim in a tmux pane of 80x24, 100x30
# and 200x60; a potentiometer fault injected; the pane read back with
# `tmux capture-pane -J` (wrapped lines joined, so a line that wrapped
# shows longer than the width):
#   - no line longer than the pane is wide, during the run and after the
#     fault;
#   - the board's header "RoboELF  mode" exactly once on the screen;
#   - the FAULT text and its recovery still on the screen 10 s after the
#     fault;
#   - after a resize to 80x24 mid-run: the same;
#   - a joystick held from before the start (80x24): the board and the
#     message say to release it, no "Ready" before, "Ready" after;
#   - a full calibration on the board (80x24): each axis's phase, bar and
#     time left; interrupted with Ctrl-C, which table is in force said
#     (none before the first calibration file, the file's one after).
# Every wait polls a condition with a deadline. Needs tmux (make deps).
set -u
cd "$(dirname "$0")/../.." || exit 1
BIN=${ROBOELF_BIN:-$PWD/${BUILD:-build}/bin}
command -v tmux >/dev/null || { echo "console_tmux: tmux missing (make deps)"; exit 1; }
tmp=$(mktemp -d) || exit 1
sock="$tmp/tmux.sock"
simpid=""
cleanup() {
	tmux -S "$sock" kill-server 2>/dev/null
	[ -n "$simpid" ] && kill "$simpid" 2>/dev/null
	[ -n "$simpid" ] && wait "$simpid" 2>/dev/null
	[ -n "${KEEP:-}" ] || rm -rf "$tmp"
}
trap cleanup EXIT
fail() { echo "console_tmux: FAIL: $*"; exit 1; }

# wait_for SECONDS COMMAND...: poll every 0.1 s until COMMAND succeeds
wait_for() {
	t=$(( $1 * 10 )); shift
	while [ "$t" -gt 0 ]; do
		"$@" && return 0
		sleep 0.1; t=$((t - 1))
	done
	return 1
}

"$BIN/galil-sim" --port 0 --control-port 0 --relay-link "$tmp/relay" \
	>"$tmp/sim.out" 2>"$tmp/sim.err" &
simpid=$!
wait_for 10 grep -qs "listening" "$tmp/sim.out" || fail "galil-sim did not start"
port=$(sed -n 's/.*127.0.0.1:\([0-9]*\) control.*/\1/p' "$tmp/sim.out")
ctl=$(sed -n 's/.* control \([0-9]*\) relay.*/\1/p' "$tmp/sim.out")
sed -e "s#port_development: .*#port_development: $tmp/relay#" \
    -e "s#icstation_state: .*#icstation_state: $tmp/ic.state#" \
    -e "s#^  file: .*#  file: $tmp/cal.txt#" \
    -e "s#^  path: .*#  path: $tmp/roboelf.log#" \
    config/roboelf.yaml >"$tmp/roboelf.yaml"
"$BIN/galil-load" -a "127.0.0.1:$port" --start dmc/ >"$tmp/load.out" 2>&1 ||
	fail "galil-load: $(cat "$tmp/load.out")"

ctlreq() { # one request on galil-sim's control port; prints its answer
	local ans=""
	exec 9<>"/dev/tcp/127.0.0.1/$ctl" || return 1
	printf '%s\n' "$1" >&9
	read -r -t 5 ans <&9
	exec 9>&-
	printf '%s\n' "${ans%$'\r'}"
}

screen() { tmux -S "$sock" capture-pane -p -J -t re; }
on_screen() { screen | tr '\n' ' ' | tr -s ' ' | grep -q -- "$1"; }
# interrupt SIZE PHASE WANT [WANT2]: a full calibration in a tmux pane, its
# board showing PHASE on axis A's line, Ctrl-C, then WANT (and WANT2) said
# (the table in force)
interrupt() {
	tmux -S "$sock" new-session -d -s re -x "${1%x*}" -y "${1#*x}" \
		"$BIN/roboelf -c $tmp/roboelf.yaml --galil 127.0.0.1:$port --calibration full; echo EXIT=\$?; sleep 60"
	wait_for 60 sh -c "tmux -S '$sock' capture-pane -p -J -t re | grep -q '^A  $2 '" ||
		{ screen; fail "calibration board: no '$2' on axis A"; }
	check_screen "${1%x*}" "calibration ($2)"
	grep -q "^calibrating [0-9]* s, about [0-9]* s left; Ctrl-C stops it (old table kept)" "$tmp/screen" ||
		{ cat "$tmp/screen"; fail "calibration board: no time left"; }
	cp "$tmp/screen" "$tmp/screen-calibration-$2.txt"
	[ -n "${SHOW:-}" ] && { echo "--- calibration $1"; cat "$tmp/screen"; }
	tmux -S "$sock" send-keys -t re C-c
	wait_for 20 on_screen "EXIT=0" || { screen; fail "Ctrl-C in calibration: no exit 0"; }
	on_screen "$3" || { screen; fail "Ctrl-C in calibration: not said: $3"; }
	[ -z "${4:-}" ] || on_screen "$4" || { screen; fail "Ctrl-C in calibration: not said: $4"; }
	tmux -S "$sock" kill-session -t re 2>/dev/null
}
# one_header, check_screen: see below (defined before use)
one_header() { [ "$(screen | grep -c '^RoboELF  mode')" = 1 ]; }
check_screen() { # WIDTH WHAT
	# a capture can meet a frame half drawn (tmux reads the terminal's
	# bytes in pieces): the board must show one header within 2 s
	wait_for 2 one_header || { screen; fail "$2: the header is not there exactly once"; }
	screen >"$tmp/screen"
	long=$(awk -v w="$1" 'length($0) > w' "$tmp/screen" | head -1)
	[ -z "$long" ] || fail "$2: a line longer than $1: '$long'"
}

# A session that lives as long as the check: killing the last session
# ends the tmux server, and a new-session racing with that ending fails
# ("server exited unexpectedly").
tmux -S "$sock" new-session -d -s keep -x 80 -y 24 "sleep 100000" ||
	fail "tmux: cannot start a server"

# no calibration file yet: interrupted, none is in force
interrupt 80x24 "sweep fwd" "calibration interrupted: no table is in force ('$tmp/cal.txt' does not exist): the next start needs a full calibration"

# one full calibration, in line mode, to have a file for every size
"$BIN/roboelf" -c "$tmp/roboelf.yaml" --galil "127.0.0.1:$port" \
	--calibration full </dev/null >"$tmp/cal.out" 2>&1 &
rpid=$!
wait_for 120 grep -q "RoboELF Ready for Use" "$tmp/cal.out" ||
	{ kill $rpid; fail "calibration: $(tail -3 "$tmp/cal.out")"; }
kill -TERM $rpid; wait $rpid

ready() { screen | grep -q "RoboELF  mode"; }
faulted() { screen | grep -q "FAULT ENCODER"; }

for size in 80x24 100x30 200x60; do
	w=${size%x*}; h=${size#*x}
	tmux -S "$sock" new-session -d -s re -x "$w" -y "$h" \
		"$BIN/roboelf -c $tmp/roboelf.yaml --galil 127.0.0.1:$port --calibration file; sleep 60"
	wait_for 90 ready || { screen; fail "$size: no board within 90 s"; }
	check_screen "$w" "$size running"
	[ "$(ctlreq 'pot B offset 0.5')" = ok ] || fail "inject"
	wait_for 5 faulted || { screen; fail "$size: no FAULT on the board"; }
	sleep 10 # the operator looks 10 s later: the fault must still be there
	check_screen "$w" "$size 10 s after the fault"
	grep -q "FAULT ENCODER" "$tmp/screen" || fail "$size: FAULT gone after 10 s"
	grep -q "Recovery" "$tmp/screen" || { cat "$tmp/screen"; fail "$size: the recovery text is gone after 10 s"; }
	if [ "$size" = 200x60 ]; then
		tmux -S "$sock" resize-window -t re -x 80 -y 24 2>/dev/null ||
			tmux -S "$sock" resize-pane -t re -x 80 -y 24
		wait_for 5 sh -c "tmux -S '$sock' capture-pane -p -J -t re | awk 'length(\$0) > 80 { bad = 1 } END { exit bad }'" ||
			{ screen; fail "after the resize to 80x24: lines wider than 80"; }
		check_screen 80 "resized to 80x24"
		grep -q "FAULT ENCODER" "$tmp/screen" || fail "resize: FAULT gone"
	fi
	[ -n "${SHOW:-}" ] && { echo "--- $size"; cat "$tmp/screen"; }
	cp "$tmp/screen" "$tmp/screen-$size.txt"
	tmux -S "$sock" send-keys -t re q
	# roboelf has quit (its locks released) before the next one starts
	wait_for 20 sh -c "! pgrep -f '^$BIN/roboelf -c $tmp/roboelf.yaml' >/dev/null" ||
		fail "$size: roboelf did not quit within 20 s of q"
	tmux -S "$sock" kill-session -t re 2>/dev/null
	ctlreq 'pot B ok' >/dev/null
done
# the joystick held from before the start (80x24): the board says to
# release it, the message is on the screen whole, no "Ready" until released
[ "$(ctlreq 'joy A fwd')" = ok ] || fail "joy A fwd"
tmux -S "$sock" new-session -d -s re -x 80 -y 24 \
	"$BIN/roboelf -c $tmp/roboelf.yaml --galil 127.0.0.1:$port --calibration file; sleep 60"
held() { on_screen "controller armed, release the joystick"; }
wait_for 90 held || { screen; fail "held joystick: the board does not say to release it"; }
check_screen 80 "joystick held"
on_screen "roboelf: the joystick is held (axis A forward) since arming: release it to neutral; nothing moves until the controller has seen it released" ||
	{ screen; fail "held joystick: the message is not on the screen"; }
on_screen "RoboELF Ready for Use" && { screen; fail "held joystick: Ready before the release"; }
[ -n "${SHOW:-}" ] && { echo "--- joystick held 80x24"; cat "$tmp/screen"; }
cp "$tmp/screen" "$tmp/screen-held.txt"
[ "$(ctlreq 'joy A neutral')" = ok ] || fail "joy A neutral"
released() { on_screen "RoboELF Ready for Use" && on_screen "controller armed "; }
wait_for 5 released || { screen; fail "released joystick: no Ready"; }
check_screen 80 "joystick released"
tmux -S "$sock" send-keys -t re q
wait_for 20 sh -c "! pgrep -f '^$BIN/roboelf -c $tmp/roboelf.yaml' >/dev/null" ||
	fail "joystick held: roboelf did not quit within 20 s of q"
# quit without a fault: the board is gone (it would show "relay ON"), the
# switch-off's confirmation is the last word
wait_for 5 on_screen "motor power off (relay): confirmed; bye" ||
	{ screen; fail "q: no confirmed switch-off on the screen"; }
[ "$(screen | grep -c '^RoboELF  mode')" = 0 ] || { screen; fail "q without a fault: a stale board is left on the screen"; }
tmux -S "$sock" kill-session -t re 2>/dev/null
# with a calibration file: interrupted, the file's table is kept
interrupt 80x24 "onto rev switch" "calibration interrupted: no new table; the table in force is still the one in '$tmp/cal.txt' (made 20" \
	"Z), kept unchanged: the next start can load it"
# Ctrl-D at the calibration question: said, exit 2, nothing moved
tmux -S "$sock" new-session -d -s re -x 80 -y 24 \
	"$BIN/roboelf -c $tmp/roboelf.yaml --galil 127.0.0.1:$port; echo EXIT=\$?; sleep 60"
asked() { screen | grep -q "Calibration: \[f\]ull"; }
wait_for 90 asked || { screen; fail "no calibration question"; }
tmux -S "$sock" send-keys -t re C-d
said() { screen | grep -q "EXIT=2"; }
wait_for 10 said || { screen; fail "Ctrl-D: no exit 2"; }
screen | tr '\n' ' ' | tr -s ' ' | grep -q "no answer to the calibration question (end of input): nothing moved, motor power stays off" ||
	{ screen; fail "Ctrl-D: no reason given"; }
echo "console_tmux: ok (80x24, 100x30, 200x60 and a resize: no wrapped line, one header, the FAULT and its recovery on screen 10 s later; the calibration board with phases and time left, Ctrl-C in it says which table is in force; Ctrl-D at the calibration question explained, exit 2; a joystick held at arming named on the board and the screen, Ready after its release; no stale board after q)"
