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
 *   - another client slows the stream on our handle: to a record every
 *     100 ms (under C), no fault for 3 s, still armed, the late records
 *     warned as counted; to one every 200 ms (past C), WATCHDOG;
 * each FAULT checked against galil-sim's event log (sys_truth). Each case
 * prints one "[ ROW      ]" line: what | relay off ms | FAULT line.
 * And the facts roboelf prints about the stream, against galil-sim's
 * events: the start-up's "record stream: UDP handle X, every N samples
 * ...; measured over M records I ms (lo-hi)" line against the DR that
 * galil-sim executed, and the end-of-run "stream:" counters (after a quit)
 * against the records galil-sim made.
 */
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "re_linkmeas.h"
#include "sys_h.h"
#include "sys_truth.h"

#define SLACK_MS      25  /* scheduling allowance on a busy 2-core box */
#define HOLD_MS	      300 /* no motion over this after the safe state */
#define FAULT_WAIT_MS 5000
#define QUIET_MS      3000 /* no fault over this under a tolerable delay */
#define EXIT_MS	      5000 /* SIGTERM to roboelf's exit */
#define EVENT_MS      3000 /* an event galil-sim logs, its deadline */
#define SIM_SAMPLE_MS 1.0  /* galil-sim's servo sample (its default) */
#define PRINT_MS      0.05 /* half the last printed digit of "%.1f" */
/* roboelf's nominal interval is n0 samples of a DMC-4030 at TM 1000
 * (1000/1024 ms: docs/link.md), 2.4 % shorter than galil-sim's 1 ms */
#define DMC_SHORT     (1.0 - 1000.0 / 1024.0)

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

/* The FAULT after @what (at simulated @t0), its class, the relay's time
 * (bound: d_stop_to_relay() after the last record, which may come up to
 * @late_ms after @t0), the safe state, the truth. */
static void expect_trip(struct sys_case *c, const char *what, double t0,
			double late_ms, const char *prefix)
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
		      what, t_relay - t0, late_ms + d_stop_to_relay(), line);
	if (strncmp(line, prefix, strlen(prefix)))
		fail_msg("'%s': not '%s...': %s", what, prefix, line);
	if (t_relay - t0 > late_ms + d_stop_to_relay())
		fail_msg("'%s': relay off %.0f ms after (bound %.0f)", what,
			 t_relay - t0, late_ms + d_stop_to_relay());
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
	expect_trip(&cs, write, t0, 0,
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
	expect_trip(&cs, "link stall stream", t0, 0,
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
	expect_trip(&cs, "link stall tcp", t0, 0, "FAULT WATCHDOG: ");
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

/* What roboelf's start-up line says about the stream. */
struct meas_line {
	char handle;
	unsigned n0;
	double nominal_ms, mean_ms, lo_ms, hi_ms, reply_ms, reply_max_ms;
	int records;
};

/* Parse the whole line, or fail: a clause between "(lo-hi)" and "; command
 * reply" (", a record every X samples by their numbers (not N: ...)") is
 * the records' own sample numbers disagreeing with N, and fails too. */
static void parse_meas(const char *line, struct meas_line *m)
{
	int end = -1;

	if (sscanf(line,
		   "roboelf: record stream: UDP handle %c, every %u samples "
		   "(%lf ms); measured over %d records %lf ms (%lf-%lf); "
		   "command reply %lf ms (max %lf)%n",
		   &m->handle, &m->n0, &m->nominal_ms, &m->records, &m->mean_ms,
		   &m->lo_ms, &m->hi_ms, &m->reply_ms, &m->reply_max_ms,
		   &end) != 9 ||
	    end != (int)strlen(line))
		fail_msg("not the measurement line of a whole stream: '%s'",
			 line);
}

/* The one "handle X: data record every N samples (handle Y)" event of the
 * case (roboelf's DR): X, N and Y. */
static void dr_event(struct sys_case *c, char *handle, unsigned *n0, char *who)
{
	int found = 0, end;

	if (sys_events(c) < 0)
		fail_msg("%s", c->err);
	for (size_t i = 0; i < c->nev; i++) {
		end = -1;
		if (!strstr(c->ev[i].text, ": data record every "))
			continue;
		if (sscanf(c->ev[i].text,
			   "handle %c: data record every %u samples (handle "
			   "%c)%n",
			   handle, n0, who, &end) != 3 ||
		    end != (int)strlen(c->ev[i].text))
			fail_msg("galil-sim's DR event is not as documented: "
				 "'%s'",
				 c->ev[i].text);
		found++;
	}
	if (found != 1)
		fail_msg("%d DR events in galil-sim's log, want 1", found);
}

/* An event "@prefix... (UDP)": a UDP peer took that handle. */
static int udp_opened(const struct sys_case *c, const char *prefix)
{
	size_t n;

	for (size_t i = 0; i < c->nev; i++) {
		n = strlen(c->ev[i].text);
		if (!strncmp(c->ev[i].text, prefix, strlen(prefix)) && n > 6 &&
		    !strcmp(c->ev[i].text + n - 6, " (UDP)"))
			return 1;
	}
	return 0;
}

/* The start-up's measurement line, against the DR galil-sim executed:
 * the same UDP handle and n0, and an interval of n0 of galil-sim's 1 ms
 * samples. The mean is taken over the times of arrival of M records, each
 * made by galil-sim at an exact multiple of n0 samples (its timer keeps
 * its clock on the wall clock, catching up after a late wake-up) and
 * delivered after it by 0 to SLACK_MS of scheduling on this busy box: the
 * mean's error is at most SLACK_MS / (M - 1), plus the printed rounding.
 * The records' own sample numbers agree with n0 exactly (parse_meas()). */
static void check_meas(struct sys_case *c, const struct meas_line *m)
{
	char handle, who, udp[64];
	unsigned n0;
	double want = 0, tol_ms;

	dr_event(c, &handle, &n0, &who);
	if (m->handle != handle || m->n0 != n0)
		fail_msg("roboelf says UDP handle %c every %u samples; "
			 "galil-sim ran DR %u to handle %c",
			 m->handle, m->n0, n0, handle);
	snprintf(udp, sizeof(udp), "handle %c opened from ", handle);
	if (!udp_opened(c, udp))
		fail_msg("no '%s... (UDP)' event: handle %c is not a UDP "
			 "handle",
			 udp, handle);
	/* more when the last read found several records waiting */
	if (m->records < RE_LINKMEAS_RECORDS || m->records > RE_LINKMEAS_MAX)
		fail_msg("measured over %d records, want %d..%d", m->records,
			 RE_LINKMEAS_RECORDS, RE_LINKMEAS_MAX);
	want = n0 * SIM_SAMPLE_MS;
	if (fabs(m->nominal_ms - want) > want * DMC_SHORT + PRINT_MS)
		fail_msg("nominal %.1f ms for %u samples (galil-sim: %.1f)",
			 m->nominal_ms, n0, want);
	tol_ms = (double)SLACK_MS / (m->records - 1) + PRINT_MS;
	if (fabs(m->mean_ms - want) > tol_ms)
		fail_msg("measured %.1f ms a record; galil-sim sent one every "
			 "%.1f ms (tolerance %.2f ms)",
			 m->mean_ms, want, tol_ms);
	if (m->lo_ms > m->mean_ms + PRINT_MS ||
	    m->hi_ms < m->mean_ms - PRINT_MS ||
	    m->reply_ms > m->reply_max_ms + PRINT_MS)
		fail_msg("a mean outside its min-max, or a median above its "
			 "max: %.2f (%.2f-%.2f), reply %.2f (max %.2f)",
			 m->mean_ms, m->lo_ms, m->hi_ms, m->reply_ms,
			 m->reply_max_ms);
	print_message("[ ROW      ] start-up line | handle %c, %u samples, "
		      "%.1f ms over %d (tolerance %.2f) | galil-sim: DR %u,%d "
		      "from handle %c\n",
		      m->handle, m->n0, m->mean_ms, m->records, tol_ms, n0,
		      handle - 'A', who);
}

/* The counters of the end-of-run "stream:" log line. */
struct stream_counts {
	unsigned long long dgrams, records, lost, dup, reord, supers, foreign,
	    shorts, longs, malformed, refused;
};

static void parse_counts(const char *line, struct stream_counts *k)
{
	const char *p = strstr(line, "stream: datagrams=");
	int end = -1;

	if (!p ||
	    sscanf(p,
		   "stream: datagrams=%llu records=%llu lost=%llu "
		   "duplicates=%llu reordered=%llu superseded=%llu "
		   "foreign=%llu short=%llu long=%llu malformed=%llu; "
		   "heartbeat lines refused=%llu%n",
		   &k->dgrams, &k->records, &k->lost, &k->dup, &k->reord,
		   &k->supers, &k->foreign, &k->shorts, &k->longs,
		   &k->malformed, &k->refused, &end) != 11 ||
	    end != (int)strlen(p))
		fail_msg("not the stream counters line: '%s'", line);
}

/* After a quit: the "stream:" counters against the records galil-sim made
 * from roboelf's DR to its DR 0 (the stop event's count). On loopback with
 * no fault galil-sim sends each record once, in order, one a datagram:
 * nothing duplicated, reordered, foreign, short, long or malformed; every
 * datagram counts in exactly one verdict; a record received or counted lost
 * was made (datagrams + lost <= made). How many of the made ones were still
 * on their way when roboelf stopped reading is not known to galil-sim: not
 * checked, printed. */
static void check_counts(struct sys_case *c, char handle, char who)
{
	char line[1024], prefix[96];
	struct stream_counts k;
	unsigned long long made;
	double t;
	int i, end = -1;

	if (sys_log_find(c, "stream: datagrams=", NULL, line, sizeof(line)) < 0)
		fail_msg("no stream counters in the log");
	parse_counts(line, &k);
	snprintf(prefix, sizeof(prefix),
		 "handle %c: data record stopped: DR 0 (handle %c); records "
		 "made: ",
		 handle, who);
	if (sys_wait_event(c, prefix, 0, EVENT_MS, &t) < 0)
		fail_msg("no '%s' event: %s", prefix, c->err);
	i = sys_event_find(c, prefix, 0);
	if (sscanf(c->ev[i].text + strlen(prefix), "%llu%n", &made, &end) !=
		1 ||
	    end != (int)strlen(c->ev[i].text + strlen(prefix)))
		fail_msg("galil-sim's stop event: '%s'", c->ev[i].text);
	if (k.dgrams != k.records + k.dup + k.reord + k.supers + k.foreign +
			    k.shorts + k.longs + k.malformed)
		fail_msg("datagrams=%llu is not the sum of the verdicts: %s",
			 k.dgrams, line);
	if (k.dup || k.reord || k.foreign || k.shorts || k.longs || k.malformed)
		fail_msg("a verdict galil-sim cannot cause on loopback: %s",
			 line);
	if (k.records == 0 || k.dgrams + k.lost > made)
		fail_msg("%llu datagrams and %llu lost, but galil-sim made "
			 "%llu records: %s",
			 k.dgrams, k.lost, made, line);
	print_message("[ ROW      ] end-of-run counters | datagrams %llu "
		      "(records %llu, superseded %llu) lost %llu | galil-sim "
		      "made %llu, %llu not read by the end\n",
		      k.dgrams, k.records, k.supers, k.lost, made,
		      made - k.dgrams - k.lost);
}

/* The start-up's measurement line and, after a quit, the end-of-run
 * counters, each against galil-sim's events. */
static void test_printed_facts(void **state)
{
	struct meas_line m;
	char line[512], handle, who;
	unsigned n0;
	int status;

	(void)state;
	start_armed(&cs, 0);
	if (proc_find_line(&cs.re, PROC_STDOUT, "roboelf: record stream: ",
			   line, sizeof(line)) < 0)
		fail_msg("no 'record stream' line");
	parse_meas(line, &m);
	check_meas(&cs, &m);
	if (proc_signal(&cs.re, SIGTERM) < 0 ||
	    proc_wait_exit(&cs.re, EXIT_MS, &status) < 0)
		fail_msg("roboelf did not exit within %d ms of SIGTERM",
			 EXIT_MS);
	if (proc_exit_code(&cs.re) != 0)
		fail_msg("roboelf exited %d after SIGTERM, want 0",
			 proc_exit_code(&cs.re));
	dr_event(&cs, &handle, &n0, &who);
	check_counts(&cs, handle, who);
}

/* Another client's "DR @n0,<our handle>" (the handle from roboelf's
 * start-up line), armed at rest; the simulated time of the write. */
static double foreign_dr(struct sys_case *c, unsigned n0)
{
	struct meas_line m;
	char line[512], cmd[32];
	double t0;
	int fd, rc;

	start_armed(c, 0);
	if (proc_find_line(&c->re, PROC_STDOUT, "roboelf: record stream: ",
			   line, sizeof(line)) < 0)
		fail_msg("no 'record stream' line");
	parse_meas(line, &m);
	snprintf(cmd, sizeof(cmd), "DR %u,%d", n0, m.handle - 'A');
	fd = sys_cmd_open(c);
	if (fd < 0)
		fail_msg("%s", c->err);
	t0 = sys_sim_time(c);
	rc = sys_cmd(fd, cmd, 1000);
	close(fd);
	if (rc != 0)
		fail_msg("'%s' from another client: %s", cmd,
			 rc > 0 ? "refused (?)" : "no answer");
	return t0;
}

/* Another client slows the stream to a record every 100 samples (100 ms,
 * under C = 125 ms): each record is judged as it comes, within the
 * limits, so no fault; the cycles that find none warn (late records), as
 * the log and the supervisor's own count say after the quit. */
static void test_dr_slowed_within(void **state)
{
	char line[2048];
	long counted, logged;
	int status;

	(void)state;
	foreign_dr(&cs, 100);
	if (sys_ctl(&cs, "watch state") < 0)
		fail_msg("%s", cs.err);
	if (sys_wait_fault(&cs, QUIET_MS, line, sizeof(line)) == 0)
		fail_msg("a FAULT with a record every 100 ms: %s", line);
	if (sys_still_armed(&cs, "after 3 s of a record every 100 ms") < 0)
		fail_msg("%s", cs.err);
	if (proc_signal(&cs.re, SIGTERM) < 0 ||
	    proc_wait_exit(&cs.re, EXIT_MS, &status) < 0)
		fail_msg("roboelf did not exit within %d ms of SIGTERM",
			 EXIT_MS);
	counted = sys_wd_counter(&cs);
	logged = sys_wd_warnings(&cs, NULL, NULL);
	if (counted < 1 || logged != counted)
		fail_msg("late records: %ld counted, %ld in the log (want the "
			 "same, at least 1)",
			 counted, logged);
	print_message("[ ROW      ] DR 100 (another client) | no fault in %d "
		      "ms, still armed | %ld late-record warnings\n",
		      QUIET_MS, counted);
}

/* Slowed past C (a record every 200 samples): the record's age passes C,
 * WATCHDOG, relay off within C + P of the last record, which may come up
 * to 200 samples after the write (galil-sim starts the new interval at
 * the DR, so its last record is the one before; a real controller's phase
 * is not documented). */
static void test_dr_slowed_past(void **state)
{
	double t0;

	(void)state;
	t0 = foreign_dr(&cs, 200);
	expect_trip(&cs, "DR 200", t0, 200 * SIM_SAMPLE_MS,
		    "FAULT WATCHDOG: no data record from the controller for ");
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
	    cmocka_unit_test_teardown(test_printed_facts, case_teardown),
	    cmocka_unit_test_teardown(test_dr_slowed_within, case_teardown),
	    cmocka_unit_test_teardown(test_dr_slowed_past, case_teardown),
	};

	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
