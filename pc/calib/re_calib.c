/*
 * re_calib.c - calibration on the controller: the settings from the
 * configuration, the working state, and full calibration (all axes at
 * once, each through its phases, every move a supervised service move),
 * then the tables built and every axis to the centre. The phases are in
 * re_calib_seek.c and re_calib_sweep.c, the check of tables loaded from a
 * file in re_calib_verify.c (re_calib_int.h). See re_calib.h.
 */
#include "re_calib_int.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"

int re_calib_new(struct re_calib **out)
{
	*out = calloc(1, sizeof(**out));
	return *out ? GL_OK : GL_ERR_NOMEM;
}

void re_calib_free(struct re_calib *c)
{
	free(c);
}

static void axis_cfg_from(const struct re_config *cfg,
			  const struct re_plan_axis *pa, int i,
			  struct re_calib_axis_cfg *o)
{
	const struct re_config_axis *a = &cfg->axes[i];
	int back = cfg->calibration.backoff_counts;
	double lo = a->travel_counts * (1 - a->travel_tolerance) - 2.0 * back;
	double hi = a->travel_counts * (1 + a->travel_tolerance);

	o->vmax_cps = a->vmax_cps;
	o->travel_cps = pa->travel_cps;
	o->seek_cps = pa->seek_cps;
	o->gain_v = pa->gain_v_per_count;
	o->pnlo_v = pa->pnlo_v;
	o->pnhi_v = pa->pnhi_v;
	o->potlo_v = pa->potlo_v;
	o->pothi_v = pa->pothi_v;
	o->step_counts = a->step_counts;
	o->travel_counts = a->travel_counts;
	o->travel_tol = a->travel_tolerance;
	o->backoff_counts = back;
	o->pot_input = a->analog.input;
	o->check.noise_margin_v = a->monotonic_margin_v;
	o->check.expected_range_v = a->analog.expected_range_v;
	o->check.range_tol = a->analog.range_tolerance;
	o->check.min_points =
	    lo / a->step_counts > 2 ? (int)(lo / a->step_counts) : 2;
	o->check.max_points = (int)(hi / a->step_counts) + 1;
	if (o->check.max_points > RE_CAL_MAX_POINTS)
		o->check.max_points = RE_CAL_MAX_POINTS;
	/* the mean sample positions of two neighbouring points: each within
	 * half a step of its point, so 0 < advance < 2 steps; a PC stall
	 * leaves points with samples at one edge only */
	o->check.step_tol_counts = a->step_counts - 1.0;
	/* the table ends are a back-off inside the switches */
	o->check.abs_first_v =
	    a->analog.reverse_v + back * pa->gain_v_per_count;
	o->check.abs_last_v = a->analog.forward_v - back * pa->gain_v_per_count;
	o->check.abs_tol_v = a->analog.absolute_tolerance_v;
	o->encpot.allowed_error = a->allowed_error;
	o->encpot.persistence_cycles = a->persistence_cycles;
}

void re_calib_cfg_from(const struct re_config *cfg, const struct re_plan *plan,
		       const char *const *names, struct re_calib_cfg *out)
{
	memset(out, 0, sizeof(*out));
	out->n_axes = RE_AXES;
	out->names = names;
	out->move_timeout_ms = cfg->calibration.move_timeout_ms;
	out->cmd_timeout_ms = cfg->controller.timeout_ms;
	out->accept_ms = 3 * (plan->mainms > 0 ? plan->mainms : 10) + 20;
	for (int i = 0; i < RE_AXES; i++)
		axis_cfg_from(cfg, &plan->axis[i], i, &out->axis[i]);
}

static int axis_step(struct re_calib *c, const struct re_io *io,
		     const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	int64_t age = cal_now_ns(io) - c->ax[i].t_phase_ns;

	if (c->ax[i].ph != PH_START && c->ax[i].ph != PH_DONE &&
	    age > (int64_t)cfg->move_timeout_ms * BASE_NS_PER_MS)
		return cal_abort(f, i,
				 "a calibration move did not end "
				 "within %d ms (encoder %.0f)",
				 cfg->move_timeout_ms, cal_enc(c, i));
	if (cal_waiting(c, i)) {
		if (c->ax[i].ph == PH_SWEEP || c->ax[i].ph == PH_SLOW_FWD)
			return cal_sweep_sample(c, cfg, i, f);
		return GL_OK;
	}
	switch (c->ax[i].ph) {
	case PH_START: return cal_step_start(c, io, cfg, i);
	case PH_FAST_REV: return cal_step_fast_rev(c, io, cfg, i, f);
	case PH_TO_REV: return cal_step_to_rev(c, io, cfg, i, f);
	case PH_BACK_REV: return cal_step_back_rev(c, io, cfg, i, f);
	case PH_SWEEP: return cal_step_sweep(c, io, cfg, i, f);
	case PH_SLOW_FWD: return cal_step_slow_fwd(c, io, cfg, i, f);
	case PH_BACK_FWD: return cal_step_back_fwd(c, io, cfg, i, f);
	default: return GL_OK;
	}
}

static int sweep_all(struct re_calib *c, const struct re_io *io,
		     const struct re_calib_cfg *cfg, struct re_fault *f)
{
	int rc, done;

	do {
		rc = cal_sample(c, cfg, f);
		if (rc == GL_OK)
			rc = cal_taken(c, io, cfg, f);
		done = !c->pending && !c->taken_now && !c->b.mask;
		for (int i = 0; rc == GL_OK && i < cfg->n_axes; i++) {
			rc = axis_step(c, io, cfg, i, f);
			done &= c->ax[i].ph == PH_DONE;
		}
		if (rc == GL_OK)
			rc = cal_send_batch(c, io, cfg, f);
	} while (rc == GL_OK && !done);
	return rc;
}

int re_calib_full(struct re_calib *c, const struct re_io *io,
		  const struct re_calib_cfg *cfg, struct re_calset *set,
		  struct re_fault *fault, double *seconds, int *filled)
{
	int rc;

	if (!c || !io || !cfg || !set || cfg->n_axes != RE_AXES ||
	    !cfg->sampler.sample)
		return GL_ERR_ARG;
	memset(set, 0, sizeof(*set));
	memset(&c->b, 0, sizeof(c->b));
	c->pending = 0;
	c->taken_now = 0;
	c->filled = 0;
	for (int i = 0; i < RE_AXES; i++)
		cal_enter(c, io, i, PH_START);
	c->t0_ns = cal_now_ns(io);
	c->running = 1;
	c->full = 1;
	cal_own(cfg, 7);
	rc = sweep_all(c, io, cfg, fault);
	for (int i = 0; rc == GL_OK && i < RE_AXES; i++)
		rc = cal_build_table(c, cfg, i, &set->axis[i], fault);
	set->n_axes = RE_AXES;
	for (int i = 0; i < RE_AXES; i++)
		snprintf(set->name[i], sizeof(set->name[i]), "%s",
			 cfg->names[i]);
	if (rc == GL_OK) {
		cal_use_tables(cfg, set);
		rc = cal_to_centre(c, io, cfg, set, fault);
	}
	cal_own(cfg, 0);
	c->running = 0;
	if (seconds)
		*seconds = (double)(cal_now_ns(io) - c->t0_ns) / 1e9;
	if (filled)
		*filled = c->filled;
	if (rc != GL_OK)
		memset(set, 0, sizeof(*set));
	return rc;
}
