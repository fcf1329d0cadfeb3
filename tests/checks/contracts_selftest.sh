#!/bin/sh
# contracts_selftest.sh - contracts.sh finds a public function without a
# contract comment, and accepts a comment above a group of declarations.
set -u
cd "$(dirname "$0")/../.." || exit 1
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
pass=0; fail=0
check() { # check EXPECTED-RC EXPECTED-LAST-LINE WHAT
	out=$(sh tests/checks/contracts.sh --list "$tmp/d" 2>&1); rc=$?
	if [ "$rc" = "$1" ] && printf '%s\n' "$out" | grep -qxF "$2"; then
		pass=$((pass + 1)); echo "ok: $3"
	else
		fail=$((fail + 1)); echo "FAIL: $3: exit $rc; got:"
		printf '%s\n' "$out" | sed 's/^/    /'
	fi
}
mkdir -p "$tmp/d"
cat >"$tmp/d/x.h" <<'H'
#ifndef X_H
#define X_H
/* x_open() - open a thing; returns 0 or a negative error code. */
int x_open(const char *path,
	   int flags);
/* The getters: each returns the field, never fails. */
int x_a(void);
int x_b(void);
struct x { int (*cb)(void); };
typedef int (*x_fn)(int a);
#endif
H
check 0 "contracts.sh: 3 public functions declared, 0 without a contract comment" \
      "commented declarations and a commented group pass"
cat >>"$tmp/d/x.h" <<'H'

int x_close(int fd);
H
check 1 "contracts.sh: $tmp/d/x.h:13: x_close() has no contract comment" \
      "a declaration without a comment is named with file:line"
check 1 "contracts.sh: 4 public functions declared, 1 without a contract comment" \
      "the count is exact"
echo "contracts_selftest: $pass passed, $fail failed"
[ "$fail" = 0 ]
