/*
 * test_dmc_static.c - dmc/ fits a DMC-4030 and starts safely from a bare
 * XQ; its loops wait with literal periods equal to its constants.
 *
 * The limits come from galil-notes.md 3.4 (DMC-40x0): 80 characters per
 * line, 4000 lines, labels '#' + up to 7 characters starting with a letter
 * (510 of them), variable names up to 8 characters (510 variables), 30
 * arrays and 24000 array elements. They are checked on the program as
 * galil-load sends it (comments and blank lines stripped), so the DMC
 * cannot silently grow past them.
 */
#include <ctype.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "dmc_h.h"
#include "dmc_lint.h"
#include "dmc_text.h"

#define LINE_MAX_CH 80
#define PROG_LINES  4000
#define LABELS_MAX  510
#define LABEL_LEN   7
#define VARS_MAX    510
#define VAR_LEN	    8
#define ARRAYS_MAX  30
#define ARRAY_SPACE 24000
#define NAMES_MAX   600

static char prog[DMC_H_PROG_MAX];
static int prog_len;

struct names {
	char name[NAMES_MAX][16];
	int n;
};

static int names_add(struct names *ns, const char *s, size_t n)
{
	char tmp[16];

	snprintf(tmp, sizeof(tmp), "%.*s", (int)(n < 15 ? n : 15), s);
	for (int i = 0; i < ns->n; i++)
		if (!strcmp(ns->name[i], tmp))
			return 0;
	if (ns->n < NAMES_MAX)
		strcpy(ns->name[ns->n++], tmp);
	return 1;
}

static int names_has(const struct names *ns, const char *s)
{
	for (int i = 0; i < ns->n; i++)
		if (!strcmp(ns->name[i], s))
			return 1;
	return 0;
}

/* Copy line @i (0-based) of the program into @out; Return its length or -1. */
static int prog_line(int i, char *out, size_t cap)
{
	const char *p = prog;

	while (i-- > 0) {
		p = strchr(p, '\n');
		if (!p)
			return -1;
		p++;
	}
	if (!*p)
		return -1;
	size_t n = strcspn(p, "\n");

	snprintf(out, cap, "%.*s", (int)n, p);
	return (int)n;
}

/* The program as galil-load sends it: dmc/ and the seal (made from the
 * tests' default parameters, as galil-load makes it from roboelf.yaml). */
static int setup_prog(void **state)
{
	static struct dmc_h h;

	(void)state;
	if (dmc_h_open(&h) < 0) {
		fprintf(stderr, "cannot load dmc/: %s\n", h.err);
		dmc_h_close(&h);
		return -1;
	}
	prog_len = (int)h.prog_len;
	memcpy(prog, h.prog, h.prog_len);
	prog[prog_len] = '\0';
	dmc_h_close(&h);
	return 0;
}

/* Every raw source line of the files in dmc/MANIFEST: <= 80 characters,
 * no tab (style.md 14 h). */
static void test_source_lines(void **state)
{
	const char *top = getenv("ROBOELF_TOP");
	char path[512], name[128], line[512];
	FILE *man;
	int files = 0;

	(void)state;
	top = top && *top ? top : ".";
	snprintf(path, sizeof(path), "%s/dmc/MANIFEST", top);
	man = fopen(path, "r");
	assert_non_null(man);
	while (fscanf(man, "%127s", name) == 1) {
		FILE *fp;
		int no = 0;

		if (!strcmp(name, "@seal")) /* generated: test_lines */
			continue;
		snprintf(path, sizeof(path), "%s/dmc/%s", top, name);
		fp = fopen(path, "r");
		if (!fp)
			fail_msg("cannot open '%s'", path);
		while (fgets(line, sizeof(line), fp)) {
			size_t n = strcspn(line, "\r\n");

			no++;
			if (n > LINE_MAX_CH || memchr(line, '\t', n))
				fail_msg("%s:%d: %zu characters or a tab", path,
					 no, n);
		}
		fclose(fp);
		files++;
	}
	fclose(man);
	assert_int_equal(files, 2);
}

/* Stripped program: line count, length, first line EN, no backslash. */
static void test_lines(void **state)
{
	char line[256];
	int i, n;

	(void)state;
	assert_true(prog_len > 0);
	assert_int_equal(prog_line(0, line, sizeof(line)), 2);
	assert_string_equal(line, "EN");
	assert_null(strchr(prog, '\\'));
	for (i = 0; (n = prog_line(i, line, sizeof(line))) >= 0; i++)
		if (n > LINE_MAX_CH)
			fail_msg("program line %d: %d characters: %s", i + 1, n,
				 line);
	assert_true(i <= PROG_LINES);
	assert_true(i > 100); /* the program is really there */
}

/* Scan one statement for identifiers outside strings. */
static void scan_idents(const char *s, struct names *vars, struct names *refs)
{
	int in_str = 0;

	for (const char *p = s; *p; p++) {
		if (*p == '"') {
			in_str = !in_str;
			continue;
		}
		if (in_str)
			continue;
		if (*p == '#') {
			size_t n = 1;

			while (isalnum((unsigned char)p[n]))
				n++;
			names_add(refs, p + 1, n - 1);
			p += n - 1;
		} else if (islower((unsigned char)*p) &&
			   (p == s ||
			    (!isalnum((unsigned char)p[-1]) && p[-1] != '^' &&
			     p[-1] != '~' && p[-1] != '_'))) {
			size_t n = 0;

			while (isalnum((unsigned char)p[n]))
				n++;
			if (n > VAR_LEN)
				fail_msg("variable '%.*s' longer than %d",
					 (int)n, p, VAR_LEN);
			names_add(vars, p, n);
			p += n - 1;
		} else if (isalpha((unsigned char)*p)) {
			while (isalnum((unsigned char)p[1]))
				p++;
		}
	}
}

/* The program as galil-load sends it passes every rule of the one linter
 * galil-load --check uses (pc/dmc/dmc_lint.h) on the DMC-4030, with
 * galil-load's identity line counted: no finding, and the counts fit. */
static void test_lint_clean(void **state)
{
	struct dmc_lint r = {0};
	int n;

	(void)state;
	n = dmc_lint_text(prog, (size_t)prog_len, dmc_model_default(), 1, &r);
	for (int i = 0; i < r.n; i++)
		fprintf(stderr, "program line %d: %s: %s\n", r.v[i].line,
			dmc_rule(r.v[i].rule)->name, r.v[i].msg);
	assert_int_equal(n, 0);
	assert_true(r.lines > 100 && r.lines <= PROG_LINES);
	assert_true(r.labels > 10 && r.labels <= LABELS_MAX);
	assert_true(r.vars > 10 && r.vars <= VARS_MAX);
	dmc_lint_free(&r);
}

/* Routines the interface names (docs/dmc-interface.md). */
static const char *const auto_labels[] = {
    "AUTO",   "MAIN",	"MOTION", "POSERR", "LIMSWI",
    "CMDERR", "TCPERR", "AMPERR", "FAULT",  NULL};

/* Variables the interface names. */
static const char *const interface_vars[] = {
    "vmin",  "vmax",  "wst",   "wen",	"stp",	"srev",	 "sfwd",
    "jin",   "jval",  "jpol",  "jto",	"wdto", "hbpc",	 "armreq",
    "pcflt", "state", "fcode", "faxis", "fdet", "fline", "hbdmc",
    "jraw",  "jcmd",  "mcmd",  "vcur",	"vers", NULL};

/* Labels: syntax, length, unique, count; every #target defined. */
static void test_labels(void **state)
{
	static struct names labels, vars, refs;
	char line[256];

	(void)state;
	memset(&labels, 0, sizeof(labels));
	memset(&vars, 0, sizeof(vars));
	memset(&refs, 0, sizeof(refs));
	for (int i = 0; prog_line(i, line, sizeof(line)) >= 0; i++) {
		if (line[0] == '#') {
			size_t n = strspn(
			    line + 1, "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
				      "abcdefghijklmnopqrstuvwxyz0123456789");

			if (!isalpha((unsigned char)line[1]) || n > LABEL_LEN ||
			    (line[1 + n] && line[1 + n] != ';'))
				fail_msg("line %d: bad label '%s'", i + 1,
					 line);
			if (!names_add(&labels, line + 1, n))
				fail_msg("line %d: duplicate label '%s'", i + 1,
					 line);
			continue;
		}
		scan_idents(line, &vars, &refs);
	}
	assert_true(labels.n <= LABELS_MAX);
	for (int i = 0; i < refs.n; i++)
		if (!names_has(&labels, refs.name[i]))
			fail_msg("undefined label '#%s'", refs.name[i]);
	for (const char *const *a = auto_labels; *a; a++)
		if (!names_has(&labels, *a))
			fail_msg("label '#%s' missing", *a);
	assert_true(vars.n <= VARS_MAX);
	/* the interface variables are all there */
	for (const char *const *v = interface_vars; *v; v++)
		if (!names_has(&vars, *v))
			fail_msg("variable '%s' missing", *v);
}

/* Statements: upper-case commands, ST always names axes, IF/ENDIF balanced,
 * no comment left, arrays within the controller's limits. */
static void test_statements(void **state)
{
	char line[256];
	int ifs = 0, endifs = 0, arrays = 0, elements = 0;

	(void)state;
	for (int i = 0; prog_line(i, line, sizeof(line)) >= 0; i++) {
		size_t pos = 0, at, len;
		char stmt[256];

		if (line[0] == '#')
			continue;
		if (strchr(line, '\''))
			fail_msg("line %d: comment left: %s", i + 1, line);
		/* the one splitter: ';' inside a "string" does not split */
		while (dmc_stmt_next(line, strlen(line), &pos, &at, &len)) {
			char *st = stmt;
			int n;

			if (!len)
				continue;
			memcpy(stmt, line + at, len);
			stmt[len] = '\0';
			while (*st == ' ')
				st++;
			if (islower((unsigned char)st[0])) {
				if (!strchr(st, '='))
					fail_msg("line %d: '%s' is no command",
						 i + 1, st);
				continue;
			}
			if (!isupper((unsigned char)st[0]) ||
			    !isupper((unsigned char)st[1]))
				fail_msg("line %d: bad command '%s'", i + 1,
					 st);
			if (!strncmp(st, "ST", 2) || !strncmp(st, "MO", 2)) {
				const char *a = st + 2;

				while (*a == ' ')
					a++;
				if (strspn(a, "ABC") == 0 ||
				    a[strspn(a, "ABC")])
					fail_msg("line %d: '%s' must name its "
						 "axes",
						 i + 1, st);
			}
			/* a bare AB (AB 0) would abort the program too */
			if (!strncmp(st, "AB", 2) && strcmp(st, "AB 1"))
				fail_msg("line %d: '%s' must be 'AB 1'", i + 1,
					 st);
			if (!strncmp(st, "IF", 2))
				ifs++;
			if (!strcmp(st, "ENDIF"))
				endifs++;
			if (!strncmp(st, "DM ", 3) &&
			    sscanf(st, "DM %*[a-z0-9][%d]", &n) == 1) {
				arrays++;
				elements += n;
			}
		}
	}
	assert_int_equal(ifs, endifs);
	assert_true(arrays > 0);
	assert_true(arrays <= ARRAYS_MAX);
	assert_true(elements <= ARRAY_SPACE);
}

/* The simulator accepts the download; a bare XQ runs line 0 (EN) and
 * nothing else: no variable defined, motors off, nothing moves. */
static void test_bare_xq(void **state)
{
	struct dmc_h h;
	int rc;

	(void)state;
	rc = dmc_h_open(&h);
	if (rc < 0)
		fail_msg("%s", h.err);
	assert_int_equal(dmc_h_cmd(&h, "XQ", NULL, 0), 0);
	dmc_h_advance(&h, 100);
	assert_int_equal(ctrl_threads(h.ctrl), 0);
	assert_true(isnan(dmc_h_var(&h, "state")));
	assert_true(isnan(dmc_h_var(&h, "hbdmc")));
	for (int i = 0; i < DMC_H_AXES; i++) {
		struct ctrl_axis_info ai = dmc_h_axis(&h, i);

		assert_int_equal(ai.motor_off, 1);
		assert_int_equal(ai.moving, 0);
	}
	assert_int_equal(h.unsol_len, 0);
	dmc_h_close(&h);
}

/* The value of constant @name in #CONSTS ("name=value"), or NAN. */
static double const_value(const char *name)
{
	char pat[32];
	const char *p;

	snprintf(pat, sizeof(pat), "\n%s=", name);
	p = strstr(prog, pat);
	return p ? atof(p + strlen(pat)) : NAN;
}

/* The loops wait with a literal (a variable would let a client stall the
 * thread that checks everything): "AT -n" in #MAIN and #PRWD is -mainms,
 * in #MOTION -loopms; no AT takes a variable. */
static void test_loop_periods(void **state)
{
	double mainms = const_value("mainms"), loopms = const_value("loopms");
	const char *routine = "", *p = prog;
	int seen = 0;

	(void)state;
	assert_false(isnan(mainms) || isnan(loopms));
	while (p && *p) {
		const char *eol = strchr(p, '\n');
		size_t n = eol ? (size_t)(eol - p) : strlen(p);

		if (n == 5 && !strncmp(p, "#MAIN", 5))
			routine = "#MAIN";
		else if (n == 5 && !strncmp(p, "#PRWD", 5))
			routine = "#PRWD";
		else if (n == 7 && !strncmp(p, "#MOTION", 7))
			routine = "#MOTION";
		if (n > 3 && !strncmp(p, "AT ", 3) && strncmp(p, "AT 0", n)) {
			double want =
			    !strcmp(routine, "#MOTION") ? loopms : mainms;

			if (p[3] != '-' || !isdigit((unsigned char)p[4]) ||
			    atof(p + 4) != want)
				fail_msg(
				    "'%.*s' in %s: want the literal AT -%g",
				    (int)n, p, routine, want);
			seen++;
		}
		p = eol ? eol + 1 : NULL;
	}
	assert_int_equal(seen, 3);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_source_lines), cmocka_unit_test(test_lines),
	    cmocka_unit_test(test_lint_clean),	 cmocka_unit_test(test_labels),
	    cmocka_unit_test(test_statements),	 cmocka_unit_test(test_bare_xq),
	    cmocka_unit_test(test_loop_periods),
	};

	return cmocka_run_group_tests(tests, setup_prog, NULL);
}
