#!/bin/sh
# mkdeb.sh - make deb: the two Debian packages, built with the standard
# Debian tools (dpkg-buildflags, dpkg-shlibdeps, dpkg-deb) from packaging/deb/
# (docs/technician.md, "Installation"):
#   $BUILD/roboelf_<version>_<arch>.deb      the operator's and technician's:
#       roboelf, roboelf-tech, galil-load, the DMC programs, their man pages,
#       the manuals, the clinical template (conffile), the relay's udev rule,
#       the real-time limits, the link's ifupdown hook, /var/lib/roboelf and
#       /var/log/roboelf (2770 root:roboelf, set by the postinst)
#   $BUILD/roboelf-sim_<version>_<arch>.deb  the simulator: galil-sim, its
#       man page, the development configuration, galil-sim's robot
#       (plant.yaml) and the demo (/usr/share/roboelf/demo.sh); Depends:
#       roboelf of the same version (the demo runs roboelf and galil-load)
#       and gnuplot (it draws its trace); roboelf Recommends gnuplot
#
# The programs are built again with the Debian build flags (hardening, and
# --as-needed so only the libraries used are depended on) in $BUILD/deb/build,
# installed with PREFIX=/usr into $BUILD/deb/root, stripped; the man pages
# and the changelogs compressed; then the tree is split (SIM_FILES below go to
# roboelf-sim, the rest to roboelf); the copyright, the relay's udev rules file
# (which names no board: roboelf-tech bind-relay binds one), the
# group's real-time limits, the conffile list and the maintainer scripts
# added; then dpkg-deb builds each package (root-owned files, no fakeroot
# needed).
set -eu
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
MAKE=${MAKE:-make}
MAINTAINER=${DEB_MAINTAINER:-RoboELF maintainers <roboelf@example.org>}
PKG=packaging/deb
DEB=$BUILD/deb
root=$DEB/root
version=$(sed -n 's/^#define ROBOELF_VERSION[ \t]*"\(.*\)"/\1/p' pc/base/base_version.h)
# DEB_VERSION_SUFFIX (e.g. +rebuilt1): a later package of the same sources,
# for the package test's upgrade
[ -n "$version" ] && version=$version${DEB_VERSION_SUFFIX:-}
arch=$(dpkg --print-architecture)
out=$BUILD/roboelf_${version}_${arch}.deb
out_sim=$BUILD/roboelf-sim_${version}_${arch}.deb
sim=$DEB/sim
[ -n "$version" ] || { echo "mkdeb: no ROBOELF_VERSION in pc/base/base_version.h" >&2; exit 1; }

rm -rf "$root" "$sim" "$out" "$out_sim"
mkdir -p "$root" "$sim" "$DEB/shlibs/debian"
abs_root=$(cd "$root" && pwd)
abs_sim=$(cd "$sim" && pwd)

# the programs, with the Debian build flags, in their own build directory
# (the caller's make flags, e.g. a sanitizer build's, are not passed on)
export DEB_BUILD_MAINT_OPTIONS=hardening=+all
cflags="$(dpkg-buildflags --get CFLAGS) $(dpkg-buildflags --get CPPFLAGS)"
ldflags="$(dpkg-buildflags --get LDFLAGS) -Wl,--as-needed"
if ! env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL "$MAKE" -s --no-print-directory -j2 \
	BUILD="$DEB/build" PREFIX=/usr SYSCONFDIR=/etc SANITIZE= DEVELOPER= \
	CFLAGS="$cflags" LDFLAGS="$ldflags" DESTDIR="$abs_root" install \
	>"$DEB/make.log" 2>&1; then
	cat "$DEB/make.log" >&2
	echo "mkdeb: make install failed" >&2
	exit 1
fi

strip --remove-section=.comment --remove-section=.note --strip-unneeded \
	"$root"/usr/bin/*
gzip -9n "$root"/usr/share/man/man*/*

# the simulator's files to roboelf-sim, the same paths
SIM_FILES="usr/bin/galil-sim usr/share/man/man1/galil-sim.1.gz
usr/share/roboelf/config/roboelf.yaml usr/share/roboelf/config/plant.yaml
usr/share/roboelf/demo.sh"
for f in $SIM_FILES; do
	[ -f "$root/$f" ] || { echo "mkdeb: make install made no /$f" >&2; exit 1; }
	mkdir -p "$sim/$(dirname "$f")"
	mv "$root/$f" "$sim/$f"
done

# copyright and changelog, each package its own
date=$(git log -1 --format=%cD 2>/dev/null || date -R)
for p in roboelf roboelf-sim; do
	doc=$root/usr/share/doc/$p
	[ $p = roboelf ] || doc=$sim/usr/share/doc/$p
	mkdir -p "$doc"
	install -m 644 "$PKG/copyright" "$doc/copyright"
	printf '%s (%s) unstable; urgency=medium\n\n  * Release %s (README.md, docs/).\n\n -- %s  %s\n' \
		"$p" "$version" "$version" "$MAINTAINER" "$date" | gzip -9n >"$doc/changelog.gz"
done

# the relay's udev rules file: no rule until the technician binds the
# board by its serial number (roboelf-tech bind-relay writes the one in
# /etc/udev/rules.d, which masks this one)
install -D -m 644 "$PKG/60-roboelf-relay.rules.in" "$root/lib/udev/rules.d/60-roboelf-relay.rules"

# the operators' real-time limits (pam_limits)
install -D -m 644 "$PKG/limits.conf" "$root/etc/security/limits.d/roboelf.conf"

# the link's hook (ifupdown) comes from make install; the state
# directories are 0755 root:root in the package, the postinst gives them
# to the group
[ -f "$root/etc/network/if-up.d/roboelf" ] || { echo "mkdeb: no ifupdown hook" >&2; exit 1; }
[ -d "$root/var/lib/roboelf" ] && [ -d "$root/var/log/roboelf" ] ||
	{ echo "mkdeb: no /var/lib/roboelf or /var/log/roboelf" >&2; exit 1; }

# control(ROOT, TEMPLATE, DEPENDS): ROOT/DEBIAN/control and md5sums
control() {
	find "$1" -type d -exec chmod 00755 {} + # 00: the setgid bit cleared too
	find "$1" -type f -exec chmod 644 {} +
	for x in "$1"/usr/bin/* "$1"/etc/network/if-up.d/* "$1"/usr/share/roboelf/*.sh; do
		if [ -f "$x" ]; then chmod 755 "$x"; fi
	done
	mkdir "$1/DEBIAN"
	size=$(du -sk "$1" | cut -f1)
	sed -e "s/@VERSION@/$version/g" -e "s/@ARCH@/$arch/" -e "s/@SIZE@/$size/" \
		-e "s/@DEPENDS@/$3/" -e "s|@MAINTAINER@|$MAINTAINER|" \
		"$PKG/$2" >"$1/DEBIAN/control"
	(cd "$1" && find . -path ./DEBIAN -prune -o -type f -print | sed 's|^\./||' |
		LC_ALL=C sort | xargs md5sum) >"$1/DEBIAN/md5sums"
	chmod 644 "$1/DEBIAN/md5sums"
}
# shlibs(ROOT): the libraries its programs need (dpkg-shlibdeps)
shlibs() {
	printf 'Source: roboelf\n\nPackage: roboelf\nArchitecture: any\n' >"$DEB/shlibs/debian/control"
	d=$(cd "$DEB/shlibs" && dpkg-shlibdeps -O "$1"/usr/bin/* 2>/dev/null |
		sed -n 's/^shlibs:Depends=//p')
	[ -n "$d" ] || { echo "mkdeb: dpkg-shlibdeps found no dependencies in $1" >&2; exit 1; }
	echo "$d"
}
dep=$(shlibs "$abs_root")
dep_sim=$(shlibs "$abs_sim")
control "$root" control.in "$dep"
control "$sim" control-sim.in "$dep_sim"
install -m 644 "$PKG/conffiles" "$root/DEBIAN/conffiles"
install -m 755 "$PKG/postinst" "$root/DEBIAN/postinst"
install -m 755 "$PKG/postrm" "$root/DEBIAN/postrm"
dpkg-deb --root-owner-group -Zxz --build "$root" "$out" >/dev/null
dpkg-deb --root-owner-group -Zxz --build "$sim" "$out_sim" >/dev/null
echo "deb: $out"
echo "deb: $out_sim"
