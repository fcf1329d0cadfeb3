/*
 * test_gload_check.c - galil-load's offline checker on the fixtures in
 * tests/data/dmc_bad (one per kind of error; each file's REM header says
 * what is expected where) and on small in-memory programs for the edges.
 * Every expectation is the exact "FILE:LINE: rule: message" text (the
 * rules are pc/dmc/dmc_lint's; tests/load/test_gload_lint has one
 * fixture per rule).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "gl_err.h"
#include "gload_check.h"
#include "gload_prep.h"

#define BAD  "tests/data/dmc_bad/"
#define GOOD "tests/data/dmc_good/"

/* Check @path with @model; return every diagnostic, one per line. */
static char *check_path(const char *path, const char *model, int *problems)
{
	struct gload_prog p = {0};
	struct gload_diags d = {0};
	const struct dmc_model *m = dmc_model_find(model);
	size_t len = 0;
	char *out;
	int i;

	assert_non_null(m);
	gload_prep_path(&p, path, &d);
	*problems = gload_check(&p, m, &d, NULL);
	assert_true(*problems >= 0);
	gload_diags_sort(&d);
	for (i = 0; i < d.n; i++)
		len += strlen(d.v[i].text) + 1;
	out = calloc(1, len + 1);
	assert_non_null(out);
	for (i = 0; i < d.n; i++) {
		strcat(out, d.v[i].text);
		strcat(out, "\n");
	}
	*problems = d.n;
	gload_diags_free(&d);
	gload_prog_free(&p);
	return out;
}

/* Check an in-memory program named "mem.dmc". */
static char *check_text(const char *text, int *problems)
{
	struct gload_prog p = {0};
	struct gload_diags d = {0};
	size_t len = 0;
	char *out;
	int i;

	gload_prep_buffer(&p, "mem.dmc", text, strlen(text), &d);
	gload_check(&p, dmc_model_default(), &d, NULL);
	gload_diags_sort(&d);
	for (i = 0; i < d.n; i++)
		len += strlen(d.v[i].text) + 1;
	out = calloc(1, len + 1);
	assert_non_null(out);
	for (i = 0; i < d.n; i++) {
		strcat(out, d.v[i].text);
		strcat(out, "\n");
	}
	*problems = d.n;
	gload_diags_free(&d);
	gload_prog_free(&p);
	return out;
}

struct fixture_case {
	const char *file;
	const char *model;
	const char *expect;
};

static const struct fixture_case cases[] = {
    {"line_too_long.dmc", "40x0",
     BAD "line_too_long.dmc:7: line-length: line is 81 characters long "
	 "(DMC-40x0 limit 80)\n"},
    {"label_syntax.dmc", "40x0",
     BAD "label_syntax.dmc:6: label-syntax: invalid label '#1ABC' (a letter, "
	 "then letters or digits)\n" BAD
	 "label_syntax.dmc:8: label-syntax: invalid label '#A-B' (a letter, "
	 "then letters or digits)\n" BAD
	 "label_syntax.dmc:10: label-position: label '#X' is not at the start "
	 "of a line\n"},
    {"label_long.dmc", "40x0",
     BAD "label_long.dmc:6: label-length: label '#TOOLONGL' is longer than 7 "
	 "characters\n"},
    {"label_duplicate.dmc", "40x0",
     BAD "label_duplicate.dmc:9: label-duplicate: duplicate label '#LOOP' "
	 "(first at " BAD "label_duplicate.dmc:6)\n"},
    {"label_undefined.dmc", "40x0",
     BAD "label_undefined.dmc:7: label-undefined: undefined label '#NOWHERE' "
	 "in 'JP'\n" BAD "label_undefined.dmc:8: label-undefined: undefined "
	 "label '#SUB' in 'JS'\n" BAD
	 "label_undefined.dmc:9: label-undefined: undefined label '#THR' in "
	 "'XQ'\n"},
    {"var_name.dmc", "40x0",
     BAD
     "var_name.dmc:6: var-length: variable name 'position12' is longer than 8 "
     "characters\n" BAD "var_name.dmc:7: var-reserved: variable name 'TIME' is "
     "a reserved word\n" BAD
     "var_name.dmc:8: var-command: variable name 'TP' is a command name\n" BAD
     "var_name.dmc:9: var-syntax: invalid variable name '9ab' (a letter, then "
     "letters, digits or '_')\n" BAD
     "var_name.dmc:10: var-length: variable name 'toolongarr' is longer than 8 "
     "characters\n" BAD "var_name.dmc:11: var-length: variable name "
     "'distance12' is longer than 8 characters\n"},
    {"backslash.dmc", "40x0",
     BAD "backslash.dmc:6: backslash: '\\' ends the download early\n"},
    {"lowercase.dmc", "40x0",
     BAD "lowercase.dmc:8: lower-case: lower-case command 'bg' (commands are "
	 "upper case)\n" BAD "lowercase.dmc:9: lower-case: lower-case command "
	 "'mg' (commands are upper case)\n" BAD
	 "lowercase.dmc:10: lower-case: lower-case command 'if' (commands are "
	 "upper case)\n" BAD "lowercase.dmc:12: lower-case: lower-case command "
	 "'endif' (commands are upper case)\n"},
    {"no_semicolon.dmc", "40x0",
     BAD "no_semicolon.dmc:6: no-semicolon: ';' ends the NO comment: 'then ST "
	 "A' runs as commands\n"},
    {"string_open.dmc", "40x0",
     BAD "string_open.dmc:5: string-open: missing closing '\"'\n"},
    {"if_nesting.dmc", "40x0",
     BAD "if_nesting.dmc:7: if-match: 'ENDIF' without 'IF'\n" BAD
	 "if_nesting.dmc:8: if-match: 'ELSE' without 'IF'\n" BAD
	 "if_nesting.dmc:9: if-match: 'IF' without 'ENDIF'\n"},
    {"non_ascii.dmc", "40x0",
     BAD "non_ascii.dmc:5: char-printable: character 0xC2 is not printable "
	 "ASCII\n"},
    {"too_many_lines.dmc", "21x3",
     BAD "too_many_lines.dmc:1003: lines-limit: program is 1001 lines long "
	 "(DMC-21x3 limit 1000)\n"},
    {"too_many_labels.dmc", "21x3",
     BAD "too_many_labels.dmc:258: labels-limit: 255 labels (DMC-21x3 limit "
	 "254)\n"},
    {"too_many_vars.dmc", "21x3",
     BAD
     "too_many_vars.dmc:55: vars-limit: 255 variables (DMC-21x3 limit 254)\n"},
    {"missing_dir", "40x0",
     BAD "missing_dir/MANIFEST:3: cannot open '" BAD
	 "missing_dir/absent.dmc': No such file or directory\n"},
};

/* Every fixture gives exactly the diagnostics its header announces. */
static void test_fixtures(void **state)
{
	char path[256];
	size_t i;
	int n;

	(void)state;
	for (i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		char *out;

		snprintf(path, sizeof(path), BAD "%s", cases[i].file);
		out = check_path(path, cases[i].model, &n);
		if (strcmp(out, cases[i].expect))
			fail_msg("%s:\n got: %s\nwant: %s", path, out,
				 cases[i].expect);
		assert_true(n > 0);
		free(out);
	}
}

/* The limits of the default model are not reached by the 21x3 fixtures. */
static void test_fixtures_fit_40x0(void **state)
{
	static const char *const files[] = {
	    "too_many_lines.dmc", "too_many_labels.dmc", "too_many_vars.dmc"};
	char path[256];
	size_t i;
	int n;

	(void)state;
	for (i = 0; i < 3; i++) {
		char *out;

		snprintf(path, sizeof(path), BAD "%s", files[i]);
		out = check_path(path, "40x0", &n);
		assert_string_equal(out, "");
		free(out);
	}
}

/* The good programs pass, alone and through a manifest. */
static void test_good_programs(void **state)
{
	char *out;
	int n;

	(void)state;
	out = check_path(GOOD "clean.dmc", "40x0", &n);
	assert_string_equal(out, "");
	free(out);
	out = check_path(GOOD "split", "40x0", &n);
	assert_string_equal(out, "");
	free(out);
}

/* Legal forms the checker must not report. */
static void test_legal_forms(void **state)
{
	static const char text[] =
	    "EN\n"
	    "#AUTO\n"
	    "x=5;speed=10;VERS=1;abc12345=1\n" /* lower, upper, 8 chars */
	    "KPA=10;SPB=500\n"		       /* command with an axis */
	    "IHT=>-3\n"
	    "DM vmin[3],vmax[3];vmin[0]=1\n"
	    "JS #sub(1,2),x>0\n"
	    "JS #sub(3,4)\n"
	    "JP #AUTO,(x=5)&(speed>1)\n"
	    "XQ #thr,1;XQ _ED2,_ED1,1;XQ\n"
	    "IF (x=5);MG \"a;b 'c'\", x {F3.1};ENDIF\n"
	    "NO a comment with \"quotes\n"
	    "NO;x=1\n"
	    "NOTES=4\n" /* a variable */
	    "~a=0;^b=1;hex=$FF\n"
	    "#sub\n"
	    "EN\n"
	    "#thr\n"
	    "WT10;AT-500;SB1;CB 2;ZS\n"
	    "EN\n";
	char *out;
	int n;

	(void)state;
	out = check_text(text, &n);
	assert_string_equal(out, "");
	free(out);
}

/* Several problems on one line are all reported, in order. */
static void test_several_per_line(void **state)
{
	char *out;
	int n;

	(void)state;
	out = check_text("#A\nbg;JP #B;st AB;zs\nEN\n", &n);
	assert_string_equal(
	    out, "mem.dmc:2: lower-case: lower-case command 'bg' (commands "
		 "are upper case)\n"
		 "mem.dmc:2: lower-case: lower-case command 'st' (commands "
		 "are upper case)\n"
		 "mem.dmc:2: lower-case: lower-case command 'zs' (commands "
		 "are upper case)\n"
		 "mem.dmc:2: label-undefined: undefined label '#B' in 'JP'\n");
	free(out);
}

/* An empty program (only comments) is refused. */
static void test_empty_program(void **state)
{
	char *out;
	int n;

	(void)state;
	out = check_text("REM nothing\n' nothing\n\n", &n);
	assert_string_equal(out, "mem.dmc: empty: no program lines\n");
	assert_int_equal(n, 1);
	free(out);
}

/* Label references are case sensitive; the 7-character limit is exact. */
static void test_label_case_and_length(void **state)
{
	char *out;
	int n;

	(void)state;
	out = check_text("#Loop\nJP #LOOP\n#ABCDEFG\n#ABCDEFGH\nEN\n", &n);
	assert_string_equal(
	    out, "mem.dmc:2: label-undefined: undefined label '#LOOP' in 'JP'\n"
		 "mem.dmc:4: label-length: label '#ABCDEFGH' is longer than 7 "
		 "characters\n");
	free(out);
}

/* The model table and its aliases. */
static void test_models(void **state)
{
	const struct dmc_model *m;

	(void)state;
	m = dmc_model_default();
	assert_string_equal(m->name, "40x0");
	assert_int_equal(m->max_lines, 4000);
	assert_int_equal(m->max_vars, 510);
	assert_int_equal(m->max_labels, 510);
	assert_int_equal(m->line_chars, 80);
	assert_ptr_equal(dmc_model_find("DMC-4030"), m);
	assert_ptr_equal(dmc_model_find("dmc4040"), m);
	assert_string_equal(dmc_model_find("4143")->name, "41x3");
	assert_int_equal(dmc_model_find("30010")->threads, 6);
	assert_int_equal(dmc_model_find("21x3")->max_lines, 1000);
	assert_null(dmc_model_find("1806"));
}

/* Random text made of DMC's special characters never crashes the
 * preprocessor or the checker (run under the sanitizers by make asan). */
static void test_random_input(void **state)
{
	static const char alphabet[] = "#\"';\\ \t\r\n=[](),{}^~_@$&|<>"
				       "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefxyz"
				       "0123456789\x01\x80\xff";
	char buf[400];
	unsigned seed = 12345;
	int i, n, j;

	(void)state;
	for (i = 0; i < 3000; i++) {
		struct gload_prog p = {0};
		struct gload_diags d = {0};

		n = (int)((seed = seed * 1103515245u + 12345u) >> 16) % 400;
		for (j = 0; j < n; j++) {
			seed = seed * 1103515245u + 12345u;
			buf[j] =
			    alphabet[(seed >> 16) % (sizeof(alphabet) - 1)];
		}
		gload_prep_buffer(&p, "r.dmc", buf, (size_t)n, &d);
		assert_true(gload_check(&p, dmc_model_default(), &d, NULL) >=
			    0);
		assert_int_equal(gload_prog_finish(&p), 0);
		gload_diags_free(&d);
		gload_prog_free(&p);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_fixtures),
	    cmocka_unit_test(test_fixtures_fit_40x0),
	    cmocka_unit_test(test_good_programs),
	    cmocka_unit_test(test_legal_forms),
	    cmocka_unit_test(test_several_per_line),
	    cmocka_unit_test(test_empty_program),
	    cmocka_unit_test(test_label_case_and_length),
	    cmocka_unit_test(test_models),
	    cmocka_unit_test(test_random_input),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
