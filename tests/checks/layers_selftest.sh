#!/bin/sh
# layers_selftest.sh - layers.sh finds what it must: synthetic object trees
# with a clean dependency, a loop and an upward use, each checked for the
# exact verdict and exit status.
set -u
cd "$(dirname "$0")/../.." || exit 1
CC=${CC:-cc}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
pass=0; fail=0
ok() { pass=$((pass + 1)); echo "ok: $1"; }
bad() { fail=$((fail + 1)); echo "FAIL: $1"; }

# obj NAME 'C source': compile one module of the synthetic tree
obj() {
	mkdir -p "$tmp/t/obj/$(dirname "$1")"
	printf '%s\n' "$2" >"$tmp/src.c"
	"$CC" -c -o "$tmp/t/obj/$1.o" "$tmp/src.c" || exit 1
}
run() { # run EXPECTED-RC EXPECTED-LINE WHAT
	out=$(BUILD="$tmp/t" sh tests/checks/layers.sh 2>&1); rc=$?
	if [ "$rc" = "$1" ] && printf '%s\n' "$out" | grep -qxF "$2"; then
		ok "$3"
	else
		bad "$3: exit $rc, expected $1 and the line '$2'; got:"
		printf '%s\n' "$out" | sed 's/^/    /'
	fi
}

obj pc/super/re_a 'int b(void); int a(void) { return b(); }'
obj pc/super/re_b 'int b(void) { return 1; }'
obj pc/base/base_x 'int x(void) { return 2; }'
run 0 "layers.sh: 3 modules, 1 dependencies, 0 loop(s) holding 0 modules, 0 problem(s)" \
    "a clean tree passes"

obj pc/super/re_b 'int a(void); int b(void) { return a(); }'
run 1 "layers.sh: loop of 2 modules: pc/super/re_a pc/super/re_b" "a loop of two modules is found"

obj pc/super/re_b 'int b(void) { return 1; }'
obj pc/base/base_x 'int a(void); int x(void) { return a(); }'
run 1 "layers.sh: pc/base/base_x (base) uses pc/super/re_a (super), which is not below it" \
    "the base using the supervisor is found"

rm -f "$tmp/t/obj/pc/base/base_x.o"
obj pc/config/re_k 'int k(void) { return 3; }'
obj pc/super/re_b 'int k(void); int b(void) { return k(); }'
run 1 "layers.sh: pc/super/re_b (super) uses pc/config/re_k (config), which is not below it" \
    "the safety core using the configuration is found"

obj pc/super/re_b 'int b(void) { return 1; }'
rm -f "$tmp/t/obj/pc/config/re_k.o"
obj tools/galil-sim/s 'int b(void); int s(void) { return b(); }'
obj pc/super/re_c 'int s(void); int c(void) { return s(); }'
run 1 "layers.sh: pc/super/re_c (super) uses tools/galil-sim/s (galil-sim), which is not below it" \
    "the supervisor using the simulator is found"

rm -f "$tmp/t/obj/pc/super/re_c.o" "$tmp/t/obj/tools/galil-sim/s.o"
obj pc/re_d 'int b(void); int d(void) { return b(); }'
run 1 "layers.sh: pc/re_d is in no folder of the layering" \
    "a module outside the layering's folders is found"

echo "layers_selftest: $pass passed, $fail failed"
[ "$fail" = 0 ]
