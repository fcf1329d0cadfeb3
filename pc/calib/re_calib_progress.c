/*
 * re_calib_progress.c - where a running calibration is, for the console:
 * per axis its phase, its position over the travel and the time left.
 */
#include "re_calib_int.h"

#include <math.h>
#include <string.h>

#include "re_pot.h"

static const char *const phase_names[] = {
    [PH_START] = "starting",	      [PH_FAST_REV] = "to rev switch",
    [PH_TO_REV] = "onto rev switch",  [PH_BACK_REV] = "off rev switch",
    [PH_SWEEP] = "sweep fwd",	      [PH_SLOW_FWD] = "onto fwd switch",
    [PH_BACK_FWD] = "off fwd switch", [PH_DONE] = "table built",
    [PH_CHECK] = "checking file",     [PH_CENTRE] = "to centre",
};

/* The pot at the reverse and forward switches, and the lengths run
 * slowly before each, counts: the slow zone and what the fast moves keep
 * before it (cal_brake_counts()). */
struct span {
	double rev_v, fwd_v, zone_rev, zone_fwd;
};

static struct span span_of(const struct re_calib_axis_cfg *a)
{
	struct span sp;
	double g = a->gain_v > 0 ? a->gain_v : 1;

	sp.rev_v = a->check.abs_first_v - a->backoff_counts * a->gain_v;
	sp.fwd_v = a->check.abs_last_v + a->backoff_counts * a->gain_v;
	sp.zone_rev = fmax(0, (a->pnlo_v - sp.rev_v) / g) +
		      cal_brake_counts(a->travel_cps);
	sp.zone_fwd =
	    fmax(0, (sp.fwd_v - a->pnhi_v) / g) + cal_brake_counts(a->vmax_cps);
	return sp;
}

static double secs(double counts, int cps)
{
	return cps > 0 ? fmax(0, counts) / cps : 0;
}

/* Seconds left for axis @i in phase @ph at encoder @enc, pot @pot: fast
 * to the slow zone, slowly onto the reverse switch, the sweep from there
 * (its start is the reverse back-off), slowly onto the forward switch,
 * off it and to the centre at the travel speed. */
static double axis_left_s(const struct re_calib *c,
			  const struct re_calib_axis_cfg *a, int i, double enc,
			  double pot)
{
	struct span sp = span_of(a);
	double g = a->gain_v > 0 ? a->gain_v : 1, t = a->travel_counts;
	double d_rev = fmax(0, (pot - sp.rev_v) / g);
	double d_fwd = fmax(0, (sp.fwd_v - pot) / g);
	double centre = secs(t / 2, a->travel_cps);
	double back = secs(a->backoff_counts, a->travel_cps);
	double sweep = secs(t - sp.zone_fwd, a->vmax_cps) +
		       secs(sp.zone_fwd, a->seek_cps) + back + centre;

	switch (c->ax[i].ph) {
	case PH_START:
	case PH_FAST_REV:
	case PH_TO_REV:
		return secs(d_rev - sp.zone_rev, a->travel_cps) +
		       secs(fmin(d_rev, sp.zone_rev), a->seek_cps) + sweep;
	case PH_BACK_REV: return back + sweep;
	case PH_SWEEP:
		return secs(d_fwd - sp.zone_fwd, a->vmax_cps) +
		       secs(fmin(d_fwd, sp.zone_fwd), a->seek_cps) + back +
		       centre;
	case PH_SLOW_FWD: return secs(d_fwd, a->seek_cps) + back + centre;
	case PH_BACK_FWD:
	case PH_DONE: return centre;
	case PH_CHECK:
		return secs(fabs(pot - (sp.rev_v + sp.fwd_v) / 2) / g,
			    a->travel_cps);
	case PH_CENTRE: return secs(fabs(enc - c->ax[i].centre), a->travel_cps);
	}
	return 0;
}

void re_calib_progress(const struct re_calib *c, const struct re_calib_cfg *cfg,
		       const struct gl_record *rec, int64_t now_ns,
		       struct re_calib_progress *out)
{
	memset(out, 0, sizeof(*out));
	if (!c || !c->running)
		return;
	rec = rec ? rec : c->rec;
	out->active = 1;
	out->full = c->full;
	out->elapsed_s = (double)(now_ns - c->t0_ns) / 1e9;
	for (int i = 0; i < cfg->n_axes && i < RE_AXES; i++) {
		const struct re_calib_axis_cfg *a = &cfg->axis[i];
		struct re_calib_axis_progress *p = &out->axis[i];
		struct span sp = span_of(a);
		double pot, enc;

		p->phase = phase_names[c->ax[i].ph];
		p->pct = -1;
		if (!rec || rec->n_axes <= i)
			continue;
		pot = re_pot_of(rec, i, a->pot_input);
		enc = rec->axis[i].motor_pos;
		if (sp.fwd_v > sp.rev_v)
			p->pct =
			    fmin(100, fmax(0, (pot - sp.rev_v) /
						  (sp.fwd_v - sp.rev_v) * 100));
		p->left_s = axis_left_s(c, a, i, enc, pot);
		out->left_s = fmax(out->left_s, p->left_s);
	}
}
