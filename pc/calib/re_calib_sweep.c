/*
 * re_calib_sweep.c - the sweep: forward at vmax to short of the forward
 * slow zone, slowly onto the forward switch, every sample into the table,
 * then the forward soft limit (off the switch).
 */
#include "re_calib_int.h"

#include <math.h>

#include "gl_err.h"

/* One sample of the sweep: into the table, and the first one at or past
 * point 0 (the back-off from the reverse switch's edge) must show that
 * switch open. */
int cal_sweep_sample(struct re_calib *c, const struct re_calib_cfg *cfg, int i,
		     struct re_fault *f)
{
	struct cal_axis *ax = &c->ax[i];

	cal_accumulate(c, cfg, i);
	if (ax->off_rev || cal_enc(c, i) < ax->start)
		return GL_OK;
	if (cal_rev_switch(c, i))
		return cal_abort(f, i,
				 "still on the reverse limit switch "
				 "after backing off %d counts",
				 cfg->axis[i].backoff_counts);
	ax->off_rev = 1;
	return GL_OK;
}

/* A sweep move ended short of the forward slow zone: another one at vmax
 * while what is left is worth it (as cal_step_fast_rev()), then slowly on. */
int cal_step_sweep(struct re_calib *c, const struct re_io *io,
		   const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	struct cal_axis *ax = &c->ax[i];
	double pot, len;

	if (cal_sweep_sample(c, cfg, i, f) == RE_FAULT)
		return RE_FAULT;
	if (cal_moving(c, i))
		return GL_OK;
	if (cal_fwd_switch(c, i))
		return cal_enter(c, io, i, PH_SLOW_FWD);
	if (c->rec->axis[i].stop_code != 1)
		return cal_stopped_badly(c, i,
					 "slow zone of the forward switch", f);
	pot = cal_pot(c, cfg, i);
	len =
	    pot < a->pnhi_v ? cal_fast_len(a, pot, a->pnhi_v, a->vmax_cps) : 0;
	if (cal_fast_worth(len, a->vmax_cps, a->seek_cps, 0)) {
		cal_move_to(c, i, cal_enc(c, i) + len, a->vmax_cps);
		return cal_enter(c, io, i, PH_SWEEP);
	}
	ax->seek_len = cal_seek_len(a, pot, a->pothi_v);
	cal_move_to(c, i, cal_enc(c, i) + ax->seek_len, a->seek_cps);
	return cal_enter(c, io, i, PH_SLOW_FWD);
}

/* How far the encoder check reaches past the table cal_build_table() will
 * make from start to soft_fwd: its last point and RE_CAL_EXTRAP_STEPS
 * more (less a tenth of a step), counts. */
static double table_reach(const struct cal_axis *ax,
			  const struct re_calib_axis_cfg *a)
{
	double last = floor((ax->soft_fwd - ax->start) / a->step_counts);

	return ax->start + (last + RE_CAL_EXTRAP_STEPS - 0.1) * a->step_counts;
}

int cal_step_slow_fwd(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];

	if (cal_sweep_sample(c, cfg, i, f) == RE_FAULT)
		return RE_FAULT;
	cal_note_edge(c, i, cal_fwd_switch(c, i));
	if (cal_moving(c, i))
		return GL_OK;
	if (c->rec->axis[i].stop_code == 1 && !cal_fwd_switch(c, i))
		return cal_abort(f, i,
				 "the forward limit switch never came "
				 "within %.0f counts (potentiometer %.3f V)",
				 c->ax[i].seek_len, cal_pot(c, cfg, i));
	if (!cal_fwd_switch(c, i))
		return cal_stopped_badly(c, i, "forward limit switch", f);
	if (cal_check_at_switch(c, cfg, i, 1, f) == RE_FAULT)
		return RE_FAULT;
	/* the forward soft limit: the back-off from the switch's edge. When
	 * the axis rests where the new table still reaches (table_reach()),
	 * the back-off is the start of the move to the centre (cal_to_centre()
	 * checks the switch open there); else a move of its own, away from
	 * the switch at the travel speed */
	c->ax[i].soft_fwd = c->ax[i].edge - a->backoff_counts;
	if (cal_enc(c, i) < table_reach(&c->ax[i], a)) {
		c->ax[i].off_fwd = 0;
		return cal_enter(c, io, i, PH_DONE);
	}
	cal_move_to(c, i, c->ax[i].soft_fwd, a->travel_cps);
	return cal_enter(c, io, i, PH_BACK_FWD);
}

int cal_step_back_fwd(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	if (cal_moving(c, i))
		return GL_OK;
	if (cal_fwd_switch(c, i))
		return cal_abort(f, i,
				 "still on the forward limit switch "
				 "after backing off %d counts",
				 cfg->axis[i].backoff_counts);
	if (c->rec->axis[i].stop_code != 1)
		return cal_stopped_badly(c, i, "end of the back-off", f);
	c->ax[i].soft_fwd = cal_enc(c, i);
	c->ax[i].off_fwd = 1;
	return cal_enter(c, io, i, PH_DONE);
}
