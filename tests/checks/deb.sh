#!/bin/sh
# deb.sh - the Debian packages: `make deb` builds
# $BUILD/roboelf_<version>_<arch>.deb and $BUILD/roboelf-sim_<version>_<arch>.deb;
# `dpkg -c` lists exactly the files each should hold (roboelf: the
# operator's and technician's programs, man pages and manuals, the DMC
# programs, the conffiles /etc/roboelf/roboelf.yaml - the site template
# config/roboelf-site.yaml, which the packaged roboelf refuses until it is
# filled in -, the group's real-time limits and the link's ifupdown hook,
# the relay's udev rules file (no rule: it names no board until
# roboelf-tech bind-relay binds one), /var/lib/roboelf and /var/log/roboelf; roboelf-sim:
# galil-sim, its man page, the development configuration, plant.yaml and
# the demo; no developer document in either), all owned by root;
# roboelf-sim depends on roboelf of the same version and gnuplot, roboelf
# recommends gnuplot (roboelf-tech's plots); the packaged
# galil-load finds the packaged DMC programs; the postinst creates the
# group roboelf once and gives it the state directories (2770), unless
# dpkg-statoverride holds them; the postrm's purge removes them only when
# empty (both run against stand-in commands and directories, never on this
# machine's); lintian reports no error on either. lintian comes from `make
# deps`: a missing lintian is a failure, not a skip.
set -u
cd "$(dirname "$0")/../.." || exit 1
BUILD=${BUILD:-build}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fail() { echo "deb: FAIL: $*"; exit 1; }
command -v lintian >/dev/null || fail "lintian is not installed (make deps installs it)"
command -v dpkg-deb >/dev/null || fail "dpkg-deb is not installed (make deps installs dpkg-dev)"

version=$(sed -n 's/^#define ROBOELF_VERSION[ \t]*"\(.*\)"/\1/p' pc/base/base_version.h)
arch=$(dpkg --print-architecture)
deb=$BUILD/roboelf_${version}_$arch.deb
sim=$BUILD/roboelf-sim_${version}_$arch.deb
make -s --no-print-directory BUILD="$BUILD" deb >"$tmp/make.log" 2>&1 ||
	{ cat "$tmp/make.log"; fail "make deb"; }
[ "$(cat "$tmp/make.log")" = "deb: $deb
deb: $sim" ] || fail "make deb said: $(cat "$tmp/make.log")"
[ -f "$deb" ] && [ -f "$sim" ] || fail "no $deb or $sim"

# files(DEB): its files and links, one path a line (directories left out)
files() { dpkg -c "$1" | awk '$1 !~ /^d/ {print $6}'; }
dmc=$(for f in dmc/MANIFEST dmc/*.dmc; do echo "./usr/share/roboelf/$f"; done | LC_ALL=C sort)
want="./etc/network/if-up.d/roboelf
./etc/roboelf/roboelf.yaml
./etc/security/limits.d/roboelf.conf
./lib/udev/rules.d/60-roboelf-relay.rules
./usr/bin/galil-load
./usr/bin/roboelf
./usr/bin/roboelf-tech
./usr/share/doc/roboelf/README.md
./usr/share/doc/roboelf/changelog.gz
./usr/share/doc/roboelf/copyright
./usr/share/doc/roboelf/docs/calibration-file.md
./usr/share/doc/roboelf/docs/config.md
./usr/share/doc/roboelf/docs/dmc-interface.md
./usr/share/doc/roboelf/docs/galil-load.md
./usr/share/doc/roboelf/docs/galil-sim-controller.md
./usr/share/doc/roboelf/docs/galil-sim.md
./usr/share/doc/roboelf/docs/link.md
./usr/share/doc/roboelf/docs/operator.md
./usr/share/doc/roboelf/docs/safety.md
./usr/share/doc/roboelf/docs/supervisor.md
./usr/share/doc/roboelf/docs/technician.md
./usr/share/doc/roboelf/docs/trace-demo-pot-B.png
./usr/share/doc/roboelf/docs/trace-format.md
./usr/share/man/man1/galil-load.1.gz
./usr/share/man/man1/roboelf-tech.1.gz
./usr/share/man/man1/roboelf.1.gz
./usr/share/man/man5/roboelf.yaml.5.gz
./usr/share/roboelf/config/roboelf-site.yaml
$dmc"
[ "$(files "$deb" | LC_ALL=C sort)" = "$(printf '%s\n' "$want" | LC_ALL=C sort)" ] ||
	fail "roboelf's files: $(files "$deb" | LC_ALL=C sort)"
want="./usr/bin/galil-sim
./usr/share/doc/roboelf-sim/changelog.gz
./usr/share/doc/roboelf-sim/copyright
./usr/share/man/man1/galil-sim.1.gz
./usr/share/roboelf/config/plant.yaml
./usr/share/roboelf/config/roboelf.yaml
./usr/share/roboelf/demo.sh"
[ "$(files "$sim")" = "$want" ] || fail "roboelf-sim's files: $(files "$sim")"
dpkg -c "$deb" >"$tmp/list" || fail "dpkg -c"
dpkg -c "$sim" >>"$tmp/list" || fail "dpkg -c"
awk '$2 != "root/root" {print; bad=1} END {exit bad}' "$tmp/list" || fail "files not owned by root"
for p in ./usr/bin/roboelf ./usr/bin/galil-sim ./usr/share/roboelf/demo.sh ./etc/network/if-up.d/roboelf; do
	grep -q "^-rwxr-xr-x .* $p\$" "$tmp/list" || fail "$p is not 0755"
done
for d in ./var/lib/roboelf/ ./var/log/roboelf/; do # 0755 as packaged: the postinst sets 2770
	grep -q "^drwxr-xr-x .* $d\$" "$tmp/list" || fail "no directory $d (0755)"
done

[ "$(dpkg-deb -f "$deb" Package)" = roboelf ] || fail "Package"
[ "$(dpkg-deb -f "$deb" Version)" = "$version" ] || fail "Version"
[ "$(dpkg-deb -f "$sim" Package)" = roboelf-sim ] || fail "Package of roboelf-sim"
case $(dpkg-deb -f "$sim" Depends) in
*", roboelf (= $version), gnuplot-nox | gnuplot") ;; # the demo draws its trace
*) fail "roboelf-sim's Depends: $(dpkg-deb -f "$sim" Depends)" ;;
esac
[ "$(dpkg-deb -f "$deb" Recommends)" = "gnuplot-nox | gnuplot" ] ||
	fail "roboelf's Recommends: $(dpkg-deb -f "$deb" Recommends)"
dpkg-deb -e "$deb" "$tmp/ctl" || fail "dpkg-deb -e"
[ "$(cat "$tmp/ctl/conffiles")" = "/etc/roboelf/roboelf.yaml
/etc/security/limits.d/roboelf.conf
/etc/network/if-up.d/roboelf" ] || fail "conffiles: $(cat "$tmp/ctl/conffiles")"

dpkg-deb -x "$deb" "$tmp/x" || fail "dpkg-deb -x"
dpkg-deb -x "$sim" "$tmp/x" || fail "dpkg-deb -x roboelf-sim"
cmp -s "$tmp/x/etc/network/if-up.d/roboelf" packaging/ifupdown/roboelf ||
	fail "the ifupdown hook is not packaging/ifupdown/roboelf"
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
# the conffile's state in its place (the directories the postinst gives
# to the group)
[ "$(grep -E '^  (file|path): ' "$tmp/x/etc/roboelf/roboelf.yaml")" = "  file: /var/lib/roboelf/roboelf-calibration.txt
  path: /var/log/roboelf/roboelf.log" ] || fail "the conffile's calibration file and log"
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

# the postinst, twice, with stand-ins for getent, groupadd, udevadm,
# dpkg-statoverride, chown and chmod (this machine's groups and
# directories are never touched); the second time an administrator's
# statoverride holds /var/log/roboelf
mkdir "$tmp/bin"
cat >"$tmp/bin/getent" <<EOS
#!/bin/sh
[ "\$1 \$2" = "group roboelf" ] && grep -qx roboelf "$tmp/groups"
EOS
cat >"$tmp/bin/groupadd" <<EOS
#!/bin/sh
echo "groupadd \$*" >>"$tmp/calls"; echo "\$2" >>"$tmp/groups"
EOS
cat >"$tmp/bin/dpkg-statoverride" <<EOS
#!/bin/sh
[ "\$1" = --list ] && grep -qxF "\$2" "$tmp/overrides"
EOS
for c in udevadm chown chmod rmdir; do
	printf '#!/bin/sh\necho "%s $*" >>"%s/calls"\n' "$c" "$tmp" >"$tmp/bin/$c"
done
chmod +x "$tmp/bin/"*
: >"$tmp/groups"
: >"$tmp/overrides"
calls() { grep -v '^udevadm ' "$tmp/calls"; }
PATH=$tmp/bin:$PATH sh "$tmp/ctl/postinst" configure || fail "postinst run 1: exit $?"
[ "$(calls)" = "groupadd --system roboelf
chown root:roboelf /var/lib/roboelf
chmod 2770 /var/lib/roboelf
chown root:roboelf /var/log/roboelf
chmod 2770 /var/log/roboelf" ] || fail "postinst run 1: $(cat "$tmp/calls")"
: >"$tmp/calls"
echo /var/log/roboelf >"$tmp/overrides"
PATH=$tmp/bin:$PATH sh "$tmp/ctl/postinst" configure || fail "postinst run 2: exit $?"
[ "$(calls)" = "chown root:roboelf /var/lib/roboelf
chmod 2770 /var/lib/roboelf" ] || fail "postinst run 2: $(cat "$tmp/calls")"
# the postrm: remove keeps everything; purge removes empty directories only
: >"$tmp/calls"
PATH=$tmp/bin:$PATH sh "$tmp/ctl/postrm" remove || fail "postrm remove: exit $?"
[ ! -s "$tmp/calls" ] || fail "postrm remove: $(cat "$tmp/calls")"
PATH=$tmp/bin:$PATH sh "$tmp/ctl/postrm" purge || fail "postrm purge: exit $?"
[ "$(cat "$tmp/calls")" = "rmdir /var/lib/roboelf
rmdir /var/log/roboelf" ] || fail "postrm purge: $(cat "$tmp/calls")"

# lintian runs helpers of its own (nproc, file, ...), which its package
# depends on: it gets the system's PATH back (docs/commands.md)
PATH=${ROBOELF_SYSPATH:-$PATH} lintian "$deb" "$sim" >"$tmp/lintian" 2>&1
rc=$?
grep -v 'running with root privileges' "$tmp/lintian"
grep -q '^E: ' "$tmp/lintian" && fail "lintian reports errors"
[ $rc -eq 0 ] || fail "lintian: exit $rc"
echo "deb: ok"
