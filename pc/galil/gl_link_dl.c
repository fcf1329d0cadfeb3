/*
 * gl_link_dl.c - programs over the link: DL (the lines checked, sent one
 * by one with a look for an early '?', then "\\") and UL (the program read
 * back). What the controller answers and what *bad_line means: gl_link.c's
 * header ("DL").
 */
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link_int.h"

/* Length of the line at @p (up to CR or LF) and of its line end. */
static size_t line_len(const char *p, size_t left, size_t *eol)
{
	size_t n = 0;

	while (n < left && p[n] != '\r' && p[n] != '\n')
		n++;
	*eol = 0;
	if (n < left)
		*eol =
		    (p[n] == '\r' && n + 1 < left && p[n + 1] == '\n') ? 2 : 1;
	return n;
}

/* Refuse what the controller would reject or misread; nothing is sent. */
static int dl_validate(const char *prog, size_t len, int *bad_line)
{
	size_t off = 0, n, eol, i;
	int line = 0;

	while (off < len) {
		n = line_len(prog + off, len - off, &eol);
		line++;
		for (i = 0; i < n; i++) {
			unsigned char c = (unsigned char)prog[off + i];

			if ((c < 0x20 && c != '\t') || c > 0x7e || c == '\\')
				break;
		}
		if (i < n || n > GL_LINE_MAX) {
			*bad_line = line;
			return GL_ERR_ARG;
		}
		off += n + eol;
	}
	return GL_OK;
}

/*
 * Look for an early '?', waiting up to the DL pace (0: not at all).
 * Return 1 if one was seen, 0 if not, or an error.
 */
static int dl_early_reject(gl_link *l, struct gl_reply *r, bool *done)
{
	int64_t deadline =
	    l->dl_pace_ms > 0 ? base_now_ms() + l->dl_pace_ms : -1;
	int rc, n_err = 0;

	rc = gl_link_chan_read(l, &l->cmd, deadline);
	if (rc == GL_ERR_AGAIN || rc == GL_ERR_TIMEOUT)
		return 0;
	if (rc < 0)
		return gl_link_chan_fail(&l->cmd, rc);
	rc = gl_proto_next(&l->cmd.p, r);
	if (rc == GL_OK) {
		*done = true;
		return r->n_err ? 1 : gl_link_chan_fail(&l->cmd, GL_ERR_PROTO);
	}
	if (rc != GL_ERR_AGAIN)
		return gl_link_chan_fail(&l->cmd, rc);
	gl_proto_progress(&l->cmd.p, &n_err);
	return n_err > 0;
}

/* Send the lines (each + CR); stop early on '?'. */
static int dl_send_lines(gl_link *l, const char *prog, size_t len,
			 int64_t deadline, int *bad_line, struct gl_reply *r,
			 bool *done)
{
	char buf[GL_LINE_MAX + 1];
	size_t off = 0, n, eol;
	int line = 0, rc;

	while (off < len) {
		n = line_len(prog + off, len - off, &eol);
		memcpy(buf, prog + off, n);
		buf[n] = '\r';
		rc = gl_link_chan_write(l, &l->cmd, buf, n + 1, deadline);
		if (rc < 0)
			return gl_link_chan_fail(&l->cmd, rc);
		line++;
		off += n + eol;
		rc = dl_early_reject(l, r, done);
		if (rc < 0)
			return rc;
		if (rc == 1) {
			*bad_line = line;
			break;
		}
	}
	return GL_OK;
}

/* DL after validation: "DL", the lines, "\\", then both terminators. */
static int dl_run(gl_link *l, const char *prog, size_t len, int *bad,
		  int timeout_ms, struct gl_reply *r)
{
	const struct gl_xfer x = {.line = "DL", .len = 2, .n_term = 2};
	int64_t deadline = base_now_ms() + timeout_ms;
	bool done = false;
	int rc;

	rc = gl_link_xfer_begin(l, &l->cmd, &x, deadline);
	if (rc < 0)
		return rc;
	rc = dl_send_lines(l, prog, len, deadline, bad, r, &done);
	if (rc < 0)
		return rc;
	rc = gl_link_chan_write(l, &l->cmd, "\\", 1, deadline);
	if (rc < 0)
		return gl_link_chan_fail(&l->cmd, rc);
	return done ? gl_link_xfer_finish(l, &l->cmd, false)
		    : gl_link_xfer_end(l, &l->cmd, &x, r, deadline);
}

int gl_link_download(gl_link *l, const char *prog, size_t len, int *bad_line,
		     int timeout_ms)
{
	struct gl_reply r;
	int rc, bad = 0,
		t = l ? gl_link_pick_timeout(l, timeout_ms) : GL_ERR_ARG;

	if (bad_line)
		*bad_line = 0;
	if (!l || (!prog && len) || t < 0)
		return GL_ERR_ARG;
	gl_link_ctrl_clear(l);
	rc = dl_validate(prog, len, &bad);
	if (rc == GL_OK)
		rc = dl_run(l, prog, len, &bad, t, &r);
	if (bad_line)
		*bad_line = bad;
	if (rc < 0)
		return rc;
	return r.n_err ? gl_link_fetch_tc1(l) : GL_OK;
}

int gl_link_set_dl_pace(gl_link *l, int pace_ms)
{
	if (!l || pace_ms < 0)
		return GL_ERR_ARG;
	l->dl_pace_ms = pace_ms;
	return GL_OK;
}

int gl_link_upload(gl_link *l, char *buf, size_t cap, int timeout_ms)
{
	struct gl_xfer x = {
	    .line = "UL", .len = 2, .n_term = 1, .ubuf = buf, .ucap = cap};
	struct gl_reply r;
	int rc, t = l ? gl_link_pick_timeout(l, timeout_ms) : GL_ERR_ARG;

	if (!l || !buf || cap == 0 || t < 0)
		return GL_ERR_ARG;
	gl_link_ctrl_clear(l);
	rc = gl_link_xfer(l, &l->cmd, &x, t, &r);
	if (rc < 0)
		return rc;
	if (r.n_err)
		return gl_link_fetch_tc1(l);
	return r.truncated ? GL_ERR_OVERFLOW : (int)r.text_len;
}
