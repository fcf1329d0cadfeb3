#!/bin/sh
# have-deps.sh - before compiling (make, make tests, make install, make deb)
# or linting (make lint): name the Debian packages that are missing and the
# command that installs them, instead of letting the compiler fail on a
# missing header. Exit 0 when nothing is missing, 1 otherwise.
#
#   have-deps.sh build   the compiler, pkg-config and the libraries
#   have-deps.sh lint    clang-format and cppcheck
#
# Environment (the Makefile passes its own values): CC, PKG_CONFIG,
# CLANG_FORMAT, CPPCHECK.
set -u
missing=""
add() { missing="$missing $1"; }
case ${1:-build} in
build)
	command -v "${CC:-cc}" >/dev/null 2>&1 || add gcc
	pc=${PKG_CONFIG:-pkg-config}
	if ! command -v "$pc" >/dev/null 2>&1; then
		add pkgconf
		# without pkg-config the libraries cannot be asked for
		add libserialport-dev; add libyaml-dev; add libcmocka-dev
	else
		"$pc" --exists libserialport 2>/dev/null || add libserialport-dev
		"$pc" --exists yaml-0.1 2>/dev/null || add libyaml-dev
		"$pc" --exists cmocka 2>/dev/null || add libcmocka-dev
	fi
	;;
lint)
	command -v "${CLANG_FORMAT:-clang-format}" >/dev/null 2>&1 || add clang-format
	command -v "${CPPCHECK:-cppcheck}" >/dev/null 2>&1 || add cppcheck
	;;
*) echo "usage: have-deps.sh build|lint" >&2; exit 2 ;;
esac
[ -z "$missing" ] && exit 0
echo "make: missing Debian packages:$missing" >&2
echo "make: install them with 'make deps' (as root), or run: sudo apt-get install --no-install-recommends$missing" >&2
exit 1
