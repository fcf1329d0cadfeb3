#!/bin/sh
# includes.sh - no include cycle between the headers of pc/ and tools/: for
# every header, each "#include "x.h"" of another header of ours is an edge,
# and the edges must form a directed acyclic graph (tsort finds a loop). A
# header including one that does not exist in the tree is not ours (a
# library's) and is left out.
cd "$(dirname "$0")/../.." || exit 1
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
find pc tools -name '*.h' | sort >"$tmp/hdrs"
sed 's|.*/||' "$tmp/hdrs" | sort >"$tmp/names"
while read -r h; do
	sed -n 's/^#include "\([^"]*\.h\)".*/\1/p' "$h" | while read -r inc; do
		grep -qxF "$inc" "$tmp/names" && echo "${h##*/} $inc"
	done
done <"$tmp/hdrs" >"$tmp/edges"
if ! tsort "$tmp/edges" >/dev/null 2>"$tmp/err"; then
	echo "includes: a loop of headers:"
	sed -n 's/^tsort: //p' "$tmp/err" | grep -v 'input contains a loop'
	exit 1
fi
echo "includes: $(wc -l <"$tmp/hdrs") headers, $(wc -l <"$tmp/edges") includes between them, no loop"
