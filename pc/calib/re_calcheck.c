/*
 * re_calcheck.c - calibration-time checks. See re_calcheck.h and
 * docs/calibration-file.md ("Checks").
 */
#include "re_calcheck.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gl_err.h"

/* ---- calibration-time checks ---------------------------------------------*/

static int re_calcheck_cfg_ok(const struct re_calcheck_cfg *c)
{
	return c && isfinite(c->noise_margin_v) && c->noise_margin_v >= 0 &&
	       isfinite(c->expected_range_v) && c->expected_range_v > 0 &&
	       isfinite(c->range_tol) && c->range_tol >= 0 &&
	       c->min_points >= 2 && c->max_points <= RE_CAL_MAX_POINTS &&
	       c->min_points <= c->max_points && isfinite(c->step_tol_counts) &&
	       c->step_tol_counts >= 0;
}

static int re_nonmono(struct re_fault *f, int axis, int index, double prev,
		      double cur, double margin)
{
	if (f) {
		re_fault_set(f, RE_F_CAL_NONMONO, axis);
		f->i[0] = index;
		f->f[0] = prev;
		f->f[1] = cur;
		f->f[2] = margin;
	}
	return RE_FAULT;
}

int re_cal_check_point(const struct re_calcheck_cfg *cfg, int axis, int index,
		       double step_counts, double prev_enc_counts,
		       double enc_counts, double prev_pot_v, double pot_v,
		       struct re_fault *fault)
{
	double adv = enc_counts - prev_enc_counts;

	if (!re_calcheck_cfg_ok(cfg) || index < 1 || !isfinite(step_counts) ||
	    step_counts <= 0)
		return GL_ERR_ARG;
	if (!(fabs(adv - step_counts) <= cfg->step_tol_counts)) {
		if (fault) {
			re_fault_set(fault, RE_F_CAL_ENCSTEP, axis);
			fault->i[0] = index;
			fault->f[0] = adv;
			fault->f[1] = step_counts;
			fault->f[2] = cfg->step_tol_counts;
		}
		return RE_FAULT;
	}
	if (!(pot_v - prev_pot_v > cfg->noise_margin_v))
		return re_nonmono(fault, axis, index, prev_pot_v, pot_v,
				  cfg->noise_margin_v);
	return RE_OK;
}

static int re_cal_check_values(const struct re_calcheck_cfg *cfg, int axis,
			       const struct re_caltable *t,
			       struct re_fault *fault)
{
	double range;
	int k;

	if (!isfinite(t->pot_v[0]))
		return re_nonmono(fault, axis, 0, t->pot_v[0], t->pot_v[0],
				  cfg->noise_margin_v);
	for (k = 1; k < t->n; k++)
		if (!(t->pot_v[k] - t->pot_v[k - 1] > cfg->noise_margin_v) ||
		    !isfinite(t->pot_v[k]))
			return re_nonmono(fault, axis, k, t->pot_v[k - 1],
					  t->pot_v[k], cfg->noise_margin_v);
	range = t->pot_v[t->n - 1] - t->pot_v[0];
	if (!(fabs(range - cfg->expected_range_v) <=
	      cfg->range_tol * cfg->expected_range_v)) {
		if (fault) {
			re_fault_set(fault, RE_F_CAL_RANGE, axis);
			fault->f[0] = range;
			fault->f[1] = cfg->expected_range_v;
			fault->f[2] = cfg->range_tol * 100.0;
		}
		return RE_FAULT;
	}
	return RE_OK;
}

static int re_cal_check_limits(int axis, const struct re_caltable *t,
			       struct re_fault *fault)
{
	double first = t->start_counts;
	double last = t->start_counts + (t->n - 1) * t->step_counts;
	double lo = first - RE_CAL_EXTRAP_STEPS * t->step_counts;
	double hi = last + RE_CAL_EXTRAP_STEPS * t->step_counts;

	if (lo <= t->soft_rev && t->soft_rev < t->soft_fwd && t->soft_fwd <= hi)
		return RE_OK;
	if (fault) {
		re_fault_set(fault, RE_F_CAL_LIMITS, axis);
		fault->f[0] = t->soft_rev;
		fault->f[1] = t->soft_fwd;
		fault->f[2] = first;
		fault->f[3] = last;
	}
	return RE_FAULT;
}

/* The end values against the potentiometer's absolute readings. */
static int re_cal_check_ends(const struct re_calcheck_cfg *cfg, int axis,
			     const struct re_caltable *t,
			     struct re_fault *fault)
{
	double v[2] = {t->pot_v[0], t->pot_v[t->n - 1]};
	double want[2] = {cfg->abs_first_v, cfg->abs_last_v};

	if (!(cfg->abs_tol_v > 0))
		return RE_OK;
	for (int k = 0; k < 2; k++) {
		if (fabs(v[k] - want[k]) <= cfg->abs_tol_v)
			continue;
		if (fault) {
			re_fault_set(fault, RE_F_CAL_ABSOLUTE, axis);
			snprintf(fault->s, sizeof(fault->s), "%s",
				 k ? "forward" : "reverse");
			fault->f[0] = v[k];
			fault->f[1] = want[k];
			fault->f[2] = cfg->abs_tol_v;
		}
		return RE_FAULT;
	}
	return RE_OK;
}

int re_cal_check_table(const struct re_calcheck_cfg *cfg, int axis,
		       const struct re_caltable *t, struct re_fault *fault)
{
	int v;

	if (!re_calcheck_cfg_ok(cfg) || !t)
		return GL_ERR_ARG;
	if (t->n < cfg->min_points || t->n > cfg->max_points) {
		if (fault) {
			re_fault_set(fault, RE_F_CAL_POINTS, axis);
			fault->i[0] = t->n;
			fault->i[1] = cfg->min_points;
			fault->i[2] = cfg->max_points;
		}
		return RE_FAULT;
	}
	if (!re_caltable_ok(t))
		return GL_ERR_ARG;
	v = re_cal_check_values(cfg, axis, t, fault);
	if (v == RE_OK)
		v = re_cal_check_limits(axis, t, fault);
	if (v == RE_OK)
		v = re_cal_check_ends(cfg, axis, t, fault);
	return v;
}
