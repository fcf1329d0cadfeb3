/*
 * re_calib.c - full calibration (all axes at once, continuous sweep) and the
 * check of tables loaded from a file. See re_calib.h.
 */
#include "re_calib.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "re_super.h"

#define NS_PER_MS 1000000LL
#define AXES	  "ABC"

enum phase {
	PH_START,    /* nothing sent yet */
	PH_TO_REV,   /* bounded move onto the reverse switch */
	PH_BACK_REV, /* backing off it: then table point 0 */
	PH_SWEEP,    /* bounded move onto the forward switch, sampling */
	PH_BACK_FWD, /* backing off it: the forward soft limit */
	PH_DONE,
};

/* Least-squares sums of one table point's samples, dx = enc - point. */
struct acc {
	int n;
	double sx, sy, sxx, sxy;
};

struct cal_axis {
	enum phase ph;
	int64_t t_phase_ns;
	double edge; /* encoder where the switch was first seen */
	int have_edge;
	double start; /* table point 0 = reverse soft limit */
	double soft_fwd;
	struct acc acc[RE_CAL_MAX_POINTS];
};

struct re_calib {
	struct cal_axis ax[RE_AXES];
	struct gl_record rec;
	struct re_encpot_state encpot[RE_AXES];
	int64_t t0_ns, next_ns;
	char line[GL_LINE_MAX + 1];
	char resp[128];
};

int re_calib_new(struct re_calib **out)
{
	*out = calloc(1, sizeof(**out));
	return *out ? GL_OK : GL_ERR_NOMEM;
}

void re_calib_free(struct re_calib *c)
{
	free(c);
}

void re_calib_cfg_from(const struct re_config *cfg, const char *const *names,
		       struct re_calib_cfg *out)
{
	memset(out, 0, sizeof(*out));
	out->n_axes = RE_AXES;
	out->names = names;
	out->move_timeout_ms = cfg->calibration.move_timeout_ms;
	out->cmd_timeout_ms = cfg->controller.timeout_ms;
	for (int i = 0; i < RE_AXES; i++) {
		const struct re_config_axis *a = &cfg->axes[i];
		struct re_calib_axis_cfg *o = &out->axis[i];
		double lo = a->travel_counts * (1 - a->travel_tolerance) -
			    2.0 * cfg->calibration.backoff_counts;
		double hi = a->travel_counts * (1 + a->travel_tolerance);

		o->vmax_cps = a->vmax_cps;
		o->step_counts = a->step_counts;
		o->travel_counts = a->travel_counts;
		o->travel_tol = a->travel_tolerance;
		o->backoff_counts = cfg->calibration.backoff_counts;
		o->pot_input = a->analog.input;
		o->check.noise_margin_v = a->monotonic_margin_v;
		o->check.expected_range_v = a->analog.expected_range_v;
		o->check.range_tol = a->analog.range_tolerance;
		o->check.min_points =
		    lo / a->step_counts > 2 ? (int)(lo / a->step_counts) : 2;
		o->check.max_points = (int)(hi / a->step_counts) + 1;
		if (o->check.max_points > RE_CAL_MAX_POINTS)
			o->check.max_points = RE_CAL_MAX_POINTS;
		o->check.step_tol_counts = a->step_counts / 2.0;
		o->encpot.allowed_error = a->allowed_error;
		o->encpot.persistence_cycles = a->persistence_cycles;
	}
}

/* ---- faults ----------------------------------------------------------------
 */

static int abort_axis(struct re_fault *f, int axis, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static int abort_axis(struct re_fault *f, int axis, const char *fmt, ...)
{
	va_list ap;

	re_fault_set(f, RE_F_CAL_ABORT, axis);
	va_start(ap, fmt);
	vsnprintf(f->s, sizeof(f->s), fmt, ap);
	va_end(ap);
	return RE_FAULT;
}

static int comm_fault(struct re_fault *f, const char *what, int rc)
{
	re_fault_set(f, RE_F_COMM, -1);
	snprintf(f->s, sizeof(f->s), "%s: %s", what, gl_strerror(rc));
	return RE_FAULT;
}

/* ---- I/O ------------------------------------------------------------------
 */

static int send(struct re_calib *c, const struct re_io *io,
		const struct re_calib_cfg *cfg, struct re_fault *f)
{
	int rc = io->ops->command(io->ud, c->line, c->resp, sizeof(c->resp),
				  cfg->cmd_timeout_ms);

	if (rc == GL_ERR_CTRL) {
		re_fault_set(f, RE_F_CAL_ABORT, -1);
		snprintf(f->s, sizeof(f->s), "the controller refused '%s': %s",
			 c->line, io->ops->ctrl_error(io->ud, NULL));
		return RE_FAULT;
	}
	return rc < 0 ? comm_fault(f, "command failed", rc) : GL_OK;
}

static int sendf(struct re_calib *c, const struct re_io *io,
		 const struct re_calib_cfg *cfg, struct re_fault *f,
		 const char *fmt, ...) __attribute__((format(printf, 5, 6)));

static int sendf(struct re_calib *c, const struct re_io *io,
		 const struct re_calib_cfg *cfg, struct re_fault *f,
		 const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(c->line, sizeof(c->line), fmt, ap);
	va_end(ap);
	return send(c, io, cfg, f);
}

static int64_t now_ns(const struct re_io *io)
{
	return io->ops->now_ns(io->ud);
}

/* Next sample: wait for its deadline, read the record, check the relay
 * and that every motor is still on. */
static int sample_x(struct re_calib *c, const struct re_io *io,
		    const struct re_calib_cfg *cfg, int motors_on,
		    struct re_fault *f)
{
	char why[sizeof(f->s)];
	int rc;

	if (cfg->stop && *cfg->stop)
		return GL_ERR_AGAIN;
	c->next_ns += RE_CALIB_SAMPLE_MS * NS_PER_MS;
	if (c->next_ns < now_ns(io))
		c->next_ns = now_ns(io);
	io->ops->sleep_until(io->ud, c->next_ns);
	rc = io->ops->record(io->ud, NULL, &c->rec, cfg->cmd_timeout_ms);
	if (rc < 0)
		return comm_fault(f, "cannot read the data record", rc);
	if (c->rec.n_axes < cfg->n_axes)
		return comm_fault(f, "data record", GL_ERR_RECORD);
	if (io->ops->relay_check(io->ud, why, sizeof(why)) != GL_OK) {
		re_fault_set(f, RE_F_ESTOP_LOST, -1);
		snprintf(f->s, sizeof(f->s), "%s", why);
		return RE_FAULT;
	}
	if (re_check_motors(&c->rec, cfg->n_axes, motors_on, f) == RE_FAULT)
		return abort_axis(f, f->axis,
				  "the controller switched the "
				  "motor off: %s (stop code %d)",
				  re_stop_reason((int)f->i[0]), (int)f->i[0]);
	return GL_OK;
}

static int sample(struct re_calib *c, const struct re_io *io,
		  const struct re_calib_cfg *cfg, struct re_fault *f)
{
	return sample_x(c, io, cfg, 1, f);
}

static double enc_of(const struct re_calib *c, int i)
{
	return c->rec.axis[i].motor_pos;
}

static double pot_of(const struct re_calib *c, const struct re_calib_cfg *cfg,
		     int i)
{
	int in = cfg->axis[i].pot_input;
	int k = in >= 1 && in <= c->rec.n_axes ? in - 1 : i;

	return re_pot_volts(c->rec.axis[k].analog_in);
}

static int moving(const struct re_calib *c, int i)
{
	return !!(c->rec.axis[i].status & GL_AXST_MOVING);
}

static int rev_switch(const struct re_calib *c, int i)
{
	return !(c->rec.axis[i].switches & GL_AXSW_RLS);
}

static int fwd_switch(const struct re_calib *c, int i)
{
	return !(c->rec.axis[i].switches & GL_AXSW_FLS);
}

/* ---- the per-axis steps ----------------------------------------------------
 */

static int enter(struct re_calib *c, const struct re_io *io, int i,
		 enum phase ph)
{
	c->ax[i].ph = ph;
	c->ax[i].t_phase_ns = now_ns(io);
	c->ax[i].have_edge = 0;
	return GL_OK;
}

/* Remember where a switch first showed active: the axis stops past it by
 * its deceleration distance, and "just off the limit" is measured from
 * the switch, not from where the axis came to rest. */
static void note_edge(struct re_calib *c, int i, int active)
{
	if (active && !c->ax[i].have_edge) {
		c->ax[i].edge = enc_of(c, i);
		c->ax[i].have_edge = 1;
	}
}

/* An absolute move of axis i at its maximum velocity. */
static int move_abs(struct re_calib *c, const struct re_io *io,
		    const struct re_calib_cfg *cfg, int i, double target,
		    struct re_fault *f)
{
	return sendf(c, io, cfg, f, "SP%c=%d;PA%c=%.0f;BG%c", AXES[i],
		     cfg->axis[i].vmax_cps, AXES[i], target, AXES[i]);
}

/* A bounded relative move of axis i at its maximum velocity. */
static int move_rel(struct re_calib *c, const struct re_io *io,
		    const struct re_calib_cfg *cfg, int i, double counts,
		    struct re_fault *f)
{
	return sendf(c, io, cfg, f, "SP%c=%d;PR%c=%.0f;BG%c", AXES[i],
		     cfg->axis[i].vmax_cps, AXES[i], counts, AXES[i]);
}

static double sweep_counts(const struct re_calib_axis_cfg *a)
{
	return a->travel_counts * (1 + a->travel_tol) + 2.0 * a->backoff_counts;
}

static int stopped_badly(const struct re_calib *c, int i, const char *where,
			 struct re_fault *f)
{
	int sc = c->rec.axis[i].stop_code;

	return abort_axis(f, i,
			  "stopped before the %s: %s (stop code %d, "
			  "encoder %.0f)",
			  where, re_stop_reason(sc), sc, enc_of(c, i));
}

static int step_start(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	int rc;

	if (rev_switch(c, i)) { /* already on it: just back off */
		rc = move_abs(c, io, cfg, i, enc_of(c, i) + a->backoff_counts,
			      f);
		return rc ? rc : enter(c, io, i, PH_BACK_REV);
	}
	rc = move_rel(c, io, cfg, i, -sweep_counts(a), f);
	return rc ? rc : enter(c, io, i, PH_TO_REV);
}

static int step_to_rev(struct re_calib *c, const struct re_io *io,
		       const struct re_calib_cfg *cfg, int i,
		       struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	double edge;
	int rc;

	note_edge(c, i, rev_switch(c, i));
	if (moving(c, i))
		return GL_OK;
	if (c->rec.axis[i].stop_code == 1 && !rev_switch(c, i))
		return abort_axis(f, i,
				  "the reverse limit switch never came "
				  "within %.0f counts",
				  sweep_counts(a));
	if (!rev_switch(c, i))
		return stopped_badly(c, i, "reverse limit switch", f);
	edge = c->ax[i].edge;
	rc = move_abs(c, io, cfg, i, edge + a->backoff_counts, f);
	return rc ? rc : enter(c, io, i, PH_BACK_REV);
}

static int step_back_rev(struct re_calib *c, const struct re_io *io,
			 const struct re_calib_cfg *cfg, int i,
			 struct re_fault *f)
{
	struct cal_axis *ax = &c->ax[i];
	int rc;

	if (moving(c, i))
		return GL_OK;
	if (rev_switch(c, i))
		return abort_axis(f, i,
				  "still on the reverse limit switch "
				  "after backing off %d counts",
				  cfg->axis[i].backoff_counts);
	if (c->rec.axis[i].stop_code != 1)
		return stopped_badly(c, i, "end of the back-off", f);
	ax->start = enc_of(c, i);
	memset(ax->acc, 0, sizeof(ax->acc));
	rc = move_rel(c, io, cfg, i, sweep_counts(&cfg->axis[i]), f);
	return rc ? rc : enter(c, io, i, PH_SWEEP);
}

/* Add this sample to the table point nearest to the encoder. */
static void accumulate(struct re_calib *c, const struct re_calib_cfg *cfg,
		       int i)
{
	struct cal_axis *ax = &c->ax[i];
	double step = cfg->axis[i].step_counts;
	double enc = enc_of(c, i), pot = pot_of(c, cfg, i);
	long j = lround((enc - ax->start) / step);
	struct acc *a;
	double dx;

	if (j < 0 || j >= RE_CAL_MAX_POINTS)
		return;
	a = &ax->acc[j];
	dx = enc - (ax->start + (double)j * step);
	a->n++;
	a->sx += dx;
	a->sy += pot;
	a->sxx += dx * dx;
	a->sxy += dx * pot;
}

static int step_sweep(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	double edge;
	int rc;

	accumulate(c, cfg, i);
	note_edge(c, i, fwd_switch(c, i));
	if (moving(c, i))
		return GL_OK;
	if (c->rec.axis[i].stop_code == 1 && !fwd_switch(c, i))
		return abort_axis(f, i,
				  "the forward limit switch never came "
				  "within %.0f counts",
				  sweep_counts(a));
	if (!fwd_switch(c, i))
		return stopped_badly(c, i, "forward limit switch", f);
	edge = c->ax[i].edge;
	rc = move_abs(c, io, cfg, i, edge - a->backoff_counts, f);
	return rc ? rc : enter(c, io, i, PH_BACK_FWD);
}

static int step_back_fwd(struct re_calib *c, const struct re_io *io,
			 const struct re_calib_cfg *cfg, int i,
			 struct re_fault *f)
{
	if (moving(c, i))
		return GL_OK;
	if (fwd_switch(c, i))
		return abort_axis(f, i,
				  "still on the forward limit switch "
				  "after backing off %d counts",
				  cfg->axis[i].backoff_counts);
	if (c->rec.axis[i].stop_code != 1)
		return stopped_badly(c, i, "end of the back-off", f);
	c->ax[i].soft_fwd = enc_of(c, i);
	return enter(c, io, i, PH_DONE);
}

static int axis_step(struct re_calib *c, const struct re_io *io,
		     const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	int64_t age = now_ns(io) - c->ax[i].t_phase_ns;

	if (c->ax[i].ph != PH_START && c->ax[i].ph != PH_DONE &&
	    age > (int64_t)cfg->move_timeout_ms * NS_PER_MS)
		return abort_axis(f, i,
				  "a calibration move did not end "
				  "within %d ms (encoder %.0f)",
				  cfg->move_timeout_ms, enc_of(c, i));
	switch (c->ax[i].ph) {
	case PH_START: return step_start(c, io, cfg, i, f);
	case PH_TO_REV: return step_to_rev(c, io, cfg, i, f);
	case PH_BACK_REV: return step_back_rev(c, io, cfg, i, f);
	case PH_SWEEP: return step_sweep(c, io, cfg, i, f);
	case PH_BACK_FWD: return step_back_fwd(c, io, cfg, i, f);
	default: return GL_OK;
	}
}

/* ---- tables ----------------------------------------------------------------
 */

/* The value at a point: the least-squares line through its samples, read
 * at the point; the mean when the samples do not spread. */
static double point_value(const struct acc *a, double step, double *enc_off)
{
	double mx = a->sx / a->n, my = a->sy / a->n;
	double var = a->sxx / a->n - mx * mx;

	*enc_off = mx;
	if (a->n < 3 || var < (step / 20) * (step / 20))
		return my;
	return my - (a->sxy / a->n - mx * my) / var * mx;
}

static int build_table(struct re_calib *c, const struct re_calib_cfg *cfg,
		       int i, struct re_caltable *t, struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	struct cal_axis *ax = &c->ax[i];
	double prev_enc = 0, enc_off;
	long n = lround(floor((ax->soft_fwd - ax->start) / a->step_counts)) + 1;

	memset(t, 0, sizeof(*t));
	t->n = n > RE_CAL_MAX_POINTS ? RE_CAL_MAX_POINTS : (int)n;
	t->start_counts = ax->start;
	t->step_counts = a->step_counts;
	t->soft_rev = ax->start;
	t->soft_fwd = ax->soft_fwd;
	for (int j = 0; j < t->n; j++) {
		double x = ax->start + (double)j * a->step_counts;

		if (ax->acc[j].n == 0)
			return abort_axis(f, i,
					  "no potentiometer sample near "
					  "point %d (encoder %.0f)",
					  j, x);
		t->pot_v[j] =
		    point_value(&ax->acc[j], a->step_counts, &enc_off);
		if (j > 0 &&
		    re_cal_check_point(&a->check, i, j, a->step_counts,
				       prev_enc, x + enc_off, t->pot_v[j - 1],
				       t->pot_v[j], f) == RE_FAULT)
			return RE_FAULT;
		prev_enc = x + enc_off;
	}
	return re_cal_check_table(&a->check, i, t, f) == RE_FAULT ? RE_FAULT
								  : GL_OK;
}

/* ---- to the centre, checking the pot against the tables --------------------
 */

static int check_encpot(struct re_calib *c, const struct re_calib_cfg *cfg,
			const struct re_calset *set, struct re_fault *f)
{
	for (int i = 0; i < cfg->n_axes; i++) {
		struct re_encpot_result r;
		double enc = enc_of(c, i), pot = pot_of(c, cfg, i);

		if (re_check_encpot(&set->axis[i], &cfg->axis[i].encpot, i, enc,
				    pot, &c->encpot[i], &r, f) != RE_FAULT)
			continue;
		return abort_axis(f, i,
				  "potentiometer %.3f V at encoder %.0f,"
				  " table expects %.3f V +- %.3f V",
				  pot, enc, r.exp.pot_v, r.tol_v);
	}
	return GL_OK;
}

static int all_stopped(const struct re_calib *c, int n)
{
	for (int i = 0; i < n; i++)
		if (moving(c, i))
			return 0;
	return 1;
}

static int to_centre(struct re_calib *c, const struct re_io *io,
		     const struct re_calib_cfg *cfg,
		     const struct re_calset *set, struct re_fault *f)
{
	int64_t deadline = now_ns(io) + cfg->move_timeout_ms * NS_PER_MS;
	long tgt[RE_AXES];
	int rc;

	for (int i = 0; i < RE_AXES; i++)
		tgt[i] =
		    lround((set->axis[i].soft_rev + set->axis[i].soft_fwd) / 2);
	memset(c->encpot, 0, sizeof(c->encpot));
	rc = sendf(c, io, cfg, f, "SP %d,%d,%d;PA %ld,%ld,%ld;BG ABC",
		   cfg->axis[0].vmax_cps, cfg->axis[1].vmax_cps,
		   cfg->axis[2].vmax_cps, tgt[0], tgt[1], tgt[2]);
	do {
		if (rc == GL_OK)
			rc = sample(c, io, cfg, f);
		if (rc == GL_OK)
			rc = check_encpot(c, cfg, set, f);
		if (rc == GL_OK && all_stopped(c, cfg->n_axes))
			return GL_OK;
	} while (rc == GL_OK && now_ns(io) < deadline);
	if (rc != GL_OK)
		return rc;
	return abort_axis(f, -1,
			  "the move to the centre did not end within "
			  "%d ms",
			  cfg->move_timeout_ms);
}

/* ---- the procedures --------------------------------------------------------
 */

static int sweep_all(struct re_calib *c, const struct re_io *io,
		     const struct re_calib_cfg *cfg, struct re_fault *f)
{
	int rc, done;

	do {
		rc = sample(c, io, cfg, f);
		done = 1;
		for (int i = 0; rc == GL_OK && i < cfg->n_axes; i++) {
			rc = axis_step(c, io, cfg, i, f);
			done &= c->ax[i].ph == PH_DONE;
		}
	} while (rc == GL_OK && !done);
	return rc;
}

int re_calib_full(struct re_calib *c, const struct re_io *io,
		  const struct re_calib_cfg *cfg, struct re_calset *set,
		  struct re_fault *fault, double *seconds)
{
	int rc;

	if (!c || !io || !cfg || !set || cfg->n_axes != RE_AXES)
		return GL_ERR_ARG;
	memset(set, 0, sizeof(*set));
	for (int i = 0; i < RE_AXES; i++)
		enter(c, io, i, PH_START);
	c->t0_ns = c->next_ns = now_ns(io);
	rc = sendf(c, io, cfg, fault, "SH ABC");
	if (rc == GL_OK)
		rc = sweep_all(c, io, cfg, fault);
	for (int i = 0; rc == GL_OK && i < RE_AXES; i++)
		rc = build_table(c, cfg, i, &set->axis[i], fault);
	set->n_axes = RE_AXES;
	for (int i = 0; i < RE_AXES; i++)
		snprintf(set->name[i], sizeof(set->name[i]), "%s",
			 cfg->names[i]);
	if (rc == GL_OK)
		rc = to_centre(c, io, cfg, set, fault);
	if (seconds)
		*seconds = (double)(now_ns(io) - c->t0_ns) / 1e9;
	if (rc != GL_OK)
		memset(set, 0, sizeof(*set));
	return rc;
}

/* The robot where the loaded tables say: every axis inside its table and
 * the potentiometer within the run-time tolerance. */
static int check_position(struct re_calib *c, const struct re_calib_cfg *cfg,
			  const struct re_calset *set, struct re_fault *f)
{
	for (int i = 0; i < cfg->n_axes; i++) {
		struct re_encpot_state st = {0};
		struct re_encpot_result r;
		const struct re_caltable *t = &set->axis[i];
		double enc = enc_of(c, i), pot = pot_of(c, cfg, i);
		struct re_encpot_cfg once = cfg->axis[i].encpot;

		once.persistence_cycles = 0;
		if (re_check_encpot(t, &once, i, enc, pot, &st, &r, f) !=
		    RE_FAULT)
			continue;
		if (r.exp.where == RE_TPOS_OUTSIDE)
			return abort_axis(f, i,
					  "encoder %.0f is outside the "
					  "file's travel %.0f..%.0f (encoder "
					  "origin lost?)",
					  enc, t->soft_rev, t->soft_fwd);
		return abort_axis(f, i,
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

	if (!c || !io || !cfg || !set || set->n_axes != cfg->n_axes)
		return GL_ERR_ARG;
	c->t0_ns = c->next_ns = now_ns(io);
	rc = sample_x(c, io, cfg, 0, fault);
	if (rc == GL_OK)
		rc = check_position(c, cfg, set, fault);
	if (rc == GL_OK)
		rc = sendf(c, io, cfg, fault, "SH ABC");
	if (rc == GL_OK)
		rc = to_centre(c, io, cfg, set, fault);
	return rc;
}
