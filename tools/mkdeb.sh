#!/bin/sh
# mkdeb.sh - make deb: the Debian package $BUILD/roboelf_<version>_<arch>.deb,
# built with the standard Debian tools (dpkg-buildflags, dpkg-shlibdeps,
# dpkg-deb) from packaging/deb/ (docs/technician.md,
# "Installation").
#
# The programs are built again with the Debian build flags (hardening, and
# --as-needed so only the libraries used are depended on) in $BUILD/deb/build,
# installed with PREFIX=/usr into $BUILD/deb/root, stripped; the man pages
# and the changelog compressed; the copyright, the relay's udev rules file
# (which names no board: roboelf-tech bind-relay binds one), the
# group's real-time limits, the conffile list and the postinst added; then dpkg-deb builds the package
# (root-owned files, no fakeroot needed).
set -eu
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
MAKE=${MAKE:-make}
MAINTAINER=${DEB_MAINTAINER:-RoboELF maintainers <roboelf@example.org>}
PKG=packaging/deb
DEB=$BUILD/deb
root=$DEB/root
version=$(sed -n 's/^#define ROBOELF_VERSION[ \t]*"\(.*\)"/\1/p' pc/base/base_version.h)
arch=$(dpkg --print-architecture)
out=$BUILD/roboelf_${version}_${arch}.deb
[ -n "$version" ] || { echo "mkdeb: no ROBOELF_VERSION in pc/base/base_version.h" >&2; exit 1; }

rm -rf "$root" "$out"
mkdir -p "$root" "$DEB/shlibs/debian"
abs_root=$(cd "$root" && pwd)

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
doc=$root/usr/share/doc/roboelf
install -m 644 "$PKG/copyright" "$doc/copyright"
date=$(git log -1 --format=%cD 2>/dev/null || date -R)
printf 'roboelf (%s) unstable; urgency=medium\n\n  * Release %s (README.md, docs/).\n\n -- %s  %s\n' \
	"$version" "$version" "$MAINTAINER" "$date" | gzip -9n >"$doc/changelog.gz"

# the relay's udev rules file: no rule until the technician binds the
# board by its serial number (roboelf-tech bind-relay writes the one in
# /etc/udev/rules.d, which masks this one)
install -D -m 644 "$PKG/60-roboelf-relay.rules.in" "$root/lib/udev/rules.d/60-roboelf-relay.rules"

# the operators' real-time limits (pam_limits)
install -D -m 644 "$PKG/limits.conf" "$root/etc/security/limits.d/roboelf.conf"

# the control files
printf 'Source: roboelf\n\nPackage: roboelf\nArchitecture: any\n' >"$DEB/shlibs/debian/control"
depends=$(cd "$DEB/shlibs" && dpkg-shlibdeps -O "$abs_root"/usr/bin/* 2>/dev/null |
	sed -n 's/^shlibs:Depends=//p')
[ -n "$depends" ] || { echo "mkdeb: dpkg-shlibdeps found no dependencies" >&2; exit 1; }
find "$root" -type d -exec chmod 755 {} +
find "$root" -type f -exec chmod 644 {} +
chmod 755 "$root"/usr/bin/*
mkdir "$root/DEBIAN"
size=$(du -sk "$root" | cut -f1)
sed -e "s/@VERSION@/$version/" -e "s/@ARCH@/$arch/" -e "s/@SIZE@/$size/" \
	-e "s/@DEPENDS@/$depends/" -e "s|@MAINTAINER@|$MAINTAINER|" \
	"$PKG/control.in" >"$root/DEBIAN/control"
install -m 644 "$PKG/conffiles" "$root/DEBIAN/conffiles"
install -m 755 "$PKG/postinst" "$root/DEBIAN/postinst"
(cd "$root" && find . -path ./DEBIAN -prune -o -type f -print | sed 's|^\./||' |
	LC_ALL=C sort | xargs md5sum) >"$DEB/md5sums"
install -m 644 "$DEB/md5sums" "$root/DEBIAN/md5sums"
dpkg-deb --root-owner-group -Zxz --build "$root" "$out" >/dev/null
echo "deb: $out"
