/*
 * gl_link_io.c - the link's byte moving: send and receive on one channel
 * with deadlines, and one exchange (a line sent, its reply awaited). The
 * parser (gl_proto) frames the bytes; the rules for a channel out of step
 * are in gl_link.c's header.
 */
#include <errno.h>
#include <poll.h>
#include <stdint.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link_int.h"

#define READ_CHUNK 1024 /* bytes per recv() */

int gl_link_left_ms(int64_t deadline)
{
	int64_t d = deadline - base_now_ms();

	return d < 0 ? 0 : (int)d;
}

static int wait_fd(int fd, short events, int64_t deadline)
{
	struct pollfd pfd = {.fd = fd, .events = events};
	int rc;

	do {
		rc = poll(&pfd, 1, gl_link_left_ms(deadline));
	} while (rc < 0 && errno == EINTR);
	if (rc < 0)
		return GL_ERR_SYS;
	return rc == 0 ? GL_ERR_TIMEOUT : GL_OK;
}

int gl_link_chan_write(gl_link *l, struct gl_chan *ch, const void *buf,
		       size_t len, int64_t deadline)
{
	const char *b = buf;
	ssize_t n;
	int rc;

	while (len > 0) {
		n = send(ch->fd, b, len, MSG_NOSIGNAL);
		if (n > 0) {
			b += n;
			len -= (size_t)n;
			l->tx_bytes += (uint64_t)n;
			continue;
		}
		if (errno == EPIPE || errno == ECONNRESET)
			return GL_ERR_CLOSED;
		if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
			return GL_ERR_SYS;
		rc = wait_fd(ch->fd, POLLOUT, deadline);
		if (rc < 0)
			return rc;
	}
	return GL_OK;
}

/* Read what is there (one recv) into the parser (gl_link_int.h). */
int gl_link_chan_read(gl_link *l, struct gl_chan *ch, int64_t deadline)
{
	uint8_t buf[READ_CHUNK];
	size_t want = gl_proto_space(&ch->p);
	ssize_t n;
	int rc;

	if (want > sizeof(buf))
		want = sizeof(buf);
	if (want == 0)
		return GL_ERR_PROTO; /* cannot happen: next() drains input */
	if (deadline >= 0) {
		rc = wait_fd(ch->fd, POLLIN, deadline);
		if (rc < 0)
			return rc;
	}
	for (;;) {
		n = recv(ch->fd, buf, want, 0);
		if (n > 0)
			break;
		if (n == 0 || errno == ECONNRESET)
			return GL_ERR_CLOSED;
		if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
			return GL_ERR_SYS;
		if (deadline < 0)
			return GL_ERR_AGAIN;
		rc = wait_fd(ch->fd, POLLIN, deadline);
		if (rc < 0)
			return rc;
	}
	l->rx_bytes += (uint64_t)n;
	return gl_proto_feed(&ch->p, buf, (size_t)n);
}

int gl_link_chan_fail(struct gl_chan *ch, int rc)
{
	if (rc == GL_ERR_TIMEOUT || rc == GL_ERR_PROTO || rc == GL_ERR_CLOSED ||
	    rc == GL_ERR_SYS)
		ch->broken = true;
	return rc;
}

void gl_link_chan_close(struct gl_chan *ch)
{
	if (ch->fd >= 0)
		close(ch->fd);
	ch->fd = -1;
}

/*
 * Before sending: take bytes that arrived since the last reply (only
 * unsolicited ones are allowed). At most GL_LINK_MSG_READS_MAX reads, so that a
 * flood cannot hold the caller; the rest is taken with the reply.
 */
int gl_link_chan_drain_idle(gl_link *l, struct gl_chan *ch)
{
	struct gl_reply r;
	int i, rc;

	for (i = 0; i < GL_LINK_MSG_READS_MAX; i++) {
		rc = gl_link_chan_read(l, ch, -1);
		if (rc == GL_ERR_AGAIN)
			return GL_OK;
		if (rc < 0)
			return gl_link_chan_fail(ch, rc);
		if (gl_proto_next(&ch->p, &r) != GL_ERR_AGAIN)
			return gl_link_chan_fail(ch, GL_ERR_PROTO);
	}
	return GL_OK;
}

int gl_link_xfer_begin(gl_link *l, struct gl_chan *ch, const struct gl_xfer *x,
		       int64_t deadline)
{
	char line[GL_LINE_MAX + 2];
	int rc;

	if (ch->broken || ch->fd < 0)
		return GL_ERR_BROKEN;
	if (x->len > GL_LINE_MAX)
		return GL_ERR_ARG;
	if (ch == &l->cmd && l->n_posted > 0) {
		rc = gl_link_post_settle(l, deadline);
		if (rc < 0)
			return rc;
	}
	rc = x->seen_idle ? GL_OK : gl_link_chan_drain_idle(l, ch);
	if (rc < 0)
		return rc;
	rc = x->ubuf ? gl_proto_expect_upload(&ch->p, x->ubuf, x->ucap)
		     : gl_proto_expect(&ch->p, x->n_term, x->bin_len);
	if (rc < 0)
		return rc;
	memcpy(line, x->line, x->len);
	line[x->len] = '\r';
	return gl_link_chan_fail(
	    ch, gl_link_chan_write(l, ch, line, x->len + 1, deadline));
}

/* After a reply: retire it; nothing solicited may follow (gl_link_int.h). */
int gl_link_xfer_finish(gl_link *l, struct gl_chan *ch, bool seen_idle)
{
	struct gl_reply extra;

	if (!seen_idle && gl_proto_space(&ch->p) > 0)
		gl_link_chan_read(l, ch,
				  -1); /* errors show up at the next call */
	if (gl_proto_next(&ch->p, &extra) != GL_ERR_AGAIN)
		return gl_link_chan_fail(ch, GL_ERR_PROTO);
	if (ch == &l->cmd)
		l->round_trips++;
	return GL_OK;
}

/* Wait for the awaited reply. */
int gl_link_xfer_end(gl_link *l, struct gl_chan *ch, const struct gl_xfer *x,
		     struct gl_reply *r, int64_t deadline)
{
	int rc;

	while ((rc = gl_proto_next(&ch->p, r)) == GL_ERR_AGAIN) {
		rc = gl_link_chan_read(l, ch, deadline);
		if (rc < 0)
			return gl_link_chan_fail(ch, rc);
	}
	if (rc < 0)
		return gl_link_chan_fail(ch, rc);
	return gl_link_xfer_finish(l, ch, x->seen_idle);
}

/* The posted lines' replies, awaited before another exchange. */
int gl_link_post_settle(gl_link *l, int64_t deadline)
{
	struct gl_reply r;
	int rc;

	while (l->n_posted > 0) {
		while ((rc = gl_proto_next(&l->cmd.p, &r)) == GL_ERR_AGAIN) {
			rc = gl_link_chan_read(l, &l->cmd, deadline);
			if (rc < 0)
				return gl_link_chan_fail(&l->cmd, rc);
		}
		if (rc < 0)
			return gl_link_chan_fail(&l->cmd, rc);
		l->n_posted--;
		if (r.n_err)
			l->post_errors++;
	}
	return gl_link_xfer_finish(l, &l->cmd, true);
}

int gl_link_xfer(gl_link *l, struct gl_chan *ch, const struct gl_xfer *x,
		 int timeout_ms, struct gl_reply *r)
{
	int64_t deadline = base_now_ms() + timeout_ms;
	int rc;

	rc = gl_link_xfer_begin(l, ch, x, deadline);
	if (rc < 0)
		return rc;
	return gl_link_xfer_end(l, ch, x, r, deadline);
}
