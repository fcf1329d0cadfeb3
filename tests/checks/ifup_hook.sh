#!/bin/sh
# ifup_hook.sh - the link's ifupdown hook (packaging/ifupdown/roboelf,
# installed as /etc/network/if-up.d/roboelf; docs/link.md) with stand-ins
# for ip and logger on PATH (never this machine's routes) and the built
# roboelf-tech reading test configurations:
#   - the interface that reaches the controller: exactly "route get HOST",
#     then "route replace HOST dev IFACE rto_min 5ms" (HOST without the
#     configured port), and the syslog line;
#   - another interface, the loopback, MODE=stop: no replace, nothing logged
#     (the loopback and stop: not even a route lookup);
#   - a route through a gateway, a route lookup that fails, a replace that
#     fails: no (further) change, the reason logged;
#   - the clinical template not filled in: no ip call, the reason logged;
#   - without logger on PATH: the same calls, exit 0;
# and roboelf-tech --print's keys and exit codes.
# Every case exits 0: a hook that fails would stop ifup.
set -u
cd "$(dirname "$0")/../.." || exit 1
TOP=$PWD
BUILD=${BUILD:-build}
BIN=$TOP/$BUILD/bin
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fail() { echo "ifup_hook: FAIL: $*"; exit 1; }
[ -x "$BIN/roboelf-tech" ] || fail "no $BIN/roboelf-tech (make all)"
hook=$TOP/packaging/ifupdown/roboelf
mkdir "$tmp/bin" "$tmp/nolog" "$tmp/run"
# ip: every call recorded; "route get" answers $tmp/route (exit 2 when the
# file is absent); "route replace" fails when $tmp/refuse exists
cat >"$tmp/bin/ip" <<EOS
#!/bin/sh
echo "ip \$*" >>"$tmp/calls"
case "\$*" in
"-o route get "*) [ -f "$tmp/route" ] || { echo "RTNETLINK answers: Network is unreachable" >&2; exit 2; }
	cat "$tmp/route" ;;
"route replace "*) [ -f "$tmp/refuse" ] && { echo "RTNETLINK answers: Operation not permitted" >&2; exit 2; }
	exit 0 ;;
esac
EOS
printf '#!/bin/sh\necho "logger $*" >>"%s/calls"\n' "$tmp" >"$tmp/bin/logger"
ln -s "$BIN/roboelf-tech" "$tmp/bin/roboelf-tech"
ln -s "$BIN/roboelf-tech" "$tmp/nolog/roboelf-tech"
cp "$tmp/bin/ip" "$tmp/nolog/ip"
# the PATH without logger: nothing but what the hook and the stand-in run
for c in sh head cat; do ln -s "$(command -v $c)" "$tmp/nolog/$c" || fail "no $c"; done
chmod +x "$tmp/bin/ip" "$tmp/bin/logger" "$tmp/nolog/ip"

sed 's#^  address: .*#  address: "192.0.2.10:23"#' config/roboelf.yaml >"$tmp/dev.yaml"
grep -q '^  address: "192.0.2.10:23"$' "$tmp/dev.yaml" || fail "dev.yaml not made"

# run NAME IFACE [MODE] [PATH] [CONFIG]: the hook as ifup runs it; its
# calls in $tmp/calls; its exit status must be 0 and it prints nothing
run() {
	: >"$tmp/calls"
	out=$(cd "$tmp/run" && env IFACE="$2" MODE="${3:-start}" ADDRFAM=inet PHASE=post-up \
		ROBOELF_CONFIG="${5:-$tmp/dev.yaml}" PATH="${4:-$tmp/bin:$PATH}" sh "$hook" 2>&1)
	rc=$?
	[ $rc -eq 0 ] || fail "$1: exit $rc: $out"
	[ -z "$out" ] || fail "$1: printed '$out'"
}
want() { # want NAME EXPECTED-CALLS
	[ "$(cat "$tmp/calls")" = "$2" ] || fail "$1: calls
$(cat "$tmp/calls")
want
$2"
}

printf '192.0.2.10 dev eth1 src 192.0.2.1 uid 0 \\    cache \n' >"$tmp/route"
run "the controller's interface" eth1
want "the controller's interface" "ip -o route get 192.0.2.10
ip route replace 192.0.2.10 dev eth1 rto_min 5ms
logger -t roboelf-link -- eth1 up: route to the controller 192.0.2.10: rto_min 5ms"

run "another interface" eth0
want "another interface" "ip -o route get 192.0.2.10"
run "a prefix of the interface's name" eth
want "a prefix of the interface's name" "ip -o route get 192.0.2.10"
run "the loopback" lo
want "the loopback" ""
run "ifdown" eth1 stop
want "ifdown" ""

run "no logger" eth1 start "$tmp/nolog"
want "no logger" "ip -o route get 192.0.2.10
ip route replace 192.0.2.10 dev eth1 rto_min 5ms"

touch "$tmp/refuse"
run "the replace refused" eth1
want "the replace refused" "ip -o route get 192.0.2.10
ip route replace 192.0.2.10 dev eth1 rto_min 5ms
logger -t roboelf-link -- eth1 up: FAILED to set rto_min 5ms on the route to the controller 192.0.2.10: RTNETLINK answers: Operation not permitted (roboelf refuses a clinical start until it is set)"
rm "$tmp/refuse"

printf '192.0.2.10 via 10.0.0.1 dev eth1 src 10.0.0.2 uid 0 \\    cache \n' >"$tmp/route"
run "a gateway" eth1
want "a gateway" "ip -o route get 192.0.2.10
logger -t roboelf-link -- eth1 up: rto_min not set: the controller 192.0.2.10 is reached through a gateway (a direct link is the one supported network: docs/technician.md)"

rm "$tmp/route"
run "no route" eth1
want "no route" "ip -o route get 192.0.2.10
logger -t roboelf-link -- eth1 up: rto_min not set: no route to the controller 192.0.2.10: RTNETLINK answers: Network is unreachable"

site=$TOP/config/roboelf-site.yaml
n=$(grep -c '^ *[a-z_]*: FILL-IN$' "$site")
run "the template" eth1 start "$tmp/bin:$PATH" "$site"
want "the template" "logger -t roboelf-link -- eth1 up: rto_min not set: $site cannot be used yet: $site: this site's configuration is not finished: $n values are still FILL-IN"

# roboelf-tech --print: the keys, in full, and the exit codes
tp() { (cd "$tmp/run" && "$BIN/roboelf-tech" --print "$@" 2>&1); }
[ "$(tp controller.address -c "$tmp/dev.yaml")" = "192.0.2.10:23" ] || fail "--print controller.address"
[ "$(tp controller.host -c "$tmp/dev.yaml")" = "192.0.2.10" ] || fail "--print controller.host"
[ "$(tp mode -c "$tmp/dev.yaml")" = "development" ] || fail "--print mode"
[ "$(tp log.path -c "$tmp/dev.yaml")" = "$tmp/run/roboelf.log" ] || fail "--print log.path: $(tp log.path -c "$tmp/dev.yaml")"
[ "$(tp calibration.file -c "$tmp/dev.yaml")" = "$tmp/run/roboelf-calibration.txt" ] ||
	fail "--print calibration.file"
out=$(tp colour -c "$tmp/dev.yaml")
rc=$?
[ $rc -eq 2 ] && [ "$out" = "roboelf-tech: error: --print 'colour': not a key it prints (controller.address, controller.host, mode, log.path, calibration.file)" ] ||
	fail "--print colour: exit $rc: $out"
out=$(tp controller.host -c "$site")
rc=$?
[ $rc -eq 2 ] && [ "$(printf '%s\n' "$out" | head -n 1)" = "$site: this site's configuration is not finished: $n values are still FILL-IN" ] ||
	fail "--print with the template: exit $rc: $out"
out=$(tp controller.host -c "$tmp/dev.yaml" commission)
rc=$?
[ $rc -eq 2 ] && [ "$out" = "roboelf-tech: error: --print takes no command" ] || fail "--print with a command: exit $rc: $out"
echo "ifup_hook: ok"
