/*
 * test_sys_second.c - one master: a second supervisor or a loader on a
 * supervised controller (docs/safety.md H9, D21, D22), on the whole system:
 * galil-sim running dmc/ (downloaded by galil-load), roboelf supervising it
 * through the virtual relay.
 *
 * One full calibration for the binary (group setup; its first try is case
 * 0, which this program reports), then every case on a fresh galil-sim
 * with `--calibration file`:
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
 *  4. roboelf's start-up closes a client connected before it (IHT=>-3).
 *
 * Every case asserts the outcome, the exact text (sys_exact_h.h) and the
 * reaction time against the deadlines of docs/safety.md section 3 plus
 * SX_SLACK_MS; the group teardown prints the summary table.
 *
 * Environment: ROBOELF_SYS_FILTER=PATTERN runs only the matching cases;
 * ROBOELF_KEEP=1 keeps the temporary directory; ROBOELF_SYS_CAL=FILE
 * reuses a calibration (development).
 */
#include <errno.h>
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
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <arpa/inet.h>
#include <netinet/in.h>

#include <cmocka.h>

#include "sys_exact_h.h"
#include "sys_truth.h"

#define REFUSE_WAIT_MS 5000 /* a refused roboelf has exited */
#define LOCK_REFUSE_MS 1000 /* a lock refusal: no I/O, no wait */
#define WATCH_MS       1200 /* the first watched undisturbed (>= 1 s) */
#define WATCH_STEP_MS  100  /* ... one state line this often */

/* Recovery text of the PROGRAM fault, as roboelf prints it
 * (pc/super/re_fault.c; docs/operator.md section 7). */
#define REC_THREAD                                                             \
	" Recovery: press the E-stop and keep it pressed, restart roboelf; "   \
	"if it happens again, reload the program with galil-load"

static struct sys_env env;
static struct sx_fixture fx;
static struct sys_case cs;   /* the first roboelf and its controller */
static struct proc re2;	     /* a second roboelf, or a galil-load */
static struct proc_sim sim2; /* a second controller and relay */
static int raw_fd = -1;	     /* a raw client of the controller */

static int group_setup(void **state)
{
	(void)state;
	return sx_group_setup(&fx, &env);
}

static int group_teardown(void **state)
{
	(void)state;
	return sx_group_teardown(&fx, 1);
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
	return 0;
}

/* A second galil-sim: another controller, and a relay of its own. */
static void start_sim2(void)
{
	char link[SYS_PATH_MAX + 16];

	snprintf(link, sizeof(link), "%s/relay-other", env.dir);
	char *extra[] = {(char *)"--udp-port", (char *)"0", NULL};

	if (proc_sim_start(&sim2, env.bin, link, extra, 10000) < 0)
		fail_msg("a second galil-sim did not start");
}

static const char *sim2_relay(void)
{
	static char link[SYS_PATH_MAX + 16];

	snprintf(link, sizeof(link), "%s/relay-other", env.dir);
	return link;
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
	char st[SX_TEXT_MAX], line[SX_TEXT_MAX];
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
	i = sys_event_find(c, "relay", t0);
	if (i >= 0)
		fail_msg("the relay was touched: '%s' at %.0f ms",
			 c->ev[i].text, c->ev[i].t_ms);
	i = sys_event_find(c, "handle ", t0);
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
	struct sx_row *r = sx_row_begin("0 full calibration (setup)");

	(void)state;
	if (fx.cal_fail[0]) {
		sx_row_text(r, fx.cal_line[0] ? fx.cal_line : fx.cal_fail);
		fail_msg("the full calibration failed on its first try: %s\n%s",
			 fx.cal_line, fx.cal_fail);
	}
	if (!fx.ok)
		fail_msg("no calibration: %s", env.err);
	sx_row_reaction(r, "%.1f s (wall)", env.calib_s);
	sx_row_pass(r, "calibrated and armed, no fault");
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

/* A configuration copy naming controller @addr (its UDP port @udp) and
 * relay @port. */
static void write_config(const char *path, const char *addr, int udp,
			 const char *port)
{
	char qa[SYS_PATH_MAX + 4], qp[SYS_PATH_MAX + 4], qu[16];
	struct sys_subst sub[] = {{"address", qa},
				  {"port_development", qp},
				  {"udp_port", qu},
				  {NULL, NULL}};

	snprintf(qu, sizeof(qu), "%d", udp);
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
	sx_expect_text("the refusal", tpl, line, num, max);
	return ms;
}

/* A refusal by a lock: at once, before the relay or the controller. */
static void refused_by_lock(struct sx_row *r, const char *tpl, long long w0,
			    double t0)
{
	char line[SX_TEXT_MAX];
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
	sx_row_text(r, line);
	sx_row_reaction(r,
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
	struct sx_row *r = sx_row_begin("1a second roboelf, same config");
	char addr[32], tpl[256];
	long long w0;
	double t0;

	(void)state;
	sx_start(&cs, &fx);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", cs.sim.port);
	snprintf(tpl, sizeof(tpl),
		 "roboelf: error: controller %s is already supervised by "
		 "roboelf (pid {n}, since {t})",
		 addr);
	t0 = sys_sim_time(&cs);
	w0 = proc_now_ms();
	spawn_second(&re2, cs.cfg, addr, cs.relay_link, fx.lock_env);
	refused_by_lock(r, tpl, w0, t0);
	sx_row_pass(r,
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
	struct sx_row *r = sx_row_begin("1b second config, same relay");
	char cfg[SYS_PATH_MAX + 16], addr[32], tpl[512];
	long long w0;
	double t0;

	(void)state;
	sx_start(&cs, &fx);
	start_sim2();
	snprintf(cfg, sizeof(cfg), "%s/same-relay.yaml", env.dir);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", sim2.port);
	write_config(cfg, addr, sim2.udp_port, cs.sim.relay);
	snprintf(tpl, sizeof(tpl),
		 "roboelf: error: relay %s is already supervised by roboelf "
		 "(pid {n}, since {t})",
		 cs.sim.relay);
	t0 = sys_sim_time(&cs);
	w0 = proc_now_ms();
	spawn_second(&re2, cfg, NULL, NULL, fx.lock_env);
	refused_by_lock(r, tpl, w0, t0);
	sx_row_pass(r,
		    "refused by the relay lock, exit 3; first undisturbed "
		    ">= %d ms",
		    WATCH_MS);
}

/* 1c. Another configuration file naming the same controller address and
 * another relay (a second galil-sim's): the controller lock refuses it. */
static void test_second_same_controller(void **state)
{
	struct sx_row *r = sx_row_begin("1c second config, same controller");
	char cfg[SYS_PATH_MAX + 16], addr[32], tpl[256];
	long long w0;
	double t0;

	(void)state;
	sx_start(&cs, &fx);
	start_sim2();
	snprintf(cfg, sizeof(cfg), "%s/same-controller.yaml", env.dir);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", cs.sim.port);
	write_config(cfg, addr, cs.sim.udp_port, sim2_relay());
	snprintf(tpl, sizeof(tpl),
		 "roboelf: error: controller %s is already supervised by "
		 "roboelf (pid {n}, since {t})",
		 addr);
	t0 = sys_sim_time(&cs);
	w0 = proc_now_ms();
	spawn_second(&re2, cfg, NULL, NULL, fx.lock_env);
	refused_by_lock(r, tpl, w0, t0);
	sx_row_pass(r,
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
	struct sx_row *r = sx_row_begin("2 second supervisor, other host");
	char cfg[SYS_PATH_MAX + 16], addr[32], line[SX_TEXT_MAX];
	static const char tpl[] =
	    "roboelf: error: the controller's program is armed and its "
	    "heartbeat is advancing: another supervisor is running the robot; "
	    "quit it first (nothing was changed on the controller)";
	long long w0;
	double t0, ms, bound;

	(void)state;
	sx_start(&cs, &fx);
	start_sim2();
	snprintf(cfg, sizeof(cfg), "%s/other-host.yaml", env.dir);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", cs.sim.port);
	write_config(cfg, addr, cs.sim.udp_port, sim2_relay());
	t0 = sys_sim_time(&cs);
	w0 = proc_now_ms();
	spawn_second(&re2, cfg, NULL, NULL, fx.lock_env2);
	ms = expect_refused(&re2, w0, tpl, NULL, 0, line, sizeof(line));
	sx_row_text(r, line);
	bound = env.wdto_ms + 50 + 2000;
	sx_row_reaction(r,
			"refused (exit 3) %.0f ms after its start (bound "
			"wdto + 50 + 2000 = %.0f ms, wall)",
			ms, bound);
	if (ms > bound)
		fail_msg("the refusal took %.0f ms (bound %.0f)", ms, bound);
	expect_undisturbed(&cs, t0, 0);
	sx_row_pass(r,
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
	struct sx_row *r = sx_row_begin("3a galil-load, no --force");
	static const char tpl[] =
	    "galil-load: the controller's program is armed and its "
	    "supervisor's heartbeat is advancing: roboelf is driving the "
	    "robot. Loading halts the program: every axis stops, every motor "
	    "is switched off and roboelf latches a fault. Quit roboelf first, "
	    "or give --force to do exactly that";
	char line[SX_TEXT_MAX];
	long long w0;
	double t0;
	int code;

	(void)state;
	sx_start(&cs, &fx);
	t0 = sys_sim_time(&cs);
	w0 = proc_now_ms();
	spawn_load(&re2, 0);
	code = load_exit(&re2, 30000);
	if (proc_find_line(&re2, PROC_STDERR, "galil-load: ", line,
			   sizeof(line)) < 0)
		snprintf(line, sizeof(line), "(no message on stderr)");
	sx_row_text(r, line);
	sx_row_reaction(r, "exit %d after %lld ms (wall)", code,
			proc_now_ms() - w0);
	if (code != 5)
		fail_msg("galil-load exited with %d, not 5\n--- stdout:\n%s\n"
			 "--- stderr:\n%s",
			 code, proc_output(&re2, PROC_STDOUT),
			 proc_output(&re2, PROC_STDERR));
	sx_expect_text("galil-load's refusal", tpl, line, NULL, 0);
	expect_undisturbed(&cs, t0, 0);
	sx_row_pass(r, "exit 5; first undisturbed >= %d ms", WATCH_MS);
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
	struct sx_row *r = sx_row_begin("3b galil-load --force");
	char line[SX_TEXT_MAX], tpl[1024], h;
	double t0, t_conn, t_hx, t_relay, t_mo;
	int i, code;

	(void)state;
	sx_start(&cs, &fx);
	t0 = sys_sim_time(&cs);
	spawn_load(&re2, 1);
	i = sx_wait_event(&cs, "handle ", " opened from ", t0, 5000);
	h = cs.ev[i].text[7];
	t_conn = cs.ev[i].t_ms;
	i = sx_wait_event(&cs, "thread 0 stopped: halted by HX", NULL, t_conn,
			  5000);
	t_hx = cs.ev[i].t_ms;
	if (sys_wait_fault(&cs, SX_FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	sx_row_text(r, line);
	i = sx_wait_event(&cs, "relay off", NULL, t_conn, 3000);
	t_relay = cs.ev[i].t_ms;
	t_mo = sx_wait_motors_off(&cs, t_conn, 3000);
	sx_row_reaction(
	    r,
	    "galil-load connected (handle %c), halted %.0f ms later; "
	    "from the halt: relay off %.0f ms (deadline %.0f), "
	    "motors off %.0f ms (deadline %.0f)",
	    h, t_hx - t_conn, t_relay - t_hx, 2.0 * sx_p(&env), t_mo - t_hx,
	    2.0 * sx_p(&env) + SYS_MAINMS);
	snprintf(tpl, sizeof(tpl),
		 "FAULT PROGRAM: controller thread 0 is not running "
		 "(running: none)." SX_OTHER_PROG SX_SAFE_OK REC_THREAD,
		 h);
	sx_expect_text("roboelf's FAULT line", tpl, line, NULL, 0);
	code = load_exit(&re2, 60000);
	if (code != 0)
		fail_msg("galil-load --force exited with %d, not 0\n--- "
			 "stderr:\n%s",
			 code, proc_output(&re2, PROC_STDERR));
	if (sys_check_safe(&cs, 0, SX_HOLD_MS) < 0 ||
	    sys_truth_check(&cs, line, t0, 1u << (h - 'A')) < 0)
		fail_msg("%s", cs.err);
	if (t_relay - t_hx > 2.0 * sx_p(&env) + SX_SLACK_MS ||
	    t_mo - t_hx > 2.0 * sx_p(&env) + SYS_MAINMS + SX_SLACK_MS)
		fail_msg("too late: relay off %.0f ms, motors off %.0f ms "
			 "after the halt",
			 t_relay - t_hx, t_mo - t_hx);
	sx_row_pass(r, "PROGRAM latched naming galil-load's handle, galil-load "
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
	struct sx_row *r = sx_row_begin("4 start-up closes a client");
	char addr[32], want[64], text[SYS_EVT_TEXT], hx, hy;
	double t0, t_y, t_close;
	long long w0, eof_ms;
	int i, status;

	(void)state;
	sx_start(&cs, &fx);
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, SX_EXIT_WAIT_MS, &status) < 0 ||
	    proc_exit_code(&cs.re) != 0)
		fail_msg("the first roboelf did not quit cleanly (exit %d)",
			 proc_exit_code(&cs.re));
	t0 = sys_sim_time(&cs);
	raw_fd = sys_cmd_open(&cs);
	if (raw_fd < 0)
		fail_msg("%s", cs.err);
	hx = sx_handle_of(&cs, raw_fd, t0, &t_y);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", cs.sim.port);
	w0 = proc_now_ms();
	spawn_second(&re2, cs.cfg, addr, cs.relay_link, fx.lock_env);
	if (wait_eof(raw_fd, EOF_MS) < 0)
		fail_msg("the raw client (handle %c) was not closed within "
			 "%d ms of roboelf's start\n--- roboelf:\n%s",
			 hx, EOF_MS, proc_output(&re2, PROC_STDOUT));
	eof_ms = proc_now_ms() - w0;
	snprintf(want, sizeof(want), "handle %c closed by IHT from handle ",
		 hx);
	i = sx_wait_event(&cs, want, NULL, t0, 3000);
	t_close = cs.ev[i].t_ms;
	snprintf(text, sizeof(text), "%s", cs.ev[i].text);
	sx_row_text(r, text);
	hy = text[strlen(text) - 1];
	snprintf(want, sizeof(want), "handle %c closed by IHT from handle %c",
		 hx, hy);
	sx_expect_text("the close event", want, text, NULL, 0);
	snprintf(want, sizeof(want), "handle %c opened from ", hy);
	i = sx_wait_event(&cs, want, NULL, t_y, 1000);
	sx_row_reaction(
	    r,
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
	sx_row_pass(r, "client got EOF; roboelf armed after it");
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_full_calibration),  T(test_second_same_config),
	    T(test_second_same_relay), T(test_second_same_controller),
	    T(test_second_other_host), T(test_load_without_force),
	    T(test_load_force),	       T(test_startup_closes_client),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
