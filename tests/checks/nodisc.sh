#!/bin/sh
# nodisc.sh - roboelf's operation never discovers controllers: it connects
# only to its configured address. Only the commissioning run (pc/comm) may
# offer the controllers that answer the discovery probe, on the
# technician's choice: gl_disc is named by pc/comm/re_comm_find.[ch] alone
# (outside pc/galil, which defines it), and re_comm_find() is called only
# from the commissioning run's own files.
cd "$(dirname "$0")/../.." || exit 1
[ -f pc/comm/re_comm_find.c ] || { echo "nodisc: pc/comm/re_comm_find.c is missing"; exit 1; }
hits=$(grep -l 'gl_disc' pc/*.c pc/*/*.c pc/*/*.h 2>/dev/null |
	grep -v '^pc/galil/gl_disc\.[ch]$' | grep -v '^pc/comm/re_comm_find\.[ch]$')
if [ -n "$hits" ]; then
	echo "nodisc: roboelf sources outside the commissioning run use controller discovery: $hits"
	exit 1
fi
callers=$(grep -l 're_comm_find(' pc/*.c pc/*/*.c 2>/dev/null | grep -v '^pc/comm/')
if [ -n "$callers" ]; then
	echo "nodisc: re_comm_find() called outside the commissioning run: $callers"
	exit 1
fi
echo "nodisc: ok (discovery only in the commissioning run)"
