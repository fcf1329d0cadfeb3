/*
 * ctrl_axcmd.c - axis commands: the parameters (SP AC DC SD KP KI KD TL IL
 * OF OV ER OE OA OT LD FL BL TW), motion (PA PR JG PT DP ZA BG ST AB SH MO)
 * and the reports (TP TE TD RP TV TT TS SC). The parameter table and the
 * _operands that read an axis are in ctrl_axis.c.
 *
 * Ranges and resolutions are those of the DMC-40x0 command reference; a
 * value out of range is TC 6 and nothing is changed.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "ctrl_axcmd.h"
#include "ctrl_args.h"
#include "ctrl_axis.h"
#include "ctrl_buf.h"
#include "ctrl_expr.h"
#include "ctrl_motion.h"
#include "ctrl_out.h"
#include "ctrl_thread.h"

/* Print the queried fields: " 1, 2\r\n". */
static void put_queries(struct ctrl_xc *x, const struct ctrl_args *a,
			const double *v, int fmt)
{
	int i, first = 1;

	for (i = 0; i < CTRL_AXES; i++) {
		if (a->set[i] != 2)
			continue;
		if (!first)
			ctrl_buf_puts(&x->c->tmp, ",");
		ctrl_put_num(x, v[i], fmt);
		first = 0;
	}
	if (!first)
		ctrl_buf_puts(&x->c->tmp, "\r\n");
}

/*
 * Generic "XX n,n,n" for a value per axis: range check all, then store.
 * @get/@set read and write one axis; @fmt for queries.
 */
static int
axis_values(struct ctrl_xc *x, const char *a, double lo, double hi, double step,
	    int fmt, double *(*slot)(struct ctrl *c, int axis, const void *ud),
	    const void *ud)
{
	struct ctrl_args args;
	double cur[CTRL_AXES];
	int i, rc = ctrl_parse_axis_args(x, a, &args);

	if (rc)
		return rc;
	for (i = 0; i < CTRL_AXES; i++) {
		cur[i] = *slot(x->c, i, ud);
		if (args.set[i] == 1 && (args.v[i] < lo || args.v[i] > hi))
			return 6;
	}
	for (i = 0; i < CTRL_AXES; i++) {
		if (args.set[i] != 1)
			continue;
		*slot(x->c, i, ud) =
		    step > 0 ? trunc(args.v[i] / step) * step : args.v[i];
	}
	put_queries(x, &args, cur, fmt);
	return 0;
}

static double *par_slot(struct ctrl *c, int axis, const void *ud)
{
	return ctrl_par_ptr(&c->ax[axis].p, ud);
}

static int cmd_par(struct ctrl_xc *x, const struct ctrl_par_desc *d,
		   const char *a)
{
	struct ctrl_args args;
	int i, rc;

	if (!d->in_motion) {
		rc = ctrl_parse_axis_args(x, a, &args);
		if (rc)
			return rc;
		for (i = 0; i < CTRL_AXES; i++)
			if (args.set[i] == 1 && x->c->ax[i].profiling &&
			    !x->c->ax[i].stopping &&
			    x->c->ax[i].mode != CTRL_MODE_JG)
				return 7;
	}
	if (!strcmp(d->name, "OV")) {
		rc = ctrl_parse_axis_args(x, a, &args);
		if (rc)
			return rc;
		for (i = 0; i < CTRL_AXES; i++)
			if (args.set[i] == 1 && args.v[i] > x->c->ax[i].p.tl)
				return 6;
	}
	return axis_values(x, a, d->lo, d->hi, d->step, d->fmt, par_slot, d);
}

static int cmd_ipar(struct ctrl_xc *x, const struct ctrl_ipar_desc *d,
		    const char *a)
{
	struct ctrl_args args;
	double cur[CTRL_AXES];
	int i, rc = ctrl_parse_axis_args(x, a, &args);

	if (rc)
		return rc;
	for (i = 0; i < CTRL_AXES; i++) {
		cur[i] = *ctrl_ipar_ptr(&x->c->ax[i].p, d);
		if (args.set[i] == 1 &&
		    (args.v[i] != (int)args.v[i] || args.v[i] < d->lo ||
		     args.v[i] > d->hi))
			return 6;
	}
	for (i = 0; i < CTRL_AXES; i++)
		if (args.set[i] == 1)
			*ctrl_ipar_ptr(&x->c->ax[i].p, d) = (int)args.v[i];
	put_queries(x, &args, cur, CTRL_NUM_INT);
	return 0;
}

/* ---- PA PR JG PT DP ZA --------------------------------------------------- */

/* PA in position tracking: a move that starts from rest is an event
 * "axis A begin PT (thread 1 line 80)". */
static void pt_target(struct ctrl_xc *x, int i, double target)
{
	char who[CTRL_WHO_LEN];
	int was = x->c->ax[i].profiling;

	ctrl_motion_pt_target(x->c, i, target);
	if (was || !x->c->ax[i].profiling)
		return;
	ctrl_xc_who(x, who, sizeof(who));
	ctrl_event(x->c, "axis %c begin PT (%s)", 'A' + i, who);
}

static int cmd_pa(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	struct ctrl_args args;
	double cur[CTRL_AXES];
	int i, rc = ctrl_parse_axis_args(x, a, &args);

	if (rc)
		return rc;
	for (i = 0; i < CTRL_AXES; i++) {
		cur[i] = c->ax[i].pa_last;
		if (args.set[i] != 1)
			continue;
		if (args.v[i] < -2147483648.0 || args.v[i] > 2147483647)
			return 6;
		if (!c->ax[i].pt && c->ax[i].profiling)
			return 7;
		if (c->ax[i].pt && c->ax[i].p.motor_off)
			return 20;
	}
	for (i = 0; i < CTRL_AXES; i++) {
		if (args.set[i] != 1)
			continue;
		if (c->ax[i].pt) {
			pt_target(x, i, floor(args.v[i]));
		} else {
			c->ax[i].pa = floor(args.v[i]);
			c->ax[i].next_mode = CTRL_MODE_PA;
		}
	}
	put_queries(x, &args, cur, CTRL_NUM_PF);
	return 0;
}

static int cmd_pr(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	struct ctrl_args args;
	double cur[CTRL_AXES];
	int i, rc = ctrl_parse_axis_args(x, a, &args);

	if (rc)
		return rc;
	for (i = 0; i < CTRL_AXES; i++) {
		struct ctrl_axis *ax = &c->ax[i];

		cur[i] =
		    ax->next_mode == CTRL_MODE_PA ? ax->pa - ax->ref : ax->pr;
		if (args.set[i] != 1)
			continue;
		if (fabs(args.v[i]) > 2147483647)
			return 6;
		if (ax->profiling)
			return 7;
	}
	for (i = 0; i < CTRL_AXES; i++) {
		if (args.set[i] != 1)
			continue;
		c->ax[i].pr = floor(args.v[i]);
		c->ax[i].next_mode = CTRL_MODE_PR;
	}
	put_queries(x, &args, cur, CTRL_NUM_PF);
	return 0;
}

static int cmd_jg(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	struct ctrl_args args;
	double cur[CTRL_AXES];
	int i, rc = ctrl_parse_axis_args(x, a, &args);

	if (rc)
		return rc;
	for (i = 0; i < CTRL_AXES; i++) {
		struct ctrl_axis *ax = &c->ax[i];

		cur[i] = ax->jg;
		if (args.set[i] != 1)
			continue;
		if (fabs(args.v[i]) > 15000000)
			return 6;
		if (ax->profiling && ax->mode != CTRL_MODE_JG)
			return 13;
	}
	for (i = 0; i < CTRL_AXES; i++) {
		if (args.set[i] != 1)
			continue;
		c->ax[i].jg = trunc(args.v[i] / 2) * 2;
		c->ax[i].p.sp = fabs(c->ax[i].jg);
		if (!c->ax[i].profiling)
			c->ax[i].next_mode = CTRL_MODE_JG;
	}
	put_queries(x, &args, cur, CTRL_NUM_INT);
	return 0;
}

static int cmd_pt(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	struct ctrl_args args;
	double cur[CTRL_AXES];
	int i, rc = ctrl_parse_axis_args(x, a, &args);

	if (rc)
		return rc;
	for (i = 0; i < CTRL_AXES; i++) {
		cur[i] = c->ax[i].pt;
		if (args.set[i] == 1 && args.v[i] != 0 && args.v[i] != 1)
			return 6;
		if (args.set[i] == 1 && args.v[i] == 1 && !c->ax[i].pt &&
		    c->ax[i].profiling)
			return 7;
	}
	for (i = 0; i < CTRL_AXES; i++) {
		if (args.set[i] != 1)
			continue;
		if (args.v[i] == 1 && !c->ax[i].pt)
			c->ax[i].target = c->ax[i].ref;
		c->ax[i].pt = args.v[i] == 1;
	}
	put_queries(x, &args, cur, CTRL_NUM_INT);
	return 0;
}

static int cmd_dp(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	struct ctrl_args args;
	double cur[CTRL_AXES];
	int i, rc = ctrl_parse_axis_args(x, a, &args);

	if (rc)
		return rc;
	for (i = 0; i < CTRL_AXES; i++) {
		cur[i] = round(c->ax[i].enc);
		if (args.set[i] == 1 && c->ax[i].profiling)
			return 7;
		if (args.set[i] == 1 && fabs(args.v[i]) > 2147483647)
			return 6;
	}
	for (i = 0; i < CTRL_AXES; i++) {
		struct ctrl_axis *ax = &c->ax[i];
		double v = floor(args.v[i]);

		if (args.set[i] != 1)
			continue;
		ax->offset += v - ax->enc;
		ax->enc = v;
		ax->ref = v;
		ax->target = v;
		ax->pa_last = v;
		ax->err_prev = 0;
		ax->integ = 0;
	}
	put_queries(x, &args, cur, CTRL_NUM_PF);
	return 0;
}

static double *za_slot(struct ctrl *c, int axis, const void *ud)
{
	(void)ud;
	return &c->ax[axis].za;
}

/* ---- BG ST AB SH MO ------------------------------------------------------ */

/* BG: every axis of the mask is checked first; each start is an event
 * "axis A begin (handle B)". */
static int cmd_bg(struct ctrl_xc *x, const char *a)
{
	char who[CTRL_WHO_LEN];
	unsigned mask;
	int i, rc = ctrl_parse_mask(x, a, &mask);

	if (rc)
		return rc;
	for (i = 0; i < CTRL_AXES; i++)
		if ((mask & (1u << i)) &&
		    (rc = ctrl_motion_begin(x->c, i, 1)) != 0)
			return rc;
	ctrl_xc_who(x, who, sizeof(who));
	for (i = 0; i < CTRL_AXES; i++) {
		if (!(mask & (1u << i)))
			continue;
		ctrl_motion_begin(x->c, i, 0);
		ctrl_event(x->c, "axis %c begin (%s)", 'A' + i, who);
	}
	return 0;
}

/* ST: each axis that was moving is an event "axis A stop: ST (handle B)". */
static int cmd_st(struct ctrl_xc *x, const char *a)
{
	char who[CTRL_WHO_LEN], why[CTRL_WHO_LEN + 16];
	unsigned mask;
	int i, rc = ctrl_parse_mask(x, a, &mask);

	if (rc)
		return rc;
	ctrl_xc_who(x, who, sizeof(who));
	for (i = 0; i < CTRL_AXES; i++) {
		struct ctrl_axis *ax = &x->c->ax[i];

		if (!(mask & (1u << i)))
			continue;
		if (ax->profiling && !ax->stopping)
			ctrl_event(x->c, "axis %c stop: ST (%s)", 'A' + i, who);
		ctrl_motion_stop(x->c, i, 4, ax->p.dc);
	}
	/* a bare ST from a host also stops the program */
	if (x->thread < 0 && *ctrl_skip(a) == '\0') {
		snprintf(why, sizeof(why), "halted by ST (%s)", who);
		ctrl_threads_halt_all(x->c, why);
	}
	return 0;
}

static int cmd_ab(struct ctrl_xc *x, const char *a)
{
	char who[CTRL_WHO_LEN], why[CTRL_WHO_LEN + 16];
	double v = 0;
	int i, rc = ctrl_num_list(x, a, &v, 1, NULL);

	if (rc)
		return rc;
	if (v != 0 && v != 1)
		return 6;
	ctrl_xc_who(x, who, sizeof(who));
	/* a host's stop is an event even when nothing moves: the system
	 * tests' ground truth for "stop command delivered" */
	if (x->thread < 0)
		ctrl_event(x->c, "AB %d received (%s)", (int)v, who);
	for (i = 0; i < CTRL_AXES; i++)
		ctrl_motion_abort(x->c, i, who);
	if (v == 0) {
		snprintf(why, sizeof(why), "aborted by AB (%s)", who);
		ctrl_threads_halt_all(x->c, why);
		return x->thread >= 0 ? CTRL_STOP : 0;
	}
	return 0;
}

/* SH (@on) / MO: events "axis A motor on: SH (handle B)", "axis A motor
 * off: MO (thread 0 line 57)" for each axis whose state changes. */
static int cmd_shmo(struct ctrl_xc *x, const char *a, int on)
{
	struct ctrl *c = x->c;
	char who[CTRL_WHO_LEN], why[CTRL_WHO_LEN + 8];
	unsigned mask;
	int i, rc = ctrl_parse_mask(x, a, &mask);

	if (rc)
		return rc;
	for (i = 0; i < CTRL_AXES; i++)
		if ((mask & (1u << i)) && c->ax[i].profiling &&
		    (on || !(c->cfg.deviate & CTRL_DEV_MO_MOVING)))
			return 7; /* deviation mo-moving: MO accepted */
	ctrl_xc_who(x, who, sizeof(who));
	if (!on && x->thread < 0) /* as AB: the stop arrived */
		ctrl_event(c, "MO received (%s)", who);
	snprintf(why, sizeof(why), "MO (%s)", who);
	for (i = 0; i < CTRL_AXES; i++) {
		struct ctrl_axis *ax = &c->ax[i];

		if (!(mask & (1u << i)))
			continue;
		if (!on) {
			if (!ax->p.motor_off)
				ctrl_motion_off(c, i, -1, why);
			continue;
		}
		if (ax->p.motor_off)
			ctrl_event(c, "axis %c motor on: SH (%s)", 'A' + i,
				   who);
		ax->p.motor_off = 0;
		ax->ref = ax->enc;
		ax->target = ax->enc;
		ax->vel = 0;
		ax->err_prev = 0;
		ax->integ = 0;
		ax->poserr = 0;
		ax->oa_cnt = 0;
	}
	return 0;
}

/* ---- reports and operands ------------------------------------------------ */

/* TP TE TD RP TV TT TS SC [mask] */
static int cmd_report(struct ctrl_xc *x, const char *name, const char *a)
{
	unsigned mask;
	int i, first = 1, fmt, rc = ctrl_parse_mask(x, a, &mask);
	double v;

	if (rc)
		return rc;
	fmt = strchr("PEDR", name[1]) && name[0] != 'S' ? CTRL_NUM_PF
	      : !strcmp(name, "TT")			? CTRL_NUM_GAIN
							: CTRL_NUM_INT;
	for (i = 0; i < CTRL_AXES; i++) {
		if (!(mask & (1u << i)))
			continue;
		ctrl_axis_operand(x->c, name, i, &v);
		if (!first)
			ctrl_buf_puts(&x->c->tmp, ",");
		ctrl_put_num(x, v, fmt);
		first = 0;
	}
	ctrl_buf_puts(&x->c->tmp, "\r\n");
	return 0;
}

/* ctrl_axis_cmd() - the axis commands of the command table. */
int ctrl_axis_cmd(struct ctrl_xc *x, const char *name, const char *a)
{
	const struct ctrl_par_desc *d = ctrl_par_find(name);
	const struct ctrl_ipar_desc *id = ctrl_ipar_find(name);

	if (d)
		return cmd_par(x, d, a);
	if (id)
		return cmd_ipar(x, id, a);
	switch (name[0] << 8 | name[1]) {
	case 'P' << 8 | 'A': return cmd_pa(x, a);
	case 'P' << 8 | 'R': return cmd_pr(x, a);
	case 'J' << 8 | 'G': return cmd_jg(x, a);
	case 'P' << 8 | 'T': return cmd_pt(x, a);
	case 'D' << 8 | 'P': return cmd_dp(x, a);
	case 'Z' << 8 | 'A':
		return axis_values(x, a, -2147483648.0, 2147483647, 1,
				   CTRL_NUM_INT, za_slot, NULL);
	case 'B' << 8 | 'G': return cmd_bg(x, a);
	case 'S' << 8 | 'T': return cmd_st(x, a);
	case 'A' << 8 | 'B': return cmd_ab(x, a);
	case 'S' << 8 | 'H': return cmd_shmo(x, a, 1);
	case 'M' << 8 | 'O': return cmd_shmo(x, a, 0);
	}
	return cmd_report(x, name, a);
}
