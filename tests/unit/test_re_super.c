/*
 * test_re_super.c - the supervisor cycle (re_super) against a fake
 * controller, relay, log and clock behind struct re_io: no sockets, no
 * sleeping. Covers one round trip per cycle, every fault path and its
 * reaction order (relay off, then "pcflt=1;AB 1;MO ABC", then the fsync'ed
 * log entry), the latch, the watchdog levels, the schedule (overruns) and
 * that the cycle allocates nothing.
 */
#include <malloc.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_file.h"
#include "gl_err.h"
#include "re_rec.h"
#include "re_super_int.h"
#include "re_trace.h"

#define MS	  1000000LL
#define PERIOD_MS 50

/* ---- allocation counter (linked with --wrap, see .ldflags) --------------- */

static long n_allocs;
void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t m);
void *__real_realloc(void *p, size_t n);
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t m);
void *__wrap_realloc(void *p, size_t n);

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

void *__wrap_realloc(void *p, size_t n)
{
	n_allocs++;
	return __real_realloc(p, n);
}

/* ---- the fake world ------------------------------------------------------ */

struct fake {
	int64_t now;	      /* fake CLOCK_MONOTONIC */
	struct gl_record rec; /* what the next QR returns */
	int record_rc;	      /* GL_OK or an error to return */
	int64_t delay_ns;     /* round-trip time */
	int64_t stall_ns;     /* the process stopped inside the next QR */
	int freeze_hb, freeze_sample;
	int n_records;
	char last_prefix[64];
	int last_timeout_ms;
	int relay_check_rc;
	int64_t check_stall_ns; /* the relay check: the clock jumps this once */
	int relay_off_rc;
	int n_relay_off;
	char commands[24][96];
	int n_commands;
	char mg_fdet[32]; /* answer to "MG fdet" */
	int fcode_after;  /* "MG fcode" answers 0 this many times, */
	int fcode_val;	  /* then this */
	int n_fcode;
	int motors_on_after_stop; /* "MG _MOx" answers 0 (motor still on) */
	int fhnew;		  /* "MG fhnew": another program's handles */
	int faxis;		  /* "MG faxis" */
	char logs[16][2560];
	int log_level[16];
	int n_logs;
	char seq[512]; /* order of reactions */
	const char *msgs[4];
	int n_msgs;
};

static struct fake fk;

static void seq_add(const char *what)
{
	size_t n = strlen(fk.seq);

	snprintf(fk.seq + n, sizeof(fk.seq) - n, "%s%s", n ? "," : "", what);
}

static int f_record(void *ud, const char *prefix, struct gl_record *rec,
		    int timeout_ms)
{
	(void)ud;
	fk.n_records++;
	snprintf(fk.last_prefix, sizeof(fk.last_prefix), "%s",
		 prefix ? prefix : "(none)");
	fk.last_timeout_ms = timeout_ms;
	fk.now += fk.stall_ns;
	fk.stall_ns = 0;
	if (fk.record_rc == GL_ERR_TIMEOUT ||
	    fk.delay_ns > (int64_t)timeout_ms * MS) {
		fk.now += (int64_t)timeout_ms * MS;
		return GL_ERR_TIMEOUT;
	}
	fk.now += fk.delay_ns;
	if (fk.record_rc != GL_OK)
		return fk.record_rc;
	if (!fk.freeze_sample)
		fk.rec.sample += 50;
	if (!fk.freeze_hb)
		fk.rec.axis[0].za = (fk.rec.axis[0].za + 5) % 1000000;
	*rec = fk.rec;
	return GL_OK;
}

static int f_command(void *ud, const char *cmd, char *resp, size_t cap,
		     int timeout_ms)
{
	char s[128];

	(void)ud;
	(void)timeout_ms;
	if (fk.n_commands < 24)
		snprintf(fk.commands[fk.n_commands++], 96, "%s", cmd);
	snprintf(s, sizeof(s), "cmd:%s", cmd);
	seq_add(s);
	if (!strcmp(cmd, "MG fcode"))
		snprintf(resp, cap, " %d.0000",
			 fk.n_fcode++ < fk.fcode_after ? 0 : fk.fcode_val);
	else if (!strcmp(cmd, "MG faxis"))
		snprintf(resp, cap, " %d.0000", fk.faxis);
	else if (!strcmp(cmd, "MG fhnew"))
		snprintf(resp, cap, " %d.0000", fk.fhnew);
	else if (!strncmp(cmd, "MG _MO", 6))
		snprintf(resp, cap, " %d.0000",
			 fk.motors_on_after_stop ? 0 : 1);
	else
		snprintf(resp, cap, "%s",
			 strcmp(cmd, "MG fdet") ? "" : fk.mg_fdet);
	return (int)strlen(resp);
}

static const char *f_ctrl_error(void *ud, int *code)
{
	(void)ud;
	if (code)
		*code = 1;
	return "";
}

static int f_message(void *ud, char *line, size_t cap)
{
	(void)ud;
	if (fk.n_msgs == 0)
		return GL_ERR_AGAIN;
	snprintf(line, cap, "%s", fk.msgs[--fk.n_msgs]);
	return (int)strlen(line);
}

static int f_relay_check(void *ud, char *why, size_t cap)
{
	(void)ud;
	fk.now += fk.check_stall_ns; /* stopped after the round trip */
	fk.check_stall_ns = 0;
	if (fk.relay_check_rc != GL_OK)
		snprintf(why, cap, "relay '/tmp/r': device vanished");
	return fk.relay_check_rc;
}

static int f_relay_off(void *ud)
{
	(void)ud;
	fk.n_relay_off++;
	seq_add("relay_off");
	return fk.relay_off_rc;
}

/* Not used by the cycle yet (it calls relay_off): recorded if called. */
static int f_relay_off_start(void *ud)
{
	(void)ud;
	fk.n_relay_off++;
	seq_add("relay_off_start");
	return fk.relay_off_rc;
}

static int f_relay_off_finish(void *ud, int deadline_ms)
{
	(void)ud;
	(void)deadline_ms;
	seq_add("relay_off_finish");
	return fk.relay_off_rc;
}

static enum re_relay_state f_relay_state(void *ud)
{
	(void)ud;
	return fk.n_relay_off ? RE_RELAY_OFF : RE_RELAY_ON;
}

static int f_log(void *ud, enum re_log_level lvl, const char *text)
{
	(void)ud;
	if (fk.n_logs < 16) {
		snprintf(fk.logs[fk.n_logs], sizeof(fk.logs[0]), "%s", text);
		fk.log_level[fk.n_logs++] = lvl;
	}
	seq_add(lvl == RE_LOG_FAULT ? "log:FAULT" : "log");
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
    .ctrl_error = f_ctrl_error,
    .message = f_message,
    .relay_check = f_relay_check,
    .relay_off = f_relay_off,
    .relay_off_start = f_relay_off_start,
    .relay_off_finish = f_relay_off_finish,
    .relay_state = f_relay_state,
    .log = f_log,
    .now_ns = f_now,
    .sleep_until = f_sleep_until,
};

/* ---- fixtures ------------------------------------------------------------ */

static struct re_caltable table;
static const struct re_caltable *tables[3] = {&table, &table, &table};
static const char *const names[3] = {"A", "B", "C"};
static struct re_super sup;

static void make_table(void)
{
	memset(&table, 0, sizeof(table));
	table.n = 101;
	table.start_counts = -50000;
	table.step_counts = 1000;
	for (int i = 0; i < table.n; i++)
		table.pot_v[i] = 0.5 + 0.04 * i; /* 2.5 V at 0 */
	table.soft_rev = -50000;
	table.soft_fwd = 50000;
}

static void set_pot(int axis, double volts)
{
	fk.rec.axis[axis].analog_in =
	    (int32_t)(volts * RE_AN_COUNTS_PER_V + (volts < 0 ? -0.5 : 0.5));
}

static void make_record(void)
{
	struct gl_record *r = &fk.rec;

	memset(r, 0, sizeof(*r));
	r->layout = GL_LAYOUT_4000;
	r->n_axes = 3;
	r->threads = 0x03;
	for (int i = 0; i < 3; i++) {
		r->axis[i].switches = GL_AXSW_FLS | GL_AXSW_RLS;
		set_pot(i, 2.5);
	}
	r->axis[1].za = 1;    /* ZAB: armed, no fault */
	r->axis[2].za = 4096; /* ZAC: jcmd 0 */
}

static struct re_super_cfg make_cfg(void)
{
	struct re_super_cfg c;

	memset(&c, 0, sizeof(c));
	c.n_axes = 3;
	c.period_ns = PERIOD_MS * MS;
	c.wdog.noncrit_ns = 3 * c.period_ns / 2; /* 1.5 and 2.5 periods */
	c.wdog.crit_ns = 5 * c.period_ns / 2;
	c.alive.hb_limit_ns = 125 * MS;
	c.alive.sample_limit_ns = 125 * MS;
	for (int i = 0; i < 3; i++) {
		c.encpot[i].allowed_error = 0.5;
		c.encpot[i].persistence_cycles = 1;
		c.axis_names[i] = names[i];
	}
	c.fault_cmd_timeout_ms = 100;
	c.mode_name = "development";
	return c;
}

static int setup(void **state)
{
	struct re_io io = {&fake_ops, NULL};
	struct re_super_cfg c = make_cfg();

	(void)state;
	memset(&fk, 0, sizeof(fk));
	fk.now = 1000 * MS;
	fk.delay_ns = MS / 10;
	make_table();
	make_record();
	return re_super_init(&sup, &io, &c, tables, 1) == GL_OK ? 0 : -1;
}

/* One cycle: wait for the deadline, then run it. */
static int step(void)
{
	re_super_wait(&sup);
	return re_super_cycle(&sup);
}

static int run(int n)
{
	int v = RE_OK;

	for (int i = 0; i < n && v != RE_FAULT; i++)
		v = step();
	return v;
}

static const char *fault_log(void)
{
	for (int i = 0; i < fk.n_logs; i++)
		if (fk.log_level[i] == RE_LOG_FAULT)
			return fk.logs[i];
	return NULL;
}

/* ---- tests --------------------------------------------------------------- */

/* The heartbeat text counted up in place (no division per
 * cycle): carries, a value set from outside, and the wrap. */
static void test_super_hbpc_text(void **state)
{
	(void)state;
	assert_int_equal(run(10), RE_OK);
	assert_string_equal(fk.last_prefix, "hbpc=10");
	sup.pub.hbpc = 12344; /* not the last one + 1: written anew */
	assert_int_equal(run(1), RE_OK);
	assert_string_equal(fk.last_prefix, "hbpc=12345");
	sup.pub.hbpc = 1998;
	assert_int_equal(run(2), RE_OK);
	assert_string_equal(fk.last_prefix, "hbpc=2000");
	sup.pub.hbpc = 9998;
	assert_int_equal(run(1), RE_OK);
	assert_string_equal(fk.last_prefix, "hbpc=9999");
	assert_int_equal(run(1), RE_OK); /* one digit more */
	assert_string_equal(fk.last_prefix, "hbpc=10000");
	sup.pub.hbpc = RE_HBPC_WRAP - 2;
	assert_int_equal(run(1), RE_OK);
	assert_string_equal(fk.last_prefix, "hbpc=999999999");
	assert_int_equal(run(2), RE_OK); /* the wrap */
	assert_string_equal(fk.last_prefix, "hbpc=1");
}

/* A healthy controller: one QR round trip per cycle, heartbeat counting. */
static void test_super_healthy_one_round_trip(void **state)
{
	(void)state;
	assert_int_equal(run(100), RE_OK);
	assert_int_equal(fk.n_records, 100);
	assert_int_equal(fk.n_commands, 0);
	assert_string_equal(fk.last_prefix, "hbpc=100");
	assert_int_equal(fk.n_relay_off, 0);
	assert_int_equal(fk.n_logs, 0);
	assert_string_equal(re_super_fault_line(&sup), "");
	/* the record deadline is what is left until the critical limit:
	 * 125 ms after the last reply, which came 0.1 ms into the last cycle */
	assert_int_equal(fk.last_timeout_ms, 76);
}

/* The reaction order: relay off, controller stop, log fsync'ed - in the
 * cycle that sees the fault; ENCODER after persistence + 1 cycles. */
static void test_super_encpot_fault_order(void **state)
{
	(void)state;
	assert_int_equal(run(3), RE_OK);
	set_pot(1, 2.5 + 0.1); /* tolerance is 1.5 x 0.04 V = 0.06 V */
	assert_int_equal(step(), RE_OK); /* persistence 1: tolerated */
	assert_int_equal(fk.n_relay_off, 0);
	assert_int_equal(step(), RE_FAULT);
	/* relay, stop, motors read back, the program's own verdict asked
	 * (a consequence to name), another program's handles, then the log */
	assert_string_equal(fk.seq, "relay_off_start,cmd:pcflt=1;AB 1;MO ABC,"
				    "relay_off_finish,"
				    "cmd:MG _MOA,cmd:MG _MOB,cmd:MG _MOC,"
				    "cmd:MG fcode,cmd:MG fhnew,log:FAULT");
	assert_non_null(strstr(re_super_fault_line(&sup),
			       ". Safe state confirmed: motor power off "
			       "(relay open), motors off. Recovery: "));
	assert_true(!strncmp(re_super_fault_line(&sup), "FAULT ENCODER: ", 15));
	assert_non_null(strstr(re_super_fault_line(&sup), "Recovery: "));
	assert_non_null(strstr(fault_log(), re_super_fault_line(&sup)));
	assert_non_null(strstr(fault_log(), "relay off: confirmed"));
	assert_non_null(strstr(fault_log(), "B enc=0"));
}

/* A single violating cycle between good ones never trips. */
static void test_super_encpot_transient(void **state)
{
	(void)state;
	for (int i = 0; i < 10; i++) {
		set_pot(0, i % 2 ? 2.6 : 2.5);
		assert_int_equal(step(), RE_OK);
	}
	assert_int_equal(fk.n_relay_off, 0);
}

/* Late reply between the limits: logged, not a fault. */
static void test_super_watchdog_noncritical(void **state)
{
	(void)state;
	assert_int_equal(run(2), RE_OK);
	/* the reply comes 40 ms into the cycle: 89.9 ms after the last */
	fk.delay_ns = 40 * MS;
	assert_int_equal(step(), RE_WARN);
	assert_int_equal(fk.n_logs, 1);
	assert_int_equal(fk.log_level[0], RE_LOG_WARN);
	assert_non_null(strstr(fk.logs[0], "watchdog: reply after 89.9 ms"));
	fk.delay_ns = MS / 10;
	assert_int_equal(step(), RE_OK);
	assert_int_equal(fk.n_relay_off, 0);
}

/* One cycle whose reply comes @ms into it (the next ones 0.1 ms in). */
static int late(int ms)
{
	int v;

	fk.delay_ns = ms * MS;
	v = step();
	fk.delay_ns = MS / 10;
	return v;
}

/* @n pairs of cycles: a good reply, then one 40 ms into its cycle (89.9
 * ms after the last), or 45 ms (94.9 ms) in pair @worst. */
static void late_pairs(int n, int worst)
{
	for (int k = 0; k < n; k++) {
		assert_int_equal(step(), RE_OK);
		assert_int_equal(late(k == worst ? 45 : 40), RE_WARN);
	}
}

static const char *const wd_tail =
    "non-critical limit 75.0 ms, critical 125.0 ms)";

/* Repeated late replies condensed: the first logged at once; the 5 more
 * within RE_SUPER_WD_WINDOW_MS counted, not logged, and logged as one
 * summary with their count and worst age by the cycle that ends the
 * window (10 s after the first, not the one before); every one counted
 * for the board; the next late reply logged in full again. No
 * allocation. */
static void test_super_wd_summary(void **state)
{
	struct re_status st;
	struct re_event ev;
	char want[256];
	long n0;

	(void)state;
	assert_int_equal(RE_SUPER_WD_WINDOW_MS, 10000);
	assert_int_equal(run(2), RE_OK);
	n0 = n_allocs;
	assert_int_equal(late(40), RE_WARN); /* the window opens now */
	late_pairs(5, 2);
	assert_int_equal(fk.n_logs, 1);
	assert_string_equal(fk.logs[0],
			    "watchdog: reply after 89.9 ms (non-critical limit "
			    "75.0 ms, critical 125.0 ms)");
	re_super_status(&sup, &st);
	assert_int_equal(st.wd_warnings, 6);
	/* it opened 40 ms into its cycle: the 200th cycle after it judges
	 * 9960.1 ms after, the 201st 10010.1 ms */
	assert_int_equal(run(190), RE_OK);
	assert_int_equal(fk.n_logs, 1);
	assert_int_equal(step(), RE_OK);
	assert_int_equal(fk.n_logs, 2);
	assert_int_equal(fk.log_level[1], RE_LOG_WARN);
	snprintf(want, sizeof(want),
		 "watchdog: 5 more late replies in the last 10.0 s (worst "
		 "94.9 ms, %s",
		 wd_tail);
	assert_string_equal(fk.logs[1], want);
	assert_int_equal(re_super_event(&sup, 1, &ev), 1); /* the console's */
	assert_int_equal(ev.kind, RE_EV_WATCHDOG);
	assert_string_equal(ev.text, want);
	assert_int_equal(late(40), RE_WARN);
	assert_int_equal(fk.n_logs, 3);
	assert_true(!strncmp(fk.logs[2], "watchdog: reply after 89.9 ms", 29));
	re_super_status(&sup, &st);
	assert_int_equal(st.wd_warnings, 7);
	assert_int_equal(n_allocs, n0);
	assert_int_equal(fk.n_relay_off, 0);
}

/* One late reply and none after it: its line alone, no summary at the
 * window's end, none at a flush, none at the quit. */
static void test_super_wd_no_summary(void **state)
{
	struct re_status st;
	char what[128];

	(void)state;
	assert_int_equal(run(2), RE_OK);
	assert_int_equal(late(40), RE_WARN);
	assert_int_equal(run(250), RE_OK);
	re_super_wd_flush(&sup);
	assert_int_equal(re_super_shutdown(&sup, what, sizeof(what)), GL_OK);
	assert_int_equal(fk.n_logs, 1);
	assert_true(!strncmp(fk.logs[0], "watchdog: reply after 89.9 ms", 29));
	re_super_status(&sup, &st);
	assert_int_equal(st.wd_warnings, 1);
}

/* A fault inside the window: the late replies counted so far are logged
 * before the FAULT entry, after the stop (which they must not delay). */
static void test_super_wd_fault_flushes(void **state)
{
	static const char tail[] = "cmd:MG fhnew,log,log:FAULT";
	struct re_status st;
	char want[256];
	size_t n;

	(void)state;
	assert_int_equal(run(2), RE_OK);
	assert_int_equal(late(40), RE_WARN);
	late_pairs(3, -1);
	fk.record_rc = GL_ERR_CLOSED;
	assert_int_equal(step(), RE_FAULT);
	assert_int_equal(fk.n_logs, 3);
	/* opened 40 ms into its cycle, the fault 0.1 ms into the 7th after */
	snprintf(want, sizeof(want),
		 "watchdog: 3 more late replies in the last 0.3 s (worst "
		 "89.9 ms, %s",
		 wd_tail);
	assert_string_equal(fk.logs[1], want);
	assert_int_equal(fk.log_level[1], RE_LOG_WARN);
	assert_int_equal(fk.log_level[2], RE_LOG_FAULT);
	n = strlen(fk.seq);
	assert_true(n > strlen(tail));
	assert_string_equal(fk.seq + n - strlen(tail), tail);
	assert_non_null(strstr(fk.seq, "cmd:pcflt=1;AB 1;MO ABC,"));
	re_super_status(&sup, &st);
	assert_int_equal(st.wd_warnings, 4);
	assert_int_equal(re_super_shutdown(&sup, NULL, 0), GL_OK);
	assert_int_equal(fk.n_logs, 3); /* nothing left to log */
}

/* The quit inside the window: the one more late reply logged after the
 * stop and the relay's off; a second flush logs nothing. */
static void test_super_wd_quit_flushes(void **state)
{
	char want[256];

	(void)state;
	assert_int_equal(run(2), RE_OK);
	assert_int_equal(late(40), RE_WARN);
	late_pairs(1, 0);
	assert_int_equal(fk.n_logs, 1);
	fk.seq[0] = '\0';
	assert_int_equal(re_super_shutdown(&sup, NULL, 0), GL_OK);
	/* 105 ms after the first, and the 25 ms given to offreq */
	snprintf(want, sizeof(want),
		 "watchdog: 1 more late reply in the last 0.1 s (worst 94.9 "
		 "ms, %s",
		 wd_tail);
	assert_int_equal(fk.n_logs, 2);
	assert_string_equal(fk.logs[1], want);
	assert_string_equal(fk.seq, "cmd:offreq=1,cmd:AB 1;MO ABC,cmd:MG _MOA,"
				    "cmd:MG _MOB,cmd:MG _MOC,relay_off_start,"
				    "relay_off_finish,log");
	re_super_wd_flush(&sup);
	assert_int_equal(fk.n_logs, 2);
}

/* No reply before the critical limit: WATCHDOG fault in that cycle. */
static void test_super_watchdog_critical(void **state)
{
	(void)state;
	assert_int_equal(run(2), RE_OK);
	fk.record_rc = GL_ERR_TIMEOUT;
	assert_int_equal(step(), RE_FAULT);
	assert_int_equal(fk.last_timeout_ms, 76); /* 125 - 49.9 */
	assert_true(
	    !strncmp(re_super_fault_line(&sup), "FAULT WATCHDOG: ", 16));
	assert_int_equal(fk.n_relay_off, 1);
}

/* The process stopped inside the round trip (SIGSTOP while waiting for the
 * reply) for 2 s: the wait returned 1924 ms after its 76 ms timeout, so
 * the supervisor names its own stall, whether the reply was there
 * (rc OK) or not (timeout) - not the link. The figure is the time since
 * the round trip began (the last moment it is known to have run): at
 * least the stop, never the 1924 ms past the timeout (CI saw a 2 s
 * freeze reported as 1924 ms). */
static void test_super_stall_in_round_trip(void **state)
{
	static const int rcs[] = {GL_OK, GL_ERR_TIMEOUT};

	for (size_t k = 0; k < 2; k++) {
		setup(state);
		assert_int_equal(run(2), RE_OK);
		fk.stall_ns = 2000 * MS;
		fk.record_rc = rcs[k];
		assert_int_equal(step(), RE_FAULT);
		assert_int_equal(fk.last_timeout_ms, 76);
		assert_int_equal(sup.pub.fault.id, RE_F_STALL);
		assert_int_equal(sup.pub.fault.i[0], k ? 2076 : 2000);
		assert_non_null(strstr(re_super_fault_line(&sup),
				       "FAULT WATCHDOG: this supervisor did "
				       "not run for "));
		assert_non_null(strstr(re_super_fault_line(&sup),
				       " ms (limit 125 ms): the PC stalled"));
		assert_int_equal(fk.n_relay_off, 1);
	}
}

/* The process stopped in the tail of a cycle (after its round trip, in its
 * checks) for 2 s: the next cycle names its own stall, from the end of
 * that round trip, not the last good reply's age. */
static void test_super_stall_in_cycle_tail(void **state)
{
	(void)state;
	assert_int_equal(run(2), RE_OK);
	fk.check_stall_ns = 2000 * MS;
	assert_int_equal(step(), RE_OK);
	assert_int_equal(step(), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_STALL);
	assert_true(sup.pub.fault.i[0] >= 2000);
	assert_non_null(strstr(re_super_fault_line(&sup),
			       "FAULT WATCHDOG: this supervisor did not run "
			       "for "));
	assert_int_equal(fk.n_relay_off, 1);
}

/*
 * Another program: a handle that opens between two records is logged as a
 * warning (no fault: it may only look) and shown in the status; a fault
 * that follows names it, with the handles the program saw (fhnew) too.
 */
static void test_super_foreign_named(void **state)
{
	struct re_status st;

	(void)state;
	fk.rec.handles[0] = 2; /* ours */
	assert_int_equal(run(2), RE_OK);
	fk.rec.handles[2] = 2; /* C opens */
	assert_int_equal(step(), RE_OK);
	assert_int_equal(fk.n_relay_off, 0);
	assert_int_equal(fk.n_logs, 1);
	assert_int_equal(fk.log_level[0], RE_LOG_WARN);
	assert_string_equal(fk.logs[0], "another program connected to the "
					"controller (handle C)");
	re_super_status(&sup, &st);
	assert_int_equal(st.foreign, 4);
	fk.rec.handles[2] = 0; /* C leaves; E came and went unseen */
	fk.fhnew = 4 | 16;
	assert_int_equal(step(), RE_OK);
	assert_int_equal(fk.n_logs, 1);
	fk.record_rc = GL_ERR_CLOSED;
	assert_int_equal(step(), RE_FAULT);
	assert_non_null(strstr(re_super_fault_line(&sup),
			       ". Another program had connected to the "
			       "controller (handle CE). "));
}

/*
 * What the program latched after our stop is named as "Then:" only when it
 * is not our doing: a motor found off with stop code 0 (no motion ended
 * on it yet), 1 (at rest), 4 (ST) or 7 (AB) was switched off by our own
 * "MO ABC" (it landed mid-pass);
 * stop code 8 (the position error switched it off) is a consequence.
 */
static void test_super_consequences(void **state)
{
	static const struct {
		const char *fdet;
		int then;
	} cases[] = {
	    {" 0.0000", 0}, {" 1.0000", 0}, {" 4.0000", 0},
	    {" 7.0000", 0}, {" 8.0000", 1}};

	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
		const char *line;

		setup(state);
		assert_int_equal(run(2), RE_OK);
		fk.fcode_val = 10;
		fk.faxis = 1;
		snprintf(fk.mg_fdet, sizeof(fk.mg_fdet), "%s", cases[k].fdet);
		fk.record_rc = GL_ERR_CLOSED;
		assert_int_equal(step(), RE_FAULT);
		line = re_super_fault_line(&sup);
		assert_true(!strncmp(line, "FAULT COMM: ", 12));
		if (cases[k].then)
			assert_non_null(strstr(line, ". Then: axis A: the "
						     "controller "
						     "found the motor off "
						     "while armed: position "
						     "error above the limit "
						     "(stop code 8)."));
		else
			assert_null(strstr(line, "Then:"));
	}
}

/* The program's "motor power lost on every axis" (AMPERR on no single
 * axis) is our own relay's doing when the relay's off is confirmed: no
 * "Then:" (it can come before our pcflt=1: the amplifier error runs at
 * once); with the relay's off not confirmed it is said. */
static void test_super_power_loss_ours(void **state)
{
	for (int k = 0; k < 2; k++) {
		const char *line;

		setup(state);
		assert_int_equal(run(2), RE_OK);
		fk.fcode_val = 8;
		fk.faxis = 0;
		fk.relay_off_rc = k ? GL_ERR_RELAY : GL_OK;
		fk.record_rc = GL_ERR_CLOSED;
		assert_int_equal(step(), RE_FAULT);
		line = re_super_fault_line(&sup);
		assert_true(!strncmp(line, "FAULT COMM: ", 12));
		if (k)
			assert_non_null(strstr(line, ". Then: motor power lost "
						     "on every axis (E-stop "
						     "button, relay or power "
						     "supply)."));
		else
			assert_null(strstr(line, "Then:"));
	}
}

/*
 * The board's word for what the program latched after our fault: B's
 * potentiometer (our encoder/pot check) latches the supervisor's fault;
 * our "MO ABC" landing mid-pass makes the program find A off first and
 * latch 10 on A with stop code 7 (AB): that is our stop's doing
 * (ctrl_ours), never a motor-off fault on A; stop code 8 on A would be
 * the controller's own (a consequence); 12 (pcflt) names the supervisor
 * in its own words already (FAULT SUPERVISOR).
 */
static void test_super_ctrl_ours(void **state)
{
	static const struct {
		int fcode, faxis, stop_code, ours;
	} cases[] = {{10, 1, 7, 1},
		     {10, 1, 4, 1},
		     {12, 0, 0, 0},
		     {10, 1, 8, 0},
		     {4, 2, 1, 0}};
	struct re_status st;

	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
		setup(state);
		assert_int_equal(run(2), RE_OK);
		fk.relay_check_rc = GL_ERR_RELAY; /* a fault of roboelf's */
		assert_int_equal(step(), RE_FAULT);
		re_super_status(&sup, &st);
		assert_int_equal(st.ctrl_ours, 0); /* nothing latched yet */
		fk.rec.axis[1].za =
		    2 + 10 * cases[k].fcode + 1000 * cases[k].faxis;
		for (int a = 0; a < 3; a++) {
			fk.rec.axis[a].status |= GL_AXST_MOTOR_OFF;
			fk.rec.axis[a].stop_code = cases[k].stop_code;
		}
		step();
		re_super_status(&sup, &st);
		assert_int_equal(st.za.fcode, cases[k].fcode);
		assert_int_equal(st.ctrl_ours, cases[k].ours);
	}
	/* the program's own fault, found first, is the cause: never ours */
	setup(state);
	assert_int_equal(run(2), RE_OK);
	fk.rec.axis[1].za = 2 + 10 * 10 + 1000 * 1;
	fk.rec.axis[0].status |= GL_AXST_MOTOR_OFF;
	fk.rec.axis[0].stop_code = 7;
	snprintf(fk.mg_fdet, sizeof(fk.mg_fdet), " 7.0000");
	assert_int_equal(step(), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_CTRL_MOTOROFF);
	re_super_status(&sup, &st);
	assert_int_equal(st.ctrl_ours, 0);
}

/* A closed connection: COMM fault. */
static void test_super_comm_fault(void **state)
{
	(void)state;
	fk.record_rc = GL_ERR_CLOSED;
	assert_int_equal(step(), RE_FAULT);
	assert_true(!strncmp(re_super_fault_line(&sup), "FAULT COMM: ", 12));
	assert_non_null(
	    strstr(re_super_fault_line(&sup), gl_strerror(GL_ERR_CLOSED)));
}

/* Relay lost: ESTOP; the motors are switched off through the controller
 * even though the relay cannot confirm "off". */
static void test_super_relay_lost(void **state)
{
	(void)state;
	assert_int_equal(run(2), RE_OK);
	fk.relay_check_rc = GL_ERR_RELAY;
	fk.relay_off_rc = GL_ERR_RELAY;
	assert_int_equal(step(), RE_FAULT);
	assert_true(!strncmp(re_super_fault_line(&sup), "FAULT ESTOP: ", 13));
	assert_string_equal(fk.commands[0], "pcflt=1;AB 1;MO ABC");
	assert_non_null(strstr(fault_log(), "relay off: NOT confirmed"));
}

/* A fault latched by the program (position error on B) is read from ZAB,
 * its detail asked with MG fdet after the stop. */
static void test_super_controller_fault(void **state)
{
	(void)state;
	assert_int_equal(run(2), RE_OK);
	fk.rec.axis[1].za = 2 + 10 * 4 + 1000 * 2;
	fk.rec.axis[1].status |= GL_AXST_MOTOR_OFF;
	snprintf(fk.mg_fdet, sizeof(fk.mg_fdet), " 5012.0000");
	assert_int_equal(step(), RE_FAULT);
	assert_string_equal(fk.commands[0], "pcflt=1;AB 1;MO ABC");
	assert_string_equal(fk.commands[1], "MG fdet");
	assert_int_equal(sup.pub.fault.id, RE_F_CTRL_POSERR);
	assert_int_equal(sup.pub.fault.axis, 1);
	assert_int_equal(sup.pub.fault.i[0], 5012);
	assert_true(!strncmp(re_super_fault_line(&sup), "FAULT MOTION: ", 14));
}

/* A motor the controller switched off, seen before the program latched. */
static void test_super_motor_off(void **state)
{
	(void)state;
	assert_int_equal(run(2), RE_OK);
	fk.rec.axis[2].status |= GL_AXST_MOTOR_OFF;
	fk.rec.axis[2].stop_code = 12;
	assert_int_equal(step(), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_MOTOR_OFF);
	assert_int_equal(sup.pub.fault.axis, 2);
	assert_non_null(strstr(re_super_fault_line(&sup), "encoder failure"));
}

/* Motors found off before the program published its own verdict (here
 * INPUT: #JINV stops and switches off in thread 1, #MAIN latches a few ms
 * later): power cut and motors off at once, then the program's fault code
 * is awaited (settle_ms) and reported, then pcflt. */
static void test_super_settle_program_verdict(void **state)
{
	(void)state;
	sup.pub.cfg.settle_ms = 25;
	assert_int_equal(run(2), RE_OK);
	for (int i = 0; i < 3; i++) {
		fk.rec.axis[i].status |= GL_AXST_MOTOR_OFF;
		fk.rec.axis[i].stop_code = 4;
	}
	fk.fcode_after = 3;
	fk.fcode_val = 3;
	snprintf(fk.mg_fdet, sizeof(fk.mg_fdet), " 1.0000");
	assert_int_equal(step(), RE_FAULT);
	assert_string_equal(fk.seq, "relay_off_start,cmd:AB 1;MO ABC,"
				    "cmd:MG fcode,"
				    "cmd:MG fcode,cmd:MG fcode,cmd:MG fcode,"
				    "cmd:MG faxis,cmd:MG fdet,cmd:pcflt=1,"
				    "relay_off_finish,"
				    "cmd:MG _MOA,cmd:MG _MOB,cmd:MG _MOC,"
				    "cmd:MG fhnew,log:FAULT");
	assert_int_equal(sup.pub.fault.id, RE_F_CTRL_INPUT);
	assert_int_equal(sup.pub.fault.i[0], 1);
	assert_true(!strncmp(re_super_fault_line(&sup), "FAULT INPUT: ", 13));
	assert_non_null(strstr(fault_log(), " | program fault 3 after "));
}

/* Nothing from the program within settle_ms: our own finding stands. */
static void test_super_settle_timeout(void **state)
{
	int64_t t;

	(void)state;
	sup.pub.cfg.settle_ms = 25;
	assert_int_equal(run(2), RE_OK);
	fk.rec.axis[0].status |= GL_AXST_MOTOR_OFF;
	fk.rec.axis[0].stop_code = 8;
	fk.fcode_after = 1000;
	t = fk.now;
	assert_int_equal(step(), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_MOTOR_OFF);
	assert_true(fk.now - t >= 25 * MS && fk.now - t < 80 * MS);
	assert_string_equal(fk.commands[fk.n_commands - 6], "pcflt=1");
	assert_string_equal(fk.commands[fk.n_commands - 5], "MG _MOA");
	assert_string_equal(fk.commands[fk.n_commands - 1], "MG fhnew");
	assert_non_null(strstr(re_super_fault_line(&sup), "position error"));
	assert_non_null(strstr(fault_log(), "no program fault within 25 ms"));
}

/* The motion thread stopped while armed. */
static void test_super_thread_missing(void **state)
{
	(void)state;
	assert_int_equal(run(2), RE_OK);
	fk.rec.threads = 0x01;
	assert_int_equal(step(), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_THREAD);
	assert_int_equal(sup.pub.fault.i[0], 1);
}

/* The program heartbeat stops: WATCHDOG after its limit, not before. */
static void test_super_heartbeat_frozen(void **state)
{
	(void)state;
	assert_int_equal(run(2), RE_OK);
	fk.freeze_hb = 1;
	assert_int_equal(run(2), RE_OK);    /* 100 ms frozen < 125 ms */
	assert_int_equal(step(), RE_FAULT); /* 150 ms */
	assert_int_equal(sup.pub.fault.id, RE_F_WDOG_HEARTBEAT);
	assert_true(
	    !strncmp(re_super_fault_line(&sup), "FAULT WATCHDOG: ", 16));
}

/* The record's sample number frozen (stale data from a live TCP stack). */
static void test_super_sample_frozen(void **state)
{
	(void)state;
	assert_int_equal(run(2), RE_OK);
	fk.freeze_sample = 1;
	assert_int_equal(run(10), RE_FAULT);
	assert_int_equal(sup.pub.fault.id, RE_F_WDOG_SAMPLE);
}

/* Once latched: no more reactions, no heartbeat, status polling only; a
 * second fault is only logged. */
static void test_super_latch(void **state)
{
	struct re_fault f;
	struct re_status st;
	int n;

	(void)state;
	fk.record_rc = GL_ERR_CLOSED;
	assert_int_equal(step(), RE_FAULT);
	n = fk.n_commands;
	assert_string_equal(fk.commands[0], "pcflt=1;AB 1;MO ABC");
	fk.record_rc = GL_OK;
	fk.relay_check_rc = GL_ERR_RELAY;
	assert_int_equal(run(20), RE_OK);
	assert_int_equal(fk.n_relay_off, 1);
	assert_int_equal(fk.n_commands, n);
	assert_string_equal(fk.last_prefix, "(none)");
	re_fault_set(&f, RE_F_ESTOP_LOST, -1);
	assert_int_equal(re_super_fault(&sup, &f), RE_OK);
	assert_int_equal(fk.n_relay_off, 1);
	assert_true(!strncmp(re_super_fault_line(&sup), "FAULT COMM: ", 12));
	re_super_status(&sup, &st);
	assert_int_equal(st.latched, 1);
	assert_int_equal(st.armed, 0);
	assert_int_equal(st.relay, RE_RELAY_OFF);
}

/* The later faults and warnings for the console, in the fixed ring: the
 * watchdog warning, the relay lost and a fault while latched, in order,
 * read once each; the oldest overwritten after RE_SUPER_EVENTS more. */
static void test_super_events_ring(void **state)
{
	struct re_event ev;
	struct re_fault f;
	uint64_t seen = 0;

	(void)state;
	assert_int_equal(re_super_event(&sup, 0, &ev), 0);
	assert_int_equal(run(2), RE_OK);
	fk.delay_ns = 40 * MS;
	assert_int_equal(step(), RE_WARN);
	fk.delay_ns = MS / 10;
	fk.record_rc = GL_ERR_CLOSED;
	assert_int_equal(step(), RE_FAULT); /* the first: not an event */
	fk.record_rc = GL_OK;
	fk.relay_check_rc = GL_ERR_RELAY;
	assert_int_equal(run(3), RE_OK);
	re_fault_set(&f, RE_F_ESTOP_LOST, -1);
	snprintf(f.s, sizeof(f.s), "test");
	assert_int_equal(re_super_fault(&sup, &f), RE_OK);
	assert_int_equal(re_super_event(&sup, seen, &ev), 1);
	assert_int_equal(ev.seq, 1);
	assert_int_equal(ev.level, RE_LOG_WARN);
	assert_int_equal(ev.kind, RE_EV_WATCHDOG);
	assert_true(!strncmp(ev.text, "watchdog: reply after 89.9 ms", 29));
	seen = ev.seq;
	assert_int_equal(re_super_event(&sup, seen, &ev), 1);
	assert_int_equal(ev.kind, RE_EV_RELAY);
	assert_int_equal(ev.level, RE_LOG_FAULT);
	assert_true(!strncmp(ev.text, "FAULT ESTOP: ", 13));
	seen = ev.seq;
	assert_int_equal(re_super_event(&sup, seen, &ev), 1);
	assert_int_equal(ev.kind, RE_EV_LATER);
	assert_true(!strncmp(ev.text, "FAULT ESTOP: ", 13));
	assert_non_null(strstr(ev.text, "(test)"));
	seen = ev.seq;
	assert_int_equal(re_super_event(&sup, seen, &ev), 0);
	for (int i = 0; i < RE_SUPER_EVENTS + 2; i++)
		re_super_note(&sup, RE_LOG_WARN, RE_EV_OTHER, "n");
	/* 3 + 18 kept in a ring of 16: the next unread one is seq 6 */
	assert_int_equal(re_super_event(&sup, seen, &ev), 1);
	assert_int_equal(ev.seq, 3 + RE_SUPER_EVENTS + 2 - RE_SUPER_EVENTS + 1);
}

/* Absolute deadlines: a long cycle is one overrun and no burst after. */
static void test_super_schedule_overrun(void **state)
{
	int64_t t;

	(void)state;
	assert_int_equal(run(4), RE_OK);
	t = fk.now;
	assert_int_equal(sup.pub.overruns, 0);
	fk.now += 120 * MS; /* the process was held up */
	re_super_wait(&sup);
	assert_int_equal(sup.pub.overruns, 1);
	t = fk.now;
	re_super_wait(&sup); /* the next one is a full period on */
	assert_int_equal(fk.now - t, PERIOD_MS * MS);
	assert_int_equal(sup.pub.overruns, 1);
}

/* The quit path: stop and motors off first, then the relay. */
static void test_super_shutdown(void **state)
{
	(void)state;
	assert_int_equal(run(2), RE_OK);
	char what[128];

	assert_int_equal(re_super_shutdown(&sup, what, sizeof(what)), GL_OK);
	assert_string_equal(fk.seq, "cmd:offreq=1,cmd:AB 1;MO ABC,cmd:MG _MOA,"
				    "cmd:MG _MOB,cmd:MG _MOC,relay_off_start,"
				    "relay_off_finish");
	assert_string_equal(what, "motors off: confirmed; motor power off "
				  "(relay): confirmed");
}

/* Status snapshot: position %, pot against expected, limits, margin. */
static void test_super_status(void **state)
{
	struct re_status st;

	(void)state;
	fk.rec.axis[0].motor_pos = 25000;
	set_pot(0, 3.5);
	fk.rec.axis[0].switches = GL_AXSW_RLS; /* forward limit active */
	assert_int_equal(step(), RE_OK);
	re_super_status(&sup, &st);
	assert_int_equal(st.axis[0].enc_counts, 25000);
	assert_true(st.axis[0].pos_pct > 74.99 && st.axis[0].pos_pct < 75.01);
	assert_true(st.axis[0].have_expect);
	assert_true(st.axis[0].pot_expected_v > 3.499 &&
		    st.axis[0].pot_expected_v < 3.501);
	assert_true(st.axis[0].margin_v > 0.059 && st.axis[0].margin_v < 0.061);
	assert_int_equal(st.axis[0].fwd_limit, 1);
	assert_int_equal(st.axis[0].rev_limit, 0);
	assert_int_equal(st.cycles, 1);
}

/* Unsolicited lines from the program go to the log. */
static void test_super_messages_logged(void **state)
{
	(void)state;
	fk.msgs[0] = "FAULT 4 2 5012";
	fk.n_msgs = 1;
	assert_int_equal(step(), RE_OK);
	assert_int_equal(fk.n_logs, 1);
	assert_string_equal(fk.logs[0], "controller: FAULT 4 2 5012");
}

/* No heap allocation in the cycle (wrapped malloc count and the arena). */
static void test_super_no_alloc(void **state)
{
	struct mallinfo2 before, after;
	long n0;

	(void)state;
	assert_int_equal(run(2), RE_OK);
	before = mallinfo2();
	n0 = n_allocs;
	assert_int_equal(run(1000), RE_OK);
	set_pot(0, 3.0);
	assert_int_equal(run(5), RE_FAULT);
	assert_int_equal(run(50), RE_OK);
	after = mallinfo2();
	assert_int_equal(n_allocs, n0);
	assert_int_equal(after.uordblks, before.uordblks);
}

static int find_log(const char *a)
{
	for (int i = 0; i < fk.n_logs; i++)
		if (strstr(fk.logs[i], a))
			return i;
	return -1;
}

/* Read the trace at @path (strictly) into @h and @r. */
static void read_trace(const char *path, struct re_trace_hdr *h,
		       struct re_trace_rec **r)
{
	char *buf, err[256];
	size_t len;

	assert_int_equal(base_file_read(path, RE_TRACE_MAX_BYTES, &buf, &len),
			 0);
	if (re_trace_parse(buf, len, h, r, err, sizeof(err)) != GL_OK)
		fail_msg("%s: %s", path, err);
	free(buf);
}

/* The flight recorder on the cycle: no allocation in any cycle
 * (the ring is allocated at start-up), the FAULT log entry names the
 * trace, which is written only once after_fault_s has passed, and holds
 * the cycles before the fault, the fault cycle and those after it, with
 * the potentiometer step in the cycle that first saw it. */
static void test_super_recorder(void **state)
{
	static struct re_rec rec;
	struct re_rec_cfg rc = {.seconds = 2,
				.after_fault_s = 0.5,
				.period_ms = PERIOD_MS,
				.n_axes = 3,
				.axis_names = {"A", "B", "C"},
				.config_hash = 0x1234};
	char dir[] = "/tmp/test_re_rec.XXXXXX", path[RE_REC_PATH], err[256];
	char want[RE_REC_PATH + 8];
	struct re_trace_hdr h;
	struct re_trace_rec *r;
	size_t n;
	double ms;
	long n0;
	int i;

	(void)state;
	assert_non_null(mkdtemp(dir));
	rc.dir = dir;
	assert_int_equal(re_rec_init(&rec, &rc), GL_OK);
	assert_int_equal(rec.cap, 50); /* (2 + 0.5) s / 50 ms */
	re_rec_attach(&rec, &sup, "12345");
	assert_int_equal(run(2), RE_OK);
	n0 = n_allocs;
	assert_int_equal(run(100), RE_OK);
	set_pot(0, 3.0);
	assert_int_equal(run(5), RE_FAULT);
	i = find_log("| trace ");
	assert_true(i >= 0);
	assert_int_equal(fk.log_level[i], RE_LOG_FAULT);
	snprintf(want, sizeof(want), "| trace %s", rec.fault_path);
	assert_non_null(strstr(fk.logs[i], want));
	assert_int_equal(strncmp(rec.fault_path, dir, strlen(dir)), 0);
	assert_int_equal(run(9), RE_OK); /* 0.45 s: not yet due */
	assert_int_equal(re_rec_poll(&rec, fk.now), 0);
	assert_int_equal(run(11), RE_OK);
	assert_int_equal(n_allocs, n0);
	assert_int_equal(re_rec_poll(&rec, fk.now), 1);
	re_rec_finish(&rec);
	assert_int_equal(
	    re_rec_done(&rec, path, sizeof(path), err, sizeof(err), &n, &ms),
	    1);
	assert_string_equal(path, rec.fault_path);
	assert_int_equal(n, 50);
	read_trace(path, &h, &r);
	re_rec_free(&rec);
	assert_int_equal(h.n_records, 50);
	assert_string_equal(h.serial, "12345");
	assert_string_equal(h.reason, "fault");
	assert_int_equal(h.have_fault, 1);
	assert_int_equal(strncmp(h.fault_text, "FAULT ", 6), 0);
	assert_int_equal(r[49].cycle, (int32_t)sup.pub.cycles);
	/* 20 latched cycles after the fault cycle, 29 before it */
	assert_int_equal(r[29].phase, RE_TPH_FAULT);
	assert_int_equal(r[28].phase, RE_TPH_ARMED);
	assert_true(r[29].fault != 0);
	assert_float_equal(r[29].t_s, h.fault_t_s, 1e-6);
	/* the step: first seen one cycle before the fault (persistence 1) */
	assert_float_equal(r[27].axis[0].pot_v, 2.5, 1e-3);
	assert_float_equal(r[28].axis[0].pot_v, 3.0, 1e-3);
	assert_true(r[28].axis[0].margin_v < 0);
	assert_true(r[27].axis[0].margin_v > 0);
	assert_float_equal(r[28].t_s - r[27].t_s, PERIOD_MS / 1000.0, 1e-3);
	free(r);
	unlink(path);
	rmdir(dir);
}

/* The lateness percentiles of the exit statistics: upper bin edges, the
 * worst value for 100 %, 0 with no cycle. */
static void test_super_late_percentiles(void **state)
{
	static struct re_super s; /* zeroed; only the histogram is used */

	(void)state;
	memset(&s, 0, sizeof(s));
	assert_true(re_super_late_ms(&s, 50) == 0.0);
	s.late_hist[0] = 90; /* 90 cycles late by less than 50 us */
	s.late_hist[4] = 9;  /* 9 cycles at 200..250 us */
	s.late_hist[RE_LATE_BINS - 1] = 1; /* one beyond 100 ms */
	s.late_worst_ns = 123456789;
	assert_true(re_super_late_ms(&s, 50) == 0.05);
	assert_true(re_super_late_ms(&s, 90) == 0.05);
	assert_true(re_super_late_ms(&s, 91) == 0.25);
	assert_true(re_super_late_ms(&s, 99) == 0.25);
	assert_true(re_super_late_ms(&s, 99.5) == 123.456789);
	assert_true(re_super_late_ms(&s, 100) == 123.456789);
	/* a percentile never reads above the worst (it was p99=3.950
	 * max=3.931: the bin's upper edge) */
	memset(&s, 0, sizeof(s));
	s.late_hist[3] = 100; /* 150..200 us */
	s.late_worst_ns = 180000;
	assert_true(re_super_late_ms(&s, 99) == 0.18);
	assert_true(re_super_late_ms(&s, 100) == 0.18);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup(test_super_healthy_one_round_trip, setup),
	    cmocka_unit_test_setup(test_super_hbpc_text, setup),
	    cmocka_unit_test_setup(test_super_events_ring, setup),
	    cmocka_unit_test_setup(test_super_encpot_fault_order, setup),
	    cmocka_unit_test_setup(test_super_encpot_transient, setup),
	    cmocka_unit_test_setup(test_super_watchdog_noncritical, setup),
	    cmocka_unit_test_setup(test_super_wd_summary, setup),
	    cmocka_unit_test_setup(test_super_wd_no_summary, setup),
	    cmocka_unit_test_setup(test_super_wd_fault_flushes, setup),
	    cmocka_unit_test_setup(test_super_wd_quit_flushes, setup),
	    cmocka_unit_test_setup(test_super_watchdog_critical, setup),
	    cmocka_unit_test_setup(test_super_stall_in_round_trip, setup),
	    cmocka_unit_test_setup(test_super_stall_in_cycle_tail, setup),
	    cmocka_unit_test_setup(test_super_comm_fault, setup),
	    cmocka_unit_test_setup(test_super_foreign_named, setup),
	    cmocka_unit_test_setup(test_super_consequences, setup),
	    cmocka_unit_test_setup(test_super_ctrl_ours, setup),
	    cmocka_unit_test_setup(test_super_power_loss_ours, setup),
	    cmocka_unit_test_setup(test_super_relay_lost, setup),
	    cmocka_unit_test_setup(test_super_controller_fault, setup),
	    cmocka_unit_test_setup(test_super_motor_off, setup),
	    cmocka_unit_test_setup(test_super_settle_program_verdict, setup),
	    cmocka_unit_test_setup(test_super_settle_timeout, setup),
	    cmocka_unit_test_setup(test_super_thread_missing, setup),
	    cmocka_unit_test_setup(test_super_heartbeat_frozen, setup),
	    cmocka_unit_test_setup(test_super_sample_frozen, setup),
	    cmocka_unit_test_setup(test_super_latch, setup),
	    cmocka_unit_test_setup(test_super_schedule_overrun, setup),
	    cmocka_unit_test_setup(test_super_shutdown, setup),
	    cmocka_unit_test_setup(test_super_status, setup),
	    cmocka_unit_test_setup(test_super_messages_logged, setup),
	    cmocka_unit_test_setup(test_super_no_alloc, setup),
	    cmocka_unit_test_setup(test_super_recorder, setup),
	    cmocka_unit_test(test_super_late_percentiles),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
