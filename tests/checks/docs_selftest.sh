#!/bin/sh
# docs_selftest.sh - prove that tests/checks/docs.sh can fail, and fails for
# the right reason (run by `make check` from the repo root; POSIX sh).
#
# 1. A small synthetic tree in which everything is documented: docs.sh must
#    pass (exit 0); then each kind of gap is made in a copy of it, and docs.sh
#    must fail (exit 1) naming exactly that item.
# 2. A copy of the real tree: deleting one FAULT line from docs/operator.md,
#    one config key from docs/config.md and one option from each man page,
#    or adding a FAULT template, a config key or an option to the code, must
#    make docs.sh fail naming that item (whatever else the copy reports).
set -u
TOP=$(cd "$(dirname "$0")/../.." && pwd)
DOCS="$TOP/tests/checks/docs.sh"
TMP=$(mktemp -d "${TMPDIR:-/tmp}/docs-selftest.XXXXXX") || exit 1
trap 'rm -rf "$TMP"' EXIT
trap 'exit 1' INT TERM
failed=0; passed=0

ok() { passed=$((passed + 1)); echo "ok: $*"; }
bad() { failed=$((failed + 1)); echo "FAILED: $*"; }

# run_docs DIR: docs.sh on DIR; output in $TMP/out, exit code in $rc.
run_docs() {
	sh "$DOCS" "$1" >"$TMP/out" 2>&1
	rc=$?
}

# expect_fail NAME DIR LINE: docs.sh on DIR exits 1 and prints LINE exactly.
expect_fail() {
	run_docs "$2"
	if [ "$rc" -ne 1 ]; then
		bad "$1: docs.sh exited $rc, expected 1"; sed 's/^/  | /' "$TMP/out"
	elif ! grep -qxF "$3" "$TMP/out"; then
		bad "$1: docs.sh did not print: $3"; sed 's/^/  | /' "$TMP/out"
	else
		ok "$1"
	fi
}

# drop FILE TEXT: delete every line of FILE that contains TEXT (fixed string).
drop() {
	awk -v t="$2" 'index($0, t) == 0' "$1" >"$1.new" && mv "$1.new" "$1"
}

# ---- 1. synthetic tree ---------------------------------------------------------
S=$TMP/syn
mkdir -p "$S/pc/super" "$S/pc/config" "$S/tools/galil-load" "$S/tools/galil-sim" \
	"$S/tools/roboelf-tech" "$S/docs"
cat >"$S/pc/super/re_fault.c" <<'EOF'
/* "FAULT FAKE: in a comment. Recovery: never counted" */
static const char *const re_fclass_names[RE_FC_COUNT] = {
    [RE_FC_NONE] = "NONE",
    [RE_FC_MOTION] = "MOTION",
    [RE_FC_ESTOP] = "ESTOP",
};
static const struct re_fault_msg re_fault_table[] = {
	{RE_F_ONE, RE_FC_MOTION,
	 "axis {a}: it moved {i0} counts (\"quoted\")",
	 "press the E-stop and keep it pressed, then restart roboelf"},
	{RE_F_TWO, RE_FC_ESTOP,
	 "the relay is gone ({s}); "
	 "split over two literals",
	 "press the hardware E-stop now"},
};
static int n = sizeof(re_fault_table) / sizeof(re_fault_table[0]);
EOF
cat >"$S/pc/super/re_super.c" <<'EOF'
static void f(char *b, int id)
{
	snprintf(b, 9, "FAULT PROGRAM: unknown fault %d. Recovery: quit, "
		 "note the log", id);
}
EOF
cat >"$S/pc/config/re_config.c" <<'EOF'
#define I(s, m, lo, hi) { #m, FT_INT, offsetof(s, m), lo, hi, 0, NULL, NULL }
#define IK(key, s, m, lo, hi) { key, FT_INT, offsetof(s, m), lo, hi, 0, NULL, NULL }
static const struct field sub_fields[] = {
	I(struct re_sub, depth_mm, 1, 9),
	{"custom_key", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_custom},
	{NULL, FT_INT, 0, 0, 0, 0, NULL, NULL},
};
static const struct field root_fields[] = {
	IK("speed", struct re_root, speed_cps, 1, 9),
	M(struct re_root, sub, sub_fields),
	END,
};
EOF
cat >"$S/pc/roboelf.c" <<'EOF'
static const struct option lo[] = {
	{"config", required_argument, NULL, 'c'},
	{"show-calibration", required_argument, NULL, 's'},
	{NULL, 0, NULL, 0},
};
int main(int argc, char **argv) { return getopt_long(argc, argv, "c:h", lo, NULL); }
EOF
cat >"$S/tools/galil-load/main.c" <<'EOF'
static const struct option long_opts[] = {
    {"address", required_argument, NULL, 'a'},
    {NULL, 0, NULL, 0},
};
int main(int argc, char **argv)
{
	return getopt_long(argc, argv,
			   ":a:", long_opts, NULL);
}
EOF
cat >"$S/tools/roboelf-tech/main.c" <<'EOF'
static const struct option lo[] = {
    {"wait", required_argument, NULL, 'W'},
    {NULL, 0, NULL, 0},
};
int main(int argc, char **argv) { return getopt_long(argc, argv, "", lo, NULL); }
EOF
cat >"$S/tools/galil-sim/main.c" <<'EOF'
static const struct option longopts[] = {
    {"port", required_argument, NULL, 'p'},
    {"no-relay-link", no_argument, NULL, 'n'},
    {NULL, 0, NULL, 0},
};
int main(int argc, char **argv) { return getopt_long(argc, argv, "", longopts, NULL); }
EOF
cat >"$S/docs/operator.md" <<'EOF'
# faults
```
FAULT MOTION: axis {a}: it moved {i0} counts ("quoted"). Recovery: press the E-stop and keep it pressed, then restart roboelf
```
    FAULT ESTOP: the relay is gone ({s}); split over two literals. Recovery: press the hardware E-stop now
An internal error: `FAULT PROGRAM: unknown fault N. Recovery: quit, note the log`.
EOF
cat >"$S/docs/config.md" <<'EOF'
| `speed` | counts/s |
| `sub` | mapping |
| `sub.depth_mm` | mm |
| `custom_key` | |
EOF
printf '.TP\n.BR \\-c ", " \\-\\-config " \\fIFILE\\fR"\n.TP\n.B \\-h\n.BI \\-\\-show\\-calibration " FILE"\n' >"$S/docs/roboelf.1"
printf '.BR \\-a ", " \\-\\-address\n' >"$S/docs/galil-load.1"
printf '.BI \\-\\-wait " S"\n' >"$S/docs/roboelf-tech.1"
printf '.BI \\-\\-port " N"\n.B \\-\\-no\\-relay\\-link\n' >"$S/docs/galil-sim.1"

run_docs "$S"
if [ "$rc" -eq 0 ]; then
	ok "synthetic tree, everything documented: docs.sh passes"
else
	bad "synthetic tree: docs.sh exited $rc, expected 0"; sed 's/^/  | /' "$TMP/out"
fi
sh "$DOCS" --list "$S" >"$TMP/list"
if [ "$(grep -c '^fault	' "$TMP/list")" -eq 2 ] &&
   grep -qxF 'fault	RE_F_TWO	FAULT ESTOP: the relay is gone ({s}); split over two literals. Recovery: press the hardware E-stop now' "$TMP/list" &&
   grep -qxF 'config	sub_fields	depth_mm' "$TMP/list" &&
   grep -qxF 'config	sub_fields	custom_key' "$TMP/list" &&
   grep -qxF 'config	root_fields	speed' "$TMP/list" &&
   [ "$(grep -c '^config	' "$TMP/list")" -eq 4 ] &&
   grep -qxF 'option	roboelf	-h' "$TMP/list" &&
   grep -qxF 'option	galil-load	-a' "$TMP/list" &&
   grep -qxF 'option	roboelf-tech	--wait' "$TMP/list" &&
   [ "$(grep -c '^option	galil-sim	' "$TMP/list")" -eq 2 ]; then
	ok "synthetic tree: --list extracts exactly the items"
else
	bad "synthetic tree: --list output differs"; sed 's/^/  | /' "$TMP/list"
fi

# each kind of gap, in a fresh copy
gap() { rm -rf "$TMP/g"; cp -R "$S" "$TMP/g"; }
gap; drop "$TMP/g/docs/operator.md" 'FAULT MOTION: axis'
expect_fail "synthetic: FAULT line removed" "$TMP/g" \
	'docs.sh: FAULT message RE_F_ONE ("FAULT MOTION: axis {a}: it moved {i0} counts ("quoted"). Recovery: press the E-stop and keep it pressed, then restart roboelf") is in pc/super/re_fault.c but not in docs/operator.md'
gap; sed 's/then restart roboelf/then restart/' "$S/docs/operator.md" >"$TMP/g/docs/operator.md"
expect_fail "synthetic: recovery text changed in the doc" "$TMP/g" \
	'docs.sh: FAULT message RE_F_ONE ("FAULT MOTION: axis {a}: it moved {i0} counts ("quoted"). Recovery: press the E-stop and keep it pressed, then restart roboelf") is in pc/super/re_fault.c but not in docs/operator.md'
gap; drop "$TMP/g/docs/operator.md" 'unknown fault'
expect_fail "synthetic: printf FAULT line removed" "$TMP/g" \
	'docs.sh: FAULT message "FAULT PROGRAM: unknown fault %d. Recovery: quit, note the log" is in pc/super/re_super.c but not in docs/operator.md'
gap; echo 'FAULT MOTION: it flew away. Recovery: catch it' >>"$TMP/g/docs/operator.md"
expect_fail "synthetic: stale FAULT line in the doc" "$TMP/g" \
	'docs.sh: "FAULT MOTION: it flew away. Recovery: catch it" is in docs/operator.md:7 but the code has no such FAULT message (stale)'
gap; drop "$TMP/g/docs/config.md" '`sub.depth_mm`'
expect_fail "synthetic: config key removed" "$TMP/g" \
	"docs.sh: config field 'depth_mm' (sub_fields) is in pc/config/re_config*.c but not in docs/config.md"
gap; drop "$TMP/g/docs/roboelf.1" '\-h'
expect_fail "synthetic: short option removed" "$TMP/g" \
	'docs.sh: option -h is in pc/roboelf.c but not in docs/roboelf.1'
gap; drop "$TMP/g/docs/galil-sim.1" 'no\-relay'
expect_fail "synthetic: long option removed" "$TMP/g" \
	'docs.sh: option --no-relay-link is in tools/galil-sim/main.c but not in docs/galil-sim.1'
gap; rm "$TMP/g/docs/galil-load.1"
expect_fail "synthetic: man page missing" "$TMP/g" \
	"docs.sh: cannot read 'docs/galil-load.1'"
gap; : >"$TMP/g/pc/config/re_config.c"
expect_fail "synthetic: no config table found" "$TMP/g" \
	"docs.sh: no configuration keys found in the 'struct field' tables of pc/config/re_config*.c (the extraction no longer matches the code)"

# ---- 2. the real tree ----------------------------------------------------------
R=$TMP/real
mkdir -p "$R/tools/galil-load" "$R/tools/galil-sim" "$R/tools/roboelf-tech"
cp -R "$TOP/pc" "$TOP/docs" "$R/" &&
cp "$TOP/tools/roboelf-tech/main.c" "$R/tools/roboelf-tech/" &&
cp "$TOP/tools/galil-load/main.c" "$R/tools/galil-load/" &&
cp "$TOP/tools/galil-sim/main.c" "$R/tools/galil-sim/" || { bad "cannot copy the tree"; exit 1; }
sh "$DOCS" --list "$R" >"$TMP/rlist"
nf=$(grep -c '^fault	' "$TMP/rlist"); nk=$(grep -c '^config	' "$TMP/rlist")
no=$(grep -c '^option	' "$TMP/rlist")
echo "real tree: $nf FAULT templates, $nk config keys, $no options extracted"
if [ "$nf" -ge 20 ] && [ "$nk" -ge 40 ] && [ "$no" -ge 25 ]; then
	ok "real tree: extraction finds the tables"
else
	bad "real tree: too little extracted"
fi

real() { rm -rf "$TMP/r2"; cp -R "$R" "$TMP/r2"; }

# a FAULT line removed from operator.md: the first template of the table
first=$(awk -F '\t' '$1 == "fault" { print $2 "\t" $3; exit }' "$TMP/rlist")
fid=${first%%	*}; fline=${first#*	}
real; drop "$TMP/r2/docs/operator.md" "$fline"
expect_fail "real: FAULT line $fid removed from operator.md" "$TMP/r2" \
	"docs.sh: FAULT message $fid (\"$fline\") is in pc/super/re_fault.c but not in docs/operator.md"

# a FAULT template added to the code
real; awk '{ print } /re_fault_table\[\] = \{/ {
	print "\t{RE_F_SELFTEST, RE_FC_MOTION, \"a new message\", \"a new recovery\"}," }' \
	"$R/pc/super/re_fault.c" >"$TMP/r2/pc/super/re_fault.c"
expect_fail "real: FAULT template added to re_fault.c" "$TMP/r2" \
	'docs.sh: FAULT message RE_F_SELFTEST ("FAULT MOTION: a new message. Recovery: a new recovery") is in pc/super/re_fault.c but not in docs/operator.md'

# a FAULT printf line added elsewhere in pc/
real; printf 'static const char *x = "FAULT COMM: lost %%s. Recovery: "\n\t"check it";\n' \
	>"$TMP/r2/pc/re_selftest.c"
expect_fail "real: printf FAULT line added in pc/" "$TMP/r2" \
	'docs.sh: FAULT message "FAULT COMM: lost %s. Recovery: check it" is in pc/re_selftest.c but not in docs/operator.md'

# a config key: removed from config.md, and added to the loader
key=$(awk -F '\t' '$1 == "config" && $2 == "log_fields" { print $3; exit }' "$TMP/rlist")
# every line that documents it as docs.sh reads them, dotted forms too
# (`log.path`)
real; awk -v k="$key" '$0 !~ ("`([A-Za-z0-9_]+[.])*" k "`")' "$TMP/r2/docs/config.md" \
	>"$TMP/r2/docs/config.md.new" && mv "$TMP/r2/docs/config.md.new" "$TMP/r2/docs/config.md"
expect_fail "real: config key '$key' removed from config.md" "$TMP/r2" \
	"docs.sh: config field '$key' (log_fields) is in pc/config/re_config*.c but not in docs/config.md"
real; awk '{ print } /static const struct field log_fields\[\] = \{/ {
	print "\tB(struct re_config_log, selftest_compress)," }' "$R/pc/config/re_config_schema.c" >"$TMP/r2/pc/config/re_config_schema.c"
expect_fail "real: config key added to re_config_schema.c" "$TMP/r2" \
	"docs.sh: config field 'selftest_compress' (log_fields) is in pc/config/re_config*.c but not in docs/config.md"

# options: the last long option of each program removed from its man page,
# and a new option added to roboelf
for p in roboelf roboelf-tech galil-load galil-sim; do
	case $p in
	roboelf) src=pc/roboelf.c ;;
	roboelf-tech) src=tools/roboelf-tech/main.c ;;
	galil-load) src=tools/galil-load/main.c ;;
	galil-sim) src=tools/galil-sim/main.c ;;
	esac
	opt=$(awk -F '\t' -v p="$p" '$1 == "option" && $2 == p && $3 ~ /^--/ { o = $3 } END { print o }' "$TMP/rlist")
	real
	sed -e 's/\\-/-/g' "$R/docs/$p.1" | awk -v t="$opt" '
		{ if (match($0, t "([^A-Za-z0-9-]|$)") == 0) print }' >"$TMP/r2/docs/$p.1"
	expect_fail "real: option $opt removed from $p.1" "$TMP/r2" \
		"docs.sh: option $opt is in $src but not in docs/$p.1"
done
real; awk '{ print } /\{"period", required_argument/ {
	print "\t\t{\"selftest-dry-run\", no_argument, NULL, 0x100}," }' "$R/pc/roboelf.c" >"$TMP/r2/pc/roboelf.c"
expect_fail "real: option added to roboelf.c" "$TMP/r2" \
	'docs.sh: option --selftest-dry-run is in pc/roboelf.c but not in docs/roboelf.1'

echo "docs_selftest: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
