/*
 * test_sys_jam.c - faults that name their real cause: a jam and a stuck
 * encoder on each axis, jogging and during the full calibration
 * (docs/safety.md H11, D31), on the whole system: galil-sim running dmc/
 * (downloaded by galil-load), roboelf supervising it through the virtual
 * relay. The FAULT line names the axis and the first cause (the
 * controller's position error or encoder failure, or the PC's
 * encoder/potentiometer check), never the supervisor's own fault request
 * as a consequence; relay and motors off within the deadlines of D4 and D6.
 *
 * One full calibration for the binary (group setup), then every case on a
 * fresh galil-sim (`--calibration file` jogging, `full` calibrating). Every
 * case asserts the outcome, the exact text (sys_exact_h.h) and the
 * reaction time against the deadlines of docs/safety.md section 3 plus
 * SX_SLACK_MS; the group teardown prints the summary table.
 *
 * Environment: ROBOELF_SYS_FILTER=PATTERN runs only the matching cases;
 * ROBOELF_KEEP=1 keeps the temporary directory; ROBOELF_SYS_CAL=FILE
 * reuses a calibration (development).
 */
#include <errno.h>
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

#include <cmocka.h>

#include "sys_exact_h.h"

static struct sys_env env;
static struct sx_fixture fx;
static struct sys_case cs; /* the first roboelf and its controller */

static int group_setup(void **state)
{
	(void)state;
	return sx_group_setup(&fx, &env);
}

static int group_teardown(void **state)
{
	(void)state;
	return sx_group_teardown(&fx, 0);
}

static int case_teardown(void **state)
{
	(void)state;
	sys_case_stop(&cs);
	return 0;
}

/* ---- root cause: a jam and a stuck encoder on each axis --------------------
 */

/* Jam (or stuck encoder) detection, docs/safety.md "E": the position error
 * grows at vmin (every move here is at least that fast) to at most one
 * step; ER < step trips, or OA first: 2L + vmin/(10 vmax) + step/vmin. */
static double d_jam(void)
{
	return 2 * SYS_LOOPMS + 1000.0 * env.vmin_cps / (10.0 * env.vmax_cps) +
	       1000.0 * env.step_counts / env.vmin_cps;
}

/* A stuck encoder while jogging: the pot disagrees once the axis moved
 * the tolerance, "T_tol + (2 + k) P" of docs/safety.md. */
static double d_enc_jog(void)
{
	double tol = (1.0 + env.allowed_error) * env.step_counts * 1.1;
	double t_tol = SYS_LOOPMS +
		       1000.0 * env.vmin_cps / (10.0 * env.vmax_cps) +
		       1000.0 * tol / env.vmin_cps;

	return t_tol + (2.0 + env.persistence) * sx_p(&env);
}

/*
 * A FAULT after @t_inj: the line exactly @tpl, relay off within @d_relay
 * (< 0: not asserted; galil-sim cut the power itself) and every motor off
 * within @d_motors, the safe state held, roboelf exits 4 on SIGTERM.
 */
static void expect_cause(struct sx_row *r, double t_inj, const char *tpl,
			 double d_relay, double d_motors, double *num, int max)
{
	char line[SX_TEXT_MAX];
	double t_relay = -1, t_mo;
	int i, status;

	if (sys_wait_fault(&cs, SX_FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	sx_row_text(r, line);
	i = sx_wait_event(&cs, "relay off", NULL, t_inj, 3000);
	t_relay = cs.ev[i].t_ms - t_inj;
	t_mo = sx_wait_motors_off(&cs, t_inj, 3000) - t_inj;
	sx_row_reaction(r,
			"relay off %.0f ms (deadline %.0f), motors off %.0f "
			"ms (deadline %.0f)",
			t_relay, d_relay, t_mo, d_motors);
	sx_not_own_request(line);
	sx_expect_text("the FAULT line", tpl, line, num, max);
	if (sys_check_safe(&cs, 0, SX_HOLD_MS) < 0)
		fail_msg("%s", cs.err);
	if (d_relay >= 0 && t_relay > d_relay + SX_SLACK_MS)
		fail_msg("relay off %.0f ms after the injection, deadline "
			 "%.0f ms",
			 t_relay, d_relay);
	if (t_mo > d_motors + SX_SLACK_MS)
		fail_msg("motors off %.0f ms after the injection, deadline "
			 "%.0f ms",
			 t_mo, d_motors);
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, SX_EXIT_WAIT_MS, &status) < 0 ||
	    proc_exit_code(&cs.re) != 4)
		fail_msg("roboelf did not exit 4 after the fault (exit %d)",
			 proc_exit_code(&cs.re));
}

/* Jogging: @req (e.g. "block B 1") at rest, then the joystick drives the
 * axis forward; the deadline counts from the joystick command. */
static double cause_jogging(int axis, const char *req)
{
	char joy[32];

	sx_start(&cs, &fx);
	sx_inject(&cs, "inject: ", req);
	snprintf(joy, sizeof(joy), "joy %c fwd", 'A' + axis);
	return sx_inject(&cs, "input: ", joy);
}

/* During the full calibration: once the axis moves (its first, fast move
 * toward the reverse switch), @req. */
static double cause_calibrating(int axis, const char *req)
{
	struct sys_opts o = {.calibration = "full", .no_ready = 1};
	char begin[32];

	sx_start_with(&cs, &fx, &o);
	snprintf(begin, sizeof(begin), "axis %c begin", 'A' + axis);
	sx_wait_event(&cs, begin, NULL, 0, 20000);
	if (sys_wait_moving(&cs, (char)('A' + axis), 2000, 10000) < 0)
		fail_msg("%s", cs.err);
	return sx_inject(&cs, "inject: ", req);
}

/* The controller's position error (fault 4) on @axis: the limit ER. */
static void tpl_poserr(char *tpl, size_t cap, int axis)
{
	char er[64];

	sys_counts_text(&env, axis, env.er_counts, er, sizeof(er));
	snprintf(tpl, cap,
		 "FAULT MOTION: axis %c: position error of at least %s, "
		 "above its limit (blocked, jammed, or its encoder "
		 "stuck?)." SX_SAFE_OK
		 " Recovery: press the E-stop and keep it pressed, check "
		 "that axis %c moves freely and nothing blocks it, then its "
		 "encoder cable, then restart roboelf",
		 'A' + axis, er, 'A' + axis);
}

static void jam(int axis, int calibrating)
{
	char name[48], req[32], tpl[1024];
	double t;
	struct sx_row *r;

	snprintf(name, sizeof(name), "7 jam axis %c, %s", 'A' + axis,
		 calibrating ? "calibrating" : "jogging");
	r = sx_row_begin(name);
	snprintf(req, sizeof(req), "block %c 1", 'A' + axis);
	t = calibrating ? cause_calibrating(axis, req)
			: cause_jogging(axis, req);
	if (calibrating)
		tpl_poserr(tpl, sizeof(tpl), axis);
	else
		snprintf(
		    tpl, sizeof(tpl),
		    "FAULT ENCODER: axis %c: the controller detected an "
		    "encoder failure or a blocked axis (stop code "
		    "12)." SX_SAFE_OK
		    " Recovery: press the E-stop and keep it pressed, check "
		    "that axis %c moves freely, then its encoder cable "
		    "and its motor, restart roboelf and recalibrate",
		    'A' + axis, 'A' + axis);
	expect_cause(r, t, tpl, d_jam() + sx_d_ctrl_to_relay(&env), d_jam(),
		     NULL, 0);
	sx_row_pass(r, "axis %c named (%s)", 'A' + axis,
		    calibrating ? "MOTION position error" : "ENCODER, OA");
}

static void enc_stuck(int axis, int calibrating)
{
	char name[48], req[32], tpl[1024], act[8], pos[8];
	double t, d, num[7], runaway;
	int k = 0;
	struct sx_row *r;

	snprintf(name, sizeof(name), "7 encoder stuck %c, %s", 'A' + axis,
		 calibrating ? "calibrating" : "jogging");
	r = sx_row_begin(name);
	snprintf(act, sizeof(act), "%c.act", 'A' + axis);
	snprintf(pos, sizeof(pos), "%c.pos", 'A' + axis);
	snprintf(req, sizeof(req), "enc %c stuck", 'A' + axis);
	t = calibrating ? cause_calibrating(axis, req)
			: cause_jogging(axis, req);
	d = calibrating ? d_jam() : d_enc_jog();
	if (calibrating)
		tpl_poserr(tpl, sizeof(tpl), axis);
	else
		k = sx_tpl_encpot(&env, tpl, sizeof(tpl), axis) - 1;
	expect_cause(r, t, tpl, d + sx_d_ctrl_to_relay(&env), d, num, 7);
	if (!calibrating)
		sx_check_encpot_units(&env, num, k + 1, axis, r->text);
	if (!calibrating &&
	    (fabs(num[0] - num[1]) <= num[4 + k] || num[3 + k] <= num[4 + k] ||
	     (int)num[5 + k] != env.persistence + 1))
		fail_msg("the values do not show a disagreement beyond the "
			 "tolerance for persistence + 1 cycles: %s",
			 r->text);
	runaway = fabs(sx_state_num(&cs, act) - sx_state_num(&cs, pos));
	sx_row_pass(r,
		    "axis %c named (%s); the motor ran %.0f counts past the "
		    "frozen count",
		    'A' + axis,
		    calibrating ? "MOTION position error"
				: "ENCODER pot/encoder",
		    runaway);
}

static void test_jam_jog_a(void **state)
{
	(void)state;
	jam(0, 0);
}
static void test_jam_jog_b(void **state)
{
	(void)state;
	jam(1, 0);
}
static void test_jam_jog_c(void **state)
{
	(void)state;
	jam(2, 0);
}
static void test_jam_cal_a(void **state)
{
	(void)state;
	jam(0, 1);
}
static void test_jam_cal_b(void **state)
{
	(void)state;
	jam(1, 1);
}
static void test_jam_cal_c(void **state)
{
	(void)state;
	jam(2, 1);
}
static void test_enc_jog_a(void **state)
{
	(void)state;
	enc_stuck(0, 0);
}
static void test_enc_jog_b(void **state)
{
	(void)state;
	enc_stuck(1, 0);
}
static void test_enc_jog_c(void **state)
{
	(void)state;
	enc_stuck(2, 0);
}
static void test_enc_cal_a(void **state)
{
	(void)state;
	enc_stuck(0, 1);
}
static void test_enc_cal_b(void **state)
{
	(void)state;
	enc_stuck(1, 1);
}
static void test_enc_cal_c(void **state)
{
	(void)state;
	enc_stuck(2, 1);
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_jam_jog_a), T(test_jam_jog_b), T(test_jam_jog_c),
	    T(test_jam_cal_a), T(test_jam_cal_b), T(test_jam_cal_c),
	    T(test_enc_jog_a), T(test_enc_jog_b), T(test_enc_jog_c),
	    T(test_enc_cal_a), T(test_enc_cal_b), T(test_enc_cal_c),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
