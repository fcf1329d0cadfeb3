/*
 * test_net_rig.c - the network cases (docs/link.md) on a virtual cable:
 * galil-sim in its own network namespace behind a veth pair
 * (tests/net/netns_rig.sh), roboelf, galil-load and the relay on the host.
 * The rig's second veth pair carries only galil-sim's control port, so the
 * test reads the controller's events while the cable is out.
 *
 * The PC's side of the link is set up as installed (docs/link.md): rto_min
 * RTO_MIN_MS on its route. The controller's side is, per case, either tuned
 * the same way (a controller whose TCP resends as fast as the PC's) or left
 * at the kernel's defaults (rto_min 200 ms: a real controller's timer is
 * nobody's to set); the loss and delay cases are a table (struct link_case),
 * each row in one of the two designs of controller.record: the round trip
 * per cycle (poll) or the record streamed over UDP with the heartbeat posted
 * on TCP (stream), its loss or delay on one protocol or on both.
 * Each case asserts the outcome that docs/safety.md ("Network cases")
 * states: no trip, warnings only, or a WATCHDOG fault with the relay off and
 * every motor off within the deadline, measured on galil-sim's event log
 * from the injection (the simulated time read just before the rig command).
 *
 * Without root (no CAP_NET_ADMIN) or without iptables/NFQUEUE the program
 * prints "SKIP: <reason>" and exits 77: tests/run-all.sh reports SKIPPED.
 * `make check` runs the short cases; ROBOELF_NETRIG=long (make netrig) adds
 * the long ones (minutes). ROBOELF_REACTION_CSV=FILE appends the figures.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "proc.h"
#include "re_fault.h"
#include "sys_h.h"

#define SKIP_EXIT     77
#define SLACK_MS      25   /* scheduling allowance, as test_sys_faults */
#define HOLD_MS	      300  /* no motion over this after the safe state */
#define FAULT_WAIT_MS 8000 /* FAULT line, beyond the deadline */
#define EXIT_WAIT_MS  8000
#define RIG_WAIT_MS   10000
#define RTO_MIN_MS    5 /* the installed route's rto_min (docs/link.md) */

static struct sys_env env;
static int env_ok, rig_ok;
static char rig_sh[SYS_PATH_MAX + 32], rig_id[16], ns[32];
static char data_addr[16], mgmt_addr[16], data_if[IFNAMSIZ];
static struct sys_case cs;

/* ---- the rig script --------------------------------------------------- */

/* Run netns_rig.sh with @args (space separated); its exit code, -1. */
static int rig(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int rig(const char *fmt, ...)
{
	char args[256], *argv[16], *save = NULL;
	struct proc p;
	va_list ap;
	int n = 0, status;

	va_start(ap, fmt);
	vsnprintf(args, sizeof(args), fmt, ap);
	va_end(ap);
	argv[n++] = (char *)"/bin/bash";
	argv[n++] = rig_sh;
	for (char *t = strtok_r(args, " ", &save); t && n < 15;
	     t = strtok_r(NULL, " ", &save))
		argv[n++] = t;
	argv[n] = NULL;
	if (proc_spawn(&p, argv, NULL) < 0)
		return -1;
	if (proc_wait_exit(&p, RIG_WAIT_MS, &status) < 0) {
		proc_kill(&p);
		return -1;
	}
	n = proc_exit_code(&p);
	if (n != 0)
		print_message("[   RIG    ] %s: exit %d: %s%s\n", args, n,
			      proc_output(&p, PROC_STDOUT),
			      proc_output(&p, PROC_STDERR));
	proc_kill(&p);
	return n;
}

/* The host's end of the data pair up or down (SIOCSIFFLAGS: no process
 * to start, so the injection time is exact even on a loaded machine). */
static int link_set(int up)
{
	struct ifreq ifr;
	int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0), rc = -1;

	memset(&ifr, 0, sizeof(ifr));
	snprintf(ifr.ifr_name, sizeof(ifr.ifr_name), "%s", data_if);
	if (fd >= 0 && ioctl(fd, SIOCGIFFLAGS, &ifr) == 0) {
		if (up)
			ifr.ifr_flags |= IFF_UP;
		else
			ifr.ifr_flags &= ~IFF_UP;
		rc = ioctl(fd, SIOCSIFFLAGS, &ifr);
	}
	if (fd >= 0)
		close(fd);
	return rc;
}

/* Pull the cable: the simulated time just before it (the injection). */
static double pull_cable(struct sys_case *c)
{
	double t = sys_sim_time(c);

	if (t < 0)
		fail_msg("sim time: %s", c->err);
	if (link_set(0) < 0)
		fail_msg("cannot set '%s' down", data_if);
	return t;
}

/* A rig command that takes effect as it returns (delay, loss): the
 * simulated time just after it; the measured reaction is from the moment
 * the rule was in place at the latest. */
static double rig_after(struct sys_case *c, const char *what, const char *arg)
{
	double t;

	if (rig("%s %s %s", what, rig_id, arg) != 0)
		fail_msg("rig '%s %s' failed", what, arg);
	t = sys_sim_time(c);
	if (t < 0)
		fail_msg("sim time: %s", c->err);
	return t;
}

/* ---- expectations ----------------------------------------------------- */

static double P(void)
{
	return env.period_ms;
}
static double C(void)
{
	return env.crit_factor * env.period_ms;
}
/* the controller's own watchdog: the last heartbeat got through before the
 * injection at the latest; then wdto, one main loop and one sample */
static double W_stop(void)
{
	return env.wdto_ms + SYS_MAINMS + 1;
}

struct outcome {
	double relay_ms;  /* relay off after the injection, -1 none */
	double motors_ms; /* every motor off after the injection, -1 */
	double age_ms;	  /* the reply age the FAULT line names, -1 */
	long warnings;	  /* late replies in the log (sys_wd_warnings) */
	char line[1024];  /* the FAULT line, "" none */
};

static void record(const char *name, const char *expected,
		   const struct outcome *o)
{
	const char *csv = getenv("ROBOELF_REACTION_CSV");
	FILE *f;

	print_message(
	    "[ MEASURE  ] %s: expected %s; relay off %.0f ms, "
	    "motors off %.0f ms, reply age %.0f ms, %ld warnings%s%s\n",
	    name, expected, o->relay_ms, o->motors_ms, o->age_ms, o->warnings,
	    o->line[0] ? "; " : "", o->line);
	if (!csv || !*csv || !(f = fopen(csv, "a")))
		return;
	fprintf(f, "%s,%s,%.1f,%.1f,%.1f,%ld\n", name, expected, o->relay_ms,
		o->motors_ms, o->age_ms, o->warnings);
	fclose(f);
}

/* The late replies the log accounts for so far: each logged in full
 * ("watchdog: reply after ..." or, in the stream design, "watchdog: a
 * record or the heartbeat's reply came after ...") and those counted in a
 * summary ("watchdog: N more late ..."). Complete after a fault or a quit
 * (the pending count is logged then), not while roboelf runs. -1: the log
 * could not be read. */
static long count_warnings(struct sys_case *c)
{
	return sys_wd_warnings(c, NULL, NULL);
}

/* Wait until every motor has a "motor off" event after @after. */
static double wait_motors_off(struct sys_case *c, double after, int ms)
{
	long long deadline = proc_now_ms() + ms;

	for (;;) {
		double t = sys_motors_off_time(c, after);

		if (t >= 0 || proc_now_ms() > deadline)
			return t;
		if (sys_wait_sim(c, sys_sim_time(c) + 15, 1000) < 0 ||
		    sys_events(c) < 0)
			return -1;
	}
}

/* The link's WATCHDOG faults: the round trip's reply age, and the stream
 * design's record, acknowledgement and echo ages (docs/link.md). */
static const enum re_fault_id link_wdogs[] = {RE_F_WDOG_REPLY, RE_F_WDOG_STREAM,
					      RE_F_WDOG_ACK, RE_F_WDOG_ECHO,
					      RE_F_NONE};

/* Which of link_wdogs @line is: the class and the recovery (which the
 * four share), and the text of its template up to the first figure.
 * Return: the id, or RE_F_NONE. */
static enum re_fault_id link_fault_id(const char *line)
{
	for (int i = 0; link_wdogs[i] != RE_F_NONE; i++) {
		const enum re_fault_id one[] = {link_wdogs[i], RE_F_NONE};
		const char *what = NULL, *brace;
		char head[128];

		if (sys_fault_match(line, -1, one) == RE_F_NONE ||
		    re_fault_template(link_wdogs[i], &what, NULL) != 0 || !what)
			continue;
		brace = strchr(what, '{');
		snprintf(head, sizeof(head), "%.*s",
			 (int)(brace ? brace - what : (long)strlen(what)),
			 what);
		if (head[0] && strstr(line, head))
			return link_wdogs[i];
	}
	return RE_F_NONE;
}

/* The age and the limit a link WATCHDOG FAULT line names ("... for A ms
 * (limit L ms"): 0, or -1 when the line has no such figures. */
static int fault_age(const char *line, double *age_ms, double *limit_ms)
{
	const char *p = strstr(line, " ms (limit ");

	if (!p)
		return -1;
	while (p > line && (p[-1] == '.' || (p[-1] >= '0' && p[-1] <= '9')))
		p--;
	return sscanf(p, "%lf ms (limit %lf ms", age_ms, limit_ms) == 2 ? 0
									: -1;
}

/*
 * A WATCHDOG trip within @wait_ms (real time): the FAULT line is @want
 * (RE_F_NONE: any of link_wdogs) and names an age past its limit by at
 * most a period, the relay goes off within @d_relay and every motor within
 * @d_motors of @t_inj (a negative deadline: not asserted, only measured),
 * the robot is safe and stays so.
 */
static void expect_trip(struct sys_case *c, const char *name, double t_inj,
			double d_relay, double d_motors, int wait_ms,
			enum re_fault_id want, struct outcome *o)
{
	enum re_fault_id got;
	double t, lim = -1;

	if (sys_wait_fault(c, wait_ms, o->line, sizeof(o->line)) < 0)
		fail_msg("%s: %s", name, c->err);
	got = link_fault_id(o->line);
	if (got == RE_F_NONE || (want != RE_F_NONE && got != want))
		fail_msg("%s: not the expected link WATCHDOG fault: %s", name,
			 o->line);
	if (fault_age(o->line, &o->age_ms, &lim) < 0)
		o->age_ms = -1;
	if (sys_wait_event(c, "relay off", t_inj, 3000, &t) < 0)
		fail_msg("%s: %s", name, c->err);
	o->relay_ms = t - t_inj;
	t = wait_motors_off(c, t_inj, 3000);
	if (t < 0)
		fail_msg("%s: not every motor was switched off", name);
	o->motors_ms = t - t_inj;
	o->warnings = count_warnings(c);
	record(name, "trip", o);
	if (sys_check_safe(c, 0, HOLD_MS) < 0)
		fail_msg("%s: %s", name, c->err);
	if (d_relay >= 0 && o->relay_ms > d_relay + SLACK_MS)
		fail_msg("%s: relay off after %.0f ms, deadline %.0f ms (+%d)",
			 name, o->relay_ms, d_relay, SLACK_MS);
	if (d_motors >= 0 && o->motors_ms > d_motors + SLACK_MS)
		fail_msg("%s: motors off after %.0f ms, deadline %.0f ms (+%d)",
			 name, o->motors_ms, d_motors, SLACK_MS);
	/* the echo's limit is its own (re_plan); the other ages' is C */
	if (got != RE_F_WDOG_ECHO && lim != C())
		fail_msg("%s: limit %.0f ms in the FAULT line, not C = %.0f ms",
			 name, lim, C());
	if (o->age_ms < 0 || o->age_ms > lim + P() + SLACK_MS)
		fail_msg("%s: age %.0f ms in the FAULT line, limit %.0f ms + P "
			 "= %.0f ms",
			 name, o->age_ms, lim, lim + P());
}

/* An unexpected trip of a no-trip case: measured like an expected one
 * (the relay's and the motors' times from @t0, the safe state held), so
 * that the failure names the fault and says whether the robot was safe. */
static void unexpected_trip(struct sys_case *c, const char *name, double t0,
			    const char *expected, struct outcome *o)
{
	double t;

	if (sys_wait_event(c, "relay off", t0, 3000, &t) == 0)
		o->relay_ms = t - t0;
	t = wait_motors_off(c, t0, 3000);
	if (t >= 0)
		o->motors_ms = t - t0;
	if (fault_age(o->line, &o->age_ms, &t) < 0)
		o->age_ms = -1;
	o->warnings = count_warnings(c);
	record(name, expected, o);
	if (strstr(o->line, "this supervisor did not run"))
		fail_msg("%s: inconclusive: the PC stalled (machine "
			 "overloaded), not the link: %s",
			 name, o->line);
	fail_msg("%s: tripped (%s; relay off %.0f ms, motors off %.0f ms "
		 "after the rule): %s",
		 name,
		 o->relay_ms >= 0 && o->motors_ms >= 0 &&
			 sys_check_safe(c, 0, HOLD_MS) == 0
		     ? "safe state reached and held"
		     : "NOT SAFE",
		 o->relay_ms, o->motors_ms, o->line);
}

/* No trip for @secs of simulated time from @t0: no FAULT line, still
 * armed (relay on, every motor on). A trip ends the wait at once and is
 * measured (unexpected_trip()). Then roboelf quits (SIGTERM), so that the
 * late replies still held for a summary are logged, and the log must
 * account for every one the supervisor counted (its "stats:" line). */
static void expect_no_trip(struct sys_case *c, const char *name, double t0,
			   double secs, const char *expected, long max_warn)
{
	struct outcome o = {.relay_ms = -1, .motors_ms = -1, .age_ms = -1};
	char st[2048];
	long counted;
	int status;

	if (sys_wait_fault(c, (int)(secs * 1000), o.line, sizeof(o.line)) == 0)
		unexpected_trip(c, name, t0, expected, &o);
	if (sys_wait_sim(c, t0 + secs * 1000, 5000) < 0)
		fail_msg("%s: %s", name, c->err);
	proc_pump(&c->re, 0);
	proc_find_line(&c->re, PROC_STDOUT, "FAULT ", o.line, sizeof(o.line));
	if (o.line[0])
		unexpected_trip(c, name, t0, expected, &o);
	if (sys_state(c, st, sizeof(st)) < 0)
		fail_msg("%s: %s", name, c->err);
	proc_signal(&c->re, SIGTERM);
	if (proc_wait_exit(&c->re, EXIT_WAIT_MS, &status) < 0)
		fail_msg("%s: roboelf did not exit within %d ms of SIGTERM",
			 name, EXIT_WAIT_MS);
	o.warnings = count_warnings(c);
	record(name, expected, &o);
	if (!strstr(st, " relay=on ") || !strstr(st, " A.mo=0 ") ||
	    !strstr(st, " B.mo=0 ") || !strstr(st, " C.mo=0 "))
		fail_msg("%s: no longer armed: %s", name, st);
	counted = sys_wd_counter(c);
	if (counted < 0 || o.warnings != counted)
		fail_msg("%s: the log accounts for %ld late replies, the "
			 "supervisor counted %ld%s%s",
			 name, o.warnings, counted, counted < 0 ? ": " : "",
			 counted < 0 ? c->err : "");
	if (max_warn >= 0 && o.warnings > max_warn)
		fail_msg("%s: %ld watchdog warnings, at most %ld expected",
			 name, o.warnings, max_warn);
}

/* After a fault: SIGTERM, exit 4 (a latched fault) within EXIT_WAIT_MS. */
static void quit_latched(struct sys_case *c, const char *name)
{
	int status;

	proc_signal(&c->re, SIGTERM);
	if (proc_wait_exit(&c->re, EXIT_WAIT_MS, &status) < 0)
		fail_msg("%s: roboelf did not exit within %d ms of SIGTERM",
			 name, EXIT_WAIT_MS);
	assert_int_equal(proc_exit_code(&c->re), 4);
}

/* ---- cases -------------------------------------------------------------- */

/* Which ends of the data route carry rto_min RTO_MIN_MS (netns_rig.sh rto). */
enum rto_ends {
	/* both, and linear timeouts in the namespace: a controller whose
	 * TCP resends as fast as the PC's */
	RTO_BOTH,
	/* the PC's route only, as the package installs it; the controller's
	 * side at the kernel's defaults (a real controller's timer is nobody's
	 * to set) */
	RTO_PC,
	/* neither: the kernel's 200 ms, the state before docs/link.md */
	RTO_NONE,
};

/* How the cycle gets the controller's record (controller.record). */
enum design {
	POLL,	/* one round trip per cycle, "hbpc=N;QR" */
	STREAM, /* the record streamed (DR over UDP), the heartbeat posted */
};

/* A case on the rig in @design with rto_min on the @ends of the route.
 * The design is written into the case's configuration, so a case never
 * depends on ROBOELF_SYS_RECORD. */
static void start_rto(struct sys_case *c, const char *calibration,
		      enum rto_ends ends, enum design design)
{
	/* the script exec's ip, which exec's galil-sim: the pid is its */
	char *wrap[] = {(char *)"/bin/bash", rig_sh, (char *)"exec", rig_id,
			NULL};
	const struct sys_subst subst[] = {
	    {"record", design == STREAM ? "stream" : "poll"}, {NULL, NULL}};
	struct sys_opts o = {.sim_wrap = wrap,
			     .sim_addr = data_addr,
			     .ctl_addr = mgmt_addr,
			     .subst = subst,
			     .calibration = calibration,
			     .no_ready = calibration != NULL};

	/* a case that failed left its processes: they would run on (and
	 * hold their relay's lock) beside the next case */
	sys_case_stop(c);
	if (!env_ok || !rig_ok)
		fail_msg("no environment (calibration or rig failed)");
	if (rig("clear %s", rig_id) || rig("up %s", rig_id) ||
	    (ends != RTO_NONE && rig("rto %s %d %s", rig_id, RTO_MIN_MS,
				     ends == RTO_PC ? "pc" : "both")))
		fail_msg("rig reset failed");
	if (sys_case_start(c, &env, &o) < 0)
		fail_msg("case start: %s", c->err);
	/* the rig measures the link, not a CPU shared with builds and
	 * fuzzers: roboelf and galil-sim run at nice -10 (root is given) */
	setpriority(PRIO_PROCESS, (id_t)c->re.pid, -10);
	setpriority(PRIO_PROCESS, (id_t)c->sim.p.pid, -10);
}

static void start(struct sys_case *c, const char *calibration)
{
	start_rto(c, calibration, RTO_BOTH, POLL);
}

static void stop(struct sys_case *c)
{
	sys_case_stop(c);
	rig("clear %s", rig_id);
	rig("up %s", rig_id);
}

/* Jog axis B so that a pull meets a moving robot. */
static void jog(struct sys_case *c)
{
	if (sys_ctl(c, "joy B fwd") < 0 ||
	    sys_wait_moving(c, 'B', 200, 5000) < 0)
		fail_msg("jog: %s", c->err);
}

/* Cable pulled while armed and jogging: the PC's reply-age watchdog opens
 * the relay within C + P; its stop cannot reach the controller, whose own
 * watchdog switches the motors off within W + M + s. */
static void test_pull_armed(void **state)
{
	struct outcome o = {0};
	double t;

	(void)state;
	start(&cs, NULL);
	/* roboelf checked the route at start-up (docs/link.md) */
	assert_int_equal(proc_find_line(&cs.re, PROC_STDOUT,
					"roboelf: route to the controller: "
					"rto_min 5 ms (limit 25 ms)",
					NULL, 0),
			 0);
	jog(&cs);
	t = pull_cable(&cs);
	expect_trip(&cs, "cable pull, armed", t, C() + P(), W_stop(),
		    FAULT_WAIT_MS, RE_F_WDOG_REPLY, &o);
	quit_latched(&cs, "cable pull, armed");
	stop(&cs);
}

/* Cable pulled during the full calibration (state 3, axes moving). */
static void test_pull_calibrating(void **state)
{
	struct outcome o = {0};
	double t;

	(void)state;
	start(&cs, "full");
	if (sys_wait_moving(&cs, 'A', 200, 60000) < 0)
		fail_msg("no calibration motion: %s", cs.err);
	t = pull_cable(&cs);
	expect_trip(&cs, "cable pull, calibrating", t, C() + P(), W_stop(),
		    FAULT_WAIT_MS, RE_F_WDOG_REPLY, &o);
	quit_latched(&cs, "cable pull, calibrating");
	stop(&cs);
}

/* Cable pulled while latched (after an encoder/pot fault): nothing changes,
 * nothing moves, no second fault is invented, the quit still exits 4. */
static void test_pull_latched(void **state)
{
	char line[1024];
	double t;

	(void)state;
	start(&cs, NULL);
	if (sys_ctl(&cs, "pot A offset 0.5") < 0 ||
	    sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0 ||
	    sys_check_safe(&cs, 0, HOLD_MS) < 0)
		fail_msg("latch: %s", cs.err);
	t = pull_cable(&cs);
	if (sys_check_safe(&cs, 0, 1000) < 0)
		fail_msg("cable pull, latched: %s", cs.err);
	if (sys_events(&cs) < 0)
		fail_msg("%s", cs.err);
	assert_int_equal(sys_event_find(&cs, "relay on", t), -1);
	assert_int_equal(sys_event_find(&cs, "axis A motor on", t), -1);
	print_message("[ MEASURE  ] cable pull, latched: expected safe "
		      "state held; held 1000 ms, no relay or motor on\n");
	quit_latched(&cs, "cable pull, latched");
	stop(&cs);
}

/* Cable pulled and back after 200 ms: the fault stays latched, nothing
 * resumes (relay off, motors off, no motion) after the link is back. */
static void test_pull_back_200ms(void **state)
{
	struct outcome o = {0};
	double t;

	(void)state;
	start(&cs, NULL);
	jog(&cs);
	t = pull_cable(&cs);
	if (sys_wait_sim(&cs, t + 200, 3000) < 0 || link_set(1) < 0)
		fail_msg("cable back: %s", cs.err);
	expect_trip(&cs, "cable back after 200 ms", t, C() + P(), W_stop(),
		    FAULT_WAIT_MS, RE_F_WDOG_REPLY, &o);
	if (sys_check_safe(&cs, 0, 1000) < 0 || sys_events(&cs) < 0)
		fail_msg("cable back after 200 ms: %s", cs.err);
	for (int a = 0; a < 3; a++) {
		char ev[32];

		snprintf(ev, sizeof(ev), "axis %c motor on", 'A' + a);
		assert_int_equal(sys_event_find(&cs, ev, t), -1);
	}
	assert_int_equal(sys_event_find(&cs, "relay on", t), -1);
	/* no second Ready after the one the case started with */
	assert_int_equal(proc_wait_line(&cs.re, PROC_STDOUT,
					"RoboELF Ready for Use", 0, NULL, 0),
			 -1);
	quit_latched(&cs, "cable back after 200 ms");
	stop(&cs);
}

/* ---- loss and delay: a table of cases --------------------------------- */

/* What a case asserts (docs/safety.md, "Network cases"). */
enum expect {
	NO_TRIP, /* held @secs: no FAULT line, still armed */
	TRIP,	 /* a link WATCHDOG fault, relay and motors off */
};

/*
 * One loss or delay case: the same injections for both designs of
 * controller.record, so that the rows compare them.
 */
struct link_case {
	const char *name;   /* the measurement's name (output, CSV) */
	enum design design; /* how the cycle gets the record */
	int loss_pct;	    /* random loss, 0 none */
	const char *dir;    /* the loss's frames (netns_rig.sh loss): "both"
			       ways, "ctl" (the controller's replies), "pc"
			       (the PC's requests) */
	const char *proto;  /* the loss's or the delay's protocol: "tcp" (the
			       command port), "udp" (the record stream) or
			       "all" */
	int delay_ms;	    /* on the frames of @proto the controller sends,
			       0 none */
	enum rto_ends rto;  /* which ends resend fast */
	enum expect expect; /* the outcome asserted */
	/* TRIP: the fault's class; RE_F_NONE: any of link_wdogs (a loss in
	 * the stream design may meet the record's, the acknowledgement's or
	 * the echo's limit first). The round trip's is always WDOG_REPLY. */
	enum re_fault_id fault;
	/* NO_TRIP: the time held; TRIP on loss (at a random time): the
	 * longest wait for the fault; a trip on delay must come within the
	 * deadline C + P + the delay */
	double secs;
	int in_check; /* in `make check`; all run under ROBOELF_NETRIG=long */
};

/* Loss: a trip comes at a random time, so there is no deadline from the
 * injection; the age in the FAULT line and the controller's stop are
 * asserted. */
static void loss_trip(const struct link_case *k, enum re_fault_id want,
		      double t)
{
	struct outcome o = {0};

	expect_trip(&cs, k->name, t, -1, -1, (int)(k->secs * 1000) + 5000, want,
		    &o);
	if (o.motors_ms > o.relay_ms + W_stop() + SLACK_MS)
		fail_msg("%s: motors off %.0f ms after the relay", k->name,
			 o.motors_ms - o.relay_ms);
}

/* The start-up lines: about the route (the installed rto_min, or, none
 * set, the warning a development start gives) and about the record (the
 * stream opened and measured through the rig's cable, or polled). */
static void expect_start_lines(const struct link_case *k)
{
	const char *want[] = {
	    k->rto == RTO_NONE
		? "roboelf: warning: the route to the controller '10.231."
		: "roboelf: route to the controller: rto_min 5 ms (limit 25 "
		  "ms)",
	    k->design == STREAM ? "roboelf: record stream: UDP handle "
				: "roboelf: record polled (QR each cycle)",
	};

	for (size_t i = 0; i < sizeof(want) / sizeof(want[0]); i++)
		if (proc_find_line(&cs.re, PROC_STDOUT, want[i], NULL, 0) != 0)
			fail_msg("%s: no start-up line '%s'", k->name, want[i]);
}

/* The stream design: roboelf's run ended (a no-trip case quit it, a trip
 * case too, once latched), the record stream's counters that its log ends
 * with, printed beside the measurement: the datagrams the loss took. */
static void stream_counters(struct sys_case *c, const struct link_case *k)
{
	char line[1024];

	if (k->design != STREAM)
		return;
	if (sys_log_find(c, "stream: datagrams=", NULL, line, sizeof(line)) ==
	    0)
		print_message("[ MEASURE  ] %s: %s\n", k->name,
			      strstr(line, "stream: datagrams="));
	else
		print_message("[ MEASURE  ] %s: no stream counters in the "
			      "log\n",
			      k->name);
}

/* Run the case that cmocka passes as the initial state. */
static void run_case(void **state)
{
	const struct link_case *k = *state;
	enum re_fault_id want = k->design == POLL ? RE_F_WDOG_REPLY : k->fault;
	char arg[SYS_PATH_MAX + 48];
	struct outcome o = {0};
	double t;

	start_rto(&cs, NULL, k->rto, k->design);
	expect_start_lines(k);
	if (k->delay_ms) {
		snprintf(arg, sizeof(arg), "%d %s %s", k->delay_ms, env.bin,
			 k->proto);
		t = rig_after(&cs, "delay", arg);
	} else {
		snprintf(arg, sizeof(arg), "%d %s %s", k->loss_pct, k->dir,
			 k->proto);
		t = rig_after(&cs, "loss", arg);
	}
	if (k->expect == NO_TRIP) {
		expect_no_trip(&cs, k->name, t, k->secs,
			       k->delay_ms ? "no trip, warnings" : "no trip",
			       -1);
	} else {
		if (k->delay_ms)
			expect_trip(&cs, k->name, t, C() + P() + k->delay_ms,
				    W_stop() + k->delay_ms, FAULT_WAIT_MS, want,
				    &o);
		else
			loss_trip(k, want, t);
		quit_latched(&cs, k->name);
	}
	stream_counters(&cs, k);
	stop(&cs);
}

/* One function per case: docs/safety.md names them (tests/checks/
 * safety_trace.sh); each runs its row of the table below. */
static void test_delay_40(void **state)
{
	run_case(state);
}
static void test_delay_80(void **state)
{
	run_case(state);
}
static void test_delay_150(void **state)
{
	run_case(state);
}
static void test_loss_5_short(void **state)
{
	run_case(state);
}
static void test_loss_30(void **state)
{
	run_case(state);
}
static void test_loss_1_60s(void **state)
{
	run_case(state);
}
static void test_loss_5_60s(void **state)
{
	run_case(state);
}
static void test_loss_5_no_rto(void **state)
{
	run_case(state);
}
static void test_ctl_untuned_loss_1(void **state)
{
	run_case(state);
}
static void test_ctl_untuned_loss_5(void **state)
{
	run_case(state);
}
static void test_ctl_untuned_loss_30(void **state)
{
	run_case(state);
}
static void test_ctl_untuned_loss_5_replies(void **state)
{
	run_case(state);
}
static void test_ctl_untuned_loss_5_requests(void **state)
{
	run_case(state);
}
static void test_ctl_untuned_delay_40(void **state)
{
	run_case(state);
}
static void test_ctl_untuned_delay_80(void **state)
{
	run_case(state);
}
static void test_ctl_untuned_delay_150(void **state)
{
	run_case(state);
}
static void test_stream_loss_1_udp(void **state)
{
	run_case(state);
}
static void test_stream_loss_1_tcp(void **state)
{
	run_case(state);
}
static void test_stream_loss_1_both(void **state)
{
	run_case(state);
}
static void test_stream_loss_5_udp(void **state)
{
	run_case(state);
}
static void test_stream_loss_5_tcp(void **state)
{
	run_case(state);
}
static void test_stream_loss_5_both(void **state)
{
	run_case(state);
}
static void test_stream_loss_30_udp(void **state)
{
	run_case(state);
}
static void test_stream_loss_30_tcp(void **state)
{
	run_case(state);
}
static void test_stream_loss_30_both(void **state)
{
	run_case(state);
}
static void test_stream_delay_40_udp(void **state)
{
	run_case(state);
}
static void test_stream_delay_40_tcp(void **state)
{
	run_case(state);
}
static void test_stream_delay_80_udp(void **state)
{
	run_case(state);
}
static void test_stream_delay_80_tcp(void **state)
{
	run_case(state);
}
static void test_stream_delay_150_udp(void **state)
{
	run_case(state);
}
static void test_stream_delay_150_tcp(void **state)
{
	run_case(state);
}

/* Rows: a loss of @pct % of @dir's frames of @proto, a delay of @ms ms of
 * the frames of @proto the controller sends. */
#define LOSS(d, pct, dir_, proto_)                                             \
	.design = d, .loss_pct = pct, .dir = dir_, .proto = proto_
#define DELAY(d, ms, proto_) .design = d, .delay_ms = ms, .proto = proto_
#define ROW(f)		     #f, f

/* The cases: the function, then the row it runs. Outcomes as measured
 * (docs/link.md, "Measurements"; docs/safety.md, "Network cases"). */
static struct {
	const char *test;
	CMUnitTestFunction fn;
	struct link_case k;
} cases[] = {
    /* the round trip, both ends resend fast (rto_min 5 ms, linear
     * timeouts) */
    {ROW(test_delay_40),
     {"delay 40 ms", DELAY(POLL, 40, "all"), .rto = RTO_BOTH, .expect = NO_TRIP,
      .secs = 10}},
    {ROW(test_delay_80),
     {"delay 80 ms", DELAY(POLL, 80, "all"), .rto = RTO_BOTH, .expect = TRIP}},
    {ROW(test_delay_150),
     {"delay 150 ms", DELAY(POLL, 150, "all"), .rto = RTO_BOTH, .expect = TRIP,
      .in_check = 1}},
    {ROW(test_loss_5_short),
     {"loss 5 % (10 s)", LOSS(POLL, 5, "both", "all"), .rto = RTO_BOTH,
      .expect = NO_TRIP, .secs = 10}},
    {ROW(test_loss_30),
     {"loss 30 %", LOSS(POLL, 30, "both", "all"), .rto = RTO_BOTH,
      .expect = TRIP, .secs = 3, .in_check = 1}},
    {ROW(test_loss_1_60s),
     {"loss 1 % (60 s)", LOSS(POLL, 1, "both", "all"), .rto = RTO_BOTH,
      .expect = NO_TRIP, .secs = 60}},
    {ROW(test_loss_5_60s),
     {"loss 5 % (60 s)", LOSS(POLL, 5, "both", "all"), .rto = RTO_BOTH,
      .expect = NO_TRIP, .secs = 60}},
    /* the round trip, neither end: the state before docs/link.md */
    {ROW(test_loss_5_no_rto),
     {"loss 5 %, no rto_min", LOSS(POLL, 5, "both", "all"), .rto = RTO_NONE,
      .expect = TRIP, .secs = 3}},
    /* the round trip, the PC as installed, the controller's TCP at the
     * kernel's defaults */
    {ROW(test_ctl_untuned_loss_1),
     {"ctl untuned, loss 1 %", LOSS(POLL, 1, "both", "all"), .rto = RTO_PC,
      .expect = TRIP, .secs = 60}},
    {ROW(test_ctl_untuned_loss_5),
     {"ctl untuned, loss 5 %", LOSS(POLL, 5, "both", "all"), .rto = RTO_PC,
      .expect = TRIP, .secs = 20, .in_check = 1}},
    {ROW(test_ctl_untuned_loss_30),
     {"ctl untuned, loss 30 %", LOSS(POLL, 30, "both", "all"), .rto = RTO_PC,
      .expect = TRIP, .secs = 3, .in_check = 1}},
    {ROW(test_ctl_untuned_loss_5_replies),
     {"ctl untuned, loss 5 % of replies", LOSS(POLL, 5, "ctl", "all"),
      .rto = RTO_PC, .expect = TRIP, .secs = 20}},
    {ROW(test_ctl_untuned_loss_5_requests),
     {"ctl untuned, loss 5 % of requests (30 s)", LOSS(POLL, 5, "pc", "all"),
      .rto = RTO_PC, .expect = NO_TRIP, .secs = 30}},
    {ROW(test_ctl_untuned_delay_40),
     {"ctl untuned, delay 40 ms", DELAY(POLL, 40, "all"), .rto = RTO_PC,
      .expect = NO_TRIP, .secs = 10}},
    {ROW(test_ctl_untuned_delay_80),
     {"ctl untuned, delay 80 ms", DELAY(POLL, 80, "all"), .rto = RTO_PC,
      .expect = TRIP}},
    {ROW(test_ctl_untuned_delay_150),
     {"ctl untuned, delay 150 ms", DELAY(POLL, 150, "all"), .rto = RTO_PC,
      .expect = TRIP, .in_check = 1}},
    /* the record as a stream, the controller's TCP at the kernel's
     * defaults: a lost or late record costs one sample of the stream; the
     * heartbeat's reply, resent after the controller's 200 ms, is not
     * waited for (docs/link.md, "The record as a stream") */
    {ROW(test_stream_loss_1_udp),
     {"stream, loss 1 % of the stream (60 s)", LOSS(STREAM, 1, "both", "udp"),
      .rto = RTO_PC, .expect = NO_TRIP, .secs = 60}},
    {ROW(test_stream_loss_1_tcp),
     {"stream, loss 1 % on TCP (60 s)", LOSS(STREAM, 1, "both", "tcp"),
      .rto = RTO_PC, .expect = NO_TRIP, .secs = 60}},
    {ROW(test_stream_loss_1_both),
     {"stream, loss 1 % of both (60 s)", LOSS(STREAM, 1, "both", "all"),
      .rto = RTO_PC, .expect = NO_TRIP, .secs = 60}},
    {ROW(test_stream_loss_5_udp),
     {"stream, loss 5 % of the stream (20 s)", LOSS(STREAM, 5, "both", "udp"),
      .rto = RTO_PC, .expect = NO_TRIP, .secs = 20, .in_check = 1}},
    {ROW(test_stream_loss_5_tcp),
     {"stream, loss 5 % on TCP (20 s)", LOSS(STREAM, 5, "both", "tcp"),
      .rto = RTO_PC, .expect = NO_TRIP, .secs = 20, .in_check = 1}},
    {ROW(test_stream_loss_5_both),
     {"stream, loss 5 % of both (20 s)", LOSS(STREAM, 5, "both", "all"),
      .rto = RTO_PC, .expect = NO_TRIP, .secs = 20}},
    {ROW(test_stream_loss_30_udp),
     {"stream, loss 30 % of the stream (20 s)", LOSS(STREAM, 30, "both", "udp"),
      .rto = RTO_PC, .expect = NO_TRIP, .secs = 20}},
    {ROW(test_stream_loss_30_tcp),
     {"stream, loss 30 % on TCP", LOSS(STREAM, 30, "both", "tcp"),
      .rto = RTO_PC, .expect = TRIP, .fault = RE_F_NONE, .secs = 20}},
    {ROW(test_stream_loss_30_both),
     {"stream, loss 30 % of both", LOSS(STREAM, 30, "both", "all"),
      .rto = RTO_PC, .expect = TRIP, .fault = RE_F_NONE, .secs = 20}},
    {ROW(test_stream_delay_40_udp),
     {"stream, delay 40 ms of the stream", DELAY(STREAM, 40, "udp"),
      .rto = RTO_PC, .expect = NO_TRIP, .secs = 10}},
    {ROW(test_stream_delay_40_tcp),
     {"stream, delay 40 ms on TCP", DELAY(STREAM, 40, "tcp"), .rto = RTO_PC,
      .expect = NO_TRIP, .secs = 10}},
    {ROW(test_stream_delay_80_udp),
     {"stream, delay 80 ms of the stream", DELAY(STREAM, 80, "udp"),
      .rto = RTO_PC, .expect = NO_TRIP, .secs = 10}},
    {ROW(test_stream_delay_80_tcp),
     {"stream, delay 80 ms on TCP", DELAY(STREAM, 80, "tcp"), .rto = RTO_PC,
      .expect = NO_TRIP, .secs = 10}},
    {ROW(test_stream_delay_150_udp),
     {"stream, delay 150 ms of the stream", DELAY(STREAM, 150, "udp"),
      .rto = RTO_PC, .expect = TRIP, .fault = RE_F_WDOG_ECHO, .in_check = 1}},
    {ROW(test_stream_delay_150_tcp),
     {"stream, delay 150 ms on TCP", DELAY(STREAM, 150, "tcp"), .rto = RTO_PC,
      .expect = NO_TRIP, .secs = 10}},
};
#undef ROW
#undef DELAY
#undef LOSS

/* ---- fixtures ----------------------------------------------------------- */

static int group_setup(void **state)
{
	(void)state;
	if (rig("setup %s", rig_id) == 0)
		rig_ok = 1;
	if (sys_env_init(&env) == 0 && sys_env_calibrate(&env, 150000) == 0)
		env_ok = 1;
	print_message("[   INFO   ] rig %s (%s, galil-sim at %s, control %s); "
		      "full calibration %s in %.1f s (P %d ms)\n",
		      rig_ok ? "up" : "FAILED", ns, data_addr, mgmt_addr,
		      env_ok ? "done" : "FAILED", env.calib_s, env.period_ms);
	return 0;
}

static int group_teardown(void **state)
{
	(void)state;
	sys_case_stop(&cs);
	rig("teardown %s", rig_id);
	sys_env_cleanup(&env);
	return 0;
}

/* The rig's precondition: 0, or prints the SKIP line and returns 77. */
static int rig_check(void)
{
	char *argv[] = {(char *)"/bin/bash", rig_sh, (char *)"check", NULL};
	struct proc p;
	int status, rc;

	if (proc_spawn(&p, argv, NULL) < 0 ||
	    proc_wait_exit(&p, RIG_WAIT_MS, &status) < 0) {
		proc_kill(&p);
		printf("SKIP: cannot run '%s'\n", rig_sh);
		return SKIP_EXIT;
	}
	rc = proc_exit_code(&p);
	if (rc != 0)
		printf("%s", rc == SKIP_EXIT ? proc_output(&p, PROC_STDOUT)
					     : "SKIP: the rig check failed\n");
	proc_kill(&p);
	return rc == 0 ? 0 : SKIP_EXIT;
}

#define N_CASES (sizeof(cases) / sizeof(cases[0]))

/* The program's list: the cable pulls, then the table's rows (all, or
 * those of `make check`). Returns the number of tests in @t. */
static size_t list_tests(struct CMUnitTest *t, int all)
{
	const struct CMUnitTest pulls[] = {
	    cmocka_unit_test(test_pull_armed),
	    cmocka_unit_test(test_pull_back_200ms),
	    cmocka_unit_test(test_pull_latched),
	    cmocka_unit_test(test_pull_calibrating),
	};
	size_t n = 0;

	for (size_t i = 0; i < sizeof(pulls) / sizeof(pulls[0]); i++)
		if (all || pulls[i].test_func != test_pull_calibrating)
			t[n++] = pulls[i];
	for (size_t i = 0; i < N_CASES; i++) {
		if (!all && !cases[i].k.in_check)
			continue;
		t[n] = (struct CMUnitTest){.name = cases[i].test,
					   .test_func = cases[i].fn,
					   .initial_state = &cases[i].k};
		n++;
	}
	return n;
}

int main(void)
{
	struct CMUnitTest tests[4 + N_CASES];
	const char *top = getenv("ROBOELF_TOP"),
		   *mode = getenv("ROBOELF_NETRIG");
	const char *filter = getenv("ROBOELF_SYS_FILTER");
	unsigned id = (unsigned)getpid() % 100000;
	size_t n;
	int rc;

	snprintf(rig_sh, sizeof(rig_sh), "%s/tests/net/netns_rig.sh",
		 top && *top ? top : ".");
	rc = rig_check();
	if (rc)
		return rc;
	snprintf(rig_id, sizeof(rig_id), "%u", id);
	snprintf(ns, sizeof(ns), "roboelf-net-%u", id);
	snprintf(data_addr, sizeof(data_addr), "10.231.%u.2", id % 250 + 1);
	snprintf(mgmt_addr, sizeof(mgmt_addr), "10.232.%u.2", id % 250 + 1);
	snprintf(data_if, sizeof(data_if), "rd%uh", id);
	if (filter && *filter)
		cmocka_set_test_filter(filter);
	n = list_tests(tests, mode && !strcmp(mode, "long"));
	return _cmocka_run_group_tests("test_net_rig", tests, n, group_setup,
				       group_teardown);
}
