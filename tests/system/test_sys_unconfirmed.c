/*
 * test_sys_unconfirmed.c - a stop that cannot be confirmed: the link lost
 * or the relay board wedged while the amplifiers keep motor power
 * (docs/safety.md D26, D27), on the short-robot rig (sys_rig_h.h):
 *
 *  - link loss with the amplifier model off (--no-amp-undervoltage): who
 *    stops the motors when the controller cannot see motor power go (the
 *    supervisor over a new connection, else the controller's watchdog),
 *    within the watchdog's deadline; the FAULT line and the log say
 *    whether the stop was delivered;
 *  - a wedged relay board, alone and with a fault: the controller stop
 *    within the fault's deadline, the FAULT line says the relay open was
 *    not confirmed and asks for the hardware E-stop, roboelf still exits
 *    4 at once on SIGTERM.
 *
 * One full calibration for the binary (group setup), then every case on a
 * fresh galil-sim with `--calibration file`. Each test runs all its cases,
 * prints a [ MEASURE ] line for each and a [  FAILS   ] line for each
 * failed assertion, then fails.
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

#include "re_check.h"
#include "sys_phase_h.h"
#include "sys_truth.h"

#define WEDGE_EXIT_MS 1000 /* SIGTERM to exit with a wedged relay */

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

/* ---- link loss with the amplifier model off ----------------------------- */

/* Start armed with galil-sim's amplifiers blind to motor power

 * (--no-amp-undervoltage) and axis A jogging. */
static void start_jogging_blind(void)
{
	struct rig_opts o = {.calibration = "file", .no_amp_uv = 1};

	if (rig_start(&cs, &env, &o) < 0 ||
	    rig_wait_ready(&cs, RIG_READY_MS) < 0 ||
	    rig_inject(&cs, "joy A fwd") < 0 ||
	    sys_wait_moving(&cs, 'A', 300, 5000) < 0)
		fail_msg("%s", cs.err);
}

struct link_case {
	const char *name;
	const char *req;
	int transient;	   /* "link ok" at once: only the sockets died */
	int by_supervisor; /* the supervisor's new connection stops */
	enum re_fault_id id;
	double d_relay; /* the supervisor's deadline to relay off */
};

/*
 * With the amplifier model off, cutting motor power is invisible to the
 * controller: no amplifier fault switches the motors off; only a stop
 * command (the supervisor's, over a new connection) or the controller's
 * watchdog can. Every motor must be off within the watchdog's deadline
 * after the link went (RIG_D_CTRL_MS) whoever does it; the relay opens.
 */
static void link_loss(const struct link_case *lc)
{
	char line[1024], logline[4096], by[3][48];
	enum re_fault_id ids[2] = {lc->id, RE_F_NONE};
	double t_link, t_relay, t_mo, t_power;
	int status;

	start_jogging_blind();
	if (lc->transient) {
		/* both requests back to back (well under a millisecond) */
		double t0 = sys_sim_time(&cs), t;

		t_link = -1;
		if (t0 >= 0 && sys_ctl(&cs, "%s", lc->req) == 0 &&
		    sys_ctl(&cs, "link ok") == 0 &&
		    sys_wait_event(&cs, "inject: link drop", t0, 2000, &t) == 0)
			t_link = t;
	} else {
		t_link = rig_inject(&cs, lc->req);
	}
	if (t_link < 0 ||
	    sys_wait_fault(&cs, RIG_FAULT_WAIT_MS, line, sizeof(line)) < 0 ||
	    sys_wait_event(&cs, "relay off", t_link, 3000, &t_relay) < 0)
		fail_msg("%s: %s", lc->name, cs.err);
	t_mo = rig_wait_motors_off(&cs, t_link, 3000);
	if (t_mo < 0 || ph_who_off(&cs, t_link, by) < 0)
		fail_msg("%s: not every motor was switched off", lc->name);
	print_message("[ MEASURE  ] %s, amplifier model off: relay off %.0f ms"
		      " (deadline %.0f), motors off %.0f ms (deadline %d) by "
		      "A: %s, B: %s, C: %s\n[ MEASURE  ]   %s\n",
		      lc->name, t_relay - t_link, lc->d_relay, t_mo - t_link,
		      RIG_D_CTRL_MS, by[0], by[1], by[2], line);
	if (sys_log_find(&cs, " FAULT ", line, logline, sizeof(logline)) < 0)
		fail_msg("%s: %s", lc->name, cs.err);
	print_message("[ MEASURE  ]   log: ...%s\n",
		      strstr(logline, " | relay off: ")
			  ? strstr(logline, " | relay off: ")
			  : logline);
	rig_check_fault_line(&cs, lc->name, line, -1, ids);
	for (int a = 0; a < 3; a++)
		if (strncmp(by[a], lc->by_supervisor ? "handle " : "thread 0",
			    lc->by_supervisor ? 7 : 8))
			rig_fail("%s: motor %c switched off by '%s', expected "
				 "%s",
				 lc->name, 'A' + a, by[a],
				 lc->by_supervisor
				     ? "the supervisor's new connection"
				     : "the controller's watchdog (thread 0)");
	/* galil-sim logs it at its next step after the relay opened: it may
	 * follow the events read so far */
	if (sys_wait_event(&cs, "motor power lost (amplifiers report nothing",
			   t_link, 1000, &t_power) < 0)
		rig_fail("%s: no 'motor power lost' event: was the amplifier "
			 "model off?",
			 lc->name);
	if (lc->by_supervisor) {
		if (!strstr(line, "Safe state confirmed") ||
		    !strstr(logline, "delivered over a new connection"))
			rig_fail("%s: the stop over a new connection is not "
				 "confirmed: %s",
				 lc->name, logline);
	} else if (!strstr(line, "NOT CONFIRMED") ||
		   (!strstr(line, "stop command not delivered (") &&
		    !strstr(line, "no answer to the stop command in time (")) ||
		   !strstr(line, "PRESS THE HARDWARE E-STOP NOW") ||
		   !strstr(logline, "over a new connection") ||
		   !strstr(logline, "motors off: NOT confirmed")) {
		rig_fail("%s: the FAULT line or the log does not say that the "
			 "stop was not delivered or not answered:\n    %s",
			 lc->name, logline);
	}
	if (sys_truth_check(&cs, line, t_link, 0) < 0)
		rig_fail("%s: %s", lc->name, cs.err);
	if (t_relay - t_link > lc->d_relay + RIG_SLACK_MS)
		rig_fail("%s: relay off after %.0f ms, deadline %.0f ms",
			 lc->name, t_relay - t_link, lc->d_relay);
	if (t_mo - t_link > RIG_D_CTRL_MS)
		rig_fail("%s: motors off after %.0f ms, deadline %d ms",
			 lc->name, t_mo - t_link, RIG_D_CTRL_MS);
	if (sys_check_safe(&cs, 0, RIG_HOLD_MS) < 0)
		rig_fail("%s: %s", lc->name, cs.err);
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, RIG_EXIT_WAIT_MS, &status) < 0 ||
	    proc_exit_code(&cs.re) != 4)
		rig_fail("%s: no exit 4 within %d ms of SIGTERM", lc->name,
			 RIG_EXIT_WAIT_MS);
}

static void test_link_loss_amp_model_off(void **state)
{
	/* a drop that lasts: galil-sim closes every new connection until
	 * "link ok", so only the controller's watchdog can stop */
	const struct link_case cases[] = {
	    {"link drop (sockets reset, link back at once)", "link drop", 1, 1,
	     RE_F_COMM, 2 * rig_p()},
	    {"link drop (lasting)", "link drop", 0, 0, RE_F_COMM, 2 * rig_p()},
	    {"link stall", "link stall", 0, 0, sys_stall_fault(),
	     rig_c() + rig_p()},
	};

	(void)state;
	rig_need_env(&env, env_ok);
	rig_fails_reset();
	for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		link_loss(&cases[i]);
		sys_case_stop(&cs);
	}
	rig_fails_check("link loss, amplifier model off");
}

/* ---- a wedged relay board ----------------------------------------------- */

/* The relay board hangs with the relay on (motor power stays on whatever
 * roboelf writes), then @fault_req (or nothing: the read-back finds the
 * board silent). The controller stop meets the fault's deadline, the FAULT
 * line says the relay open was not confirmed and asks for the hardware
 * E-stop, and roboelf still exits on SIGTERM at once with 4. */
static void wedged(const char *name, const char *fault_req, enum re_fault_id id,
		   int axis, double d_motors)
{
	enum re_fault_id ids[2] = {id, RE_F_NONE};
	struct rig_opts o = {.calibration = "file"};
	double t_w = -1, t_f, t_mo;
	long long q0;
	char line[1024], st[2048];
	int status;

	if (rig_start(&cs, &env, &o) < 0 ||
	    rig_wait_ready(&cs, RIG_READY_MS) < 0 ||
	    (t_w = rig_inject(&cs, "relayfault wedge")) < 0)
		fail_msg("%s: %s", name, cs.err);
	t_f = fault_req ? rig_inject(&cs, fault_req) : t_w;
	if (t_f < 0 ||
	    sys_wait_fault(&cs, RIG_FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s: %s", name, cs.err);
	t_mo = rig_wait_motors_off(&cs, t_f, 3000);
	if (t_mo < 0)
		fail_msg("%s: not every motor was switched off", name);
	if (sys_state(&cs, st, sizeof(st)) < 0)
		fail_msg("%s", cs.err);
	print_message("[ MEASURE  ] %s: motors off %.0f ms after the %s "
		      "(deadline %.0f); relay %s, power %s\n[ MEASURE  ]   "
		      "%s\n",
		      name, t_mo - t_f, fault_req ? "fault" : "wedge", d_motors,
		      strstr(st, " relay=on ") ? "on" : "off",
		      strstr(st, " power=1 ") ? "on" : "off", line);
	rig_check_fault_line(&cs, name, line, axis, ids);
	if (!strstr(line, "NOT CONFIRMED: relay open not confirmed;") ||
	    !strstr(line, "PRESS THE HARDWARE E-STOP NOW"))
		rig_fail("%s: the FAULT line does not say that the relay did "
			 "not open: %s",
			 name, line);
	if (t_mo - t_f > d_motors + RIG_SLACK_MS)
		rig_fail("%s: motors off after %.0f ms, deadline %.0f ms", name,
			 t_mo - t_f, d_motors);
	/* the wedged board keeps motor power on: the motors are off */
	if (sys_check_safe(&cs, 1, RIG_HOLD_MS) < 0)
		rig_fail("%s: %s", name, cs.err);
	else if (sys_truth_check(&cs, line, t_w, 0) < 0)
		rig_fail("%s: %s", name, cs.err);
	/* the power-off waits relay.off_deadline_ms (50) for the relay,
	 * never for the wedged board itself */
	q0 = proc_now_ms();
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, WEDGE_EXIT_MS, &status) < 0) {
		rig_fail("%s: roboelf hangs: no exit within %d ms of SIGTERM",
			 name, WEDGE_EXIT_MS);
		return;
	}
	line[0] = '\0';
	proc_find_line(&cs.re, PROC_STDOUT, "roboelf: motors off", line,
		       sizeof(line));
	print_message("[ MEASURE  ] %s: exit %d %lld ms after SIGTERM: %s\n",
		      name, proc_exit_code(&cs.re), proc_now_ms() - q0, line);
	if (proc_exit_code(&cs.re) != 4)
		rig_fail("%s: exit %d, not 4", name, proc_exit_code(&cs.re));
	if (!strstr(proc_output(&cs.re, PROC_STDOUT),
		    "NOT ALL CONFIRMED: press the hardware E-stop"))
		rig_fail("%s: the quit message does not ask for the hardware "
			 "E-stop",
			 name);
}

static void test_wedged_relay(void **state)
{
	(void)state;
	rig_need_env(&env, env_ok);
	rig_fails_reset();
	/* a fault while the board is wedged (before its read-back times
	 * out): the encoder/pot deadline of test_sys_faults */
	wedged("wedged relay, then pot offset", "pot A offset 0.5", RE_F_ENCPOT,
	       0, rig_d_encpot() + SYS_MAINMS);
	sys_case_stop(&cs);
	/* the wedge alone: the read-back finds the board silent after R,
	 * the cycle after it acts (R + 3P, as relay writefail), plus mainms */
	wedged("wedged relay alone", NULL, RE_F_ESTOP_LOST, -1,
	       RIG_READBACK_MS + 3 * rig_p() + SYS_MAINMS);
	sys_case_stop(&cs);
	rig_fails_check("wedged relay");
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_link_loss_amp_model_off),
	    T(test_wedged_relay),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
