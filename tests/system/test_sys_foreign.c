/*
 * test_sys_foreign.c - one master: commands from another program are
 * faults (docs/safety.md H9, D19, D20), on the whole system: galil-sim
 * running dmc/ (downloaded by galil-load), roboelf supervising it through
 * the virtual relay.
 *
 * One full calibration for the binary (group setup), then every case on a
 * fresh galil-sim with `--calibration file`:
 *  5. a client that connects while armed and starts a move (PA or JG, BG):
 *     MOTION (a move another program started) naming its handle, and how
 *     far the axis went;
 *  6. after roboelf is killed, a naive client writing hbpc=1, 2, 3 ...
 *     does not keep the robot alive (FOREIGN heartbeat, motors off).
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

/* Recovery text of the MOTION fault of another program's move, as
 * roboelf prints it (pc/super/re_fault.c; docs/operator.md section 7). */
#define REC_UNCMD                                                              \
	" Recovery: press the E-stop and keep it pressed, find which other "   \
	"program or person sent commands to the controller (another "          \
	"roboelf, galil-load, a terminal) and stop it, then restart roboelf"

static struct sys_env env;
static struct sx_fixture fx;
static struct sys_case cs; /* the first roboelf and its controller */
static int raw_fd = -1;	   /* a raw client of the controller */

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
	if (raw_fd >= 0)
		close(raw_fd);
	raw_fd = -1;
	sys_case_stop(&cs);
	return 0;
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

/* ---- a raw client ---------------------------------------------------------
 */

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
	struct sx_row *r = sx_row_begin(name);
	char line[SX_TEXT_MAX], tpl[1024], ans[64] = "", ans2[64] = "", h;
	double t0, t_conn, t_relay, t_mo, a0, a1;
	int i;

	sx_start(&cs, &fx);
	a0 = sx_state_num(&cs, "A.act");
	t0 = sys_sim_time(&cs);
	raw_fd = sys_cmd_open(&cs);
	if (raw_fd < 0)
		fail_msg("%s", cs.err);
	raw_cmd(raw_fd, line1, 1000, ans, sizeof(ans));
	if (ans[0] == '?') { /* the controller does not take the line */
		raw_cmd(raw_fd, cmd1, 1000, ans, sizeof(ans));
		raw_cmd(raw_fd, cmd2, 1000, ans2, sizeof(ans2));
	}
	h = sx_handle_of(&cs, raw_fd, t0, &t_conn);
	if (sys_wait_fault(&cs, SX_FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	sx_row_text(r, line);
	i = sx_wait_event(&cs, "relay off", NULL, t_conn, 3000);
	t_relay = cs.ev[i].t_ms;
	t_mo = sx_wait_motors_off(&cs, t_conn, 3000);
	if (sys_check_safe(&cs, 0, SX_HOLD_MS) < 0 ||
	    sys_truth_check(&cs, line, t0, 1u << (h - 'A')) < 0)
		fail_msg("%s", cs.err);
	a1 = sx_state_num(&cs, "A.act");
	i = sys_event_find(&cs, "axis A begin", t0);
	sx_row_reaction(r,
			"from the connection (handle %c): relay off %.0f ms "
			"(deadline %.0f), motors off %.0f ms (deadline %d); "
			"answers '%s%s%s'; axis A travel %.0f counts (bound "
			"%d)%s",
			h, t_relay - t_conn, sx_d_ctrl_to_relay(&env),
			t_mo - t_conn, SYS_MAINMS + 1, ans,
			ans2[0] ? "' then '" : "", ans2, a1 - a0, TRAVEL_BOUND,
			i >= 0 ? "; the move began" : "; no move began");
	snprintf(tpl, sizeof(tpl),
		 "FAULT MOTION: axis A: the controller stopped motion its "
		 "program did not command: a move started by another "
		 "program." SX_OTHER_PROG SX_SAFE_OK REC_UNCMD,
		 h);
	sx_expect_text("the FAULT line", tpl, line, NULL, 0);
	if (fabs(a1 - a0) > TRAVEL_BOUND)
		fail_msg("axis A travelled %.0f counts (bound %d)", a1 - a0,
			 TRAVEL_BOUND);
	if (t_relay - t_conn > sx_d_ctrl_to_relay(&env) + SX_SLACK_MS ||
	    t_mo - t_conn > SYS_MAINMS + 1 + SX_SLACK_MS)
		fail_msg("too late: relay off %.0f ms, motors off %.0f ms",
			 t_relay - t_conn, t_mo - t_conn);
	sx_row_pass(r,
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
	struct sx_row *r = sx_row_begin("6 killed, naive hbpc=n writer");
	double t_kill, t_conn, t_off, hm0, fcode, fdet, d;
	char h, st[SX_TEXT_MAX], text[256];
	int ok, refused, closed, i;

	(void)state;
	sx_start(&cs, &fx);
	if (sys_ctl(&cs, "watch hm0") < 0)
		fail_msg("%s", cs.err);
	hm0 = sx_state_num(&cs, "var.hm0");
	t_kill = sys_sim_time(&cs);
	proc_signal(&cs.re, SIGKILL);
	proc_wait_exit(&cs.re, SX_EXIT_WAIT_MS, NULL);
	raw_fd = sys_cmd_open(&cs);
	if (raw_fd < 0)
		fail_msg("%s", cs.err);
	ok = naive_heartbeat(raw_fd, &refused, &closed);
	h = sx_handle_of(&cs, raw_fd, t_kill, &t_conn);
	t_off = sx_wait_motors_off(&cs, t_kill, 3000);
	if (sys_check_safe(&cs, 1, SX_HOLD_MS) < 0 ||
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
	sx_row_text(r, text);
	sx_row_reaction(r,
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
	if (t_off - t_kill > d + SX_SLACK_MS)
		fail_msg("motors off %.0f ms after the kill, deadline %.0f ms",
			 t_off - t_kill, d);
	sx_row_pass(r, "FOREIGN heartbeat (14, 1) latched; motors off and "
		       "kept off");
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_foreign_pa),
	    T(test_foreign_jg),
	    T(test_kill_naive_heartbeat),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
