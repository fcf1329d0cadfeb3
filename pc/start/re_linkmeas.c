/*
 * re_linkmeas.c - the link's reply time and record interval, measured.
 * See re_linkmeas.h.
 */
#include "re_linkmeas.h"

#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_record.h"
#include "gl_stream.h"

static int cmp_i64(const void *a, const void *b)
{
	int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;

	return (x > y) - (x < y);
}

double re_linkmeas_median_ms(int64_t *ns, int n)
{
	if (n < 1)
		return 0;
	qsort(ns, (size_t)n, sizeof(ns[0]), cmp_i64);
	if (n % 2)
		return (double)ns[n / 2] / 1e6;
	return ((double)ns[n / 2 - 1] + (double)ns[n / 2]) / 2e6;
}

int re_linkmeas_open(gl_link *l, const char *addr, int udp_port, unsigned n0,
		     int64_t sample_ns, int timeout_ms, char *err, size_t cap)
{
	char why[GL_ERRTEXT_LEN] = "", tc[GL_ERRTEXT_LEN + 40] = "";
	const char *text;
	int code = 0;
	int rc =
	    gl_link_stream_open(l, udp_port, n0, sample_ns, timeout_ms, why);

	if (rc == GL_OK)
		return rc;
	if (!why[0])
		snprintf(why, sizeof(why), "%s", gl_strerror(rc));
	text = rc == GL_ERR_CTRL ? gl_link_ctrl_error(l, &code) : NULL;
	if (text && *text && !strstr(why, text))
		snprintf(tc, sizeof(tc), " (TC1 '%d %s')", code, text);
	if (rc == GL_ERR_CTRL)
		snprintf(err, cap,
			 "the controller at %s refused the record stream "
			 "'DR %u' to its UDP port %d: %s%s; its shortest "
			 "interval may be longer than %u samples (a "
			 "DMC-4030's command reference gives 8): make "
			 "period_ms longer (the interval is a quarter of "
			 "it, docs/link.md) or set controller.record: poll",
			 addr, n0, udp_port, why, tc, n0);
	else
		snprintf(err, cap,
			 "cannot open the record stream from the controller "
			 "at %s, UDP port %d (DR %u): %s; check that the "
			 "controller answers on that port (controller.udp_port;"
			 " 60007 on a DMC-40x0) and that nothing between "
			 "drops UDP, or set controller.record: poll "
			 "(docs/link.md)",
			 addr, udp_port, n0, why);
	return rc;
}

int re_linkmeas_stream(gl_link *l, const char *addr, int udp_port, unsigned n0,
		       int64_t sample_ns, struct re_linkmeas *m, char *err,
		       size_t cap)
{
	double rec_ms = (double)n0 * (double)sample_ns / 1e6;
	int dl_ms = (int)(3 * RE_LINKMEAS_RECORDS * rec_ms) + 500;
	int rc = re_linkmeas_open(l, addr, udp_port, n0, sample_ns,
				  RE_LINKMEAS_OPEN_MS, err, cap);

	if (rc != GL_OK)
		return rc;
	rc = re_linkmeas_records(l, RE_LINKMEAS_RECORDS, sample_ns, dl_ms, m);
	if (rc == GL_ERR_TIMEOUT)
		snprintf(err, cap,
			 "the record stream from the controller at %s (UDP "
			 "port %d, DR %u) opened, but only %d of %d records "
			 "arrived within %d ms: UDP from the controller is "
			 "lost or dropped on the way (a firewall?); fix the "
			 "network or set controller.record: poll "
			 "(docs/link.md)",
			 addr, udp_port, n0, m->records, RE_LINKMEAS_RECORDS,
			 dl_ms);
	else if (rc != GL_OK)
		snprintf(err, cap,
			 "cannot read the record stream from the controller "
			 "at %s (UDP port %d): %s",
			 addr, udp_port,
			 rc == GL_ERR_SYS ? strerror(errno) : gl_strerror(rc));
	return rc;
}

int re_linkmeas_reply(gl_link *l, int n, int timeout_ms, struct re_linkmeas *m)
{
	int64_t rt[RE_LINKMEAS_MAX], t0, max = 0;
	char resp[64];
	int rc;

	if (!l || !m || n < 1 || n > RE_LINKMEAS_MAX)
		return GL_ERR_ARG;
	for (int i = 0; i < n; i++) {
		t0 = base_now_ns();
		rc = gl_link_command(l, "MG TIME", resp, sizeof(resp),
				     timeout_ms);
		if (rc < 0)
			return rc;
		rt[i] = base_now_ns() - t0;
		if (rt[i] > max)
			max = rt[i];
	}
	m->replies = n;
	m->reply_max_ms = (double)max / 1e6;
	m->reply_med_ms = re_linkmeas_median_ms(rt, n);
	return GL_OK;
}

int re_linkmeas_intervals(const int64_t *t_ns, const uint16_t *sample,
			  const int *count, int n, struct re_linkmeas *m)
{
	int64_t d, min, max;
	int recs = 1, k;

	if (!t_ns || !sample || !m || n < 2)
		return GL_ERR_ARG;
	for (int i = 1; i < n; i++)
		if (count && count[i] < 1)
			return GL_ERR_ARG;
	min = max = t_ns[1] - t_ns[0];
	for (int i = 1; i < n; i++) {
		k = count ? count[i] : 1;
		d = t_ns[i] - t_ns[i - 1];
		/* records read together arrived together, as seen here */
		min = k > 1 ? 0 : (d < min ? d : min);
		max = d > max ? d : max;
		recs += k;
	}
	m->records = recs;
	m->mean_ms = (double)(t_ns[n - 1] - t_ns[0]) / (recs - 1) / 1e6;
	m->min_ms = (double)min / 1e6;
	m->max_ms = (double)max / 1e6;
	/* the 16-bit number wraps every 65 536 samples: the span modulo
	 * 2^16 is right for any span shorter than that */
	m->step_samples =
	    (double)(uint16_t)(sample[n - 1] - sample[0]) / (recs - 1);
	return GL_OK;
}

/* Wait on the stream's socket until @end_ns; 1 readable, 0 not by then,
 * GL_ERR_SYS (errno). */
static int wait_readable(int fd, int64_t end_ns)
{
	struct pollfd p = {.fd = fd, .events = POLLIN};
	int64_t left = end_ns - base_now_ns();
	int rc;

	if (left <= 0)
		return 0;
	rc = poll(&p, 1, (int)((left + 999999) / 1000000));
	if (rc < 0)
		return errno == EINTR ? 0 : GL_ERR_SYS;
	return rc > 0;
}

/* The records the stream's reader accepted so far. */
static uint64_t accepted(const gl_link *l)
{
	struct gl_stream_stats st;

	gl_link_stream_stats(l, &st);
	return st.accepted;
}

int re_linkmeas_records(gl_link *l, int n, int64_t sample_ns, int deadline_ms,
			struct re_linkmeas *m)
{
	int64_t t[RE_LINKMEAS_MAX], now;
	int64_t end = base_now_ns() + (int64_t)deadline_ms * 1000000;
	uint16_t s[RE_LINKMEAS_MAX];
	int c[RE_LINKMEAS_MAX];
	struct gl_record rec;
	uint64_t before;
	unsigned n0 = 0;
	int handle = 0, k = 0, got = 0, rc;

	if (!l || !m || n < 2 || n > RE_LINKMEAS_MAX ||
	    gl_link_stream_info(l, &handle, &n0) != 1)
		return GL_ERR_ARG;
	m->records = 0;
	m->handle = handle;
	m->n0 = n0;
	m->n0_ms = (double)n0 * (double)sample_ns / 1e6;
	before = accepted(l);
	/* a read takes every record waiting: the ones a late wake-up finds
	 * together count each (the first read's newest only: it starts) */
	while (got < n && base_now_ns() < end) {
		rc = wait_readable(gl_link_stream_fd(l), end);
		if (rc < 0)
			return rc;
		now = base_now_ns();
		rc = rc ? gl_link_stream_read(l, &rec, now) : 0;
		if (rc < 0)
			return rc;
		if (rc == 1) {
			c[k] = (int)(accepted(l) - before);
			before += (uint64_t)c[k];
			got += k ? c[k] : 1;
			t[k] = now;
			s[k++] = rec.sample;
		}
	}
	if (got < n) {
		m->records = got;
		return GL_ERR_TIMEOUT;
	}
	return re_linkmeas_intervals(t, s, c, k, m);
}

/* A duration in ms: one decimal, two under 0.1 ms (a loopback's reply
 * would read "0.0", like a time never measured). */
static const char *ms_text(double ms, char *buf, size_t cap)
{
	snprintf(buf, cap, ms < 0.095 ? "%.2f" : "%.1f", ms);
	return buf;
}

int re_linkmeas_line(const struct re_linkmeas *m, char *buf, size_t cap)
{
	char a[16], b[16], c[16], d[16], r[16], x[16], step[96] = "";

	ms_text(m->reply_med_ms, r, sizeof(r));
	ms_text(m->reply_max_ms, x, sizeof(x));
	if (m->records < 2)
		return snprintf(buf, cap,
				"record polled (QR each cycle); command reply "
				"%s ms (max %s)",
				r, x);
	/* the records' own numbers say what the controller did: a step other
	 * than n0 is a lost record or a rate other than the one asked */
	if (m->step_samples < m->n0 - 0.01 || m->step_samples > m->n0 + 0.01)
		snprintf(step, sizeof(step),
			 ", a record every %.1f samples by their numbers (not "
			 "%u: lost or uneven)",
			 m->step_samples, m->n0);
	return snprintf(buf, cap,
			"record stream: UDP handle %c, every %u samples (%s "
			"ms); measured over %d records %s ms (%s-%s)%s; "
			"command reply %s ms (max %s)",
			'A' + (m->handle & 7), m->n0,
			ms_text(m->n0_ms, a, sizeof(a)), m->records,
			ms_text(m->mean_ms, b, sizeof(b)),
			ms_text(m->min_ms, c, sizeof(c)),
			ms_text(m->max_ms, d, sizeof(d)), step, r, x);
}
