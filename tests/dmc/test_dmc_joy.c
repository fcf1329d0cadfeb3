/*
 * test_dmc_joy.c - joystick decode and the invalid-state timeout: valid states
 * are all released or exactly one command with both switches; anything else
 * stops motion at once, a valid state within jto resumes, an invalid state held
 * longer than jto is fault 3 INPUT.
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

static void positions(struct dmc_h *h, double pos[DMC_H_AXES])
{
	for (int i = 0; i < DMC_H_AXES; i++)
		pos[i] = dmc_h_axis(h, i).enc;
}

/* Advance until no axis moves (profiler idle), at most @ms. */
static double wait_still(struct dmc_h *h, double ms)
{
	double t0 = dmc_h_now(h);

	while (dmc_h_now(h) - t0 < ms) {
		int moving = 0;

		for (int i = 0; i < DMC_H_AXES; i++)
			moving |= dmc_h_axis(h, i).moving;
		if (!moving)
			return dmc_h_now(h) - t0;
		dmc_h_advance(h, 1);
	}
	return -1;
}

/* Each of the six commands moves its axis, in its direction, alone; the
 * decoded command and the switch word are published. */
static void test_each_command(void **state)
{
	static const char *const name[6] = {"A fwd", "A rev", "B fwd",
					    "B rev", "C fwd", "C rev"};
	struct dmc_h *h = *state;

	for (int k = 0; k < 6; k++) {
		double p0[DMC_H_AXES], p1[DMC_H_AXES];
		char req[32];
		int ax = k / 2, dir = k % 2 ? -1 : 1;

		positions(h, p0);
		snprintf(req, sizeof(req), "joy %s", name[k]);
		DMC_H_CHECK(h, dmc_h_control(h, req));
		dmc_h_advance(h, 300);
		assert_true(dmc_h_var(h, "jcmd") == k + 1);
		assert_true(dmc_h_var(h, "mcmd") == k + 1);
		assert_true(dmc_h_var(h, "jraw") == 3 << (2 * k));
		positions(h, p1);
		for (int i = 0; i < DMC_H_AXES; i++) {
			double d = (p1[i] - p0[i]) * dir;

			if (i == ax)
				assert_true(d > 300);
			else
				assert_true(fabs(p1[i] - p0[i]) < 1);
		}
		snprintf(req, sizeof(req), "joy %c neutral", "ABC"[ax]);
		DMC_H_CHECK(h, dmc_h_control(h, req));
		assert_true(wait_still(h, 300) >= 0);
		assert_true(dmc_h_var(h, "jcmd") == 0);
		assert_true(dmc_h_var(h, "mcmd") == 0);
	}
	assert_true(dmc_h_var(h, "state") == 1);
}

/* Neutral stops motion at once: the stop starts within one motion loop and
 * ends within the deceleration time vmax / DC = 0.1 s after that. */
static void test_neutral_stops(void **state)
{
	struct dmc_h *h = *state;
	double loopms = dmc_h_var(h, "loopms"), t;

	DMC_H_CHECK(h, dmc_h_control(h, "joy B fwd"));
	dmc_h_advance(h, 2500); /* at vmax */
	assert_true(dmc_h_axis(h, 1).vel > 9000);
	DMC_H_CHECK(h, dmc_h_control(h, "joy B neutral"));
	t = wait_still(h, 500);
	assert_true(t >= 0);
	print_message("measured: neutral -> still after %.0f ms\n", t);
	/* + 5 samples: from the read of the inputs to the ST (test_dmc_ramp) */
	assert_true(t <= loopms + 100 + 5);
	assert_true(dmc_h_var(h, "state") == 1);
}

/* Invalid for 0.4 s (one channel of a command): motion stops at once, no
 * fault; both channels then resume motion (the ramp starts again). */
static void test_invalid_short(void **state)
{
	struct dmc_h *h = *state;
	double loopms = dmc_h_var(h, "loopms"), p0, t;

	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 1000);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd a"));
	t = wait_still(h, 400);
	assert_true(t >= 0 && t <= loopms + 100 + 2);
	assert_true(dmc_h_var(h, "jcmd") == -1);
	dmc_h_advance(h, 400 - t);
	assert_true(dmc_h_var(h, "state") == 1);
	p0 = dmc_h_axis(h, 0).enc;
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 2 * loopms + 1);
	/* the ramp restarted: the first velocity is vmin */
	assert_true(fabs(dmc_h_var(h, "vcur") - 2500) < 1);
	dmc_h_advance(h, 1000);
	assert_true(dmc_h_axis(h, 0).enc - p0 > 1000);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* Invalid for 0.6 s: fault 3 INPUT, detected within one motion loop after
 * jto and latched by thread 0 within one main loop after that; every motor
 * off; fdet = the switch word. */
static void test_invalid_long(void **state)
{
	struct dmc_h *h = *state;
	double loopms = dmc_h_var(h, "loopms"), mainms = dmc_h_var(h, "mainms");
	double t_off, t_latch, det = 0;
	int code = 0, axis = -1;

	DMC_H_CHECK(h, dmc_h_control(h, "joy C rev b")); /* switch 11 */
	t_off = dmc_h_wait_motor_off(h, 7, 600);
	assert_true(t_off >= 500);
	assert_true(t_off <= 500 + 2 * loopms + 2);
	t_latch = dmc_h_wait_var(h, "state", 2, 100);
	assert_true(t_latch >= 0 && t_latch <= mainms + 2);
	assert_true(dmc_h_var(h, "fcode") == 3);
	assert_true(dmc_h_var(h, "fdet") == 2048);
	dmc_h_advance(h, 20);
	assert_int_equal(dmc_h_fault_lines(h, &code, &axis, &det), 1);
	assert_int_equal(code, 3);
	assert_int_equal(axis, 0);
	assert_true(det == 2048);
}

/* One switch stuck closed with the joystick released: an invalid state
 * that lasts, so fault 3 after jto. */
static void test_stuck_closed(void **state)
{
	struct dmc_h *h = *state;
	double lim = 500 + 2 * dmc_h_var(h, "loopms") + dmc_h_var(h, "mainms");
	double t;

	DMC_H_CHECK(h, dmc_h_control(h, "in 3 1")); /* B fwd, channel a */
	t = dmc_h_wait_var(h, "state", 2, 700);
	assert_true(t >= 500 && t <= lim + 2);
	assert_true(dmc_h_var(h, "fcode") == 3);
	assert_true(dmc_h_var(h, "fdet") == 4);
}

/* One switch broken open: pressing its command gives one channel only, so
 * no motion and fault 3 after jto. */
static void test_broken_open(void **state)
{
	struct dmc_h *h = *state;
	double lim = 500 + 2 * dmc_h_var(h, "loopms") + dmc_h_var(h, "mainms");
	double p0[DMC_H_AXES], p1[DMC_H_AXES], t;

	positions(h, p0);
	DMC_H_CHECK(h, dmc_h_control(h, "in 20 0")); /* C rev, channel b */
	DMC_H_CHECK(h, dmc_h_control(h, "joy C rev"));
	t = dmc_h_wait_var(h, "state", 2, 700);
	assert_true(t >= 500 && t <= lim + 2);
	assert_true(dmc_h_var(h, "fcode") == 3);
	assert_true(dmc_h_var(h, "fdet") == 1024);
	positions(h, p1);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_true(fabs(p1[i] - p0[i]) < 1);
}

/* Two directions pressed (A fwd and B fwd): invalid, nothing moves, fault
 * 3 after jto. */
static void test_two_directions(void **state)
{
	struct dmc_h *h = *state;
	double p0[DMC_H_AXES], p1[DMC_H_AXES], t;

	positions(h, p0);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	DMC_H_CHECK(h, dmc_h_control(h, "joy B fwd"));
	dmc_h_advance(h, 400);
	assert_true(dmc_h_var(h, "jcmd") == -1);
	assert_true(dmc_h_var(h, "state") == 1);
	positions(h, p1);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_true(fabs(p1[i] - p0[i]) < 1);
	t = dmc_h_wait_var(h, "state", 2, 300);
	assert_true(t >= 0);
	assert_true(dmc_h_var(h, "fcode") == 3);
	assert_true(dmc_h_var(h, "fdet") == 3 + 48);
	positions(h, p1);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_true(fabs(p1[i] - p0[i]) < 1);
}

/* Active-low switches (jpol 1): a closed switch reads 0. */
static void test_active_low(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double a0;

	dmc_h_close(h);
	dmc_h_params_default(&p);
	p.jpol = 1;
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	DMC_H_CHECK(h, dmc_h_configure(h, &p));
	for (int i = 0; i < DMC_H_SWITCHES; i++) {
		char req[32];

		snprintf(req, sizeof(req), "in %d 1", (int)p.jin[i]);
		DMC_H_CHECK(h, dmc_h_control(h, req));
	}
	DMC_H_CHECK(h, dmc_h_arm(h));
	dmc_h_advance(h, 50);
	a0 = dmc_h_axis(h, 0).enc;
	DMC_H_CHECK(h, dmc_h_control(h, "in 5 0")); /* B fwd a, b closed */
	DMC_H_CHECK(h, dmc_h_control(h, "in 6 0"));
	dmc_h_advance(h, 300);
	assert_true(dmc_h_var(h, "jcmd") == 3);
	assert_true(dmc_h_var(h, "jraw") == 48);
	assert_true(dmc_h_axis(h, 1).enc > 300);
	assert_true(fabs(dmc_h_axis(h, 0).enc - a0) < 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_each_command, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_neutral_stops, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_invalid_short, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_invalid_long, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_stuck_closed, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_broken_open, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_two_directions, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_active_low, dmc_h_fx_armed,
					    dmc_h_fx_free),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
