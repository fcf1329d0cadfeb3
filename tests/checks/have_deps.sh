#!/bin/sh
# have_deps.sh - before `make deps`, `make` and `make lint` name the missing
# Debian packages and the `make deps` command instead of failing in the
# compiler (tools/have-deps.sh). The missing tools are simulated
# with the Makefile's PKG_CONFIG, CLANG_FORMAT and CPPCHECK variables (a
# pkg-config that knows only libserialport; names that do not exist), so
# nothing on this machine is changed.
set -u
cd "$(dirname "$0")/../.." || exit 1
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fail() { echo "have_deps: FAIL: $*"; exit 1; }
hint() { echo "make: install them with 'make deps' (as root), or run: sudo apt-get install --no-install-recommends$1"; }

printf '#!/bin/sh\n[ "$1 $2" = "--exists libserialport" ]\n' >"$tmp/pkg-config"
chmod +x "$tmp/pkg-config"
out=$(make -s --no-print-directory BUILD="$tmp/build" PKG_CONFIG="$tmp/pkg-config" all 2>&1)
rc=$?
[ $rc -ne 0 ] || fail "make succeeded without the libraries"
want="make: missing Debian packages: libyaml-dev libcmocka-dev
$(hint " libyaml-dev libcmocka-dev")"
[ "$(printf '%s\n' "$out" | head -2)" = "$want" ] || fail "make: '$out'"
case $out in *"No such file"* | *"error:"*) fail "make reached the compiler: $out" ;; esac
[ -z "$(find "$tmp/build" -name '*.o' 2>/dev/null)" ] || fail "make compiled something"

out=$(make -s --no-print-directory PKG_CONFIG="$tmp/no-pkg-config" have-deps 2>&1)
want="make: missing Debian packages: pkgconf libserialport-dev libyaml-dev libcmocka-dev
$(hint " pkgconf libserialport-dev libyaml-dev libcmocka-dev")"
[ "$(printf '%s\n' "$out" | head -2)" = "$want" ] || fail "no pkg-config: '$out'"

out=$(make -s --no-print-directory CLANG_FORMAT="$tmp/no-clang-format" CPPCHECK="$tmp/no-cppcheck" lint 2>&1)
rc=$?
[ $rc -ne 0 ] || fail "make lint succeeded without its tools"
want="make: missing Debian packages: clang-format cppcheck
$(hint " clang-format cppcheck")"
[ "$(printf '%s\n' "$out" | head -2)" = "$want" ] || fail "make lint: '$out'"

make -s --no-print-directory have-deps have-lint-deps || fail "this machine has everything, but the check says not"
echo "have_deps: ok"
