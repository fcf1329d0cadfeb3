/*
 * roboelf.c - the RoboELF operator's console supervisor (robotTask and its
 * GUI, rebuilt): options, the life cycle Configure -> Startup -> Run every
 * period -> Cleanup, signals and exit codes.
 *
 *   roboelf [-c FILE] [--galil HOST[:PORT]] [--relay PORT]
 *           [--calibration full|file] [--period MS] [--log FILE]
 *   roboelf --show-calibration FILE
 *
 * Exit codes: 0 normal quit; 2 configuration or usage error (also: a
 * calibration file that cannot be used, without a terminal to offer a full
 * calibration); 3 no relay, no controller, or the controller refused the
 * start-up (wrong program, read-back differs); 4 a fault was latched.
 *
 * Power-on order (docs/supervisor.md): the relay opened and kept off; the
 * controller identified, refused when another supervisor runs it, other
 * connections closed, program identity checked; what will move chosen by
 * the operator (or --calibration); the program halted and every motor read
 * back off; configured and read back; the amplifiers seen without motor
 * power; the program started; only then the relay closes (and the
 * amplifiers see power); parameters; the service state, in which the
 * calibration (or the check of the file) and the move to the centre run as
 * supervised cycles; back to the safe state; the file saved; armed; "RoboELF
 * Ready for Use". Any fault on the way, or in the cycle, goes through
 * re_super_fault(). Power-off is the reverse (re_super_shutdown()).
 */
#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link.h"
#include "re_calfile.h"
#include "re_calib.h"
#include "re_calshow.h"
#include "re_check.h"
#include "re_config.h"
#include "re_console.h"
#include "re_ctl.h"
#include "re_io.h"
#include "re_lock.h"
#include "re_log.h"
#include "re_plan.h"
#include "re_relay.h"
#include "re_super.h"

#define EXIT_USAGE     2
#define EXIT_CONNECT   3
#define EXIT_FAULT     4
#define DEFAULT_CONFIG "config/roboelf.yaml"

struct opts {
	const char *config;
	const char *galil;
	const char *relay;
	const char *log;
	const char *show_cal;
	int period_ms; /* 0: from the configuration */
	enum re_calib_choice calib;
};

struct app {
	struct opts o;
	struct re_config cfg;
	struct re_log log;
	struct re_console con;
	re_relay *relay;
	struct re_lock lock_ctl, lock_relay; /* one supervisor per each */
	struct re_io_real real; /* real.link: the command link */
	struct re_io io;
	struct re_ctl_info info;
	struct re_plan plan;
	struct re_calset *cal;
	struct re_super *sup;
	const char *names[RE_AXES];
	long hbpc;
	int calib;   /* the operator's choice: RE_CALIB_FULL / _FILE */
	int powered; /* the relay was switched on at some point */
	unsigned foreign_shown; /* other programs' handles already shown */
	int ctl_ours; /* the controller was taken over: ours to stop */
	char err[RE_CONFIG_ERR_MAX];
};

static volatile sig_atomic_t quit_signal;

static void on_signal(int sig)
{
	quit_signal = sig;
}

/* A stop (SIGSTOP, a debugger) during start-up: the cycle measures its own
 * gaps, but start-up is a sequence of waits and commands. SIGCONT says
 * the process was stopped; the stop lasted from the last moment it is
 * known to have run (a link call's start or end) to the SIGCONT. */
static volatile sig_atomic_t continued;
static volatile int64_t cont_stop_ms;
static struct re_io_real *volatile cont_real;

static void on_cont(int sig)
{
	int64_t now, from;

	(void)sig;
	now = base_now_ns();
	from = cont_real ? cont_real->last_run_ns : now;
	cont_stop_ms = (now - from) / 1000000;
	continued = 1;
}

/* Every signal a terminal or a person can send ends in the orderly
 * shutdown (the safe state), never in a kill or a freeze with power on:
 * Ctrl-C, Ctrl-\, SIGTERM and a lost terminal (SIGHUP) quit; Ctrl-Z and
 * background terminal I/O are ignored; a closed pipe is an error return. */
static void install_signals(void)
{
	static const int quit[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
	static const int ignore[] = {SIGPIPE, SIGTSTP, SIGTTIN, SIGTTOU};
	struct sigaction sa;

	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal;
	sigemptyset(&sa.sa_mask);
	for (size_t i = 0; i < sizeof(quit) / sizeof(quit[0]); i++)
		sigaction(quit[i], &sa, NULL);
	sa.sa_handler = on_cont;
	sa.sa_flags = SA_RESTART;
	sigaction(SIGCONT, &sa, NULL);
	sa.sa_flags = 0;
	sa.sa_handler = SIG_IGN;
	for (size_t i = 0; i < sizeof(ignore) / sizeof(ignore[0]); i++)
		sigaction(ignore[i], &sa, NULL);
}

/* ---- options ----------------------------------------------------------- */

static void usage(FILE *f)
{
	fprintf(
	    f,
	    "usage: roboelf [-c FILE] [--galil HOST[:PORT]] [--relay PORT]\n"
	    "               [--calibration full|file] [--period MS] "
	    "[--log FILE]\n"
	    "       roboelf --show-calibration FILE\n"
	    "\n"
	    "  -c, --config FILE        configuration (default %s)\n"
	    "      --galil HOST[:PORT]  controller address (overrides the "
	    "file)\n"
	    "      --relay PORT         E-stop relay port for this mode\n"
	    "      --calibration MODE   full: calibrate now; file: load "
	    "the tables\n"
	    "      --period MS          supervisor period, 2..100 ms\n"
	    "      --log FILE           failure log\n"
	    "      --show-calibration FILE  print a calibration file (and "
	    "plot it)\n"
	    "  -h, --help               this text\n"
	    "\n"
	    "exit: 0 quit, 2 usage/config, 3 no relay/controller, "
	    "4 fault latched\n",
	    DEFAULT_CONFIG);
}

static int parse_period(const char *s, int *out)
{
	char *end;
	long v;

	errno = 0;
	v = strtol(s, &end, 10);
	if (errno || end == s || *end || v < 2 || v > 100)
		return -1;
	*out = (int)v;
	return 0;
}

static int parse_calib(const char *s, enum re_calib_choice *out)
{
	if (!strcmp(s, "full"))
		*out = RE_CALIB_FULL;
	else if (!strcmp(s, "file"))
		*out = RE_CALIB_FILE;
	else
		return -1;
	return 0;
}

static int opt_value(struct opts *o, int c, const char *arg)
{
	switch (c) {
	case 'c': o->config = arg; return 0;
	case 'g': o->galil = arg; return 0;
	case 'r': o->relay = arg; return 0;
	case 'l': o->log = arg; return 0;
	case 's': o->show_cal = arg; return 0;
	case 'p':
		if (parse_period(arg, &o->period_ms) == 0)
			return 0;
		fprintf(stderr,
			"roboelf: error: invalid period '%s': must be "
			"2..100 ms\n",
			arg);
		return -1;
	case 'k':
		if (parse_calib(arg, &o->calib) == 0)
			return 0;
		fprintf(stderr,
			"roboelf: error: invalid calibration '%s': "
			"use full or file\n",
			arg);
		return -1;
	default: usage(stderr); return -1;
	}
}

/* Return: 0 to run, 1 after --help, -1 on a usage error. */
static int parse_opts(int argc, char **argv, struct opts *o)
{
	static const struct option lo[] = {
	    {"config", required_argument, NULL, 'c'},
	    {"galil", required_argument, NULL, 'g'},
	    {"relay", required_argument, NULL, 'r'},
	    {"calibration", required_argument, NULL, 'k'},
	    {"period", required_argument, NULL, 'p'},
	    {"log", required_argument, NULL, 'l'},
	    {"show-calibration", required_argument, NULL, 's'},
	    {"help", no_argument, NULL, 'h'},
	    {NULL, 0, NULL, 0},
	};
	int c;

	memset(o, 0, sizeof(*o));
	o->config = DEFAULT_CONFIG;
	while ((c = getopt_long(argc, argv, "c:h", lo, NULL)) != -1) {
		if (c == 'h') {
			usage(stdout);
			return 1;
		}
		if (opt_value(o, c, optarg) < 0)
			return -1;
	}
	if (optind < argc) {
		fprintf(stderr, "roboelf: error: unexpected argument '%s'\n",
			argv[optind]);
		return -1;
	}
	return 0;
}

/* ---- configuration and log ---------------------------------------------- */

static void apply_overrides(struct app *a)
{
	struct re_config *c = &a->cfg;
	char *port = c->mode == RE_MODE_CLINICAL ? c->relay.port_clinical
						 : c->relay.port_development;

	if (a->o.galil)
		snprintf(c->controller.address, sizeof(c->controller.address),
			 "%s", a->o.galil);
	if (a->o.relay)
		snprintf(port, RE_PATH_MAX, "%s", a->o.relay);
	if (a->o.period_ms)
		c->period_ms = a->o.period_ms;
	if (a->o.log)
		snprintf(c->log.path, sizeof(c->log.path), "%s", a->o.log);
}

static int check_analog(const struct re_config *c, char *err, size_t len)
{
	for (int i = 0; i < RE_AXES; i++) {
		if (c->axes[i].analog.input > RE_AXES) {
			snprintf(err, len,
				 "axis '%s': analog input %d is not "
				 "in the DMC-4030 data record (use 1..%d)",
				 c->axes[i].name, c->axes[i].analog.input,
				 RE_AXES);
			return GL_ERR_CONFIG;
		}
	}
	return GL_OK;
}

static int load_config(struct app *a)
{
	if (re_config_load_file(a->o.config, &a->cfg, a->err, sizeof(a->err)) !=
	    GL_OK) {
		fprintf(stderr, "%s\n", a->err);
		return -1;
	}
	apply_overrides(a);
	if (re_config_validate(&a->cfg, a->err, sizeof(a->err)) != GL_OK ||
	    check_analog(&a->cfg, a->err, sizeof(a->err)) != GL_OK) {
		fprintf(stderr, "roboelf: error: %s\n", a->err);
		return -1;
	}
	for (int i = 0; i < RE_AXES; i++)
		a->names[i] = a->cfg.axes[i].name;
	return 0;
}

static int open_log(struct app *a)
{
	struct re_log_cfg lc = re_log_cfg_default();
	char dump[1536];
	int rc;

	lc.max_bytes = (size_t)a->cfg.log.max_bytes;
	lc.keep = a->cfg.log.keep; /* 1..9, checked by the config loader */
	rc = re_log_open(&a->log, a->cfg.log.path, &lc);
	if (rc != GL_OK) {
		fprintf(stderr, "roboelf: error: cannot open log '%s': %s\n",
			a->cfg.log.path,
			rc == GL_ERR_SYS ? strerror(errno) : gl_strerror(rc));
		return -1;
	}
	re_log_msg(&a->log, RE_LOG_INFO, "start: roboelf, config '%s'",
		   a->o.config);
	re_config_dump(&a->cfg, dump, sizeof(dump));
	re_log_msg(&a->log, RE_LOG_INFO, "config: %s", dump);
	return 0;
}

/* ---- start-up ------------------------------------------------------------ */

static void progress(struct app *a, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void progress(struct app *a, const char *fmt, ...)
{
	char text[512];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(text, sizeof(text), fmt, ap);
	va_end(ap);
	re_console_msg(&a->con, "roboelf: %s", text);
	re_log_msg(&a->log, RE_LOG_INFO, "%s", text);
	a->real.last_run_ns = re_io_now_ns();
}

static int64_t stalled_ms(const struct app *a);
static int64_t stall_limit_ms(const struct app *a);

/* The start refused with @what; a stop just before is named first. */
static int fail(struct app *a, const char *what)
{
	int64_t ms = stalled_ms(a);

	if (ms)
		re_console_msg(&a->con,
			       "roboelf: error: roboelf did not run for %lld ms "
			       "(limit %lld ms: stopped, e.g. SIGSTOP or a "
			       "debugger); then: %s",
			       (long long)ms, (long long)stall_limit_ms(a),
			       what);
	else
		re_console_msg(&a->con, "roboelf: error: %s", what);
	re_log_msg(&a->log, RE_LOG_WARN, "start-up refused: %s%s", what,
		   ms ? " (after a stop of roboelf itself)" : "");
	return EXIT_CONNECT;
}

/* One supervisor per controller and per relay: both locks before the
 * relay is opened (opening switches it off: a second roboelf must not cut
 * the first one's motor power) and before the controller is touched. */
static int take_locks(struct app *a)
{
	char key[RE_LOCK_PATH_MAX];
	const char *port = re_config_relay_port(&a->cfg);

	if (re_lock_controller_key(a->cfg.controller.address, key,
				   sizeof(key)) != GL_OK) {
		snprintf(a->err, sizeof(a->err),
			 "bad controller address '%s'",
			 a->cfg.controller.address);
		return fail(a, a->err);
	}
	if (re_lock_acquire(&a->lock_ctl, "controller", key, a->err,
			    sizeof(a->err)) != GL_OK)
		return fail(a, a->err);
	if (re_lock_relay_key(port, key, sizeof(key)) != GL_OK) {
		snprintf(a->err, sizeof(a->err),
			 "cannot open the E-stop relay '%s': %s (is galil-sim "
			 "running, or the relay plugged in?)",
			 port, strerror(errno));
		return fail(a, a->err);
	}
	if (re_lock_acquire(&a->lock_relay, "relay", key, a->err,
			    sizeof(a->err)) != GL_OK)
		return fail(a, a->err);
	return 0;
}

/* The relay opened (which switches it off) and kept off. */
static int start_relay(struct app *a)
{
	struct re_relay_cfg rc;

	re_config_relay_cfg(&a->cfg, &rc);
	progress(a, "opening the E-stop relay '%s' (motor power stays off)",
		 rc.port);
	if (re_relay_open(&a->relay, &rc, a->err, sizeof(a->err)) != GL_OK)
		return fail(a, a->err);
	a->real.relay = a->relay;
	return 0;
}

/* Connect, identify, refuse a controller another supervisor runs, close
 * the other connections, check the program's identity. */
static int start_link(struct app *a)
{
	char e[GL_ERRTEXT_LEN];
	char id[256];
	gl_link *l;

	progress(a, "connecting to the controller at %s",
		 a->cfg.controller.address);
	if (gl_link_open(&l, a->cfg.controller.address,
			 a->cfg.controller.connect_timeout_ms, e) != GL_OK)
		return fail(a, e);
	gl_link_set_timeout(l, a->cfg.controller.timeout_ms);
	a->real.link = l;
	a->real.address = a->cfg.controller.address;
	a->real.cmd_timeout_ms = a->cfg.controller.timeout_ms;
	if (re_ctl_identify(l, &a->cfg, &a->info, a->err, sizeof(a->err)) ||
	    re_ctl_check_busy(&a->io, a->cfg.watchdog.controller_timeout_ms,
			      a->err, sizeof(a->err)) ||
	    re_ctl_take_over(l, &a->info, a->err, sizeof(a->err)))
		return fail(a, a->err);
	a->ctl_ours = 1;
	snprintf(id, sizeof(id), "%s, serial %ld, program id %016llX",
		 a->info.model, a->info.serial,
		 (unsigned long long)a->info.program_id);
	progress(a, "controller %s", id);
	return 0;
}

/* In development mode (the simulator, a bench) an amplifier check that
 * fails is logged; in clinical mode it refuses the start. */
static int amp_check(struct app *a, int want_on, int timeout_ms)
{
	int ta0 = 0;

	if (re_ctl_amp_power(&a->io, want_on, timeout_ms, &ta0, a->err,
			     sizeof(a->err)) == GL_OK)
		return 0;
	if (a->cfg.mode == RE_MODE_CLINICAL)
		return fail(a, a->err);
	re_console_msg(&a->con, "roboelf: warning: %s (development mode: "
				"continuing)", a->err);
	re_log_msg(&a->log, RE_LOG_WARN, "%s (development mode)", a->err);
	return 0;
}

/* Halted and read back off, configured, no motor power seen, program
 * started: the controller is known safe before the relay closes. */
static int prepare_controller(struct app *a)
{
	re_plan_make(&a->cfg, 0, &a->plan);
	progress(a, "halting the controller program; every motor off");
	if (re_ctl_halt(&a->io, a->err, sizeof(a->err)) ||
	    re_ctl_configure(&a->io, &a->cfg, &a->plan, a->err,
			     sizeof(a->err)))
		return fail(a, a->err);
	progress(a, "controller configured and read back");
	if (amp_check(a, 0, 200))
		return EXIT_CONNECT;
	if (re_ctl_start_program(&a->io, &a->info, a->err, sizeof(a->err)))
		return fail(a, a->err);
	re_plan_make(&a->cfg, a->info.mainms, &a->plan);
	return 0;
}

static int power_on(struct app *a)
{
	if (re_relay_on(a->relay) != GL_OK) {
		snprintf(a->err, sizeof(a->err),
			 "cannot switch motor power on: %s",
			 re_relay_errmsg(a->relay));
		return fail(a, a->err);
	}
	a->powered = 1;
	progress(a, "motor power on (relay closed); the motors are off");
	return amp_check(a, 1, 500);
}

static int init_super(struct app *a)
{
	struct re_super_cfg sc;

	re_plan_super_cfg(&a->plan, &a->cfg, a->names, &sc);
	a->sup = calloc(1, sizeof(*a->sup));
	if (!a->sup || re_super_init(a->sup, &a->io, &sc, NULL, 0) != GL_OK)
		return fail(a, "cannot set up the supervisor");
	return 0;
}

/* The critical reply-age limit, ms: a stop longer than this is a stall. */
static int64_t stall_limit_ms(const struct app *a)
{
	return a->sup ? a->sup->crit_ns / 1000000
		      : (int64_t)(a->cfg.watchdog.critical_factor *
				  a->cfg.period_ms);
}

/* The stop of a SIGCONT since the last look, when it outlasted the
 * limit: its length in ms; else 0 (and forgotten). */
static int64_t stalled_ms(const struct app *a)
{
	int64_t ms;

	if (!continued)
		return 0;
	continued = 0;
	ms = cont_stop_ms;
	return ms > stall_limit_ms(a) ? ms : 0;
}

/* A stop during start-up is the cause of whatever failed after it (the
 * controller's watchdog, a command timed out): the fault says so. */
static void stall_first(struct app *a, struct re_fault *f)
{
	int64_t ms = stalled_ms(a);

	if (!ms)
		return;
	if (f->id != RE_F_NONE) {
		char what[512];

		re_fault_format(f, a->names, what, sizeof(what));
		re_log_msg(&a->log, RE_LOG_WARN,
			   "start-up: after a stop of %lld ms: %s",
			   (long long)ms, what);
	}
	re_fault_set(f, RE_F_STALL, -1);
	f->i[0] = ms;
	f->i[1] = stall_limit_ms(a);
}

static int latch(struct app *a, const struct re_fault *fault)
{
	struct re_fault f = *fault;

	stall_first(a, &f);
	if (f.id != RE_F_NONE && re_super_fault(a->sup, &f) == RE_FAULT)
		re_console_fault(&a->con, re_super_fault_line(a->sup));
	return EXIT_FAULT;
}

/* Between start-up steps: a stop is a fault once the supervisor exists
 * (motor power may be on), else the start is refused. */
static int check_stall(struct app *a)
{
	struct re_fault f;

	if (!continued)
		return 0;
	if (!a->sup) {
		int64_t ms = stalled_ms(a);

		if (!ms)
			return 0;
		snprintf(a->err, sizeof(a->err),
			 "roboelf did not run for %lld ms during start-up "
			 "(limit %lld ms: stopped, e.g. SIGSTOP or a "
			 "debugger); motor power was not switched on; start "
			 "it again",
			 (long long)ms, (long long)stall_limit_ms(a));
		return fail(a, a->err);
	}
	re_fault_set(&f, RE_F_NONE, -1);
	stall_first(a, &f);
	return f.id == RE_F_NONE ? 0 : latch(a, &f);
}

/* A start-up step that failed with a message: a CONFIG fault. */
static int latch_err(struct app *a)
{
	struct re_fault f;

	re_fault_set(&f, RE_F_CONFIG, -1);
	snprintf(f.s, sizeof(f.s), "%.*s", (int)sizeof(f.s) - 1, a->err);
	return latch(a, &f);
}

/* Parameters, then the service state: from here every move is supervised
 * by the program and by the cycle. */
static int enter_service(struct app *a)
{
	struct re_fault f;
	int rc;

	if (re_ctl_write_params(&a->io, &a->cfg, &a->plan, NULL, a->err,
				sizeof(a->err)))
		return latch_err(a);
	a->hbpc = re_ctl_session();
	rc = re_ctl_service(&a->io, &a->hbpc, &f, a->err, sizeof(a->err));
	if (rc == RE_FAULT)
		return latch(a, &f);
	if (rc != GL_OK)
		return latch_err(a);
	re_super_start(a->sup, NULL, a->hbpc, RE_DMC_SERVICE);
	re_super_set_period(a->sup, a->plan.sample_ns);
	return 0;
}

/* ---- calibration --------------------------------------------------------- */

static void log_calibration(struct app *a, const char *how, double secs,
			    int filled)
{
	for (int i = 0; i < a->cal->n_axes; i++) {
		const struct re_caltable *t = &a->cal->axis[i];

		re_log_msg(&a->log, RE_LOG_INFO,
			   "calibration (%s) axis %s: "
			   "%d points, start %.0f, step %.0f counts, soft "
			   "limits %.0f..%.0f, pot %.3f..%.3f V",
			   how, a->names[i], t->n, t->start_counts,
			   t->step_counts, t->soft_rev, t->soft_fwd,
			   t->pot_v[0], t->pot_v[t->n - 1]);
	}
	if (filled)
		re_log_msg(&a->log, RE_LOG_WARN,
			   "calibration: %d table point(s) had no sample of "
			   "their own (the PC was late) and were fitted from "
			   "their neighbours",
			   filled);
	re_log_msg(&a->log, RE_LOG_INFO, "calibration (%s) done in %.1f s", how,
		   secs);
	re_console_msg(&a->con, "roboelf: calibration (%s) done in %.1f s", how,
		       secs);
}

static void stamp_calset(struct app *a)
{
	snprintf(a->cal->serial, sizeof(a->cal->serial), "%ld", a->info.serial);
	a->cal->config_hash = re_config_hash(&a->cfg);
	re_calfile_date(time(NULL), a->cal->date, sizeof(a->cal->date));
}

/* calibration.backup false: the save kept the previous table as FILE.bak
 * (re_calfile_save always does, atomically); remove it afterwards. */
static void drop_backup(struct app *a)
{
	char bak[RE_PATH_MAX + 8];

	if (a->cfg.calibration.backup)
		return;
	snprintf(bak, sizeof(bak), "%s.bak", a->cfg.calibration.file);
	if (unlink(bak) != 0 && errno != ENOENT)
		re_log_msg(&a->log, RE_LOG_WARN, "cannot remove '%s': %s", bak,
			   strerror(errno));
}

/* Another program connected to the controller: not a fault (it may only
 * look), but the operator is told once per handle. */
static void show_foreign(struct app *a, unsigned mask)
{
	unsigned fresh = mask & ~a->foreign_shown;
	char hs[9];
	int n = 0;

	if (!fresh)
		return;
	a->foreign_shown |= fresh;
	for (int h = 0; h < 8; h++)
		if (fresh >> h & 1)
			hs[n++] = (char)('A' + h);
	hs[n] = '\0';
	re_console_msg(&a->con,
		       "roboelf: WARNING: another program connected to the "
		       "controller (handle %s). roboelf still supervises; if "
		       "nobody should be there, press q and find it.",
		       hs);
}

/* The calibration's sampler: one supervised cycle per sample. */
static int sample_cb(void *ud, const struct gl_record **rec)
{
	struct app *a = ud;
	struct re_status st;
	int v;

	if (quit_signal)
		return GL_ERR_AGAIN;
	re_super_wait(a->sup);
	v = re_super_cycle(a->sup);
	re_super_status(a->sup, &st);
	show_foreign(a, st.foreign);
	re_console_status(&a->con, &st, re_io_now_ns(), 0);
	if (v == RE_FAULT) {
		re_console_fault(&a->con, re_super_fault_line(a->sup));
		return RE_FAULT;
	}
	*rec = &a->sup->rec;
	return GL_OK;
}

static void own_cb(void *ud, unsigned mask)
{
	struct app *a = ud;

	re_super_own(a->sup, mask);
}

static void tables_cb(void *ud, const struct re_calset *set)
{
	const struct re_caltable *t[RE_AXES];
	struct app *a = ud;

	for (int i = 0; i < RE_AXES; i++)
		t[i] = &set->axis[i];
	re_super_tables(a->sup, t);
}

static void fill_expect(struct app *a, const struct re_calib_cfg *cc,
			struct re_calfile_expect *e, char *serial)
{
	memset(e, 0, sizeof(*e));
	snprintf(serial, 32, "%ld", a->info.serial);
	e->serial = serial;
	e->n_axes = RE_AXES;
	e->config_hash = re_config_hash(&a->cfg);
	for (int i = 0; i < RE_AXES; i++) {
		snprintf(e->name[i], sizeof(e->name[i]), "%s", a->names[i]);
		e->step_counts[i] = a->cfg.axes[i].step_counts;
		e->check[i] = cc->axis[i].check;
	}
}

/* Load the tables (before anything is powered); on failure offer a full
 * calibration (terminal only). Return: 0 loaded, 1 full calibration
 * instead, EXIT_USAGE. */
static int calib_load(struct app *a)
{
	struct re_calfile_expect e;
	struct re_calib_cfg cc;
	char serial[32];

	re_calib_cfg_from(&a->cfg, &a->plan, a->names, &cc);
	progress(a, "loading calibration '%s'", a->cfg.calibration.file);
	fill_expect(a, &cc, &e, serial);
	if (re_calfile_load(a->cfg.calibration.file, &e, a->cal, a->err,
			    sizeof(a->err)) == GL_OK)
		return 0;
	re_console_msg(&a->con, "roboelf: error: %s", a->err);
	re_log_msg(&a->log, RE_LOG_WARN, "calibration file refused: %s",
		   a->err);
	if (re_console_ask_yes(&a->con, "Run a full calibration instead? "
					"Every axis will move to both of its "
					"limit switches, then to the centre."))
		return 1;
	re_console_msg(&a->con, "roboelf: run again with --calibration full");
	return EXIT_USAGE;
}

/* What will move and where, said before anything moves; the choice is the
 * operator's (the prompt) or the command line's. Return: 0, EXIT_USAGE. */
static int choose_calibration(struct app *a)
{
	int how = a->o.calib, rc;

	if (how == RE_CALIB_ASK)
		how = re_console_ask_calibration(&a->con);
	if (how != RE_CALIB_FULL && how != RE_CALIB_FILE)
		return quit_signal ? 0 : EXIT_USAGE;
	a->cal = calloc(1, sizeof(*a->cal));
	if (!a->cal)
		return fail(a, "out of memory");
	if (how == RE_CALIB_FILE) {
		rc = calib_load(a);
		if (rc > 1)
			return rc;
		how = rc == 1 ? RE_CALIB_FULL : how;
	}
	a->calib = how;
	if (how == RE_CALIB_FULL)
		progress(a, "full calibration chosen: every axis will move to "
			    "its reverse and forward limit switches, then to "
			    "the centre of its travel");
	else
		progress(a, "calibration from the file: every axis will move "
			    "to the centre of its calibrated travel (A %.0f, "
			    "B %.0f, C %.0f counts)",
			 (a->cal->axis[0].soft_rev + a->cal->axis[0].soft_fwd) / 2,
			 (a->cal->axis[1].soft_rev + a->cal->axis[1].soft_fwd) / 2,
			 (a->cal->axis[2].soft_rev + a->cal->axis[2].soft_fwd) / 2);
	return 0;
}

static void save_calibration(struct app *a)
{
	stamp_calset(a);
	if (re_calfile_save(a->cfg.calibration.file, a->cal, a->err,
			    sizeof(a->err)) != GL_OK) {
		re_console_msg(&a->con, "roboelf: warning: %s", a->err);
		re_log_msg(&a->log, RE_LOG_WARN, "calibration not saved: %s",
			   a->err);
		return;
	}
	progress(a, "calibration saved to '%s'", a->cfg.calibration.file);
	drop_backup(a);
}

/* The chosen procedure in the service state. Return: 0, EXIT_FAULT, or
 * 0 with quit_signal set (interrupted). */
static int run_calibration(struct app *a, struct re_calib *c,
			   struct re_calib_cfg *cc)
{
	struct re_fault f;
	double secs = 0;
	int rc, filled = 0;

	if (a->calib == RE_CALIB_FULL) {
		progress(a, "full calibration: every axis end to end");
		rc = re_calib_full(c, &a->io, cc, a->cal, &f, &secs, &filled);
	} else {
		progress(a, "checking the robot against the file, moving to "
			    "the centre");
		rc = re_calib_check_robot(c, &a->io, cc, a->cal, &f);
	}
	if (rc == RE_FAULT)
		return latch(a, &f);
	if (rc == GL_ERR_AGAIN) {
		progress(a, "calibration interrupted: '%s' was not changed",
			 a->cfg.calibration.file);
		return 0;
	}
	if (rc != GL_OK) {
		snprintf(a->err, sizeof(a->err), "calibration failed: %s",
			 gl_strerror(rc));
		return latch_err(a);
	}
	log_calibration(a, a->calib == RE_CALIB_FULL ? "full" : "file", secs,
			filled);
	return 0;
}

static int calibrate(struct app *a)
{
	struct re_calib_cfg cc;
	struct re_calib *c;
	int rc;

	if (re_calib_new(&c) != GL_OK)
		return fail(a, "out of memory");
	re_calib_cfg_from(&a->cfg, &a->plan, a->names, &cc);
	cc.stop = &quit_signal;
	cc.sampler = (struct re_calib_sampler){sample_cb, own_cb, tables_cb, a};
	rc = run_calibration(a, c, &cc);
	re_calib_free(c);
	return rc;
}

/* Back to the safe state (motors off) for the slow file I/O, then armed. */
static int arm(struct app *a)
{
	const struct re_caltable *t[RE_AXES];
	struct re_fault f;
	int rc;

	/* the cycle wrote the heartbeat since the service began: go on
	 * from its last value (a value behind it is out of sequence) */
	a->hbpc = a->sup->hbpc;
	if (re_ctl_off(&a->io, &a->hbpc, a->err, sizeof(a->err)) != GL_OK)
		return latch_err(a);
	re_super_start(a->sup, NULL, a->hbpc, 0);
	if (a->calib == RE_CALIB_FULL)
		save_calibration(a);
	progress(a, "soft limits from the calibration; arming");
	rc = re_ctl_arm(&a->io, a->cal, &a->hbpc, &f, a->err, sizeof(a->err));
	if (rc == RE_FAULT)
		return latch(a, &f);
	if (rc != GL_OK)
		return latch_err(a);
	for (int i = 0; i < RE_AXES; i++)
		t[i] = &a->cal->axis[i];
	re_super_set_period(a->sup, 0);
	re_super_start(a->sup, t, a->hbpc, RE_DMC_ARMED);
	return 0;
}

typedef int (*startup_step)(struct app *a);

static int startup(struct app *a)
{
	static const startup_step steps[] = {
	    start_relay,   start_link, choose_calibration, prepare_controller,
	    init_super,	   power_on,   enter_service,	   calibrate,
	    arm,
	};
	int rc = take_locks(a);

	cont_real = &a->real;
	/* a stop while the operator chooses is no stall: nothing is on */
	for (size_t i = 0; !rc && !quit_signal && i < sizeof(steps) /
		 sizeof(steps[0]); i++) {
		rc = steps[i](a);
		if (steps[i] == choose_calibration)
			continued = 0;
		if (!rc)
			rc = check_stall(a);
	}
	if (!rc && !quit_signal) {
		re_console_msg(&a->con, "RoboELF Ready for Use");
		re_log_msg(&a->log, RE_LOG_INFO, "RoboELF Ready for Use");
	}
	return rc;
}

/* ---- run and cleanup ------------------------------------------------------
 */

static const char *quit_reason(int key)
{
	if (key)
		return "operator pressed q";
	switch (quit_signal) {
	case SIGINT: return "Ctrl-C (SIGINT)";
	case SIGTERM: return "SIGTERM";
	case SIGHUP: return "SIGHUP (terminal lost)";
	case SIGQUIT: return "Ctrl-\\ (SIGQUIT)";
	default: return "signal";
	}
}

static double ms_of_ns(int64_t ns)
{
	return (double)ns / 1e6;
}

/* A log entry the disk refused: retried once a second, and shown. */
static void retry_log(struct app *a, int64_t *next_ns)
{
	int64_t now = re_io_now_ns();

	if (!a->sup->log_failing || now < *next_ns)
		return;
	*next_ns = now + 1000000000LL;
	if (re_super_retry(a->sup) == GL_OK)
		re_console_msg(&a->con, "roboelf: the log '%s' is written "
					"again",
			       a->cfg.log.path);
	else
		re_console_msg(&a->con,
			       "roboelf: WARNING: cannot write the log '%s' "
			       "(%s): the last entry is not on disk; retrying",
			       a->cfg.log.path, strerror(errno));
}

/* Every period until the operator quits; a latched fault keeps the status
 * board running. A terminal that went away (end of input) quits. */
static void run(struct app *a)
{
	struct re_status st;
	int64_t next_retry = 0;
	int key = 0;

	re_console_raw(&a->con);
	while (!quit_signal) {
		re_super_wait(a->sup);
		if (re_super_cycle(a->sup) == RE_FAULT)
			re_console_fault(&a->con, re_super_fault_line(a->sup));
		re_super_status(a->sup, &st);
		show_foreign(a, st.foreign);
		re_console_status(&a->con, &st, re_io_now_ns(), 0);
		retry_log(a, &next_retry);
		key = re_console_key(&a->con);
		if (key == 'q' || key == 'Q' || key < 0)
			break;
		key = 0;
	}
	re_log_msg(&a->log, RE_LOG_INFO, "stop: %s",
		   key < 0 ? "the terminal went away" : quit_reason(key));
	re_log_msg(
	    &a->log, RE_LOG_INFO,
	    "stats: cycles=%llu overruns=%llu period=%.1f ms "
	    "late p50=%.3f p99=%.3f max=%.3f ms; reply age worst=%.1f ms; "
	    "status frames dropped=%llu",
	    (unsigned long long)a->sup->cycles,
	    (unsigned long long)a->sup->overruns,
	    ms_of_ns(a->sup->period_ns), re_super_late_ms(a->sup, 50),
	    re_super_late_ms(a->sup, 99), re_super_late_ms(a->sup, 100),
	    ms_of_ns(a->sup->age_worst_ns), (unsigned long long)a->con.dropped);
}

/* Power-off, the reverse of power-on: the program back to its safe
 * state, every motor off and read back, then the relay off and closed.
 * What was confirmed is said, on the screen and in the log. */
static void power_off(struct app *a, int latched)
{
	char what[192] = "";
	int rc = GL_OK;

	if (a->sup)
		rc = re_super_shutdown(a->sup, what, sizeof(what));
	else if (a->real.link && a->ctl_ours)
		rc = re_ctl_stop(&a->io, a->cfg.controller.timeout_ms);
	/* refused (busy, not identified): somebody else's, left alone */
	if (a->relay && re_relay_close(a->relay) != GL_OK)
		rc = rc ? rc : GL_ERR_RELAY;
	a->relay = a->real.relay = NULL;
	gl_link_close(a->real.link);
	a->real.link = NULL;
	if (!a->powered) {
		re_console_msg(&a->con, "roboelf: motor power was never "
					"switched on; %s",
			       latched ? "a fault was latched" : "bye");
		re_log_msg(&a->log, RE_LOG_INFO, "stop: motor power never on");
		return;
	}
	if (!what[0])
		snprintf(what, sizeof(what), "motors off: %s",
			 rc == GL_OK ? "confirmed" : gl_strerror(rc));
	re_console_msg(&a->con, "roboelf: %s%s; %s", what,
		       rc == GL_OK ? ""
				   : " - NOT ALL CONFIRMED: press the hardware "
				     "E-stop",
		       latched ? "a fault was latched" : "bye");
	re_log_msg(&a->log, rc == GL_OK ? RE_LOG_INFO : RE_LOG_WARN,
		   "stop: %s%s", what, latched ? " (fault latched)" : "");
}

/* Return: 1 when a fault was latched. */
static int cleanup(struct app *a)
{
	int latched = a->sup && a->sup->latched;

	power_off(a, latched);
	re_lock_release(&a->lock_relay);
	re_lock_release(&a->lock_ctl);
	re_console_close(&a->con);
	re_log_close(&a->log);
	free(a->sup);
	free(a->cal);
	a->sup = NULL;
	a->cal = NULL;
	return latched;
}

static int supervise(struct app *a)
{
	int rc;

	re_console_open(&a->con, stdout, STDIN_FILENO);
	if (a->o.calib == RE_CALIB_ASK && !a->con.tty_in) {
		fprintf(stderr, "roboelf: error: no terminal to ask full or "
				"file calibration: use --calibration full or "
				"--calibration file\n");
		re_console_close(&a->con);
		re_log_close(&a->log);
		return EXIT_USAGE;
	}
	a->real.log = &a->log;
	re_lock_init(&a->lock_ctl);
	re_lock_init(&a->lock_relay);
	re_io_bind(&a->io, &a->real);
	install_signals();
	rc = startup(a);
	if ((rc == 0 || rc == EXIT_FAULT) && a->sup)
		run(a);
	if (cleanup(a))
		return EXIT_FAULT;
	return rc;
}

/* --show-calibration: the tables, and a plot per axis where gnuplot is
 * installed; the tolerance band from the configuration when it loads. */
static int show_calibration(struct app *a)
{
	double allowed[RE_AXES];

	if (re_config_load_file(a->o.config, &a->cfg, a->err, sizeof(a->err)) !=
	    GL_OK)
		re_config_defaults(&a->cfg);
	for (int i = 0; i < RE_AXES; i++)
		allowed[i] = a->cfg.axes[i].allowed_error;
	return re_calshow_print(a->o.show_cal, allowed, RE_AXES, stdout,
				stderr) == GL_OK
		   ? 0
		   : EXIT_USAGE;
}

int main(int argc, char **argv)
{
	static struct app a;
	int rc = parse_opts(argc, argv, &a.o);

	if (rc)
		return rc > 0 ? 0 : EXIT_USAGE;
	if (a.o.show_cal)
		return show_calibration(&a);
	if (load_config(&a) < 0 || open_log(&a) < 0)
		return EXIT_USAGE;
	return supervise(&a);
}
