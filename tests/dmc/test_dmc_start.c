/*
 * test_dmc_start.c - safe start, arming and the data record fields
 * (docs/dmc-interface.md "Arming sequence").
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

static double axis_pos(struct dmc_h *h, int ax)
{
	return dmc_h_axis(h, ax).enc;
}

/* After #AUTO: motors off, state 0, BOOT sent, every parameter at the value
 * the program was sealed with (#SEALIN; dmc_h seals the tests' defaults),
 * the soft limits still 0 (they fail check 6 until the supervisor writes
 * them), the heartbeat advancing once per mainms; a pressed joystick moves
 * nothing. */
static void test_safe_start(void **state)
{
	struct dmc_h *h = *state;
	double hb0, hb1, mainms, pos[DMC_H_AXES];

	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	assert_true(dmc_h_unsol_has(h, "BOOT"));
	assert_true(dmc_h_var(h, "state") == 0);
	assert_true(dmc_h_var(h, "fcode") == 0);
	assert_true(dmc_h_var(h, "vmax[0]") == 10000);
	assert_true(dmc_h_var(h, "vmin[2]") == 2000);
	assert_true(dmc_h_var(h, "jin[11]") == 20);
	assert_true(dmc_h_var(h, "jval[5]") == 3072);
	assert_true(dmc_h_var(h, "jpol") == 0);
	assert_true(dmc_h_var(h, "jto") == 500);
	assert_true(dmc_h_var(h, "wdto") == 125);
	assert_true(dmc_h_var(h, "srev[0]") == 0);
	assert_true(dmc_h_var(h, "sfwd[0]") == 0);
	assert_true(dmc_h_var(h, "armreq") == 0);
	assert_int_equal(ctrl_threads(h->ctrl), 1u); /* thread 0 only */

	mainms = dmc_h_var(h, "mainms");
	hb0 = dmc_h_var(h, "hbdmc");
	for (int i = 0; i < DMC_H_AXES; i++)
		pos[i] = axis_pos(h, i);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 1000);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A neutral"));
	DMC_H_CHECK(h, dmc_h_control(h, "joy C rev"));
	dmc_h_advance(h, 1000);
	hb1 = dmc_h_var(h, "hbdmc");
	/* one heartbeat step per mainms, within two periods over 2 s */
	assert_true(fabs((hb1 - hb0) - 2000 / mainms) <= 2);
	for (int i = 0; i < DMC_H_AXES; i++) {
		struct ctrl_axis_info ai = dmc_h_axis(h, i);

		assert_int_equal(ai.motor_off, 1);
		assert_true(fabs(ai.enc - pos[i]) < 1);
	}
	assert_true(dmc_h_var(h, "state") == 0);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* Power-up with the program burned (BP): #AUTO runs by itself, BOOT is
 * sent, the motors stay off and the program waits unarmed. */
static void test_power_up(void **state)
{
	struct dmc_h *h = *state;
	double hb;

	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_cmd(h, "BP", NULL, 0));
	DMC_H_CHECK(h, dmc_h_control(h, "power-cycle"));
	ctrl_handle_open(h->ctrl, 0);
	DMC_H_CHECK(h, dmc_h_cmd(h, "CF A", NULL, 0));
	dmc_h_advance(h, 100);
	assert_true(dmc_h_var(h, "state") == 0);
	hb = dmc_h_var(h, "hbdmc");
	assert_true(hb >= 5);
	dmc_h_advance(h, 100);
	assert_true(dmc_h_var(h, "hbdmc") > hb);
	assert_int_equal(ctrl_threads(h->ctrl), 1u);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
}

/* An arm request before the supervisor wrote the soft limits (the other
 * parameters are sealed in the program): refused with fault 1, check 6
 * (srev < sfwd, axis A), motors stay off. */
static void test_arm_without_parameters(void **state)
{
	struct dmc_h *h = *state;
	int code = 0, axis = 0;
	double det = 0;

	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	assert_int_equal(dmc_h_arm(h), GL_ERR_CTRL);
	assert_true(dmc_h_var(h, "state") == 2);
	assert_true(dmc_h_var(h, "fcode") == 1);
	assert_true(dmc_h_var(h, "faxis") == 1);
	assert_true(dmc_h_var(h, "fdet") == 6);
	assert_int_equal(dmc_h_fault_lines(h, &code, &axis, &det), 1);
	assert_int_equal(code, 1);
	assert_int_equal(axis, 1);
	assert_true(det == 6);
	assert_int_equal(ctrl_threads(h->ctrl), 1u);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
}

/* Good parameters: armed, motors on, thread 1 running, ARMED sent,
 * AC/DC = 10 * vmax, nothing moving. */
static void test_arm(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	char resp[64];

	dmc_h_params_default(&p);
	DMC_H_CHECK(h, dmc_h_setup(h));
	dmc_h_advance(h, 100);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_true(dmc_h_unsol_has(h, "ARMED"));
	assert_int_equal(ctrl_threads(h->ctrl) & 3u, 3u);
	for (int i = 0; i < DMC_H_AXES; i++) {
		struct ctrl_axis_info ai = dmc_h_axis(h, i);
		char q[16];

		assert_int_equal(ai.motor_off, 0);
		assert_int_equal(ai.moving, 0);
		snprintf(q, sizeof(q), "MG _AC%c", 'A' + i);
		DMC_H_CHECK(h, dmc_h_cmd(h, q, resp, sizeof(resp)));
		assert_true(fabs(atof(resp) - 10 * p.vmax[i]) < 1024);
		snprintf(q, sizeof(q), "MG _DC%c", 'A' + i);
		DMC_H_CHECK(h, dmc_h_cmd(h, q, resp, sizeof(resp)));
		assert_true(fabs(atof(resp) - 10 * p.vmax[i]) < 1024);
	}
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* The record fields: ZAA = hbdmc, ZAB state/fault, ZAC joystick/motion. */
static void test_record_fields(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_za za;

	DMC_H_CHECK(h, dmc_h_setup(h));
	dmc_h_advance(h, 50);
	DMC_H_CHECK(h, dmc_h_za(h, &za));
	assert_int_equal(za.state, 1);
	assert_int_equal(za.fcode, 0);
	assert_int_equal(za.faxis, 0);
	assert_int_equal(za.jraw, 0);
	assert_int_equal(za.jcmd, 0);
	assert_int_equal(za.mcmd, 0);
	assert_int_equal(za.mneut, 1); /* thread 1 saw neutral (2.10) */
	/* published every mainms: at most one step behind */
	assert_true(dmc_h_var(h, "hbdmc") - za.hbdmc <= 1);
	assert_true(za.hbdmc > 0);

	DMC_H_CHECK(h, dmc_h_control(h, "joy B rev")); /* command 3 */
	dmc_h_advance(h, 100);
	DMC_H_CHECK(h, dmc_h_za(h, &za));
	assert_int_equal(za.jraw, 3 * 4 * 4 * 4);
	assert_int_equal(za.jcmd, 4);
	assert_int_equal(za.mcmd, 4);
	assert_int_equal(za.mneut, 1);
	assert_int_equal(za.state, 1);

	DMC_H_CHECK(h, dmc_h_control(h, "joy B rev a")); /* invalid */
	dmc_h_advance(h, 50);
	DMC_H_CHECK(h, dmc_h_za(h, &za));
	assert_int_equal(za.jraw, 1 << 6);
	assert_int_equal(za.jcmd, -1);
	assert_int_equal(za.mcmd, 0);

	DMC_H_CHECK(h, dmc_h_set(h, "pcflt", 1)); /* fault 12 */
	dmc_h_advance(h, 50);
	DMC_H_CHECK(h, dmc_h_za(h, &za));
	assert_int_equal(za.state, 2);
	assert_int_equal(za.fcode, 12);
	assert_int_equal(za.faxis, 0);
}

/* A command held while arming is ignored until the joystick has been
 * released once; the record says so (mneut 0 with the command), so that
 * the supervisor can tell the operator, and mneut 1 once released. */
static void test_held_at_arm(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	struct dmc_h_za za;
	double a0;

	dmc_h_params_default(&p);
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	DMC_H_CHECK(h, dmc_h_configure(h, &p));
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	DMC_H_CHECK(h, dmc_h_arm(h));
	a0 = axis_pos(h, 0);
	dmc_h_advance(h, 1000);
	assert_true(fabs(axis_pos(h, 0) - a0) < 1);
	assert_true(dmc_h_var(h, "mcmd") == 0);
	assert_true(dmc_h_var(h, "state") == 1);
	DMC_H_CHECK(h, dmc_h_za(h, &za));
	assert_int_equal(za.state, 1);
	assert_int_equal(za.jcmd, 1);
	assert_int_equal(za.mcmd, 0);
	assert_int_equal(za.mneut, 0);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A neutral"));
	dmc_h_advance(h, 100);
	DMC_H_CHECK(h, dmc_h_za(h, &za));
	assert_int_equal(za.jcmd, 0);
	assert_int_equal(za.mneut, 1);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 500);
	assert_true(axis_pos(h, 0) - a0 > 500);
}

/* Armed again after an orderly switch-off, with the joystick held: from
 * the first record that shows the armed state, mneut is 0 (the previous
 * arming's 1 is never published with state 1), and stays 0. */
static void test_rearm_held(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_za za;
	double mainms, t0;

	DMC_H_CHECK(h, dmc_h_setup(h));
	dmc_h_advance(h, 50);
	DMC_H_CHECK(h, dmc_h_za(h, &za));
	assert_int_equal(za.mneut, 1);
	mainms = dmc_h_var(h, "mainms");
	DMC_H_CHECK(h, dmc_h_set(h, "offreq", 1));
	assert_true(dmc_h_wait_var(h, "state", 0, 3 * mainms) >= 0);
	DMC_H_CHECK(h, dmc_h_control(h, "joy C rev"));
	dmc_h_advance(h, 2 * mainms);
	DMC_H_CHECK(h, dmc_h_set(h, "armreq", 1));
	t0 = dmc_h_now(h);
	do {
		dmc_h_advance(h, 1);
		DMC_H_CHECK(h, dmc_h_za(h, &za));
	} while (za.state != 1 && dmc_h_now(h) - t0 < 1000);
	assert_int_equal(za.state, 1);
	assert_int_equal(za.mneut, 0);
	dmc_h_advance(h, 200);
	DMC_H_CHECK(h, dmc_h_za(h, &za));
	assert_int_equal(za.state, 1);
	assert_int_equal(za.jcmd, 6);
	assert_int_equal(za.mcmd, 0);
	assert_int_equal(za.mneut, 0);
}

/* Only HX + XQ #AUTO,0 clears a latched fault; the program then arms
 * again with fresh parameters. */
static void test_restart_clears_latch(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;

	dmc_h_params_default(&p);
	DMC_H_CHECK(h, dmc_h_setup(h));
	DMC_H_CHECK(h, dmc_h_set(h, "pcflt", 1));
	dmc_h_advance(h, 50);
	assert_true(dmc_h_var(h, "state") == 2);
	assert_true(dmc_h_var(h, "fcode") == 12);
	/* an arm request does not clear it */
	DMC_H_CHECK(h, dmc_h_set(h, "pcflt", 0));
	DMC_H_CHECK(h, dmc_h_set(h, "armreq", 1));
	dmc_h_advance(h, 100);
	assert_true(dmc_h_var(h, "state") == 2);
	/* the supervisor restarts the program */
	DMC_H_CHECK(h, dmc_h_cmd(h, "HX", NULL, 0));
	DMC_H_CHECK(h, dmc_h_start(h));
	assert_true(dmc_h_var(h, "state") == 0);
	assert_true(dmc_h_var(h, "fcode") == 0);
	assert_true(dmc_h_var(h, "vmax[0]") == 10000); /* sealed */
	assert_true(dmc_h_var(h, "sfwd[0]") == 0);     /* the session's */
	DMC_H_CHECK(h, dmc_h_configure(h, &p));
	DMC_H_CHECK(h, dmc_h_arm(h));
	assert_int_equal(dmc_h_axis(h, 0).motor_off, 0);
}

/* In service the supervisor may run an axis into its limit switch (as
 * the calibration does: fast far from it, slowly where the potentiometer
 * says it is near) without a latch; arming on the switch is refused with
 * fault 5 (axis A, forward). */
static void test_limit_service_then_arm(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double t;

	dmc_h_params_default(&p);
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	DMC_H_CHECK(h, dmc_h_configure(h, &p));
	DMC_H_CHECK(h, dmc_h_service(h));
	DMC_H_CHECK(h, dmc_h_move(h, 0, 30000, p.svmax[0], 10000));
	for (t = 0; t < 5000 && dmc_h_var(h, "own[0]") != 0; t += 10)
		dmc_h_advance(h, 10);
	assert_true(fabs(dmc_h_axis(h, 0).enc - 30000) < 2);
	DMC_H_CHECK(h, dmc_h_move(h, 0, 60000, p.svslow[0], 20000));
	for (t = 0; t < 15000 && !dmc_h_axis(h, 0).fwd_limit; t += 10)
		dmc_h_advance(h, 10);
	assert_true(dmc_h_axis(h, 0).fwd_limit);
	dmc_h_advance(h, 500);
	assert_int_equal(dmc_h_axis(h, 0).moving, 0);
	assert_true(dmc_h_var(h, "own[0]") == 0);
	assert_true(dmc_h_var(h, "state") == 3);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
	assert_int_equal(dmc_h_arm(h), GL_ERR_CTRL);
	assert_true(dmc_h_var(h, "fcode") == 5);
	assert_true(dmc_h_var(h, "faxis") == 1);
	assert_true(dmc_h_var(h, "fdet") == 2);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_safe_start, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_power_up, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_arm_without_parameters,
					    dmc_h_fx_new, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_arm, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_record_fields, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_rearm_held, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_held_at_arm, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_restart_clears_latch,
					    dmc_h_fx_new, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_limit_service_then_arm,
					    dmc_h_fx_new, dmc_h_fx_free),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
