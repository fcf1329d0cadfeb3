/*
 * test_re_xcheck.c - the supervisor's own joystick decode and motion check
 * (pc/super/re_xcheck.h) on records made by hand: the decode with both
 * polarities and the input banks; the program's decode agreeing, lagging
 * within the allowance, and disagreeing (the fault names both readings);
 * an axis against the command, another axis running, the commanded one
 * over its ramp, each after two cycles and not while TV settles; the
 * figures held to dmc/constants.dmc.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "base_clock.h"
#include "base_file.h"
#include "gl_err.h"
#include "re_check.h"
#include "re_xcheck.h"

#define MS BASE_NS_PER_MS

static struct re_xcheck_cfg cfg;

/* The default wiring (inputs 1..8, 17..20), vmin 2000, vmax 8000, window
 * 500..2000 ms, lag 80 ms. */
static int setup(void **state)
{
	static const int in[RE_XC_INPUTS] = {1, 2, 3,  4,  5,  6,
					     7, 8, 17, 18, 19, 20};

	(void)state;
	memset(&cfg, 0, sizeof(cfg));
	memcpy(cfg.inputs, in, sizeof(in));
	for (int i = 0; i < RE_XC_AXES; i++) {
		cfg.vmin_cps[i] = 2000;
		cfg.vmax_cps[i] = 8000;
		cfg.wst_ms[i] = 500;
		cfg.wen_ms[i] = 2000;
	}
	cfg.lag_ns = 80 * MS;
	return 0;
}

/* A record with the switches of @raw closed (active high) and the axis
 * velocities @v (counts/s). */
static void record(struct gl_record *r, int raw, const double v[3])
{
	memset(r, 0, sizeof(*r));
	r->n_axes = 3;
	for (int j = 0; j < RE_XC_INPUTS; j++)
		if (raw >> j & 1) {
			int n = cfg.inputs[j];

			r->inputs[(n - 1) / 8] |=
			    (uint8_t)(1u << ((n - 1) % 8));
		}
	for (int i = 0; i < 3; i++)
		r->axis[i].velocity = (int32_t)(v[i] * 64);
}

static void test_decode(void **state)
{
	struct gl_record r;
	static const double v0[3] = {0, 0, 0};
	int raw = 0;

	(void)state;
	record(&r, 0, v0);
	assert_int_equal(re_xcheck_decode(&cfg, r.inputs, &raw), 0);
	for (int k = 0; k < 6; k++) {
		record(&r, 3 << (2 * k), v0);
		assert_int_equal(re_xcheck_decode(&cfg, r.inputs, &raw), k + 1);
		assert_int_equal(raw, 3 << (2 * k));
	}
	record(&r, 1, v0); /* one switch of A forward */
	assert_int_equal(re_xcheck_decode(&cfg, r.inputs, NULL), -1);
	record(&r, 3 | 3 << 4, v0); /* A forward and B forward */
	assert_int_equal(re_xcheck_decode(&cfg, r.inputs, &raw), -1);
	assert_int_equal(raw, 0x33);
	/* active low: a closed switch reads 0 */
	cfg.active_low = 1;
	record(&r, 0xfff & ~(3 << 8), v0);
	assert_int_equal(re_xcheck_decode(&cfg, r.inputs, &raw), 5);
	cfg.active_low = 0;
	/* input 17 is bank 2, bit 0 */
	record(&r, 1 << 8, v0);
	assert_int_equal(r.inputs[2], 1);
	cfg.inputs[0] = 0;
	assert_int_equal(re_xcheck_decode(&cfg, r.inputs, NULL), -2);
	setup(NULL);
	assert_string_equal(re_xcheck_cmd_text(4), "axis B reverse");
	assert_string_equal(re_xcheck_cmd_text(-1), "no valid command");
}

static void test_ramp(void **state)
{
	(void)state;
	assert_true(re_xcheck_ramp(&cfg, 0, 0) == 2000);
	assert_true(re_xcheck_ramp(&cfg, 0, 500) == 2000);
	assert_true(re_xcheck_ramp(&cfg, 0, 1250) == 5000);
	assert_true(re_xcheck_ramp(&cfg, 0, 2000) == 8000);
	assert_true(re_xcheck_ramp(&cfg, 2, 9000) == 8000);
}

/* Step @x @n cycles of 50 ms from @t (ns), each with the same record. */
static int run(struct re_xcheck *x, int raw, const double v[3],
	       const struct re_za *za, int64_t *t, int n, struct re_fault *f)
{
	struct gl_record r;
	int rc = RE_OK;

	record(&r, raw, v);
	for (int i = 0; i < n && rc == RE_OK; i++) {
		rc = re_xcheck_step(x, &cfg, &r, za, *t, f);
		*t += 50 * MS;
	}
	return rc;
}

/* The program's decode may lag the inputs by the allowance; a longer
 * difference is a fault with both readings. */
static void test_program_decode(void **state)
{
	static const double v0[3] = {0, 0, 0};
	struct re_xcheck x;
	struct re_za za = {.state = RE_DMC_ARMED, .mneut = 0};
	struct re_fault f;
	int64_t t = 1000 * MS;

	(void)state;
	re_xcheck_reset(&x, t);
	za.jcmd = 0;
	assert_int_equal(run(&x, 3, v0, &za, &t, 2, &f), RE_OK); /* lag */
	za.jcmd = 1;
	assert_int_equal(run(&x, 3, v0, &za, &t, 10, &f), RE_OK);
	/* the program decodes A reverse while the switches say A forward */
	za.jcmd = 2;
	assert_int_equal(run(&x, 3, v0, &za, &t, 2, &f), RE_OK);
	assert_int_equal(run(&x, 3, v0, &za, &t, 1, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_XC_DECODE);
	assert_string_equal(f.s, "roboelf reads axis A forward (switches "
				 "closed: A fwd a, A fwd b), the program axis "
				 "A reverse, for 100 ms");
	/* not judged in the safe state */
	re_xcheck_reset(&x, t);
	za.state = RE_DMC_UNARMED;
	assert_int_equal(run(&x, 3, v0, &za, &t, 20, &f), RE_OK);
	/* in service too */
	za.state = RE_DMC_SERVICE;
	assert_int_equal(run(&x, 3, v0, &za, &t, 3, &f), RE_FAULT);
}

/* Armed, after mneut: against the command, another axis, over the ramp. */
static void test_motion(void **state)
{
	struct re_xcheck x;
	struct re_za za = {.state = RE_DMC_ARMED, .mneut = 1, .jcmd = 1};
	struct re_fault f;
	int64_t t = 1000 * MS;
	double v[3] = {0, 0, 0};

	(void)state;
	/* A forward, A runs backwards: tolerated while TV settles (400 ms +
	 * lag), then two cycles */
	re_xcheck_reset(&x, t);
	v[0] = -3900;
	assert_int_equal(run(&x, 3, v, &za, &t, 10, &f), RE_OK);
	assert_int_equal(run(&x, 3, v, &za, &t, 2, &f), RE_FAULT);
	assert_int_equal(f.id, RE_F_XC_MOTION);
	assert_int_equal(f.axis, 0);
	assert_string_equal(f.s, "runs against the joystick (axis A forward "
				 "by roboelf's own decode)");
	assert_true(f.f[0] == -3900 && f.f[1] == -1000);
	/* A forward, A at 12152 counts/s: over 1.25 x vmax (10000), at once
	 * after two cycles, even long after the command */
	re_xcheck_reset(&x, t);
	v[0] = 2400; /* under the ramp's 1.25 x vmin from the start */
	assert_int_equal(run(&x, 3, v, &za, &t, 60, &f), RE_OK);
	v[0] = 12152;
	assert_int_equal(run(&x, 3, v, &za, &t, 1, &f), RE_OK);
	assert_int_equal(run(&x, 3, v, &za, &t, 1, &f), RE_FAULT);
	assert_true(f.f[0] == 12152 && f.f[1] == 10000);
	/* the ramp removed: 8000 at 200 ms after the command, where the ramp
	 * allows 1.25 x 2000 */
	re_xcheck_reset(&x, t);
	v[0] = 0;
	za.jcmd = 0;
	assert_int_equal(run(&x, 0, v, &za, &t, 12, &f), RE_OK);
	za.jcmd = 1;
	v[0] = 8000;
	assert_int_equal(run(&x, 3, v, &za, &t, 4, &f), RE_FAULT);
	assert_true(f.f[1] == 2500);
	assert_non_null(strstr(f.s, "faster than its ramp allows"));
	/* B runs while A is commanded (and nothing ran before) */
	re_xcheck_reset(&x, t);
	v[0] = 2000;
	v[1] = 2500;
	assert_int_equal(run(&x, 3, v, &za, &t, 1, &f), RE_OK);
	assert_int_equal(run(&x, 3, v, &za, &t, 1, &f), RE_FAULT);
	assert_int_equal(f.axis, 1);
	assert_string_equal(f.s, "runs while the joystick says axis A forward");
	/* released after a fast jog: TV still high for the settling time,
	 * no fault; pressed again at once: the old bound holds meanwhile */
	re_xcheck_reset(&x, t);
	v[1] = 0;
	v[0] = 2400;
	assert_int_equal(run(&x, 3, v, &za, &t, 40, &f), RE_OK);
	v[0] = 9000; /* 2 s after the command: vmax x 1.25 allowed */
	assert_int_equal(run(&x, 3, v, &za, &t, 10, &f), RE_OK);
	za.jcmd = 0;
	v[0] = 6000;
	assert_int_equal(run(&x, 0, v, &za, &t, 3, &f), RE_OK);
	za.jcmd = 1;
	v[0] = 5000;
	assert_int_equal(run(&x, 3, v, &za, &t, 4, &f), RE_OK);
	/* before mneut nothing moves: no motion judged */
	re_xcheck_reset(&x, t);
	za.mneut = 0;
	v[0] = -5000;
	assert_int_equal(run(&x, 3, v, &za, &t, 30, &f), RE_OK);
}

/* The figures are the program's (dmc/constants.dmc). */
static void test_program_figures(void **state)
{
	char *src = NULL, want[64];
	size_t len;

	(void)state;
	assert_int_equal(
	    base_file_read("dmc/constants.dmc", 1 << 20, &src, &len), 0);
	snprintf(want, sizeof(want), "vover=%.2f;vstill=%d", RE_XC_VOVER,
		 RE_XC_VSTILL);
	assert_non_null(strstr(src, want));
	snprintf(want, sizeof(want), "\ntvwin=%d\n", RE_XC_SETTLE_MS);
	assert_non_null(strstr(src, want));
	free(src);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_decode),
	    cmocka_unit_test(test_ramp),
	    cmocka_unit_test(test_program_decode),
	    cmocka_unit_test(test_motion),
	    cmocka_unit_test(test_program_figures),
	};

	return cmocka_run_group_tests(tests, setup, NULL);
}
