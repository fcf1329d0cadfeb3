/*
 * re_comm_wire.c - commissioning steps 4-6, with motor power off: the
 * joystick switches asked for in turn and seen on the configured inputs,
 * the potentiometers at rest (range, noise), the limit switches at rest
 * and tripped by hand one at a time.
 *
 * A switch counts as pressed once the set of closed inputs has been the
 * same for RC_STEADY_MS (a hand on a switch bounces); every wait for the
 * technician has the deadline c->wait_ms.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "re_comm.h"
#include "re_comm_steps.h"
#include "re_comm_util.h"

#define RC_STEADY_MS 300 /* the same switches closed this long */
#define RC_POLL_MS   20
#define NJOY	     RE_JOY_INPUTS

static const char *const cmd_name[NJOY / 2] = {
    "A forward", "A reverse", "B forward",
    "B reverse", "C forward", "C reverse",
};

/* "B forward channel b" for joystick switch @i (0..11). */
static const char *sw_name(int i, char *buf, size_t cap)
{
	snprintf(buf, cap, "%s channel %c", cmd_name[i / 2], i % 2 ? 'b' : 'a');
	return buf;
}

/* Read @n values, "MG <expr>" each, several per command line. */
static int read_many(struct re_comm *c, char exprs[][16], int n, double *v)
{
	char line[96], resp[256], *p, *end;
	int i = 0, rc;

	while (i < n) {
		int k = i, len = 0;

		for (; k < n && len + 20 < (int)sizeof(line) && k - i < 6; k++)
			len += snprintf(line + len, sizeof(line) - (size_t)len,
					"%sMG %s", k > i ? ";" : "", exprs[k]);
		if ((rc = rc_cmd(c, line, resp, sizeof(resp))) < 0)
			return rc;
		for (p = resp; i < k; i++, p = end) {
			v[i] = strtod(p, &end);
			if (end == p)
				return GL_ERR_PROTO;
		}
	}
	return GL_OK;
}

/* Bit i set: joystick switch i reads closed. */
static int joy_mask(struct re_comm *c, unsigned *mask)
{
	char ex[NJOY][16];
	double v[NJOY];
	int rc;

	for (int i = 0; i < NJOY; i++)
		snprintf(ex[i], sizeof(ex[i]), "@IN[%d]",
			 c->cfg->joystick.inputs[i]);
	if ((rc = read_many(c, ex, NJOY, v)) != GL_OK)
		return rc;
	*mask = 0;
	for (int i = 0; i < NJOY; i++)
		if ((v[i] != 0) != c->cfg->joystick.active_low)
			*mask |= 1u << i;
	return GL_OK;
}

/* Wait until the set @fn reads is steady and (@want_any) not empty, or
 * (!@want_any) empty; *@timed_out on the deadline c->wait_ms. Every set
 * read goes to the lanes @l. */
static int wait_mask(struct re_comm *c, int (*fn)(struct re_comm *, unsigned *),
		     struct re_comm_lanes *l, int want_any, unsigned *mask,
		     int *timed_out)
{
	double t0 = rc_now_ms(c), since = t0;
	unsigned last = ~0u;
	int rc;

	*timed_out = 0;
	for (;;) {
		double now;

		if ((rc = fn(c, mask)) != GL_OK)
			return rc;
		rc_lane_mark(c, l, *mask);
		now = rc_now_ms(c);
		if (*mask != last) {
			last = *mask;
			since = now;
		}
		if ((want_any ? *mask != 0 : *mask == 0) &&
		    now - since >= RC_STEADY_MS)
			return GL_OK;
		if (rc_quit(c))
			return GL_ERR_AGAIN;
		if (now - t0 > c->wait_ms) {
			*timed_out = 1;
			return GL_OK;
		}
		rc_sleep_ms(c, RC_POLL_MS);
	}
}

static void list_inputs(const struct re_comm *c, unsigned mask, char *buf,
			size_t cap)
{
	size_t n = 0;
	char nm[40];

	buf[0] = '\0';
	for (int i = 0; i < NJOY && n < cap; i++)
		if (mask & (1u << i))
			n += (size_t)snprintf(buf + n, cap - n,
					      "%sinput %d (%s)", n ? ", " : "",
					      c->cfg->joystick.inputs[i],
					      sw_name(i, nm, sizeof(nm)));
}

/* Nothing pressed: every switch must read open. */
static int joy_rest(struct re_comm *c)
{
	unsigned mask;
	char list[512];
	int rc, al = c->cfg->joystick.active_low;

	rc_lane_start(c, &c->joy);
	if ((rc = joy_mask(c, &mask)) != GL_OK)
		return rc;
	rc_lane_mark(c, &c->joy, mask);
	if (mask == (1u << NJOY) - 1) {
		re_comm_add(c, "joystick", "polarity", RE_COMM_FAIL,
			    al ? "set joystick.active_low: false (a closed "
				 "switch reads 1)"
			       : "set joystick.active_low: true (a closed "
				 "switch reads 0), or rewire the switches",
			    "with nothing pressed all 12 joystick inputs read "
			    "%d, which the configuration (active_low: %s) "
			    "takes for closed: the polarity is the wrong way "
			    "round",
			    al ? 0 : 1, al ? "true" : "false");
		return GL_OK;
	}
	if (mask) {
		list_inputs(c, mask, list, sizeof(list));
		re_comm_add(c, "joystick", "rest", RE_COMM_FAIL,
			    "release the joystick; check those switches and "
			    "their wires for a short or a switch stuck closed",
			    "with nothing pressed these read closed: %s", list);
		return GL_OK;
	}
	re_comm_add(c, "joystick", "rest", RE_COMM_PASS, NULL,
		    "nothing pressed: all 12 inputs read open (active_low: "
		    "%s)",
		    al ? "true" : "false");
	return GL_OK;
}

/* What closed when command @k was pressed, in words. */
static void joy_judge(struct re_comm *c, int k, unsigned mask, int timed_out)
{
	const int *in = c->cfg->joystick.inputs;
	unsigned want = 3u << (2 * k), missing = want & ~mask,
		 extra = mask & ~want;
	char ls[512], lm[512], nm[40], fix[RE_COMM_FIX];

	if (mask == want) {
		re_comm_add(c, "joystick", cmd_name[k], RE_COMM_PASS, NULL,
			    "inputs %d and %d closed, nothing else", in[2 * k],
			    in[2 * k + 1]);
		return;
	}
	if (timed_out && !mask) {
		re_comm_add(c, "joystick", cmd_name[k], RE_COMM_FAIL,
			    "check that switch pair's wiring to the controller",
			    "nothing closed within %d s of asking for %s "
			    "(inputs %d and %d)",
			    c->wait_ms / 1000, cmd_name[k], in[2 * k],
			    in[2 * k + 1]);
		return;
	}
	list_inputs(c, missing, lm, sizeof(lm));
	list_inputs(c, extra, ls, sizeof(ls));
	if (__builtin_popcount(missing) == 1 &&
	    __builtin_popcount(extra) == 1) {
		int m = __builtin_ctz(missing), e = __builtin_ctz(extra);

		snprintf(fix, sizeof(fix),
			 "exchange the wires on inputs %d and %d (or the two "
			 "numbers in joystick.inputs)",
			 in[m], in[e]);
		re_comm_add(c, "joystick", cmd_name[k], RE_COMM_FAIL, fix,
			    "swapped pair: %s did not close and %s did: the "
			    "switch of %s is wired to input %d",
			    lm, ls, sw_name(m, nm, sizeof(nm)), in[e]);
	} else if (!extra) {
		re_comm_add(c, "joystick", cmd_name[k], RE_COMM_FAIL,
			    "check that switch and its wire (a dead switch or "
			    "a broken wire); the redundant channel is lost",
			    "dead switch: %s did not close; the other channel "
			    "did",
			    lm);
	} else {
		re_comm_add(c, "joystick", cmd_name[k], RE_COMM_FAIL,
			    "check the wiring of those inputs",
			    "asked for %s: %s%s%s closed", cmd_name[k],
			    missing ? lm : "",
			    missing ? " did not close; " : "", ls);
	}
}

int rc_step_joystick(struct re_comm *c)
{
	char ask[24];
	unsigned mask;
	int rc, to;

	if ((rc = joy_rest(c)) != GL_OK || c->failed_step)
		return rc;
	for (int k = 0; k < NJOY / 2; k++) {
		rc_say(c, "PRESS and hold the joystick %s (inputs %d and %d)",
		       cmd_name[k], c->cfg->joystick.inputs[2 * k],
		       c->cfg->joystick.inputs[2 * k + 1]);
		snprintf(ask, sizeof(ask), "PRESS %s", cmd_name[k]);
		rc_lane_ask(c, &c->joy, ask);
		if ((rc = wait_mask(c, joy_mask, &c->joy, 1, &mask, &to)) !=
		    GL_OK)
			return rc;
		joy_judge(c, k, mask, to);
		if (c->failed_step)
			return GL_OK;
		rc_say(c, "RELEASE the joystick %s", cmd_name[k]);
		rc_lane_ask(c, &c->joy, "RELEASE");
		if ((rc = wait_mask(c, joy_mask, &c->joy, 0, &mask, &to)) !=
		    GL_OK)
			return rc;
		if (to) {
			re_comm_add(c, "joystick", cmd_name[k], RE_COMM_FAIL,
				    "release the joystick; check for a switch "
				    "stuck closed",
				    "still closed %d s after the release was "
				    "asked for",
				    c->wait_ms / 1000);
			return GL_OK;
		}
	}
	return GL_OK;
}

/* ---- potentiometers at rest ---------------------------------------------- */

/* The supervisor's tolerance at the table step, V. */
static double pot_tol_v(const struct re_config_axis *a)
{
	return a->allowed_error * a->analog.expected_range_v * a->step_counts /
	       a->travel_counts;
}

static void pot_judge(struct re_comm *c, int ax)
{
	const struct re_config_axis *a = &c->cfg->axes[ax];
	double lo = fmin(a->analog.reverse_v, a->analog.forward_v) -
		    a->analog.absolute_tolerance_v;
	double hi = fmax(a->analog.reverse_v, a->analog.forward_v) +
		    a->analog.absolute_tolerance_v;
	double mn = 1e9, mx = -1e9, sum = 0, tol = pot_tol_v(a);

	for (int i = 0; i < c->noise_n; i++) {
		mn = fmin(mn, c->noise_v[ax][i]);
		mx = fmax(mx, c->noise_v[ax][i]);
		sum += c->noise_v[ax][i];
	}
	if (mn < lo || mx > hi)
		re_comm_add(c, "pots", a->name, RE_COMM_FAIL,
			    "check the potentiometer's supply, wiper and "
			    "analog input (a reading near 0 V: wiper open or "
			    "wrong input)",
			    "analog input %d read %.3f..%.3f V at rest, "
			    "outside the range %.3f..%.3f V the configuration "
			    "allows (reverse_v, forward_v +- "
			    "absolute_tolerance_v)",
			    a->analog.input, mn, mx, lo, hi);
	else if (mx - mn > tol / 2)
		re_comm_add(c, "pots", a->name, RE_COMM_FAIL,
			    "screen and ground the potentiometer cable; the "
			    "noise must stay below half the tolerance",
			    "analog input %d: noise %.1f mV peak to peak at "
			    "rest, more than half the supervisor's tolerance "
			    "%.1f mV",
			    a->analog.input, (mx - mn) * 1e3, tol * 1e3);
	else
		re_comm_add(c, "pots", a->name, RE_COMM_PASS, NULL,
			    "analog input %d: %.4f V mean at rest, noise %.1f "
			    "mV peak to peak over %d samples (limit %.1f mV, "
			    "half the tolerance)",
			    a->analog.input, sum / c->noise_n, (mx - mn) * 1e3,
			    c->noise_n, tol * 1e3 / 2);
}

int rc_step_pots(struct re_comm *c)
{
	char ex[RE_AXES][16];
	double v[RE_AXES];
	int rc;

	for (int ax = 0; ax < RE_AXES; ax++)
		snprintf(ex[ax], sizeof(ex[ax]), "@AN[%d]",
			 c->cfg->axes[ax].analog.input);
	for (c->noise_n = 0; c->noise_n < RE_COMM_NOISE_N; c->noise_n++) {
		if ((rc = read_many(c, ex, RE_AXES, v)) != GL_OK)
			return rc;
		for (int ax = 0; ax < RE_AXES; ax++)
			c->noise_v[ax][c->noise_n] = v[ax];
		rc_sleep_ms(c, 10);
	}
	for (int ax = 0; ax < RE_AXES && !c->failed_step; ax++)
		pot_judge(c, ax);
	return GL_OK;
}

/* ---- limit switches ------------------------------------------------------ */

/* Bit 2*ax: forward switch of axis ax active; bit 2*ax+1: reverse. With
 * CN -1 (probed in the firmware step) _LFx / _LRx read 0 when active. */
static int lim_mask(struct re_comm *c, unsigned *mask)
{
	char ex[2 * RE_AXES][16];
	double v[2 * RE_AXES];
	int rc;

	for (int ax = 0; ax < RE_AXES; ax++) {
		snprintf(ex[2 * ax], 16, "_LF%c", 'A' + ax);
		snprintf(ex[2 * ax + 1], 16, "_LR%c", 'A' + ax);
	}
	if ((rc = read_many(c, ex, 2 * RE_AXES, v)) != GL_OK)
		return rc;
	*mask = 0;
	for (int i = 0; i < 2 * RE_AXES; i++)
		if (v[i] == 0)
			*mask |= 1u << i;
	return GL_OK;
}

static const char *lim_name(int i, char *buf, size_t cap)
{
	snprintf(buf, cap, "the %s limit switch of axis %c",
		 i % 2 ? "reverse" : "forward", 'A' + i / 2);
	return buf;
}

static void lim_judge(struct re_comm *c, int i, unsigned mask, int to)
{
	char want[48], got[48], nm[64];
	int g = mask ? __builtin_ctz(mask) : -1;

	lim_name(i, want, sizeof(want));
	snprintf(nm, sizeof(nm), "%c %s", 'A' + i / 2, i % 2 ? "rev" : "fwd");
	if (mask == 1u << i) {
		re_comm_add(c, "limits", nm, RE_COMM_PASS, NULL,
			    "_L%c%c read 0 (active) while %s was held, "
			    "nothing else",
			    i % 2 ? 'R' : 'F', 'A' + i / 2, want);
		return;
	}
	if (to && !mask) {
		re_comm_add(c, "limits", nm, RE_COMM_FAIL,
			    "check that switch, its wire and the controller's "
			    "limit input (a dead switch or a broken wire)",
			    "nothing became active within %d s of asking for "
			    "%s",
			    c->wait_ms / 1000, want);
		return;
	}
	lim_name(g, got, sizeof(got));
	if (mask == 1u << (i ^ 1))
		re_comm_add(c, "limits", nm, RE_COMM_FAIL,
			    "exchange the forward and reverse limit switch "
			    "wires of that axis",
			    "swapped: %s was held and the controller saw %s",
			    want, got);
	else
		re_comm_add(c, "limits", nm, RE_COMM_FAIL,
			    "check which switch is wired to which axis's limit "
			    "inputs",
			    "%s was held and the controller saw %s%s", want,
			    got,
			    __builtin_popcount(mask) > 1 ? " and more" : "");
}

int rc_step_limits(struct re_comm *c)
{
	char nm[48], ask[24];
	unsigned mask;
	int rc, to;

	rc_lane_start(c, &c->lim);
	if ((rc = lim_mask(c, &mask)) != GL_OK)
		return rc;
	rc_lane_mark(c, &c->lim, mask);
	if (mask) {
		re_comm_add(c, "limits", "rest", RE_COMM_FAIL,
			    "if the axis is not at that end: a switch stuck, "
			    "or wired normally open where the controller "
			    "expects it closed at rest",
			    "at rest %s reads active",
			    lim_name(__builtin_ctz(mask), nm, sizeof(nm)));
		return GL_OK;
	}
	re_comm_add(c, "limits", "rest", RE_COMM_PASS, NULL,
		    "at rest no limit switch reads active (_LFx, _LRx 1)");
	for (int i = 0; i < 2 * RE_AXES; i++) {
		rc_say(c, "TRIP %s by hand and hold it",
		       lim_name(i, nm, sizeof(nm)));
		snprintf(ask, sizeof(ask), "TRIP %c %s", 'A' + i / 2,
			 i % 2 ? "rev" : "fwd");
		rc_lane_ask(c, &c->lim, ask);
		if ((rc = wait_mask(c, lim_mask, &c->lim, 1, &mask, &to)) !=
		    GL_OK)
			return rc;
		lim_judge(c, i, mask, to);
		if (c->failed_step)
			return GL_OK;
		rc_say(c, "RELEASE %s", nm);
		rc_lane_ask(c, &c->lim, "RELEASE");
		if ((rc = wait_mask(c, lim_mask, &c->lim, 0, &mask, &to)) !=
		    GL_OK)
			return rc;
		if (to) {
			re_comm_add(c, "limits", nm, RE_COMM_FAIL,
				    "check for a switch stuck active",
				    "still active %d s after the release was "
				    "asked for",
				    c->wait_ms / 1000);
			return GL_OK;
		}
	}
	return GL_OK;
}
