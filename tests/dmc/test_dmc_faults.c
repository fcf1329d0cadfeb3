/*
 * test_dmc_faults.c - error routines, the latched fault and the "stops by
 * itself" property.
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

/* The fault latched in the program and reported by exactly one line. */
static void assert_fault(struct dmc_h *h, int code, int axis)
{
	int c = -1, a = -1;

	if (dmc_h_var(h, "fcode") != code || dmc_h_var(h, "faxis") != axis)
		fail_msg("fault %g axis %g (detail %g), want %d axis %d",
			 dmc_h_var(h, "fcode"), dmc_h_var(h, "faxis"),
			 dmc_h_var(h, "fdet"), code, axis);
	assert_true(dmc_h_var(h, "state") == 2);
	assert_int_equal(dmc_h_fault_lines(h, &c, &a, NULL), 1);
	assert_int_equal(c, code);
	assert_int_equal(a, axis);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
}

/* A jammed axis during motion: the position error passes ER (< stp), OE
 * switches the motor off, #POSERR latches fault 4 on that axis. */
static void test_jam(void **state)
{
	struct dmc_h *h = *state;
	double t;

	DMC_H_CHECK(h, dmc_h_control(h, "joy B fwd"));
	dmc_h_advance(h, 300);
	DMC_H_CHECK(h, dmc_h_control(h, "block B 1"));
	/* at vmin = 2500 counts/s the error reaches ER = 500 in 0.2 s */
	t = dmc_h_wait_motor_off(h, 2, 400);
	assert_true(t >= 0 && t <= 260);
	dmc_h_advance(h, 20);
	assert_fault(h, 4, 2);
	/* OE switched it off as the error passed ER: fdet = ER (500), or the
	 * error itself if it was read above ER */
	assert_true(fabs(dmc_h_var(h, "fdet")) >= 500);
	assert_true(fabs(dmc_h_var(h, "fdet")) <= 1000);
}

/* The jam at every phase of the 10 ms motion loop, with ER 500 and 800
 * (the system tests' setting): OE switches the motor off while thread 1
 * may be about to retarget it, and that retarget then fails with TC 20.
 * The fault latched must always be the position error (4) on that axis,
 * never a command error (6): #CMDERR passes a TC 20 on a protected axis
 * on as the protection's fault. */
static void test_jam_any_phase(void **state)
{
	static const double ers[] = {500, 800};

	(void)state;
	for (int e = 0; e < 2; e++) {
		for (int phase = 0; phase < 10; phase++) {
			static struct dmc_h h;
			struct dmc_h_params p;

			memset(&h, 0, sizeof(h));
			dmc_h_params_default(&p);
			for (int i = 0; i < DMC_H_AXES; i++)
				p.er[i] = ers[e];
			if (dmc_h_open(&h) < 0 || dmc_h_start(&h) < 0 ||
			    dmc_h_configure(&h, &p) < 0 || dmc_h_arm(&h) < 0)
				fail_msg("set-up: %s", h.err);
			DMC_H_CHECK(&h, dmc_h_control(&h, "joy A fwd"));
			dmc_h_advance(&h, 300 + phase);
			DMC_H_CHECK(&h, dmc_h_control(&h, "block A 1"));
			assert_true(dmc_h_wait_motor_off(&h, 1, 600) >= 0);
			dmc_h_advance(&h, 30);
			if (dmc_h_var(&h, "fcode") != 4)
				fail_msg("ER %g, jam at +%d ms: fault %g "
					 "(detail %g), want 4",
					 ers[e], phase, dmc_h_var(&h, "fcode"),
					 dmc_h_var(&h, "fdet"));
			assert_fault(&h, 4, 1);
			dmc_h_close(&h);
		}
	}
}

/*
 * Encoder failure (OA on) during motion: the motor runs on while the count
 * stays, so the servo torque rises with no counts; OA switches the motor
 * off with stop code 12 before the position error reaches ER, and thread 0
 * latches fault 9 ENCODER (docs/dmc-interface.md: with OA 1, OT 20 and the
 * default gains OA trips first; otherwise it is fault 4).
 */
static void test_encoder_failure(void **state)
{
	struct dmc_h *h = *state;
	double t;

	/* the robot's configuration: sealed with the program */
	DMC_H_CHECK(h, dmc_h_setup_with(h, "KI 1,1,1;OT 20,20,20;OA 1,1,1"));
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 300);
	DMC_H_CHECK(h, dmc_h_control(h, "enc A stuck"));
	t = dmc_h_wait_motor_off(h, 1, 400);
	assert_true(t >= 0);
	dmc_h_advance(h, dmc_h_var(h, "mainms") + 2);
	assert_fault(h, 9, 1);
	assert_true(dmc_h_var(h, "fdet") == 12);
}

/* No motion while a fault is latched: a pressed joystick moves nothing,
 * and a motor switched on from outside is switched off again at once. */
static void test_latched_no_motion(void **state)
{
	struct dmc_h *h = *state;
	double p0[DMC_H_AXES], t;

	DMC_H_CHECK(h, dmc_h_set(h, "pcflt", 1));
	dmc_h_advance(h, 50);
	assert_fault(h, 12, 0);
	DMC_H_CHECK(h, dmc_h_set(h, "pcflt", 0)); /* the latch stays */
	for (int i = 0; i < DMC_H_AXES; i++)
		p0[i] = dmc_h_axis(h, i).enc;
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 1000);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A neutral"));
	DMC_H_CHECK(h, dmc_h_control(h, "joy C rev"));
	dmc_h_advance(h, 1000);
	DMC_H_CHECK(h, dmc_h_cmd(h, "SH ABC", NULL, 0));
	assert_int_equal(dmc_h_axis(h, 0).motor_off, 0);
	t = dmc_h_wait_motor_off(h, 7, 30);
	assert_true(t >= 0 && t <= dmc_h_var(h, "mainms") + 1);
	DMC_H_CHECK(h, dmc_h_set(h, "armreq", 1));
	dmc_h_advance(h, 500);
	for (int i = 0; i < DMC_H_AXES; i++) {
		assert_true(fabs(dmc_h_axis(h, i).enc - p0[i]) < 1);
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
	}
	assert_true(dmc_h_var(h, "state") == 2);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 1);
}

/* The motion thread halted at full speed: thread 0 latches fault 11
 * within one main loop; the axis travels less than one step. */
static void test_motion_thread_halted(void **state)
{
	struct dmc_h *h = *state;
	double p_hx, t;

	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 2500);
	p_hx = dmc_h_axis(h, 0).enc;
	DMC_H_CHECK(h, dmc_h_cmd(h, "HX1", NULL, 0));
	t = dmc_h_wait_var(h, "state", 2, 100);
	assert_true(t >= 0 && t <= dmc_h_var(h, "mainms") + 1);
	dmc_h_advance(h, 300);
	assert_fault(h, 11, 0);
	assert_int_equal(dmc_h_axis(h, 0).moving, 0);
	assert_true(dmc_h_axis(h, 0).enc - p_hx < dmc_h_var(h, "stp[0]"));
}

/* Every program thread halted at full speed (a dead program): nobody
 * switches the motors off, but the axis stops by itself within one step
 * of where the last target was set. */
static void test_stops_by_itself(void **state)
{
	struct dmc_h *h = *state;
	double p_hx;

	DMC_H_CHECK(h, dmc_h_control(h, "joy B rev"));
	dmc_h_advance(h, 2500);
	assert_true(dmc_h_axis(h, 1).vel < -9000);
	p_hx = dmc_h_axis(h, 1).enc;
	DMC_H_CHECK(h, dmc_h_cmd(h, "HX", NULL, 0));
	dmc_h_advance(h, 500);
	assert_int_equal(ctrl_threads(h->ctrl), 0u);
	assert_int_equal(dmc_h_axis(h, 1).moving, 0);
	assert_true(fabs(dmc_h_axis(h, 1).vel) < 1);
	assert_true(p_hx - dmc_h_axis(h, 1).enc < dmc_h_var(h, "stp[1]"));
	/* and stays there */
	p_hx = dmc_h_axis(h, 1).enc;
	dmc_h_advance(h, 1000);
	assert_true(fabs(dmc_h_axis(h, 1).enc - p_hx) < 1);
}

/* A hardware limit switch reached while armed: fault 5 on that axis,
 * detail 2 (forward). The soft limit is set beyond the switch for this. */
static void test_hard_limit(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double det = 0;

	dmc_h_close(h);
	dmc_h_params_default(&p);
	p.sfwd[2] = 60000; /* beyond the switch at 40000 */
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	DMC_H_CHECK(h, dmc_h_configure(h, &p));
	DMC_H_CHECK(h, dmc_h_arm(h));
	DMC_H_CHECK(h, dmc_h_control(h, "joy C fwd"));
	for (int t = 0; t < 8000 && dmc_h_var(h, "state") == 1; t += 10)
		dmc_h_advance(h, 10);
	dmc_h_advance(h, 20);
	assert_true(dmc_h_axis(h, 2).fwd_limit);
	assert_fault(h, 5, 3);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, &det), 1);
	assert_true(det == 2);
}

/* The controller's soft limit FL reached while jogging is no fault: the
 * axis stops there, #LIMSWI returns, and the axis can be jogged back. */
static void test_soft_limit_fl(void **state)
{
	struct dmc_h *h = *state;

	/* FL set before arming, as the supervisor sets it from the
	 * calibration: a session value the arming seals */
	DMC_H_CHECK(h, dmc_h_setup_with(h, "FL 4000,2147483647,2147483647"));
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 2000);
	assert_int_equal(dmc_h_axis(h, 0).moving, 0);
	assert_true(dmc_h_axis(h, 0).enc <= 4000 + 1000);
	assert_true(dmc_h_var(h, "state") == 1);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A neutral"));
	dmc_h_advance(h, 100);
	DMC_H_CHECK(h, dmc_h_control(h, "joy A rev"));
	dmc_h_advance(h, 1000);
	assert_true(dmc_h_axis(h, 0).enc < 3000);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* A command that fails in the motion thread (a negative speed written over
 * vmin after arming) is caught by #CMDERR: fault 6 with the TC code and
 * the program line; no thread dies silently, thread 0 keeps running. */
static void test_cmderr(void **state)
{
	struct dmc_h *h = *state;
	double hb, det = 0;
	int code = 0;

	DMC_H_CHECK(h, dmc_h_set(h, "vmin[0]", -100));
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	assert_true(dmc_h_wait_var(h, "state", 2, 200) >= 0);
	dmc_h_advance(h, 20);
	assert_fault(h, 6, 0);
	assert_true(dmc_h_var(h, "fdet") > 0);
	assert_true(dmc_h_var(h, "fline") > 0);
	assert_int_equal(dmc_h_fault_lines(h, &code, NULL, &det), 1);
	assert_true(det == dmc_h_var(h, "fdet"));
	hb = dmc_h_var(h, "hbdmc");
	dmc_h_advance(h, 100);
	assert_true(dmc_h_var(h, "hbdmc") > hb);
	assert_int_equal(ctrl_threads(h->ctrl) & 1u, 1u);
}

/* Motor power lost (E-stop relay off) while armed: the motors go off; the
 * program latches fault 8 AMPERR on all axes (axis 0: every axis lost its
 * amplifier, stop code 15), detail 15. */
static void test_power_lost(void **state)
{
	struct dmc_h *h = *state;

	DMC_H_CHECK(h, dmc_h_control(h, "joy C rev"));
	dmc_h_advance(h, 300);
	DMC_H_CHECK(h, dmc_h_control(h, "relay off"));
	assert_true(dmc_h_wait_var(h, "state", 2, 100) >= 0);
	dmc_h_advance(h, 20);
	assert_fault(h, 8, 0);
	assert_true(dmc_h_var(h, "fdet") == 15);
}

/* In the safe state (motors off) motor power lost and restored is only
 * counted: nothing can move, and the supervisor switches the relay on
 * during its start-up before it asks for the service state. */
static void test_power_lost_unarmed(void **state)
{
	struct dmc_h *h = *state;

	dmc_h_close(h);
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	DMC_H_CHECK(h, dmc_h_control(h, "relay off"));
	dmc_h_advance(h, 100);
	DMC_H_CHECK(h, dmc_h_control(h, "relay on"));
	dmc_h_advance(h, 100);
	assert_true(dmc_h_var(h, "state") == 0);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
}

/* In the safe state nothing may switch a motor on: a host's SH is fault
 * 13 (axis 0, detail 3) within one main loop, every motor off again. */
static void test_servo_on_in_safe_state(void **state)
{
	struct dmc_h *h = *state;
	double mainms, t;

	dmc_h_close(h);
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	mainms = dmc_h_var(h, "mainms");
	DMC_H_CHECK(h, dmc_h_cmd(h, "SH B", NULL, 0));
	assert_int_equal(dmc_h_axis(h, 1).motor_off, 0);
	t = dmc_h_wait_var(h, "state", 2, 100);
	assert_true(t >= 0 && t <= mainms + 1);
	dmc_h_advance(h, 5);
	assert_fault(h, 13, 0);
	assert_true(dmc_h_var(h, "fdet") == 3);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
}

/* A TCP handle lost while armed: #TCPERR latches fault 7 with the handle
 * (_IA4) as detail; unarmed it is only counted. */
static void test_tcp_lost(void **state)
{
	struct dmc_h *h = *state;
	double n0 = dmc_h_var(h, "ntcpe");

	ctrl_handle_open(h->ctrl, 2);
	ctrl_handle_lost(h->ctrl, 2); /* handle C */
	assert_true(dmc_h_wait_var(h, "state", 2, 50) >= 0);
	dmc_h_advance(h, 10);
	assert_fault(h, 7, 0);
	assert_true(dmc_h_var(h, "fdet") == 2);
	assert_true(dmc_h_var(h, "ntcpe") == n0 + 1);

	dmc_h_close(h);
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	ctrl_handle_open(h->ctrl, 2);
	ctrl_handle_lost(h->ctrl, 2);
	dmc_h_advance(h, 50);
	assert_true(dmc_h_var(h, "state") == 0);
	assert_true(dmc_h_var(h, "ntcpe") == 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_jam_any_phase),
	    cmocka_unit_test_setup_teardown(test_jam, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_encoder_failure, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_latched_no_motion,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_motion_thread_halted,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_stops_by_itself,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_hard_limit, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_soft_limit_fl, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_cmderr, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_power_lost, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_servo_on_in_safe_state,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_power_lost_unarmed,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_tcp_lost, dmc_h_fx_armed,
					    dmc_h_fx_free),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
