/*
 * gl_stream.c - judge and decode the datagrams of the DR record stream.
 *
 * Sequencing is by the record's own 16-bit sample number in serial-number
 * arithmetic (RFC 1982): the difference to the last accepted number, taken
 * modulo 65536, is "after" from 1 to 32767 and "not after" from 32768 to
 * 65535 or 0. So the number may wrap freely, as long as the comparison only
 * spans less than half its period: the horizon (a quarter of it, in time)
 * keeps a record sent before a long silence from being taken for a new one,
 * and lets the stream start afresh after such a silence instead of
 * dropping every record as "reordered" until the number catches up.
 *
 * A record read by another route (gl_stream_seen()) becomes the reference
 * while the stream's own last accepted record is kept beside it, so that a
 * record dropped for being behind tells which it is behind: behind the
 * stream's own (reordered on the stream) or only behind the other route's
 * (superseded: the QR round trip was simply faster than the stream).
 *
 * The header is checked here only for its general form (bit 7, the axis
 * bits, the announced length) so that the length can be judged against
 * what the header announces; the layout's own rules are gl_record's, whose
 * decoder runs last and writes the caller's record only on success.
 */
#include <netinet/in.h>
#include <string.h>
#include <sys/socket.h>

#include "gl_err.h"
#include "gl_stream.h"

#define HDR_BYTES     4
#define HDR_BIT7      0x80u
#define SAMPLE_OFF    4		 /* UW sample number, galil-notes.md 2.2 */
#define SERIAL_HALF   32768u	 /* half the 16-bit number's period */
#define N0_MAX	      16383u	 /* below the horizon, in samples */
#define SAMPLE_NS_MAX 1000000000 /* 1 s: no controller samples slower */

static uint16_t get_u16(const uint8_t *p)
{
	return (uint16_t)(p[0] | (p[1] << 8));
}

int gl_stream_init(struct gl_stream *s, const struct gl_stream_peer *ctrl,
		   enum gl_rec_layout layout, int n_axes, unsigned n0_samples,
		   int64_t sample_ns, int64_t now_ns)
{
	size_t size;

	if (!s || !ctrl)
		return GL_ERR_ARG;
	size = gl_record_size(layout, n_axes);
	if (size == 0 || n0_samples < 1 || n0_samples > N0_MAX ||
	    sample_ns <= 0 || sample_ns > SAMPLE_NS_MAX)
		return GL_ERR_ARG;
	memset(s, 0, sizeof(*s));
	s->ctrl = *ctrl;
	s->layout = layout;
	s->n_axes = n_axes;
	s->rec_bytes = size;
	s->n0_samples = n0_samples;
	s->horizon_ns = GL_STREAM_HORIZON_SAMPLES * sample_ns;
	s->last_ns = now_ns;
	s->ref_ns = now_ns;
	return GL_OK;
}

/* Sender, header form and length: the checks that need no history. */
static int check_frame(const struct gl_stream *s, const uint8_t *dg, size_t len,
		       const struct gl_stream_peer *from)
{
	uint8_t axes = (uint8_t)((1u << s->n_axes) - 1u);
	size_t announced;

	if (from->port != s->ctrl.port ||
	    memcmp(from->addr, s->ctrl.addr, sizeof(from->addr)) != 0)
		return GL_STREAM_FOREIGN;
	if (len < HDR_BYTES)
		return GL_STREAM_SHORT;
	announced = get_u16(dg + 2);
	if (!(dg[0] & HDR_BIT7) || dg[1] != axes || announced != s->rec_bytes)
		return GL_STREAM_MALFORMED;
	if (len < announced)
		return GL_STREAM_SHORT;
	if (len > announced)
		return GL_STREAM_LONG;
	return GL_STREAM_ACCEPTED;
}

/* A number not after the reference when the reference is a record read
 * by another route: the stream's own last accepted, if one is within the
 * horizon, decides between DUPLICATE, REORDERED (the stream delivered it
 * late) and SUPERSEDED (made between the two: late only against the
 * record read over TCP). */
static int check_behind(const struct gl_stream *s, uint16_t sample,
			int64_t now_ns)
{
	uint16_t d = (uint16_t)(sample - s->own_sample);

	if (!s->have_own || now_ns - s->last_ns > s->horizon_ns)
		return GL_STREAM_SUPERSEDED;
	if (d == 0)
		return GL_STREAM_DUPLICATE;
	if (d >= SERIAL_HALF)
		return GL_STREAM_REORDERED;
	return GL_STREAM_SUPERSEDED;
}

/* The sample number against the reference; @delta: [out] the samples
 * since it, 0 for a restart (first record, or past the horizon). */
static int check_order(const struct gl_stream *s, uint16_t sample,
		       int64_t now_ns, unsigned *delta)
{
	uint16_t d = (uint16_t)(sample - s->last_sample);

	*delta = 0;
	if (!s->have_last || now_ns - s->ref_ns > s->horizon_ns)
		return GL_STREAM_ACCEPTED;
	if (d == 0 || d >= SERIAL_HALF) {
		if (s->seen_other)
			return check_behind(s, sample, now_ns);
		return d == 0 ? GL_STREAM_DUPLICATE : GL_STREAM_REORDERED;
	}
	*delta = d;
	return GL_STREAM_ACCEPTED;
}

/* Take an accepted record's number and time, and count what it skipped. */
static void commit(struct gl_stream *s, uint16_t sample, unsigned delta,
		   int64_t now_ns)
{
	unsigned n0 = s->n0_samples;
	unsigned records = (delta + n0 / 2) / n0; /* rounded */

	if (delta == 0)
		s->stats.restarts += s->have_last ? 1 : 0;
	else if (records > 1 && !s->seen_other)
		s->stats.lost += records - 1;
	if (delta % n0 != 0 && !s->seen_other)
		s->stats.uneven++;
	s->seen_other = 0;
	s->have_last = 1;
	s->last_sample = sample;
	s->last_ns = now_ns;
	s->ref_ns = now_ns;
	s->have_own = 1;
	s->own_sample = sample;
}

int gl_stream_seen(struct gl_stream *s, uint16_t sample, int64_t now_ns)
{
	uint16_t d;

	if (!s)
		return GL_ERR_ARG;
	d = (uint16_t)(sample - s->last_sample);
	if (s->have_last && now_ns - s->ref_ns <= s->horizon_ns &&
	    (d == 0 || d >= SERIAL_HALF))
		return GL_OK; /* not after the last accepted */
	s->have_last = 1;
	s->last_sample = sample;
	s->seen_other = 1;
	s->ref_ns = now_ns; /* the age (last_ns) stays the stream's own */
	return GL_OK;
}

static void count(struct gl_stream_stats *st, int verdict)
{
	st->received++;
	switch (verdict) {
	case GL_STREAM_ACCEPTED: st->accepted++; break;
	case GL_STREAM_DUPLICATE: st->duplicates++; break;
	case GL_STREAM_REORDERED: st->reordered++; break;
	case GL_STREAM_SUPERSEDED: st->superseded++; break;
	case GL_STREAM_SHORT: st->shorts++; break;
	case GL_STREAM_LONG: st->longs++; break;
	case GL_STREAM_FOREIGN: st->foreign++; break;
	default: st->malformed++; break;
	}
}

int gl_stream_feed(struct gl_stream *s, const uint8_t *dg, size_t len,
		   const struct gl_stream_peer *from, int64_t now_ns,
		   struct gl_record *out)
{
	unsigned delta = 0;
	uint16_t sample = 0;
	int v;

	if (!s || (!dg && len) || !from || !out)
		return GL_ERR_ARG;
	v = check_frame(s, dg, len, from);
	if (v == GL_STREAM_ACCEPTED) {
		sample = get_u16(dg + SAMPLE_OFF);
		v = check_order(s, sample, now_ns, &delta);
	}
	/* last, so that a record dropped above is never decoded */
	if (v == GL_STREAM_ACCEPTED &&
	    gl_record_decode(dg, len, s->layout, s->n_axes, out) != GL_OK)
		v = GL_STREAM_MALFORMED;
	if (v == GL_STREAM_ACCEPTED)
		commit(s, sample, delta, now_ns);
	count(&s->stats, v);
	return v;
}

int64_t gl_stream_age_ns(const struct gl_stream *s, int64_t now_ns)
{
	if (!s)
		return GL_ERR_ARG;
	return now_ns > s->last_ns ? now_ns - s->last_ns : 0;
}

int gl_stream_last_sample(const struct gl_stream *s, uint16_t *sample)
{
	if (!s || !sample)
		return GL_ERR_ARG;
	if (!s->have_last)
		return 0;
	*sample = s->last_sample;
	return 1;
}

int gl_stream_peer_from_sockaddr(const struct sockaddr *sa, size_t len,
				 struct gl_stream_peer *out)
{
	struct sockaddr_in v4;
	struct sockaddr_in6 v6;

	if (!sa || !out)
		return GL_ERR_ARG;
	/* copied out: @sa need not be aligned for either type */
	if (sa->sa_family == AF_INET && len >= sizeof(v4)) {
		memcpy(&v4, sa, sizeof(v4));
		memset(out->addr, 0, 10);
		out->addr[10] = 0xff;
		out->addr[11] = 0xff;
		memcpy(out->addr + 12, &v4.sin_addr.s_addr, 4);
		out->port = ntohs(v4.sin_port);
		return GL_OK;
	}
	if (sa->sa_family == AF_INET6 && len >= sizeof(v6)) {
		memcpy(&v6, sa, sizeof(v6));
		memcpy(out->addr, v6.sin6_addr.s6_addr, 16);
		out->port = ntohs(v6.sin6_port);
		return GL_OK;
	}
	return GL_ERR_ARG;
}

const char *gl_stream_verdict_name(int verdict)
{
	switch (verdict) {
	case GL_STREAM_ACCEPTED: return "accepted";
	case GL_STREAM_DUPLICATE: return "duplicate";
	case GL_STREAM_REORDERED: return "reordered";
	case GL_STREAM_SHORT: return "short";
	case GL_STREAM_LONG: return "long";
	case GL_STREAM_FOREIGN: return "foreign";
	case GL_STREAM_MALFORMED: return "malformed";
	case GL_STREAM_SUPERSEDED: return "superseded";
	}
	return "unknown";
}
