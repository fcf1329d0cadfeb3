/*
 * re_config.h - the supervisor's configuration (YAML, read with libyaml).
 *
 * Every field is typed and range-checked; unknown keys, duplicate keys, an
 * empty file and a root that is not a mapping are rejected. Errors read
 * "FILE:LINE:COLUMN: message" (1-based), e.g.
 *   roboelf.yaml:12:3: unknown key 'relay_prot'
 * and nothing is applied on error. docs/config.md documents every field,
 * its unit, range and default; config/roboelf.yaml is the commented default.
 *
 * Units: positions and steps in encoder counts, velocities in counts/s,
 * times in ms, analog values in volts, tolerances as fractions (0.1 = 10 %).
 */
#ifndef RE_CONFIG_H
#define RE_CONFIG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "re_bind.h"
#include "re_dmcif.h"
#include "re_relay.h"

#define RE_NAME_MAX	  16   /* axis name, bytes including the NUL */
#define RE_ADDR_MAX	  128  /* controller address, bytes incl. NUL */
#define RE_MODEL_MAX	  32   /* controller model, bytes incl. NUL */
#define RE_PATH_MAX	  256  /* file paths, bytes incl. NUL */
#define RE_CONFIG_ERR_MAX 8192 /* a good size for the @err buffers */
/* most table points per axis: travel_counts / step_counts at most this */
#define RE_CONFIG_POINTS_MAX 10000
/* The value a site configuration (config/roboelf-site.yaml) leaves in every
 * field the technician must set. It is never a valid value: the loader
 * refuses a file holding it, listing every place it is left, one line of
 * about 100 bytes each (34 in that file: RE_CONFIG_ERR_MAX holds them). */
#define RE_CONFIG_FILL_IN "FILL-IN"

/* How the cycle gets the controller's data record (docs/link.md). */
enum re_record {
	RE_RECORD_POLL = 0, /* default: one "hbpc=N;QR" round trip a cycle */
	RE_RECORD_STREAM,   /* the controller sends it (DR) to a UDP handle */
};

enum re_mode {
	RE_MODE_CLINICAL = 0, /* default: real relay through libserialport,
			       * real (non-loopback) controller */
	RE_MODE_DEVELOPMENT,  /* simulator allowed: pty relay, loopback */
};

struct re_config_controller {
	char address[RE_ADDR_MAX]; /* "host", "host:port", "[v6]:port" */
	char model[RE_MODEL_MAX];  /* expected model, e.g. "DMC4030" */
	int timeout_ms;		   /* deadline of one command reply */
	int connect_timeout_ms;	   /* deadline of the TCP connect */
	int power_output;	   /* digital output that closes the motor-
				    * power chain (DMC pwrout), 0: none */
	enum re_record record;	   /* how the cycle gets the record */
	int udp_port;		   /* the controller's UDP command port,
				    * where the record stream's handle
				    * opens (60007 on a DMC-40x0) */
};

struct re_config_relay {
	char port_clinical[RE_PATH_MAX];    /* used in clinical mode */
	char port_development[RE_PATH_MAX]; /* used in development mode */
	char serial[RE_BIND_SERIAL_MAX];    /* the relay board's USB serial
					     * number (re_bind.h); clinical:
					     * required */
	enum re_relay_proto protocol;
	int channel; /* 1..8 */
	enum re_relay_backend backend;
	int baud;	      /* bits/s */
	int write_timeout_ms; /* deadline of "on", ms */
	int off_deadline_ms;  /* deadline of "off" confirmed, ms */
	bool readback;	      /* Devantech state query */
	int readback_timeout_ms;
	uint8_t on[RE_RELAY_CODE_MAX]; /* protocol {on:, off:} only */
	size_t on_len;
	uint8_t off[RE_RELAY_CODE_MAX];
	size_t off_len;
	char icstation_state[RE_PATH_MAX]; /* handshake record file */
};

struct re_config_watchdog {
	double noncritical_factor; /* x period_ms: logged, no stop */
	double critical_factor;	   /* x period_ms: WATCHDOG fault */
	int controller_timeout_ms; /* DMC-side watchdog (wdto), ms */
};

struct re_config_joystick {
	/* Digital input number (1..8, 17..48) of each switch, in the order
	 * A fwd a, A fwd b, A rev a, A rev b, B fwd a, B fwd b, B rev a,
	 * B rev b, C fwd a, C fwd b, C rev a, C rev b (= DMC jin[0..11]). */
	int inputs[RE_JOY_INPUTS];
	bool active_low;	/* closed switch reads 0 (DMC jpol) */
	int invalid_timeout_ms; /* DMC jto */
};

/* The unit an axis is shown in on the console. */
enum re_unit {
	RE_UNIT_DEG = 0, /* a rotary axis, degrees */
	RE_UNIT_MM,	 /* a linear axis, millimetres */
};

/* re_record_name() - "poll" or "stream". */
const char *re_record_name(enum re_record r);

/* re_unit_name() - "deg" or "mm". */
const char *re_unit_name(enum re_unit u);

struct re_config_encoder_failure {
	bool enabled;	  /* OA */
	int time_samples; /* OT, servo samples, 2..32000 */
	double torque_v;  /* OV, volts */
};

struct re_config_analog {
	int input;		     /* analog input 1..8 (AN[n]) */
	double expected_range_v;     /* pot span over the full travel, V */
	double range_tolerance;	     /* fraction of expected_range_v */
	double reverse_v;	     /* pot at the reverse limit switch, V */
	double forward_v;	     /* pot at the forward limit switch, V */
	double absolute_tolerance_v; /* how far a real pot may read from
				      * reverse_v / forward_v there, V */
};

struct re_config_axis {
	char name[RE_NAME_MAX];	 /* "A", "B", "C" by default */
	int vmax_cps;		 /* maximum velocity, counts/s */
	int vmin_cps;		 /* minimum (starting) velocity, counts/s;
				  * default vmax_cps / 4 */
	int accel_start_ms;	 /* acceleration window start */
	int accel_end_ms;	 /* acceleration window end */
	int step_counts;	 /* table step and tracking step */
	int travel_counts;	 /* expected hard-limit to hard-limit
				  * travel, counts */
	double travel_tolerance; /* fraction of travel_counts */
	double kp, ki, kd;	 /* PID gains (KP, KI, KD) */
	double torque_limit_v;	 /* TL, volts */
	int position_error_limit_counts; /* ER */
	bool off_on_error;		 /* OE */
	struct re_config_encoder_failure encoder_failure;
	struct re_config_analog analog;
	double allowed_error;	   /* fraction of the local pot step */
	int persistence_cycles;	   /* cycles an ENCODER mismatch must
				    * last before it is a fault, >= 1 */
	double monotonic_margin_v; /* calibration noise margin, V */
	/* How the console shows this axis (display only: no check, no
	 * calibration depends on it): @unit "deg" or "mm", @counts_per_unit
	 * encoder counts per degree or mm; 0: not known, counts are shown. */
	enum re_unit unit;
	double counts_per_unit;
};

struct re_config_calibration {
	char file[RE_PATH_MAX]; /* calibration table file */
	bool backup;		/* keep the previous file as FILE.bak */
	int backoff_counts;	/* distance backed off a hard limit */
	int move_timeout_ms;	/* deadline of one calibration move */
	int travel_cps;		/* speed of the moves that measure nothing
				 * (to a switch, to the centre); 0: each
				 * axis's vmax */
	int seek_cps;		/* speed where a limit switch may be near;
				 * 0: each axis's vmax / 2 */
	int near_margin_counts; /* the slow zone starts this far before the
				 * earliest place a switch can be */
};

struct re_config_log {
	char path[RE_PATH_MAX];
	long max_bytes; /* rotate when the file reaches this */
	int keep;	/* rotated files kept: PATH.1 .. PATH.n */
};

/* The flight recorder (docs/trace-format.md). */
struct re_config_recorder {
	double seconds;	       /* a trace holds this much before a fault, s */
	double after_fault_s;  /* and this much after it, s (< seconds) */
	char dir[RE_PATH_MAX]; /* where traces go; "": the log's directory */
};

/* Real-time set-up of the supervisor's thread (pc/super/re_rt.h). */
struct re_config_realtime {
	int priority;	  /* SCHED_FIFO 1..99; 0: not requested */
	int cpu;	  /* pin the cycle to this CPU; -1: not pinned */
	bool lock_memory; /* mlockall before the first cycle */
};

struct re_config {
	enum re_mode mode;
	int period_ms; /* supervisor cycle, 2..100 */
	struct re_config_controller controller;
	struct re_config_relay relay;
	struct re_config_watchdog watchdog;
	struct re_config_joystick joystick;
	struct re_config_axis axes[RE_AXES];
	struct re_config_calibration calibration;
	struct re_config_log log;
	struct re_config_recorder recorder;
	struct re_config_realtime realtime;
};

/*
 * re_config_defaults() - fill @out with the documented defaults.
 * The defaults are safe, not convenient: mode is clinical, and the clinical
 * relay port is empty, so a clinical start without a configured relay fails
 * validation. config/roboelf.yaml is the development default.
 * @out: [out] must not be NULL.
 */
void re_config_defaults(struct re_config *out);

/*
 * re_config_parse() - parse a YAML configuration held in memory.
 * @buf: [in] the file content (need not be NUL-terminated).
 * @len: length of @buf, bytes.
 * @filename: [in] name used in messages (e.g. "roboelf.yaml"); NULL gives
 *            "<config>".
 * @out: [out] the configuration: defaults overridden by the file. Written
 *       only on success; untouched on error (nothing half-applied).
 * @err: [out] optional; on error "FILE:LINE:COLUMN: message".
 * @errlen: size of @err (RE_CONFIG_ERR_MAX is enough).
 * Fields absent from the file keep their defaults; the result is validated
 * as re_config_validate() does, each cross-field error reported at the
 * position of the later of the fields involved.
 * A file with RE_CONFIG_FILL_IN values (a site configuration not finished)
 * is refused before anything else is checked, with every place listed, one
 * line each, in the order of the file:
 *   "FILE: this site's configuration is not finished: N values are still
 *   FILL-IN\nFILE:LINE:COLUMN: 'controller.address' is still FILL-IN\n..."
 * (a list longer than @errlen ends "... and N more").
 * Return: GL_OK; GL_ERR_CONFIG (syntax, unknown or duplicate key, wrong
 *         type, out of range, inconsistent, not filled in); GL_ERR_NOMEM.
 */
int re_config_parse(const char *buf, size_t len, const char *filename,
		    struct re_config *out, char *err, size_t errlen);

/*
 * re_config_load_file() - read @path and re_config_parse() it.
 * Messages use @path as FILE. A file that cannot be read gives
 * "cannot read 'PATH': <strerror>" (no position).
 * Return: as re_config_parse(), plus GL_ERR_SYS (errno kept) when the file
 *         cannot be read; errno is 0 after any other return.
 */
int re_config_load_file(const char *path, struct re_config *out, char *err,
			size_t errlen);

/*
 * re_config_site_key() - the @i-th value only a site can know (from 0, in
 * the order of the site template, config/roboelf-site.yaml, where each is
 * FILL-IN), e.g. "controller.address", "axes[1].analog.reverse_v". A
 * clinical configuration must write every one: one left out is refused
 * (re_config_parse()) instead of taking the built-in default, which is
 * galil-sim's robot.
 * Return: the key in @buf (@cap bytes), or NULL past the last one.
 */
const char *re_config_site_key(int i, char *buf, size_t cap);

/*
 * re_config_validate() - check the ranges and cross-field rules of @cfg,
 * e.g. after command-line overrides (--period, --relay, --galil).
 * @err: [out] optional; on error a message without position, e.g.
 *       "'period_ms' must be between 2 and 100, got 500".
 * Return: GL_OK or GL_ERR_CONFIG.
 */
int re_config_validate(const struct re_config *cfg, char *err, size_t errlen);

/*
 * re_config_relay_port() - the relay port for @cfg's operating mode.
 * Return: relay.port_clinical or relay.port_development; never NULL.
 */
const char *re_config_relay_port(const struct re_config *cfg);

/*
 * re_config_relay_cfg() - the settings for re_relay_open(): the port of the
 * current mode, protocol, channel, back-end, and clinical = (mode is
 * clinical).
 * @out: [out] must not be NULL.
 */
void re_config_relay_cfg(const struct re_config *cfg, struct re_relay_cfg *out);

/*
 * re_config_hash() - FNV-1a 64 (pc/galil/gl_hash.h) over the fields a
 * calibration table depends on: per axis its name, step_counts, travel_counts,
 * travel_tolerance, analog input, expected_range_v, range_tolerance,
 * allowed_error and monotonic_margin_v. A calibration file whose hash
 * differs was made for another configuration.
 */
uint64_t re_config_hash(const struct re_config *cfg);

/*
 * re_config_absolute() - the files the configuration names relative to the
 * directory a program is started in - calibration.file, log.path and
 * recorder.dir (unless "") - made absolute against @cwd
 * (base_paths_absolute()). Called once at start, before anything is opened:
 * every line that names one of them then names it in full, and nothing is
 * resolved later (no allocation, no lookup in the cycle).
 * @cwd: the working directory at start, absolute; "" when it is not known
 *       (a relative name is then an error)
 * Return: GL_OK, or GL_ERR_CONFIG with @err naming the field and the value
 * (the result longer than RE_PATH_MAX - 1 bytes, or no working directory);
 * @cfg is then unchanged.
 */
int re_config_absolute(struct re_config *cfg, const char *cwd, char *err,
		       size_t errlen);

/*
 * re_config_dump() - a one-paragraph summary for the log (no newline).
 * @buf: [out] NUL-terminated, truncated to @cap.
 * Return: the length the full summary needs (as snprintf).
 */
int re_config_dump(const struct re_config *cfg, char *buf, size_t cap);

/* re_mode_name() - "clinical" or "development". */
const char *re_mode_name(enum re_mode mode);

#endif /* RE_CONFIG_H */
