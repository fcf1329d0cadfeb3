/*
 * test_sys_notrip.c - what must NOT trip the supervisor or the controller:
 * transient invalid joystick states shorter than the timeout,
 * potentiometer noise at half the encoder/pot tolerance, reply delays
 * between the non-critical and the critical watchdog limits. The long
 * randomised session of joystick use is the soak, test_sys_soak.c.
 *
 * Each case runs on a fresh galil-sim with roboelf started from the
 * calibration made once in the group setup, and asserts: no FAULT line,
 * the program still armed (state 1), motor power on and every motor on,
 * and the robot still answering the joystick; then a clean quit (exit 0).
 */
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "re_calfile.h"
#include "sys_h.h"

#define SLACK_MS     25
#define EXIT_WAIT_MS 5000

static struct sys_env env;
static int env_ok;
static struct sys_case cs;

/* ---- fixtures and common checks ----------------------------------------- */

static int group_setup(void **state)
{
	(void)state;
	env_ok = sys_env_ready(&env);
	return 0;
}

static int group_teardown(void **state)
{
	(void)state;
	sys_env_done(&env, env_ok);
	return 0;
}

static int case_teardown(void **state)
{
	(void)state;
	sys_case_stop(&cs);
	return 0;
}

static void start(void)
{
	if (!env_ok)
		fail_msg("no calibrated environment: %s", env.err);
	if (sys_case_start(&cs, &env, NULL) < 0)
		fail_msg("%s", cs.err);
	if (sys_ctl(&cs, "watch state") < 0)
		fail_msg("%s", cs.err);
}

static void no_fault(const char *when)
{
	if (sys_no_fault(&cs, when) < 0)
		fail_msg("%s", cs.err);
}

/* Still armed: program state 1, power on, every motor on. */
static void still_armed(const char *when)
{
	if (sys_still_armed(&cs, when) < 0)
		fail_msg("%s", cs.err);
}

/* The joystick still moves axis @axis: a short jog and back to neutral. */
static void still_moves(char axis)
{
	char req[32];

	snprintf(req, sizeof(req), "joy %c fwd", axis);
	if (sys_ctl(&cs, "%s", req) < 0 ||
	    sys_wait_moving(&cs, axis, 200, 3000) < 0)
		fail_msg("%s", cs.err);
	if (sys_ctl(&cs, "joy %c neutral", axis) < 0)
		fail_msg("%s", cs.err);
	if (sys_wait_stopped(&cs, axis, 3000, &(double){0}) < 0)
		fail_msg("%s", cs.err);
}

static void quit_clean(void)
{
	int status;

	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0)
		fail_msg("roboelf did not exit within %d ms of SIGTERM",
			 EXIT_WAIT_MS);
	if (proc_exit_code(&cs.re) != 0)
		fail_msg("roboelf exited %d, not 0:\n%s",
			 proc_exit_code(&cs.re),
			 proc_output(&cs.re, PROC_STDOUT));
}

/* Inject @req; return the simulated time of its event. */
static double inject(const char *evt, const char *req)
{
	double before = sys_sim_time(&cs), t;
	char want[300];

	if (before < 0 || sys_ctl(&cs, "%s", req) < 0)
		fail_msg("%s", cs.err);
	snprintf(want, sizeof(want), "%s%s", evt, req);
	if (sys_wait_event(&cs, want, before, 2000, &t) < 0)
		fail_msg("%s", cs.err);
	return t;
}

/* ---- transient invalid joystick states ---------------------------------- */

struct transient {
	const char *set[2];   /* requests making the state invalid */
	const char *clear[2]; /* requests making it valid again */
};

/*
 * Each invalid state lasts half the invalid-input timeout J (by the
 * simulator's clock: from the first request's event to the last clearing
 * request's event). If the machine stretches it past J - 2 DMC loops -
 * SLACK the case cannot say anything and fails as such.
 */
static void one_transient(const struct transient *tr)
{
	double t0, t1, hold = env.jto_ms / 2.0;
	double limit = env.jto_ms - 2 * SYS_LOOPMS - SLACK_MS;

	t0 = inject(tr->set[0][0] == 'j' ? "input: " : "inject: ", tr->set[0]);
	if (tr->set[1])
		inject(tr->set[1][0] == 'j' ? "input: " : "inject: ",
		       tr->set[1]);
	if (sys_wait_sim(&cs, t0 + hold, 5000) < 0)
		fail_msg("%s", cs.err);
	t1 = inject(tr->clear[0][0] == 'j' ? "input: " : "inject: ",
		    tr->clear[0]);
	if (tr->clear[1])
		t1 = inject(tr->clear[1][0] == 'j' ? "input: " : "inject: ",
			    tr->clear[1]);
	if (t1 - t0 > limit)
		fail_msg("the transient '%s' lasted %.0f ms (> %.0f ms): the "
			 "machine is too slow for this test",
			 tr->set[0], t1 - t0, limit);
	print_message("[   INFO   ] invalid state '%s%s%s' for %.0f ms (J %d "
		      "ms): no trip expected\n",
		      tr->set[0], tr->set[1] ? " + " : "",
		      tr->set[1] ? tr->set[1] : "", t1 - t0, env.jto_ms);
	/* a full J after the end: a latch would have shown by now */
	if (sys_wait_sim(&cs, t1 + env.jto_ms + 3 * env.period_ms, 5000) < 0)
		fail_msg("%s", cs.err);
	still_armed(tr->set[0]);
}

static void test_transient_invalid(void **state)
{
	static const struct transient tr[] = {
	    /* one channel of a command (broken switch for a moment) */
	    {{"joy A fwd a", NULL}, {"joy A neutral", NULL}},
	    /* a switch stuck closed for a moment, at neutral */
	    {{"in 7 1", NULL}, {"release in 7", NULL}},
	    /* two commands at once: B fwd, then C rev pressed too */
	    {{"joy B fwd", "joy C rev"}, {"joy C neutral", "joy B neutral"}},
	    /* both directions of one axis */
	    {{"joy A rev", "in 1 1"}, {"release in 1", "joy A neutral"}},
	};

	(void)state;
	start();
	for (size_t i = 0; i < sizeof(tr) / sizeof(tr[0]); i++)
		one_transient(&tr[i]);
	still_moves('A');
	still_moves('B');
	still_armed("after the transients");
	quit_clean();
}

/* ---- potentiometer noise at half the tolerance -------------------------- */

/* Half the smallest encoder/pot tolerance of axis @i in the calibration:
 * tolerance = (1 + allowed_error) x the local pot step. */
static double half_tolerance(const struct re_caltable *t)
{
	double min_step = INFINITY;

	for (int k = 0; k + 1 < t->n; k++) {
		double d = fabs(t->pot_v[k + 1] - t->pot_v[k]);

		if (d < min_step)
			min_step = d;
	}
	return 0.5 * (1.0 + env.allowed_error) * min_step;
}

static void jog(char axis, const char *dir, double ms)
{
	char req[32];
	double t;

	snprintf(req, sizeof(req), "joy %c %s", axis, dir);
	t = inject("input: ", req);
	if (sys_wait_sim(&cs, t + ms, (int)ms + 5000) < 0)
		fail_msg("%s", cs.err);
	if (sys_ctl(&cs, "joy %c neutral", axis) < 0)
		fail_msg("%s", cs.err);
	if (sys_wait_stopped(&cs, axis, 3000, &(double){0}) < 0)
		fail_msg("%s", cs.err);
	no_fault("jogging with noise");
}

static void test_pot_noise_half_tolerance(void **state)
{
	struct re_calset *set = calloc(1, sizeof(*set));
	char err[512];
	double noise[3];

	(void)state;
	assert_non_null(set);
	if (!env_ok)
		fail_msg("no calibrated environment: %s", env.err);
	if (re_calfile_load(env.cal, NULL, set, err, sizeof(err)) != 0)
		fail_msg("%s", err);
	for (int i = 0; i < 3; i++)
		noise[i] = half_tolerance(&set->axis[i]);
	free(set);
	start();
	for (int i = 0; i < 3; i++) {
		if (sys_ctl(&cs, "pot %c noise %.4f", 'A' + i, noise[i]) < 0)
			fail_msg("%s", cs.err);
		print_message("[   INFO   ] axis %c: potentiometer noise bound "
			      "%.1f mV (half the tolerance)\n",
			      'A' + i, noise[i] * 1000);
	}
	for (int i = 0; i < 3; i++) {
		jog((char)('A' + i), "fwd", 1500);
		jog((char)('A' + i), "rev", 1500);
	}
	if (sys_wait_sim(&cs, sys_sim_time(&cs) + 2000, 5000) < 0)
		fail_msg("%s", cs.err);
	still_armed("after jogging with noise");
	quit_clean();
}

/* ---- watchdog: replies late, but within the critical limit -------------- */

/*
 * The reply age is the time between two good replies. A step of D ms in
 * the link's latency makes one age of P + D; choosing P + D half-way
 * between the non-critical limit N and the critical limit C gives a
 * non-critical watchdog event (logged) and no fault. The step is repeated
 * while an axis moves. After the quit, the log accounts for every late
 * reply the supervisor counted: the first logged in full, the ones within
 * RE_SUPER_WD_WINDOW_MS after it in a summary (the last one at the quit).
 */
static void test_watchdog_between_limits(void **state)
{
	double n, c, d;
	int steps = 6;
	char line[4096];
	long full = 0, sums = 0, logged, counted;

	(void)state;
	start();
	n = env.noncrit_factor * env.period_ms;
	c = env.crit_factor * env.period_ms;
	d = (n + c) / 2.0 - env.period_ms;
	print_message("[   INFO   ] latency steps of %.0f ms: reply age %.0f "
		      "ms between N %.0f and C %.0f ms\n",
		      d, env.period_ms + d, n, c);
	inject("input: ", "joy A fwd");
	for (int k = 0; k < steps; k++) {
		char req[32];
		double t;

		snprintf(req, sizeof(req), "link delay %.0f", d);
		t = inject("inject: ", req);
		if (sys_wait_sim(&cs, t + 6 * env.period_ms, 5000) < 0)
			fail_msg("%s", cs.err);
		t = inject("inject: ", "link delay 0");
		if (sys_wait_sim(&cs, t + 4 * env.period_ms, 5000) < 0)
			fail_msg("%s", cs.err);
		no_fault("latency step");
	}
	inject("inject: ", "link ok");
	if (sys_ctl(&cs, "joy A neutral") < 0)
		fail_msg("%s", cs.err);
	still_armed("after the latency steps");
	if (sys_log_find(&cs, " WARN ", "watchdog", line, sizeof(line)) < 0)
		fail_msg("no non-critical watchdog event in the log: %s",
			 cs.err);
	print_message("[   INFO   ] logged: %s\n", line);
	still_moves('B');
	quit_clean();
	logged = sys_wd_warnings(&cs, &full, &sums);
	counted = sys_wd_counter(&cs);
	if (logged < 0 || counted < 0)
		fail_msg("%s", cs.err);
	print_message("[   INFO   ] late replies: %ld counted, %ld in the log "
		      "(%ld lines in full, %ld summaries)\n",
		      counted, logged, full, sums);
	if (sums && sys_log_find(&cs, " WARN watchdog: ", " more late ", line,
				 sizeof(line)) == 0)
		print_message("[   INFO   ] summary: %s\n", line);
	if (full < 1 || logged != counted)
		fail_msg("the log accounts for %ld late replies (%ld lines, "
			 "%ld summaries), the supervisor counted %ld",
			 logged, full, sums, counted);
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_transient_invalid),
	    T(test_pot_noise_half_tolerance),
	    T(test_watchdog_between_limits),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
