/*
 * test_gl_stream.c - the DR stream reader on datagrams built with
 * gl_record_encode() (the decoder itself is checked against the published
 * offsets in test_gl_record.c): gaps, duplicates, reordering, records
 * superseded by one read over another route (gl_stream_seen()), the 16-bit
 * sample number's wrap, short, long, foreign and malformed datagrams, the
 * horizon, the age and the counters.
 *
 * The stream is a DMC-4030 record (3 axes, 190 bytes) every n0 = 8 samples
 * of 1 ms, from 192.168.1.10 port 23.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <string.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <cmocka.h>

#include "gl_err.h"
#include "gl_record.h"
#include "gl_stream.h"

#define REC_BYTES 190
#define N0	  8u
#define MS	  1000000LL
#define T0	  (1000 * MS) /* init time */

static struct gl_stream_peer peer(const char *ip4, uint16_t port)
{
	struct sockaddr_in a;
	struct gl_stream_peer p;

	memset(&a, 0, sizeof(a));
	a.sin_family = AF_INET;
	a.sin_port = htons(port);
	assert_int_equal(inet_pton(AF_INET, ip4, &a.sin_addr), 1);
	assert_int_equal(
	    gl_stream_peer_from_sockaddr((struct sockaddr *)&a, sizeof(a), &p),
	    GL_OK);
	return p;
}

static struct gl_stream_peer ctrl(void)
{
	return peer("192.168.1.10", 23);
}

/* A 190-byte record numbered @sample; axis A's motor position is @sample
 * too, so that a decoded record can be told from another. */
static void make(uint8_t b[REC_BYTES + 8], uint16_t sample)
{
	struct gl_record r;

	memset(&r, 0, sizeof(r));
	r.layout = GL_LAYOUT_4000;
	r.n_axes = 3;
	r.sample = sample;
	r.axis[0].motor_pos = 1000 + sample;
	assert_int_equal(gl_record_encode(&r, b, REC_BYTES + 8), REC_BYTES);
}

static void start(struct gl_stream *s)
{
	struct gl_stream_peer c = ctrl();

	assert_int_equal(gl_stream_init(s, &c, GL_LAYOUT_4000, 3, N0, MS, T0),
			 GL_OK);
}

/* Feed record @sample from the controller at @t_ns; the verdict. */
static int feed(struct gl_stream *s, uint16_t sample, int64_t t_ns,
		struct gl_record *out)
{
	uint8_t b[REC_BYTES + 8];
	struct gl_stream_peer c = ctrl();

	make(b, sample);
	return gl_stream_feed(s, b, REC_BYTES, &c, t_ns, out);
}

/* A dropped datagram leaves the caller's record as it was. */
static void assert_untouched(const struct gl_record *out)
{
	struct gl_record ref;

	memset(&ref, 0x5A, sizeof(ref));
	assert_memory_equal(out, &ref, sizeof(ref));
}

/* TEST_stream_gap: a gap of one record and of five are counted as lost,
 * and each record after a gap is accepted and decoded. */
static void test_stream_gap(void **state)
{
	struct gl_stream s;
	struct gl_record out;

	(void)state;
	start(&s);
	assert_int_equal(feed(&s, 100, T0 + 1 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(out.sample, 100);
	assert_int_equal(out.axis[0].motor_pos, 1100);
	assert_int_equal(feed(&s, 108, T0 + 9 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.lost, 0);
	/* 116 lost */
	assert_int_equal(feed(&s, 124, T0 + 25 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(out.sample, 124);
	assert_int_equal(out.axis[0].motor_pos, 1124);
	assert_int_equal(s.stats.lost, 1);
	/* 132, 140, 148, 156, 164 lost */
	assert_int_equal(feed(&s, 172, T0 + 73 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(out.sample, 172);
	assert_int_equal(s.stats.lost, 6);
	assert_int_equal(s.stats.accepted, 4);
	assert_int_equal(s.stats.received, 4);
	assert_int_equal(s.stats.uneven, 0);
	assert_int_equal(s.stats.restarts, 0);
}

/* TEST_stream_duplicate: the same number again is dropped, not decoded,
 * and does not count as a loss. */
static void test_stream_duplicate(void **state)
{
	struct gl_stream s;
	struct gl_record out;

	(void)state;
	start(&s);
	assert_int_equal(feed(&s, 100, T0 + 1 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(feed(&s, 108, T0 + 9 * MS, &out), GL_STREAM_ACCEPTED);
	memset(&out, 0x5A, sizeof(out));
	assert_int_equal(feed(&s, 108, T0 + 10 * MS, &out),
			 GL_STREAM_DUPLICATE);
	assert_untouched(&out);
	assert_int_equal(feed(&s, 116, T0 + 17 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.duplicates, 1);
	assert_int_equal(s.stats.lost, 0);
	assert_int_equal(s.stats.accepted, 3);
	assert_int_equal(s.stats.received, 4);
}

/* TEST_stream_reordered: a record overtaken by a later one is dropped when
 * it arrives (it stays counted as lost), and the stream goes on. */
static void test_stream_reordered(void **state)
{
	struct gl_stream s;
	struct gl_record out;
	uint16_t last = 0;

	(void)state;
	start(&s);
	assert_int_equal(feed(&s, 100, T0 + 1 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(feed(&s, 116, T0 + 17 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.lost, 1);
	memset(&out, 0x5A, sizeof(out));
	assert_int_equal(feed(&s, 108, T0 + 18 * MS, &out),
			 GL_STREAM_REORDERED);
	assert_untouched(&out);
	assert_int_equal(gl_stream_last_sample(&s, &last), 1);
	assert_int_equal(last, 116);
	assert_int_equal(feed(&s, 124, T0 + 25 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.reordered, 1);
	assert_int_equal(s.stats.lost, 1);
	assert_int_equal(s.stats.accepted, 3);
}

/* TEST_stream_seen: a record read by another route (QR) moves the
 * reference: records after the last accepted and up to it are dropped as
 * superseded, the next one is accepted without counting the gap as lost;
 * the age stays the stream's own; a sample not after the last accepted is
 * ignored. */
static void test_stream_seen(void **state)
{
	struct gl_stream s;
	struct gl_record out;

	(void)state;
	start(&s);
	assert_int_equal(feed(&s, 100, T0 + 1 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(gl_stream_seen(&s, 90, T0 + 2 * MS), GL_OK);
	assert_int_equal(s.last_sample, 100); /* not after: ignored */
	assert_int_equal(gl_stream_seen(&s, 131, T0 + 40 * MS), GL_OK);
	assert_int_equal(gl_stream_age_ns(&s, T0 + 40 * MS), 39 * MS);
	assert_int_equal(gl_stream_seen(&s, 120, T0 + 40 * MS), GL_OK);
	assert_int_equal(s.last_sample, 131); /* not after the seen one */
	assert_int_equal(feed(&s, 124, T0 + 41 * MS, &out),
			 GL_STREAM_SUPERSEDED);
	assert_int_equal(feed(&s, 131, T0 + 41 * MS, &out),
			 GL_STREAM_SUPERSEDED);
	assert_int_equal(feed(&s, 132, T0 + 42 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(out.sample, 132);
	assert_int_equal(s.stats.lost, 0);
	assert_int_equal(s.stats.uneven, 0);
	assert_int_equal(s.stats.superseded, 2);
	assert_int_equal(s.stats.reordered, 0);
	assert_int_equal(s.stats.duplicates, 0);
	assert_int_equal(feed(&s, 148, T0 + 58 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.lost, 1); /* counted again from here */
	/* before any record: the first one must come after the seen one,
	 * and the ones before it were superseded, not reordered */
	start(&s);
	assert_int_equal(gl_stream_seen(&s, 500, T0 + 1 * MS), GL_OK);
	assert_int_equal(feed(&s, 496, T0 + 2 * MS, &out),
			 GL_STREAM_SUPERSEDED);
	assert_int_equal(feed(&s, 500, T0 + 2 * MS, &out),
			 GL_STREAM_SUPERSEDED);
	assert_int_equal(feed(&s, 504, T0 + 3 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.restarts, 0);
	assert_int_equal(s.stats.superseded, 2);
	assert_int_equal(s.stats.reordered, 0);
	assert_int_equal(gl_stream_seen(NULL, 1, T0), GL_ERR_ARG);
}

/* TEST_stream_superseded: a stream 24 samples behind (n0 = 8) and a QR
 * that read sample 164 while the stream's last accepted was 140: the
 * stream's 148, 156 and 164, already in flight, are superseded (not
 * reordered, not lost, not duplicates); a record at or before 140 that
 * comes now is still the stream's own fault (duplicate, reordered); once
 * 172 is accepted, a late 164 is reordered on the stream. */
static void test_stream_superseded(void **state)
{
	struct gl_stream s;
	struct gl_record out;
	uint16_t last = 0;

	(void)state;
	start(&s);
	for (int k = 0; k < 6; k++) /* 100, 108, ... 140 */
		assert_int_equal(feed(&s, (uint16_t)(100 + 8 * k),
				      T0 + (24 + 8 * k) * MS, &out),
				 GL_STREAM_ACCEPTED);
	assert_int_equal(gl_stream_seen(&s, 164, T0 + 65 * MS), GL_OK);
	memset(&out, 0x5A, sizeof(out));
	assert_int_equal(feed(&s, 148, T0 + 72 * MS, &out),
			 GL_STREAM_SUPERSEDED);
	assert_int_equal(feed(&s, 140, T0 + 73 * MS, &out),
			 GL_STREAM_DUPLICATE);
	assert_int_equal(feed(&s, 132, T0 + 74 * MS, &out),
			 GL_STREAM_REORDERED);
	assert_int_equal(feed(&s, 156, T0 + 80 * MS, &out),
			 GL_STREAM_SUPERSEDED);
	assert_int_equal(feed(&s, 164, T0 + 88 * MS, &out),
			 GL_STREAM_SUPERSEDED);
	assert_untouched(&out);
	assert_int_equal(gl_stream_last_sample(&s, &last), 1);
	assert_int_equal(last, 164); /* the reference, from the QR */
	assert_int_equal(gl_stream_age_ns(&s, T0 + 88 * MS), 24 * MS);
	assert_int_equal(feed(&s, 172, T0 + 96 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(out.sample, 172);
	/* from here the stream's own 172 is the reference: late is late */
	assert_int_equal(feed(&s, 164, T0 + 97 * MS, &out),
			 GL_STREAM_REORDERED);
	assert_int_equal(feed(&s, 172, T0 + 98 * MS, &out),
			 GL_STREAM_DUPLICATE);
	assert_int_equal(feed(&s, 180, T0 + 104 * MS, &out),
			 GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.received, 15);
	assert_int_equal(s.stats.accepted, 8);
	assert_int_equal(s.stats.superseded, 3);
	assert_int_equal(s.stats.reordered, 2);
	assert_int_equal(s.stats.duplicates, 2);
	assert_int_equal(s.stats.lost, 0);
	assert_int_equal(s.stats.uneven, 0);
}

/* TEST_stream_superseded_horizon: the stream's own last record more than
 * the horizon old no longer tells a late record from a superseded one:
 * behind a record seen since, every number is superseded. */
static void test_stream_superseded_horizon(void **state)
{
	struct gl_stream s;
	struct gl_record out;
	const int64_t h = GL_STREAM_HORIZON_SAMPLES * MS;

	(void)state;
	start(&s);
	assert_int_equal(feed(&s, 1000, T0, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(gl_stream_seen(&s, 2000, T0 + h), GL_OK);
	/* within the horizon of the accepted 1000: its own verdicts */
	assert_int_equal(feed(&s, 1000, T0 + h, &out), GL_STREAM_DUPLICATE);
	assert_int_equal(feed(&s, 992, T0 + h, &out), GL_STREAM_REORDERED);
	/* past it (but within the seen one's): superseded */
	assert_int_equal(feed(&s, 1000, T0 + h + 1, &out),
			 GL_STREAM_SUPERSEDED);
	assert_int_equal(feed(&s, 992, T0 + h + 1, &out), GL_STREAM_SUPERSEDED);
	assert_int_equal(feed(&s, 2008, T0 + h + 2, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.superseded, 2);
	assert_int_equal(s.stats.reordered, 1);
	assert_int_equal(s.stats.duplicates, 1);
	assert_int_equal(s.stats.restarts, 0);
	assert_int_equal(s.stats.lost, 0);
}

/* TEST_stream_wrap: the 16-bit sample number wraps from 65535 to 0; gaps
 * and reordering are judged across the wrap. */
static void test_stream_wrap(void **state)
{
	struct gl_stream s;
	struct gl_record out;

	(void)state;
	start(&s);
	assert_int_equal(feed(&s, 65520, T0 + 1 * MS, &out),
			 GL_STREAM_ACCEPTED);
	assert_int_equal(feed(&s, 65528, T0 + 9 * MS, &out),
			 GL_STREAM_ACCEPTED);
	assert_int_equal(feed(&s, 0, T0 + 17 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(out.sample, 0);
	assert_int_equal(s.stats.lost, 0);
	/* 8 lost */
	assert_int_equal(feed(&s, 16, T0 + 33 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.lost, 1);
	/* from before the wrap: late */
	assert_int_equal(feed(&s, 65528, T0 + 34 * MS, &out),
			 GL_STREAM_REORDERED);
	/* exactly half the period back counts as not after */
	assert_int_equal(feed(&s, (uint16_t)(16 + 32768), T0 + 35 * MS, &out),
			 GL_STREAM_REORDERED);
	/* half the period minus one ahead is after: 4096 records, 4095 lost */
	assert_int_equal(feed(&s, (uint16_t)(16 + 32767), T0 + 36 * MS, &out),
			 GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.lost, 1 + 4095);
	assert_int_equal(s.stats.uneven, 1);
	assert_int_equal(s.stats.reordered, 2);
}

/* TEST_stream_short: fewer bytes than the header announces (one missing),
 * and fewer than a header. */
static void test_stream_short(void **state)
{
	struct gl_stream s;
	struct gl_record out;
	struct gl_stream_peer c = ctrl();
	uint8_t b[REC_BYTES + 8];

	(void)state;
	start(&s);
	make(b, 100);
	memset(&out, 0x5A, sizeof(out));
	assert_int_equal(gl_stream_feed(&s, b, REC_BYTES - 1, &c, T0, &out),
			 GL_STREAM_SHORT);
	assert_int_equal(gl_stream_feed(&s, b, 3, &c, T0, &out),
			 GL_STREAM_SHORT);
	assert_int_equal(gl_stream_feed(&s, NULL, 0, &c, T0, &out),
			 GL_STREAM_SHORT);
	assert_untouched(&out);
	assert_int_equal(s.stats.shorts, 3);
	assert_int_equal(s.stats.accepted, 0);
	assert_int_equal(gl_stream_feed(&s, b, REC_BYTES, &c, T0, &out),
			 GL_STREAM_ACCEPTED);
}

/* TEST_stream_long: one byte more than announced (a trailing ':' as on
 * the TCP QR reply, which DR does not send). */
static void test_stream_long(void **state)
{
	struct gl_stream s;
	struct gl_record out;
	struct gl_stream_peer c = ctrl();
	uint8_t b[REC_BYTES + 8];

	(void)state;
	start(&s);
	make(b, 100);
	b[REC_BYTES] = ':';
	memset(&out, 0x5A, sizeof(out));
	assert_int_equal(gl_stream_feed(&s, b, REC_BYTES + 1, &c, T0, &out),
			 GL_STREAM_LONG);
	assert_untouched(&out);
	assert_int_equal(s.stats.longs, 1);
	assert_int_equal(gl_stream_last_sample(&s, &(uint16_t){0}), 0);
}

/* TEST_stream_foreign: another address on the same port, and the same
 * address from another port, are dropped before their bytes are read;
 * the controller seen through an IPv6 socket (::ffff:a.b.c.d) is not. */
static void test_stream_foreign(void **state)
{
	struct gl_stream s;
	struct gl_record out;
	struct gl_stream_peer other_addr = peer("192.168.1.11", 23);
	struct gl_stream_peer other_port = peer("192.168.1.10", 24);
	struct gl_stream_peer mapped;
	struct sockaddr_in6 a6;
	uint8_t b[REC_BYTES + 8];

	(void)state;
	start(&s);
	make(b, 100);
	memset(&out, 0x5A, sizeof(out));
	assert_int_equal(
	    gl_stream_feed(&s, b, REC_BYTES, &other_addr, T0, &out),
	    GL_STREAM_FOREIGN);
	assert_int_equal(
	    gl_stream_feed(&s, b, REC_BYTES, &other_port, T0, &out),
	    GL_STREAM_FOREIGN);
	/* a foreign datagram is dropped whatever it holds */
	assert_int_equal(gl_stream_feed(&s, b, 2, &other_port, T0, &out),
			 GL_STREAM_FOREIGN);
	assert_untouched(&out);
	assert_int_equal(s.stats.foreign, 3);

	memset(&a6, 0, sizeof(a6));
	a6.sin6_family = AF_INET6;
	a6.sin6_port = htons(23);
	assert_int_equal(
	    inet_pton(AF_INET6, "::ffff:192.168.1.10", &a6.sin6_addr), 1);
	assert_int_equal(gl_stream_peer_from_sockaddr((struct sockaddr *)&a6,
						      sizeof(a6), &mapped),
			 GL_OK);
	assert_int_equal(mapped.port, 23);
	assert_int_equal(gl_stream_feed(&s, b, REC_BYTES, &mapped, T0, &out),
			 GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.foreign, 3);
	assert_int_equal(s.stats.received, 4);
}

/* TEST_stream_malformed: header bit 7 clear, the axis bits of another
 * axis count, an announced length that is not the layout's, and the
 * header flags of a partial QR; none is decoded. */
static void test_stream_malformed(void **state)
{
	struct gl_stream s;
	struct gl_record out;
	struct gl_stream_peer c = ctrl();
	uint8_t b[REC_BYTES + 8];

	(void)state;
	start(&s);
	memset(&out, 0x5A, sizeof(out));
	make(b, 100);
	b[0] = 0x07;
	assert_int_equal(gl_stream_feed(&s, b, REC_BYTES, &c, T0, &out),
			 GL_STREAM_MALFORMED);
	make(b, 100);
	b[1] = 0x0F; /* four axes */
	assert_int_equal(gl_stream_feed(&s, b, REC_BYTES, &c, T0, &out),
			 GL_STREAM_MALFORMED);
	make(b, 100);
	b[2] = 196; /* announces 196 bytes, and 196 come */
	assert_int_equal(gl_stream_feed(&s, b, 196, &c, T0, &out),
			 GL_STREAM_MALFORMED);
	make(b, 100);
	b[0] = 0x81; /* S plane only: not the full record (gl_record says) */
	assert_int_equal(gl_stream_feed(&s, b, REC_BYTES, &c, T0, &out),
			 GL_STREAM_MALFORMED);
	assert_untouched(&out);
	assert_int_equal(s.stats.malformed, 4);
	assert_int_equal(s.stats.received, 4);
	assert_int_equal(gl_stream_last_sample(&s, &(uint16_t){0}), 0);
}

/* TEST_stream_age: counted from init until a record is accepted, then
 * from that record; dropped datagrams do not make it younger. */
static void test_stream_age(void **state)
{
	struct gl_stream s;
	struct gl_record out;
	struct gl_stream_peer c = ctrl();
	uint16_t last = 0;

	(void)state;
	start(&s);
	assert_int_equal(gl_stream_age_ns(&s, T0 + 40 * MS), 40 * MS);
	assert_int_equal(gl_stream_last_sample(&s, &last), 0);
	assert_int_equal(last, 0);
	assert_int_equal(feed(&s, 500, T0 + 50 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(gl_stream_age_ns(&s, T0 + 50 * MS), 0);
	assert_int_equal(gl_stream_age_ns(&s, T0 + 55 * MS + 7), 5 * MS + 7);
	assert_int_equal(feed(&s, 500, T0 + 60 * MS, &out),
			 GL_STREAM_DUPLICATE);
	assert_int_equal(feed(&s, 492, T0 + 61 * MS, &out),
			 GL_STREAM_REORDERED);
	assert_int_equal(
	    gl_stream_feed(&s, (const uint8_t *)"x", 1, &c, T0 + 62 * MS, &out),
	    GL_STREAM_SHORT);
	assert_int_equal(gl_stream_age_ns(&s, T0 + 70 * MS), 20 * MS);
	assert_int_equal(gl_stream_last_sample(&s, &last), 1);
	assert_int_equal(last, 500);
	/* earlier than the last record: 0, never negative */
	assert_int_equal(gl_stream_age_ns(&s, T0), 0);
	assert_int_equal(gl_stream_age_ns(NULL, T0), GL_ERR_ARG);
}

/* TEST_stream_horizon: after a silence longer than 16384 samples the next
 * record starts the sequence again, whatever its number (a controller
 * that stopped and restarted DR, or a number that went past half its
 * period); within the horizon an earlier number is still reordered. */
static void test_stream_horizon(void **state)
{
	struct gl_stream s;
	struct gl_record out;
	const int64_t h = GL_STREAM_HORIZON_SAMPLES * MS;

	(void)state;
	start(&s);
	assert_int_equal(s.horizon_ns, h);
	assert_int_equal(feed(&s, 40000, T0, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(feed(&s, 39000, T0 + h, &out), GL_STREAM_REORDERED);
	assert_int_equal(feed(&s, 39000, T0 + h + 1, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(out.sample, 39000);
	assert_int_equal(s.stats.restarts, 1);
	assert_int_equal(s.stats.lost, 0);
	assert_int_equal(feed(&s, 39008, T0 + h + 9 * MS, &out),
			 GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.lost, 0);
}

/* TEST_stream_uneven: a spacing that is not a multiple of n0 is counted,
 * and the loss is rounded to the nearest whole record. */
static void test_stream_uneven(void **state)
{
	struct gl_stream s;
	struct gl_record out;

	(void)state;
	start(&s);
	assert_int_equal(feed(&s, 100, T0, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(feed(&s, 103, T0 + 3 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.lost, 0); /* 3/8 rounds to 0 records */
	assert_int_equal(feed(&s, 115, T0 + 15 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.lost, 1); /* 12/8 rounds to 2 records */
	assert_int_equal(feed(&s, 126, T0 + 26 * MS, &out), GL_STREAM_ACCEPTED);
	assert_int_equal(s.stats.lost, 1); /* 11/8 rounds to 1 */
	assert_int_equal(s.stats.uneven, 3);
}

/* TEST_stream_init_args: every refused argument leaves the reader as it
 * was; the other layouts are taken with their own sizes. */
static void test_stream_init_args(void **state)
{
	struct gl_stream s, ref;
	struct gl_stream_peer c = ctrl();

	(void)state;
	memset(&s, 0x33, sizeof(s));
	ref = s;
	assert_int_equal(gl_stream_init(NULL, &c, GL_LAYOUT_4000, 3, 8, MS, 0),
			 GL_ERR_ARG);
	assert_int_equal(gl_stream_init(&s, NULL, GL_LAYOUT_4000, 3, 8, MS, 0),
			 GL_ERR_ARG);
	assert_int_equal(gl_stream_init(&s, &c, GL_LAYOUT_NONE, 3, 8, MS, 0),
			 GL_ERR_ARG);
	assert_int_equal(gl_stream_init(&s, &c, GL_LAYOUT_4000, 9, 8, MS, 0),
			 GL_ERR_ARG);
	assert_int_equal(gl_stream_init(&s, &c, GL_LAYOUT_30000, 2, 8, MS, 0),
			 GL_ERR_ARG);
	assert_int_equal(gl_stream_init(&s, &c, GL_LAYOUT_4000, 3, 0, MS, 0),
			 GL_ERR_ARG);
	assert_int_equal(
	    gl_stream_init(&s, &c, GL_LAYOUT_4000, 3, 16384, MS, 0),
	    GL_ERR_ARG);
	assert_int_equal(gl_stream_init(&s, &c, GL_LAYOUT_4000, 3, 8, 0, 0),
			 GL_ERR_ARG);
	assert_int_equal(
	    gl_stream_init(&s, &c, GL_LAYOUT_4000, 3, 8, 1000000001, 0),
	    GL_ERR_ARG);
	assert_memory_equal(&s, &ref, sizeof(s));
	assert_int_equal(
	    gl_stream_init(&s, &c, GL_LAYOUT_4000, 3, 16383, 976563, 0), GL_OK);
	assert_int_equal(s.rec_bytes, 190);
	assert_int_equal(s.horizon_ns, 16384LL * 976563);
	assert_int_equal(gl_stream_init(&s, &c, GL_LAYOUT_30000, 1, 1, MS, 0),
			 GL_OK);
	assert_int_equal(s.rec_bytes, 74);
	assert_int_equal(gl_stream_init(&s, &c, GL_LAYOUT_2103, 8, 8, MS, 0),
			 GL_OK);
	assert_int_equal(s.rec_bytes, 268);
}

/* TEST_stream_other_layout: a DMC-21x3 record (4 axes, 156 bytes) goes
 * through the same checks. */
static void test_stream_other_layout(void **state)
{
	struct gl_stream s;
	struct gl_record r, out;
	struct gl_stream_peer c = ctrl();
	uint8_t b[GL_REC_MAX_BYTES];

	(void)state;
	assert_int_equal(gl_stream_init(&s, &c, GL_LAYOUT_2103, 4, 2, MS, T0),
			 GL_OK);
	memset(&r, 0, sizeof(r));
	r.layout = GL_LAYOUT_2103;
	r.n_axes = 4;
	r.sample = 7;
	r.axis[3].ref_pos = -42;
	assert_int_equal(gl_record_encode(&r, b, sizeof(b)), 156);
	assert_int_equal(gl_stream_feed(&s, b, 156, &c, T0, &out),
			 GL_STREAM_ACCEPTED);
	assert_int_equal(out.layout, GL_LAYOUT_2103);
	assert_int_equal(out.axis[3].ref_pos, -42);
	assert_int_equal(gl_stream_feed(&s, b, 155, &c, T0, &out),
			 GL_STREAM_SHORT);
	assert_int_equal(gl_stream_feed(&s, b, 156, &c, T0, &out),
			 GL_STREAM_DUPLICATE);
}

/* TEST_stream_feed_args: NULL arguments are refused and not counted. */
static void test_stream_feed_args(void **state)
{
	struct gl_stream s;
	struct gl_record out;
	struct gl_stream_peer c = ctrl();
	uint8_t b[REC_BYTES + 8];

	(void)state;
	start(&s);
	make(b, 1);
	assert_int_equal(gl_stream_feed(NULL, b, REC_BYTES, &c, T0, &out),
			 GL_ERR_ARG);
	assert_int_equal(gl_stream_feed(&s, NULL, REC_BYTES, &c, T0, &out),
			 GL_ERR_ARG);
	assert_int_equal(gl_stream_feed(&s, b, REC_BYTES, NULL, T0, &out),
			 GL_ERR_ARG);
	assert_int_equal(gl_stream_feed(&s, b, REC_BYTES, &c, T0, NULL),
			 GL_ERR_ARG);
	assert_int_equal(gl_stream_last_sample(&s, NULL), GL_ERR_ARG);
	assert_int_equal(gl_stream_last_sample(NULL, &(uint16_t){0}),
			 GL_ERR_ARG);
	assert_int_equal(s.stats.received, 0);
}

/* TEST_stream_peer: IPv4 becomes ::ffff:a.b.c.d with the port in host
 * order; IPv6 is kept; other families and short lengths are refused. */
static void test_stream_peer(void **state)
{
	static const uint8_t want4[16] = {0, 0, 0,    0,    0,	 0,   0, 0,
					  0, 0, 0xff, 0xff, 192, 168, 1, 10};
	struct gl_stream_peer p = ctrl();
	struct sockaddr_in6 a6;
	struct sockaddr_un un;

	(void)state;
	assert_memory_equal(p.addr, want4, 16);
	assert_int_equal(p.port, 23);

	memset(&a6, 0, sizeof(a6));
	a6.sin6_family = AF_INET6;
	a6.sin6_port = htons(60000);
	assert_int_equal(inet_pton(AF_INET6, "fe80::1", &a6.sin6_addr), 1);
	assert_int_equal(gl_stream_peer_from_sockaddr((struct sockaddr *)&a6,
						      sizeof(a6), &p),
			 GL_OK);
	assert_memory_equal(p.addr, a6.sin6_addr.s6_addr, 16);
	assert_int_equal(p.port, 60000);
	assert_int_equal(gl_stream_peer_from_sockaddr((struct sockaddr *)&a6,
						      sizeof(a6) - 1, &p),
			 GL_ERR_ARG);

	memset(&un, 0, sizeof(un));
	un.sun_family = AF_UNIX;
	assert_int_equal(gl_stream_peer_from_sockaddr((struct sockaddr *)&un,
						      sizeof(un), &p),
			 GL_ERR_ARG);
	assert_int_equal(gl_stream_peer_from_sockaddr(NULL, sizeof(a6), &p),
			 GL_ERR_ARG);
	assert_int_equal(gl_stream_peer_from_sockaddr((struct sockaddr *)&a6,
						      sizeof(a6), NULL),
			 GL_ERR_ARG);
}

/* TEST_stream_verdict_name: one word per verdict. */
static void test_stream_verdict_name(void **state)
{
	(void)state;
	assert_string_equal(gl_stream_verdict_name(GL_STREAM_ACCEPTED),
			    "accepted");
	assert_string_equal(gl_stream_verdict_name(GL_STREAM_DUPLICATE),
			    "duplicate");
	assert_string_equal(gl_stream_verdict_name(GL_STREAM_REORDERED),
			    "reordered");
	assert_string_equal(gl_stream_verdict_name(GL_STREAM_SHORT), "short");
	assert_string_equal(gl_stream_verdict_name(GL_STREAM_LONG), "long");
	assert_string_equal(gl_stream_verdict_name(GL_STREAM_FOREIGN),
			    "foreign");
	assert_string_equal(gl_stream_verdict_name(GL_STREAM_MALFORMED),
			    "malformed");
	assert_string_equal(gl_stream_verdict_name(GL_STREAM_SUPERSEDED),
			    "superseded");
	assert_string_equal(gl_stream_verdict_name(8), "unknown");
	assert_string_equal(gl_stream_verdict_name(GL_ERR_ARG), "unknown");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_stream_gap),
	    cmocka_unit_test(test_stream_duplicate),
	    cmocka_unit_test(test_stream_reordered),
	    cmocka_unit_test(test_stream_wrap),
	    cmocka_unit_test(test_stream_seen),
	    cmocka_unit_test(test_stream_superseded),
	    cmocka_unit_test(test_stream_superseded_horizon),
	    cmocka_unit_test(test_stream_short),
	    cmocka_unit_test(test_stream_long),
	    cmocka_unit_test(test_stream_foreign),
	    cmocka_unit_test(test_stream_malformed),
	    cmocka_unit_test(test_stream_age),
	    cmocka_unit_test(test_stream_horizon),
	    cmocka_unit_test(test_stream_uneven),
	    cmocka_unit_test(test_stream_init_args),
	    cmocka_unit_test(test_stream_other_layout),
	    cmocka_unit_test(test_stream_feed_args),
	    cmocka_unit_test(test_stream_peer),
	    cmocka_unit_test(test_stream_verdict_name),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
