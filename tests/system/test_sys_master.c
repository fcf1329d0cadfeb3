/*
 * test_sys_master.c - "One master, and faults that name their real cause",
 * on the whole system: galil-sim running dmc/ (downloaded by galil-load),
 * roboelf supervising it through the virtual relay.
 *
 * One full calibration for the binary (group setup; its first try is case
 * 0), then every case on a fresh galil-sim with `--calibration file`:
 *  1. a second roboelf on the same controller or relay (the same
 *     configuration; another file naming the same relay; another naming
 *     the same controller) is refused at once by the locks (exit 3, the
 *     holder's pid named), and the first runs on undisturbed: no relay
 *     event, no connection, no FAULT, its heartbeat advancing, still armed,
 *     watched over >= 1 s;
 *  2. a second supervisor "on another host" (its own lock directory and
 *     relay) is refused by the controller check, the first undisturbed;
 *  3. galil-load refuses an armed controller without --force (exit 5,
 *     nothing changed), and with --force halts it: roboelf latches
 *     PROGRAM (thread 0 halted) naming galil-load's connection;
 *  4. roboelf's start-up closes a client connected before it (IHT=>-3);
 *  5. a client that connects while armed and starts a move (PA or JG, BG):
 *     MOTION (a move another program started) naming its handle, and how
 *     far the axis went;
 *  6. after roboelf is killed, a naive client writing hbpc=1, 2, 3 ...
 *     does not keep the robot alive (FOREIGN heartbeat, motors off);
 *  7. root cause: a jam and a stuck encoder on each axis, jogging and
 *     during the calibration; a relay board that swallows its bytes; the
 *     supervisor stopped for 2 s (in its sleep, before its first armed
 *     cycle, awaiting a reply); controller and relay lost together; a full
 *     disk.
 *
 * Every case asserts the outcome, the exact text the operator sees (the
 * whole line; in a template "{n}" stands for a number, "{t}" for a local
 * time, "{s}" for a text), and the reaction time from galil-sim's events
 * (simulated ms) against the deadlines of docs/safety.md section 3 plus
 * SLACK_MS. Each case prints a "[ MEASURE  ]" line; the group teardown
 * prints a table: case | outcome | reaction | exact FAULT line or message.
 *
 * Every roboelf started here gets ROBOELF_LOCK_DIR inside the temporary
 * directory. The full-disk case mounts a tmpfs when run as root (else the
 * log is /dev/full). Environment: ROBOELF_SYS_FILTER=PATTERN runs only the
 * matching cases; ROBOELF_KEEP=1 keeps the temporary directory;
 * ROBOELF_SYS_CAL=FILE reuses a calibration (development).
 */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mount.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <arpa/inet.h>
#include <netinet/in.h>

#include <cmocka.h>

#include "sys_h.h"

#define SLACK_MS       25   /* scheduling allowance (docs/safety.md, 3) */
#define HOLD_MS	       300  /* no motion over this after the safe state */
#define FAULT_WAIT_MS  8000 /* a FAULT line, beyond any deadline */
#define EXIT_WAIT_MS   5000 /* roboelf exits after SIGTERM */
#define REFUSE_WAIT_MS 5000 /* a refused roboelf has exited */
#define LOCK_REFUSE_MS 1000 /* a lock refusal: no I/O, no wait */
#define WATCH_MS       1200 /* the first watched undisturbed (>= 1 s) */
#define WATCH_STEP_MS  100  /* ... one state line this often */
#define TEXT_MAX       2048

static struct sys_env env;
static int env_ok;
static struct sys_case cs;   /* the first roboelf and its controller */
static struct proc re2;	     /* a second roboelf, or a galil-load */
static struct proc_sim sim2; /* a second controller and relay */
static int raw_fd = -1;	     /* a raw client of the controller */
static char lock_dir[SYS_PATH_MAX], lock_dir2[SYS_PATH_MAX + 8];
static char lock_env[SYS_PATH_MAX + 32], lock_env2[SYS_PATH_MAX + 40];
static char *re_env[] = {lock_env, NULL};
static char log_mnt[SYS_PATH_MAX + 8]; /* a tmpfs mounted here, or "" */

/* ---- the summary table ---------------------------------------------------
 */

#define MAX_ROWS 40

struct row {
	char name[48];
	char outcome[160];
	char reaction[320];
	char text[TEXT_MAX];
};

static struct row rows[MAX_ROWS];
static int nrows;

/* A new row, "FAILED" until row_pass(): a failed case leaves it so. */
static struct row *row_begin(const char *name)
{
	static struct row spare;
	struct row *r = nrows < MAX_ROWS ? &rows[nrows++] : &spare;

	memset(r, 0, sizeof(*r));
	snprintf(r->name, sizeof(r->name), "%s", name);
	snprintf(r->outcome, sizeof(r->outcome), "FAILED (see above)");
	snprintf(r->reaction, sizeof(r->reaction), "-");
	return r;
}

static void row_set(char *dst, size_t cap, const char *fmt, va_list ap)
{
	vsnprintf(dst, cap, fmt, ap);
}

static void row_reaction(struct row *r, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void row_reaction(struct row *r, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	row_set(r->reaction, sizeof(r->reaction), fmt, ap);
	va_end(ap);
	print_message("[ MEASURE  ] %s: %s\n", r->name, r->reaction);
}

static void row_text(struct row *r, const char *text)
{
	snprintf(r->text, sizeof(r->text), "%s", text);
}

static void row_pass(struct row *r, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void row_pass(struct row *r, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	row_set(r->outcome, sizeof(r->outcome), fmt, ap);
	va_end(ap);
}

static void print_table(void)
{
	print_message("[ SUMMARY  ] case | outcome | reaction | exact FAULT "
		      "line or message\n");
	for (int i = 0; i < nrows; i++)
		print_message("[ SUMMARY  ] %s | %s | %s | %s\n", rows[i].name,
			      rows[i].outcome, rows[i].reaction,
			      rows[i].text[0] ? rows[i].text : "-");
}

/* ---- exact texts -----------------------------------------------------------
 */

/* Recovery texts and confirmations, as roboelf prints them
 * (pc/super/re_fault.c, pc/super/re_react.c; docs/operator.md section 7). */
#define SAFE_OK                                                                \
	" Safe state confirmed: motor power off (relay open), motors off."
#define REC_FOREIGN                                                            \
	" Recovery: keep the E-stop pressed, close every other program "       \
	"connected to the controller (another roboelf, galil-load, a "         \
	"terminal), then restart roboelf"

#define REC_UNCMD                                                              \
	" Recovery: keep the E-stop pressed, find which other program or "     \
	"person sent commands to the controller (another roboelf, "            \
	"galil-load, a terminal) and stop it, then restart roboelf"
#define REC_THREAD                                                             \
	" Recovery: keep the E-stop pressed, restart roboelf; if it happens "  \
	"again, reload the program with galil-load"
/* The sentence that names another program's connection (%c: its handle). */
#define OTHER_PROG                                                             \
	" Another program had connected to the controller (handle %c)."

/* One number: -?digits[.digits]. Return: its length, 0 when none. */
static size_t number_len(const char *s)
{
	size_t n = *s == '-' ? 1 : 0, d = n;

	while (s[n] >= '0' && s[n] <= '9')
		n++;
	if (n == d)
		return 0;
	if (s[n] == '.' && s[n + 1] >= '0' && s[n + 1] <= '9')
		for (n++; s[n] >= '0' && s[n] <= '9'; n++)
			;
	return n;
}

/* "YYYY-MM-DD HH:MM:SS": 1 when @s starts with one. */
static int is_time(const char *s)
{
	static const char shape[] = "dddd-dd-dd dd:dd:dd";

	for (size_t i = 0; shape[i]; i++)
		if (shape[i] == 'd' ? s[i] < '0' || s[i] > '9'
				    : s[i] != shape[i])
			return 0;
	return 1;
}

/*
 * tpl_match() - does @s match @tpl exactly? "{n}" in @tpl stands for one
 * number (its value goes to @num, up to @max), "{t}" for a local time,
 * "{s}" for a non-empty text (the shortest that lets the rest match).
 * @k: numbers matched so far (0 at the top).
 * @at: [in,out] the furthest offset of @s matched (for the message).
 * Return: the count of numbers, or -1.
 */
static int tpl_match(const char *tpl, const char *s, const char *s0,
		     double *num, int max, int k, size_t *at)
{
	while (*tpl) {
		size_t n;

		if ((size_t)(s - s0) > *at)
			*at = (size_t)(s - s0);
		if (!strncmp(tpl, "{s}", 3)) {
			for (n = 1; n <= strlen(s); n++) {
				int r = tpl_match(tpl + 3, s + n, s0, num, max,
						  k, at);

				if (r >= 0)
					return r;
			}
			return -1;
		}
		if (!strncmp(tpl, "{n}", 3) && (n = number_len(s)) > 0) {
			if (k < max)
				num[k] = strtod(s, NULL);
			k++;
			s += n;
			tpl += 3;
		} else if (!strncmp(tpl, "{t}", 3) && is_time(s)) {
			s += 19;
			tpl += 3;
		} else if (*tpl == *s) {
			tpl++;
			s++;
		} else {
			return -1;
		}
	}
	return *s ? -1 : k;
}

/* Assert that @line is exactly @tpl; the numbers go to @num. */
static int expect_text(const char *what, const char *tpl, const char *line,
		       double *num, int max)
{
	size_t at = 0;
	int k = tpl_match(tpl, line, line, num, max, 0, &at);

	if (k < 0)
		fail_msg("%s: not the exact text\n  got:      %s\n  expected: "
			 "%s\n  they part at offset %zu: '%.40s'",
			 what, line, tpl, at, line + at);
	return k;
}

/* ---- fixtures ----------------------------------------------------------- */

/* Remove the files of a one-level directory, then the directory. */
static void remove_dir(const char *path)
{
	char cmd[SYS_PATH_MAX * 2];

	if (!path[0] || access(path, F_OK) < 0)
		return;
	snprintf(cmd, sizeof(cmd), "rm -rf -- '%s'", path);
	if (system(cmd) != 0)
		print_message("[   WARN   ] cannot remove '%s'\n", path);
}

/* The first full calibration's failure, or "" (test_full_calibration),
 * and its FAULT line from its log, or "". */
static char cal_fail[SYS_ERR_MAX], cal_line[TEXT_MAX];

/* The FAULT line of the last case's log (up to the " | " of the log's
 * details), or "". */
static void cal_fault_line(char *out, size_t cap)
{
	char path[SYS_PATH_MAX + 32], buf[8192];
	FILE *f;

	out[0] = '\0';
	snprintf(path, sizeof(path), "%s/case-%d.log", env.dir, env.ncase);
	f = fopen(path, "r");
	while (f && fgets(buf, sizeof(buf), f)) {
		char *p = strstr(buf, " FAULT FAULT "), *end;

		if (!p)
			continue;
		p += 7;
		end = strstr(p, " | ");
		snprintf(out, cap, "%.*s",
			 end ? (int)(end - p) : (int)strlen(p), p);
		break;
	}
	if (f)
		fclose(f);
}

/*
 * One full calibration for every case. A calibration is a supervised phase
 * like any other: when the first one fails, test_full_calibration reports
 * that as a failure, and a second one gives the other cases their file.
 */
static void calibrate_env(void)
{
	if (sys_env_calibrate(&env, 150000) == 0) {
		env_ok = 1;
		return;
	}
	snprintf(cal_fail, sizeof(cal_fail), "%s", env.err);
	cal_fault_line(cal_line, sizeof(cal_line));
	print_message("[   WARN   ] the full calibration failed; once more "
		      "for the other cases:\n%s\n",
		      cal_fail);
	env_ok = sys_env_calibrate(&env, 150000) == 0;
}

static int group_setup(void **state)
{
	(void)state;
	if (sys_env_init(&env) == 0) {
		snprintf(lock_dir, sizeof(lock_dir), "%s/locks", env.dir);
		snprintf(lock_dir2, sizeof(lock_dir2), "%s/locks-other-host",
			 env.dir);
		snprintf(lock_env, sizeof(lock_env), "ROBOELF_LOCK_DIR=%s",
			 lock_dir);
		snprintf(lock_env2, sizeof(lock_env2), "ROBOELF_LOCK_DIR=%s",
			 lock_dir2);
		/* the calibration's roboelf inherits it */
		if (mkdir(lock_dir, 0700) == 0 && mkdir(lock_dir2, 0700) == 0 &&
		    setenv("ROBOELF_LOCK_DIR", lock_dir, 1) == 0)
			calibrate_env();
	}
	print_message("[   INFO   ] full calibration %s in %.1f s (P %d ms, "
		      "%s)\n",
		      env_ok ? "done" : "FAILED", env.calib_s, env.period_ms,
		      env.dir);
	return 0;
}

static int group_teardown(void **state)
{
	(void)state;
	print_table();
	if (!env_ok)
		env.keep = 1;
	if (!env.keep) {
		remove_dir(lock_dir);
		remove_dir(lock_dir2);
	}
	sys_env_cleanup(&env);
	return 0;
}

static void unmount_log(void)
{
	if (!log_mnt[0])
		return;
	if (umount2(log_mnt, MNT_DETACH) < 0)
		print_message("[   WARN   ] cannot unmount '%s': %s\n", log_mnt,
			      strerror(errno));
	rmdir(log_mnt);
	log_mnt[0] = '\0';
}

static int case_teardown(void **state)
{
	(void)state;
	if (raw_fd >= 0)
		close(raw_fd);
	raw_fd = -1;
	proc_kill(&re2);
	memset(&re2, 0, sizeof(re2));
	proc_kill(&sim2.p);
	memset(&sim2, 0, sizeof(sim2));
	sys_case_stop(&cs);
	unmount_log();
	return 0;
}

static void start_with(struct sys_case *c, struct sys_opts *o)
{
	if (!env_ok)
		fail_msg("no calibrated environment: %s", env.err);
	o->re_env = re_env;
	if (sys_case_start(c, &env, o) < 0)
		fail_msg("%s", c->err);
}

/* The first roboelf, armed; its heartbeat, state and fault watched. */
static void start(struct sys_case *c)
{
	struct sys_opts o = {0};

	start_with(c, &o);
	if (sys_ctl(c, "watch state") < 0 || sys_ctl(c, "watch fcode") < 0 ||
	    sys_ctl(c, "watch fdet") < 0 || sys_ctl(c, "watch hbpc") < 0)
		fail_msg("%s", c->err);
}

/* A second galil-sim: another controller, and a relay of its own. */
static void start_sim2(void)
{
	char link[SYS_PATH_MAX + 16];

	snprintf(link, sizeof(link), "%s/relay-other", env.dir);
	if (proc_sim_start(&sim2, env.bin, link, NULL, 10000) < 0)
		fail_msg("a second galil-sim did not start");
}

static const char *sim2_relay(void)
{
	static char link[SYS_PATH_MAX + 16];

	snprintf(link, sizeof(link), "%s/relay-other", env.dir);
	return link;
}

/* ---- deadlines (docs/safety.md, section 3) --------------------------------
 */

static double P(void)
{
	return env.period_ms;
}

/* A fault the controller latches reaches the relay within M + 2P. */
static double d_ctrl_to_relay(void)
{
	return SYS_MAINMS + 2.0 * P();
}

/* ---- events and the state line ---------------------------------------------
 */

/* Wait for an event at or after @after starting with @prefix and, when
 * @sub is not NULL, containing @sub. Return: its index; fails the case on
 * timeout. */
static int wait_event(struct sys_case *c, const char *prefix, const char *sub,
		      double after, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	size_t k = strlen(prefix);

	for (;;) {
		for (size_t i = 0; i < c->nev; i++)
			if (c->ev[i].t_ms >= after &&
			    !strncmp(c->ev[i].text, prefix, k) &&
			    (!sub || strstr(c->ev[i].text, sub)))
				return (int)i;
		if (proc_now_ms() > deadline)
			fail_msg("no event '%s...%s' after %.0f ms within %d "
				 "ms",
				 prefix, sub ? sub : "", after, timeout_ms);
		if (c->re_up)
			proc_pump(&c->re, 0);
		poll(NULL, 0, 15);
		if (sys_events(c) < 0)
			fail_msg("%s", c->err);
	}
}

/* The first held event at or after @after starting with @prefix, or -1. */
static int find_event(const struct sys_case *c, const char *prefix,
		      double after)
{
	return sys_event_find(c, prefix, after);
}

/* The first held event at or after @after starting with @prefix and
 * containing @sub, or -1. */
static int find_event_sub(const struct sys_case *c, const char *prefix,
			  const char *sub, double after)
{
	size_t k = strlen(prefix);

	for (size_t i = 0; i < c->nev; i++)
		if (c->ev[i].t_ms >= after &&
		    !strncmp(c->ev[i].text, prefix, k) &&
		    strstr(c->ev[i].text, sub))
			return (int)i;
	return -1;
}

/* Every motor off after @after: the time of the last one (fails). */
static double wait_motors_off(struct sys_case *c, double after, int ms)
{
	long long deadline = proc_now_ms() + ms;

	for (;;) {
		double t = sys_motors_off_time(c, after);

		if (t >= 0)
			return t;
		if (proc_now_ms() > deadline)
			fail_msg("not every motor was switched off after %.0f "
				 "ms (no 'axis <X> motor off' event for each "
				 "axis within %d ms)",
				 after, ms);
		poll(NULL, 0, 15);
		if (sys_events(c) < 0)
			fail_msg("%s", c->err);
	}
}

static double state_num(struct sys_case *c, const char *key)
{
	char st[TEXT_MAX];
	double v;

	if (sys_state(c, st, sizeof(st)) < 0)
		fail_msg("%s", c->err);
	v = sys_state_num(st, key);
	if (isnan(v))
		fail_msg("no '%s' in the state line: %s", key, st);
	return v;
}

/* The handle letter galil-sim gave the connection @fd ("handle C opened
 * from 127.0.0.1:<its port>"); @t: [out] the event's time. */
static char handle_of(struct sys_case *c, int fd, double after, double *t)
{
	struct sockaddr_in sa;
	socklen_t len = sizeof(sa);
	char from[48];
	int i;

	if (getsockname(fd, (struct sockaddr *)&sa, &len) < 0)
		fail_msg("getsockname: %s", strerror(errno));
	snprintf(from, sizeof(from), " opened from 127.0.0.1:%u",
		 (unsigned)ntohs(sa.sin_port));
	i = wait_event(c, "handle ", from, after, 3000);
	*t = c->ev[i].t_ms;
	return c->ev[i].text[7];
}

/* ---- the first roboelf undisturbed ----------------------------------------
 */

/*
 * For WATCH_MS of simulated time from @t0, a state line every
 * WATCH_STEP_MS: relay on, motor power, every motor on, the program armed
 * (state 1) without a fault, its supervisor's heartbeat hbpc advancing
 * between every two lines; then no relay event, no FAULT line, and (when
 * @no_connect) no connection to the controller since @t0.
 */
static void expect_undisturbed(struct sys_case *c, double t0, int no_connect)
{
	double hb_prev = NAN, t = t0;
	char st[TEXT_MAX], line[TEXT_MAX];
	int i;

	while (t < t0 + WATCH_MS) {
		double hb;

		if (sys_wait_sim(c, t + WATCH_STEP_MS, 5000) < 0 ||
		    sys_state(c, st, sizeof(st) - 1) < 0)
			fail_msg("%s", c->err);
		strcat(st, " ");
		t = sys_state_num(st, "time");
		hb = sys_state_num(st, "var.hbpc");
		if (!strstr(st, " relay=on ") || !strstr(st, " power=1 ") ||
		    !strstr(st, " A.mo=0 ") || !strstr(st, " B.mo=0 ") ||
		    !strstr(st, " C.mo=0 ") ||
		    !strstr(st, " var.state=1.0000 ") ||
		    !strstr(st, " var.fcode=0.0000 ")) {
			proc_pump(&c->re, 100);
			if (proc_find_line(&c->re, PROC_STDOUT, "FAULT ", line,
					   sizeof(line)) < 0)
				snprintf(line, sizeof(line), "(none yet)");
			fail_msg("the first roboelf was disturbed at %.0f ms "
				 "(%.0f ms after the second one started): %s\n"
				 "  its FAULT line: %s",
				 t, t - t0, st, line);
		}
		if (!(hb != hb_prev))
			fail_msg("the first roboelf's heartbeat hbpc did not "
				 "advance within %d ms (%.0f): %s",
				 WATCH_STEP_MS, hb, st);
		hb_prev = hb;
	}
	if (sys_events(c) < 0)
		fail_msg("%s", c->err);
	i = find_event(c, "relay", t0);
	if (i >= 0)
		fail_msg("the relay was touched: '%s' at %.0f ms",
			 c->ev[i].text, c->ev[i].t_ms);
	i = find_event(c, "handle ", t0);
	if (no_connect && i >= 0)
		fail_msg("the second one reached the controller: '%s' at %.0f "
			 "ms",
			 c->ev[i].text, c->ev[i].t_ms);
	proc_pump(&c->re, 0);
	if (proc_find_line(&c->re, PROC_STDOUT, "FAULT ", line, sizeof(line)) ==
	    0)
		fail_msg("the first roboelf printed a FAULT line: %s", line);
}

/* 0. The full calibration of the group setup, first try. */
static void test_full_calibration(void **state)
{
	struct row *r = row_begin("0 full calibration (setup)");

	(void)state;
	if (cal_fail[0]) {
		row_text(r, cal_line[0] ? cal_line : cal_fail);
		fail_msg("the full calibration failed on its first try: %s\n%s",
			 cal_line, cal_fail);
	}
	if (!env_ok)
		fail_msg("no calibration: %s", env.err);
	row_reaction(r, "%.1f s (wall)", env.calib_s);
	row_pass(r, "calibrated and armed, no fault");
}

/* ---- a second roboelf ------------------------------------------------------
 */

/*
 * spawn_second() - start roboelf with @cfg (and --galil / --relay only
 * when given), its own log, ROBOELF_LOCK_DIR from @lockenv.
 */
static void spawn_second(struct proc *p, const char *cfg, const char *galil,
			 const char *relay, char *lockenv)
{
	char bin[SYS_PATH_MAX + 16], log[SYS_PATH_MAX + 16];
	char *argv[16], *envv[] = {lockenv, NULL};
	int n = 0;

	snprintf(bin, sizeof(bin), "%s/roboelf", env.bin);
	snprintf(log, sizeof(log), "%s/second.log", env.dir);
	argv[n++] = bin;
	argv[n++] = (char *)"-c";
	argv[n++] = (char *)cfg;
	if (galil) {
		argv[n++] = (char *)"--galil";
		argv[n++] = (char *)galil;
	}
	if (relay) {
		argv[n++] = (char *)"--relay";
		argv[n++] = (char *)relay;
	}
	argv[n++] = (char *)"--calibration";
	argv[n++] = (char *)"file";
	argv[n++] = (char *)"--log";
	argv[n++] = log;
	argv[n] = NULL;
	if (proc_spawn(p, argv, envv) < 0)
		fail_msg("cannot start '%s': %s", bin, strerror(errno));
}

/* A configuration copy naming controller @addr and relay @port. */
static void write_config(const char *path, const char *addr, const char *port)
{
	char qa[SYS_PATH_MAX + 4], qp[SYS_PATH_MAX + 4];
	struct sys_subst sub[] = {
	    {"address", qa}, {"port_development", qp}, {NULL, NULL}};

	snprintf(qa, sizeof(qa), "\"%s\"", addr);
	snprintf(qp, sizeof(qp), "\"%s\"", port);
	if (sys_env_write_config(&env, sub, path) < 0)
		fail_msg("%s", env.err);
}

/*
 * expect_refused() - @p exits 3 within REFUSE_WAIT_MS, having printed
 * exactly @tpl as its "roboelf: error: " line.
 * @line: [out] that line. Return: the wall ms from @w0 to its exit.
 */
static double expect_refused(struct proc *p, long long w0, const char *tpl,
			     double *num, int max, char *line, size_t cap)
{
	int status;
	double ms;

	if (proc_wait_exit(p, REFUSE_WAIT_MS, &status) < 0)
		fail_msg("the second roboelf was not refused: still running "
			 "%d ms after its start\n--- stdout:\n%s",
			 REFUSE_WAIT_MS, proc_output(p, PROC_STDOUT));
	ms = (double)(proc_now_ms() - w0);
	if (proc_exit_code(p) != 3)
		fail_msg("the second roboelf exited with %d, not 3\n--- "
			 "stdout:\n%s\n--- stderr:\n%s",
			 proc_exit_code(p), proc_output(p, PROC_STDOUT),
			 proc_output(p, PROC_STDERR));
	if (proc_find_line(p, PROC_STDOUT, "roboelf: error: ", line, cap) < 0)
		fail_msg("no 'roboelf: error: ' line from the second "
			 "roboelf\n--- stdout:\n%s",
			 proc_output(p, PROC_STDOUT));
	expect_text("the refusal", tpl, line, num, max);
	return ms;
}

/* A refusal by a lock: at once, before the relay or the controller. */
static void refused_by_lock(struct row *r, const char *tpl, long long w0,
			    double t0)
{
	char line[TEXT_MAX];
	double pid = 0, ms;

	ms = expect_refused(&re2, w0, tpl, &pid, 1, line, sizeof(line));
	if ((long)pid != (long)cs.re.pid)
		fail_msg("the refusal names pid %.0f, the first roboelf is "
			 "%ld: %s",
			 pid, (long)cs.re.pid, line);
	if (proc_find_line(&re2, PROC_STDOUT,
			   "roboelf: opening the E-stop relay", NULL, 0) == 0 ||
	    proc_find_line(&re2, PROC_STDOUT, "roboelf: connecting", NULL, 0) ==
		0)
		fail_msg("the refused roboelf went on past the locks:\n%s",
			 proc_output(&re2, PROC_STDOUT));
	row_text(r, line);
	row_reaction(r,
		     "refused (exit 3) %.0f ms after its start (bound %d "
		     "ms, wall)",
		     ms, LOCK_REFUSE_MS);
	if (ms > LOCK_REFUSE_MS)
		fail_msg("the lock refusal took %.0f ms (bound %d ms)", ms,
			 LOCK_REFUSE_MS);
	expect_undisturbed(&cs, t0, 1);
}

/* 1a. The same configuration (the same controller and relay): the
 * controller lock, taken first, refuses it. */
static void test_second_same_config(void **state)
{
	struct row *r = row_begin("1a second roboelf, same config");
	char addr[32], tpl[256];
	long long w0;
	double t0;

	(void)state;
	start(&cs);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", cs.sim.port);
	snprintf(tpl, sizeof(tpl),
		 "roboelf: error: controller %s is already supervised by "
		 "roboelf (pid {n}, since {t})",
		 addr);
	t0 = sys_sim_time(&cs);
	w0 = proc_now_ms();
	spawn_second(&re2, cs.cfg, addr, cs.relay_link, lock_env);
	refused_by_lock(r, tpl, w0, t0);
	row_pass(r,
		 "refused by the controller lock, exit 3; first "
		 "undisturbed >= %d ms",
		 WATCH_MS);
}

/* 1b. Another configuration file naming the same relay (by its device
 * node, /dev/pts/N, where the first names galil-sim's link to it) and
 * another controller (a second galil-sim): the relay lock refuses it. Had
 * it opened the relay, it would have switched the first's motor power
 * off. */
static void test_second_same_relay(void **state)
{
	struct row *r = row_begin("1b second config, same relay");
	char cfg[SYS_PATH_MAX + 16], addr[32], tpl[512];
	long long w0;
	double t0;

	(void)state;
	start(&cs);
	start_sim2();
	snprintf(cfg, sizeof(cfg), "%s/same-relay.yaml", env.dir);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", sim2.port);
	write_config(cfg, addr, cs.sim.relay);
	snprintf(tpl, sizeof(tpl),
		 "roboelf: error: relay %s is already supervised by roboelf "
		 "(pid {n}, since {t})",
		 cs.sim.relay);
	t0 = sys_sim_time(&cs);
	w0 = proc_now_ms();
	spawn_second(&re2, cfg, NULL, NULL, lock_env);
	refused_by_lock(r, tpl, w0, t0);
	row_pass(r,
		 "refused by the relay lock, exit 3; first undisturbed "
		 ">= %d ms",
		 WATCH_MS);
}

/* 1c. Another configuration file naming the same controller address and
 * another relay (a second galil-sim's): the controller lock refuses it. */
static void test_second_same_controller(void **state)
{
	struct row *r = row_begin("1c second config, same controller");
	char cfg[SYS_PATH_MAX + 16], addr[32], tpl[256];
	long long w0;
	double t0;

	(void)state;
	start(&cs);
	start_sim2();
	snprintf(cfg, sizeof(cfg), "%s/same-controller.yaml", env.dir);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", cs.sim.port);
	write_config(cfg, addr, sim2_relay());
	snprintf(tpl, sizeof(tpl),
		 "roboelf: error: controller %s is already supervised by "
		 "roboelf (pid {n}, since {t})",
		 addr);
	t0 = sys_sim_time(&cs);
	w0 = proc_now_ms();
	spawn_second(&re2, cfg, NULL, NULL, lock_env);
	refused_by_lock(r, tpl, w0, t0);
	row_pass(r,
		 "refused by the controller lock, exit 3; first "
		 "undisturbed >= %d ms",
		 WATCH_MS);
}

/*
 * 2. A second supervisor on another host: its own lock directory (the
 * locks cannot see each other) and its own relay (a second galil-sim's),
 * the same controller. The controller check must refuse it (the program
 * armed, its heartbeat advancing), exit 3, and the first run on
 * undisturbed. The check needs wdto + 50 ms by design (docs/supervisor.md,
 * power-on step 2).
 */
static void test_second_other_host(void **state)
{
	struct row *r = row_begin("2 second supervisor, other host");
	char cfg[SYS_PATH_MAX + 16], addr[32], line[TEXT_MAX];
	static const char tpl[] =
	    "roboelf: error: the controller's program is armed and its "
	    "heartbeat is advancing: another supervisor is running the robot; "
	    "quit it first (nothing was changed on the controller)";
	long long w0;
	double t0, ms, bound;

	(void)state;
	start(&cs);
	start_sim2();
	snprintf(cfg, sizeof(cfg), "%s/other-host.yaml", env.dir);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", cs.sim.port);
	write_config(cfg, addr, sim2_relay());
	t0 = sys_sim_time(&cs);
	w0 = proc_now_ms();
	spawn_second(&re2, cfg, NULL, NULL, lock_env2);
	ms = expect_refused(&re2, w0, tpl, NULL, 0, line, sizeof(line));
	row_text(r, line);
	bound = env.wdto_ms + 50 + 2000;
	row_reaction(r,
		     "refused (exit 3) %.0f ms after its start (bound "
		     "wdto + 50 + 2000 = %.0f ms, wall)",
		     ms, bound);
	if (ms > bound)
		fail_msg("the refusal took %.0f ms (bound %.0f)", ms, bound);
	expect_undisturbed(&cs, t0, 0);
	row_pass(r,
		 "refused by the controller check, exit 3; first "
		 "undisturbed >= %d ms",
		 WATCH_MS);
}

/* ---- galil-load on an armed controller ----------------------------------- */

static void spawn_load(struct proc *p, int force)
{
	char bin[SYS_PATH_MAX + 16], addr[32], dmc[SYS_PATH_MAX + 8];
	char *argv[8];
	int n = 0;

	snprintf(bin, sizeof(bin), "%s/galil-load", env.bin);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", cs.sim.port);
	snprintf(dmc, sizeof(dmc), "%s/dmc", env.top);
	argv[n++] = bin;
	argv[n++] = (char *)"-a";
	argv[n++] = addr;
	if (force)
		argv[n++] = (char *)"--force";
	argv[n++] = dmc;
	argv[n] = NULL;
	if (proc_spawn(p, argv, NULL) < 0)
		fail_msg("cannot start '%s': %s", bin, strerror(errno));
}

/* galil-load's exit within @ms; its code. */
static int load_exit(struct proc *p, int ms)
{
	int status;

	if (proc_wait_exit(p, ms, &status) < 0)
		fail_msg("galil-load did not exit within %d ms", ms);
	return proc_exit_code(p);
}

/* 3a. Without --force: exit 5 with its message, nothing changed. */
static void test_load_without_force(void **state)
{
	struct row *r = row_begin("3a galil-load, no --force");
	static const char tpl[] =
	    "galil-load: the controller's program is armed and its "
	    "supervisor's heartbeat is advancing: roboelf is driving the "
	    "robot. Loading halts the program: every axis stops, every motor "
	    "is switched off and roboelf latches a fault. Quit roboelf first, "
	    "or give --force to do exactly that";
	char line[TEXT_MAX];
	long long w0;
	double t0;
	int code;

	(void)state;
	start(&cs);
	t0 = sys_sim_time(&cs);
	w0 = proc_now_ms();
	spawn_load(&re2, 0);
	code = load_exit(&re2, 30000);
	if (proc_find_line(&re2, PROC_STDERR, "galil-load: ", line,
			   sizeof(line)) < 0)
		snprintf(line, sizeof(line), "(no message on stderr)");
	row_text(r, line);
	row_reaction(r, "exit %d after %lld ms (wall)", code,
		     proc_now_ms() - w0);
	if (code != 5)
		fail_msg("galil-load exited with %d, not 5\n--- stdout:\n%s\n"
			 "--- stderr:\n%s",
			 code, proc_output(&re2, PROC_STDOUT),
			 proc_output(&re2, PROC_STDERR));
	expect_text("galil-load's refusal", tpl, line, NULL, 0);
	expect_undisturbed(&cs, t0, 0);
	row_pass(r, "exit 5; first undisturbed >= %d ms", WATCH_MS);
}

/*
 * 3b. With --force: galil-load halts the program (prun=0, HX, ST, MO) and
 * downloads. Its connection alone is not a fault (a second program may
 * look: docs/dmc-interface.md, #FORGN); the halt is. The supervisor sees
 * thread 0 gone in its next record and names galil-load's connection.
 * Deadlines from the halt (galil-sim's "thread 0 stopped: halted by HX"):
 * relay 2P (the next record, one P of allowance), motors 2P + M.
 */
static void test_load_force(void **state)
{
	struct row *r = row_begin("3b galil-load --force");
	char line[TEXT_MAX], tpl[1024], h;
	double t0, t_conn, t_hx, t_relay, t_mo;
	int i, code;

	(void)state;
	start(&cs);
	t0 = sys_sim_time(&cs);
	spawn_load(&re2, 1);
	i = wait_event(&cs, "handle ", " opened from ", t0, 5000);
	h = cs.ev[i].text[7];
	t_conn = cs.ev[i].t_ms;
	i = wait_event(&cs, "thread 0 stopped: halted by HX", NULL, t_conn,
		       5000);
	t_hx = cs.ev[i].t_ms;
	if (sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	row_text(r, line);
	i = wait_event(&cs, "relay off", NULL, t_conn, 3000);
	t_relay = cs.ev[i].t_ms;
	t_mo = wait_motors_off(&cs, t_conn, 3000);
	row_reaction(r,
		     "galil-load connected (handle %c), halted %.0f ms later; "
		     "from the halt: relay off %.0f ms (deadline %.0f), "
		     "motors off %.0f ms (deadline %.0f)",
		     h, t_hx - t_conn, t_relay - t_hx, 2.0 * P(), t_mo - t_hx,
		     2.0 * P() + SYS_MAINMS);
	snprintf(tpl, sizeof(tpl),
		 "FAULT PROGRAM: controller thread 0 is not running (thread "
		 "bits 0x{n})." OTHER_PROG SAFE_OK REC_THREAD,
		 h);
	expect_text("roboelf's FAULT line", tpl, line, NULL, 0);
	code = load_exit(&re2, 60000);
	if (code != 0)
		fail_msg("galil-load --force exited with %d, not 0\n--- "
			 "stderr:\n%s",
			 code, proc_output(&re2, PROC_STDERR));
	if (sys_check_safe(&cs, 0, HOLD_MS) < 0)
		fail_msg("%s", cs.err);
	if (t_relay - t_hx > 2.0 * P() + SLACK_MS ||
	    t_mo - t_hx > 2.0 * P() + SYS_MAINMS + SLACK_MS)
		fail_msg("too late: relay off %.0f ms, motors off %.0f ms "
			 "after the halt",
			 t_relay - t_hx, t_mo - t_hx);
	row_pass(r, "PROGRAM latched naming galil-load's handle, galil-load "
		    "exit 0, safe state held");
}

/* ---- a raw client ---------------------------------------------------------
 */

/* Wait until the peer closes @fd (EOF or reset). Return: 0, -1 on timeout
 * or when data arrives instead. */
static int wait_eof(int fd, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;

	for (;;) {
		struct pollfd pfd = {.fd = fd, .events = POLLIN};
		long long left = deadline - proc_now_ms();
		char ch;
		ssize_t n;

		if (left <= 0 || poll(&pfd, 1, (int)left) <= 0)
			return -1;
		n = recv(fd, &ch, 1, 0);
		if (n == 0 || (n < 0 && errno == ECONNRESET))
			return 0;
		if (n < 0)
			return -1;
	}
}

/*
 * raw_cmd() - send "@cmd\r" and collect the controller's answers: one
 * terminator (':' or '?') per command of the line ('; ' separated).
 * @ans: [out] the terminators in order, "EOF" when the connection closed,
 * "timeout" when an answer did not come within @timeout_ms.
 */
static void raw_cmd(int fd, const char *cmd, int timeout_ms, char *ans,
		    size_t cap)
{
	long long deadline = proc_now_ms() + timeout_ms;
	size_t want = 1, n = 0;
	char buf[256];
	int len = snprintf(buf, sizeof(buf), "%s\r", cmd);

	for (const char *p = cmd; *p; p++)
		want += *p == ';';
	ans[0] = '\0';
	if (send(fd, buf, (size_t)len, MSG_NOSIGNAL) != len) {
		snprintf(ans, cap, "EOF");
		return;
	}
	while (n < want && n + 1 < cap) {
		struct pollfd pfd = {.fd = fd, .events = POLLIN};
		long long left = deadline - proc_now_ms();
		char ch;
		ssize_t got;

		if (left <= 0 || poll(&pfd, 1, (int)left) <= 0) {
			snprintf(ans + n, cap - n, "timeout");
			return;
		}
		got = recv(fd, &ch, 1, 0);
		if (got <= 0) {
			snprintf(ans + n, cap - n, "EOF");
			return;
		}
		if (ch == ':' || ch == '?') {
			ans[n++] = ch;
			ans[n] = '\0';
		}
	}
}

/*
 * 4. A raw client connected to the controller before roboelf starts (the
 * controller idle after a first roboelf quit cleanly) is closed by
 * roboelf's start-up (IHT=>-3): the client sees EOF, galil-sim logs
 * "handle X closed by IHT from handle Y" with Y roboelf's command handle;
 * then roboelf arms. Reaction: from roboelf's connection to the close.
 * EOF_MS bounds roboelf's start to its IHT: the relay opened and read back
 * (R = 500 ms), the connection (connect_timeout_ms = 2000), identification
 * and an idle busy check (no wait), with margin.
 */
#define EOF_MS 5000

static void test_startup_closes_client(void **state)
{
	struct row *r = row_begin("4 start-up closes a client");
	char addr[32], want[64], text[SYS_EVT_TEXT], hx, hy;
	double t0, t_y, t_close;
	long long w0, eof_ms;
	int i, status;

	(void)state;
	start(&cs);
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0 ||
	    proc_exit_code(&cs.re) != 0)
		fail_msg("the first roboelf did not quit cleanly (exit %d)",
			 proc_exit_code(&cs.re));
	t0 = sys_sim_time(&cs);
	raw_fd = sys_cmd_open(&cs);
	if (raw_fd < 0)
		fail_msg("%s", cs.err);
	hx = handle_of(&cs, raw_fd, t0, &t_y);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", cs.sim.port);
	w0 = proc_now_ms();
	spawn_second(&re2, cs.cfg, addr, cs.relay_link, lock_env);
	if (wait_eof(raw_fd, EOF_MS) < 0)
		fail_msg("the raw client (handle %c) was not closed within "
			 "%d ms of roboelf's start\n--- roboelf:\n%s",
			 hx, EOF_MS, proc_output(&re2, PROC_STDOUT));
	eof_ms = proc_now_ms() - w0;
	snprintf(want, sizeof(want), "handle %c closed by IHT from handle ",
		 hx);
	i = wait_event(&cs, want, NULL, t0, 3000);
	t_close = cs.ev[i].t_ms;
	snprintf(text, sizeof(text), "%s", cs.ev[i].text);
	row_text(r, text);
	hy = text[strlen(text) - 1];
	snprintf(want, sizeof(want), "handle %c closed by IHT from handle %c",
		 hx, hy);
	expect_text("the close event", want, text, NULL, 0);
	snprintf(want, sizeof(want), "handle %c opened from ", hy);
	i = wait_event(&cs, want, NULL, t_y, 1000);
	row_reaction(r,
		     "closed %.0f ms after roboelf connected (handle %c); "
		     "the client saw EOF %lld ms after roboelf's start (bound "
		     "%d, wall)",
		     t_close - cs.ev[i].t_ms, hy, eof_ms, EOF_MS);
	if (hy == hx || hy < 'A' || hy > 'H')
		fail_msg("not closed by roboelf's handle: %s", text);
	if (proc_wait_line(&re2, PROC_STDOUT, "RoboELF Ready for Use", 20000,
			   NULL, 0) < 0)
		fail_msg("roboelf did not arm after closing the client\n%s",
			 proc_output(&re2, PROC_STDOUT));
	row_pass(r, "client got EOF; roboelf armed after it");
}

/*
 * 5. While armed and at rest, a raw client connects and sends a motion
 * command. The connection alone is not a fault; the move is: #GUARD sees
 * a profiler the program did not start within one main loop, so the
 * operator sees FAULT MOTION (a move started by another program) naming
 * the client's handle, within M + 2P (relay) and M + s (motors) of the
 * connection (the command follows it at once). The axis moved for at most
 * M + s from rest at AC = 10 vmax: 1/2 AC (M + s)^2 = 4.8 counts at the
 * defaults; with the servo's dither of a count or two, TRAVEL_BOUND.
 */
#define TRAVEL_BOUND 10 /* counts */

static void foreign_move(const char *name, const char *line1, const char *cmd1,
			 const char *cmd2)
{
	struct row *r = row_begin(name);
	char line[TEXT_MAX], tpl[1024], ans[64] = "", ans2[64] = "", h;
	double t0, t_conn, t_relay, t_mo, a0, a1;
	int i;

	start(&cs);
	a0 = state_num(&cs, "A.act");
	t0 = sys_sim_time(&cs);
	raw_fd = sys_cmd_open(&cs);
	if (raw_fd < 0)
		fail_msg("%s", cs.err);
	raw_cmd(raw_fd, line1, 1000, ans, sizeof(ans));
	if (ans[0] == '?') { /* the controller does not take the line */
		raw_cmd(raw_fd, cmd1, 1000, ans, sizeof(ans));
		raw_cmd(raw_fd, cmd2, 1000, ans2, sizeof(ans2));
	}
	h = handle_of(&cs, raw_fd, t0, &t_conn);
	if (sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	row_text(r, line);
	i = wait_event(&cs, "relay off", NULL, t_conn, 3000);
	t_relay = cs.ev[i].t_ms;
	t_mo = wait_motors_off(&cs, t_conn, 3000);
	if (sys_check_safe(&cs, 0, HOLD_MS) < 0)
		fail_msg("%s", cs.err);
	a1 = state_num(&cs, "A.act");
	i = find_event(&cs, "axis A begin", t0);
	row_reaction(r,
		     "from the connection (handle %c): relay off %.0f ms "
		     "(deadline %.0f), motors off %.0f ms (deadline %d); "
		     "answers '%s%s%s'; axis A travel %.0f counts (bound "
		     "%d)%s",
		     h, t_relay - t_conn, d_ctrl_to_relay(), t_mo - t_conn,
		     SYS_MAINMS + 1, ans, ans2[0] ? "' then '" : "", ans2,
		     a1 - a0, TRAVEL_BOUND,
		     i >= 0 ? "; the move began" : "; no move began");
	snprintf(tpl, sizeof(tpl),
		 "FAULT MOTION: axis A: the controller stopped motion its "
		 "program did not command: a move started by another "
		 "program." OTHER_PROG SAFE_OK REC_UNCMD,
		 h);
	expect_text("the FAULT line", tpl, line, NULL, 0);
	if (fabs(a1 - a0) > TRAVEL_BOUND)
		fail_msg("axis A travelled %.0f counts (bound %d)", a1 - a0,
			 TRAVEL_BOUND);
	if (t_relay - t_conn > d_ctrl_to_relay() + SLACK_MS ||
	    t_mo - t_conn > SYS_MAINMS + 1 + SLACK_MS)
		fail_msg("too late: relay off %.0f ms, motors off %.0f ms",
			 t_relay - t_conn, t_mo - t_conn);
	row_pass(r,
		 "MOTION (another program's move) latched; travel %.0f "
		 "counts",
		 a1 - a0);
}

static void test_foreign_pa(void **state)
{
	(void)state;
	foreign_move("5a client sends PA 30000;BG A", "PA 30000;BG A",
		     "PA 30000", "BG A");
}

static void test_foreign_jg(void **state)
{
	(void)state;
	foreign_move("5b client sends JG 8000;BG A", "JG 8000;BG A", "JG 8000",
		     "BG A");
}

/*
 * 6. roboelf SIGKILLed while armed; at once a naive program connects and
 * writes hbpc=1, 2, 3 ... every 20 ms for NAIVE_MS. It must not keep the
 * robot alive: the program latches FOREIGN (fault 14, detail 1: a
 * heartbeat out of the dead session's sequence) - or, had the writes come
 * too late, its watchdog (fault 2). Which one is asserted: 14 detail 1,
 * because the first write comes within a few ms of the kill, long before
 * wdto - mainms. The client's connection itself is not a new connection
 * to #FORGN when it reuses a handle letter the dead supervisor had when
 * the motors went on (hm0): the test reports which letter it got. Motors
 * off within W + M + s of the kill, and off while the writes go on.
 */
#define NAIVE_MS     1500
#define NAIVE_PERIOD 20

/* The naive writer: hbpc=n every NAIVE_PERIOD ms for NAIVE_MS. Return:
 * the writes the controller answered with ':'. */
static int naive_heartbeat(int fd, int *refused, int *closed)
{
	long long t0 = proc_now_ms();
	int ok = 0;

	*refused = *closed = 0;
	for (int n = 1; proc_now_ms() - t0 < NAIVE_MS; n++) {
		char cmd[32], ans[16];
		long long next = t0 + (long long)n * NAIVE_PERIOD;

		snprintf(cmd, sizeof(cmd), "hbpc=%d", n);
		raw_cmd(fd, cmd, 500, ans, sizeof(ans));
		if (!strcmp(ans, ":"))
			ok++;
		else if (!strcmp(ans, "?"))
			(*refused)++;
		else {
			*closed = 1;
			break;
		}
		if (next > proc_now_ms())
			poll(NULL, 0, (int)(next - proc_now_ms()));
	}
	return ok;
}

static void test_kill_naive_heartbeat(void **state)
{
	struct row *r = row_begin("6 killed, naive hbpc=n writer");
	double t_kill, t_conn, t_off, hm0, fcode, fdet, d;
	char h, st[TEXT_MAX], text[256];
	int ok, refused, closed, i;

	(void)state;
	start(&cs);
	if (sys_ctl(&cs, "watch hm0") < 0)
		fail_msg("%s", cs.err);
	hm0 = state_num(&cs, "var.hm0");
	t_kill = sys_sim_time(&cs);
	proc_signal(&cs.re, SIGKILL);
	proc_wait_exit(&cs.re, EXIT_WAIT_MS, NULL);
	raw_fd = sys_cmd_open(&cs);
	if (raw_fd < 0)
		fail_msg("%s", cs.err);
	ok = naive_heartbeat(raw_fd, &refused, &closed);
	h = handle_of(&cs, raw_fd, t_kill, &t_conn);
	t_off = wait_motors_off(&cs, t_kill, 3000);
	if (sys_check_safe(&cs, 1, HOLD_MS) < 0 ||
	    sys_state(&cs, st, sizeof(st)) < 0)
		fail_msg("%s", cs.err);
	fcode = sys_state_num(st, "var.fcode");
	fdet = sys_state_num(st, "var.fdet");
	i = find_event_sub(&cs, "axis ", " motor on", t_off);
	d = env.wdto_ms + SYS_MAINMS + 1;
	snprintf(text, sizeof(text),
		 "program fault %.0f detail %.0f; client handle %c (hm0 %.0f: "
		 "%s), %d writes taken, %d refused%s",
		 fcode, fdet, h, hm0,
		 ((long)hm0 >> (h - 'A')) & 1 ? "a letter the dead supervisor "
						"had"
					      : "a new letter",
		 ok, refused, closed ? ", then closed" : "");
	row_text(r, text);
	row_reaction(r,
		     "motors off %.0f ms after the kill (deadline W + M + "
		     "s = %.0f), client connected %.0f ms after it",
		     t_off - t_kill, d, t_conn - t_kill);
	if (fcode != 14 || fdet != 1)
		fail_msg("the program did not latch FOREIGN heartbeat (14, "
			 "detail 1): %s",
			 text);
	if (i >= 0)
		fail_msg("a motor went on again while the client wrote: '%s' "
			 "at %.0f ms",
			 cs.ev[i].text, cs.ev[i].t_ms);
	if (t_off - t_kill > d + SLACK_MS)
		fail_msg("motors off %.0f ms after the kill, deadline %.0f ms",
			 t_off - t_kill, d);
	row_pass(r, "FOREIGN heartbeat (14, 1) latched; motors off and "
		    "kept off");
}

/* ---- root cause: a jam and a stuck encoder on each axis --------------------
 */

/* Jam (or stuck encoder) detection, docs/safety.md "E": the position error
 * grows at vmin (every move here is at least that fast) to at most one
 * step; ER < step trips, or OA first: 2L + vmin/(10 vmax) + step/vmin. */
static double d_jam(void)
{
	return 2 * SYS_LOOPMS + 1000.0 * env.vmin_cps / (10.0 * env.vmax_cps) +
	       1000.0 * env.step_counts / env.vmin_cps;
}

/* A stuck encoder while jogging: the pot disagrees once the axis moved
 * the tolerance, "T_tol + (2 + k) P" of docs/safety.md. */
static double d_enc_jog(void)
{
	double tol = (1.0 + env.allowed_error) * env.step_counts * 1.1;
	double t_tol = SYS_LOOPMS +
		       1000.0 * env.vmin_cps / (10.0 * env.vmax_cps) +
		       1000.0 * tol / env.vmin_cps;

	return t_tol + (2.0 + env.persistence) * P();
}

/* Inject @req; the simulated time of its "inject: " / "input: " event. */
static double inject(struct sys_case *c, const char *evt, const char *req)
{
	char want[300];
	double before = sys_sim_time(c);
	int i;

	if (before < 0 || sys_ctl(c, "%s", req) < 0)
		fail_msg("%s", c->err);
	snprintf(want, sizeof(want), "%s%s", evt, req);
	i = wait_event(c, want, NULL, before, 2000);
	return c->ev[i].t_ms;
}

/* The supervisor's own request (pcflt=1, the program's fault 12) is not a
 * consequence of the cause: docs/supervisor.md, fault reaction step 5,
 * names as "Then:" only a fault the controller latched by itself. */
static void not_own_request(const char *line)
{
	if (strstr(line, "Then: the controller latched the supervisor's "
			 "fault request"))
		fail_msg("the FAULT line names the supervisor's own fault "
			 "request (pcflt=1, fault 12) as a consequence:\n  %s",
			 line);
}

/*
 * A FAULT after @t_inj: the line exactly @tpl, relay off within @d_relay
 * (< 0: not asserted; galil-sim cut the power itself) and every motor off
 * within @d_motors, the safe state held, roboelf exits 4 on SIGTERM.
 */
static void expect_cause(struct row *r, double t_inj, const char *tpl,
			 double d_relay, double d_motors, double *num, int max)
{
	char line[TEXT_MAX];
	double t_relay = -1, t_mo;
	int i, status;

	if (sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	row_text(r, line);
	i = wait_event(&cs, "relay off", NULL, t_inj, 3000);
	t_relay = cs.ev[i].t_ms - t_inj;
	t_mo = wait_motors_off(&cs, t_inj, 3000) - t_inj;
	row_reaction(r,
		     "relay off %.0f ms (deadline %.0f), motors off %.0f "
		     "ms (deadline %.0f)",
		     t_relay, d_relay, t_mo, d_motors);
	not_own_request(line);
	expect_text("the FAULT line", tpl, line, num, max);
	if (sys_check_safe(&cs, 0, HOLD_MS) < 0)
		fail_msg("%s", cs.err);
	if (d_relay >= 0 && t_relay > d_relay + SLACK_MS)
		fail_msg("relay off %.0f ms after the injection, deadline "
			 "%.0f ms",
			 t_relay, d_relay);
	if (t_mo > d_motors + SLACK_MS)
		fail_msg("motors off %.0f ms after the injection, deadline "
			 "%.0f ms",
			 t_mo, d_motors);
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0 ||
	    proc_exit_code(&cs.re) != 4)
		fail_msg("roboelf did not exit 4 after the fault (exit %d)",
			 proc_exit_code(&cs.re));
}

/* Jogging: @req (e.g. "block B 1") at rest, then the joystick drives the
 * axis forward; the deadline counts from the joystick command. */
static double cause_jogging(int axis, const char *req)
{
	char joy[32];

	start(&cs);
	inject(&cs, "inject: ", req);
	snprintf(joy, sizeof(joy), "joy %c fwd", 'A' + axis);
	return inject(&cs, "input: ", joy);
}

/* During the full calibration: once the axis moves (its first, fast move
 * toward the reverse switch), @req. */
static double cause_calibrating(int axis, const char *req)
{
	struct sys_opts o = {.calibration = "full", .no_ready = 1};
	char begin[32];

	start_with(&cs, &o);
	snprintf(begin, sizeof(begin), "axis %c begin", 'A' + axis);
	wait_event(&cs, begin, NULL, 0, 20000);
	if (sys_wait_moving(&cs, (char)('A' + axis), 2000, 10000) < 0)
		fail_msg("%s", cs.err);
	return inject(&cs, "inject: ", req);
}

/* The controller's position error (fault 4) on @axis: the limit ER. */
static void tpl_poserr(char *tpl, size_t cap, int axis)
{
	char er[64];

	sys_counts_text(&env, axis, env.er_counts, er, sizeof(er));
	snprintf(
	    tpl, cap,
	    "FAULT MOTION: axis %c: position error of at least %s, "
	    "above its limit (blocked, jammed, or its encoder stuck?)." SAFE_OK
	    " Recovery: keep the E-stop pressed, check that axis %c moves "
	    "freely and nothing blocks it, then its encoder cable, then "
	    "restart roboelf",
	    'A' + axis, er, 'A' + axis);
}

/* The ENCODER pot/encoder FAULT line of @axis as a template; the numbers
 * are pot, expected, position[, in units], difference, allowed, cycles.
 * Return: how many numbers the position takes (1, or 2 with a unit). */
static int tpl_encpot(char *tpl, size_t cap, int axis)
{
	char pos[48];
	int k = sys_counts_tpl(&env, axis, pos, sizeof(pos));

	snprintf(tpl, cap,
		 "FAULT ENCODER: axis %c: potentiometer reads {n} V "
		 "but {n} V is expected at encoder position %s; "
		 "they differ by {n} V, more than the {n} V allowed, "
		 "for {n} cycles." SAFE_OK " Recovery: keep the E-stop "
		 "pressed, check the encoder and potentiometer cables "
		 "of axis %c, restart roboelf and recalibrate",
		 'A' + axis, pos, 'A' + axis);
	return k;
}

/* The position of an ENCODER pot/encoder line (matched by tpl_encpot with
 * @k numbers for it) in units is the one in counts, to 2 decimals. */
static void check_encpot_units(const double *num, int k, int axis,
			       const char *line)
{
	if (k == 2 && fabs(num[3] - num[2] / env.per_unit[axis]) > 0.0051)
		fail_msg("the position in %s (%.2f) is not %.0f counts: %s",
			 env.unit[axis], num[3], num[2], line);
}

static void jam(int axis, int calibrating)
{
	char name[48], req[32], tpl[1024];
	double t;
	struct row *r;

	snprintf(name, sizeof(name), "7 jam axis %c, %s", 'A' + axis,
		 calibrating ? "calibrating" : "jogging");
	r = row_begin(name);
	snprintf(req, sizeof(req), "block %c 1", 'A' + axis);
	t = calibrating ? cause_calibrating(axis, req)
			: cause_jogging(axis, req);
	if (calibrating)
		tpl_poserr(tpl, sizeof(tpl), axis);
	else
		snprintf(
		    tpl, sizeof(tpl),
		    "FAULT ENCODER: axis %c: the controller detected an "
		    "encoder failure or a blocked axis (stop code 12)." SAFE_OK
		    " Recovery: keep the E-stop pressed, check "
		    "that axis %c moves freely, then its encoder cable "
		    "and its motor, restart roboelf and recalibrate",
		    'A' + axis, 'A' + axis);
	expect_cause(r, t, tpl, d_jam() + d_ctrl_to_relay(), d_jam(), NULL, 0);
	row_pass(r, "axis %c named (%s)", 'A' + axis,
		 calibrating ? "MOTION position error" : "ENCODER, OA");
}

static void enc_stuck(int axis, int calibrating)
{
	char name[48], req[32], tpl[1024], act[8], pos[8];
	double t, d, num[7], runaway;
	int k = 0;
	struct row *r;

	snprintf(name, sizeof(name), "7 encoder stuck %c, %s", 'A' + axis,
		 calibrating ? "calibrating" : "jogging");
	r = row_begin(name);
	snprintf(act, sizeof(act), "%c.act", 'A' + axis);
	snprintf(pos, sizeof(pos), "%c.pos", 'A' + axis);
	snprintf(req, sizeof(req), "enc %c stuck", 'A' + axis);
	t = calibrating ? cause_calibrating(axis, req)
			: cause_jogging(axis, req);
	d = calibrating ? d_jam() : d_enc_jog();
	if (calibrating)
		tpl_poserr(tpl, sizeof(tpl), axis);
	else
		k = tpl_encpot(tpl, sizeof(tpl), axis) - 1;
	expect_cause(r, t, tpl, d + d_ctrl_to_relay(), d, num, 7);
	if (!calibrating)
		check_encpot_units(num, k + 1, axis, r->text);
	if (!calibrating &&
	    (fabs(num[0] - num[1]) <= num[4 + k] || num[3 + k] <= num[4 + k] ||
	     (int)num[5 + k] != env.persistence + 1))
		fail_msg("the values do not show a disagreement beyond the "
			 "tolerance for persistence + 1 cycles: %s",
			 r->text);
	runaway = fabs(state_num(&cs, act) - state_num(&cs, pos));
	row_pass(r,
		 "axis %c named (%s); the motor ran %.0f counts past the "
		 "frozen count",
		 'A' + axis,
		 calibrating ? "MOTION position error" : "ENCODER pot/encoder",
		 runaway);
}

static void test_jam_jog_a(void **state)
{
	(void)state;
	jam(0, 0);
}
static void test_jam_jog_b(void **state)
{
	(void)state;
	jam(1, 0);
}
static void test_jam_jog_c(void **state)
{
	(void)state;
	jam(2, 0);
}
static void test_jam_cal_a(void **state)
{
	(void)state;
	jam(0, 1);
}
static void test_jam_cal_b(void **state)
{
	(void)state;
	jam(1, 1);
}
static void test_jam_cal_c(void **state)
{
	(void)state;
	jam(2, 1);
}
static void test_enc_jog_a(void **state)
{
	(void)state;
	enc_stuck(0, 0);
}
static void test_enc_jog_b(void **state)
{
	(void)state;
	enc_stuck(1, 0);
}
static void test_enc_jog_c(void **state)
{
	(void)state;
	enc_stuck(2, 0);
}
static void test_enc_cal_a(void **state)
{
	(void)state;
	enc_stuck(0, 1);
}
static void test_enc_cal_b(void **state)
{
	(void)state;
	enc_stuck(1, 1);
}
static void test_enc_cal_c(void **state)
{
	(void)state;
	enc_stuck(2, 1);
}

/* ---- root cause: the relay, the supervisor, the link, the disk -------------
 */

/* Wall ms (epoch) of the log's FAULT entry; waits up to @ms for it. */
static double log_fault_wall(struct sys_case *c, const char *text, int ms)
{
	long long deadline = proc_now_ms() + ms;
	double w;

	while (sys_log_time_ms(c, text, &w) < 0) {
		if (proc_now_ms() > deadline)
			fail_msg("%s", c->err);
		poll(NULL, 0, 20);
	}
	return w;
}

/*
 * 7. The relay board swallows every byte (galil-sim cuts motor power at
 * once; the controller sees every amplifier lose power). The cause named
 * first is the relay board: FAULT ESTOP naming the relay. galil-sim's
 * power cut is the "relay off" (0 ms), the controller's motors off within
 * M; the supervisor's own reaction is measured on the wall clock from the
 * injection to its FAULT log entry, deadline R + 3P (docs/safety.md D16).
 */
static void test_relay_writefail(void **state)
{
	struct row *r = row_begin("7 relay board write failing");
	char tpl[2048], line[TEXT_MAX], later[TEXT_MAX];
	double t, t_relay, t_mo, w0, w1, d_pc;
	int i;

	(void)state;
	start(&cs);
	w0 = sys_wall_ms();
	t = inject(&cs, "inject: ", "relayfault writefail");
	if (sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	row_text(r, line);
	i = wait_event(&cs, "relay off", NULL, t, 3000);
	t_relay = cs.ev[i].t_ms - t;
	t_mo = wait_motors_off(&cs, t, 3000) - t;
	w1 = log_fault_wall(&cs, " FAULT FAULT ESTOP", 3000);
	d_pc = env.readback_timeout_ms + 3 * P();
	row_reaction(r,
		     "power cut by the board %.0f ms, motors off %.0f ms "
		     "(deadline M + s = %d); the supervisor's FAULT entry "
		     "%.0f ms (deadline R + 3P = %.0f, wall)",
		     t_relay, t_mo, SYS_MAINMS + 1, w1 - w0, d_pc);
	/* what the log says of the relay afterwards, for the report */
	if (sys_wait_sim(&cs, t + d_pc + SLACK_MS, 5000) == 0 &&
	    sys_log_find(&cs, "while latched: FAULT ESTOP", NULL, later,
			 sizeof(later)) == 0)
		print_message("[   INFO   ] %s: then the log: %s\n", r->name,
			      later);
	snprintf(tpl, sizeof(tpl),
		 "FAULT ESTOP: motor power lost on every axis and the E-stop "
		 "relay board does not confirm its state ({s})."
		 " NOT CONFIRMED: relay open not confirmed; motors off "
		 "confirmed; PRESS THE HARDWARE E-STOP NOW. Recovery: press "
		 "the hardware E-stop now, check the relay board, its USB "
		 "cable and its power, then restart roboelf");
	expect_text("the FAULT line", tpl, line, NULL, 0);
	if (sys_check_safe(&cs, 0, HOLD_MS) < 0)
		fail_msg("%s", cs.err);
	if (t_mo > SYS_MAINMS + 1 + SLACK_MS || w1 - w0 > d_pc + SLACK_MS)
		fail_msg("too late: motors off %.0f ms, FAULT entry %.0f ms",
			 t_mo, w1 - w0);
	row_pass(r, "the relay board named first");
}

/*
 * 7. roboelf stopped (SIGSTOP) for 2 s while armed, then continued: the
 * controller's watchdog switches every motor off within W + M + s of the
 * stop; the supervisor's first cycle after SIGCONT names its own stall
 * first (then the controller's watchdog) and cuts the relay within 2P.
 * Where in its cycle the supervisor is stopped must not matter: in its
 * sleep between two cycles, before its first armed cycle, or while it
 * waits for a reply.
 */
#define STALL_MS 2000

/* Wait, without sleeping, until the simulated time reaches @t (a few
 * hundred microseconds per request), at most @timeout_ms. */
static void wait_sim_tight(struct sys_case *c, double t, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	double now;

	while ((now = sys_sim_time(c)) < t) {
		if (now < 0)
			fail_msg("%s", c->err);
		if (proc_now_ms() > deadline)
			fail_msg("simulated time %.0f not reached", t);
	}
}

/* Phase-lock to roboelf's cycle: the simulated time at which its
 * heartbeat hbpc next changes, to the resolution of one state request. */
static double next_heartbeat(struct sys_case *c)
{
	long long deadline = proc_now_ms() + 2000;
	double hb0 = state_num(c, "var.hbpc");
	char st[TEXT_MAX];

	for (;;) {
		if (sys_state(c, st, sizeof(st)) < 0)
			fail_msg("%s", c->err);
		if (sys_state_num(st, "var.hbpc") != hb0)
			return sys_state_num(st, "time");
		if (proc_now_ms() > deadline)
			fail_msg("the heartbeat did not change within 2 s");
	}
}

/*
 * @phase_ms: < 0 at once after Ready; else this long after a heartbeat
 * write (the cycle's request). @delay_ms: replies held back this long
 * ("link delay"), 0 none.
 */
static void sigstop(const char *name, int phase_ms, int delay_ms)
{
	struct row *r = row_begin(name);
	char line[TEXT_MAX], tpl[1024];
	double t_stop, t_cont, t_relay, t_mo, num[3];
	int i, status;

	start(&cs);
	if (delay_ms > 0 &&
	    (sys_ctl(&cs, "link delay %d", delay_ms) < 0 ||
	     sys_wait_sim(&cs, sys_sim_time(&cs) + 10 * P(), 5000) < 0))
		fail_msg("%s", cs.err);
	if (phase_ms >= 0)
		wait_sim_tight(&cs, next_heartbeat(&cs) + phase_ms, 2000);
	t_stop = sys_sim_time(&cs);
	proc_signal(&cs.re, SIGSTOP);
	if (sys_wait_sim(&cs, t_stop + STALL_MS, STALL_MS + 5000) < 0)
		fail_msg("%s", cs.err);
	t_cont = sys_sim_time(&cs);
	proc_signal(&cs.re, SIGCONT);
	if (sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	row_text(r, line);
	t_mo = wait_motors_off(&cs, t_stop, 3000) - t_stop;
	i = wait_event(&cs, "relay off", NULL, t_stop, 3000);
	t_relay = cs.ev[i].t_ms - t_cont;
	row_reaction(r,
		     "motors off %.0f ms after SIGSTOP (deadline W + M + "
		     "s = %d), relay off %.0f ms after SIGCONT (deadline "
		     "2P = %.0f)",
		     t_mo, env.wdto_ms + SYS_MAINMS + 1, t_relay, 2 * P());
	snprintf(
	    tpl, sizeof(tpl),
	    "FAULT WATCHDOG: this supervisor did not run for {n} ms "
	    "(limit %.0f ms): the PC stalled (suspended, overloaded or "
	    "stopped in a debugger), not the link. Then: the controller "
	    "stopped the robot: no heartbeat from this PC for {n} ms." SAFE_OK
	    " Recovery: keep the E-stop pressed, find what "
	    "stopped roboelf (Ctrl-Z, a debugger, CPU or disk load), then "
	    "restart it",
	    env.crit_factor * P());
	expect_text("the FAULT line", tpl, line, num, 3);
	if (num[0] < t_cont - t_stop - 2 * P())
		fail_msg("the stall named is %.0f ms, it was stopped %.0f ms",
			 num[0], t_cont - t_stop);
	if (sys_check_safe(&cs, 0, HOLD_MS) < 0)
		fail_msg("%s", cs.err);
	if (t_mo > env.wdto_ms + SYS_MAINMS + 1 + SLACK_MS ||
	    t_relay > 2 * P() + SLACK_MS)
		fail_msg("too late: motors off %.0f ms after SIGSTOP, relay "
			 "off %.0f ms after SIGCONT",
			 t_mo, t_relay);
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0 ||
	    proc_exit_code(&cs.re) != 4)
		fail_msg("roboelf did not exit 4 (exit %d)",
			 proc_exit_code(&cs.re));
	row_pass(r, "the stall named first, the controller's watchdog as "
		    "Then:");
}

/* In its sleep: half a period after a cycle's request. */
static void test_sigstop(void **state)
{
	(void)state;
	sigstop("7 supervisor stopped 2 s", env.period_ms / 2, 0);
}

/* At once after "Ready", before the first armed cycle. */
static void test_sigstop_first_cycle(void **state)
{
	(void)state;
	sigstop("7 stopped 2 s before 1st cycle", -1, 0);
}

/* While it waits for a reply: replies held back 30 ms (a slow network,
 * below every limit: the reply age stays one period), stopped 10 ms after
 * a cycle's request. */
static void test_sigstop_in_round_trip(void **state)
{
	(void)state;
	sigstop("7 stopped 2 s awaiting a reply", 10, 30);
}

/* Read one control-port answer line from @fd within @ms. */
static int ctl_line(int fd, char *line, size_t cap, int ms)
{
	long long deadline = proc_now_ms() + ms;
	size_t n = 0;

	for (;;) {
		struct pollfd pfd = {.fd = fd, .events = POLLIN};
		long long left = deadline - proc_now_ms();
		char ch;

		if (left <= 0 || poll(&pfd, 1, (int)left) <= 0 ||
		    recv(fd, &ch, 1, 0) != 1)
			return -1;
		if (ch == '\n')
			break;
		if (ch != '\r' && n + 1 < cap)
			line[n++] = ch;
	}
	line[n] = '\0';
	return 0;
}

/*
 * 7. Controller and relay lost together: "link drop" and "relayfault
 * unplug" in one write to the control port (one request burst). Nothing
 * can be confirmed: the line must say NOT CONFIRMED and PRESS THE
 * HARDWARE E-STOP NOW. galil-sim cuts the power at the unplug; the
 * supervisor's reaction is measured on the wall clock to its FAULT entry,
 * deadline 2P + FRESH_STOP_MS: a lost link or relay is seen in the next
 * cycle, the relay is told to open at once, and the stop then tries new
 * connections to the controller for up to 2 x controller.timeout_ms
 * before the FAULT entry is written (docs/safety.md D28).
 */
#define FRESH_STOP_MS 200 /* 2 x controller.timeout_ms (default 100 ms) */
static void test_link_and_relay_lost(void **state)
{
	static const char burst[] = "link drop\nrelayfault unplug\n";
	struct row *r = row_begin("7 controller and relay lost");
	char a1[64], a2[64], line[TEXT_MAX], tpl[2048];
	double t0, t_link, t_relay, t_off, t_mo, w0, w1;
	int i;

	(void)state;
	start(&cs);
	t0 = sys_sim_time(&cs);
	w0 = sys_wall_ms();
	if (send(cs.ctl, burst, sizeof(burst) - 1, MSG_NOSIGNAL) !=
		(ssize_t)(sizeof(burst) - 1) ||
	    ctl_line(cs.ctl, a1, sizeof(a1), 2000) < 0 ||
	    ctl_line(cs.ctl, a2, sizeof(a2), 2000) < 0 || strcmp(a1, "ok") ||
	    strcmp(a2, "ok"))
		fail_msg("the burst was not taken");
	i = wait_event(&cs, "inject: link drop", NULL, t0, 2000);
	t_link = cs.ev[i].t_ms;
	i = wait_event(&cs, "inject: relayfault unplug", NULL, t0, 2000);
	t_relay = cs.ev[i].t_ms;
	if (sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	row_text(r, line);
	w1 = log_fault_wall(&cs, " FAULT FAULT ", 3000);
	i = wait_event(&cs, "relay off", NULL, t0, 3000);
	t_off = cs.ev[i].t_ms - t_relay;
	t_mo = wait_motors_off(&cs, t_relay, 3000) - t_relay;
	row_reaction(r,
		     "both injected at +%.0f / +%.0f ms; power cut %.0f ms "
		     "and motors off %.0f ms (deadline M + s = %d) after "
		     "the unplug; the FAULT entry %.0f ms after the burst "
		     "(deadline 2P + fresh stop = %.0f, wall)",
		     t_link - t0, t_relay - t0, t_off, t_mo, SYS_MAINMS + 1,
		     w1 - w0, 2 * P() + FRESH_STOP_MS);
	if (sys_check_safe(&cs, 0, HOLD_MS) < 0)
		fail_msg("%s", cs.err);
	if (t_mo > SYS_MAINMS + 1 + SLACK_MS)
		fail_msg("motors off %.0f ms after the unplug", t_mo);
	if (!strstr(line, "NOT CONFIRMED") ||
	    !strstr(line, "PRESS THE HARDWARE E-STOP NOW"))
		fail_msg("the line does not say NOT CONFIRMED ... PRESS THE "
			 "HARDWARE E-STOP NOW:\n  %s",
			 line);
	snprintf(tpl, sizeof(tpl),
		 "FAULT ESTOP: the E-stop relay stopped answering (relay '%s': "
		 "link lost (hang-up)). NOT CONFIRMED: relay open not "
		 "confirmed; stop command not delivered; the controller did "
		 "not answer. PRESS THE HARDWARE E-STOP NOW. Recovery: press "
		 "the hardware E-stop now, check the relay's USB cable and "
		 "power, then restart roboelf",
		 cs.relay_link);
	expect_text("the FAULT line", tpl, line, NULL, 0);
	if (w1 - w0 > 2 * P() + FRESH_STOP_MS + SLACK_MS)
		fail_msg("the FAULT entry came %.0f ms after the burst",
			 w1 - w0);
	row_pass(r, "NOT CONFIRMED, press the hardware E-stop");
}

/* ---- root cause: a full disk --------------------------------------------- */

/* A tiny tmpfs for the log (root only). Return: 0 mounted, -1 not. */
static int mount_logfs(void)
{
	snprintf(log_mnt, sizeof(log_mnt), "%s/logfs", env.dir);
	if (geteuid() != 0 || mkdir(log_mnt, 0700) < 0)
		goto not_mounted;
	if (mount("tmpfs", log_mnt, "tmpfs", MS_NOSUID | MS_NODEV,
		  "size=256k,mode=0700") == 0)
		return 0;
	rmdir(log_mnt);
not_mounted:
	log_mnt[0] = '\0';
	return -1;
}

/* Append @n bytes to @path: a line of '#' ending in a newline. */
static void pad_log(const char *path, size_t n)
{
	char buf[8192];
	int fd = open(path, O_WRONLY | O_APPEND | O_CLOEXEC);

	if (fd < 0 || n == 0 || n > sizeof(buf))
		fail_msg("cannot pad '%s' by %zu bytes", path, n);
	memset(buf, '#', n);
	buf[n - 1] = '\n';
	if (write(fd, buf, n) != (ssize_t)n)
		fail_msg("cannot pad '%s': %s", path, strerror(errno));
	close(fd);
}

/* Write @fd full until the filesystem refuses (ENOSPC). */
static void fill_fd(int fd)
{
	static char chunk[65536];
	size_t sz = sizeof(chunk);

	while (sz >= 1) {
		ssize_t n = write(fd, chunk, sz);

		if (n < 0 && errno != ENOSPC)
			fail_msg("filling the disk: %s", strerror(errno));
		if (n <= 0)
			sz /= 2;
	}
}

/*
 * Fill the log's filesystem so that every write to the log fails: the
 * log's last block padded to its end (a write into it would still
 * succeed), then every free block taken by @filler. Checked: no block
 * free, the log ending on a block boundary (roboelf may write a line
 * meanwhile: then padded again).
 */
static void fill_disk(const char *log, const char *filler)
{
	struct statvfs vfs;
	struct stat st;
	int fd = open(filler, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);

	if (fd < 0 || statvfs(log, &vfs) < 0)
		fail_msg("cannot fill '%s': %s", filler, strerror(errno));
	for (int k = 0; k < 3; k++) {
		if (stat(log, &st) < 0)
			fail_msg("stat '%s': %s", log, strerror(errno));
		if (st.st_size % (off_t)vfs.f_bsize != 0)
			pad_log(log,
				vfs.f_bsize -
				    (size_t)(st.st_size % (off_t)vfs.f_bsize));
		fill_fd(fd);
		if (stat(log, &st) == 0 && st.st_size % (off_t)vfs.f_bsize == 0)
			break;
	}
	close(fd);
	if (statvfs(log, &vfs) < 0 || vfs.f_bavail != 0 ||
	    st.st_size % (off_t)vfs.f_bsize != 0)
		fail_msg("the disk is not full: %lu blocks free, log %lld "
			 "bytes",
			 (unsigned long)vfs.f_bavail, (long long)st.st_size);
}

/* Does the file @path hold a line containing @a? */
static int file_has(const char *path, const char *a)
{
	char line[4096];
	FILE *f = fopen(path, "r");
	int found = 0;

	while (f && !found && fgets(line, sizeof(line), f))
		found = strstr(line, a) != NULL;
	if (f)
		fclose(f);
	return found;
}

/*
 * 7. A full disk. As root: the log on a 256 KiB tmpfs, filled after Ready
 * (fill_disk()); otherwise the log is a symbolic link to /dev/full (every
 * write fails from the start). Then a fault the PC finds at rest (pot A
 * offset 0.5 V, deadline (2 + k) P, D1 of docs/safety.md). The FAULT line
 * is shown all the same and in time; the screen says the log cannot be
 * written, once a second; on the tmpfs, once space is freed, it says the
 * log is written again and the FAULT entry is in the log.
 */
#define RETRY_MS 1000 /* roboelf retries the log once a second */

static void test_log_full(void **state)
{
	struct row *r = row_begin("7 full disk");
	char log[SYS_PATH_MAX + 32], filler[SYS_PATH_MAX + 32];
	char logopt[SYS_PATH_MAX + 40], warn[SYS_PATH_MAX + 160];
	char line[TEXT_MAX], msg[TEXT_MAX], tpl[1024], how[64];
	char *args[] = {(char *)"--log", logopt, NULL};
	struct sys_opts o = {.re_args = args};
	double t, t_relay, t_mo, num[7], d = (2.0 + env.persistence) * P();
	long long w1, w2;
	int k;
	int i, tmpfs = mount_logfs() == 0;

	(void)state;
	if (tmpfs) {
		snprintf(log, sizeof(log), "%s/roboelf.log", log_mnt);
		snprintf(filler, sizeof(filler), "%s/filler", log_mnt);
		snprintf(how, sizeof(how), "tmpfs filled after Ready");
	} else {
		snprintf(log, sizeof(log), "%s/full.log", env.dir);
		unlink(log);
		if (symlink("/dev/full", log) < 0)
			fail_msg("symlink '%s': %s", log, strerror(errno));
		snprintf(how, sizeof(how), "log -> /dev/full (not root)");
	}
	snprintf(logopt, sizeof(logopt), "%s", log);
	start_with(&cs, &o);
	if (tmpfs)
		fill_disk(log, filler);
	t = inject(&cs, "inject: ", "pot A offset 0.5");
	if (sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	row_text(r, line);
	i = wait_event(&cs, "relay off", NULL, t, 3000);
	t_relay = cs.ev[i].t_ms - t;
	t_mo = wait_motors_off(&cs, t, 3000) - t;
	snprintf(warn, sizeof(warn),
		 "roboelf: WARNING: cannot write the log '%s' (No space left "
		 "on device): the last entry is not on disk; retrying",
		 log);
	if (proc_wait_line(&cs.re, PROC_STDOUT, "roboelf: WARNING: ",
			   2 * RETRY_MS, msg, sizeof(msg)) < 0)
		fail_msg("no 'cannot write the log' message after the "
			 "fault\n--- stdout:\n%s",
			 proc_output(&cs.re, PROC_STDOUT));
	w1 = proc_now_ms();
	expect_text("the log message", warn, msg, NULL, 0);
	if (proc_wait_line(&cs.re, PROC_STDOUT, "roboelf: WARNING: ",
			   2 * RETRY_MS, msg, sizeof(msg)) < 0)
		fail_msg("the log was not retried within %d ms", 2 * RETRY_MS);
	w2 = proc_now_ms();
	expect_text("the repeated log message", warn, msg, NULL, 0);
	row_reaction(r,
		     "%s: relay off %.0f ms (deadline %.0f), motors off "
		     "%.0f ms (deadline %.0f); log retried after %lld ms",
		     how, t_relay, d, t_mo, d + SYS_MAINMS, w2 - w1);
	k = tpl_encpot(tpl, sizeof(tpl), 0);
	not_own_request(line);
	expect_text("the FAULT line", tpl, line, num, 7);
	check_encpot_units(num, k, 0, line);
	if (t_relay > d + SLACK_MS || t_mo > d + SYS_MAINMS + SLACK_MS)
		fail_msg("too late: relay off %.0f ms, motors off %.0f ms",
			 t_relay, t_mo);
	if (w2 - w1 < RETRY_MS / 2 || w2 - w1 > RETRY_MS * 3 / 2 + SLACK_MS)
		fail_msg("retried after %lld ms, not once a second", w2 - w1);
	if (tmpfs) {
		snprintf(warn, sizeof(warn),
			 "roboelf: the log '%s' is written again", log);
		unlink(filler);
		if (proc_wait_line(&cs.re, PROC_STDOUT, "roboelf: the log ",
				   2 * RETRY_MS, msg, sizeof(msg)) < 0)
			fail_msg("the log was not written again within %d ms "
				 "of freeing the disk",
				 2 * RETRY_MS);
		expect_text("the log message", warn, msg, NULL, 0);
		if (!file_has(log, line))
			fail_msg("the FAULT entry is not in the log after the "
				 "disk was freed");
	}
	row_pass(r, "%s: FAULT shown, log retried%s", how,
		 tmpfs ? ", written once freed" : "");
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_full_calibration),
	    T(test_second_same_config),
	    T(test_second_same_relay),
	    T(test_second_same_controller),
	    T(test_second_other_host),
	    T(test_load_without_force),
	    T(test_load_force),
	    T(test_startup_closes_client),
	    T(test_foreign_pa),
	    T(test_foreign_jg),
	    T(test_kill_naive_heartbeat),
	    T(test_jam_jog_a),
	    T(test_jam_jog_b),
	    T(test_jam_jog_c),
	    T(test_jam_cal_a),
	    T(test_jam_cal_b),
	    T(test_jam_cal_c),
	    T(test_enc_jog_a),
	    T(test_enc_jog_b),
	    T(test_enc_jog_c),
	    T(test_enc_cal_a),
	    T(test_enc_cal_b),
	    T(test_enc_cal_c),
	    T(test_relay_writefail),
	    T(test_sigstop),
	    T(test_sigstop_first_cycle),
	    T(test_sigstop_in_round_trip),
	    T(test_link_and_relay_lost),
	    T(test_log_full),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
