/*
 * gload_cmd.c - galil-load's -c commands: the checks of a command given,
 * the guard for writes to a running RoboELF program, the sending
 * (gload_cmd.h).
 */
#include <string.h>

#include "dmc_cmd.h"
#include "gl_link.h"
#include "gl_proto.h"
#include "gload_cmd.h"
#include "gload_dl.h"

const char *gload_cmd_shown(const char *c, char out[GLOAD_SHOWN_LEN])
{
	size_t o = 0;

	for (; *c && o < 2 * GL_LINE_MAX + 4; c++) {
		unsigned char b = (unsigned char)*c;

		if (b < 0x20 || b == 0x7f) {
			out[o++] = '^';
			out[o++] = (char)(b ^ 0x40);
		} else {
			out[o++] = (char)b;
		}
	}
	out[o] = '\0';
	return out;
}

/* A control-character request: ^R^V, or ^L^K ? (the lock state); the
 * others change the controller (command reference ^R^S, ^L^K). */
static int check_ctrl_request(const char *cmd, enum gl_ctrl_kind k,
			      gload_usage_fn *usage)
{
	char sh[GLOAD_SHOWN_LEN];
	const char *a = cmd + 2;

	while (*a == ' ')
		a++;
	if (k == GL_CTRL_REVISION || (k == GL_CTRL_LOCK && !strcmp(a, "?")))
		return 0;
	if (k == GL_CTRL_RESET)
		return usage("'^R^S' (master reset: erases the "
			     "controller's EEPROM and its IP address) "
			     "is not sent by galil-load");
	if (k == GL_CTRL_LOCK)
		return usage("'%s': only '^L^K ?' (is the program "
			     "locked?) may be sent with -c",
			     gload_cmd_shown(cmd, sh));
	return usage("'%s' holds a control character: only the "
		     "requests ^R^V and '^L^K ?' may be sent with -c",
		     gload_cmd_shown(cmd, sh));
}

int gload_cmd_check(const char *cmd, gload_usage_fn *usage)
{
	static const char *const refused[] = {"DL", "UL", "ED",
					      "QD", "QU", "QR"};
	enum gl_ctrl_kind k = gl_link_ctrl_kind(cmd);
	size_t i;

	if (k != GL_CTRL_NONE)
		return check_ctrl_request(cmd, k, usage);
	if (strlen(cmd) == 0 || strlen(cmd) > GL_LINE_MAX)
		return usage("command '%s' is empty or longer than 80 "
			     "characters",
			     cmd);
	if (strchr(cmd, '\r') || strchr(cmd, '\n'))
		return usage("command '%s' holds a line end", cmd);
	for (i = 0; i < sizeof(refused) / sizeof(refused[0]); i++)
		if (!strncmp(cmd, refused[i], 2))
			return usage("'%s' cannot be sent with -c "
				     "(give program files to download)",
				     cmd);
	return 0;
}

int gload_cmd_timeout(const char *c, int timeout_ms)
{
	/* burns and BZ pause the controller [galil-notes 1.6] */
	int tmo = (c[0] == 'B' && c[1] && strchr("PNVZ", c[1]))
		      ? GLOAD_SLOW_TIMEOUT_MS
		      : timeout_ms;

	if (tmo < timeout_ms)
		tmo = timeout_ms;
	return tmo;
}

/* The RoboELF program's state: 1 armed or 3 service while it runs, else
 * -1 (no program, halted, or not ours: no "state" variable). */
static int running_state(gl_link *l, int timeout_ms)
{
	char resp[64];
	double v;
	int rc = gl_link_command(l, "MG _XQ0", resp, sizeof(resp), timeout_ms);

	if (rc < 0 || !gl_parse_double(resp, (size_t)rc, NULL, &v) || v < 0)
		return -1;
	rc = gl_link_command(l, "MG state", resp, sizeof(resp), timeout_ms);
	if (rc < 0 || !gl_parse_double(resp, (size_t)rc, NULL, &v))
		return -1;
	return v == 1 || v == 3 ? (int)v : -1;
}

int gload_cmd_write_state(gl_link *l, const char *c, int timeout_ms)
{
	if (dmc_cmd_line_is_read(c))
		return -1;
	return running_state(l, timeout_ms);
}

int gload_cmd_send(gl_link *l, const char *c, char *resp, size_t cap,
		   int timeout_ms)
{
	if (gl_link_ctrl_kind(c) > GL_CTRL_NONE)
		return gl_link_ctrl_request(l, c, resp, cap, timeout_ms);
	return gl_link_command(l, c, resp, cap, timeout_ms);
}
