#!/bin/sh
# contracts.sh - every public function of pc/ and tools/ has a contract
# comment: a function declared in a header must have a comment directly
# above it (a group of declarations with no blank line between them may
# share the comment above the first one).
#
# Usage: contracts.sh [--list] [DIR...]   (default: pc tools)
#   --list  print every declaration without a comment (the default prints
#           at most 40).
# Exits 0 when every declaration has one, 1 otherwise.
set -u
cd "$(dirname "$0")/../.." || exit 1
all=0
if [ "${1:-}" = --list ]; then all=1; shift; fi
[ $# -eq 0 ] && set -- pc tools
find "$@" -name '*.h' | sort | xargs awk -v all="$all" '
FNR == 1 { prev = "blank"; incom = 0; indecl = 0 }
{
	line = $0
	if (incom) {
		if (line ~ /\*\//) { incom = 0; prev = "comment" }
		next
	}
	if (indecl) {
		if (line ~ /[;{]/) { indecl = 0; prev = "decl" }
		next
	}
	if (line ~ /^[ \t]*$/) { prev = "blank"; next }
	if (line ~ /^[ \t]*\/\*/) {
		if (line !~ /\*\//) incom = 1; else prev = "comment"
		next
	}
	if (line ~ /^[ \t]*\/\//) { prev = "comment"; next }
	if (line ~ /^[A-Za-z_]/ && line ~ /\(/ && line !~ /^(struct|enum|union)[ \t]+[A-Za-z_0-9]*[ \t]*\{/ &&
	    line !~ /^typedef/ && line !~ /^#/ && line !~ /^extern "C"/) {
		decls++
		if (prev != "comment" && prev != "decl") {
			missing++
			if (all || missing <= 40) {
				d = line; sub(/\(.*/, "", d); sub(/.*[ *]/, "", d)
				print "contracts.sh: " FILENAME ":" FNR ": " d "() has no contract comment"
			}
		}
		if (line ~ /[;{]/) prev = "decl"; else indecl = 1
		next
	}
	prev = "other"
}
END {
	printf "contracts.sh: %d public functions declared, %d without a contract comment\n", decls, missing
	exit missing > 0
}' || exit 1
