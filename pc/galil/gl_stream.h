/*
 * gl_stream.h - the PC's reader of the data record sent as a stream (DR
 * over a UDP handle), as a parser on buffers: one datagram in, one verdict
 * out (docs/link.md, "The record as a stream: the reader").
 *
 * Each datagram carries one whole record, header first, no ':'
 * (galil-notes.md 2.6). A datagram is accepted only when it comes from the
 * controller's address and port, its header announces the record the
 * layout expects, its length is the one announced, and its sample number
 * (16 bits, bytes 4-5: galil-notes.md 2.2) is after the last accepted one.
 * A lost record costs one sample: the gap is counted, nothing waits for it.
 * A duplicate, a late (reordered) record, and a record superseded by one
 * the caller read by another route (gl_stream_seen()) are dropped, never
 * decoded.
 *
 * Staleness is the caller's: gl_stream_age_ns() is the time since the last
 * accepted record, to be judged with the deadlines the cycle already uses
 * for a reply's age and a frozen sample number.
 *
 * No socket, no allocation, nothing printed; times are the caller's
 * monotonic clock in ns (base_clock).
 */
#ifndef GL_STREAM_H
#define GL_STREAM_H

#include <stddef.h>
#include <stdint.h>

#include "gl_record.h"

struct sockaddr;

/* The sample number's comparison is trusted over at most this many samples
 * (a quarter of its 65536 period, so a late datagram is never taken for a
 * new one); after a longer silence the next record restarts the sequence. */
#define GL_STREAM_HORIZON_SAMPLES 16384

/* What gl_stream_feed() did with a datagram (>= 0; errors are < 0). */
enum gl_stream_verdict {
	GL_STREAM_ACCEPTED = 0,	  /* decoded into the caller's record */
	GL_STREAM_DUPLICATE = 1,  /* same sample number as the last accepted */
	GL_STREAM_REORDERED = 2,  /* sample number before the last accepted */
	GL_STREAM_SHORT = 3,	  /* fewer bytes than the header announces */
	GL_STREAM_LONG = 4,	  /* more bytes than the header announces */
	GL_STREAM_FOREIGN = 5,	  /* not from the controller's address+port */
	GL_STREAM_MALFORMED = 6,  /* the header is not the layout's record */
	GL_STREAM_SUPERSEDED = 7, /* at or before a record read by another
				   * route (gl_stream_seen()), after the
				   * last accepted */
};

/* A UDP sender: IPv6 address, or IPv4 as ::ffff:a.b.c.d; port in host
 * byte order. Two peers are the same when both fields are equal. */
struct gl_stream_peer {
	uint8_t addr[16];
	uint16_t port;
};

/* Counters since gl_stream_init(); each datagram fed counts once in
 * @received and once in the counter of its verdict. */
struct gl_stream_stats {
	uint64_t received; /* datagrams fed */
	uint64_t accepted;
	uint64_t lost; /* records missing between accepted ones */
	uint64_t duplicates;
	uint64_t reordered;
	uint64_t superseded;
	uint64_t shorts;
	uint64_t longs;
	uint64_t foreign;
	uint64_t malformed;
	uint64_t uneven;   /* accepted with a spacing not a multiple of n0 */
	uint64_t restarts; /* accepted after a silence past the horizon */
};

/* The reader's state: a plain struct the caller owns (stack or static);
 * read the fields, change them only through the functions below. */
struct gl_stream {
	struct gl_stream_peer ctrl; /* the controller's address and port */
	enum gl_rec_layout layout;
	int n_axes;
	size_t rec_bytes;     /* gl_record_size(layout, n_axes) */
	unsigned n0_samples;  /* samples between two records (DR n0) */
	int64_t horizon_ns;   /* GL_STREAM_HORIZON_SAMPLES samples */
	int have_last;	      /* 1 once a record was accepted or seen */
	uint16_t last_sample; /* sample number of the last accepted, or of
			       * the record seen after it */
	int64_t last_ns;      /* when it was accepted, or init time */
	int seen_other;	      /* last_sample came from gl_stream_seen() */
	int64_t ref_ns;	      /* when last_sample was taken (the horizon
			       * counts from here) */
	int have_own;	      /* 1 once a record of the stream was accepted */
	uint16_t own_sample;  /* sample number of the last accepted */
	struct gl_stream_stats stats;
};

/*
 * gl_stream_init() - start a reader (also to start again, e.g. after a new
 * connection: every counter is zeroed).
 * @s: [out] the reader; must not be NULL.
 * @ctrl: the controller's address and its UDP port (the handle's source);
 *        must not be NULL.
 * @layout, @n_axes: the record layout, as found from QZ.
 * @n0_samples: samples between two records (the DR interval), 1..16383.
 * @sample_ns: one controller sample in ns (976563 on a DMC-40x0 at TM 1000,
 *             1000000 in galil-sim); sets the horizon; > 0.
 * @now_ns: monotonic time now; the age counts from here until a record is
 *          accepted.
 * Return: GL_OK, or GL_ERR_ARG (NULL, unknown layout or axis count, n0 or
 *         sample_ns out of range); @s is untouched on error.
 */
int gl_stream_init(struct gl_stream *s, const struct gl_stream_peer *ctrl,
		   enum gl_rec_layout layout, int n_axes, unsigned n0_samples,
		   int64_t sample_ns, int64_t now_ns);

/*
 * gl_stream_feed() - judge one datagram, and decode it when accepted.
 * @s: the reader; must not be NULL.
 * @dg: the datagram's bytes (may be NULL only when @len is 0).
 * @len: its length in bytes.
 * @from: its sender; must not be NULL.
 * @now_ns: monotonic time of its reception.
 * @out: [out] the decoded record, written only when GL_STREAM_ACCEPTED;
 *       must not be NULL.
 * The checks, in order: sender (FOREIGN), at least the 4 header bytes
 * (SHORT), header bit 7, axis bits and announced length of the layout's
 * record (MALFORMED), @len against the announced length (SHORT, LONG), the
 * sample number (below), the full decode (MALFORMED). The first record,
 * and the first after a silence longer than the horizon, is accepted
 * whatever its number (a restart). The sample number x is judged against
 * the last accepted record A and the newest record S read by another
 * route since A (gl_stream_seen()): x after A and after S: accepted; x
 * equal to A: DUPLICATE; x before A: REORDERED (the stream itself
 * delivered it late); x after A and at or before S: SUPERSEDED (made no
 * later than a record the caller already has; nothing was reordered).
 * With no A within the horizon, every x at or before S is SUPERSEDED.
 * An accepted record n samples after the last adds round(n / n0) - 1 to
 * the lost count.
 * Return: an enum gl_stream_verdict (>= 0), or GL_ERR_ARG.
 */
int gl_stream_feed(struct gl_stream *s, const uint8_t *dg, size_t len,
		   const struct gl_stream_peer *from, int64_t now_ns,
		   struct gl_record *out);

/*
 * gl_stream_seen() - a record of @sample was read by another route (a QR
 * round trip on the command handle, e.g. the one that saw the program
 * armed): from now on only records after it are accepted, so the stream
 * never goes back behind what the caller already knows; a record at or
 * before it but after the last accepted is dropped as SUPERSEDED, one at
 * or before the last accepted still as DUPLICATE or REORDERED
 * (gl_stream_feed()). Ignored when @sample is not after the last accepted
 * or the last seen. The samples up to the next accepted record are not
 * counted as lost. The age is not changed.
 * Return: GL_OK, or GL_ERR_ARG when @s is NULL.
 */
int gl_stream_seen(struct gl_stream *s, uint16_t sample, int64_t now_ns);

/*
 * gl_stream_age_ns() - ns since the last accepted record (since init when
 * none was), at @now_ns; 0 when @now_ns is earlier. Datagrams dropped do
 * not make the stream younger.
 * Return: the age in ns, or GL_ERR_ARG when @s is NULL.
 */
int64_t gl_stream_age_ns(const struct gl_stream *s, int64_t now_ns);

/*
 * gl_stream_last_sample() - the sample number of the last accepted record.
 * @sample: [out] the number, written only when one was accepted.
 * Return: 1 when a record was accepted, 0 none yet, GL_ERR_ARG on NULL.
 */
int gl_stream_last_sample(const struct gl_stream *s, uint16_t *sample);

/*
 * gl_stream_peer_from_sockaddr() - the peer of a recvfrom() address.
 * @sa, @len: an AF_INET or AF_INET6 address and its size in bytes.
 * @out: [out] the peer (IPv4 as ::ffff:a.b.c.d, so that an IPv4 sender
 *       seen by an IPv6 socket is the same peer); the IPv6 scope is not
 *       kept.
 * Return: GL_OK, or GL_ERR_ARG (NULL, other family, @len too small).
 */
int gl_stream_peer_from_sockaddr(const struct sockaddr *sa, size_t len,
				 struct gl_stream_peer *out);

/*
 * gl_stream_verdict_name() - a short lower-case word for a verdict
 * ("accepted", "duplicate", "superseded", ...), for status lines and the
 * bench.
 * Return: a static string, never NULL ("unknown" for other values).
 */
const char *gl_stream_verdict_name(int verdict);

#endif /* GL_STREAM_H */
