/*
 * test_dmc_seal.c - the seal (docs/dmc-interface.md, "The seal"): every
 * item of the seal table, changed from outside while armed and while in
 * service, is caught by the program within RE_SEAL_SLICES main passes (plus
 * one pass and a sample): fault 17 with that item's number, its axis and
 * the value found; a sealed value changed before a request refuses the
 * service or the arm; thread 2 started or thread 1 restarted elsewhere is
 * caught; an untouched robot runs without a fault.
 *
 * The table is the one the harness sealed the program with (dmc_h.seal),
 * so a new item is tested without editing this file. Reaction times are in
 * simulated ms; the longest is printed ("measured:").
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "ctrl.h"
#include "dmc_h.h"

/* A value the controller computes, read with a host MG (NAN on error). */
static double mg(struct dmc_h *h, const char *expr)
{
	char line[64], resp[64];

	snprintf(line, sizeof(line), "MG %s", expr);
	if (dmc_h_cmd(h, line, resp, sizeof(resp)) < 0)
		return NAN;
	return atof(resp);
}

/* The value a foreign write puts in place of @v for item @it: another
 * value the controller takes. */
static double changed(const struct re_seal_item *it, double v)
{
	const char *r = it->ref;

	if (!strcmp(r, "prun"))
		return 0;
	if (r[0] != '_')
		return v + 1;
	if (!strncmp(r, "_OE", 3) || !strncmp(r, "_OA", 3))
		return 1 - v;
	if (!strncmp(r, "_LD", 3))
		return 3;
	if (!strncmp(r, "_MT", 3))
		return -1;
	if (!strncmp(r, "_CE", 3))
		return 2;
	if (!strcmp(r, "_CN0"))
		return 1;
	if (!strcmp(r, "_TM"))
		return 500;
	if (!strncmp(r, "_TL", 3))
		return v + 0.5; /* more torque: a lower TL is no change */
	if (!strncmp(r, "_OV", 3))
		return v > 1 ? v - 0.5 : v + 0.5;
	if (!strncmp(r, "_AC", 3) || !strncmp(r, "_DC", 3))
		return v + 1024;
	if (!strncmp(r, "_FL", 3))
		return v - 1000; /* inward: the open FL is the largest value */
	if (!strncmp(r, "_BL", 3))
		return v + 1000;
	return v + 1;
}

/* The host command that changes item @it to @v: a variable is assigned; a
 * setting of axis i is "XX ,,v" (i commas); CN and TM are controller-wide.
 */
static void write_cmd(const struct re_seal_item *it, double v, char *buf,
		      size_t cap)
{
	const char *r = it->ref;

	if (r[0] != '_') {
		snprintf(buf, cap, "%s=%.4f", r, v);
		return;
	}
	if (!strcmp(r, "_CN0") || !strcmp(r, "_TM")) {
		snprintf(buf, cap, "%.2s %.4f", r + 1, v);
		return;
	}
	snprintf(buf, cap, "%.2s %.*s%.4f", r + 1, it->axis, ",,,", v);
}

/* The items a check that runs every pass names first, with the fault it
 * latches: wdto and jto changed, OE switched off (#FORGN, fault 14 detail
 * 3 and 4, older than the seal and faster than its rotation). */
static int named_earlier(const char *ref, double *code, double *det)
{
	*code = 14;
	*det = !strcmp(ref, "wdto") || !strcmp(ref, "jto") ? 3
	       : !strncmp(ref, "_OE", 3)		   ? 4
							   : 0;
	return *det != 0;
}

/* An armed robot (@service 0) or one in its service state (1). */
static void setup(struct dmc_h *h, int service)
{
	struct dmc_h_params p;

	dmc_h_params_default(&p);
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	/* a torque limit below the largest, as the robot's configuration */
	DMC_H_CHECK(h, dmc_h_cmd(h, "TL 5,5,5", NULL, 0));
	DMC_H_CHECK(h, dmc_h_configure(h, &p));
	DMC_H_CHECK(h, service ? dmc_h_service(h) : dmc_h_arm(h));
}

/* Item @k (0-based) written from outside in @state (1 armed, 3 service):
 * fault 17 naming it within the bound. Return: the reaction, ms. */
static double one_item(int k, int service)
{
	struct dmc_h *h = calloc(1, sizeof(*h));
	const struct re_seal_item *it;
	double v, nv, mainms, t, bound, det = 0, want_code, want_det;
	int code = 0, axis = -1;
	char cmd[64];

	assert_non_null(h);
	setup(h, service);
	it = &h->seal.item[k];
	mainms = dmc_h_var(h, "mainms");
	bound = (RE_SEAL_SLICES + 1) * mainms + 2;
	v = mg(h, it->ref);
	nv = changed(it, v);
	if (it->kind == RE_SEAL_THREAD) {
		/* thread 1 is tested apart; threads 2..7: the motion
		 * thread started there too (a stale tool's XQ) */
		snprintf(cmd, sizeof(cmd), "XQ #MOTION,%s", it->ref + 3);
		nv = -2; /* not compared: a line number */
	} else {
		write_cmd(it, nv, cmd, sizeof(cmd));
	}
	DMC_H_CHECK(h, dmc_h_cmd(h, cmd, NULL, 0));
	if (it->kind == RE_SEAL_THREAD && service) {
		/* #MOTION ends at once outside the armed state: the thread
		 * is gone within a pass and nothing else happened */
		dmc_h_advance(h, bound);
		assert_true(dmc_h_var(h, "state") == 3);
		assert_int_equal(ctrl_threads(h->ctrl), 1u);
		dmc_h_close(h);
		free(h);
		return 0;
	}
	t = dmc_h_wait_var(h, "state", 2, bound);
	if (t < 0)
		fail_msg("%s: '%s' (%g -> %g) %s: no fault within %.0f ms",
			 it->ref, cmd, v, nv, service ? "in service" : "armed",
			 bound);
	dmc_h_advance(h, 2 * mainms); /* #SLF finds it, then latches */
	if (getenv("SEAL_LIST"))
		print_message("item %d %s: fault %g axis %g detail %g\n", k + 1,
			      it->ref, dmc_h_var(h, "fcode"),
			      dmc_h_var(h, "faxis"), dmc_h_var(h, "fdet"));
	if (getenv("SEAL_LIST"))
		return t;
	if (named_earlier(it->ref, &want_code, &want_det)) {
		if (dmc_h_var(h, "fcode") != want_code ||
		    dmc_h_var(h, "fdet") != want_det)
			fail_msg("%s: fault %g detail %g, want %g detail %g",
				 it->ref, dmc_h_var(h, "fcode"),
				 dmc_h_var(h, "fdet"), want_code, want_det);
		dmc_h_close(h);
		free(h);
		return t;
	}
	if (dmc_h_var(h, "fcode") != 17 || dmc_h_var(h, "fdet") != k + 1)
		fail_msg("%s: '%s': fault %g detail %g (found %g), want 17 "
			 "detail %d",
			 it->ref, cmd, dmc_h_var(h, "fcode"),
			 dmc_h_var(h, "fdet"), dmc_h_var(h, "sfv"), k + 1);
	assert_true(dmc_h_var(h, "faxis") == it->axis + 1);
	if (it->kind != RE_SEAL_THREAD &&
	    fabs(dmc_h_var(h, "sfv") - mg(h, it->ref)) > 1e-3)
		fail_msg("%s: sfv %g, the value is %g", it->ref,
			 dmc_h_var(h, "sfv"), mg(h, it->ref));
	assert_int_equal(dmc_h_fault_lines(h, &code, &axis, &det), 1);
	assert_int_equal(code, 17);
	assert_true(det == k + 1);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
	dmc_h_close(h);
	free(h);
	return t;
}

static void every_item(int service)
{
	struct dmc_h *h = calloc(1, sizeof(*h));
	double worst = 0, t;
	int n, worst_k = 0, xq1 = -1;

	assert_non_null(h);
	DMC_H_CHECK(h, dmc_h_open(h));
	n = h->seal.n;
	for (int k = 0; k < n; k++)
		if (!strcmp(h->seal.item[k].ref, "_XQ1"))
			xq1 = k;
	dmc_h_close(h);
	free(h);
	assert_true(n > 100 && xq1 >= 0);
	for (int k = 0; k < n; k++) {
		if (k == xq1) /* tested apart: test_thread1_elsewhere */
			continue;
		t = one_item(k, service);
		if (t > worst) {
			worst = t;
			worst_k = k;
		}
	}
	print_message("measured: %d sealed values %s, the slowest caught "
		      "after %.0f ms (item %d)\n",
		      n - 1, service ? "in service" : "armed", worst,
		      worst_k + 1);
}

/* Every item but _XQ1, changed while armed. */
static void test_every_item_armed(void **state)
{
	(void)state;
	every_item(0);
}

/* Every item but _XQ1, changed in the service state. */
static void test_every_item_service(void **state)
{
	(void)state;
	every_item(1);
}

/* Thread 1 halted and started again outside #MOTION while armed (a
 * client's "HX1;XQ #MAIN,1" on one line): fault 17 on _XQ1. */
static void test_thread1_elsewhere(void **state)
{
	struct dmc_h *h = *state;
	double mainms;
	int k;

	setup(h, 0);
	mainms = dmc_h_var(h, "mainms");
	for (k = 0; k < h->seal.n && strcmp(h->seal.item[k].ref, "_XQ1"); k++)
		;
	assert_true(k < h->seal.n);
	DMC_H_CHECK(h, dmc_h_cmd(h, "HX1;XQ #MAIN,1", NULL, 0));
	assert_true(dmc_h_wait_var(h, "state", 2,
				   (RE_SEAL_SLICES + 1) * mainms + 2) >= 0);
	dmc_h_advance(h, 2 * mainms);
	if (dmc_h_var(h, "fcode") != 17 || dmc_h_var(h, "fdet") != k + 1)
		fail_msg("fault %g axis %g detail %g, want 17 detail %d (_XQ1)",
			 dmc_h_var(h, "fcode"), dmc_h_var(h, "faxis"),
			 dmc_h_var(h, "fdet"), k + 1);
}

/* Thread 1 started in the finder itself while armed (a client's "HX1;XQ
 * #SLF,1"): it stops the motion and waits at #SLW instead of ending
 * itself, so thread 0 finds it there: fault 17 on _XQ1, and thread 1
 * halted. */
static void test_thread1_in_finder(void **state)
{
	struct dmc_h *h = *state;
	double mainms;
	int k;

	setup(h, 0);
	mainms = dmc_h_var(h, "mainms");
	for (k = 0; k < h->seal.n && strcmp(h->seal.item[k].ref, "_XQ1"); k++)
		;
	assert_true(k < h->seal.n);
	DMC_H_CHECK(h, dmc_h_cmd(h, "HX1;XQ #SLF,1", NULL, 0));
	assert_true(dmc_h_wait_var(h, "state", 2,
				   (RE_SEAL_SLICES + 1) * mainms + 2) >= 0);
	dmc_h_advance(h, 2 * mainms);
	if (dmc_h_var(h, "fcode") != 17 || dmc_h_var(h, "fdet") != k + 1)
		fail_msg("fault %g axis %g detail %g, want 17 detail %d (_XQ1)",
			 dmc_h_var(h, "fcode"), dmc_h_var(h, "faxis"),
			 dmc_h_var(h, "fdet"), k + 1);
	assert_int_equal(ctrl_threads(h->ctrl) & 2u, 0);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
}

/* A sealed value changed in the safe state is caught at the request,
 * before any motor goes on: the arm and the service request refused. */
static void test_refused_at_request(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;

	for (int service = 0; service < 2; service++) {
		dmc_h_params_default(&p);
		DMC_H_CHECK(h, dmc_h_open(h));
		DMC_H_CHECK(h, dmc_h_start(h));
		DMC_H_CHECK(h, dmc_h_configure(h, &p));
		DMC_H_CHECK(h, dmc_h_set(h, "jin[3]", 21)); /* free input */
		assert_int_equal(service ? dmc_h_service(h) : dmc_h_arm(h),
				 GL_ERR_CTRL);
		dmc_h_advance(h, 30);
		assert_true(dmc_h_var(h, "fcode") == 17);
		assert_true(dmc_h_var(h, "faxis") == 1);
		assert_true(dmc_h_var(h, "sfv") == 21);
		assert_string_equal(
		    h->seal.item[(int)dmc_h_var(h, "fdet") - 1].ref, "jin[3]");
		for (int i = 0; i < DMC_H_AXES; i++)
			assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
		dmc_h_close(h);
	}
}

/* A torque limit lowered (as the commissioning run does for its first
 * moves) is the safe side: no fault; raised, fault 17. */
static void test_tl_lowered(void **state)
{
	struct dmc_h *h = *state;

	setup(h, 0);
	DMC_H_CHECK(h, dmc_h_cmd(h, "TL 2,2,2", NULL, 0));
	dmc_h_advance(h, 300);
	assert_true(dmc_h_var(h, "state") == 1);
	DMC_H_CHECK(h, dmc_h_cmd(h, "TL ,5.5", NULL, 0));
	dmc_h_advance(h, 200);
	assert_true(dmc_h_var(h, "fcode") == 17);
	assert_string_equal(h->seal.item[(int)dmc_h_var(h, "fdet") - 1].ref,
			    "_TLB");
}

/* Nothing changed: armed with the joystick used, then in service with a
 * move, for 3 s of simulated time each, no fault. */
static void test_untouched(void **state)
{
	struct dmc_h *h = *state;

	setup(h, 0);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 1500);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A neutral"));
	DMC_H_CHECK(h, dmc_h_control(h, "joy C rev"));
	dmc_h_advance(h, 1500);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
	/* the main pass with its slice of the seal keeps its period */
	print_message("measured: the main pass's longest period armed with "
		      "the seal: %g ms (mainms %g)\n",
		      dmc_h_var(h, "mnmax"), dmc_h_var(h, "mainms"));
	assert_true(dmc_h_var(h, "mnmax") <= dmc_h_var(h, "mainms") + 1);
	dmc_h_close(h);
	setup(h, 1);
	DMC_H_CHECK(h, dmc_h_move(h, 0, 20000, 5000, 10000));
	dmc_h_advance(h, 3000);
	assert_true(dmc_h_var(h, "state") == 3);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_every_item_armed),
	    cmocka_unit_test(test_every_item_service),
	    cmocka_unit_test_setup_teardown(test_thread1_elsewhere,
					    dmc_h_fx_new, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_thread1_in_finder,
					    dmc_h_fx_new, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_refused_at_request,
					    dmc_h_fx_new, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_tl_lowered, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_untouched, dmc_h_fx_new,
					    dmc_h_fx_free),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
