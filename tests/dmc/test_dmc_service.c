/*
 * test_dmc_service.c - the service state of DMC 2.00 (state 3; the headers
 * of #SVCIN, #GOON, #SVC, #MVGO, #MVSUP, #HBCHK, #OFF, #ARM and #POSERR in
 * dmc/roboelf.dmc are the specification): entering it, the supervisor's
 * move requests (taken, refused with fault 15 detail 1..5, supervised with
 * detail 6 and 7), the heartbeat and the joystick while in service, the
 * orderly switch-off (#OFF), arming from service, and the automatic
 * routines when the program was halted on purpose (prun=0).
 *
 * Reaction times are measured in simulated time and printed ("measured:")
 * so that the figures can be compared with the formulas of the headers.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "dmc_h.h"

#define PWROUT 1 /* the motor-power output of these tests */

static char events[SIM_RESPONSE_MAX];

/* ---- helpers ------------------------------------------------------------- */

/* The default parameters with the motor-power output wired to PWROUT. */
static void params_service(struct dmc_h_params *p)
{
	dmc_h_params_default(p);
	p->pwrout = PWROUT;
}

/* A started program with @p written, not yet in service. */
static int open_configured(struct dmc_h *h, const struct dmc_h_params *p)
{
	int rc;

	if ((rc = dmc_h_open(h)) < 0 || (rc = dmc_h_start(h)) < 0 ||
	    (rc = dmc_h_configure(h, p)) < 0)
		return rc;
	return 0;
}

/* Fixture: the robot in service with params_service(). */
static int fx_service(void **state)
{
	struct dmc_h_params p;
	struct dmc_h *h;

	if (dmc_h_fx_new(state) < 0)
		return -1;
	h = *state;
	params_service(&p);
	if (open_configured(h, &p) < 0 || dmc_h_service(h) < 0) {
		fprintf(stderr, "set-up: %s\n", h->err);
		return -1;
	}
	return 0;
}

/* A value the controller computes, read with a host MG (NAN on error). */
static double mg(struct dmc_h *h, const char *expr)
{
	char line[64], resp[64];

	snprintf(line, sizeof(line), "MG %s", expr);
	if (dmc_h_cmd(h, line, resp, sizeof(resp)) < 0)
		return NAN;
	return atof(resp);
}

/* The level of digital output @n (@OUT[n]: 1 closed, 0 open). */
static double out_level(struct dmc_h *h, int n)
{
	char expr[16];

	snprintf(expr, sizeof(expr), "@OUT[%d]", n);
	return mg(h, expr);
}

static double var_i(struct dmc_h *h, const char *name, int i)
{
	char el[24];

	snprintf(el, sizeof(el), "%s[%d]", name, i);
	return dmc_h_var(h, el);
}

static int set_i(struct dmc_h *h, const char *name, int i, double v)
{
	char el[24];

	snprintf(el, sizeof(el), "%s[%d]", name, i);
	return dmc_h_set(h, el, v);
}

/* Write a move request of one axis without waiting: mvax[] = only @ax. */
static void request(struct dmc_h *h, int ax, double target, double speed,
		    double mvto)
{
	for (int i = 0; i < DMC_H_AXES; i++)
		DMC_H_CHECK(h, set_i(h, "mvax", i, i == ax));
	DMC_H_CHECK(h, set_i(h, "mvtg", ax, target));
	DMC_H_CHECK(h, set_i(h, "mvsp", ax, speed));
	DMC_H_CHECK(h, dmc_h_set(h, "mvto", mvto));
	DMC_H_CHECK(h, dmc_h_set(h, "mvreq", 1));
}

/* Advance until axis @ax is no longer owned and its profiler is idle. */
static void wait_move_done(struct dmc_h *h, int ax, double timeout_ms)
{
	double t0 = dmc_h_now(h);

	while (var_i(h, "own", ax) != 0 || dmc_h_axis(h, ax).moving) {
		if (dmc_h_now(h) - t0 > timeout_ms)
			fail_msg(
			    "move of axis %d not done in %.0f ms (state %g, "
			    "fault %g)",
			    ax, timeout_ms, dmc_h_var(h, "state"),
			    dmc_h_var(h, "fcode"));
		dmc_h_advance(h, 1);
	}
}

/* One accepted move of @ax to @target at @speed, waited for to the end. */
static void move_to(struct dmc_h *h, int ax, double target, double speed)
{
	double d = fabs(target - dmc_h_axis(h, ax).enc);

	DMC_H_CHECK(h, dmc_h_move(h, ax, target, speed, 20000));
	wait_move_done(h, ax, d / speed * 1000 + 1000);
	assert_true(fabs(dmc_h_axis(h, ax).enc - target) <= 1);
}

/*
 * The latched fault: state 2, fcode/faxis/fdet, exactly one FAULT line with
 * the same numbers, every motor off and the power output open.
 */
static void assert_latched(struct dmc_h *h, int code, int axis, double det)
{
	int c = -1, a = -1;
	double d = -1;

	dmc_h_advance(h, 2); /* the FAULT line leaves the output queue */
	if (dmc_h_var(h, "fcode") != code || dmc_h_var(h, "faxis") != axis ||
	    dmc_h_var(h, "fdet") != det)
		fail_msg("fault %g axis %g detail %g, want %d axis %d detail "
			 "%g",
			 dmc_h_var(h, "fcode"), dmc_h_var(h, "faxis"),
			 dmc_h_var(h, "fdet"), code, axis, det);
	assert_true(dmc_h_var(h, "state") == 2);
	assert_int_equal(dmc_h_fault_lines(h, &c, &a, &d), 1);
	assert_int_equal(c, code);
	assert_int_equal(a, axis);
	assert_true(d == det);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
	assert_true(out_level(h, PWROUT) == 0);
}

/* No program error event and no thread stopped by an error since the last
 * call; returns 1 if @want occurs among the events. */
static int events_check(struct dmc_h *h, const char *want)
{
	assert_int_equal(sim_control(h->sim, "events", events, sizeof(events)),
			 0);
	if (strstr(events, "program error"))
		fail_msg("program error event:\n%s", events);
	return want && strstr(events, want) != NULL;
}

/* ---- entering the service state ------------------------------------------ */

/*
 * svcreq=1 in the safe state: state 3 (after the whole parameter check,
 * which no header bounds: within the supervisor's deadline of 1 s), svcreq
 * back to 0, every motor on, one "SERVICE" line, no FAULT line, the
 * motor-power output closed (SB pwrout, read as @OUT[pwrout] and in _OP0)
 * and open before; AC = DC = acfact * svmax (#GOON(1)); thread 1 does not
 * run (no jogging in service).
 */
static void test_enter(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double t;

	params_service(&p);
	p.svmax[0] = 20000; /* AC differs from the armed value 10 * vmax */
	DMC_H_CHECK(h, open_configured(h, &p));
	assert_true(out_level(h, PWROUT) == 0);
	assert_true(mg(h, "_OP0") == 0);
	h->hb_on = 1;
	h->hb_next_ms = dmc_h_now(h);
	dmc_h_advance(h, 1);
	DMC_H_CHECK(h, dmc_h_set(h, "svcreq", 1));
	t = dmc_h_wait_var(h, "state", 3, 100);
	print_message("measured: svcreq -> state 3 in %.0f ms\n", t);
	/* the supervisor's deadline: ARM_WAIT_MS in pc/start/re_ctl.c */
	assert_true(t >= 0 && t <= 1000);
	dmc_h_advance(h, 5);
	assert_true(dmc_h_var(h, "svcreq") == 0);
	assert_true(dmc_h_unsol_has(h, "SERVICE"));
	assert_false(dmc_h_unsol_has(h, "ARMED"));
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
	for (int i = 0; i < DMC_H_AXES; i++) {
		assert_int_equal(dmc_h_axis(h, i).motor_off, 0);
		assert_int_equal(dmc_h_axis(h, i).moving, 0);
	}
	assert_true(out_level(h, PWROUT) == 1);
	assert_true(mg(h, "_OP0") == 1 << (PWROUT - 1));
	/* AC and DC are stored in steps of 1024 counts/s^2, rounded down */
	assert_true(fabs(mg(h, "_ACA") - 10 * 20000) < 1024);
	assert_true(fabs(mg(h, "_DCA") - 10 * 20000) < 1024);
	assert_true(fabs(mg(h, "_ACB") - 10 * p.svmax[1]) < 1024);
	assert_int_equal(ctrl_threads(h->ctrl), 1u);
	/* and it stays so: the heartbeat keeps it alive */
	dmc_h_advance(h, 1000);
	assert_true(dmc_h_var(h, "state") == 3);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* Without a power output (pwrout 0) service closes no output at all. */
static void test_enter_no_output(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;

	dmc_h_params_default(&p);
	assert_true(p.pwrout == 0);
	DMC_H_CHECK(h, open_configured(h, &p));
	DMC_H_CHECK(h, dmc_h_service(h));
	dmc_h_advance(h, 20);
	assert_true(mg(h, "_OP0") == 0);
	assert_int_equal(dmc_h_axis(h, 0).motor_off, 0);
}

/* ---- moves --------------------------------------------------------------- */

/*
 * A move request taken: mvreq back to 0 within one main loop, mvn + 1,
 * mvrej 0, the axis owned while it moves. The profiler cruises at exactly
 * the requested speed (an even number: SP's resolution is 2), the encoder
 * follows at it within 2 counts/s (whole counts at both ends of a 1 s
 * window), the profile ends at d/v + v/AC (a trapezoid with AC = DC, the
 * controller's AC read back) within 3 ms (start and end seen at 1 ms
 * steps, and the profiler's last sample jumps onto the target), the
 * encoder settles within 1 count of the target, and the ownership is
 * released within one main loop (+1 sample) of the profile's end. The
 * other axes do not move.
 */
static void test_move_taken(void **state)
{
	struct dmc_h *h = *state;
	const double target = 30000, speed = 6000;
	double mainms = dmc_h_var(h, "mainms"), ac = mg(h, "_ACA");
	double p0[DMC_H_AXES], t_start = -1, t_end = -1, t_rel = -1, t0, e0;
	double mvn0 = dmc_h_var(h, "mvn"), t_exp;

	for (int i = 0; i < DMC_H_AXES; i++)
		p0[i] = dmc_h_axis(h, i).enc;
	t0 = dmc_h_now(h);
	request(h, 0, target, speed, 10000);
	while (dmc_h_var(h, "mvreq") != 0 && dmc_h_now(h) - t0 <= mainms + 1) {
		dmc_h_advance(h, 1);
		if (t_start < 0 && dmc_h_axis(h, 0).moving)
			t_start = dmc_h_now(h);
	}
	print_message("measured: mvreq taken in %.0f ms\n", dmc_h_now(h) - t0);
	assert_true(dmc_h_var(h, "mvreq") == 0);
	assert_true(dmc_h_var(h, "mvn") == mvn0 + 1);
	assert_true(dmc_h_var(h, "mvrej") == 0);
	assert_true(dmc_h_var(h, "own[0]") == 1);
	/* cruise: the middle of the move */
	dmc_h_advance(h, 2000);
	assert_true(dmc_h_axis(h, 0).vel == speed);
	e0 = dmc_h_axis(h, 0).enc;
	dmc_h_advance(h, 1000);
	assert_true(dmc_h_axis(h, 0).vel == speed);
	assert_true(fabs(dmc_h_axis(h, 0).enc - e0 - speed) <= 2);
	while (dmc_h_now(h) - t0 < 10000 && t_rel < 0) {
		if (t_start < 0 && dmc_h_axis(h, 0).moving)
			t_start = dmc_h_now(h);
		if (t_end < 0 && !dmc_h_axis(h, 0).moving)
			t_end = dmc_h_now(h);
		if (t_end >= 0 && dmc_h_var(h, "own[0]") == 0)
			t_rel = dmc_h_now(h);
		if (t_rel < 0)
			dmc_h_advance(h, 1);
	}
	t_exp = (target - p0[0]) / speed + speed / ac;
	print_message("measured: profile %.0f ms (expected %.1f), own "
		      "released %.0f ms after its end\n",
		      t_end - t_start, t_exp * 1000, t_rel - t_end);
	assert_true(t_start >= 0 && t_end > t_start && t_rel >= t_end);
	assert_true(fabs((t_end - t_start) - t_exp * 1000) <= 3);
	assert_true(t_rel - t_end <= mainms + 1);
	dmc_h_advance(h, 50);
	assert_true(fabs(dmc_h_axis(h, 0).enc - target) <= 1);
	assert_true(fabs(dmc_h_axis(h, 1).enc - p0[1]) < 1);
	assert_true(fabs(dmc_h_axis(h, 2).enc - p0[2]) < 1);
	assert_true(dmc_h_var(h, "state") == 3);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
	/* the speed limit of a released axis is vstill again after tvwin:
	 * standing still it holds without a fault */
	dmc_h_advance(h, dmc_h_var(h, "tvwin") + 100);
	assert_true(dmc_h_var(h, "state") == 3);
}

/* One request for two axes: both start in the same pass (mvn + 1 once),
 * both reach their targets, both are released. */
static void test_move_two_axes(void **state)
{
	struct dmc_h *h = *state;
	double mvn0 = dmc_h_var(h, "mvn");

	DMC_H_CHECK(h, set_i(h, "mvax", 0, 0));
	DMC_H_CHECK(h, set_i(h, "mvax", 1, 1));
	DMC_H_CHECK(h, set_i(h, "mvax", 2, 1));
	DMC_H_CHECK(h, set_i(h, "mvtg", 1, -8000));
	DMC_H_CHECK(h, set_i(h, "mvsp", 1, 4000));
	DMC_H_CHECK(h, set_i(h, "mvtg", 2, 5000));
	DMC_H_CHECK(h, set_i(h, "mvsp", 2, 8000));
	DMC_H_CHECK(h, dmc_h_set(h, "mvto", 5000));
	DMC_H_CHECK(h, dmc_h_set(h, "mvreq", 1));
	assert_true(dmc_h_wait_var(h, "mvreq", 0, 11) >= 0);
	dmc_h_advance(h, 1);
	assert_true(dmc_h_axis(h, 1).moving && dmc_h_axis(h, 2).moving);
	assert_int_equal(dmc_h_axis(h, 0).moving, 0);
	assert_true(dmc_h_var(h, "mvn") == mvn0 + 1);
	wait_move_done(h, 1, 4000);
	wait_move_done(h, 2, 4000);
	assert_true(fabs(dmc_h_axis(h, 1).enc + 8000) <= 1);
	assert_true(fabs(dmc_h_axis(h, 2).enc - 5000) <= 1);
	assert_true(dmc_h_var(h, "state") == 3);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* ---- refusals (fault 15, detail 1..5) ------------------------------------ */

/*
 * Write the request and advance until the program latched (at most two
 * main loops), checking at every sample that no profiler runs on an axis
 * that was at rest. Return: ms from the request to the latch.
 */
static double refused_request(struct dmc_h *h, int ax, double target,
			      double speed, double mvto, unsigned at_rest)
{
	double t0 = dmc_h_now(h), mainms = dmc_h_var(h, "mainms");

	request(h, ax, target, speed, mvto);
	while (dmc_h_var(h, "state") != 2) {
		if (dmc_h_now(h) - t0 > 2 * mainms)
			fail_msg("request not refused (state %g, mvreq %g)",
				 dmc_h_var(h, "state"), dmc_h_var(h, "mvreq"));
		dmc_h_advance(h, 1);
		for (int i = 0; i < DMC_H_AXES; i++)
			if ((at_rest >> i & 1) && dmc_h_axis(h, i).moving)
				fail_msg("axis %d moves after a refused "
					 "request",
					 i);
	}
	return dmc_h_now(h) - t0;
}

struct rcase {
	const char *what;
	int axis;
	double dist, speed, mvto; /* target = position + dist */
	int detail;		  /* 0: accepted */
};

/* Each bound, just outside (refused) and on it (accepted); the defaults:
 * svmax 10000/10000/8000, svdmax 20000 here, svtmax 120000 ms. */
static const struct rcase rcases[] = {
    {"speed above svmax", 1, 5000, 10002, 5000, 2},
    {"speed = svmax", 1, 5000, 10000, 5000, 0},
    {"speed 0", 2, 5000, 0, 5000, 2},
    {"speed negative", 0, 5000, -2000, 5000, 2},
    {"distance above svdmax", 0, 20001, 5000, 8000, 3},
    {"distance above svdmax, reverse", 2, -20001, 5000, 8000, 3},
    {"distance = svdmax", 0, 20000, 8000, 8000, 0},
    {"mvto 0", 1, 1000, 5000, 0, 4},
    {"mvto negative", 1, 1000, 5000, -100, 4},
    {"mvto above svtmax", 2, 1000, 5000, 120001, 4},
    {"mvto = svtmax", 2, 1000, 5000, 120000, 0},
};

/*
 * Detail 2 (0 < speed <= svmax), 3 (|target - position| <= svdmax) and 4
 * (0 < mvto <= svtmax): outside a bound the request latches fault 15 with
 * that axis and detail (also in mvrej) within one main loop (+1 sample),
 * mvreq is back to 0, mvn unchanged, nothing moves, the power output is
 * opened; on the bound it is taken.
 */
static void test_refuse_bounds(void **state)
{
	(void)state;
	for (size_t k = 0; k < sizeof(rcases) / sizeof(rcases[0]); k++) {
		static struct dmc_h h;
		const struct rcase *c = &rcases[k];
		struct dmc_h_params p;
		double t, mvn0, pos;

		params_service(&p);
		for (int i = 0; i < DMC_H_AXES; i++)
			p.svdmax[i] = 20000;
		if (open_configured(&h, &p) < 0 || dmc_h_service(&h) < 0)
			fail_msg("%s: set-up: %s", c->what, h.err);
		mvn0 = dmc_h_var(&h, "mvn");
		pos = dmc_h_axis(&h, c->axis).enc;
		if (c->detail == 0) {
			if (dmc_h_move(&h, c->axis, pos + c->dist, c->speed,
				       c->mvto) < 0)
				fail_msg("%s: %s", c->what, h.err);
			assert_true(dmc_h_var(&h, "mvn") == mvn0 + 1);
			dmc_h_advance(&h, 1);
			assert_true(dmc_h_axis(&h, c->axis).moving);
			dmc_h_close(&h);
			continue;
		}
		t = refused_request(&h, c->axis, pos + c->dist, c->speed,
				    c->mvto, 7);
		print_message("measured: %s refused in %.0f ms\n", c->what, t);
		assert_true(t <= dmc_h_var(&h, "mainms") + 1);
		assert_latched(&h, 15, c->axis + 1, c->detail);
		assert_true(dmc_h_var(&h, "mvrej") == c->detail);
		assert_true(dmc_h_var(&h, "mvreq") == 0);
		assert_true(dmc_h_var(&h, "mvn") == mvn0);
		assert_true(fabs(dmc_h_axis(&h, c->axis).enc - pos) < 1);
		dmc_h_close(&h);
	}
}

/* A request for two axes with one bad (B above svmax): every requested
 * axis is checked before any starts, so A (valid) never moves either. */
static void test_refuse_one_of_two(void **state)
{
	struct dmc_h *h = *state;
	double mainms = dmc_h_var(h, "mainms"), t0;

	DMC_H_CHECK(h, set_i(h, "mvax", 0, 1));
	DMC_H_CHECK(h, set_i(h, "mvax", 1, 1));
	DMC_H_CHECK(h, set_i(h, "mvax", 2, 0));
	DMC_H_CHECK(h, set_i(h, "mvtg", 0, 5000));
	DMC_H_CHECK(h, set_i(h, "mvsp", 0, 5000));
	DMC_H_CHECK(h, set_i(h, "mvtg", 1, 5000));
	DMC_H_CHECK(h, set_i(h, "mvsp", 1, var_i(h, "svmax", 1) + 2));
	DMC_H_CHECK(h, dmc_h_set(h, "mvto", 5000));
	t0 = dmc_h_now(h);
	DMC_H_CHECK(h, dmc_h_set(h, "mvreq", 1));
	while (dmc_h_var(h, "state") != 2 && dmc_h_now(h) - t0 <= mainms + 1) {
		dmc_h_advance(h, 1);
		assert_int_equal(dmc_h_axis(h, 0).moving, 0);
		assert_int_equal(dmc_h_axis(h, 1).moving, 0);
	}
	assert_latched(h, 15, 2, 2);
	assert_true(fabs(dmc_h_axis(h, 0).enc) < 1);
}

/* Detail 1: a request for an axis whose profiler still runs (a move in
 * flight) is refused; the moving axis is stopped and switched off, the
 * others never start. */
static void test_refuse_moving(void **state)
{
	struct dmc_h *h = *state;
	double t, mvn0;

	DMC_H_CHECK(h, dmc_h_move(h, 2, 20000, 5000, 10000));
	dmc_h_advance(h, 500);
	assert_true(dmc_h_axis(h, 2).moving);
	mvn0 = dmc_h_var(h, "mvn");
	t = refused_request(h, 2, -5000, 2000, 10000, 3);
	print_message("measured: request on a moving axis refused in %.0f "
		      "ms\n",
		      t);
	assert_true(t <= dmc_h_var(h, "mainms") + 1);
	assert_latched(h, 15, 3, 1);
	assert_true(dmc_h_var(h, "mvrej") == 1);
	assert_true(dmc_h_var(h, "mvn") == mvn0);
	dmc_h_advance(h, 100);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).moving, 0);
}

/*
 * Detail 5: near a limit switch (potentiometer below pnlo) only slow moves
 * toward it. A fast move to just outside the zone and a slow one into it
 * (every bound respected: no fault); there a slow request toward the
 * switch and a fast one away from it are taken; a fast one toward it
 * latches fault 15 detail 5 and nothing moves.
 */
static void test_refuse_near_switch(void **state)
{
	struct dmc_h *h = *state;
	double pnlo = dmc_h_var(h, "pnlo[0]"),
	       svslow = dmc_h_var(h, "svslow[0]");
	double svmax = dmc_h_var(h, "svmax[0]"), t;

	/* the pot reads 1.12 V at -35000 and 0.83 V at -42000 (0.5 V at the
	 * switch, -50000; docs/galil-sim.md) */
	move_to(h, 0, -35000, svmax);
	assert_true(mg(h, "@AN[1]") > pnlo + 0.1);
	move_to(h, 0, -42000, svslow);
	assert_true(mg(h, "@AN[1]") < pnlo - 0.1);
	move_to(h, 0, -42500, svslow); /* slow toward: taken */
	move_to(h, 0, -42000, svmax);  /* fast away: taken */
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
	t = refused_request(h, 0, -44000, svmax, 10000, 7);
	print_message("measured: fast toward a near switch refused in %.0f "
		      "ms\n",
		      t);
	assert_true(t <= dmc_h_var(h, "mainms") + 1);
	assert_latched(h, 15, 1, 5);
	assert_true(dmc_h_var(h, "mvrej") == 5);
	assert_true(fabs(dmc_h_axis(h, 0).enc + 42000) <= 1);
}

/* ---- supervision of a move in flight (detail 6, 7) ----------------------- */

/*
 * Detail 6: a slow long move (20000 counts at 2000 counts/s, 10 s) with a
 * time limit of 1000 ms. #MVSUP checks TIME - mvt0 > mvto every main loop,
 * so the fault comes after mvto and within mvto + mainms + 1 of the start;
 * the axis stops and goes off.
 */
static void test_time_limit(void **state)
{
	struct dmc_h *h = *state;
	double mainms = dmc_h_var(h, "mainms"), t0, t;

	DMC_H_CHECK(h, dmc_h_move(h, 1, 20000, 2000, 1000));
	/* the start as the program took it (mvt0, in TIME) */
	t0 = dmc_h_var(h, "mvt0[1]") - (mg(h, "TIME") - dmc_h_now(h));
	assert_true(dmc_h_axis(h, 1).moving);
	t = dmc_h_wait_var(h, "state", 2, 1000 + 3 * mainms);
	assert_true(t >= 0);
	t = dmc_h_now(h) - t0;
	print_message("measured: time limit 1000 ms -> fault after %.0f ms\n",
		      t);
	assert_true(t > 1000 && t <= 1000 + mainms + 1);
	assert_latched(h, 15, 2, 6);
	dmc_h_advance(h, 50);
	assert_int_equal(dmc_h_axis(h, 1).moving, 0);
}

/*
 * Detail 7: a fast request from outside the near zone (the pot reads about
 * 2.55 V at 0) with its target deep inside it (44000 counts from the
 * centre: 0.75 V toward the reverse switch, 4.27 V toward the forward one)
 * is taken, and latched as fault 15 detail 7 after the first sample in
 * which the potentiometer reads past pnlo (moving in reverse) or pnhi
 * (forward; noise off, so the crossing is one instant) within one main
 * loop plus the part of a pass from #GUARD's @AN read to #MVSUP's latch
 * (about 60 program lines: at most 4 samples at galil-sim's 16 lines per
 * sample). The axis stops short of its target.
 */
static void fast_into_zone(struct dmc_h *h, int ax, int dir)
{
	double mainms = dmc_h_var(h, "mainms"), t_zone = -1, t_f, t0, zone;
	char req[32], an[16];

	zone = var_i(h, dir < 0 ? "pnlo" : "pnhi", ax);
	snprintf(req, sizeof(req), "pot %c noise 0", 'A' + ax);
	snprintf(an, sizeof(an), "@AN[%d]", (int)var_i(h, "potin", ax));
	DMC_H_CHECK(h, dmc_h_control(h, req));
	DMC_H_CHECK(
	    h, dmc_h_move(h, ax, dir * 44000, var_i(h, "svmax", ax), 20000));
	t0 = dmc_h_now(h);
	while (dmc_h_var(h, "state") == 3 && dmc_h_now(h) - t0 < 6000) {
		dmc_h_advance(h, 1);
		if (t_zone < 0 && (mg(h, an) - zone) * dir > 0)
			t_zone = dmc_h_now(h);
	}
	t_f = dmc_h_now(h);
	assert_true(t_zone > 0);
	print_message("measured: fast move in the near zone (axis %c) latched "
		      "%.0f ms after the pot crossed %.1f V (at %.0f counts)\n",
		      'A' + ax, t_f - t_zone, zone, dmc_h_axis(h, ax).enc);
	assert_true(t_f - t_zone <= mainms + 4);
	assert_latched(h, 15, ax + 1, 7);
	dmc_h_advance(h, 100);
	assert_int_equal(dmc_h_axis(h, ax).moving, 0);
	assert_true(dmc_h_axis(h, ax).enc * dir < 40000);
}

/* Detail 7 toward the reverse switch (A, below pnlo). */
static void test_fast_into_zone_rev(void **state)
{
	fast_into_zone(*state, 0, -1);
}

/* Detail 7 toward the forward switch (B, above pnhi). */
static void test_fast_into_zone_fwd(void **state)
{
	fast_into_zone(*state, 1, 1);
}

/*
 * A move keeps the bounds it was started with: after a fast move toward
 * the reverse switch has started, the supervisor prepares its next
 * request and writes mvsp[0] (the slow speed) without requesting it. The
 * move in flight is still fast (its SP did not change), so entering the
 * near zone is still fault 15 detail 7, as without the write. (#MVGO
 * copies mvto to mvtl and the direction to mvdir for the same reason.)
 */
static void test_fast_into_zone_mvsp_rewritten(void **state)
{
	struct dmc_h *h = *state;
	double svmax = dmc_h_var(h, "svmax[0]");
	double t0;

	DMC_H_CHECK(h, dmc_h_control(h, "pot A noise 0"));
	DMC_H_CHECK(h, dmc_h_move(h, 0, -44000, svmax, 20000));
	dmc_h_advance(h, 500);
	DMC_H_CHECK(h, set_i(h, "mvsp", 0, dmc_h_var(h, "svslow[0]")));
	t0 = dmc_h_now(h);
	while (dmc_h_var(h, "state") == 3 && dmc_h_axis(h, 0).moving &&
	       dmc_h_now(h) - t0 < 6000)
		dmc_h_advance(h, 1);
	/* #FAULT stops the axis (AB 1) a few lines before it sets state 2 */
	dmc_h_wait_var(h, "state", 2, dmc_h_var(h, "mainms"));
	if (dmc_h_var(h, "state") != 2)
		fail_msg("fast move ran into the near zone without a fault: "
			 "stopped at %.0f counts (pot %.3f V), state %g",
			 dmc_h_axis(h, 0).enc, mg(h, "@AN[1]"),
			 dmc_h_var(h, "state"));
	assert_latched(h, 15, 1, 7);
	assert_true(dmc_h_axis(h, 0).enc > -40000);
}

/* ---- heartbeat and joystick in service ----------------------------------- */

/*
 * The heartbeat stops in service: nothing happens before wdto - mainms;
 * the motors are off within wdto + mainms + 1 of the last change (#HBCHK);
 * fault 2, fdet = ms since the change was seen; the power output opens.
 */
static void test_heartbeat_stopped(void **state)
{
	struct dmc_h *h = *state;
	double wdto = dmc_h_var(h, "wdto"), mainms = dmc_h_var(h, "mainms");
	double t_last, t_off;

	DMC_H_CHECK(h, dmc_h_move(h, 0, 30000, 5000, 10000));
	dmc_h_advance(h, 500);
	/* the next advance writes hbpc at its start: the last change */
	while (dmc_h_now(h) < h->hb_next_ms - 1e-9)
		dmc_h_advance(h, 1);
	t_last = dmc_h_now(h);
	dmc_h_advance(h, 1);
	h->hb_on = 0;
	dmc_h_advance(h, wdto - mainms - 1);
	assert_true(dmc_h_var(h, "state") == 3);
	assert_true(dmc_h_axis(h, 0).moving);
	assert_true(dmc_h_wait_motor_off(h, 7, 3 * mainms) >= 0);
	t_off = dmc_h_now(h) - t_last;
	print_message("measured: heartbeat stopped -> motors off %.0f ms after "
		      "the last change (wdto %.0f)\n",
		      t_off, wdto);
	/* #FAULT switches off first and sets fcode a few lines later */
	assert_true(dmc_h_wait_var(h, "state", 2, 3) >= 0);
	assert_true(t_off > wdto - mainms && t_off <= wdto + mainms + 1);
	assert_true(dmc_h_var(h, "fdet") > wdto - mainms);
	assert_true(dmc_h_var(h, "fdet") <= wdto + mainms);
	assert_latched(h, 2, 0, dmc_h_var(h, "fdet"));
}

/* A heartbeat slower than the supervisor's, but every wdto - mainms - 5
 * ms, never trips (3 s, with a move running). */
static void test_heartbeat_slow_ok(void **state)
{
	struct dmc_h *h = *state;

	h->hb_period_ms = dmc_h_var(h, "wdto") - dmc_h_var(h, "mainms") - 5;
	DMC_H_CHECK(h, dmc_h_move(h, 2, -10000, 4000, 10000));
	dmc_h_advance(h, 3000);
	assert_true(dmc_h_var(h, "state") == 3);
	assert_int_equal(dmc_h_axis(h, 2).motor_off, 0);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/*
 * An invalid joystick state (one channel of A fwd) held in service: fault
 * 3, fdet = the switch word (1), no earlier than jto and within jto + 2 *
 * mainms + 1 (thread 0 reads the switches every mainms in service: first
 * sight within mainms, then the first read more than jto later).
 */
static void test_joy_invalid(void **state)
{
	struct dmc_h *h = *state;
	double jto = dmc_h_var(h, "jto"), mainms = dmc_h_var(h, "mainms"), t;

	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd a"));
	t = dmc_h_wait_var(h, "state", 2, jto + 5 * mainms);
	print_message("measured: invalid joystick in service -> fault 3 "
		      "after %.0f ms (jto %.0f)\n",
		      t, jto);
	assert_true(t > jto && t <= jto + 2 * mainms + 1);
	assert_latched(h, 3, 0, 1);
}

/* A valid command in service is decoded (jcmd, jraw) but moves nothing;
 * no fault. */
static void test_joy_valid_no_motion(void **state)
{
	struct dmc_h *h = *state;
	double p0[DMC_H_AXES];

	for (int i = 0; i < DMC_H_AXES; i++)
		p0[i] = dmc_h_axis(h, i).enc;
	DMC_H_CHECK(h, dmc_h_control(h, "joy B rev"));
	dmc_h_advance(h, 1000);
	assert_true(dmc_h_var(h, "jcmd") == 4);
	assert_true(dmc_h_var(h, "jraw") == 192);
	for (int i = 0; i < DMC_H_AXES; i++) {
		assert_int_equal(dmc_h_axis(h, i).moving, 0);
		assert_true(fabs(dmc_h_axis(h, i).enc - p0[i]) < 1);
	}
	assert_true(dmc_h_var(h, "state") == 3);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* ---- #OFF ---------------------------------------------------------------- */

/*
 * offreq=1 in service: within one main loop (+1) state 0, offreq 0, every
 * motor off, the power output open, "OFF" and no FAULT line. Then a host's
 * SH (nothing in state 0 switches a motor on) is fault 13 detail 3 within
 * one main loop (+1).
 */
static void test_off(void **state)
{
	struct dmc_h *h = *state;
	double mainms = dmc_h_var(h, "mainms"), t;

	assert_true(out_level(h, PWROUT) == 1);
	DMC_H_CHECK(h, dmc_h_set(h, "offreq", 1));
	t = dmc_h_wait_var(h, "state", 0, 3 * mainms);
	print_message("measured: offreq -> state 0 in %.0f ms\n", t);
	assert_true(t >= 0 && t <= mainms + 1);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
	assert_true(out_level(h, PWROUT) == 0);
	dmc_h_advance(h, 5);
	assert_true(dmc_h_var(h, "offreq") == 0);
	assert_true(dmc_h_unsol_has(h, "OFF"));
	h->hb_on = 0; /* the supervisor's cycle stops: not needed in state 0 */
	dmc_h_advance(h, 500);
	assert_true(dmc_h_var(h, "state") == 0);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);

	DMC_H_CHECK(h, dmc_h_cmd(h, "SH A", NULL, 0));
	assert_int_equal(dmc_h_axis(h, 0).motor_off, 0);
	t = dmc_h_wait_var(h, "state", 2, 3 * mainms);
	print_message("measured: SH in state 0 -> fault 13 in %.0f ms\n", t);
	assert_true(t >= 0 && t <= mainms + 1);
	assert_latched(h, 13, 0, 3);
}

/* offreq=1 while a service move runs: the move ends at once (AB 1, MO),
 * nothing is owned any more, state 0, no fault. */
static void test_off_during_move(void **state)
{
	struct dmc_h *h = *state;
	double mainms = dmc_h_var(h, "mainms"), t;

	DMC_H_CHECK(h, dmc_h_move(h, 1, 30000, 8000, 10000));
	dmc_h_advance(h, 1000);
	DMC_H_CHECK(h, dmc_h_set(h, "offreq", 1));
	t = dmc_h_wait_motor_off(h, 7, 3 * mainms);
	assert_true(t >= 0 && t <= mainms + 1);
	dmc_h_advance(h, 5);
	assert_true(dmc_h_var(h, "state") == 0);
	assert_int_equal(dmc_h_axis(h, 1).moving, 0);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_true(var_i(h, "own", i) == 0);
	assert_true(out_level(h, PWROUT) == 0);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* ---- arming from service ------------------------------------------------- */

/*
 * armreq=1 in service arms (#SVC -> #ARM): state 1, "ARMED", thread 1
 * running, AC back to acfact * vmax (svmax differed), the power output
 * still closed, and the joystick jogs.
 */
static void test_arm_from_service(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double a0;

	params_service(&p);
	p.svmax[0] = 20000;
	DMC_H_CHECK(h, open_configured(h, &p));
	DMC_H_CHECK(h, dmc_h_service(h));
	assert_true(fabs(mg(h, "_ACA") - 200000) < 1024);
	DMC_H_CHECK(h, dmc_h_arm(h));
	assert_true(dmc_h_unsol_has(h, "ARMED"));
	assert_int_equal(ctrl_threads(h->ctrl) & 3u, 3u);
	assert_true(fabs(mg(h, "_ACA") - 10 * p.vmax[0]) < 1024);
	assert_true(out_level(h, PWROUT) == 1);
	a0 = dmc_h_axis(h, 0).enc;
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 500);
	assert_true(dmc_h_axis(h, 0).enc - a0 > 500);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/*
 * Arming from service right after a fast service move (svmax 3 * vmax, as
 * calibration moves may be): TV, a 256-sample average, still remembers the
 * service speed for a while, so "at rest" for the arm check 17 includes
 * TV below vstill. Right after the move the arm is refused (fault 1,
 * check 17) instead of arming and then seeing a speed its limit does not
 * allow; once TV has decayed (within tvwin), arming succeeds and holds
 * with no false fault 13. The supervisor waits for TV itself before it
 * asks (re_ctl_arm).
 */
static void test_arm_after_fast_move(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double t0, vstill, tvwin;

	params_service(&p);
	p.svmax[0] = 3 * p.vmax[0];
	DMC_H_CHECK(h, open_configured(h, &p));
	DMC_H_CHECK(h, dmc_h_service(h));
	DMC_H_CHECK(h, dmc_h_move(h, 0, 20000, p.svmax[0], 5000));
	wait_move_done(h, 0, 2000);
	vstill = dmc_h_var(h, "vstill");
	tvwin = dmc_h_var(h, "tvwin");
	print_message("measured: TV at the end of the move %.0f counts/s "
		      "(vstill %.0f)\n",
		      mg(h, "_TVA"), vstill);
	assert_true(mg(h, "_TVA") > vstill);
	assert_int_equal(dmc_h_arm(h), GL_ERR_CTRL);
	assert_true(dmc_h_var(h, "fcode") == 1);
	assert_true(dmc_h_var(h, "fdet") == 17);

	/* again, this time waiting for TV as the supervisor does */
	dmc_h_close(h);
	DMC_H_CHECK(h, open_configured(h, &p));
	DMC_H_CHECK(h, dmc_h_service(h));
	DMC_H_CHECK(h, dmc_h_move(h, 0, 20000, p.svmax[0], 5000));
	wait_move_done(h, 0, 2000);
	t0 = dmc_h_now(h);
	while (mg(h, "_TVA") > vstill && dmc_h_now(h) - t0 < tvwin)
		dmc_h_advance(h, 1);
	print_message("measured: TV below vstill %.0f ms after the move\n",
		      dmc_h_now(h) - t0);
	assert_true(dmc_h_now(h) - t0 < tvwin);
	DMC_H_CHECK(h, dmc_h_arm(h));
	dmc_h_advance(h, 500);
	if (dmc_h_var(h, "state") != 1)
		fail_msg("armed after a fast service move, then fault %g axis "
			 "%g detail %g with every axis at rest",
			 dmc_h_var(h, "fcode"), dmc_h_var(h, "faxis"),
			 dmc_h_var(h, "fdet"));
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* armreq=1 while a service move runs: refused with fault 1, check 17 (no
 * profiler may run when arming), axis 0; everything stops and goes off. */
static void test_arm_refused_moving(void **state)
{
	struct dmc_h *h = *state;
	double t;

	DMC_H_CHECK(h, dmc_h_move(h, 0, 20000, 5000, 10000));
	dmc_h_advance(h, 300);
	DMC_H_CHECK(h, dmc_h_set(h, "armreq", 1));
	t = dmc_h_wait_var(h, "state", 2, 1000);
	/* check 17 comes after every other check of #PCHK: the refusal
	 * takes the whole check (no header bounds it; the supervisor's
	 * deadline is 1 s), the move runs on meanwhile */
	print_message("measured: arm request during a move -> fault 1 "
		      "check 17 in %.0f ms\n",
		      t);
	assert_true(t >= 0 && t <= 1000);
	assert_latched(h, 1, 0, 17);
	assert_true(dmc_h_var(h, "armreq") == 0);
	dmc_h_advance(h, 100);
	assert_int_equal(dmc_h_axis(h, 0).moving, 0);
	assert_int_equal(ctrl_threads(h->ctrl) & 2u, 0u);
}

/* ---- the program halted on purpose --------------------------------------- */

/*
 * prun=0 and HX (as galil-load and the supervisor do before they halt the
 * program) with the motors on in service and the power output closed;
 * then a host's move of a jammed axis B: the position error passes ER, OE
 * switches B off and #POSERR runs in thread 0. With prun=0 it only stops,
 * switches every motor off, opens the power output and ends: no fault
 * latched (fcode 0, state untouched), no FAULT line, no program error
 * event, and no thread left running.
 */
static void test_halted_poserr(void **state)
{
	struct dmc_h *h = *state;

	assert_true(out_level(h, PWROUT) == 1);
	DMC_H_CHECK(h, dmc_h_set(h, "prun", 0));
	DMC_H_CHECK(h, dmc_h_cmd(h, "HX", NULL, 0));
	h->hb_on = 0;
	dmc_h_advance(h, 5);
	assert_int_equal(ctrl_threads(h->ctrl), 0u);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 0);
	events_check(h, NULL);
	DMC_H_CHECK(h, dmc_h_control(h, "block B 1"));
	DMC_H_CHECK(h, dmc_h_cmd(h, "PR ,5000", NULL, 0));
	DMC_H_CHECK(h, dmc_h_cmd(h, "BG B", NULL, 0));
	assert_true(dmc_h_wait_motor_off(h, 2, 500) >= 0);
	dmc_h_advance(h, 20);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
	assert_int_equal(dmc_h_axis(h, 1).stop_code, 8);
	assert_true(out_level(h, PWROUT) == 0);
	assert_true(dmc_h_var(h, "fcode") == 0);
	assert_true(dmc_h_var(h, "state") == 3);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
	assert_false(dmc_h_unsol_has(h, "FAULT"));
	assert_true(events_check(h, "#POSERR running in thread 0"));
	assert_int_equal(ctrl_threads(h->ctrl), 0u);
}

/*
 * prun=0 and HX in service, then motor power lost (relay off): #AMPERR
 * runs in thread 0 and, halted, only stops, switches the motors off, opens
 * the power output and ends: no fault, no count (namp), no FAULT line, no
 * program error event, no thread left running.
 */
static void test_halted_amperr(void **state)
{
	struct dmc_h *h = *state;
	double namp = dmc_h_var(h, "namp");

	DMC_H_CHECK(h, dmc_h_set(h, "prun", 0));
	DMC_H_CHECK(h, dmc_h_cmd(h, "HX", NULL, 0));
	h->hb_on = 0;
	dmc_h_advance(h, 5);
	events_check(h, NULL);
	DMC_H_CHECK(h, dmc_h_control(h, "relay off"));
	assert_true(dmc_h_wait_motor_off(h, 7, 50) >= 0);
	dmc_h_advance(h, 20);
	assert_true(out_level(h, PWROUT) == 0);
	assert_true(dmc_h_var(h, "fcode") == 0);
	assert_true(dmc_h_var(h, "namp") == namp);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
	assert_true(events_check(h, "#AMPERR running in thread 0"));
	assert_int_equal(ctrl_threads(h->ctrl), 0u);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_enter, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_enter_no_output, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_move_taken, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_move_two_axes, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test(test_refuse_bounds),
	    cmocka_unit_test_setup_teardown(test_refuse_one_of_two, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_refuse_moving, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_refuse_near_switch, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_time_limit, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_fast_into_zone_rev, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_fast_into_zone_fwd, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_fast_into_zone_mvsp_rewritten,
					    fx_service, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_heartbeat_stopped, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_heartbeat_slow_ok, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_joy_invalid, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_joy_valid_no_motion,
					    fx_service, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_off, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_off_during_move, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_arm_from_service, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_arm_after_fast_move,
					    dmc_h_fx_new, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_arm_refused_moving, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_halted_poserr, fx_service,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_halted_amperr, fx_service,
					    dmc_h_fx_free),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
