#!/bin/sh
# layers.sh - no dependency cycle between the modules of pc/ and tools/, and
# no library using a library above it, measured at link level.
#
# A module is one object file (one .c, with its .h). Module X depends on
# module Y when X uses a global symbol Y defines (nm). The modules must form
# a directed acyclic graph, and each library may use only the libraries
# below it (docs/architecture.md):
#   0 base (pc/base)  1 galil (pc/galil), dmc (pc/dmc)
#   2 super (pc/super): the safety core, over base, galil and dmc only
#   3 config (pc/config)  4 calib (pc/calib), rec (pc/rec)
#   5 console (pc/console)  6 start (pc/start)
#   7 roboelf (pc/roboelf.c), roboelf-tech, galil-load, galil-sim (tools/)
#
# Usage: layers.sh [--list]    (BUILD selects the build tree, default build)
#   --list  also print every dependency.
# Prints one line per loop (its modules) and per upward use, then a summary;
# exits 0 when there is none, 1 otherwise.
set -u
BUILD=${BUILD:-build}
cd "$(dirname "$0")/../.." || exit 1
OBJ=$BUILD/obj
list=0
[ "${1:-}" = --list ] && list=1
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT

find "$OBJ/pc" "$OBJ/tools" -name '*.o' 2>/dev/null | sort >"$tmp/objs"
if [ ! -s "$tmp/objs" ]; then
	echo "layers.sh: no objects under $OBJ/pc or $OBJ/tools: build first" >&2
	exit 1
fi
# main() of each program is a root: leave it out (two programs define it)
xargs nm -A --defined-only -g <"$tmp/objs" 2>/dev/null |
	awk '$2 ~ /^[TDBRVWGSC]$/ && $3 != "main" {
		sub(/:.*/, "", $1); print $3, $1 }' >"$tmp/defs"
xargs nm -A -u <"$tmp/objs" 2>/dev/null |
	awk '{ sub(/:.*/, "", $1); print $NF, $1 }' >"$tmp/uses"

awk -v pre="$OBJ/" -v list="$list" -v nobj="$(wc -l <"$tmp/objs")" '
function mod(p) { sub(pre, "", p); sub(/\.o$/, "", p); return p }
function lib(m) {
	if (m ~ /^pc\/base\//) return "base"
	if (m ~ /^pc\/galil\// || m ~ /^pc\/gl_/) return "galil"
	if (m ~ /^pc\/dmc\//) return "dmc"
	if (m ~ /^pc\/super\//) return "super"
	if (m ~ /^pc\/config\//) return "config"
	if (m ~ /^pc\/calib\//) return "calib"
	if (m ~ /^pc\/rec\//) return "rec"
	if (m ~ /^pc\/console\//) return "console"
	if (m ~ /^pc\/start\//) return "start"
	if (m == "pc/roboelf") return "roboelf"
	if (m ~ /^tools\/galil-load\//) return "galil-load"
	if (m ~ /^tools\/roboelf-tech\//) return "roboelf-tech"
	if (m ~ /^tools\/galil-sim\//) return "galil-sim"
	return "other"
}
function rank(l) {
	if (l == "base") return 0
	if (l == "galil" || l == "dmc") return 1
	if (l == "super") return 2
	if (l == "config") return 3
	if (l == "calib" || l == "rec") return 4
	if (l == "console") return 5
	if (l == "start") return 6
	return 7
}
BEGIN { n = 0 }
NR == FNR { def[$1] = mod($2); next }
($1 in def) {
	u = mod($2); d = def[$1]
	if (u == d || ((u, d) in e)) next
	e[u, d] = 1
	if (!(u in id)) { id[u] = n; name[n++] = u }
	if (!(d in id)) { id[d] = n; name[n++] = d }
	r[id[u], id[d]] = 1; nedge++
	if (list) print "edge: " u " -> " d
	lu = lib(u); ld = lib(d)
	if (lu != ld && rank(ld) >= rank(lu)) {
		print "layers.sh: " u " (" lu ") uses " d " (" ld "), which is not below it"
		bad++
	}
}
END {
	for (i = 0; i < n; i++)
		if (lib(name[i]) == "other") {
			print "layers.sh: " name[i] " is in no folder of the layering"
			bad++
		}
	# transitive closure (Warshall), then the loops are the groups of
	# modules that reach each other
	for (k = 0; k < n; k++) for (i = 0; i < n; i++) if (r[i, k])
		for (j = 0; j < n; j++) if (r[k, j]) r[i, j] = 1
	for (i = 0; i < n; i++) {
		if (done[i] || !r[i, i]) continue
		s = name[i]; c = 1; done[i] = 1
		for (j = i + 1; j < n; j++)
			if (r[i, j] && r[j, i]) { s = s " " name[j]; c++; done[j] = 1 }
		print "layers.sh: loop of " c " modules: " s
		loops++; inloops += c; bad++
	}
	printf "layers.sh: %d modules, %d dependencies, %d loop(s) holding %d modules, %d problem(s)\n",
	       nobj, nedge, loops, inloops, bad
	exit bad > 0
}' "$tmp/defs" "$tmp/uses"
