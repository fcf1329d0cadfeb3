/*
 * test_re_linkmeas.c - the link's measurement (pc/start/re_linkmeas.c):
 * the statistics of the records' arrival (exact, the sample number's wrap
 * included), the median, the start-up line in both forms, the refusals
 * without a stream; and the reply time against a real galil-sim
 * ($ROBOELF_BIN/galil-sim, started by pid, every wait with a deadline).
 * The stream's own reading against galil-sim needs gl_link's stream
 * (gl_link_stream_open) and is proven by the system tests with
 * ROBOELF_SYS_RECORD=stream.
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
#include "gl_link.h"
#include "proc.h"
#include "re_linkmeas.h"

#define MS	 1000000LL
#define START_MS 5000

/* 20 records every 12 samples, arriving 11.5 to 12.0 ms apart; the
 * sample number wraps past 65535 on the way. */
static void test_intervals_exact(void **state)
{
	int64_t t[20];
	uint16_t s[20];
	struct re_linkmeas m = {0};

	(void)state;
	t[0] = 1000 * MS;
	s[0] = 65500;
	for (int i = 1; i < 20; i++) {
		/* 11.5 ms ten times (odd i), 12.0 ms nine: 223 ms in all */
		t[i] = t[i - 1] + (i % 2 ? 11500000 : 12000000);
		s[i] = (uint16_t)(s[i - 1] + 12);
	}
	assert_int_equal(re_linkmeas_intervals(t, s, NULL, 20, &m), GL_OK);
	assert_int_equal(m.records, 20);
	assert_true(m.mean_ms > 223.0 / 19 - 1e-9 &&
		    m.mean_ms < 223.0 / 19 + 1e-9);
	assert_true(m.min_ms > 11.4999 && m.min_ms < 11.5001);
	assert_true(m.max_ms > 11.9999 && m.max_ms < 12.0001);
	assert_true(m.step_samples > 11.9999 && m.step_samples < 12.0001);
	assert_int_equal(re_linkmeas_intervals(t, s, NULL, 1, &m), GL_ERR_ARG);
	assert_int_equal(re_linkmeas_intervals(NULL, s, NULL, 20, &m),
			 GL_ERR_ARG);
}

/* Reads that took several records each (late wake-ups): 6 reads of a
 * record every 2 samples (2 ms); the first read's 4 count as its newest
 * only, the third took 3 records, the sixth 2: 1 + 1 + 3 + 1 + 1 + 2 = 9
 * records over 16 ms (2 ms each), nothing lost by their numbers (16
 * samples over 8 intervals), the minimum 0. */
static void test_intervals_batches(void **state)
{
	const int64_t t[6] = {100 * MS, 102 * MS, 108 * MS,
			      110 * MS, 112 * MS, 116 * MS};
	const uint16_t s[6] = {40, 42, 48, 50, 52, 56};
	const int c[6] = {4, 1, 3, 1, 1, 2};
	const int bad[6] = {1, 1, 0, 1, 1, 1};
	struct re_linkmeas m = {0};

	(void)state;
	assert_int_equal(re_linkmeas_intervals(t, s, c, 6, &m), GL_OK);
	assert_int_equal(m.records, 9);
	assert_true(m.mean_ms > 1.9999 && m.mean_ms < 2.0001);
	assert_true(m.min_ms == 0);
	assert_true(m.max_ms > 5.9999 && m.max_ms < 6.0001);
	assert_true(m.step_samples > 1.9999 && m.step_samples < 2.0001);
	/* read one by one, the same records said one was lost: 16 samples
	 * over 5 intervals, 3.2 ms each */
	assert_int_equal(re_linkmeas_intervals(t, s, NULL, 6, &m), GL_OK);
	assert_int_equal(m.records, 6);
	assert_true(m.step_samples > 3.1999 && m.step_samples < 3.2001);
	m.records = 77;
	assert_int_equal(re_linkmeas_intervals(t, s, bad, 6, &m), GL_ERR_ARG);
	assert_int_equal(m.records, 77);
}

static void test_median(void **state)
{
	int64_t odd[] = {9 * MS / 10, 3 * MS / 10, 4 * MS / 10};
	int64_t even[] = {4 * MS / 10, 1 * MS / 10, 2 * MS / 10, 9 * MS};

	(void)state;
	assert_true(re_linkmeas_median_ms(odd, 3) > 0.3999 &&
		    re_linkmeas_median_ms(odd, 3) < 0.4001);
	/* the mean of the middle two: 0.2 and 0.4 */
	assert_true(re_linkmeas_median_ms(even, 4) > 0.2999 &&
		    re_linkmeas_median_ms(even, 4) < 0.3001);
	assert_true(re_linkmeas_median_ms(even, 0) == 0);
}

static void test_line_stream(void **state)
{
	struct re_linkmeas m = {.replies = 10,
				.reply_med_ms = 0.4,
				.reply_max_ms = 0.9,
				.records = 20,
				.handle = 1,
				.n0 = 12,
				.n0_ms = 11.71875,
				.mean_ms = 11.7,
				.min_ms = 11.5,
				.max_ms = 12.0,
				.step_samples = 12};
	char buf[400];

	(void)state;
	re_linkmeas_line(&m, buf, sizeof(buf));
	assert_string_equal(buf, "record stream: UDP handle B, every 12 "
				 "samples (11.7 ms); measured over 20 records "
				 "11.7 ms (11.5-12.0); command reply 0.4 ms "
				 "(max 0.9)");
	/* one record lost on the way: the numbers say so */
	m.step_samples = 12.6;
	re_linkmeas_line(&m, buf, sizeof(buf));
	assert_string_equal(buf, "record stream: UDP handle B, every 12 "
				 "samples (11.7 ms); measured over 20 records "
				 "11.7 ms (11.5-12.0), a record every 12.6 "
				 "samples by their numbers (not 12: lost or "
				 "uneven); command reply 0.4 ms (max 0.9)");
}

/* No stream: the reply time alone; under 0.1 ms two decimals. */
static void test_line_poll(void **state)
{
	struct re_linkmeas m = {
	    .replies = 10, .reply_med_ms = 0.052, .reply_max_ms = 0.31};
	char buf[200];

	(void)state;
	re_linkmeas_line(&m, buf, sizeof(buf));
	assert_string_equal(buf, "record polled (QR each cycle); command "
				 "reply 0.05 ms (max 0.3)");
}

/* A real galil-sim: ten round trips, each a reply; no stream open, so
 * reading records is refused at once. */
static void test_reply_sim(void **state)
{
	const char *bin = getenv("ROBOELF_BIN");
	struct re_linkmeas m = {0};
	struct proc_sim sim;
	char addr[64], err[GL_ERRTEXT_LEN];
	gl_link *l = NULL;

	(void)state;
	assert_non_null(bin);
	assert_int_equal(proc_sim_start(&sim, bin, NULL, NULL, START_MS), 0);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", sim.port);
	assert_int_equal(gl_link_open(&l, addr, START_MS, err), GL_OK);
	assert_int_equal(re_linkmeas_reply(l, 10, 1000, &m), GL_OK);
	assert_int_equal(m.replies, 10);
	assert_true(m.reply_med_ms > 0 && m.reply_med_ms <= m.reply_max_ms);
	assert_true(m.reply_max_ms < 1000);
	assert_int_equal(re_linkmeas_reply(l, 0, 1000, &m), GL_ERR_ARG);
	assert_int_equal(re_linkmeas_records(l, 20, 1000000, 100, &m),
			 GL_ERR_ARG);
	gl_link_close(l);
	proc_kill(&sim.p);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_intervals_exact),
	    cmocka_unit_test(test_intervals_batches),
	    cmocka_unit_test(test_median),
	    cmocka_unit_test(test_line_stream),
	    cmocka_unit_test(test_line_poll),
	    cmocka_unit_test(test_reply_sim),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
