#!/bin/sh
# install.sh - an installation works outside the source tree:
# `make install DESTDIR=$tmp/root PREFIX=/usr`, then the installed roboelf
# and galil-load, started in an empty directory with ROBOELF_ROOT=$tmp/root
# (the staged installation's root, base_paths.h), find the installed DMC
# programs and configuration; the installed configuration is the site
# template config/roboelf-site.yaml, refused with every FILL-IN listed until
# it is filled in, and its calibration file and log are under /var; the
# state directories /var/lib/roboelf and /var/log/roboelf are made 2770
# (setgid, for the operators' group); the link's ifupdown hook is
# installed; --dmc and -c still win; the edited configuration survives a
# second install; the operator's and technician's docs are installed, the
# developer's are not, and every link between the installed ones resolves.
set -u
cd "$(dirname "$0")/../.." || exit 1
TOP=$PWD
BUILD=${BUILD:-build}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fail() { echo "install: FAIL: $*"; exit 1; }
root=$tmp/root
mkdir "$tmp/elsewhere"

make -s --no-print-directory BUILD="$BUILD" install DESTDIR="$root" PREFIX=/usr \
	>"$tmp/make.log" 2>&1 || { cat "$tmp/make.log"; fail "make install"; }
for f in usr/bin/roboelf usr/bin/roboelf-tech usr/bin/galil-load usr/bin/galil-sim \
	usr/share/roboelf/dmc/MANIFEST usr/share/roboelf/dmc/constants.dmc \
	usr/share/roboelf/dmc/roboelf.dmc usr/share/roboelf/config/plant.yaml \
	usr/share/roboelf/config/roboelf.yaml usr/share/roboelf/config/roboelf-site.yaml \
	etc/roboelf/roboelf.yaml usr/share/man/man1/roboelf.1 \
	usr/share/man/man1/galil-load.1 usr/share/man/man1/roboelf-tech.1 usr/share/man/man5/roboelf.yaml.5 \
	usr/share/doc/roboelf/README.md usr/share/doc/roboelf/docs/technician.md \
	usr/share/doc/roboelf/docs/trace-demo-pot-B.png usr/share/roboelf/demo.sh \
	etc/network/if-up.d/roboelf; do
	[ -f "$root/$f" ] || fail "not installed: /$f"
done
[ -e "$root/usr/bin/galil-stub" ] && fail "the test stub was installed"
[ -x "$root/etc/network/if-up.d/roboelf" ] || fail "the ifupdown hook is not executable"
# the developer's documents stay in the source tree
dev="docs/architecture.md docs/commands.md docs/fuzzing.md $(ls docs/*.1 docs/*.5)"
for f in $dev; do
	[ -e "$root/usr/share/doc/roboelf/$f" ] && fail "a developer's document was installed: $f"
done
# the site's state: the directories, setgid and the group's (the group
# itself is the package's postinst's, or the root's who installs)
for d in var/lib/roboelf var/log/roboelf; do
	[ "$(stat -c %a "$root/$d" 2>/dev/null)" = 2770 ] || fail "/$d: mode '$(stat -c %a "$root/$d" 2>&1)', not 2770"
done
[ "$(grep -E '^  (file|path): ' "$root/etc/roboelf/roboelf.yaml")" = "  file: /var/lib/roboelf/roboelf-calibration.txt
  path: /var/log/roboelf/roboelf.log" ] ||
	fail "the installed template's calibration file and log: $(grep -E '^  (file|path): ' "$root/etc/roboelf/roboelf.yaml")"
grep -qx '  dir: ""  *# "": next to the log (/var/log/roboelf)' "$root/etc/roboelf/roboelf.yaml" ||
	fail "the installed template's traces are not next to the log"

# every relative link of the installed Markdown resolves in the installed
# tree, but those to the developer's documents (named exactly: the man
# pages are read with man)
doc=$root/usr/share/doc/roboelf
for md in "$doc"/README.md "$doc"/docs/*.md; do
	for l in $(grep -o '](\([^)#: ]*\)' "$md" | sed 's/^](//' | sort -u); do
		[ -e "$(dirname "$md")/$l" ] && continue
		t=$(dirname "${md#$doc/}")/$l
		t=${t#./}
		case " $(echo $dev) " in *" $t "*) continue ;; esac
		fail "broken link in ${md#$doc/}: $l"
	done
done

re() { (cd "$tmp/elsewhere" && ROBOELF_ROOT=$root "$root/usr/bin/roboelf" "$@" </dev/null); }
# the installed configuration is the site template, refused until filled
# in, with every value to fill in listed (the exact list: test_re_config)
cfg=$root/etc/roboelf/roboelf.yaml
cmp -s "$cfg" config/roboelf-site.yaml || fail "the installed configuration is not config/roboelf-site.yaml"
out=$(re --calibration file 2>&1)
rc=$?
n=$(grep -c '^ *[a-z_]*: FILL-IN$' "$cfg")
line=$(grep -n '^  address: FILL-IN$' "$cfg" | cut -d: -f1)
[ "$n" -gt 30 ] && [ -n "$line" ] || fail "the template's FILL-INs: $n, address at '$line'"
want="roboelf: ROBOELF_ROOT=$root: the installed files are looked for under it
$cfg: this site's configuration is not finished: $n values are still FILL-IN
$cfg:$line:12: 'controller.address' is still FILL-IN"
[ $rc -eq 2 ] || fail "the template: exit $rc: $out"
[ "$(printf '%s\n' "$out" | head -3)" = "$want" ] || fail "the template: '$out'"
[ "$(printf '%s\n' "$out" | grep -c "^$cfg:[0-9]*:[0-9]*: '[][a-z_.0-9]*' is still FILL-IN$")" = "$n" ] &&
	[ "$(printf '%s\n' "$out" | wc -l)" = $((n + 2)) ] || fail "the template: not every FILL-IN listed: $out"
# galil-load seals the program with it: refused as well
out=$(cd "$tmp/elsewhere" && ROBOELF_ROOT=$root "$root/usr/bin/galil-load" --check 2>&1)
rc=$?
[ $rc -eq 2 ] || fail "galil-load --check with the template: exit $rc: $out"
printf '%s\n' "$out" | grep -qxF "galil-load: cannot seal the program with '$cfg': $cfg: this site's configuration is not finished: $n values are still FILL-IN" ||
	fail "galil-load --check with the template: $out"
# filled in with the values of the source tree's configuration
sed -i -e 's|^\(  address:\) FILL-IN$|\1 "192.0.2.1"|' -e 's|^\(  power_output:\) FILL-IN$|\1 0|' \
	-e 's|^\(  port_clinical:\) FILL-IN$|\1 /dev/roboelf-relay|' -e 's|^\(  serial:\) FILL-IN$|\1 A10KXYZ9|' \
	-e 's|^\(  protocol:\) FILL-IN$|\1 devantech|' \
	-e 's|^\(  channel:\) FILL-IN$|\1 1|' -e 's|^\(  inputs:\) FILL-IN$|\1 [1, 2, 3, 4, 5, 6, 7, 8, 17, 18, 19, 20]|' \
	-e 's|^\(  active_low:\) FILL-IN$|\1 false|' -e 's|^\( *vmax:\) FILL-IN$|\1 8000|' \
	-e 's|^\( *travel_counts:\) FILL-IN$|\1 100000|' -e 's|^\( *kp:\) FILL-IN$|\1 6|' -e 's|^\( *ki:\) FILL-IN$|\1 1|' \
	-e 's|^\( *kd:\) FILL-IN$|\1 64|' -e 's|^\( *torque_limit_v:\) FILL-IN$|\1 5.0|' \
	-e 's|^\( *expected_range_v:\) FILL-IN$|\1 4.0|' -e 's|^\( *reverse_v:\) FILL-IN$|\1 0.5|' \
	-e 's|^\( *forward_v:\) FILL-IN$|\1 4.5|' "$cfg"
# C's travel as in the source tree's configuration: the same seal, so the
# same identity as its dmc/ (below)
sed -i '/^  - name: C$/,/travel_counts/ s/^\(    travel_counts:\) 100000$/\1 80000/' "$cfg"
grep -v '^ *#' "$cfg" | grep -q FILL-IN && fail "a FILL-IN left: $(grep -n FILL-IN "$cfg")"
# galil-load: no files -> the installed DMC; the identity is the source tree's
want_id=$("$BUILD/bin/galil-load" --check dmc | sed -n "s/.*identity line '\(.*\)'/\1/p")
[ -n "$want_id" ] || fail "no identity from galil-load --check dmc"
gl() { (cd "$tmp/elsewhere" && ROBOELF_ROOT=$root "$root/usr/bin/galil-load" "$@"); }
out=$(gl --check 2>"$tmp/err") || fail "galil-load --check: exit $?: $(cat "$tmp/err")"
first=$(printf '%s\n' "$out" | head -1)
[ "$first" = "DMC programs: $root/usr/share/roboelf/dmc (no files given)" ] || fail "galil-load --check: '$first'"
printf '%s\n' "$out" | grep -qF "identity line '$want_id'" || fail "galil-load --check: identity: $out"
[ "$(cat "$tmp/err")" = "galil-load: ROBOELF_ROOT=$root: the installed files are looked for under it" ] ||
	fail "galil-load: ROBOELF_ROOT notice: '$(cat "$tmp/err")'"
version=$(sed -n 's/^#define ROBOELF_VERSION[ \t]*"\(.*\)"/\1/p' pc/base/base_version.h)
iface=$(sed -n 's/^#define ROBOELF_DMC_VERSION[ \t]*"\(.*\)"/\1/p' pc/base/base_version.h)
want="galil-load $version (controller program interface $iface, dmc/constants.dmc vers)
DMC programs: $root/usr/share/roboelf/dmc, identity '$want_id'"
out=$(gl --version 2>/dev/null) || fail "galil-load --version: exit $?"
[ "$out" = "$want" ] || fail "galil-load --version: '$out'"
# --dmc wins over the installed programs
out=$(gl --check --dmc "$TOP/tests/data/dmc_good/split" 2>&1) || fail "--dmc: exit $?: $out"
case $out in *"DMC programs:"* | *"$want_id"*) fail "--dmc did not win: $out" ;; esac
# nothing installed under the root: the message names both places
out=$(cd "$tmp/elsewhere" && ROBOELF_ROOT=$tmp/none "$root/usr/bin/galil-load" --check 2>&1)
rc=$?
[ $rc -eq 2 ] || fail "no DMC: exit $rc"
want="galil-load: no program files and no commands, and no DMC programs: neither dmc/MANIFEST here nor $tmp/none/usr/share/roboelf/dmc/MANIFEST"
[ "$(printf '%s\n' "$out" | head -1)" = "$want" ] || fail "no DMC: '$out'"

# roboelf: --version names the installed configuration and DMC programs
want="roboelf $version (controller program interface $iface, dmc/constants.dmc vers)
configuration: $root/etc/roboelf/roboelf.yaml
DMC programs: $root/usr/share/roboelf/dmc"
out=$(re --version 2>/dev/null) || fail "roboelf --version: exit $?"
[ "$out" = "$want" ] || fail "roboelf --version: '$out'"
# the filled-in configuration loads: clinical, so ROBOELF_ROOT is refused,
# before anything is opened
out=$(re --calibration file 2>&1)
rc=$?
want="roboelf: ROBOELF_ROOT=$root: the installed files are looked for under it
roboelf: error: ROBOELF_ROOT is set: refused in clinical mode (it is for testing a staged installation); unset it"
[ $rc -eq 2 ] && [ "$out" = "$want" ] || fail "clinical with ROBOELF_ROOT: exit $rc: '$out'"
# the installed configuration is the one read: an edit shows in the error
sed -i 's/^period_ms: .*/period_ms: 1/' "$cfg"
line=$(grep -n '^period_ms: 1$' "$cfg" | cut -d: -f1)
[ -n "$line" ] || fail "no period_ms line in the installed configuration"
out=$(re --calibration file 2>&1)
rc=$?
[ $rc -eq 2 ] || fail "edited configuration: exit $rc: $out"
printf '%s\n' "$out" | grep -q "^$cfg:$line:" || fail "edited configuration not read: $out"
# -c wins
printf 'period_ms: 0\n' >"$tmp/mine.yaml"
out=$(re -c "$tmp/mine.yaml" --calibration file 2>&1)
printf '%s\n' "$out" | grep -q "^$tmp/mine.yaml:1:" || fail "-c did not win: $out"
# a second install keeps the edited configuration
make -s --no-print-directory BUILD="$BUILD" install DESTDIR="$root" PREFIX=/usr \
	>"$tmp/make.log" 2>&1 || { cat "$tmp/make.log"; fail "second make install"; }
grep -q '^period_ms: 1$' "$cfg" || fail "the second install replaced the edited configuration"
echo "install: ok"
