/*
 * re_xcheck.c - the supervisor's own decode of the joystick and its check
 * of the motion. See re_xcheck.h.
 */
#include "re_xcheck.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"
#include "re_check.h"

static const char *const CMD_TEXT[] = {
    "no valid command", "neutral",	  "axis A forward", "axis A reverse",
    "axis B forward",	"axis B reverse", "axis C forward", "axis C reverse",
};

const char *re_xcheck_cmd_text(int cmd)
{
	return cmd >= -1 && cmd <= 6 ? CMD_TEXT[cmd + 1] : CMD_TEXT[0];
}

int re_xcheck_decode(const struct re_xcheck_cfg *c, const uint8_t banks[10],
		     int *raw)
{
	int r = 0;

	for (int j = 0; j < RE_XC_INPUTS; j++) {
		int n = c->inputs[j], level;

		if (n < 1 || n > 80)
			return -2;
		level = banks[(n - 1) / 8] >> ((n - 1) % 8) & 1;
		if (level != c->active_low)
			r |= 1 << j;
	}
	if (raw)
		*raw = r;
	if (r == 0)
		return 0;
	for (int k = 0; k < 6; k++)
		if (r == 3 << (2 * k))
			return k + 1;
	return -1;
}

double re_xcheck_ramp(const struct re_xcheck_cfg *c, int ax, double t_ms)
{
	double lo = c->vmin_cps[ax], hi = c->vmax_cps[ax];

	if (t_ms <= c->wst_ms[ax])
		return lo;
	if (t_ms >= c->wen_ms[ax])
		return hi;
	return lo + (hi - lo) * (t_ms - c->wst_ms[ax]) /
			(c->wen_ms[ax] - c->wst_ms[ax]);
}

void re_xcheck_reset(struct re_xcheck *x, int64_t now_ns)
{
	memset(x, 0, sizeof(*x));
	x->pc_cmd = 0;
	x->pc_since_ns = now_ns;
	x->still_since_ns = now_ns;
}

static double ms_of(int64_t ns)
{
	return (double)ns / BASE_NS_PER_MS;
}

/* The speed axis @i may have now under the supervisor's decode: the ramp
 * of its command (times vover) when it is the commanded axis, else
 * vstill; while TV settles after a change, also the bound before it. */
static double limit_of(const struct re_xcheck *x, const struct re_xcheck_cfg *c,
		       int i, int64_t now_ns)
{
	double t = ms_of(now_ns - x->pc_since_ns), lim = RE_XC_VSTILL;

	if (x->pc_cmd > 0 && (x->pc_cmd - 1) / 2 == i)
		lim = RE_XC_VOVER * re_xcheck_ramp(c, i, t + ms_of(c->lag_ns));
	if (t < RE_XC_SETTLE_MS + ms_of(c->lag_ns) &&
	    x->prev_limit_cps[i] > lim)
		lim = x->prev_limit_cps[i];
	return lim;
}

/* The switches closed in @raw, as "A fwd a, A fwd b" (at most 12). */
static void switch_names(int raw, char *buf, size_t cap)
{
	static const char *const cmd[6] = {"A fwd", "A rev", "B fwd",
					   "B rev", "C fwd", "C rev"};
	size_t n = 0;

	buf[0] = '\0';
	for (int j = 0; j < RE_XC_INPUTS && n < cap; j++)
		if (raw >> j & 1)
			n += (size_t)snprintf(buf + n, cap - n, "%s%s %c",
					      n ? ", " : "", cmd[j / 2],
					      'a' + j % 2);
	if (!n)
		snprintf(buf, cap, "none");
}

/* The supervisor's command changed to @cmd: the bounds until now are kept
 * while TV settles. */
static void new_command(struct re_xcheck *x, const struct re_xcheck_cfg *c,
			int cmd, int64_t now_ns)
{
	for (int i = 0; i < RE_XC_AXES; i++)
		x->prev_limit_cps[i] = limit_of(x, c, i, now_ns);
	x->pc_cmd = cmd;
	x->pc_since_ns = now_ns;
	if (cmd == 0)
		x->still_since_ns = now_ns;
}

static int decode_check(struct re_xcheck *x, const struct re_xcheck_cfg *c,
			const struct re_za *za, int raw, int64_t now_ns,
			struct re_fault *f)
{
	char sw[96];

	if (za->jcmd == x->pc_cmd) {
		x->differ_since_ns = 0;
		x->differ_cycles = 0;
		return RE_OK;
	}
	if (!x->differ_since_ns)
		x->differ_since_ns = now_ns;
	if (++x->differ_cycles < 2 || now_ns - x->differ_since_ns <= c->lag_ns)
		return RE_OK;
	switch_names(raw, sw, sizeof(sw));
	re_fault_set(f, RE_F_XC_DECODE, -1);
	snprintf(f->s, sizeof(f->s),
		 "roboelf reads %s (switches closed: %s), the program %s, for "
		 "%.0f ms",
		 re_xcheck_cmd_text(x->pc_cmd), sw,
		 re_xcheck_cmd_text(za->jcmd),
		 ms_of(now_ns - x->differ_since_ns));
	return RE_FAULT;
}

static void motion_text(const struct re_xcheck *x, int i, double v, double lim,
			int against, int64_t now_ns, struct re_fault *f)
{
	int ax = x->pc_cmd > 0 ? (x->pc_cmd - 1) / 2 : -1;

	re_fault_set(f, RE_F_XC_MOTION, i);
	f->f[0] = v;
	f->f[1] = lim;
	if (against)
		snprintf(f->s, sizeof(f->s),
			 "runs against the joystick (%s by roboelf's own "
			 "decode)",
			 re_xcheck_cmd_text(x->pc_cmd));
	else if (ax == i)
		snprintf(f->s, sizeof(f->s),
			 "runs faster than its ramp allows %.0f ms after the "
			 "joystick command",
			 ms_of(now_ns - x->pc_since_ns));
	else
		snprintf(f->s, sizeof(f->s), "runs while the joystick says %s",
			 re_xcheck_cmd_text(x->pc_cmd));
}

static int motion_check(struct re_xcheck *x, const struct re_xcheck_cfg *c,
			const struct gl_record *rec, int64_t now_ns,
			struct re_fault *f)
{
	int64_t settle = (int64_t)RE_XC_SETTLE_MS * BASE_NS_PER_MS + c->lag_ns;

	for (int i = 0; i < RE_XC_AXES && i < rec->n_axes; i++) {
		double v = rec->axis[i].velocity / 64.0;
		double lim = limit_of(x, c, i, now_ns), dir = 0;
		int against;

		if (x->pc_cmd > 0 && (x->pc_cmd - 1) / 2 == i)
			dir = (x->pc_cmd - 1) % 2 ? -1 : 1;
		against = dir != 0 && v * dir < -RE_XC_VSTILL &&
			  now_ns - x->pc_since_ns > settle;
		if (!against && (dir != 0 ? v * dir : fabs(v)) <= lim) {
			x->bad_cycles[i] = 0;
			continue;
		}
		if (++x->bad_cycles[i] < 2)
			continue;
		motion_text(x, i, v, against ? -RE_XC_VSTILL * dir : lim,
			    against, now_ns, f);
		return RE_FAULT;
	}
	return RE_OK;
}

int re_xcheck_step(struct re_xcheck *x, const struct re_xcheck_cfg *c,
		   const struct gl_record *rec, const struct re_za *za,
		   int64_t now_ns, struct re_fault *f)
{
	int raw = 0, cmd;

	if (!x || !c || !rec || !za || !f)
		return GL_ERR_ARG;
	cmd = re_xcheck_decode(c, rec->inputs, &raw);
	if (cmd < -1)
		return GL_ERR_ARG;
	if (cmd != x->pc_cmd)
		new_command(x, c, cmd, now_ns);
	if (za->state != RE_DMC_ARMED && za->state != RE_DMC_SERVICE) {
		x->differ_since_ns = 0;
		x->differ_cycles = 0;
		memset(x->bad_cycles, 0, sizeof(x->bad_cycles));
		return RE_OK;
	}
	if (decode_check(x, c, za, raw, now_ns, f) == RE_FAULT)
		return RE_FAULT;
	if (za->state != RE_DMC_ARMED || !za->mneut)
		return RE_OK;
	return motion_check(x, c, rec, now_ns, f);
}
