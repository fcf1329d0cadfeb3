/*
 * re_calib_verify.c - the check of tables loaded from a file: the robot
 * where they say (every axis inside its table, the potentiometer within
 * the run-time tolerance), then to the centre checked on every sample.
 */
#include "re_calib_int.h"

#include <string.h>

#include "gl_err.h"

/* The robot where the loaded tables say: every axis inside its table and
 * the potentiometer within the run-time tolerance. */
static int check_position(struct re_calib *c, const struct re_calib_cfg *cfg,
			  const struct re_calset *set, struct re_fault *f)
{
	for (int i = 0; i < cfg->n_axes; i++) {
		struct re_encpot_state st = {0};
		struct re_encpot_result r;
		const struct re_caltable *t = &set->axis[i];
		double enc = cal_enc(c, i), pot = cal_pot(c, cfg, i);
		struct re_encpot_cfg once = cfg->axis[i].encpot;
		int v;

		once.persistence_cycles = 0;
		v = re_check_encpot(t, &once, i, enc, pot, &st, &r, f);
		if (v == RE_OK)
			continue;
		if (v < 0)
			return cal_abort(f, i,
					 "the table cannot be used "
					 "(%s)",
					 gl_strerror(v));
		if (r.exp.where == RE_TPOS_OUTSIDE)
			return cal_abort(f, i,
					 "encoder %.0f is outside the "
					 "file's travel %.0f..%.0f (encoder "
					 "origin lost?)",
					 enc, t->soft_rev, t->soft_fwd);
		return cal_abort(f, i,
				 "the file does not match the robot: "
				 "pot %.3f V at encoder %.0f, table %.3f V",
				 pot, enc, r.exp.pot_v);
	}
	return GL_OK;
}

int re_calib_check_robot(struct re_calib *c, const struct re_io *io,
			 const struct re_calib_cfg *cfg,
			 const struct re_calset *set, struct re_fault *fault)
{
	int rc;

	if (!c || !io || !cfg || !set || set->n_axes != cfg->n_axes ||
	    !cfg->sampler.sample)
		return GL_ERR_ARG;
	memset(&c->b, 0, sizeof(c->b));
	c->pending = 0;
	c->taken_now = 0;
	c->t0_ns = cal_now_ns(io);
	c->running = 1;
	c->full = 0;
	for (int i = 0; i < RE_AXES; i++) {
		cal_enter(c, io, i, PH_CHECK);
		c->ax[i].off_fwd = 1; /* not at a switch: nothing to check */
	}
	rc = cal_sample(c, cfg, fault);
	if (rc == GL_OK)
		rc = check_position(c, cfg, set, fault);
	cal_own(cfg, 7);
	if (rc == GL_OK)
		cal_use_tables(cfg, set);
	if (rc == GL_OK)
		rc = cal_to_centre(c, io, cfg, set, fault);
	cal_own(cfg, 0);
	c->running = 0;
	return rc;
}
