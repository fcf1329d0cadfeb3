/*
 * test_sys_soak.c - the soak: a randomised, seeded session of
 * joystick use on galil-sim with potentiometer noise at half the
 * encoder/pot tolerance on every axis and transient invalid joystick
 * states shorter than half the invalid-input timeout J. Nothing in it may
 * trip the supervisor or the controller: any FAULT line fails the run.
 *
 *   ROBOELF_SOAK_S     duration in simulated seconds (default 60: make check;
 *                      `make soak` sets SOAK_SECONDS, default 600)
 *   ROBOELF_SOAK_SEED  the seed (default 20261125); the seed is printed so
 *                      that a failing run can be replayed exactly
 *
 * At the end: roboelf quits (exit 0) and the figures are printed from its
 * own "stats:" log line (cycles, overruns, lateness p50/p99/max, worst
 * reply age) with the commands, transients and counts moved.
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

#define SOAK_S_DEFAULT	  60
#define SOAK_SEED_DEFAULT 20261125ULL
#define SLACK_MS	  25
#define EXIT_WAIT_MS	  5000
#define TRANSIENT_PCT	  20 /* share of steps that are a transient */

static struct sys_env env;
static int env_ok;
static struct sys_case cs;

struct soak_fig {
	int moves, transients;
	double moved_counts, longest_transient_ms;
};

/* ---- fixtures ------------------------------------------------------------ */

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

/* ---- checks -------------------------------------------------------------- */

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

/* ---- the random session -------------------------------------------------- */

static unsigned long rng_next(unsigned long long *s)
{
	*s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
	return (unsigned long)(*s >> 33);
}

static unsigned long long env_ull(const char *name, unsigned long long def)
{
	const char *v = getenv(name);

	return v && *v ? strtoull(v, NULL, 10) : def;
}

/* Inject @req (a control request); return the simulated time of its event
 * ("input: joy ..." for joystick requests, "inject: ..." otherwise). */
static double inject(const char *req)
{
	double before = sys_sim_time(&cs), t;
	char want[300];

	if (before < 0 || sys_ctl(&cs, "%s", req) < 0)
		fail_msg("%s", cs.err);
	snprintf(want, sizeof(want), "%s%s",
		 req[0] == 'j' ? "input: " : "inject: ", req);
	if (sys_wait_event(&cs, want, before, 2000, &t) < 0)
		fail_msg("%s", cs.err);
	return t;
}

/* One joystick command: an axis, a direction away from the nearer end, a
 * hold of 200-1500 ms, then neutral and a rest of 100-500 ms. */
static void one_move(unsigned long long *rng, struct soak_fig *f)
{
	static const double half[3] = {50000, 50000, 40000};
	char st[2048], key[8], axis = (char)('A' + rng_next(rng) % 3);
	const char *dir;
	double x0, x1, hold = 200 + rng_next(rng) % 1300, t;

	if (sys_state(&cs, st, sizeof(st)) < 0)
		fail_msg("%s", cs.err);
	snprintf(key, sizeof(key), "%c.act", axis);
	x0 = sys_state_num(st, key);
	if (fabs(x0) > 0.5 * half[axis - 'A'])
		dir = x0 > 0 ? "rev" : "fwd";
	else
		dir = rng_next(rng) % 2 ? "fwd" : "rev";
	if (sys_ctl(&cs, "joy %c %s", axis, dir) < 0)
		fail_msg("%s", cs.err);
	t = sys_sim_time(&cs);
	if (sys_wait_sim(&cs, t + hold, (int)hold + 5000) < 0)
		fail_msg("%s", cs.err);
	if (sys_ctl(&cs, "joy %c neutral", axis) < 0)
		fail_msg("%s", cs.err);
	if (sys_wait_stopped(&cs, axis, 3000, &t) < 0 ||
	    sys_wait_sim(&cs, t + 100 + rng_next(rng) % 400, 5000) < 0 ||
	    sys_state(&cs, st, sizeof(st)) < 0)
		fail_msg("%s", cs.err);
	x1 = sys_state_num(st, key);
	f->moved_counts += fabs(x1 - x0);
	f->moves++;
}

/* A transient invalid joystick state at neutral: set, held for J/8 to
 * J/2 by the simulator's clock, cleared. */
static void one_transient(unsigned long long *rng, struct soak_fig *f)
{
	static const char *const tr[][4] = {
	    {"joy A fwd a", NULL, "joy A neutral", NULL},
	    {"in 7 1", NULL, "release in 7", NULL},
	    {"joy B fwd", "joy C rev", "joy C neutral", "joy B neutral"},
	    {"joy A rev", "in 1 1", "release in 1", "joy A neutral"},
	    {"joy C fwd b", NULL, "joy C neutral", NULL},
	};
	const char *const *s = tr[rng_next(rng) % (sizeof(tr) / sizeof(tr[0]))];
	double hold = env.jto_ms / 8.0 + rng_next(rng) % (env.jto_ms * 3 / 8);
	double limit = env.jto_ms - 2 * SYS_LOOPMS - SLACK_MS, t0, t1;

	t0 = inject(s[0]);
	if (s[1])
		inject(s[1]);
	if (sys_wait_sim(&cs, t0 + hold, 5000) < 0)
		fail_msg("%s", cs.err);
	t1 = inject(s[2]);
	if (s[3])
		t1 = inject(s[3]);
	if (t1 - t0 > limit)
		fail_msg("the transient '%s' lasted %.0f ms (> %.0f ms): the "
			 "machine is too slow for this test",
			 s[0], t1 - t0, limit);
	if (t1 - t0 > f->longest_transient_ms)
		f->longest_transient_ms = t1 - t0;
	/* a full J after the end: a latch would have shown by now */
	if (sys_wait_sim(&cs, t1 + env.jto_ms + 3 * env.period_ms, 5000) < 0)
		fail_msg("%s", cs.err);
	f->transients++;
}

/* Half the smallest local pot step x (1 + allowed error) of @t. */
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

static void set_noise(void)
{
	struct re_calset *set = calloc(1, sizeof(*set));
	char err[512];

	assert_non_null(set);
	if (re_calfile_load(env.cal, NULL, set, err, sizeof(err)) != 0) {
		free(set);
		fail_msg("%s", err);
	}
	for (int i = 0; i < 3; i++) {
		double n = half_tolerance(&set->axis[i]);

		if (sys_ctl(&cs, "pot %c noise %.4f", 'A' + i, n) < 0) {
			free(set);
			fail_msg("%s", cs.err);
		}
		print_message("[   INFO   ] axis %c: potentiometer noise bound "
			      "%.1f mV (half the tolerance)\n",
			      'A' + i, n * 1000);
	}
	free(set);
}

static void quit_and_report(const struct soak_fig *f, double sim_s)
{
	char line[1024];
	int status;

	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0)
		fail_msg("roboelf did not exit within %d ms of SIGTERM",
			 EXIT_WAIT_MS);
	if (proc_exit_code(&cs.re) != 0)
		fail_msg("roboelf exited %d, not 0:\n%s",
			 proc_exit_code(&cs.re),
			 proc_output(&cs.re, PROC_STDOUT));
	if (sys_log_find(&cs, "stats: cycles=", NULL, line, sizeof(line)) < 0)
		fail_msg("no stats line in the log: %s", cs.err);
	print_message("[   INFO   ] soak figures: %.0f s, %d commands, %d "
		      "transients (longest %.0f ms, J %d ms), %.0f counts "
		      "moved, 0 trips\n",
		      sim_s, f->moves, f->transients, f->longest_transient_ms,
		      env.jto_ms, f->moved_counts);
	print_message("[   INFO   ] %s\n", strstr(line, "stats:"));
}

static void test_soak(void **state)
{
	unsigned long long seed =
	    env_ull("ROBOELF_SOAK_SEED", SOAK_SEED_DEFAULT);
	unsigned long long rng = seed;
	long secs = (long)env_ull("ROBOELF_SOAK_S", SOAK_S_DEFAULT);
	struct soak_fig f = {0};
	double t0, t_end;

	(void)state;
	if (!env_ok)
		fail_msg("no calibrated environment: %s", env.err);
	if (secs < 1)
		secs = 1;
	if (sys_case_start(&cs, &env, NULL) < 0 ||
	    sys_ctl(&cs, "watch state") < 0)
		fail_msg("%s", cs.err);
	print_message("[   INFO   ] soak: %ld s, seed %llu "
		      "(ROBOELF_SOAK_S, ROBOELF_SOAK_SEED)\n",
		      secs, seed);
	set_noise();
	t0 = sys_sim_time(&cs);
	t_end = t0 + secs * 1000.0;
	while (sys_sim_time(&cs) < t_end) {
		if (rng_next(&rng) % 100 < TRANSIENT_PCT)
			one_transient(&rng, &f);
		else
			one_move(&rng, &f);
		no_fault("soak");
	}
	still_armed("after the soak");
	if (f.moves < secs / 3 || f.moved_counts < 1000.0 * secs)
		fail_msg("the soak hardly moved the robot: %d commands, %.0f "
			 "counts",
			 f.moves, f.moved_counts);
	quit_and_report(&f, (sys_sim_time(&cs) - t0) / 1000.0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_teardown(test_soak, case_teardown),
	};

	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
