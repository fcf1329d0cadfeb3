/*
 * test_dmc_guard.c - what DMC 2.00 holds while armed (the headers of
 * #GUARD, #FORGN, #HBCHK, #JVAL, #MRAMP and #POSERR in dmc/roboelf.dmc are
 * the specification): motion only where the program commanded it (fault
 * 13 detail 1 and 2), the supervisor's heartbeat as a sequence (fault 14
 * detail 1; a fraction or a value outside 0..hbpcwr-1 too, 2.24) and
 * its echo in the record (2.23), another program's
 * connection (reported, "FOREIGN") and its changes to the safety settings
 * (fault 14, detail 3 and 4), the potentiometers' absolute range (fault
 * 16), the flicker-proof invalid joystick timer (fault 3), position-
 * tracking targets one count inside FL/BL, and an encoder failure (OA) at
 * rest named as fault 9.
 *
 * Reaction times are measured in simulated time and printed ("measured:")
 * so that the figures can be compared with the formulas of the headers.
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

/* ---- helpers ------------------------------------------------------------- */

/* A value the controller computes, read with a host MG (NAN on error). */
static double mg(struct dmc_h *h, const char *expr)
{
	char line[64], resp[64];

	snprintf(line, sizeof(line), "MG %s", expr);
	if (dmc_h_cmd(h, line, resp, sizeof(resp)) < 0)
		return NAN;
	return atof(resp);
}

/* An armed robot with @p written (and @cmd, if any, the robot's controller
 * settings: sent before the program is sealed). */
static void setup_armed(struct dmc_h *h, const struct dmc_h_params *p,
			const char *cmd)
{
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	if (cmd)
		DMC_H_CHECK(h, dmc_h_cmd(h, cmd, NULL, 0));
	DMC_H_CHECK(h, dmc_h_configure(h, p));
	DMC_H_CHECK(h, dmc_h_arm(h));
}

/*
 * Advance 1 ms at a time until the program latched (state 2), at most
 * @timeout_ms. Return: ms waited; fails the test on timeout.
 */
static double wait_latch(struct dmc_h *h, double timeout_ms)
{
	double t = dmc_h_wait_var(h, "state", 2, timeout_ms);

	if (t < 0)
		fail_msg("no fault within %.0f ms (state %g)", timeout_ms,
			 dmc_h_var(h, "state"));
	return t;
}

/*
 * The latched fault: fcode/faxis/fdet (fdet within @tol), exactly one FAULT
 * line with the same code and axis, every motor off.
 */
static void assert_latched(struct dmc_h *h, int code, int axis, double det,
			   double tol)
{
	int c = -1, a = -1;
	double d = -1;

	dmc_h_advance(h, 2); /* the FAULT line leaves the output queue */
	if (dmc_h_var(h, "fcode") != code || dmc_h_var(h, "faxis") != axis ||
	    fabs(dmc_h_var(h, "fdet") - det) > tol)
		fail_msg("fault %g axis %g detail %g, want %d axis %d detail "
			 "%g",
			 dmc_h_var(h, "fcode"), dmc_h_var(h, "faxis"),
			 dmc_h_var(h, "fdet"), code, axis, det);
	assert_true(dmc_h_var(h, "state") == 2);
	assert_int_equal(dmc_h_fault_lines(h, &c, &a, &d), 1);
	assert_int_equal(c, code);
	assert_int_equal(a, axis);
	/* the line prints fdet without decimals ({Z10.0}) */
	assert_true(fabs(d - dmc_h_var(h, "fdet")) <= 0.5);
	for (int i = 0; i < DMC_H_AXES; i++)
		assert_int_equal(dmc_h_axis(h, i).motor_off, 1);
}

/* ---- motion the program did not command (fault 13) ----------------------- */

/*
 * A host's PA + BG on an axis at rest, which the program does not own:
 * #GUARD sees its profiler within one main loop (+1 sample) and latches
 * fault 13, that axis, detail 1; the axis stops after less than the
 * distance a start at AC covers in that time.
 */
static void test_host_pa_bg(void **state)
{
	struct dmc_h *h = *state;
	double mainms = dmc_h_var(h, "mainms"), ac = mg(h, "_ACA"), a0, t;

	a0 = dmc_h_axis(h, 0).enc;
	DMC_H_CHECK(h, dmc_h_cmd(h, "PA 30000", NULL, 0));
	DMC_H_CHECK(h, dmc_h_cmd(h, "BG A", NULL, 0));
	t = wait_latch(h, 5 * mainms);
	print_message("measured: host PA/BG -> fault 13 in %.0f ms\n", t);
	assert_true(t <= mainms + 1);
	assert_latched(h, 13, 1, 1, 0);
	dmc_h_advance(h, 50);
	assert_int_equal(dmc_h_axis(h, 0).moving, 0);
	assert_true(dmc_h_axis(h, 0).enc - a0 <=
		    ac / 2 * pow((mainms + 1) / 1000, 2) + 1);
}

/* The same with a host's JG + BG: fault 13 axis 1 detail 1 within one main
 * loop (+1 sample). */
static void test_host_jg_bg(void **state)
{
	struct dmc_h *h = *state;
	double mainms = dmc_h_var(h, "mainms"), t;

	DMC_H_CHECK(h, dmc_h_cmd(h, "JG 8000", NULL, 0));
	DMC_H_CHECK(h, dmc_h_cmd(h, "BG A", NULL, 0));
	t = wait_latch(h, 5 * mainms);
	print_message("measured: host JG/BG -> fault 13 in %.0f ms\n", t);
	assert_true(t <= mainms + 1);
	assert_latched(h, 13, 1, 1, 0);
	dmc_h_advance(h, 50);
	assert_int_equal(dmc_h_axis(h, 0).moving, 0);
}

/* A host's BG on another axis while A is jogged: B is not owned, fault 13
 * axis 2 detail 1 (the jogged axis's ownership covers only that axis). */
static void test_host_bg_other_axis(void **state)
{
	struct dmc_h *h = *state;
	double mainms = dmc_h_var(h, "mainms"), t;

	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 500);
	assert_true(dmc_h_axis(h, 0).moving);
	DMC_H_CHECK(h, dmc_h_cmd(h, "PR ,2000", NULL, 0));
	DMC_H_CHECK(h, dmc_h_cmd(h, "BG B", NULL, 0));
	t = wait_latch(h, 5 * mainms);
	assert_true(t <= mainms + 1);
	assert_latched(h, 13, 2, 1, 0);
}

/*
 * A host's SP 20000 (twice vmax, above vmax * vover = 12500) on the axis
 * being jogged at vmax: thread 1 writes SP = vcur at every retarget, so the
 * host's value is overwritten within one motion loop (+1 sample); in that
 * time the profiler can gain at most AC * (loopms + 1) ms above vmax, TV
 * (a 256-sample average) stays far below the limit and nothing trips:
 * overwritten, not detail 2.
 */
static void test_host_sp_overwritten(void **state)
{
	struct dmc_h *h = *state;
	double loopms = dmc_h_var(h, "loopms"), ac = mg(h, "_ACA");
	double vmax = dmc_h_var(h, "vmax[0]"), vpeak = 0, t0, t_back = -1;

	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 2500); /* past wen: at vmax */
	assert_true(dmc_h_var(h, "vcur") == vmax);
	t0 = dmc_h_now(h);
	DMC_H_CHECK(h, dmc_h_cmd(h, "SP 20000", NULL, 0));
	assert_true(mg(h, "_SPA") == 20000);
	while (dmc_h_now(h) - t0 < 1000) {
		dmc_h_advance(h, 1);
		if (dmc_h_axis(h, 0).vel > vpeak)
			vpeak = dmc_h_axis(h, 0).vel;
		if (t_back < 0 && mg(h, "_SPA") == vmax)
			t_back = dmc_h_now(h) - t0;
	}
	print_message("measured: host SP overwritten after %.0f ms, peak "
		      "profiler speed %.0f counts/s\n",
		      t_back, vpeak);
	assert_true(t_back >= 0 && t_back <= loopms + 1);
	assert_true(vpeak <= vmax + ac * (loopms + 1) / 1000);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_true(dmc_h_axis(h, 0).vel == vmax);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/*
 * A host that keeps writing SP 20000 (every ms) on the axis being jogged:
 * thread 1 writes SP back every loopms, but for 9 of every 10 ms the host's
 * value stands, so the axis gets faster (as far as position tracking with
 * the step stp lets it) and TV passes vmax * vover: fault 13 axis 1 detail
 * 2 within one main loop (+1 sample) of the first sample in which |TV|
 * exceeds the limit (read with MG _TVA every ms, as the program reads it).
 */
static void test_host_sp_persistent(void **state)
{
	struct dmc_h *h = *state;
	double lim = dmc_h_var(h, "vmax[0]") * dmc_h_var(h, "vover");
	double mainms = dmc_h_var(h, "mainms"), t0, t_over = -1, t_f = -1;

	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	dmc_h_advance(h, 2500);
	t0 = dmc_h_now(h);
	while (t_f < 0 && dmc_h_now(h) - t0 < 3000) {
		DMC_H_CHECK(h, dmc_h_cmd(h, "SP 20000", NULL, 0));
		dmc_h_advance(h, 1);
		if (t_over < 0 && fabs(mg(h, "_TVA")) > lim)
			t_over = dmc_h_now(h);
		if (dmc_h_var(h, "state") == 2)
			t_f = dmc_h_now(h);
	}
	print_message("measured: host SP every ms -> TV above %.0f after %.0f "
		      "ms, fault %.0f ms later\n",
		      lim, t_over - t0, t_f - t_over);
	assert_true(t_over > t0 && t_f >= t_over);
	assert_true(t_f - t_over <= mainms + 1);
	assert_latched(h, 13, 1, 2, 0);
}

/* ---- the heartbeat as a sequence (fault 14 detail 1) --------------------- */

struct hbcase {
	const char *what;
	long step; /* hbpc written = last value + step */
	int trips;
};

/* hbmaxd is 5 (dmc_h_params_default): a step of 1..5 is in sequence. */
static const struct hbcase hbcases[] = {
    {"step hbmaxd + 1", 6, 1}, {"step far ahead", 123456, 1},
    {"step back by 1", -1, 1}, {"step back far", -100, 1},
    {"step hbmaxd", 5, 0},
};

/*
 * A heartbeat written out of sequence (a stray client after the supervisor
 * died, which starts from its own value): fault 14, axis 0, detail 1
 * within one main loop (+1 sample). A step of exactly hbmaxd is in
 * sequence (the supervisor may skip cycles).
 */
static void test_hb_out_of_sequence(void **state)
{
	(void)state;
	for (size_t k = 0; k < sizeof(hbcases) / sizeof(hbcases[0]); k++) {
		static struct dmc_h h;
		const struct hbcase *c = &hbcases[k];
		double mainms, t;

		if (dmc_h_setup(&h) < 0)
			fail_msg("%s: set-up: %s", c->what, h.err);
		mainms = dmc_h_var(&h, "mainms");
		/* the harness's next write is the stray value */
		h.hb += c->step - 1;
		h.hb_next_ms = dmc_h_now(&h);
		dmc_h_advance(&h, 1);
		assert_true(dmc_h_var(&h, "hbpc") == (double)h.hb);
		if (!c->trips) {
			dmc_h_advance(&h, 1000);
			if (dmc_h_var(&h, "state") != 1)
				fail_msg("%s: fault %g detail %g", c->what,
					 dmc_h_var(&h, "fcode"),
					 dmc_h_var(&h, "fdet"));
			dmc_h_close(&h);
			continue;
		}
		/* + 1: hbpc was written at the start of the last ms */
		t = wait_latch(&h, 5 * mainms) + 1;
		print_message("measured: hbpc %s -> fault 14 in %.0f ms\n",
			      c->what, t);
		assert_true(t <= mainms + 1);
		assert_latched(&h, 14, 0, 1, 0);
		dmc_h_close(&h);
	}
}

/* Line budgets per sample tried: a host write lands at a sample boundary,
 * and the budget moves the boundaries across the lines of #HBCHK. */
#define STRAY_BUDGET_MIN  8
#define STRAY_BUDGET_MAX  40
#define STRAY_FIRST_AHEAD 1000 /* the stray value, past the heartbeat */
#define STRAY_SAMPLES	  3000 /* how long one budget waits for its chance */
#define STRAY_PASSES	  3    /* the next look, in mainms, at any budget */

/* The 0-based number of the first line of @h's program at or after line
 * @from that starts with @prefix, or -1. */
static int prog_line(const struct dmc_h *h, const char *prefix, int from)
{
	const char *p = h->prog, *end = h->prog + h->prog_len;
	size_t n = strlen(prefix);

	for (int i = 0; p < end; i++) {
		const char *nl = memchr(p, '\n', (size_t)(end - p));

		if (i >= from && (size_t)(end - p) >= n && !memcmp(p, prefix, n))
			return i;
		p = nl ? nl + 1 : end;
	}
	return -1;
}

/* One budget: the supervisor writes once a pass until thread 0, in the
 * pass after a write, is between #HBCHK's first statement and its copy
 * into hbold (the look has begun with that write); then the stray write,
 * and the supervisor is dead.
 * Return: 1 and fault 14 detail 1 latched at the next look (within
 * STRAY_PASSES * mainms of the stray write); 0 when no sample boundary fell in that window (nothing tested). */
static int stray_run(int budget, int first, int copy)
{
	static struct dmc_h h;
	double mainms, t0, t = -1;
	int legit = 0, stray = 0;

	if (dmc_h_setup(&h) < 0)
		fail_msg("set-up: %s", h.err);
	ctrl_set_line_budget(h.ctrl, budget);
	mainms = dmc_h_var(&h, "mainms");
	h.hb_on = 0;
	for (int k = 0; k < STRAY_SAMPLES && !stray; k++) {
		char r[32];
		int xq;

		DMC_H_CHECK(&h, ctrl_command(h.ctrl, "MG _XQ0", r, sizeof(r)));
		xq = atoi(r);
		/* no chance in this pass: the supervisor writes again */
		if (legit && k - legit >= mainms)
			legit = 0;
		if (!legit && (xq < first - 1 || xq > copy)) {
			DMC_H_CHECK(&h, dmc_h_set(&h, "hbpc", (double)++h.hb));
			legit = k + 1;
		} else if (legit && xq > first + 1 && xq <= copy) {
			DMC_H_CHECK(&h, dmc_h_set(&h, "hbpc",
						  h.hb + STRAY_FIRST_AHEAD));
			stray = 1;
			break;
		}
		dmc_h_advance(&h, 1);
	}
	if (!stray) {
		dmc_h_close(&h);
		return 0;
	}
	t0 = dmc_h_now(&h);
	while (t < 0 && dmc_h_now(&h) - t0 < 10 * mainms) {
		dmc_h_advance(&h, 1);
		if (dmc_h_var(&h, "state") == 2)
			t = dmc_h_now(&h) - t0;
	}
	/* a small budget stretches the pass: the next look, not mainms */
	if (t < 0 || t > STRAY_PASSES * mainms ||
	    dmc_h_var(&h, "fcode") != 14 || dmc_h_var(&h, "fdet") != 1)
		fail_msg("%d lines per sample: the stray write inside #HBCHK "
			 "was not judged (state %g, fault %g detail %g, %.0f "
			 "ms after it)",
			 budget, dmc_h_var(&h, "state"), dmc_h_var(&h, "fcode"),
			 dmc_h_var(&h, "fdet"),
			 t < 0 ? dmc_h_now(&h) - t0 : t);
	assert_latched(&h, 14, 0, 1, 0);
	dmc_h_close(&h);
	return 1;
}

/*
 * A stray writer (it starts from its own value) whose write lands inside
 * #HBCHK, after the look began with the supervisor's last write: it is
 * judged, fault 14, axis 0, detail 1 at the next look, never taken for the heartbeat (its later values would then be in
 * sequence and hold the watchdog off). Tried with every line budget from
 * STRAY_BUDGET_MIN to STRAY_BUDGET_MAX; at least one must land there.
 */
static void test_hb_stray_inside_look(void **state)
{
	static struct dmc_h h;
	int first, copy, landed = 0;

	(void)state;
	DMC_H_CHECK(&h, dmc_h_open(&h));
	first = prog_line(&h, "#HBCHK", 0);
	copy = prog_line(&h, "hbold=", first);
	dmc_h_close(&h);
	assert_true(first > 0 && copy > first && copy - first < 10);
	for (int b = STRAY_BUDGET_MIN; b <= STRAY_BUDGET_MAX; b++)
		landed += stray_run(b, first, copy);
	print_message("measured: a stray hbpc write inside #HBCHK (lines "
		      "%d..%d) at %d of %d line budgets -> fault 14 at the next "
		      "look each\n",
		      first + 2, copy, landed,
		      STRAY_BUDGET_MAX - STRAY_BUDGET_MIN + 1);
	assert_true(landed > 0);
}

/*
 * The supervisor's heartbeat wraps from hbpcwr - 1 to 0: one step, in
 * sequence, no fault (written by hand here, every 50 ms, across the wrap).
 */
static void test_hb_wrap(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double wrap;
	int wrapped = 0;
	long v;

	dmc_h_params_default(&p);
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	DMC_H_CHECK(h, dmc_h_configure(h, &p));
	wrap = dmc_h_var(h, "hbpcwr");
	h->hb = (long)wrap - 12; /* arming takes about 3 writes */
	DMC_H_CHECK(h, dmc_h_arm(h));
	h->hb_on = 0;
	v = h->hb;
	assert_true(v < (long)wrap - 3);
	for (int i = 0; i < 20; i++) {
		v = (v + 1) % (long)wrap;
		wrapped |= v == 0;
		DMC_H_CHECK(h, dmc_h_set(h, "hbpc", (double)v));
		dmc_h_advance(h, 50);
	}
	assert_true(wrapped);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* The echo's modulus and weight in ZAB (constants.dmc hbemod, hbemul; the
 * harness decodes ZAB / 10000). */
#define ECHO_MOD 10000L

/*
 * Write hbpc=@v (by hand: the harness's own heartbeat is off) and wait for
 * the record's echo of it, in state @st, no fault: within two passes (a
 * write just after one pass's look is seen by the next). Then 20 ms more,
 * a supervisor's cycle.
 */
static void echo_follows(struct dmc_h *h, long v, int st)
{
	double t0 = dmc_h_now(h), mainms = dmc_h_var(h, "mainms");
	struct dmc_h_za za;

	DMC_H_CHECK(h, dmc_h_set(h, "hbpc", (double)v));
	do {
		dmc_h_advance(h, 1);
		DMC_H_CHECK(h, dmc_h_za(h, &za));
	} while (za.hb_echo != v % ECHO_MOD &&
		 dmc_h_now(h) - t0 < 2 * mainms + 1);
	if (za.hb_echo != v % ECHO_MOD || za.state != st || za.fcode != 0 ||
	    za.faxis != 0)
		fail_msg("hbpc %ld: echo %ld (want %ld) state %d fault %d axis "
			 "%d after %.0f ms",
			 v, za.hb_echo, v % ECHO_MOD, za.state, za.fcode,
			 za.faxis, dmc_h_now(h) - t0);
	dmc_h_advance(h, 20);
}

/* The record's echo, state, fault and axis now. */
static void assert_echo(struct dmc_h *h, long echo, int st, int code)
{
	struct dmc_h_za za;

	DMC_H_CHECK(h, dmc_h_za(h, &za));
	if (za.hb_echo != echo || za.state != st || za.fcode != code ||
	    za.faxis != 0)
		fail_msg("echo %ld state %d fault %d axis %d, want echo %ld "
			 "state %d fault %d axis 0",
			 za.hb_echo, za.state, za.fcode, za.faxis, echo, st,
			 code);
}

/*
 * The record echoes the heartbeat the program accepted as the supervisor's
 * (ZAB / hbemul = hbok mod hbemod, program 2.23): 0 before any; in the
 * safe state every change (no sequence judged there); armed, each write in
 * sequence within two passes, across a multiple of 10000 and across
 * hbpcwr (999999999: the largest echo, 9999, then 0); a write out of
 * sequence is not echoed: fault 14 detail 1, the echo stays at the last
 * value accepted, and stays there while latched (state 2 follows no
 * heartbeat) whatever is written next. Whatever a client writes to hbok,
 * the echo is whole, 0..9999, and leaves state, fault and axis intact.
 */
static void test_hb_echo(void **state)
{
	static const struct {
		double hbok;
		long echo;
	} odd[] = {
	    {2147483647.0, 3647}, {-123456789.0, 6789}, {12345.75, 2345}};
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	long v, wrap;
	int crossed = 0, wrapped = 0;

	dmc_h_params_default(&p);
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	DMC_H_CHECK(h, dmc_h_configure(h, &p));
	assert_true(dmc_h_var(h, "hbemod") == ECHO_MOD);
	assert_true(dmc_h_var(h, "hbemul") == ECHO_MOD);
	wrap = (long)dmc_h_var(h, "hbpcwr");
	dmc_h_advance(h, 50);
	assert_echo(h, 0, 0, 0); /* nothing written since #AUTO */
	echo_follows(h, 123459990, 0);
	echo_follows(h, 7, 0); /* safe: a jump is followed */
	/* a client's write to hbok itself: the echo is made whole and not
	 * negative, exact at the top of the range, and the fields below it
	 * stay whole */
	for (size_t i = 0; i < sizeof(odd) / sizeof(odd[0]); i++) {
		DMC_H_CHECK(h, dmc_h_set(h, "hbok", odd[i].hbok));
		dmc_h_advance(h, dmc_h_var(h, "mainms") + 1);
		assert_echo(h, odd[i].echo, 0, 0);
	}
	h->hb = 123459990; /* arming writes from 123459991 on */
	DMC_H_CHECK(h, dmc_h_arm(h));
	h->hb_on = 0;
	dmc_h_advance(h, 2 * dmc_h_var(h, "mainms") + 1);
	assert_echo(h, h->hb % ECHO_MOD, 1, 0); /* arming's last write */
	for (v = h->hb; v < 123460005;) {
		v++;
		crossed |= v % ECHO_MOD == 0;
		echo_follows(h, v, 1);
	}
	assert_true(crossed);
	/* back to safe (no fault), then armed again just below hbpcwr */
	DMC_H_CHECK(h, dmc_h_set(h, "offreq", 1));
	assert_true(dmc_h_wait_var(h, "state", 0, 50) >= 0);
	echo_follows(h, wrap - 12, 0);
	h->hb = wrap - 12;
	DMC_H_CHECK(h, dmc_h_arm(h));
	h->hb_on = 0;
	v = h->hb;
	assert_true(v < wrap - 3);
	for (int i = 0; i < 12; i++) {
		v = (v + 1) % wrap;
		if (v == wrap - 1)
			assert_int_equal(v % ECHO_MOD, 9999);
		wrapped |= v == 0;
		echo_follows(h, v, 1);
	}
	assert_true(wrapped);
	/* a stray client's value: fault 14/1, the echo stays at v */
	DMC_H_CHECK(h, dmc_h_set(h, "hbpc", (double)(v + 1000)));
	wait_latch(h, 2 * dmc_h_var(h, "mainms") + 1);
	assert_latched(h, 14, 0, 1, 0);
	dmc_h_advance(h, 10);
	assert_echo(h, v % ECHO_MOD, 2, 14);
	for (int i = 1; i <= 5; i++) {
		DMC_H_CHECK(h, dmc_h_set(h, "hbpc", (double)(v + i)));
		dmc_h_advance(h, 20);
		assert_echo(h, v % ECHO_MOD, 2, 14);
	}
}

/* Heartbeats the supervisor never writes (it writes whole numbers in
 * 0..hbpcwr-1, one more each cycle): written as the last value accepted
 * + step - wraps * hbpcwr. hbmaxd is 5 (dmc_h_params_default). */
struct hbodd {
	const char *what;
	double step;
	int wraps;
};

static const struct hbodd hbodd[] = {
    {"half a step", 0.5, 0},
    {"0.0001 of a step", 0.0001, 0},
    {"one and a half steps", 1.5, 0},
    {"hbmaxd - 0.5 steps", 4.5, 0},
    {"a step of 1 to below 0", 1, 1},
    {"a step of 1 that the wrap leaves below 1", 1, 2},
};

/*
 * Armed, a whole step is in sequence and echoed; then another client
 * writes a value the supervisor never writes: a fraction of a step (a
 * DMC number keeps 4 decimals, so hbold + 0.0001 is a new value), or a
 * whole step to a value below 0. It is out of sequence (program 2.24):
 * fault 14, axis 0, detail 1 within two passes (a write just after one
 * look is seen by the next); hbok and the echo stay at the whole value.
 */
static void test_hb_not_whole(void **state)
{
	(void)state;
	for (size_t k = 0; k < sizeof(hbodd) / sizeof(hbodd[0]); k++) {
		static struct dmc_h h;
		const struct hbodd *c = &hbodd[k];
		char line[48];
		double mainms, wrap, t;
		long v;

		if (dmc_h_setup(&h) < 0)
			fail_msg("%s: set-up: %s", c->what, h.err);
		assert_true(dmc_h_var(&h, "hbmaxd") == 5);
		h.hb_on = 0;
		mainms = dmc_h_var(&h, "mainms");
		wrap = dmc_h_var(&h, "hbpcwr");
		v = h.hb + 1;
		echo_follows(&h, v, 1); /* a whole step: in sequence */
		snprintf(line, sizeof(line), "hbpc=%.4f",
			 ((double)v + c->step) - (c->wraps * wrap));
		DMC_H_CHECK(&h, dmc_h_cmd(&h, line, NULL, 0));
		t = dmc_h_wait_var(&h, "state", 2, 2 * mainms + 1);
		if (t < 0)
			fail_msg("%s ('%s' after hbpc=%ld): no fault within "
				 "%.0f ms (state %g, hbok %.4f)",
				 c->what, line, v, 2 * mainms + 1,
				 dmc_h_var(&h, "state"), dmc_h_var(&h, "hbok"));
		print_message("measured: '%s' after hbpc=%ld (%s) -> fault 14 "
			      "in %.0f ms\n",
			      line, v, c->what, t);
		assert_latched(&h, 14, 0, 1, 0);
		assert_true(dmc_h_var(&h, "hbok") == (double)v);
		assert_echo(&h, v % ECHO_MOD, 2, 14);
		dmc_h_close(&h);
	}
}

/*
 * In the safe state (#HBSEEN: no sequence judged) every whole change is
 * followed, but not a value the supervisor never writes (program 2.24,
 * the fail-safe reading: no sign of its life): a fraction, a value below
 * 0 or at hbpcwr. hbold, hbok, the echo and hbt (the date a request is
 * judged by) stay at the last whole write; the next whole one is
 * followed again.
 */
static void test_hb_safe_not_whole(void **state)
{
	static const char *const odd[] = {"hbpc=1000.5", "hbpc=1000.0001",
					  "hbpc=999.9999", "hbpc=-7",
					  "hbpc=1000000000"};
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double hbt, mainms;

	dmc_h_params_default(&p);
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	DMC_H_CHECK(h, dmc_h_configure(h, &p));
	assert_true(dmc_h_var(h, "hbpcwr") == 1000000000);
	h->hb_on = 0;
	mainms = dmc_h_var(h, "mainms");
	echo_follows(h, 1000, 0);
	hbt = dmc_h_var(h, "hbt");
	for (size_t i = 0; i < sizeof(odd) / sizeof(odd[0]); i++) {
		DMC_H_CHECK(h, dmc_h_cmd(h, odd[i], NULL, 0));
		dmc_h_advance(h, 2 * mainms + 1);
		if (dmc_h_var(h, "hbold") != 1000 ||
		    dmc_h_var(h, "hbok") != 1000 || dmc_h_var(h, "hbt") != hbt)
			fail_msg("'%s' in the safe state was followed: hbold "
				 "%.4f hbok %.4f hbt %.0f (was %.0f)",
				 odd[i], dmc_h_var(h, "hbold"),
				 dmc_h_var(h, "hbok"), dmc_h_var(h, "hbt"),
				 hbt);
		assert_echo(h, 1000, 0, 0);
	}
	echo_follows(h, 1001, 0);
	assert_true(dmc_h_var(h, "hbold") == 1001);
	assert_true(dmc_h_var(h, "hbt") > hbt);
}

/* ---- another program at the controller (#FORGN) -------------------------- */

/* The number of received lines that start with @prefix. */
static int count_lines(const struct dmc_h *h, const char *prefix)
{
	size_t n = strlen(prefix);
	int k = 0;

	for (const char *p = h->unsol; *p;) {
		const char *eol = strchr(p, '\n');

		if (!eol)
			break;
		while (*p == ' ')
			p++;
		k += !strncmp(p, prefix, n);
		p = eol + 1;
	}
	return k;
}

/*
 * A connection opened while armed (the harness holds A and B since before
 * arming) is not a fault: a second supervisor or galil-load must be able
 * to look without stopping the robot (docs/dmc-interface.md). #FORGN
 * reports it once, "FOREIGN <mask>" (C = 4, H = 128), keeps it in fhnew,
 * and the robot stays armed for 10 main loops.
 */
static void test_new_handle(void **state)
{
	static const int handles[] = {2, 7};

	(void)state;
	for (size_t k = 0; k < sizeof(handles) / sizeof(handles[0]); k++) {
		static struct dmc_h h;
		double mainms, t;
		char want[32];

		if (dmc_h_setup(&h) < 0)
			fail_msg("set-up: %s", h.err);
		mainms = dmc_h_var(&h, "mainms");
		ctrl_handle_open(h.ctrl, handles[k]);
		t = dmc_h_wait_var(&h, "fhnew", 1 << handles[k], 5 * mainms);
		if (t < 0)
			fail_msg("handle %c: fhnew %g after %.0f ms",
				 'A' + handles[k], dmc_h_var(&h, "fhnew"),
				 5 * mainms);
		print_message("measured: handle %c opened -> reported in %.0f "
			      "ms\n",
			      'A' + handles[k], t);
		assert_true(t <= mainms + 1);
		dmc_h_advance(&h, 10 * mainms);
		snprintf(want, sizeof(want), "FOREIGN %d", 1 << handles[k]);
		assert_int_equal(count_lines(&h, want), 1);
		assert_int_equal(count_lines(&h, "FOREIGN"), 1);
		assert_true(dmc_h_var(&h, "state") == 1);
		assert_int_equal(dmc_h_fault_lines(&h, NULL, NULL, NULL), 0);
		dmc_h_close(&h);
	}
}

/*
 * A connection that was open when the motors went on closes (its client
 * leaves), and a new client gets the same handle: reported as new
 * ("FOREIGN 2", B), still no fault.
 */
static void test_handle_reused(void **state)
{
	struct dmc_h *h = *state;
	double mainms = dmc_h_var(h, "mainms");

	ctrl_handle_close(h->ctrl, 1);
	dmc_h_advance(h, 3 * mainms);
	assert_int_equal(count_lines(h, "FOREIGN"), 0);
	ctrl_handle_open(h->ctrl, 1);
	if (dmc_h_wait_var(h, "fhnew", 2, 5 * mainms) < 0)
		fail_msg("a new connection on the freed handle B was not "
			 "reported: fhnew %g",
			 dmc_h_var(h, "fhnew"));
	dmc_h_advance(h, 10 * mainms);
	assert_int_equal(count_lines(h, "FOREIGN 2"), 1);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

struct setcase {
	const char *cmd; /* what another program sends */
	int det;	 /* fault 14's detail */
};

/*
 * Another program changes a safety setting while armed: the watchdog or
 * the joystick timeout (detail 3), off-on-error on one axis (detail 4).
 * Fault 14 within one main loop (+1 sample).
 */
static void test_settings_changed(void **state)
{
	static const struct setcase cases[] = {
	    {"wdto=5000", 3}, {"jto=9000", 3}, {"OE 0,1,1", 4},
	    {"OE 1,0,1", 4},  {"OE ,,0", 4},
	};

	(void)state;
	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
		static struct dmc_h h;
		double mainms, t;

		if (dmc_h_setup(&h) < 0)
			fail_msg("set-up: %s", h.err);
		mainms = dmc_h_var(&h, "mainms");
		DMC_H_CHECK(&h, dmc_h_cmd(&h, cases[k].cmd, NULL, 0));
		t = wait_latch(&h, 5 * mainms);
		print_message("measured: %s -> fault 14 detail %d in %.0f ms\n",
			      cases[k].cmd, cases[k].det, t);
		assert_true(t <= mainms + 1);
		assert_latched(&h, 14, 0, cases[k].det, 0);
		dmc_h_close(&h);
	}
}

/* ---- potentiometer range (fault 16) -------------------------------------- */

struct potcase {
	const char *req; /* control request */
	int axis;	 /* 0..2 */
};

/*
 * A potentiometer reading outside potlo..pothi (0.25..4.75 V; the centre
 * reads 2.55 V on B, 2.54 V on C): +2.5 V on B reads 5.05 V, -2.4 V on C
 * reads 0.14 V.
 * Fault 16 on that axis within one main loop (+1 sample), fdet = the
 * reading * 1000, compared with the controller's own @AN (noise off, the
 * axis at rest: the reading does not change) within 1.
 */
static void test_pot_range(void **state)
{
	static const struct potcase pc[] = {
	    {"pot B offset 2.5", 1},
	    {"pot C offset -2.4", 2},
	};

	(void)state;
	for (size_t k = 0; k < sizeof(pc) / sizeof(pc[0]); k++) {
		static struct dmc_h h;
		char req[40], an[32];
		double mainms, t, v;

		if (dmc_h_setup(&h) < 0)
			fail_msg("set-up: %s", h.err);
		mainms = dmc_h_var(&h, "mainms");
		snprintf(req, sizeof(req), "pot %c noise 0", 'A' + pc[k].axis);
		DMC_H_CHECK(&h, dmc_h_control(&h, req));
		dmc_h_advance(&h, 20);
		assert_true(dmc_h_var(&h, "state") == 1);
		DMC_H_CHECK(&h, dmc_h_control(&h, pc[k].req));
		t = wait_latch(&h, 5 * mainms);
		snprintf(an, sizeof(an), "@AN[%d]", pc[k].axis + 1);
		v = mg(&h, an);
		print_message("measured: %s -> fault 16 in %.0f ms, fdet %g "
			      "(@AN %.4f V)\n",
			      pc[k].req, t, dmc_h_var(&h, "fdet"), v);
		assert_true(t <= mainms + 1);
		assert_true(v > 4.75 || v < 0.25);
		assert_latched(&h, 16, pc[k].axis + 1, v * 1000, 1);
		dmc_h_close(&h);
	}
}

/* ---- the invalid joystick timer (fault 3) -------------------------------- */

/* Set the joystick of axis A: 1 both channels of fwd, 0 channel a only. */
static void joy_a(struct dmc_h *h, int valid)
{
	DMC_H_CHECK(h, dmc_h_control(h, valid ? "joy A fwd" : "joy A fwd a"));
}

/*
 * A flickering channel while A fwd is held: invalid 20 ms, valid 20 ms,
 * repeated. The episode never ends (never valid for jto), so it trips
 * instead of restarting the timer: thread 1 reads every loopms, its first
 * invalid read tinv is within loopms of the first invalid sample t0, and it
 * trips at the first invalid read later than tinv + jto, which must fall in
 * an invalid phase: at most one valid phase (20 ms) + loopms after tinv +
 * jto. So the motors are off (thread 1 switches them off itself) within
 * jto + 2 * loopms + 20 of t0, and thread 0 latches fault 3 (axis 0, fdet
 * = the switch word of the invalid state, 1) within mainms (+1 sample) of
 * that. Run at each of the 40 phases of the flicker against the start of
 * the jog (1 ms apart), so that every alignment of reads and phases occurs.
 */
static void test_flicker(void **state)
{
	double off_min = 1e9, off_max = 0, lat_max = 0;

	(void)state;
	for (int phase = 0; phase < 40; phase++) {
		static struct dmc_h h;
		double jto, loopms, mainms, t0, t_off = -1, t_latch = -1;

		if (dmc_h_setup(&h) < 0)
			fail_msg("set-up: %s", h.err);
		jto = dmc_h_var(&h, "jto");
		loopms = dmc_h_var(&h, "loopms");
		mainms = dmc_h_var(&h, "mainms");
		joy_a(&h, 1);
		dmc_h_advance(&h, 1000 + phase);
		assert_true(dmc_h_axis(&h, 0).moving);
		t0 = dmc_h_now(&h);
		while (t_latch < 0 && dmc_h_now(&h) - t0 < 3 * jto) {
			double dt = dmc_h_now(&h) - t0;

			if (fmod(dt, 40) == 0)
				joy_a(&h, 0);
			else if (fmod(dt, 40) == 20)
				joy_a(&h, 1);
			dmc_h_advance(&h, 1);
			if (t_off < 0 && dmc_h_axis(&h, 0).motor_off)
				t_off = dmc_h_now(&h) - t0;
			if (dmc_h_var(&h, "state") == 2)
				t_latch = dmc_h_now(&h) - t0;
		}
		if (!(t_off > jto && t_off <= jto + 2 * loopms + 20) ||
		    !(t_latch >= t_off && t_latch <= t_off + mainms + 1))
			fail_msg("phase %d: motors off after %.0f ms, latched "
				 "after %.0f ms",
				 phase, t_off, t_latch);
		assert_latched(&h, 3, 0, 1, 0);
		off_min = fmin(off_min, t_off);
		off_max = fmax(off_max, t_off);
		lat_max = fmax(lat_max, t_latch);
		dmc_h_close(&h);
	}
	print_message("measured: flicker 20/20 ms -> motors off after "
		      "%.0f..%.0f ms, latched at most %.0f ms after the first "
		      "invalid sample\n",
		      off_min, off_max, lat_max);
}

/*
 * A single invalid transient of jto / 2, then the command steadily valid:
 * no fault; the episode ends after jto valid (jbad back to 0) and the axis
 * jogs again.
 */
static void test_transient_ok(void **state)
{
	struct dmc_h *h = *state;
	double jto = dmc_h_var(h, "jto"), a0;

	joy_a(h, 1);
	dmc_h_advance(h, 1000);
	joy_a(h, 0);
	dmc_h_advance(h, jto / 2);
	assert_true(dmc_h_var(h, "jbad") == 1);
	joy_a(h, 1);
	a0 = dmc_h_axis(h, 0).enc;
	dmc_h_advance(h, 2000);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_true(dmc_h_var(h, "jbad") == 0);
	assert_true(dmc_h_axis(h, 0).enc - a0 > 1000);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/*
 * Two invalid transients: separated by more than jto of valid state they
 * are two episodes (jto/2 and 0.6 jto, each shorter than jto): no fault.
 * Separated by less than jto they are one episode: held invalid after the
 * second begins, it trips at the first read more than jto after the first
 * transient's first invalid read, i.e. within jto + 2 * loopms of the
 * first transient, and is latched within mainms (+1) of that.
 */
static void test_two_transients(void **state)
{
	struct dmc_h *h = *state;
	double jto = dmc_h_var(h, "jto"), loopms = dmc_h_var(h, "loopms");
	double mainms = dmc_h_var(h, "mainms"), t0, t;

	joy_a(h, 1);
	dmc_h_advance(h, 1000);
	joy_a(h, 0);
	dmc_h_advance(h, jto / 2);
	joy_a(h, 1);
	dmc_h_advance(h, jto + 2 * loopms);
	joy_a(h, 0);
	dmc_h_advance(h, 0.6 * jto);
	joy_a(h, 1);
	dmc_h_advance(h, 1000);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);

	t0 = dmc_h_now(h);
	joy_a(h, 0);
	dmc_h_advance(h, jto / 2);
	joy_a(h, 1);
	dmc_h_advance(h, jto / 5);
	joy_a(h, 0);
	wait_latch(h, 2 * jto);
	t = dmc_h_now(h) - t0;
	print_message("measured: two transients %.0f ms apart -> fault 3 "
		      "%.0f ms after the first\n",
		      jto / 5, t);
	assert_true(t > jto && t <= jto + 2 * loopms + mainms + 1);
	assert_latched(h, 3, 0, 1, 0);
}

/* ---- position-tracking targets inside FL/BL ------------------------------ */

/*
 * Jogging into the forward soft limit with FL = sfwd (as the supervisor
 * sets them): the target is clamped one count inside, so the reference
 * never reaches sfwd, the controller's FL never stops the axis (no stop
 * code 2), and the axis comes to rest at sfwd - 1 (the encoder settles on
 * the target within one count).
 */
static void test_pt_inside_fl(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double ref_max = -1e9, pos;

	dmc_h_params_default(&p);
	p.sfwd[0] = 3000;
	setup_armed(h, &p, "FL 3000");
	DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
	for (int i = 0; i < 3000; i++) {
		dmc_h_advance(h, 1);
		if (dmc_h_axis(h, 0).ref > ref_max)
			ref_max = dmc_h_axis(h, 0).ref;
	}
	pos = dmc_h_axis(h, 0).enc;
	print_message("measured: jog into sfwd 3000: rest at %.0f, highest "
		      "reference %.3f\n",
		      pos, ref_max);
	assert_true(ref_max <= p.sfwd[0] - 1);
	assert_true(pos <= p.sfwd[0] - 1 && pos >= p.sfwd[0] - 2);
	assert_int_equal(dmc_h_axis(h, 0).moving, 0);
	assert_true(dmc_h_axis(h, 0).stop_code != 2);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* The same toward the reverse soft limit with BL = srev: rest at srev + 1,
 * the reference never below it, no stop code 3. */
static void test_pt_inside_bl(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double ref_min = 1e9, pos;

	dmc_h_params_default(&p);
	p.srev[1] = -2000;
	setup_armed(h, &p, "BL ,-2000");
	DMC_H_CHECK(h, dmc_h_control(h, "joy B rev"));
	for (int i = 0; i < 3000; i++) {
		dmc_h_advance(h, 1);
		if (dmc_h_axis(h, 1).ref < ref_min)
			ref_min = dmc_h_axis(h, 1).ref;
	}
	pos = dmc_h_axis(h, 1).enc;
	assert_true(ref_min >= p.srev[1] + 1);
	assert_true(pos >= p.srev[1] + 1 && pos <= p.srev[1] + 2);
	assert_true(dmc_h_axis(h, 1).stop_code != 3);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_int_equal(dmc_h_fault_lines(h, NULL, NULL, NULL), 0);
}

/* ---- encoder failure at rest (fault 9) ----------------------------------- */

/*
 * An encoder failure at rest: A with OA 1 (OT 30 samples, OV 0.9438 V, the
 * controller's defaults), its encoder stuck, and a torque offset OF 2 V
 * above OV (the simulated motor ignores torque, so only OF makes one at
 * rest). OA switches A off after OT samples; #POSERR names the axis: fault
 * 9 ENCODER axis 1 detail 12, not fault 4 on axis 0.
 *
 * galil-sim records stop code 12 even for an axis at rest (its documented
 * fail-safe choice, docs/galil-sim-controller.md 8.21), so #POSERR takes
 * its first branch (stop code 12). The last branch (an axis on at the last
 * #MAIN pass and off now without a stop code: a firmware that leaves the
 * stop code at rest) cannot be produced by galil-sim.
 */
static void test_oa_at_rest(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;
	double mainms, ot, t_off, t_latch;

	dmc_h_params_default(&p);
	setup_armed(h, &p, "OA 1,0,0");
	mainms = dmc_h_var(h, "mainms");
	ot = mg(h, "_OTA");
	assert_true(mg(h, "_OVA") < 2);
	DMC_H_CHECK(h, dmc_h_control(h, "enc A stuck"));
	dmc_h_advance(h, 50);
	assert_true(dmc_h_var(h, "state") == 1); /* at rest: nothing yet */
	DMC_H_CHECK(h, dmc_h_cmd(h, "OF 2,0,0", NULL, 0));
	t_off = dmc_h_wait_motor_off(h, 1, ot + 10);
	assert_true(t_off >= 0);
	t_latch = wait_latch(h, 3 * mainms) + t_off;
	print_message("measured: OA at rest (OT %.0f) -> motor off after %.0f "
		      "ms, fault after %.0f ms\n",
		      ot, t_off, t_latch);
	assert_true(t_off >= ot && t_off <= ot + 1);
	assert_true(t_latch <= t_off + mainms + 1);
	assert_latched(h, 9, 1, 12, 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_host_pa_bg, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_host_jg_bg, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_host_bg_other_axis,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_host_sp_overwritten,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_host_sp_persistent,
					    dmc_h_fx_armed, dmc_h_fx_free),
	    cmocka_unit_test(test_hb_out_of_sequence),
	    cmocka_unit_test(test_hb_stray_inside_look),
	    cmocka_unit_test_setup_teardown(test_hb_wrap, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_hb_echo, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test(test_hb_not_whole),
	    cmocka_unit_test_setup_teardown(test_hb_safe_not_whole,
					    dmc_h_fx_new, dmc_h_fx_free),
	    cmocka_unit_test(test_new_handle),
	    cmocka_unit_test_setup_teardown(test_handle_reused, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test(test_settings_changed),
	    cmocka_unit_test(test_pot_range),
	    cmocka_unit_test(test_flicker),
	    cmocka_unit_test_setup_teardown(test_transient_ok, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_two_transients, dmc_h_fx_armed,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_pt_inside_fl, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_pt_inside_bl, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_oa_at_rest, dmc_h_fx_new,
					    dmc_h_fx_free),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
