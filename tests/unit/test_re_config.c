/*
 * test_re_config.c - the configuration loader (pc/config/re_config.c).
 *
 * Every malformed file in tests/data/config/bad_*.yaml is listed below with
 * the exact message and position it must produce; the default file must load
 * and equal the documented defaults; every field must survive a round trip
 * through YAML text; nothing is applied on error. The site template
 * config/roboelf-site.yaml is refused with every FILL-IN listed, and loads
 * once they are filled in.
 */
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "gl_err.h"
#include "re_config.h"

#define DATA_DIR "tests/data/config/"

struct bad_case {
	const char *file;    /* under DATA_DIR */
	int line, column;    /* 1-based */
	const char *message; /* after "FILE:LINE:COLUMN: " */
};

static const struct bad_case bad_cases[] = {
    {"bad_address_port.yaml", 2, 12,
     "'address' '127.0.0.1:99999' is not HOST, HOST:PORT or [V6]:PORT with a "
     "port 1..65535"},
    {"bad_analog_shared.yaml", 6, 14,
     "analog input 1 is used by axes 'A' and 'B'"},
    {"bad_axes_count.yaml", 3, 3,
     "'axes' must list exactly 3 axes (A, B, C), got 2"},
    {"bad_axes_not_list.yaml", 3, 3,
     "expected a list for 'axes', got a mapping"},
    {"bad_axis_name_long.yaml", 3, 11, "'name' is too long (at most 15 bytes)"},
    {"bad_axis_name_twice.yaml", 4, 11, "axis name 'A' is used twice"},
    {"bad_backend.yaml", 3, 12,
     "'backend' must be auto, serialport or tty, got 'usb'"},
    {"bad_baud.yaml", 3, 9,
     "'baud' must be 1200, 2400, 4800, 9600, 19200, 38400, 57600 or 115200, "
     "got 9601"},
    {"bad_bool.yaml", 3, 15,
     "expected true or false for 'active_low', got 'yes'"},
    {"bad_unit.yaml", 5, 11, "'unit' must be deg or mm, got 'inch'"},
    {"bad_counts_per_unit.yaml", 6, 22,
     "'counts_per_unit' must be between 0 and 10000000, got -5"},
    {"bad_channel.yaml", 3, 12, "'channel' must be between 1 and 8, got 9"},
    {"bad_clinical_loopback.yaml", 5, 12,
     "'address' 127.0.0.1:23023 is a loopback address; clinical mode needs the "
     "real controller"},
    {"bad_clinical_noport.yaml", 1, 7,
     "'port_clinical' must be set in clinical mode"},
    {"bad_clinical_pty.yaml", 5, 18,
     "'port_clinical' must be a serial device under /dev, got '/dev/pts/3'"},
    {"bad_clinical_tty.yaml", 6, 7,
     "'backend' tty is not allowed in clinical mode (a pseudo-terminal is "
     "never a real relay)"},
    {"bad_comments_only.yaml", 1, 1, "empty configuration file"},
    {"bad_controller_timeout.yaml", 4, 26,
     "'controller_timeout_ms' (200) must be at least 'critical_factor' x "
     "'period_ms' (250)"},
    {"bad_critical_factor.yaml", 4, 20,
     "'critical_factor' (1.4) must be greater than 'noncritical_factor' (1.5)"},
    {"bad_dev_noport.yaml", 3, 21,
     "'port_development' must be set in development mode"},
    {"bad_duplicate_key.yaml", 5, 1, "duplicate key 'period_ms'"},
    {"bad_duplicate_nested.yaml", 5, 3, "duplicate key 'critical_factor'"},
    {"bad_empty.yaml", 1, 1, "empty configuration file"},
    {"bad_er_huge.yaml", 4, 34,
     "'position_error_limit_counts' must be between 1 and 2147483647, got "
     "99999999999"},
    {"bad_er_above_step.yaml", 5, 34,
     "'position_error_limit_counts' (1000) must be below 'step_counts' "
     "(1000)"},
    {"bad_inputs_count.yaml", 3, 11,
     "'inputs' must list exactly 12 inputs, got 11"},
    {"bad_inputs_duplicate.yaml", 3, 48,
     "'inputs' lists input 3 twice (entries 3 and 12)"},
    {"bad_inputs_range.yaml", 3, 48,
     "'inputs' must be between 1 and 48, got 49"},
    {"bad_inputs_9_16.yaml", 3, 36,
     "'inputs' entry 9 is input 12: a DMC-4030 has no inputs 9 to 16 "
     "(use 1..8 or 17..48)"},
    {"bad_oa_ki0.yaml", 6, 9,
     "'encoder_failure' needs a non-zero 'ki': the controller's "
     "encoder-failure detection (OA, OT) does not work with KI 0"},
    {"bad_pot_absolute.yaml", 7, 18,
     "'forward_v' (1) must be above 'reverse_v' (0.9) by more than twice "
     "'absolute_tolerance_v' (0.25)"},
    {"bad_pot_span.yaml", 7, 18,
     "'forward_v' - 'reverse_v' (3 V) must agree with 'expected_range_v' "
     "(4 V) within 'range_tolerance'"},
    {"bad_seek_fast.yaml", 4, 13,
     "'seek_cps' (9000) must not exceed 'travel_cps' (8000): it is the "
     "slow speed near a switch"},
    {"bad_near_margin.yaml", 8, 23,
     "axis 'A': the lowest potentiometer reading allowed ('reverse_v' - "
     "'absolute_tolerance_v' - 'near_margin_counts' x 0.00025 V/count = "
     "-0.250 V) is below 0.1 V, so an open potentiometer (0 V) would look "
     "like the axis at its end stop: make 'near_margin_counts' at most "
     "600"},
    {"bad_record.yaml", 3, 11,
     "'record' must be poll or stream, got 'udp'"},
    {"bad_udp_port.yaml", 4, 13,
     "'udp_port' must be between 1 and 65535, got 0"},
    {"bad_power_output.yaml", 3, 17,
     "'power_output' must be between 0 and 8, got 9"},
    {"bad_invalid_timeout.yaml", 3, 23,
     "'invalid_timeout_ms' must be between 50 and 5000, got 20"},
    {"bad_key_not_scalar.yaml", 2, 3, "expected a key name, got a list"},
    {"bad_log_keep.yaml", 3, 9, "'keep' must be between 1 and 9, got 10"},
    {"bad_log_path_empty.yaml", 3, 9, "'path' must not be empty"},
    {"bad_recorder_seconds.yaml", 3, 12,
     "'seconds' must be between 1 and 120, got 500"},
    {"bad_recorder_after.yaml", 4, 18,
     "'after_fault_s' (5 s) must be less than 'seconds' (5 s): both are in "
     "the one ring"},
    {"bad_map_for_number.yaml", 2, 12,
     "expected an integer for 'period_ms', got a mapping"},
    {"bad_missing_value.yaml", 2, 11, "missing value for 'period_ms'"},
    {"bad_mode.yaml", 1, 7,
     "'mode' must be clinical or development, got 'clinic'"},
    {"bad_name_control.yaml", 3, 11, "'name' contains a control character"},
    {"bad_nan.yaml", 4, 9, "expected a number for 'kp', got '.nan'"},
    {"bad_noncritical_after.yaml", 4, 23,
     "'critical_factor' (2) must be greater than 'noncritical_factor' (2)"},
    {"bad_off_deadline_high.yaml", 3, 20,
     "'off_deadline_ms' must be between 10 and 1000, got 1001"},
    {"bad_off_deadline_low.yaml", 3, 20,
     "'off_deadline_ms' must be between 10 and 1000, got 9"},
    {"bad_ot_range.yaml", 5, 21,
     "'time_samples' must be between 2 and 32000, got 1"},
    {"bad_period_high.yaml", 2, 12,
     "'period_ms' must be between 2 and 100, got 500"},
    {"bad_period_huge.yaml", 2, 12,
     "'period_ms' must be between 2 and 100, got 99999999999999999999"},
    {"bad_period_low.yaml", 2, 12,
     "'period_ms' must be between 2 and 100, got 1"},
    /* found by tests/fuzz/fuzz_config.c: 4 x period_ms overflowed int
     * (undefined behaviour) before the range check */
    {"bad_period_overflow.yaml", 2, 12,
     "'period_ms' must be between 2 and 100, got 1326439257"},
    {"bad_protocol_byte.yaml", 4, 22,
     "'on' bytes must be between 0 and 255, got 0x101"},
    {"bad_protocol_name.yaml", 3, 13,
     "'protocol' must be devantech, icstation, lcus or kmtronic, got 'numato'"},
    {"bad_protocol_no_off.yaml", 3, 13,
     "'protocol' needs both 'on' and 'off' bytes"},
    {"bad_protocol_same.yaml", 5, 10, "'on' and 'off' bytes must differ"},
    {"bad_protocol_too_long.yaml", 4, 9,
     "'on' must list 1 to 16 bytes, got 17"},
    {"bad_quoted_number.yaml", 2, 12,
     "expected an integer for 'period_ms', got a quoted string"},
    {"bad_realtime_cpu.yaml", 3, 8,
     "'cpu' must be between -1 and 1023, got -2"},
    {"bad_realtime_period.yaml", 4, 13,
     "'period_ms' 5 needs real-time scheduling: set 'realtime.priority' "
     "1..99 or a period of 10 ms or more"},
    {"bad_quote_single.yaml", 3, 10,
     "this quote is not closed on its line (the parser then stopped at "
     "line 5 column 1: found unexpected end of stream)"},
    {"bad_quote_unclosed.yaml", 3, 12,
     "this quote is not closed on its line (the parser then stopped at "
     "line 8 column 1: found unexpected end of stream)"},
    {"bad_readback_protocol.yaml", 4, 13,
     "'readback' needs the devantech protocol"},
    {"bad_root_list.yaml", 1, 1,
     "expected a mapping of settings at the top level, got a list"},
    {"bad_root_scalar.yaml", 1, 1,
     "expected a mapping of settings at the top level, got a value"},
    {"bad_scalar_for_map.yaml", 2, 13,
     "expected a mapping for 'controller', got '127.0.0.1'"},
    {"bad_syntax_indent.yaml", 4, 2,
     "did not find expected key (while parsing a block mapping at line 1 "
     "column 1)"},
    {"bad_syntax_tab.yaml", 3, 1,
     "found character that cannot start any token (while scanning for the next "
     "token at line 3 column 1)"},
    {"bad_syntax_unclosed.yaml", 3, 1,
     "did not find expected ',' or ']' (while parsing a flow sequence at line "
     "2 column 12)"},
    {"bad_tl_range.yaml", 3, 31,
     "'torque_limit_v' must be between 0 and 9.9982, got 10"},
    {"bad_tolerance_negative.yaml", 5, 41,
     "'range_tolerance' must be between 0 and 1, got -0.1"},
    {"bad_travel_step.yaml", 4, 18,
     "'travel_counts' (100000) must be 4 to 10000 times 'step_counts' (50000)"},
    {"bad_two_documents.yaml", 2, 1, "only one document is allowed"},
    {"bad_undefined_alias.yaml", 2, 12, "found undefined alias"},
    {"bad_unknown_key.yaml", 12, 3, "unknown key 'relay_prot'"},
    {"bad_unknown_nested.yaml", 4, 14, "unknown key 'inptu'"},
    {"bad_utf8.yaml", 3, 11, "invalid leading UTF-8 octet"},
    {"bad_vmax_below_vmin.yaml", 6, 11,
     "'vmin' (3000) must not exceed 'vmax' (2000)"},
    {"bad_vmax_fraction.yaml", 3, 21,
     "expected an integer for 'vmax', got '8000.5'"},
    {"bad_vmax_text.yaml", 4, 11, "expected a number for 'vmax', got 'fast'"},
    {"bad_vmin_above_vmax.yaml", 5, 11,
     "'vmin' (9000) must not exceed 'vmax' (8000)"},
    {"bad_window_length.yaml", 4, 22,
     "'accel_window_ms' must list exactly 2 times (start and end), got 1"},
    {"bad_window_order.yaml", 6, 29,
     "'accel_window_ms' end (500) must be after its start (2000) and at most "
     "60000"},
};

#define N_BAD (sizeof(bad_cases) / sizeof(bad_cases[0]))

/* One malformed file: exact message, nothing written to @out. */
static void test_bad_file(void **state)
{
	const struct bad_case *bc = *state;
	struct re_config cfg, pattern;
	char path[256], want[768], err[RE_CONFIG_ERR_MAX];
	int rc;

	snprintf(path, sizeof(path), DATA_DIR "%s", bc->file);
	snprintf(want, sizeof(want), "%s:%d:%d: %s", path, bc->line, bc->column,
		 bc->message);
	memset(&cfg, 0xA5, sizeof(cfg));
	memset(&pattern, 0xA5, sizeof(pattern));
	rc = re_config_load_file(path, &cfg, err, sizeof(err));
	assert_int_equal(rc, GL_ERR_CONFIG);
	assert_string_equal(err, want);
	assert_memory_equal(&cfg, &pattern, sizeof(cfg));
}

/* Parse @text (NUL-terminated) as "t.yaml"; returns the code. */
static int parse_text(const char *text, struct re_config *cfg, char *err,
		      size_t errlen)
{
	return re_config_parse(text, strlen(text), "t.yaml", cfg, err, errlen);
}

/* The documented defaults (docs/config.md), field by field. */
static void test_defaults_documented(void **state)
{
	static const int joy[RE_JOY_INPUTS] = {1, 2, 3,	 4,  5,	 6,
					       7, 8, 17, 18, 19, 20};
	struct re_config c;
	int i;

	(void)state;
	re_config_defaults(&c);
	assert_int_equal(c.mode, RE_MODE_CLINICAL);
	assert_int_equal(c.period_ms, 50);
	assert_string_equal(c.controller.address, "127.0.0.1:23023");
	assert_string_equal(c.controller.model, "DMC4030");
	assert_int_equal(c.controller.timeout_ms, 100);
	assert_int_equal(c.controller.connect_timeout_ms, 2000);
	assert_int_equal(c.controller.record, RE_RECORD_POLL);
	assert_int_equal(c.controller.udp_port, 60007);
	assert_string_equal(c.relay.port_clinical, "");
	assert_string_equal(c.relay.port_development, "/tmp/roboelf-relay");
	assert_int_equal(c.relay.protocol, RE_RELAY_DEVANTECH);
	assert_int_equal(c.relay.channel, 1);
	assert_int_equal(c.relay.backend, RE_RELAY_BACKEND_AUTO);
	assert_int_equal(c.relay.baud, 9600);
	assert_int_equal(c.relay.write_timeout_ms, 100);
	assert_int_equal(c.relay.off_deadline_ms, 50);
	assert_true(c.relay.readback);
	assert_int_equal(c.relay.readback_timeout_ms, 500);
	assert_string_equal(c.relay.icstation_state,
			    "/tmp/roboelf-icstation.state");
	assert_true(c.watchdog.noncritical_factor == 1.5);
	assert_true(c.watchdog.critical_factor == 2.5);
	assert_int_equal(c.watchdog.controller_timeout_ms, 200);
	assert_memory_equal(c.joystick.inputs, joy, sizeof(joy));
	assert_false(c.joystick.active_low);
	assert_int_equal(c.joystick.invalid_timeout_ms, 500);
	for (i = 0; i < RE_AXES; i++) {
		const struct re_config_axis *a = &c.axes[i];

		assert_string_equal(a->name, i == 0 ? "A" : i == 1 ? "B" : "C");
		assert_int_equal(a->vmax_cps, 8000);
		assert_int_equal(a->vmin_cps, 2000); /* vmax / 4 */
		assert_int_equal(a->accel_start_ms, 500);
		assert_int_equal(a->accel_end_ms, 2000);
		assert_int_equal(a->step_counts, 1000);
		assert_int_equal(a->travel_counts, i == 2 ? 80000 : 100000);
		assert_true(a->travel_tolerance == 0.1);
		assert_true(a->kp == 6.0 && a->ki == 1.0 && a->kd == 64.0);
		assert_true(a->analog.reverse_v == 0.5);
		assert_true(a->analog.forward_v == 4.5);
		assert_true(a->analog.absolute_tolerance_v == 0.25);
		assert_true(a->torque_limit_v == 5.0);
		assert_int_equal(a->position_error_limit_counts, 500);
		assert_true(a->off_on_error);
		assert_true(a->encoder_failure.enabled);
		assert_int_equal(a->encoder_failure.time_samples, 100);
		assert_true(a->encoder_failure.torque_v == 2.0);
		assert_int_equal(a->analog.input, i + 1);
		assert_true(a->analog.expected_range_v == 4.0);
		assert_true(a->analog.range_tolerance == 0.1);
		assert_true(a->allowed_error == 0.5);
		assert_int_equal(a->persistence_cycles, 1);
		assert_true(a->monotonic_margin_v == 0.005);
		assert_int_equal(a->unit, i == 2 ? RE_UNIT_MM : RE_UNIT_DEG);
		assert_true(a->counts_per_unit == 0); /* counts shown */
	}
	assert_string_equal(c.calibration.file, "roboelf-calibration.txt");
	assert_true(c.calibration.backup);
	assert_int_equal(c.calibration.backoff_counts, 500);
	assert_int_equal(c.calibration.move_timeout_ms, 30000);
	assert_string_equal(c.log.path, "roboelf.log");
	assert_int_equal(c.log.max_bytes, 10485760);
	assert_int_equal(c.log.keep, 5);
	assert_float_equal(c.recorder.seconds, 30, 0);
	assert_float_equal(c.recorder.after_fault_s, 2, 0);
	assert_string_equal(c.recorder.dir, "");
}

/* The built-in defaults are clinical without a relay port: refused. */
static void test_defaults_refused_clinical(void **state)
{
	struct re_config c;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	re_config_defaults(&c);
	assert_int_equal(re_config_validate(&c, err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(err,
			    "'port_clinical' must be set in clinical mode");
	c.mode = RE_MODE_DEVELOPMENT;
	assert_int_equal(re_config_validate(&c, err, sizeof(err)), GL_OK);
}

/* config/roboelf.yaml: the defaults in development mode, with galil-sim's
 * scale for the console. */
static void test_default_file_loads(void **state)
{
	struct re_config c, d;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	assert_int_equal(
	    re_config_load_file("config/roboelf.yaml", &c, err, sizeof(err)),
	    GL_OK);
	assert_string_equal(err, "");
	re_config_defaults(&d);
	d.mode = RE_MODE_DEVELOPMENT;
	/* the scale of galil-sim's robot (the default is 0: counts shown) */
	for (int i = 0; i < RE_AXES; i++)
		d.axes[i].counts_per_unit = 1000;
	assert_memory_equal(&c, &d, sizeof(c));
}

/* An empty mapping gives the defaults (here in development mode). */
static void test_minimal_file(void **state)
{
	struct re_config c, d;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	assert_int_equal(
	    parse_text("mode: development\n", &c, err, sizeof(err)), GL_OK);
	re_config_defaults(&d);
	d.mode = RE_MODE_DEVELOPMENT;
	assert_memory_equal(&c, &d, sizeof(c));
}

/* ---- round trip: struct -> YAML text -> struct ---- */

struct sbuf {
	char *p;
	size_t n, cap;
};

static void put(struct sbuf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static void put(struct sbuf *b, const char *fmt, ...)
{
	va_list ap;
	int n;

	va_start(ap, fmt);
	n = vsnprintf(b->p + b->n, b->cap - b->n, fmt, ap);
	va_end(ap);
	assert_true(n >= 0 && (size_t)n < b->cap - b->n);
	b->n += (size_t)n;
}

static void put_bytes(struct sbuf *b, const char *key, const uint8_t *v,
		      size_t n)
{
	size_t i;

	put(b, "    %s: [", key);
	for (i = 0; i < n; i++)
		put(b, "%s0x%02X", i ? ", " : "", v[i]);
	put(b, "]\n");
}

static const char *tf(bool v)
{
	return v ? "true" : "false";
}

static void emit_axis(struct sbuf *b, const struct re_config_axis *a)
{
	put(b, "  - name: \"%s\"\n    vmax: %d\n    vmin: %d\n", a->name,
	    a->vmax_cps, a->vmin_cps);
	put(b, "    accel_window_ms: [%d, %d]\n", a->accel_start_ms,
	    a->accel_end_ms);
	put(b, "    step_counts: %d\n    travel_counts: %d\n", a->step_counts,
	    a->travel_counts);
	put(b, "    travel_tolerance: %.17g\n", a->travel_tolerance);
	put(b, "    kp: %.17g\n    ki: %.17g\n    kd: %.17g\n", a->kp, a->ki,
	    a->kd);
	put(b, "    torque_limit_v: %.17g\n", a->torque_limit_v);
	put(b, "    position_error_limit_counts: %d\n",
	    a->position_error_limit_counts);
	put(b, "    off_on_error: %s\n", tf(a->off_on_error));
	put(b,
	    "    encoder_failure: {enabled: %s, time_samples: %d, "
	    "torque_v: %.17g}\n",
	    tf(a->encoder_failure.enabled), a->encoder_failure.time_samples,
	    a->encoder_failure.torque_v);
	put(b,
	    "    analog: {input: %d, expected_range_v: %.17g, "
	    "range_tolerance: %.17g,\n             reverse_v: %.17g, "
	    "forward_v: %.17g, absolute_tolerance_v: %.17g}\n",
	    a->analog.input, a->analog.expected_range_v,
	    a->analog.range_tolerance, a->analog.reverse_v,
	    a->analog.forward_v, a->analog.absolute_tolerance_v);
	put(b, "    allowed_error: %.17g\n    persistence_cycles: %d\n",
	    a->allowed_error, a->persistence_cycles);
	put(b, "    monotonic_margin_v: %.17g\n", a->monotonic_margin_v);
	put(b, "    unit: %s\n    counts_per_unit: %.17g\n",
	    re_unit_name(a->unit), a->counts_per_unit);
}

/* emit() - every field of @c as YAML. */
static void emit(struct sbuf *b, const struct re_config *c)
{
	static const char *const be[] = {"auto", "serialport", "tty"};
	int i;

	put(b, "mode: %s\nperiod_ms: %d\n", re_mode_name(c->mode),
	    c->period_ms);
	put(b, "controller:\n  address: \"%s\"\n  model: %s\n",
	    c->controller.address, c->controller.model);
	put(b, "  timeout_ms: %d\n  connect_timeout_ms: %d\n",
	    c->controller.timeout_ms, c->controller.connect_timeout_ms);
	put(b, "  power_output: %d\n", c->controller.power_output);
	put(b, "  record: %s\n  udp_port: %d\n",
	    re_record_name(c->controller.record), c->controller.udp_port);
	put(b, "relay:\n  port_clinical: \"%s\"\n  port_development: \"%s\"\n",
	    c->relay.port_clinical, c->relay.port_development);
	put(b, "  serial: \"%s\"\n", c->relay.serial);
	if (c->relay.protocol == RE_RELAY_EXPLICIT) {
		put(b, "  protocol:\n");
		put_bytes(b, "on", c->relay.on, c->relay.on_len);
		put_bytes(b, "off", c->relay.off, c->relay.off_len);
	} else {
		put(b, "  protocol: %s\n",
		    re_relay_proto_name(c->relay.protocol));
	}
	put(b, "  channel: %d\n  backend: %s\n  baud: %d\n", c->relay.channel,
	    be[c->relay.backend], c->relay.baud);
	put(b, "  write_timeout_ms: %d\n  off_deadline_ms: %d\n",
	    c->relay.write_timeout_ms, c->relay.off_deadline_ms);
	put(b, "  readback: %s\n", tf(c->relay.readback));
	put(b, "  readback_timeout_ms: %d\n  icstation_state: \"%s\"\n",
	    c->relay.readback_timeout_ms, c->relay.icstation_state);
	put(b,
	    "watchdog:\n  noncritical_factor: %.17g\n"
	    "  critical_factor: %.17g\n  controller_timeout_ms: %d\n",
	    c->watchdog.noncritical_factor, c->watchdog.critical_factor,
	    c->watchdog.controller_timeout_ms);
	put(b, "joystick:\n  inputs: [");
	for (i = 0; i < RE_JOY_INPUTS; i++)
		put(b, "%s%d", i ? ", " : "", c->joystick.inputs[i]);
	put(b, "]\n  active_low: %s\n  invalid_timeout_ms: %d\naxes:\n",
	    tf(c->joystick.active_low), c->joystick.invalid_timeout_ms);
	for (i = 0; i < RE_AXES; i++)
		emit_axis(b, &c->axes[i]);
	put(b, "calibration:\n  file: \"%s\"\n  backup: %s\n",
	    c->calibration.file, tf(c->calibration.backup));
	put(b, "  backoff_counts: %d\n  move_timeout_ms: %d\n",
	    c->calibration.backoff_counts, c->calibration.move_timeout_ms);
	put(b, "log:\n  path: \"%s\"\n  max_bytes: %ld\n  keep: %d\n",
	    c->log.path, c->log.max_bytes, c->log.keep);
	put(b, "recorder:\n  seconds: %.17g\n  after_fault_s: %.17g\n",
	    c->recorder.seconds, c->recorder.after_fault_s);
	put(b, "  dir: \"%s\"\n", c->recorder.dir);
	put(b, "realtime:\n  priority: %d\n  cpu: %d\n  lock_memory: %s\n",
	    c->realtime.priority, c->realtime.cpu, tf(c->realtime.lock_memory));
}

/* A configuration with every field away from its default. */
static void changed(struct re_config *c)
{
	static const uint8_t on[] = {0xA0, 0x02, 0x01, 0xA3};
	static const uint8_t off[] = {0xA0, 0x02, 0x00, 0xA2};
	int i;

	re_config_defaults(c);
	c->mode = RE_MODE_CLINICAL;
	c->period_ms = 20;
	c->realtime.priority = 70;
	c->realtime.cpu = 1;
	c->realtime.lock_memory = false;
	strcpy(c->controller.address, "192.168.42.7:23");
	strcpy(c->controller.model, "DMC4040");
	c->controller.timeout_ms = 75;
	c->controller.connect_timeout_ms = 1500;
	c->controller.record = RE_RECORD_STREAM;
	c->controller.udp_port = 23;
	strcpy(c->relay.port_clinical, "/dev/serial/by-id/usb-relay");
	strcpy(c->relay.port_development, "/tmp/other-relay");
	strcpy(c->relay.serial, "FT4-ab.c_1:2");
	c->relay.protocol = RE_RELAY_EXPLICIT;
	memcpy(c->relay.on, on, sizeof(on));
	c->relay.on_len = sizeof(on);
	memcpy(c->relay.off, off, sizeof(off));
	c->relay.off_len = sizeof(off);
	c->relay.channel = 2;
	c->relay.backend = RE_RELAY_BACKEND_SERIALPORT;
	c->relay.baud = 19200;
	c->relay.write_timeout_ms = 40;
	c->relay.off_deadline_ms = 35;
	c->relay.readback = false;
	c->relay.readback_timeout_ms = 300;
	strcpy(c->relay.icstation_state, "/run/roboelf/ics.state");
	c->watchdog.noncritical_factor = 1.25;
	c->watchdog.critical_factor = 3.75;
	c->watchdog.controller_timeout_ms = 150;
	for (i = 0; i < RE_JOY_INPUTS; i++)
		c->joystick.inputs[i] = 21 + i;
	c->joystick.active_low = true;
	c->joystick.invalid_timeout_ms = 400;
	for (i = 0; i < RE_AXES; i++) {
		struct re_config_axis *a = &c->axes[i];

		snprintf(a->name, sizeof(a->name), "axis-%c", 'a' + i);
		a->vmax_cps = 9000 + i;
		a->vmin_cps = 1000 + i;
		a->accel_start_ms = 300 + i;
		a->accel_end_ms = 1700 + i;
		a->step_counts = 800 + i;
		a->travel_counts = 90000 + i;
		a->travel_tolerance = 0.07;
		a->kp = 12.5;
		a->ki = 0.25;
		a->kd = 100.125;
		a->torque_limit_v = 3.3;
		a->position_error_limit_counts = 300 + i;
		a->off_on_error = false;
		a->encoder_failure.enabled = false;
		a->encoder_failure.time_samples = 250;
		a->encoder_failure.torque_v = 1.1;
		a->analog.input = 6 + i;
		a->analog.expected_range_v = 3.6;
		a->analog.range_tolerance = 0.15;
		a->allowed_error = 0.3;
		a->persistence_cycles = 2 + i;
		a->monotonic_margin_v = 0.01;
		a->unit = i == 0 ? RE_UNIT_MM : RE_UNIT_DEG;
		a->counts_per_unit = 123.25 + i;
	}
	strcpy(c->calibration.file, "/var/lib/roboelf/cal.txt");
	c->calibration.backup = false;
	c->calibration.backoff_counts = 750;
	c->calibration.move_timeout_ms = 20000;
	strcpy(c->log.path, "/var/log/roboelf/roboelf.log");
	c->log.max_bytes = 65536;
	c->log.keep = 3;
	c->recorder.seconds = 12.5;
	c->recorder.after_fault_s = 0.5;
	strcpy(c->recorder.dir, "/var/log/roboelf/traces");
}

/* Every field written as YAML reads back to the same struct. */
static void test_round_trip_every_field(void **state)
{
	struct re_config want, got, def;
	char text[8192], err[RE_CONFIG_ERR_MAX];
	struct sbuf b = {text, 0, sizeof(text)};

	(void)state;
	changed(&want);
	assert_int_equal(re_config_validate(&want, err, sizeof(err)), GL_OK);
	emit(&b, &want);
	assert_int_equal(
	    re_config_parse(text, b.n, "rt.yaml", &got, err, sizeof(err)),
	    GL_OK);
	assert_string_equal(err, "");
	assert_memory_equal(&got, &want, sizeof(got));
	/* ... and the change really touched every field the file can set. */
	re_config_defaults(&def);
	assert_int_not_equal(got.relay.readback_timeout_ms,
			     def.relay.readback_timeout_ms);
	assert_true(re_config_hash(&got) != re_config_hash(&def));
	/* The defaults round-trip too. */
	def.mode = RE_MODE_DEVELOPMENT;
	b.n = 0;
	emit(&b, &def);
	assert_int_equal(
	    re_config_parse(text, b.n, "rt.yaml", &got, err, sizeof(err)),
	    GL_OK);
	assert_memory_equal(&got, &def, sizeof(got));
}

/* ---- derived defaults and individual rules ---- */

/* vmin defaults to vmax / 4 when only vmax is given. */
static void test_vmin_follows_vmax(void **state)
{
	struct re_config c;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	assert_int_equal(parse_text("mode: development\naxes:\n"
				    "  - {vmax: 10000}\n  - {vmax: 7}\n"
				    "  - {vmax: 8000, vmin: 8000}\n",
				    &c, err, sizeof(err)),
			 GL_OK);
	assert_int_equal(c.axes[0].vmin_cps, 2500);
	assert_int_equal(c.axes[1].vmin_cps, 1); /* 7 / 4 */
	assert_int_equal(c.axes[2].vmin_cps, 8000);
	assert_string_equal(c.axes[1].name, "B"); /* untouched */
}

/* controller_timeout_ms defaults to 4 x period, at least 100 ms. */
static void test_controller_timeout_auto(void **state)
{
	struct re_config c;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	assert_int_equal(parse_text("mode: development\nperiod_ms: 100\n", &c,
				    err, sizeof(err)),
			 GL_OK);
	assert_int_equal(c.watchdog.controller_timeout_ms, 400);
	assert_int_equal(parse_text("mode: development\nperiod_ms: 2\n", &c,
				    err, sizeof(err)),
			 GL_OK);
	assert_int_equal(c.watchdog.controller_timeout_ms, 100);
	assert_int_equal(parse_text("mode: development\nperiod_ms: 2\n"
				    "watchdog: {controller_timeout_ms: 20}\n",
				    &c, err, sizeof(err)),
			 GL_OK);
	assert_int_equal(c.watchdog.controller_timeout_ms, 20);
}

/* Read-back is on by default for Devantech only. */
static void test_readback_default(void **state)
{
	struct re_config c;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	assert_int_equal(parse_text("mode: development\n"
				    "relay: {protocol: icstation}\n",
				    &c, err, sizeof(err)),
			 GL_OK);
	assert_int_equal(c.relay.protocol, RE_RELAY_ICSTATION);
	assert_false(c.relay.readback);
	assert_int_equal(parse_text("mode: development\n"
				    "relay: {protocol: devantech}\n",
				    &c, err, sizeof(err)),
			 GL_OK);
	assert_true(c.relay.readback);
	assert_int_equal(parse_text("mode: development\n"
				    "relay: {readback: false}\n",
				    &c, err, sizeof(err)),
			 GL_OK);
	assert_false(c.relay.readback);
}

/* A clinical configuration that passes every clinical rule. */
/* The robot's values a clinical configuration must write (besides the
 * controller's and the relay's): the development configuration's. */
#define SITE_AXIS(range)                                                    \
	"  - {vmax: 8000, travel_counts: " range ", kp: 6, ki: 1, kd: 64, "  \
	"torque_limit_v: 5.0,\n     analog: {expected_range_v: 4.0, "       \
	"reverse_v: 0.5, forward_v: 4.5}}\n"
#define SITE_ROBOT                                                          \
	"joystick:\n  inputs: [1, 2, 3, 4, 5, 6, 7, 8, 17, 18, 19, 20]\n"   \
	"  active_low: false\naxes:\n" SITE_AXIS("100000")                   \
	    SITE_AXIS("100000") SITE_AXIS("80000")

static void test_clinical_accepted(void **state)
{
	struct re_config c;
	struct re_relay_cfg r;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	assert_int_equal(
	    parse_text(
		"mode: clinical\ncontroller:\n"
		"  address: 10.0.0.2\n  power_output: 0\nrelay:\n"
		"  port_clinical: /dev/serial/by-id/usb-TEST_relay-if00\n"
		"  serial: A10KXYZ9\n  protocol: devantech\n"
		"  channel: 2\n" SITE_ROBOT,
		&c, err, sizeof(err)),
	    GL_OK);
	assert_string_equal(c.relay.serial, "A10KXYZ9");
	assert_string_equal(re_config_relay_port(&c),
			    "/dev/serial/by-id/usb-TEST_relay-if00");
	re_config_relay_cfg(&c, &r);
	assert_string_equal(r.port, "/dev/serial/by-id/usb-TEST_relay-if00");
	assert_true(r.clinical);
	assert_int_equal(r.channel, 2);
	assert_int_equal(r.proto, RE_RELAY_DEVANTECH);
	assert_int_equal(r.baud, 9600);
	assert_true(r.readback);
	assert_int_equal(r.write_timeout_ms, 100);
	assert_int_equal(r.off_deadline_ms, 50);
	c.mode = RE_MODE_DEVELOPMENT;
	re_config_relay_cfg(&c, &r);
	assert_string_equal(r.port, "/tmp/roboelf-relay");
	assert_false(r.clinical);
}

/* relay.serial: required in clinical mode (after the other clinical
 * rules), and whatever the mode only a value a udev rule can hold, each
 * refusal at the value's (or mode's) position. */
static void test_relay_serial(void **state)
{
	struct re_config c;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	assert_int_equal(parse_text("mode: clinical\ncontroller:\n"
				    "  address: 10.0.0.2\nrelay:\n"
				    "  port_clinical: /dev/roboelf-relay\n",
				    &c, err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(err, "t.yaml:1:7: 'serial' must be set in clinical "
				 "mode: the relay board's USB serial number, "
				 "which 'roboelf-tech bind-relay' prints");
	assert_int_equal(parse_text("relay:\n  serial: \"A1*\"\n"
				    "mode: development\n",
				    &c, err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(err, "t.yaml:2:11: 'serial': serial number 'A1*' "
				 "has a character not allowed in a udev rule "
				 "('*' at position 3): only letters, digits, "
				 "'.', '_', '-' and ':'");
	assert_int_equal(parse_text("mode: development\nrelay:\n"
				    "  serial: A10KXYZ9\n",
				    &c, err, sizeof(err)),
			 GL_OK);
	assert_string_equal(c.relay.serial, "A10KXYZ9");
	re_config_defaults(&c);
	assert_string_equal(c.relay.serial, "");
}

/* Command-line overrides are validated without a position. */
static void test_validate_overrides(void **state)
{
	struct re_config c;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	re_config_defaults(&c);
	c.mode = RE_MODE_DEVELOPMENT;
	c.period_ms = 500;
	assert_int_equal(re_config_validate(&c, err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(err, "'period_ms' must be between 2 and 100, "
				 "got 500");
	c.period_ms = 100; /* 2.5 x 100 > 200 */
	assert_int_equal(re_config_validate(&c, err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(err, "'controller_timeout_ms' (200) must be at "
				 "least 'critical_factor' x 'period_ms' (250)");
	c.period_ms = 50;
	c.relay.protocol = RE_RELAY_EXPLICIT; /* with no bytes */
	assert_int_equal(re_config_validate(&c, err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(err, "'on' and 'off' must list 1 to 16 bytes "
				 "each");
	c.relay.protocol = RE_RELAY_KMTRONIC;
	c.relay.readback = false;
	assert_int_equal(re_config_validate(&c, err, sizeof(err)), GL_OK);
	c.mode = RE_MODE_CLINICAL;
	strcpy(c.relay.port_clinical, "/dev/serial/by-id/usb-TEST_relay-if00");
	assert_int_equal(re_config_validate(&c, err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(err,
			    "'address' 127.0.0.1:23023 is a loopback "
			    "address; clinical mode needs the real controller");
}

/* Strings and names may be quoted; numbers may not (see bad_quoted_*). */
static void test_quoted_strings(void **state)
{
	struct re_config c;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	assert_int_equal(parse_text("mode: \"development\"\n"
				    "relay: {protocol: 'lcus', backend: tty}\n"
				    "log: {path: 'my log.txt'}\n",
				    &c, err, sizeof(err)),
			 GL_OK);
	assert_int_equal(c.mode, RE_MODE_DEVELOPMENT);
	assert_int_equal(c.relay.protocol, RE_RELAY_LCUS);
	assert_int_equal(c.relay.backend, RE_RELAY_BACKEND_TTY);
	assert_string_equal(c.log.path, "my log.txt");
	assert_int_equal(parse_text("mode: \"\"\n", &c, err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(err, "t.yaml:1:7: 'mode' must be clinical or "
				 "development, got ''");
}

/* The buffer need not be NUL-terminated; the name defaults. */
static void test_buffer_not_terminated(void **state)
{
	static const char text[] = "mode: development\nperiod_ms: 20XXX";
	struct re_config c;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	assert_int_equal(re_config_parse(text, sizeof(text) - 4, "b.yaml", &c,
					 err, sizeof(err)),
			 GL_OK);
	assert_int_equal(c.period_ms, 20);
	assert_int_equal(
	    re_config_parse(text, sizeof(text) - 1, NULL, &c, err, sizeof(err)),
	    GL_ERR_CONFIG);
	assert_string_equal(err, "<config>:2:12: expected a number for "
				 "'period_ms', got '20XXX'");
}

/* A missing file: "cannot read", GL_ERR_SYS, errno kept. */
static void test_missing_file(void **state)
{
	struct re_config c;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	assert_int_equal(re_config_load_file(DATA_DIR "no-such-file.yaml", &c,
					     err, sizeof(err)),
			 GL_ERR_SYS);
	assert_int_equal(errno, ENOENT);
	assert_string_equal(err, "cannot read '" DATA_DIR "no-such-file.yaml"
				 "': No such file or directory");
	assert_int_equal(re_config_load_file(DATA_DIR, &c, err, sizeof(err)),
			 GL_ERR_SYS);
	assert_int_equal(errno, EISDIR);
	assert_string_equal(err, "cannot read '" DATA_DIR "': it is a "
				 "directory; give the configuration file "
				 "(e.g. " DATA_DIR "/roboelf.yaml)");
}

/* A short error buffer is truncated, never overrun. */
static void test_short_error_buffer(void **state)
{
	struct re_config c;
	char err[16];

	(void)state;
	memset(err, 'x', sizeof(err));
	assert_int_equal(parse_text("period_ms: 500\n", &c, err, 12),
			 GL_ERR_CONFIG);
	assert_string_equal(err, "t.yaml:1:12");
	assert_int_equal(err[12], 'x');
}

/* The hash covers calibration fields only. */
static void test_hash(void **state)
{
	struct re_config a, b;
	uint64_t h;

	(void)state;
	re_config_defaults(&a);
	b = a;
	h = re_config_hash(&a);
	assert_true(h == re_config_hash(&b));
	b.period_ms = 20;
	b.axes[1].vmax_cps = 100;
	b.relay.channel = 3;
	assert_true(h == re_config_hash(&b));
	b.axes[2].step_counts = 999;
	assert_true(h != re_config_hash(&b));
	b = a;
	strcpy(b.axes[0].name, "X");
	assert_true(h != re_config_hash(&b));
	b = a;
	b.axes[1].analog.expected_range_v = 4.1;
	assert_true(h != re_config_hash(&b));
	b = a;
	b.axes[2].allowed_error = 0.6;
	assert_true(h != re_config_hash(&b));
}

/* The summary names the essentials and is safely truncated. */
static void test_dump(void **state)
{
	struct re_config c;
	char buf[4096], small[32];
	int n;

	(void)state;
	re_config_defaults(&c);
	c.mode = RE_MODE_DEVELOPMENT;
	n = re_config_dump(&c, buf, sizeof(buf));
	assert_int_equal(n, (int)strlen(buf));
	assert_non_null(strstr(buf, "mode development, period 50 ms, "
				    "controller 127.0.0.1:23023 (DMC4030"));
	assert_non_null(strstr(buf, "relay /tmp/roboelf-relay (devantech, "
				    "channel 1"));
	assert_non_null(strstr(buf, "; axis C: v 2000..8000 counts/s"));
	assert_null(strchr(buf, '\n'));
	assert_int_equal(re_config_dump(&c, small, sizeof(small)), n);
	assert_int_equal(strlen(small), sizeof(small) - 1);
	assert_memory_equal(small, buf, sizeof(small) - 1);
	assert_int_equal(re_config_dump(&c, NULL, 0), n);
}

/* ---- the site template, config/roboelf-site.yaml ---- */

#define SITE_FILE "config/roboelf-site.yaml"
#define ETC_NAME  "/etc/roboelf/roboelf.yaml" /* as installed */

/* Where the template leaves a value to fill in, in file order. */
struct fill_at {
	int line, column;
	const char *path;
};

static const struct fill_at site_fill[] = {
    {34, 12, "controller.address"},
    {44, 17, "controller.power_output"},
    {50, 18, "relay.port_clinical"},
    {56, 11, "relay.serial"},
    {64, 13, "relay.protocol"},
    {66, 12, "relay.channel"},
    {95, 11, "joystick.inputs"},
    {97, 15, "joystick.active_low"},
    {118, 11, "axes[0].vmax"},
    {121, 20, "axes[0].travel_counts"},
    {123, 9, "axes[0].kp"},
    {124, 9, "axes[0].ki"},
    {125, 9, "axes[0].kd"},
    {126, 21, "axes[0].torque_limit_v"},
    {135, 25, "axes[0].analog.expected_range_v"},
    {137, 18, "axes[0].analog.reverse_v"},
    {138, 18, "axes[0].analog.forward_v"},
    {149, 11, "axes[1].vmax"},
    {152, 20, "axes[1].travel_counts"},
    {154, 9, "axes[1].kp"},
    {155, 9, "axes[1].ki"},
    {156, 9, "axes[1].kd"},
    {157, 21, "axes[1].torque_limit_v"},
    {163, 25, "axes[1].analog.expected_range_v"},
    {165, 18, "axes[1].analog.reverse_v"},
    {166, 18, "axes[1].analog.forward_v"},
    {174, 11, "axes[2].vmax"},
    {177, 20, "axes[2].travel_counts"},
    {179, 9, "axes[2].kp"},
    {180, 9, "axes[2].ki"},
    {181, 9, "axes[2].kd"},
    {182, 21, "axes[2].torque_limit_v"},
    {188, 25, "axes[2].analog.expected_range_v"},
    {190, 18, "axes[2].analog.reverse_v"},
    {191, 18, "axes[2].analog.forward_v"},
};

#define N_SITE_FILL (sizeof(site_fill) / sizeof(site_fill[0]))

/* A site's values for site_fill[], in the same order: none is a default,
 * so the test sees each one read. */
static const char *const site_values[N_SITE_FILL] = {
    "192.0.2.10",
    "4",
    "/dev/roboelf-relay",
    "A10KXYZ9",
    "lcus",
    "2",
    "[2, 1, 3, 4, 5, 6, 7, 8, 17, 18, 19, 21]",
    "true",
    /* A */ "6000",
    "90000",
    "7",
    "2",
    "70",
    "4.5",
    "3.8",
    "0.6",
    "4.4",
    /* B */ "7000",
    "100000",
    "6",
    "1",
    "64",
    "5.0",
    "4.0",
    "0.5",
    "4.5",
    /* C */ "5000",
    "60000",
    "5.5",
    "0.5",
    "50",
    "3.0",
    "3.9", /* C's potentiometer: each within range_tolerance of the */
    "0.6", /* default of another, so that a deleted one is refused by */
    "4.3", /* the site-key rule, not the span's (test_site_key_deleted) */
};

/* The whole of @path, NUL-terminated; the test fails if it cannot be read. */
static char *slurp(const char *path, size_t *len)
{
	FILE *f = fopen(path, "rb");
	char *buf = malloc(65536);
	size_t n;

	assert_non_null(f);
	assert_non_null(buf);
	n = fread(buf, 1, 65535, f);
	assert_true(feof(f));
	fclose(f);
	buf[n] = '\0';
	*len = n;
	return buf;
}

/* The template as shipped is refused with every value to fill in, each at
 * its line and column, in file order, and nothing is applied. */
static void test_site_template_refused(void **state)
{
	static char want[RE_CONFIG_ERR_MAX], err[RE_CONFIG_ERR_MAX];
	struct re_config cfg, pattern;
	size_t len, n, i;
	char *buf = slurp(SITE_FILE, &len);

	(void)state;
	n = (size_t)snprintf(want, sizeof(want),
			     ETC_NAME ": this site's configuration is not "
				      "finished: 35 values are still FILL-IN");
	for (i = 0; i < N_SITE_FILL; i++)
		n += (size_t)snprintf(want + n, sizeof(want) - n,
				      "\n" ETC_NAME ":%d:%d: '%s' is still "
				      "FILL-IN",
				      site_fill[i].line, site_fill[i].column,
				      site_fill[i].path);
	assert_true(n < sizeof(want));
	memset(&cfg, 0xA5, sizeof(cfg));
	memset(&pattern, 0xA5, sizeof(pattern));
	assert_int_equal(
	    re_config_parse(buf, len, ETC_NAME, &cfg, err, sizeof(err)),
	    GL_ERR_CONFIG);
	assert_string_equal(err, want);
	assert_memory_equal(&cfg, &pattern, sizeof(cfg));
	free(buf);
}

/* @text with its value placeholders (": FILL-IN") replaced by
 * site_values[] in order; comments that name FILL-IN stay. */
static char *fill_in(const char *text)
{
	static const char mark[] = ": FILL-IN";
	char *out = malloc(strlen(text) + 65536), *o = out;
	const char *p = text, *q;
	size_t k = 0;

	assert_non_null(out);
	while ((q = strstr(p, mark)) != NULL) {
		assert_true(k < N_SITE_FILL);
		memcpy(o, p, (size_t)(q - p));
		o += q - p;
		o += sprintf(o, ": %s", site_values[k++]);
		p = q + sizeof(mark) - 1;
	}
	strcpy(o, p);
	assert_int_equal(k, N_SITE_FILL);
	return out;
}

/* Filled in, the template loads: clinical, and every value is the site's. */
static void test_site_template_filled(void **state)
{
	static const int joy[RE_JOY_INPUTS] = {2, 1, 3,	 4,  5,	 6,
					       7, 8, 17, 18, 19, 21};
	struct re_config c;
	char err[RE_CONFIG_ERR_MAX];
	size_t len;
	char *tmpl = slurp(SITE_FILE, &len), *text = fill_in(tmpl);
	const struct re_config_axis *a = c.axes, *cc = &c.axes[2];

	(void)state;
	assert_int_equal(parse_text(text, &c, err, sizeof(err)), GL_OK);
	assert_string_equal(err, "");
	assert_int_equal(c.mode, RE_MODE_CLINICAL);
	assert_string_equal(c.controller.address, "192.0.2.10");
	assert_int_equal(c.controller.power_output, 4);
	/* not site keys: the defaults */
	assert_int_equal(c.controller.record, RE_RECORD_POLL);
	assert_int_equal(c.controller.udp_port, 60007);
	assert_string_equal(c.relay.port_clinical, "/dev/roboelf-relay");
	assert_string_equal(c.relay.serial, "A10KXYZ9");
	assert_int_equal(c.relay.protocol, RE_RELAY_LCUS);
	assert_false(c.relay.readback); /* its default for lcus */
	assert_int_equal(c.relay.channel, 2);
	assert_memory_equal(c.joystick.inputs, joy, sizeof(joy));
	assert_true(c.joystick.active_low);
	assert_int_equal(a->vmax_cps, 6000);
	assert_int_equal(a->vmin_cps, 1500); /* vmax / 4 */
	assert_int_equal(a->travel_counts, 90000);
	assert_true(a->kp == 7 && a->ki == 2 && a->kd == 70);
	assert_true(a->torque_limit_v == 4.5);
	assert_true(a->analog.expected_range_v == 3.8);
	assert_true(a->analog.reverse_v == 0.6 && a->analog.forward_v == 4.4);
	assert_int_equal(c.axes[1].vmax_cps, 7000);
	assert_int_equal(cc->vmax_cps, 5000);
	assert_int_equal(cc->travel_counts, 60000);
	assert_true(cc->kp == 5.5 && cc->ki == 0.5 && cc->kd == 50);
	assert_true(cc->torque_limit_v == 3.0);
	assert_true(cc->analog.expected_range_v == 3.9);
	assert_true(cc->analog.reverse_v == 0.6 && cc->analog.forward_v == 4.3);
	assert_int_equal(cc->unit, RE_UNIT_MM);
	/* the site's state in its place: the package makes these
	 * directories for the group roboelf (docs/technician.md) */
	assert_string_equal(c.calibration.file,
			    "/var/lib/roboelf/roboelf-calibration.txt");
	assert_string_equal(c.log.path, "/var/log/roboelf/roboelf.log");
	assert_string_equal(c.recorder.dir, ""); /* next to the log */
	free(text);
	free(tmpl);
}

/* The filled template with the line of every site value deleted in turn:
 * refused, naming that key (it would take galil-sim's default); the keys
 * are the template's FILL-INs, in order (re_config_site_key()). */
static void test_site_key_deleted(void **state)
{
	char err[RE_CONFIG_ERR_MAX], want[256], key[64];
	struct re_config c;
	size_t len, k;
	char *tmpl = slurp(SITE_FILE, &len), *text = fill_in(tmpl);

	(void)state;
	for (k = 0; k < N_SITE_FILL; k++) {
		char *cut = strdup(text), *p = cut;

		assert_non_null(re_config_site_key((int)k, key, sizeof(key)));
		assert_string_equal(key, site_fill[k].path);
		for (int l = 1; l < site_fill[k].line; l++)
			p = strchr(p, '\n') + 1;
		memmove(p, strchr(p, '\n') + 1, strlen(strchr(p, '\n') + 1) + 1);
		assert_int_equal(parse_text(cut, &c, err, sizeof(err)),
				 GL_ERR_CONFIG);
		/* three have a rule of their own, checked first */
		if (k == 0)
			snprintf(want, sizeof(want), "'address' 127.0.0.1:23023 "
				 "is a loopback address; clinical mode needs the "
				 "real controller");
		else if (k == 2 || k == 3)
			snprintf(want, sizeof(want),
				 "'%s' must be set in clinical mode",
				 k == 2 ? "port_clinical" : "serial");
		else
			snprintf(want, sizeof(want),
				 "clinical mode: 1 value of this site is not "
				 "written: '%s'.",
				 site_fill[k].path);
		if (!strstr(err, want))
			fail_msg("%s deleted: %s", site_fill[k].path, err);
		free(cut);
	}
	assert_null(re_config_site_key((int)N_SITE_FILL, key, sizeof(key)));
	free(text);
	free(tmpl);
}

/* Relative names made absolute against the working directory, once; an
 * absolute one and "" (traces next to the log) kept; a result too long,
 * or no working directory, refused with the field named and nothing
 * changed. */
static void test_absolute(void **state)
{
	struct re_config c, before;
	char err[RE_CONFIG_ERR_MAX], cwd[300], want[400];

	(void)state;
	re_config_defaults(&c);
	assert_string_equal(c.calibration.file, "roboelf-calibration.txt");
	strcpy(c.log.path, "./logs/roboelf.log");
	assert_int_equal(re_config_absolute(&c, "/home/op", err, sizeof(err)),
			 GL_OK);
	assert_string_equal(c.calibration.file,
			    "/home/op/roboelf-calibration.txt");
	assert_string_equal(c.log.path, "/home/op/logs/roboelf.log");
	assert_string_equal(c.recorder.dir, "");
	strcpy(c.recorder.dir, "traces");
	assert_int_equal(re_config_absolute(&c, "/srv", err, sizeof(err)),
			 GL_OK);
	assert_string_equal(c.calibration.file,
			    "/home/op/roboelf-calibration.txt");
	assert_string_equal(c.recorder.dir, "/srv/traces");

	re_config_defaults(&c);
	strcpy(c.log.path, "/var/log/roboelf/roboelf.log");
	before = c;
	assert_int_equal(re_config_absolute(&c, "", err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(err, "calibration.file: 'roboelf-calibration.txt' "
				 "is relative to the working directory, "
				 "which is not known");
	assert_memory_equal(&c, &before, sizeof(c));
	strcpy(c.calibration.file, "/var/lib/roboelf/cal.txt");
	memset(cwd, 'd', sizeof(cwd));
	cwd[0] = '/';
	cwd[250] = '\0';
	strcpy(c.recorder.dir, "traces");
	before = c;
	assert_int_equal(re_config_absolute(&c, cwd, err, sizeof(err)),
			 GL_ERR_CONFIG);
	snprintf(want, sizeof(want),
		 "recorder.dir: 'traces' in '%s' is longer than 255 bytes: "
		 "give an absolute path",
		 cwd);
	assert_string_equal(err, want);
	assert_memory_equal(&c, &before, sizeof(c));
}

/* The placeholder is found wherever it is: quoted, in a list, in a flow
 * mapping, under an unknown key (before that key is refused); one value
 * reads "1 value is". */
static void test_fill_in_anywhere(void **state)
{
	struct re_config c;
	char err[RE_CONFIG_ERR_MAX];

	(void)state;
	assert_int_equal(parse_text("relay: {port_clinical: \"FILL-IN\"}\n"
				    "joystick:\n"
				    "  inputs: [1, 2, FILL-IN]\n"
				    "axes:\n"
				    "  - {analog: {reverse_v: FILL-IN}}\n"
				    "colour: 'FILL-IN'\n",
				    &c, err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(
	    err, "t.yaml: this site's configuration is not finished: 4 "
		 "values are still FILL-IN\n"
		 "t.yaml:1:24: 'relay.port_clinical' is still FILL-IN\n"
		 "t.yaml:3:18: 'joystick.inputs[2]' is still FILL-IN\n"
		 "t.yaml:5:26: 'axes[0].analog.reverse_v' is still FILL-IN\n"
		 "t.yaml:6:9: 'colour' is still FILL-IN");
	assert_int_equal(
	    parse_text("period_ms: 20\nmode: FILL-IN\n", &c, err, sizeof(err)),
	    GL_ERR_CONFIG);
	assert_string_equal(err, "t.yaml: this site's configuration is not "
				 "finished: 1 value is still FILL-IN\n"
				 "t.yaml:2:7: 'mode' is still FILL-IN");
	/* met again through an alias, it is still the one place */
	assert_int_equal(parse_text("a: &x [1, FILL-IN]\nb: [*x, *x]\n"
				    "c: *x\nd: FILL-IN\n",
				    &c, err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(err, "t.yaml: this site's configuration is not "
				 "finished: 2 values are still FILL-IN\n"
				 "t.yaml:1:11: 'a[1]' is still FILL-IN\n"
				 "t.yaml:4:4: 'd' is still FILL-IN");
	/* a value that merely contains the word is a value */
	assert_int_equal(parse_text("mode: development\n"
				    "log: {path: FILL-IN.log}\n",
				    &c, err, sizeof(err)),
			 GL_OK);
	assert_string_equal(c.log.path, "FILL-IN.log");
}

/* A list longer than the buffer ends with whole lines and the count of
 * those left out. */
static void test_fill_in_list_cut(void **state)
{
	static const char head[] = "t.yaml: this site's configuration is not "
				   "finished: 3 values are still FILL-IN";
	static const char first[] =
	    "\nt.yaml:2:12: 'controller.address' is still FILL-IN";
	char err[RE_CONFIG_ERR_MAX];
	struct re_config c;

	(void)state;
	/* room for the first line and 40 bytes more: not for the second */
	assert_int_equal(parse_text("controller:\n"
				    "  address: FILL-IN\n"
				    "  model: FILL-IN\n"
				    "relay: {port_clinical: FILL-IN}\n",
				    &c, err, strlen(head) + strlen(first) + 40),
			 GL_ERR_CONFIG);
	assert_string_equal(err, "t.yaml: this site's configuration is not "
				 "finished: 3 values are still FILL-IN\n"
				 "t.yaml:2:12: 'controller.address' is still "
				 "FILL-IN\n"
				 "... and 2 more");
}

int main(void)
{
	static const struct CMUnitTest fixed[] = {
	    cmocka_unit_test(test_defaults_documented),
	    cmocka_unit_test(test_defaults_refused_clinical),
	    cmocka_unit_test(test_default_file_loads),
	    cmocka_unit_test(test_minimal_file),
	    cmocka_unit_test(test_round_trip_every_field),
	    cmocka_unit_test(test_vmin_follows_vmax),
	    cmocka_unit_test(test_controller_timeout_auto),
	    cmocka_unit_test(test_readback_default),
	    cmocka_unit_test(test_clinical_accepted),
	    cmocka_unit_test(test_relay_serial),
	    cmocka_unit_test(test_validate_overrides),
	    cmocka_unit_test(test_quoted_strings),
	    cmocka_unit_test(test_buffer_not_terminated),
	    cmocka_unit_test(test_missing_file),
	    cmocka_unit_test(test_short_error_buffer),
	    cmocka_unit_test(test_hash),
	    cmocka_unit_test(test_dump),
	    cmocka_unit_test(test_site_template_refused),
	    cmocka_unit_test(test_site_template_filled),
	    cmocka_unit_test(test_site_key_deleted),
	    cmocka_unit_test(test_absolute),
	    cmocka_unit_test(test_fill_in_anywhere),
	    cmocka_unit_test(test_fill_in_list_cut),
	};
	enum { N_FIXED = sizeof(fixed) / sizeof(fixed[0]) };
	static struct CMUnitTest tests[N_FIXED + N_BAD];
	size_t i;

	memcpy(tests, fixed, sizeof(fixed));
	for (i = 0; i < N_BAD; i++) {
		tests[N_FIXED + i].name = bad_cases[i].file;
		tests[N_FIXED + i].test_func = test_bad_file;
		tests[N_FIXED + i].initial_state = (void *)&bad_cases[i];
	}
	return _cmocka_run_group_tests("re_config", tests, N_FIXED + N_BAD,
				       NULL, NULL);
}
