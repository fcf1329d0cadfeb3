#!/bin/sh
# pkgtest.sh - make pkgtest: the two Debian packages (make deb) installed,
# used and purged where nothing else was installed. A copy of the minimal
# Debian 12 root of tools/debroot.sh (built once and kept pristine by make
# fresh; ROBOELF_DEBROOT names the directory that holds it, default
# $BUILD/fresh: its base is only read, never changed) is made afresh in
# $BUILD/pkgtest/root, the packages are copied in, and tests/pkg/inroot.sh
# runs there as root: apt installs both (fetching their dependencies), then
# the group, the state directories, the conffiles, the refusal of the
# unfilled template, two operators sharing one log, the ifupdown hook, the
# installed demo (roboelf-sim), and the purge that keeps the log. Output: $BUILD/pkgtest/run.log.
#
# Not root: "SKIPPED" with the reason and exit 77 (never a pass).
# Exit: 0 passed; 1 otherwise.
set -u
BUILD=${BUILD:-build}
TOP=$(cd "$(dirname "$0")/../.." && pwd) || exit 1
cd "$TOP" || exit 1
if [ "$(id -u)" != 0 ]; then
	echo "pkgtest: SKIPPED: needs root (chroot, apt in the root); run make pkgtest as root"
	exit 77
fi
fail() { echo "pkgtest: FAIL: $*"; exit 1; }
base=${ROBOELF_DEBROOT:-$TOP/$BUILD/fresh}
dir=$TOP/$BUILD/pkgtest
root=$dir/root
start=$(date +%s)
sh tools/debroot.sh base "$base" || exit 1
rm -rf "$root" && mkdir -p "$dir" || fail "cannot make $dir"
cp -a "$base/base" "$root" || fail "cannot copy $base/base to $root"
make -s --no-print-directory BUILD="$BUILD" deb >"$dir/deb.log" 2>&1 || { cat "$dir/deb.log"; fail "make deb"; }
mkdir "$root/root/pkg" || fail "cannot make the root's /root/pkg"
for d in $(sed -n 's/^deb: //p' "$dir/deb.log"); do
	cp "$d" "$root/root/pkg/" || fail "cannot copy $d"
done
[ "$(ls "$root/root/pkg" | wc -l)" = 2 ] || fail "make deb said: $(cat "$dir/deb.log")"
# the same sources rebuilt as a later version, for the upgrade
DEB_VERSION_SUFFIX=+rebuilt1 make -s --no-print-directory BUILD="$BUILD" deb >"$dir/deb-up.log" 2>&1 ||
	{ cat "$dir/deb-up.log"; fail "make deb (the upgrade)"; }
mkdir "$root/root/pkg/up" || fail "cannot make the root's /root/pkg/up"
for d in $(sed -n 's/^deb: //p' "$dir/deb-up.log"); do
	cp "$d" "$root/root/pkg/up/" && rm -f "$d" || fail "cannot copy $d"
done
[ "$(ls "$root/root/pkg/up" | wc -l)" = 2 ] || fail "make deb (the upgrade) said: $(cat "$dir/deb-up.log")"
cp tests/pkg/inroot.sh "$root/root/pkg/" || fail "cannot copy inroot.sh"
echo "pkgtest: the packages in a fresh Debian 12 root ($root); output in $dir/run.log"
sh tools/debroot.sh run "$root" sh /root/pkg/inroot.sh >"$dir/run.log" 2>&1
rc=$?
secs=$(($(date +%s) - start))
grep -E '^pkgtest: ' "$dir/run.log"
echo "pkgtest: $([ "$rc" -eq 0 ] && echo passed || echo "FAILED (exit $rc; $dir/run.log)") in $secs s"
[ "$rc" -eq 0 ]
