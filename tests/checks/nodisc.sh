#!/bin/sh
# nodisc.sh - roboelf (the operator's program) never discovers controllers:
# it connects only to its configured address (issue 14, part 5). Fails when
# any supervisor source names the discovery module gl_disc.
cd "$(dirname "$0")/../.." || exit 1
hits=$(grep -l 'gl_disc' pc/re_*.c pc/re_*.h pc/roboelf.c 2>/dev/null)
if [ -n "$hits" ]; then
	echo "nodisc: roboelf sources use controller discovery: $hits"
	exit 1
fi
echo "nodisc: ok (no discovery in roboelf)"
