/*
 * test_sys_centring.c - centring, then armed: a calibration from the file
 * with the robot off-centre moves it to the centre (the program's own
 * service move), and arming right after it is not taken for motion nobody
 * commanded: no fault, armed, exit 0 on SIGTERM. On the short-robot rig
 * (sys_rig_h.h): one full calibration for the binary (group setup), then
 * every run on a fresh galil-sim.
 *
 * Environment: ROBOELF_BIN, ROBOELF_TOP (see sys_h.h), ROBOELF_KEEP=1
 * keeps the temporary directory, ROBOELF_SYS_FILTER=PATTERN runs only the
 * matching tests.
 */
#include <math.h>
#include <poll.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "sys_rig_h.h"

static struct sys_env env;
static int env_ok;
static struct sys_case cs;
static struct rig_ref ref; /* the group set-up measures it */

static int group_setup(void **state)
{
	(void)state;
	env_ok = rig_env_ready(&env, &ref);
	return 0;
}

static int group_teardown(void **state)
{
	(void)state;
	sys_env_done(&env, env_ok);
	return 0;
}

static int case_teardown(void **state)
{
	(void)state;
	sys_case_stop(&cs);
	return 0;
}

/* ---- centring, then armed ----------------------------------------------- */

/*
 * A calibration from the file with the robot off-centre: the move to the
 * centre is the program's own service move; arming right after it must
 * not be taken for motion nobody commanded. Whether it is depends on the
 * order of two things within one mainms (the program releasing the axis
 * in #MVSUP, roboelf's off request after it saw the move end): the off
 * request came first in 10 of 24 runs on the development machine, but not
 * independently (runs of one binary tend to repeat the order). So the
 * scenario runs up to CENTRING_RUNS times; each must arm and stay armed.
 */
#define CENTRING_RUNS 8

static void test_centring_then_armed(void **state)
{
	struct rig_opts o = {.calibration = "file", .off_centre = 1};
	int status;

	(void)state;
	rig_need_env(&env, env_ok);
	for (int k = 0; k < CENTRING_RUNS; k++) {
		char line[1024];
		double t = -1;

		if (rig_start(&cs, &env, &o) < 0 ||
		    rig_wait_ready(&cs, RIG_READY_MS) < 0 ||
		    (t = sys_sim_time(&cs)) < 0 ||
		    rig_wait_sim_fine(&cs, t + 500, 3000) < 0)
			fail_msg("run %d: %s", k + 1, cs.err);
		proc_pump(&cs.re, 0);
		if (proc_find_line(&cs.re, PROC_STDOUT, "FAULT ", line,
				   sizeof(line)) == 0)
			fail_msg("run %d: armed after centring from (%.0f, "
				 "%.0f, %.0f), then: %s",
				 k + 1, rig_off_centre[0], rig_off_centre[1],
				 rig_off_centre[2], line);
		proc_signal(&cs.re, SIGTERM);
		if (proc_wait_exit(&cs.re, RIG_EXIT_WAIT_MS, &status) < 0)
			fail_msg("no exit within %d ms of SIGTERM",
				 RIG_EXIT_WAIT_MS);
		assert_int_equal(proc_exit_code(&cs.re), 0);
		sys_case_stop(&cs);
	}
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_centring_then_armed),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
