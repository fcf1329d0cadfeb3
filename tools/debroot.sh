#!/bin/sh
# debroot.sh - minimal Debian 12 roots for the tests that need a machine of
# their own (make fresh; docs/commands.md). Root only.
#
#   debroot.sh base DIR         DIR/base: debootstrap --variant=minbase
#                               bookworm plus gcc and make (README's fresh
#                               machine), built once and then kept pristine;
#                               a half-built one (no DIR/base.done) is made
#                               again
#   debroot.sh copy DIR NAME    DIR/NAME made afresh as a copy of DIR/base:
#                               nothing a previous run installed survives
#   debroot.sh run ROOT CMD...  CMD inside ROOT (chroot), in a mount
#                               namespace of its own with /proc, /sys, /dev,
#                               /dev/pts, /run and /tmp mounted and this
#                               machine's resolv.conf; the mounts end with it
#
# MIRROR overrides the Debian mirror (default http://deb.debian.org/debian).
# Exit: CMD's status for run; 0, or 1 with a message.
set -u
MIRROR=${MIRROR:-http://deb.debian.org/debian}
SUITE=bookworm
die() { echo "debroot: $*" >&2; exit 1; }
[ "$(id -u)" = 0 ] || die "needs root (debootstrap, chroot, mount)"

case ${1:-} in
base)
	[ $# -eq 2 ] || die "usage: debroot.sh base DIR"
	dir=$2
	[ -e "$dir/base.done" ] && exit 0
	rm -rf "$dir/base" "$dir/base.done" && mkdir -p "$dir" || die "cannot make $dir"
	echo "debroot: building the pristine Debian $SUITE root in $dir/base (once)"
	# debootstrap runs helpers of its own (perl, wget, ...), which its
	# package depends on: the system's PATH (docs/commands.md)
	PATH=${ROBOELF_SYSPATH:-$PATH} debootstrap --variant=minbase \
		--include=gcc,make "$SUITE" "$dir/base" "$MIRROR" \
		>"$dir/base.log" 2>&1 ||
		die "debootstrap failed: the end of $dir/base.log: $(tail -n 3 "$dir/base.log")"
	touch "$dir/base.done"
	;;
copy)
	[ $# -eq 3 ] || die "usage: debroot.sh copy DIR NAME"
	[ -e "$2/base.done" ] || die "no base in $2 (debroot.sh base $2)"
	rm -rf "${2:?}/$3" || die "cannot remove $2/$3"
	cp -a "$2/base" "$2/$3" || die "cannot copy $2/base to $2/$3"
	;;
run)
	[ $# -ge 3 ] || die "usage: debroot.sh run ROOT CMD..."
	root=$(cd "$2" && pwd) || die "no root $2"
	shift 2
	cp /etc/resolv.conf "$root/etc/resolv.conf" 2>/dev/null
	# shellcheck disable=SC2016
	exec unshare --mount --propagation private sh -c '
		r=$1; shift
		# the root a mount point of its own: "ip netns exec" remounts
		# / as a slave, which a plain directory refuses
		mount --bind "$r" "$r" &&
		mount -t proc proc "$r/proc" &&
		mount -t sysfs sys "$r/sys" &&
		mount --rbind /dev "$r/dev" &&
		mount -t tmpfs run "$r/run" &&
		mount -t tmpfs tmp "$r/tmp" || exit 1
		exec chroot "$r" /usr/bin/env -i HOME=/root TERM="${TERM:-dumb}" \
			PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
			LANG=C.UTF-8 "$@"' debroot "$root" "$@"
	;;
*)
	die "usage: debroot.sh base DIR | copy DIR NAME | run ROOT CMD..."
	;;
esac
