#!/bin/sh
# nodisc.sh - roboelf's operation never discovers controllers: it connects
# only to its configured address (issue 14, part 5). Only the commissioning
# run may offer the controllers that answer the discovery probe, on the
# technician's choice: gl_disc is named by pc/re_comm_find.[ch] alone, and
# re_comm_find() is called only from re_start.c's commission_*() functions.
cd "$(dirname "$0")/../.." || exit 1
hits=$(grep -l 'gl_disc' pc/re_*.c pc/re_*.h pc/roboelf.c 2>/dev/null |
	grep -v '^pc/re_comm_find\.[ch]$')
if [ -n "$hits" ]; then
	echo "nodisc: roboelf sources use controller discovery: $hits"
	exit 1
fi
callers=$(grep -l 're_comm_find(' pc/*.c 2>/dev/null |
	grep -v '^pc/re_comm_find\.c$')
if [ -n "$callers" ] && [ "$callers" != pc/re_start.c ]; then
	echo "nodisc: re_comm_find() called outside re_start.c: $callers"
	exit 1
fi
# in re_start.c: only inside commission_link()
bad=$(awk '/^[a-z].*\(/ { fn = $0 } /re_comm_find\(/ && fn !~ /^static int commission_/ { print FILENAME ":" FNR }' pc/re_start.c)
if [ -n "$bad" ]; then
	echo "nodisc: re_comm_find() outside the commission_*() functions: $bad"
	exit 1
fi
echo "nodisc: ok (discovery only in the commissioning run)"
