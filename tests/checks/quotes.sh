#!/bin/sh
# quotes.sh - every line the manuals quote as roboelf's output is one the
# program can print: docs/operator.md and docs/roboelf.1 held word for word
# to roboelf's sources and the board's goldens. Run by `make check`
# (tests/run-all.sh) from the repo root; POSIX sh and awk only.
#
#   sh tests/checks/quotes.sh [ROOT]         check the tree at ROOT (default .)
#   sh tests/checks/quotes.sh --list [ROOT]  print the quoted lines, check nothing
#
# A quoted line is:
#   - in docs/operator.md, a line of a ``` block or an indented (4 spaces)
#     block that begins with "roboelf: ", "RoboELF Ready" or "Calibration:",
#     joined with the lines under it indented by two spaces (the console's
#     own wrapping); and a `back-quoted` span that begins with "roboelf: ";
#   - in docs/operator.md, every line of a ``` block that begins with the
#     board's header "RoboELF  mode" (a picture of the board);
#   - in docs/roboelf.1, such a line between .nf and .fi, or a quoted
#     .B/.BR argument that begins with "roboelf: " (groff escapes \- \f. \&
#     removed).
# It is held when a string literal of pc/**/*.c (adjacent literals joined,
# as the compiler joins them) matches it whole, its printf conversions
# (%s, %d, %.1f ...) standing for any text and "..." in the quote for any
# text, with at least half of the quote's characters the literal's own;
# a leading "roboelf: " may come from the program's name ("%s: "). A line
# of the board's goldens (tests/data/console/*.txt) holds a quote equal to
# it; a picture of the board is held only line by line by the goldens.
# FAULT lines are docs.sh's (every template against operator.md).
#
# Output: one line per quote the program cannot print,
#   quotes.sh: FILE:LINE: "quote" is printed by no string of pc/ (nor a golden)
# then a summary. Exit 0 when every quote is held, 1 otherwise; extracting
# no quote or no literal is itself a failure.
set -u

LIST=0
if [ "${1:-}" = "--list" ]; then
	LIST=1
	shift
fi
ROOT=${1:-.}
cd "$ROOT" || { echo "quotes.sh: cannot enter '$ROOT'"; exit 1; }
TMPD=$(mktemp -d "${TMPDIR:-/tmp}/quotes-sh.XXXXXX") || exit 1
trap 'rm -rf "$TMPD"' EXIT
trap 'exit 1' INT TERM

# literals FILE...: the string literals, one per line (adjacent ones joined;
# \" \\ resolved, \n \t and other escapes dropped to a space or kept)
literals() {
	for f in "$@"; do
		awk -v q="'" '
		{ src = src $0 "\n" }
		function flush() { if (have) { print str; have = 0; str = "" } }
		END {
			n = length(src); i = 1
			while (i <= n) {
				c = substr(src, i, 1); two = substr(src, i, 2)
				if (two == "/*") {
					j = index(substr(src, i + 2), "*/")
					i = j ? i + 2 + j + 1 : n + 1
				} else if (two == "//") {
					while (i <= n && substr(src, i, 1) != "\n") i++
				} else if (c == "\"") {
					i++; s = ""
					while (i <= n && (c = substr(src, i, 1)) != "\"") {
						if (c == "\\") {
							d = substr(src, i + 1, 1)
							s = s (d == "n" ? "\001" : d == "t" ? " " : d)
							i += 2
						} else { s = s c; i++ }
					}
					i++; str = str s; have = 1
				} else if (c == q) {
					i++
					while (i <= n && (c = substr(src, i, 1)) != q)
						i += (c == "\\") ? 2 : 1
					i++
				} else if (c ~ /[ \t\r\n\f\v]/) {
					i++
				} else { flush(); i++ }
			}
			flush()
		}' "$f"
	done
}

# quotes of docs/operator.md: "FILE:LINE<TAB>text"
md_quotes() {
	awk -v file="$1" '
	function start(s) {
		return s ~ /^roboelf: / || s ~ /^RoboELF Ready/ || s ~ /^Calibration:/
	}
	function out() { if (cur != "") print file ":" at "\t" cur; cur = "" }
	/^```/ { out(); fence = !fence; board = 0; next }
	fence && /^RoboELF  mode / { board = 1 }
	board { print file ":" NR "\tBOARD\t" $0; next }
	{
		line = $0
		if (!fence && line ~ /^    [^ ]/) { line = substr(line, 5); ind = 1 }
		else ind = 0
		if (fence || ind) {
			if (cur != "" && line ~ /^  [^ ]/) {
				sub(/^  /, "", line); cur = cur " " line; next
			}
			out()
			if (start(line)) { cur = line; at = NR }
			next
		}
		out()
		rest = line
		while ((k = index(rest, "`roboelf: ")) > 0) {
			rest = substr(rest, k + 1)
			e = index(rest, "`")
			if (!e) break
			print file ":" NR "\t" substr(rest, 1, e - 1)
			rest = substr(rest, e + 1)
		}
	}
	END { out() }' "$1"
}

# quotes of a man page: "FILE:LINE<TAB>text"
man_quotes() {
	awk -v file="$1" '
	function clean(s) {
		gsub(/\\-/, "-", s); gsub(/\\f[A-Z]/, "", s); gsub(/\\&/, "", s)
		return s
	}
	/^\.nf/ { nf = 1; next }
	/^\.fi/ { nf = 0; next }
	nf {
		s = clean($0)
		if (s ~ /^roboelf: / || s ~ /^RoboELF Ready/ || s ~ /^Calibration:/)
			print file ":" NR "\t" s
		next
	}
	/^\.B/ {
		s = clean($0)
		while ((k = index(s, "\"roboelf: ")) > 0) {
			s = substr(s, k + 1)
			e = index(s, "\"")
			if (!e) break
			print file ":" NR "\t" substr(s, 1, e - 1)
			s = substr(s, e + 1)
		}
	}' "$1"
}

md_quotes docs/operator.md >"$TMPD/quotes"
man_quotes docs/roboelf.1 >>"$TMPD/quotes"
if [ "$LIST" = 1 ]; then
	cat "$TMPD/quotes"
	exit 0
fi
literals $(find pc/ -name '*.c' | sort) >"$TMPD/lits"
cat tests/data/console/*.txt >"$TMPD/golden"
[ -s "$TMPD/quotes" ] || { echo "quotes.sh: no quoted line found (the extraction no longer matches the docs)"; exit 1; }
[ -s "$TMPD/lits" ] || { echo "quotes.sh: no string literal found in pc/"; exit 1; }

awk -F '\t' -v lits="$TMPD/lits" -v golden="$TMPD/golden" '
# split a literal at its printf conversions into fixed pieces p[0..n]
function pieces(s, p,   n) {
	n = 0; p[0] = ""
	while (match(s, /%[-+ #0]*[0-9*]*(\.[0-9*]+)?(hh|h|ll|l|z|j|t|L)?[diouxXfFeEgGcsp%]/)) {
		if (substr(s, RSTART, RLENGTH) == "%%") {
			p[n] = p[n] substr(s, 1, RSTART - 1) "%"
		} else {
			p[n] = p[n] substr(s, 1, RSTART - 1); n++; p[n] = ""
		}
		s = substr(s, RSTART + RLENGTH)
	}
	p[n] = p[n] s
	return n
}
# a value a conversion took counts as explained when it is a number, a
# quoted name (between the literal'"'"'s own quotes) or a system error text
function value(seg, before, after) {
	if (seg ~ /^-?[0-9.]+$/ || seg in ERRNO) return length(seg)
	if (before ~ /\047$/ && after ~ /^\047/) return length(seg)
	return 0
}
# How much of @t the literal L[li] explains: its fixed pieces must match
# @t whole, in order, its conversions standing for any text (with
# @partial, @t may end inside the literal: a quote cut short by "...");
# a last conversion that takes the rest of @t may itself be a message (a
# module error after "roboelf: error: %s"), explained again (@depth
# levels). Return: the characters explained, or 0.
function explain(t, li, depth, partial,   p, n, i, k, j, pos, fixed, rest) {
	n = pieces(L[li], p)
	if (partial && length(t) <= length(p[0]))
		return substr(p[0], 1, length(t)) == t ? length(t) : 0
	if (substr(t, 1, length(p[0])) != p[0]) return 0
	pos = length(p[0]) + 1; fixed = length(p[0])
	if (n == 0) return pos == length(t) + 1 ? fixed : 0
	for (i = 1; i < n; i++) {
		k = index(substr(t, pos), p[i])
		if (!k && partial) {
			for (j = pos; j <= length(t); j++)
				if (index(p[i], substr(t, j)) == 1)
					return fixed + length(t) - j + 1
			return fixed
		}
		if (!k) return 0
		fixed += taken(substr(t, pos, k - 1), p[i - 1], p[i], depth)
		pos += k - 1 + length(p[i]); fixed += length(p[i])
	}
	if (p[n] != "" && partial) {
		if (index(substr(t, pos), p[n])) return fixed + length(p[n])
		for (j = pos; j <= length(t); j++)
			if (index(p[n], substr(t, j)) == 1)
				return fixed + length(t) - j + 1
		return fixed
	}
	if (p[n] != "") {
		if (length(p[n]) > length(t) - pos + 1) return 0
		if (substr(t, length(t) - length(p[n]) + 1) != p[n]) return 0
		seg = substr(t, pos, length(t) - length(p[n]) - pos + 1)
		return fixed + length(p[n]) + taken(seg, p[n - 1], p[n], depth)
	}
	rest = substr(t, pos)
	if (value(rest, p[n - 1], "")) return fixed + length(rest)
	if (depth > 0 && length(rest) >= 8)
		fixed += best(rest, depth - 1, partial)
	return fixed
}
# what a conversion took: a value, or a message of its own (the module
# error inside a sentence), explained again while @depth allows
function taken(seg, before, after, depth,   v, b) {
	v = value(seg, before, after)
	if (v || depth <= 0 || length(seg) < 8) return v
	b = best(seg, depth - 1, 0)
	return 2 * b >= length(seg) ? b : 0
}
function best(t, depth, partial,   i, b, f, key) {
	key = depth SUBSEP partial SUBSEP t
	if (key in MEMO) return MEMO[key]
	b = 0
	for (i = 0; i < nl; i++) {
		f = explain(t, i, depth, partial)
		if (f > b) b = f
	}
	return MEMO[key] = b
}
# "..." or "<what it stands for>" in a quote leaves text out: the part
# before it must be explained as the start of a message
function held(t,   head, i, x, h) {
	if (t in G) return 1
	gsub(/<[^>]*>/, "...", t)
	if (!index(t, "...")) {
		if (2 * best(t, 2, 0) >= length(t)) return 1
		# a sentence the program appends to a message ("snprintf(err +
		# strlen(err), ...)"): the message without it
		for (i = 0; i < nl; i++) {
			x = L[i]
			if (length(x) < 16 || x ~ /%/ || length(t) <= length(x))
				continue
			if (substr(t, length(t) - length(x) + 1) != x)
				continue
			h = substr(t, 1, length(t) - length(x))
			if (2 * best(h, 2, 0) >= length(h))
				return 1
		}
		return 0
	}
	head = substr(t, 1, index(t, "...") - 1)
	sub(/ +$/, "", head)
	return 2 * best(head, 2, 1) >= length(head)
}
BEGIN {
	split("No such file or directory|Permission denied|Connection refused|" \
	      "Connection timed out|Is a directory|No space left on device", e, "|")
	for (i in e) ERRNO[e[i]] = 1
	while ((getline l < lits) > 0) {
		m = split(l, part, /\001/)
		for (j = 1; j <= m; j++) {
			sub(/[ ]+$/, "", part[j])
			f = part[j]; gsub(/%[-+ #0-9.*hlzjtL]*[a-zA-Z%]/, "", f)
			if (length(f) >= 6) L[nl++] = part[j]
		}
	}
	while ((getline l < golden) > 0) G[l] = 1
}
$2 == "BOARD" {
	if ($3 in G) next
	printf "quotes.sh: %s: board line \"%s\" is in no golden of tests/data/console\n", $1, $3
	bad++
	next
}
{
	if (held($2)) next
	printf "quotes.sh: %s: \"%s\" is printed by no string of pc/ (nor a golden)\n", $1, $2
	bad++
}
END {
	printf "quotes.sh: %d quoted line(s) of docs/operator.md and docs/roboelf.1 checked, %d not printed by roboelf\n", NR, bad
	exit bad > 0
}' "$TMPD/quotes"
