/*
 * re_check.c - the supervisor's cycle checks as pure functions.
 *
 * See re_check.h for the contracts and docs/calibration-file.md ("Checks")
 * for the decisions. The operator texts are in re_fault.c.
 */
#include "re_check.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gl_err.h"

/* ---- encoder / potentiometer ---------------------------------------------*/

int re_caltable_ok(const struct re_caltable *t)
{
	return t && t->n >= 2 && t->n <= RE_CAL_MAX_POINTS &&
	       isfinite(t->start_counts) && isfinite(t->step_counts) &&
	       t->step_counts > 0;
}

int re_cal_expect(const struct re_caltable *t, double enc_counts,
		  struct re_expect *out)
{
	double x, frac;
	int seg;

	if (!re_caltable_ok(t) || !out || !isfinite(enc_counts))
		return GL_ERR_ARG;
	x = (enc_counts - t->start_counts) / t->step_counts;
	out->where = RE_TPOS_INSIDE;
	if (x < 0) {
		seg = 0;
		if (x < -RE_CAL_EXTRAP_STEPS)
			out->where = RE_TPOS_OUTSIDE;
		else
			out->where = RE_TPOS_EXTRAP;
	} else if (x > t->n - 1) {
		seg = t->n - 2;
		if (x > t->n - 1 + RE_CAL_EXTRAP_STEPS)
			out->where = RE_TPOS_OUTSIDE;
		else
			out->where = RE_TPOS_EXTRAP;
	} else {
		seg = (int)floor(x);
		if (seg > t->n - 2)
			seg = t->n - 2; /* exactly at the last point */
	}
	frac = x - seg;
	/* Exact at frac 0 and 1, i.e. at every table point. */
	out->pot_v = t->pot_v[seg] * (1.0 - frac) + t->pot_v[seg + 1] * frac;
	out->step_v = fabs(t->pot_v[seg + 1] - t->pot_v[seg]);
	out->seg = seg;
	return GL_OK;
}

static void re_encpot_fault(const struct re_caltable *t, int axis,
			    double enc_counts, double pot_v,
			    const struct re_encpot_result *r,
			    struct re_fault *f)
{
	if (r->exp.where == RE_TPOS_OUTSIDE) {
		re_fault_set(f, RE_F_ENC_OUTSIDE, axis);
		f->i[0] = isfinite(enc_counts) && fabs(enc_counts) < 1e18
			      ? llround(enc_counts)
			      : RE_VAL_UNKNOWN;
		f->i[1] = llround(t->start_counts);
		f->i[2] =
		    llround(t->start_counts + (t->n - 1) * t->step_counts);
		return;
	}
	re_fault_set(f, RE_F_ENCPOT, axis);
	f->i[0] = llround(enc_counts);
	f->i[1] = r->violations;
	f->f[0] = pot_v;
	f->f[1] = r->exp.pot_v;
	f->f[2] = r->diff_v;
	f->f[3] = r->tol_v;
}

int re_check_encpot(const struct re_caltable *t,
		    const struct re_encpot_cfg *cfg, int axis,
		    double enc_counts, double pot_v, struct re_encpot_state *st,
		    struct re_encpot_result *res, struct re_fault *fault)
{
	struct re_encpot_result r;

	if (!re_caltable_ok(t) || !cfg || !st ||
	    !isfinite(cfg->allowed_error) || cfg->allowed_error < 0 ||
	    cfg->persistence_cycles < 0)
		return GL_ERR_ARG;
	memset(&r, 0, sizeof(r));
	if (re_cal_expect(t, enc_counts, &r.exp) != GL_OK) {
		/* a non-finite encoder reading: a violation, never OK */
		r.exp.where = RE_TPOS_OUTSIDE;
		r.exp.pot_v = NAN;
		r.exp.step_v = NAN;
	}
	r.diff_v = fabs(pot_v - r.exp.pot_v); /* NaN pot -> NaN diff */
	r.tol_v = (1.0 + cfg->allowed_error) * r.exp.step_v;
	r.margin_v = r.tol_v - r.diff_v;
	r.violating = r.exp.where == RE_TPOS_OUTSIDE || !(r.diff_v <= r.tol_v);
	if (!r.violating)
		st->violations = 0;
	else if (st->violations < INT_MAX)
		st->violations++;
	r.violations = st->violations;
	if (res)
		*res = r;
	if (r.violations <= cfg->persistence_cycles)
		return RE_OK;
	if (fault)
		re_encpot_fault(t, axis, enc_counts, pot_v, &r, fault);
	return RE_FAULT;
}

/* ---- watchdog ------------------------------------------------------------*/

int re_wdog_limits(const struct re_wdog_cfg *cfg, struct re_wdog_lim *out)
{
	if (!cfg || !out || cfg->period_ns <= 0 ||
	    !isfinite(cfg->noncrit_factor) || !isfinite(cfg->crit_factor) ||
	    cfg->noncrit_factor < 1.0 ||
	    cfg->crit_factor < cfg->noncrit_factor || cfg->crit_factor > 1e6)
		return GL_ERR_ARG;
	out->noncrit_ns = llround(cfg->noncrit_factor * (double)cfg->period_ns);
	out->crit_ns = llround(cfg->crit_factor * (double)cfg->period_ns);
	return GL_OK;
}

int re_check_reply_age(const struct re_wdog_lim *lim, int64_t last_good_ns,
		       int64_t now_ns, int64_t *age_ns, struct re_fault *fault)
{
	int64_t warn_ns, crit_ns, age;

	if (!lim || lim->noncrit_ns <= 0 || lim->crit_ns < lim->noncrit_ns ||
	    now_ns < last_good_ns)
		return GL_ERR_ARG;
	warn_ns = lim->noncrit_ns;
	crit_ns = lim->crit_ns;
	age = now_ns - last_good_ns;
	if (age_ns)
		*age_ns = age;
	if (age > crit_ns) {
		if (fault) {
			re_fault_set(fault, RE_F_WDOG_REPLY, -1);
			fault->i[0] = age / 1000000;
			fault->i[1] = (crit_ns + 500000) / 1000000;
		}
		return RE_FAULT;
	}
	return age > warn_ns ? RE_WARN : RE_OK;
}

void re_alive_reset(struct re_alive_state *st)
{
	memset(st, 0, sizeof(*st));
}

static void re_alive_fault(struct re_fault *f, enum re_fault_id id,
			   long long value, int64_t frozen_ns, int64_t limit_ns)
{
	if (!f)
		return;
	re_fault_set(f, id, -1);
	f->i[0] = value;
	f->i[1] = frozen_ns / 1000000;
	f->i[2] = (limit_ns + 500000) / 1000000;
}

int re_check_alive(const struct re_alive_cfg *cfg, struct re_alive_state *st,
		   int64_t now_ns, int32_t hbdmc, uint16_t sample,
		   struct re_fault *fault)
{
	if (!cfg || !st || cfg->hb_limit_ns <= 0 || cfg->sample_limit_ns <= 0)
		return GL_ERR_ARG;
	if (!st->seen) {
		st->seen = 1;
		st->hb = hbdmc;
		st->sample = sample;
		st->hb_since_ns = now_ns;
		st->sample_since_ns = now_ns;
		return RE_OK;
	}
	if (now_ns < st->hb_since_ns || now_ns < st->sample_since_ns)
		return GL_ERR_ARG;
	if (hbdmc != st->hb) {
		st->hb = hbdmc;
		st->hb_since_ns = now_ns;
	}
	if (sample != st->sample) {
		st->sample = sample;
		st->sample_since_ns = now_ns;
	}
	if (now_ns - st->hb_since_ns > cfg->hb_limit_ns) {
		re_alive_fault(fault, RE_F_WDOG_HEARTBEAT, hbdmc,
			       now_ns - st->hb_since_ns, cfg->hb_limit_ns);
		return RE_FAULT;
	}
	if (now_ns - st->sample_since_ns > cfg->sample_limit_ns) {
		re_alive_fault(fault, RE_F_WDOG_SAMPLE, sample,
			       now_ns - st->sample_since_ns,
			       cfg->sample_limit_ns);
		return RE_FAULT;
	}
	return RE_OK;
}

int re_check_motors(const struct gl_record *rec, int n_axes, int expect_on,
		    struct re_fault *fault)
{
	int k;

	if (!rec || n_axes < 0 || n_axes > rec->n_axes ||
	    n_axes > GL_REC_MAX_AXES)
		return GL_ERR_ARG;
	if (!expect_on)
		return RE_OK;
	for (k = 0; k < n_axes; k++) {
		const struct gl_rec_axis *ax = &rec->axis[k];

		if (!(ax->status & GL_AXST_MOTOR_OFF))
			continue;
		if (fault) {
			re_fault_set(fault, RE_F_MOTOR_OFF, k);
			fault->i[0] = ax->stop_code;
			snprintf(fault->s, sizeof(fault->s), "%s",
				 re_stop_reason(ax->stop_code));
		}
		return RE_FAULT;
	}
	return RE_OK;
}

static int re_thread_fault(const struct gl_record *rec, int thread,
			   struct re_fault *fault)
{
	if (rec->threads & (1u << thread))
		return RE_OK;
	if (fault) {
		re_fault_set(fault, RE_F_THREAD, -1);
		fault->i[0] = thread;
		fault->i[1] = rec->threads;
	}
	return RE_FAULT;
}

static const char *re_state_name(int state)
{
	switch (state) {
	case RE_DMC_UNARMED: return "safe";
	case RE_DMC_ARMED: return "armed";
	case RE_DMC_FAULT: return "latched";
	case RE_DMC_SERVICE: return "service";
	default: return "unknown";
	}
}

int re_check_record(const struct gl_record *rec, int n_axes, int expect,
		    struct re_za *za, struct re_fault *fault)
{
	struct re_fault dummy;
	struct re_za z;
	int v;

	if (!rec || rec->n_axes < 3 || n_axes < 0 || n_axes > rec->n_axes)
		return GL_ERR_ARG;
	if (!fault)
		fault = &dummy;
	if (re_za_decode(rec->axis[0].za, rec->axis[1].za, rec->axis[2].za,
			 &z) != GL_OK) {
		re_fault_set(fault, RE_F_RECORD, -1);
		fault->i[0] = rec->axis[1].za;
		fault->i[1] = rec->axis[2].za;
		return RE_FAULT;
	}
	if (za)
		*za = z;
	if (z.state == RE_DMC_FAULT || z.fcode != RE_DMC_F_NONE) {
		re_ctrl_fault(&z, RE_VAL_UNKNOWN, fault);
		return RE_FAULT;
	}
	v = re_thread_fault(rec, 0, fault);
	if (v != RE_OK || (expect != RE_DMC_ARMED && expect != RE_DMC_SERVICE))
		return v;
	if (expect == RE_DMC_SERVICE && z.state != RE_DMC_SERVICE) {
		re_fault_set(fault, RE_F_CTRL_STATE, -1);
		fault->i[0] = z.state;
		snprintf(fault->s, sizeof(fault->s), "%s",
			 re_state_name(expect));
		return RE_FAULT;
	}
	if (expect == RE_DMC_SERVICE)
		return re_check_motors(rec, n_axes, 1, fault);
	if (z.state != RE_DMC_ARMED) {
		re_fault_set(fault, RE_F_STATE, -1);
		fault->i[0] = z.state;
		return RE_FAULT;
	}
	v = re_thread_fault(rec, 1, fault);
	if (v != RE_OK)
		return v;
	return re_check_motors(rec, n_axes, 1, fault);
}
