/*
 * re_config_schema.c - the configuration's schema: every key, its type, its
 * place in struct re_config, its range and its default; the custom fields
 * (the joystick inputs, the relay's bytes).
 */
#include "re_config_int.h"

#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base_file.h"
#include "base_yaml.h"
#include "gl_err.h"
#include "gl_hash.h"
#include "gl_link.h"
#include "re_rt.h"

const char *const cfg_mode_names[] = {"clinical", "development", NULL};
const char *const cfg_backend_names[] = {"auto", "serialport", "tty", NULL};
const char *const cfg_unit_names[] = {"deg", "mm", NULL};
const char *const cfg_record_names[] = {"poll", "stream", NULL};
const char *const cfg_proto_names[] = {"devantech", "icstation", "lcus",
				       "kmtronic", NULL};
const int cfg_bauds[] = {1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200};

/* ---- lists (custom fields) ---- */

/* seq_items() - @v as a list of exactly @n items (n = 0: 1..max). */
static int seq_items(struct pctx *c, yaml_node_t *v, const char *key,
		     const char *what, int n, int max, int *count)
{
	int k;

	if (v->type != YAML_SEQUENCE_NODE)
		return cfg_type_error(c, v, "a list", key);
	k = (int)(v->data.sequence.items.top - v->data.sequence.items.start);
	if (n && k != n)
		return cfg_fail_at(c, &v->start_mark,
				   "'%s' must list exactly %d %s, got %d", key,
				   n, what, k);
	if (!n && (k < 1 || k > max))
		return cfg_fail_at(c, &v->start_mark,
				   "'%s' must list 1 to %d %s, got %d", key,
				   max, what, k);
	*count = k;
	return GL_OK;
}

static yaml_node_t *seq_item(struct pctx *c, yaml_node_t *v, int i)
{
	return cfg_node_at(c, v->data.sequence.items.start[i]);
}

/* An int list element; stored unchecked (validation checks the range). */
static int seq_int(struct pctx *c, yaml_node_t *seq, int i, const char *key,
		   int min, int max, int *dst)
{
	yaml_node_t *it = seq_item(c, seq, i);
	long long ll;
	int rc;

	if (!it)
		return cfg_fail_at(c, &seq->start_mark, "bad list '%s'", key);
	rc = cfg_get_integer(c, it, key, min, max, INT_MIN, INT_MAX, &ll);
	if (rc)
		return rc;
	*dst = (int)ll;
	cfg_seen_add(c, dst, it->start_mark);
	return GL_OK;
}

static int parse_inputs(struct pctx *c, const struct field *f, yaml_node_t *v,
			void *base)
{
	struct re_config_joystick *j = base;
	int i, n = 0, rc;

	rc = seq_items(c, v, f->key, "inputs", RE_JOY_INPUTS, 0, &n);
	for (i = 0; !rc && i < n; i++)
		rc = seq_int(c, v, i, f->key, 1, 48, &j->inputs[i]);
	return rc;
}

static int parse_window(struct pctx *c, const struct field *f, yaml_node_t *v,
			void *base)
{
	struct re_config_axis *a = base;
	int n = 0, rc;

	rc = seq_items(c, v, f->key, "times (start and end)", 2, 0, &n);
	if (!rc)
		rc = seq_int(c, v, 0, f->key, 0, 60000, &a->accel_start_ms);
	if (!rc)
		rc = seq_int(c, v, 1, f->key, 1, 60000, &a->accel_end_ms);
	return rc;
}

/* A list of bytes, decimal or 0x hex, each 0..255. */
static int parse_bytes(struct pctx *c, const struct field *f, yaml_node_t *v,
		       uint8_t *dst, size_t *len)
{
	yaml_node_t *it;
	unsigned long b;
	char *end;
	int i, n = 0, rc;

	rc = seq_items(c, v, f->key, "bytes", 0, RE_RELAY_CODE_MAX, &n);
	for (i = 0; !rc && i < n; i++) {
		it = seq_item(c, v, i);
		if (!it || it->type != YAML_SCALAR_NODE || cfg_quoted(it) ||
		    !*cfg_scalar(it))
			return cfg_type_error(c, it ? it : v, "a byte", f->key);
		errno = 0;
		b = strtoul(cfg_scalar(it), &end, 0);
		if (*end || errno || cfg_scalar(it)[0] == '-' ||
		    cfg_scalar(it)[0] == '+')
			return cfg_type_error(c, it, "a byte", f->key);
		if (b > 255)
			return cfg_fail_at(
			    c, &it->start_mark,
			    "'%s' bytes must be between 0 and 255, "
			    "got %.*s",
			    f->key, TEXT_SHOWN, cfg_scalar(it));
		dst[i] = (uint8_t)b;
	}
	if (!rc) {
		*len = (size_t)n;
		cfg_seen_add(c, dst, v->start_mark);
	}
	return rc;
}

static int parse_on(struct pctx *c, const struct field *f, yaml_node_t *v,
		    void *base)
{
	struct re_config_relay *r = base;

	return parse_bytes(c, f, v, r->on, &r->on_len);
}

static int parse_off(struct pctx *c, const struct field *f, yaml_node_t *v,
		     void *base)
{
	struct re_config_relay *r = base;

	return parse_bytes(c, f, v, r->off, &r->off_len);
}

static const struct field explicit_fields[] = {
    {"on", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_on},
    {"off", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_off},
    {NULL, FT_INT, 0, 0, 0, 0, NULL, NULL},
};

/* protocol: a preset name, or {on: [bytes], off: [bytes]}. */
static int parse_protocol(struct pctx *c, const struct field *f, yaml_node_t *v,
			  void *base)
{
	struct re_config_relay *r = base;
	int e, rc;

	if (v->type == YAML_MAPPING_NODE) {
		r->on_len = r->off_len = 0;
		rc = cfg_parse_map(c, v, explicit_fields, r, f->key);
		if (rc)
			return rc;
		if (!r->on_len || !r->off_len)
			return cfg_fail_at(
			    c, &v->start_mark,
			    "'%s' needs both 'on' and 'off' bytes", f->key);
		r->protocol = RE_RELAY_EXPLICIT;
	} else {
		rc = cfg_get_enum(c, v, f->key, cfg_proto_names, &e);
		if (rc)
			return rc;
		r->protocol = (enum re_relay_proto)e;
	}
	cfg_seen_add(c, &r->protocol, v->start_mark);
	return GL_OK;
}

/* ---- the schema ---- */

/* clang-format off */
#define I(s, m, lo, hi) { #m, FT_INT, offsetof(s, m), lo, hi, 0, NULL, NULL }
#define L(s, m, lo, hi) { #m, FT_LONG, offsetof(s, m), lo, hi, 0, NULL, NULL }
#define D(s, m, lo, hi) \
	{ #m, FT_DOUBLE, offsetof(s, m), lo, hi, 0, NULL, NULL }
#define B(s, m) { #m, FT_BOOL, offsetof(s, m), 0, 0, 0, NULL, NULL }
#define S(s, m, req) \
	{ #m, FT_STR, offsetof(s, m), req, 0, sizeof(((s *)0)->m), NULL, NULL }
#define E(s, m, names, max) \
	{ #m, FT_ENUM, offsetof(s, m), 0, max, 0, names, NULL }
#define M(s, m, tab) { #m, FT_MAP, offsetof(s, m), 0, 0, 0, tab, NULL }
#define END { NULL, FT_INT, 0, 0, 0, 0, NULL, NULL }

/* YAML key -> member with another name (units in the C names only). */
#define IK(key, s, m, lo, hi) \
	{ key, FT_INT, offsetof(s, m), lo, hi, 0, NULL, NULL }

static const struct field controller_fields[] = {
	S(struct re_config_controller, address, 1),
	S(struct re_config_controller, model, 1),
	I(struct re_config_controller, timeout_ms, 5, 10000),
	I(struct re_config_controller, connect_timeout_ms, 100, 60000),
	I(struct re_config_controller, power_output, 0, 8),
	E(struct re_config_controller, record, cfg_record_names, 1),
	I(struct re_config_controller, udp_port, 1, 65535),
	END,
};

static const struct field relay_fields[] = {
	S(struct re_config_relay, port_clinical, 0),
	S(struct re_config_relay, port_development, 0),
	S(struct re_config_relay, serial, 0),
	{ "protocol", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_protocol },
	I(struct re_config_relay, channel, 1, 8),
	E(struct re_config_relay, backend, cfg_backend_names, 2),
	I(struct re_config_relay, baud, 1200, 115200),
	I(struct re_config_relay, write_timeout_ms, 1, 1000),
	I(struct re_config_relay, off_deadline_ms, 10, 1000),
	B(struct re_config_relay, readback),
	I(struct re_config_relay, readback_timeout_ms, 10, 5000),
	S(struct re_config_relay, icstation_state, 1),
	END,
};

static const struct field watchdog_fields[] = {
	D(struct re_config_watchdog, noncritical_factor, 1.0, 10.0),
	D(struct re_config_watchdog, critical_factor, 1.0, 20.0),
	I(struct re_config_watchdog, controller_timeout_ms, 20, 5000),
	END,
};

static const struct field joystick_fields[] = {
	{ "inputs", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_inputs },
	B(struct re_config_joystick, active_low),
	I(struct re_config_joystick, invalid_timeout_ms, 50, 5000),
	END,
};

static const struct field encfail_fields[] = {
	B(struct re_config_encoder_failure, enabled),
	I(struct re_config_encoder_failure, time_samples, 2, 32000),
	D(struct re_config_encoder_failure, torque_v, 0.0, 9.9982),
	END,
};

static const struct field analog_fields[] = {
	I(struct re_config_analog, input, 1, 8),
	D(struct re_config_analog, expected_range_v, 0.01, 20.0),
	D(struct re_config_analog, range_tolerance, 0.0, 1.0),
	D(struct re_config_analog, reverse_v, -10.0, 10.0),
	D(struct re_config_analog, forward_v, -10.0, 10.0),
	D(struct re_config_analog, absolute_tolerance_v, 0.001, 5.0),
	END,
};

const struct field cfg_axis_fields[] = {
	S(struct re_config_axis, name, 1),
	IK("vmax", struct re_config_axis, vmax_cps, 1, 10000000),
	IK("vmin", struct re_config_axis, vmin_cps, 1, 10000000),
	{ "accel_window_ms", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_window },
	I(struct re_config_axis, step_counts, 1, 1000000),
	I(struct re_config_axis, travel_counts, 4, 100000000),
	D(struct re_config_axis, travel_tolerance, 0.0, 1.0),
	D(struct re_config_axis, kp, 0.0, 1023.875),
	D(struct re_config_axis, ki, 0.0, 255.999),
	D(struct re_config_axis, kd, 0.0, 4095.875),
	D(struct re_config_axis, torque_limit_v, 0.0, 9.9982),
	I(struct re_config_axis, position_error_limit_counts, 1, INT_MAX),
	B(struct re_config_axis, off_on_error),
	M(struct re_config_axis, encoder_failure, encfail_fields),
	M(struct re_config_axis, analog, analog_fields),
	D(struct re_config_axis, allowed_error, 0.0, 10.0),
	I(struct re_config_axis, persistence_cycles, 1, 1000),
	D(struct re_config_axis, monotonic_margin_v, 0.0, 1.0),
	E(struct re_config_axis, unit, cfg_unit_names, 1),
	D(struct re_config_axis, counts_per_unit, 0.0, 10000000.0),
	END,
};

static const struct field calibration_fields[] = {
	S(struct re_config_calibration, file, 1),
	B(struct re_config_calibration, backup),
	I(struct re_config_calibration, backoff_counts, 1, 1000000),
	I(struct re_config_calibration, move_timeout_ms, 100, 600000),
	I(struct re_config_calibration, travel_cps, 0, 10000000),
	I(struct re_config_calibration, seek_cps, 0, 10000000),
	I(struct re_config_calibration, near_margin_counts, 0, 10000000),
	END,
};

static const struct field log_fields[] = {
	S(struct re_config_log, path, 1),
	L(struct re_config_log, max_bytes, 4096, 1073741824),
	I(struct re_config_log, keep, 1, 9),
	END,
};

static const struct field recorder_fields[] = {
	D(struct re_config_recorder, seconds, 1, 120),
	D(struct re_config_recorder, after_fault_s, 0, 60),
	S(struct re_config_recorder, dir, 0),
	END,
};

static const struct field realtime_fields[] = {
	I(struct re_config_realtime, priority, 0, 99),
	I(struct re_config_realtime, cpu, -1, 1023),
	B(struct re_config_realtime, lock_memory),
	END,
};

static int parse_axes(struct pctx *c, const struct field *f, yaml_node_t *v,
		      void *base)
{
	struct re_config *cfg = base;
	yaml_node_t *it;
	int i, n = 0, rc;

	rc = seq_items(c, v, f->key, "axes (A, B, C)", RE_AXES, 0, &n);
	for (i = 0; !rc && i < n; i++) {
		it = seq_item(c, v, i);
		if (!it)
			return cfg_fail_at(c, &v->start_mark, "bad list 'axes'");
		rc = cfg_parse_map(c, it, cfg_axis_fields, &cfg->axes[i], "axes");
		if (!rc && !cfg_seen_mark(c, &cfg->axes[i].vmin_cps))
			cfg->axes[i].vmin_cps = cfg->axes[i].vmax_cps / 4;
	}
	return rc;
}

const struct field cfg_root_fields[] = {
	E(struct re_config, mode, cfg_mode_names, 1),
	I(struct re_config, period_ms, 2, 100),
	M(struct re_config, controller, controller_fields),
	M(struct re_config, relay, relay_fields),
	M(struct re_config, watchdog, watchdog_fields),
	M(struct re_config, joystick, joystick_fields),
	{ "axes", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_axes },
	M(struct re_config, calibration, calibration_fields),
	M(struct re_config, log, log_fields),
	M(struct re_config, recorder, recorder_fields),
	M(struct re_config, realtime, realtime_fields),
	END,
};
/* clang-format on */

/* ---- defaults ---- */

static void axis_defaults(struct re_config_axis *a, int i)
{
	static const char *const names[RE_AXES] = {"A", "B", "C"};

	memset(a, 0, sizeof(*a));
	snprintf(a->name, sizeof(a->name), "%s", names[i]);
	a->vmax_cps = 8000;
	a->vmin_cps = a->vmax_cps / 4;
	a->accel_start_ms = 500;
	a->accel_end_ms = 2000;
	a->step_counts = 1000;
	a->travel_counts = i == 2 ? 80000 : 100000;
	a->travel_tolerance = 0.1;
	a->kp = 6.0;
	a->ki = 1.0;
	a->kd = 64.0;
	a->torque_limit_v = 5.0;
	a->position_error_limit_counts = 500;
	a->off_on_error = true;
	a->encoder_failure.enabled = true;
	a->encoder_failure.time_samples = 100;
	a->encoder_failure.torque_v = 2.0;
	a->analog.input = i + 1;
	a->analog.expected_range_v = 4.0;
	a->analog.range_tolerance = 0.1;
	a->analog.reverse_v = 0.5;
	a->analog.forward_v = 4.5;
	a->analog.absolute_tolerance_v = 0.25;
	a->allowed_error = 0.5;
	a->persistence_cycles = 1;
	a->monotonic_margin_v = 0.005;
	a->unit = i == 2 ? RE_UNIT_MM : RE_UNIT_DEG;
	a->counts_per_unit = 0; /* not known: the console shows counts */
}

const char *re_record_name(enum re_record r)
{
	return r == RE_RECORD_STREAM ? "stream" : "poll";
}

const char *re_unit_name(enum re_unit u)
{
	return u == RE_UNIT_MM ? "mm" : "deg";
}

static void relay_defaults(struct re_config_relay *r)
{
	memset(r, 0, sizeof(*r));
	snprintf(r->port_development, sizeof(r->port_development), "%s",
		 "/tmp/roboelf-relay");
	r->protocol = RE_RELAY_DEVANTECH;
	r->channel = 1;
	r->backend = RE_RELAY_BACKEND_AUTO;
	r->baud = 9600;
	r->write_timeout_ms = 100;
	r->off_deadline_ms = 50; /* docs/config.md: 9600 baud, USB, read-back */
	r->readback = true; /* devantech; see auto_defaults() in re_config.c */
	r->readback_timeout_ms = 500;
	snprintf(r->icstation_state, sizeof(r->icstation_state), "%s",
		 "/tmp/roboelf-icstation.state");
}

void re_config_defaults(struct re_config *out)
{
	static const int joy[RE_JOY_INPUTS] = {1, 2, 3,	 4,  5,	 6,
					       7, 8, 17, 18, 19, 20};
	int i;

	memset(out, 0, sizeof(*out));
	out->mode = RE_MODE_CLINICAL;
	out->period_ms = 50;
	snprintf(out->controller.address, sizeof(out->controller.address), "%s",
		 "127.0.0.1:23023");
	snprintf(out->controller.model, sizeof(out->controller.model), "%s",
		 "DMC4030");
	out->controller.timeout_ms = 100;
	out->controller.connect_timeout_ms = 2000;
	out->controller.record = RE_RECORD_POLL;
	out->controller.udp_port = 60007; /* galil-notes 1.1 */
	relay_defaults(&out->relay);
	out->watchdog.noncritical_factor = 1.5;
	out->watchdog.critical_factor = 2.5;
	out->watchdog.controller_timeout_ms = 200;
	memcpy(out->joystick.inputs, joy, sizeof(joy));
	out->joystick.active_low = false;
	out->joystick.invalid_timeout_ms = 500;
	for (i = 0; i < RE_AXES; i++)
		axis_defaults(&out->axes[i], i);
	snprintf(out->calibration.file, sizeof(out->calibration.file), "%s",
		 "roboelf-calibration.txt");
	out->calibration.backup = true;
	out->calibration.backoff_counts = 500;
	out->calibration.move_timeout_ms = 30000;
	out->calibration.near_margin_counts = 2000;
	snprintf(out->log.path, sizeof(out->log.path), "%s", "roboelf.log");
	out->log.max_bytes = 10L * 1024 * 1024;
	out->log.keep = 5;
	out->recorder.seconds = 30;
	out->recorder.after_fault_s = 2;
	out->realtime.priority = 50;
	out->realtime.cpu = -1;
	out->realtime.lock_memory = true;
}
