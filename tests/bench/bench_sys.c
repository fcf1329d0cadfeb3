/*
 * bench_sys.c - make bench: performance figures of the whole system on
 * galil-sim, printed as a table and written as CSV. Figures, not pass/fail.
 *
 *   bench_sys --csv FILE [--seconds S] [--repeat N] [--alloc-lib SO]
 *             [--faults-bin PATH] [--long L] [--only instr]
 *
 *  1. full calibration time (roboelf --calibration full on the default
 *     robot);
 *  2. at supervisor periods 50, 10 and 2 ms, each in both designs of
 *     getting the controller's record (controller.record: poll, one
 *     "hbpc=N;QR" round trip a cycle; stream, the record sent by the
 *     controller over UDP and the heartbeat posted on TCP: docs/link.md),
 *     S seconds (default 20) of joystick use: cycles (the program
 *     heartbeat hbpc the supervisor writes every cycle, watched in the
 *     simulator), overruns and the worst reply age (roboelf's last status
 *     line; in the stream design the worst time between two fresh
 *     records), wake-up lateness p50/p99/max (roboelf's "stats:" log line
 *     at exit, when it writes one), TCP segments and bytes per cycle on
 *     roboelf's controller connections (ss -ti), UDP datagrams (the
 *     stream's records) received per cycle (perf stat on the
 *     sock:sock_recv_length tracepoint), CPU time per cycle
 *     (/proc/PID/schedstat), heap allocations after start-up (LD_PRELOAD
 *     counter, SIGUSR2 marks), system calls per cycle (perf stat on the
 *     raw_syscalls:sys_enter tracepoint, all threads of roboelf), and
 *     the record's interval from roboelf's start-up line;
 *  2a. with --long L (L > 0): the stream design at 2 ms for L seconds of
 *     joystick use (make bench: 600 under chrt -f 50), the same figures;
 *     the target is ten minutes with no overrun and no trip;
 *  3. galil-sim's virtual-time speed (galil-sim --bench 10: 8 busy
 *     program threads, in-process sim_advance_ms());
 *  4. fault reaction times: test_sys_faults run with ROBOELF_REPEAT=N,
 *     median / p99 / max per fault in ms and in supervisor periods;
 *  5. the flight recorder: its cost per cycle (re_rec_take()
 *     on a filled supervisor, 10^6 times in-process), its system calls
 *     per cycle (strace -c of this program run with --rec-loop N against
 *     --rec-loop 0), and the dump of a full 30 s ring at 10 ms (text and
 *     durable write, ms and bytes);
 *  6. user instructions per cycle, in both designs: roboelf under
 *     valgrind's callgrind at 50 ms with S / 3 and S seconds of joystick
 *     use, the instructions collected in its supervisor loop, the
 *     difference over the difference of the cycles run (--only instr:
 *     these figures alone).
 * Beside each figure: the original system's value where it has one
 * (roboelf-software-description.txt: 50 ms loop, 75/125 ms watchdog,
 * 0.5 s invalid input, one controller command per value read). The loop
 * figures are printed as one grid, a column per period and design
 * (item "period P ms, DESIGN"), so the two designs are read side by side;
 * the CSV has one row per figure as for every other section.
 *
 * Environment as for the system tests (ROBOELF_BIN, ROBOELF_TOP, BUILD).
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <sched.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base_clock.h"
#include "gl_err.h"
#include "re_config.h"
#include "re_rec.h"
#include "sys_h.h"

#define MAX_ROWS    512
#define MAX_SAMPLES 256
#define MAX_FAULTS  48

struct row {
	char section[24];
	char item[64];
	char stat[48];
	char value[400]; /* a FAULT line whole */
	char unit[16];
	char original[96];
};

static struct row rows[MAX_ROWS];
static int n_rows;

static void add(const char *section, const char *item, const char *stat,
		const char *unit, const char *original, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));

static void add(const char *section, const char *item, const char *stat,
		const char *unit, const char *original, const char *fmt, ...)
{
	struct row *r;
	va_list ap;

	if (n_rows == MAX_ROWS)
		return;
	r = &rows[n_rows++];
	snprintf(r->section, sizeof(r->section), "%s", section);
	snprintf(r->item, sizeof(r->item), "%s", item);
	snprintf(r->stat, sizeof(r->stat), "%s", stat);
	snprintf(r->unit, sizeof(r->unit), "%s", unit);
	snprintf(r->original, sizeof(r->original), "%s",
		 original ? original : "");
	va_start(ap, fmt);
	vsnprintf(r->value, sizeof(r->value), fmt, ap);
	va_end(ap);
}

/* ---- options ------------------------------------------------------------ */

struct opts {
	const char *csv;
	const char *alloc_lib;
	const char *faults_bin;
	const char *only; /* "instr": only the instruction count */
	int seconds;
	int repeat;
	int long_s; /* the stream design at 2 ms for this long; 0: not */
};

static int parse_opts(int argc, char **argv, struct opts *o)
{
	memset(o, 0, sizeof(*o));
	o->seconds = 20;
	o->repeat = 5;
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;

		if (!v)
			goto usage;
		if (!strcmp(a, "--csv"))
			o->csv = v;
		else if (!strcmp(a, "--alloc-lib"))
			o->alloc_lib = v;
		else if (!strcmp(a, "--faults-bin"))
			o->faults_bin = v;
		else if (!strcmp(a, "--only") && !strcmp(v, "instr"))
			o->only = v;
		else if (!strcmp(a, "--seconds"))
			o->seconds = atoi(v);
		else if (!strcmp(a, "--repeat"))
			o->repeat = atoi(v);
		else if (!strcmp(a, "--long"))
			o->long_s = atoi(v);
		else
			goto usage;
		i++;
	}
	if (o->csv && o->seconds >= 1 && o->repeat >= 0 && o->long_s >= 0)
		return 0;
usage:
	fprintf(stderr, "usage: bench_sys --csv FILE [--seconds S] [--repeat "
			"N] [--alloc-lib SO] [--faults-bin PATH] [--long L] "
			"[--only instr]\n");
	return -1;
}

/* ---- process figures ---------------------------------------------------- */

/* CPU time of @pid in ns (schedstat; else utime + stime in ticks). */
static double cpu_ns(pid_t pid)
{
	char path[64];
	unsigned long long ns, ut, st;
	FILE *f;
	int ok;

	snprintf(path, sizeof(path), "/proc/%d/schedstat", (int)pid);
	f = fopen(path, "r");
	if (f) {
		ok = fscanf(f, "%llu", &ns) == 1;
		fclose(f);
		if (ok)
			return (double)ns;
	}
	snprintf(path, sizeof(path), "/proc/%d/stat", (int)pid);
	f = fopen(path, "r");
	if (!f)
		return -1;
	ok = fscanf(f,
		    "%*d %*s %*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u "
		    "%llu %llu",
		    &ut, &st) == 2;
	fclose(f);
	return ok ? (double)(ut + st) * 1e9 / (double)sysconf(_SC_CLK_TCK) : -1;
}

struct tcp_fig {
	int ok;
	double bytes_out, bytes_in, segs_out;
};

static double field(const char *line, const char *key)
{
	const char *p = strstr(line, key);

	return p ? strtod(p + strlen(key), NULL) : 0;
}

/* Sum over roboelf's established connections to the controller port. */
static struct tcp_fig tcp_now(int port)
{
	struct tcp_fig t = {0};
	char cmd[128], line[2048];
	FILE *f;

	snprintf(cmd, sizeof(cmd),
		 "ss -tinH state established dst "
		 "127.0.0.1:%d 2>/dev/null",
		 port);
	f = popen(cmd, "r");
	if (!f)
		return t;
	while (fgets(line, sizeof(line), f)) {
		if (!strstr(line, "bytes_received:") &&
		    !strstr(line, "segs_out:"))
			continue;
		t.ok = 1;
		t.bytes_out += field(line, "bytes_acked:");
		t.bytes_in += field(line, "bytes_received:");
		t.segs_out += field(line, "data_segs_out:");
	}
	pclose(f);
	return t;
}

/* ---- one supervised run at a period ------------------------------------- */

/* The observer at normal scheduling while a run is measured: this
 * program's polls and the tools it starts (perf, ss) then never take a CPU
 * from roboelf and galil-sim, which inherited SCHED_FIFO at their start
 * under chrt -f 50 (at the same priority a starting perf held a CPU for
 * more than the 5 ms a 2 ms period allows). Return: the policy before, for
 * observe_end(). */
static int observe_begin(struct sched_param *old)
{
	struct sched_param normal = {.sched_priority = 0};
	int pol = sched_getscheduler(0);

	if (sched_getparam(0, old) < 0)
		old->sched_priority = 0;
	if (pol == SCHED_FIFO || pol == SCHED_RR)
		sched_setscheduler(0, SCHED_OTHER, &normal);
	return pol;
}

/* Back to @pol for the next case's start (its processes inherit it). */
static void observe_end(int pol, const struct sched_param *old)
{
	if (pol == SCHED_FIFO || pol == SCHED_RR)
		sched_setscheduler(0, pol, old);
}

struct loop_fig {
	int period_ms;
	const char *design; /* controller.record: "poll" or "stream" */
	int long_s;	    /* the long run's seconds; 0: an ordinary run */
	char link[160];	    /* the record's interval (start-up line) */
	char link_ms[16];   /* its measured interval, "" if none */
	char fault[512];    /* the FAULT line if it tripped */
	double trip_s;	    /* when, from the start of the run; -1 */
	double ready_s;
	double seconds;
	double cycles;
	double cpu_us;	    /* per cycle */
	struct tcp_fig tcp; /* per cycle */
	double udp_in;	    /* datagrams received per cycle, -1 n/a */
	long allocs;	    /* after start-up; -1 n/a */
	long overruns;	    /* -1 n/a */
	double wd_worst_ms; /* -1 n/a */
	double late[3];	    /* p50, p99, max ms; -1 n/a */
	double syscalls;    /* per cycle (perf raw_syscalls), -1 n/a */
	int rb_values;	    /* sealed values roboelf reads back, -1 n/a */
	int rb_cycles;	    /* cycles to read them all, -1 n/a */
};

/* roboelf's start-up line "checked twice: ... the program's N sealed
 * values back, all every K cycles (T ms) ..." (wrapped on two lines). */
static void readback_figures(const struct proc *re, struct loop_fig *f)
{
	const char *out = proc_output(re, PROC_STDOUT);
	const char *p = out ? strstr(out, "the program's ") : NULL;
	const char *q = p ? strstr(p, "every ") : NULL;

	f->rb_values = f->rb_cycles = -1;
	if (!p || !q || sscanf(p, "the program's %d", &f->rb_values) != 1 ||
	    sscanf(q, "every %d", &f->rb_cycles) != 1)
		f->rb_values = f->rb_cycles = -1;
}

/* roboelf's start-up line of the record, "roboelf: record stream: UDP
 * handle B, every N samples (T ms); measured over 20 records M ms ..." or
 * "roboelf: record polled (QR each cycle); ...", shortened into f->link.
 * Return: 0, or -1 when it is missing or names the other design. */
static int link_figure(const struct proc *re, struct loop_fig *f)
{
	char line[512], n0_ms[16], meas_ms[16];
	const char *p;
	unsigned n0;

	if (proc_find_line(re, PROC_STDOUT, "roboelf: record ", line,
			   sizeof(line)) < 0) {
		snprintf(f->link, sizeof(f->link), "no 'roboelf: record' line");
		return -1;
	}
	if (!strcmp(f->design, "poll")) {
		snprintf(f->link, sizeof(f->link), "%s",
			 strstr(line, "record polled") ? "QR each cycle"
						       : "not polled");
		return strstr(line, "record polled") ? 0 : -1;
	}
	p = strstr(line, "every ");
	if (!strstr(line, "record stream: ") || !p ||
	    sscanf(p, "every %u samples (%15[0-9.] ms)", &n0, n0_ms) != 2) {
		snprintf(f->link, sizeof(f->link), "not a stream: %.100s",
			 line + 9);
		return -1;
	}
	p = strstr(line, "records ");
	if (p && sscanf(p, "records %15[0-9.] ms", meas_ms) == 1)
		snprintf(f->link_ms, sizeof(f->link_ms), "%s", meas_ms);
	snprintf(f->link, sizeof(f->link), "DR %u (%s ms)", n0, n0_ms);
	return 0;
}

/* ---- system calls per cycle: perf stat on the tracepoint ---------------- */

/* perf stat counting @event (with @filter, or NULL) of @pid, all threads,
 * into @out until SIGINT; -1 when it cannot start. Counting a tracepoint
 * costs the process nothing measurable (strace's ptrace would slow every
 * call). */
static pid_t perf_start(pid_t pid, const char *out, const char *event,
			const char *filter)
{
	char p[24];
	pid_t k;

	snprintf(p, sizeof(p), "%d", (int)pid);
	k = fork();
	if (k == 0) {
		int fd = open("/dev/null", O_WRONLY);

		if (fd >= 0) {
			dup2(fd, 1);
			dup2(fd, 2);
		}
		if (filter)
			execlp("perf", "perf", "stat", "-x,", "-o", out, "-e",
			       event, "--filter", filter, "-p", p,
			       (char *)NULL);
		else
			execlp("perf", "perf", "stat", "-x,", "-o", out, "-e",
			       event, "-p", p, (char *)NULL);
		_exit(127);
	}
	return k;
}

/* Stop @perf; the count of @event it wrote to @out, or -1. */
static double perf_stop(pid_t perf, const char *out, const char *event)
{
	char line[256];
	double n = -1;
	int status;
	FILE *f;

	if (perf <= 0)
		return -1;
	kill(perf, SIGINT);
	/* perf stat ends on SIGINT by re-raising it (after writing @out) */
	if (waitpid(perf, &status, 0) != perf ||
	    (WIFEXITED(status) && WEXITSTATUS(status) != 0))
		return -1;
	f = fopen(out, "r");
	while (f && fgets(line, sizeof(line), f))
		if (strstr(line, event))
			n = strncmp(line, "<not counted>", 13)
				? strtod(line, NULL)
				: 0;
	if (f)
		fclose(f);
	return n;
}

/* The two counts of a run: every system call, and the UDP datagrams
 * roboelf received (the sock_recv_length tracepoint, Linux 6.3 on; a
 * receive that found nothing is not counted). */
#define EV_SYSCALLS "raw_syscalls:sys_enter"
#define EV_RECV	    "sock:sock_recv_length"
#define EV_UDP_IN   "protocol == 17 && ret > 0"

static double hbpc(struct sys_case *c)
{
	char st[2048];

	if (sys_state(c, st, sizeof(st)) < 0)
		return NAN;
	return sys_state_num(st, "var.hbpc");
}

/* Joystick use for @secs of simulated time: A and B back and forth.
 * Return: 0, or the simulated time at which a FAULT line was seen (> 0),
 * or -1 on error. */
static double drive(struct sys_case *c, int secs)
{
	static const char *const moves[] = {"A fwd", "A rev", "B fwd", "B rev"};
	double t = sys_sim_time(c), end = t + secs * 1000.0;

	for (int k = 0; t >= 0 && t < end; k++) {
		const char *m = moves[k % 4];

		if (sys_ctl(c, "joy %s", m) < 0 ||
		    sys_wait_sim(c, t + 1000, 10000) < 0 ||
		    sys_ctl(c, "joy %c neutral", m[0]) < 0 ||
		    sys_wait_sim(c, t + 1300, 10000) < 0)
			return -1;
		if (proc_find_line(&c->re, PROC_STDOUT, "FAULT ", NULL, 0) == 0)
			return t;
		t = sys_sim_time(c);
	}
	return t < 0 ? -1 : 0;
}

/* The last "status" line's overruns and worst reply age. */
static void status_figures(struct sys_case *c, struct loop_fig *f)
{
	const char *out = proc_output(&c->re, PROC_STDOUT), *p, *last = NULL;
	double wl, ww;

	for (p = strstr(out, "status "); p; p = strstr(p + 1, "\nstatus "))
		last = p;
	if (!last)
		return;
	p = strstr(last, " overruns=");
	if (p)
		f->overruns = strtol(p + 10, NULL, 10);
	p = strstr(last, " wd=");
	if (p && sscanf(p + 4, "%lf/%lfms", &wl, &ww) == 2)
		f->wd_worst_ms = ww;
}

/* roboelf's "stats:" log line, if it writes one (lateness p50/p99/max). */
static void stats_line(struct sys_case *c, struct loop_fig *f)
{
	char line[4096];
	const char *p;

	if (sys_log_find(c, "stats:", NULL, line, sizeof(line)) < 0)
		return;
	p = strstr(line, "late");
	if (!p)
		return;
	f->late[0] = strstr(p, "p50=") ? field(p, "p50=") : -1;
	f->late[1] = strstr(p, "p99=") ? field(p, "p99=") : -1;
	f->late[2] = strstr(p, "max=") ? field(p, "max=") : -1;
	if (strstr(line, "overruns="))
		f->overruns = (long)field(line, "overruns=");
}

static long alloc_figure(const char *path)
{
	long total, m0, m1;
	FILE *f = fopen(path, "r");
	int n;

	if (!f)
		return -1;
	n = fscanf(f, "allocs total=%ld marks=%ld,%ld", &total, &m0, &m1);
	fclose(f);
	return n == 3 ? m1 - m0 : -1;
}

struct mark {
	double hb, cpu, t;
	struct tcp_fig tcp;
};

static int take_mark(struct sys_case *c, int use_alloc, struct mark *m)
{
	if (use_alloc)
		proc_signal(&c->re, SIGUSR2);
	m->t = sys_sim_time(c);
	m->hb = hbpc(c);
	m->cpu = cpu_ns(c->re.pid);
	m->tcp = tcp_now(c->sim.port);
	return m->t < 0 || isnan(m->hb) ? -1 : 0;
}

static void figures(struct loop_fig *f, const struct mark *a,
		    const struct mark *b)
{
	f->seconds = (b->t - a->t) / 1000.0;
	f->cycles = fmod(b->hb - a->hb + 1e6, 1e6);
	if (f->cycles <= 0)
		return;
	f->cpu_us = a->cpu >= 0 && b->cpu >= 0
			? (b->cpu - a->cpu) / f->cycles / 1000.0
			: -1;
	f->tcp.ok = a->tcp.ok && b->tcp.ok;
	f->tcp.bytes_out = (b->tcp.bytes_out - a->tcp.bytes_out) / f->cycles;
	f->tcp.bytes_in = (b->tcp.bytes_in - a->tcp.bytes_in) / f->cycles;
	f->tcp.segs_out = (b->tcp.segs_out - a->tcp.segs_out) / f->cycles;
}

static void loop_init(struct loop_fig *f, int period, const char *design,
		      int long_s)
{
	memset(f, 0, sizeof(*f));
	f->period_ms = period;
	f->design = design;
	f->long_s = long_s;
	f->allocs = f->overruns = -1;
	f->trip_s = -1;
	f->wd_worst_ms = f->late[0] = f->late[1] = f->late[2] = -1;
	f->syscalls = f->udp_in = -1;
}

/* One run of @f's period and design (loop_init()): o->seconds of joystick
 * use, or f->long_s. Return: 0, or -1 with f->fault saying why. */
static int loop_run(struct sys_env *e, const struct opts *o, struct loop_fig *f)
{
	char out_env[SYS_PATH_MAX + 32], pre_env[SYS_PATH_MAX + 16],
	    alloc_out[SYS_PATH_MAX], perf_out[2][SYS_PATH_MAX], tag[32];
	pid_t perf[2] = {-1, -1};
	double calls = -1, udp = -1;
	char *env[3] = {NULL, NULL, NULL};
	const struct sys_subst rec[] = {{"record", f->design}, {NULL, NULL}};
	struct sys_opts so = {
	    .period_ms = f->period_ms, .re_env = env, .subst = rec};
	struct sys_case c;
	struct sched_param sp;
	struct mark a, b;
	int rc = -1, pol;

	snprintf(tag, sizeof(tag), "%d-%s%s", f->period_ms, f->design,
		 f->long_s ? "-long" : "");
	snprintf(alloc_out, sizeof(alloc_out), "%s/alloc-%s.txt", e->dir, tag);
	if (o->alloc_lib) {
		snprintf(pre_env, sizeof(pre_env), "LD_PRELOAD=%s",
			 o->alloc_lib);
		snprintf(out_env, sizeof(out_env), "ROBOELF_ALLOC_OUT=%s",
			 alloc_out);
		env[0] = pre_env;
		env[1] = out_env;
	}
	if (sys_case_start(&c, e, &so) < 0) {
		snprintf(f->fault, sizeof(f->fault), "did not start: %.400s",
			 c.err);
		return -1;
	}
	f->ready_s = c.ready_wall_s;
	pol = observe_begin(&sp);
	snprintf(perf_out[0], sizeof(perf_out[0]), "%s/perf-%s.txt", e->dir,
		 tag);
	snprintf(perf_out[1], sizeof(perf_out[1]), "%s/perf-udp-%s.txt", e->dir,
		 tag);
	if (link_figure(&c.re, f) < 0) {
		snprintf(c.err, sizeof(c.err), "not the %s design: %s",
			 f->design, f->link);
		goto out;
	}
	if (sys_ctl(&c, "watch hbpc") < 0 ||
	    sys_wait_sim(&c, c.t_ready_ms + 1000, 5000) < 0)
		goto out;
	perf[0] = perf_start(c.re.pid, perf_out[0], EV_SYSCALLS, NULL);
	perf[1] = perf_start(c.re.pid, perf_out[1], EV_RECV, EV_UDP_IN);
	if (take_mark(&c, o->alloc_lib != NULL, &a) < 0)
		goto out;
	f->trip_s = drive(&c, f->long_s ? f->long_s : o->seconds);
	if (f->trip_s < 0 || take_mark(&c, o->alloc_lib != NULL, &b) < 0)
		goto out;
	calls = perf_stop(perf[0], perf_out[0], EV_SYSCALLS);
	udp = perf_stop(perf[1], perf_out[1], EV_RECV);
	perf[0] = perf[1] = -1;
	if (f->trip_s > 0) {
		int i = sys_events(&c) < 0
			    ? -1
			    : sys_event_find(&c, "relay off", c.t_ready_ms + 1);

		f->trip_s = i < 0 ? -1 : (c.ev[i].t_ms - c.t_ready_ms) / 1e3;
	} else {
		f->trip_s = -1;
	}
	figures(f, &a, &b);
	/* the count spans the two marks and two hbpc reads: good to 1 % */
	f->syscalls = calls >= 0 && f->cycles > 0 ? calls / f->cycles : -1;
	f->udp_in = udp >= 0 && f->cycles > 0 ? udp / f->cycles : -1;
	proc_find_line(&c.re, PROC_STDOUT, "FAULT ", f->fault,
		       sizeof(f->fault));
	readback_figures(&c.re, f);
	proc_signal(&c.re, SIGTERM);
	proc_wait_exit(&c.re, 5000, NULL);
	status_figures(&c, f);
	stats_line(&c, f);
	if (o->alloc_lib)
		f->allocs = alloc_figure(alloc_out);
	rc = 0;
out:
	for (int k = 0; k < 2; k++)
		if (perf[k] > 0)
			perf_stop(perf[k], perf_out[k], EV_RECV);
	observe_end(pol, &sp);
	if (rc < 0)
		snprintf(f->fault, sizeof(f->fault), "run failed: %.400s",
			 c.err);
	sys_case_stop(&c);
	return rc;
}

/* @v with @decimals, or "n/a" when negative or NaN. */
static void fmt_or_na(char *buf, size_t cap, double v, int decimals)
{
	if (v < 0 || isnan(v))
		snprintf(buf, cap, "n/a");
	else
		snprintf(buf, cap, "%.*f", decimals, v);
}

/* Lateness, overruns and the worst reply age: from roboelf's exit, over
 * the whole run (after a trip too). */
static void add_loop_timing(const struct loop_fig *f, const char *item,
			    int is50)
{
	static const char *const st[] = {"lateness p50", "lateness p99",
					 "lateness max"};
	char v[48];

	for (int k = 0; k < 3; k++) {
		fmt_or_na(v, sizeof(v), f->late[k], 3);
		add("loop", item, st[k], "ms", "", "%s%s", v,
		    f->late[k] < 0 ? " (not reported by roboelf)" : "");
	}
	add("loop", item, "overruns", "", "", "%ld", f->overruns);
	fmt_or_na(v, sizeof(v), f->wd_worst_ms, 1);
	add("loop", item, "worst reply age", "ms",
	    is50 ? "limits 75 / 125 ms" : "", "%s", v);
}

static void add_loop_cycle(const struct loop_fig *f, const char *item, int is50)
{
	char v[48];

	if (f->tcp.ok) {
		add("loop", item, "requests per cycle (TCP)", "",
		    is50 ? "one command per value read" : "", "%.2f",
		    f->tcp.segs_out);
		add("loop", item, "bytes out / in per cycle (TCP)", "B", "",
		    "%.1f / %.1f", f->tcp.bytes_out, f->tcp.bytes_in);
	} else {
		add("loop", item, "requests per cycle (TCP)", "", "",
		    "n/a (ss not available)");
	}
	fmt_or_na(v, sizeof(v), f->udp_in, 2);
	add("loop", item, "records per cycle (UDP datagrams in)", "", "",
	    "%s%s", v, f->udp_in < 0 ? " (perf not available)" : "");
	fmt_or_na(v, sizeof(v), f->cpu_us, 1);
	add("loop", item, "supervisor CPU per cycle", "us", "", "%s", v);
	fmt_or_na(v, sizeof(v), f->syscalls, 2);
	add("loop", item, "system calls per cycle", "", "", "%s%s", v,
	    f->syscalls < 0 ? " (perf not available)" : "");
	fmt_or_na(v, sizeof(v), (double)f->allocs, 0);
	add("loop", item, "heap allocations after start-up", "", "", "%s", v);
}

/* "period P ms, DESIGN" (and ", L s" for the long run): the grid's
 * column. */
static void loop_item(const struct loop_fig *f, char *buf, size_t cap)
{
	if (f->long_s)
		snprintf(buf, cap, "period %d ms, %s, %d s", f->period_ms,
			 f->design, f->long_s);
	else
		snprintf(buf, cap, "period %d ms, %s", f->period_ms, f->design);
}

static void add_loop(const struct loop_fig *f)
{
	char item[64];
	int is50 = f->period_ms == 50, pol = sched_getscheduler(0);
	const char *how = pol == SCHED_FIFO ? "SCHED_FIFO" : "normal";

	loop_item(f, item, sizeof(item));
	add("loop", item, "start-up with --calibration file", "s", "", "%.2f",
	    f->ready_s);
	add("loop", item, "record (start-up line)", "", "", "%s", f->link);
	add("loop", item, "record interval, 20 at start-up", "ms", "", "%s",
	    f->link_ms[0] ? f->link_ms : "n/a (polled)");
	if (f->long_s)
		add("loop", item, "galil-sim's scheduling", "", "", "%s", how);
	if (f->fault[0]) {
		add("loop", item, "tripped", "", is50 ? "50 ms loop" : "",
		    "%.1f s after Ready", f->trip_s);
		add("loop", item, "FAULT line", "", "", "%s", f->fault);
		add_loop_timing(f, item, is50);
		return;
	}
	add("loop", item, "tripped", "", is50 ? "50 ms loop" : "", "no");
	add("loop", item, "cycles measured", "", "", "%.0f in %.1f s",
	    f->cycles, f->seconds);
	if (f->rb_cycles > 0) {
		add("loop", item, "seal read back: all values every", "ms",
		    "none", "%d", f->rb_cycles * f->period_ms);
		add("loop", item, "seal read back: values / cycles", "", "",
		    "%d / %d", f->rb_values, f->rb_cycles);
	}
	add_loop_timing(f, item, is50);
	add_loop_cycle(f, item, is50);
}

/* ---- user instructions per cycle: callgrind ------------------- */

/* This VM, like many, has no hardware performance counters (perf stat -e
 * instructions:u is "not supported"), so the instructions are counted by
 * valgrind's callgrind: roboelf runs under it armed on galil-sim at 50 ms
 * with joystick use, collecting only inside roboelf.c's run() (the
 * supervisor loop: wait, cycle, status, console, log flush, keyboard,
 * recorder tick; --toggle-collect, so start-up and power-off are not
 * counted) the instructions (Ir, user space only: the kernel's side of the
 * system calls and the wait is not seen) and the calls to re_super_cycle().
 * run() also has one-time work (the "stats:" log line at its end: some
 * 50 k instructions), so it is run twice, S / 3 and S seconds, and the
 * figure is the difference of the instructions over the difference of the
 * cycles. */

struct instr_fig {
	double ir;     /* collected Ir, -1 n/a */
	long cycles;   /* calls to re_super_cycle */
	double cyc_ir; /* inclusive Ir of the calls to re_super_cycle and
			* re_super_wait: the cycle itself */
	char why[256];
	char out[SYS_PATH_MAX + 32];
};

/* The absolute path of valgrind on PATH into @buf (cap >= PATH_MAX), or
 * -1. Its real path: Debian's valgrind is a script that runs "$0.bin",
 * which make bench's PATH of symbolic links (tools/cmdtable.sh) lacks. */
static int find_valgrind(char *buf, size_t cap)
{
	FILE *f = popen("command -v valgrind 2>/dev/null", "r");
	char found[PATH_MAX];
	int ok = f && fgets(found, (int)sizeof(found), f) && found[0] == '/';

	if (f)
		pclose(f);
	if (!ok)
		return -1;
	found[strcspn(found, "\n")] = '\0';
	if (cap < PATH_MAX || !realpath(found, buf))
		return -1;
	return 0;
}

/* Name compression of callgrind's output: "(id) name" defines @id's name,
 * "(id)" refers to it. Does @ref (after "fn=" / "cfn=") name @want? */
static int cg_names(const char *ref, const char *want, long *want_id)
{
	char *end;
	long id;

	if (*ref != '(')
		return !strcmp(ref, want);
	id = strtol(ref + 1, &end, 10);
	if (*end != ')')
		return 0;
	if (end[1] == ' ' && !strcmp(end + 2, want))
		*want_id = id;
	return *want_id >= 0 && id == *want_id;
}

/* From a callgrind output file: the total Ir, the calls to
 * re_super_cycle, and the inclusive Ir of the calls to it and to
 * re_super_wait (the line after a "calls=" line: position, then the
 * callee's inclusive cost). */
static int cg_read(const char *path, struct instr_fig *f)
{
	static const char *const fns[2] = {"re_super_cycle", "re_super_wait"};
	char line[4096], *sp;
	long id[2] = {-1, -1};
	int in_cfn = -1, cost_next = 0;
	FILE *in = fopen(path, "r");

	if (!in)
		return -1;
	while (fgets(line, sizeof(line), in)) {
		line[strcspn(line, "\n")] = '\0';
		if (cost_next && (sp = strrchr(line, ' ')))
			f->cyc_ir += strtod(sp + 1, NULL);
		cost_next = 0;
		if (!strncmp(line, "cfn=", 4)) {
			in_cfn = -1;
			for (int k = 0; k < 2; k++)
				if (cg_names(line + 4, fns[k], &id[k]))
					in_cfn = k;
			continue;
		}
		if (!strncmp(line, "fn=", 3)) {
			for (int k = 0; k < 2; k++)
				cg_names(line + 3, fns[k], &id[k]);
		} else if (!strncmp(line, "calls=", 6) && in_cfn >= 0) {
			if (in_cfn == 0)
				f->cycles += strtol(line + 6, NULL, 10);
			cost_next = 1;
		} else if (!strncmp(line, "summary:", 8) ||
			   !strncmp(line, "totals:", 7)) {
			f->ir = strtod(strchr(line, ':') + 1, NULL);
		}
		in_cfn = -1;
	}
	fclose(in);
	return 0;
}

static void instr_run(struct sys_env *e, int secs, const char *design,
		      struct instr_fig *f)
{
	const struct sys_subst rec[] = {{"record", design}, {NULL, NULL}};
	char vg[PATH_MAX], outopt[SYS_PATH_MAX + 64];
	char *wrap[] = {vg,
			(char *)"--tool=callgrind",
			(char *)"--collect-atstart=no",
			(char *)"--toggle-collect=run",
			(char *)"--toggle-collect=run.*",
			outopt,
			NULL};
	struct sys_opts so = {.period_ms = 50,
			      .re_wrap = wrap,
			      .ready_timeout_ms = 120000,
			      .subst = rec};
	struct sys_case c;
	double t;

	memset(f, 0, sizeof(*f));
	f->ir = -1;
	if (find_valgrind(vg, sizeof(vg)) < 0) {
		snprintf(f->why, sizeof(f->why), "valgrind not installed");
		return;
	}
	snprintf(f->out, sizeof(f->out), "%s/callgrind-50-%s-%ds.out", e->dir,
		 design, secs);
	snprintf(outopt, sizeof(outopt), "--callgrind-out-file=%s", f->out);
	if (sys_case_start(&c, e, &so) < 0) {
		snprintf(f->why, sizeof(f->why), "did not start: %.200s",
			 c.err);
		return;
	}
	t = drive(&c, secs);
	if (t != 0)
		snprintf(f->why, sizeof(f->why), "%s",
			 t > 0 ? "tripped under valgrind" : "run failed");
	proc_signal(&c.re, SIGTERM);
	if (proc_wait_exit(&c.re, 30000, NULL) < 0 && !f->why[0])
		snprintf(f->why, sizeof(f->why), "roboelf did not exit");
	sys_case_stop(&c);
	if (!f->why[0] &&
	    (cg_read(f->out, f) < 0 || f->ir < 0 || f->cycles <= 0))
		snprintf(f->why, sizeof(f->why), "no cycles in '%.200s'",
			 f->out);
}

/* The instructions per cycle of @design ("poll", "stream") at 50 ms,
 * item "period 50 ms, DESIGN" like the loop figures. */
static void instr(struct sys_env *e, const struct opts *o, const char *design)
{
	int short_s = o->seconds / 3 > 2 ? o->seconds / 3 : 2;
	struct instr_fig a, b;
	const char *why;
	char item[64];

	snprintf(item, sizeof(item), "period 50 ms, %s", design);
	printf("bench: %d and %d s of joystick use at 50 ms under callgrind "
	       "(%s) ...\n",
	       short_s, o->seconds, design);
	fflush(stdout);
	instr_run(e, short_s, design, &a);
	instr_run(e, o->seconds, design, &b);
	why = a.why[0] ? a.why : b.why;
	if (!why[0] && b.cycles <= a.cycles)
		why = "no more cycles in the longer run";
	if (why[0]) {
		add("loop", item, "user instructions per cycle, run()", "", "",
		    "n/a (%.200s)", why);
		return;
	}
	add("loop", item, "user instructions per cycle, run()", "", "5 k",
	    "%.0f", (b.ir - a.ir) / (double)(b.cycles - a.cycles));
	add("loop", item, "user instructions per cycle, cycle alone", "", "5 k",
	    "%.0f", (b.cyc_ir - a.cyc_ir) / (double)(b.cycles - a.cycles));
	add("loop", item, "callgrind Ir / cycles, 2 runs", "", "",
	    "%.0f/%ld, %.0f/%ld", a.ir, a.cycles, b.ir, b.cycles);
	printf("bench: the cycle's instructions by function (%s): "
	       "callgrind_annotate --inclusive=yes %s\n",
	       design, b.out);
}

/* ---- galil-sim's virtual-time speed ------------------------------------- */

static void sim_speed(const struct sys_env *e)
{
	char cmd[SYS_PATH_MAX + 32], line[512];
	double x = -1;
	FILE *f;

	snprintf(cmd, sizeof(cmd), "'%s/galil-sim' --bench 10", e->bin);
	f = popen(cmd, "r");
	if (f) {
		while (fgets(line, sizeof(line), f))
			if (sscanf(line, "galil-sim virtual time: %lf", &x) ==
			    1)
				break;
		pclose(f);
	}
	if (x < 0)
		add("sim", "virtual time, 8 busy threads", "speed",
		    "x real time", "", "n/a");
	else
		add("sim", "virtual time, 8 busy threads", "speed",
		    "x real time", "", "%.1f", x);
}

/* ---- fault reaction times ----------------------------------------------- */

struct fault_samples {
	char name[64];
	double relay[MAX_SAMPLES], motors[MAX_SAMPLES];
	int nr, nm;
	double d_relay, d_motors;
	int period_ms;
};

static const char *original_for(const char *name)
{
	static const struct {
		const char *key, *orig;
	} t[] = {
	    {"pot stuck", "<= 50 ms after the tolerance is passed"},
	    {"encoder stuck", "<= 50 ms after the tolerance is passed"},
	    {"pot", "<= 50 ms (every cycle, no persistence)"},
	    {"encoder slip", "<= 50 ms (every cycle, no persistence)"},
	    {"link stalled", "125 ms (critical watchdog 2.5 P)"},
	    {"link latency", "125 ms (critical watchdog 2.5 P)"},
	    {"link dropped", "<= 50 ms (next command fails)"},
	    {"power cycle", "<= 50 ms (next command fails)"},
	    {"joystick", "0.5 s + <= 50 ms (PC checks)"},
	    {"invalid", "0.5 s + <= 50 ms (PC checks)"},
	    {"two directions", "0.5 s + <= 50 ms (PC checks)"},
	    {"relay unplugged", "<= 50 ms (EStop_CheckConnection)"},
	    {"supervisor killed", "Galil watchdog (timeout undocumented)"},
	};

	for (size_t i = 0; i < sizeof(t) / sizeof(t[0]); i++)
		if (strstr(name, t[i].key))
			return t[i].orig;
	return "";
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;

	return x < y ? -1 : x > y;
}

/* Nearest-rank percentile of @n sorted values. */
static double pct(const double *v, int n, double p)
{
	int k = (int)ceil(p / 100.0 * n) - 1;

	return v[k < 0 ? 0 : k >= n ? n - 1 : k];
}

static int load_reactions(const char *csv, struct fault_samples *fs)
{
	char line[512];
	int n = 0;
	FILE *f = fopen(csv, "r");

	while (f && fgets(line, sizeof(line), f)) {
		char name[64];
		double r, m, dr, dm;
		int p, i;

		if (sscanf(line, "%63[^,],%lf,%lf,%lf,%lf,%d", name, &r, &m,
			   &dr, &dm, &p) != 6)
			continue;
		for (i = 0; i < n && strcmp(fs[i].name, name); i++)
			;
		if (i == n) {
			if (n == MAX_FAULTS)
				continue;
			memset(&fs[n], 0, sizeof(fs[n]));
			snprintf(fs[n].name, sizeof(fs[n].name), "%s", name);
			n++;
		}
		fs[i].d_relay = dr;
		fs[i].d_motors = dm;
		fs[i].period_ms = p;
		if (r >= 0 && fs[i].nr < MAX_SAMPLES)
			fs[i].relay[fs[i].nr++] = r;
		if (m >= 0 && fs[i].nm < MAX_SAMPLES)
			fs[i].motors[fs[i].nm++] = m;
	}
	if (f)
		fclose(f);
	return n;
}

static void add_reaction(const struct fault_samples *s, const char *what,
			 double *v, int n, double deadline)
{
	char item[96], dl[48] = "";
	double p = s->period_ms > 0 ? s->period_ms : 50;

	if (n == 0)
		return;
	qsort(v, (size_t)n, sizeof(v[0]), cmp_double);
	snprintf(item, sizeof(item), "%s: %s (n=%d)", s->name, what, n);
	if (deadline >= 0)
		snprintf(dl, sizeof(dl), ", deadline %.0f", deadline);
	add("reaction", item, "median / p99 / max", "ms", original_for(s->name),
	    "%.0f / %.0f / %.0f%s", pct(v, n, 50), pct(v, n, 99),
	    pct(v, n, 100), dl);
	if (deadline >= 0)
		snprintf(dl, sizeof(dl), ", deadline %.2f", deadline / p);
	add("reaction", item, "median / p99 / max", "P", "",
	    "%.2f / %.2f / %.2f%s", pct(v, n, 50) / p, pct(v, n, 99) / p,
	    pct(v, n, 100) / p, dl);
}

static void reactions(const struct sys_env *e, const struct opts *o)
{
	static struct fault_samples fs[MAX_FAULTS];
	char csv[SYS_PATH_MAX + 16], outp[SYS_PATH_MAX + 16], cmd[4096];
	int n, rc;

	if (o->repeat == 0 || !o->faults_bin)
		return;
	snprintf(csv, sizeof(csv), "%s/reactions.csv", e->dir);
	snprintf(outp, sizeof(outp), "%s/faults.out", e->dir);
	snprintf(cmd, sizeof(cmd),
		 "ROBOELF_REPEAT=%d ROBOELF_REACTION_CSV='%s' "
		 "ROBOELF_SYS_CAL='%s' ROBOELF_BIN='%s' ROBOELF_TOP='%s' '%s' "
		 "> '%s' 2>&1",
		 o->repeat, csv, e->cal, e->bin, e->top, o->faults_bin, outp);
	printf("bench: fault matrix x %d (%s) ...\n", o->repeat, outp);
	fflush(stdout);
	rc = system(cmd);
	add("reaction", "test_sys_faults run", "failed tests", "", "",
	    "%d (output: %s)", WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, outp);
	n = load_reactions(csv, fs);
	for (int i = 0; i < n; i++) {
		add_reaction(&fs[i], "relay off", fs[i].relay, fs[i].nr,
			     fs[i].d_relay);
		add_reaction(&fs[i], "motors off", fs[i].motors, fs[i].nm,
			     fs[i].d_motors);
	}
}

/* ---- output ------------------------------------------------------------- */

static void csv_field(FILE *f, const char *s, int last)
{
	int quote = strpbrk(s, ",\"\n") != NULL;

	if (quote) {
		fputc('"', f);
		for (; *s; s++) {
			if (*s == '"')
				fputc('"', f);
			fputc(*s, f);
		}
		fputc('"', f);
	} else {
		fputs(s, f);
	}
	fputc(last ? '\n' : ',', f);
}

static int write_csv(const char *path)
{
	FILE *f = fopen(path, "w");

	if (!f) {
		fprintf(stderr, "bench: cannot write '%s': %s\n", path,
			strerror(errno));
		return -1;
	}
	fprintf(f, "section,item,statistic,value,unit,original\n");
	for (int i = 0; i < n_rows; i++) {
		csv_field(f, rows[i].section, 0);
		csv_field(f, rows[i].item, 0);
		csv_field(f, rows[i].stat, 0);
		csv_field(f, rows[i].value, 0);
		csv_field(f, rows[i].unit, 0);
		csv_field(f, rows[i].original, 1);
	}
	return fclose(f);
}

/* A loop figure of one period and design (item "period ..."): printed in
 * the grid, not in the table. */
static int in_grid(const struct row *r)
{
	return !strcmp(r->section, "loop") && !strncmp(r->item, "period ", 7);
}

#define GRID_COLS 6  /* columns of one grid */
#define GRID_W	  18 /* a cell's width; longer values are listed below */

/* The row of @item and @stat, or NULL. */
static const struct row *find_row(const char *item, const char *stat)
{
	for (int i = 0; i < n_rows; i++)
		if (in_grid(&rows[i]) && !strcmp(rows[i].item, item) &&
		    !strcmp(rows[i].stat, stat))
			return &rows[i];
	return NULL;
}

/* The grid's lines for @ncol columns @col: one line per statistic (in the
 * order they were added), one cell per column, then the original
 * system's value; the values too long for a cell in full after it. */
static void print_grid(const char *const *col, int ncol)
{
	char label[72];
	int w[GRID_COLS];

	printf("\n%-40s", "loop");
	for (int k = 0; k < ncol; k++) {
		w[k] = (int)strlen(col[k] + 7);
		w[k] = w[k] > GRID_W ? w[k] : GRID_W;
		printf(" %-*s", w[k], col[k] + 7);
	}
	printf(" original design\n");
	for (int i = 0; i < n_rows; i++) {
		const char *orig = "";
		int first = 1, here = 0;

		for (int j = 0; j < i && first; j++)
			first = !in_grid(&rows[j]) ||
				strcmp(rows[j].stat, rows[i].stat);
		for (int k = 0; k < ncol && first; k++)
			here |= find_row(col[k], rows[i].stat) != NULL;
		if (!in_grid(&rows[i]) || !here)
			continue;
		snprintf(label, sizeof(label),
			 rows[i].unit[0] ? "%s (%s)" : "%s", rows[i].stat,
			 rows[i].unit);
		printf("%-40.40s", label);
		for (int k = 0; k < ncol; k++) {
			const struct row *r = find_row(col[k], rows[i].stat);

			printf(" %-*.*s", w[k], GRID_W, r ? r->value : "-");
			if (r && r->original[0] && !orig[0])
				orig = r->original;
		}
		printf(" %s\n", orig);
	}
	for (int k = 0; k < ncol; k++)
		for (int i = 0; i < n_rows; i++)
			if (in_grid(&rows[i]) &&
			    !strcmp(rows[i].item, col[k]) &&
			    strlen(rows[i].value) > GRID_W)
				printf("  %s: %s: %s\n", rows[i].item,
				       rows[i].stat, rows[i].value);
}

/* Every figure: the loops as grids (periods and designs side by side),
 * the rest as a table. */
static void print_table(void)
{
	const char *col[MAX_ROWS];
	int ncol = 0;

	for (int i = 0; i < n_rows; i++) {
		int k = 0;

		while (k < ncol && strcmp(col[k], rows[i].item))
			k++;
		if (in_grid(&rows[i]) && k == ncol)
			col[ncol++] = rows[i].item;
	}
	for (int k = 0; k < ncol; k += GRID_COLS)
		print_grid(col + k,
			   ncol - k < GRID_COLS ? ncol - k : GRID_COLS);
	printf("\n%-10s %-44s %-36s %-22s %-6s %s\n", "section", "item",
	       "statistic", "value", "unit", "original design");
	for (int i = 0; i < n_rows; i++)
		if (!in_grid(&rows[i]))
			printf("%-10s %-44.44s %-36.36s %-22s %-6s %s\n",
			       rows[i].section, rows[i].item, rows[i].stat,
			       rows[i].value, rows[i].unit, rows[i].original);
}

/* ---- calibration against its physical bounds ----------------- */

/* The sweep (travel / vmax of the slowest axis: the axes move together)
 * and the least a calibration from the centre can take at vmax: half the
 * travel to the reverse switch, the sweep, half back to the centre. */
static void calib_bounds(const struct sys_env *e)
{
	static struct re_config cfg;
	char err[RE_CONFIG_ERR_MAX];
	double sweep = 0;

	if (re_config_load_file(e->cfg, &cfg, err, sizeof(err)) != GL_OK) {
		add("calibration", "sweep time (travel / vmax)", "time", "s",
		    "", "n/a (%s)", err);
		return;
	}
	for (int i = 0; i < RE_AXES; i++) {
		double t =
		    (double)cfg.axes[i].travel_counts / cfg.axes[i].vmax_cps;

		if (t > sweep)
			sweep = t;
	}
	add("calibration", "sweep time (travel / vmax, slowest axis)", "time",
	    "s", "", "%.1f", sweep);
	add("calibration", "least from the centre (1/2 + sweep + 1/2 at vmax)",
	    "time", "s", "", "%.1f", 2 * sweep);
	add("calibration", "full calibration / sweep time", "ratio", "", "",
	    "%.2f", e->calib_s / sweep);
}

/* ---- the flight recorder ------------------------------------- */

static int64_t rb_now(void *ud)
{
	(void)ud;
	return base_now_ns();
}

static enum re_relay_state rb_relay(void *ud)
{
	(void)ud;
	return RE_RELAY_ON;
}

static const struct re_io_ops rb_ops = {.now_ns = rb_now,
					.relay_state = rb_relay};
static struct re_super_view rb_sup;
static struct re_rec rb_rec;

/* A supervisor as after an armed cycle with tables, and a 30 s ring at
 * 10 ms attached to it. */
static int rec_setup(void)
{
	struct re_rec_cfg rc = {.seconds = 30,
				.after_fault_s = 2,
				.period_ms = 10,
				.dir = "/tmp",
				.n_axes = 3,
				.axis_names = {"A", "B", "C"}};
	struct re_super_view *s = &rb_sup;

	memset(s, 0, sizeof(*s));
	s->io.ops = &rb_ops;
	s->cfg.n_axes = 3;
	s->have_record = s->have_za = s->link_ok = 1;
	s->expect = RE_DMC_ARMED;
	for (int i = 0; i < 3; i++) {
		s->cfg.pot_input[i] = i + 1;
		s->have_encres[i] = 1;
		s->encres[i].exp.pot_v = 2.5;
		s->encres[i].tol_v = 0.06;
		s->encres[i].margin_v = 0.05;
		s->rec.axis[i].analog_in = 16384;
		s->rec.axis[i].velocity = 64 * 1000;
	}
	if (re_rec_init(&rb_rec, &rc) != 0)
		return -1;
	re_rec_begin(&rb_rec, s, "1");
	return 0;
}

/* @n cycles copied; ns per copy. */
static double rec_loop(long n)
{
	int64_t t0 = base_now_ns();

	for (long i = 0; i < n; i++) {
		rb_sup.cycles++;
		rb_sup.rec.sample++;
		rb_sup.rec.axis[0].ref_pos += 10;
		rb_sup.rec.axis[0].motor_pos += 10;
		re_rec_take(&rb_rec, &rb_sup);
	}
	return n ? (double)(base_now_ns() - t0) / (double)n : 0;
}

/* System calls made by "@self --rec-loop @n" (strace -f -c), or -1. */
static long rec_syscalls(const char *self, long n)
{
	char cmd[SYS_PATH_MAX * 2], line[256];
	long calls = -1;
	FILE *f;

	snprintf(cmd, sizeof(cmd),
		 "strace -f -c -o /dev/stdout '%s' --rec-loop %ld "
		 "2>/dev/null",
		 self, n);
	f = popen(cmd, "r");
	while (f && fgets(line, sizeof(line), f)) {
		double pct, secs;
		long usecs, c;

		if (strstr(line, " total") &&
		    sscanf(line, "%lf %lf %ld %ld", &pct, &secs, &usecs, &c) ==
			4)
			calls = c;
	}
	if (f && pclose(f) != 0)
		calls = -1;
	return calls;
}

static void recorder_cost(const char *self)
{
	char path[] = "/tmp/bench-trace-XXXXXX";
	long a, b, n = 200000;
	double ns, ms = -1;
	int64_t t0;
	int fd;

	if (rec_setup() < 0) {
		add("recorder", "copy of one cycle", "time", "ns/cycle", "",
		    "n/a");
		return;
	}
	rec_loop(3200); /* the ring full, as after 32 s */
	ns = rec_loop(1000000);
	add("recorder", "copy of one cycle into the ring (re_rec_take)", "time",
	    "ns/cycle", "none (no recorder)", "%.0f", ns);
	a = rec_syscalls(self, 0);
	b = rec_syscalls(self, n);
	if (a < 0 || b < 0)
		add("recorder", "system calls per cycle (strace -c)", "count",
		    "1/cycle", "", "n/a (no strace)");
	else
		add("recorder", "system calls per cycle (strace -c)", "count",
		    "1/cycle", "", "%.4f (%ld over %ld cycles)",
		    (double)(b - a) / (double)n, b - a, n);
	fd = mkstemp(path);
	if (fd >= 0) {
		struct re_trace_hdr h = rb_rec.hdr;

		close(fd);
		snprintf(h.created, sizeof(h.created), "2026-01-01T00:00:00Z");
		snprintf(h.reason, sizeof(h.reason), "request");
		t0 = base_now_ns();
		if (re_rec_dump_to(path, &h, rb_rec.ring, rb_rec.count,
				   rb_rec.text, rb_rec.text_cap) == 0)
			ms = (double)(base_now_ns() - t0) / 1e6;
		unlink(path);
	}
	add("recorder", "trace of a full ring (3200 cycles): text + write",
	    "time", "ms", "", ms < 0 ? "n/a" : "%.1f", ms);
	add("recorder", "ring of 30 s at 10 ms (+2 s after a fault)", "memory",
	    "MB", "", "%.1f",
	    (double)(rb_rec.cap * 2 * sizeof(struct re_trace_rec) +
		     rb_rec.text_cap) /
		1e6);
	re_rec_free(&rb_rec);
}

/* One loop run and its rows; a trip or a failure is said at once. */
static void loop_one(struct sys_env *e, const struct opts *o, int period,
		     const char *design, int long_s)
{
	struct loop_fig f;

	loop_init(&f, period, design, long_s);
	printf("bench: %d s of joystick use at a %d ms period, %s ...\n",
	       long_s ? long_s : o->seconds, period, design);
	fflush(stdout);
	loop_run(e, o, &f);
	if (f.fault[0])
		printf("bench: period %d ms, %s: %s\n", period, design,
		       f.fault);
	add_loop(&f);
}

int main(int argc, char **argv)
{
	static const int periods[] = {50, 10, 2};
	static const char *const designs[] = {"poll", "stream"};
	static struct sys_env env;
	struct opts o;

	if (argc == 3 && !strcmp(argv[1], "--rec-loop")) { /* for strace */
		if (rec_setup() < 0)
			return 1;
		rec_loop(atol(argv[2]));
		re_rec_free(&rb_rec);
		return 0;
	}
	if (parse_opts(argc, argv, &o) < 0)
		return 2;
	if (sys_env_init(&env) < 0 || sys_env_calibrate(&env, 150000) < 0) {
		fprintf(stderr, "bench: %s\n", env.err);
		env.keep = 1;
		sys_env_cleanup(&env);
		return 1;
	}
	if (getenv("ROBOELF_SYS_CAL") && *getenv("ROBOELF_SYS_CAL"))
		add("calibration", "full calibration, default robot", "time",
		    "s", "", "n/a (reused from ROBOELF_SYS_CAL)");
	else {
		add("calibration", "full calibration, default robot", "time",
		    "s", "", "%.1f", env.calib_s);
		calib_bounds(&env);
	}
	for (size_t i = 0; !o.only && i < sizeof(periods) / sizeof(periods[0]);
	     i++)
		for (size_t d = 0; d < 2; d++)
			loop_one(&env, &o, periods[i], designs[d], 0);
	for (size_t d = 0; d < 2; d++)
		instr(&env, &o, designs[d]);
	if (!o.only && o.long_s > 0)
		loop_one(&env, &o, 2, "stream", o.long_s);
	if (!o.only) {
		sim_speed(&env);
		recorder_cost(argv[0]);
		reactions(&env, &o);
	}
	print_table();
	printf("\nbench: written to %s (work files in %s)\n", o.csv, env.dir);
	env.keep = 1;
	return write_csv(o.csv) < 0 ? 1 : 0;
}
