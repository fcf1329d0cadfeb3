#!/bin/sh
# modtests.sh - every module of pc/ and tools/ has its test: a test program
# named after it (tests/<dir>/test_<module>.c), or a row of the table
# "Tests of each module" in docs/architecture.md naming the tests that
# exercise it:
#   | `re_pot` | `test_re_check`, `test_sys_faults` (roboelf) |
# A test named plainly must link the module (its binary holds a global
# symbol the module defines); a test named with a program in parentheses
# runs that program, which must link the module, and the test's source
# must name the program. A row for a module that does not exist, or a test
# that does not exist, fails too. A module is one .c file (main.c of a
# program is named after its program: galil-load, galil-sim, roboelf-tech).
#
# Usage: modtests.sh [--list]   (BUILD selects the build tree; build first)
set -u
BUILD=${BUILD:-build}
cd "$(dirname "$0")/../.." || exit 1
DOC=docs/architecture.md
list=0
[ "${1:-}" = --list ] && list=1
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
bad=0
problem() { echo "modtests: $*"; bad=$((bad + 1)); }

# the table: "module<TAB>test<TAB>program" per test named
awk '
/^## Tests of each module/ { on = 1; next }
on && /^## / { on = 0 }
on && /^\| `/ {
	n = split($0, c, "|")
	m = c[2]; gsub(/[ `]/, "", m)
	k = split(c[3], t, ",")
	for (i = 1; i <= k; i++) {
		s = t[i]; prog = ""
		if (match(s, /\([a-z-]+\)/)) prog = substr(s, RSTART + 1, RLENGTH - 2)
		sub(/\(.*/, "", s); gsub(/[ `]/, "", s)
		if (s != "") print m "\t" s "\t" prog
	}
}' "$DOC" >"$tmp/rows"
[ -s "$tmp/rows" ] || { echo "modtests: no table 'Tests of each module' in $DOC"; exit 1; }

# modules: "name<TAB>object"
find pc tools -name '*.c' | sort | while read -r f; do
	m=$(basename "$f" .c)
	[ "$m" = main ] && m=$(basename "$(dirname "$f")")
	[ "$f" = pc/roboelf.c ] && m=roboelf
	echo "$m	$BUILD/obj/${f%.c}.o"
done >"$tmp/mods"

defs() { nm --defined-only -g "$1" 2>/dev/null | awk '$2 ~ /^[TDBR]$/ && $3 != "main" { print $3 }' | sort -u; }
testsrc() { ls tests/*/"$1".c 2>/dev/null | head -1; }
testbin() { ls "$BUILD"/tests/*/"$1" 2>/dev/null | head -1; }

while IFS='	' read -r m obj; do
	[ -f "$obj" ] || { problem "$obj: not built (build first)"; continue; }
	if [ -n "$(testsrc "test_$m")" ] && ! grep -q "^$m	" "$tmp/rows"; then
		[ "$list" = 1 ] && echo "$m: test_$m"
		continue
	fi
	grep -q "^$m	" "$tmp/rows" || {
		problem "module $m has no test named after it and no row in $DOC ('Tests of each module')"
		continue
	}
	defs "$obj" >"$tmp/d"
	grep "^$m	" "$tmp/rows" | while IFS='	' read -r _ t prog; do
		src=$(testsrc "$t")
		[ -n "$src" ] || { problem "$m: its test $t does not exist"; continue; }
		if [ -n "$prog" ]; then
			bin=$BUILD/bin/$prog
			grep -q "$prog" "$src" || problem "$m: $t does not run $prog"
		else
			bin=$(testbin "$t")
		fi
		[ -n "$bin" ] && [ -f "$bin" ] || { problem "$m: $t: no binary to look in (build first)"; continue; }
		if [ -s "$tmp/d" ]; then
			defs "$bin" | grep -qxFf "$tmp/d" ||
				problem "$m: ${prog:-$t} does not link $m"
		fi
		[ "$list" = 1 ] && echo "$m: $t${prog:+ ($prog)}"
	done >>"$tmp/out"
done <"$tmp/mods"
[ -f "$tmp/out" ] && cat "$tmp/out" && bad=$((bad + $(grep -c '^modtests: ' "$tmp/out")))
cut -f1 "$tmp/rows" | sort -u | while read -r m; do
	grep -q "^$m	" "$tmp/mods" || echo "modtests: $DOC names module $m, which does not exist"
done >"$tmp/stale"
cat "$tmp/stale"
bad=$((bad + $(grep -c . "$tmp/stale")))
echo "modtests: $(wc -l <"$tmp/mods") modules, $(grep -c . "$tmp/rows") tests named in the table, $bad problem(s)"
[ "$bad" -eq 0 ]
