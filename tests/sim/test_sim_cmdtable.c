/*
 * test_sim_cmdtable.c - galil-sim's command dispatch agrees with the one
 * DMC command table (pc/dmc/dmc_cmd.h): every command galil-sim runs is in
 * the table flagged DMC_CMD_SIM, every command flagged so is run, and
 * every command of the table galil-sim does not run is answered '?' with
 * TC 1 "Unrecognized command" (galil-sim refuses, it never pretends).
 * Prints the commands galil-load accepts that galil-sim does not run
 * (docs/galil-sim.md, "Commands galil-sim does not run").
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "ctrl_cmd.h"
#include "dmc_cmd.h"
#include "test_ctrl_util.h"

static int sim_runs(const char *name)
{
	const char *n;

	for (size_t i = 0; (n = ctrl_cmd_name_at(i)); i++)
		if (!strcmp(n, name))
			return 1;
	return 0;
}

/* The table is sorted and unique (dmc_cmd_find searches it), and its
 * size is what galil-load checks against: 206 + CO + IF. */
static void test_table_sorted(void **state)
{
	(void)state;
	assert_int_equal(dmc_cmd_count(), 208);
	for (size_t i = 1; i < dmc_cmd_count(); i++)
		assert_true(
		    strcmp(dmc_cmd_at(i - 1)->name, dmc_cmd_at(i)->name) < 0);
	assert_null(dmc_cmd_at(dmc_cmd_count()));
	assert_string_equal(dmc_cmd_find("KPA=10")->name, "KP");
	assert_null(dmc_cmd_find("XX"));
	assert_null(dmc_cmd_find("K"));
}

static void test_sim_commands_in_table(void **state)
{
	const char *n;
	size_t i;

	(void)state;
	for (i = 0; (n = ctrl_cmd_name_at(i)); i++) {
		const struct dmc_cmd *e = dmc_cmd_find(n);

		if (!e || !(e->flags & DMC_CMD_SIM))
			fail_msg("galil-sim runs %s, the table says it does "
				 "not",
				 n);
	}
	assert_int_equal(i, 93);
}

static void test_table_commands_in_sim(void **state)
{
	struct tplant p;
	char resp[256], list[1024] = "";
	int missing = 0;

	(void)state;
	assert_int_equal(tp_init(&p), 0);
	for (size_t i = 0; i < dmc_cmd_count(); i++) {
		const struct dmc_cmd *e = dmc_cmd_at(i);

		assert_int_equal(sim_runs(e->name), !!(e->flags & DMC_CMD_SIM));
		if (e->flags & DMC_CMD_SIM)
			continue;
		/* not run: refused as unknown, from a host */
		assert_int_equal(tp_cmd(&p, e->name, resp, sizeof(resp)),
				 GL_ERR_CTRL);
		assert_int_equal(tp_cmd(&p, "TC1", resp, sizeof(resp)), GL_OK);
		if (strcmp(resp, " 1 Unrecognized command\r\n"))
			fail_msg("%s: TC1 gave '%s'", e->name, resp);
		snprintf(list + strlen(list), sizeof(list) - strlen(list),
			 "%s%s", missing++ ? " " : "", e->name);
	}
	print_message("[ MEASURE  ] %d commands galil-load accepts that "
		      "galil-sim does not run: %s\n",
		      missing, list);
	assert_int_equal(missing, 208 - 93);
	tp_free(&p);
}

/*
 * An unimplemented command of each family galil-sim leaves out (axis
 * setup, homing, contour, vector, ECAM ...), written the way
 * real programs write them, answers '?' and TC1 "1 Unrecognized command";
 * none becomes a variable (HMA=1 leaves no variable HMA behind).
 */
static void test_unimplemented_families(void **state)
{
	static const char *const cmds[] = {
	    "HMA=1", "HM A",  "FEA",	  "ALA",     "ITA=1", "KSA=2",
	    "TKA=5", "AGA=1", "BMA=4000", "HVA=500", "LCA=1", "DEA=0",
	    "AFA=1", "VDS=1", "VAS=9",	  "FE",	     "HM",
	};
	struct tplant p;
	char resp[256];

	(void)state;
	assert_int_equal(tp_init(&p), 0);
	for (size_t i = 0; i < sizeof(cmds) / sizeof(cmds[0]); i++) {
		if (tp_cmd(&p, cmds[i], resp, sizeof(resp)) != GL_ERR_CTRL)
			fail_msg("%s accepted: '%s'", cmds[i], resp);
		assert_int_equal(tp_cmd(&p, "TC1", resp, sizeof(resp)), GL_OK);
		if (strcmp(resp, " 1 Unrecognized command\r\n"))
			fail_msg("%s: TC1 gave '%s'", cmds[i], resp);
	}
	assert_int_equal(tp_cmd(&p, "MTA=?", resp, sizeof(resp)), GL_OK);
	assert_string_equal(resp, " 1\r\n");
	assert_int_equal(tp_cmd(&p, "LV", resp, sizeof(resp)), GL_OK);
	assert_string_equal(resp, "");
	/* a variable whose name is no command form stays a variable */
	assert_int_equal(tp_cmd(&p, "CD0=2;SPEED=3", resp, sizeof(resp)),
			 GL_OK);
	assert_int_equal((int)tp_mg(&p, "CD0+SPEED"), 5);
	tp_free(&p);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_table_sorted),
	    cmocka_unit_test(test_sim_commands_in_table),
	    cmocka_unit_test(test_table_commands_in_sim),
	    cmocka_unit_test(test_unimplemented_families),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
