/*
 * test_dmc_watchdog.c - the controller side of the PC watchdog and the
 * program heartbeat (issue 4, point 5): if hbpc does not change within
 * wdto while armed, every axis is stopped and switched off and fault 2
 * WATCHDOG is latched; thread 1 backs thread 0 up; pcflt latches 12.
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

/* Heartbeat stopped during motion: nothing happens before wdto - mainms;
 * every axis is stopped and off within wdto + one main loop (+1 sample) of
 * the last change; fault 2 with fdet = ms since that change was seen. */
static void test_heartbeat_stopped(void **state)
{
	struct dmc_h *h = *state;
	double wdto = dmc_h_var(h, "wdto"), mainms = dmc_h_var(h, "mainms");
	double t_last, t_off, det = 0;
	int code = 0, axis = -1;

	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 1000);
	assert_true(dmc_h_axis(h, 0).moving);
	/* the next advance writes hbpc at its start: the last change */
	while (dmc_h_now(h) < h->hb_next_ms - 1e-9)
		dmc_h_advance(h, 1);
	t_last = dmc_h_now(h);
	dmc_h_advance(h, 1);
	h->hb_on = 0;
	dmc_h_advance(h, wdto - mainms - 1);
	assert_int_equal(dmc_h_axis(h, 0).motor_off, 0);
	assert_true(dmc_h_var(h, "state") == 1);
	t_off = dmc_h_wait_motor_off(h, 7, 3 * mainms);
	assert_true(t_off >= 0);
	t_off = dmc_h_now(h) - t_last;
	assert_true(t_off > wdto - mainms);
	assert_true(t_off <= wdto + mainms + 1);
	assert_true(dmc_h_var(h, "state") == 2);
	assert_true(dmc_h_var(h, "fcode") == 2);
	/* fdet: ms since thread 0 saw the last change (up to mainms late) */
	assert_true(dmc_h_var(h, "fdet") > wdto - mainms);
	assert_true(dmc_h_var(h, "fdet") <= wdto + mainms + 1);
	dmc_h_advance(h, 200);
	for (int i = 0; i < DMC_H_AXES; i++) {
		assert_int_equal(dmc_h_axis(h, i).moving, 0);
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
	}
	assert_int_equal(dmc_h_fault_lines(h, &code, &axis, &det), 1);
	assert_int_equal(code, 2);
	assert_int_equal(axis, 0);
	/* the program itself keeps running: heartbeat and record */
	det = dmc_h_var(h, "hbdmc");
	dmc_h_advance(h, 100);
	assert_true(dmc_h_var(h, "hbdmc") > det);
}

struct reqcase {
	const char *req; /* svcreq or armreq */
	double want;	 /* the state it asks for */
	int stale;	 /* 0: request 20 ms after the last heartbeat
			    change, 1: wdto after it */
};

/*
 * The supervisor dies between its last heartbeat and its request (or just
 * after both): the program judges the request by that last change, not by
 * the request's own time (#GOON). A request wdto after the change latches
 * fault 2 with no motor ever on; one 20 ms after it goes on, and every
 * motor is off again within wdto + mainms (+1 sample) of the change.
 */
static void test_request_after_death(void **state)
{
	static const struct reqcase cases[] = {
	    {"svcreq", 3, 0},
	    {"armreq", 1, 0},
	    {"svcreq", 3, 1},
	    {"armreq", 1, 1},
	};

	(void)state;
	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
		static struct dmc_h h;
		const struct reqcase *c = &cases[k];
		struct dmc_h_params p;
		double wdto, mainms, t_last, t_on = -1, t, delay;
		int on = 0;

		dmc_h_params_default(&p);
		DMC_H_CHECK(&h, dmc_h_open(&h));
		DMC_H_CHECK(&h, dmc_h_start(&h));
		DMC_H_CHECK(&h, dmc_h_configure(&h, &p));
		wdto = dmc_h_var(&h, "wdto");
		mainms = dmc_h_var(&h, "mainms");
		h.hb_on = 0;
		DMC_H_CHECK(&h, dmc_h_set(&h, "hbpc", (double)++h.hb));
		t_last = dmc_h_now(&h);
		delay = c->stale ? wdto : 20;
		dmc_h_advance(&h, delay);
		DMC_H_CHECK(&h, dmc_h_set(&h, c->req, 1));
		while ((t = dmc_h_now(&h) - t_last) < delay + wdto &&
		       dmc_h_var(&h, "state") != 2) {
			dmc_h_advance(&h, 1);
			if (!dmc_h_axis(&h, 0).motor_off && !on) {
				on = 1;
				t_on = dmc_h_now(&h) - t_last;
			}
			if (dmc_h_var(&h, "state") == c->want && t_on < 0)
				t_on = dmc_h_now(&h) - t_last;
		}
		(void)dmc_h_wait_motor_off(&h, 7, 3 * mainms);
		t = dmc_h_now(&h) - t_last;
		print_message("measured: %s %.0f ms after the last heartbeat: "
			      "motors %s, fault %g at %.0f ms\n",
			      c->req, delay, on ? "went on" : "never on",
			      dmc_h_var(&h, "fcode"), t);
		assert_true(dmc_h_var(&h, "state") == 2);
		assert_true(dmc_h_var(&h, "fcode") == 2);
		if (c->stale) {
			/* refused in the pass that takes the request, after
			 * the parameter check (#PCHK, about 30 ms): nothing
			 * was on meanwhile */
			assert_int_equal(on, 0);
			assert_true(t <= delay + mainms + 50);
		} else {
			assert_int_equal(on, 1);
			assert_true(t <= wdto + mainms + 1);
		}
		for (int i = 0; i < DMC_H_AXES; i++)
			assert_int_equal(dmc_h_axis(&h, i).motor_off, 1);
		dmc_h_close(&h);
	}
}

/* A heartbeat slower than the supervisor's but inside wdto - mainms never
 * trips (3 s). */
static void test_heartbeat_slow_ok(void **state)
{
	struct dmc_h *h = *state;

	h->hb_period_ms = dmc_h_var(h, "wdto") - dmc_h_var(h, "mainms") - 5;
	DMC_H_CHECK(h, dmc_h_control(h, "joy C fwd"));
	dmc_h_advance(h, 3000);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_int_equal(dmc_h_axis(h, 2).motor_off, 0);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* Thread 0 halted (HX0) while the PC keeps its heartbeat: thread 1 stops
 * and switches off every axis within wdto + 2 main loops + one motion loop
 * of the last change thread 0 saw. */
static void test_thread0_halted(void **state)
{
	struct dmc_h *h = *state;
	double wdto = dmc_h_var(h, "wdto"), mainms = dmc_h_var(h, "mainms");
	double loopms = dmc_h_var(h, "loopms"), t_hx, t;

	DMC_H_CHECK(h, dmc_h_control(h, "joy B rev"));
	dmc_h_advance(h, 1000);
	t_hx = dmc_h_now(h);
	DMC_H_CHECK(h, dmc_h_cmd(h, "HX0", NULL, 0));
	t = dmc_h_wait_motor_off(h, 7, wdto + 2 * mainms + loopms + 20);
	assert_true(t >= 0);
	assert_true(t <= wdto + 2 * mainms + loopms + 1);
	assert_true(dmc_h_var(h, "mflt") == 2);
	dmc_h_advance(h, 200);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).moving, 0);
	assert_int_equal(ctrl_threads(h->ctrl), 0u);
	(void)t_hx;
}

/* pcflt=1 from the supervisor: fault 12 within one main loop. */
static void test_pcflt(void **state)
{
	struct dmc_h *h = *state;
	double t;

	DMC_H_CHECK(h, dmc_h_control(h, "joy A rev"));
	dmc_h_advance(h, 500);
	DMC_H_CHECK(h, dmc_h_set(h, "pcflt", 1));
	t = dmc_h_wait_motor_off(h, 7, 100);
	assert_true(t >= 0 && t <= dmc_h_var(h, "mainms") + 1);
	/* #FAULT latches a few lines after MO ABC (and OP 0) */
	assert_true(dmc_h_wait_var(h, "state", 2, 3) >= 0);
	assert_true(dmc_h_var(h, "fcode") == 12);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_heartbeat_stopped,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test(test_request_after_death),
	    cmocka_unit_test_setup_teardown(test_heartbeat_slow_ok,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_thread0_halted, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_pcflt, dmc_h_fx_armed,
					    dmc_h_fx_free),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
