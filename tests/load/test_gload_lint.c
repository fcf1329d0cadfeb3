/*
 * test_gload_lint.c - the linter that agrees with the firmware
 * (pc/dmc/dmc_lint.h, rules in pc/dmc/dmc_rule.c): one fixture per rule in
 * tests/data/lint/<rule>.dmc, each with the statements the rule must flag
 * and look-alikes it must not, checked through galil-load's --check path
 * for the exact "FILE:LINE: rule: message" text; the rules that depend on
 * the model flag their fixture on a small model and not on the DMC-40x0,
 * and labels with '_' pass on the DMC-40x0 and not on the DMC-41x3; a NO
 * comment ends at ';' and a tab inside a string is refused;
 * a program written in the style of production DMC passes clean, and so
 * do our own dmc/ files; the rule table is complete and documented; and
 * galil-sim's download agrees with every fixture: it refuses a program at
 * the first line a rule it shares (DMC_RULE_SIM) flags, accepts a program
 * no such rule flags, and accepts every fixture once the flagged lines are
 * removed.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "../sim/test_ctrl_util.h"
#include "base_file.h"
#include "dmc_lint.h"
#include "dmc_model.h"
#include "dmc_rule.h"
#include "gl_err.h"
#include "gload_check.h"
#include "gload_prep.h"
#include "gload_seal.h"

#define LINT "tests/data/lint/"

/* A model with small limits, so that the per-model rules' fixtures stay
 * small: 8 lines, 2 labels, 2 variables. */
static const struct dmc_model tiny = {"tiny", "DMC-test", 80, 8, 2, 2, 8, 0, 0};

/* Check @path with @m as galil-load --check does; every finding, one per
 * line, into @out. */
static void check_path(const char *path, const struct dmc_model *m, char *out,
		       size_t cap)
{
	struct gload_prog p = {0};
	struct gload_diags d = {0};
	size_t n = 0;

	out[0] = '\0';
	assert_int_equal(gload_prep_path(&p, path, &d), GL_OK);
	if (p.seal) { /* as galil-load: the seal from the configuration */
		char err[512];
		int nsealed = 0;

		if (gload_seal_append(&p, "config/roboelf.yaml", &nsealed, err,
				      sizeof(err)) != GL_OK)
			fail_msg("%s: the seal: %s", path, err);
	}
	assert_true(gload_check(&p, m, &d, NULL) >= 0);
	gload_diags_sort(&d);
	for (int i = 0; i < d.n && n < cap; i++)
		n += (size_t)snprintf(out + n, cap - n, "%s\n", d.v[i].text);
	gload_diags_free(&d);
	gload_prog_free(&p);
}

#define L(f, line) LINT f ".dmc:" #line ": "

static const struct {
	const char *rule;
	const char *model;  /* NULL: the DMC-40x0; "tiny"; or a --model */
	const char *expect; /* on that model */
} cases[] = {
    {"line-length", NULL,
     L("line-length", 6) "line-length: line is 81 characters long (DMC-40x0 "
			 "limit 80)\n"},
    {"char-printable", NULL,
     L("char-printable", 5) "char-printable: character 0xC2 is not "
			    "printable ASCII\n"},
    {"backslash", NULL,
     L("backslash", 5) "backslash: '\\' ends the download early\n"},
    {"string-open", NULL,
     L("string-open", 5) "string-open: missing closing '\"'\n"},
    /* the reference's rule on the DMC-41x3; the DMC-40x0 accepts '_' */
    {"label-syntax", "41x3",
     L("label-syntax",
       9) "label-syntax: invalid label '#A_B' (a letter, "
	  "then letters or digits)\n" L(
	      "label-syntax",
	      10) "label-syntax: invalid label '#1AB' (a letter, "
		  "then letters or digits)\n"},
    {"label-length", NULL,
     L("label-length", 4) "label-length: label '#ABCDEFGH' is longer than 7 "
			  "characters\n"},
    {"label-position", NULL,
     L("label-position", 5) "label-position: label '#L' is not at the start "
			    "of a line\n"},
    {"label-duplicate", NULL,
     L("label-duplicate", 5) "label-duplicate: duplicate label '#LOOP' (first "
			     "at " LINT "label-duplicate.dmc:3)\n"},
    {"label-undefined", NULL,
     L("label-undefined",
       5) "label-undefined: undefined label '#NOPE' in "
	  "'JP'\n" L("label-undefined",
		     6) "label-undefined: undefined label '#GONE' in "
			"'JS'\n" L("label-undefined",
				   7) "label-undefined: undefined label '#THR' "
				      "in 'XQ'\n"},
    {"var-syntax", NULL,
     L("var-syntax", 5) "var-syntax: invalid variable name '9ab' (a letter, "
			"then letters, digits or '_')\n"},
    {"var-length", NULL,
     L("var-length",
       5) "var-length: variable name 'position12' is longer "
	  "than 8 characters\n" L(
	      "var-length",
	      7) "var-length: variable name 'distance12' is longer "
		 "than 8 characters\n"},
    {"var-reserved", NULL,
     L("var-reserved", 5) "var-reserved: variable name 'TIME' is a reserved "
			  "word\n"},
    {"var-command", NULL,
     L("var-command", 5) "var-command: variable name 'TP' is a command "
			 "name\n"},
    {"if-match", NULL,
     L("if-match", 5) "if-match: 'ENDIF' without 'IF'\n" L(
	 "if-match",
	 6) "if-match: 'ELSE' without 'IF'\n" L("if-match",
						11) "if-match: 'IF' without "
						    "'ENDIF'\n"},
    {"lower-case", NULL,
     L("lower-case",
       5) "lower-case: lower-case command 'bg' (commands are "
	  "upper case)\n" L(
	      "lower-case",
	      6) "lower-case: lower-case command 'mg' (commands are "
		 "upper case)\n"},
    {"no-semicolon", NULL,
     L("no-semicolon", 5) "no-semicolon: ';' ends the NO comment: 'ST A' "
			  "runs as commands\n"},
    {"eq-eq", NULL,
     L("eq-eq", 5) "eq-eq: '==' is not a DMC operator ('=' compares)\n"},
    {"dl-in-program", NULL,
     L("dl-in-program", 5) "dl-in-program: 'DL' inside a program (a host "
			   "command: it would end or dump the program)\n" L(
			       "dl-in-program", 6) "dl-in-program: 'UL' inside "
						   "a program (a host command: "
						   "it would end or dump the "
						   "program)\n"},
    {"wt-assign", NULL,
     L("wt-assign", 5) "wt-assign: 'WT=1000' does not wait (write 'WT "
		       "1000')\n"},
    {"jp-args", NULL,
     L("jp-args", 5) "jp-args: 'JP #SUB(1)': JP takes no arguments (JS "
		     "does)\n"},
    {"js-args", NULL,
     L("js-args",
       6) "js-args: 'JS #SUB' passes 9 arguments (at most 8: "
	  "^a..^h)\n" L(
	      "js-args",
	      7) "js-args: array 'pos_log' passed on the JS stack has "
		 "a name longer than 6 characters\n"},
    {"lines-limit", "tiny",
     L("lines-limit", 11) "lines-limit: program is 9 lines long (DMC-test "
			  "limit 8)\n"},
    {"labels-limit", "tiny",
     L("labels-limit", 6) "labels-limit: 3 labels (DMC-test limit 2)\n"},
    {"vars-limit", "tiny",
     L("vars-limit", 4) "vars-limit: 3 variables (DMC-test limit 2)\n"},
    {"empty", NULL, LINT "empty.dmc: empty: no program lines\n"},
};

#define NCASES ((int)(sizeof(cases) / sizeof(cases[0])))

/* What a case linted on another model gives on the DMC-40x0; every other
 * such case is clean there. */
static const struct {
	const char *rule, *expect;
} on_40x0[] = {
    {"label-syntax",
     L("label-syntax", 10) "label-syntax: invalid label '#1AB' (a letter, "
			   "then letters or digits)\n"},
};

static const char *expect_40x0(const char *rule)
{
	for (size_t i = 0; i < sizeof(on_40x0) / sizeof(on_40x0[0]); i++)
		if (!strcmp(on_40x0[i].rule, rule))
			return on_40x0[i].expect;
	return "";
}

/* The model a case is linted on. */
static const struct dmc_model *case_model(int i)
{
	const struct dmc_model *m;

	if (!cases[i].model)
		return dmc_model_default();
	if (!strcmp(cases[i].model, "tiny"))
		return &tiny;
	m = dmc_model_find(cases[i].model);
	assert_non_null(m);
	return m;
}

/* Each fixture gives exactly the findings listed (its true positives, and
 * none of its false positives); a per-model rule's fixture gives on the
 * DMC-40x0 exactly what its case says there. */
static void test_rule_fixtures(void **state)
{
	char path[256], out[4096];

	(void)state;
	for (int i = 0; i < NCASES; i++) {
		const char *want40 = expect_40x0(cases[i].rule);

		snprintf(path, sizeof(path), LINT "%s.dmc", cases[i].rule);
		check_path(path, case_model(i), out, sizeof(out));
		if (strcmp(out, cases[i].expect))
			fail_msg("%s:\n got: %s\nwant: %s", path, out,
				 cases[i].expect);
		if (cases[i].model) {
			check_path(path, dmc_model_default(), out, sizeof(out));
			if (strcmp(out, want40))
				fail_msg("%s on the DMC-40x0:\n got: %s\nwant: "
					 "%s",
					 path, out, want40);
		}
	}
}

/* A NO comment ends at ';' (command reference, NO and ';'): what follows
 * runs, and is reported, unless it is a comment itself; a ' in the NO
 * text is comment text, so the statements after the ';' are still sent
 * and judged. */
static void test_no_comment_rest(void **state)
{
	char out[1024];

	(void)state;
	check_path(LINT "no-comment.dmc", dmc_model_default(), out,
		   sizeof(out));
	assert_string_equal(
	    out, L("no-comment",
		   8) "no-semicolon: ';' ends "
		      "the NO comment: 'x=1' "
		      "runs as commands\n" L("no-comment",
					     9) "no-semicolon: ';' ends the "
						"NO comment: 'ST' runs as "
						"commands\n");
}

/* A tab inside a string is refused with the way to print one (the
 * firmware keeping it is unconfirmed: docs/galil-sim.md); a tab outside a
 * string becomes a space and passes. */
static void test_tab_in_string(void **state)
{
	char out[1024];

	(void)state;
	check_path(LINT "tab-string.dmc", dmc_model_default(), out,
		   sizeof(out));
	assert_string_equal(out, L("tab-string", 5) "char-printable: tab "
						    "inside a string is not "
						    "known to reach the "
						    "firmware (print one with "
						    "{^9})\n");
}

/* Every rule of the table has its fixture case, and only those. */
static void test_fixture_per_rule(void **state)
{
	(void)state;
	assert_int_equal(NCASES, DMC_R_COUNT);
	for (int i = 0; i < DMC_R_COUNT; i++) {
		const char *name = dmc_rule((enum dmc_rule_id)i)->name;
		int found = 0;

		for (int j = 0; j < NCASES; j++)
			found += !strcmp(cases[j].rule, name);
		if (found != 1)
			fail_msg("rule '%s' has %d fixture cases", name, found);
	}
}

/* Our own programs pass every rule: the MANIFEST directory, and
 * constants.dmc alone; roboelf.dmc alone misses only the label its
 * constants file defines. The production-style program passes too. */
static void test_clean_programs(void **state)
{
	char out[2048];

	(void)state;
	check_path("dmc", dmc_model_default(), out, sizeof(out));
	assert_string_equal(out, "");
	check_path("dmc/constants.dmc", dmc_model_default(), out, sizeof(out));
	assert_string_equal(out, "");
	/* alone, the program lacks the constants and the seal: the only
	 * findings are those labels, one line each */
	check_path("dmc/roboelf.dmc", dmc_model_default(), out, sizeof(out));
	{
		static const char *const labels[] = {"#CONSTS", "#SEALIN",
						     "#SEAL'",	"#SEALA",
						     "#SEALS",	"#SEALP"};
		int lines = 0;

		for (const char *p = out; (p = strchr(p, '\n')); p++)
			lines++;
		/* #SEALA twice (service, arm), #CONSTS twice (#AUTO, #PRWD) */
		assert_int_equal(lines, 8);
		for (size_t k = 0; k < sizeof(labels) / sizeof(labels[0]); k++)
			assert_non_null(strstr(out, labels[k]));
		for (const char *p = out; *p; p = strchr(p, '\n') + 1)
			assert_non_null(strstr(p, "label-undefined: undefined "
						  "label '#"));
	}
	check_path(LINT "production.dmc", dmc_model_default(), out,
		   sizeof(out));
	assert_string_equal(out, "");
}

/* Every rule has a unique name and a source, and docs/galil-load.md lists
 * each name with its source. */
static void test_rule_table(void **state)
{
	char *doc = NULL, want[256];
	size_t len = 0;

	(void)state;
	assert_int_equal(
	    base_file_read("docs/galil-load.md", 1 << 20, &doc, &len), GL_OK);
	assert_null(dmc_rule(DMC_R_COUNT));
	for (int i = 0; i < DMC_R_COUNT; i++) {
		const struct dmc_rule *r = dmc_rule((enum dmc_rule_id)i);

		assert_non_null(r->name);
		assert_true(strlen(r->source) > 10);
		for (int j = 0; j < i; j++)
			assert_string_not_equal(
			    r->name, dmc_rule((enum dmc_rule_id)j)->name);
		snprintf(want, sizeof(want), "| `%s` | %s |", r->name,
			 r->source);
		if (!strstr(doc, want))
			fail_msg("docs/galil-load.md lacks the row '%s'", want);
	}
	free(doc);
}

/* The preprocessed text of @path (LF lines), as galil-load downloads it,
 * without the lines whose source line is in @skip (0-terminated; NULL:
 * none); @src: the source line of each kept line. */
static size_t prep_text(const char *path, const int *skip, char *buf,
			size_t cap, int *src)
{
	struct gload_prog p = {0};
	struct gload_diags d = {0};
	size_t n = 0;
	int k = 0;

	buf[0] = '\0';
	gload_prep_path(&p, path, &d);
	for (int i = 0; i < p.nlines; i++) {
		int drop = 0;

		for (int j = 0; skip && skip[j]; j++)
			drop |= skip[j] == p.lines[i].src_line;
		if (drop)
			continue;
		n += (size_t)snprintf(buf + n, cap - n, "%.*s\n",
				      (int)p.lines[i].len, p.lines[i].text);
		src[k++] = p.lines[i].src_line;
	}
	gload_diags_free(&d);
	gload_prog_free(&p);
	return n;
}

/* The source lines the linter flags in @path (0-terminated), and in
 * *@sim_line the first one flagged by a rule galil-sim shares (0: none). */
static void lint_lines(const char *path, int *flagged, int *sim_line)
{
	char text[8192];
	int src[256], k = 0;
	struct dmc_lint r = {0};
	size_t n = prep_text(path, NULL, text, sizeof(text), src);

	*sim_line = 0;
	assert_true(dmc_lint_text(text, n, dmc_model_default(), 1, &r) >= 0);
	for (int i = 0; i < r.n && k < 63; i++) {
		int line = r.v[i].line ? src[r.v[i].line - 1] : 0;

		if (line)
			flagged[k++] = line;
		if (line && !*sim_line &&
		    (dmc_rule(r.v[i].rule)->flags & DMC_RULE_SIM))
			*sim_line = line;
	}
	flagged[k] = 0;
	dmc_lint_free(&r);
}

/* galil-sim and the linter agree on every fixture of the DMC-40x0 (the
 * per-model fixtures are linted on a test model galil-sim is not). */
static void test_sim_agrees(void **state)
{
	struct tplant tp;
	char path[256], text[8192], resp[64];
	int src[256], flagged[64], sim_line, bad, rc, refused = 0;
	size_t n;

	(void)state;
	assert_int_equal(tp_init(&tp), 0);
	for (int i = 0; i < NCASES; i++) {
		if (case_model(i) == &tiny || !strcmp(cases[i].rule, "empty"))
			continue;
		snprintf(path, sizeof(path), LINT "%s.dmc", cases[i].rule);
		lint_lines(path, flagged, &sim_line);
		n = prep_text(path, NULL, text, sizeof(text), src);
		bad = 0;
		rc = ctrl_download(tp.c, text, n, &bad);
		refused += rc == GL_ERR_CTRL;
		if (sim_line && (rc != GL_ERR_CTRL || src[bad - 1] != sim_line))
			fail_msg("%s: galil-sim rc %d at line %d, the linter "
				 "flags line %d",
				 path, rc, bad ? src[bad - 1] : 0, sim_line);
		if (!sim_line && rc != 0)
			fail_msg("%s: galil-sim refused line %d; no shared "
				 "rule flags it",
				 path, src[bad - 1]);
		n = prep_text(path, flagged, text, sizeof(text), src);
		if (ctrl_download(tp.c, text, n, &bad) != 0)
			fail_msg("%s without its flagged lines: galil-sim "
				 "refused line %d",
				 path, src[bad - 1]);
	}
	/* line-length, label-syntax, label-length, label-duplicate */
	assert_int_equal(refused, 4);
	/* '_' inside variable and array names runs; so does a label with
	 * '_' (#A_B, line 9), which the DMC-40x0 accepts */
	n = prep_text(LINT "label-syntax.dmc", (const int[]){10, 0}, text,
		      sizeof(text), src);
	assert_int_equal(ctrl_download(tp.c, text, n, &bad), 0);
	assert_int_equal(ctrl_command(tp.c, "XQ #A", resp, sizeof(resp)), 0);
	tp_step(&tp, 20);
	assert_true(tp_mg(&tp, "a_rr[0]") == 1.0);
	assert_true(tp_mg(&tp, "x_pos") == 1.0);
	assert_int_equal(ctrl_command(tp.c, "XQ #A_B", resp, sizeof(resp)), 0);
	tp_step(&tp, 5);
	assert_int_equal(ctrl_threads(tp.c), 0);
	/* the production-style program loads as well */
	n = prep_text(LINT "production.dmc", NULL, text, sizeof(text), src);
	if (ctrl_download(tp.c, text, n, &bad) != 0) {
		ctrl_command(tp.c, "TC1", resp, sizeof(resp));
		fail_msg("galil-sim refused production.dmc at line %d: %s",
			 src[bad - 1], resp);
	}
	tp_free(&tp);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_rule_fixtures),
	    cmocka_unit_test(test_no_comment_rest),
	    cmocka_unit_test(test_tab_in_string),
	    cmocka_unit_test(test_fixture_per_rule),
	    cmocka_unit_test(test_clean_programs),
	    cmocka_unit_test(test_rule_table),
	    cmocka_unit_test(test_sim_agrees),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
