/*
 * gl_link_post.c - a line sent now and its reply collected later, so that
 * a periodic cycle never waits for the controller (the heartbeat and the
 * seal's read-back beside the record stream: docs/link.md, "The record as
 * a stream"). The reply is framed by the same parser as every other; any
 * other exchange waits for it first (gl_link_post_settle()), so the
 * command handle is never out of step.
 */
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link_int.h"

int gl_link_post(gl_link *l, const char *cmd)
{
	struct gl_xfer x = {.line = cmd};
	int n;

	if (!l || !cmd)
		return GL_ERR_ARG;
	if (l->cmd.broken || l->cmd.fd < 0)
		return GL_ERR_BROKEN;
	if (l->posted)
		return GL_ERR_BUSY;
	x.len = strlen(cmd);
	n = gl_link_count_commands(cmd, x.len);
	if (n < 0 || x.len > GL_LINE_MAX)
		return GL_ERR_ARG;
	x.n_term = n;
	gl_link_ctrl_clear(l);
	/* the deadline is now: the send never waits (a socket that cannot
	 * take one short line means a peer that stopped reading long ago) */
	n = gl_link_xfer_begin(l, &l->cmd, &x, base_now_ms());
	if (n < 0)
		return n;
	l->posted = true;
	return GL_OK;
}

int gl_link_collect(gl_link *l, char *text, size_t cap)
{
	struct gl_reply r;
	int rc;

	if (!l)
		return GL_ERR_ARG;
	if (!l->posted)
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
	l->posted = false;
	rc = gl_link_xfer_finish(l, &l->cmd, false);
	if (rc < 0)
		return rc;
	if (r.n_err)
		return gl_link_fetch_tc1(l);
	return gl_link_text_out(&r, text, cap);
}

int gl_link_posted(const gl_link *l)
{
	return l && l->posted;
}

uint64_t gl_link_post_errors(const gl_link *l)
{
	return l ? l->post_errors : 0;
}
