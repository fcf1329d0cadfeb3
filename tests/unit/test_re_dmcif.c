/*
 * test_re_dmcif.c - the DMC contract holds on both sides: the program's
 * fault codes as dmc/roboelf.dmc raises them (#FAULT(n,...)), as the
 * supervisor names them (enum re_dmc_fcode, pc/super/re_dmcif.h), and as
 * docs/dmc-interface.md lists them ("| n | NAME |") are the same set with
 * the same names; ZAB's layout (the echo's weight and modulus) is the
 * program's. Sources are read from ROBOELF_TOP (default ".").
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "base_file.h"
#include "base_version.h"
#include "dmc_h.h"
#include "re_config.h"
#include "re_dmcif.h"
#include "re_seal.h"
#include "re_sealmake.h"

/* The supervisor's names of the codes, in the enum's words. */
static const struct {
	enum re_dmc_fcode code;
	const char *name;
} names[] = {
    {RE_DMC_F_PARAM, "PARAM"},	   {RE_DMC_F_WATCHDOG, "WATCHDOG"},
    {RE_DMC_F_INPUT, "INPUT"},	   {RE_DMC_F_POSERR, "POSERR"},
    {RE_DMC_F_LIMIT, "LIMIT"},	   {RE_DMC_F_CMDERR, "CMDERR"},
    {RE_DMC_F_TCPERR, "TCPERR"},   {RE_DMC_F_AMPERR, "AMPERR"},
    {RE_DMC_F_ENCODER, "ENCODER"}, {RE_DMC_F_MOTOROFF, "MOTOROFF"},
    {RE_DMC_F_THREAD, "THREAD"},   {RE_DMC_F_SUPERVISOR, "SUPERVISOR"},
    {RE_DMC_F_UNCMD, "UNCMD"},	   {RE_DMC_F_FOREIGN, "FOREIGN"},
    {RE_DMC_F_SVCMOVE, "SVCMOVE"}, {RE_DMC_F_POTRANGE, "POTRANGE"},
    {RE_DMC_F_SEAL, "SEAL"},
};
#define N_NAMES (sizeof(names) / sizeof(names[0]))

static char *slurp(const char *rel)
{
	const char *top = getenv("ROBOELF_TOP");
	char path[1024], *buf = NULL;
	size_t len;

	snprintf(path, sizeof(path), "%s/%s", top ? top : ".", rel);
	if (base_file_read(path, 4u << 20, &buf, &len) != 0)
		fail_msg("cannot read %s", path);
	return buf;
}

/* Every code 1..RE_DMC_F_MAX is named once, in order, and the supervisor
 * names it so (re_dmc_fcode_name), with words for the board. */
static void test_enum_complete(void **state)
{
	(void)state;
	assert_int_equal(N_NAMES, RE_DMC_F_MAX);
	for (size_t i = 0; i < N_NAMES; i++) {
		assert_int_equal(names[i].code, (int)i + 1);
		assert_string_equal(re_dmc_fcode_name(names[i].code),
				    names[i].name);
		assert_non_null(re_dmc_fcode_words(names[i].code));
	}
	assert_string_equal(re_dmc_fcode_name(0), "none");
	assert_null(re_dmc_fcode_name(RE_DMC_F_MAX + 1));
	assert_null(re_dmc_fcode_words(-1));
}

/* The legend at the top of dmc/roboelf.dmc: lines "'  N NAME  what",
 * after the line that opens it, one per code 1..RE_DMC_F_MAX in order,
 * each with the supervisor's name. */
static void test_dmc_legend(void **state)
{
	char *src = slurp("dmc/roboelf.dmc");
	const char *p = strstr(src, "' Fault codes (fcode");
	int next = 1;

	(void)state;
	if (!p)
		fail_msg(
		    "dmc/roboelf.dmc has no legend \"' Fault codes (fcode\"");
	/* to the first line that is a bare "'" */
	for (p = strchr(p, '\n'); p && p[1] == '\'' && p[2] != '\n';
	     p = strchr(p + 1, '\n')) {
		char name[32];
		int code, k;

		if (sscanf(p + 2, " %d %31s%n", &code, name, &k) != 2)
			continue; /* a continued line, the blank end */
		if (code != next)
			fail_msg("the legend gives code %d where %d belongs",
				 code, next);
		if (strcmp(name, re_dmc_fcode_name(code)))
			fail_msg("the legend names code %d '%s', the "
				 "supervisor '%s'",
				 code, name, re_dmc_fcode_name(code));
		next++;
	}
	assert_int_equal(next - 1, RE_DMC_F_MAX);
	free(src);
}

/* dmc/roboelf.dmc and the seal galil-load appends to it (made from
 * config/roboelf.yaml): every #FAULT the controller can raise. */
static char *program_source(void)
{
	static char body[DMC_H_PROG_MAX];
	static struct re_seal seal;
	struct re_config cfg;
	char *src = slurp("dmc/roboelf.dmc"), *all, err[512], path[1024];
	const char *top = getenv("ROBOELF_TOP");
	size_t n = strlen(src);
	int len, m;

	len = dmc_h_load_program(NULL, body, sizeof(body), err, sizeof(err));
	if (len < 0)
		fail_msg("dmc/: %s", err);
	snprintf(path, sizeof(path), "%s/config/roboelf.yaml", top ? top : ".");
	if (re_config_load_file(path, &cfg, err, sizeof(err)) != 0 ||
	    re_seal_make(body, (size_t)len, &cfg, &seal, err, sizeof(err)))
		fail_msg("the seal: %s", err);
	all = realloc(src, n + RE_SEAL_TEXT_MAX);
	assert_non_null(all);
	m = re_seal_emit(&seal, all + n, RE_SEAL_TEXT_MAX);
	assert_true(m > 0);
	return all;
}

/* The program raises exactly the codes the supervisor knows. */
static void test_dmc_raises_known_codes(void **state)
{
	char *src = program_source();
	int seen[RE_DMC_F_MAX + 1] = {0};

	(void)state;
	for (const char *p = src; (p = strstr(p, "#FAULT(")); p++) {
		char *end;
		long n = strtol(p + 7, &end, 10);

		if (end == p + 7)
			continue; /* a code in a variable: #FAULT(mflt,...) */
		if (n < 1 || n > RE_DMC_F_MAX)
			fail_msg("dmc raises fault code %ld, unknown to the "
				 "supervisor",
				 n);
		seen[n]++;
	}
	for (int c = 1; c <= RE_DMC_F_MAX; c++)
		if (!seen[c])
			fail_msg("the supervisor knows fault code %d (%s), "
				 "dmc never raises it",
				 c, names[c - 1].name);
	free(src);
}

/* docs/dmc-interface.md lists each code with the same name. */
static void test_docs_agree(void **state)
{
	char *doc = slurp("docs/dmc-interface.md");

	(void)state;
	for (size_t i = 0; i < N_NAMES; i++) {
		char row[64];

		snprintf(row, sizeof(row), "\n| %d | %s |", (int)names[i].code,
			 names[i].name);
		if (!strstr(doc, row))
			fail_msg("docs/dmc-interface.md has no row '%s'",
				 row + 1);
	}
	free(doc);
}

/* The interface version the programs print (--version) is the one
 * dmc/constants.dmc sets. */
static void test_version_agrees(void **state)
{
	char *text = NULL;
	size_t len = 0;

	(void)state;
	assert_int_equal(
	    base_file_read("dmc/constants.dmc", 1 << 20, &text, &len), 0);
	assert_non_null(strstr(text, "\nvers=" ROBOELF_DMC_VERSION "\n"));
	free(text);
}

/* ZAB's layout as the supervisor decodes it (RE_ZAB_*, RE_HB_ECHO_MOD) is
 * the one dmc/roboelf.dmc publishes: its zb line and the echo's constants
 * in dmc/constants.dmc. */
static void test_zab_agrees(void **state)
{
	char *consts = slurp("dmc/constants.dmc");
	char *prog = slurp("dmc/roboelf.dmc");
	char want[96];

	(void)state;
	snprintf(want, sizeof(want), "\nhbemod=%ld;hbemul=%ld\n",
		 RE_HB_ECHO_MOD, RE_ZAB_ECHO);
	if (!strstr(consts, want))
		fail_msg("dmc/constants.dmc has no line '%s'", want + 1);
	snprintf(want, sizeof(want),
		 "\nzb=state+(fcode*%ld)+(faxis*%ld)+(hbe*hbemul)\n",
		 RE_ZAB_FCODE, RE_ZAB_FAXIS);
	if (!strstr(prog, want))
		fail_msg("dmc/roboelf.dmc has no line '%s'", want + 1);
	free(consts);
	free(prog);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_enum_complete),
	    cmocka_unit_test(test_dmc_legend),
	    cmocka_unit_test(test_dmc_raises_known_codes),
	    cmocka_unit_test(test_docs_agree),
	    cmocka_unit_test(test_version_agrees),
	    cmocka_unit_test(test_zab_agrees),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
