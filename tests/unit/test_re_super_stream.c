/*
 * test_re_super_stream.c - the supervisor cycle in the stream design
 * (re_super_stream.c: re_super_cfg.stream = 1) against a fake controller
 * behind struct re_io: records arrive by the stream op (none, one, or a
 * fresh one per cycle as the test says), the heartbeat is posted and its
 * reply collected in the next cycle. Covers: one post per cycle and never
 * two outstanding, a lost record costing nothing, the record's, the
 * acknowledgement's and the echo's ages against the critical limit (exact
 * ms in the FAULT), a reply taken by another command, a refused line, and
 * no allocation in the cycle. No sockets, no sleeping.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "gl_err.h"
#include "re_super_int.h"

#define MS	  1000000LL
#define PERIOD_MS 50

/* ---- allocation counter (linked with --wrap, see .ldflags) --------------- */

static long n_allocs;
void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t m);
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t m);

void *__wrap_malloc(size_t n)
{
	n_allocs++;
	return __real_malloc(n);
}

void *__wrap_calloc(size_t n, size_t m)
{
	n_allocs++;
	return __real_calloc(n, m);
}

/* ---- the fake world ------------------------------------------------------ */

struct fake {
	int64_t now;
	struct gl_record rec;
	int stream_off;	   /* no record arrives */
	int drop_next;	   /* the next cycle's record is lost */
	int ack_stall;	   /* collect: never complete */
	int cmd_rc;	   /* command: fails with this (0: answers) */
	int zab_state;	   /* ZAB below the echo: state + 10 * fcode */
	int latch_zab;	   /* zab_state once a command failed (0: kept) */
	int collect_rc;	   /* collect: this error once (0: none) */
	long echo_frozen;  /* >= 0: the program echoes this, not the last */
	long last_hb;	   /* the value of the last "hbpc=N" posted */
	int posted;	   /* lines outstanding (the fake's view) */
	int n_posts, n_collects, n_busy;
	char last_post[96];
	int n_relay_off;
	char commands[16][96];
	int n_commands;
	char logs[8][2560];
	int n_logs;
};

static struct fake fk;

static int f_post(void *ud, const char *line)
{
	(void)ud;
	if (fk.posted >= GL_LINK_POST_MAX) {
		fk.n_busy++;
		return GL_ERR_BUSY;
	}
	fk.n_posts++;
	fk.posted++;
	snprintf(fk.last_post, sizeof(fk.last_post), "%s", line);
	fk.last_hb = strtol(line + 5, NULL, 10);
	return GL_OK;
}

static int f_collect(void *ud, char *text, size_t cap)
{
	int rc = fk.collect_rc;

	(void)ud;
	if (!fk.posted)
		return GL_ERR_NOENT;
	if (fk.ack_stall)
		return GL_ERR_AGAIN;
	fk.n_collects++;
	fk.posted--;
	fk.collect_rc = 0;
	if (rc)
		return rc;
	snprintf(text, cap, "%s", "");
	return 0;
}

static int f_stream(void *ud, struct gl_record *rec, int64_t now_ns)
{
	long echo = fk.echo_frozen >= 0 ? fk.echo_frozen : fk.last_hb;

	(void)ud;
	(void)now_ns;
	if (fk.stream_off)
		return 0;
	if (fk.drop_next) {
		fk.drop_next = 0;
		return 0;
	}
	fk.rec.sample += 50;
	fk.rec.axis[0].za = (fk.rec.axis[0].za + 5) % 1000000;
	fk.rec.axis[1].za = fk.zab_state + (int32_t)(echo % 10000) * 10000;
	*rec = fk.rec;
	return 1;
}

static int f_stream_counts(void *ud, uint64_t *records, uint64_t *lost)
{
	(void)ud;
	*records = 4998;
	*lost = 2;
	return 0;
}

static int f_record(void *ud, const char *prefix, struct gl_record *rec,
		    int timeout_ms)
{
	(void)ud;
	(void)prefix;
	(void)rec;
	(void)timeout_ms;
	fail_msg("the stream design made a QR round trip");
	return GL_ERR_ARG;
}

static int f_command(void *ud, const char *cmd, char *resp, size_t cap,
		     int timeout_ms)
{
	(void)ud;
	(void)timeout_ms;
	fk.posted = 0; /* another exchange takes the posted reply first */
	if (fk.n_commands < 16)
		snprintf(fk.commands[fk.n_commands++], 96, "%s", cmd);
	if (fk.cmd_rc) {
		/* the program goes on while the command waits */
		if (fk.latch_zab)
			fk.zab_state = fk.latch_zab;
		return fk.cmd_rc;
	}
	snprintf(resp, cap, "%s", strncmp(cmd, "MG _MO", 6) ? " 0.0000"
							   : " 1.0000");
	return (int)strlen(resp);
}

static const char *f_ctrl_error(void *ud, int *code)
{
	(void)ud;
	if (code)
		*code = 1;
	return "Unrecognized command";
}

static int f_message(void *ud, char *line, size_t cap)
{
	(void)ud;
	(void)line;
	(void)cap;
	return GL_ERR_AGAIN;
}

static int f_relay_check(void *ud, char *why, size_t cap)
{
	(void)ud;
	(void)why;
	(void)cap;
	return GL_OK;
}

static int f_relay_off(void *ud)
{
	(void)ud;
	fk.n_relay_off++;
	return GL_OK;
}

static int f_relay_off_finish(void *ud, int deadline_ms)
{
	(void)ud;
	(void)deadline_ms;
	return GL_OK;
}

static enum re_relay_state f_relay_state(void *ud)
{
	(void)ud;
	return fk.n_relay_off ? RE_RELAY_OFF : RE_RELAY_ON;
}

static int f_log(void *ud, enum re_log_level lvl, const char *text)
{
	(void)ud;
	(void)lvl;
	if (fk.n_logs < 8)
		snprintf(fk.logs[fk.n_logs++], sizeof(fk.logs[0]), "%s", text);
	return GL_OK;
}

static int64_t f_now(void *ud)
{
	(void)ud;
	return fk.now;
}

static void f_sleep_until(void *ud, int64_t t)
{
	(void)ud;
	if (t > fk.now)
		fk.now = t;
}

static const struct re_io_ops fake_ops = {
    .record = f_record,
    .command = f_command,
    .post = f_post,
    .collect = f_collect,
    .stream = f_stream,
    .stream_counts = f_stream_counts,
    .ctrl_error = f_ctrl_error,
    .message = f_message,
    .relay_check = f_relay_check,
    .relay_off = f_relay_off,
    .relay_off_start = f_relay_off,
    .relay_off_finish = f_relay_off_finish,
    .relay_state = f_relay_state,
    .log = f_log,
    .now_ns = f_now,
    .sleep_until = f_sleep_until,
};

/* ---- fixtures ------------------------------------------------------------ */

static struct re_super sup;

static struct re_super_cfg make_cfg(void)
{
	struct re_super_cfg c;

	memset(&c, 0, sizeof(c));
	c.n_axes = 3;
	c.period_ns = PERIOD_MS * MS;
	c.wdog.noncrit_ns = 3 * c.period_ns / 2; /* 75 and 125 ms */
	c.wdog.crit_ns = 5 * c.period_ns / 2;
	c.alive.hb_limit_ns = 125 * MS;
	c.alive.sample_limit_ns = 125 * MS;
	c.fault_cmd_timeout_ms = 100;
	c.mode_name = "development";
	c.stream = 1;
	c.echo_limit_ns = 150 * MS;
	c.ack_limit_ns = 1000 * MS;
	return c;
}

static int setup(void **state)
{
	struct re_io io = {&fake_ops, NULL};
	struct re_super_cfg c = make_cfg();

	(void)state;
	memset(&fk, 0, sizeof(fk));
	memset(&sup, 0, sizeof(sup));
	fk.now = 1000 * MS;
	fk.echo_frozen = -1;
	fk.zab_state = 1; /* armed */
	fk.rec.layout = GL_LAYOUT_4000;
	fk.rec.n_axes = 3;
	fk.rec.threads = 0x03;
	for (int i = 0; i < 3; i++)
		fk.rec.axis[i].switches = GL_AXSW_FLS | GL_AXSW_RLS;
	fk.rec.axis[1].za = 1;	  /* ZAB: armed */
	fk.rec.axis[2].za = 4096; /* ZAC: jcmd 0 */
	return re_super_init(&sup, &io, &c, NULL, RE_DMC_ARMED) == GL_OK ? 0
									 : -1;
}

static int run(int n)
{
	int v = RE_OK;

	for (int i = 0; i < n && v != RE_FAULT; i++) {
		re_super_wait(&sup);
		v = re_super_cycle(&sup);
	}
	return v;
}

/* ---- tests --------------------------------------------------------------- */

/* One post per cycle, collected in the next; no round trip, no command,
 * no allocation; the ages are one period. */
static void test_stream_healthy(void **state)
{
	long before;

	(void)state;
	assert_int_equal(run(3), RE_OK);
	before = n_allocs;
	assert_int_equal(run(97), RE_OK);
	assert_int_equal(n_allocs, before);
	assert_int_equal(fk.n_posts, 100);
	assert_int_equal(fk.n_collects, 99);
	assert_int_equal(fk.n_busy, 0);
	assert_string_equal(fk.last_post, "hbpc=100");
	assert_int_equal(fk.n_commands, 0);
	assert_int_equal(fk.n_relay_off, 0);
	for (int i = 0; i < fk.n_logs; i++)
		print_message("log: %s\n", fk.logs[i]);
	assert_int_equal(fk.n_logs, 0);
	assert_int_equal(sup.pub.age_last_ns, PERIOD_MS * MS);
	assert_string_equal(re_super_fault_line(&sup), "");
}

/* The status (the board's source) carries the stream's own counts. */
static void test_stream_status_counts(void **state)
{
	struct re_status st;

	(void)state;
	assert_int_equal(run(3), RE_OK);
	re_super_status(&sup, &st);
	assert_int_equal(st.stream, 1);
	assert_int_equal(st.stream_records, 4998);
	assert_int_equal(st.stream_lost, 2);
}

/* A lost record costs nothing but its age: two periods, a warning. */
static void test_stream_lost_record(void **state)
{
	(void)state;
	assert_int_equal(run(5), RE_OK);
	fk.drop_next = 1;
	assert_int_equal(run(1), RE_OK); /* none this cycle: 50 ms old */
	assert_int_equal(run(1), RE_WARN);
	assert_int_equal(sup.pub.age_last_ns, 100 * MS);
	assert_int_equal(fk.n_logs, 1);
	assert_string_equal(fk.logs[0],
			    "watchdog: a record or the heartbeat's reply came "
			    "after 100.0 ms (non-critical limit 75.0 ms, "
			    "critical 125.0 ms)");
	assert_int_equal(run(10), RE_OK);
	assert_int_equal(fk.n_relay_off, 0);
}

/* One lost record: the next cycle's is 100 ms after the last (a late
 * one, RE_WARN). */
static void lose_one(void)
{
	fk.drop_next = 1;
	assert_int_equal(run(1), RE_OK);
	assert_int_equal(run(1), RE_WARN);
}

/* Late records condensed as the round trip's late replies are: the first
 * logged; the 3 more within RE_SUPER_WD_WINDOW_MS counted into one
 * summary, worded for the stream, by the cycle 10 s after the first (not
 * the one before); the next logged in full, and one more counted and
 * logged at the quit, after the stop. Every one counted for the board; no
 * allocation in the cycles. */
static void test_stream_wd_summary(void **state)
{
	static const char tail[] =
	    "(worst 100.0 ms, non-critical limit 75.0 ms, critical 125.0 ms)";
	struct re_status st;
	char want[256];
	long n0;

	(void)state;
	assert_int_equal(run(5), RE_OK);
	n0 = n_allocs;
	lose_one(); /* logged: the window opens */
	for (int k = 0; k < 3; k++)
		lose_one();
	assert_int_equal(fk.n_logs, 1);
	assert_int_equal(run(193), RE_OK); /* 9950 ms after the first */
	assert_int_equal(fk.n_logs, 1);
	assert_int_equal(run(1), RE_OK);
	assert_int_equal(fk.n_logs, 2);
	snprintf(want, sizeof(want),
		 "watchdog: 3 more late records or heartbeat replies in the "
		 "last 10.0 s %s",
		 tail);
	assert_string_equal(fk.logs[1], want);
	lose_one();
	assert_string_equal(fk.logs[2],
			    "watchdog: a record or the heartbeat's reply came "
			    "after 100.0 ms (non-critical limit 75.0 ms, "
			    "critical 125.0 ms)");
	lose_one();
	assert_int_equal(n_allocs, n0);
	assert_int_equal(fk.n_logs, 3);
	re_super_status(&sup, &st);
	assert_int_equal(st.wd_warnings, 6);
	/* the quit 10 ms later: 110 ms after the one logged, and the 25 ms
	 * given to offreq */
	fk.now += 10 * MS;
	assert_int_equal(re_super_shutdown(&sup, NULL, 0), GL_OK);
	assert_int_equal(fk.n_logs, 4);
	snprintf(want, sizeof(want),
		 "watchdog: 1 more late record or heartbeat reply in the last "
		 "0.1 s %s",
		 tail);
	assert_string_equal(fk.logs[3], want);
	assert_int_equal(fk.n_relay_off, 1);
}

/* The stream stops: WATCHDOG at the first cycle past 125 ms. */
static void test_stream_stops(void **state)
{
	(void)state;
	assert_int_equal(run(5), RE_OK);
	fk.stream_off = 1;
	assert_int_equal(run(2), RE_OK); /* 50, 100 ms */
	assert_int_equal(run(1), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_WDOG_STREAM);
	assert_int_equal(sup.pub.fault.i[0], 150);
	assert_int_equal(sup.pub.fault.i[1], 125);
	assert_int_equal(fk.n_relay_off, 1);
	assert_string_equal(fk.commands[0], "pcflt=1;AB 1;MO ABC");
	assert_true(!strncmp(re_super_fault_line(&sup),
			     "FAULT WATCHDOG: no data record from the "
			     "controller for 150 ms (limit 125 ms).",
			     72));
}

/* The heartbeat's replies stop coming (the controller's TCP holds them
 * back): the heartbeat is still posted every cycle and the program still
 * takes it (its echo), so nothing trips until the oldest reply has waited
 * longer than its own limit (1 s): WATCHDOG then. */
static void test_stream_ack_stalls(void **state)
{
	(void)state;
	assert_int_equal(run(5), RE_OK); /* post 5 (1250 ms) outstanding */
	fk.ack_stall = 1;
	assert_int_equal(run(20), RE_OK); /* up to 2250 ms */
	assert_int_equal(fk.n_posts, 25);
	assert_int_equal(fk.posted, 21);
	assert_int_equal(fk.n_busy, 0);
	assert_int_equal(fk.n_relay_off, 0);
	assert_int_equal(run(1), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_WDOG_ACK);
	assert_int_equal(sup.pub.fault.i[0], 1050);
	assert_int_equal(sup.pub.fault.i[1], 1000);
	assert_int_equal(fk.n_relay_off, 1);
}

/* Replies held back, then all at once: each collected in order, the
 * warning names the oldest's wait, nothing trips. */
static void test_stream_replies_late(void **state)
{
	(void)state;
	assert_int_equal(run(5), RE_OK);
	fk.ack_stall = 1;
	assert_int_equal(run(5), RE_OK); /* 5 more posted, none collected */
	fk.ack_stall = 0;
	assert_int_equal(run(1), RE_WARN); /* post 5 waited 300 ms */
	assert_int_equal(sup.pub.age_last_ns, 300 * MS);
	assert_int_equal(fk.posted, 1);	   /* this cycle's */
	assert_int_equal(fk.n_collects, 10);
	assert_int_equal(run(5), RE_OK);
	assert_int_equal(fk.n_relay_off, 0);
}

/* The program stops taking the heartbeat (its echo frozen): WATCHDOG
 * once the echoed one was sent more than echo_limit (150 ms) ago. */
static void test_stream_echo_frozen(void **state)
{
	(void)state;
	assert_int_equal(run(5), RE_OK); /* posts 1..5, records echo them */
	fk.echo_frozen = fk.last_hb;	 /* 5, sent at the 5th cycle */
	assert_int_equal(run(3), RE_OK); /* 50, 100, 150 ms */
	assert_int_equal(run(1), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_WDOG_ECHO);
	assert_int_equal(sup.pub.fault.i[0], 200);
	assert_int_equal(sup.pub.fault.i[1], 150);
	assert_int_equal(sup.pub.fault.i[2], 5);
	assert_int_equal(fk.n_relay_off, 1);
}

/* An echo of a heartbeat this supervisor never sent (a foreign writer)
 * counts as none: WATCHDOG once the oldest remembered is too old. */
static void test_stream_echo_foreign(void **state)
{
	(void)state;
	fk.echo_frozen = 7777;
	assert_int_equal(run(4), RE_OK); /* sent 0, 50, 100, 150 ms ago */
	assert_int_equal(run(1), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_WDOG_ECHO);
	assert_int_equal(sup.pub.fault.i[0], RE_VAL_UNKNOWN);
	assert_int_equal(sup.pub.fault.i[2], 7777);
}

/* A command between two cycles takes the posted reply (the link waits for
 * it first): acknowledged, the next cycle posts again. */
static void test_stream_reply_taken(void **state)
{
	char resp[32];

	(void)state;
	assert_int_equal(run(3), RE_OK);
	assert_int_equal(fk.posted, 1);
	f_command(NULL, "MG 1", resp, sizeof(resp), 0);
	assert_int_equal(run(1), RE_OK);
	assert_int_equal(fk.n_posts, 4);
	assert_int_equal(run(10), RE_OK);
	assert_int_equal(fk.n_busy, 0);
}

/* The heartbeat line refused ('?'): COMM, with the reason. */
static void test_stream_refused(void **state)
{
	(void)state;
	assert_int_equal(run(3), RE_OK);
	fk.collect_rc = GL_ERR_CTRL;
	assert_int_equal(run(1), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_COMM);
	assert_string_equal(sup.pub.fault.s,
			    "the controller refused the heartbeat line: "
			    "Unrecognized command");
}

/* Thread 1 found halted while armed and no fault latched yet (the
 * program's #FAULT half-way: it halts thread 1 before it latches), with
 * the command link stalled: the stop is not delivered, and the record
 * stream, beside that link, shows the fault the program latched
 * meanwhile: its watchdog is the fault named, not the thread. */
static void test_stream_settles_over_stream(void **state)
{
	char line[1024];

	(void)state;
	sup.pub.cfg.settle_ms = 25;
	assert_int_equal(run(3), RE_OK);
	fk.rec.threads = 0x01;
	fk.cmd_rc = GL_ERR_TIMEOUT;
	fk.latch_zab = 2 + 10 * 2; /* latched, fault 2 (watchdog) */
	assert_int_equal(run(1), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_CTRL_WATCHDOG);
	assert_string_equal(sup.verdict,
			    "program fault 2 in the record stream after 0.0 ms");
	snprintf(line, sizeof(line), "%s", re_super_fault_line(&sup));
	line[strcspn(line, ".")] = '\0';
	assert_string_equal(line, "FAULT WATCHDOG: the controller stopped the "
				  "robot: no heartbeat from this PC for "
				  "unknown ms");
	assert_int_equal(fk.n_relay_off, 1);
}

/* The same with nothing latched by the program within the settle time:
 * the thread is the fault named, and the log says what was looked at. */
static void test_stream_settle_nothing(void **state)
{
	(void)state;
	sup.pub.cfg.settle_ms = 25;
	assert_int_equal(run(3), RE_OK);
	fk.rec.threads = 0x01;
	fk.cmd_rc = GL_ERR_TIMEOUT;
	assert_int_equal(run(1), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_THREAD);
	assert_int_equal(sup.pub.fault.i[0], 1);
	assert_string_equal(sup.verdict, "no program fault in the record "
					 "stream within 25 ms");
	assert_int_equal(fk.n_relay_off, 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup(test_stream_healthy, setup),
	    cmocka_unit_test_setup(test_stream_lost_record, setup),
	    cmocka_unit_test_setup(test_stream_status_counts, setup),
	    cmocka_unit_test_setup(test_stream_wd_summary, setup),
	    cmocka_unit_test_setup(test_stream_stops, setup),
	    cmocka_unit_test_setup(test_stream_ack_stalls, setup),
	    cmocka_unit_test_setup(test_stream_replies_late, setup),
	    cmocka_unit_test_setup(test_stream_echo_frozen, setup),
	    cmocka_unit_test_setup(test_stream_echo_foreign, setup),
	    cmocka_unit_test_setup(test_stream_reply_taken, setup),
	    cmocka_unit_test_setup(test_stream_refused, setup),
	    cmocka_unit_test_setup(test_stream_settles_over_stream, setup),
	    cmocka_unit_test_setup(test_stream_settle_nothing, setup),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
