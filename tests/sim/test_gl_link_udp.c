/*
 * test_gl_link_udp.c - the link's record stream and posted lines
 * (pc/galil/gl_link_udp.c, gl_link_post.c) against galil-sim over real
 * sockets ($ROBOELF_BIN/galil-sim --udp-port 0): gl_link_stream_open()
 * finds the UDP handle with WH and starts DR; records arrive n0 samples
 * apart and are read without waiting; a stalled stream makes no record
 * and ages; a QR over TCP while the stream is late makes the records on
 * their way superseded, not reordered; DR refused (n1 of a TCP handle is
 * impossible here, so an interval the controller refuses) is reported
 * with its text; a posted line is collected later, and another command
 * waits for it first; gl_link_stream_close() stops the stream (DR 0).
 *
 * Every wait polls with a deadline.
 */
#include <poll.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link.h"
#include "gl_stream.h"
#include "proc.h"

#define START_MS  5000 /* ready line deadline */
#define REPLY_MS  2000 /* generous reply deadline */
#define SAMPLE_NS 1000000 /* galil-sim's sample */

struct fx {
	struct proc_sim sim;
	int ctl;
	gl_link *l;
	char addr[64];
	char resp[65536];
};

static int teardown(void **state);

static int setup(void **state)
{
	static char *const extra[] = {(char *)"--udp-port", (char *)"0", NULL};
	const char *bin = getenv("ROBOELF_BIN");
	struct fx *f = calloc(1, sizeof(*f));

	if (!f)
		return -1;
	*state = f;
	f->ctl = -1;
	if (!bin || proc_sim_start(&f->sim, bin, NULL, extra, START_MS) < 0) {
		fprintf(stderr, "galil-sim did not start (ROBOELF_BIN?)\n");
		teardown(state);
		return -1;
	}
	f->ctl = proc_ctl_connect(f->sim.ctl_port, REPLY_MS);
	snprintf(f->addr, sizeof(f->addr), "127.0.0.1:%d", f->sim.port);
	if (f->ctl < 0 || f->sim.udp_port <= 0 ||
	    gl_link_open(&f->l, f->addr, REPLY_MS, NULL) != GL_OK) {
		teardown(state);
		return -1;
	}
	return 0;
}

static int teardown(void **state)
{
	struct fx *f = *state;

	gl_link_close(f->l);
	if (f->ctl >= 0)
		close(f->ctl);
	proc_kill(&f->sim.p);
	free(f);
	return 0;
}

static const char *ctl(struct fx *f, const char *req)
{
	if (proc_ctl_request(f->ctl, req, f->resp, sizeof(f->resp), REPLY_MS) <
	    0)
		fail_msg("no answer to '%s'", req);
	return f->resp;
}

/* Read the stream until a new record came (1) or @ms passed (0). */
static int next_record(struct fx *f, struct gl_record *rec, int ms)
{
	int64_t end = base_now_ms() + ms;
	struct pollfd p = {.fd = gl_link_stream_fd(f->l), .events = POLLIN};
	int rc;

	do {
		rc = gl_link_stream_read(f->l, rec, base_now_ns());
		if (rc != 0)
			return rc;
		poll(&p, 1, 5);
	} while (base_now_ms() < end);
	return 0;
}

/* The stream opens on the handle WH names; records come n0 apart. */
static void test_open_and_read(void **state)
{
	struct fx *f = *state;
	struct gl_record rec;
	struct gl_stream_stats st;
	char err[GL_ERRTEXT_LEN], resp[64];
	uint16_t first;
	unsigned n0 = 0;
	int h = -1;

	assert_int_equal(gl_link_stream_open(f->l, f->sim.udp_port, 10,
					     SAMPLE_NS, 0, err),
			 GL_OK);
	assert_int_equal(gl_link_stream_info(f->l, &h, &n0), 1);
	assert_int_equal(n0, 10);
	assert_int_equal(h, 1); /* TCP took A; the UDP peer B */
	assert_true(gl_link_command(f->l, "MG _DR0,_DR1", resp, sizeof(resp),
				    0) > 0);
	assert_string_equal(resp, " 10.0000 1.0000");
	assert_int_equal(next_record(f, &rec, REPLY_MS), 1);
	first = rec.sample;
	for (int i = 0; i < 5; i++)
		assert_int_equal(next_record(f, &rec, REPLY_MS), 1);
	gl_link_stream_stats(f->l, &st);
	assert_true(st.accepted >= 6);
	/* every record read: the samples advanced by n0 per record */
	assert_int_equal((uint16_t)(rec.sample - first) % 10, 0);
	assert_true((uint16_t)(rec.sample - first) >= 50);
	assert_true(gl_link_stream_age_ns(f->l, base_now_ns()) < 1000000000);
	assert_int_equal(gl_link_stream_close(f->l, 0), GL_OK);
	assert_int_equal(gl_link_stream_info(f->l, NULL, NULL), 0);
	assert_int_equal(gl_link_command(f->l, "MG _DR0", resp, sizeof(resp),
					 0),
			 (int)strlen(" 0.0000"));
}

/* A stalled stream: no record, the age grows; TCP still answers. */
static void test_stall_ages(void **state)
{
	struct fx *f = *state;
	struct gl_record rec;
	char resp[64];
	int64_t t0;

	assert_int_equal(gl_link_stream_open(f->l, f->sim.udp_port, 5,
					     SAMPLE_NS, 0, NULL),
			 GL_OK);
	assert_int_equal(next_record(f, &rec, REPLY_MS), 1);
	assert_string_equal(ctl(f, "link stall stream"), "ok");
	next_record(f, &rec, 50); /* what was on its way */
	t0 = base_now_ns();
	assert_int_equal(next_record(f, &rec, 300), 0);
	assert_true(gl_link_stream_age_ns(f->l, base_now_ns()) >=
		    base_now_ns() - t0);
	assert_int_equal(gl_link_command(f->l, "MG 7", resp, sizeof(resp), 0),
			 (int)strlen(" 7.0000"));
	assert_string_equal(ctl(f, "link ok"), "ok");
	assert_int_equal(next_record(f, &rec, REPLY_MS), 1);
}

/* A QR round trip over TCP while the stream is 300 ms late: the records
 * made after the last one read (A) up to the QR's sample S, still on their
 * way, are superseded, exactly (S - A) / n0 of them; none is counted as
 * reordered, duplicate or lost, and the first record after S is accepted. */
static void test_qr_supersedes(void **state)
{
	struct fx *f = *state;
	struct gl_stream_stats st0, st1;
	struct gl_record rec, qr;
	uint16_t a;
	int64_t end;

	assert_int_equal(gl_link_stream_open(f->l, f->sim.udp_port, 2,
					     SAMPLE_NS, 0, NULL),
			 GL_OK);
	assert_string_equal(ctl(f, "link delay 300 stream"), "ok");
	/* past the records sent before the delay: one that arrives 250 ms
	 * after it was made at least 300 ms before */
	end = base_now_ms() + 250;
	do
		assert_int_equal(next_record(f, &rec, REPLY_MS), 1);
	while (base_now_ms() < end);
	a = rec.sample; /* the newest accepted: nothing else was fed */
	gl_link_stream_stats(f->l, &st0);
	assert_int_equal(gl_link_record(f->l, NULL, &qr, 0), GL_OK);
	/* the records up to the QR's come first and are all dropped */
	assert_int_equal(next_record(f, &rec, REPLY_MS), 1);
	assert_in_range((uint16_t)(rec.sample - qr.sample), 1, 32767);
	gl_link_stream_stats(f->l, &st1);
	/* 300 ms behind, less a simulated clock lagging the wall's */
	assert_true((uint16_t)(qr.sample - a) >= 200);
	assert_int_equal(st1.superseded - st0.superseded,
			 (uint16_t)(qr.sample - a) / 2);
	assert_int_equal(st1.reordered, 0);
	assert_int_equal(st1.duplicates, 0);
	assert_int_equal(st1.lost, 0);
	assert_true(st1.accepted > st0.accepted);
}

/* An interval the controller refuses: its own words come back. */
static void test_dr_refused(void **state)
{
	struct fx *f = *state;
	char err[GL_ERRTEXT_LEN];
	int code = 0;

	assert_int_equal(gl_link_stream_open(f->l, f->sim.udp_port, 30001,
					     SAMPLE_NS, 0, err),
			 GL_ERR_ARG); /* beyond the reader's horizon */
	assert_int_equal(gl_link_stream_open(f->l, f->sim.udp_port, 16383,
					     SAMPLE_NS, 0, err),
			 GL_OK);
	assert_int_equal(gl_link_stream_close(f->l, 0), GL_OK);
	/* no UDP port there: WH is never answered */
	assert_int_equal(gl_link_stream_open(f->l, 9, 10, SAMPLE_NS, 300, err),
			 GL_ERR_TIMEOUT);
	assert_string_equal(err, "no answer to WH on UDP port 9");
	assert_int_equal(gl_link_stream_info(f->l, NULL, NULL), 0);
	(void)code;
}

/* Collect the oldest outstanding reply within REPLY_MS. */
static int collect_one(struct fx *f, char *text, size_t cap)
{
	int64_t end = base_now_ms() + REPLY_MS;
	int rc;

	while ((rc = gl_link_collect(f->l, text, cap)) == GL_ERR_AGAIN &&
	       base_now_ms() < end)
		poll(NULL, 0, 1);
	return rc;
}

/* Posted lines' replies are collected later, in order; up to
 * GL_LINK_POST_MAX outstanding; a command waits for them first. */
static void test_post_collect(void **state)
{
	struct fx *f = *state;
	char text[64];

	assert_int_equal(gl_link_post(f->l, "hbx=5;MG hbx"), GL_OK);
	assert_int_equal(gl_link_post(f->l, "hbx=6"), GL_OK);
	assert_int_equal(gl_link_post(f->l, "MG hbx"), GL_OK);
	assert_int_equal(gl_link_posted(f->l), 3);
	assert_int_equal(collect_one(f, text, sizeof(text)),
			 (int)strlen(" 5.0000"));
	assert_string_equal(text, " 5.0000");
	assert_int_equal(collect_one(f, text, sizeof(text)), 0);
	assert_int_equal(collect_one(f, text, sizeof(text)),
			 (int)strlen(" 6.0000"));
	assert_string_equal(text, " 6.0000");
	assert_int_equal(gl_link_posted(f->l), 0);
	assert_int_equal(gl_link_collect(f->l, text, sizeof(text)),
			 GL_ERR_NOENT);
	/* the limit: one more is refused, nothing sent */
	for (int i = 0; i < GL_LINK_POST_MAX; i++)
		assert_int_equal(gl_link_post(f->l, "hbx=7"), GL_OK);
	assert_int_equal(gl_link_post(f->l, "hbx=8"), GL_ERR_BUSY);
	/* a command at once: it takes every posted reply first */
	assert_int_equal(gl_link_command(f->l, "MG hbx", text, sizeof(text),
					 0),
			 (int)strlen(" 7.0000"));
	assert_string_equal(text, " 7.0000");
	assert_int_equal(gl_link_posted(f->l), 0);
	assert_int_equal(gl_link_collect(f->l, text, sizeof(text)),
			 GL_ERR_NOENT);
	assert_int_equal(gl_link_post_errors(f->l), 0);
	/* refused posted lines: set aside by a command, counted; collected
	 * while others wait: GL_ERR_CTRL; the last: the controller's text */
	assert_int_equal(gl_link_post(f->l, "XYZZY"), GL_OK);
	assert_int_equal(gl_link_command(f->l, "MG 2", text, sizeof(text), 0),
			 (int)strlen(" 2.0000"));
	assert_int_equal(gl_link_post_errors(f->l), 1);
	assert_int_equal(gl_link_post(f->l, "XYZZY"), GL_OK);
	assert_int_equal(gl_link_post(f->l, "XYZZY"), GL_OK);
	assert_int_equal(collect_one(f, text, sizeof(text)), GL_ERR_CTRL);
	assert_int_equal(gl_link_post_errors(f->l), 2);
	assert_int_equal(collect_one(f, text, sizeof(text)), GL_ERR_CTRL);
	assert_int_equal(gl_link_post_errors(f->l), 2);
	assert_string_equal(gl_link_ctrl_error(f->l, NULL),
			    "Unrecognized command");
	assert_false(gl_link_broken(f->l));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_open_and_read, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_stall_ages, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_dr_refused, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_qr_supersedes, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_post_collect, setup,
					    teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
