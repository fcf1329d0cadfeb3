/*
 * main.c - roboelf-tech, the technician's program: what roboelf (the
 * operator's supervisor) does not do, on the same libraries and the same
 * bring-up (re_start_bringup()):
 *
 *   roboelf-tech commission DIR [-c FILE] [--galil HOST[:PORT]]
 *                [--relay PORT] [--log FILE] [--wait S]
 *                [--find-addr A] [--find-port P]
 *   roboelf-tech show-calibration FILE [-c FILE]
 *   roboelf-tech show-trace FILE [--window FROM:TO] [-c FILE]
 *   roboelf-tech check-host[=SECONDS] [-c FILE] [--period MS]
 *   roboelf-tech bind-relay [--serial S] [--rules-file PATH]
 *   roboelf-tech --print KEY [-c FILE]
 *
 * Exit codes: 0 done; 2 usage, configuration or a file that cannot be
 * read (bind-relay: the rules file cannot be written); 3 no relay or
 * controller, or the controller refused (bind-relay: no single relay
 * board, or its serial number refused); 5 the commissioning run found a
 * fault; 6 check-host: the configured period is not safe on this host.
 */
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "gl_err.h"
#include "gl_link.h"
#include "re_app.h"
#include "re_bindrelay.h"
#include "re_calshow.h"
#include "re_comm.h"
#include "re_comm_report.h"
#include "re_comm_start.h"
#include "re_rt.h"
#include "re_traceshow.h"

/* roboelf-tech's own exit codes (roboelf-tech.1); 2 and 3 as roboelf's
 * (re_start.h). */
#define EXIT_COMMISSION 5 /* the commissioning run found a fault */
#define EXIT_HOST	6 /* check-host: the configured period is not safe */

/* The command line. */
struct topts {
	struct re_app_args g;
	const char *sub;       /* the subcommand */
	const char *dir;       /* commission: the report's directory */
	const char *file;      /* show-calibration, show-trace */
	const char *window;    /* show-trace --window FROM:TO */
	int wait_s;	       /* commission: each wait for the technician */
	const char *find_addr; /* commission: the discovery probe's address */
	int find_port;	       /* and port (0: the defaults) */
	int seconds;	       /* check-host: the probe's length */
	struct re_bindrelay_opts bind; /* bind-relay: --serial, --rules-file */
	const char *print;     /* --print KEY */
	int version;
};

static void usage(FILE *f)
{
	fprintf(f,
		"usage: roboelf-tech commission DIR [-c FILE] "
		"[--galil HOST[:PORT]] [--relay PORT]\n"
		"                    [--log FILE] [--wait S] [--find-addr A] "
		"[--find-port P]\n"
		"       roboelf-tech show-calibration FILE [-c FILE]\n"
		"       roboelf-tech show-trace FILE [--window FROM:TO] [-c FILE]\n"
		"       roboelf-tech check-host[=SECONDS] [-c FILE] "
		"[--period MS]\n"
		"       roboelf-tech bind-relay [--serial S] [--rules-file "
		"PATH]\n"
		"       roboelf-tech --print KEY [-c FILE]\n"
		"\n"
		"  commission DIR       the commissioning run; report in DIR\n"
		"  show-calibration FILE  print a calibration file (and "
		"plot it)\n"
		"  show-trace FILE      check a flight-recorder trace and plot "
		"it (PNG pages)\n"
		"  check-host[=S]       measure this host's wake-up lateness "
		"for S s (10) and\n"
		"                       name the shortest safe period "
		"(check-host S: the same)\n"
		"  bind-relay           write the udev rule that names the "
		"relay board, by its\n"
		"                       USB serial number, /dev/roboelf-relay "
		"(also --bind-relay)\n"
		"\n"
		"  -c, --config FILE    configuration (default %s, else %s)\n"
		"      --galil HOST[:PORT]  controller address (overrides the "
		"file)\n"
		"      --relay PORT     E-stop relay port for this mode\n"
		"      --log FILE       failure log\n"
		"      --period MS      check-host: the period to judge, "
		"2..100 ms\n"
		"      --wait S         commission: each wait for the "
		"technician (60 s)\n"
		"      --find-addr A, --find-port P  commission: where the "
		"discovery probe goes\n"
		"                       (255.255.255.255, 50000)\n"
		"      --window FROM:TO show-trace: only t_s FROM..TO seconds "
		"(either may be empty)\n"
		"      --serial S       bind-relay: the board of this USB "
		"serial number\n"
		"      --rules-file PATH  bind-relay: where the rule goes "
		"(%s)\n"
		"      --dmc DIR        the DMC programs --version names\n"
		"  -h, --help           this text\n"
		"      --version        the release, the DMC interface, the "
		"files it uses\n"
		"      --print KEY      one checked value: controller.address, "
		"controller.host,\n"
		"                       mode, log.path, calibration.file (in "
		"full)\n"
		"\n"
		"exit: 0 done, 2 usage/config, 3 no relay/controller, "
		"5 commissioning found a fault,\n"
		"      6 check-host: the configured period is not safe here\n",
		DEFAULT_CONFIG, re_app_system_config(), RE_BINDRELAY_RULES);
}

/* check-host's table: the verdict for each candidate period on probe @p.
 * Return: the shortest safe one this host's scheduling allows, 0: none. */
static int host_table(struct app *a, const struct re_rt_probe *p)
{
	static const int cand[] = {2, 3, 5, 10, 20, 50, 100};
	const struct re_config_watchdog *w = &a->cfg.watchdog;
	int min = re_rt_min_period_ms(&a->rt), best = 0;
	struct re_rt_verdict v;

	printf("period  lateness allowed  verdict (watchdog %.1f/%.1f x P)\n",
	       w->noncritical_factor, w->critical_factor);
	for (size_t i = 0; i < sizeof(cand) / sizeof(cand[0]); i++) {
		re_rt_verdict(p, cand[i], w->noncritical_factor,
			      w->critical_factor, &v);
		if (v.safe && cand[i] >= min && !best)
			best = cand[i];
		printf("%4d ms  %8.1f ms        %s\n", cand[i], v.margin_ms,
		       cand[i] < min ? "refused without real-time scheduling"
		       : !v.safe     ? "NOT SAFE: would trip WATCHDOG"
		       : v.quiet     ? "safe"
				 : "safe, with occasional watchdog warnings");
	}
	return best;
}

/* check-host: this host's wake-up lateness under the configured real-
 * time set-up, and the verdict per period. Return: 0, EXIT_HOST when the
 * configured period is not safe, EXIT_USAGE when the probe failed. */
static int check_host(struct app *a, int seconds)
{
	const struct re_config_realtime *r = &a->cfg.realtime;
	const struct re_config_watchdog *w = &a->cfg.watchdog;
	struct re_rt_cfg rc = {r->priority, r->cpu, r->lock_memory};
	struct re_rt_probe p;
	struct re_rt_verdict v;
	char d[RE_RT_DESCRIBE_MAX];
	int best, own_safe;

	re_app_signals();
	re_rt_setup(&rc, &a->rt);
	printf("host check: %s\n", re_rt_describe(&a->rt, d, sizeof(d)));
	printf("host check: sleeping to 1 ms deadlines for %d s ...\n",
	       seconds);
	fflush(stdout);
	if (re_rt_probe_run(1000000, seconds * 1000000000LL, &re_sig.quit, &p) <
		0 ||
	    p.wakes == 0) {
		fprintf(stderr, "roboelf-tech: error: host check: %s\n",
			strerror(errno));
		return EXIT_USAGE;
	}
	printf("host check: %llu wake-ups, late p50 %.3f p99 %.3f p99.9 %.3f "
	       "max %.3f ms; %llu later than 1 ms, %llu later than 5 ms\n",
	       (unsigned long long)p.wakes, p.p50_ms, p.p99_ms, p.p999_ms,
	       p.max_ms, (unsigned long long)p.over_1ms,
	       (unsigned long long)p.over_5ms);
	best = host_table(a, &p);
	re_rt_verdict(&p, a->cfg.period_ms, w->noncritical_factor,
		      w->critical_factor, &v);
	own_safe = v.safe && a->cfg.period_ms >= re_rt_min_period_ms(&a->rt);
	printf("host check: shortest safe period on this host: %s%d ms; the "
	       "configured %d ms (%s) is %s\n",
	       best ? "" : "none of these; more than ", best ? best : 100,
	       a->cfg.period_ms, a->config_path,
	       own_safe ? "safe" : "NOT SAFE");
	return own_safe ? 0 : EXIT_HOST;
}

/* show-calibration: the tables, and a plot per axis where gnuplot is
 * installed; the tolerance band from the configuration when it loads. */
static int show_calibration(struct app *a, struct re_app_args *g,
			    const char *file)
{
	double allowed[RE_AXES];

	re_app_find_config(g);
	if (re_config_load_file(g->config, &a->cfg, a->err, sizeof(a->err)) !=
	    GL_OK)
		re_config_defaults(&a->cfg);
	for (int i = 0; i < RE_AXES; i++)
		allowed[i] = a->cfg.axes[i].allowed_error;
	return re_calshow_print(file, allowed, RE_AXES, stdout, stderr) == GL_OK
		   ? 0
		   : EXIT_USAGE;
}

/* --print KEY: one value of the configuration, read and checked as
 * roboelf reads it (a template not filled in is refused), for scripts
 * that must not parse YAML (the link's ifupdown hook). Return: 0 printed,
 * EXIT_USAGE (unknown KEY, configuration refused: said on stderr). */
static int print_key(struct app *a, struct re_app_args *g, const char *key)
{
	static const char *const keys[] = {"controller.address",
					   "controller.host", "mode",
					   "log.path", "calibration.file"};
	char host[RE_PATH_MAX], port[16];
	size_t k = 0, n = sizeof(keys) / sizeof(keys[0]);

	while (k < n && strcmp(key, keys[k]))
		k++;
	if (k == n) {
		fprintf(stderr,
			"roboelf-tech: error: --print '%s': not a key it "
			"prints (controller.address, controller.host, mode, "
			"log.path, calibration.file)\n",
			key);
		return EXIT_USAGE;
	}
	if (re_app_load_config(a, g) < 0)
		return EXIT_USAGE;
	if (k == 1 &&
	    gl_link_addr_split(a->cfg.controller.address, host, sizeof(host),
			       port, sizeof(port)) != GL_OK) {
		fprintf(stderr, "roboelf-tech: error: invalid address '%s'\n",
			a->cfg.controller.address);
		return EXIT_USAGE;
	}
	printf("%s\n", k == 0	? a->cfg.controller.address
		       : k == 1 ? host
		       : k == 2 ? re_mode_name(a->cfg.mode)
		       : k == 3 ? a->cfg.log.path
				: a->cfg.calibration.file);
	return 0;
}

/* The console's units of each axis (deg, mm) from the configuration, for
 * show-trace. Return: @u, or NULL when the configuration does not load. */
static const struct re_traceshow_units *trace_units(struct app *a,
						    struct re_app_args *g,
						    struct re_traceshow_units *u)
{
	re_app_find_config(g);
	if (re_config_load_file(g->config, &a->cfg, a->err, sizeof(a->err)) !=
	    GL_OK)
		return NULL;
	memset(u, 0, sizeof(*u));
	u->config = g->config;
	u->config_hash = re_config_hash(&a->cfg);
	for (int i = 0; i < RE_AXES && i < RE_TRACE_AXES; i++) {
		const struct re_config_axis *x = &a->cfg.axes[i];

		snprintf(u->name[i], sizeof(u->name[i]), "%s", x->name);
		snprintf(u->unit[i], sizeof(u->unit[i]), "%s",
			 re_unit_name(x->unit));
		u->per_unit[i] = x->counts_per_unit;
		u->n = i + 1;
	}
	return u;
}

/* show-trace: the trace checked, summarised and drawn. */
static int show_trace(struct app *a, struct re_app_args *g, const char *file,
		      const char *window)
{
	static struct re_traceshow_units units;
	struct re_traceshow_win w;

	if (window && re_traceshow_window(window, &w) < 0) {
		fprintf(
		    stderr,
		    "roboelf-tech: error: invalid window '%s': use FROM:TO in "
		    "seconds, FROM < TO, either may be empty\n",
		    window);
		return EXIT_USAGE;
	}
	return re_traceshow_run(file, window ? &w : NULL,
				trace_units(a, g, &units), stdout, stderr);
}

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
static int comm_steps(struct app *a, const char *dir, int wait_s)
{
	static struct re_comm c;
	char date[32], line[1024], err[256];
	struct re_comm_where w = {a->cfg.controller.address, a->config_path,
				  date};
	int rc, plots = 0;

	re_comm_init(&c);
	c.io = &a->io;
	c.link = a->real.link;
	c.relay = a->relay;
	c.cfg = &a->cfg;
	c.ui = (struct re_comm_ui){a, comm_say, comm_confirm};
	c.quit = &re_sig.quit;
	if (wait_s)
		c.wait_ms = wait_s * 1000;
	snprintf(c.model, sizeof(c.model), "%s", a->info.model);
	c.serial = a->info.serial;
	rc = re_comm_run(&c);
	a->powered = c.power_on_seen;
	comm_date(date, sizeof(date));
	re_comm_summary(&c, line, sizeof(line));
	re_console_msg(&a->con, "commission: %s", line);
	re_log_msg(&a->log, rc ? RE_LOG_WARN : RE_LOG_INFO, "commission: %s",
		   line);
	if (re_comm_report(&c, &w, dir, &plots, err, sizeof(err)) != GL_OK) {
		re_console_msg(&a->con, "roboelf-tech: error: %s", err);
		return EXIT_CONNECT;
	}
	re_console_msg(&a->con, "commission: report %s/%s, %d plot(s)", dir,
		       RE_COMM_REPORT_NAME, plots);
	return rc == GL_OK ? 0 : EXIT_COMMISSION;
}

static int commission(struct app *a, const struct topts *o)
{
	int rc;

	re_console_open(&a->con, stdout, STDIN_FILENO);
	a->real.log = &a->log;
	re_lock_init(&a->lock_ctl);
	re_lock_init(&a->lock_relay);
	re_io_bind(&a->io, &a->real);
	re_app_signals();
	rc = re_comm_start(a, o->find_addr, o->find_port);
	if (!rc)
		rc = comm_steps(a, o->dir, o->wait_s);
	re_io_flush_log(&a->real);
	re_app_power_off(a, 0);
	re_app_release(a);
	return rc;
}

/* ---- the command line ---------------------------------------------------- */

static int bad(const char *what, const char *arg, const char *rule)
{
	fprintf(stderr, "roboelf-tech: error: invalid %s '%s': %s\n", what, arg,
		rule);
	return -1;
}

static int int_in(const char *s, int lo, int hi, int *out)
{
	char *end;
	long v;

	errno = 0;
	v = strtol(s, &end, 10);
	if (errno || end == s || *end || v < lo || v > hi)
		return -1;
	*out = (int)v;
	return 0;
}

static int opt_value(struct topts *o, int c, const char *arg)
{
	switch (c) {
	case 'c': o->g.config = arg; return 0;
	case 'g': o->g.galil = arg; return 0;
	case 'r': o->g.relay = arg; return 0;
	case 'l': o->g.log = arg; return 0;
	case 'D': o->g.dmc = arg; return 0;
	case 'w': o->window = arg; return 0;
	case 'F': o->find_addr = arg; return 0;
	case 'S': o->bind.serial = arg; return 0;
	case 'R': o->bind.rules_file = arg; return 0;
	case 'P':
		return int_in(arg, 1, 65535, &o->find_port)
			   ? bad("port", arg, "must be 1..65535")
			   : 0;
	case 'W':
		return int_in(arg, 1, 3600, &o->wait_s)
			   ? bad("wait", arg, "must be 1..3600 s")
			   : 0;
	case 'p':
		return int_in(arg, 2, 100, &o->g.period_ms)
			   ? bad("period", arg, "must be 2..100 ms")
			   : 0;
	default: usage(stderr); return -1;
	}
}

/* check-host's time in s: @eq from "check-host=S", else the one operand
 * of "check-host S" (of @n), else 10 s. */
static int host_seconds(struct topts *o, const char *eq, int n, char **arg)
{
	const char *s = eq ? eq : n == 1 ? arg[0] : NULL;

	o->seconds = 10;
	if (n > (eq ? 0 : 1)) {
		fprintf(stderr, "roboelf-tech: error: check-host takes at most "
				"a time in s\n");
		return -1;
	}
	if (s && int_in(s, 1, 3600, &o->seconds))
		return bad("check-host time", s, "must be 1..3600 s");
	return 0;
}

/* The subcommand's operands: DIR, FILE or SECONDS. */
static int operands(struct topts *o, int n, char **arg)
{
	if (!strncmp(o->sub, "check-host=", 11)) {
		const char *eq = o->sub + 11;

		o->sub = "check-host";
		return host_seconds(o, eq, n, arg);
	}
	if (!strcmp(o->sub, "check-host"))
		return host_seconds(o, NULL, n, arg);
	if (!strcmp(o->sub, "bind-relay")) {
		if (!n)
			return 0;
		fprintf(stderr, "roboelf-tech: error: bind-relay takes no "
				"operand (roboelf-tech --help)\n");
		return -1;
	}
	if (n != 1) {
		fprintf(stderr,
			"roboelf-tech: error: %s takes one %s (roboelf-tech "
			"--help)\n",
			o->sub,
			!strcmp(o->sub, "commission") ? "directory" : "file");
		return -1;
	}
	if (!strcmp(o->sub, "commission"))
		o->dir = arg[0];
	else
		o->file = arg[0];
	return 0;
}

/* Return: 0 to run, 1 after --help, -1 on a usage error. */
static int parse_opts(int argc, char **argv, struct topts *o)
{
	static const char *const subs[] = {"commission", "show-calibration",
					   "show-trace", "check-host",
					   "bind-relay"};
	static const struct option lo[] = {
	    {"config", required_argument, NULL, 'c'},
	    {"galil", required_argument, NULL, 'g'},
	    {"relay", required_argument, NULL, 'r'},
	    {"log", required_argument, NULL, 'l'},
	    {"period", required_argument, NULL, 'p'},
	    {"window", required_argument, NULL, 'w'},
	    {"wait", required_argument, NULL, 'W'},
	    {"find-addr", required_argument, NULL, 'F'},
	    {"find-port", required_argument, NULL, 'P'},
	    {"dmc", required_argument, NULL, 'D'},
	    {"serial", required_argument, NULL, 'S'},
	    {"rules-file", required_argument, NULL, 'R'},
	    {"bind-relay", no_argument, NULL, 'B'},
	    {"help", no_argument, NULL, 'h'},
	    {"version", no_argument, NULL, 'V'},
	    {"print", required_argument, NULL, 'K'},
	    {NULL, 0, NULL, 0},
	};
	int c;

	memset(o, 0, sizeof(*o));
	while ((c = getopt_long(argc, argv, "c:h", lo, NULL)) != -1) {
		if (c == 'h') {
			usage(stdout);
			return 1;
		}
		if (c == 'V')
			o->version = 1;
		else if (c == 'B')
			o->sub = "bind-relay";
		else if (c == 'K')
			o->print = optarg;
		else if (opt_value(o, c, optarg) < 0)
			return -1;
	}
	if (o->version || (o->print && optind == argc))
		return 0;
	if (o->sub) /* --bind-relay */
		return operands(o, argc - optind, argv + optind);
	if (o->print) {
		fprintf(stderr, "roboelf-tech: error: --print takes no "
				"command\n");
		return -1;
	}
	if (optind >= argc) {
		usage(stderr);
		return -1;
	}
	o->sub = argv[optind];
	if (!strncmp(o->sub, "check-host=", 11)) /* the old --check-host=S */
		return operands(o, argc - optind - 1, argv + optind + 1);
	for (size_t i = 0; i < sizeof(subs) / sizeof(subs[0]); i++)
		if (!strcmp(o->sub, subs[i]))
			return operands(o, argc - optind - 1,
					argv + optind + 1);
	fprintf(stderr,
		"roboelf-tech: error: unknown command '%s': commission, "
		"show-calibration, show-trace, check-host or bind-relay\n",
		o->sub);
	return -1;
}

int main(int argc, char **argv)
{
	static struct app a;
	static struct topts o;
	int rc = parse_opts(argc, argv, &o);

	if (rc)
		return rc > 0 ? 0 : EXIT_USAGE;
	a.prog = "roboelf-tech";
	re_app_root_note(a.prog);
	if (o.version)
		return re_app_print_version(a.prog, &o.g);
	if (o.print)
		return print_key(&a, &o.g, o.print);
	if (!strcmp(o.sub, "show-calibration"))
		return show_calibration(&a, &o.g, o.file);
	if (!strcmp(o.sub, "show-trace"))
		return show_trace(&a, &o.g, o.file, o.window);
	if (!strcmp(o.sub, "bind-relay"))
		return re_bindrelay_run(&o.bind, re_bindrelay_list_sp, stdout,
					stderr);
	if (re_app_load_config(&a, &o.g) < 0)
		return EXIT_USAGE;
	a.config_path = o.g.config;
	if (!strcmp(o.sub, "check-host"))
		return check_host(&a, o.seconds);
	if (re_app_open_log(&a, &o.g) < 0)
		return EXIT_USAGE;
	return commission(&a, &o);
}
