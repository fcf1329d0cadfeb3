/*
 * test_ctrl_stream.c - DR, the data record as a stream, in the simulated
 * DMC-4030 in virtual time: the replies and refusals of DR (minimum 2
 * samples, TC 6; a handle that is not UDP, TC 133), _DR0/_DR1, one record
 * every n0 samples (the QR bytes, checked by their sample number), the
 * pause during a download, UDP handles (_IHh2, TH, the record's handle
 * bytes) and IH=>-1 closing them, the stream stopping with its handle,
 * and the events of DR starting and stopping the stream.
 * Expectations: galil-notes.md 1.1 and 2.6, real-controller-facts.md (DR),
 * docs/galil-sim.md "The record stream".
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "gl_record.h"
#include "test_ctrl_util.h"

#define TCP_A 0 /* handle A: a TCP host */
#define UDP_B 1 /* handle B: a UDP peer */

static int setup(void **state)
{
	static struct tplant p;

	if (tp_init(&p))
		return -1;
	ctrl_handle_open(p.c, TCP_A);
	ctrl_handle_open_udp(p.c, UDP_B);
	ctrl_handle_peer(p.c, UDP_B, 60007, 0x7f000001u, 40000);
	tp_step(&p, 1);
	*state = &p;
	return 0;
}

static int teardown(void **state)
{
	tp_free(*state);
	return 0;
}

static void exchange(struct tplant *p, int h, const char *send,
		     const char *want)
{
	char buf[4096];

	tp_send(p, h, send);
	tp_out(p, h, buf, sizeof(buf));
	assert_string_equal(buf, want);
}

/* @line is refused with '?' and TC @tc (its text @text). */
static void refused(struct tplant *p, const char *line, const char *tc_text)
{
	exchange(p, TCP_A, line, "?");
	exchange(p, TCP_A, "TC1\r", tc_text);
}

static int records_waiting(struct tplant *p, uint16_t *sample, int max)
{
	uint8_t rec[GL_REC_MAX_BYTES];
	int h, n = 0;

	while (ctrl_stream_take(p->c, &h, rec, sizeof(rec))) {
		assert_int_equal(h, UDP_B);
		if (n < max)
			sample[n] = (uint16_t)(rec[4] | rec[5] << 8);
		n++;
	}
	return n;
}

/* DR n0,n1: accepted, read back, and each refusal exact. */
static void test_dr_replies(void **state)
{
	struct tplant *p = *state;

	exchange(p, TCP_A, "MG _DR0\r", " 0.0000\r\n:");
	exchange(p, TCP_A, "DR 10,1\r", ":");
	exchange(p, TCP_A, "MG _DR0\r", " 10.0000\r\n:");
	exchange(p, TCP_A, "MG _DR1\r", " 1.0000\r\n:");
	exchange(p, TCP_A, "DR 2,1\r", ":"); /* the minimum on a DMC-40x0 */
	exchange(p, TCP_A, "MG _DR0\r", " 2.0000\r\n:");
	refused(p, "DR 1,1\r", " 6 Number out of range\r\n:");
	refused(p, "DR -2,1\r", " 6 Number out of range\r\n:");
	refused(p, "DR 2.5,1\r", " 6 Number out of range\r\n:");
	refused(p, "DR 30001,1\r", " 6 Number out of range\r\n:");
	refused(p, "DR 10,8\r", " 6 Number out of range\r\n:");
	refused(p, "DR 10,0\r", " 133 Handle must be UDP\r\n:"); /* TCP */
	refused(p, "DR 10,2\r", " 133 Handle must be UDP\r\n:"); /* closed */
	refused(p, "DR\r", " 50 Not enough fields\r\n:");
	/* a refusal keeps the stream as it was */
	exchange(p, TCP_A, "MG _DR0\r", " 2.0000\r\n:");
	exchange(p, TCP_A, "MG _DR1\r", " 1.0000\r\n:");
	exchange(p, TCP_A, "DR 0\r", ":");
	exchange(p, TCP_A, "MG _DR0\r", " 0.0000\r\n:");
	exchange(p, TCP_A, "MG _DR1\r", " 1.0000\r\n:");
	/* without n1: the CF handle (serial after power-up: no UDP) */
	refused(p, "DR 10\r", " 133 Handle must be UDP\r\n:");
	exchange(p, TCP_A, "CF B\r", ":");
	exchange(p, TCP_A, "DR 10\r", ":");
	exchange(p, TCP_A, "MG _DR1\r", " 1.0000\r\n:");
	exchange(p, TCP_A, "DR 0,3\r", ":"); /* stopping needs no UDP */
	exchange(p, TCP_A, "MG _DR1\r", " 3.0000\r\n:");
	exchange(p, UDP_B, "WH\r", "IHB\r\n:");
}

/* One record every n0 samples, each the QR bytes of its sample. */
static void test_interval(void **state)
{
	struct tplant *p = *state;
	uint8_t rec[GL_REC_MAX_BYTES];
	char qr[1024];
	uint16_t s[16];
	size_t n, q;

	exchange(p, TCP_A, "DR 5,1\r", ":");
	tp_step(p, 4);
	assert_int_equal(records_waiting(p, s, 16), 0);
	tp_step(p, 1);
	assert_int_equal(records_waiting(p, s, 16), 1);
	tp_step(p, 50);
	assert_int_equal(records_waiting(p, s, 16), 10);
	for (int i = 1; i < 10; i++)
		assert_int_equal((uint16_t)(s[i] - s[i - 1]), 5);
	tp_step(p, 5);
	n = ctrl_stream_take(p->c, NULL, rec, sizeof(rec));
	assert_int_equal(n, rec[2] | rec[3] << 8);
	assert_int_equal(rec[0], 0x87); /* S, T, I blocks */
	assert_int_equal(rec[1], 0x07); /* axes A-C */
	tp_send(p, TCP_A, "QR\r");
	q = tp_out(p, TCP_A, qr, sizeof(qr));
	assert_int_equal(q, n + 1); /* QR adds only its ':' */
	assert_memory_equal(qr, rec, n);
	assert_int_equal(qr[n], ':');
	/* DR 2: every other sample */
	exchange(p, TCP_A, "DR 2,1\r", ":");
	tp_step(p, 20);
	assert_int_equal(records_waiting(p, s, 16), 10);
	assert_int_equal((uint16_t)(s[9] - s[0]), 18);
	exchange(p, TCP_A, "DR 0\r", ":");
	tp_step(p, 20);
	assert_int_equal(records_waiting(p, s, 16), 0);
}

/* No record while a download is in progress; the interval restarts at
 * its end. UL and LS finish between two samples: no record is lost. */
static void test_pause(void **state)
{
	struct tplant *p = *state;
	char buf[256];
	uint16_t s[64];

	exchange(p, TCP_A, "DR 4,1\r", ":");
	tp_step(p, 2);
	exchange(p, TCP_A, "DL\r", "");
	tp_step(p, 40);
	assert_int_equal(records_waiting(p, s, 64), 0);
	exchange(p, TCP_A, "#A\rEN\r", "");
	tp_step(p, 40);
	assert_int_equal(records_waiting(p, s, 64), 0);
	exchange(p, TCP_A, "\\", "::");
	tp_step(p, 3);
	assert_int_equal(records_waiting(p, s, 64), 0);
	tp_step(p, 1);
	assert_int_equal(records_waiting(p, s, 64), 1);
	tp_step(p, 2);
	tp_send(p, TCP_A, "UL\r");
	tp_out(p, TCP_A, buf, sizeof(buf));
	tp_step(p, 2);
	assert_int_equal(records_waiting(p, s, 64), 1);
	exchange(p, TCP_A, "DR 0\r", ":");
}

/* UDP handles: _IHh2 1, TH, the record's handle bytes; IH=>-1 closes the
 * UDP ones only; the stream stops with its handle and at a power cycle. */
static void test_udp_handles(void **state)
{
	struct tplant *p = *state;
	uint8_t rec[GL_REC_MAX_BYTES];
	char th[1024];

	exchange(p, TCP_A, "MG _IHA2, _IHB2, _IHC2\r",
		 " 2.0000 1.0000 0.0000\r\n:");
	tp_send(p, TCP_A, "TH\r");
	tp_out(p, TCP_A, th, sizeof(th));
	assert_non_null(strstr(th, "IHB UDP PORT 60007 TO IP ADDRESS "
				   "127,0,0,1 PORT 40000\r\n"));
	exchange(p, TCP_A, "DR 3,1\r", ":");
	tp_step(p, 3);
	assert_int_equal(ctrl_stream_take(p->c, NULL, rec, sizeof(rec)), 190);
	assert_int_equal(rec[42], 2); /* handle A TCP */
	assert_int_equal(rec[43], 1); /* handle B UDP */
	assert_int_equal(rec[44], 0);
	ctrl_handle_open(p->c, 3);
	exchange(p, TCP_A, "IHT=>-2\r", ":");
	assert_false(ctrl_handle_close_wanted(p->c, UDP_B));
	assert_true(ctrl_handle_close_wanted(p->c, 3));
	ctrl_handle_close(p->c, 3);
	exchange(p, TCP_A, "IHT=>-1\r", ":");
	assert_true(ctrl_handle_close_wanted(p->c, UDP_B));
	assert_false(ctrl_handle_close_wanted(p->c, TCP_A));
	tp_step(p, 3); /* the network layer closes it after the reply */
	ctrl_stream_take(p->c, NULL, rec, sizeof(rec));
	ctrl_handle_close(p->c, UDP_B);
	assert_true(tp_has_event(p, "handle B closed by IHT from handle A"));
	exchange(p, TCP_A, "MG _DR0\r", " 0.0000\r\n:");
	tp_step(p, 9);
	assert_int_equal(ctrl_stream_take(p->c, NULL, rec, sizeof(rec)), 0);
	/* a power cycle stops it too */
	ctrl_handle_open_udp(p->c, UDP_B);
	exchange(p, TCP_A, "DR 3,1\r", ":");
	ctrl_power_cycle(p->c);
	tp_step(p, 9);
	assert_int_equal(ctrl_stream_take(p->c, NULL, rec, sizeof(rec)), 0);
	assert_int_equal(tp_mg(p, "_DR0"), 0);
}

/* The event of the last statement: exactly @want, and only it since
 * @before events. */
static void last_event(const struct tplant *p, int before, const char *want)
{
	assert_int_equal(p->nevents, before + 1);
	assert_string_equal(p->events[p->nevents - 1], want);
}

/* Each DR that takes effect is an event naming the stream's handle, its
 * interval and who sent it; each stop (DR 0, its handle closed, a power
 * cycle) names why and the records made since the DR that started it; a
 * refused DR and a DR 0 with nothing running are silent. */
static void test_dr_events(void **state)
{
	struct tplant *p = *state;
	uint8_t rec[GL_REC_MAX_BYTES];
	int n = p->nevents;

	exchange(p, TCP_A, "DR 5,1\r", ":");
	last_event(p, n, "handle B: data record every 5 samples (handle A)");
	tp_step(p, 25);
	exchange(p, TCP_A, "DR 0\r", ":");
	last_event(p, n + 1,
		   "handle B: data record stopped: DR 0 (handle A); records "
		   "made: 5");
	n = p->nevents;
	exchange(p, TCP_A, "DR 0,1\r", ":");
	refused(p, "DR 1,1\r", " 6 Number out of range\r\n:");
	assert_int_equal(p->nevents, n);
	exchange(p, UDP_B, "DR 2,1\r", ":"); /* from the UDP handle itself */
	last_event(p, n, "handle B: data record every 2 samples (handle B)");
	tp_step(p, 7);
	exchange(p, TCP_A, "DR 4,1\r", ":"); /* a new interval, a new count */
	last_event(p, n + 1,
		   "handle B: data record every 4 samples (handle A)");
	tp_step(p, 8);
	while (ctrl_stream_take(p->c, NULL, rec, sizeof(rec)))
		;
	ctrl_handle_close(p->c, UDP_B);
	last_event(p, n + 2,
		   "handle B: data record stopped: handle closed; records "
		   "made: 2");
	ctrl_handle_open_udp(p->c, UDP_B);
	exchange(p, TCP_A, "DR 3,1\r", ":");
	tp_step(p, 3);
	ctrl_power_cycle(p->c);
	assert_true(tp_has_event(p, "handle B: data record stopped: power "
				    "cycle; records made: 1"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_dr_replies, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_interval, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_pause, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_udp_handles, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_dr_events, setup, teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
