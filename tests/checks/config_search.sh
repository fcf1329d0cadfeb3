#!/bin/sh
# config_search.sh - roboelf without -c looks for config/roboelf.yaml in
# the directory it is started in, then /etc/roboelf/roboelf.yaml (roboelf.1,
# FILES); with neither it exits 2 naming both.
set -u
cd "$(dirname "$0")/../.." || exit 1
BIN=${ROBOELF_BIN:-$PWD/${BUILD:-build}/bin}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fail() { echo "config_search: FAIL: $*"; exit 1; }

# started in the source tree: config/roboelf.yaml is used (a bad one is
# reported with its own path, proving which file was read)
mkdir -p "$tmp/tree/config"
printf 'period_ms: 1\n' >"$tmp/tree/config/roboelf.yaml"
out=$(cd "$tmp/tree" && "$BIN/roboelf" --calibration file 2>&1 </dev/null)
rc=$?
[ $rc -eq 2 ] || fail "tree: exit $rc: $out"
case $out in config/roboelf.yaml:1:*) ;; *) fail "tree: $out" ;; esac

# started elsewhere
out=$(cd "$tmp" && "$BIN/roboelf" --calibration file 2>&1 </dev/null)
rc=$?
if [ -e /etc/roboelf/roboelf.yaml ]; then
	case $out in *"cannot read 'config/roboelf.yaml'"*) fail "elsewhere: the installed file was not tried: $out" ;; esac
else
	[ $rc -eq 2 ] || fail "elsewhere: exit $rc: $out"
	want="roboelf: no configuration: neither 'config/roboelf.yaml' (in this directory) nor '/etc/roboelf/roboelf.yaml' exists; give one with -c FILE"
	printf '%s\n' "$out" | grep -qxF "$want" || fail "elsewhere: '$out'"
fi
echo "config_search: ok"
