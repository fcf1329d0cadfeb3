/*
 * test_re_plan.c - every limit the supervisor and the controller program
 * work with, derived from the configuration (pc/config/re_plan.c): the
 * potentiometer zones in volts, the service speeds and the longest move,
 * the heartbeat step, the watchdog, settle and grace times, and the
 * supervisor's settings made from them. Exact values for the shipped
 * defaults and for a variant.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "re_config.h"
#include "re_plan.h"

#define MS 1000000LL

static const char *const names[RE_AXES] = {"A", "B", "C"};

static void near(double got, double want)
{
	if (fabs(got - want) > 1e-9)
		fail_msg("got %.12g, want %.12g", got, want);
}

/* The built-in defaults (galil-sim's robot): A and B travel 100000
 * counts, C 80000, the pot 0.5..4.5 V within 0.25 V, near margin 2000
 * counts, vmax 8000, period 50 ms, wdto 200 ms, critical 2.5. */
static void test_plan_defaults(void **state)
{
	struct re_config c;
	struct re_plan p;

	(void)state;
	re_config_defaults(&c);
	re_plan_make(&c, 0, &p);
	near(p.axis[0].gain_v_per_count, 4.0 / 100000);
	near(p.axis[2].gain_v_per_count, 4.0 / 80000);
	near(p.axis[0].margin_v, 0.08);
	near(p.axis[2].margin_v, 0.1);
	near(p.axis[0].potlo_v, 0.5 - 0.25 - 0.08);
	near(p.axis[0].pothi_v, 4.5 + 0.25 + 0.08);
	/* the slow zone: one pass (10 ms) and the braking distance at
	 * svmax 8000 (8000 / 20), in volts, plus the 5 mV noise margin:
	 * 0.0242 V, less than near_margin_counts (0.08 V), which it is then */
	near(p.axis[0].zone_v, 0.08);
	near(p.axis[0].pnlo_v, 0.5 + 0.25 + 0.08);
	near(p.axis[0].pnhi_v, 4.5 - 0.25 - 0.08);
	near(p.axis[2].pnlo_v, 0.5 + 0.25 + 0.1);
	/* a small near margin: the stopping distance rules */
	c.calibration.near_margin_counts = 100;
	re_plan_make(&c, 0, &p);
	near(p.axis[0].zone_v, (80 + 400) * 4.0 / 100000 + 0.005);
	near(p.axis[2].pnlo_v, 0.5 + 0.25 + 480 * 4.0 / 80000 + 0.005);
	c.calibration.near_margin_counts = 2000;
	re_plan_make(&c, 0, &p);
	assert_int_equal(p.axis[0].travel_cps, 8000); /* 0: vmax */
	assert_int_equal(p.axis[0].seek_cps, 4000);   /* 0: vmax / 2 */
	assert_int_equal(p.axis[0].svmax_cps, 8000);
	/* travel x 1.1 + 2 back-offs + 2 near margins */
	assert_int_equal(p.axis[0].svdmax_counts, 110000 + 1000 + 4000);
	assert_int_equal(p.axis[2].svdmax_counts, 88000 + 1000 + 4000);
	assert_int_equal(p.wdto_ms, 200);
	/* ceil(200 / 2) + 2: at the shortest period, whatever the configured
	 * one (the program holds it sealed) */
	assert_int_equal(p.hbmaxd, 102);
	assert_int_equal(p.pwrout, 0);
	assert_int_equal(p.move_timeout_ms, 30000);
	assert_int_equal(p.period_ns, 50 * MS);
	assert_int_equal(p.sample_ns, 10 * MS);
	assert_int_equal(p.sample_limit_ns, 125 * MS);
	assert_int_equal(p.hb_limit_ns, 125 * MS); /* 2.5 x max(50, 10) */
	assert_int_equal(p.settle_ms, 25);	   /* 2 x 10 + 5 */
	/* (2 x 10 + 100 + 50) ms + 2 periods */
	assert_int_equal(p.uncmd_grace_ns, 270 * MS);
	assert_int_equal(p.fresh_stop_ms, 200);
	assert_int_equal(p.relay_off_ms, 50);
}

/* A variant: a slower program loop (mainms 30), a 2 ms period, explicit
 * calibration speeds, a power output, another pot. */
static void test_plan_variant(void **state)
{
	struct re_config c;
	struct re_plan p;
	struct re_super_cfg sc;

	(void)state;
	re_config_defaults(&c);
	c.period_ms = 2;
	c.watchdog.controller_timeout_ms = 125;
	c.controller.power_output = 3;
	c.calibration.travel_cps = 30000;
	c.calibration.seek_cps = 5000;
	c.calibration.near_margin_counts = 1000;
	c.axes[1].analog.reverse_v = 1.0;
	c.axes[1].analog.forward_v = 9.0;
	c.axes[1].analog.absolute_tolerance_v = 0.5;
	re_plan_make(&c, 30, &p);
	assert_int_equal(p.axis[0].travel_cps, 30000);
	assert_int_equal(p.axis[0].seek_cps, 5000);
	assert_int_equal(p.axis[0].svmax_cps, 30000);
	near(p.axis[1].gain_v_per_count, 8.0 / 100000);
	near(p.axis[1].margin_v, 0.08);
	/* svmax 30000, mainms 30: 900 + 1500 counts x 8e-5 V + 5 mV (more
	 * than near_margin_counts' 0.08 V) */
	near(p.axis[1].pnlo_v, 1.0 + 0.5 + 2400 * 8.0 / 100000 + 0.005);
	near(p.axis[1].potlo_v, 1.0 - 0.5 - 0.08);
	assert_int_equal(p.hbmaxd, 125 / 2 + 1 + 2); /* ceil(125 / 2) + 2 */
	assert_int_equal(p.pwrout, 3);
	/* the heartbeat limit follows the slower of the period and mainms */
	assert_int_equal(p.hb_limit_ns, (int64_t)(2.5 * 30 * MS));
	assert_int_equal(p.sample_limit_ns, 5 * MS);
	assert_int_equal(p.sample_ns, 2 * MS); /* never slower than P */
	assert_int_equal(p.settle_ms, 65);
	assert_int_equal(p.uncmd_grace_ns, (60 + 150) * MS + 4 * MS);
	re_plan_super_cfg(&p, &c, names, &sc);
	assert_int_equal(sc.n_axes, RE_AXES);
	assert_int_equal(sc.period_ns, 2 * MS);
	assert_int_equal(sc.alive.hb_limit_ns, p.hb_limit_ns);
	assert_int_equal(sc.settle_ms, 65);
	assert_int_equal(sc.fresh_stop_ms, 200);
	assert_int_equal(sc.relay_off_ms, 50);
	assert_int_equal(sc.pot_input[2], 3);
	assert_string_equal(sc.axis_names[1], "B");
	assert_string_equal(sc.mode_name, "clinical");
}

/* The seek speed never above the service limit; never 0. */
static void test_plan_seek_clamped(void **state)
{
	struct re_config c;
	struct re_plan p;

	(void)state;
	re_config_defaults(&c);
	c.axes[0].vmax_cps = 1;
	re_plan_make(&c, 10, &p);
	assert_int_equal(p.axis[0].seek_cps, 1);
	c.calibration.seek_cps = 50000;
	c.calibration.travel_cps = 20000;
	re_plan_make(&c, 10, &p);
	assert_int_equal(p.axis[0].svmax_cps, 50000);
	assert_int_equal(p.axis[0].seek_cps, 50000);
}

/* The record stream's interval: a quarter of the period in whole samples
 * of a DMC-40x0 at TM 1000 (976 563 ns), never below 2 (docs/link.md). */
static void test_plan_stream_n0(void **state)
{
	static const struct {
		int period_ms;
		unsigned n0;
	} cases[] = {
	    /* from the fastest cycle: the calibration's 10 ms when the
	     * period is longer (a quarter: 2.5 ms, 2.56 samples) */
	    {50, 2},
	    {10, 2}, /* 2.5 ms: 2.56 */
	    {2, 2},  /* 0.5 ms: 0.51, raised to the minimum */
	    {100, 2},
	    {20, 2},
	};
	struct re_config c;
	struct re_plan p;

	(void)state;
	for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		re_config_defaults(&c);
		c.period_ms = cases[i].period_ms;
		re_plan_make(&c, 0, &p);
		assert_int_equal(p.ctl_sample_ns, 976563);
		assert_int_equal(p.stream_n0, cases[i].n0);
		/* critical (2.5 P) + P + two passes of 10 ms + n0 samples */
		assert_int_equal(p.echo_limit_ns,
				 (int64_t)(3.5 * cases[i].period_ms * MS) +
				     20 * MS + 2 * 976563);
	}
	/* galil-sim's 1 ms sample: 12.5 samples at 50 ms, 2.5 at 10 ms */
	assert_int_equal(re_plan_stream_n0(50 * MS, 1000000), 12);
	assert_int_equal(re_plan_stream_n0(10 * MS, 1000000), 2);
	assert_int_equal(re_plan_stream_n0(2 * MS, 1000000), 2);
	assert_int_equal(re_plan_stream_n0(16 * MS, 1000000), 4);
	assert_int_equal(re_plan_stream_n0(0, 1000000), 2);
	assert_int_equal(re_plan_stream_n0(50 * MS, 0), 2);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_plan_defaults),
	    cmocka_unit_test(test_plan_variant),
	    cmocka_unit_test(test_plan_seek_clamped),
	    cmocka_unit_test(test_plan_stream_n0),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
