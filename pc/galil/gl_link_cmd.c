/*
 * gl_link_cmd.c - the link's command round trip: a command line checked,
 * sent and its reply read; after '?' the controller's reason from TC1. The
 * rules for commands and errors are in gl_link.c's header.
 */
#include <stdbool.h>
#include <string.h>

#include "gl_err.h"
#include "gl_link_int.h"

int gl_link_pick_timeout(const gl_link *l, int timeout_ms)
{
	if (timeout_ms < 0)
		return GL_ERR_ARG;
	return timeout_ms == 0 ? l->timeout_ms : timeout_ms;
}

/* Check a command line; return the number of ';'-separated commands. */
int gl_link_count_commands(const char *cmd, size_t len)
{
	bool quoted = false, empty = true;
	int n = 1;
	size_t i;

	if (len == 0 || len > GL_LINE_MAX)
		return GL_ERR_ARG;
	for (i = 0; i < len; i++) {
		unsigned char c = (unsigned char)cmd[i];

		if (c < 0x20 || c > 0x7e)
			return GL_ERR_ARG;
		if (c == '"')
			quoted = !quoted;
		if (c == ';' && !quoted) {
			if (empty)
				return GL_ERR_ARG;
			n++;
			empty = true;
		} else if (c != ' ') {
			empty = false;
		}
	}
	return quoted || empty || n > GL_PROTO_CMDS_MAX ? GL_ERR_ARG : n;
}

/* After '?': ask TC1, keep code and text, return GL_ERR_CTRL. */
int gl_link_fetch_tc1(gl_link *l)
{
	const struct gl_xfer x = {.line = "TC1", .len = 3, .n_term = 1};
	struct gl_reply r;
	const char *ep;
	double code;
	size_t n;
	int rc;

	rc = gl_link_xfer(l, &l->cmd, &x, l->timeout_ms, &r);
	if (rc < 0)
		return rc;
	if (r.n_err || !gl_parse_double(r.text, r.text_len, &ep, &code) ||
	    code < 0 || code > 255) {
		l->cmd.broken = true;
		return GL_ERR_PROTO;
	}
	while (*ep == ' ')
		ep++;
	n = strlen(ep);
	if (n >= sizeof(l->ctrl_text))
		n = sizeof(l->ctrl_text) - 1;
	memcpy(l->ctrl_text, ep, n);
	l->ctrl_text[n] = '\0';
	l->ctrl_code = (int)code;
	return GL_ERR_CTRL;
}

void gl_link_ctrl_clear(gl_link *l)
{
	l->ctrl_code = 0;
	l->ctrl_text[0] = '\0';
}

/* Copy reply text out; GL_ERR_OVERFLOW when it does not fit. */
int gl_link_text_out(const struct gl_reply *r, char *resp, size_t cap)
{
	size_t n = r->text_len;

	if (!resp || cap == 0)
		return r->truncated ? GL_ERR_OVERFLOW : (int)n;
	if (n >= cap)
		n = cap - 1;
	memcpy(resp, r->text, n);
	resp[n] = '\0';
	return (n < r->text_len || r->truncated) ? GL_ERR_OVERFLOW
						 : (int)r->text_len;
}

/* Send an already checked line of @n commands on the command handle. */
static int command_n(gl_link *l, const char *cmd, size_t len, int n, char *resp,
		     size_t cap, int timeout_ms)
{
	struct gl_xfer x = {.line = cmd, .len = len, .n_term = n};
	struct gl_reply r;
	int rc;

	rc = gl_link_xfer(l, &l->cmd, &x, timeout_ms, &r);
	if (rc < 0)
		return rc;
	if (r.n_err)
		return gl_link_fetch_tc1(l);
	return gl_link_text_out(&r, resp, cap);
}

int gl_link_command(gl_link *l, const char *cmd, char *resp, size_t cap,
		    int timeout_ms)
{
	int n, t;

	if (!l || !cmd)
		return GL_ERR_ARG;
	gl_link_ctrl_clear(l);
	n = gl_link_count_commands(cmd, strlen(cmd));
	t = gl_link_pick_timeout(l, timeout_ms);
	if (n < 0 || t < 0)
		return GL_ERR_ARG;
	return command_n(l, cmd, strlen(cmd), n, resp, cap, t);
}

void gl_link_trim(const char **s, size_t *len)
{
	while (*len > 0 && (**s == ' ' || **s == '\t')) {
		(*s)++;
		(*len)--;
	}
	while (*len > 0 && ((*s)[*len - 1] == ' ' || (*s)[*len - 1] == '\t'))
		(*len)--;
}
