#!/bin/sh
# commands_selftest.sh - commands.sh fails where it must: on a small tree
# (a table, a Makefile with DEB_PKGS, one script) that passes, then with
# one gap made at a time: a script calling an undeclared command, the same
# hidden in "sh -c", behind timeout and behind a function of the script
# that runs its arguments, a declared command whose package
# make deps does not install, and a command said to come from a package it
# does not come from. Each must fail with its exact message.
set -u
TOP=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
pass=0; fail=0
ok() { pass=$((pass + 1)); echo "ok: $1"; }
nok() { fail=$((fail + 1)); echo "FAILED: $1"; }

# tree DIR: the passing tree
tree() {
	rm -rf "$1"
	mkdir -p "$1/docs" "$1/tests"
	cat >"$1/docs/commands.md" <<'EOF'
| command | package | called by |
|---|---|---|
| `grep` | grep (E) | tests/t.sh |
| `sed` | sed (E) | tests/t.sh |
| `sh` | dash (E) | tests/t.sh |
| `tmux` | tmux | tests/t.sh |
EOF
	printf 'DEB_PKGS = tmux\n%s:\n\t@true\nprint-deb-pkgs:\n\t@echo $(DEB_PKGS)\n' \
		'all tests check asan demo bench soak lint netrig install uninstall clean deps have-deps have-lint-deps fuzz-build' \
		>"$1/Makefile"
	printf '#!/bin/sh\nlook() { grep -q x "$1"; }\nlook f && sed -n 1p f\ntmux -V\n' >"$1/tests/t.sh"
}
# expect NAME WANT: commands.sh on $tmp/t fails and prints WANT as a line
expect() {
	out=$(COMMANDS_ROOT=$tmp/t sh "$TOP/tests/checks/commands.sh" 2>&1)
	rc=$?
	if [ "$rc" -ne 0 ] && printf '%s\n' "$out" | grep -qxF -- "$2"; then
		ok "$1"
	else
		nok "$1 (exit $rc): $out"
	fi
}

tree "$tmp/t"
out=$(COMMANDS_ROOT=$tmp/t sh "$TOP/tests/checks/commands.sh" 2>&1) &&
	[ "$out" = "commands.sh: 4 commands declared; every script's calls are among them and make deps installs their packages" ] &&
	ok "the passing tree passes" || nok "the passing tree: $out"

tree "$tmp/t"
printf 'pgrep -f roboelf\n' >>"$tmp/t/tests/t.sh"
expect "an undeclared command" "commands.sh: tests/t.sh calls 'pgrep', which docs/commands.md does not list (add it with its Debian package, and the package to DEB_PKGS)"

tree "$tmp/t"
printf 'sh -c "! pgrep -f roboelf >/dev/null"\n' >>"$tmp/t/tests/t.sh"
expect "an undeclared command in sh -c" "commands.sh: tests/t.sh calls 'pgrep', which docs/commands.md does not list (add it with its Debian package, and the package to DEB_PKGS)"

tree "$tmp/t"
printf 'timeout --kill-after=1 5 ip link\n' >>"$tmp/t/tests/t.sh"
expect "an undeclared command behind timeout" "commands.sh: tests/t.sh calls 'ip', which docs/commands.md does not list (add it with its Debian package, and the package to DEB_PKGS)"

tree "$tmp/t"
printf 'inns() { ip netns exec x "$@"; }\ninns sysctl -w a=1\n' >>"$tmp/t/tests/t.sh"
expect "an undeclared command through a function that runs its arguments" "commands.sh: tests/t.sh calls 'sysctl', which docs/commands.md does not list (add it with its Debian package, and the package to DEB_PKGS)"

tree "$tmp/t"
sed -i 's/^DEB_PKGS = tmux$/DEB_PKGS =/' "$tmp/t/Makefile"
expect "a package make deps does not install" "commands.sh: docs/commands.md: 'tmux' comes from tmux, which make deps does not install (add it to DEB_PKGS)"

tree "$tmp/t"
sed -i 's/^| `sed` | sed (E)/| `sed` | grep (E)/' "$tmp/t/docs/commands.md"
expect "the wrong package" "commands.sh: docs/commands.md says 'sed' comes from grep; here it belongs to sed"

echo "commands_selftest: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
