/*
 * re_linkmeas.h - what the controller's link really does, measured at
 * start-up (roboelf) and at commissioning (roboelf-tech): the reply time
 * of the command handle (round trips of "MG TIME") and, with the record
 * stream open (gl_link_stream_open()), the interval at which its records
 * arrive, from their times of arrival and their own sample numbers. One
 * line says both (re_linkmeas_line()). docs/link.md, "The record as a
 * stream".
 *
 * Start-up only: the waits are bounded but not short (about 20 records,
 * 10 round trips); never inside the supervisor's cycle. Prints nothing.
 */
#ifndef RE_LINKMEAS_H
#define RE_LINKMEAS_H

#include <stddef.h>
#include <stdint.h>

#include "gl_link.h"

#define RE_LINKMEAS_REPLIES 10	 /* round trips measured */
#define RE_LINKMEAS_RECORDS 20	 /* records measured (19 intervals) */
#define RE_LINKMEAS_MAX	    64	 /* the most of either */
#define RE_LINKMEAS_OPEN_MS 1000 /* WH over UDP (resent), then DR */

struct re_linkmeas {
	/* the command handle: @replies round trips, their median and max */
	int replies;
	double reply_med_ms, reply_max_ms;
	/* the stream (@records 0: not measured): its handle (0..7 = A..H),
	 * interval asked (@n0 samples, @n0_ms at the plan's sample time),
	 * and over @records records the intervals of arrival (mean, min,
	 * max; records read together are 0 apart) and the mean step of the
	 * sample number (samples) */
	int records;
	int handle;
	unsigned n0;
	double n0_ms;
	double mean_ms, min_ms, max_ms;
	double step_samples;
};

/*
 * re_linkmeas_open() - gl_link_stream_open() on @l (the controller at
 * @addr, its UDP port @udp_port, "DR @n0" with a sample of @sample_ns,
 * within @timeout_ms); on failure a message for the operator in @err
 * (@cap bytes): the address, the UDP port, why (a refused DR with the
 * controller's own error text, TC1) and what to do.
 * Return: as gl_link_stream_open().
 */
int re_linkmeas_open(gl_link *l, const char *addr, int udp_port, unsigned n0,
		     int64_t sample_ns, int timeout_ms, char *err, size_t cap);

/*
 * re_linkmeas_stream() - the start-up's stream: re_linkmeas_open() within
 * RE_LINKMEAS_OPEN_MS, then RE_LINKMEAS_RECORDS records read
 * (re_linkmeas_records()) within 3 x that many intervals + 0.5 s, into
 * @m's stream fields; on failure the operator's message in @err (@cap
 * bytes). The stream stays open on success and when only the records
 * failed (gl_link_stream_info() says; the caller closes it).
 * Return: GL_OK; as re_linkmeas_open(); as re_linkmeas_records().
 */
int re_linkmeas_stream(gl_link *l, const char *addr, int udp_port, unsigned n0,
		       int64_t sample_ns, struct re_linkmeas *m, char *err,
		       size_t cap);

/*
 * re_linkmeas_reply() - @n (1..RE_LINKMEAS_MAX) round trips of "MG TIME"
 * on @l's command handle, each within @timeout_ms (0: the link default);
 * sets @m->replies, reply_med_ms and reply_max_ms.
 * Return: GL_OK; the first failing exchange's error (nothing set).
 */
int re_linkmeas_reply(gl_link *l, int n, int timeout_ms, struct re_linkmeas *m);

/*
 * re_linkmeas_records() - read at least @n (2..RE_LINKMEAS_MAX) records
 * from @l's open stream (gl_link_stream_read(), waiting on its socket with
 * poll()), all within @deadline_ms, and set @m's stream fields from their
 * times of arrival and sample numbers; @sample_ns (the plan's controller
 * sample) gives n0_ms. A read takes every record waiting: each counts
 * (the reader's accepted count says how many), at the time of that read,
 * so that a late wake-up makes neither a longer interval nor a record
 * that looks lost; the first read counts its newest record only.
 * Return: GL_OK; GL_ERR_ARG (no stream open, @n out of range);
 *         GL_ERR_TIMEOUT (fewer than @n records by the deadline:
 *         @m->records says how many came); GL_ERR_SYS.
 */
int re_linkmeas_records(gl_link *l, int n, int64_t sample_ns, int deadline_ms,
			struct re_linkmeas *m);

/*
 * re_linkmeas_intervals() - the stream fields of @m from @n (>= 2) reads:
 * their times @t_ns, the 16-bit sample number of the newest record each
 * took @sample (in order of arrival; the number wraps: serial arithmetic)
 * and how many records each took @count (>= 1; @count[0] is not used: the
 * first read's newest starts; NULL: one each). @m->records is 1 + the sum
 * of @count[1..n-1]; the mean interval and the step of the sample number
 * are per record; the minimum is 0 when a read took more than one. Pure.
 * Return: GL_OK; GL_ERR_ARG (NULL, @n < 2, a @count below 1).
 */
int re_linkmeas_intervals(const int64_t *t_ns, const uint16_t *sample,
			  const int *count, int n, struct re_linkmeas *m);

/*
 * re_linkmeas_median_ms() - the median of @n (>= 1) durations in ns, in
 * ms (the mean of the middle two for an even @n); @ns is sorted in place.
 * 0 for n < 1.
 */
double re_linkmeas_median_ms(int64_t *ns, int n);

/*
 * re_linkmeas_line() - the one line that says it, without the program's
 * name, into @buf (@cap bytes), e.g.
 *   record stream: UDP handle B, every 12 samples (11.7 ms); measured over
 *   20 records 11.7 ms (11.5-12.0); command reply 0.4 ms (max 0.9)
 * or, with no stream measured,
 *   record polled (QR each cycle); command reply 0.4 ms (max 0.9)
 * Return: the length snprintf() gives.
 */
int re_linkmeas_line(const struct re_linkmeas *m, char *buf, size_t cap);

#endif /* RE_LINKMEAS_H */
