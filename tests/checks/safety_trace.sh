#!/bin/sh
# safety_trace.sh - docs/safety.md's traceability must name tests that exist.
# Run by `make check` (tests/run-all.sh) from the repository root.
#
#  - every `binary:function` reference in docs/safety.md must be a function
#    "static void function(" in tests/*/binary.c;
#  - every row of the table in section "4. Traceability" must name at least
#    one such reference;
#  - every bare `test_*` name in section "3. Deadlines" must be a test
#    function of a tests/system/*.c file.
# Output: one line per problem, then a summary; exit 0 when all is well.
set -u
ROOT=${1:-.}
cd "$ROOT" || { echo "safety_trace.sh: cannot enter '$ROOT'"; exit 1; }
DOC=docs/safety.md
[ -r "$DOC" ] || { echo "safety_trace.sh: cannot read '$DOC'"; exit 1; }
fails=0
refs=0

has_test() {	# FILE FUNCTION
	grep -q "^static void $2(" "$1" 2>/dev/null
}

for ref in $(grep -o '`test_[a-z0-9_]*:test_[a-z0-9_]*`' "$DOC" | tr -d '`' |
	     sort -u); do
	bin=${ref%%:*}
	fn=${ref#*:}
	refs=$((refs + 1))
	found=0
	for f in tests/*/"$bin".c; do
		[ -f "$f" ] && has_test "$f" "$fn" && found=1
	done
	if [ "$found" -eq 0 ]; then
		echo "safety_trace.sh: $DOC names '$bin:$fn', which is not a test in tests/*/$bin.c"
		fails=$((fails + 1))
	fi
done

rows=$(awk '/^## 4\. Traceability/ { on = 1; next } /^## / { on = 0 }
	on && /^\| / && !/^\| requirement/ && !/^\|---/ { print }' "$DOC")
if [ -z "$rows" ]; then
	echo "safety_trace.sh: no traceability table found in $DOC"
	fails=$((fails + 1))
fi
bad=$(echo "$rows" | grep -v '`test_[a-z0-9_]*:test_[a-z0-9_]*`' |
      grep -v '^$')
if [ -n "$bad" ]; then
	echo "$bad" | while IFS= read -r row; do
		echo "safety_trace.sh: a traceability row names no test: $row"
	done
	fails=$((fails + $(echo "$bad" | wc -l)))
fi

for fn in $(awk '/^## 3\. Deadlines/ { on = 1; next } /^## / { on = 0 }
	on { print }' "$DOC" | grep -o '(`test_[a-z0-9_]*`)' | tr -d '(`)' |
	sort -u); do
	found=0
	for f in tests/system/*.c; do
		[ -f "$f" ] && has_test "$f" "$fn" && found=1
	done
	if [ "$found" -eq 0 ]; then
		echo "safety_trace.sh: deadline table names '$fn', which is not a test in tests/system/"
		fails=$((fails + 1))
	fi
done

if [ "$refs" -eq 0 ]; then
	echo "safety_trace.sh: no test references found in $DOC"
	fails=$((fails + 1))
fi
echo "safety_trace.sh: $refs test references checked, $fails problem(s)"
[ "$fails" -eq 0 ]
