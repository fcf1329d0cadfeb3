#!/bin/bash
# console_tmux.sh - the operator's board in a real terminal (tmux), as an
# operator sees it: roboelf on galil-sim in a tmux pane of 80x24, 120x40
# and 200x60; a potentiometer fault injected; the pane read back with
# `tmux capture-pane -J` (wrapped lines joined, so a line that wrapped
# shows longer than the width):
#   - no line longer than the pane is wide, during the run and after the
#     fault, but a path alone on its line: the log's path (wider than 120
#     columns here) is on the screen whole on a line of its own, the
#     fault's trace's whole on one line (its own where it does not fit
#     after "roboelf: trace"), never cut or split;
#   - the speeds with their units (deg/s for A and B, mm/s for C);
#   - after q, the board's fault panel still under its header, its first
#     line the FAULT's first words;
#   - two joysticks pressed together (A forward, B forward) past the
#     invalid-input timeout (80x24): the FAULT INPUT names the switches
#     and the timeout in ms; nothing on the screen in codes (no "0x", no
#     "(axis N)" with a digit), and no negative zero ("-0", "-0.0");
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
# the log (and the traces next to it) in a directory whose path is wider
# than a 120-column terminal: it must be shown whole, never cut or split
logdir="$tmp/$(printf 'a-directory-with-a-rather-long-name-%s-' 1 2 3)"
mkdir -p "$logdir" || fail "cannot make $logdir"
logpath="$logdir/roboelf.log"
[ "${#logpath}" -gt 120 ] || fail "the log's path is not wider than 120: $logpath"
sed -e "s#port_development: .*#port_development: $tmp/relay#" \
    -e "s#icstation_state: .*#icstation_state: $tmp/ic.state#" \
    -e "s#^  file: .*#  file: $tmp/cal.txt#" \
    -e "s#^  path: .*#  path: $logpath#" \
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
	# a path alone on its line is the one text that may be wider: whole
	# (or its end, at the top, when its first rows scrolled off)
	long=$(awk -v w="$1" 'length($0) > w && !(NR == 1 && $0 ~ /^[^ ]*\/[^ ]*$/) && $0 !~ /^\/[^ ]*$/' "$tmp/screen" | head -1)
	[ -z "$long" ] || fail "$2: a line longer than $1: '$long'"
	# no code where words belong, in the joystick's and the faults' texts
	grep -n '0x[0-9a-fA-F]\|(axis [0-9]' "$tmp/screen" &&
		fail "$2: a code on the screen (0x..., (axis N))"
	# no negative zero ("-0", "-0.0", "-0.00"), in any unit
	grep -nE '(^|[ (])-0(\.0+)?([ ,)]|$)' "$tmp/screen" &&
		fail "$2: a negative zero on the screen"
	return 0
}
# path_whole WHAT PATH [-x]: PATH whole on one screen line (-x: on a line
# of its own); a path that does not fit after the words before it starts
# a line, so a line that holds only its end is a split path
path_whole() {
	grep -qF${3:+x} -- "$2" "$tmp/screen" || { cat "$tmp/screen"; fail "$1: the path '$2' is not whole on a line${3:+ of its own}"; }
}
# units WHAT: the axis lines give their speeds with units
units() {
	grep -q '^A .* -\{0,1\}[0-9]*\.[0-9] deg/s ' "$tmp/screen" &&
	grep -q '^B .* -\{0,1\}[0-9]*\.[0-9] deg/s ' "$tmp/screen" &&
	grep -q '^C .* -\{0,1\}[0-9]*\.[0-9] mm/s ' "$tmp/screen" ||
		{ cat "$tmp/screen"; fail "$1: a speed without its unit"; }
}
# panel_first WHAT TEXT: the line under the board's header begins with TEXT
panel_first() {
	screen >"$tmp/screen"
	awk -v t="$2" 'prev ~ /^RoboELF  mode / && index($0, t) == 1 { ok = 1 } { prev = $0 } END { exit !ok }' "$tmp/screen" ||
		{ cat "$tmp/screen"; fail "$1: the fault panel's first line '$2' is not under the header"; }
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
axes() { screen | grep -q "^ax     position "; }
faulted() { screen | grep -q "FAULT ENCODER"; }

for size in 80x24 120x40 200x60; do
	w=${size%x*}; h=${size#*x}
	tmux -S "$sock" new-session -d -s re -x "$w" -y "$h" \
		"$BIN/roboelf -c $tmp/roboelf.yaml --galil 127.0.0.1:$port --calibration file; echo EXIT=\$?; sleep 60"
	wait_for 90 ready || { screen; fail "$size: no board within 90 s"; }
	# the axis lines (not the calibration's): armed
	wait_for 30 axes || { screen; fail "$size: no axis lines within 30 s"; }
	check_screen "$w" "$size running"
	units "$size running"
	[ "$(ctlreq 'pot B offset 0.5')" = ok ] || fail "inject"
	wait_for 5 faulted || { screen; fail "$size: no FAULT on the board"; }
	sleep 10 # the operator looks 10 s later: the fault must still be there
	check_screen "$w" "$size 10 s after the fault"
	grep -q "FAULT ENCODER" "$tmp/screen" || fail "$size: FAULT gone after 10 s"
	grep -q "Recovery" "$tmp/screen" || { cat "$tmp/screen"; fail "$size: the recovery text is gone after 10 s"; }
	units "$size after the fault"
	path_whole "$size: the log under the fault panel" "$logpath" -x
	# this run's trace: the last one (the sizes share one log)
	trace=$(sed -n 's/.* trace: \(.*\) written (.*/\1/p' "$logpath" | tail -n 1)
	[ -n "$trace" ] || fail "$size: no trace of the fault in the log"
	path_whole "$size: the trace's message" "$trace"
	if [ "$size" = 200x60 ]; then
		tmux -S "$sock" resize-window -t re -x 80 -y 24 2>/dev/null ||
			tmux -S "$sock" resize-pane -t re -x 80 -y 24
		wait_for 5 sh -c "tmux -S '$sock' capture-pane -p -J -t re | awk 'length(\$0) > 80 && \$0 !~ /^\\/[^ ]*\$/ { bad = 1 } END { exit bad }'" ||
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
	wait_for 5 on_screen "EXIT=4" || { screen; fail "$size: no exit 4 after the fault"; }
	# after the end: the fault panel's first line still on the screen
	[ "$size" = 200x60 ] && firstw=80 || firstw=$w
	panel_first "$size after the end" "FAULT ENCODER: axis B: potentiometer"
	check_screen "$firstw" "$size after the end"
	tmux -S "$sock" kill-session -t re 2>/dev/null
	ctlreq 'pot B ok' >/dev/null
done
# two joysticks together (A forward and B forward) past the invalid-input
# timeout (80x24): the FAULT INPUT in words, the switches and the timeout
tmux -S "$sock" new-session -d -s re -x 80 -y 24 \
	"$BIN/roboelf -c $tmp/roboelf.yaml --galil 127.0.0.1:$port --calibration file; echo EXIT=\$?; sleep 60"
armed() { on_screen "RoboELF Ready for Use"; }
wait_for 90 armed || { screen; fail "two joysticks: not ready within 90 s"; }
[ "$(ctlreq 'joy A fwd')" = ok ] && [ "$(ctlreq 'joy B fwd')" = ok ] || fail "joy A fwd, B fwd"
input() { screen | grep -q "FAULT INPUT"; }
wait_for 10 input || { screen; fail "two joysticks: no FAULT INPUT"; }
ctlreq 'joy A neutral' >/dev/null; ctlreq 'joy B neutral' >/dev/null
check_screen 80 "two joysticks"
on_screen "FAULT INPUT: invalid joystick state held longer than the invalid-input timeout of 500 ms: A forward (switches a and b) and B forward (switches a and b) closed at once." ||
	{ screen; fail "two joysticks: the FAULT INPUT does not name the switches and the timeout"; }
# the board is redrawn after the FAULT lines (later under the sanitizers):
# its controller field names the fault, the program's own INPUT or, when
# roboelf latched first, its stop by the supervisor (one first cause)
ctrl_named() {
	screen | grep -Eq "^controller (FAULT INPUT \(code 3\)|stopped by the supervisor \(code [0-9]+\))  joystick"
}
wait_for 10 ctrl_named ||
	{ screen; fail "two joysticks: the controller's fault not by its name"; }
[ -n "${SHOW:-}" ] && { echo "--- two joysticks 80x24"; cat "$tmp/screen"; }
cp "$tmp/screen" "$tmp/screen-input.txt"
tmux -S "$sock" send-keys -t re q
wait_for 20 sh -c "! pgrep -f '^$BIN/roboelf -c $tmp/roboelf.yaml' >/dev/null" ||
	fail "two joysticks: roboelf did not quit within 20 s of q"
panel_first "two joysticks, after the end" "FAULT INPUT: invalid joystick state"
tmux -S "$sock" kill-session -t re 2>/dev/null
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
echo "console_tmux: ok (80x24, 120x40, 200x60 and a resize: no wrapped line but whole paths (the log's, the trace's), one header, speeds with units, the FAULT and its recovery on screen 10 s later and its panel's first line after the end; two joysticks: FAULT INPUT naming the switches and the timeout, no code on the screen; the calibration board with phases and time left, Ctrl-C in it says which table is in force; Ctrl-D at the calibration question explained, exit 2; a joystick held at arming named on the board and the screen, Ready after its release; no stale board after q)"
