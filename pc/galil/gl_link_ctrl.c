/*
 * gl_link_ctrl.c - the control-character requests of the command reference
 * (^R^V, ^R^S, ^L^K: which one a command is, and the request sent) and the
 * controller's identification (^R^V and MG _BN).
 */
#include <string.h>

#include "gl_err.h"
#include "gl_link_int.h"

int gl_link_identify(gl_link *l, char *model, size_t cap, long *serial)
{
	static const char rv[] = {0x12, 0x16}; /* ^R ^V */
	const struct gl_xfer x = {.line = rv, .len = 2, .n_term = 1};
	struct gl_reply r;
	char bn[64];
	const char *s;
	size_t n;
	double v;
	int rc;

	if (!l || !model || cap == 0 || !serial)
		return GL_ERR_ARG;
	gl_link_ctrl_clear(l);
	rc = gl_link_xfer(l, &l->cmd, &x, l->timeout_ms, &r);
	if (rc < 0)
		return rc;
	if (r.n_err)
		return gl_link_fetch_tc1(l);
	s = r.text;
	n = r.text_len;
	gl_link_trim(&s, &n);
	if (n >= cap)
		return GL_ERR_OVERFLOW;
	memcpy(model, s, n);
	model[n] = '\0';
	rc = gl_link_command(l, "MG _BN", bn, sizeof(bn), 0);
	if (rc < 0)
		return rc;
	if (!gl_parse_double(bn, (size_t)rc, NULL, &v) || v < 0 || v > 2e9)
		return GL_ERR_PROTO;
	*serial = (long)v;
	return GL_OK;
}

enum gl_ctrl_kind gl_link_ctrl_kind(const char *cmd)
{
	size_t i, n = strlen(cmd);
	enum gl_ctrl_kind k = GL_CTRL_NONE;

	if (n >= 2 && cmd[0] == 0x12 && cmd[1] == 0x16)
		k = n == 2 ? GL_CTRL_REVISION : GL_CTRL_OTHER;
	else if (n >= 2 && cmd[0] == 0x12 && cmd[1] == 0x13)
		k = n == 2 ? GL_CTRL_RESET : GL_CTRL_OTHER;
	else if (n >= 2 && cmd[0] == 0x0c && cmd[1] == 0x0b)
		k = GL_CTRL_LOCK;
	for (i = k == GL_CTRL_NONE ? 0 : 2; i < n; i++)
		if ((unsigned char)cmd[i] < 0x20 ||
		    (unsigned char)cmd[i] > 0x7e)
			return GL_CTRL_OTHER;
	return k;
}

int gl_link_ctrl_request(gl_link *l, const char *req, char *resp, size_t cap,
			 int timeout_ms)
{
	struct gl_xfer x = {.line = req, .n_term = 1};
	struct gl_reply r;
	int rc, t = l ? gl_link_pick_timeout(l, timeout_ms) : GL_ERR_ARG;

	if (!l || !req || t < 0 || strlen(req) > GL_LINE_MAX ||
	    gl_link_ctrl_kind(req) <= GL_CTRL_NONE)
		return GL_ERR_ARG;
	gl_link_ctrl_clear(l);
	x.len = strlen(req);
	rc = gl_link_xfer(l, &l->cmd, &x, t, &r);
	if (rc < 0)
		return rc;
	if (r.n_err)
		return gl_link_fetch_tc1(l);
	return gl_link_text_out(&r, resp, cap);
}
