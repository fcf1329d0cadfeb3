/*
 * re_ctl.c - the controller in the supervisor's start-up and shutdown
 * order: identification, busy check, take-over, halt, configuration with
 * read-back, amplifier power, program start, parameters, states. See
 * re_ctl.h.
 */
#include "re_ctl.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>

#include "base_clock.h"
#include "base_version.h"
#include "gl_err.h"
#include "gl_ident.h"
#include "re_sealmake.h"

#define LINE_MAX_CHARS	GL_LINE_MAX
#define POLL_MS		10
#define PROGRAM_WAIT_MS 1000 /* XQ #AUTO,0 -> state 0, heartbeat */
#define ARM_WAIT_MS	1000 /* armreq/svcreq -> state (dmc-interface.md) */
#define OFF_WAIT_MS	200  /* offreq=1 -> state 0 */
#define TA0_UNDERVOLT	8    /* TA0 bit 3: under-voltage, axes A-D */
#define SOFT_WIDE	2000000000 /* srev/sfwd before calibration */
#define AXES		"ABC"

/* ---- small helpers ------------------------------------------------------- */

static void seterr(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void seterr(char *err, size_t errlen, const char *fmt, ...)
{
	va_list ap;

	if (!err || !errlen)
		return;
	va_start(ap, fmt);
	vsnprintf(err, errlen, fmt, ap);
	va_end(ap);
}

/* A number as the controller takes it: up to 4 decimals, no trailing 0. */
static void fmt_num(char *buf, size_t cap, double v)
{
	char *p;

	snprintf(buf, cap, "%.4f", v);
	p = strchr(buf, '.');
	if (!p)
		return;
	for (p = buf + strlen(buf) - 1; *p == '0'; p--)
		*p = '\0';
	if (*p == '.')
		*p = '\0';
	if (!strcmp(buf, "-0"))
		snprintf(buf, cap, "0");
}

static int cmd(const struct re_io *io, const char *line, char *err,
	       size_t errlen)
{
	char resp[128];
	int rc = io->ops->command(io->ud, line, resp, sizeof(resp), 0);

	if (rc == GL_ERR_CTRL)
		seterr(err, errlen, "controller refused '%s': %s", line,
		       io->ops->ctrl_error(io->ud, NULL));
	else if (rc < 0)
		seterr(err, errlen, "command '%s' failed: %s", line,
		       gl_strerror(rc));
	return rc < 0 ? rc : GL_OK;
}

static int read_err(const struct re_io *io, const char *expr, double *v,
		    char *err, size_t errlen)
{
	int rc = re_io_read(io, expr, v, 0);

	if (rc == GL_ERR_CTRL)
		seterr(err, errlen, "cannot read '%s': %s", expr,
		       io->ops->ctrl_error(io->ud, NULL));
	else if (rc < 0)
		seterr(err, errlen, "cannot read '%s': %s", expr,
		       gl_strerror(rc));
	return rc;
}

static int same(double wrote, double read, int integer, double res)
{
	if (res > 0)
		return fabs(wrote - read) < res;
	if (integer)
		return fabs(wrote - read) < 0.5;
	return fabs(wrote - read) <= 1e-3 + 1e-6 * fabs(wrote);
}

static int64_t now_ns(const struct re_io *io)
{
	return io->ops->now_ns(io->ud);
}

static void pause_ms(const struct re_io *io, int ms)
{
	io->ops->sleep_until(io->ud, now_ns(io) + ms * BASE_NS_PER_MS);
}

int re_ctl_stop(const struct re_io *io, int timeout_ms)
{
	char resp[64];
	int rc = io->ops->command(io->ud, RE_STOP_ALL, resp, sizeof(resp),
				  timeout_ms);

	return rc < 0 ? rc : GL_OK;
}

/* ---- identification ------------------------------------------------------ */

/* The seal part of the program @text (normal form, stamp line last)
 * against what @cfg gives: the controller's program must hold exactly the
 * values this configuration seals (re_seal.h). @seal gets the table. */
static int check_seal(const char *text, size_t len, const struct re_config *cfg,
		      struct re_seal *seal, char *err, size_t errlen)
{
	long at = re_seal_split(text, len);
	size_t end = len;
	char *want;
	int n, rc;

	if (at < 0) {
		seterr(err, errlen,
		       "the controller's program holds no seal (%s): load "
		       "this release's dmc/ with galil-load and this "
		       "configuration (docs/technician.md)",
		       RE_SEAL_FIRST);
		return GL_ERR_MISMATCH;
	}
	/* the stamp line is the last one: the seal ends before it */
	while (end > 0 && text[end - 1] == '\n')
		end--;
	while (end > 0 && text[end - 1] != '\n')
		end--;
	rc = re_seal_make(text, (size_t)at, cfg, seal, err, errlen);
	if (rc != GL_OK)
		return rc;
	want = malloc(RE_SEAL_TEXT_MAX);
	if (!want)
		return GL_ERR_NOMEM;
	n = re_seal_emit(seal, want, RE_SEAL_TEXT_MAX);
	rc = n < 0 ? n
		   : re_seal_compare(seal, text + at, end - (size_t)at, want,
				     (size_t)n, err, errlen);
	free(want);
	if (rc == GL_ERR_MISMATCH)
		snprintf(err + strlen(err), errlen - strlen(err),
			 ": load the program again with galil-load --config "
			 "and the configuration roboelf uses");
	return rc;
}

int re_ctl_check_program(gl_link *l, const struct re_config *cfg,
			 struct re_ctl_info *info, struct re_seal *seal,
			 char *err, size_t errlen)
{
	char *buf = malloc(RE_CTL_UPLOAD_MAX);
	int n, rc;

	if (!buf)
		return GL_ERR_NOMEM;
	n = gl_link_upload(l, buf, RE_CTL_UPLOAD_MAX, 0);
	if (n < 0) {
		seterr(err, errlen,
		       "cannot upload the controller's program: "
		       "%s",
		       gl_strerror(n));
		free(buf);
		return n;
	}
	rc = gl_ident_verify(buf, (size_t)n, &info->program_id);
	if (rc == GL_OK) {
		n = gl_ident_normalise(buf, (size_t)n, buf, RE_CTL_UPLOAD_MAX);
		rc = n < 0 ? GL_ERR_FORMAT
			   : check_seal(buf, (size_t)n, cfg, seal, err, errlen);
		free(buf);
		return rc == GL_OK ? GL_OK : GL_ERR_MISMATCH;
	}
	free(buf);
	if (rc == GL_ERR_FORMAT)
		seterr(err, errlen,
		       "the controller holds no program stamped "
		       "by galil-load: run galil-load with dmc/ first");
	else if (rc == GL_ERR_MISMATCH)
		seterr(err, errlen,
		       "the controller's program was changed "
		       "after galil-load stamped it (id %016llX): run "
		       "galil-load with dmc/ again",
		       (unsigned long long)info->program_id);
	return rc == GL_OK ? GL_OK : GL_ERR_MISMATCH;
}

int re_ctl_identify(gl_link *l, const struct re_config *cfg,
		    struct re_ctl_info *info, char *err, size_t errlen)
{
	int rc;

	memset(info, 0, sizeof(*info));
	rc = gl_link_identify(l, info->model, sizeof(info->model),
			      &info->serial);
	if (rc < 0) {
		seterr(err, errlen, "cannot identify the controller: %s",
		       gl_strerror(rc));
		return rc;
	}
	if (!strstr(info->model, cfg->controller.model)) {
		seterr(err, errlen,
		       "controller '%s' is not the configured "
		       "model '%s'",
		       info->model, cfg->controller.model);
		return GL_ERR_MISMATCH;
	}
	return GL_OK;
}

int re_ctl_check_busy(const struct re_io *io, int wdto_ms, char *err,
		      size_t errlen)
{
	double xq = -1, state = 0, hb0 = 0, hb1 = 0;

	if (re_io_read(io, "_XQ0", &xq, 0) != GL_OK || xq < 0)
		return GL_OK; /* no program running */
	if (re_io_read(io, "state", &state, 0) != GL_OK ||
	    (state != RE_DMC_ARMED && state != RE_DMC_SERVICE))
		return GL_OK;
	if (re_io_read(io, "hbpc", &hb0, 0) != GL_OK)
		return GL_OK;
	pause_ms(io, wdto_ms + 50);
	if (re_io_read(io, "hbpc", &hb1, 0) != GL_OK || hb1 == hb0)
		return GL_OK; /* an orphan: its own watchdog stops it */
	seterr(err, errlen,
	       "the controller's program is %s and its heartbeat is "
	       "advancing: another supervisor is running the robot; quit it "
	       "first (nothing was changed on the controller)",
	       state == RE_DMC_ARMED ? "armed" : "in its service state");
	return GL_ERR_BUSY;
}

int re_ctl_take_over(gl_link *l, const struct re_config *cfg,
		     struct re_ctl_info *info, struct re_seal *seal, char *err,
		     size_t errlen)
{
	char resp[64];
	int rc;

	/* close every other handle before opening our message handle */
	rc = gl_link_command(l, "IHT=>-3", resp, sizeof(resp), 0);
	if (rc < 0) {
		seterr(err, errlen,
		       "cannot close the controller's other "
		       "connections (IHT=>-3): %s",
		       rc == GL_ERR_CTRL ? gl_link_ctrl_error(l, NULL)
					 : gl_strerror(rc));
		return rc;
	}
	rc = gl_link_open_messages(l, 0);
	if (rc < 0) {
		seterr(err, errlen, "cannot open the message handle: %s",
		       gl_strerror(rc));
		return rc;
	}
	return re_ctl_check_program(l, cfg, info, seal, err, errlen);
}

/* ---- configuration --------------------------------------------------------
 */

struct setting {
	const char *name; /* command and operand, e.g. "KP" */
	double v[RE_AXES];
	int integer;
	double res; /* the controller's resolution, 0: none */
};

/* DMC-40x0 command reference: AC and DC are kept in steps of 1024
 * counts/s^2, KP and KD in steps of 1/8; a read-back within one step of
 * what was written is what the controller stores, not a difference. */
static double resolution(const char *name)
{
	if (!strcmp(name, "AC") || !strcmp(name, "DC"))
		return 1024;
	if (!strcmp(name, "KP") || !strcmp(name, "KD"))
		return 0.125;
	return 0;
}

static int fill_settings(const struct re_config *cfg,
			 const struct re_plan *plan, struct setting *s)
{
	static const char *const names[] = {
	    "KP", "KI", "KD", "TL", "ER", "OE", "OA",
	    "OT", "OV", "AC", "DC", "FL", "BL",
	};
	int n = (int)(sizeof(names) / sizeof(names[0]));

	for (int k = 0; k < n; k++) {
		s[k].name = names[k];
		s[k].integer = k >= 4 && k != 8; /* TL, OV, gains: real */
		s[k].res = resolution(names[k]);
	}
	for (int i = 0; i < RE_AXES; i++) {
		const struct re_config_axis *a = &cfg->axes[i];

		s[0].v[i] = a->kp;
		s[1].v[i] = a->ki;
		s[2].v[i] = a->kd;
		s[3].v[i] = a->torque_limit_v;
		s[4].v[i] = a->position_error_limit_counts;
		s[5].v[i] = a->off_on_error ? 1 : 0;
		s[6].v[i] = a->encoder_failure.enabled ? 1 : 0;
		s[7].v[i] = a->encoder_failure.time_samples;
		s[8].v[i] = a->encoder_failure.torque_v;
		s[9].v[i] = 10.0 * plan->axis[i].svmax_cps;
		s[10].v[i] = 10.0 * plan->axis[i].svmax_cps;
		s[11].v[i] = RE_CTL_SOFT_OPEN;
		s[12].v[i] = -RE_CTL_SOFT_OPEN;
	}
	return n;
}

/* "XX a,b,c" then MG _XXA, _XXB, _XXC compared with what was written. */
static int write_setting(const struct re_io *io, const struct setting *s,
			 char *err, size_t errlen)
{
	char line[LINE_MAX_CHARS + 1], num[3][24], op[8];
	double got;
	int rc;

	for (int i = 0; i < RE_AXES; i++)
		fmt_num(num[i], sizeof(num[i]), s->v[i]);
	snprintf(line, sizeof(line), "%s %s,%s,%s", s->name, num[0], num[1],
		 num[2]);
	rc = cmd(io, line, err, errlen);
	for (int i = 0; rc == GL_OK && i < RE_AXES; i++) {
		snprintf(op, sizeof(op), "_%s%c", s->name, AXES[i]);
		rc = read_err(io, op, &got, err, errlen);
		if (rc == GL_OK && !same(s->v[i], got, s->integer, s->res)) {
			seterr(err, errlen,
			       "read-back of %s%c differs: wrote "
			       "%s, read %g",
			       s->name, AXES[i], num[i], got);
			rc = GL_ERR_MISMATCH;
		}
	}
	return rc;
}

/* CO 0: extended I/O (inputs 17..48) all inputs, as the joystick needs.
 * A controller without CO (DMC-41x3, galil-sim) answers TC 1: accepted in
 * development mode with a logged warning, refused in clinical mode. */
static int write_co(const struct re_io *io, const struct re_config *cfg,
		    char *err, size_t errlen)
{
	double got;
	int code = 0, rc = cmd(io, "CO 0", err, errlen);

	if (rc == GL_ERR_CTRL) {
		io->ops->ctrl_error(io->ud, &code);
		if (code == 1 && cfg->mode == RE_MODE_DEVELOPMENT) {
			re_io_logf(io, RE_LOG_WARN,
				   "controller: %s; extended "
				   "I/O left at its default (development "
				   "mode)",
				   err);
			return GL_OK;
		}
	}

	if (rc == GL_OK)
		rc = read_err(io, "_CO", &got, err, errlen);
	if (rc == GL_OK && got != 0) {
		seterr(err, errlen, "read-back of CO differs: wrote 0, read %g",
		       got);
		rc = GL_ERR_MISMATCH;
	}
	return rc;
}

int re_ctl_halt(const struct re_io *io, char *err, size_t errlen)
{
	static const char *const mo[RE_AXES] = {"_MOA", "_MOB", "_MOC"};
	double v;
	int rc = cmd(io, "prun=0", err, errlen);

	if (rc == GL_OK)
		rc = cmd(io, "HX", err, errlen);
	if (rc == GL_OK)
		rc = cmd(io, RE_STOP_ALL, err, errlen);
	for (int i = 0; rc == GL_OK && i < RE_AXES; i++) {
		rc = read_err(io, mo[i], &v, err, errlen);
		if (rc == GL_OK && v != 1) {
			seterr(err, errlen,
			       "axis %c: the motor is still on after "
			       "'%s' (%s read %g)",
			       AXES[i], RE_STOP_ALL, mo[i], v);
			rc = GL_ERR_MISMATCH;
		}
	}
	return rc;
}

int re_ctl_amp_power(const struct re_io *io, int want_on, int timeout_ms,
		     int *ta0, char *err, size_t errlen)
{
	int64_t deadline = now_ns(io) + (int64_t)timeout_ms * BASE_NS_PER_MS;
	double v = 0;
	int rc, off;

	for (;;) {
		rc = read_err(io, "_TA0", &v, err, errlen);
		if (rc != GL_OK)
			return rc;
		if (ta0)
			*ta0 = (int)v;
		off = ((int)v & TA0_UNDERVOLT) != 0;
		if (off != want_on)
			return GL_OK;
		if (now_ns(io) >= deadline)
			break;
		pause_ms(io, POLL_MS);
	}
	seterr(err, errlen,
	       want_on ? "the amplifiers still report no motor power %d ms "
			 "after the relay closed (TA0 %d): the hardware "
			 "E-stop is pressed, or the relay or the motor power "
			 "supply failed"
		       : "the amplifiers report motor power with the E-stop "
			 "relay open (%d ms, TA0 %d): the relay does not cut "
			 "motor power (miswired or bypassed)",
	       timeout_ms, (int)v);
	return GL_ERR_TIMEOUT;
}

int re_ctl_configure(const struct re_io *io, const struct re_config *cfg,
		     const struct re_plan *plan, char *err, size_t errlen)
{
	struct setting s[16];
	int n, rc;

	rc = write_co(io, cfg, err, errlen);
	n = fill_settings(cfg, plan, s);
	for (int k = 0; rc == GL_OK && k < n; k++)
		rc = write_setting(io, &s[k], err, errlen);
	return rc;
}

int re_ctl_set_limits(const struct re_io *io, const struct re_calset *cal,
		      char *err, size_t errlen)
{
	struct setting s[2] = {{"FL", {0}, 1, 0}, {"BL", {0}, 1, 0}};
	int rc = GL_OK;

	if (cal->n_axes != RE_AXES) {
		seterr(err, errlen, "calibration has %d axes, not %d",
		       cal->n_axes, RE_AXES);
		return GL_ERR_ARG;
	}
	for (int i = 0; i < RE_AXES; i++) {
		s[0].v[i] = floor(cal->axis[i].soft_fwd + 0.5);
		s[1].v[i] = floor(cal->axis[i].soft_rev + 0.5);
	}
	for (int k = 0; rc == GL_OK && k < 2; k++)
		rc = write_setting(io, &s[k], err, errlen);
	return rc;
}

/* ---- arming ------------------------------------------------------------- */

struct param {
	const char *name; /* variable or array name */
	int n;		  /* 0: plain variable, else elements */
	double v[RE_JOY_INPUTS];
};

static int check_param(const struct re_io *io, const struct param *p, char *err,
		       size_t errlen);

#define N_PARAMS 23

static void axis_params(const struct re_config *cfg, const struct re_plan *pl,
			const struct re_calset *cal, struct param *p)
{
	static const char *const arrays[] = {
	    "vmin", "vmax", "wst",   "wen",    "stp",
	    "srev", "sfwd", "potin", "potlo",  "pothi",
	    "pnlo", "pnhi", "svmax", "svslow", "svdmax",
	};

	for (int k = 0; k < 15; k++) {
		p[k].name = arrays[k];
		p[k].n = RE_AXES;
	}
	for (int i = 0; i < RE_AXES; i++) {
		const struct re_config_axis *a = &cfg->axes[i];
		const struct re_plan_axis *x = &pl->axis[i];

		p[0].v[i] = a->vmin_cps;
		p[1].v[i] = a->vmax_cps;
		p[2].v[i] = a->accel_start_ms;
		p[3].v[i] = a->accel_end_ms;
		p[4].v[i] = a->step_counts;
		p[5].v[i] =
		    cal ? floor(cal->axis[i].soft_rev + 0.5) : -SOFT_WIDE;
		p[6].v[i] =
		    cal ? floor(cal->axis[i].soft_fwd + 0.5) : SOFT_WIDE;
		p[7].v[i] = a->analog.input;
		p[8].v[i] = x->potlo_v;
		p[9].v[i] = x->pothi_v;
		p[10].v[i] = x->pnlo_v;
		p[11].v[i] = x->pnhi_v;
		p[12].v[i] = x->svmax_cps;
		p[13].v[i] = x->seek_cps;
		p[14].v[i] = (double)x->svdmax_counts;
	}
}

static int fill_params(const struct re_config *cfg, const struct re_plan *pl,
		       const struct re_calset *cal, struct param *p)
{
	axis_params(cfg, pl, cal, p);
	p[15] = (struct param){"jin", RE_JOY_INPUTS, {0}};
	for (int j = 0; j < RE_JOY_INPUTS; j++)
		p[15].v[j] = cfg->joystick.inputs[j];
	p[16] = (struct param){"jval", 6, {3, 12, 48, 192, 768, 3072}};
	p[17] = (struct param){"jpol", 0, {cfg->joystick.active_low ? 1 : 0}};
	p[18] = (struct param){"jto", 0, {cfg->joystick.invalid_timeout_ms}};
	p[19] = (struct param){"wdto", 0, {pl->wdto_ms}};
	p[20] = (struct param){"hbmaxd", 0, {pl->hbmaxd}};
	p[21] = (struct param){"pwrout", 0, {pl->pwrout}};
	p[22] = (struct param){"mvto", 0, {pl->move_timeout_ms}};
	return N_PARAMS;
}

static void param_ref(const struct param *p, int i, char *buf, size_t cap)
{
	if (p->n)
		snprintf(buf, cap, "%s[%d]", p->name, i);
	else
		snprintf(buf, cap, "%s", p->name);
}

/* Assignments joined with ';' into lines of at most 80 characters. */
static int write_param(const struct re_io *io, const struct param *p, char *err,
		       size_t errlen)
{
	char line[LINE_MAX_CHARS + 1] = "", item[48], ref[16], num[24];
	int count = p->n ? p->n : 1, rc = GL_OK;

	for (int i = 0; rc == GL_OK && i < count; i++) {
		param_ref(p, i, ref, sizeof(ref));
		fmt_num(num, sizeof(num), p->v[i]);
		snprintf(item, sizeof(item), "%s%s=%s", line[0] ? ";" : "", ref,
			 num);
		if (strlen(line) + strlen(item) > LINE_MAX_CHARS) {
			rc = cmd(io, line, err, errlen);
			snprintf(item, sizeof(item), "%s=%s", ref, num);
			line[0] = '\0';
		}
		strncat(line, item, sizeof(line) - strlen(line) - 1);
	}
	if (rc == GL_OK && line[0])
		rc = cmd(io, line, err, errlen);
	return rc;
}

static int check_param(const struct re_io *io, const struct param *p, char *err,
		       size_t errlen)
{
	char ref[16];
	double got;
	int count = p->n ? p->n : 1, rc = GL_OK;

	for (int i = 0; rc == GL_OK && i < count; i++) {
		param_ref(p, i, ref, sizeof(ref));
		rc = read_err(io, ref, &got, err, errlen);
		if (rc == GL_OK &&
		    !same(p->v[i], got, p->v[i] == floor(p->v[i]), 0)) {
			seterr(err, errlen,
			       "read-back of %s differs: wrote "
			       "%g, read %g",
			       ref, p->v[i], got);
			rc = GL_ERR_MISMATCH;
		}
	}
	return rc;
}

/* The program's vers (dmc/constants.dmc) is the interface this roboelf
 * was built for: the identity stamp only shows that the program is whole,
 * and a whole program of another release may publish other fields. */
static int check_version(const struct re_io *io, char *err, size_t errlen)
{
	double vers = 0, want = strtod(ROBOELF_DMC_VERSION, NULL);
	int rc = read_err(io, "vers", &vers, err, errlen);

	if (rc == GL_OK && fabs(vers - want) > 0.005) {
		seterr(err, errlen,
		       "the controller's program is version %.2f and this "
		       "roboelf needs version %s: load this release's dmc/ "
		       "with galil-load (docs/technician.md)",
		       vers, ROBOELF_DMC_VERSION);
		rc = GL_ERR_MISMATCH;
	}
	return rc;
}

/* After XQ #AUTO,0: state 0 and the program heartbeat advancing. */
static int wait_program(const struct re_io *io, struct re_ctl_info *info,
			char *err, size_t errlen)
{
	int64_t deadline = now_ns(io) + PROGRAM_WAIT_MS * BASE_NS_PER_MS;
	double state = -1, hb0 = -1, hb = -1, mainms = 0;
	int rc;

	do {
		pause_ms(io, POLL_MS);
		rc = re_io_read(io, "state", &state, 0);
		if (rc == GL_OK)
			rc = re_io_read(io, "hbdmc", &hb, 0);
		if (rc == GL_OK && hb0 < 0)
			hb0 = hb;
		if (rc == GL_OK && state == 0 && hb != hb0)
			break;
	} while (now_ns(io) < deadline && (rc == GL_OK || rc == GL_ERR_CTRL));
	if (!(state == 0 && hb != hb0)) {
		seterr(err, errlen,
		       "the controller's program did not start "
		       "(state %g, heartbeat %g): run galil-load again",
		       state, hb);
		return GL_ERR_TIMEOUT;
	}
	rc = read_err(io, "mainms", &mainms, err, errlen);
	info->mainms = (int)mainms;
	return rc == GL_OK ? check_version(io, err, errlen) : rc;
}

int re_ctl_start_program(const struct re_io *io, struct re_ctl_info *info,
			 char *err, size_t errlen)
{
	int rc = cmd(io, "XQ #AUTO,0", err, errlen);

	return rc == GL_OK ? wait_program(io, info, err, errlen) : rc;
}

/* Records carrying the heartbeat every POLL_MS until the program shows
 * @want (GL_OK), a latched fault (RE_FAULT, @fault filled) or @wait_ms
 * passed (GL_ERR_TIMEOUT). @want 0 also accepts a latched state. */
static int wait_state(const struct re_io *io, int want, int wait_ms, long *hbpc,
		      struct re_fault *fault, char *err, size_t errlen)
{
	int64_t deadline = now_ns(io) + (int64_t)wait_ms * BASE_NS_PER_MS;
	struct gl_record rec;
	struct re_za za;
	char prefix[32];
	int rc;

	while (now_ns(io) < deadline) {
		pause_ms(io, POLL_MS);
		*hbpc = (*hbpc + 1) % RE_HBPC_WRAP;
		snprintf(prefix, sizeof(prefix), "hbpc=%ld", *hbpc);
		rc = io->ops->record(io->ud, prefix, &rec, 0);
		if (rc < 0) {
			seterr(err, errlen, "cannot read the data record: %s",
			       gl_strerror(rc));
			return rc;
		}
		if (rec.n_axes < 3 ||
		    re_za_decode(rec.axis[0].za, rec.axis[1].za, rec.axis[2].za,
				 &za) != GL_OK)
			continue;
		if (za.state == want && za.fcode == 0)
			return GL_OK;
		if (za.state == RE_DMC_FAULT && want == RE_DMC_UNARMED)
			return GL_OK;
		if (za.state == RE_DMC_FAULT && fault) {
			double fdet = 0;

			re_io_read(io, "fdet", &fdet, 0);
			re_ctrl_fault(&za, (long long)fdet, fault);
			return RE_FAULT;
		}
	}
	seterr(err, errlen, "the program did not reach state %d within %d ms",
	       want, wait_ms);
	return GL_ERR_TIMEOUT;
}

int re_ctl_write_params(const struct re_io *io, const struct re_config *cfg,
			const struct re_plan *plan, const struct re_calset *cal,
			char *err, size_t errlen)
{
	struct param p[N_PARAMS];
	int n = fill_params(cfg, plan, cal, p), rc = GL_OK;

	/* the program set the sealed ones itself (#SEALIN): only the
	 * session's soft limits and the move time limit are written; every
	 * one is read back and compared with this plan */
	for (int k = 0; rc == GL_OK && k < n; k++)
		if (!strcmp(p[k].name, "srev") || !strcmp(p[k].name, "sfwd") ||
		    !strcmp(p[k].name, "mvto"))
			rc = write_param(io, &p[k], err, errlen);
	for (int k = 0; rc == GL_OK && k < n; k++)
		rc = check_param(io, &p[k], err, errlen);
	return rc;
}

long re_ctl_session(void)
{
	unsigned long r = 0;

	if (getrandom(&r, sizeof(r), GRND_NONBLOCK) != (ssize_t)sizeof(r)) {
		struct timespec ts;

		clock_gettime(CLOCK_REALTIME, &ts);
		r = (unsigned long)ts.tv_nsec * 2654435761UL ^
		    (unsigned long)ts.tv_sec;
	}
	return 1 + (long)(r % (unsigned long)(RE_HBPC_WRAP - 1));
}

int re_ctl_service(const struct re_io *io, long *hbpc, struct re_fault *fault,
		   char *err, size_t errlen)
{
	char line[48];
	int rc;

	/* a new heartbeat with the request: the program judges the request
	 * by the supervisor's last change (docs/dmc-interface.md, #GOON) */
	*hbpc = (*hbpc + 1) % RE_HBPC_WRAP;
	snprintf(line, sizeof(line), "hbpc=%ld;svcreq=1", *hbpc);
	rc = cmd(io, line, err, errlen);
	if (rc == GL_OK)
		rc = wait_state(io, RE_DMC_SERVICE, ARM_WAIT_MS, hbpc, fault,
				err, errlen);
	return rc;
}

/* The check 17 of #PCHK (before service and at arm) wants every axis at
 * rest, TV included: TV averages 256 samples, so it remembers the last
 * move for a while. */
int re_ctl_wait_still(const struct re_io *io, char *err, size_t errlen)
{
	static const char *const tv[RE_AXES] = {"_TVA", "_TVB", "_TVC"};
	int64_t deadline = now_ns(io) + ARM_WAIT_MS * BASE_NS_PER_MS;
	double vstill = 0, v = 0;
	int rc = read_err(io, "vstill", &vstill, err, errlen), i = 0;

	while (rc == GL_OK && i < RE_AXES) {
		rc = read_err(io, tv[i], &v, err, errlen);
		if (rc != GL_OK || fabs(v) <= vstill) {
			i++;
			continue;
		}
		if (now_ns(io) >= deadline) {
			seterr(err, errlen,
			       "axis %c still moving (TV %g counts/s) after "
			       "%d ms of waiting for it to be at rest",
			       AXES[i], v, ARM_WAIT_MS);
			return GL_ERR_TIMEOUT;
		}
		pause_ms(io, POLL_MS);
	}
	return rc;
}

int re_ctl_arm(const struct re_io *io, const struct re_calset *cal, long *hbpc,
	       struct re_fault *fault, char *err, size_t errlen)
{
	struct param p[2] = {{"srev", RE_AXES, {0}}, {"sfwd", RE_AXES, {0}}};
	char line[48];
	int rc = re_ctl_set_limits(io, cal, err, errlen);

	for (int i = 0; i < RE_AXES; i++) {
		p[0].v[i] = floor(cal->axis[i].soft_rev + 0.5);
		p[1].v[i] = floor(cal->axis[i].soft_fwd + 0.5);
	}
	for (int k = 0; rc == GL_OK && k < 2; k++)
		rc = write_param(io, &p[k], err, errlen);
	for (int k = 0; rc == GL_OK && k < 2; k++)
		rc = check_param(io, &p[k], err, errlen);
	if (rc == GL_OK)
		rc = re_ctl_wait_still(io, err, errlen);
	*hbpc = (*hbpc + 1) % RE_HBPC_WRAP;
	snprintf(line, sizeof(line), "hbpc=%ld;armreq=1", *hbpc);
	if (rc == GL_OK)
		rc = cmd(io, line, err, errlen);
	if (rc == GL_OK)
		rc = wait_state(io, RE_DMC_ARMED, ARM_WAIT_MS, hbpc, fault, err,
				errlen);
	return rc;
}

int re_ctl_off(const struct re_io *io, long *hbpc, char *err, size_t errlen)
{
	int rc = cmd(io, "offreq=1", err, errlen);

	if (rc == GL_OK)
		rc = wait_state(io, RE_DMC_UNARMED, OFF_WAIT_MS, hbpc, NULL,
				err, errlen);
	return rc;
}
