/*
 * test_sys_calfault.c - fault-anywhere: every class of the fault matrix
 * (test_sys_faults.c) injected during a full calibration and during the
 * centring after a calibration from the file ("every phase supervised",
 * docs/supervisor.md; docs/safety.md D25), on the short-robot rig
 * (sys_rig_h.h): the FAULT line of an accepted class naming its axis, in
 * the log, the relay and the motors off within the deadlines of
 * docs/safety.md section 3, the calibration not ended and nothing armed,
 * the safe state held, exit 4 on SIGTERM.
 *
 * One full calibration for the binary (group setup; it also measures the
 * length of the service state and of the centring), then every injection
 * on a fresh galil-sim. Each case runs all its classes, prints a
 * [ MEASURE ] line for each and a [  FAILS   ] line for each failed
 * assertion, then fails.
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

/* ---- fault-anywhere ----------------------------------------------------- */

/* Deadlines, as test_sys_faults.c derives them from docs/safety.md
 * ("Deadlines"), with P the configured period (in the service state the
 * cycle runs every 10 ms, so these are upper bounds there too); P, C and
 * (2 + k) P are rig_p(), rig_c() and rig_d_encpot() (sys_rig_h.h). */
static double t_tolerance(void)

{
	double tol = (1.0 + RIG_ALLOWED_ERR) * RIG_STEP_COUNTS * 1.1;

	return SYS_LOOPMS + 1000.0 * RIG_VMIN_CPS / (10.0 * RIG_VMAX_CPS) +
	       1000.0 * tol / RIG_VMIN_CPS;
}

static double d_ctrl_to_relay(void)
{
	return SYS_MAINMS + 2.0 * rig_p();
}

static double d_jam_motors(void)
{
	return 2 * SYS_LOOPMS + 1000.0 * RIG_VMIN_CPS / (10.0 * RIG_VMAX_CPS) +
	       1000.0 * RIG_STEP_COUNTS / RIG_VMIN_CPS;
}

enum fkind {
	FK_POT_OFFSET,
	FK_POT_OPEN,
	FK_ENC_STUCK,
	FK_JAM,
	FK_JOY,
	FK_STALL,
	FK_DROP,
	FK_UNPLUG,
	FK_WRITEFAIL,
	FK_COUNT
};

struct fclass {
	const char *name;
	const char *req; /* the control request */
	int axis;	 /* the axis the FAULT line must name, -1 none */
	enum re_fault_id cal[6], ctr[6]; /* accepted: calibration, centring */
};

/* The matrix of test_sys_faults.c; the axis of a jam or a dead encoder is
 * one that moves (every axis moves in the service state). */
static struct fclass fclasses[FK_COUNT] = {
    [FK_POT_OFFSET] = {"pot offset",
		       "pot A offset 0.5",
		       0,
		       {RE_F_CAL_ABSOLUTE, RE_F_CTRL_POTRANGE, RE_F_CAL_RANGE,
			RE_F_NONE},
		       {RE_F_ENCPOT, RE_F_NONE}},
    [FK_POT_OPEN] = {"pot open",
		     "pot C open",
		     2,
		     {RE_F_CTRL_POTRANGE, RE_F_NONE},
		     {RE_F_CTRL_POTRANGE, RE_F_NONE}},
    /* in calibration also the pot's range (16): stuck within ER of a
     * switch, the profiler stops at the switch before the error reaches
     * ER and the open loop drives the axis on past it */
    [FK_ENC_STUCK] = {"encoder stuck",
		      "enc A stuck",
		      0,
		      {RE_F_CTRL_POSERR, RE_F_CTRL_ENCODER, RE_F_MOTOR_OFF,
		       RE_F_CTRL_POTRANGE, RE_F_NONE},
		      {RE_F_ENCPOT, RE_F_CTRL_POSERR, RE_F_CTRL_ENCODER,
		       RE_F_MOTOR_OFF, RE_F_NONE}},
    [FK_JAM] = {"jammed axis",
		"block B 1",
		1,
		{RE_F_CTRL_POSERR, RE_F_CTRL_ENCODER, RE_F_MOTOR_OFF,
		 RE_F_NONE},
		{RE_F_CTRL_POSERR, RE_F_CTRL_ENCODER, RE_F_MOTOR_OFF,
		 RE_F_NONE}},
    [FK_JOY] = {"joystick invalid held",
		"joy B fwd a",
		-1,
		{RE_F_CTRL_INPUT, RE_F_NONE},
		{RE_F_CTRL_INPUT, RE_F_NONE}},
    [FK_STALL] = {"link stall",
		  "link stall",
		  -1,
		  {RE_F_WDOG_REPLY, RE_F_NONE},
		  {RE_F_WDOG_REPLY, RE_F_NONE}},
    [FK_DROP] = {"link drop",
		 "link drop",
		 -1,
		 {RE_F_COMM, RE_F_NONE},
		 {RE_F_COMM, RE_F_NONE}},
    [FK_UNPLUG] = {"relay unplug",
		   "relayfault unplug",
		   -1,
		   {RE_F_ESTOP_LOST, RE_F_NONE},
		   {RE_F_ESTOP_LOST, RE_F_NONE}},
    [FK_WRITEFAIL] = {"relay writefail",
		      "relayfault writefail",
		      -1,
		      {RE_F_ESTOP_LOST, RE_F_CTRL_POWER, RE_F_RELAY_POWER,
		       RE_F_NONE},
		      {RE_F_ESTOP_LOST, RE_F_CTRL_POWER, RE_F_RELAY_POWER,
		       RE_F_NONE}},
};

/* The potentiometer's absolute range the program checks (fault 16):
 * potlo = reverse_v - absolute_tolerance_v - near_margin_counts x gain,
 * gain = (forward_v - reverse_v) / travel_counts (pc/config/re_plan.c), with
 * the defaults 0.5 V, 0.25 V, 4.0 V and RIG_NEAR_MARGIN. roboelf refuses a
 * configuration whose potlo is below 0.1 V (an open wiper must stay a
 * fault): on the short robot potlo is 0.125 V for C, so an open wiper
 * (0 V) is outside the range. */
static int open_v_outside_range(int axis)
{
	static const double travel[3] = {20000, 20000, 16000};
	double potlo = 0.5 - 0.25 - RIG_NEAR_MARGIN * 4.0 / travel[axis];

	return 0.0 < potlo;
}

struct fdeadline {
	double relay, motors; /* from the injection, ms; < 0: none applies */
	double pc;	      /* the PC's ESTOP log entry (relay faults) */
};

static struct fdeadline fault_deadlines(enum fkind k, enum ph_phase ph)
{
	int tables = ph == PH_CENTRE; /* the encoder/pot check can run */
	struct fdeadline d = {-1, -1, -1};
	double dm;

	switch (k) {
	case FK_POT_OFFSET:
		/* without tables only the ends of the travel and the
		 * controller's range can tell: no deadline from the injection
		 */
		if (tables)
			d = (struct fdeadline){rig_d_encpot(),
					       rig_d_encpot() + SYS_MAINMS, -1};
		break;
	case FK_POT_OPEN:
		/* the controller's range check (fault 16) sees an open wiper
		 * only where its reading is below potlo; else as an offset */
		if (open_v_outside_range(2))
			d = (struct fdeadline){d_ctrl_to_relay(),
					       SYS_MAINMS + 1, -1};
		else if (tables)
			d = (struct fdeadline){rig_d_encpot(),
					       rig_d_encpot() + SYS_MAINMS, -1};
		break;
	case FK_ENC_STUCK:
		dm = tables ? t_tolerance() + rig_d_encpot() + SYS_MAINMS
			    : d_jam_motors();
		d = (struct fdeadline){
		    tables ? dm - SYS_MAINMS : dm + d_ctrl_to_relay(), dm, -1};
		break;
	case FK_JAM:
		dm = d_jam_motors();
		d = (struct fdeadline){dm + d_ctrl_to_relay(), dm, -1};
		break;
	case FK_JOY:
		dm = RIG_JTO_MS + 2 * SYS_LOOPMS;
		d = (struct fdeadline){dm + d_ctrl_to_relay(), dm, -1};
		break;
	case FK_STALL:
		d = (struct fdeadline){rig_c() + rig_p(),
				       rig_c() + rig_p() + SYS_MAINMS, -1};
		break;
	case FK_DROP:
		d = (struct fdeadline){2 * rig_p(), 2 * rig_p() + SYS_MAINMS,
				       -1};
		break;
	case FK_UNPLUG:
		d = (struct fdeadline){0, SYS_MAINMS, 2 * rig_p()};
		break;
	case FK_WRITEFAIL:
		d = (struct fdeadline){0, SYS_MAINMS,
				       RIG_READBACK_MS + 3 * rig_p()};
		break;
	default: break;
	}
	return d;
}

static void fmt_deadline(char *buf, size_t cap, double d)
{
	if (d >= 0)
		snprintf(buf, cap, "deadline %.0f", d);
	else
		snprintf(buf, cap, "no deadline applies");
}

/* The supervisor's ESTOP log entry, wall ms after @w0 (relay faults). */
static double pc_estop_ms(struct sys_case *c, double w0)
{
	double w1;

	if (sys_log_time_ms(c,
			    "FAULT ESTOP: the E-stop relay stopped "
			    "answering",
			    &w1) < 0)
		return -1;
	return w1 - w0;
}

static void fault_one(enum fkind k, const struct ph_instant *in)
{
	const struct fclass *fc = &fclasses[k];
	struct fdeadline d = fault_deadlines(k, in->ph);
	double anchor, t_inj, t_relay = -1, t_mo, w0, pc = -1;
	char what[160], line[1024];
	int status;

	snprintf(what, sizeof(what), "%s in %s +%.0f ms", fc->name,
		 ph_name[in->ph], in->at_ms);
	if (ph_reach(&cs, &env, in, 0, &anchor) < 0) {
		rig_fail("%s: %s", what, cs.err);
		return;
	}
	w0 = sys_wall_ms();
	t_inj = rig_inject(&cs, fc->req);
	if (t_inj < 0 ||
	    sys_wait_fault(&cs, RIG_FAULT_WAIT_MS, line, sizeof(line)) < 0) {
		rig_fail("%s: %s", what, cs.err);
		return;
	}
	if (sys_wait_event(&cs, "relay off", t_inj, 3000, &t_relay) < 0)
		rig_fail("%s: %s", what, cs.err);
	t_mo = rig_wait_motors_off(&cs, t_inj, 3000);
	if (t_mo < 0)
		rig_fail("%s: not every motor was switched off", what);
	if (d.pc >= 0) {
		/* the log entry may follow the controller's own fault */
		if (rig_wait_sim_fine(&cs, t_inj + d.pc + RIG_SLACK_MS, 5000) <
			0 ||
		    (pc = pc_estop_ms(&cs, w0)) < 0)
			rig_fail("%s: %s", what, cs.err);
	}
	{
		char dr[32], dmo[32], dpc[64] = "";

		fmt_deadline(dr, sizeof(dr), d.relay);
		fmt_deadline(dmo, sizeof(dmo), d.motors);
		if (d.pc >= 0)
			snprintf(dpc, sizeof(dpc),
				 ", ESTOP logged %.0f ms (deadline %.0f)", pc,
				 d.pc);
		print_message("[ MEASURE  ] %s (%.0f ms into the phase): relay "
			      "off %.0f ms (%s), motors off %.0f ms (%s)%s: "
			      "%.150s...\n",
			      what, t_inj - anchor, t_relay - t_inj, dr,
			      t_mo - t_inj, dmo, dpc, line);
	}
	rig_check_fault_line(&cs, what, line, fc->axis,
			     in->ph == PH_CENTRE ? fc->ctr : fc->cal);
	if (proc_find_line(&cs.re, PROC_STDOUT, "RoboELF Ready", NULL, 0) ==
		0 ||
	    proc_find_line(&cs.re, PROC_STDOUT, "roboelf: calibration (", NULL,
			   0) == 0)
		rig_fail("%s: the calibration ended or the robot armed despite "
			 "the fault",
			 what);
	if (sys_check_safe(&cs, 0, RIG_HOLD_MS) < 0)
		rig_fail("%s: %s", what, cs.err);
	if (d.relay >= 0 && t_relay - t_inj > d.relay + RIG_SLACK_MS)
		rig_fail("%s: relay off after %.0f ms, deadline %.0f ms (+%d)",
			 what, t_relay - t_inj, d.relay, RIG_SLACK_MS);
	if (d.motors >= 0 && t_mo - t_inj > d.motors + RIG_SLACK_MS)
		rig_fail("%s: motors off after %.0f ms, deadline %.0f ms (+%d)",
			 what, t_mo - t_inj, d.motors, RIG_SLACK_MS);
	if (d.pc >= 0 && pc > d.pc + RIG_SLACK_MS)
		rig_fail("%s: ESTOP logged %.0f ms after the injection, "
			 "deadline %.0f ms",
			 what, pc, d.pc);
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, RIG_EXIT_WAIT_MS, &status) < 0 ||
	    proc_exit_code(&cs.re) != 4)
		rig_fail("%s: no exit 4 within %d ms of SIGTERM (exit %d)",
			 what, RIG_EXIT_WAIT_MS, proc_exit_code(&cs.re));
}

/* During a full calibration: class k at (k + 0.5) / FK_COUNT of the
 * measured service state, so that the classes meet its stages in turn
 * (fast toward the reverse switches, the switches, the sweep, the forward
 * switches, the move to the centre). */
static void test_fault_in_calibration(void **state)
{
	(void)state;
	rig_need_env(&env, env_ok);
	rig_fails_reset();
	for (int k = 0; k < FK_COUNT; k++) {
		struct ph_instant in = {PH_CALIB, NULL,
					ref.d_cal * (k + 0.5) / FK_COUNT};

		fault_one((enum fkind)k, &in);
		sys_case_stop(&cs);
	}
	rig_fails_check("fault-anywhere, full calibration");
}

/* During centring from a file: at 40 % of the move, every axis at speed. */
static void test_fault_in_centring(void **state)
{
	(void)state;
	rig_need_env(&env, env_ok);
	rig_fails_reset();
	for (int k = 0; k < FK_COUNT; k++) {
		struct ph_instant in = {PH_CENTRE, NULL, ref.d_centre * 0.4};

		fault_one((enum fkind)k, &in);
		sys_case_stop(&cs);
	}
	rig_fails_check("fault-anywhere, centring");
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_fault_in_calibration),
	    T(test_fault_in_centring),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	/* the stall's fault in the design the run selects */
	fclasses[FK_STALL].cal[0] = fclasses[FK_STALL].ctr[0] =
	    sys_stall_fault();
	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
