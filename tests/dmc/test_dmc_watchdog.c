/*
 * test_dmc_watchdog.c - the controller side of the PC watchdog and the
 * program heartbeat: if hbpc does not change within
 * wdto while armed, every axis is stopped and switched off and fault 2
 * WATCHDOG is latched; thread 1 backs thread 0 up; pcflt latches 12. A
 * stale tool's fractional hbpc (never the supervisor's, 2.24) gives a
 * request no fresh date and keeps no probe watchdog (#PRWD) alive.
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
	int frac;	 /* 1: a stale tool's "hbpc=<last>.5" on the
			    request's line (program 2.24) */
};

/*
 * The supervisor dies between its last heartbeat and its request (or just
 * after both): the program judges the request by that last change, not by
 * the request's own time (#GOON). A request wdto after the change latches
 * fault 2 with no motor ever on; one 20 ms after it goes on, and every
 * motor is off again within wdto + mainms (+1 sample) of the change. A
 * stale tool's fractional heartbeat on the late request's line
 * ("hbpc=n.5;armreq=1") is not the supervisor's and gives the request no
 * fresh date (#HBSEEN, 2.24): refused the same, no motor ever on.
 */
static void test_request_after_death(void **state)
{
	static const struct reqcase cases[] = {
	    {"svcreq", 3, 0, 0}, {"armreq", 1, 0, 0}, {"svcreq", 3, 1, 0},
	    {"armreq", 1, 1, 0}, {"svcreq", 3, 1, 1}, {"armreq", 1, 1, 1},
	};

	(void)state;
	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
		static struct dmc_h h;
		const struct reqcase *c = &cases[k];
		struct dmc_h_params p;
		double wdto, mainms, t_last, t_on = -1, t, delay;
		char line[48];
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
		if (c->frac) {
			snprintf(line, sizeof(line), "hbpc=%ld.5;%s=1", h.hb,
				 c->req);
			DMC_H_CHECK(&h, dmc_h_cmd(&h, line, NULL, 0));
		} else {
			DMC_H_CHECK(&h, dmc_h_set(&h, c->req, 1));
		}
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
		print_message("measured: %s%s %.0f ms after the last "
			      "heartbeat: motors %s, fault %g at %.0f ms\n",
			      c->req, c->frac ? " with hbpc=<last>.5" : "",
			      delay, on ? "went on" : "never on",
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

/*
 * The request window: the supervisor writes "hbpc=n;REQ=1" on one line,
 * goes on writing its heartbeat every 10 ms and dies 0..39 ms after the
 * request (the heartbeat stops; a kill at 40 instants of the window, in
 * which the program takes the request: its checks hold thread 0 for tens
 * of ms). Wherever it dies, every motor is off within wdto + mainms (+1
 * sample) of that last write, whether the program put them on or not:
 * the request is dated by the look before the write (#HBSEEN), not by the
 * pass that saw it after its parameter and seal checks.
 */
static void test_request_window(void **state)
{
	static const char *const req[2] = {"svcreq", "armreq"};
	double worst[2] = {0, 0};
	int went_on[2] = {0, 0};

	(void)state;
	for (int r = 0; r < 2; r++)
		for (int d = 0; d < 40; d++) {
			static struct dmc_h h;
			struct dmc_h_params p;
			char line[48];
			double wdto, mainms, t_last, t;

			dmc_h_params_default(&p);
			DMC_H_CHECK(&h, dmc_h_open(&h));
			DMC_H_CHECK(&h, dmc_h_start(&h));
			DMC_H_CHECK(&h, dmc_h_configure(&h, &p));
			wdto = dmc_h_var(&h, "wdto");
			mainms = dmc_h_var(&h, "mainms");
			h.hb_on = 1;
			dmc_h_advance(&h, 100 + d % 11);
			h.hb_on = 0;
			snprintf(line, sizeof(line), "hbpc=%ld;%s=1", ++h.hb,
				 req[r]);
			DMC_H_CHECK(&h, dmc_h_cmd(&h, line, NULL, 0));
			t_last = dmc_h_now(&h);
			/* it goes on writing every 10 ms (its cycle while the
			 * program takes the request) and dies d ms after the
			 * request: its last write is the last one before d */
			for (int w = 10; w <= d; w += 10) {
				dmc_h_advance(&h, 10);
				DMC_H_CHECK(
				    &h, dmc_h_set(&h, "hbpc", (double)++h.hb));
				t_last = dmc_h_now(&h);
			}
			dmc_h_advance(&h, d % 10);
			for (t = dmc_h_now(&h) - t_last; t < wdto + mainms + 1;
			     t = dmc_h_now(&h) - t_last) {
				dmc_h_advance(&h, 1);
				went_on[r] += !dmc_h_axis(&h, 0).motor_off;
			}
			for (int i = 0; i < DMC_H_AXES; i++)
				if (!dmc_h_axis(&h, i).motor_off)
					fail_msg(
					    "%s, died %d ms after it: axis "
					    "%c on %.0f ms after the last "
					    "write (wdto %.0f, mainms "
					    "%.0f)",
					    req[r], d, 'A' + i, t, wdto,
					    mainms);
			t = dmc_h_wait_motor_off(&h, 7, 0);
			if (t > worst[r])
				worst[r] = t;
			assert_true(dmc_h_var(&h, "state") == 2);
			assert_true(dmc_h_var(&h, "fcode") == 2);
			dmc_h_close(&h);
		}
	print_message("measured: 40 instants each, the motors went on %s "
		      "and %s, and were off within wdto + mainms + 1 of the "
		      "last write in every case\n",
		      went_on[0] ? "in service" : "never in service",
		      went_on[1] ? "armed" : "never armed");
}

/*
 * The commissioning run's direct probes under #PRWD: the program halted,
 * #PRWD started, axis A moving under direct commands while the probe
 * writes hbpc every 10 ms; the probe dies at 20 instants of a 300-count
 * move: the motors are off within wdto + mainms (+1) of its last write,
 * with "PROBE WATCHDOG".
 */
static void test_probe_watchdog(void **state)
{
	(void)state;
	for (int d = 0; d < 20; d++) {
		static struct dmc_h h;
		double wdto, mainms, t_last = 0, t;

		DMC_H_CHECK(&h, dmc_h_open(&h));
		DMC_H_CHECK(&h, dmc_h_cmd(&h, "XQ #PRWD,0", NULL, 0));
		dmc_h_advance(&h, 30);
		wdto = dmc_h_var(&h, "wdto");
		mainms = dmc_h_var(&h, "mainms");
		DMC_H_CHECK(
		    &h, dmc_h_cmd(&h, "SH A;SPA=1000;PRA=300;BG A", NULL, 0));
		for (int k = 0; k <= d; k++) {
			DMC_H_CHECK(&h, dmc_h_set(&h, "hbpc", (double)++h.hb));
			t_last = dmc_h_now(&h);
			dmc_h_advance(&h, 10);
		}
		t = dmc_h_wait_motor_off(&h, 7, wdto + mainms + 1);
		if (t < 0)
			fail_msg("probe died after %d writes: a motor still on "
				 "%.0f ms after the last",
				 d + 1, dmc_h_now(&h) - t_last);
		t = dmc_h_now(&h) - t_last;
		assert_true(t <= wdto + mainms + 1);
		assert_true(dmc_h_unsol_has(&h, "PROBE WATCHDOG"));
		dmc_h_close(&h);
	}
}

/*
 * Under #PRWD, after the probe's last write, a stale tool writes
 * fractional heartbeats every 10 ms (last + 0.5, last + 0.0001 in turn):
 * not the probe's (it writes whole values, 2.24), so they feed no
 * watchdog: axis A's motor is off within wdto + mainms (+1) of the
 * probe's last write, with "PROBE WATCHDOG".
 */
static void test_probe_watchdog_fraction(void **state)
{
	static struct dmc_h h;
	double wdto, mainms, t_last, t;
	char line[48];

	(void)state;
	DMC_H_CHECK(&h, dmc_h_open(&h));
	DMC_H_CHECK(&h, dmc_h_cmd(&h, "XQ #PRWD,0", NULL, 0));
	dmc_h_advance(&h, 30);
	wdto = dmc_h_var(&h, "wdto");
	mainms = dmc_h_var(&h, "mainms");
	DMC_H_CHECK(&h, dmc_h_cmd(&h, "SH A", NULL, 0));
	DMC_H_CHECK(&h, dmc_h_set(&h, "hbpc", (double)++h.hb));
	t_last = dmc_h_now(&h);
	for (int k = 1; !dmc_h_axis(&h, 0).motor_off &&
			dmc_h_now(&h) - t_last < wdto + mainms + 50;
	     k++) {
		dmc_h_advance(&h, 1);
		if (k % 10)
			continue;
		snprintf(line, sizeof(line), "hbpc=%ld.%s", h.hb,
			 k % 20 ? "5" : "0001");
		DMC_H_CHECK(&h, dmc_h_cmd(&h, line, NULL, 0));
	}
	t = dmc_h_now(&h) - t_last;
	dmc_h_advance(&h, 2); /* "PROBE WATCHDOG" leaves the output queue */
	print_message("measured: probe's last write, then fractional "
		      "heartbeats every 10 ms: motor A off after %.0f ms "
		      "(wdto %.0f + mainms %.0f)\n",
		      t, wdto, mainms);
	if (!dmc_h_axis(&h, 0).motor_off || t > wdto + mainms + 1)
		fail_msg("motor A %s %.0f ms after the probe's last write",
			 dmc_h_axis(&h, 0).motor_off ? "went off" : "still on",
			 t);
	assert_true(dmc_h_unsol_has(&h, "PROBE WATCHDOG"));
	dmc_h_close(&h);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_heartbeat_stopped,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test(test_request_after_death),
	    cmocka_unit_test(test_request_window),
	    cmocka_unit_test(test_probe_watchdog),
	    cmocka_unit_test(test_probe_watchdog_fraction),
	    cmocka_unit_test_setup_teardown(test_heartbeat_slow_ok,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_thread0_halted, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_pcflt, dmc_h_fx_armed,
					    dmc_h_fx_free),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
