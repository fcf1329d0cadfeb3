/*
 * roboelf.c - the RoboELF operator's console supervisor (robotTask and its
 * GUI, rebuilt): options, the life cycle Configure -> Startup (re_start.c)
 * -> Run every period -> Cleanup, signals and exit codes.
 *
 *   roboelf [-c FILE] [--galil HOST[:PORT]] [--relay PORT]
 *           [--calibration full|file] [--period MS] [--log FILE]
 *           [--counts]
 *
 * roboelf supervises, and nothing else: the technician's commissioning
 * run, the viewers of calibration files and traces and the host's
 * self-test are roboelf-tech (tools/roboelf-tech).
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
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gl_err.h"
#include "gl_stream.h"
#include "re_app.h"
#include "re_calib.h"
#include "re_config.h"
#include "re_console.h"
#include "re_io.h"
#include "re_lock.h"
#include "re_log.h"
#include "re_rec.h"
#include "re_relay.h"
#include "re_rt.h"
#include "re_start.h"
#include "re_super.h"

/* ---- options ----------------------------------------------------------- */

static void usage(FILE *f)
{
	fprintf(
	    f,
	    "usage: roboelf [-c FILE] [--galil HOST[:PORT]] [--relay PORT]\n"
	    "               [--calibration full|file] [--period MS] "
	    "[--log FILE]\n"
	    "               [--counts]\n"
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
	    "      --dmc DIR            the DMC programs --version names "
	    "(default ./dmc, else the installed ones)\n"
	    "  -h, --help               this text\n"
	    "      --version            the release, the DMC interface it "
	    "expects, the files it uses\n"
	    "\n"
	    "The commissioning run, the viewers of calibration files and "
	    "traces and the\n"
	    "host's self-test are roboelf-tech (roboelf-tech --help).\n"
	    "\n"
	    "exit: 0 quit, 2 usage/config, 3 no relay/controller, "
	    "4 fault latched\n",
	    DEFAULT_CONFIG, re_app_system_config());
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

/* The command line. */
struct opts {
	struct re_app_args g; /* what roboelf-tech takes too */
	int version;	      /* --version asked */
	int counts;	      /* --counts: the board in encoder counts */
	enum re_calib_choice calib;
};

/* An option that moved to the technician's program. */
static const struct moved {
	const char *opt, *now;
} MOVED[] = {
    {"commission", "roboelf-tech commission DIR"},
    {"show-calibration", "roboelf-tech show-calibration FILE"},
    {"show-trace", "roboelf-tech show-trace FILE"},
    {"check-host", "roboelf-tech check-host"},
    {"window", "roboelf-tech show-trace FILE --window FROM:TO"},
    {"wait", "roboelf-tech commission DIR --wait S"},
    {"find-addr", "roboelf-tech commission DIR --find-addr A"},
    {"find-port", "roboelf-tech commission DIR --find-port P"},
};
#define N_MOVED ((int)(sizeof(MOVED) / sizeof(MOVED[0])))

static int opt_value(struct opts *o, int c, const char *arg)
{
	if (c >= 1000 && c < 1000 + N_MOVED) {
		fprintf(stderr,
			"roboelf: error: --%s is not roboelf's: roboelf "
			"supervises, and nothing else; run %s (the "
			"technician's program)\n",
			MOVED[c - 1000].opt, MOVED[c - 1000].now);
		return -1;
	}
	switch (c) {
	case 'c': o->g.config = arg; return 0;
	case 'g': o->g.galil = arg; return 0;
	case 'r': o->g.relay = arg; return 0;
	case 'l': o->g.log = arg; return 0;
	case 'D': o->g.dmc = arg; return 0;
	case 'p':
		if (parse_period(arg, &o->g.period_ms) == 0)
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
	    {"dmc", required_argument, NULL, 'D'},
	    {"help", no_argument, NULL, 'h'},
	    {"version", no_argument, NULL, 'V'},
	    {"counts", no_argument, NULL, 'U'},
	    {"commission", optional_argument, NULL, 1000},
	    {"show-calibration", optional_argument, NULL, 1001},
	    {"show-trace", optional_argument, NULL, 1002},
	    {"check-host", optional_argument, NULL, 1003},
	    {"window", optional_argument, NULL, 1004},
	    {"wait", optional_argument, NULL, 1005},
	    {"find-addr", optional_argument, NULL, 1006},
	    {"find-port", optional_argument, NULL, 1007},
	    {NULL, 0, NULL, 0},
	};
	int c;

	memset(o, 0, sizeof(*o));
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

/* ---- run and cleanup --------------------------------------------------- */

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

/* ---- the flight recorder ----------------------------------------------- */

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
	re_console_trace_key(&a->con, 1); /* key t: a trace now */
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
	if ((re_sig.trace_asked || key == 't' || key == 'T') &&
	    re_rec_request(a->rec) == GL_OK)
		re_sig.trace_asked = 0;
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

/* The record stream's counters (the stream design only). */
static void log_stream(struct app *a)
{
	struct gl_stream_stats st;

	if (gl_link_stream_info(a->real.link, NULL, NULL))
		gl_link_stream_stats(a->real.link, &st);
	else if (a->real.have_stream_was)
		st = a->real.stream_was; /* the link the stop replaced */
	else
		return;
	re_log_msg(&a->log, RE_LOG_INFO,
		   "stream: datagrams=%llu records=%llu lost=%llu "
		   "duplicates=%llu reordered=%llu superseded=%llu "
		   "foreign=%llu short=%llu long=%llu malformed=%llu; "
		   "heartbeat lines refused=%llu",
		   (unsigned long long)st.received,
		   (unsigned long long)st.accepted,
		   (unsigned long long)st.lost,
		   (unsigned long long)st.duplicates,
		   (unsigned long long)st.reordered,
		   (unsigned long long)st.superseded,
		   (unsigned long long)st.foreign,
		   (unsigned long long)st.shorts, (unsigned long long)st.longs,
		   (unsigned long long)st.malformed,
		   (unsigned long long)gl_link_post_errors(a->real.link));
}

/* The run's end in the log: why it stopped (@key: the key that quit, -1:
 * the terminal went away, 0: a signal) and the cycle's figures. */
static void log_stop(struct app *a, int key)
{
	const struct re_super_view *v = re_super_view(a->sup);
	struct re_status st;

	/* the late replies counted for a summary, before the run's end */
	re_super_wd_flush(a->sup);
	re_super_status(a->sup, &st);
	re_log_msg(&a->log, RE_LOG_INFO, "stop: %s",
		   key < 0 ? "the terminal went away" : quit_reason(key));
	re_log_msg(&a->log, RE_LOG_INFO,
		   "stats: cycles=%llu overruns=%llu period=%.1f ms "
		   "late p50=%.3f p99=%.3f max=%.3f ms; reply age worst=%.1f "
		   "ms, watchdog warnings=%llu; status frames dropped=%llu",
		   (unsigned long long)v->cycles,
		   (unsigned long long)v->overruns, ms_of_ns(v->period_ns),
		   re_super_late_ms(a->sup, 50), re_super_late_ms(a->sup, 99),
		   re_super_late_ms(a->sup, 100), ms_of_ns(v->age_worst_ns),
		   (unsigned long long)st.wd_warnings,
		   (unsigned long long)a->con.dropped);
	log_stream(a);
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
	log_stop(a, key);
}

/* ---- real time --------------------------------------------------------- */

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

/* Return: 1 when a fault was latched. */
static int cleanup(struct app *a)
{
	int latched = a->sup && re_super_view(a->sup)->latched;

	re_io_flush_log(&a->real);
	re_app_power_off(a, latched);
	close_recorder(a);
	re_app_release(a);
	return latched;
}

/* The console: the board in each axis's unit (or counts, --counts). */
static void open_console(struct app *a, int counts)
{
	re_console_open(&a->con, stdout, STDIN_FILENO);
	/* absolute since the start (re_app_load_config()) */
	re_console_log_path(&a->con, a->cfg.log.path);
	for (int i = 0; i < RE_AXES; i++)
		re_console_units(&a->con, i, re_unit_name(a->cfg.axes[i].unit),
				 a->cfg.axes[i].counts_per_unit);
	re_console_counts(&a->con, counts);
}

static int supervise(struct app *a, int counts)
{
	int rc;

	open_console(a, counts);
	if (a->calib_opt == RE_CALIB_ASK && !a->con.tty_in) {
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
	re_app_signals();
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

int main(int argc, char **argv)
{
	static struct app a;
	static struct opts o;
	int rc = parse_opts(argc, argv, &o);

	if (rc)
		return rc > 0 ? 0 : EXIT_USAGE;
	a.prog = "roboelf";
	re_app_root_note(a.prog);
	if (o.version)
		return re_app_print_version(a.prog, &o.g);
	if (re_app_load_config(&a, &o.g) < 0)
		return EXIT_USAGE;
	a.config_path = o.g.config;
	a.calib_opt = o.calib;
	if (re_app_open_log(&a, &o.g) < 0)
		return EXIT_USAGE;
	return supervise(&a, o.counts);
}
