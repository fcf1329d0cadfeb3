/*
 * ctrl_motion.c - per-sample motion: feedback, protection (amplifier,
 * position error / OE, encoder failure / OA, hardware and soft limits), the
 * trapezoidal profiler (PA, PR, PT, JG, ST) and the servo output.
 *
 * Profiler: each sample the reference moves at a velocity that rises by
 * AC*dt towards SP (JG: the jog speed), and is limited to sqrt(2*DC*d) so
 * the axis decelerates at DC onto the target d counts away. A target
 * reached in the sample is taken exactly. ST decelerates at DC, a limit at
 * SD, AB stops the reference at once.
 *
 * Servo model (docs/galil-sim-controller.md): with e = RP - TP in counts,
 * torque = (4*KP*e + 4*KD*(e - e_prev) + KI/2 * sum(e)) * 10/32768 + OF
 * volts, limited to +-TL (the integrator's part to +-IL; the sum leaks
 * with a 100-sample time constant: the robot model has no load). Motor
 * off: the reference follows the encoder and the torque is 0.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ctrl_motion.h"
#include "ctrl_out.h"
#include "ctrl_thread.h"

#define DAC_V_PER_COUNT (10.0 / 32768.0)
#define CTRL_KI_LEAK	100.0 /* integrator leak time constant, samples */

double ctrl_dt(const struct ctrl *c)
{
	return c->sample_us / 1e6;
}

static char axis_name(int i)
{
	return (char)('A' + i);
}

/* ctrl_axis_tv() - _TV: velocity over the last CTRL_TV_SAMPLES samples. */
double ctrl_axis_tv(const struct ctrl_axis *a, double dt)
{
	double oldest = a->tv_ring[a->tv_i];
	double newest =
	    a->tv_ring[(a->tv_i + CTRL_TV_SAMPLES - 1) % CTRL_TV_SAMPLES];

	return (newest - oldest) / ((CTRL_TV_SAMPLES - 1) * dt);
}

/* Is motion in direction @dir refused by a switch or a soft limit? */
int ctrl_blocked_dir(const struct ctrl_axis *a, int dir)
{
	if (dir > 0)
		return a->lim_f || a->ref > a->p.fl;
	if (dir < 0)
		return a->lim_r || a->ref < a->p.bl;
	return 0;
}

static int sign(double v)
{
	return (v > 0) - (v < 0);
}

/* Direction the profiler is driving the axis: -1, 0 or 1. */
static int motion_dir(const struct ctrl_axis *a)
{
	if (a->vel != 0)
		return sign(a->vel);
	if (!a->profiling)
		return 0;
	if (a->mode == CTRL_MODE_JG)
		return sign(a->jg);
	return sign(a->target - a->ref);
}

/* ---- commands from the interpreter -------------------------------- */

/*
 * ctrl_motion_begin() - BG for one axis: TC 20 motor off, 21 already
 * moving, 22 a limit in the way, 7 in position tracking mode.
 * @dry_run: only check.
 */
int ctrl_motion_begin(struct ctrl *c, int i, int dry_run)
{
	struct ctrl_axis *a = &c->ax[i];
	double target = a->ref;
	int dir;

	if (a->p.motor_off)
		return 20;
	if (a->profiling)
		return 21;
	if (a->pt)
		return 7;
	if (a->next_mode == CTRL_MODE_PR)
		target = a->ref + a->pr;
	else if (a->next_mode == CTRL_MODE_PA)
		target = a->pa;
	dir =
	    a->next_mode == CTRL_MODE_JG ? sign(a->jg) : sign(target - a->ref);
	if (ctrl_blocked_dir(a, dir))
		return 22;
	if (dry_run)
		return 0;
	a->mode = a->next_mode;
	a->target = target;
	a->profiling = 1;
	a->stopping = 0;
	a->stop_code = 0;
	return 0;
}

/* ctrl_motion_pt_target() - PA in position tracking: retarget on the fly. */
int ctrl_motion_pt_target(struct ctrl *c, int i, double target)
{
	struct ctrl_axis *a = &c->ax[i];

	a->target = target;
	if (!a->profiling && target == a->ref)
		return 0;
	/* UNCONFIRMED: a new target towards an active limit does not move */
	if (!a->profiling && ctrl_blocked_dir(a, sign(target - a->ref)))
		return 0;
	a->mode = CTRL_MODE_PT;
	a->profiling = 1;
	a->stopping = 0;
	a->stop_code = 0;
	return 0;
}

/* ctrl_motion_stop() - decelerate at @dec; stop code @code (ST: 4). */
void ctrl_motion_stop(struct ctrl *c, int i, int code, double dec)
{
	struct ctrl_axis *a = &c->ax[i];

	if (code == 4)
		a->pt = 0; /* ST leaves position tracking */
	if (!a->profiling || a->stopping)
		return;
	a->stopping = 1;
	a->stop_dec = dec;
	a->stop_code = code;
}

/*
 * ctrl_motion_abort() - AB: the reference stops at once (event "axis A
 * abort: AB (@who)"); with OE set the motor goes off. @who: "handle B" ...
 */
void ctrl_motion_abort(struct ctrl *c, int i, const char *who)
{
	struct ctrl_axis *a = &c->ax[i];
	char why[CTRL_WHO_LEN + 32];

	a->pt = 0;
	if (a->profiling) {
		a->profiling = 0;
		a->stopping = 0;
		a->vel = 0;
		a->stop_code = 7;
		a->pa_last = a->ref;
		a->target = a->ref;
		ctrl_event(c, "axis %c abort: AB (%s)", axis_name(i), who);
	}
	if (a->p.oe && !a->p.motor_off) {
		snprintf(why, sizeof(why), "abort with OE set (%s)", who);
		ctrl_motion_off(c, i, -1, why);
	}
}

/*
 * ctrl_motion_off() - motor off; @code: stop code to set if the axis was
 * profiling (-1: keep), @why: for the event.
 */
void ctrl_motion_off(struct ctrl *c, int i, int code, const char *why)
{
	struct ctrl_axis *a = &c->ax[i];

	/* A protection that switches off a servoing axis records its cause
	 * even when the axis was at rest (UNCONFIRMED on a real DMC-4030: the
	 * fail-safe reading, so that the cause of a motor-off is never lost;
	 * docs/galil-sim-controller.md). */
	if (code >= 0 && (a->profiling || !a->p.motor_off))
		a->stop_code = code;
	a->p.motor_off = 1;
	a->profiling = 0;
	a->stopping = 0;
	a->vel = 0;
	a->pa_last = a->ref;
	if (code >= 0)
		ctrl_event(c, "axis %c motor off: %s (stop code %d)",
			   axis_name(i), why, a->stop_code);
	else
		ctrl_event(c, "axis %c motor off: %s", axis_name(i), why);
}

/* ---- feedback -------------------------------------------------------- */

/* ctrl_motion_sense() - take the plant's sample. */
void ctrl_motion_sense(struct ctrl *c, const struct ctrl_sense *in)
{
	int i, f, r;

	c->in = *in;
	for (i = 0; i < CTRL_AXES; i++) {
		struct ctrl_axis *a = &c->ax[i];

		if (c->zero_pending) {
			a->offset = -in->enc[i]; /* TP = 0 at power-up */
			a->ref = a->target = a->pa_last = 0;
			for (f = 0; f < CTRL_TV_SAMPLES; f++)
				a->tv_ring[f] = 0;
		}
		a->enc = in->enc[i] + a->offset;
		f = in->fwd_limit[i] != 0;
		r = in->rev_limit[i] != 0;
		if (c->cn0 == 1) { /* switches configured active high */
			f = !f;
			r = !r;
		}
		a->lim_f = f && !(a->p.ld & 1);
		a->lim_r = r && !(a->p.ld & 2);
	}
	if (c->zero_pending) {
		/* the amplifiers' status at power-up: under-voltage while
		 * motor power is absent, as after a loss */
		c->amp_ok = in->amp_power != 0;
		c->ta0 =
		    c->amp_ok ? (uint8_t)(c->ta0 & ~8) : (uint8_t)(c->ta0 | 8);
	}
	c->zero_pending = 0;
}

/* ---- protection ------------------------------------------------------- */

static void amp_check(struct ctrl *c)
{
	int i, ok = c->in.amp_power != 0;

	if (ok != c->amp_ok) {
		c->amp_ok = ok;
		if (ok)
			c->ta0 &= (uint8_t)~8;
		else
			c->ta0 |= 8; /* under-voltage, axes A-D */
		ctrl_event(c, ok ? "amplifier power restored"
				 : "amplifier power lost (under-voltage)");
	}
	for (i = 0; i < CTRL_AXES; i++) {
		struct ctrl_axis *a = &c->ax[i];

		if (ok || a->p.motor_off) {
			a->amp_fault = 0;
			continue;
		}
		if (a->amp_fault)
			continue;
		a->amp_fault = 1;
		ctrl_autosub_raise(c, CTRL_AS_AMPERR);
		if (a->p.oe)
			ctrl_motion_off(c, i, 15, "amplifier fault");
		else
			ctrl_event(c,
				   "axis %c amplifier fault, OE 0: motor "
				   "stays on",
				   axis_name(i));
	}
}

static void poserr_check(struct ctrl *c, int i)
{
	struct ctrl_axis *a = &c->ax[i];
	double te = fabs(round(a->ref) - round(a->enc));
	char why[96];

	if (a->p.motor_off || a->p.er < 0 || te <= a->p.er) {
		a->poserr = 0;
		return;
	}
	if (a->poserr)
		return;
	a->poserr = 1;
	ctrl_autosub_raise(c, CTRL_AS_POSERR);
	snprintf(why, sizeof(why), "position error %.0f > ER %.0f", te,
		 a->p.er);
	if (a->p.oe & 1)
		ctrl_motion_off(c, i, 8, why);
	else
		ctrl_event(c, "axis %c %s (OE %d: motor stays on)",
			   axis_name(i), why, a->p.oe);
}

/* Encoder failure: torque above OV for OT samples with < 4 counts moved. */
static void oa_check(struct ctrl *c, int i)
{
	struct ctrl_axis *a = &c->ax[i];

	if (a->p.motor_off || !a->p.oa || fabs(a->torque) <= a->p.ov) {
		a->oa_cnt = 0;
		return;
	}
	if (a->oa_cnt == 0)
		a->oa_enc0 = a->enc;
	if (fabs(a->enc - a->oa_enc0) >= 4) {
		a->oa_cnt = 0;
		return;
	}
	if (++a->oa_cnt < a->p.ot)
		return;
	a->oa_cnt = 0;
	ctrl_motion_off(c, i, 12, "encoder failure (OA)");
	ctrl_autosub_raise(c, CTRL_AS_POSERR);
}

static void limit_hit(struct ctrl *c, int i, int code, int hw)
{
	struct ctrl_axis *a = &c->ax[i];
	const char *dir = code == 2 ? "forward" : "reverse";

	ctrl_autosub_raise(c, CTRL_AS_LIMSWI);
	if (hw && (a->p.oe & 2)) {
		ctrl_motion_off(c, i, code,
				hw ? "limit switch with OE 2" : "soft limit");
		return;
	}
	ctrl_motion_stop(c, i, code, a->p.sd);
	ctrl_event(c, "axis %c %s %s (stop code %d)", axis_name(i),
		   hw ? "limit" : "soft limit", dir, code);
}

static void limit_check(struct ctrl *c, int i)
{
	struct ctrl_axis *a = &c->ax[i];
	int dir = motion_dir(a);

	if (!a->profiling || a->stopping)
		return;
	if (dir > 0 && a->lim_f)
		limit_hit(c, i, 2, 1);
	else if (dir < 0 && a->lim_r)
		limit_hit(c, i, 3, 1);
	else if (dir > 0 && a->ref > a->p.fl)
		limit_hit(c, i, 2, 0);
	else if (dir < 0 && a->ref < a->p.bl)
		limit_hit(c, i, 3, 0);
}

/* ---- profiler ----------------------------------------------------------- */

/* Velocity one sample nearer to @vd (AC speeding up, @dec slowing down). */
static double approach(double v, double vd, double ac, double dec, double dt)
{
	if (v == vd)
		return v;
	if (v != 0 && sign(v) != sign(vd))
		vd = 0; /* through zero first */
	if (fabs(vd) > fabs(v))
		return fabs(vd - v) <= ac * dt ? vd
					       : v + sign(vd - v) * ac * dt;
	return fabs(vd - v) <= dec * dt ? vd : v + sign(vd - v) * dec * dt;
}

static void finish(struct ctrl_axis *a)
{
	a->profiling = 0;
	a->vel = 0;
	a->pa_last = a->ref;
	if (!a->stopping)
		a->stop_code = 1;
	a->stopping = 0;
}

/* Move towards a->target; return 1 when reached. */
static int to_target(struct ctrl_axis *a, double dt)
{
	double d = a->target - a->ref, s = fabs(a->vel), s_new;
	int dir = sign(d);

	if (dir == 0 && a->vel == 0)
		return 1;
	if (dir == 0 || a->vel * dir < 0) { /* moving away: brake */
		a->vel = approach(a->vel, 0, a->p.ac, a->p.dc, dt);
		a->ref += a->vel * dt;
		return 0;
	}
	s_new = s > a->p.sp ? fmax(s - a->p.dc * dt, a->p.sp)
			    : fmin(s + a->p.ac * dt, a->p.sp);
	s_new = fmin(s_new, sqrt(2 * a->p.dc * fabs(d)));
	if (s_new * dt >= fabs(d) || s_new <= 0) {
		a->ref = a->target;
		return 1;
	}
	a->vel = dir * s_new;
	a->ref += a->vel * dt;
	return 0;
}

static void profile(struct ctrl_axis *a, double dt)
{
	if (!a->profiling)
		return;
	if (a->stopping) {
		a->vel = approach(a->vel, 0, a->p.ac, a->stop_dec, dt);
		a->ref += a->vel * dt;
		if (a->vel == 0)
			finish(a);
		return;
	}
	if (a->mode == CTRL_MODE_JG) {
		a->vel = approach(a->vel, a->jg, a->p.ac, a->p.dc, dt);
		a->ref += a->vel * dt;
		return;
	}
	if (to_target(a, dt))
		finish(a);
}

/* ---- servo ------------------------------------------------------------ */

static void servo(struct ctrl_axis *a)
{
	double e, t, ilim, ki_v;

	if (a->p.motor_off) {
		a->ref = a->enc;
		a->target = a->enc;
		a->vel = 0;
		a->torque = 0;
		a->integ = 0;
		a->err_prev = 0;
		return;
	}
	e = a->ref - a->enc;
	/* The plant has no load: a real loop's integrator settles at the
	 * torque that holds the axis (about 0) once it follows. The velocity
	 * model does not feed the torque back, so the integrator leaks with
	 * a time constant of CTRL_KI_LEAK samples instead of winding up for
	 * ever; a growing error (a jam, a stuck encoder) still integrates. */
	a->integ += e - a->integ / CTRL_KI_LEAK;
	ki_v = a->p.ki / 2 * a->integ * DAC_V_PER_COUNT;
	ilim = fabs(a->p.il);
	if (a->p.ki > 0 && fabs(ki_v) > ilim) {
		ki_v = ilim * sign(ki_v);
		a->integ = ki_v / (a->p.ki / 2 * DAC_V_PER_COUNT);
	}
	t = (4 * a->p.kp * e + 4 * a->p.kd * (e - a->err_prev)) *
		DAC_V_PER_COUNT +
	    ki_v + a->p.of;
	/* MT -1 (-1.5): a servo of reversed polarity drives the other way;
	 * MT 2 and above: a stepper, whose pulses this servo does not take */
	if (a->p.mt < 0)
		t = -t;
	if (fabs(a->p.mt) >= 2)
		t = 0;
	a->torque = fmax(-a->p.tl, fmin(a->p.tl, t));
	a->err_prev = e;
}

/* ctrl_motion_sample() - protection, profiler and servo of one sample. */
void ctrl_motion_sample(struct ctrl *c)
{
	double dt = ctrl_dt(c);
	int i;

	amp_check(c);
	for (i = 0; i < CTRL_AXES; i++) {
		struct ctrl_axis *a = &c->ax[i];

		poserr_check(c, i);
		oa_check(c, i);
		limit_check(c, i);
		if (!a->p.motor_off)
			profile(a, dt);
		servo(a);
		a->tv_ring[a->tv_i] = a->enc;
		a->tv_i = (a->tv_i + 1) % CTRL_TV_SAMPLES;
	}
}

/* ctrl_motion_drive() - what goes to the plant (plant coordinates). */
void ctrl_motion_drive(struct ctrl *c, struct ctrl_drive *out)
{
	int i;

	memset(out, 0, sizeof(*out));
	for (i = 0; i < CTRL_AXES; i++) {
		const struct ctrl_axis *a = &c->ax[i];

		out->ref[i] = a->ref - a->offset;
		out->motor_on[i] = !a->p.motor_off;
		out->torque_v[i] = a->torque;
	}
	out->outputs = c->outputs;
}
