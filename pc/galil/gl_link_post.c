/*
 * gl_link_post.c - lines sent now and their replies collected later, so
 * that a periodic cycle never waits for the controller (the heartbeat and
 * the seal's read-back beside the record stream: docs/link.md, "The record
 * as a stream"). Up to GL_LINK_POST_MAX lines may be outstanding: a reply
 * the controller's TCP resends on its own timer (200 ms at least) then
 * holds nothing back, the next lines still reach the controller. Their
 * replies come in order and are framed by the same parser as every other
 * (it queues what it awaits); any other exchange first waits for all of
 * them (gl_link_post_settle()), so the command handle is never out of
 * step.
 */
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link_int.h"

int gl_link_post(gl_link *l, const char *cmd)
{
	char line[GL_LINE_MAX + 2];
	size_t len;
	int n, rc;

	if (!l || !cmd)
		return GL_ERR_ARG;
	if (l->cmd.broken || l->cmd.fd < 0)
		return GL_ERR_BROKEN;
	if (l->n_posted >= GL_LINK_POST_MAX)
		return GL_ERR_BUSY;
	len = strlen(cmd);
	n = gl_link_count_commands(cmd, len);
	if (n < 0 || len > GL_LINE_MAX)
		return GL_ERR_ARG;
	/* bytes that came while nothing was awaited may only be
	 * unsolicited; with replies outstanding they are theirs */
	if (!l->n_posted && (rc = gl_link_chan_drain_idle(l, &l->cmd)) < 0)
		return rc;
	rc = gl_proto_expect(&l->cmd.p, n, 0);
	if (rc < 0)
		return rc;
	memcpy(line, cmd, len);
	line[len] = '\r';
	/* the deadline is now: the send never waits (a socket that cannot
	 * take one short line means a peer that stopped reading long ago) */
	rc = gl_link_chan_fail(&l->cmd, gl_link_chan_write(l, &l->cmd, line,
							   len + 1,
							   base_now_ms()));
	if (rc < 0)
		return rc;
	l->n_posted++;
	return GL_OK;
}

int gl_link_collect(gl_link *l, char *text, size_t cap)
{
	struct gl_reply r;
	int rc;

	if (!l)
		return GL_ERR_ARG;
	if (!l->n_posted)
		return GL_ERR_NOENT;
	if (l->cmd.broken)
		return GL_ERR_BROKEN;
	while ((rc = gl_proto_next(&l->cmd.p, &r)) == GL_ERR_AGAIN) {
		rc = gl_link_chan_read(l, &l->cmd, -1);
		if (rc == GL_ERR_AGAIN)
			return GL_ERR_AGAIN;
		if (rc < 0)
			return gl_link_chan_fail(&l->cmd, rc);
	}
	if (rc < 0)
		return gl_link_chan_fail(&l->cmd, rc);
	l->n_posted--;
	/* the last one: nothing solicited may follow it (and it counts the
	 * round trip); the others are counted here */
	if (l->n_posted)
		l->round_trips++;
	else if ((rc = gl_link_xfer_finish(l, &l->cmd, true)) < 0)
		return rc;
	if (r.n_err) {
		if (l->n_posted) {
			/* TC1 would have to wait behind the others */
			gl_link_ctrl_clear(l);
			l->post_errors++;
			return GL_ERR_CTRL;
		}
		return gl_link_fetch_tc1(l);
	}
	return gl_link_text_out(&r, text, cap);
}

int gl_link_posted(const gl_link *l)
{
	return l ? l->n_posted : 0;
}

uint64_t gl_link_post_errors(const gl_link *l)
{
	return l ? l->post_errors : 0;
}
