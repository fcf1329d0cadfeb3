/*
 * re_config_check.c - the validation of a whole configuration: ranges and
 * the rules across fields (axes, joystick, watchdog, relay, clinical mode,
 * calibration, real time), with the position of the value concerned.
 */
#include "re_config_int.h"

#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base_file.h"
#include "base_yaml.h"
#include "gl_err.h"
#include "gl_hash.h"
#include "gl_link.h"
#include "re_bind.h"
#include "re_rt.h"

/* ---- validation ---- */

static int check_num(struct pctx *c, const struct field *f, const void *dst)
{
	char got[32];
	double v;

	if (f->type == FT_INT)
		v = *(const int *)dst;
	else if (f->type == FT_LONG)
		v = (double)*(const long *)dst;
	else
		v = *(const double *)dst;
	if (v >= f->min && v <= f->max && !isnan(v))
		return GL_OK;
	return cfg_range_error(c, cfg_later_mark(c, dst, NULL), f->key, f->min,
			       f->max, cfg_num_text(v, got, sizeof(got)));
}

/* cfg_check_table() - ranges of the plain fields of @tab over @base. */
int cfg_check_table(struct pctx *c, const struct field *tab, const void *base)
{
	const char *dst;
	int rc = GL_OK, e;

	for (; !rc && tab->key; tab++) {
		dst = (const char *)base + tab->off;
		switch (tab->type) {
		case FT_INT:
		case FT_LONG:
		case FT_DOUBLE: rc = check_num(c, tab, dst); break;
		case FT_STR:
			if (tab->min > 0 && !dst[0])
				rc = cfg_fail_at(
				    c, cfg_later_mark(c, dst, NULL),
				    "'%s' must not be empty", tab->key);
			break;
		case FT_ENUM:
			memcpy(&e, dst, sizeof(e));
			if (e < 0 || e > (int)tab->max)
				rc = cfg_fail_at(
				    c, cfg_later_mark(c, dst, NULL),
				    "'%s' has an invalid value", tab->key);
			break;
		case FT_MAP: rc = cfg_check_table(c, tab->aux, dst); break;
		default: break;
		}
	}
	return rc;
}

/* The encoder-failure detection and the potentiometer's absolute values. */
static int check_axis_more(struct pctx *c, const struct re_config_axis *a)
{
	const struct re_config_analog *an = &a->analog;
	double span = an->forward_v - an->reverse_v;

	/* DMC-4000 command reference, OT: a non-zero KI is necessary for the
	 * encoder-failure detection (OA's page: recommended) */
	if (a->encoder_failure.enabled && a->ki <= 0)
		return cfg_fail_at(
		    c, cfg_later_mark(c, &a->ki, &a->encoder_failure),
		    "'encoder_failure' needs a non-zero 'ki': the "
		    "controller's encoder-failure detection (OA, "
		    "OT) does not work with KI 0");
	if (span <= 2 * an->absolute_tolerance_v)
		return cfg_fail_at(
		    c, cfg_later_mark(c, &an->forward_v, &an->reverse_v),
		    "'forward_v' (%g) must be above 'reverse_v' "
		    "(%g) by more than twice "
		    "'absolute_tolerance_v' (%g)",
		    an->forward_v, an->reverse_v, an->absolute_tolerance_v);
	if ((cfg_seen_mark(c, &an->forward_v) ||
	     cfg_seen_mark(c, &an->reverse_v)) &&
	    fabs(span - an->expected_range_v) >
		an->range_tolerance * an->expected_range_v)
		return cfg_fail_at(
		    c, cfg_later_mark(c, &an->forward_v, &an->reverse_v),
		    "'forward_v' - 'reverse_v' (%g V) must agree "
		    "with 'expected_range_v' (%g V) within "
		    "'range_tolerance'",
		    span, an->expected_range_v);
	return GL_OK;
}

static int check_axis(struct pctx *c, const struct re_config_axis *a)
{
	char got[32];
	int rc = cfg_check_table(c, cfg_axis_fields, a);

	if (rc)
		return rc;
	if (a->vmin_cps > a->vmax_cps)
		return cfg_fail_at(
		    c, cfg_later_mark(c, &a->vmin_cps, &a->vmax_cps),
		    "'vmin' (%d) must not exceed 'vmax' (%d)", a->vmin_cps,
		    a->vmax_cps);
	if (a->accel_start_ms < 0 || a->accel_start_ms > 60000)
		return cfg_range_error(
		    c, cfg_later_mark(c, &a->accel_start_ms, NULL),
		    "accel_window_ms", 0, 60000,
		    cfg_num_text(a->accel_start_ms, got, sizeof(got)));
	if (a->accel_end_ms <= a->accel_start_ms || a->accel_end_ms > 60000)
		return cfg_fail_at(
		    c, cfg_later_mark(c, &a->accel_end_ms, &a->accel_start_ms),
		    "'accel_window_ms' end (%d) must be after its "
		    "start (%d) and at most 60000",
		    a->accel_end_ms, a->accel_start_ms);
	/* With position tracking the target is one step ahead of the
	 * encoder, so a jammed axis never builds an error above the step: ER
	 * at or above it would never trip (the DMC refuses it too, check 7). */
	if (a->position_error_limit_counts >= a->step_counts)
		return cfg_fail_at(
		    c,
		    cfg_later_mark(c, &a->position_error_limit_counts,
				   &a->step_counts),
		    "'position_error_limit_counts' (%d) must be below "
		    "'step_counts' (%d)",
		    a->position_error_limit_counts, a->step_counts);
	if (a->travel_counts / a->step_counts < 4 ||
	    a->travel_counts / a->step_counts > RE_CONFIG_POINTS_MAX)
		return cfg_fail_at(
		    c, cfg_later_mark(c, &a->travel_counts, &a->step_counts),
		    "'travel_counts' (%d) must be 4 to %d times "
		    "'step_counts' (%d)",
		    a->travel_counts, RE_CONFIG_POINTS_MAX, a->step_counts);
	return check_axis_more(c, a);
}

/* Axis names and analog inputs must differ between axes. */
static int check_axes_distinct(struct pctx *c, const struct re_config *cfg)
{
	const struct re_config_axis *a, *b;
	int i, j;

	for (j = 1; j < RE_AXES; j++) {
		for (i = 0; i < j; i++) {
			a = &cfg->axes[i];
			b = &cfg->axes[j];
			if (!strcmp(a->name, b->name))
				return cfg_fail_at(
				    c, cfg_later_mark(c, a->name, b->name),
				    "axis name '%s' is used twice", b->name);
			if (a->analog.input == b->analog.input)
				return cfg_fail_at(
				    c,
				    cfg_later_mark(c, &a->analog.input,
						   &b->analog.input),
				    "analog input %d is used by axes "
				    "'%s' and '%s'",
				    b->analog.input, a->name, b->name);
		}
	}
	return GL_OK;
}

static int check_joystick(struct pctx *c, const struct re_config_joystick *j)
{
	char got[16];
	int i, k;

	for (i = 0; i < RE_JOY_INPUTS; i++) {
		if (j->inputs[i] < 1 || j->inputs[i] > 48) {
			snprintf(got, sizeof(got), "%d", j->inputs[i]);
			return cfg_range_error(
			    c, cfg_later_mark(c, &j->inputs[i], NULL), "inputs",
			    1, 48, got);
		}
		/* DMC-4000 command reference, @IN: "Inputs 9-16 only valid
		 * for 5-8 axis controller" - a DMC-4030 has none */
		if (j->inputs[i] >= 9 && j->inputs[i] <= 16)
			return cfg_fail_at(
			    c, cfg_later_mark(c, &j->inputs[i], NULL),
			    "'inputs' entry %d is input %d: a "
			    "DMC-4030 has no inputs 9 to 16 (use "
			    "1..8 or 17..48)",
			    i + 1, j->inputs[i]);
		for (k = 0; k < i; k++)
			if (j->inputs[k] == j->inputs[i])
				return cfg_fail_at(
				    c,
				    cfg_later_mark(c, &j->inputs[i],
						   &j->inputs[k]),
				    "'inputs' lists input %d twice "
				    "(entries %d and %d)",
				    j->inputs[i], k + 1, i + 1);
	}
	return GL_OK;
}

static int check_watchdog(struct pctx *c, const struct re_config *cfg)
{
	const struct re_config_watchdog *w = &cfg->watchdog;
	double crit_ms = w->critical_factor * cfg->period_ms;

	if (w->critical_factor <= w->noncritical_factor)
		return cfg_fail_at(
		    c,
		    cfg_later_mark(c, &w->critical_factor,
				   &w->noncritical_factor),
		    "'critical_factor' (%g) must be greater than "
		    "'noncritical_factor' (%g)",
		    w->critical_factor, w->noncritical_factor);
	if (w->controller_timeout_ms < crit_ms)
		return cfg_fail_at(
		    c,
		    cfg_later_mark(c, &w->controller_timeout_ms,
				   cfg_seen_mark(c, &w->critical_factor)
				       ? (const void *)&w->critical_factor
				       : (const void *)&cfg->period_ms),
		    "'controller_timeout_ms' (%d) must be at least "
		    "'critical_factor' x 'period_ms' (%g)",
		    w->controller_timeout_ms, crit_ms);
	return GL_OK;
}

static bool baud_ok(int baud)
{
	size_t i;

	for (i = 0; i < sizeof(cfg_bauds) / sizeof(cfg_bauds[0]); i++)
		if (cfg_bauds[i] == baud)
			return true;
	return false;
}

/* A serial number set is one a udev rule can hold (re_bind.h): the one
 * 'roboelf-tech bind-relay' can bind. */
static int check_serial(struct pctx *c, const struct re_config_relay *r)
{
	char why[RE_BIND_ERR_MAX];

	if (!r->serial[0] || !re_bind_serial_check(r->serial, why, sizeof(why)))
		return GL_OK;
	return cfg_fail_at(c, cfg_later_mark(c, r->serial, NULL),
			   "'serial': %s", why);
}

static int check_relay(struct pctx *c, const struct re_config *cfg)
{
	const struct re_config_relay *r = &cfg->relay;

	if (!baud_ok(r->baud))
		return cfg_fail_at(
		    c, cfg_later_mark(c, &r->baud, NULL),
		    "'baud' must be 1200, 2400, 4800, 9600, 19200, "
		    "38400, 57600 or 115200, got %d",
		    r->baud);
	if (r->protocol == RE_RELAY_EXPLICIT &&
	    (!r->on_len || r->on_len > RE_RELAY_CODE_MAX || !r->off_len ||
	     r->off_len > RE_RELAY_CODE_MAX))
		return cfg_fail_at(
		    c, cfg_later_mark(c, r->on, r->off),
		    "'on' and 'off' must list 1 to %d bytes each",
		    RE_RELAY_CODE_MAX);
	if (r->protocol == RE_RELAY_EXPLICIT && r->on_len == r->off_len &&
	    !memcmp(r->on, r->off, r->on_len))
		return cfg_fail_at(c, cfg_later_mark(c, r->on, r->off),
				   "'on' and 'off' bytes must differ");
	if (r->readback && r->protocol != RE_RELAY_DEVANTECH)
		return cfg_fail_at(
		    c, cfg_later_mark(c, &r->readback, &r->protocol),
		    "'readback' needs the devantech protocol");
	if (cfg->mode == RE_MODE_DEVELOPMENT && !r->port_development[0])
		return cfg_fail_at(
		    c, cfg_later_mark(c, r->port_development, &cfg->mode),
		    "'port_development' must be set in "
		    "development mode");
	return check_serial(c, r);
}

static bool is_loopback(const char *addr)
{
	return !strncmp(addr, "127.", 4) || !strncmp(addr, "localhost", 9) ||
	       !strncmp(addr, "[::1]", 5) || !strcmp(addr, "::1");
}

/* The values only a site can know (the site template's FILL-INs), by
 * their offset in the configuration; the axes' for each axis. */
struct site_key {
	const char *key;
	size_t off;
};

static const struct site_key site_top[] = {
    {"controller.address", offsetof(struct re_config, controller.address)},
    {"controller.power_output",
     offsetof(struct re_config, controller.power_output)},
    {"relay.port_clinical", offsetof(struct re_config, relay.port_clinical)},
    {"relay.serial", offsetof(struct re_config, relay.serial)},
    {"relay.protocol", offsetof(struct re_config, relay.protocol)},
    {"relay.channel", offsetof(struct re_config, relay.channel)},
    {"joystick.inputs", offsetof(struct re_config, joystick.inputs)},
    {"joystick.active_low", offsetof(struct re_config, joystick.active_low)},
};

static const struct site_key site_axis[] = {
    {"vmax", offsetof(struct re_config_axis, vmax_cps)},
    {"travel_counts", offsetof(struct re_config_axis, travel_counts)},
    {"kp", offsetof(struct re_config_axis, kp)},
    {"ki", offsetof(struct re_config_axis, ki)},
    {"kd", offsetof(struct re_config_axis, kd)},
    {"torque_limit_v", offsetof(struct re_config_axis, torque_limit_v)},
    {"analog.expected_range_v",
     offsetof(struct re_config_axis, analog.expected_range_v)},
    {"analog.reverse_v", offsetof(struct re_config_axis, analog.reverse_v)},
    {"analog.forward_v", offsetof(struct re_config_axis, analog.forward_v)},
};

#define N_TOP  (int)(sizeof(site_top) / sizeof(site_top[0]))
#define N_AXIS (int)(sizeof(site_axis) / sizeof(site_axis[0]))

/* The @i-th site key's name in @buf and its field in @cfg (NULL: none). */
static const void *site_field(const struct re_config *cfg, int i, char *buf,
			      size_t cap)
{
	const struct site_key *k;
	int ax = 0;

	if (i < 0 || i >= N_TOP + RE_AXES * N_AXIS)
		return NULL;
	if (i < N_TOP) {
		k = &site_top[i];
		snprintf(buf, cap, "%s", k->key);
		return (const char *)cfg + k->off;
	}
	ax = (i - N_TOP) / N_AXIS;
	k = &site_axis[(i - N_TOP) % N_AXIS];
	snprintf(buf, cap, "axes[%d].%s", ax, k->key);
	return (const char *)&cfg->axes[ax] + k->off;
}

const char *re_config_site_key(int i, char *buf, size_t cap)
{
	static struct re_config any;

	if (!buf || !cap)
		return NULL;
	return site_field(&any, i, buf, cap) ? buf : NULL;
}

/*
 * Clinical, from a file: every value only the site can know is written
 * there. The template has them as FILL-IN; a line deleted to silence that
 * refusal would otherwise take the built-in default (galil-sim's robot).
 * All of them at once, like the FILL-INs.
 */
static int check_site_keys(struct pctx *c, const struct re_config *cfg)
{
	char key[64], list[RE_CONFIG_ERR_MAX / 2] = "";
	size_t used = 0;
	int n = 0;
	const void *f;

	if (cfg->mode != RE_MODE_CLINICAL || !c->doc)
		return GL_OK;
	for (int i = 0; (f = site_field(cfg, i, key, sizeof(key))); i++) {
		int w;

		if (cfg_seen_mark(c, f))
			continue;
		n++;
		w = snprintf(list + used, sizeof(list) - used, "%s'%s'",
			     used ? ", " : "", key);
		if (w > 0 && used + (size_t)w < sizeof(list))
			used += (size_t)w;
	}
	if (!n)
		return GL_OK;
	return cfg_fail_at(c, cfg_seen_mark(c, &cfg->mode),
			   "clinical mode: %d value%s of this site %s not "
			   "written: %s. Each is a value of this robot "
			   "(config/roboelf-site.yaml has it as FILL-IN); "
			   "left out, it would take the built-in default, "
			   "which is galil-sim's robot",
			   n, n == 1 ? "" : "s", n == 1 ? "is" : "are", list);
}

/*
 * Clinical mode: a real relay through libserialport, on a device under
 * /dev (not a pseudo-terminal), and a controller that is not the local
 * simulator.
 */
static int check_clinical(struct pctx *c, const struct re_config *cfg)
{
	const struct re_config_relay *r = &cfg->relay;
	const char *port = r->port_clinical;

	if (cfg->mode != RE_MODE_CLINICAL)
		return GL_OK;
	if (!port[0])
		return cfg_fail_at(
		    c, cfg_later_mark(c, port, &cfg->mode),
		    "'port_clinical' must be set in clinical mode");
	if (strncmp(port, "/dev/", 5) || !strncmp(port, "/dev/pts/", 9) ||
	    !strcmp(port, "/dev/ptmx") || strstr(port, "/../"))
		return cfg_fail_at(
		    c, cfg_later_mark(c, port, &cfg->mode),
		    "'port_clinical' must be a serial device under "
		    "/dev, got '%.*s'",
		    TEXT_SHOWN, port);
	if (r->backend == RE_RELAY_BACKEND_TTY)
		return cfg_fail_at(
		    c, cfg_later_mark(c, &r->backend, &cfg->mode),
		    "'backend' tty is not allowed in clinical mode "
		    "(a pseudo-terminal is never a real relay)");
	if (is_loopback(cfg->controller.address))
		return cfg_fail_at(
		    c, cfg_later_mark(c, cfg->controller.address, &cfg->mode),
		    "'address' %.*s is a loopback address; clinical "
		    "mode needs the real controller",
		    TEXT_SHOWN, cfg->controller.address);
	if (!r->serial[0])
		return cfg_fail_at(
		    c, cfg_later_mark(c, r->serial, &cfg->mode),
		    "'serial' must be set in clinical mode: the relay "
		    "board's USB serial number, which 'roboelf-tech "
		    "bind-relay' prints");
	return check_site_keys(c, cfg);
}

/* An open potentiometer wiper reads about 0 V: the lowest reading the
 * controller accepts (potlo, docs/supervisor.md) must stay above this, so
 * that an open wiper is a fault (16), not an axis at its end stop. */
#define POT_OPEN_V 0.1

/*
 * The slow speed near a switch is not faster than the travel speed; the
 * margin past a switch keeps an open potentiometer detectable.
 */
static int check_calibration(struct pctx *c, const struct re_config *cfg)
{
	const struct re_config_calibration *k = &cfg->calibration;

	if (k->seek_cps && k->travel_cps && k->seek_cps > k->travel_cps)
		return cfg_fail_at(
		    c, cfg_later_mark(c, &k->seek_cps, &k->travel_cps),
		    "'seek_cps' (%d) must not exceed 'travel_cps' "
		    "(%d): it is the slow speed near a switch",
		    k->seek_cps, k->travel_cps);
	for (int i = 0; i < RE_AXES; i++) {
		const struct re_config_axis *a = &cfg->axes[i];
		const struct re_config_analog *an = &a->analog;
		double gain =
		    (an->forward_v - an->reverse_v) / (double)a->travel_counts;
		double room =
		    an->reverse_v - an->absolute_tolerance_v - POT_OPEN_V;
		double lo = room + POT_OPEN_V - k->near_margin_counts * gain;

		if (an->reverse_v <= POT_OPEN_V || lo >= POT_OPEN_V)
			continue;
		return cfg_fail_at(
		    c,
		    cfg_later_mark(c, &k->near_margin_counts, &an->reverse_v),
		    "axis '%s': the lowest potentiometer reading allowed "
		    "('reverse_v' - 'absolute_tolerance_v' - "
		    "'near_margin_counts' x %.3g V/count = %.3f V) is below "
		    "%.1f V, so an open potentiometer (0 V) would look like "
		    "the axis at its end stop: make 'near_margin_counts' at "
		    "most %.0f",
		    a->name, gain, lo, POT_OPEN_V,
		    room > 0 ? floor(room / gain + 1e-9) : 0.0);
	}
	return GL_OK;
}

/* The controller address as the link will read it (gl_link_addr_split):
 * a bad port is refused here, before anything is opened. */
static int check_address(struct pctx *c, const struct re_config *cfg)
{
	char host[RE_ADDR_MAX], port[16];

	if (gl_link_addr_split(cfg->controller.address, host, sizeof(host),
			       port, sizeof(port)) == GL_OK)
		return GL_OK;
	return cfg_fail_at(
	    c, cfg_later_mark(c, cfg->controller.address, &cfg->mode),
	    "'address' '%.*s' is not HOST, HOST:PORT or [V6]:PORT "
	    "with a port 1..65535",
	    TEXT_SHOWN, cfg->controller.address);
}

/* The time after a fault is recorded into the same ring: less than it. */
static int check_recorder(struct pctx *c, const struct re_config_recorder *r)
{
	if (r->after_fault_s < r->seconds)
		return GL_OK;
	return cfg_fail_at(c, cfg_later_mark(c, &r->seconds, &r->after_fault_s),
			   "'after_fault_s' (%g s) must be less than 'seconds' "
			   "(%g s): both are in the one ring",
			   r->after_fault_s, r->seconds);
}

/* A period under RE_RT_MIN_MS_WITHOUT needs SCHED_FIFO asked for. */
static int check_realtime(struct pctx *c, const struct re_config *cfg)
{
	if (cfg->period_ms >= RE_RT_MIN_MS_WITHOUT ||
	    cfg->realtime.priority > 0)
		return GL_OK;
	return cfg_fail_at(
	    c, cfg_later_mark(c, &cfg->period_ms, &cfg->realtime.priority),
	    "'period_ms' %d needs real-time scheduling: set "
	    "'realtime.priority' 1..99 or a period of %d ms or more",
	    cfg->period_ms, RE_RT_MIN_MS_WITHOUT);
}

int cfg_check_all(struct pctx *c, const struct re_config *cfg)
{
	int i, rc = cfg_check_table(c, cfg_root_fields, cfg);

	if (!rc)
		rc = check_address(c, cfg);
	for (i = 0; !rc && i < RE_AXES; i++)
		rc = check_axis(c, &cfg->axes[i]);
	if (!rc)
		rc = check_axes_distinct(c, cfg);
	if (!rc)
		rc = check_calibration(c, cfg);
	if (!rc)
		rc = check_joystick(c, &cfg->joystick);
	if (!rc)
		rc = check_watchdog(c, cfg);
	if (!rc)
		rc = check_relay(c, cfg);
	if (!rc)
		rc = check_clinical(c, cfg);
	if (!rc)
		rc = check_recorder(c, &cfg->recorder);
	if (!rc)
		rc = check_realtime(c, cfg);
	return rc;
}

int re_config_validate(const struct re_config *cfg, char *err, size_t errlen)
{
	struct pctx c;

	memset(&c, 0, sizeof(c));
	c.err = err;
	c.errlen = errlen;
	if (err && errlen)
		err[0] = '\0';
	if (!cfg)
		return GL_ERR_ARG;
	return cfg_check_all(&c, cfg);
}
