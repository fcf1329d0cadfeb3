/*
 * test_sys_stream.c - the record as a stream (controller.record: stream,
 * docs/link.md "The record as a stream: the cycle") end to end, whatever
 * ROBOELF_SYS_RECORD says: every case writes record: stream into its own
 * configuration. On the armed robot, A jogging:
 *   - another client stops the stream (DR 0), or closes its UDP handle
 *     (IHT=>-1): WATCHDOG "no data record", relay off within C + P;
 *   - galil-sim loses every record (link stall stream) while the command
 *     connection answers: the same;
 *   - galil-sim loses every TCP frame (link stall tcp) while records keep
 *     coming: WATCHDOG (the program's echo of the heartbeat stops, or its
 *     own watchdog, whichever first), relay off within C + P;
 *   - the records 40 ms late (link delay 40 stream), at rest: no fault
 *     for 3 s, still armed;
 * each FAULT checked against galil-sim's event log (sys_truth). Each case
 * prints one "[ ROW      ]" line: what | relay off ms | FAULT line.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "sys_h.h"
#include "sys_truth.h"

#define SLACK_MS      25  /* scheduling allowance on a busy 2-core box */
#define HOLD_MS	      300 /* no motion over this after the safe state */
#define FAULT_WAIT_MS 5000
#define QUIET_MS      3000 /* no fault over this under a tolerable delay */

static struct sys_env env;
static int env_ok;
static struct sys_case cs; /* stopped by the teardown, also after a failure */
static const struct sys_subst stream_cfg[] = {{"record", "stream"},
					      {NULL, NULL}};

/* The relay off after the stream stops, at the latest: the record's age
 * passes C at the first cycle after it, P later at most. */
static double d_stop_to_relay(void)
{
	return env.crit_factor * env.period_ms + env.period_ms + SLACK_MS;
}

/* A fresh armed robot on the stream, A jogging (@jog) or at rest. */
static void start_armed(struct sys_case *c, int jog)
{
	struct sys_opts o = {.subst = stream_cfg};
	char line[512];

	if (!env_ok)
		fail_msg("no calibrated environment: %s", env.err);
	if (sys_case_start(c, &env, &o) < 0)
		fail_msg("case start: %s", c->err);
	if (proc_find_line(&c->re, PROC_STDOUT, "roboelf: record stream: ",
			   line, sizeof(line)) < 0)
		fail_msg("no 'record stream' line: roboelf polls");
	if (jog && (sys_ctl(c, "joy A fwd") < 0 ||
		    sys_wait_moving(c, 'A', 300, 3000) < 0))
		fail_msg("jogging A: %s", c->err);
}

/* The FAULT after @what (at simulated @t0), its class, the relay's time,
 * the safe state, the truth. */
static void expect_trip(struct sys_case *c, const char *what, double t0,
			const char *prefix)
{
	char line[2048];
	double t_relay;

	if (sys_wait_fault(c, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("'%s': no FAULT line: %s", what, c->err);
	if (sys_wait_event(c, "relay off", t0, 3000, &t_relay) < 0)
		fail_msg("'%s': no relay off: %s", what, c->err);
	if (sys_ctl(c, "joy A neutral") < 0 || sys_check_safe(c, 0, HOLD_MS) < 0)
		fail_msg("'%s': not safe: %s", what, c->err);
	if (sys_truth_check(c, line, t0, 0) < 0)
		fail_msg("'%s': %s", what, c->err);
	print_message("[ ROW      ] %s | relay off %.0f ms (bound %.0f) | %s\n",
		      what, t_relay - t0, d_stop_to_relay(), line);
	if (strncmp(line, prefix, strlen(prefix)))
		fail_msg("'%s': not '%s...': %s", what, prefix, line);
	if (t_relay - t0 > d_stop_to_relay())
		fail_msg("'%s': relay off %.0f ms after (bound %.0f)", what,
			 t_relay - t0, d_stop_to_relay());
}

/* Another client's write to the controller stops the stream. */
static void foreign_write(const char *write)
{
	double t0;
	int fd;

	start_armed(&cs, 1);
	fd = sys_cmd_open(&cs);
	if (fd < 0)
		fail_msg("%s", cs.err);
	t0 = sys_sim_time(&cs);
	(void)sys_cmd(fd, write, 1000);
	close(fd);
	expect_trip(&cs, write, t0,
		    "FAULT WATCHDOG: no data record from the controller for ");
}

static void test_dr_stopped(void **state)
{
	(void)state;
	foreign_write("DR 0");
}

static void test_udp_handle_closed(void **state)
{
	(void)state;
	foreign_write("IHT=>-1");
}

/* galil-sim loses every record; TCP answers. */
static void test_stream_stalled(void **state)
{
	double t0;

	(void)state;
	start_armed(&cs, 1);
	t0 = sys_sim_time(&cs);
	if (sys_ctl(&cs, "link stall stream") < 0)
		fail_msg("%s", cs.err);
	expect_trip(&cs, "link stall stream", t0,
		    "FAULT WATCHDOG: no data record from the controller for ");
}

/* galil-sim loses every TCP reply; records keep coming. The program's
 * own watchdog misses the heartbeat too: either is the first cause. */
static void test_tcp_stalled(void **state)
{
	double t0;

	(void)state;
	start_armed(&cs, 1);
	t0 = sys_sim_time(&cs);
	if (sys_ctl(&cs, "link stall tcp") < 0)
		fail_msg("%s", cs.err);
	expect_trip(&cs, "link stall tcp", t0, "FAULT WATCHDOG: ");
}

/* Records 40 ms late (at rest: 3 s of jogging would reach the soft
 * limit): every limit holds, no fault, still armed. */
static void test_delay_tolerated(void **state)
{
	char line[2048];

	(void)state;
	start_armed(&cs, 0);
	if (sys_ctl(&cs, "watch state") < 0 ||
	    sys_ctl(&cs, "link delay 40 stream") < 0)
		fail_msg("%s", cs.err);
	if (sys_wait_fault(&cs, QUIET_MS, line, sizeof(line)) == 0)
		fail_msg("a FAULT under a 40 ms delay: %s", line);
	if (sys_still_armed(&cs, "after 3 s of records 40 ms late") < 0)
		fail_msg("%s", cs.err);
	print_message("[ ROW      ] link delay 40 stream | no fault in %d ms "
		      "| still armed\n",
		      QUIET_MS);
}

static int case_teardown(void **state)
{
	(void)state;
	sys_case_stop(&cs);
	return 0;
}

static int group_setup(void **state)
{
	(void)state;
	env_ok = sys_env_ready(&env);
	return 0;
}

static int group_teardown(void **state)
{
	(void)state;
	sys_env_done(&env, env_ok);
	return 0;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_teardown(test_dr_stopped, case_teardown),
	    cmocka_unit_test_teardown(test_udp_handle_closed, case_teardown),
	    cmocka_unit_test_teardown(test_stream_stalled, case_teardown),
	    cmocka_unit_test_teardown(test_tcp_stalled, case_teardown),
	    cmocka_unit_test_teardown(test_delay_tolerated, case_teardown),
	};

	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
