/*
 * gl_link_msg.c - the unsolicited message handle: a second connection to
 * the controller, named with WH and made the target of CF and CW1 on the
 * command handle, and the queue of complete message lines (those that
 * still reached the command handle first).
 */
#include <stdbool.h>
#include <stdio.h>
#include <sys/socket.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link_int.h"

/* WH on the message handle: its letter A..H. */
static int msg_which_handle(gl_link *l, int timeout_ms, char *letter)
{
	const struct gl_xfer x = {.line = "WH", .len = 2, .n_term = 1};
	struct gl_reply r;
	const char *s;
	size_t n;
	int rc;

	rc = gl_link_xfer(l, &l->msg, &x, timeout_ms, &r);
	if (rc < 0)
		return rc;
	s = r.text;
	n = r.text_len;
	gl_link_trim(&s, &n);
	if (r.n_err || n != 3 || s[0] != 'I' || s[1] != 'H' || s[2] < 'A' ||
	    s[2] > 'H')
		return GL_ERR_PROTO;
	*letter = s[2];
	return GL_OK;
}

int gl_link_open_messages(gl_link *l, int timeout_ms)
{
	char cf[8], letter = 0;
	int rc, t = l ? gl_link_pick_timeout(l, timeout_ms) : GL_ERR_ARG;

	if (!l || t < 0)
		return GL_ERR_ARG;
	if (l->cmd.broken)
		return GL_ERR_BROKEN;
	gl_link_chan_close(&l->msg);
	gl_proto_init(&l->msg.p);
	l->msg.broken = false;
	rc = gl_link_sock_connect((struct sockaddr *)&l->addr, l->addr_len,
				  base_now_ms() + t, &l->msg.fd);
	if (rc < 0)
		return rc;
	rc = msg_which_handle(l, t, &letter);
	if (rc < 0)
		goto out_close_msg;
	snprintf(cf, sizeof(cf), "CF %c", letter);
	rc = gl_link_command(l, cf, NULL, 0, t);
	if (rc >= 0)
		rc = gl_link_command(l, "CW1", NULL, 0, t);
	if (rc < 0)
		goto out_close_msg;
	gl_proto_set_all_unsol(&l->msg.p, true);
	return GL_OK;

out_close_msg:
	gl_link_chan_close(&l->msg);
	return rc;
}

/* Move whatever the message handle holds into its queue. */
static int msg_pump(gl_link *l)
{
	struct gl_reply r;
	int i, rc;

	for (i = 0; i < GL_LINK_MSG_READS_MAX; i++) {
		rc = gl_link_chan_read(l, &l->msg, -1);
		if (rc == GL_ERR_AGAIN)
			return GL_OK;
		if (rc < 0)
			return rc;
		gl_proto_next(&l->msg.p, &r); /* all bytes are unsolicited */
	}
	return GL_OK;
}

int gl_link_message_queued(gl_link *l, char *line, size_t cap)
{
	int rc;

	if (!l || !line || cap == 0)
		return GL_ERR_ARG;
	rc = gl_proto_unsol_next(&l->cmd.p, line, cap);
	if (rc != GL_ERR_AGAIN)
		return rc;
	if (l->msg.fd < 0)
		return l->msg.broken ? GL_ERR_CLOSED : GL_ERR_AGAIN;
	return gl_proto_unsol_next(&l->msg.p, line, cap);
}

int gl_link_message(gl_link *l, char *line, size_t cap)
{
	int rc = gl_link_message_queued(l, line, cap), pump;

	if (rc != GL_ERR_AGAIN || l->msg.fd < 0)
		return rc;
	pump = msg_pump(l);
	rc = gl_proto_unsol_next(&l->msg.p, line, cap);
	if (rc != GL_ERR_AGAIN || pump == GL_OK)
		return rc;
	gl_link_chan_close(&l->msg);
	l->msg.broken = true;
	return pump;
}
