/*
 * roboelf.c - the RoboELF operator's console supervisor (robotTask and its
 * GUI, rebuilt): options, the life cycle Configure -> Startup (re_start.c)
 * -> Run every period -> Cleanup, signals and exit codes.
 *
 *   roboelf [-c FILE] [--galil HOST[:PORT]] [--relay PORT]
 *           [--calibration full|file] [--period MS] [--log FILE]
 *           [--counts]
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
#include <limits.h>
#include <getopt.h>
#include <sched.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "base_clock.h"
#include "base_paths.h"
#include "base_version.h"
#include "gl_err.h"
#include "gl_link.h"
#include "re_calfile.h"
#include "re_calib.h"
#include "re_calshow.h"
#include "re_check.h"
#include "re_comm.h"
#include "re_comm_report.h"
#include "re_comm_start.h"
#include "re_config.h"
#include "re_console.h"
#include "re_ctl.h"
#include "re_io.h"
#include "re_lock.h"
#include "re_log.h"
#include "re_plan.h"
#include "re_rec.h"
#include "re_relay.h"
#include "re_rt.h"
#include "re_start.h"
#include "re_traceshow.h"
#include "re_super.h"

static void on_signal(int sig)
{
	re_sig.quit = sig;
}

/* SIGUSR1: write a trace of the flight recorder now. */
static volatile sig_atomic_t trace_asked;

static void on_usr1(int sig)
{
	(void)sig;
	trace_asked = 1;
}

/* A stop (SIGSTOP, a debugger) during start-up: the cycle measures its own
 * gaps, but start-up is a sequence of waits and commands. SIGCONT says
 * the process was stopped; the stop lasted from the last moment it is
 * known to have run (a link call's start or end) to the SIGCONT. */
static void on_cont(int sig)
{
	int64_t now, from;

	(void)sig;
	now = base_now_ns();
	from = re_sig.cont_real ? re_sig.cont_real->last_run_ns : now;
	re_sig.cont_stop_ms = (now - from) / 1000000;
	re_sig.continued = 1;
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
	sa.sa_handler = on_usr1;
	sigaction(SIGUSR1, &sa, NULL);
	sa.sa_flags = 0;
	sa.sa_handler = SIG_IGN;
	for (size_t i = 0; i < sizeof(ignore) / sizeof(ignore[0]); i++)
		sigaction(ignore[i], &sa, NULL);
}

/* ---- options ----------------------------------------------------------- */

/* The installed configuration: SYSCONFDIR/roboelf/roboelf.yaml, under
 * ROBOELF_ROOT when that is set (base_paths.h); "" when it does not fit. */
static const char *system_config(void)
{
	static char path[RE_PATH_MAX];

	if (!path[0])
		base_paths_sysconf(SYSTEM_CONFIG, path, sizeof(path));
	return path;
}

static void usage(FILE *f)
{
	fprintf(
	    f,
	    "usage: roboelf [-c FILE] [--galil HOST[:PORT]] [--relay PORT]\n"
	    "               [--calibration full|file] [--period MS] "
	    "[--log FILE]\n"
	    "               [--counts]\n"
	    "       roboelf --show-calibration FILE\n"
	    "       roboelf --show-trace FILE [--window FROM:TO]\n"
	    "       roboelf --commission DIR [-c FILE] [--galil ...] "
	    "[--wait S]\n"
	    "       roboelf --check-host[=SECONDS] [-c FILE]\n"
	    "\n"
	    "  -c, --config FILE        configuration (default %s, else "
	    "%s)\n"
	    "      --galil HOST[:PORT]  controller address (overrides the "
	    "file)\n"
	    "      --relay PORT         E-stop relay port for this mode\n"
	    "      --calibration MODE   full: calibrate now; file: load "
	    "the tables\n"
	    "      --period MS          supervisor period, 2..100 ms\n"
	    "      --log FILE           failure log\n"
	    "      --counts             the board in encoder counts, not "
	    "deg/mm (key u toggles)\n"
	    "      --show-calibration FILE  print a calibration file (and "
	    "plot it)\n"
	    "      --show-trace FILE    check a flight-recorder trace and "
	    "plot it (PNG pages)\n"
	    "      --window FROM:TO     --show-trace: only t_s FROM..TO "
	    "seconds (either may be empty)\n"
	    "      --commission DIR     the commissioning run; report "
	    "in DIR\n"
	    "      --wait S             commissioning: each wait for the "
	    "technician (60 s)\n"
	    "      --find-addr A, --find-port P  commissioning: where the "
	    "discovery probe goes\n"
	    "                           (255.255.255.255, 50000)\n"
	    "      --check-host[=S]     measure this host's wake-up "
	    "lateness for S s (10) and\n"
	    "                           name the shortest safe period\n"
	    "      --dmc DIR            the DMC programs --version names "
	    "(default ./dmc, else the installed ones)\n"
	    "  -h, --help               this text\n"
	    "      --version            the release, the DMC interface it "
	    "expects, the files it uses\n"
	    "\n"
	    "exit: 0 quit, 2 usage/config, 3 no relay/controller, "
	    "4 fault latched, 5 commissioning found a fault,\n"
	    "      6 --check-host: the configured period is not safe here\n",
	    DEFAULT_CONFIG, system_config());
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
	case 'T': o->show_trace = arg; return 0;
	case 'w': o->window = arg; return 0;
	case 'M': o->commission = arg; return 0;
	case 'F': o->find_addr = arg; return 0;
	case 'D': o->dmc = arg; return 0;
	case 'P':
		o->find_port = atoi(arg);
		if (o->find_port >= 1 && o->find_port <= 65535)
			return 0;
		fprintf(stderr, "roboelf: error: invalid port '%s'\n", arg);
		return -1;
	case 'W':
		o->wait_s = atoi(arg);
		if (o->wait_s >= 1 && o->wait_s <= 3600)
			return 0;
		fprintf(stderr,
			"roboelf: error: invalid wait '%s': must be 1..3600 "
			"s\n",
			arg);
		return -1;
	case 'H':
		o->check_host_s = arg ? atoi(arg) : 10;
		if (o->check_host_s >= 1 && o->check_host_s <= 3600)
			return 0;
		fprintf(stderr,
			"roboelf: error: invalid --check-host '%s': must be "
			"1..3600 s\n",
			arg);
		return -1;
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
	    {"show-trace", required_argument, NULL, 'T'},
	    {"window", required_argument, NULL, 'w'},
	    {"commission", required_argument, NULL, 'M'},
	    {"wait", required_argument, NULL, 'W'},
	    {"find-addr", required_argument, NULL, 'F'},
	    {"find-port", required_argument, NULL, 'P'},
	    {"check-host", optional_argument, NULL, 'H'},
	    {"dmc", required_argument, NULL, 'D'},
	    {"help", no_argument, NULL, 'h'},
	    {"version", no_argument, NULL, 'V'},
	    {"counts", no_argument, NULL, 'U'},
	    {NULL, 0, NULL, 0},
	};
	int c;

	memset(o, 0, sizeof(*o));
	o->config = NULL; /* searched for: find_config() */
	while ((c = getopt_long(argc, argv, "c:h", lo, NULL)) != -1) {
		if (c == 'h') {
			usage(stdout);
			return 1;
		}
		if (c == 'U') {
			o->counts = 1;
			continue;
		}
		if (c == 'V') {
			o->version = 1;
			continue;
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

/* Without -c: ./config/roboelf.yaml (the source tree), then the
 * installed SYSCONFDIR/roboelf/roboelf.yaml; the first that exists. */
static void find_config(struct opts *o)
{
	if (o->config)
		return;
	o->config_searched = 1;
	o->config = access(DEFAULT_CONFIG, F_OK) == 0 ||
			    access(system_config(), F_OK) != 0
			? DEFAULT_CONFIG
			: system_config();
}

/* --version: the release, the DMC interface, and the files this roboelf
 * would use from here: its configuration and the DMC programs that go
 * with it (--dmc, else ./dmc, else the installed ones). */
static int print_version(struct opts *o)
{
	char dir[RE_PATH_MAX], manifest[RE_PATH_MAX + 16];

	printf("roboelf %s (controller program interface %s, "
	       "dmc/constants.dmc vers)\n",
	       ROBOELF_VERSION, ROBOELF_DMC_VERSION);
	find_config(o);
	if (!o->config_searched)
		printf("configuration: %s (-c)\n", o->config);
	else if (access(o->config, F_OK) == 0)
		printf("configuration: %s\n", o->config);
	else
		printf("configuration: none (neither %s here nor %s)\n",
		       DEFAULT_CONFIG, system_config());
	if (o->dmc) {
		snprintf(manifest, sizeof(manifest), "%s/MANIFEST", o->dmc);
		printf("DMC programs: %s (--dmc%s)\n", o->dmc,
		       access(manifest, F_OK) == 0 ? ""
						   : "; it has no MANIFEST");
	} else if (base_paths_dmc_dir(dir, sizeof(dir)) == 0) {
		printf("DMC programs: %s\n", dir);
	} else {
		printf("DMC programs: none (neither dmc/MANIFEST here nor "
		       "%s/MANIFEST)\n",
		       dir);
	}
	return 0;
}

static int load_config(struct app *a)
{
	find_config(&a->o);
	if (re_config_load_file(a->o.config, &a->cfg, a->err, sizeof(a->err)) !=
	    GL_OK) {
		fprintf(stderr, "%s\n", a->err);
		if (errno == ENOENT && a->o.config_searched)
			fprintf(stderr,
				"roboelf: no configuration: neither '%s' (in "
				"this directory) nor '%s' exists; give one "
				"with -c FILE\n",
				DEFAULT_CONFIG, system_config());
		return -1;
	}
	apply_overrides(a);
	if (a->cfg.mode == RE_MODE_CLINICAL && base_paths_root()) {
		fprintf(stderr,
			"roboelf: error: %s is set: refused in clinical mode "
			"(it is for testing a staged installation); unset it\n",
			BASE_PATHS_ROOT_ENV);
		return -1;
	}
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

/* ---- run and cleanup ------------------------------------------------------
 */

static const char *quit_reason(int key)
{
	if (key)
		return "operator pressed q";
	switch (re_sig.quit) {
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

	if (!re_super_view(a->sup)->log_failing || now < *next_ns)
		return;
	*next_ns = now + 1000000000LL;
	if (re_super_retry(a->sup) == GL_OK)
		re_console_msg(&a->con,
			       "roboelf: the log '%s' is written "
			       "again",
			       a->cfg.log.path);
	else
		re_console_msg(&a->con,
			       "roboelf: WARNING: cannot write the log '%s' "
			       "(%s): the last entry is not on disk; retrying",
			       a->cfg.log.path, strerror(errno));
}

/* ---- the flight recorder -------------------------------------- */

/* The ring sized from the configuration; traces next to the log unless
 * recorder.dir says otherwise. */
static int open_recorder(struct app *a)
{
	static struct re_rec rec;
	struct re_rec_cfg rc;
	char dir[RE_PATH_MAX];
	char *slash;
	int err;

	snprintf(dir, sizeof(dir), "%s",
		 a->cfg.recorder.dir[0] ? a->cfg.recorder.dir
					: a->cfg.log.path);
	slash = strrchr(dir, '/');
	if (a->cfg.recorder.dir[0])
		; /* as configured */
	else if (!slash)
		snprintf(dir, sizeof(dir), ".");
	else
		slash[slash == dir] = '\0'; /* "/x.log": "/" */
	memset(&rc, 0, sizeof(rc));
	rc.seconds = a->cfg.recorder.seconds;
	rc.after_fault_s = a->cfg.recorder.after_fault_s;
	/* calibration samples every RE_CALIB_SAMPLE_MS: the ring holds
	 * seconds + after_fault_s at the shorter of the two periods */
	rc.period_ms = a->cfg.period_ms;
	rc.min_period_ms = a->cfg.period_ms < RE_CALIB_SAMPLE_MS
			       ? a->cfg.period_ms
			       : RE_CALIB_SAMPLE_MS;
	rc.dir = dir;
	rc.n_axes = RE_AXES;
	for (int i = 0; i < RE_AXES; i++)
		rc.axis_names[i] = a->names[i];
	rc.config_hash = re_config_hash(&a->cfg);
	if (access(dir, W_OK | X_OK) != 0) {
		fprintf(stderr,
			"roboelf: error: cannot write traces in '%s' "
			"(recorder.dir, else the log's directory): %s\n",
			dir, strerror(errno));
		return -1;
	}
	err = re_rec_init(&rec, &rc);
	if (err != GL_OK) {
		fprintf(stderr,
			"roboelf: error: cannot set up the flight recorder: "
			"%s\n",
			gl_strerror(err));
		return -1;
	}
	a->rec = &rec;
	return 0;
}

/* Say what the recorder's writer finished: on the console and in the log. */
static void trace_report(struct app *a)
{
	char path[RE_REC_PATH], err[RE_REC_ERR];
	size_t n = 0;
	double ms = 0;
	int v;

	while ((v = re_rec_done(a->rec, path, sizeof(path), err, sizeof(err),
				&n, &ms)) != 0) {
		if (v < 0) {
			re_console_msg(&a->con,
				       "roboelf: WARNING: cannot write the "
				       "trace '%s': %s",
				       path, err);
			re_log_msg(&a->log, RE_LOG_WARN,
				   "trace: cannot write '%s': %s", path, err);
			continue;
		}
		re_console_msg(
		    &a->con, "roboelf: trace %s written (%zu cycles)", path, n);
		re_log_msg(&a->log, RE_LOG_INFO,
			   "trace: %s written (%zu cycles, %.1f ms)", path, n,
			   ms);
	}
}

/* Between cycles: a trace asked for (SIGUSR1, key t), a fault's trace
 * once after_fault_s has passed, what the writer finished. */
static void trace_tick(struct app *a, int key)
{
	if (!a->rec)
		return;
	if ((trace_asked || key == 't' || key == 'T') &&
	    re_rec_request(a->rec) == GL_OK)
		trace_asked = 0;
	re_rec_poll(a->rec, re_io_now_ns());
	trace_report(a);
}

/* Quitting: a fault's trace still due is written now. */
static void close_recorder(struct app *a)
{
	if (!a->rec)
		return;
	re_rec_finish(a->rec);
	trace_report(a);
	re_rec_free(a->rec);
	a->rec = NULL;
}

#define KEY_POLL_MS 100 /* the keyboard is read this often, ms */

/* Every period until the operator quits; a latched fault keeps the status
 * board running. A terminal that went away (end of input) quits. */
static void run(struct app *a)
{
	struct re_status st;
	int64_t next_retry = 0, next_key = 0;
	int key = 0, v, look;

	re_console_raw(&a->con);
	a->real.key_fd = a->con.in_fd;
	a->real.watch_key = a->con.tty_in && a->con.in_fd >= 0;
	while (!re_sig.quit) {
		re_super_wait(a->sup);
		a->real.defer_log = 1; /* no file write in the cycle */
		v = re_super_cycle(a->sup);
		a->real.defer_log = 0;
		if (v == RE_FAULT) {
			re_console_fault(&a->con, re_super_fault_line(a->sup));
			/* keys typed before the fault do not act after it */
			re_console_flush_keys(&a->con);
		}
		re_start_show_foreign(a, re_super_view(a->sup)->foreign);
		re_start_show_events(a);
		re_start_show_ready(a);
		if (re_console_due(&a->con, re_io_now_ns())) {
			re_super_status(a->sup, &st); /* only when drawn */
			re_console_status(&a->con, &st, re_io_now_ns(), 1);
		}
		re_io_flush_log(&a->real); /* after the cycle */
		retry_log(a, &next_retry);
		/* the keyboard when the wait saw input, or every
		 * KEY_POLL_MS when it did not look */
		look = re_io_key_look(&a->real);
		if (look == 1 || (look < 0 && re_io_now_ns() >= next_key)) {
			next_key = re_io_now_ns() + KEY_POLL_MS * 1000000LL;
			key = re_console_key(&a->con);
		}
		trace_tick(a, key);
		if (key == 'u' || key == 'U') {
			re_console_counts(&a->con, !a->con.counts);
			re_super_status(a->sup, &st);
			re_console_status(&a->con, &st, re_io_now_ns(), 1);
		}
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
	    (unsigned long long)re_super_view(a->sup)->cycles,
	    (unsigned long long)re_super_view(a->sup)->overruns,
	    ms_of_ns(re_super_view(a->sup)->period_ns),
	    re_super_late_ms(a->sup, 50), re_super_late_ms(a->sup, 99),
	    re_super_late_ms(a->sup, 100),
	    ms_of_ns(re_super_view(a->sup)->age_worst_ns),
	    (unsigned long long)a->con.dropped);
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
		re_console_msg(&a->con,
			       "roboelf: motor power was never "
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

/* ---- real time ------------------------------------------------ */

/* SCHED_FIFO, locked memory and a CPU as configured, for this thread only
 * (the recorder's writer thread, started before, keeps the normal policy);
 * what is in force is read back from the kernel and logged. A period the
 * result cannot hold is refused. Return: 0, or -1 (said on stderr). */
static int rt_setup(struct app *a)
{
	const struct re_config_realtime *r = &a->cfg.realtime;
	struct re_rt_cfg rc = {r->priority, r->cpu, r->lock_memory};
	char d[RE_RT_DESCRIBE_MAX];
	int refused = re_rt_setup(&rc, &a->rt) < 0, pol = -1, prio = 0;
	long kb = -1;

	re_rt_describe(&a->rt, d, sizeof(d));
	re_rt_readback(&pol, &prio, &kb);
	re_log_msg(&a->log, refused ? RE_LOG_WARN : RE_LOG_INFO,
		   "real time: %s; read back: policy %s priority %d, "
		   "VmLck %ld kB",
		   d, pol == SCHED_FIFO ? "SCHED_FIFO" : "normal", prio, kb);
	if (a->cfg.period_ms < re_rt_min_period_ms(&a->rt)) {
		fprintf(stderr,
			"roboelf: error: a %d ms period needs real-time "
			"scheduling, and this host gave %s: run as root or "
			"give roboelf CAP_SYS_NICE (docs/supervisor.md, "
			"\"Real time\"), or use a period of %d ms or more\n",
			a->cfg.period_ms, d, re_rt_min_period_ms(&a->rt));
		return -1;
	}
	if (refused && a->rt.err_fifo)
		re_console_msg(&a->con,
			       "roboelf: note: real time: %s; periods under "
			       "%d ms are refused",
			       d, RE_RT_MIN_MS_WITHOUT);
	return 0;
}

/* --check-host: this host's wake-up lateness under the configured real-
 * time set-up, and the verdict per period. Return: 0, EXIT_HOST when the
 * configured period is not safe, EXIT_USAGE when the probe failed. */
static int check_host(struct app *a)
{
	static const int cand[] = {2, 3, 5, 10, 20, 50, 100};
	const struct re_config_realtime *r = &a->cfg.realtime;
	const struct re_config_watchdog *w = &a->cfg.watchdog;
	struct re_rt_cfg rc = {r->priority, r->cpu, r->lock_memory};
	struct re_rt_probe p;
	struct re_rt_verdict v;
	char d[RE_RT_DESCRIBE_MAX];
	int best = 0, own_safe;

	install_signals();
	re_rt_setup(&rc, &a->rt);
	printf("host check: %s\n", re_rt_describe(&a->rt, d, sizeof(d)));
	printf("host check: sleeping to 1 ms deadlines for %d s ...\n",
	       a->o.check_host_s);
	fflush(stdout);
	if (re_rt_probe_run(1000000, a->o.check_host_s * 1000000000LL,
			    &re_sig.quit, &p) < 0 ||
	    p.wakes == 0) {
		fprintf(stderr, "roboelf: error: host check: %s\n",
			strerror(errno));
		return EXIT_USAGE;
	}
	printf("host check: %llu wake-ups, late p50 %.3f p99 %.3f p99.9 %.3f "
	       "max %.3f ms; %llu later than 1 ms, %llu later than 5 ms\n",
	       (unsigned long long)p.wakes, p.p50_ms, p.p99_ms, p.p999_ms,
	       p.max_ms, (unsigned long long)p.over_1ms,
	       (unsigned long long)p.over_5ms);
	printf("period  lateness allowed  verdict (watchdog %.1f/%.1f x P)\n",
	       w->noncritical_factor, w->critical_factor);
	for (size_t i = 0; i < sizeof(cand) / sizeof(cand[0]); i++) {
		re_rt_verdict(&p, cand[i], w->noncritical_factor,
			      w->critical_factor, &v);
		if (v.safe && cand[i] >= re_rt_min_period_ms(&a->rt) && !best)
			best = cand[i];
		printf("%4d ms  %8.1f ms        %s\n", cand[i], v.margin_ms,
		       cand[i] < re_rt_min_period_ms(&a->rt)
			   ? "refused without real-time scheduling"
		       : !v.safe ? "NOT SAFE: would trip WATCHDOG"
		       : v.quiet ? "safe"
				 : "safe, with occasional watchdog warnings");
	}
	re_rt_verdict(&p, a->cfg.period_ms, w->noncritical_factor,
		      w->critical_factor, &v);
	own_safe = v.safe && a->cfg.period_ms >= re_rt_min_period_ms(&a->rt);
	printf("host check: shortest safe period on this host: %s%d ms; the "
	       "configured %d ms (%s) is %s\n",
	       best ? "" : "none of these; more than ", best ? best : 100,
	       a->cfg.period_ms, a->o.config, own_safe ? "safe" : "NOT SAFE");
	return own_safe ? 0 : EXIT_HOST;
}

/* Return: 1 when a fault was latched. */
static int cleanup(struct app *a)
{
	int latched = a->sup && re_super_view(a->sup)->latched;

	re_io_flush_log(&a->real);
	power_off(a, latched);
	close_recorder(a);
	re_lock_release(&a->lock_relay);
	re_lock_release(&a->lock_ctl);
	re_console_close(&a->con);
	re_log_close(&a->log);
	re_super_free(a->sup);
	free(a->cal);
	a->sup = NULL;
	a->cal = NULL;
	return latched;
}

/* The console: the board in each axis's unit (or counts, --counts). */
static void open_console(struct app *a)
{
	char abs[PATH_MAX];

	re_console_open(&a->con, stdout, STDIN_FILENO);
	re_console_log_path(
	    &a->con, realpath(a->cfg.log.path, abs) ? abs : a->cfg.log.path);
	for (int i = 0; i < RE_AXES; i++)
		re_console_units(&a->con, i, re_unit_name(a->cfg.axes[i].unit),
				 a->cfg.axes[i].counts_per_unit);
	re_console_counts(&a->con, a->o.counts);
}

static int supervise(struct app *a)
{
	int rc;

	open_console(a);
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
	if (open_recorder(a) < 0 || rt_setup(a) < 0) {
		re_console_close(&a->con);
		re_log_close(&a->log);
		return EXIT_USAGE;
	}
	rc = re_start(a);
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

	find_config(&a->o);
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

/* --show-trace: the trace checked, summarised and drawn. */
static int show_trace(struct app *a)
{
	struct re_traceshow_win w;

	if (a->o.window && re_traceshow_window(a->o.window, &w) < 0) {
		fprintf(stderr,
			"roboelf: error: invalid window '%s': use FROM:TO in "
			"seconds, FROM < TO, either may be empty\n",
			a->o.window);
		return EXIT_USAGE;
	}
	return re_traceshow_run(a->o.show_trace, a->o.window ? &w : NULL,
				stdout, stderr);
}

/* ---- the commissioning run ------------------------------------------- */

static void comm_say(void *ud, const char *line)
{
	struct app *a = ud;

	re_console_msg(&a->con, "%s", line);
	re_log_msg(&a->log, RE_LOG_INFO, "%s", line);
}

/* A yes/no question on the terminal (or a line on stdin): only "y" or
 * "yes" is a yes; end of input is a no. */
static int comm_confirm(void *ud, const char *question)
{
	struct app *a = ud;
	char line[32];
	int yes;

	re_console_msg(&a->con, "commission: %s [y/N]", question);
	yes = fgets(line, sizeof(line), stdin) &&
	      (!strcmp(line, "y\n") || !strcmp(line, "yes\n"));
	re_log_msg(&a->log, RE_LOG_INFO, "commission: %s -> %s", question,
		   yes ? "yes" : "no");
	return yes;
}

static void comm_date(char *buf, size_t cap)
{
	time_t t = time(NULL);
	struct tm tm;

	gmtime_r(&t, &tm);
	strftime(buf, cap, "%Y-%m-%d %H:%M:%S UTC", &tm);
}

/* After re_comm_start(): the steps, the report, the summary. */
static int comm_steps(struct app *a)
{
	static struct re_comm c;
	char date[32], line[1024], err[256];
	struct re_comm_where w = {a->cfg.controller.address, a->o.config, date};
	int rc, plots = 0;

	re_comm_init(&c);
	c.io = &a->io;
	c.link = a->real.link;
	c.relay = a->relay;
	c.cfg = &a->cfg;
	c.ui = (struct re_comm_ui){a, comm_say, comm_confirm};
	c.quit = &re_sig.quit;
	if (a->o.wait_s)
		c.wait_ms = a->o.wait_s * 1000;
	snprintf(c.model, sizeof(c.model), "%s", a->info.model);
	c.serial = a->info.serial;
	rc = re_comm_run(&c);
	a->powered = c.power_on_seen;
	comm_date(date, sizeof(date));
	re_comm_summary(&c, line, sizeof(line));
	re_console_msg(&a->con, "commission: %s", line);
	re_log_msg(&a->log, rc ? RE_LOG_WARN : RE_LOG_INFO, "commission: %s",
		   line);
	if (re_comm_report(&c, &w, a->o.commission, &plots, err, sizeof(err)) !=
	    GL_OK) {
		re_console_msg(&a->con, "roboelf: error: %s", err);
		return EXIT_CONNECT;
	}
	re_console_msg(&a->con, "commission: report %s/%s, %d plot(s)",
		       a->o.commission, RE_COMM_REPORT_NAME, plots);
	return rc == GL_OK ? 0 : EXIT_COMMISSION;
}

static int commission(struct app *a)
{
	int rc;

	re_console_open(&a->con, stdout, STDIN_FILENO);
	a->real.log = &a->log;
	re_lock_init(&a->lock_ctl);
	re_lock_init(&a->lock_relay);
	re_io_bind(&a->io, &a->real);
	install_signals();
	rc = re_comm_start(a);
	if (!rc)
		rc = comm_steps(a);
	cleanup(a);
	return rc;
}

int main(int argc, char **argv)
{
	static struct app a;
	int rc = parse_opts(argc, argv, &a.o);

	if (rc)
		return rc > 0 ? 0 : EXIT_USAGE;
	if (base_paths_root())
		fprintf(stderr,
			"roboelf: %s=%s: the installed files are looked for "
			"under it\n",
			BASE_PATHS_ROOT_ENV, base_paths_root());
	if (a.o.version)
		return print_version(&a.o);
	if (a.o.show_cal)
		return show_calibration(&a);
	if (a.o.show_trace)
		return show_trace(&a);
	if (load_config(&a) < 0)
		return EXIT_USAGE;
	if (a.o.check_host_s)
		return check_host(&a);
	if (open_log(&a) < 0)
		return EXIT_USAGE;
	if (a.o.commission)
		return commission(&a);
	return supervise(&a);
}
