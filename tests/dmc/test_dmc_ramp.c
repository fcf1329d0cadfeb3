/*
 * test_dmc_ramp.c - the motion ramp and incremental position control:
 * from the first sight of a command the axis runs at
 * vmin until wst, accelerates linearly to vmax at wen, then holds vmax;
 * one axis at a time; reversing goes through a stop and restarts the ramp;
 * targets never pass the soft limits.
 *
 * Formula: v(u) = vmin for u < wst; vmin + (vmax - vmin) (u - wst) /
 * (wen - wst) for wst <= u < wen; vmax after; u = ms since the first
 * sight (dmc_h_ramp_vel()).
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

static double mg(struct dmc_h *h, const char *what)
{
	char cmd[32], resp[64];

	snprintf(cmd, sizeof(cmd), "MG %s", what);
	if (dmc_h_cmd(h, cmd, resp, sizeof(resp)) < 0)
		fail_msg("%s", h->err);
	return atof(resp);
}

/* Sim time of the program's first sight of the current command. */
static double first_sight(struct dmc_h *h)
{
	double time_offset = dmc_h_now(h) - mg(h, "TIME");

	return dmc_h_var(h, "tcmd") + time_offset;
}

/*
 * Press command @k (0..5), sample every ms for 2.6 s: the commanded
 * velocity vcur and SP follow the formula within one motion loop period;
 * the profiler velocity follows it within one period plus the AC
 * transient at the start; the first sight comes within one period.
 */
static void ramp_profile(struct dmc_h *h, int k)
{
	static const char *const name[6] = {"A fwd", "A rev", "B fwd",
					    "B rev", "C fwd", "C rev"};
	struct dmc_h_params p;
	double loopms = dmc_h_var(h, "loopms"), t_press, ts = -1;
	double per = loopms + 1; /* period + one sample of jitter */
	int ax = k / 2, dir = k % 2 ? -1 : 1, samples = 0;
	char req[32], sp[8];

	dmc_h_params_default(&p);
	snprintf(req, sizeof(req), "joy %s", name[k]);
	snprintf(sp, sizeof(sp), "_SP%c", 'A' + ax);
	t_press = dmc_h_now(h);
	DMC_H_CHECK(h, dmc_h_control(h, req));
	while (dmc_h_now(h) - t_press < 2600) {
		double vcur, vel, u, lo, hi;

		dmc_h_advance(h, 1);
		if (dmc_h_var(h, "mcmd") != k + 1)
			continue;
		if (ts < 0) {
			ts = first_sight(h);
			assert_true(ts >= t_press && ts <= t_press + per);
		}
		u = dmc_h_now(h) - ts;
		vcur = dmc_h_var(h, "vcur");
		lo = dmc_h_ramp_vel(&p, ax, u - per) - 0.5;
		hi = dmc_h_ramp_vel(&p, ax, u) + 0.5;
		if (vcur < lo || vcur > hi)
			fail_msg("%s: u=%.0f ms vcur %.1f outside [%.1f, %.1f]",
				 name[k], u, vcur, lo, hi);
		/* SP has a resolution of 2 counts/s (rounded down) */
		if (mg(h, sp) > vcur + 1e-3 || mg(h, sp) <= vcur - 2)
			fail_msg("%s: u=%.0f ms SP %.1f, vcur %.1f", name[k], u,
				 mg(h, sp), vcur);
		vel = dmc_h_axis(h, ax).vel * dir;
		if (u > 50) {
			lo = dmc_h_ramp_vel(&p, ax, u - per - 5) - 1;
			if (vel < lo || vel > hi + 1)
				fail_msg("%s: u=%.0f ms profiler %.1f outside "
					 "[%.1f, %.1f]",
					 name[k], u, vel, lo, hi + 1);
		}
		samples++;
	}
	assert_true(samples > 2400);
	assert_true(fabs(dmc_h_var(h, "vcur") - p.vmax[ax]) < 0.5);
	assert_true(dmc_h_var(h, "lpmax") <= per);
	assert_true(dmc_h_var(h, "state") == 1);
	snprintf(req, sizeof(req), "joy %c neutral", 'A' + ax);
	DMC_H_CHECK(h, dmc_h_control(h, req));
	dmc_h_advance(h, 200);
}

static void test_ramp_a(void **state)
{
	ramp_profile(*state, 0);
	ramp_profile(*state, 1);
}

static void test_ramp_b(void **state)
{
	ramp_profile(*state, 2);
	ramp_profile(*state, 3);
}

static void test_ramp_c(void **state)
{
	ramp_profile(*state, 4);
	ramp_profile(*state, 5);
}

/* Reversing at full speed: the axis stops first (never reversing while
 * still moving forward), then starts backwards with the ramp restarted at
 * vmin, and reaches vmax again only at wen. */
static void test_reverse(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double t_rev, t_stop = -1, t_back = -1, ts;

	dmc_h_params_default(&p);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 2500);
	assert_true(dmc_h_axis(h, 0).vel > 0.99 * p.vmax[0]);
	t_rev = dmc_h_now(h);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A rev"));
	while (dmc_h_now(h) - t_rev < 400) {
		struct ctrl_axis_info ai;

		dmc_h_advance(h, 1);
		ai = dmc_h_axis(h, 0);
		if (t_stop < 0 && ai.vel <= 0) {
			t_stop = dmc_h_now(h);
			assert_int_equal(dmc_h_var(h, "mcmd") != 2, 1);
		}
		if (t_back < 0 && ai.vel < 0) {
			t_back = dmc_h_now(h);
			assert_true(dmc_h_var(h, "mcmd") == 2);
			/* the restarted ramp begins at vmin */
			assert_true(fabs(dmc_h_var(h, "vcur") - p.vmin[0]) <
				    0.5);
		}
	}
	assert_true(t_stop > 0 && t_back >= t_stop);
	/* + 5 samples: thread 1 runs a few lines from its read of the inputs
	 * to its ST (a line takes part of a sample on galil-sim) */
	assert_true(t_stop - t_rev <= dmc_h_var(h, "loopms") + 100 + 5);
	ts = first_sight(h);
	assert_true(ts >= t_rev && ts <= t_rev + dmc_h_var(h, "loopms") + 1);
	/* still in the slow part until wst after the first sight */
	dmc_h_advance(h, ts + p.wst[0] - 20 - dmc_h_now(h));
	assert_true(fabs(dmc_h_var(h, "vcur") - p.vmin[0]) < 0.5);
	dmc_h_advance(h, ts + p.wen[0] + 20 - dmc_h_now(h));
	assert_true(fabs(dmc_h_var(h, "vcur") - p.vmax[0]) < 0.5);
}

/* One axis at a time: switching from A to B stops A first; B starts only
 * after A's profiler has stopped. */
static void test_one_axis_at_a_time(void **state)
{
	struct dmc_h *h = *state;
	double t0, a_last = -1, b_first = -1;

	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 1500);
	t0 = dmc_h_now(h);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A neutral"));
	DMC_H_CHECK(h, dmc_h_control(h, "joy B fwd"));
	while (dmc_h_now(h) - t0 < 500) {
		dmc_h_advance(h, 1);
		if (dmc_h_axis(h, 0).moving)
			a_last = dmc_h_now(h);
		if (b_first < 0 && dmc_h_axis(h, 1).moving)
			b_first = dmc_h_now(h);
		if (dmc_h_axis(h, 0).moving && dmc_h_axis(h, 1).moving)
			fail_msg("A and B move together at %.0f ms",
				 dmc_h_now(h) - t0);
	}
	assert_true(a_last > t0);
	assert_true(b_first > a_last);
	assert_true(dmc_h_var(h, "mcmd") == 3);
}

/* Targets are clamped to the soft limits: the axis stops at sfwd without
 * a fault and can be jogged back. */
static void test_soft_limit_clamp(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double pos;

	dmc_h_close(h);
	dmc_h_params_default(&p);
	p.sfwd[0] = 3000;
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	DMC_H_CHECK(h, dmc_h_configure(h, &p));
	DMC_H_CHECK(h, dmc_h_arm(h));
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 2000);
	pos = dmc_h_axis(h, 0).enc;
	assert_true(pos <= 3000 + 1 && pos > 2990);
	assert_int_equal(dmc_h_axis(h, 0).motor_off, 0);
	assert_true(dmc_h_var(h, "state") == 1);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A rev"));
	dmc_h_advance(h, 1000);
	assert_true(dmc_h_axis(h, 0).enc < 2000);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_ramp_a, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_ramp_b, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_ramp_c, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_reverse, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_one_axis_at_a_time,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_soft_limit_clamp,
					    dmc_h_fx_armed, dmc_h_fx_free),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
