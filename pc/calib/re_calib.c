/*
 * re_calib.c - full calibration (all axes at once, continuous sweep, every
 * move a supervised service move) and the check of tables loaded from a
 * file. See re_calib.h.
 */
#include "re_calib.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"
#include "re_pot.h"

#define AXES	  "ABC"
#define ACFACT	  10  /* dmc/constants.dmc: DC = 10 x speed */
#define GUARD_CNT 200 /* extra counts before a slow zone */
/* What one more stop and start costs a move: the braking and the
 * acceleration (1 / ACFACT s each, half of it lost against the full
 * speed) and up to three samples before the next move runs. */
#define RESTART_MS (1000 / ACFACT + 3 * RE_CALIB_SAMPLE_MS)

enum phase {
	PH_START,    /* nothing sent yet */
	PH_FAST_REV, /* fast toward the reverse switch, short of its zone */
	PH_TO_REV,   /* slowly onto the reverse switch */
	PH_BACK_REV, /* backing off it: then table point 0 */
	PH_SWEEP,    /* sweeping forward at vmax, short of the fwd zone */
	PH_SLOW_FWD, /* still sweeping, slowly onto the forward switch */
	PH_BACK_FWD, /* backing off it: the forward soft limit */
	PH_DONE,
	PH_CHECK,  /* a loaded file checked against the robot */
	PH_CENTRE, /* to the centre of the new (or loaded) table */
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
	int off_rev;  /* the sweep passed start with the switch open */
	int off_fwd;  /* the axis passed soft_fwd with that switch open */
	double soft_fwd;
	double seek_len; /* length of the bounded slow move, counts */
	double centre;	 /* PH_CENTRE: the target, counts */
	struct acc acc[RE_CAL_MAX_POINTS];
};

/* The moves requested in one sample, sent together. */
struct batch {
	unsigned mask;
	long tgt[RE_AXES];
	int sp[RE_AXES];
};

struct re_calib {
	struct cal_axis ax[RE_AXES];
	const struct gl_record *rec;
	struct re_encpot_state encpot[RE_AXES];
	struct batch b;	    /* queued, not sent yet */
	unsigned pending;   /* sent, not taken yet (mvreq still 1) */
	unsigned taken_now; /* taken after this sample's record was read:
			       that record does not show the move yet */
	int64_t sent_ns;
	int64_t t0_ns;
	int running; /* a procedure runs (for re_calib_progress()) */
	int full;
	int filled;
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

static int64_t now_ns(const struct re_io *io)
{
	return io->ops->now_ns(io->ud);
}

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
	if (rc == GL_ERR_TIMEOUT) {
		/* no reply within the command's deadline: the same cause as a
		 * record without reply in the cycle (a stalled link), named
		 * the same way */
		re_fault_set(f, RE_F_WDOG_REPLY, -1);
		f->i[0] = cfg->cmd_timeout_ms;
		f->i[1] = cfg->cmd_timeout_ms;
		return RE_FAULT;
	}
	return rc < 0 ? comm_fault(f, "command failed", rc) : GL_OK;
}

/* The next supervised sample. A fault the sampler latched is passed on
 * as RE_F_NONE (the supervisor reacted to it already). */
static int sample(struct re_calib *c, const struct re_calib_cfg *cfg,
		  struct re_fault *f)
{
	int rc;

	if (cfg->stop && *cfg->stop)
		return GL_ERR_AGAIN;
	c->taken_now = 0; /* this record follows every acceptance so far */
	rc = cfg->sampler.sample(cfg->sampler.ud, &c->rec);
	if (rc == RE_FAULT)
		re_fault_set(f, RE_F_NONE, -1);
	else if (rc == GL_OK && c->rec->n_axes < cfg->n_axes)
		return comm_fault(f, "data record", GL_ERR_RECORD);
	return rc;
}

static double enc_of(const struct re_calib *c, int i)
{
	return c->rec->axis[i].motor_pos;
}

static double pot_of(const struct re_calib *c, const struct re_calib_cfg *cfg,
		     int i)
{
	return re_pot_of(c->rec, i, cfg->axis[i].pot_input);
}

static int moving(const struct re_calib *c, int i)
{
	return !!(c->rec->axis[i].status & GL_AXST_MOVING);
}

static int rev_switch(const struct re_calib *c, int i)
{
	return !(c->rec->axis[i].switches & GL_AXSW_RLS);
}

static int fwd_switch(const struct re_calib *c, int i)
{
	return !(c->rec->axis[i].switches & GL_AXSW_FLS);
}

/* ---- service moves -------------------------------------------------------
 */

/* Queue a move of axis i to @target at @speed (sent by send_batch()). */
static void move_to(struct re_calib *c, int i, double target, int speed)
{
	c->b.mask |= 1u << i;
	c->b.tgt[i] = lround(target);
	c->b.sp[i] = speed;
}

static int append(char *line, size_t cap, const char *item)
{
	if (strlen(line) + strlen(item) + 1 > cap - 1)
		return -1;
	if (line[0])
		strcat(line, ";");
	strcat(line, item);
	return 0;
}

/* Send the queued moves: the targets and speeds, then the request. The
 * program takes it in its next pass (mvreq back to 0); taken() asks at
 * every following sample, so the cycle stays periodic meanwhile. */
static int send_batch(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, struct re_fault *f)
{
	char item[48];
	int rc = GL_OK;

	if (!c->b.mask || c->pending)
		return GL_OK;
	c->line[0] = '\0';
	for (int i = 0; rc == GL_OK && i < RE_AXES; i++) {
		if (!(c->b.mask >> i & 1))
			continue;
		snprintf(item, sizeof(item), "mvtg[%d]=%ld;mvsp[%d]=%d", i,
			 c->b.tgt[i], i, c->b.sp[i]);
		if (append(c->line, sizeof(c->line), item) < 0) {
			rc = send(c, io, cfg, f);
			snprintf(c->line, sizeof(c->line), "%s", item);
		}
	}
	if (rc == GL_OK && c->line[0])
		rc = send(c, io, cfg, f);
	snprintf(c->line, sizeof(c->line),
		 "mvax[0]=%u;mvax[1]=%u;mvax[2]=%u;"
		 "mvreq=1",
		 c->b.mask & 1, c->b.mask >> 1 & 1, c->b.mask >> 2 & 1);
	if (rc == GL_OK)
		rc = send(c, io, cfg, f);
	c->pending = c->b.mask;
	c->sent_ns = now_ns(io);
	c->b.mask = 0;
	return rc;
}

/* Is the sent request taken? A refused one is a fault the program
 * latched: the supervisor's next sample reports it. */
static int taken(struct re_calib *c, const struct re_io *io,
		 const struct re_calib_cfg *cfg, struct re_fault *f)
{
	double req = 1;
	int rc;

	if (!c->pending)
		return GL_OK;
	rc = re_io_read(io, "mvreq", &req, cfg->cmd_timeout_ms);
	if (rc < 0)
		return comm_fault(f, "move request", rc);
	if (req == 0) {
		c->taken_now = c->pending;
		c->pending = 0;
		return GL_OK;
	}
	if (now_ns(io) - c->sent_ns > (int64_t)cfg->accept_ms * BASE_NS_PER_MS)
		return abort_axis(f, -1,
				  "the controller program did not take a move "
				  "request within %d ms",
				  cfg->accept_ms);
	return GL_OK;
}

/* An axis with a move queued, not yet taken, or taken only after the
 * record in hand was read: that record does not show the move, so its
 * phase must not judge it (it would see "stopped" before the start). */
static int waiting(const struct re_calib *c, int i)
{
	return ((c->b.mask | c->pending | c->taken_now) >> i) & 1;
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

/* What a fast move at @speed keeps before the slow zone it heads for:
 * its braking distance (AC = DC = ACFACT x speed: speed / (2 ACFACT)),
 * two samples at that speed and a guard for the pot's noise, counts. */
static double brake_counts(int speed)
{
	return speed / (2.0 * ACFACT) + speed * 0.02 + GUARD_CNT;
}

/* How far the axis can run at @speed before its pot reaches @zone_v:
 * from the pot's absolute reading, with the gain overestimated by the
 * range tolerance (the move ends early, never late), less brake_counts().
 * <= 0: already too close. The shortfall is range_tol of the distance:
 * a further fast move (fast_worth()) takes most of what is left. */
static double fast_len(const struct re_calib_axis_cfg *a, double pot,
		       double zone_v, int speed)
{
	double gain_hi = a->gain_v * (1 + a->check.range_tol);

	return fabs(pot - zone_v) / gain_hi - brake_counts(speed);
}

/* Is a fast move of @len counts at @fast worth making rather than going
 * on at @slow? The first one always is when there is room (the slow move
 * after it is bounded in length); a further one only when it saves more
 * than the extra stop and start cost (RESTART_MS). */
static int fast_worth(double len, int fast, int slow, int first)
{
	if (len <= 0)
		return 0;
	if (first && fast <= slow)
		return 1;
	return fast > slow && len / slow - len / fast > RESTART_MS / 1000.0;
}

/* The bounded slow move onto a switch: to the far side of where it can
 * be (the pot's lowest/highest possible reading), plus two back-offs. */
static double seek_len(const struct re_calib_axis_cfg *a, double pot,
		       double end_v)
{
	double gain_lo = a->gain_v * (1 - a->check.range_tol);

	return fabs(pot - end_v) / gain_lo + 2.0 * a->backoff_counts;
}

static int start_seek_rev(struct re_calib *c, const struct re_io *io,
			  const struct re_calib_cfg *cfg, int i)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	double pot = pot_of(c, cfg, i);

	c->ax[i].seek_len = seek_len(a, pot, a->potlo_v);
	move_to(c, i, enc_of(c, i) - c->ax[i].seek_len, a->seek_cps);
	return enter(c, io, i, PH_TO_REV);
}

static int step_start(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	double pot = pot_of(c, cfg, i), len;

	if (rev_switch(c, i)) { /* already on it: just back off */
		move_to(c, i, enc_of(c, i) + a->backoff_counts, a->travel_cps);
		return enter(c, io, i, PH_BACK_REV);
	}
	len = pot > a->pnlo_v ? fast_len(a, pot, a->pnlo_v, a->travel_cps) : 0;
	if (!fast_worth(len, a->travel_cps, a->seek_cps, 1))
		return start_seek_rev(c, io, cfg, i);
	move_to(c, i, enc_of(c, i) - len, a->travel_cps);
	return enter(c, io, i, PH_FAST_REV);
}

static int stopped_badly(const struct re_calib *c, int i, const char *where,
			 struct re_fault *f)
{
	int sc = c->rec->axis[i].stop_code;

	return abort_axis(f, i,
			  "stopped before the %s: %s (stop code %d, "
			  "encoder %.0f)",
			  where, re_stop_reason(sc), sc, enc_of(c, i));
}

/* A fast move toward the reverse switch ended short of its slow zone:
 * another one while what is left is worth it (the gain is known only
 * within the range tolerance, so each ends early by that fraction), then
 * the slow seek. */
static int step_fast_rev(struct re_calib *c, const struct re_io *io,
			 const struct re_calib_cfg *cfg, int i,
			 struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	double pot = pot_of(c, cfg, i), len;

	if (moving(c, i))
		return GL_OK;
	if (rev_switch(c, i)) /* the switch came early: fine, it is there */
		return enter(c, io, i, PH_TO_REV);
	if (c->rec->axis[i].stop_code != 1)
		return stopped_badly(c, i, "slow zone of the reverse switch",
				     f);
	len = pot > a->pnlo_v ? fast_len(a, pot, a->pnlo_v, a->travel_cps) : 0;
	if (!fast_worth(len, a->travel_cps, a->seek_cps, 0))
		return start_seek_rev(c, io, cfg, i);
	move_to(c, i, enc_of(c, i) - len, a->travel_cps);
	return enter(c, io, i, PH_FAST_REV);
}

/* At a switch the potentiometer must read what it reads there on this
 * robot (reverse_v / forward_v +- absolute_tolerance_v): an offset, a
 * wrong pot or its wiring, named at once rather than by the table. */
static int check_at_switch(const struct re_calib *c,
			   const struct re_calib_cfg *cfg, int i, int fwd,
			   struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	double shift = a->backoff_counts * a->gain_v;
	double want =
	    fwd ? a->check.abs_last_v + shift : a->check.abs_first_v - shift;
	double pot = pot_of(c, cfg, i);

	if (!(a->check.abs_tol_v > 0) || fabs(pot - want) <= a->check.abs_tol_v)
		return GL_OK;
	re_fault_set(f, RE_F_CAL_ABSOLUTE, i);
	snprintf(f->s, sizeof(f->s), "%s", fwd ? "forward" : "reverse");
	f->f[0] = pot;
	f->f[1] = want;
	f->f[2] = a->check.abs_tol_v;
	return RE_FAULT;
}

/* The sweep from where the axis is, with table point 0 at @start: at
 * vmax to short of the forward slow zone, or slowly onto the switch when
 * that is too close for a fast move. */
static int begin_sweep(struct re_calib *c, const struct re_io *io,
		       const struct re_calib_cfg *cfg, int i, double start)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	struct cal_axis *ax = &c->ax[i];
	double pot = pot_of(c, cfg, i), len;

	ax->start = start;
	ax->off_rev = enc_of(c, i) >= start && !rev_switch(c, i);
	memset(ax->acc, 0, sizeof(ax->acc));
	len = fast_len(a, pot, a->pnhi_v, a->vmax_cps);
	if (!fast_worth(len, a->vmax_cps, a->seek_cps, 1)) {
		ax->seek_len = seek_len(a, pot, a->pothi_v);
		move_to(c, i, enc_of(c, i) + ax->seek_len, a->seek_cps);
		return enter(c, io, i, PH_SLOW_FWD);
	}
	move_to(c, i, enc_of(c, i) + len, a->vmax_cps);
	return enter(c, io, i, PH_SWEEP);
}

static int step_to_rev(struct re_calib *c, const struct re_io *io,
		       const struct re_calib_cfg *cfg, int i,
		       struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];

	note_edge(c, i, rev_switch(c, i));
	if (moving(c, i))
		return GL_OK;
	if (c->rec->axis[i].stop_code == 1 && !rev_switch(c, i))
		return abort_axis(f, i,
				  "the reverse limit switch never came "
				  "within %.0f counts (potentiometer %.3f V)",
				  c->ax[i].seek_len, pot_of(c, cfg, i));
	if (!rev_switch(c, i))
		return stopped_badly(c, i, "reverse limit switch", f);
	if (check_at_switch(c, cfg, i, 0, f) == RE_FAULT)
		return RE_FAULT;
	/* the back-off is the start of the sweep: point 0 and the reverse
	 * soft limit are the back-off from where the switch was first seen,
	 * and the switch must be open there (sweep_sample()) */
	return begin_sweep(c, io, cfg, i, c->ax[i].edge + a->backoff_counts);
}

/* Only when the axis was already on the reverse switch at the start (its
 * edge unknown): backed off from there, point 0 where it came to rest. */
static int step_back_rev(struct re_calib *c, const struct re_io *io,
			 const struct re_calib_cfg *cfg, int i,
			 struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];

	if (moving(c, i))
		return GL_OK;
	if (rev_switch(c, i))
		return abort_axis(f, i,
				  "still on the reverse limit switch "
				  "after backing off %d counts",
				  a->backoff_counts);
	if (c->rec->axis[i].stop_code != 1)
		return stopped_badly(c, i, "end of the back-off", f);
	return begin_sweep(c, io, cfg, i, enc_of(c, i));
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

/* One sample of the sweep: into the table, and the first one at or past
 * point 0 (the back-off from the reverse switch's edge) must show that
 * switch open. */
static int sweep_sample(struct re_calib *c, const struct re_calib_cfg *cfg,
			int i, struct re_fault *f)
{
	struct cal_axis *ax = &c->ax[i];

	accumulate(c, cfg, i);
	if (ax->off_rev || enc_of(c, i) < ax->start)
		return GL_OK;
	if (rev_switch(c, i))
		return abort_axis(f, i,
				  "still on the reverse limit switch "
				  "after backing off %d counts",
				  cfg->axis[i].backoff_counts);
	ax->off_rev = 1;
	return GL_OK;
}

/* A sweep move ended short of the forward slow zone: another one at vmax
 * while what is left is worth it (as step_fast_rev()), then slowly on. */
static int step_sweep(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	struct cal_axis *ax = &c->ax[i];
	double pot, len;

	if (sweep_sample(c, cfg, i, f) == RE_FAULT)
		return RE_FAULT;
	if (moving(c, i))
		return GL_OK;
	if (fwd_switch(c, i))
		return enter(c, io, i, PH_SLOW_FWD);
	if (c->rec->axis[i].stop_code != 1)
		return stopped_badly(c, i, "slow zone of the forward switch",
				     f);
	pot = pot_of(c, cfg, i);
	len = pot < a->pnhi_v ? fast_len(a, pot, a->pnhi_v, a->vmax_cps) : 0;
	if (fast_worth(len, a->vmax_cps, a->seek_cps, 0)) {
		move_to(c, i, enc_of(c, i) + len, a->vmax_cps);
		return enter(c, io, i, PH_SWEEP);
	}
	ax->seek_len = seek_len(a, pot, a->pothi_v);
	move_to(c, i, enc_of(c, i) + ax->seek_len, a->seek_cps);
	return enter(c, io, i, PH_SLOW_FWD);
}

/* How far the encoder check reaches past the table build_table() will
 * make from start to soft_fwd: its last point and RE_CAL_EXTRAP_STEPS
 * more (less a tenth of a step), counts. */
static double table_reach(const struct cal_axis *ax,
			  const struct re_calib_axis_cfg *a)
{
	double last = floor((ax->soft_fwd - ax->start) / a->step_counts);

	return ax->start + (last + RE_CAL_EXTRAP_STEPS - 0.1) * a->step_counts;
}

static int step_slow_fwd(struct re_calib *c, const struct re_io *io,
			 const struct re_calib_cfg *cfg, int i,
			 struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];

	if (sweep_sample(c, cfg, i, f) == RE_FAULT)
		return RE_FAULT;
	note_edge(c, i, fwd_switch(c, i));
	if (moving(c, i))
		return GL_OK;
	if (c->rec->axis[i].stop_code == 1 && !fwd_switch(c, i))
		return abort_axis(f, i,
				  "the forward limit switch never came "
				  "within %.0f counts (potentiometer %.3f V)",
				  c->ax[i].seek_len, pot_of(c, cfg, i));
	if (!fwd_switch(c, i))
		return stopped_badly(c, i, "forward limit switch", f);
	if (check_at_switch(c, cfg, i, 1, f) == RE_FAULT)
		return RE_FAULT;
	/* the forward soft limit: the back-off from the switch's edge. When
	 * the axis rests where the new table still reaches (table_reach()),
	 * the back-off is the start of the move to the centre (to_centre()
	 * checks the switch open there); else a move of its own, away from
	 * the switch at the travel speed */
	c->ax[i].soft_fwd = c->ax[i].edge - a->backoff_counts;
	if (enc_of(c, i) < table_reach(&c->ax[i], a)) {
		c->ax[i].off_fwd = 0;
		return enter(c, io, i, PH_DONE);
	}
	move_to(c, i, c->ax[i].soft_fwd, a->travel_cps);
	return enter(c, io, i, PH_BACK_FWD);
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
	if (c->rec->axis[i].stop_code != 1)
		return stopped_badly(c, i, "end of the back-off", f);
	c->ax[i].soft_fwd = enc_of(c, i);
	c->ax[i].off_fwd = 1;
	return enter(c, io, i, PH_DONE);
}

static int axis_step(struct re_calib *c, const struct re_io *io,
		     const struct re_calib_cfg *cfg, int i, struct re_fault *f)
{
	int64_t age = now_ns(io) - c->ax[i].t_phase_ns;

	if (c->ax[i].ph != PH_START && c->ax[i].ph != PH_DONE &&
	    age > (int64_t)cfg->move_timeout_ms * BASE_NS_PER_MS)
		return abort_axis(f, i,
				  "a calibration move did not end "
				  "within %d ms (encoder %.0f)",
				  cfg->move_timeout_ms, enc_of(c, i));
	if (waiting(c, i)) {
		if (c->ax[i].ph == PH_SWEEP || c->ax[i].ph == PH_SLOW_FWD)
			return sweep_sample(c, cfg, i, f);
		return GL_OK;
	}
	switch (c->ax[i].ph) {
	case PH_START: return step_start(c, io, cfg, i);
	case PH_FAST_REV: return step_fast_rev(c, io, cfg, i, f);
	case PH_TO_REV: return step_to_rev(c, io, cfg, i, f);
	case PH_BACK_REV: return step_back_rev(c, io, cfg, i, f);
	case PH_SWEEP: return step_sweep(c, io, cfg, i, f);
	case PH_SLOW_FWD: return step_slow_fwd(c, io, cfg, i, f);
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

/* @a's sums with every dx shifted by @d. */
static void acc_add_shifted(struct acc *out, const struct acc *a, double d)
{
	out->n += a->n;
	out->sx += a->sx + a->n * d;
	out->sy += a->sy;
	out->sxx += a->sxx + 2 * d * a->sx + a->n * d * d;
	out->sxy += a->sxy + d * a->sy;
}

/* Samples that do not spread over a point's window (fewer than 3, or all
 * near one edge: the PC stalled) cannot give its value at the point. */
static int sparse(const struct acc *a, double step)
{
	double mx, var;

	if (a->n < 3)
		return 1;
	mx = a->sx / a->n;
	var = a->sxx / a->n - mx * mx;
	return var < (step / 8) * (step / 8);
}

/* A point whose samples are sparse or missing (the PC stalled up to one
 * step): the line through its own and both neighbours' samples, when
 * both neighbours have some. */
static int fill_point(const struct cal_axis *ax, int j, int n, double step,
		      struct acc *out)
{
	memset(out, 0, sizeof(*out));
	if (j < 1 || j + 1 >= n || !ax->acc[j - 1].n || !ax->acc[j + 1].n)
		return -1;
	acc_add_shifted(out, &ax->acc[j - 1], -step);
	acc_add_shifted(out, &ax->acc[j], 0);
	acc_add_shifted(out, &ax->acc[j + 1], step);
	return 0;
}

static int build_table(struct re_calib *c, const struct re_calib_cfg *cfg,
		       int i, struct re_caltable *t, struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	struct cal_axis *ax = &c->ax[i];
	double prev_enc = 0, enc_off;
	long n = lround(floor((ax->soft_fwd - ax->start) / a->step_counts)) + 1;
	struct acc filled;

	memset(t, 0, sizeof(*t));
	t->n = n > RE_CAL_MAX_POINTS ? RE_CAL_MAX_POINTS : (int)n;
	t->start_counts = ax->start;
	t->step_counts = a->step_counts;
	t->soft_rev = ax->start;
	t->soft_fwd = ax->soft_fwd;
	for (int j = 0; j < t->n; j++) {
		const struct acc *s = &ax->acc[j];
		double x = ax->start + (double)j * a->step_counts;

		if (sparse(s, a->step_counts) &&
		    fill_point(ax, j, t->n, a->step_counts, &filled) == 0) {
			s = &filled;
			c->filled++;
		} else if (s->n == 0) {
			return abort_axis(f, i,
					  "no potentiometer sample near point "
					  "%d (encoder %.0f)",
					  j, x);
		}
		t->pot_v[j] = point_value(s, a->step_counts, &enc_off);
		if (s == &filled)
			enc_off = 0; /* the line is read at the point itself */
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

static int all_stopped(const struct re_calib *c, int n)
{
	for (int i = 0; i < n; i++)
		if (moving(c, i))
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

		if (ax->off_fwd || enc_of(c, i) > set->axis[i].soft_fwd)
			continue;
		if (fwd_switch(c, i))
			return abort_axis(f, i,
					  "still on the forward limit switch "
					  "after backing off %d counts",
					  cfg->axis[i].backoff_counts);
		ax->off_fwd = 1;
	}
	return GL_OK;
}

/* Every axis to the centre of its soft limits at the travel speed; the
 * supervisor checks the encoders against @set on every sample. */
static int to_centre(struct re_calib *c, const struct re_io *io,
		     const struct re_calib_cfg *cfg,
		     const struct re_calset *set, struct re_fault *f)
{
	int64_t deadline = now_ns(io) + cfg->move_timeout_ms * BASE_NS_PER_MS;
	int rc;

	for (int i = 0; i < RE_AXES; i++) {
		c->ax[i].centre =
		    (set->axis[i].soft_rev + set->axis[i].soft_fwd) / 2;
		move_to(c, i, c->ax[i].centre, cfg->axis[i].travel_cps);
		enter(c, io, i, PH_CENTRE);
	}
	rc = send_batch(c, io, cfg, f);
	do {
		if (rc == GL_OK)
			rc = sample(c, cfg, f);
		if (rc == GL_OK)
			rc = taken(c, io, cfg, f);
		if (rc == GL_OK)
			rc = off_fwd_check(c, cfg, set, f);
		if (rc == GL_OK && !c->pending && !c->taken_now &&
		    all_stopped(c, cfg->n_axes))
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
		rc = sample(c, cfg, f);
		if (rc == GL_OK)
			rc = taken(c, io, cfg, f);
		done = !c->pending && !c->taken_now && !c->b.mask;
		for (int i = 0; rc == GL_OK && i < cfg->n_axes; i++) {
			rc = axis_step(c, io, cfg, i, f);
			done &= c->ax[i].ph == PH_DONE;
		}
		if (rc == GL_OK)
			rc = send_batch(c, io, cfg, f);
	} while (rc == GL_OK && !done);
	return rc;
}

static void own(const struct re_calib_cfg *cfg, unsigned mask)
{
	if (cfg->sampler.own)
		cfg->sampler.own(cfg->sampler.ud, mask);
}

static void use_tables(const struct re_calib_cfg *cfg,
		       const struct re_calset *set)
{
	if (cfg->sampler.tables)
		cfg->sampler.tables(cfg->sampler.ud, set);
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
		enter(c, io, i, PH_START);
	c->t0_ns = now_ns(io);
	c->running = 1;
	c->full = 1;
	own(cfg, 7);
	rc = sweep_all(c, io, cfg, fault);
	for (int i = 0; rc == GL_OK && i < RE_AXES; i++)
		rc = build_table(c, cfg, i, &set->axis[i], fault);
	set->n_axes = RE_AXES;
	for (int i = 0; i < RE_AXES; i++)
		snprintf(set->name[i], sizeof(set->name[i]), "%s",
			 cfg->names[i]);
	if (rc == GL_OK) {
		use_tables(cfg, set);
		rc = to_centre(c, io, cfg, set, fault);
	}
	own(cfg, 0);
	c->running = 0;
	if (seconds)
		*seconds = (double)(now_ns(io) - c->t0_ns) / 1e9;
	if (filled)
		*filled = c->filled;
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
		int v;

		once.persistence_cycles = 0;
		v = re_check_encpot(t, &once, i, enc, pot, &st, &r, f);
		if (v == RE_OK)
			continue;
		if (v < 0)
			return abort_axis(f, i,
					  "the table cannot be used "
					  "(%s)",
					  gl_strerror(v));
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

	if (!c || !io || !cfg || !set || set->n_axes != cfg->n_axes ||
	    !cfg->sampler.sample)
		return GL_ERR_ARG;
	memset(&c->b, 0, sizeof(c->b));
	c->pending = 0;
	c->taken_now = 0;
	c->t0_ns = now_ns(io);
	c->running = 1;
	c->full = 0;
	for (int i = 0; i < RE_AXES; i++) {
		enter(c, io, i, PH_CHECK);
		c->ax[i].off_fwd = 1; /* not at a switch: nothing to check */
	}
	rc = sample(c, cfg, fault);
	if (rc == GL_OK)
		rc = check_position(c, cfg, set, fault);
	own(cfg, 7);
	if (rc == GL_OK)
		use_tables(cfg, set);
	if (rc == GL_OK)
		rc = to_centre(c, io, cfg, set, fault);
	own(cfg, 0);
	c->running = 0;
	return rc;
}

/* ---- progress, for the console ----------------------------------------- */

static const char *const phase_names[] = {
    [PH_START] = "starting",	      [PH_FAST_REV] = "to rev switch",
    [PH_TO_REV] = "onto rev switch",  [PH_BACK_REV] = "off rev switch",
    [PH_SWEEP] = "sweep fwd",	      [PH_SLOW_FWD] = "onto fwd switch",
    [PH_BACK_FWD] = "off fwd switch", [PH_DONE] = "table built",
    [PH_CHECK] = "checking file",     [PH_CENTRE] = "to centre",
};

/* The pot at the reverse and forward switches, and the lengths run
 * slowly before each, counts: the slow zone and what the fast moves keep
 * before it (brake_counts()). */
struct span {
	double rev_v, fwd_v, zone_rev, zone_fwd;
};

static struct span span_of(const struct re_calib_axis_cfg *a)
{
	struct span sp;
	double g = a->gain_v > 0 ? a->gain_v : 1;

	sp.rev_v = a->check.abs_first_v - a->backoff_counts * a->gain_v;
	sp.fwd_v = a->check.abs_last_v + a->backoff_counts * a->gain_v;
	sp.zone_rev =
	    fmax(0, (a->pnlo_v - sp.rev_v) / g) + brake_counts(a->travel_cps);
	sp.zone_fwd =
	    fmax(0, (sp.fwd_v - a->pnhi_v) / g) + brake_counts(a->vmax_cps);
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
