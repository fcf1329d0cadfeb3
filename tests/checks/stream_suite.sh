#!/bin/sh
# stream_suite.sh - the supervisor's reactions over the record stream
# (controller.record: stream, docs/link.md "The record as a stream: the
# cycle"): the system programs of the start-up, every fault class and the
# frozen supervisor run again with ROBOELF_SYS_RECORD=stream, so that both
# designs are held to the same outcomes and deadlines in `make check` (the
# configuration's default, poll, runs in the rest of the suite;
# tests/system/test_sys_stream.c holds what only the stream has).
# Each program's own output goes to the log; the exit code is the first
# failure's.
set -u
cd "$(dirname "$0")/../.." || exit 1
BUILD=${BUILD:-build}
BIN=${ROBOELF_BIN:-$PWD/$BUILD/bin}
rc=0
for t in test_sys_basic test_sys_faults test_sys_freeze; do
	echo "=== $t (record: stream)"
	if ROBOELF_SYS_RECORD=stream ROBOELF_BIN=$BIN ROBOELF_TOP=$PWD \
		"$BUILD/tests/system/$t"; then
		echo "=== $t (record: stream): ok"
	else
		r=$?
		echo "=== $t (record: stream): FAILED (exit $r)"
		[ $rc = 0 ] && rc=$r
	fi
done
exit $rc
