/*
 * test_sys_freeze.c - freeze-anywhere: roboelf stopped (SIGSTOP) for 2 s in
 * each phase, then continued (SIGCONT) ("every phase supervised",
 * docs/supervisor.md; docs/safety.md D24), on the short-robot rig
 * (sys_rig_h.h): while it is stopped every motor off and at rest within the
 * controller's deadline, as for a kill; after SIGCONT the FAULT line names
 * the supervisor's own stall (or, latched already, the first fault stays
 * the one reported) and roboelf exits 4 on SIGTERM.
 *
 * One full calibration for the binary (group setup; it also measures the
 * phase boundaries), then every instant on a fresh galil-sim. The case
 * runs all its instants, prints a [ MEASURE ] line for each and a
 * [  FAILS   ] line for each failed assertion, then fails.
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

#include "sys_phase_h.h"
#include "sys_truth.h"

#define FREEZE_MS	2000
#define FREEZE_SLACK_MS 5 /* see check_stall_line() */

static struct sys_env env;
static int env_ok;
static struct sys_case cs;
static struct rig_ref ref; /* measured by the group set-up */

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

/* ---- freeze-anywhere ---------------------------------------------------- */

/* The FAULT line after a freeze must name the supervisor's own stall, at
 * least as long as the freeze, with the critical limit C, and not the
 * link. */
static void check_stall_line(const char *what, const char *line)
{
	static const char pre[] =
	    "FAULT WATCHDOG: this supervisor did not run for ";
	static const enum re_fault_id stall[] = {RE_F_STALL, RE_F_NONE};
	int n = -1, m = -1;

	if (strncmp(line, pre, strlen(pre)) ||
	    sscanf(line + strlen(pre), "%d ms (limit %d ms)", &n, &m) != 2) {
		rig_fail("%s: the FAULT line does not name the stall:\n    %s",
			 what, line);
		return;
	}
	/* the freeze is timed on galil-sim's clock from just after kill()
	 * returned, and roboelf may run a moment longer before the stop
	 * takes effect: its own measure can be short of it by that much
	 * (1999 ms seen once for 2000), never by more than FREEZE_SLACK_MS */
	if (n < FREEZE_MS - FREEZE_SLACK_MS)
		rig_fail("%s: stall of %d ms reported, the freeze was %d ms",
			 what, n, FREEZE_MS);
	if (m != (int)(RIG_CRIT_F * RIG_PERIOD_MS))
		rig_fail("%s: limit %d ms reported, C is %d ms", what, m,
			 (int)(RIG_CRIT_F * RIG_PERIOD_MS));
	if (!strstr(line, "the PC stalled") || strstr(line, "cable") ||
	    sys_fault_match(line, -1, stall) != RE_F_STALL)
		rig_fail("%s: not the stall's text and recovery:\n    %s", what,
			 line);
}

static void freeze_one(const struct ph_instant *in)
{
	struct ph_off r;
	double anchor, t_sig, t0;
	char what[160], line[1024], first[1024] = "";
	int status;

	snprintf(what, sizeof(what), "freeze in %s +%.0f ms", ph_name[in->ph],
		 in->at_ms);
	if (ph_reach(&cs, &env, in, 0, &anchor) < 0) {
		rig_fail("%s: %s", what, cs.err);
		return;
	}
	if (in->ph == PH_LATCHED)
		proc_find_line(&cs.re, PROC_STDOUT, "FAULT ", first,
			       sizeof(first));
	t_sig = rig_signal_at(&cs, SIGSTOP, &t0);
	if (t_sig < 0 || sys_events(&cs) < 0) {
		rig_fail("%s: %s", what, cs.err);
		return;
	}
	/* while it is stopped: the controller's deadline, the safe state */
	ph_check_off(&cs, what, t_sig, 0, &r);
	ph_measure_line("freeze", in->ph, t_sig, t_sig - t0, anchor, &r);
	if (rig_wait_sim_fine(&cs, t_sig + FREEZE_MS, FREEZE_MS + 3000) < 0 ||
	    rig_signal_at(&cs, SIGCONT, NULL) < 0) {
		rig_fail("%s: %s", what, cs.err);
		return;
	}
	if (in->ph == PH_LATCHED) {
		/* the first fault stays the one reported */
		if (proc_wait_line(&cs.re, PROC_STDOUT, "FAULT ", 1000, line,
				   sizeof(line)) == 0)
			rig_fail("%s: a second FAULT line after the freeze:\n"
				 "    %s\n  (first: %s)",
				 what, line, first);
	} else if (sys_wait_fault(&cs, 3000, line, sizeof(line)) < 0) {
		rig_fail("%s: no FAULT line within 3 s of SIGCONT; roboelf "
			 "went on%s",
			 what,
			 proc_find_line(&cs.re, PROC_STDOUT,
					"RoboELF Ready for Use", NULL, 0) == 0
			     ? " to 'RoboELF Ready for Use' and stayed armed"
			     : "");
	} else {
		print_message("[ MEASURE  ] freeze in %s: after SIGCONT: %.160s"
			      "...\n",
			      ph_name[in->ph], line);
		check_stall_line(what, line);
		if (sys_check_safe(&cs, 0, RIG_HOLD_MS) < 0)
			rig_fail("%s: after SIGCONT: %s", what, cs.err);
		else if (sys_truth_check(&cs, line, t_sig, 0) < 0)
			rig_fail("%s: %s", what, cs.err);
	}
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, RIG_EXIT_WAIT_MS, &status) < 0)
		rig_fail("%s: roboelf did not exit within %d ms of SIGTERM",
			 what, RIG_EXIT_WAIT_MS);
	else if (proc_exit_code(&cs.re) != 4)
		rig_fail("%s: exit code %d after SIGTERM, not 4 (latched)",
			 what, proc_exit_code(&cs.re));
}

static void test_freeze_anywhere(void **state)
{
	const struct ph_instant plan[] = {
	    {PH_RELAY, NULL, 0},
	    {PH_SVCREQ, NULL, 0},
	    {PH_CALIB, NULL, ref.d_cal / 2},
	    {PH_CENTRE, NULL, ref.d_centre / 2},
	    {PH_ARMREQ, NULL, 0},
	    {PH_ARMED, NULL, 100},
	    {PH_JOG, NULL, 450},
	    {PH_LATCHED, NULL, 100},
	};

	(void)state;
	rig_need_env(&env, env_ok);
	rig_fails_reset();
	for (size_t i = 0; i < sizeof(plan) / sizeof(plan[0]); i++) {
		freeze_one(&plan[i]);
		sys_case_stop(&cs);
	}
	rig_fails_check("freeze-anywhere");
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_freeze_anywhere),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
