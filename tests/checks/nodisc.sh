#!/bin/sh
# nodisc.sh - roboelf's operation never discovers controllers: it connects
# only to its configured address. Only the technician's commissioning run
# (roboelf-tech commission, tools/roboelf-tech) may offer the controllers
# that answer the discovery probe, on the technician's choice:
#   - gl_disc is named, outside pc/galil/gl_disc.[ch] (which defines it) and
#     galil-load's --find (tools/galil-load, a program of its own), only by
#     tools/roboelf-tech/re_comm_find.[ch];
#   - re_comm_find() is defined in tools/roboelf-tech/re_comm_find.c and
#     called only by the commissioning run's start (re_comm_start.c), and
#     re_comm_find.h is included only inside tools/roboelf-tech.
# Every C file under pc/ and tools/ is searched, at any depth.
cd "$(dirname "$0")/../.." || exit 1
D=tools/roboelf-tech
for f in $D/re_comm_find.c $D/re_comm_find.h $D/re_comm_start.c; do
	[ -f "$f" ] || { echo "nodisc: $f is missing"; exit 1; }
done
srcs=$(find pc tools -name '*.[ch]' | sort)
fail=0

# srcs_with PATTERN: the sources that contain PATTERN (fixed string)
srcs_with() {
	# shellcheck disable=SC2086 # one word per path: no spaces in the tree
	grep -lF -- "$1" $srcs 2>/dev/null
}

hits=$(srcs_with gl_disc | grep -vx -e 'pc/galil/gl_disc\.[ch]' \
	-e 'tools/galil-load/[^/]*\.[ch]' -e "$D/re_comm_find\\.[ch]" | tr '\n' ' ')
if [ -n "$hits" ]; then
	echo "nodisc: sources outside the commissioning run use controller discovery: $hits"
	fail=1
fi
callers=$(srcs_with 're_comm_find(' | grep -vx -e "$D/re_comm_find\\.[ch]" \
	-e "$D/re_comm_start\\.c" | tr '\n' ' ')
if [ -n "$callers" ]; then
	echo "nodisc: re_comm_find() called outside the commissioning run's start ($D/re_comm_start.c): $callers"
	fail=1
fi
incs=$(srcs_with '"re_comm_find.h"' | grep -v "^$D/" | tr '\n' ' ')
if [ -n "$incs" ]; then
	echo "nodisc: re_comm_find.h included outside $D: $incs"
	fail=1
fi
[ "$fail" = 0 ] || exit 1
echo "nodisc: ok (discovery only in the commissioning run)"
