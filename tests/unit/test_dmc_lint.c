/*
 * test_dmc_lint.c - the DMC linter's buffer API (pc/dmc/dmc_lint.h):
 * findings with rule, line, reference line and message from a text in
 * memory; LF, CR LF and CR line ends; REM lines and ' statements skipped;
 * the caller's extra lines against the model's limit; an empty text. The
 * rules themselves are tested per fixture in tests/load/test_gload_lint.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "dmc_lint.h"

static int lint(const char *text, int extra, struct dmc_lint *r)
{
	return dmc_lint_text(text, strlen(text), dmc_model_default(), extra, r);
}

/* Findings come in line order with their rule, line and message; a
 * duplicate label names the line of the first definition. */
static void test_findings(void **state)
{
	struct dmc_lint r = {0};

	(void)state;
	assert_int_equal(lint("#A\r\nIF (a==b)\rENDIF\n#A\nWT=5\n", 0, &r), 3);
	assert_int_equal(r.v[0].rule, DMC_R_EQ_EQ);
	assert_int_equal(r.v[0].line, 2);
	assert_string_equal(r.v[0].msg,
			    "'==' is not a DMC operator ('=' compares)");
	assert_int_equal(r.v[1].rule, DMC_R_LABEL_DUPLICATE);
	assert_int_equal(r.v[1].line, 4);
	assert_int_equal(r.v[1].ref_line, 1);
	assert_string_equal(r.v[1].msg, "duplicate label '#A'");
	assert_int_equal(r.v[2].rule, DMC_R_WT_ASSIGN);
	assert_int_equal(r.v[2].line, 5);
	assert_int_equal(r.lines, 5);
	assert_int_equal(r.labels, 2);
	dmc_lint_free(&r);
	assert_null(r.v);
	assert_int_equal(r.n, 0);
}

/* REM lines and ' statements are comments; x_pos is a variable. */
static void test_comments(void **state)
{
	struct dmc_lint r = {0};

	(void)state;
	assert_int_equal(lint("REM a==b; WT=1\n#A\nx_pos=1;' a==b\nEN", 0, &r),
			 0);
	assert_int_equal(r.vars, 1);
	dmc_lint_free(&r);
}

/* The caller's extra lines count against the model's line limit. */
static void test_extra_lines(void **state)
{
	struct dmc_model m = *dmc_model_default();
	struct dmc_lint r = {0};

	(void)state;
	m.max_lines = 2;
	assert_int_equal(dmc_lint_text("#A\nEN\n", 6, &m, 0, &r), 0);
	dmc_lint_free(&r);
	assert_int_equal(dmc_lint_text("#A\nEN\n", 6, &m, 1, &r), 1);
	assert_int_equal(r.v[0].rule, DMC_R_LINES_LIMIT);
	assert_int_equal(r.v[0].line, 2);
	assert_string_equal(r.v[0].msg,
			    "program is 3 lines long (DMC-40x0 limit 2)");
	dmc_lint_free(&r);
}

/* No line at all: one finding about the whole text (line 0). */
static void test_empty(void **state)
{
	struct dmc_lint r = {0};

	(void)state;
	assert_int_equal(dmc_lint_text(NULL, 0, dmc_model_default(), 1, &r), 1);
	assert_int_equal(r.v[0].rule, DMC_R_EMPTY);
	assert_int_equal(r.v[0].line, 0);
	assert_string_equal(r.v[0].msg, "no program lines");
	dmc_lint_free(&r);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_findings),
	    cmocka_unit_test(test_comments),
	    cmocka_unit_test(test_extra_lines),
	    cmocka_unit_test(test_empty),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
