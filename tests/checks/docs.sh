#!/bin/sh
# docs.sh - fail when something the programs can print or accept is not
# documented. Run by `make check` (tests/run-all.sh) from the repo
# root; POSIX sh and awk only.
#
#   sh tests/checks/docs.sh [ROOT]       check the tree at ROOT (default .)
#   sh tests/checks/docs.sh --list [ROOT]  print what was extracted, check nothing
#
# What must be documented:
#   (a) every FAULT line: each entry of re_fault_table in pc/super/re_fault.c, as the
#       operator sees it ("FAULT <CLASS>: <what>. Recovery: <recovery>", with
#       the {a} {s} {i0} ... placeholders as written in the table), verbatim on
#       one line of docs/operator.md; and every other "FAULT <CLASS>: ..."
#       string literal in pc/**.c (printf conversions such as %d may stand for
#       anything in the doc: the pieces between them must appear, in order, on
#       one line). A "FAULT <CLASS>: ... Recovery: ..." line at the start of a
#       line of docs/operator.md that the code cannot print is reported as
#       stale.
#   (b) every key of every `static const struct field NAME[]` table in
#       pc/config/re_config.c (the YAML keys the loader accepts), back-quoted in
#       docs/config.md (`key` or `parent.key`).
#   (c) every long option (`struct option` tables) and short option (the
#       getopt_long option string) of pc/roboelf.c, tools/galil-load/main.c and
#       tools/galil-sim/main.c in docs/roboelf.1, docs/galil-load.1,
#       docs/galil-sim.1 (after removing groff escapes: \- \f. \c \&).
# The C files are read with a small tokenizer (comments skipped, adjacent
# string literals joined as the compiler joins them), so line breaks and
# clang-format layout do not matter. Extracting nothing is itself a failure
# (the code changed form and this script must follow it).
#
# Output: one line per missing item,
#   docs.sh: <item> is in <code file> but not in <doc>
# then a summary. Exit 0 when complete, 1 when something is missing.
set -u

LIST=0
if [ "${1:-}" = "--list" ]; then
	LIST=1
	shift
fi
ROOT=${1:-.}
cd "$ROOT" || { echo "docs.sh: cannot enter '$ROOT'"; exit 1; }

FAILS=0
TMPD=$(mktemp -d "${TMPDIR:-/tmp}/docs-sh.XXXXXX") || exit 1
trap 'rm -rf "$TMPD"' EXIT
trap 'exit 1' INT TERM

fail() {
	echo "docs.sh: $*"
	FAILS=$((FAILS + 1))
}

need_file() {
	if [ ! -r "$1" ]; then
		fail "cannot read '$1'"
		return 1
	fi
	return 0
}

# tokens FILE: one token per line, "S<TAB>string" (adjacent literals joined,
# escapes \" \\ \' resolved, others kept), "W<TAB>identifier" or
# "P<TAB>punctuation character". Comments, character literals, numbers and
# white space produce nothing.
tokens() {
	awk -v q="'" '
	{ src = src $0 "\n" }
	function flush() {
		if (have) { print "S\t" str; have = 0; str = "" }
	}
	END {
		n = length(src); i = 1
		while (i <= n) {
			c = substr(src, i, 1)
			two = substr(src, i, 2)
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
						if (d == "\"" || d == "\\" || d == q)
							s = s d
						else
							s = s c d
						i += 2
					} else {
						s = s c; i++
					}
				}
				i++
				str = str s; have = 1
			} else if (c == q) {
				i++
				while (i <= n && (c = substr(src, i, 1)) != q)
					i += (c == "\\") ? 2 : 1
				i++
			} else if (c ~ /[ \t\r\n\f\v]/) {
				i++
			} else if (c ~ /[A-Za-z_]/) {
				flush(); w = ""
				while (i <= n && (c = substr(src, i, 1)) ~ /[A-Za-z0-9_]/) {
					w = w c; i++
				}
				print "W\t" w
			} else if (c ~ /[0-9]/) {
				flush()
				while (i <= n && substr(src, i, 1) ~ /[A-Za-z0-9_.]/) i++
			} else {
				flush(); print "P\t" c; i++
			}
		}
		flush()
	}' "$1"
}

# ---- (a) FAULT messages ------------------------------------------------------

# fault_table: "ID<TAB>CLASS<TAB>what<TAB>recovery" per re_fault_table entry;
# the class is the name re_fclass_names gives it.
fault_table() {
	tokens pc/super/re_fault.c | awk -F '\t' '
	# re_fclass_names: [ RE_FC_X ] = "NAME"
	$1 == "P" && $2 == "[" { st = 1; next }
	st == 1 && $1 == "W" && $2 ~ /^RE_FC_/ { fc = $2; st = 2; next }
	st == 2 && $1 == "P" && $2 == "]" { st = 3; next }
	st == 3 && $1 == "P" && $2 == "=" { st = 4; next }
	st == 4 && $1 == "S" { cname[fc] = $2; st = 0; next }
	{ st = 0 }
	$1 == "W" && $2 == "re_fault_table" && !done { intab = 1; done = 1; depth = 0; next }
	intab && $1 == "P" && $2 == "{" { depth++; if (depth == 2) { id = ""; cls = ""; ns = 0 } ; next }
	intab && $1 == "P" && $2 == "}" {
		if (depth == 2 && id != "") { ids[++k] = id; cl[k] = cls; wh[k] = s1; rc[k] = s2 }
		depth--; next
	}
	intab && $1 == "P" && $2 == ";" && depth == 0 { intab = 0; next }
	intab && depth == 2 && $1 == "W" && $2 ~ /^RE_F_/ && id == "" { id = $2; next }
	intab && depth == 2 && $1 == "W" && $2 ~ /^RE_FC_/ { cls = $2; next }
	intab && depth == 2 && $1 == "S" { ns++; if (ns == 1) s1 = $2; else if (ns == 2) s2 = $2; next }
	END {
		for (j = 1; j <= k; j++) {
			c = cl[j]
			name = (c in cname) ? cname[c] : substr(c, 7)
			print ids[j] "\t" name "\t" wh[j] "\t" rc[j]
		}
	}'
}

# other_faults: "FILE<TAB>literal" for every string literal of pc/**.c that
# starts like a FAULT line.
other_faults() {
	for f in pc/*.c pc/*/*.c; do
		tokens "$f" | awk -F '\t' -v f="$f" '
		$1 == "S" && $2 ~ /^FAULT [A-Z]+: / { print f "\t" $2 }'
	done
}

check_faults() {
	doc=docs/operator.md
	need_file pc/super/re_fault.c || return
	fault_table >"$TMPD/faults"
	other_faults >"$TMPD/other"
	if [ ! -s "$TMPD/faults" ]; then
		fail "no FAULT templates found in re_fault_table of pc/super/re_fault.c (the extraction no longer matches the code)"
		return
	fi
	if [ "$LIST" = 1 ]; then
		awk -F '\t' '{ print "fault\t" $1 "\tFAULT " $2 ": " $3 ". Recovery: " $4 }' "$TMPD/faults"
		awk -F '\t' '{ print "fault-literal\t" $1 "\t" $2 }' "$TMPD/other"
		return
	fi
	need_file "$doc" || return
	out=$(awk -F '\t' -v doc="$doc" '
	# the doc first (one record per line), then the two lists
	FILENAME == doc { line[++nl] = $0; next }
	FILENAME ~ /faults$/ {
		want = "FAULT " $2 ": " $3 ". Recovery: " $4
		known[want] = 1
		found = 0
		for (j = 1; j <= nl && !found; j++)
			if (index(line[j], want)) found = 1
		if (!found)
			printf "docs.sh: FAULT message %s (\"%s\") is in pc/super/re_fault.c but not in %s\n", $1, want, doc
		next
	}
	{	# a printf-style literal: pieces between conversions, in order
		lit = $2
		gsub(/%%/, "\001", lit)
		np = 0; rest = lit
		while (match(rest, /%[-+ #0]*[0-9*]*(\.[0-9*]+)?(hh|h|ll|l|j|z|t|L)?[diouxXeEfgGcsp]/)) {
			piece[++np] = substr(rest, 1, RSTART - 1)
			rest = substr(rest, RSTART + RLENGTH)
		}
		piece[++np] = rest
		for (p = 1; p <= np; p++) {
			gsub(/\001/, "%", piece[p])
			sub(/^ +/, "", piece[p]); sub(/ +$/, "", piece[p])
		}
		found = 0
		for (j = 1; j <= nl && !found; j++) {
			s = line[j]; ok = 1
			for (p = 1; p <= np && ok; p++) {
				if (piece[p] == "") continue
				at = index(s, piece[p])
				if (!at) ok = 0
				else s = substr(s, at + length(piece[p]))
			}
			if (ok) found = 1
		}
		if (!found)
			printf "docs.sh: FAULT message \"%s\" is in %s but not in %s\n", $2, $1, doc
		pat[++npat] = $2
	}
	END {
		# stale: a FAULT line in the doc that no template produces
		for (j = 1; j <= nl; j++) {
			l = line[j]
			sub(/^[ \t>]*`?/, "", l); sub(/`?[ \t]*$/, "", l)
			if (l !~ /^FAULT [A-Z]+: .*\. Recovery: /) continue
			if (l in known) continue
			ok = 0
			for (p = 1; p <= npat && !ok; p++) {
				q = pat[p]; c = substr(q, 1, index(q, ":"))
				if (substr(l, 1, length(c)) == c) ok = 1
			}
			if (!ok)
				printf "docs.sh: \"%s\" is in %s:%d but the code has no such FAULT message (stale)\n", l, doc, j
		}
	}' "$doc" "$TMPD/faults" "$TMPD/other")
	report "$out"
}

# ---- (b) configuration keys --------------------------------------------------

# config_keys: "TABLE<TAB>key" for every entry of every
# `static const struct field NAME[] = { ... };` table of pc/config/re_config*.c:
# the first string literal of the entry ({ "key", ... } or IK("key", ...)),
# else the second macro argument (I(struct s, key, ...): #m is the key).
config_keys() {
	for f in pc/config/re_config*.c; do tokens "$f"; done | awk -F '\t' '
	{ t[++n] = $1; v[n] = $2 }
	END {
		for (i = 1; i + 6 <= n; i++) {
			if (!(t[i] == "W" && v[i] == "struct" && v[i + 1] == "field" &&
			      t[i + 2] == "W" && v[i + 3] == "[" && v[i + 4] == "]" &&
			      v[i + 5] == "=" && v[i + 6] == "{"))
				continue
			tab = v[i + 2]; j = i + 7; depth = 1
			while (j <= n && depth > 0) {
				# one entry: tokens up to the "," at depth 1
				k = j; d = depth; key = ""; first = k
				while (k <= n) {
					if (t[k] == "P" && (v[k] == "{" || v[k] == "(")) d++
					else if (t[k] == "P" && (v[k] == "}" || v[k] == ")")) {
						if (d == 1) break
						d--
					} else if (t[k] == "P" && v[k] == "," && d == 1) break
					k++
				}
				if (t[first] == "P" && v[first] == "{") {
					if (t[first + 1] == "S") key = v[first + 1]
				} else if (t[first] == "W" && v[first + 1] == "(") {
					if (t[first + 2] == "S") key = v[first + 2]
					else {
						d = 0
						for (m = first + 1; m < k; m++) {
							if (v[m] == "(") d++
							else if (v[m] == ")") d--
							else if (t[m] == "P" && v[m] == "," && d == 1) {
								if (t[m + 1] == "W") key = v[m + 1]
								break
							}
						}
					}
				}
				if (key != "") print tab "\t" key
				if (k > n || (t[k] == "P" && v[k] == "}" && d == 1)) break
				j = k + 1
			}
			i = k
		}
	}'
}

check_config() {
	doc=docs/config.md
	need_file pc/config/re_config.c || return
	config_keys >"$TMPD/keys"
	if [ ! -s "$TMPD/keys" ]; then
		fail "no configuration keys found in the 'struct field' tables of pc/config/re_config*.c (the extraction no longer matches the code)"
		return
	fi
	if [ "$LIST" = 1 ]; then
		awk -F '\t' '{ print "config\t" $1 "\t" $2 }' "$TMPD/keys"
		return
	fi
	need_file "$doc" || return
	out=$(while IFS='	' read -r tab key; do
		if ! grep -Eq "\`([A-Za-z0-9_]+\.)*$key\`" "$doc"; then
			echo "docs.sh: config field '$key' ($tab) is in pc/config/re_config*.c but not in $doc"
		fi
	done <"$TMPD/keys")
	report "$out"
}

# ---- (c) command-line options ------------------------------------------------

# options FILE: "--name" for every entry of a `struct option` table and "-x"
# for every letter of the getopt_long/getopt option string.
options() {
	tokens "$1" | awk -F '\t' '
	{ t[++n] = $1; v[n] = $2 }
	END {
		for (i = 1; i <= n; i++) {
			if (t[i] == "W" && v[i] == "option" && t[i - 1] == "W" &&
			    v[i - 1] == "struct" && t[i + 1] == "W" && v[i + 2] == "[") {
				j = i + 3
				while (j <= n && v[j] != "{") j++
				depth = 1; j++
				for (; j <= n && depth > 0; j++) {
					if (v[j] == "{") { depth++; if (t[j + 1] == "S") print "--" v[j + 1] }
					else if (v[j] == "}") depth--
				}
				i = j
			}
			if (t[i] == "W" && (v[i] == "getopt_long" || v[i] == "getopt") &&
			    v[i + 1] == "(") {
				commas = 0
				for (j = i + 2; j <= n && commas < 2; j++)
					if (t[j] == "P" && v[j] == ",") commas++
				if (t[j] == "S") {
					s = v[j]
					for (m = 1; m <= length(s); m++) {
						c = substr(s, m, 1)
						if (c ~ /[A-Za-z0-9]/) print "-" c
					}
				}
			}
		}
	}' | sort -u
}

# man_text MANPAGE: the page with groff escapes removed.
man_text() {
	sed -e 's/\\-/-/g' -e 's/\\f\[[^]]*\]//g' -e 's/\\f([A-Za-z][A-Za-z]//g' \
	    -e 's/\\f[A-Za-z1-4]//g' -e 's/\\c//g' -e 's/\\&//g' -e 's/\\(en/-/g' "$1"
}

check_options() { # check_options PROG SOURCE
	prog=$1 src=$2 doc=docs/$1.1
	need_file "$src" || return
	options "$src" >"$TMPD/opts.$prog"
	if ! grep -q '^--' "$TMPD/opts.$prog"; then
		fail "no long options found in $src (the extraction no longer matches the code)"
		return
	fi
	if [ "$LIST" = 1 ]; then
		awk -v p="$prog" '{ print "option\t" p "\t" $0 }' "$TMPD/opts.$prog"
		return
	fi
	need_file "$doc" || return
	man_text "$doc" >"$TMPD/man.$prog"
	out=$(while read -r opt; do
		if ! grep -Eq -- "(^|[^A-Za-z0-9-])$opt([^A-Za-z0-9-]|\$)" "$TMPD/man.$prog"; then
			echo "docs.sh: option $opt is in $src but not in $doc"
		fi
	done <"$TMPD/opts.$prog")
	report "$out"
}

report() {
	[ -z "$1" ] && return
	printf '%s\n' "$1"
	FAILS=$((FAILS + $(printf '%s\n' "$1" | wc -l)))
}

check_faults
check_config
check_options roboelf pc/roboelf.c
check_options roboelf-tech tools/roboelf-tech/main.c
check_options galil-load tools/galil-load/main.c
check_options galil-sim tools/galil-sim/main.c

[ "$LIST" = 1 ] && exit $((FAILS > 0))
if [ "$FAILS" -gt 0 ]; then
	echo "docs.sh: $FAILS item(s) undocumented or stale"
	exit 1
fi
echo "docs.sh: ok: every FAULT message, config field and option is documented"
exit 0
