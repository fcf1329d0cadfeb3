#!/bin/sh
# messages.sh - start-up messages that once said something untrue, each
# reproduced with the built roboelf and held to its exact text and exit
# code (no controller, no relay needed):
#   - port 99999 is refused by the configuration check (exit 2), before
#     any relay is opened;
#   - no relay: the reason, a hint naming the next step, and no claim of
#     switching off what was never on (exit 3);
#   - clinical: a relay whose USB serial number cannot be read is refused
#     before it is opened (exit 3); no relay.serial is refused by the
#     configuration check (exit 2);
#   - a directory given to -c (exit 2);
#   - an unclosed quote reported at its own line (exit 2);
#   - --version names the release and the DMC interface (exit 0).
# The others of that list are held elsewhere: the configuration search
# (config_search.sh), Ctrl-D at the calibration prompt (console_tmux.sh),
# "WARN while latched" (test_re_io), p99 <= max (test_re_super).
set -u
cd "$(dirname "$0")/../.." || exit 1
BIN=${ROBOELF_BIN:-$PWD/${BUILD:-build}/bin}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fail() { echo "messages: FAIL: $*"; exit 1; }

# expect NAME RC WANT -- ARGS...: roboelf ARGS (stdin empty) exits RC and
# prints exactly WANT (stdout and stderr together, in order)
expect() {
	name=$1 rc=$2 want=$3
	shift 4
	out=$("$BIN/roboelf" "$@" 2>&1 </dev/null)
	got=$?
	[ "$got" -eq "$rc" ] || fail "$name: exit $got, want $rc: $out"
	[ "$out" = "$want" ] || fail "$name: printed
$out
want
$want"
}

# a configuration whose relay is a path in $tmp that does not exist
sed -e "s#port_development: .*#port_development: $tmp/no-relay#" \
    -e "s#^  path: .*#  path: $tmp/roboelf.log#" \
    config/roboelf.yaml >"$tmp/ok.yaml"

sed 's#address: "127.0.0.1:23023"#address: "127.0.0.1:99999"#' \
	"$tmp/ok.yaml" >"$tmp/port.yaml"
grep -q '127.0.0.1:99999' "$tmp/port.yaml" || fail "port.yaml not made"
line=$(grep -n '127.0.0.1:99999' "$tmp/port.yaml" | cut -d: -f1)
col=$(awk -v n="$line" 'NR == n { print index($0, "\"") }' "$tmp/port.yaml")
expect port 2 "$tmp/port.yaml:$line:$col: 'address' '127.0.0.1:99999' is not HOST, HOST:PORT or [V6]:PORT with a port 1..65535" \
	-- -c "$tmp/port.yaml" --calibration file

expect port-option 2 "roboelf: error: 'address' '127.0.0.1:99999' is not HOST, HOST:PORT or [V6]:PORT with a port 1..65535" \
	-- -c "$tmp/ok.yaml" --galil 127.0.0.1:99999 --calibration file

expect no-relay 3 "roboelf: error: cannot open the E-stop relay '$tmp/no-relay': No such file or directory (is galil-sim running, or the relay plugged in?)
roboelf: the E-stop relay was never switched on; bye" \
	-- -c "$tmp/ok.yaml" --calibration file
[ -e "$tmp/no-relay" ] && fail "no-relay: the relay path was created"

# clinical: a relay that is not a USB serial port is refused by the
# binding check (its USB serial number against relay.serial) before it is
# opened, so it never receives a byte (/dev/null: no device is touched)
sed -e 's#^mode: .*#mode: clinical#' -e 's#^  port_clinical: .*#  port_clinical: /dev/null#' \
    -e 's#^  serial: .*#  serial: A10KXYZ9#' -e 's#address: "127.0.0.1:23023"#address: "192.0.2.1"#' \
    "$tmp/ok.yaml" >"$tmp/clinical.yaml"
expect unbound 3 "roboelf: error: relay '/dev/null': cannot read its USB serial number: not a serial port known to libserialport
roboelf: the E-stop relay was never switched on; bye" \
	-- -c "$tmp/clinical.yaml" --calibration file
# without relay.serial: refused by the configuration check (exit 2)
sed 's#^  serial: .*#  serial: ""#' "$tmp/clinical.yaml" >"$tmp/noserial.yaml"
sline=$(grep -n '^  serial: ""$' "$tmp/noserial.yaml" | cut -d: -f1)
expect no-serial 2 "$tmp/noserial.yaml:$sline:11: 'serial' must be set in clinical mode: the relay board's USB serial number, which 'roboelf-tech bind-relay' prints" \
	-- -c "$tmp/noserial.yaml" --calibration file

expect directory 2 "cannot read '$tmp': it is a directory; give the configuration file (e.g. $tmp/roboelf.yaml)" \
	-- -c "$tmp"

# an unclosed quote on the address's line: reported at that line and the
# quote's column, not where the parser gave up
sed 's#address: "127.0.0.1:23023"#address: "127.0.0.1:23023#' \
	"$tmp/ok.yaml" >"$tmp/quote.yaml"
out=$("$BIN/roboelf" -c "$tmp/quote.yaml" --calibration file 2>&1 </dev/null)
rc=$?
[ $rc -eq 2 ] || fail "quote: exit $rc: $out"
case $out in
"$tmp/quote.yaml:$line:$col: this quote is not closed on its line "*) ;;
*) fail "quote: $out" ;;
esac

out=$("$BIN/roboelf" --version 2>&1 </dev/null)
rc=$?
[ $rc -eq 0 ] || fail "version: exit $rc"
vers=$(sed -n 's/^vers *= *\([0-9.]*\).*/\1/p' dmc/constants.dmc | head -1)
first=$(printf '%s\n' "$out" | head -1)
case $first in
"roboelf "[0-9]*.[0-9]*.[0-9]*" (controller program interface $vers, dmc/constants.dmc vers)") ;;
*) fail "version: '$first' (dmc/constants.dmc vers $vers)" ;;
esac
echo "messages: ok"
