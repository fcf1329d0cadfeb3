/*
 * test_sys_signals.c - every signal a person can send to roboelf, on the
 * short-robot rig (sys_rig_h.h): SIGQUIT (Ctrl-\), SIGHUP (terminal lost)
 * and SIGTERM while jogging end in the orderly power-off (the motors off on
 * the supervisor's request, then the relay, exit 0, no FAULT, the program
 * back in its safe state, the stop logged); SIGTSTP (Ctrl-Z) is ignored:
 * the heartbeat goes on, nothing trips, still armed.
 *
 * One full calibration for the binary (group setup), then every case on a
 * fresh galil-sim with `--calibration file`.
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

/* ---- signals ------------------------------------------------------------ */

static void quit_by(int sig, const char *logged)
{
	struct rig_opts o = {.calibration = "file"};
	const char *ok = "roboelf: motors off: confirmed; motor power off "
			 "(relay): confirmed; bye";
	double t_sig = -1, t_relay, t_mo;
	char by[3][48], st[2048];
	int status;

	if (rig_start(&cs, &env, &o) < 0 ||
	    rig_wait_ready(&cs, RIG_READY_MS) < 0 ||
	    rig_inject(&cs, "joy B rev") < 0 ||
	    sys_wait_moving(&cs, 'B', 300, 5000) < 0 ||
	    (t_sig = rig_signal_at(&cs, sig, NULL)) < 0)
		fail_msg("%s: %s", logged, cs.err);
	if (proc_wait_exit(&cs.re, RIG_EXIT_WAIT_MS, &status) < 0)
		fail_msg("%s: no exit within %d ms", logged, RIG_EXIT_WAIT_MS);
	if (sys_wait_event(&cs, "relay off", t_sig, 2000, &t_relay) < 0)
		fail_msg("%s: %s", logged, cs.err);
	t_mo = rig_wait_motors_off(&cs, t_sig, 2000);
	if (t_mo < 0 || ph_who_off(&cs, t_sig, by) < 0)
		fail_msg("%s: not every motor was switched off", logged);
	print_message("[ MEASURE  ] %s while jogging: exit %d, motors off %.0f"
		      " ms (by %s), relay off %.0f ms after the signal\n",
		      logged, proc_exit_code(&cs.re), t_mo - t_sig, by[0],
		      t_relay - t_sig);
	assert_int_equal(proc_exit_code(&cs.re), 0);
	if (proc_find_line(&cs.re, PROC_STDOUT, ok, NULL, 0) < 0)
		fail_msg("%s: no '%s' in:\n%s", logged, ok,
			 rig_tail(&cs.re, PROC_STDOUT, 600));
	if (proc_find_line(&cs.re, PROC_STDOUT, "FAULT ", NULL, 0) == 0)
		fail_msg("%s: a FAULT line on quit", logged);
	/* the motors off on the supervisor's request (offreq: the program's
	 * #OFF, or its own AB 1;MO ABC) before the relay opens - not by the
	 * amplifier fault the power cut would cause - and no program fault */
	for (int a = 0; a < 3; a++)
		if (strncmp(by[a], "handle ", 7) &&
		    strncmp(by[a], "thread 0 ", 9))
			fail_msg("%s: motor %c off by '%s', not on the "
				 "supervisor's request",
				 logged, 'A' + a, by[a]);
	if (t_mo > t_relay)
		fail_msg("%s: the relay opened before the motors were off",
			 logged);
	if (sys_check_safe(&cs, 0, RIG_HOLD_MS) < 0 ||
	    sys_state(&cs, st, sizeof(st)) < 0 ||
	    sys_log_find(&cs, "INFO stop: ", logged, NULL, 0) < 0)
		fail_msg("%s: %s", logged, cs.err);
	if (sys_state_num(st, "var.state") != 0 ||
	    sys_state_num(st, "var.fcode") != 0)
		fail_msg("%s: the program is not back in its safe state "
			 "without a fault: %s",
			 logged, st);
	sys_case_stop(&cs);
}

static void test_signals_quit(void **state)
{
	(void)state;
	rig_need_env(&env, env_ok);
	quit_by(SIGQUIT, "Ctrl-\\ (SIGQUIT)");
	quit_by(SIGHUP, "SIGHUP (terminal lost)");
	quit_by(SIGTERM, "SIGTERM");
}

/* Ctrl-Z is ignored: roboelf keeps writing its heartbeat every cycle (hbpc
 * advances in every 100 ms window for 1 s), nothing trips, still armed. */
static void test_signal_tstp_ignored(void **state)
{
	struct rig_opts o = {.calibration = "file"};
	double hb0 = NAN, t0 = -1;
	char st[2048];
	int status;

	(void)state;
	rig_need_env(&env, env_ok);
	if (rig_start(&cs, &env, &o) < 0 ||
	    rig_wait_ready(&cs, RIG_READY_MS) < 0 ||
	    (t0 = rig_signal_at(&cs, SIGTSTP, NULL)) < 0)
		fail_msg("%s", cs.err);
	for (int k = 0; k <= 10; k++) {
		double hb;

		if (rig_wait_sim_fine(&cs, t0 + k * 100.0, 2000) < 0 ||
		    sys_state(&cs, st, sizeof(st)) < 0)
			fail_msg("%s", cs.err);
		hb = sys_state_num(st, "var.hbpc");
		if (k > 0 && !(hb != hb0))
			fail_msg("SIGTSTP: hbpc did not advance from %.0f "
				 "within 100 ms (%d00 ms after): %s",
				 hb0, k, st);
		if (sys_state_num(st, "var.state") != 1)
			fail_msg("SIGTSTP: the program left the armed state: "
				 "%s",
				 st);
		hb0 = hb;
	}
	proc_pump(&cs.re, 0);
	if (proc_find_line(&cs.re, PROC_STDOUT, "FAULT ", NULL, 0) == 0)
		fail_msg("SIGTSTP: a FAULT line: %s",
			 rig_tail(&cs.re, PROC_STDOUT, 600));
	print_message("[ MEASURE  ] SIGTSTP ignored: hbpc advanced in every "
		      "100 ms over 1 s, still armed\n");
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, RIG_EXIT_WAIT_MS, &status) < 0)
		fail_msg("no exit within %d ms of SIGTERM", RIG_EXIT_WAIT_MS);
	assert_int_equal(proc_exit_code(&cs.re), 0);
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_signals_quit),
	    T(test_signal_tstp_ignored),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
