/*
 * re_calib_seek.c - seeking a limit switch (a fast move short of its slow
 * zone while the potentiometer says it is far, then a bounded slow move
 * that must end on it, the potentiometer checked there), and the first
 * phases: onto the reverse switch, off it, and the start of the sweep.
 */
#include "re_calib_int.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gl_err.h"

#define ACFACT	  10  /* dmc/constants.dmc: DC = 10 x speed */
#define GUARD_CNT 200 /* extra counts before a slow zone */
/* What one more stop and start costs a move: the braking and the
 * acceleration (1 / ACFACT s each, half of it lost against the full
 * speed) and up to three samples before the next move runs. */
#define RESTART_MS (1000 / ACFACT + 3 * RE_CALIB_SAMPLE_MS)

/* Remember where a switch first showed active: the axis stops past it by
 * its deceleration distance, and "just off the limit" is measured from
 * the switch, not from where the axis came to rest. */
void cal_note_edge(struct re_calib *c, int i, int active)
{
	if (active && !c->ax[i].have_edge) {
		c->ax[i].edge = cal_enc(c, i);
		c->ax[i].have_edge = 1;
	}
}

/* What a fast move at @speed keeps before the slow zone it heads for:
 * its braking distance (AC = DC = ACFACT x speed: speed / (2 ACFACT)),
 * two samples at that speed and a guard for the pot's noise, counts. */
double cal_brake_counts(int speed)
{
	return speed / (2.0 * ACFACT) + speed * 0.02 + GUARD_CNT;
}

/* How far the axis can run at @speed before its pot reaches @zone_v:
 * from the pot's absolute reading, with the gain overestimated by the
 * range tolerance (the move ends early, never late), less cal_brake_counts().
 * <= 0: already too close. The shortfall is range_tol of the distance:
 * a further fast move (cal_fast_worth()) takes most of what is left. */
double cal_fast_len(const struct re_calib_axis_cfg *a, double pot,
		    double zone_v, int speed)
{
	double gain_hi = a->gain_v * (1 + a->check.range_tol);

	return fabs(pot - zone_v) / gain_hi - cal_brake_counts(speed);
}

/* Is a fast move of @len counts at @fast worth making rather than going
 * on at @slow? The first one always is when there is room (the slow move
 * after it is bounded in length); a further one only when it saves more
 * than the extra stop and start cost (RESTART_MS). */
int cal_fast_worth(double len, int fast, int slow, int first)
{
	if (len <= 0)
		return 0;
	if (first && fast <= slow)
		return 1;
	return fast > slow && len / slow - len / fast > RESTART_MS / 1000.0;
}

/* The bounded slow move onto a switch: to the far side of where it can
 * be (the pot's lowest/highest possible reading), plus two back-offs. */
double cal_seek_len(const struct re_calib_axis_cfg *a, double pot, double end_v)
{
	double gain_lo = a->gain_v * (1 - a->check.range_tol);

	return fabs(pot - end_v) / gain_lo + 2.0 * a->backoff_counts;
}

int cal_stopped_badly(const struct re_calib *c, int i, const char *where,
		      struct re_fault *f)
{
	int sc = c->rec->axis[i].stop_code;

	return cal_abort(f, i,
			 "stopped before the %s: %s (stop code %d, "
			 "encoder %.0f)",
			 where, re_stop_reason(sc), sc, cal_enc(c, i));
}

/* At a switch the potentiometer must read what it reads there on this
 * robot (reverse_v / forward_v +- absolute_tolerance_v): an offset, a
 * wrong pot or its wiring, named at once rather than by the table. */
int cal_check_at_switch(const struct re_calib *c,
			const struct re_calib_cfg *cfg, int i, int fwd,
			struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	double shift = a->backoff_counts * a->gain_v;
	double want =
	    fwd ? a->check.abs_last_v + shift : a->check.abs_first_v - shift;
	double pot = cal_pot(c, cfg, i);

	if (!(a->check.abs_tol_v > 0) || fabs(pot - want) <= a->check.abs_tol_v)
		return GL_OK;
	re_fault_set(f, RE_F_CAL_ABSOLUTE, i);
	snprintf(f->s, sizeof(f->s), "%s", fwd ? "forward" : "reverse");
	f->f[0] = pot;
	f->f[1] = want;
	f->f[2] = a->check.abs_tol_v;
	return RE_FAULT;
}

static int start_seek_rev(struct re_calib *c, const struct re_io *io,
			  const struct re_calib_cfg *cfg, int i)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	double pot = cal_pot(c, cfg, i);

	c->ax[i].seek_len = cal_seek_len(a, pot, a->potlo_v);
	cal_move_to(c, i, cal_enc(c, i) - c->ax[i].seek_len, a->seek_cps);
	return cal_enter(c, io, i, PH_TO_REV);
}

int cal_step_start(struct re_calib *c, const struct re_io *io,
		   const struct re_calib_cfg *cfg, int i)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	double pot = cal_pot(c, cfg, i), len;

	if (cal_rev_switch(c, i)) { /* already on it: just back off */
		cal_move_to(c, i, cal_enc(c, i) + a->backoff_counts,
			    a->travel_cps);
		return cal_enter(c, io, i, PH_BACK_REV);
	}
	len = pot > a->pnlo_v ? cal_fast_len(a, pot, a->pnlo_v, a->travel_cps)
			      : 0;
	if (!cal_fast_worth(len, a->travel_cps, a->seek_cps, 1))
		return start_seek_rev(c, io, cfg, i);
	cal_move_to(c, i, cal_enc(c, i) - len, a->travel_cps);
	return cal_enter(c, io, i, PH_FAST_REV);
}

/* A fast move toward the reverse switch ended short of its slow zone:
 * another one while what is left is worth it (the gain is known only
 * within the range tolerance, so each ends early by that fraction), then
 * the slow seek. */
int cal_step_fast_rev(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	double pot = cal_pot(c, cfg, i), len;

	if (cal_moving(c, i))
		return GL_OK;
	if (cal_rev_switch(c, i)) /* the switch came early: fine, it is there */
		return cal_enter(c, io, i, PH_TO_REV);
	if (c->rec->axis[i].stop_code != 1)
		return cal_stopped_badly(c, i,
					 "slow zone of the reverse switch", f);
	len = pot > a->pnlo_v ? cal_fast_len(a, pot, a->pnlo_v, a->travel_cps)
			      : 0;
	if (!cal_fast_worth(len, a->travel_cps, a->seek_cps, 0))
		return start_seek_rev(c, io, cfg, i);
	cal_move_to(c, i, cal_enc(c, i) - len, a->travel_cps);
	return cal_enter(c, io, i, PH_FAST_REV);
}

int cal_step_to_rev(struct re_calib *c, const struct re_io *io,
		    const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];

	cal_note_edge(c, i, cal_rev_switch(c, i));
	if (cal_moving(c, i))
		return GL_OK;
	if (c->rec->axis[i].stop_code == 1 && !cal_rev_switch(c, i))
		return cal_abort(f, i,
				 "the reverse limit switch never came "
				 "within %.0f counts (potentiometer %.3f V)",
				 c->ax[i].seek_len, cal_pot(c, cfg, i));
	if (!cal_rev_switch(c, i))
		return cal_stopped_badly(c, i, "reverse limit switch", f);
	if (cal_check_at_switch(c, cfg, i, 0, f) == RE_FAULT)
		return RE_FAULT;
	/* the back-off is the start of the sweep: point 0 and the reverse
	 * soft limit are the back-off from where the switch was first seen,
	 * and the switch must be open there (cal_sweep_sample()) */
	return cal_begin_sweep(c, io, cfg, i,
			       c->ax[i].edge + a->backoff_counts);
}

/* Only when the axis was already on the reverse switch at the start (its
 * edge unknown): backed off from there, point 0 where it came to rest. */
int cal_step_back_rev(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];

	if (cal_moving(c, i))
		return GL_OK;
	if (cal_rev_switch(c, i))
		return cal_abort(f, i,
				 "still on the reverse limit switch "
				 "after backing off %d counts",
				 a->backoff_counts);
	if (c->rec->axis[i].stop_code != 1)
		return cal_stopped_badly(c, i, "end of the back-off", f);
	return cal_begin_sweep(c, io, cfg, i, cal_enc(c, i));
}

/* The sweep from where the axis is, with table point 0 at @start: at
 * vmax to short of the forward slow zone, or slowly onto the switch when
 * that is too close for a fast move. */
int cal_begin_sweep(struct re_calib *c, const struct re_io *io,
		    const struct re_calib_cfg *cfg, int i, double start)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	struct cal_axis *ax = &c->ax[i];
	double pot = cal_pot(c, cfg, i), len;

	ax->start = start;
	ax->off_rev = cal_enc(c, i) >= start && !cal_rev_switch(c, i);
	memset(ax->acc, 0, sizeof(ax->acc));
	len = cal_fast_len(a, pot, a->pnhi_v, a->vmax_cps);
	if (!cal_fast_worth(len, a->vmax_cps, a->seek_cps, 1)) {
		ax->seek_len = cal_seek_len(a, pot, a->pothi_v);
		cal_move_to(c, i, cal_enc(c, i) + ax->seek_len, a->seek_cps);
		return cal_enter(c, io, i, PH_SLOW_FWD);
	}
	cal_move_to(c, i, cal_enc(c, i) + len, a->vmax_cps);
	return cal_enter(c, io, i, PH_SWEEP);
}
