#!/bin/sh
# cmdtable.sh - the table of external commands in docs/commands.md.
#
#   cmdtable.sh list [TABLE]       one line per command: "COMMAND PACKAGE FLAG"
#                                  (FLAG: "e" Essential or required, "o"
#                                  optional, "-" neither)
#   cmdtable.sh path DIR [TABLE]   make DIR hold one link per command of the
#                                  table that this PATH has, and nothing else
#                                  (the tests' whole PATH: docs/commands.md)
#
# TABLE defaults to docs/commands.md beside this script. Exit 0, or 1 with a
# message on a malformed row (file:line) or a DIR that cannot be made.
set -u
TOP=$(cd "$(dirname "$0")/.." && pwd) || exit 1

# rows TABLE: the table's rows, "LINE COMMAND PACKAGE FLAG"
rows() {
	awk -v f="$1" '
	/^\| `/ {
		n = split($0, col, "|")
		cmd = col[2]; pkg = col[3]
		gsub(/[` ]/, "", cmd)
		flag = "-"
		if (pkg ~ /\(E\)/) flag = "e"
		if (pkg ~ /\(optional\)/) flag = "o"
		sub(/\(.*\)/, "", pkg); gsub(/ /, "", pkg)
		if (n < 5 || cmd == "" || pkg == "" || cmd ~ /[^A-Za-z0-9_.+-]/) {
			printf "%s:%d: malformed row of the command table\n", f, NR > "/dev/stderr"
			bad = 1
		}
		print NR, cmd, pkg, flag
	}
	END { exit bad }' "$1"
}

# exe NAME: the first executable file NAME on PATH (builtins do not count:
# `true` and `pwd` are run as programs by chrt, env and C code)
exe() {
	IFS=:
	for d in $PATH; do
		[ -f "$d/$1" ] && [ -x "$d/$1" ] && { echo "$d/$1"; return 0; }
	done
	return 1
}

case ${1:-} in
list)
	rows "${2:-$TOP/docs/commands.md}" | cut -d' ' -f2-
	;;
path)
	[ $# -ge 2 ] || { echo "usage: cmdtable.sh path DIR [TABLE]" >&2; exit 2; }
	dir=$2
	list=$(rows "${3:-$TOP/docs/commands.md}") || exit 1
	rm -rf "$dir.new" && mkdir -p "$dir.new" || exit 1
	echo "$list" | while read -r _ cmd _ _; do
		real=$(exe "$cmd") || continue
		ln -s "$real" "$dir.new/$cmd" || exit 1
	done || exit 1
	rm -rf "$dir" && mv "$dir.new" "$dir"
	;;
*)
	echo "usage: cmdtable.sh list [TABLE] | path DIR [TABLE]" >&2
	exit 2
	;;
esac
