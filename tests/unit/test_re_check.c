/*
 * test_re_check.c - the supervisor's safety checks (pc/super/re_check.c) as
 * pure functions: interpolation at the table ends and between points, tolerance
 * edges, persistence counts, watchdog thresholds at exactly 1.5x / 2.5x the
 * period +- 1 ms, liveness, ZA decoding, controller faults, motor-off
 * detection, calibration checks and the exact FAULT lines.
 *
 * The table values are binary fractions so that interpolated values and
 * tolerance edges are exact doubles and can be compared with ==.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "gl_err.h"
#include "re_calcheck.h"
#include "re_check.h"

#define MS 1000000LL /* ns */

/* Exact double comparison with a readable failure message. */
#define assert_dbl(got, want) assert_dbl_at((got), (want), __FILE__, __LINE__)

static void assert_dbl_at(double got, double want, const char *file, int line)
{
	if (got != want)
		fail_msg("%s:%d: got %.17g, want %.17g", file, line, got, want);
}

/* Points at 1000, 1100, ... 1400 counts; local pot steps 0.25, 0.25,
 * 0.125, 0.375 V. */
static void table5(struct re_caltable *t)
{
	static const double pot[5] = {1.0, 1.25, 1.5, 1.625, 2.0};

	memset(t, 0, sizeof(*t));
	t->n = 5;
	t->start_counts = 1000;
	t->step_counts = 100;
	memcpy(t->pot_v, pot, sizeof(pot));
	t->soft_rev = 1000;
	t->soft_fwd = 1400;
}

static struct re_caltable tbl;

/* ---- interpolation ------------------------------------------------------- */

static void expect_at(double enc, double pot, double step, int seg,
		      enum re_tpos where)
{
	struct re_expect e;

	assert_int_equal(re_cal_expect(&tbl, enc, &e), GL_OK);
	assert_dbl(e.pot_v, pot);
	assert_dbl(e.step_v, step);
	assert_int_equal(e.seg, seg);
	assert_int_equal(e.where, where);
}

static void test_expect_points_and_between(void **state)
{
	(void)state;
	table5(&tbl);
	expect_at(1000, 1.0, 0.25, 0, RE_TPOS_INSIDE); /* first point */
	expect_at(1100, 1.25, 0.25, 1, RE_TPOS_INSIDE);
	expect_at(1300, 1.625, 0.375, 3, RE_TPOS_INSIDE);
	expect_at(1400, 2.0, 0.375, 3, RE_TPOS_INSIDE);	    /* last point */
	expect_at(1050, 1.125, 0.25, 0, RE_TPOS_INSIDE);    /* middle */
	expect_at(1325, 1.71875, 0.375, 3, RE_TPOS_INSIDE); /* quarter */
	expect_at(1275, 1.59375, 0.125, 2, RE_TPOS_INSIDE);
	expect_at(1399.5, 1.625 * 0.005 + 2.0 * 0.995, 0.375, 3,
		  RE_TPOS_INSIDE);
}

static void test_expect_beyond_ends(void **state)
{
	(void)state;
	table5(&tbl);
	/* Extrapolated with the end segment up to one step. */
	expect_at(950, 0.875, 0.25, 0, RE_TPOS_EXTRAP);
	expect_at(900, 0.75, 0.25, 0, RE_TPOS_EXTRAP);
	expect_at(1450, 2.1875, 0.375, 3, RE_TPOS_EXTRAP);
	expect_at(1500, 2.375, 0.375, 3, RE_TPOS_EXTRAP);
	/* Further out: outside (value still the extrapolation). */
	expect_at(800, 0.5, 0.25, 0, RE_TPOS_OUTSIDE);
	expect_at(1600, 2.75, 0.375, 3, RE_TPOS_OUTSIDE);
	{
		struct re_expect e;

		assert_int_equal(re_cal_expect(&tbl, 1501, &e), GL_OK);
		assert_int_equal(e.where, RE_TPOS_OUTSIDE);
		assert_int_equal(re_cal_expect(&tbl, 899.999, &e), GL_OK);
		assert_int_equal(e.where, RE_TPOS_OUTSIDE);
	}
}

static void test_expect_bad_args(void **state)
{
	struct re_expect e;

	(void)state;
	table5(&tbl);
	assert_int_equal(re_cal_expect(NULL, 0, &e), GL_ERR_ARG);
	assert_int_equal(re_cal_expect(&tbl, NAN, &e), GL_ERR_ARG);
	tbl.n = 1;
	assert_int_equal(re_cal_expect(&tbl, 1000, &e), GL_ERR_ARG);
	tbl.n = RE_CAL_MAX_POINTS + 1;
	assert_int_equal(re_cal_expect(&tbl, 1000, &e), GL_ERR_ARG);
	table5(&tbl);
	tbl.step_counts = 0;
	assert_int_equal(re_cal_expect(&tbl, 1000, &e), GL_ERR_ARG);
	tbl.step_counts = -100;
	assert_int_equal(re_cal_expect(&tbl, 1000, &e), GL_ERR_ARG);
}

/* ---- encoder / pot check --------------------------------------------------*/

static const struct re_encpot_cfg cfg1 = {0.5, 1};

static int encpot(const struct re_encpot_cfg *c, double enc, double pot,
		  struct re_encpot_state *st, struct re_encpot_result *r,
		  struct re_fault *f)
{
	return re_check_encpot(&tbl, c, 0, enc, pot, st, r, f);
}

static void test_encpot_tolerance_edges(void **state)
{
	struct re_encpot_state st = {0};
	struct re_encpot_result r;
	struct re_fault f;
	const struct re_encpot_cfg c0 = {0.5, 0}; /* trip at once */

	(void)state;
	table5(&tbl);
	/* At 1050: expected 1.125, step 0.25, tolerance 1.5 x 0.25. */
	assert_int_equal(encpot(&c0, 1050, 1.125, &st, &r, &f), RE_OK);
	assert_dbl(r.exp.pot_v, 1.125);
	assert_dbl(r.tol_v, 0.375);
	assert_dbl(r.diff_v, 0);
	assert_dbl(r.margin_v, 0.375);
	/* Exactly at the tolerance: still within (fault is "> tol"). */
	assert_int_equal(encpot(&c0, 1050, 1.5, &st, &r, &f), RE_OK);
	assert_dbl(r.margin_v, 0);
	assert_int_equal(r.violating, 0);
	assert_int_equal(encpot(&c0, 1050, 0.75, &st, &r, &f), RE_OK);
	/* Just inside, just outside, both directions. */
	assert_int_equal(encpot(&c0, 1050, 1.5 - 1e-9, &st, &r, &f), RE_OK);
	assert_int_equal(encpot(&c0, 1050, 0.75 + 1e-9, &st, &r, &f), RE_OK);
	assert_int_equal(encpot(&c0, 1050, 1.5 + 1e-9, &st, &r, &f), RE_FAULT);
	assert_true(r.margin_v < 0 && r.margin_v > -2e-9);
	assert_int_equal(r.violating, 1);
	st.violations = 0;
	assert_int_equal(encpot(&c0, 1050, 0.75 - 1e-9, &st, &r, &f), RE_FAULT);
	/* The tolerance follows the local segment: 0.125 x 1.5 at 1250. */
	st.violations = 0;
	assert_int_equal(encpot(&c0, 1250, 1.5625 + 0.1875, &st, &r, &f),
			 RE_OK);
	assert_dbl(r.tol_v, 0.1875);
	assert_int_equal(encpot(&c0, 1250, 1.5625 + 0.1875 + 1e-9, &st, &r, &f),
			 RE_FAULT);
	/* allowed_error 0: tolerance = the step itself. */
	{
		const struct re_encpot_cfg cz = {0, 0};

		st.violations = 0;
		assert_int_equal(encpot(&cz, 1000, 1.25, &st, &r, &f), RE_OK);
		assert_int_equal(encpot(&cz, 1000, 1.25 + 1e-9, &st, &r, &f),
				 RE_FAULT);
	}
}

static void test_encpot_at_table_ends(void **state)
{
	struct re_encpot_state st = {0};
	struct re_encpot_result r;
	struct re_fault f;
	const struct re_encpot_cfg c0 = {0.5, 0};

	(void)state;
	table5(&tbl);
	/* Last point: expected 2.0, end segment step 0.375, tol 0.5625. */
	assert_int_equal(encpot(&c0, 1400, 2.5625, &st, &r, &f), RE_OK);
	assert_dbl(r.tol_v, 0.5625);
	assert_int_equal(encpot(&c0, 1400, 2.5625 + 1e-9, &st, &r, &f),
			 RE_FAULT);
	/* One step beyond: extrapolated 2.375 and checked normally. */
	st.violations = 0;
	assert_int_equal(encpot(&c0, 1500, 2.375, &st, &r, &f), RE_OK);
	assert_int_equal(r.exp.where, RE_TPOS_EXTRAP);
	/* Further out: a violation whatever the pot says. */
	assert_int_equal(encpot(&c0, 1501, 2.375375, &st, &r, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_ENC_OUTSIDE);
	assert_int_equal(f.i[0], 1501);
	assert_int_equal(f.i[1], 1000);
	assert_int_equal(f.i[2], 1400);
	st.violations = 0;
	assert_int_equal(encpot(&c0, 899, 0.7475, &st, &r, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_ENC_OUTSIDE);
	/* First point from below: 900 extrapolates to 0.75. */
	st.violations = 0;
	assert_int_equal(encpot(&c0, 900, 0.75, &st, &r, &f), RE_OK);
}

static void test_encpot_persistence(void **state)
{
	struct re_encpot_state st = {0};
	struct re_encpot_result r;
	struct re_fault f;

	(void)state;
	table5(&tbl);
	/* Persistence 1 (the default): trips on the 2nd consecutive cycle. */
	assert_int_equal(encpot(&cfg1, 1050, 2.0, &st, &r, &f), RE_OK);
	assert_int_equal(r.violations, 1);
	assert_int_equal(st.violations, 1);
	assert_int_equal(encpot(&cfg1, 1050, 2.0, &st, &r, &f), RE_FAULT);
	assert_int_equal(r.violations, 2);
	assert_int_equal(f.id, RE_F_ENCPOT);
	assert_int_equal(f.axis, 0);
	assert_int_equal(f.i[0], 1050);
	assert_int_equal(f.i[1], 2);
	assert_dbl(f.f[0], 2.0);
	assert_dbl(f.f[1], 1.125);
	assert_dbl(f.f[2], 0.875);
	assert_dbl(f.f[3], 0.375);
	/* A good cycle in between resets the count. */
	memset(&st, 0, sizeof(st));
	assert_int_equal(encpot(&cfg1, 1050, 2.0, &st, &r, &f), RE_OK);
	assert_int_equal(encpot(&cfg1, 1050, 1.125, &st, &r, &f), RE_OK);
	assert_int_equal(st.violations, 0);
	assert_int_equal(encpot(&cfg1, 1050, 2.0, &st, &r, &f), RE_OK);
	assert_int_equal(st.violations, 1);
	/* Persistence 3: OK for 3 violating cycles, fault on the 4th. */
	{
		const struct re_encpot_cfg c3 = {0.5, 3};
		int k;

		memset(&st, 0, sizeof(st));
		for (k = 1; k <= 3; k++) {
			assert_int_equal(encpot(&c3, 1050, 0.5, &st, &r, &f),
					 RE_OK);
			assert_int_equal(r.violations, k);
		}
		assert_int_equal(encpot(&c3, 1050, 0.5, &st, &r, &f), RE_FAULT);
		assert_int_equal(f.i[1], 4);
	}
}

static void test_encpot_bad_args(void **state)
{
	struct re_encpot_state st = {5};
	struct re_encpot_cfg c = {-0.1, 1};

	(void)state;
	table5(&tbl);
	assert_int_equal(encpot(&c, 1050, 1.0, &st, NULL, NULL), GL_ERR_ARG);
	c.allowed_error = 0.5;
	c.persistence_cycles = -1;
	assert_int_equal(encpot(&c, 1050, 1.0, &st, NULL, NULL), GL_ERR_ARG);
	assert_int_equal(st.violations, 5); /* untouched */
	/* A NaN potentiometer reading is a violation, not OK. */
	c.persistence_cycles = 0;
	assert_int_equal(encpot(&c, 1050, NAN, &st, NULL, NULL), RE_FAULT);
	{
		struct re_fault f;

		st.violations = 0;
		assert_int_equal(encpot(&c, NAN, 1.0, &st, NULL, &f), RE_FAULT);
		assert_int_equal(f.id, RE_F_ENC_OUTSIDE);
		assert_int_equal(f.i[0], RE_VAL_UNKNOWN);
		st.violations = 0;
		assert_int_equal(encpot(&c, INFINITY, 1.0, &st, NULL, &f),
				 RE_FAULT);
	}
}

/* ---- watchdog
 * --------------------------------------------------------------*/

static const struct re_wdog_cfg wdc = {50 * MS, 1.5, 2.5};
static const struct re_wdog_lim wd = {75 * MS, 125 * MS};

static int age_verdict(int64_t age_ns)
{
	const int64_t last = 1000 * MS;

	return re_check_reply_age(&wd, last, last + age_ns, NULL, NULL);
}

static void test_wdog_thresholds(void **state)
{
	struct re_wdog_lim lim;

	(void)state;
	assert_int_equal(re_wdog_limits(&wdc, &lim), GL_OK);
	assert_int_equal(lim.noncrit_ns, 75 * MS);
	assert_int_equal(lim.crit_ns, 125 * MS);
	assert_int_equal(age_verdict(0), RE_OK);
	assert_int_equal(age_verdict(74 * MS), RE_OK);
	assert_int_equal(age_verdict(75 * MS), RE_OK); /* exactly 1.5 x */
	assert_int_equal(age_verdict(75 * MS + 1), RE_WARN);
	assert_int_equal(age_verdict(76 * MS), RE_WARN);
	assert_int_equal(age_verdict(124 * MS), RE_WARN);
	assert_int_equal(age_verdict(125 * MS), RE_WARN); /* exactly 2.5 x */
	assert_int_equal(age_verdict(125 * MS + 1), RE_FAULT);
	assert_int_equal(age_verdict(126 * MS), RE_FAULT);
}

static void test_wdog_fault_text(void **state)
{
	struct re_fault f;
	int64_t age;
	char line[512];

	(void)state;
	assert_int_equal(re_check_reply_age(&wd, 5 * MS, 131 * MS, &age, &f),
			 RE_FAULT);
	assert_int_equal(age, 126 * MS);
	assert_int_equal(f.id, RE_F_WDOG_REPLY);
	assert_int_equal(re_fault_class(f.id), RE_FC_WATCHDOG);
	assert_true(re_fault_format(&f, NULL, line, sizeof(line)) > 0);
	assert_string_equal(
	    line,
	    "FAULT WATCHDOG: no reply from the controller for 126 ms (limit "
	    "125 ms). Recovery: press the E-stop and keep it pressed, check "
	    "the controller's Ethernet cable and power, then restart roboelf");
}

static void test_wdog_other_periods_and_args(void **state)
{
	struct re_wdog_cfg c = {2 * MS, 1.5, 2.5};
	struct re_wdog_lim lim, bad = {5 * MS, 3 * MS};

	(void)state;
	assert_int_equal(re_wdog_limits(&c, &lim), GL_OK);
	assert_int_equal(lim.noncrit_ns, 3 * MS);
	assert_int_equal(lim.crit_ns, 5 * MS);
	assert_int_equal(re_check_reply_age(&lim, 0, 5 * MS, NULL, NULL),
			 RE_WARN);
	assert_int_equal(re_check_reply_age(&lim, 0, 5 * MS + 1, NULL, NULL),
			 RE_FAULT);
	/* limits in the wrong order are a caller bug */
	assert_int_equal(re_check_reply_age(&bad, 0, 1 * MS, NULL, NULL),
			 GL_ERR_ARG);
	c.noncrit_factor = 0.9;
	assert_int_equal(re_wdog_limits(&c, &lim), GL_ERR_ARG);
	c.noncrit_factor = 3.0; /* above critical */
	assert_int_equal(re_wdog_limits(&c, &lim), GL_ERR_ARG);
	c.noncrit_factor = 1.5;
	c.period_ns = 0;
	assert_int_equal(re_wdog_limits(&c, &lim), GL_ERR_ARG);
	/* Time going backwards is a caller bug. */
	assert_int_equal(re_check_reply_age(&wd, 10 * MS, 9 * MS, NULL, NULL),
			 GL_ERR_ARG);
}

static void test_alive_heartbeat(void **state)
{
	const struct re_alive_cfg c = {125 * MS, 125 * MS};
	struct re_alive_state st;
	struct re_fault f;
	const int64_t t0 = 7000 * MS;

	(void)state;
	re_alive_reset(&st);
	assert_int_equal(re_check_alive(&c, &st, t0, 41, 100, &f), RE_OK);
	/* Sample advancing, heartbeat unchanged exactly 125 ms: still OK. */
	assert_int_equal(re_check_alive(&c, &st, t0 + 50 * MS, 41, 150, &f),
			 RE_OK);
	assert_int_equal(re_check_alive(&c, &st, t0 + 125 * MS, 41, 225, &f),
			 RE_OK);
	assert_int_equal(
	    re_check_alive(&c, &st, t0 + 125 * MS + 1, 41, 226, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_WDOG_HEARTBEAT);
	assert_int_equal(f.i[0], 41);
	assert_int_equal(f.i[1], 125);
	assert_int_equal(f.i[2], 125);
	/* A change restarts the clock; the wrap 999999 -> 0 is a change. */
	re_alive_reset(&st);
	assert_int_equal(re_check_alive(&c, &st, t0, 999999, 1, &f), RE_OK);
	assert_int_equal(re_check_alive(&c, &st, t0 + 100 * MS, 0, 101, &f),
			 RE_OK);
	assert_int_equal(re_check_alive(&c, &st, t0 + 225 * MS, 0, 226, &f),
			 RE_OK);
	assert_int_equal(re_check_alive(&c, &st, t0 + 226 * MS, 0, 227, &f),
			 RE_FAULT);
	assert_int_equal(f.i[1], 126);
}

static void test_alive_sample(void **state)
{
	const struct re_alive_cfg c = {500 * MS, 125 * MS};
	struct re_alive_state st;
	struct re_fault f;
	char line[512];

	(void)state;
	re_alive_reset(&st);
	assert_int_equal(re_check_alive(&c, &st, 0, 1, 65535, &f), RE_OK);
	assert_int_equal(re_check_alive(&c, &st, 60 * MS, 2, 65535, &f), RE_OK);
	assert_int_equal(re_check_alive(&c, &st, 125 * MS, 3, 65535, &f),
			 RE_OK);
	assert_int_equal(re_check_alive(&c, &st, 126 * MS, 4, 65535, &f),
			 RE_FAULT);
	assert_int_equal(f.id, RE_F_WDOG_SAMPLE);
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_string_equal(
	    line,
	    "FAULT WATCHDOG: the controller's sample counter froze at 65535 "
	    "for 126 ms (limit 125 ms). Recovery: press the E-stop and keep it "
	    "pressed, switch the controller off and on, then restart roboelf");
	assert_int_equal(re_check_alive(&c, &st, 100 * MS, 4, 0, &f),
			 GL_ERR_ARG); /* time went back */
}

/* ---- ZA and the record -------------------------------------------------- */

static void test_za_decode(void **state)
{
	struct re_za z;

	(void)state;
	/* state 2, fault 4 (POSERR) on axis 2 (B) */
	assert_int_equal(re_za_decode(123, 2 + 10 * 4 + 1000 * 2,
				      48 + 4096 * 4 + 32768 * 3, &z),
			 GL_OK);
	assert_int_equal(z.hbdmc, 123);
	assert_int_equal(z.state, 2);
	assert_int_equal(z.fcode, 4);
	assert_int_equal(z.faxis, 2);
	assert_int_equal(z.jraw, 48);
	assert_int_equal(z.jcmd, 3);
	assert_int_equal(z.mcmd, 3);
	assert_int_equal(z.mneut, 0);
	/* 2.10: the joystick seen neutral since arming, with mcmd 6 */
	assert_int_equal(re_za_decode(0, 1, 4096 + 32768 * 6 + 262144, &z),
			 GL_OK);
	assert_int_equal(z.mneut, 1);
	assert_int_equal(z.mcmd, 6);
	assert_int_equal(z.jcmd, 0);
	/* jcmd -1 (invalid input), jraw full 12 bits, fault 12 on axis 3 */
	assert_int_equal(re_za_decode(999999, 2 + 120 + 3000, 4095, &z), GL_OK);
	assert_int_equal(z.jcmd, -1);
	assert_int_equal(z.jraw, 4095);
	assert_int_equal(z.fcode, 12);
	assert_int_equal(z.faxis, 3);
	/* the service state (3) and the version 2.00 fault codes (to 16) */
	assert_int_equal(re_za_decode(0, 3 + 160 + 2000, 0, &z), GL_OK);
	assert_int_equal(z.state, RE_DMC_SERVICE);
	assert_int_equal(z.fcode, 16);
	assert_int_equal(z.faxis, 2);
	/* the seal's fault (17, version 2.20) */
	assert_int_equal(re_za_decode(0, 2 + 170 + 1000, 0, &z), GL_OK);
	assert_int_equal(z.fcode, 17);
	assert_int_equal(z.hb_echo, 0);
	/* 2.23: the heartbeat's echo above them; every field at its largest */
	assert_int_equal(RE_ZAB_MAX, 99993173L);
	assert_int_equal(re_za_decode(0, 3 + 170 + 3000 + 10000L * 9999, 0, &z),
			 GL_OK);
	assert_int_equal(z.state, RE_DMC_SERVICE);
	assert_int_equal(z.fcode, 17);
	assert_int_equal(z.faxis, 3);
	assert_int_equal(z.hb_echo, 9999);
	assert_int_equal(re_za_decode(0, 1 + 10000L * 4321, 0, &z), GL_OK);
	assert_int_equal(z.state, 1);
	assert_int_equal(z.fcode, 0);
	assert_int_equal(z.faxis, 0);
	assert_int_equal(z.hb_echo, 4321);
	assert_int_equal(re_za_decode(0, 2 + 40 + 2000 + 10000, 0, &z), GL_OK);
	assert_int_equal(z.fcode, 4);
	assert_int_equal(z.faxis, 2);
	assert_int_equal(z.hb_echo, 1);
	/* an echo of 10000 or a fourth axis under an echo: not the program's */
	assert_int_equal(re_za_decode(0, 100000000L, 0, &z), GL_ERR_RANGE);
	assert_int_equal(re_za_decode(0, 4000 + 10000L * 5, 0, &z),
			 GL_ERR_RANGE);
	assert_int_equal(re_za_decode(0, INT32_MAX, 0, &z), GL_ERR_RANGE);
	/* the echo the supervisor expects for what it wrote */
	assert_int_equal(re_hb_echo(0), 0);
	assert_int_equal(re_hb_echo(123459999L), 9999);
	assert_int_equal(re_hb_echo(123460000L), 0);
	assert_int_equal(re_hb_echo(999999999L), 9999);
	assert_int_equal(re_hb_echo(1000000000L - 9990), 10);
	assert_int_equal(re_hb_echo(-1), -1);
	/* Out of range fields */
	assert_int_equal(re_za_decode(0, 4, 0, &z), GL_ERR_RANGE);
	assert_int_equal(re_za_decode(0, 180, 0, &z), GL_ERR_RANGE);
	assert_int_equal(re_za_decode(0, 4001, 0, &z), GL_ERR_RANGE);
	assert_int_equal(re_za_decode(0, 0, 7 * 32768, &z), GL_ERR_RANGE);
	assert_int_equal(re_za_decode(0, 0, 4096 * 8, &z), GL_OK); /* mcmd 1 */
	assert_int_equal(re_za_decode(0, 0, 7 * 32768 + 262144, &z),
			 GL_ERR_RANGE);
	assert_int_equal(re_za_decode(0, 0, 2 * 262144, &z), GL_ERR_RANGE);
	assert_int_equal(re_za_decode(-1, 0, 0, &z), GL_ERR_RANGE);
	assert_int_equal(re_za_decode(0, -1, 0, &z), GL_ERR_RANGE);
	assert_int_equal(re_za_decode(0, 0, -1, &z), GL_ERR_RANGE);
	assert_int_equal(re_za_decode(1000000, 0, 0, &z), GL_ERR_RANGE);
	assert_int_equal(re_za_decode(0, 0, 0, NULL), GL_ERR_ARG);
}

static void test_ctrl_fault_mapping(void **state)
{
	static const struct {
		int fcode;
		enum re_fault_id id;
		enum re_fclass cls;
	} map[] = {
	    {1, RE_F_CTRL_PARAM, RE_FC_PARAM},
	    {2, RE_F_CTRL_WATCHDOG, RE_FC_WATCHDOG},
	    {3, RE_F_CTRL_INPUT, RE_FC_INPUT},
	    {4, RE_F_CTRL_POSERR, RE_FC_MOTION},
	    {5, RE_F_CTRL_LIMIT, RE_FC_LIMIT},
	    {6, RE_F_CTRL_CMDERR, RE_FC_PROGRAM},
	    {7, RE_F_CTRL_TCPERR, RE_FC_COMM},
	    {8, RE_F_CTRL_AMPERR, RE_FC_MOTION},
	    {9, RE_F_CTRL_ENCODER, RE_FC_ENCODER},
	    {10, RE_F_CTRL_MOTOROFF, RE_FC_MOTION},
	    {11, RE_F_CTRL_THREAD, RE_FC_PROGRAM},
	    {12, RE_F_CTRL_SUPERVISOR, RE_FC_PROGRAM},
	    {13, RE_F_CTRL_UNCMD, RE_FC_MOTION},
	    {14, RE_F_CTRL_FOREIGN_SET, RE_FC_FOREIGN},
	    {15, RE_F_CTRL_SVCMOVE, RE_FC_MOTION},
	    {16, RE_F_CTRL_POTRANGE, RE_FC_ENCODER},
	    {17, RE_F_CTRL_SEAL, RE_FC_FOREIGN},
	    {18, RE_F_CTRL_UNKNOWN, RE_FC_PROGRAM},
	    {0, RE_F_CTRL_UNKNOWN, RE_FC_PROGRAM},
	};
	struct re_za z = {0};
	struct re_fault f;
	size_t k;

	(void)state;
	for (k = 0; k < sizeof(map) / sizeof(map[0]); k++) {
		z.state = 2;
		z.fcode = map[k].fcode;
		z.faxis = 2;
		assert_int_equal(re_ctrl_fault(&z, 77, &f), GL_OK);
		assert_int_equal(f.id, map[k].id);
		assert_int_equal(re_fault_class(f.id), map[k].cls);
		assert_int_equal(f.axis, 1);
	}
	z.faxis = 0;
	re_ctrl_fault(&z, 77, &f);
	assert_int_equal(f.axis, -1);
	/* AMPERR on no single axis (faxis 0): every amplifier lost power. */
	z.fcode = 8;
	assert_int_equal(re_ctrl_fault(&z, 15, &f), GL_OK);
	assert_int_equal(f.id, RE_F_CTRL_POWER);
	assert_int_equal(re_fault_class(f.id), RE_FC_ESTOP);
	assert_int_equal(f.axis, -1);
}

static void test_ctrl_fault_texts(void **state)
{
	struct re_za z = {0};
	struct re_fault f;
	char line[512];

	(void)state;
	z.state = 2;
	z.fcode = 4;
	z.faxis = 2;
	re_ctrl_fault(&z, 5012, &f);
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_string_equal(
	    line,
	    "FAULT MOTION: axis B: position error of at least 5012 counts, "
	    "above its limit (blocked, jammed, or its encoder stuck?). "
	    "Recovery: press the E-stop and keep it pressed, check that axis "
	    "B moves freely and nothing blocks it, then its encoder cable, "
	    "then restart roboelf");
	z.fcode = 3;
	z.faxis = 0;
	re_ctrl_fault(&z, 0x30c, &f);
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_string_equal(
	    line,
	    "FAULT INPUT: invalid joystick state held longer than the "
	    "invalid-input timeout: A reverse (switches a and b) and C forward "
	    "(switches a and b) closed at once. Recovery: release the "
	    "joysticks, press the E-stop and keep it pressed, check the "
	    "joystick cables and switches, then restart roboelf");
	re_ctrl_fault(&z, 0x10, &f);
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_non_null(strstr(line, "FAULT INPUT: invalid joystick state held "
				     "longer than the invalid-input timeout: "
				     "B forward (switch a only) closed. "));
	re_ctrl_fault(&z, RE_VAL_UNKNOWN, &f);
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_non_null(strstr(line, "FAULT INPUT: invalid joystick state held "
				     "longer than the invalid-input timeout: "
				     "the switches closed are not known. "));
	z.fcode = 5;
	z.faxis = 3;
	re_ctrl_fault(&z, 3, &f);
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_string_equal(
	    line,
	    "FAULT LIMIT: axis C: the reverse hardware limit switch was "
	    "reached. Recovery: press the E-stop and keep it pressed, make "
	    "sure axis C is clear of the patient, check its limit switch, then "
	    "restart roboelf and recalibrate");
	z.fcode = 10;
	z.faxis = 1;
	re_ctrl_fault(&z, 8, &f);
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_non_null(strstr(line, "FAULT MOTION: axis A: the controller "
				     "found the motor off while armed: "
				     "position error above the limit (stop "
				     "code 8). "));
	z.fcode = 0;
	z.faxis = 1;
	re_ctrl_fault(&z, RE_VAL_UNKNOWN, &f);
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_non_null(strstr(line, "FAULT PROGRAM: the controller latched "
				     "unknown fault code 0 (axis 1, detail "
				     "unknown). "));
}

/* The text of program fault @fcode, axis @faxis, detail @det. */
static void v2_line(int fcode, int faxis, long long det, char *line, size_t cap,
		    struct re_fault *f)
{
	struct re_za z = {0};

	z.state = 2;
	z.fcode = fcode;
	z.faxis = faxis;
	assert_int_equal(re_ctrl_fault(&z, det, f), GL_OK);
	re_fault_format(f, NULL, line, cap);
}

/* Version 2.00's faults 13..16: each detail to its own id and words. */
static void test_ctrl_fault_v2(void **state)
{
	struct re_fault f;
	char line[512];

	(void)state;
	v2_line(13, 1, 1, line, sizeof(line), &f);
	assert_int_equal(f.id, RE_F_CTRL_UNCMD);
	assert_non_null(strstr(line, "FAULT MOTION: axis A: the controller "
				     "stopped motion its program did not "
				     "command: a move started by another "
				     "program. "));
	v2_line(13, 3, 2, line, sizeof(line), &f);
	assert_non_null(strstr(line, "axis C: the controller stopped motion "
				     "its program did not command: faster "
				     "than allowed. "));
	v2_line(13, 0, 3, line, sizeof(line), &f);
	assert_int_equal(f.id, RE_F_CTRL_SAFE_ON);
	assert_int_equal(f.axis, -1);
	assert_non_null(strstr(line, "FAULT FOREIGN: a motor was switched on "
				     "while the controller program held the "
				     "robot in its safe state"));
	v2_line(14, 0, 1, line, sizeof(line), &f);
	assert_int_equal(f.id, RE_F_CTRL_FOREIGN_HB);
	assert_non_null(strstr(line, "FAULT FOREIGN: the controller received "
				     "a heartbeat that is not this "
				     "supervisor's"));
	v2_line(14, 0, 3, line, sizeof(line), &f);
	assert_int_equal(f.id, RE_F_CTRL_FOREIGN_SET);
	assert_non_null(strstr(line, "FAULT FOREIGN: the controller's safety "
				     "settings were changed while the motors "
				     "were on (the watchdog or the joystick "
				     "timeout): another program sent commands "
				     "to the controller. "));
	v2_line(14, 0, 4, line, sizeof(line), &f);
	assert_non_null(strstr(line, "were on (off-on-error switched off): "));
	v2_line(14, 0, 9, line, sizeof(line), &f);
	assert_non_null(strstr(line, "were on (which one is not known): "));
	v2_line(15, 2, 7, line, sizeof(line), &f);
	assert_int_equal(f.id, RE_F_CTRL_SVCMOVE);
	assert_non_null(strstr(line, "FAULT MOTION: axis B: the controller "
				     "stopped an automatic move: it moved "
				     "fast near a limit switch. "));
	v2_line(15, 2, 99, line, sizeof(line), &f);
	assert_non_null(strstr(line, "automatic move: the reason is not "
				     "known. "));
	v2_line(16, 3, 140, line, sizeof(line), &f);
	assert_int_equal(f.id, RE_F_CTRL_POTRANGE);
	assert_non_null(strstr(line, "FAULT ENCODER: axis C: the "
				     "potentiometer reads 0.140 V, outside "
				     "the range it can read on this robot. "));
}

static void fill_record(struct gl_record *rec)
{
	int k;

	memset(rec, 0, sizeof(*rec));
	rec->layout = GL_LAYOUT_4000;
	rec->n_axes = 3;
	rec->threads = 0x03;
	rec->axis[0].za = 17;	/* hbdmc */
	rec->axis[1].za = 1;	/* armed, no fault */
	rec->axis[2].za = 4096; /* neutral, idle */
	for (k = 0; k < 3; k++)
		rec->axis[k].stop_code = 1;
}

static void test_check_motors(void **state)
{
	struct gl_record rec;
	struct re_fault f;
	char line[512];

	(void)state;
	fill_record(&rec);
	assert_int_equal(re_check_motors(&rec, 3, 1, &f), RE_OK);
	rec.axis[2].status = GL_AXST_MOTOR_OFF;
	rec.axis[2].stop_code = 12;
	assert_int_equal(re_check_motors(&rec, 3, 0, &f), RE_OK);
	assert_int_equal(re_check_motors(&rec, 2, 1, &f), RE_OK);
	assert_int_equal(re_check_motors(&rec, 3, 1, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_MOTOR_OFF);
	assert_int_equal(f.axis, 2);
	assert_int_equal(f.i[0], 12);
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_string_equal(
	    line,
	    "FAULT MOTION: axis C: the controller switched the motor off: "
	    "encoder failure (stop code 12). Recovery: press the E-stop and "
	    "keep it pressed, check that axis C moves freely and nothing "
	    "blocks it, check its motor and encoder cables, then restart "
	    "roboelf");
	rec.axis[1].status = GL_AXST_MOTOR_OFF | GL_AXST_MOVING;
	rec.axis[1].stop_code = 15;
	assert_int_equal(re_check_motors(&rec, 3, 1, &f), RE_FAULT);
	assert_int_equal(f.axis, 1); /* first axis wins */
	assert_string_equal(f.s, "amplifier fault");
	assert_string_equal(re_stop_reason(8),
			    "position error above the limit");
	assert_string_equal(re_stop_reason(2), "forward limit");
	assert_string_equal(re_stop_reason(3), "reverse limit");
	assert_string_equal(re_stop_reason(42), "unexpected stop");
	assert_int_equal(re_check_motors(&rec, 4, 1, &f), GL_ERR_ARG);
}

static void test_check_record(void **state)
{
	struct gl_record rec;
	struct re_fault f;
	struct re_za z;
	char line[256];

	(void)state;
	fill_record(&rec);
	assert_int_equal(re_check_record(&rec, 3, 1, &z, &f), RE_OK);
	assert_int_equal(z.state, 1);
	assert_int_equal(z.hbdmc, 17);
	/* Thread 1 stopped while armed: the threads that run, in words. */
	rec.threads = 0x01;
	assert_int_equal(re_check_record(&rec, 3, 1, &z, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_THREAD);
	assert_int_equal(f.i[0], 1);
	assert_int_equal(f.i[1], 1);
	re_fault_what(&f, NULL, line, sizeof(line));
	assert_string_equal(line, "controller thread 1 is not running "
				  "(running: thread 0)");
	f.i[1] = 0x0D;
	re_fault_what(&f, NULL, line, sizeof(line));
	assert_string_equal(line, "controller thread 1 is not running "
				  "(running: threads 0, 2 and 3)");
	f.i[1] = 0;
	re_fault_what(&f, NULL, line, sizeof(line));
	assert_string_equal(line, "controller thread 1 is not running "
				  "(running: none)");
	/* ... which is fine while not armed (state 0). */
	rec.axis[1].za = 0;
	assert_int_equal(re_check_record(&rec, 3, 0, &z, &f), RE_OK);
	/* Thread 0 must always run. */
	rec.threads = 0x02;
	assert_int_equal(re_check_record(&rec, 3, 0, &z, &f), RE_FAULT);
	assert_int_equal(f.i[0], 0);
	/* Armed expected but the program is at state 0 (reset). */
	fill_record(&rec);
	rec.axis[1].za = 0;
	assert_int_equal(re_check_record(&rec, 3, 1, &z, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_STATE);
	assert_int_equal(re_fault_class(f.id), RE_FC_PROGRAM);
	/* Latched controller fault wins over everything after it. */
	fill_record(&rec);
	rec.threads = 0x01;
	rec.axis[0].status = GL_AXST_MOTOR_OFF;
	rec.axis[1].za = 2 + 10 * 3;
	assert_int_equal(re_check_record(&rec, 3, 1, &z, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_CTRL_INPUT);
	assert_int_equal(f.i[0], RE_VAL_UNKNOWN);
	/* A fault code while the state is not yet 2 is a fault too. */
	rec.axis[1].za = 1 + 10 * 9 + 1000 * 1;
	assert_int_equal(re_check_record(&rec, 3, 1, &z, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_CTRL_ENCODER);
	assert_int_equal(f.axis, 0);
	/* Unsigned garbage in ZAB. */
	rec.axis[1].za = 99999;
	assert_int_equal(re_check_record(&rec, 3, 1, &z, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_RECORD);
	assert_int_equal(f.i[0], 99999);
	/* Motor off while armed. */
	fill_record(&rec);
	rec.axis[1].status = GL_AXST_MOTOR_OFF;
	rec.axis[1].stop_code = 8;
	assert_int_equal(re_check_record(&rec, 3, 1, &z, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_MOTOR_OFF);
	assert_int_equal(re_check_record(&rec, 3, 0, &z, &f), RE_OK);
	rec.n_axes = 2;
	assert_int_equal(re_check_record(&rec, 2, 1, &z, &f), GL_ERR_ARG);
}

/* ---- calibration checks ---------------------------------------------------
 */

static const struct re_calcheck_cfg ccfg = {
    .noise_margin_v = 0.125,
    .expected_range_v = 1.0,
    .range_tol = 0.1,
    .min_points = 3,
    .max_points = 10,
    .step_tol_counts = 5,
};

static void test_cal_point(void **state)
{
	struct re_fault f;
	char line[512];

	(void)state;
	/* Encoder advance: step 100 +- 5 inclusive. */
	assert_int_equal(
	    re_cal_check_point(&ccfg, 2, 7, 100, 1000, 1105, 1.0, 1.5, &f),
	    RE_OK);
	assert_int_equal(
	    re_cal_check_point(&ccfg, 2, 7, 100, 1000, 1095, 1.0, 1.5, &f),
	    RE_OK);
	assert_int_equal(
	    re_cal_check_point(&ccfg, 2, 7, 100, 1000, 1106, 1.0, 1.5, &f),
	    RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_ENCSTEP);
	assert_int_equal(
	    re_cal_check_point(&ccfg, 2, 7, 100, 1000, 1094, 1.0, 1.5, &f),
	    RE_FAULT);
	/* Jammed axis: no advance at all. */
	assert_int_equal(
	    re_cal_check_point(&ccfg, 2, 7, 100, 1000, 1000, 1.0, 1.0, &f),
	    RE_FAULT);
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_string_equal(
	    line,
	    "FAULT CALIBRATION: axis C: encoder advanced 0 counts at "
	    "calibration point 7, expected 100 +- 5 counts. Recovery: press "
	    "the E-stop and keep it pressed, check that axis C moves freely "
	    "(jammed?) and its encoder cable, then restart roboelf and "
	    "calibrate again");
	/* Potentiometer must rise by more than the margin. */
	assert_int_equal(
	    re_cal_check_point(&ccfg, 2, 7, 100, 1000, 1100, 1.0, 1.125, &f),
	    RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_NONMONO);
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_string_equal(
	    line,
	    "FAULT CALIBRATION: axis C: potentiometer not rising at "
	    "calibration point 7: 1.125 V after 1 V (it must rise by more than "
	    "0.125 V). Recovery: press the E-stop and keep it pressed, check "
	    "the potentiometer of axis C and its cable (worn or loose), then "
	    "restart roboelf and calibrate again");
	assert_int_equal(re_cal_check_point(&ccfg, 2, 7, 100, 1000, 1100, 1.0,
					    1.125 + 1e-9, &f),
			 RE_OK);
	assert_int_equal(
	    re_cal_check_point(&ccfg, 2, 7, 100, 1000, 1100, 1.0, 0.9, &f),
	    RE_FAULT);
	assert_int_equal(
	    re_cal_check_point(&ccfg, 2, 0, 100, 1000, 1100, 1.0, 2.0, &f),
	    GL_ERR_ARG);
}

static void test_cal_table(void **state)
{
	struct re_calcheck_cfg c = ccfg;
	struct re_fault f;
	char line[512];

	(void)state;
	table5(&tbl);
	/* The smallest rise in table5 is 0.125: exactly the margin fails. */
	assert_int_equal(re_cal_check_table(&c, 0, &tbl, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_NONMONO);
	assert_int_equal(f.i[0], 3);
	c.noise_margin_v = 0.125 - 1e-9;
	assert_int_equal(re_cal_check_table(&c, 0, &tbl, &f), RE_OK);
	/* Points */
	c.min_points = 6;
	assert_int_equal(re_cal_check_table(&c, 0, &tbl, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_POINTS);
	re_fault_what(&f, NULL, line, sizeof(line));
	assert_string_equal(line, "axis A: 5 calibration points, expected 6 "
				  "to 10");
	c.min_points = ccfg.min_points;
	c.max_points = 4;
	assert_int_equal(re_cal_check_table(&c, 0, &tbl, &f), RE_FAULT);
	c.max_points = ccfg.max_points;
	/* Non-monotonic point 2 (equal to point 1). */
	tbl.pot_v[2] = 1.25;
	assert_int_equal(re_cal_check_table(&c, 1, &tbl, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_NONMONO);
	assert_int_equal(f.i[0], 2);
	assert_int_equal(f.axis, 1);
	table5(&tbl);
	tbl.pot_v[4] = NAN;
	assert_int_equal(re_cal_check_table(&c, 1, &tbl, &f), RE_FAULT);
	assert_int_equal(f.i[0], 4);
	/* Range: 1.0 V against 2.0 +- 50 % is at the edge -> OK. */
	table5(&tbl);
	c.expected_range_v = 2.0;
	c.range_tol = 0.5;
	assert_int_equal(re_cal_check_table(&c, 0, &tbl, &f), RE_OK);
	c.range_tol = 0.499;
	assert_int_equal(re_cal_check_table(&c, 0, &tbl, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_RANGE);
	re_fault_what(&f, NULL, line, sizeof(line));
	assert_string_equal(line, "axis A: potentiometer range 1 V is outside "
				  "the expected 2 V +- 49.900 %");
	c.expected_range_v = ccfg.expected_range_v;
	c.range_tol = ccfg.range_tol;
	/* Soft limits: one step beyond the table ends is the edge. */
	tbl.soft_rev = 900;
	tbl.soft_fwd = 1500;
	assert_int_equal(re_cal_check_table(&c, 0, &tbl, &f), RE_OK);
	tbl.soft_rev = 899;
	assert_int_equal(re_cal_check_table(&c, 0, &tbl, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_LIMITS);
	re_fault_what(&f, NULL, line, sizeof(line));
	assert_string_equal(line, "axis A: soft limits 899 to 1500 counts are "
				  "outside the calibrated travel 1000 to 1400 "
				  "counts");
	tbl.soft_rev = 900;
	tbl.soft_fwd = 1501;
	assert_int_equal(re_cal_check_table(&c, 0, &tbl, &f), RE_FAULT);
	tbl.soft_rev = 1200;
	tbl.soft_fwd = 1200;
	assert_int_equal(re_cal_check_table(&c, 0, &tbl, &f), RE_FAULT);
	/* Bad configuration is a caller bug. */
	c.min_points = 1;
	assert_int_equal(re_cal_check_table(&c, 0, &tbl, &f), GL_ERR_ARG);
}

/* ---- message table ----------------------------------------------------- */

static void test_every_fault_formats(void **state)
{
	const char *names[] = {"A", "B", "C"};
	struct re_fault f;
	const char *what, *rec;
	char line[1024];
	int id, n;

	(void)state;
	for (id = RE_F_NONE + 1; id < RE_F_COUNT; id++) {
		assert_int_equal(
		    re_fault_template((enum re_fault_id)id, &what, &rec),
		    GL_OK);
		assert_true(strlen(what) > 10 && strlen(rec) > 10);
		assert_int_not_equal(re_fault_class((enum re_fault_id)id),
				     RE_FC_NONE);
		re_fault_set(&f, (enum re_fault_id)id, 1);
		snprintf(f.s, sizeof(f.s), "detail");
		n = re_fault_format(&f, names, line, sizeof(line));
		assert_true(n > 0 && (size_t)n == strlen(line));
		assert_int_equal(strncmp(line, "FAULT ", 6), 0);
		assert_non_null(strstr(line, ". Recovery: "));
		/* every placeholder was known */
		assert_null(strchr(line, '{'));
		/* short enough for the fault panel: with the safe-state
		 * sentence (at most 160 bytes) inside RE_SUPER_LINE */
		if (n >= 360)
			fail_msg("%d bytes: %s", n, line);
	}
	assert_int_equal(re_fault_template(RE_F_NONE, &what, &rec), GL_ERR_ARG);
	assert_int_equal(re_fault_template(RE_F_COUNT, &what, &rec),
			 GL_ERR_ARG);
	assert_string_equal(re_fault_class_name(RE_FC_ESTOP), "ESTOP");
	assert_string_equal(re_fault_class_name(RE_FC_COUNT), "NONE");
}

static void test_format_names_and_overflow(void **state)
{
	const char *names[] = {"roll", "pitch", "insert"};
	struct re_fault f;
	char line[512];
	char small[20];

	(void)state;
	re_fault_set(&f, RE_F_ESTOP_LOST, -1);
	snprintf(f.s, sizeof(f.s),
		 "'/dev/serial/by-id/usb-TEST_relay-if00': Input/output error");
	re_fault_format(&f, NULL, line, sizeof(line));
	assert_string_equal(
	    line, "FAULT ESTOP: the E-stop relay stopped answering "
		  "('/dev/serial/by-id/usb-TEST_relay-if00': Input/output "
		  "error). Recovery: press the hardware "
		  "E-stop now, check the relay's USB cable and power, then "
		  "restart roboelf");
	re_fault_set(&f, RE_F_CAL_ABORT, 2);
	snprintf(f.s, sizeof(f.s), "forward limit switch never came");
	re_fault_format(&f, names, line, sizeof(line));
	assert_string_equal(
	    line,
	    "FAULT CALIBRATION: axis insert: calibration aborted: forward "
	    "limit switch never came. Recovery: press the E-stop and keep it "
	    "pressed, check axis insert, its limit switches and cables, then "
	    "restart roboelf and calibrate again");
	assert_int_equal(re_fault_format(&f, names, small, sizeof(small)),
			 GL_ERR_OVERFLOW);
	assert_string_equal(small, "FAULT CALIBRATION: ");
	f.id = RE_F_COUNT;
	assert_int_equal(re_fault_format(&f, names, line, sizeof(line)),
			 GL_ERR_ARG);
	assert_string_equal(line, "");
}

/* docs/calibration-file.md lists every template verbatim (run from the
 * repository root, as tests/run-all.sh does). */
static void test_docs_list_every_template(void **state)
{
	static char doc[256 * 1024];
	const char *top = getenv("ROBOELF_TOP");
	const char *what, *rec;
	char path[1024];
	size_t n;
	FILE *f;
	int id;

	(void)state;
	snprintf(path, sizeof(path), "%s/docs/calibration-file.md",
		 top && top[0] ? top : ".");
	f = fopen(path, "r");
	if (!f)
		fail_msg("cannot open '%s' (run from the repository root or "
			 "set ROBOELF_TOP)",
			 path);
	n = fread(doc, 1, sizeof(doc) - 1, f);
	fclose(f);
	doc[n] = '\0';
	for (id = RE_F_NONE + 1; id < RE_F_COUNT; id++) {
		re_fault_template((enum re_fault_id)id, &what, &rec);
		if (!strstr(doc, what))
			fail_msg("not in the docs: '%s'", what);
		if (!strstr(doc, rec))
			fail_msg("not in the docs: '%s'", rec);
	}
}

/* Positions also in the robot's units: "{i0c}" and "{r12}";
 * without units, or for an axis without one, exactly the counts. */
static void test_format_units(void **state)
{
	struct re_fault_units u = {{"deg", "deg", "mm"}, {1000, 1000, 250}, 0};
	struct re_fault f;
	char line[512];

	(void)state;
	re_fault_set(&f, RE_F_ENC_OUTSIDE, 1);
	f.i[0] = 52000;
	f.i[1] = -49640;
	f.i[2] = 49640;
	assert_true(re_fault_what_units(&f, NULL, &u, line, sizeof(line)) > 0);
	assert_string_equal(line, "axis B: encoder position 52000 counts "
				  "(52.00 deg) is outside the calibrated "
				  "travel -49640 to 49640 counts (-49.64 to "
				  "49.64 deg)");
	re_fault_what(&f, NULL, line, sizeof(line));
	assert_string_equal(line, "axis B: encoder position 52000 counts is "
				  "outside the calibrated travel -49640 to "
				  "49640 counts");
	u.name[1] = NULL; /* no unit for B: counts only */
	re_fault_what_units(&f, NULL, &u, line, sizeof(line));
	assert_string_equal(line, "axis B: encoder position 52000 counts is "
				  "outside the calibrated travel -49640 to "
				  "49640 counts");
	re_fault_set(&f, RE_F_CTRL_POSERR, 2);
	f.i[0] = 801;
	re_fault_format_units(&f, NULL, &u, line, sizeof(line));
	assert_non_null(strstr(line, "FAULT MOTION: axis C: position error of "
				     "at least 801 counts (3.20 mm), above "));
	f.i[0] = -1; /* never "-0.00" */
	re_fault_what_units(&f, NULL, &u, line, sizeof(line));
	assert_non_null(strstr(line, "at least -1 counts (0.00 mm), above"));
	f.i[0] = RE_VAL_UNKNOWN;
	re_fault_what_units(&f, NULL, &u, line, sizeof(line));
	assert_non_null(strstr(line, "at least unknown, above"));
	/* the joysticks A forward and B forward together (0x33): the
	 * switches and the timeout in words, never the word in hex */
	re_fault_set(&f, RE_F_CTRL_INPUT, -1);
	f.i[0] = 0x33;
	u.invalid_timeout_ms = 500;
	re_fault_what_units(&f, NULL, &u, line, sizeof(line));
	assert_string_equal(line, "invalid joystick state held longer than "
				  "the invalid-input timeout of 500 ms: A "
				  "forward (switches a and b) and B forward "
				  "(switches a and b) closed at once");
	f.i[0] = 0x8 | 0x100 | 0x800;
	re_fault_what_units(&f, NULL, &u, line, sizeof(line));
	assert_string_equal(line,
			    "invalid joystick state held longer than "
			    "the invalid-input timeout of 500 ms: A "
			    "reverse (switch b only), C forward (switch "
			    "a only) and C reverse (switch b only) closed "
			    "at once");
	re_fault_set(&f, RE_F_CTRL_POSERR, 2);
	u.counts_per_unit[2] = 0; /* scale not known: counts only */
	f.i[0] = 801;
	re_fault_what_units(&f, NULL, &u, line, sizeof(line));
	assert_non_null(strstr(line, "at least 801 counts, above"));
	re_fault_set(&f, RE_F_ENCPOT, 0);
	f.i[0] = 12345;
	f.i[1] = 3;
	f.f[0] = 2.5;
	f.f[1] = 3.1;
	f.f[2] = 0.6;
	f.f[3] = 0.06;
	re_fault_what_units(&f, NULL, &u, line, sizeof(line));
	assert_string_equal(line, "axis A: potentiometer reads 2.500 V but "
				  "3.100 V is expected at encoder position "
				  "12345 counts (12.35 deg); they differ by "
				  "0.600 V, more than the 0.060 V allowed, for "
				  "3 cycles");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_expect_points_and_between),
	    cmocka_unit_test(test_expect_beyond_ends),
	    cmocka_unit_test(test_expect_bad_args),
	    cmocka_unit_test(test_encpot_tolerance_edges),
	    cmocka_unit_test(test_encpot_at_table_ends),
	    cmocka_unit_test(test_encpot_persistence),
	    cmocka_unit_test(test_encpot_bad_args),
	    cmocka_unit_test(test_wdog_thresholds),
	    cmocka_unit_test(test_wdog_fault_text),
	    cmocka_unit_test(test_wdog_other_periods_and_args),
	    cmocka_unit_test(test_alive_heartbeat),
	    cmocka_unit_test(test_alive_sample),
	    cmocka_unit_test(test_za_decode),
	    cmocka_unit_test(test_ctrl_fault_mapping),
	    cmocka_unit_test(test_ctrl_fault_texts),
	    cmocka_unit_test(test_ctrl_fault_v2),
	    cmocka_unit_test(test_check_motors),
	    cmocka_unit_test(test_check_record),
	    cmocka_unit_test(test_cal_point),
	    cmocka_unit_test(test_cal_table),
	    cmocka_unit_test(test_every_fault_formats),
	    cmocka_unit_test(test_format_names_and_overflow),
	    cmocka_unit_test(test_format_units),
	    cmocka_unit_test(test_docs_list_every_template),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
