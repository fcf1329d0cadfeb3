#!/bin/sh
# fresh.sh - make fresh: README's promise tried where nothing else was
# installed. A minimal Debian 12 root (tools/debroot.sh: debootstrap
# --variant=minbase with gcc and make, built once and kept pristine) is
# copied afresh, the current commit is cloned into it (what is not committed
# is not tried), and README's two commands run there as root: `make demo`,
# then `make check`. Its output goes to $BUILD/fresh/run.log; the last line
# is make check's "N passed, N failed, N skipped", then the time.
#
# Not root: "SKIPPED" with the reason and exit 77 (never a pass).
# Exit: 0 when both commands passed; 1 otherwise.
set -u
BUILD=${BUILD:-build}
TOP=$(cd "$(dirname "$0")/.." && pwd) || exit 1
cd "$TOP" || exit 1
if [ "$(id -u)" != 0 ]; then
	echo "fresh: SKIPPED: needs root (debootstrap and chroot); run make fresh as root"
	exit 77
fi
dir=$TOP/$BUILD/fresh
start=$(date +%s)
sh tools/debroot.sh base "$dir" || exit 1
sh tools/debroot.sh copy "$dir" run || exit 1
commit=$(git rev-parse HEAD) || exit 1
[ -z "$(git status --porcelain --untracked-files=no)" ] ||
	echo "fresh: the work tree has changes that are not committed: they are not tried"
git clone --quiet --no-hardlinks "$TOP" "$dir/run/root/roboelf" &&
	git -C "$dir/run/root/roboelf" checkout --quiet --detach "$commit" || {
	echo "fresh: cannot clone $TOP into the root"
	exit 1
}
echo "fresh: commit $commit in a fresh Debian 12 root ($dir/run); output in $dir/run.log"
# README's commands, as written there: demo, then check
sh tools/debroot.sh run "$dir/run" sh -c \
	'cd /root/roboelf && make demo && echo "fresh: make demo passed" && make check' \
	>"$dir/run.log" 2>&1
rc=$?
secs=$(($(date +%s) - start))
echo "fresh: $( [ "$rc" -eq 0 ] && echo passed || echo "FAILED (exit $rc; $dir/run.log)") in $((secs / 60)) min $((secs % 60)) s"
grep -q '^fresh: make demo passed$' "$dir/run.log" || echo "fresh: make demo FAILED"
grep -E '^fresh: make demo passed$|^failed:|^[0-9]+ passed, [0-9]+ failed, [0-9]+ skipped$' "$dir/run.log"
[ "$rc" -eq 0 ]
