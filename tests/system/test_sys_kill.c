/*
 * test_sys_kill.c - kill-anywhere: roboelf killed (SIGKILL) in every phase
 * ("every phase supervised", docs/supervisor.md; docs/safety.md section 2a,
 * D23), on the short-robot rig (sys_rig_h.h): galil-sim's short robot
 * running dmc/ (downloaded by galil-load), roboelf supervising it through
 * the virtual relay.
 *
 * One full calibration for the binary (group setup; it also measures the
 * phase boundaries from galil-sim's events), then every instant on a fresh
 * galil-sim. Times are galil-sim's simulated ms. SIGKILL at 33 instants
 * spread over every phase (start-up with the relay open, with it closed,
 * the service state requested, full calibration, centring after a
 * calibration from the file, back to safe, the arm requested, armed at
 * rest, armed jogging, latched), then one instant per phase with the
 * controller's motor-power output wired (power_output 3): every motor off
 * and at rest within the controller's deadline, or off already; motor
 * power cut as well.
 *
 * Each case runs all its instants, prints a [ MEASURE ] line for each and
 * a [  FAILS   ] line for each failed assertion, then fails.
 *
 * Environment: ROBOELF_BIN, ROBOELF_TOP (see sys_h.h), ROBOELF_KEEP=1
 * keeps the temporary directory (configurations, logs and the events of
 * every case), ROBOELF_SYS_FILTER=PATTERN runs only the matching tests.
 */
#include <math.h>
#include <poll.h>
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

#include "sys_phase_h.h"

static struct sys_env env;
static int env_ok;
static struct sys_case cs;
static struct rig_ref ref; /* measured by the group set-up */

static int group_setup(void **state)
{
	(void)state;
	env_ok = rig_env_ready(&env, &ref);
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

/* ---- kill-anywhere ------------------------------------------------------ */

/* The phase the signal at @t_sig really met, from galil-sim's events (the
 * windows of start-up are a few ms wide; the test reports what it hit). */
static enum ph_phase actual_phase(const struct sys_case *c,
				  enum ph_phase intent, double t_sig,
				  double hbpc)
{
	int svc = sys_event_find(c, PH_SVC_ON, 0);
	double t_svc = svc >= 0 ? c->ev[svc].t_ms : 1e300;
	int off = sys_event_find(c, "axis A motor off", t_svc);
	int thr = sys_event_find(c, "thread 1 started", 0);

	if (intent == PH_LATCHED)
		return PH_LATCHED;
	if (sys_event_find(c, "relay on (byte", 0) < 0 ||
	    c->ev[sys_event_find(c, "relay on (byte", 0)].t_ms > t_sig)
		return PH_BOOT;
	if (t_svc > t_sig)
		return hbpc != 0 ? PH_SVCREQ : PH_RELAY;
	if (thr >= 0 && c->ev[thr].t_ms <= t_sig)
		return intent == PH_JOG ? PH_JOG : PH_ARMED;
	if (off >= 0 && c->ev[off].t_ms <= t_sig)
		/* whether armreq was written: seen by ph_reach() */
		return intent == PH_ARMREQ ? PH_ARMREQ : PH_OFF;
	return intent == PH_CENTRE ? PH_CENTRE : PH_CALIB;
}

struct phase_stats {
	int kills, off_before; /* off_before: the motors were off already */
	double worst_ms;       /* worst time to motors off, -1 none */
	double worst_pout_ms;  /* worst time to the power output cut, -1 */
};

static void stats_add(struct phase_stats *s, const struct ph_off *r)
{
	s->kills++;
	if (!r->on_at_sig && !r->on_after)
		s->off_before++;
	else if (r->off_ms > s->worst_ms)
		s->worst_ms = r->off_ms;
	if (r->pout_ms > s->worst_pout_ms)
		s->worst_pout_ms = r->pout_ms;
}

static void print_table(const char *title, const struct phase_stats *s,
			int power_output)
{
	print_message(
	    "[ MEASURE  ] %s: phase | kills | worst time to motors "
	    "off | deadline%s\n",
	    title, power_output ? " | worst power output cut | deadline" : "");
	for (int p = 0; p < PH_COUNT; p++) {
		char worst[64], pout[64] = "";

		if (!s[p].kills)
			continue;
		if (s[p].worst_ms >= 0)
			snprintf(worst, sizeof(worst), "%.0f ms%s",
				 s[p].worst_ms,
				 s[p].off_before ? " (some off already)" : "");
		else
			snprintf(worst, sizeof(worst), "off already");
		if (power_output && s[p].worst_pout_ms >= 0)
			snprintf(pout, sizeof(pout), " | %.0f ms | %d ms",
				 s[p].worst_pout_ms, RIG_D_POWER_MS);
		else if (power_output)
			snprintf(pout, sizeof(pout), " | cut already | %d ms",
				 RIG_D_POWER_MS);
		print_message("[ MEASURE  ]   %-22s | %2d | %-24s | %d ms%s\n",
			      ph_name[p], s[p].kills, worst, RIG_D_CTRL_MS,
			      pout);
	}
}

/* One kill at @in: a fresh case, the instant, SIGKILL, the checks. */
static void kill_one(const struct ph_instant *in, int power_output,
		     struct phase_stats *stats)
{
	struct ph_off r;
	double anchor, t_sig, t0;
	enum ph_phase got;
	char what[160], st[2048];

	snprintf(what, sizeof(what), "kill in %s%s%s +%.0f ms%s",
		 ph_name[in->ph], in->line ? " at '" : "",
		 in->line ? in->line : "", in->at_ms,
		 power_output ? " (power output wired)" : "");
	if (ph_reach(&cs, &env, in, power_output, &anchor) < 0) {
		rig_fail("%s: %s", what, cs.err);
		sys_case_stop(&cs);
		return;
	}
	if (in->ph == PH_JOG && sys_state(&cs, st, sizeof(st)) == 0 &&
	    !(fabs(sys_state_num(st, "A.vel")) > 0))
		rig_fail("%s: axis A is not moving: %s", what, st);
	t_sig = rig_signal_at(&cs, SIGKILL, &t0);
	proc_wait_exit(&cs.re, RIG_EXIT_WAIT_MS, NULL);
	if (t_sig < 0 || sys_events(&cs) < 0) {
		rig_fail("%s: %s", what, cs.err);
		sys_case_stop(&cs);
		return;
	}
	ph_check_off(&cs, what, t_sig, power_output, &r);
	got = actual_phase(&cs, in->ph, t_sig, sys_state_num(r.st, "var.hbpc"));
	if (got != in->ph && !(in->ph == PH_RELAY && got == PH_SVCREQ))
		rig_fail("%s: the kill met '%s' instead", what, ph_name[got]);
	stats_add(&stats[got], &r);
	ph_measure_line("kill", got, t_sig, t_sig - t0, anchor, &r);
	sys_case_stop(&cs);
}

/* The instants: every progress line of start-up before the relay closes;
 * the relay just closed; the service request pending; the calibration and
 * the centring at evenly spread fractions of their measured lengths; the
 * arm request pending; armed at rest spread over one supervisor period;
 * jogging spread over the jog's ramp; latched spread after the fault. */
static size_t kill_plan(struct ph_instant *plan, size_t cap, int full)
{
	static const char *const boot[] = {
	    "roboelf: opening the E-stop relay",
	    "roboelf: connecting to the controller",
	    "roboelf: controller DMC",
	    "roboelf: calibration from the file",
	    "roboelf: halting the controller program",
	    "roboelf: controller configured",
	};
	/* the whole plan, or one instant per phase (the power output pass:
	 * start-up at "halting the controller program") */
	size_t b0 = full ? 0 : 4,
	       b1 = full ? sizeof(boot) / sizeof(boot[0]) : 5;
	int ncal = full ? 8 : 1, ncen = full ? 4 : 1, narm = full ? 4 : 1;
	int njog = full ? 4 : 1, nlat = full ? 3 : 1;
	size_t n = 0;

	for (size_t i = b0; i < b1 && n < cap; i++)
		plan[n++] = (struct ph_instant){PH_BOOT, boot[i], 0};
	if (n + 1 < cap) {
		plan[n++] = (struct ph_instant){PH_RELAY, NULL, 0};
		plan[n++] = (struct ph_instant){PH_SVCREQ, NULL, 0};
	}
	for (int k = 0; k < ncal && n < cap; k++)
		plan[n++] = (struct ph_instant){PH_CALIB, NULL,
						ref.d_cal * (k + 0.5) / ncal};
	for (int k = 0; k < ncen && n < cap; k++)
		plan[n++] = (struct ph_instant){
		    PH_CENTRE, NULL, ref.d_centre * (k + 0.5) / ncen};
	if (n + 1 < cap) {
		plan[n++] = (struct ph_instant){PH_OFF, NULL, 0};
		plan[n++] = (struct ph_instant){PH_ARMREQ, NULL, 0};
	}
	for (int k = 0; k < narm && n < cap; k++)
		plan[n++] = (struct ph_instant){
		    PH_ARMED, NULL, 100.0 + k * RIG_PERIOD_MS / narm};
	for (int k = 0; k < njog && n < cap; k++)
		plan[n++] = (struct ph_instant){PH_JOG, NULL,
						150.0 + k * (full ? 300.0 : 0)};
	for (int k = 0; k < nlat && n < cap; k++)
		plan[n++] = (struct ph_instant){PH_LATCHED, NULL,
						full ? k * 100.0 : 100.0};
	return n;
}

#if defined(__SANITIZE_ADDRESS__)
/* make asan looks for memory errors: one instant per phase (make check, and
 * the power-output pass in both: the whole plan) */
static const int plan_full = 0;
#else
static const int plan_full = 1;
#endif

static void kill_anywhere(int power_output)
{
	struct ph_instant plan[48];
	struct phase_stats stats[PH_COUNT];
	size_t n;

	rig_need_env(&env, env_ok);
	rig_fails_reset();
	for (int p = 0; p < PH_COUNT; p++)
		stats[p] = (struct phase_stats){0, 0, -1, -1};
	n = kill_plan(plan, sizeof(plan) / sizeof(plan[0]),
		      !power_output && plan_full);
	for (size_t i = 0; i < n; i++)
		kill_one(&plan[i], power_output, stats);
	print_table(power_output ? "kill-anywhere, power output wired"
				 : "kill-anywhere",
		    stats, power_output);
	for (int p = 0; p < PH_COUNT; p++)
		if (!stats[p].kills && p != PH_RELAY)
			rig_fail("no kill met the phase '%s'", ph_name[p]);
	rig_fails_check(power_output ? "kill-anywhere (power output)"
				     : "kill-anywhere");
}

static void test_kill_anywhere(void **state)
{
	(void)state;
	kill_anywhere(0);
}

static void test_kill_anywhere_power_output(void **state)
{
	(void)state;
	kill_anywhere(RIG_POWER_OUT);
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_kill_anywhere),
	    T(test_kill_anywhere_power_output),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
