/*
 * re_super_stream.c - the cycle's exchange when the record is a stream
 * (re_super_cfg.stream; docs/link.md, "The record as a stream"): the
 * controller sends its record by itself (DR over UDP), the supervisor
 * posts its heartbeat (and a chunk of the seal's read-back) on TCP every
 * cycle and collects the replies when they are there: a reply the
 * controller's TCP resends on its own timer holds no heartbeat back.
 * Nothing waits. Judged by the supervisor's own clock: the record's age
 * (the last fresh one) and the program's echo of the heartbeat it took
 * (the heartbeats sent are remembered with their times, so the echo is
 * judged against what this supervisor sent, never against the
 * controller's copy), with the round trip's limits; the oldest reply
 * outstanding, with a limit of its own. A lost record costs one sample; a
 * reordered or duplicated one is dropped by the reader (gl_stream). Here too: the heartbeat's text, which
 * the round trip (re_super.c) sends as well.
 */
#include "re_super_int.h"

#include <stdio.h>
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"

static int64_t now_of(const struct re_super *s)
{
	return s->pub.io.ops->now_ns(s->pub.io.ud);
}

/* "hbpc=N" into @buf (32 bytes; N < RE_HBPC_WRAP, 10 digits at most)
 * without snprintf: the one command text built every cycle.
 * Return: its length. */
static int hb_prefix(char *buf, long hb)
{
	char dig[16];
	int n = 0;

	memcpy(buf, "hbpc=", 5);
	do {
		dig[n++] = (char)('0' + hb % 10);
		hb /= 10;
	} while (hb > 0 && n < (int)sizeof(dig));
	for (int i = 0; i < n; i++)
		buf[5 + i] = dig[n - 1 - i];
	buf[5 + n] = '\0';
	return 5 + n;
}

/* s->prefix for @hb: the last one's digits counted up in place when @hb
 * is one more (as it is in every cycle but the wrap: no division), else
 * written anew. */
static void hb_prefix_next(struct re_super *s, long hb)
{
	int i = s->prefix_len - 1;

	if (s->prefix_len > 5 && hb == s->prefix_hb + 1) {
		while (i >= 5 && s->prefix[i] == '9')
			s->prefix[i--] = '0';
		if (i >= 5) { /* else 99..9 + 1: one digit more */
			s->prefix[i]++;
			s->prefix_hb = hb;
			return;
		}
	}
	s->prefix_len = hb_prefix(s->prefix, hb);
	s->prefix_hb = hb;
}

void re_super_hb_next(struct re_super *s)
{
	s->pub.hbpc = (s->pub.hbpc + 1) % RE_HBPC_WRAP;
	hb_prefix_next(s, s->pub.hbpc);
}

void re_super_stream_reset(struct re_super *s, int64_t now_ns)
{
	s->rec_ns = now_ns;
	s->sent_n = 0;
	s->pub.fresh = 0;
}

static int link_fault(struct re_fault *f, const char *what, int rc)
{
	re_fault_set(f, RE_F_COMM, -1);
	snprintf(f->s, sizeof(f->s), "%s: %s", what, gl_strerror(rc));
	return RE_FAULT;
}

static int refused(struct re_super *s, struct re_fault *f)
{
	re_fault_set(f, RE_F_COMM, -1);
	snprintf(f->s, sizeof(f->s),
		 "the controller refused the heartbeat line: %s",
		 s->pub.io.ops->ctrl_error(s->pub.io.ud, NULL));
	return RE_FAULT;
}

/* The replies to lines posted in earlier cycles that are all there, in
 * order. GL_ERR_NOENT: another exchange took them (a command in between):
 * the controller had answered them before that command's reply, but their
 * text is gone. */
static int collect(struct re_super *s, int64_t now, struct re_fault *f)
{
	while (s->n_out > 0) {
		int i = s->out_head, chunk = s->out[i].chunk;
		int rc = s->pub.io.ops->collect(
		    s->pub.io.ud, chunk >= 0 ? s->rb_reply : s->resp,
		    chunk >= 0 ? sizeof(s->rb_reply) : sizeof(s->resp));

		if (rc == GL_ERR_AGAIN)
			return RE_OK;
		if (rc == GL_ERR_NOENT) {
			s->n_out = s->chunk_out = 0;
			return RE_OK;
		}
		s->out_head = (i + 1) % RE_POST_RING;
		s->n_out--;
		if (rc == GL_ERR_CTRL)
			return refused(s, f);
		if (rc < 0)
			return link_fault(f, "no reply to the heartbeat line",
					  rc);
		/* the reply's age: from its own line */
		if (now - s->out[i].ns > s->pub.age_last_ns)
			s->pub.age_last_ns = now - s->out[i].ns;
		if (chunk >= 0) {
			s->rb_have = 1;
			s->rb_cur = chunk;
			s->chunk_out = 0;
		}
	}
	return RE_OK;
}

/* "hbpc=N[;MG chunk]" posted (a chunk only when none is outstanding: one
 * reply text at a time), remembered with its time. */
static int post_next(struct re_super *s, int64_t now, struct re_fault *f)
{
	const char *line = s->prefix;
	int rc, chunk = -1, k;

	if (s->n_out >= RE_POST_RING)
		return RE_OK; /* the heartbeat stops: the echo ages */
	re_super_hb_next(s);
	if (s->pub.rb_n && !s->chunk_out) {
		size_t n = (size_t)s->prefix_len;

		memcpy(s->rb_line, s->prefix, n);
		s->rb_line[n] = ';';
		strcpy(s->rb_line + n + 1, s->rb_chunk[s->rb_next]);
		chunk = s->rb_next;
		line = s->rb_line;
	}
	rc = s->pub.io.ops->post(s->pub.io.ud, line);
	if (rc < 0)
		return link_fault(f, "cannot send the heartbeat", rc);
	if (chunk >= 0) {
		s->rb_next = (s->rb_next + 1) % s->pub.rb_n;
		s->chunk_out = 1;
	}
	k = (s->out_head + s->n_out++) % RE_POST_RING;
	s->out[k].ns = now;
	s->out[k].chunk = chunk;
	s->sent[s->sent_n % RE_SENT_RING].hb = s->pub.hbpc;
	s->sent[s->sent_n % RE_SENT_RING].ns = now;
	s->sent_n++;
	return RE_OK;
}

static int age_fault(struct re_fault *f, enum re_fault_id id, int64_t age,
		     int64_t crit)
{
	re_fault_set(f, id, -1);
	f->i[0] = age / BASE_NS_PER_MS;
	f->i[1] = crit / BASE_NS_PER_MS;
	return RE_FAULT;
}

int re_super_exchange_stream(struct re_super *s, struct re_fault *f)
{
	int64_t now = now_of(s), crit = s->pub.crit_ns;
	int rc;

	s->pub.age_last_ns = 0;
	s->rb_have = 0;
	if (collect(s, now, f) == RE_FAULT || post_next(s, now, f) == RE_FAULT)
		return RE_FAULT;
	rc = s->pub.io.ops->stream(s->pub.io.ud, &s->pub.rec, now);
	if (rc < 0)
		return link_fault(f, "cannot read the record stream", rc);
	s->pub.fresh = rc == 1;
	if (s->pub.fresh) {
		if (now - s->rec_ns > s->pub.age_last_ns)
			s->pub.age_last_ns = now - s->rec_ns;
		s->rec_ns = now;
		s->pub.have_record = 1;
	}
	if (s->pub.age_last_ns > s->pub.age_worst_ns)
		s->pub.age_worst_ns = s->pub.age_last_ns;
	/* the link delivers in time: the record is not older than the
	 * warning's limit (a stalled stream shows as a link down) */
	s->pub.link_ok = now - s->rec_ns <= s->noncrit_ns;
	if (now - s->rec_ns > crit)
		return age_fault(f, RE_F_WDOG_STREAM, now - s->rec_ns, crit);
	/* the oldest reply outstanding: its own limit (the echo proves
	 * the heartbeat's arrival within the critical limit) */
	if (s->n_out && s->pub.cfg.ack_limit_ns &&
	    now - s->out[s->out_head].ns > s->pub.cfg.ack_limit_ns)
		return age_fault(f, RE_F_WDOG_ACK,
				 now - s->out[s->out_head].ns,
				 s->pub.cfg.ack_limit_ns);
	return RE_OK;
}

/* When the heartbeat the echo names was sent: the latest sent with that
 * remainder; -1 when none of those remembered. */
static int64_t echo_sent_ns(const struct re_super *s, long echo)
{
	unsigned n = s->sent_n < RE_SENT_RING ? s->sent_n : RE_SENT_RING;

	for (unsigned k = 1; k <= n; k++) {
		unsigned i = (s->sent_n - k) % RE_SENT_RING;

		if (s->sent[i].hb % RE_HB_ECHO_MOD == echo)
			return s->sent[i].ns;
	}
	return -1;
}

int re_super_check_echo(struct re_super *s, struct re_fault *f)
{
	int64_t lim = s->pub.cfg.echo_limit_ns, now, sent, oldest;
	unsigned n;

	if (!lim || !s->pub.fresh || !s->pub.have_za || !s->sent_n)
		return RE_OK;
	now = now_of(s);
	sent = echo_sent_ns(s, s->pub.za.hb_echo);
	if (sent >= 0 && now - sent <= lim)
		return RE_OK;
	n = s->sent_n < RE_SENT_RING ? s->sent_n : RE_SENT_RING;
	oldest = s->sent[(s->sent_n - n) % RE_SENT_RING].ns;
	if (sent < 0 && now - oldest <= lim)
		return RE_OK; /* the first heartbeats may not be taken yet */
	re_fault_set(f, RE_F_WDOG_ECHO, -1);
	f->i[0] = sent >= 0 ? (now - sent) / BASE_NS_PER_MS : RE_VAL_UNKNOWN;
	f->i[1] = lim / BASE_NS_PER_MS;
	f->i[2] = s->pub.za.hb_echo;
	return RE_FAULT;
}
