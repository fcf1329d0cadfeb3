/*
 * test_sys_firstcause.c - faults that name their real cause when several
 * things fail together (docs/safety.md H11, D24, D28, D29), on the whole
 * system: galil-sim running dmc/ (downloaded by galil-load), roboelf
 * supervising it through the virtual relay. The cause named first, its
 * consequences after it ("Then:"), and exactly what was confirmed:
 *  - a relay board that swallows its bytes: the relay board named first;
 *  - the supervisor stopped for 2 s (in its sleep, before its first armed
 *    cycle, awaiting a reply): its own stall named first, the controller's
 *    watchdog as "Then:";
 *  - controller and relay lost together: NOT CONFIRMED ... PRESS THE
 *    HARDWARE E-STOP NOW.
 *
 * One full calibration for the binary (group setup), then every case on a
 * fresh galil-sim with `--calibration file`. Every case asserts the
 * outcome, the exact text (sys_exact_h.h) and the reaction time against
 * the deadlines of docs/safety.md section 3 plus SX_SLACK_MS; the group
 * teardown prints the summary table.
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
#include <unistd.h>

#include <cmocka.h>

#include "sys_exact_h.h"
#include "sys_truth.h"

static struct sys_env env;
static struct sx_fixture fx;
static struct sys_case cs; /* the first roboelf and its controller */

static int group_setup(void **state)
{
	(void)state;
	return sx_group_setup(&fx, &env);
}

static int group_teardown(void **state)
{
	(void)state;
	return sx_group_teardown(&fx, 0);
}

static int case_teardown(void **state)
{
	(void)state;
	sys_case_stop(&cs);
	return 0;
}

/* ---- root cause: the relay, the supervisor, the link -------------------- */

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
	struct sx_row *r = sx_row_begin("7 relay board write failing");
	char tpl[2048], line[SX_TEXT_MAX], later[SX_TEXT_MAX];
	double t, t_relay, t_mo, w0, w1, d_pc;
	int i;

	(void)state;
	sx_start(&cs, &fx);
	w0 = sys_wall_ms();
	t = sx_inject(&cs, "inject: ", "relayfault writefail");
	if (sys_wait_fault(&cs, SX_FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	sx_row_text(r, line);
	i = sx_wait_event(&cs, "relay off", NULL, t, 3000);
	t_relay = cs.ev[i].t_ms - t;
	t_mo = sx_wait_motors_off(&cs, t, 3000) - t;
	w1 = log_fault_wall(&cs, " FAULT FAULT ESTOP", 3000);
	d_pc = env.readback_timeout_ms + 3 * sx_p(&env);
	sx_row_reaction(r,
			"power cut by the board %.0f ms, motors off %.0f ms "
			"(deadline M + s = %d); the supervisor's FAULT entry "
			"%.0f ms (deadline R + 3P = %.0f, wall)",
			t_relay, t_mo, SYS_MAINMS + 1, w1 - w0, d_pc);
	/* what the log says of the relay afterwards, for the report */
	if (sys_wait_sim(&cs, t + d_pc + SX_SLACK_MS, 5000) == 0 &&
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
	sx_expect_text("the FAULT line", tpl, line, NULL, 0);
	if (sys_check_safe(&cs, 0, SX_HOLD_MS) < 0 ||
	    sys_truth_check(&cs, line, t, 0) < 0)
		fail_msg("%s", cs.err);
	if (t_mo > SYS_MAINMS + 1 + SX_SLACK_MS || w1 - w0 > d_pc + SX_SLACK_MS)
		fail_msg("too late: motors off %.0f ms, FAULT entry %.0f ms",
			 t_mo, w1 - w0);
	sx_row_pass(r, "the relay board named first");
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
	double hb0 = sx_state_num(c, "var.hbpc");
	char st[SX_TEXT_MAX];

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
	struct sx_row *r = sx_row_begin(name);
	char line[SX_TEXT_MAX], tpl[1024];
	double t_stop, t_cont, t_relay, t_mo, num[3];
	int i, status;

	sx_start(&cs, &fx);
	if (delay_ms > 0 &&
	    (sys_ctl(&cs, "link delay %d", delay_ms) < 0 ||
	     sys_wait_sim(&cs, sys_sim_time(&cs) + 10 * sx_p(&env), 5000) < 0))
		fail_msg("%s", cs.err);
	if (phase_ms >= 0)
		wait_sim_tight(&cs, next_heartbeat(&cs) + phase_ms, 2000);
	t_stop = sys_sim_time(&cs);
	proc_signal(&cs.re, SIGSTOP);
	if (sys_wait_sim(&cs, t_stop + STALL_MS, STALL_MS + 5000) < 0)
		fail_msg("%s", cs.err);
	t_cont = sys_sim_time(&cs);
	proc_signal(&cs.re, SIGCONT);
	if (sys_wait_fault(&cs, SX_FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	sx_row_text(r, line);
	t_mo = sx_wait_motors_off(&cs, t_stop, 3000) - t_stop;
	i = sx_wait_event(&cs, "relay off", NULL, t_stop, 3000);
	t_relay = cs.ev[i].t_ms - t_cont;
	sx_row_reaction(r,
			"motors off %.0f ms after SIGSTOP (deadline W + M + "
			"s = %d), relay off %.0f ms after SIGCONT (deadline "
			"2P = %.0f)",
			t_mo, env.wdto_ms + SYS_MAINMS + 1, t_relay,
			2 * sx_p(&env));
	snprintf(tpl, sizeof(tpl),
		 "FAULT WATCHDOG: this supervisor did not run for {n} ms "
		 "(limit %.0f ms): the PC stalled (suspended, overloaded or "
		 "stopped in a debugger), not the link. Then: the controller "
		 "stopped the robot: no heartbeat from this PC for {n} "
		 "ms." SX_SAFE_OK
		 " Recovery: press the E-stop and keep it pressed, find what "
		 "stopped roboelf (Ctrl-Z, a debugger, CPU or disk load), then "
		 "restart it",
		 env.crit_factor * sx_p(&env));
	sx_expect_text("the FAULT line", tpl, line, num, 3);
	if (num[0] < t_cont - t_stop - 2 * sx_p(&env))
		fail_msg("the stall named is %.0f ms, it was stopped %.0f ms",
			 num[0], t_cont - t_stop);
	if (sys_check_safe(&cs, 0, SX_HOLD_MS) < 0 ||
	    sys_truth_check(&cs, line, t_stop, 0) < 0)
		fail_msg("%s", cs.err);
	if (t_mo > env.wdto_ms + SYS_MAINMS + 1 + SX_SLACK_MS ||
	    t_relay > 2 * sx_p(&env) + SX_SLACK_MS)
		fail_msg("too late: motors off %.0f ms after SIGSTOP, relay "
			 "off %.0f ms after SIGCONT",
			 t_mo, t_relay);
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, SX_EXIT_WAIT_MS, &status) < 0 ||
	    proc_exit_code(&cs.re) != 4)
		fail_msg("roboelf did not exit 4 (exit %d)",
			 proc_exit_code(&cs.re));
	sx_row_pass(r, "the stall named first, the controller's watchdog as "
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
	struct sx_row *r = sx_row_begin("7 controller and relay lost");
	char a1[64], a2[64], line[SX_TEXT_MAX], tpl[2048];
	double t0, t_link, t_relay, t_off, t_mo, w0, w1;
	int i;

	(void)state;
	sx_start(&cs, &fx);
	t0 = sys_sim_time(&cs);
	w0 = sys_wall_ms();
	if (send(cs.ctl, burst, sizeof(burst) - 1, MSG_NOSIGNAL) !=
		(ssize_t)(sizeof(burst) - 1) ||
	    ctl_line(cs.ctl, a1, sizeof(a1), 2000) < 0 ||
	    ctl_line(cs.ctl, a2, sizeof(a2), 2000) < 0 || strcmp(a1, "ok") ||
	    strcmp(a2, "ok"))
		fail_msg("the burst was not taken");
	i = sx_wait_event(&cs, "inject: link drop", NULL, t0, 2000);
	t_link = cs.ev[i].t_ms;
	i = sx_wait_event(&cs, "inject: relayfault unplug", NULL, t0, 2000);
	t_relay = cs.ev[i].t_ms;
	if (sys_wait_fault(&cs, SX_FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	sx_row_text(r, line);
	w1 = log_fault_wall(&cs, " FAULT FAULT ", 3000);
	i = sx_wait_event(&cs, "relay off", NULL, t0, 3000);
	t_off = cs.ev[i].t_ms - t_relay;
	t_mo = sx_wait_motors_off(&cs, t_relay, 3000) - t_relay;
	sx_row_reaction(r,
			"both injected at +%.0f / +%.0f ms; power cut %.0f ms "
			"and motors off %.0f ms (deadline M + s = %d) after "
			"the unplug; the FAULT entry %.0f ms after the burst "
			"(deadline 2P + fresh stop = %.0f, wall)",
			t_link - t0, t_relay - t0, t_off, t_mo, SYS_MAINMS + 1,
			w1 - w0, 2 * sx_p(&env) + FRESH_STOP_MS);
	if (sys_check_safe(&cs, 0, SX_HOLD_MS) < 0 ||
	    sys_truth_check(&cs, line, t0, 0) < 0)
		fail_msg("%s", cs.err);
	if (t_mo > SYS_MAINMS + 1 + SX_SLACK_MS)
		fail_msg("motors off %.0f ms after the unplug", t_mo);
	if (!strstr(line, "NOT CONFIRMED") ||
	    !strstr(line, "PRESS THE HARDWARE E-STOP NOW"))
		fail_msg("the line does not say NOT CONFIRMED ... PRESS THE "
			 "HARDWARE E-STOP NOW:\n  %s",
			 line);
	snprintf(tpl, sizeof(tpl),
		 "FAULT ESTOP: the E-stop relay stopped answering (relay '%s': "
		 "link lost (hang-up)). NOT CONFIRMED: relay open not "
		 "confirmed; stop command not delivered ({s}); motors off not "
		 "confirmed; PRESS THE HARDWARE E-STOP NOW. Recovery: press "
		 "the hardware E-stop now, check the relay's USB cable and "
		 "power, then restart roboelf",
		 cs.relay_link);
	sx_expect_text("the FAULT line", tpl, line, NULL, 0);
	if (w1 - w0 > 2 * sx_p(&env) + FRESH_STOP_MS + SX_SLACK_MS)
		fail_msg("the FAULT entry came %.0f ms after the burst",
			 w1 - w0);
	sx_row_pass(r, "NOT CONFIRMED, press the hardware E-stop");
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_relay_writefail),	 T(test_sigstop),
	    T(test_sigstop_first_cycle), T(test_sigstop_in_round_trip),
	    T(test_link_and_relay_lost),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
