/*
 * test_gload_lint.c - the linter's rules that agree with the firmware
 * (pc/dmc/dmc_rule.h): one fixture per rule in tests/data/lint/, each
 * with the statement the rule must flag and the look-alikes it must not
 * (the exact "FILE:LINE: message [rule]" text); a program written in the
 * style of production DMC passes clean, and so do our own dmc/ files; the
 * rule table is complete and documented; and galil-sim's download agrees
 * with the rules it shares (DMC_RULE_SIM): it refuses the label with '_'
 * at the same line and runs the names with '_'.
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
#include "dmc_model.h"
#include "dmc_rule.h"
#include "gl_err.h"
#include "gload_check.h"
#include "gload_prep.h"

#define LINT "tests/data/lint/"

/* Check @path for the DMC-40x0; every finding, one per line. */
static void check_path(const char *path, char *out, size_t cap)
{
	struct gload_prog p = {0};
	struct gload_diags d = {0};
	size_t n = 0;

	out[0] = '\0';
	gload_prep_path(&p, path, &d);
	assert_true(gload_check(&p, dmc_model_default(), &d, NULL) >= 0);
	gload_diags_sort(&d);
	for (int i = 0; i < d.n && n < cap; i++)
		n += (size_t)snprintf(out + n, cap - n, "%s\n", d.v[i].text);
	gload_diags_free(&d);
	gload_prog_free(&p);
}

static const struct {
	const char *file, *expect;
} cases[] = {
    {"eq_eq.dmc", LINT "eq_eq.dmc:5: '==' is not a DMC operator ('=' compares) "
		       "[eq-eq]\n"},
    {"dl_in_program.dmc",
     LINT "dl_in_program.dmc:5: 'DL' inside a program (a host command: it "
	  "would end or dump the program) [dl-in-program]\n" LINT
	  "dl_in_program.dmc:6: 'UL' inside a program (a host command: it "
	  "would end or dump the program) [dl-in-program]\n"},
    {"wt_assign.dmc",
     LINT "wt_assign.dmc:5: 'WT=1000' does not wait (write 'WT 1000') "
	  "[wt-assign]\n"},
    {"jp_args.dmc",
     LINT "jp_args.dmc:5: 'JP #SUB(...)': JP passes no arguments (JS does) "
	  "[jp-args]\n"},
    {"underscore.dmc",
     LINT "underscore.dmc:8: invalid label '#A_B' (a letter, then letters or "
	  "digits) [label-syntax]\n"},
    {"production.dmc", ""},
};

static void test_rule_fixtures(void **state)
{
	char path[256], out[2048];

	(void)state;
	for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		snprintf(path, sizeof(path), LINT "%s", cases[i].file);
		check_path(path, out, sizeof(out));
		if (strcmp(out, cases[i].expect))
			fail_msg("%s:\n got: %s\nwant: %s", cases[i].file, out,
				 cases[i].expect);
	}
}

/* Our own programs pass every rule. */
static void test_our_programs_clean(void **state)
{
	char out[2048];

	(void)state;
	check_path("dmc", out, sizeof(out));
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

/* The preprocessed text of @path (LF lines), as galil-load downloads it;
 * @src: the source line of each downloaded line. */
static size_t prep_text(const char *path, char *buf, size_t cap, int *src)
{
	struct gload_prog p = {0};
	struct gload_diags d = {0};
	size_t n = 0;

	gload_prep_path(&p, path, &d);
	for (int i = 0; i < p.nlines; i++) {
		n += (size_t)snprintf(buf + n, cap - n, "%.*s\n",
				      (int)p.lines[i].len, p.lines[i].text);
		src[i] = p.lines[i].src_line;
	}
	gload_diags_free(&d);
	gload_prog_free(&p);
	return n;
}

/* galil-sim refuses the label with '_' (TC 61) at the line the linter
 * names, and runs '_' inside variable and array names. */
static void test_sim_agrees(void **state)
{
	struct tplant tp;
	char text[4096], resp[64];
	int src[64], bad = 0;
	size_t n;

	(void)state;
	assert_int_equal(tp_init(&tp), 0);
	n = prep_text(LINT "underscore.dmc", text, sizeof(text), src);
	assert_int_equal(ctrl_download(tp.c, text, n, &bad), GL_ERR_CTRL);
	assert_int_equal(src[bad - 1], 8);
	assert_int_equal(ctrl_command(tp.c, "TC", resp, sizeof(resp)), 0);
	assert_int_equal(atoi(resp), 61);
	/* without that line: loads, and the names with '_' work */
	n = prep_text(LINT "underscore.dmc", text, sizeof(text), src);
	text[n - strlen("#A_B\nEN\n")] = '\0';
	strcat(text, "EN\n");
	assert_int_equal(ctrl_download(tp.c, text, strlen(text), &bad), 0);
	assert_int_equal(ctrl_command(tp.c, "XQ #A", resp, sizeof(resp)), 0);
	tp_step(&tp, 20);
	assert_int_equal(ctrl_command(tp.c, "MG a_rr[0]", resp, sizeof(resp)),
			 0);
	assert_true(strtod(resp, NULL) == 1.0);
	/* the production-style program loads as well */
	n = prep_text(LINT "production.dmc", text, sizeof(text), src);
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
	    cmocka_unit_test(test_our_programs_clean),
	    cmocka_unit_test(test_rule_table),
	    cmocka_unit_test(test_sim_agrees),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
