/*
 * re_fault.c - the fault catalogue and the FAULT line. See re_fault.h; all
 * operator texts are in re_fault_table below.
 */
#include "re_fault.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gl_err.h"

/* ---- the message table ---------------------------------------------------
 *
 * Placeholders: {a} axis name, {s} text, {i0}..{i3} integers ("unknown" for
 * RE_VAL_UNKNOWN), {x0}..{x3} the same in hex with 0x, {t0}..{t3} the
 * threads of a bit mask in words ("threads 1 and 2", "none"), {f0}..{f3} reals
 * (integral values without decimals, others with 3), {j0} the joystick's
 * switch word i0 in words, {jto} the joystick's invalid-input timeout
 * (" of 500 ms", or nothing when not known). Every recovery text is
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
	 "axis {a}: potentiometer reads {f0} V but {f1} V is expected at encoder position {i0c}; they differ by {f2} V, more than the {f3} V allowed, for {i1} cycles",
	 "press the E-stop and keep it pressed, check the encoder and potentiometer cables of axis {a}, restart roboelf and recalibrate"},
	{RE_F_ENC_OUTSIDE, RE_FC_ENCODER,
	 "axis {a}: encoder position {i0c} is outside the calibrated travel {i1} to {i2} counts{r12}",
	 "press the E-stop and keep it pressed, check the encoder cable of axis {a} and that the axis did not slip, restart roboelf and recalibrate"},
	{RE_F_CTRL_ENCODER, RE_FC_ENCODER,
	 "axis {a}: the controller detected an encoder failure or a blocked axis (stop code {i0})",
	 "press the E-stop and keep it pressed, check that axis {a} moves freely, then its encoder cable and its motor, restart roboelf and recalibrate"},
	{RE_F_WDOG_REPLY, RE_FC_WATCHDOG,
	 "no reply from the controller for {i0} ms (limit {i1} ms)",
	 "press the E-stop and keep it pressed, check the controller's Ethernet cable and power, then restart roboelf"},
	{RE_F_WDOG_STREAM, RE_FC_WATCHDOG,
	 "no data record from the controller for {i0} ms (limit {i1} ms)",
	 "press the E-stop and keep it pressed, check the controller's Ethernet cable and power, then restart roboelf"},
	{RE_F_WDOG_ACK, RE_FC_WATCHDOG,
	 "the controller has not acknowledged the supervisor's heartbeat for {i0} ms (limit {i1} ms)",
	 "press the E-stop and keep it pressed, check the controller's Ethernet cable and power, then restart roboelf"},
	{RE_F_WDOG_ECHO, RE_FC_WATCHDOG,
	 "the controller program has not taken the supervisor's heartbeat for {i0} ms (limit {i1} ms; its record echoes {i2})",
	 "press the E-stop and keep it pressed, check the network to the controller (cable, loss, delay), then restart roboelf; if it happens again on a sound link, reload the controller program with galil-load"},
	{RE_F_WDOG_HEARTBEAT, RE_FC_WATCHDOG,
	 "the controller program's heartbeat stopped at {i0} for {i1} ms (limit {i2} ms)",
	 "press the E-stop and keep it pressed, restart roboelf; if it happens again, reload the controller program with galil-load"},
	{RE_F_WDOG_SAMPLE, RE_FC_WATCHDOG,
	 "the controller's sample counter froze at {i0} for {i1} ms (limit {i2} ms)",
	 "press the E-stop and keep it pressed, switch the controller off and on, then restart roboelf"},
	{RE_F_CTRL_WATCHDOG, RE_FC_WATCHDOG,
	 "the controller stopped the robot: no heartbeat from this PC for {i0} ms",
	 "press the E-stop and keep it pressed, check the controller's Ethernet cable and that this PC is not overloaded, then restart roboelf"},
	{RE_F_ESTOP_LOST, RE_FC_ESTOP,
	 "the E-stop relay stopped answering ({s})",
	 "press the hardware E-stop now, check the relay's USB cable and power, then restart roboelf"},
	{RE_F_MOTOR_OFF, RE_FC_MOTION,
	 "axis {a}: the controller switched the motor off: {s} (stop code {i0})",
	 "press the E-stop and keep it pressed, check that axis {a} moves freely and nothing blocks it, check its motor and encoder cables, then restart roboelf"},
	{RE_F_CTRL_POSERR, RE_FC_MOTION,
	 "axis {a}: position error of at least {i0c}, above its limit (blocked, jammed, or its encoder stuck?)",
	 "press the E-stop and keep it pressed, check that axis {a} moves freely and nothing blocks it, then its encoder cable, then restart roboelf"},
	{RE_F_CTRL_AMPERR, RE_FC_MOTION,
	 "axis {a}: amplifier fault, motor power lost (stop code {i0})",
	 "press the E-stop and keep it pressed, check the amplifier and motor cable of axis {a} and the motor power supply, then restart roboelf"},
	{RE_F_CTRL_POWER, RE_FC_ESTOP,
	 "motor power lost on every axis (E-stop button, relay or power supply)",
	 "press the E-stop and keep it pressed; if nobody had pressed it before this fault, check the relay, its USB cable and the motor power supply, then restart roboelf"},
	{RE_F_CTRL_MOTOROFF, RE_FC_MOTION,
	 "axis {a}: the controller found the motor off while armed: {s} (stop code {i0})",
	 "press the E-stop and keep it pressed, check that axis {a} moves freely and nothing blocks it, check its motor and encoder cables, then restart roboelf"},
	{RE_F_CTRL_INPUT, RE_FC_INPUT,
	 "invalid joystick state held longer than the invalid-input timeout{jto}: {j0}",
	 "release the joysticks, press the E-stop and keep it pressed, check the joystick cables and switches, then restart roboelf"},
	{RE_F_COMM, RE_FC_COMM,
	 "communication with the controller failed: {s}",
	 "press the E-stop and keep it pressed, check the controller's Ethernet cable and power, then restart roboelf"},
	{RE_F_CTRL_TCPERR, RE_FC_COMM,
	 "the controller reported an Ethernet error on handle {i0}",
	 "press the E-stop and keep it pressed, check the controller's Ethernet cable and that no other program is connected to it, then restart roboelf"},
	{RE_F_RECORD, RE_FC_COMM,
	 "the controller program's status fields are invalid (ZAB {i0}, ZAC {i1})",
	 "press the E-stop and keep it pressed, reload the controller program with galil-load, then restart roboelf"},
	{RE_F_CONFIG, RE_FC_CONFIG,
	 "the controller configuration is wrong: {s}",
	 "check the configuration file against docs/config.md and the controller, then restart roboelf"},
	{RE_F_CAL_NONMONO, RE_FC_CALIBRATION,
	 "axis {a}: potentiometer not rising at calibration point {i0}: {f1} V after {f0} V (it must rise by more than {f2} V)",
	 "press the E-stop and keep it pressed, check the potentiometer of axis {a} and its cable (worn or loose), then restart roboelf and calibrate again"},
	{RE_F_CAL_RANGE, RE_FC_CALIBRATION,
	 "axis {a}: potentiometer range {f0} V is outside the expected {f1} V +- {f2} %",
	 "press the E-stop and keep it pressed, check the potentiometer of axis {a}, its cable and the expected range in the configuration, then restart roboelf and calibrate again"},
	{RE_F_CAL_POINTS, RE_FC_CALIBRATION,
	 "axis {a}: {i0} calibration points, expected {i1} to {i2}",
	 "press the E-stop and keep it pressed, check that axis {a} moves over its whole travel and that both its limit switches work, then restart roboelf and calibrate again"},
	{RE_F_CAL_ENCSTEP, RE_FC_CALIBRATION,
	 "axis {a}: encoder advanced {f0} counts at calibration point {i0}, expected {f1} +- {f2} counts",
	 "press the E-stop and keep it pressed, check that axis {a} moves freely (jammed?) and its encoder cable, then restart roboelf and calibrate again"},
	{RE_F_CAL_LIMITS, RE_FC_CALIBRATION,
	 "axis {a}: soft limits {f0} to {f1} counts are outside the calibrated travel {f2} to {f3} counts",
	 "press the E-stop and keep it pressed, restart roboelf and calibrate again with a full calibration"},
	{RE_F_CAL_ABORT, RE_FC_CALIBRATION,
	 "axis {a}: calibration aborted: {s}",
	 "press the E-stop and keep it pressed, check axis {a}, its limit switches and cables, then restart roboelf and calibrate again"},
	{RE_F_CTRL_PARAM, RE_FC_PARAM,
	 "the controller program refused the parameters (check {i0} failed)",
	 "check the configuration file against docs/config.md, then restart roboelf"},
	{RE_F_CTRL_LIMIT, RE_FC_LIMIT,
	 "axis {a}: the {s} hardware limit switch was reached",
	 "press the E-stop and keep it pressed, make sure axis {a} is clear of the patient, check its limit switch, then restart roboelf and recalibrate"},
	{RE_F_CTRL_CMDERR, RE_FC_PROGRAM,
	 "a command in the controller program failed (error code {i0})",
	 "press the E-stop and keep it pressed, restart roboelf; if it happens again, reload the program with galil-load and report the log"},
	{RE_F_CTRL_THREAD, RE_FC_PROGRAM,
	 "the controller's motion thread stopped while armed",
	 "press the E-stop and keep it pressed, restart roboelf; if it happens again, reload the program with galil-load"},
	{RE_F_CTRL_SUPERVISOR, RE_FC_PROGRAM,
	 "the controller latched the supervisor's fault request",
	 "press the E-stop and keep it pressed, read the log for the first fault, then restart roboelf"},
	{RE_F_CTRL_UNKNOWN, RE_FC_PROGRAM,
	 "the controller latched unknown fault code {i0} (axis {i1}, detail {i2})",
	 "press the E-stop and keep it pressed, reload the controller program with galil-load, then restart roboelf"},
	{RE_F_THREAD, RE_FC_PROGRAM,
	 "controller thread {i0} is not running (running: {t1})",
	 "press the E-stop and keep it pressed, restart roboelf; if it happens again, reload the program with galil-load"},
	{RE_F_STATE, RE_FC_PROGRAM,
	 "the controller program left the armed state (state {i0})",
	 "press the E-stop and keep it pressed, check whether the controller was reset or another program took over, then restart roboelf"},
	{RE_F_PROGRAM_ID, RE_FC_PROGRAM,
	 "the controller does not run the program stamped by galil-load: {s}",
	 "load the program with galil-load, then restart roboelf"},
	{RE_F_CTRL_UNCMD, RE_FC_MOTION,
	 "axis {a}: the controller stopped motion its program did not command: {s}",
	 "press the E-stop and keep it pressed, find which other program or person sent commands to the controller (another roboelf, galil-load, a terminal) and stop it, then restart roboelf"},
	{RE_F_CTRL_SAFE_ON, RE_FC_FOREIGN,
	 "a motor was switched on while the controller program held the robot in its safe state: another program sent commands to the controller",
	 "press the E-stop and keep it pressed, find which other program or person sent commands to the controller (another roboelf, galil-load, a terminal) and stop it, then restart roboelf"},
	{RE_F_CTRL_FOREIGN_HB, RE_FC_FOREIGN,
	 "the controller received a heartbeat that is not this supervisor's (out of sequence): another program writes to the controller",
	 "press the E-stop and keep it pressed, close every other program connected to the controller (another roboelf, a terminal), then restart roboelf"},
	{RE_F_CTRL_FOREIGN_SET, RE_FC_FOREIGN,
	 "the controller's safety settings were changed while the motors were on ({s}): another program sent commands to the controller",
	 "press the E-stop and keep it pressed, close every other program connected to the controller (another roboelf, galil-load, a terminal), then restart roboelf"},
	{RE_F_CTRL_SVCMOVE, RE_FC_MOTION,
	 "axis {a}: the controller stopped an automatic move: {s}",
	 "press the E-stop and keep it pressed, check axis {a}, its limit switches and its potentiometer, then restart roboelf; report the log if it happens again"},
	{RE_F_CTRL_POTRANGE, RE_FC_ENCODER,
	 "axis {a}: the potentiometer reads {f0} V, outside the range it can read on this robot",
	 "press the E-stop and keep it pressed, check the potentiometer of axis {a} and its cable (broken wire?) and that the axis is not beyond its limit switch, then restart roboelf and recalibrate"},
	{RE_F_UNCMD, RE_FC_MOTION,
	 "axis {a}: moving although nothing commanded it ({s})",
	 "press the E-stop and keep it pressed, find which other program or person sent commands to the controller (another roboelf, galil-load, a terminal) and stop it, then restart roboelf"},
	{RE_F_STALL, RE_FC_WATCHDOG,
	 "this supervisor did not run for {i0} ms (limit {i1} ms): the PC stalled (suspended, overloaded or stopped in a debugger), not the link",
	 "press the E-stop and keep it pressed, find what stopped roboelf (Ctrl-Z, a debugger, CPU or disk load), then restart it"},
	{RE_F_RELAY_POWER, RE_FC_ESTOP,
	 "motor power lost on every axis and the E-stop relay board does not confirm its state ({s})",
	 "press the hardware E-stop now, check the relay board, its USB cable and its power, then restart roboelf"},
	{RE_F_CAL_ABSOLUTE, RE_FC_CALIBRATION,
	 "axis {a}: potentiometer reads {f0} V at the {s} end of the travel, {f1} V +- {f2} V expected there",
	 "press the E-stop and keep it pressed, check the potentiometer of axis {a} (offset, wrong part, wiring) and the configured reverse_v / forward_v, then restart roboelf and calibrate again"},
	{RE_F_CTRL_SEAL, RE_FC_FOREIGN,
	 "the controller found {s} changed to {f0} (sealed {f1}): another program or a person wrote to the controller",
	 "press the E-stop and keep it pressed, close every other program connected to the controller, then restart roboelf; if this repeats, load the program with galil-load --config"},
	{RE_F_READBACK, RE_FC_FOREIGN,
	 "roboelf read {s} on the controller as {f0}, its own configuration gives {f1}: another program or a person wrote to the controller",
	 "press the E-stop and keep it pressed, close every other program connected to the controller, then restart roboelf; if this repeats, load the program with galil-load --config"},
	{RE_F_XC_DECODE, RE_FC_INPUT,
	 "the controller's program and roboelf decode the joystick differently: {s}",
	 "press the E-stop and keep it pressed, close every other program connected to the controller and check that its program was loaded with this configuration (galil-load --config), then restart roboelf"},
	{RE_F_XC_MOTION, RE_FC_MOTION,
	 "axis {a} {s}: {f0} counts/s, {f1} counts/s allowed",
	 "press the E-stop and keep it pressed, close every other program connected to the controller and check the wiring of axis {a}, then restart roboelf"},
	{RE_F_CTRL_STATE, RE_FC_PROGRAM,
	 "the controller program is in state {i0}, not {s} as expected (reset, or another program took over)",
	 "press the E-stop and keep it pressed, find out whether the controller was reset or another program took over, then restart roboelf"},
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
	if (f->axis < 0 || f->axis >= (int)(sizeof(re_axis_letters) /
					    sizeof(re_axis_letters[0])))
		return "?";
	if (names && names[f->axis])
		return names[f->axis];
	return re_axis_letters[f->axis];
}

/* What the template expander needs besides the fault. */
struct re_view {
	const char *const *names;
	const struct re_fault_units *units; /* NULL: counts only */
};

/* The fault axis's counts per unit and unit name, or 0 (counts only). */
static double re_unit_of(const struct re_fault *f, const struct re_view *v,
			 const char **name)
{
	const struct re_fault_units *u = v->units;

	if (!u || f->axis < 0 || f->axis >= RE_FAULT_UNIT_AXES ||
	    !u->name[f->axis] || !(u->counts_per_unit[f->axis] > 0))
		return 0;
	*name = u->name[f->axis];
	return u->counts_per_unit[f->axis];
}

/* @counts in units, 2 decimals, never "-0.00". */
static void re_fmt_unit(char *tmp, size_t cap, double counts, double per)
{
	double v = counts / per;

	snprintf(tmp, cap, "%.2f", v > -0.005 && v < 0 ? 0.0 : v);
}

/* "{i0c}": "<i0> counts (<in units> <unit>)"; "{r12}": " (<i1> to <i2> in
 * units <unit>)" or nothing. Return 0 if @key is neither. */
static int re_expand_units(struct re_out *o, const char *key, size_t klen,
			   const struct re_fault *f, const struct re_view *v)
{
	const char *unit = NULL;
	double per = re_unit_of(f, v, &unit);
	char a[32], b[32], tmp[96];

	if (klen == 3 && key[0] == 'i' && key[1] >= '0' && key[1] <= '3' &&
	    key[2] == 'c') {
		long long n = f->i[key[1] - '0'];

		if (n == RE_VAL_UNKNOWN)
			snprintf(tmp, sizeof(tmp), "unknown");
		else
			snprintf(tmp, sizeof(tmp), "%lld counts", n);
		re_out_str(o, tmp);
		if (per > 0 && n != RE_VAL_UNKNOWN) {
			re_fmt_unit(a, sizeof(a), (double)n, per);
			snprintf(tmp, sizeof(tmp), " (%s %s)", a, unit);
			re_out_str(o, tmp);
		}
		return 1;
	}
	if (klen == 3 && key[0] == 'r' && key[1] >= '0' && key[1] <= '3' &&
	    key[2] >= '0' && key[2] <= '3') {
		if (per > 0) {
			re_fmt_unit(a, sizeof(a), (double)f->i[key[1] - '0'],
				    per);
			re_fmt_unit(b, sizeof(b), (double)f->i[key[2] - '0'],
				    per);
			snprintf(tmp, sizeof(tmp), " (%s to %s %s)", a, b,
				 unit);
			re_out_str(o, tmp);
		}
		return 1;
	}
	return 0;
}

/* The joystick's switch word @word (bit 2k: switch a of command k, bit
 * 2k + 1: its twin b; commands A forward, A reverse, B forward ...) in
 * words: "A forward (switches a and b) and B forward (switches a and b)
 * closed at once", "A reverse (switch a only) closed". */
static void re_fmt_switches(struct re_out *o, long long word,
			    const char *const *names)
{
	int n = 0, total = 0;
	char tmp[64];

	if (word <= 0 || word >= 1 << 12) { /* RE_VAL_UNKNOWN is negative */
		re_out_str(o, word == 0 ? "no switch closed"
					: "the switches closed are not known");
		return;
	}
	for (int k = 0; k < 6; k++)
		total += (word >> (2 * k) & 3) != 0;
	for (int k = 0; k < 6; k++) {
		long long two = word >> (2 * k) & 3;
		int ax = k / 2;

		if (!two)
			continue;
		snprintf(tmp, sizeof(tmp), "%s%s %s (%s)",
			 !n		 ? ""
			 : n + 1 < total ? ", "
					 : " and ",
			 names && names[ax] ? names[ax] : re_axis_letters[ax],
			 k % 2 ? "reverse" : "forward",
			 two == 3   ? "switches a and b"
			 : two == 1 ? "switch a only"
				    : "switch b only");
		re_out_str(o, tmp);
		n++;
	}
	re_out_str(o, total > 1 ? " closed at once" : " closed");
}

/* "{j0}": the switch word i0 in words; "{jto}": " of <timeout> ms" or
 * nothing. Return 0 if @key is neither. */
static int re_expand_joy(struct re_out *o, const char *key, size_t klen,
			 const struct re_fault *f, const struct re_view *v)
{
	char tmp[48];

	if (klen == 2 && !strncmp(key, "j0", 2)) {
		re_fmt_switches(o, f->i[0], v->names);
		return 1;
	}
	if (klen != 3 || strncmp(key, "jto", 3))
		return 0;
	if (v->units && v->units->invalid_timeout_ms > 0) {
		snprintf(tmp, sizeof(tmp), " of %d ms",
			 v->units->invalid_timeout_ms);
		re_out_str(o, tmp);
	}
	return 1;
}

/* The threads of bit mask @bits (0..7) in words: "threads 0, 2 and 3",
 * "thread 1", "none". */
static void re_thread_list(char *buf, size_t cap, long long bits)
{
	int n = 0, seen = 0;
	size_t used;

	for (int t = 0; t < 8; t++)
		n += (bits >> t) & 1;
	used = (size_t)snprintf(buf, cap, "%s", n == 0   ? "none"
					       : n == 1 ? "thread"
							: "threads");
	for (int t = 0; t < 8 && used < cap; t++) {
		if (!((bits >> t) & 1))
			continue;
		seen++;
		used += (size_t)snprintf(buf + used, cap - used, "%s%d",
					 seen == 1   ? " "
					 : seen == n ? " and "
						     : ", ",
					 t);
	}
}

/* Expand one placeholder @key (without braces); return 0 if unknown. */
static int re_expand(struct re_out *o, const char *key, size_t klen,
		     const struct re_fault *f, const struct re_view *v)
{
	const char *const *names = v->names;
	char tmp[48];
	int k;

	if (re_expand_units(o, key, klen, f, v) ||
	    re_expand_joy(o, key, klen, f, v))
		return 1;
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
	else if (key[0] == 't')
		re_thread_list(tmp, sizeof(tmp), f->i[k]);
	else
		return 0;
	re_out_str(o, tmp);
	return 1;
}

static void re_out_template(struct re_out *o, const char *t,
			    const struct re_fault *f, const struct re_view *v)
{
	char one[2] = {0, 0};
	const char *end;

	while (*t) {
		end = t[0] == '{' ? strchr(t, '}') : NULL;
		if (end && re_expand(o, t + 1, (size_t)(end - t - 1), f, v)) {
			t = end + 1;
			continue;
		}
		one[0] = *t++;
		re_out_str(o, one);
	}
}

/* The FAULT line (@full) or only its "what happened" part. */
static int re_fault_text(const struct re_fault *f, const struct re_view *v,
			 char *buf, size_t cap, int full)
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
	re_out_template(&o, m->what, f, v);
	if (full) {
		re_out_str(&o, ". Recovery: ");
		re_out_template(&o, m->recovery, f, v);
	}
	return o.trunc ? GL_ERR_OVERFLOW : (int)o.len;
}

int re_fault_format_units(const struct re_fault *f,
			  const char *const *axis_names,
			  const struct re_fault_units *units, char *buf,
			  size_t cap)
{
	struct re_view v = {axis_names, units};

	return re_fault_text(f, &v, buf, cap, 1);
}

int re_fault_format(const struct re_fault *f, const char *const *axis_names,
		    char *buf, size_t cap)
{
	return re_fault_format_units(f, axis_names, NULL, buf, cap);
}

int re_fault_what_units(const struct re_fault *f, const char *const *axis_names,
			const struct re_fault_units *units, char *buf,
			size_t cap)
{
	struct re_view v = {axis_names, units};

	return re_fault_text(f, &v, buf, cap, 0);
}

int re_fault_what(const struct re_fault *f, const char *const *axis_names,
		  char *buf, size_t cap)
{
	return re_fault_what_units(f, axis_names, NULL, buf, cap);
}
