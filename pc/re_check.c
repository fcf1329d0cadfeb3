/*
 * re_check.c - the supervisor's safety checks as pure functions.
 *
 * See re_check.h for the contracts and docs/calibration-file.md ("Checks")
 * for the decisions. All operator texts are in re_fault_table below.
 */
#include "re_check.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gl_err.h"

/* ---- the message table ---------------------------------------------------
 *
 * Placeholders: {a} axis name, {s} text, {i0}..{i3} integers ("unknown" for
 * RE_VAL_UNKNOWN), {x0}..{x3} the same in hex with 0x, {f0}..{f3} reals
 * (integral values without decimals, others with 3). Every recovery text is
 * written for an operator standing next to the patient.
 */
struct re_fault_msg {
	enum re_fault_id id;
	enum re_fclass cls;
	const char *what;
	const char *recovery;
};

/* One template per line, so that they can be grepped. */
/* clang-format off */
static const struct re_fault_msg re_fault_table[] = {
	{RE_F_ENCPOT, RE_FC_ENCODER,
	 "axis {a}: potentiometer reads {f0} V but {f1} V is expected at encoder position {i0} counts (difference {f2} V above the tolerance {f3} V for {i1} cycles)",
	 "keep the E-stop pressed, check the encoder and potentiometer cables of axis {a}, restart roboelf and recalibrate"},
	{RE_F_ENC_OUTSIDE, RE_FC_ENCODER,
	 "axis {a}: encoder position {i0} counts is outside the calibrated travel {i1} to {i2} counts",
	 "keep the E-stop pressed, check the encoder cable of axis {a} and that the axis did not slip, restart roboelf and recalibrate"},
	{RE_F_CTRL_ENCODER, RE_FC_ENCODER,
	 "axis {a}: the controller detected an encoder failure or a blocked axis (stop code {i0})",
	 "keep the E-stop pressed, check that axis {a} moves freely, then its encoder cable and its motor, restart roboelf and recalibrate"},
	{RE_F_WDOG_REPLY, RE_FC_WATCHDOG,
	 "no reply from the controller for {i0} ms (limit {i1} ms)",
	 "keep the E-stop pressed, check the controller's Ethernet cable and power, then restart roboelf"},
	{RE_F_WDOG_HEARTBEAT, RE_FC_WATCHDOG,
	 "the controller program's heartbeat stopped at {i0} for {i1} ms (limit {i2} ms)",
	 "keep the E-stop pressed, restart roboelf; if it happens again, reload the controller program with galil-load"},
	{RE_F_WDOG_SAMPLE, RE_FC_WATCHDOG,
	 "the controller's sample counter froze at {i0} for {i1} ms (limit {i2} ms)",
	 "keep the E-stop pressed, switch the controller off and on, then restart roboelf"},
	{RE_F_CTRL_WATCHDOG, RE_FC_WATCHDOG,
	 "the controller stopped the robot: no heartbeat from this PC for {i0} ms",
	 "keep the E-stop pressed, check the controller's Ethernet cable and that this PC is not overloaded, then restart roboelf"},
	{RE_F_ESTOP_LOST, RE_FC_ESTOP,
	 "the E-stop relay stopped answering ({s})",
	 "press the hardware E-stop now, check the relay's USB cable and power, then restart roboelf"},
	{RE_F_MOTOR_OFF, RE_FC_MOTION,
	 "axis {a}: the controller switched the motor off: {s} (stop code {i0})",
	 "keep the E-stop pressed, check that axis {a} moves freely and nothing blocks it, check its motor and encoder cables, then restart roboelf"},
	{RE_F_CTRL_POSERR, RE_FC_MOTION,
	 "axis {a}: position error of at least {i0} counts, above its limit (blocked, jammed, or its encoder stuck?)",
	 "keep the E-stop pressed, check that axis {a} moves freely and nothing blocks it, then its encoder cable, then restart roboelf"},
	{RE_F_CTRL_AMPERR, RE_FC_MOTION,
	 "axis {a}: amplifier fault, motor power lost (stop code {i0})",
	 "keep the E-stop pressed, check the amplifier and motor cable of axis {a} and the motor power supply, then restart roboelf"},
	{RE_F_CTRL_POWER, RE_FC_ESTOP,
	 "motor power lost on every axis (E-stop button, relay or power supply)",
	 "keep the E-stop pressed; if nobody pressed it, check the relay, its USB cable and the motor power supply, then restart roboelf"},
	{RE_F_CTRL_MOTOROFF, RE_FC_MOTION,
	 "axis {a}: the controller found the motor off while armed: {s} (stop code {i0})",
	 "keep the E-stop pressed, check that axis {a} moves freely and nothing blocks it, check its motor and encoder cables, then restart roboelf"},
	{RE_F_CTRL_INPUT, RE_FC_INPUT,
	 "invalid joystick switch state {x0} held longer than the invalid-input timeout",
	 "release the joysticks, keep the E-stop pressed, check the joystick cables and switches, then restart roboelf"},
	{RE_F_COMM, RE_FC_COMM,
	 "communication with the controller failed: {s}",
	 "keep the E-stop pressed, check the controller's Ethernet cable and power, then restart roboelf"},
	{RE_F_CTRL_TCPERR, RE_FC_COMM,
	 "the controller reported an Ethernet error on handle {i0}",
	 "keep the E-stop pressed, check the controller's Ethernet cable and that no other program is connected to it, then restart roboelf"},
	{RE_F_RECORD, RE_FC_COMM,
	 "the controller program's status fields are invalid (ZAB {i0}, ZAC {i1})",
	 "keep the E-stop pressed, reload the controller program with galil-load, then restart roboelf"},
	{RE_F_CONFIG, RE_FC_CONFIG,
	 "the controller configuration is wrong: {s}",
	 "check the configuration file against docs/config.md and the controller, then restart roboelf"},
	{RE_F_CAL_NONMONO, RE_FC_CALIBRATION,
	 "axis {a}: potentiometer not rising at calibration point {i0}: {f1} V after {f0} V (it must rise by more than {f2} V)",
	 "keep the E-stop pressed, check the potentiometer of axis {a} and its cable (worn or loose), then restart roboelf and calibrate again"},
	{RE_F_CAL_RANGE, RE_FC_CALIBRATION,
	 "axis {a}: potentiometer range {f0} V is outside the expected {f1} V +- {f2} %",
	 "keep the E-stop pressed, check the potentiometer of axis {a}, its cable and the expected range in the configuration, then restart roboelf and calibrate again"},
	{RE_F_CAL_POINTS, RE_FC_CALIBRATION,
	 "axis {a}: {i0} calibration points, expected {i1} to {i2}",
	 "keep the E-stop pressed, check that axis {a} moves over its whole travel and that both its limit switches work, then restart roboelf and calibrate again"},
	{RE_F_CAL_ENCSTEP, RE_FC_CALIBRATION,
	 "axis {a}: encoder advanced {f0} counts at calibration point {i0}, expected {f1} +- {f2} counts",
	 "keep the E-stop pressed, check that axis {a} moves freely (jammed?) and its encoder cable, then restart roboelf and calibrate again"},
	{RE_F_CAL_LIMITS, RE_FC_CALIBRATION,
	 "axis {a}: soft limits {f0} to {f1} counts are outside the calibrated travel {f2} to {f3} counts",
	 "keep the E-stop pressed, restart roboelf and calibrate again with a full calibration"},
	{RE_F_CAL_ABORT, RE_FC_CALIBRATION,
	 "axis {a}: calibration aborted: {s}",
	 "keep the E-stop pressed, check axis {a}, its limit switches and cables, then restart roboelf and calibrate again"},
	{RE_F_CTRL_PARAM, RE_FC_PARAM,
	 "the controller program refused the parameters (check {i0} failed)",
	 "check the configuration file against docs/config.md, then restart roboelf"},
	{RE_F_CTRL_LIMIT, RE_FC_LIMIT,
	 "axis {a}: the {s} hardware limit switch was reached",
	 "keep the E-stop pressed, make sure axis {a} is clear of the patient, check its limit switch, then restart roboelf and recalibrate"},
	{RE_F_CTRL_CMDERR, RE_FC_PROGRAM,
	 "a command in the controller program failed (error code {i0})",
	 "keep the E-stop pressed, restart roboelf; if it happens again, reload the program with galil-load and report the log"},
	{RE_F_CTRL_THREAD, RE_FC_PROGRAM,
	 "the controller's motion thread stopped while armed",
	 "keep the E-stop pressed, restart roboelf; if it happens again, reload the program with galil-load"},
	{RE_F_CTRL_SUPERVISOR, RE_FC_PROGRAM,
	 "the controller latched the supervisor's fault request",
	 "keep the E-stop pressed, read the log for the first fault, then restart roboelf"},
	{RE_F_CTRL_UNKNOWN, RE_FC_PROGRAM,
	 "the controller latched unknown fault code {i0} (axis {i1}, detail {i2})",
	 "keep the E-stop pressed, reload the controller program with galil-load, then restart roboelf"},
	{RE_F_THREAD, RE_FC_PROGRAM,
	 "controller thread {i0} is not running (thread bits {x1})",
	 "keep the E-stop pressed, restart roboelf; if it happens again, reload the program with galil-load"},
	{RE_F_STATE, RE_FC_PROGRAM,
	 "the controller program left the armed state (state {i0})",
	 "keep the E-stop pressed, check whether the controller was reset or another program took over, then restart roboelf"},
	{RE_F_PROGRAM_ID, RE_FC_PROGRAM,
	 "the controller does not run the program stamped by galil-load: {s}",
	 "load the program with galil-load, then restart roboelf"},
	{RE_F_CTRL_UNCMD, RE_FC_MOTION,
	 "axis {a}: the controller stopped motion its program did not command: {s}",
	 "keep the E-stop pressed, find which other program or person sent commands to the controller (another roboelf, galil-load, a terminal) and stop it, then restart roboelf"},
	{RE_F_CTRL_SAFE_ON, RE_FC_FOREIGN,
	 "a motor was switched on while the controller program held the robot in its safe state: another program sent commands to the controller",
	 "keep the E-stop pressed, find which other program or person sent commands to the controller (another roboelf, galil-load, a terminal) and stop it, then restart roboelf"},
	{RE_F_CTRL_FOREIGN_HB, RE_FC_FOREIGN,
	 "the controller received a heartbeat that is not this supervisor's (out of sequence): another program writes to the controller",
	 "keep the E-stop pressed, close every other program connected to the controller (another roboelf, a terminal), then restart roboelf"},
	{RE_F_CTRL_FOREIGN_SET, RE_FC_FOREIGN,
	 "the controller's safety settings were changed while the motors were on ({s}): another program sent commands to the controller",
	 "keep the E-stop pressed, close every other program connected to the controller (another roboelf, galil-load, a terminal), then restart roboelf"},
	{RE_F_CTRL_SVCMOVE, RE_FC_MOTION,
	 "axis {a}: the controller stopped an automatic move: {s}",
	 "keep the E-stop pressed, check axis {a}, its limit switches and its potentiometer, then restart roboelf; report the log if it happens again"},
	{RE_F_CTRL_POTRANGE, RE_FC_ENCODER,
	 "axis {a}: the potentiometer reads {f0} V, outside the range it can read on this robot",
	 "keep the E-stop pressed, check the potentiometer of axis {a} and its cable (broken wire?) and that the axis is not beyond its limit switch, then restart roboelf and recalibrate"},
	{RE_F_UNCMD, RE_FC_MOTION,
	 "axis {a}: moving although nothing commanded it ({s})",
	 "keep the E-stop pressed, find which other program or person sent commands to the controller (another roboelf, galil-load, a terminal) and stop it, then restart roboelf"},
	{RE_F_STALL, RE_FC_WATCHDOG,
	 "this supervisor did not run for {i0} ms (limit {i1} ms): the PC stalled (suspended, overloaded or stopped in a debugger), not the link",
	 "keep the E-stop pressed, find what stopped roboelf (Ctrl-Z, a debugger, CPU or disk load), then restart it"},
	{RE_F_RELAY_POWER, RE_FC_ESTOP,
	 "motor power lost on every axis and the E-stop relay board does not confirm its state ({s})",
	 "press the hardware E-stop now, check the relay board, its USB cable and its power, then restart roboelf"},
	{RE_F_CAL_ABSOLUTE, RE_FC_CALIBRATION,
	 "axis {a}: potentiometer reads {f0} V at the {s} end of the travel, {f1} V +- {f2} V expected there",
	 "keep the E-stop pressed, check the potentiometer of axis {a} (offset, wrong part, wiring) and the configured reverse_v / forward_v, then restart roboelf and calibrate again"},
	{RE_F_CTRL_STATE, RE_FC_PROGRAM,
	 "the controller program is in state {i0}, not {s} as expected (reset, or another program took over)",
	 "keep the E-stop pressed, find out whether the controller was reset or another program took over, then restart roboelf"},
};
/* clang-format on */

static const char *const re_fclass_names[RE_FC_COUNT] = {
    [RE_FC_NONE] = "NONE",
    [RE_FC_ENCODER] = "ENCODER",
    [RE_FC_WATCHDOG] = "WATCHDOG",
    [RE_FC_ESTOP] = "ESTOP",
    [RE_FC_MOTION] = "MOTION",
    [RE_FC_INPUT] = "INPUT",
    [RE_FC_COMM] = "COMM",
    [RE_FC_CONFIG] = "CONFIG",
    [RE_FC_CALIBRATION] = "CALIBRATION",
    [RE_FC_PARAM] = "PARAM",
    [RE_FC_LIMIT] = "LIMIT",
    [RE_FC_PROGRAM] = "PROGRAM",
    [RE_FC_FOREIGN] = "FOREIGN",
};

static const char *const re_axis_letters[] = {"A", "B", "C", "D",
					      "E", "F", "G", "H"};

static const struct re_fault_msg *re_fault_lookup(enum re_fault_id id)
{
	size_t k;

	for (k = 0; k < sizeof(re_fault_table) / sizeof(re_fault_table[0]); k++)
		if (re_fault_table[k].id == id)
			return &re_fault_table[k];
	return NULL;
}

enum re_fclass re_fault_class(enum re_fault_id id)
{
	const struct re_fault_msg *m = re_fault_lookup(id);

	return m ? m->cls : RE_FC_NONE;
}

const char *re_fault_class_name(enum re_fclass cls)
{
	if ((int)cls < 0 || cls >= RE_FC_COUNT)
		return "NONE";
	return re_fclass_names[cls];
}

void re_fault_set(struct re_fault *f, enum re_fault_id id, int axis)
{
	memset(f, 0, sizeof(*f));
	f->id = id;
	f->axis = axis;
}

int re_fault_template(enum re_fault_id id, const char **what,
		      const char **recovery)
{
	const struct re_fault_msg *m = re_fault_lookup(id);

	if (!m)
		return GL_ERR_ARG;
	if (what)
		*what = m->what;
	if (recovery)
		*recovery = m->recovery;
	return GL_OK;
}

/* ---- template expansion ---------------------------------------------------*/

struct re_out {
	char *buf;
	size_t cap;
	size_t len;
	int trunc;
};

static void re_out_str(struct re_out *o, const char *s)
{
	size_t n = strlen(s);

	if (o->len + n >= o->cap) {
		n = o->cap - 1 - o->len;
		o->trunc = 1;
	}
	memcpy(o->buf + o->len, s, n);
	o->len += n;
	o->buf[o->len] = '\0';
}

static void re_fmt_real(char *tmp, size_t cap, double v)
{
	if (isfinite(v) && fabs(v) < 1e15 && v == nearbyint(v))
		snprintf(tmp, cap, "%.0f", v);
	else
		snprintf(tmp, cap, "%.3f", v);
}

static const char *re_axis_name(const struct re_fault *f,
				const char *const *names)
{
	if (f->axis < 0 || f->axis >= RE_CAL_MAX_AXES)
		return "?";
	if (names && names[f->axis])
		return names[f->axis];
	return re_axis_letters[f->axis];
}

/* Expand one placeholder @key (without braces); return 0 if unknown. */
static int re_expand(struct re_out *o, const char *key, size_t klen,
		     const struct re_fault *f, const char *const *names)
{
	char tmp[48];
	int k;

	if (klen == 1 && key[0] == 'a') {
		re_out_str(o, re_axis_name(f, names));
		return 1;
	}
	if (klen == 1 && key[0] == 's') {
		re_out_str(o, f->s);
		return 1;
	}
	if (klen != 2 || key[1] < '0' || key[1] > '3')
		return 0;
	k = key[1] - '0';
	if (key[0] == 'f')
		re_fmt_real(tmp, sizeof(tmp), f->f[k]);
	else if ((key[0] == 'i' || key[0] == 'x') && f->i[k] == RE_VAL_UNKNOWN)
		snprintf(tmp, sizeof(tmp), "unknown");
	else if (key[0] == 'i')
		snprintf(tmp, sizeof(tmp), "%lld", f->i[k]);
	else if (key[0] == 'x')
		snprintf(tmp, sizeof(tmp), "0x%llx",
			 (unsigned long long)f->i[k]);
	else
		return 0;
	re_out_str(o, tmp);
	return 1;
}

static void re_out_template(struct re_out *o, const char *t,
			    const struct re_fault *f, const char *const *names)
{
	char one[2] = {0, 0};
	const char *end;

	while (*t) {
		end = t[0] == '{' ? strchr(t, '}') : NULL;
		if (end &&
		    re_expand(o, t + 1, (size_t)(end - t - 1), f, names)) {
			t = end + 1;
			continue;
		}
		one[0] = *t++;
		re_out_str(o, one);
	}
}

/* The FAULT line (@full) or only its "what happened" part. */
static int re_fault_text(const struct re_fault *f,
			 const char *const *axis_names, char *buf, size_t cap,
			 int full)
{
	const struct re_fault_msg *m;
	struct re_out o = {buf, cap, 0, 0};

	if (!f || !buf || cap == 0)
		return GL_ERR_ARG;
	buf[0] = '\0';
	m = re_fault_lookup(f->id);
	if (!m)
		return GL_ERR_ARG;
	if (full) {
		re_out_str(&o, "FAULT ");
		re_out_str(&o, re_fault_class_name(m->cls));
		re_out_str(&o, ": ");
	}
	re_out_template(&o, m->what, f, axis_names);
	if (full) {
		re_out_str(&o, ". Recovery: ");
		re_out_template(&o, m->recovery, f, axis_names);
	}
	return o.trunc ? GL_ERR_OVERFLOW : (int)o.len;
}

int re_fault_format(const struct re_fault *f, const char *const *axis_names,
		    char *buf, size_t cap)
{
	return re_fault_text(f, axis_names, buf, cap, 1);
}

int re_fault_what(const struct re_fault *f, const char *const *axis_names,
		  char *buf, size_t cap)
{
	return re_fault_text(f, axis_names, buf, cap, 0);
}

/* ---- encoder / potentiometer ---------------------------------------------*/

static int re_table_ok(const struct re_caltable *t)
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

	if (!re_table_ok(t) || !out || !isfinite(enc_counts))
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

	if (!re_table_ok(t) || !cfg || !st || !isfinite(cfg->allowed_error) ||
	    cfg->allowed_error < 0 || cfg->persistence_cycles < 0)
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

int re_wdog_limits(const struct re_wdog_cfg *cfg, int64_t *noncrit_ns,
		   int64_t *crit_ns)
{
	if (!cfg || cfg->period_ns <= 0 || !isfinite(cfg->noncrit_factor) ||
	    !isfinite(cfg->crit_factor) || cfg->noncrit_factor < 1.0 ||
	    cfg->crit_factor < cfg->noncrit_factor || cfg->crit_factor > 1e6)
		return GL_ERR_ARG;
	if (noncrit_ns)
		*noncrit_ns =
		    llround(cfg->noncrit_factor * (double)cfg->period_ns);
	if (crit_ns)
		*crit_ns = llround(cfg->crit_factor * (double)cfg->period_ns);
	return GL_OK;
}

int re_check_reply_age(const struct re_wdog_cfg *cfg, int64_t last_good_ns,
		       int64_t now_ns, int64_t *age_ns, struct re_fault *fault)
{
	int64_t warn_ns, crit_ns, age;

	if (re_wdog_limits(cfg, &warn_ns, &crit_ns) != GL_OK ||
	    now_ns < last_good_ns)
		return GL_ERR_ARG;
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

/* ---- data record ---------------------------------------------------------*/

int re_za_decode(int32_t zaa, int32_t zab, int32_t zac, struct re_za *out)
{
	struct re_za z;

	if (!out)
		return GL_ERR_ARG;
	if (zaa < 0 || zaa > 999999 || zab < 0 || zac < 0)
		return GL_ERR_RANGE;
	z.hbdmc = zaa;
	z.state = zab % 10;
	z.fcode = (zab / 10) % 100;
	z.faxis = zab / 1000;
	z.jraw = zac % 4096;
	z.jcmd = (zac / 4096) % 8 - 1;
	z.mcmd = zac / 32768;
	if (z.state > RE_DMC_SERVICE || z.fcode > RE_DMC_F_MAX ||
	    z.faxis > 3 || z.mcmd > 6 || z.jcmd > 6)
		return GL_ERR_RANGE;
	*out = z;
	return GL_OK;
}

const char *re_stop_reason(int stop_code)
{
	switch (stop_code) {
	case 0: return "still running";
	case 1: return "stopped at the commanded position";
	case 2: return "forward limit";
	case 3: return "reverse limit";
	case 4: return "stop command";
	case 6: return "abort input";
	case 7: return "abort command";
	case 8: return "position error above the limit";
	case 9: return "stopped after find edge";
	case 10: return "stopped after homing";
	case 11: return "selective abort input";
	case 12: return "encoder failure";
	case 15: return "amplifier fault";
	case 99: return "MC timeout";
	default: return "unexpected stop";
	}
}

/* Axis index from the program's faxis (1..3), -1 when none. */
static int re_faxis(int faxis)
{
	return faxis >= 1 && faxis <= 3 ? faxis - 1 : -1;
}

static enum re_fault_id re_ctrl_fault_id(int fcode)
{
	switch (fcode) {
	case RE_DMC_F_PARAM: return RE_F_CTRL_PARAM;
	case RE_DMC_F_WATCHDOG: return RE_F_CTRL_WATCHDOG;
	case RE_DMC_F_INPUT: return RE_F_CTRL_INPUT;
	case RE_DMC_F_POSERR: return RE_F_CTRL_POSERR;
	case RE_DMC_F_LIMIT: return RE_F_CTRL_LIMIT;
	case RE_DMC_F_CMDERR: return RE_F_CTRL_CMDERR;
	case RE_DMC_F_TCPERR: return RE_F_CTRL_TCPERR;
	case RE_DMC_F_AMPERR: return RE_F_CTRL_AMPERR;
	case RE_DMC_F_ENCODER: return RE_F_CTRL_ENCODER;
	case RE_DMC_F_MOTOROFF: return RE_F_CTRL_MOTOROFF;
	case RE_DMC_F_THREAD: return RE_F_CTRL_THREAD;
	case RE_DMC_F_SUPERVISOR: return RE_F_CTRL_SUPERVISOR;
	case RE_DMC_F_UNCMD: return RE_F_CTRL_UNCMD;
	case RE_DMC_F_FOREIGN: return RE_F_CTRL_FOREIGN_SET;
	case RE_DMC_F_SVCMOVE: return RE_F_CTRL_SVCMOVE;
	case RE_DMC_F_POTRANGE: return RE_F_CTRL_POTRANGE;
	default: return RE_F_CTRL_UNKNOWN;
	}
}

int re_fault_is_ctrl(enum re_fault_id id)
{
	/* derived from the mapping, so that a new program fault code cannot
	 * be missing here */
	for (int code = 0; code < 100; code++)
		if (re_ctrl_fault_id(code) == id)
			return 1;
	return id == RE_F_CTRL_POWER || id == RE_F_CTRL_SAFE_ON ||
	       id == RE_F_CTRL_FOREIGN_HB;
}

/* Fault 15's detail (docs/dmc-interface.md, #MVGO and #MVSUP). */
static const char *re_svc_reason(long long det)
{
	static const char *const why[] = {
	    "the reason is not known",
	    "the axis was already moving",
	    "the requested speed is above the limit",
	    "the requested distance is above the limit",
	    "the requested time limit is out of range",
	    "a fast move toward a limit switch the potentiometer says is near",
	    "the move did not end within its time limit",
	    "it moved fast near a limit switch",
	};

	return det >= 1 && det <= 7 ? why[det] : why[0];
}

/* Fault 14's detail: 1 the heartbeat, 3 wdto or jto, 4 OE. */
static void re_foreign(long long det, struct re_fault *f)
{
	if (det == 1) {
		f->id = RE_F_CTRL_FOREIGN_HB;
		return;
	}
	snprintf(f->s, sizeof(f->s), "%s",
		 det == 3   ? "the watchdog or the joystick timeout"
		 : det == 4 ? "off-on-error switched off"
			    : "which one is not known");
}

/* The text and values of the version 2.00 faults 13..16. */
static void re_ctrl_fault_v2(long long fdet, struct re_fault *f)
{
	switch (f->id) {
	case RE_F_CTRL_UNCMD:
		if (fdet == 3) {
			re_fault_set(f, RE_F_CTRL_SAFE_ON, -1);
			break;
		}
		snprintf(f->s, sizeof(f->s), "%s",
			 fdet == 1   ? "a move started by another program"
			 : fdet == 2 ? "faster than allowed"
				     : "reason unknown");
		break;
	case RE_F_CTRL_FOREIGN_SET: re_foreign(fdet, f); break;
	case RE_F_CTRL_SVCMOVE:
		snprintf(f->s, sizeof(f->s), "%s", re_svc_reason(fdet));
		break;
	case RE_F_CTRL_POTRANGE:
		f->f[0] = fdet == RE_VAL_UNKNOWN ? NAN : (double)fdet / 1000.0;
		break;
	default: break;
	}
}

int re_ctrl_fault(const struct re_za *za, long long fdet,
		  struct re_fault *fault)
{
	enum re_fault_id id;

	if (!za || !fault)
		return GL_ERR_ARG;
	id = re_ctrl_fault_id(za->fcode);
	/* AMPERR on no single axis: every amplifier lost power at once. */
	if (id == RE_F_CTRL_AMPERR && re_faxis(za->faxis) < 0)
		id = RE_F_CTRL_POWER;
	re_fault_set(fault, id, re_faxis(za->faxis));
	fault->i[0] = fdet;
	if (id == RE_F_CTRL_UNKNOWN) {
		fault->i[0] = za->fcode;
		fault->i[1] = za->faxis;
		fault->i[2] = fdet;
	} else if (id == RE_F_CTRL_LIMIT) {
		snprintf(fault->s, sizeof(fault->s), "%s",
			 fdet == 2   ? "forward"
			 : fdet == 3 ? "reverse"
				     : "forward or reverse");
	} else if (id == RE_F_CTRL_MOTOROFF) {
		snprintf(fault->s, sizeof(fault->s), "%s",
			 fdet == RE_VAL_UNKNOWN ? "reason unknown"
						: re_stop_reason((int)fdet));
	} else {
		re_ctrl_fault_v2(fdet, fault);
	}
	return GL_OK;
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
	if (v != RE_OK ||
	    (expect != RE_DMC_ARMED && expect != RE_DMC_SERVICE))
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

/* ---- calibration-time checks ---------------------------------------------*/

static int re_calcheck_cfg_ok(const struct re_calcheck_cfg *c)
{
	return c && isfinite(c->noise_margin_v) && c->noise_margin_v >= 0 &&
	       isfinite(c->expected_range_v) && c->expected_range_v > 0 &&
	       isfinite(c->range_tol) && c->range_tol >= 0 &&
	       c->min_points >= 2 && c->max_points <= RE_CAL_MAX_POINTS &&
	       c->min_points <= c->max_points && isfinite(c->step_tol_counts) &&
	       c->step_tol_counts >= 0;
}

static int re_nonmono(struct re_fault *f, int axis, int index, double prev,
		      double cur, double margin)
{
	if (f) {
		re_fault_set(f, RE_F_CAL_NONMONO, axis);
		f->i[0] = index;
		f->f[0] = prev;
		f->f[1] = cur;
		f->f[2] = margin;
	}
	return RE_FAULT;
}

int re_cal_check_point(const struct re_calcheck_cfg *cfg, int axis, int index,
		       double step_counts, double prev_enc_counts,
		       double enc_counts, double prev_pot_v, double pot_v,
		       struct re_fault *fault)
{
	double adv = enc_counts - prev_enc_counts;

	if (!re_calcheck_cfg_ok(cfg) || index < 1 || !isfinite(step_counts) ||
	    step_counts <= 0)
		return GL_ERR_ARG;
	if (!(fabs(adv - step_counts) <= cfg->step_tol_counts)) {
		if (fault) {
			re_fault_set(fault, RE_F_CAL_ENCSTEP, axis);
			fault->i[0] = index;
			fault->f[0] = adv;
			fault->f[1] = step_counts;
			fault->f[2] = cfg->step_tol_counts;
		}
		return RE_FAULT;
	}
	if (!(pot_v - prev_pot_v > cfg->noise_margin_v))
		return re_nonmono(fault, axis, index, prev_pot_v, pot_v,
				  cfg->noise_margin_v);
	return RE_OK;
}

static int re_cal_check_values(const struct re_calcheck_cfg *cfg, int axis,
			       const struct re_caltable *t,
			       struct re_fault *fault)
{
	double range;
	int k;

	if (!isfinite(t->pot_v[0]))
		return re_nonmono(fault, axis, 0, t->pot_v[0], t->pot_v[0],
				  cfg->noise_margin_v);
	for (k = 1; k < t->n; k++)
		if (!(t->pot_v[k] - t->pot_v[k - 1] > cfg->noise_margin_v) ||
		    !isfinite(t->pot_v[k]))
			return re_nonmono(fault, axis, k, t->pot_v[k - 1],
					  t->pot_v[k], cfg->noise_margin_v);
	range = t->pot_v[t->n - 1] - t->pot_v[0];
	if (!(fabs(range - cfg->expected_range_v) <=
	      cfg->range_tol * cfg->expected_range_v)) {
		if (fault) {
			re_fault_set(fault, RE_F_CAL_RANGE, axis);
			fault->f[0] = range;
			fault->f[1] = cfg->expected_range_v;
			fault->f[2] = cfg->range_tol * 100.0;
		}
		return RE_FAULT;
	}
	return RE_OK;
}

static int re_cal_check_limits(int axis, const struct re_caltable *t,
			       struct re_fault *fault)
{
	double first = t->start_counts;
	double last = t->start_counts + (t->n - 1) * t->step_counts;
	double lo = first - RE_CAL_EXTRAP_STEPS * t->step_counts;
	double hi = last + RE_CAL_EXTRAP_STEPS * t->step_counts;

	if (lo <= t->soft_rev && t->soft_rev < t->soft_fwd && t->soft_fwd <= hi)
		return RE_OK;
	if (fault) {
		re_fault_set(fault, RE_F_CAL_LIMITS, axis);
		fault->f[0] = t->soft_rev;
		fault->f[1] = t->soft_fwd;
		fault->f[2] = first;
		fault->f[3] = last;
	}
	return RE_FAULT;
}

/* The end values against the potentiometer's absolute readings. */
static int re_cal_check_ends(const struct re_calcheck_cfg *cfg, int axis,
			     const struct re_caltable *t,
			     struct re_fault *fault)
{
	double v[2] = {t->pot_v[0], t->pot_v[t->n - 1]};
	double want[2] = {cfg->abs_first_v, cfg->abs_last_v};

	if (!(cfg->abs_tol_v > 0))
		return RE_OK;
	for (int k = 0; k < 2; k++) {
		if (fabs(v[k] - want[k]) <= cfg->abs_tol_v)
			continue;
		if (fault) {
			re_fault_set(fault, RE_F_CAL_ABSOLUTE, axis);
			snprintf(fault->s, sizeof(fault->s), "%s",
				 k ? "forward" : "reverse");
			fault->f[0] = v[k];
			fault->f[1] = want[k];
			fault->f[2] = cfg->abs_tol_v;
		}
		return RE_FAULT;
	}
	return RE_OK;
}

int re_cal_check_table(const struct re_calcheck_cfg *cfg, int axis,
		       const struct re_caltable *t, struct re_fault *fault)
{
	int v;

	if (!re_calcheck_cfg_ok(cfg) || !t)
		return GL_ERR_ARG;
	if (t->n < cfg->min_points || t->n > cfg->max_points) {
		if (fault) {
			re_fault_set(fault, RE_F_CAL_POINTS, axis);
			fault->i[0] = t->n;
			fault->i[1] = cfg->min_points;
			fault->i[2] = cfg->max_points;
		}
		return RE_FAULT;
	}
	if (!re_table_ok(t))
		return GL_ERR_ARG;
	v = re_cal_check_values(cfg, axis, t, fault);
	if (v == RE_OK)
		v = re_cal_check_limits(axis, t, fault);
	if (v == RE_OK)
		v = re_cal_check_ends(cfg, axis, t, fault);
	return v;
}
