/*
 * sys_phase_h.c - the phases of the system and what a signal met there
 * (see sys_phase_h.h).
 */
#include <math.h>
#include <poll.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "sys_phase_h.h"

/* ---- phases and instants ------------------------------------------------ */

const char *const ph_name[PH_COUNT] = {
    "start-up, relay open", "start-up, relay closed",
    "service requested",    "full calibration",
    "centring (file)",	    "back to safe",
    "arm requested",	    "armed at rest",
    "armed jogging",	    "latched",
};

#define L_POWER_ON "roboelf: motor power on (relay closed)"
#define L_ARMING   "roboelf: soft limits from the calibration; arming"

static int wait_line(struct sys_case *c, const char *prefix, int timeout_ms)
{
	if (proc_wait_line(&c->re, PROC_STDOUT, prefix, timeout_ms, NULL, 0) ==
	    0)
		return 0;
	rig_seterr(c, "no line '%s' from roboelf within %d ms\n--- stdout:\n%s",
		   prefix, timeout_ms, rig_tail(&c->re, PROC_STDOUT, 1500));
	return -1;
}

/* Poll the state line as fast as it answers (a window of start-up is a few
 * ms wide) until the watched @var equals @value, or with @nonzero is not
 * 0, at most @timeout_ms. */
static int poll_var(struct sys_case *c, const char *var, double value,
		    int nonzero, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	char st[2048];

	for (;;) {
		double v;

		if (sys_state(c, st, sizeof(st)) < 0)
			return -1;
		v = sys_state_num(st, var);
		if (nonzero ? (v != 0 && !isnan(v)) : v == value)
			return 0;
		if (proc_now_ms() > deadline) {
			rig_seterr(c, "%s never became %s%.0f: %s", var,
				   nonzero ? "non-zero, not " : "", value, st);
			return -1;
		}
		proc_pump(&c->re, 0);
	}
}

/*
 * The arm request sent, the armed state not entered: roboelf writes
 * "hbpc=<n>;armreq=1" after L_ARMING (and the soft-limit writes behind
 * it); the program takes armreq back to 0 within mainms and arms some
 * 30 ms later (#PCHK). So: armreq seen at 1, or hbpc changed since the
 * line, while the state is still 0.
 */
static int poll_arm_request(struct sys_case *c, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	double hb0 = NAN;
	char st[2048];

	for (;;) {
		double hb;

		if (sys_state(c, st, sizeof(st)) < 0)
			return -1;
		hb = sys_state_num(st, "var.hbpc");
		if (sys_state_num(st, "var.state") != 0) {
			rig_seterr(c, "the arm request was missed: %s", st);
			return -1;
		}
		if (sys_state_num(st, "var.armreq") == 1 ||
		    (!isnan(hb0) && hb != hb0))
			return 0;
		hb0 = isnan(hb0) ? hb : hb0;
		if (proc_now_ms() > deadline) {
			rig_seterr(c, "no arm request within %d ms: %s",
				   timeout_ms, st);
			return -1;
		}
	}
}

int ph_reach(struct sys_case *c, struct sys_env *e, const struct ph_instant *in,
	     int power_output, double *anchor)
{
	struct rig_opts o = {.calibration =
				 in->ph == PH_CALIB ? "full" : "file",
			     .power_output = power_output,
			     .off_centre = in->ph == PH_CENTRE};
	double t = -1;

	*anchor = -1;
	if (rig_start(c, e, &o) < 0)
		return -1;
	switch (in->ph) {
	case PH_BOOT: return wait_line(c, in->line, RIG_START_MS);
	case PH_RELAY: return wait_line(c, L_POWER_ON, RIG_START_MS);
	case PH_SVCREQ:
		/* the request carries the session's first heartbeat */
		return wait_line(c, "roboelf: controller configured",
				 RIG_START_MS) < 0 ||
			       poll_var(c, "var.hbpc", 0, 1, 2000) < 0
			   ? -1
			   : 0;
	case PH_CALIB:
	case PH_CENTRE:
		if (sys_wait_event(c, PH_SVC_ON, 0, RIG_READY_MS, &t) < 0)
			return -1;
		*anchor = t;
		return rig_wait_sim_fine(c, t + in->at_ms, RIG_READY_MS);
	case PH_OFF:
		return poll_var(c, "var.state", 3, 0, RIG_READY_MS) < 0 ||
			       poll_var(c, "var.state", 0, 0, 2000) < 0
			   ? -1
			   : 0;
	case PH_ARMREQ:
		return poll_var(c, "var.state", 3, 0, RIG_READY_MS) < 0 ||
			       wait_line(c, L_ARMING, 2000) < 0 ||
			       poll_arm_request(c, 2000) < 0
			   ? -1
			   : 0;
	case PH_ARMED:
	case PH_JOG:
	case PH_LATCHED: break;
	default: rig_seterr(c, "bad phase %d", (int)in->ph); return -1;
	}
	if (rig_wait_ready(c, RIG_READY_MS) < 0)
		return -1;
	t = c->t_ready_ms;
	if (in->ph == PH_JOG) {
		double t0 = sys_sim_time(c);

		if (sys_ctl(c, "joy A fwd") < 0 ||
		    sys_wait_event(c, "input: joy A fwd", t0, 2000, &t) < 0)
			return -1;
	} else if (in->ph == PH_LATCHED) {
		char line[1024];

		if (sys_ctl(c, "pot A offset 0.5") < 0 ||
		    sys_wait_fault(c, RIG_FAULT_WAIT_MS, line, sizeof(line)) <
			0 ||
		    (t = sys_sim_time(c)) < 0)
			return -1;
	}
	*anchor = t;
	return rig_wait_sim_fine(c, t + in->at_ms, 5000);
}

/* ---- after a kill or a freeze: who switched the motors off, when -------- */

/* "... (thread 0 line 381)" -> "thread 0 line 381" */
static void source_of(const char *text, char *by, size_t cap)
{
	const char *p = strrchr(text, '(');
	size_t n;

	if (!p) {
		snprintf(by, cap, "?");
		return;
	}
	n = strcspn(p + 1, ")");
	snprintf(by, cap, "%.*s", (int)n, p + 1);
}

/* One axis through the events: on at @t_sig, switched on after it, the
 * time and source of the last on->off after it. Return: 1 if still on. */
static int axis_walk(const struct sys_case *c, int a, double t_sig,
		     struct ph_off *r, double *t_off, char *by, size_t cap)
{
	char on_p[32], off_p[32];
	int on = 0;

	snprintf(on_p, sizeof(on_p), "axis %c motor on", 'A' + a);
	snprintf(off_p, sizeof(off_p), "axis %c motor off", 'A' + a);
	*t_off = -1;
	for (size_t i = 0; i < c->nev; i++) {
		const struct sys_evt *e = &c->ev[i];

		if (!strncmp(e->text, on_p, strlen(on_p))) {
			on = 1;
			if (e->t_ms > t_sig)
				r->on_after = 1;
		} else if (!strncmp(e->text, off_p, strlen(off_p))) {
			if (on && e->t_ms >= t_sig) {
				*t_off = e->t_ms;
				source_of(e->text, by, cap);
			}
			on = 0;
		}
		if (e->t_ms <= t_sig &&
		    (i + 1 == c->nev || c->ev[i + 1].t_ms > t_sig))
			r->on_at_sig |= on;
	}
	return on;
}

/*
 * Let the controller act on its own for the deadline and the longest
 * program transition after it (a request the dead supervisor sent may
 * still switch the motors on: #SVCIN, #ARM), then read what happened.
 * Return: 0, or -1 with c->err set (a motor still on, lost events).
 */
static int analyse_off(struct sys_case *c, double t_sig, int power_output,
		       struct ph_off *r)
{
	char pref[48];
	int i;

	memset(r, 0, sizeof(*r));
	r->off_ms = r->pout_ms = -1;
	if (rig_wait_sim_fine(c, t_sig + RIG_D_POWER_MS, 5000) < 0 ||
	    sys_state(c, r->st_d, sizeof(r->st_d)) < 0 ||
	    rig_wait_sim_fine(c, t_sig + RIG_D_CTRL_MS + 100, 5000) < 0 ||
	    sys_events(c) < 0 || sys_state(c, r->st, sizeof(r->st)) < 0)
		return -1;
	if (sys_event_find(c, "events lost", 0) >= 0) {
		rig_seterr(c, "galil-sim lost events: no analysis possible");
		return -1;
	}
	for (int a = 0; a < 3; a++) {
		double t_off;
		char by[64] = "";

		if (axis_walk(c, a, t_sig, r, &t_off, by, sizeof(by))) {
			rig_seterr(c,
				   "motor %c is still on %d ms after the "
				   "signal: %s",
				   'A' + a, RIG_D_CTRL_MS + 100, r->st);
			return -1;
		}
		if (t_off >= 0 && t_off - t_sig > r->off_ms) {
			r->off_ms = t_off - t_sig;
			snprintf(r->by, sizeof(r->by), "%s", by);
		}
	}
	snprintf(pref, sizeof(pref), "power output %d cleared", power_output);
	i = power_output ? sys_event_find(c, pref, t_sig) : -1;
	if (i >= 0)
		r->pout_ms = c->ev[i].t_ms - t_sig;
	r->fcode = sys_state_num(r->st, "var.fcode");
	return 0;
}

/* No axis moved (true position X.act) from the state line @st0 to now. */
static int still_since(struct sys_case *c, const char *st0)
{
	char st1[2048];

	if (sys_state(c, st1, sizeof(st1)) < 0)
		return -1;
	for (int a = 0; a < 3; a++) {
		char key[8];

		snprintf(key, sizeof(key), "%c.act", 'A' + a);
		if (sys_state_num(st0, key) != sys_state_num(st1, key)) {
			rig_seterr(c,
				   "axis %c moved after the deadline:\n%s\n%s",
				   'A' + a, st0, st1);
			return -1;
		}
	}
	return 0;
}

int ph_check_off(struct sys_case *c, const char *what, double t_sig,
		 int power_output, struct ph_off *r)
{
	size_t before = rig_fails_count();

	if (analyse_off(c, t_sig, power_output, r) < 0) {
		rig_fail("%s: %s", what, c->err);
		return -1;
	}
	if (r->on_at_sig || r->on_after) {
		if (r->off_ms < 0 || r->off_ms > RIG_D_CTRL_MS)
			rig_fail("%s: motors off %.0f ms after the signal, "
				 "deadline %d ms%s",
				 what, r->off_ms, RIG_D_CTRL_MS,
				 r->on_after ? " (the program switched them ON "
					       "after the signal)"
					     : "");
		if (strncmp(r->by, "thread ", 7))
			rig_fail("%s: the last motor was switched off by '%s', "
				 "not the controller program",
				 what, r->by);
		if (r->fcode != 2)
			rig_fail("%s: the program latched fault %.0f, not "
				 "WATCHDOG (2): %s",
				 what, r->fcode, r->st);
		if (power_output &&
		    (r->pout_ms < 0 || r->pout_ms > RIG_D_POWER_MS))
			rig_fail("%s: power output %d cleared %.0f ms after "
				 "the signal (-1: never), deadline %d ms",
				 what, power_output, r->pout_ms,
				 RIG_D_POWER_MS);
	}
	if (power_output && !strstr(r->st_d, " power=0 "))
		rig_fail("%s: motor power not cut at the deadline (output %d "
			 "wired): %s",
			 what, power_output, r->st_d);
	if (sys_check_safe(c, 1, RIG_HOLD_MS) < 0)
		rig_fail("%s: %s", what, c->err);
	else if (still_since(c, r->st_d) < 0)
		rig_fail("%s: %s", what, c->err);
	return rig_fails_count() == before ? 0 : -1;
}

void ph_measure_line(const char *sig, enum ph_phase ph, double t_sig,
		     double jitter, double anchor, const struct ph_off *r)
{
	char off[160], pout[48] = "";

	if (r->on_at_sig || r->on_after)
		snprintf(off, sizeof(off),
			 "motors %s, all off %.0f ms after (%s)",
			 r->on_at_sig ? "on" : "switched on AFTER it",
			 r->off_ms, r->by);
	else
		snprintf(off, sizeof(off), "motors off already");
	if (r->pout_ms >= 0)
		snprintf(pout, sizeof(pout),
			 "; power output cleared %.0f ms after", r->pout_ms);
	print_message("[ MEASURE  ] %s in %-22s at %6.0f ms (+-%.0f), %6.0f ms "
		      "into the phase: %s%s; program fault %.0f\n",
		      sig, ph_name[ph], t_sig, jitter,
		      anchor >= 0 ? t_sig - anchor : 0.0, off, pout, r->fcode);
}

double ph_who_off(const struct sys_case *c, double after, char by[3][48])
{
	double last = -1;

	for (int a = 0; a < 3; a++) {
		char pref[32];
		int i;

		snprintf(pref, sizeof(pref), "axis %c motor off", 'A' + a);
		i = sys_event_find(c, pref, after);
		if (i < 0)
			return -1;
		source_of(c->ev[i].text, by[a], sizeof(by[a]));
		if (c->ev[i].t_ms > last)
			last = c->ev[i].t_ms;
	}
	return last;
}
