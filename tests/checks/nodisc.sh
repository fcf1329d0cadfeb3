#!/bin/sh
# nodisc.sh - roboelf's operation never discovers controllers: it connects
# only to its configured address. Only the technician's commissioning run
# (roboelf-tech commission, tools/roboelf-tech) may offer the controllers
# that answer the discovery probe, on the technician's choice: gl_disc is
# named by tools/roboelf-tech/re_comm_find.[ch] alone (outside pc/galil,
# which defines it, and galil-load's --find), and re_comm_find() is called
# only from the technician's program.
cd "$(dirname "$0")/../.." || exit 1
[ -f tools/roboelf-tech/re_comm_find.c ] || { echo "nodisc: tools/roboelf-tech/re_comm_find.c is missing"; exit 1; }
hits=$(grep -l 'gl_disc' pc/*.c pc/*/*.c pc/*/*.h tools/roboelf-tech/*.[ch] 2>/dev/null |
	grep -v '^pc/galil/gl_disc\.[ch]$' | grep -v '^tools/roboelf-tech/re_comm_find\.[ch]$')
if [ -n "$hits" ]; then
	echo "nodisc: sources outside the commissioning run use controller discovery: $hits"
	exit 1
fi
callers=$(grep -l 're_comm_find(' pc/*.c pc/*/*.c 2>/dev/null)
if [ -n "$callers" ]; then
	echo "nodisc: re_comm_find() called by roboelf's sources: $callers"
	exit 1
fi
echo "nodisc: ok (discovery only in the commissioning run)"
