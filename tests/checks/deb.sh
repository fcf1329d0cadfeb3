#!/bin/sh
# deb.sh - the Debian package: `make deb` builds
# $BUILD/roboelf_<version>_<arch>.deb; `dpkg -c` lists the programs, the man
# pages, the conffiles /etc/roboelf/roboelf.yaml (the site template
# config/roboelf-site.yaml, which the packaged roboelf refuses until it is
# filled in) and the group's real-time limits, the DMC programs, the docs
# tree and the relay's udev rules file (no rule: it names no board until
# roboelf-tech bind-relay binds one), all owned by root; the packaged galil-load
# finds the packaged DMC programs; the postinst creates the group roboelf
# once (run twice against stand-in commands, never on this machine's
# groups); lintian reports no error. lintian comes from `make deps`: a
# missing lintian is a failure, not a skip.
set -u
cd "$(dirname "$0")/../.." || exit 1
BUILD=${BUILD:-build}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fail() { echo "deb: FAIL: $*"; exit 1; }
command -v lintian >/dev/null || fail "lintian is not installed (make deps installs it)"
command -v dpkg-deb >/dev/null || fail "dpkg-deb is not installed (make deps installs dpkg-dev)"

version=$(sed -n 's/^#define ROBOELF_VERSION[ \t]*"\(.*\)"/\1/p' pc/base/base_version.h)
deb=$BUILD/roboelf_${version}_$(dpkg --print-architecture).deb
make -s --no-print-directory BUILD="$BUILD" deb >"$tmp/make.log" 2>&1 ||
	{ cat "$tmp/make.log"; fail "make deb"; }
[ "$(cat "$tmp/make.log")" = "deb: $deb" ] || fail "make deb said: $(cat "$tmp/make.log")"
[ -f "$deb" ] || fail "no $deb"

dpkg -c "$deb" >"$tmp/list" || fail "dpkg -c"
awk '{print $6}' "$tmp/list" >"$tmp/paths"
for p in ./usr/bin/roboelf ./usr/bin/roboelf-tech ./usr/bin/galil-load ./usr/bin/galil-sim \
	./usr/share/man/man1/roboelf.1.gz ./usr/share/man/man1/roboelf-tech.1.gz ./usr/share/man/man1/galil-load.1.gz \
	./usr/share/man/man1/galil-sim.1.gz ./usr/share/man/man5/roboelf.yaml.5.gz \
	./etc/roboelf/roboelf.yaml ./etc/security/limits.d/roboelf.conf \
	./usr/share/roboelf/dmc/MANIFEST \
	./usr/share/roboelf/dmc/constants.dmc ./usr/share/roboelf/dmc/roboelf.dmc \
	./usr/share/roboelf/config/plant.yaml ./usr/share/roboelf/config/roboelf.yaml \
	./usr/share/roboelf/config/roboelf-site.yaml ./lib/udev/rules.d/60-roboelf-relay.rules \
	./usr/share/doc/roboelf/copyright ./usr/share/doc/roboelf/changelog.gz \
	./usr/share/doc/roboelf/README.md ./usr/share/doc/roboelf/docs/technician.md; do
	grep -qxF "$p" "$tmp/paths" || fail "dpkg -c: no $p"
done
grep -q 'galil-stub' "$tmp/paths" && fail "dpkg -c: the test stub is packaged"
awk '$2 != "root/root" {print; bad=1} END {exit bad}' "$tmp/list" || fail "files not owned by root"
grep -q '^-rwxr-xr-x .*\./usr/bin/roboelf$' "$tmp/list" || fail "roboelf is not 0755"

[ "$(dpkg-deb -f "$deb" Package)" = roboelf ] || fail "Package"
[ "$(dpkg-deb -f "$deb" Version)" = "$version" ] || fail "Version"
dpkg-deb -e "$deb" "$tmp/ctl" || fail "dpkg-deb -e"
[ "$(cat "$tmp/ctl/conffiles")" = "/etc/roboelf/roboelf.yaml
/etc/security/limits.d/roboelf.conf" ] || fail "conffiles: $(cat "$tmp/ctl/conffiles")"

dpkg-deb -x "$deb" "$tmp/x" || fail "dpkg-deb -x"
# the packaged udev rules file names no board (no rule at all: every line a
# comment) until the technician binds one (roboelf-tech bind-relay), and
# says so
rules=$tmp/x/lib/udev/rules.d/60-roboelf-relay.rules
grep -v '^#' "$rules" | grep -q . && fail "the packaged udev rules file has a rule: $(grep -v '^#' "$rules")"
grep -qF '#     roboelf-tech bind-relay' "$rules" || fail "the packaged udev rules file does not say how to bind the relay"
[ "$(grep -v '^#' "$tmp/x/etc/security/limits.d/roboelf.conf")" = "$(printf '@roboelf\t-\trtprio\t60\n@roboelf\t-\tmemlock\tunlimited')" ] ||
	fail "limits: $(cat "$tmp/x/etc/security/limits.d/roboelf.conf")"
cmp -s "$tmp/x/etc/roboelf/roboelf.yaml" config/roboelf-site.yaml ||
	fail "the conffile is not the site template config/roboelf-site.yaml"
cmp -s "$tmp/x/usr/share/roboelf/config/roboelf.yaml" config/roboelf.yaml ||
	fail "/usr/share/roboelf/config/roboelf.yaml is not the development configuration"
# the packaged roboelf refuses the conffile as installed (every FILL-IN
# listed: install.sh, test_re_config)
cfg=$tmp/x/etc/roboelf/roboelf.yaml
n=$(grep -c '^ *[a-z_]*: FILL-IN$' "$cfg")
out=$(cd "$tmp" && ROBOELF_ROOT=$tmp/x "$tmp/x/usr/bin/roboelf" --calibration file 2>&1 </dev/null)
rc=$?
[ $rc -eq 2 ] || fail "packaged roboelf with the conffile: exit $rc: $out"
[ "$(printf '%s\n' "$out" | sed -n 2p)" = "$cfg: this site's configuration is not finished: $n values are still FILL-IN" ] ||
	fail "packaged roboelf with the conffile: $out"
# built for /usr: the packaged galil-load finds the packaged DMC programs
# (sealed with the packaged development configuration: the conffile is
# refused until filled in, and the identity includes the seal)
out=$(cd "$tmp" && ROBOELF_ROOT=$tmp/x "$tmp/x/usr/bin/galil-load" --version \
	--config "$tmp/x/usr/share/roboelf/config/roboelf.yaml" 2>/dev/null | sed -n 2p)
case $out in "DMC programs: $tmp/x/usr/share/roboelf/dmc, identity 'NO ID "*"'") ;;
*) fail "packaged galil-load --version: '$out'" ;; esac

# the postinst, twice, with stand-ins for getent, groupadd and udevadm
mkdir "$tmp/bin"
cat >"$tmp/bin/getent" <<EOS
#!/bin/sh
[ "\$1 \$2" = "group roboelf" ] && grep -qx roboelf "$tmp/groups"
EOS
cat >"$tmp/bin/groupadd" <<EOS
#!/bin/sh
echo "groupadd \$*" >>"$tmp/calls"; echo "\$2" >>"$tmp/groups"
EOS
printf '#!/bin/sh\necho "udevadm $*" >>"%s/calls"\n' "$tmp" >"$tmp/bin/udevadm"
chmod +x "$tmp/bin/"*
: >"$tmp/groups"
for i in 1 2; do
	PATH=$tmp/bin:$PATH sh "$tmp/ctl/postinst" configure || fail "postinst run $i: exit $?"
done
[ "$(grep -c '^groupadd --system roboelf$' "$tmp/calls")" = 1 ] || fail "postinst: $(cat "$tmp/calls")"

# lintian runs helpers of its own (nproc, file, ...), which its package
# depends on: it gets the system's PATH back (docs/commands.md)
PATH=${ROBOELF_SYSPATH:-$PATH} lintian "$deb" >"$tmp/lintian" 2>&1
rc=$?
grep -v 'running with root privileges' "$tmp/lintian"
grep -q '^E: ' "$tmp/lintian" && fail "lintian reports errors"
[ $rc -eq 0 ] || fail "lintian: exit $rc"
echo "deb: ok"
