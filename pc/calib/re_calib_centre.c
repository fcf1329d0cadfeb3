/*
 * re_calib_centre.c - the move of every axis to the centre of its table,
 * the supervisor checking the potentiometer against the tables on every
 * sample, and the forward switch seen open on the way.
 */
#include "re_calib_int.h"

#include "base_clock.h"
#include "gl_err.h"

static int all_stopped(const struct re_calib *c, int n)
{
	for (int i = 0; i < n; i++)
		if (cal_moving(c, i))
			return 0;
	return 1;
}

/* An axis that left the forward switch on its way to the centre: the
 * first sample at or inside the forward soft limit must show the switch
 * open (as at the end of a back-off of its own). */
static int off_fwd_check(struct re_calib *c, const struct re_calib_cfg *cfg,
			 const struct re_calset *set, struct re_fault *f)
{
	for (int i = 0; i < cfg->n_axes; i++) {
		struct cal_axis *ax = &c->ax[i];

		if (ax->off_fwd || cal_enc(c, i) > set->axis[i].soft_fwd)
			continue;
		if (cal_fwd_switch(c, i))
			return cal_abort(f, i,
					 "still on the forward limit switch "
					 "after backing off %d counts",
					 cfg->axis[i].backoff_counts);
		ax->off_fwd = 1;
	}
	return GL_OK;
}

/* Every axis to the centre of its soft limits at the travel speed; the
 * supervisor checks the encoders against @set on every sample. */
int cal_to_centre(struct re_calib *c, const struct re_io *io,
		  const struct re_calib_cfg *cfg, const struct re_calset *set,
		  struct re_fault *f)
{
	int64_t deadline =
	    cal_now_ns(io) + cfg->move_timeout_ms * BASE_NS_PER_MS;
	int rc;

	for (int i = 0; i < RE_AXES; i++) {
		c->ax[i].centre =
		    (set->axis[i].soft_rev + set->axis[i].soft_fwd) / 2;
		cal_move_to(c, i, c->ax[i].centre, cfg->axis[i].travel_cps);
		cal_enter(c, io, i, PH_CENTRE);
	}
	rc = cal_send_batch(c, io, cfg, f);
	do {
		if (rc == GL_OK)
			rc = cal_sample(c, cfg, f);
		if (rc == GL_OK)
			rc = cal_taken(c, io, cfg, f);
		if (rc == GL_OK)
			rc = off_fwd_check(c, cfg, set, f);
		if (rc == GL_OK && !c->pending && !c->taken_now &&
		    all_stopped(c, cfg->n_axes))
			return GL_OK;
	} while (rc == GL_OK && cal_now_ns(io) < deadline);
	if (rc != GL_OK)
		return rc;
	return cal_abort(f, -1,
			 "the move to the centre did not end within "
			 "%d ms",
			 cfg->move_timeout_ms);
}
