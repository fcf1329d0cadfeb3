#!/bin/sh
# commands.sh - every external command is declared, and make deps installs it
# (docs/commands.md):
#   1. every command a shell script (tests/, tools/, packaging/, .ci/) or a
#      Makefile recipe calls is in the table, a shell builtin or keyword, one
#      of the script's own functions, or a path (the project's programs);
#      commands behind timeout, env, xargs, chrt, setpriv, exec and sh -c or
#      bash -c are followed;
#   2. every package of the table is in the Makefile's DEB_PKGS, or is
#      Essential or of priority required (marked (E)), or is optional;
#   3. every command of the table found here comes from its package (dpkg -S,
#      or a package that package depends on).
# Scripts are parsed by shfmt (--to-json) and read with jq. COMMANDS_ROOT
# names another tree to check (tests/checks/commands_selftest.sh).
# Exit 0, or 1 with one line per problem.
set -u
HERE=$(cd "$(dirname "$0")/../.." && pwd) || exit 1
ROOT=${COMMANDS_ROOT:-$HERE}
cd "$ROOT" || exit 1
for t in shfmt jq dpkg-query make; do
	command -v "$t" >/dev/null ||
		{ echo "commands.sh: FAILED: '$t' is not installed (make deps installs it)"; exit 1; }
done
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
bad=0
problem() { echo "commands.sh: $*"; bad=1; }

sh "$HERE/tools/cmdtable.sh" list docs/commands.md >"$tmp/table" || exit 1
cut -d' ' -f1 "$tmp/table" | sort >"$tmp/declared"
dup=$(uniq -d "$tmp/declared")
[ -z "$dup" ] || problem "docs/commands.md lists twice: $dup"

# Shell builtins and keywords (POSIX sh and bash): never looked up on PATH.
BUILTINS=': . [ [[ alias bg break builtin cd command continue declare echo eval
exec exit export false fg getopts hash jobs kill let local mapfile printf pushd
popd read readarray readonly return set shift source test times trap true type
typeset ulimit umask unalias unset wait'

# calls FILE: the words of every simple command in FILE, one call per line,
# tab-separated; a word that is not a literal reads "\001" (and @tsv writes a
# tab inside a word as \t). Own functions go to $tmp/funcs.
JQ_CALLS='def lit: if .Type == "Lit" then .Value
	elif .Type == "SglQuoted" then .Value
	elif .Type == "DblQuoted" then
		((.Parts // []) | map(if .Type == "Lit" then .Value else "\u0001" end) | join(""))
	else "\u0001" end;
	def wrappers: ["exec", "ip", "nice", "setsid", "time", "xargs", "setpriv",
		"env", "command", "timeout", "chrt", "sh", "bash"];
	.. | objects | select(.Type == "CallExpr") |
	[(.Args // [])[] | ((.Parts // []) | map(lit) | join(""))] |
	if (.[0] as $w | wrappers | index($w)) or ($runners | index(.[0]))
	then . else .[0:1] end | @tsv'
JQ_FUNCS='.. | objects | select(.Type == "FuncDecl") | .Name.Value'
# functions that run their arguments as a command ("$@" as the command, or
# after a wrapper: inns() { ip netns exec "$NS" "$@"; }, wait_for 10 grep)
JQ_RUNNERS='def at: .Parts | length == 1 and .[0].Type == "DblQuoted" and
		((.[0].Parts // []) | length == 1 and .[0].Type == "ParamExp" and
		 .[0].Param.Value == "@");
	.. | objects | select(.Type == "FuncDecl") | . as $f |
	select([.Body | .. | objects | select(.Type == "CallExpr") | .Args // [] |
		select(length > 0) |
		((.[0] | at) or ((.[0].Parts[0].Value // "") as $w |
		 (["ip", "exec", "timeout", "env", "xargs", "chrt", "setpriv",
		   "nice", "setsid"] | index($w)) and any(.[]; at)))] | any) |
	$f.Name.Value'
calls() {
	ast=$(mktemp "$tmp/ast.XXXXXX") || return
	shfmt --to-json <"$1" >"$ast" 2>"$ast.err" ||
		{ echo "commands.sh: $2: shfmt cannot parse it: $(head -n 1 "$ast.err")"; return; }
	jq -r "$JQ_FUNCS" "$ast" >>"$tmp/funcs"
	jq -r "$JQ_RUNNERS" "$ast" >>"$tmp/runners"
	jq -r --argjson runners "$(jq -R . "$tmp/runners" | jq -s .)" \
		"$JQ_CALLS" "$ast"
}

# command_of WORDS...: the command a call runs, following the wrappers; an
# "sh -c STRING" prints "-c STRING" for another round of parsing.
command_of() {
	c=$1; shift
	case $c in
	exec | nice | setsid | time | xargs | setpriv | env | command)
		[ "$c" = command ] && case ${1:-} in -v | -V) return ;; esac
		while [ $# -gt 0 ]; do
			case $1 in
			-n | -I | -d | -P | -L | -s | -a) [ "$c" = xargs ] && shift ;;
			-u) [ "$c" = env ] && shift ;;
			-* | *=*) ;;
			*) break ;;
			esac
			shift
		done
		[ $# -gt 0 ] && command_of "$@"
		;;
	timeout | chrt)
		while [ $# -gt 0 ]; do case $1 in -*) shift ;; *) break ;; esac; done
		[ $# -gt 1 ] && { shift; command_of "$@"; }
		;;
	ip)
		printf '%s\n' "$c"
		[ "${1:-}" = netns ] && [ "${2:-}" = exec ] && [ $# -ge 4 ] &&
			{ shift 3; command_of "$@"; }
		;;
	sh | bash)
		if [ "${1:-}" = -c ] && [ $# -ge 2 ]; then
			printf '%s\n' "$c"
			printf -- '-c %s\n' "$2"
		else
			printf '%s\n' "$c"
		fi
		;;
	*)
		printf '%s\n' "$c"
		# a function of the script that runs its arguments: its
		# first word that is not a number or an option is a command
		if grep -qxF -- "$c" "$tmp/runners"; then
			while [ $# -gt 0 ]; do
				case $1 in -* | [0-9]*) shift ;; *) break ;; esac
			done
			[ $# -gt 0 ] && command_of "$@"
		fi
		;;
	esac
}

# cmds_of NAME < calls: the commands the calls run, one per line; the
# strings of "sh -c" are parsed in turn; paths and words that are not
# literals (the project's programs, "$BIN/roboelf") are left out.
cmds_of() {
	sort -u | while IFS= read -r line; do
		# shellcheck disable=SC2086
		set -f; IFS='	'; set -- $line; IFS=' '; set +f
		[ $# -gt 0 ] || continue
		command_of "$@"
	done | sort -u | while IFS= read -r cmd; do
		case $cmd in
		-c\ *)
			sub=$(mktemp "$tmp/sub.XXXXXX")
			printf '%s\n' "${cmd#-c }" | tr '\001' X >"$sub"
			calls "$sub" "$1 (sh -c)" | cmds_of "$1"
			;;
		*"$(printf '\001')"* | */* | '') ;;
		*) printf '%s\n' "$cmd" ;;
		esac
	done
}

# check_calls NAME < calls: every command is declared, builtin, or one of
# the script's functions; one line per other command.
check_calls() {
	cmds_of "$1" | sort -u >"$tmp/cmds"
	{ cat "$tmp/declared" "$tmp/funcs"; printf '%s\n' $BUILTINS; } >"$tmp/known"
	grep -vxF -f "$tmp/known" "$tmp/cmds" | while IFS= read -r cmd; do
		echo "commands.sh: $1 calls '$cmd', which docs/commands.md does not list (add it with its Debian package, and the package to DEB_PKGS)"
	done
}

# 1. the scripts, then the Makefile's recipes (targets whose recipes only
# print under -n: `deb` runs tools/mkdeb.sh through $(MAKE) and is read as
# a script instead)
scripts=$(find tests tools packaging .ci -type f ! -path '*/corpus/*' \
	! -path '*/regress/*' 2>/dev/null | LC_ALL=C sort)
for f in $scripts; do
	head -n 1 "$f" | grep -qE '^#!(/usr)?/bin/(env )?(ba)?sh' || continue
	: >"$tmp/funcs"
	: >"$tmp/runners"
	calls "$f" "$f" | check_calls "$f" >>"$tmp/undeclared"
done
: >"$tmp/funcs"
: >"$tmp/runners"
make -n -B --no-print-directory all tests check asan demo bench soak lint \
	netrig install uninstall clean deps have-deps have-lint-deps fuzz-build \
	2>/dev/null | grep -vE '^make(\[[0-9]+\])?: ' |
	awk '# one single-line command per first word is enough (the compiler
	# lines differ only in their files)
	{ cont = prev ~ /\\$/; prev = $0 }
	cont || /\\$/ || !seen[$1]++' >"$tmp/recipes.sh"
calls "$tmp/recipes.sh" Makefile | check_calls Makefile >>"$tmp/undeclared"
if [ -s "$tmp/undeclared" ]; then
	sort -u "$tmp/undeclared"
	bad=1
fi

# 2. every package is installed by make deps
deb_pkgs=" $(make -s --no-print-directory print-deb-pkgs) "
while read -r cmd pkg flag; do
	case $flag in
	o) ;;
	e)
		st=$(dpkg-query -W -f='${Essential} ${Priority}' "$pkg" 2>/dev/null)
		case $st in
		yes\ * | *\ required) ;;
		*) problem "docs/commands.md marks $pkg (E) for '$cmd', but it is neither Essential nor required ('$st'): put it in DEB_PKGS" ;;
		esac
		;;
	*)
		case $deb_pkgs in
		*" $pkg "*) ;;
		*) problem "docs/commands.md: '$cmd' comes from $pkg, which make deps does not install (add it to DEB_PKGS)" ;;
		esac
		;;
	esac
done <"$tmp/table"

# 3. each command found here comes from its package: one dpkg -S over every
# candidate path (the one found, its /usr twin, what it links to and that
# one's twin: merged /usr registers files under /bin or /usr/bin)
twins() {
	printf '%s\n' "$1" "$(echo "$1" | sed -E 's#^/usr/(s?bin)/#/\1/#')" \
		"$(echo "$1" | sed -E 's#^/(s?bin)/#/usr/\1/#')"
}
: >"$tmp/paths"
while read -r cmd pkg flag; do
	path=""
	oldifs=$IFS; IFS=:
	for d in $PATH; do
		[ -f "$d/$cmd" ] && [ -x "$d/$cmd" ] && { path=$d/$cmd; break; }
	done
	IFS=$oldifs
	if [ -z "$path" ]; then
		[ "$flag" = o ] || problem "'$cmd' ($pkg) is not installed here: run make deps"
		continue
	fi
	# run-all.sh's PATH holds links to the commands: start where one points
	link=$(readlink "$path" 2>/dev/null) && case $link in /*) path=$link ;; esac
	for p in $(twins "$path"; twins "$(readlink -f "$path")"); do
		echo "$cmd $pkg $p"
	done >>"$tmp/paths"
done <"$tmp/table"
cut -d' ' -f3 "$tmp/paths" | sort -u | xargs dpkg -S 2>/dev/null |
	grep -v '^diversion' | sed -E 's/^(.*): (\/.*)$/\2 \1/; s/,//g; s/:[a-z0-9_]+( |$)/\1/g' \
	>"$tmp/owners"
while read -r cmd pkg flag; do
	grep -q "^$cmd " "$tmp/paths" || continue
	found=$(grep "^$cmd " "$tmp/paths" | cut -d' ' -f3 | while read -r p; do
		awk -v p="$p" '$1 == p { for (i = 2; i <= NF; i++) print $i }' "$tmp/owners"
	done | sort -u)
	[ -n "$found" ] || { problem "'$cmd': dpkg knows no package for $(grep "^$cmd " "$tmp/paths" | head -n 1 | cut -d' ' -f3)"; continue; }
	echo "$found" | grep -qxF "$pkg" && continue
	deps=$(dpkg-query -W -f='${Depends}, ${Pre-Depends}' "$pkg" 2>/dev/null |
		tr ',|' '\n\n' | sed 's/(.*//; s/:any//; s/ //g')
	for o in $found; do
		echo "$deps" | grep -qxF "$o" && continue 2
	done
	problem "docs/commands.md says '$cmd' comes from $pkg; here it belongs to $(echo $found)"
done <"$tmp/table"

[ "$bad" -eq 0 ] || exit 1
echo "commands.sh: $(wc -l <"$tmp/table") commands declared; every script's calls are among them and make deps installs their packages"
