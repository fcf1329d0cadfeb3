/*
 * test_dmc.c - the DMC front end (pc/dmc): the one REM rule, the
 * statement splitter, the model limits and the command table lookup.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "dmc_cmd.h"
#include "dmc_model.h"
#include "dmc_text.h"

static int rem(const char *s)
{
	return dmc_is_rem(s, strlen(s));
}

/* REM is a comment only as a whole first word (REMX=1 assigns REMX). */
static void test_rem(void **state)
{
	(void)state;
	assert_int_equal(rem("REM a comment"), 1);
	assert_int_equal(rem("  \tREM"), 1);
	assert_int_equal(rem("REM:x"), 1);
	assert_int_equal(rem("REMX=1"), 0);
	assert_int_equal(rem("REM_1=2"), 0);
	assert_int_equal(rem("rem lower case"), 0);
	assert_int_equal(rem("X=1;REM"), 0);
	assert_int_equal(rem("RE"), 0);
	assert_int_equal(rem(""), 0);
}

/* Split @line; the statements joined with '|'. */
static void split(const char *line, char *out, size_t cap)
{
	size_t pos = 0, at, len;

	out[0] = '\0';
	while (dmc_stmt_next(line, strlen(line), &pos, &at, &len))
		snprintf(out + strlen(out), cap - strlen(out), "%s%.*s",
			 out[0] ? "|" : "", (int)len, line + at);
}

static void test_split(void **state)
{
	char out[256];

	(void)state;
	split("A=1;B=2", out, sizeof(out));
	assert_string_equal(out, "A=1|B=2");
	split("MG \"a;b\";ST A", out, sizeof(out));
	assert_string_equal(out, "MG \"a;b\"|ST A");
	split("MG \"x\";", out, sizeof(out));
	assert_string_equal(out, "MG \"x\"|");
	split("", out, sizeof(out));
	assert_string_equal(out, "");
	split("EN", out, sizeof(out));
	assert_string_equal(out, "EN");
}

static void test_models(void **state)
{
	const struct dmc_model *m = dmc_model_find("DMC-4030");

	(void)state;
	assert_non_null(m);
	assert_ptr_equal(m, dmc_model_default());
	assert_int_equal(m->line_chars, 80);
	assert_int_equal(m->max_lines, 4000);
	assert_int_equal(m->max_labels, 510);
	assert_int_equal(m->max_vars, 510);
	assert_int_equal(m->confirmed, 1);
	assert_string_equal(dmc_model_find("dmc4183")->name, "41x3");
	assert_int_equal(dmc_model_find("41x3")->confirmed, 0);
	assert_string_equal(dmc_model_find("31010")->name, "30010");
	assert_null(dmc_model_find("4999"));
}

static void test_cmd_find(void **state)
{
	(void)state;
	assert_string_equal(dmc_cmd_find("BG")->name, "BG");
	assert_true(dmc_cmd_find("BG")->flags & DMC_CMD_SIM);
	assert_int_equal(dmc_cmd_find("HM")->flags & DMC_CMD_SIM, 0);
	assert_true(dmc_cmd_find("IF")->flags & DMC_CMD_KEYWORD);
	assert_null(dmc_cmd_find("bg"));
	assert_null(dmc_cmd_find("B"));
}

/* What galil-load lets through to a running robot: reads only. */
static void test_line_is_read(void **state)
{
	static const char *const reads[] = {
	    "MG state",	   "MG _XQ0,_XQ1", "TPA",	 "TP",
	    "KP ?,?,?",	   "KPA=?",	   "hbpc=",	 "hbpc=?",
	    "MG x;TPB;QZ", "\x12\x16",	   "LS",	 "MG \"a;b\"",
	    "SC",	   "TE ABC",	   "MG vmax[0]", "vmax[0]=?",
	};
	static const char *const writes[] = {
	    "x=17",	    "vmax[0]=9000", "KP 7",  "KPA=7",	 "ER 30000",
	    "XQ #MOTION,2", "HX",	    "HX1",   "SH ABC",	 "BG A",
	    "MG x;x=1",	    "OE 0",	    "CN 1",  "jin[0]=3", "LD 3,3,3",
	    "KP ?,7",	    "ST A",	    "MT -1", "AB 1",
	};

	(void)state;
	for (size_t i = 0; i < sizeof(reads) / sizeof(reads[0]); i++)
		if (!dmc_cmd_line_is_read(reads[i]))
			fail_msg("'%s' taken for a write", reads[i]);
	for (size_t i = 0; i < sizeof(writes) / sizeof(writes[0]); i++)
		if (dmc_cmd_line_is_read(writes[i]))
			fail_msg("'%s' taken for a read", writes[i]);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_rem),
	    cmocka_unit_test(test_split),
	    cmocka_unit_test(test_models),
	    cmocka_unit_test(test_cmd_find),
	    cmocka_unit_test(test_line_is_read),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
