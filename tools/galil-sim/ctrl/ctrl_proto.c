/*
 * ctrl_proto.c - the host side of the 8 Ethernet handles (and the private
 * port of ctrl_command()).
 *
 * Command mode: bytes collect into a line until CR (LF is ignored); the
 * line is split at ';' (outside "strings") and each command answers its
 * data followed by ':', or '?' alone (TC set). A line longer than 80
 * characters is refused whole: one '?' per command on it, TC 5. The bytes
 * 0x12 0x16 (^R^V) answer the model text.
 *
 * Download mode (after DL): silent while lines arrive; a line over 80
 * characters or line 4001 answers '?' at once (TC 60). '\' or ^Z (also ^Q,
 * ^D) ends the download: ':' for the terminator, then ':' when the program
 * was stored, '?' when it was refused (TC 60/61/62; program memory erased).
 *
 * Unsolicited output (program MG, run-time errors, TP in a program ...)
 * goes to the CF handle, or to the serial port (kept, never sent). With
 * CW 1 each unsolicited byte has its high bit set. More than
 * CTRL_UNSOL_FIFO bytes waiting on the handle is a full FIFO: the thread
 * waits (CW ,0, the default) or the message is dropped (CW ,1).
 */
#include <stdio.h>
#include <string.h>

#include "ctrl_proto.h"
#include "ctrl_buf.h"
#include "ctrl_exec.h"
#include "ctrl_out.h"
#include "ctrl_store.h"
#include "ctrl_stream.h"
#include "ctrl_thread.h"
#include "gl_err.h"

static int valid_handle(int h)
{
	return h >= 0 && h < CTRL_NHANDLES;
}

void ctrl_handle_open(struct ctrl *c, int h)
{
	struct ctrl_handle *hd;

	if (!valid_handle(h))
		return;
	hd = &c->h[h];
	ctrl_buf_clear(&hd->out);
	ctrl_buf_clear(&hd->dl);
	hd->open = 1;
	hd->udp = 0;
	hd->close_wanted = 0;
	hd->close_by = -1;
	hd->close_why[0] = '\0';
	hd->mode = CTRL_H_CMD;
	hd->len = 0;
	hd->overflow = 0;
	hd->semis = 0;
}

void ctrl_handle_open_udp(struct ctrl *c, int h)
{
	if (!c || h < 0 || h >= CTRL_HANDLES)
		return;
	ctrl_handle_open(c, h);
	c->h[h].udp = 1;
}

void ctrl_handle_close(struct ctrl *c, int h)
{
	struct ctrl_handle *hd;

	if (!valid_handle(h))
		return;
	hd = &c->h[h];
	if (hd->mode == CTRL_H_DL)
		ctrl_event(c, "download on handle %c abandoned", 'A' + h);
	if (hd->open && hd->close_wanted && hd->close_why[0])
		ctrl_event(c, "handle %c closed by %s", 'A' + h, hd->close_why);
	ctrl_stream_handle_closed(c, h);
	hd->open = 0;
	hd->udp = 0;
	hd->close_wanted = 0;
	hd->close_by = -1;
	hd->close_why[0] = '\0';
	hd->mode = CTRL_H_CMD;
	hd->len = 0;
	ctrl_buf_clear(&hd->out);
	ctrl_buf_clear(&hd->dl);
	hd->peer_ip = 0;
	hd->peer_port = 0;
}

/* ctrl_handle_lost() - TCP error on @h: #TCPERR, _IA4 = h, TC 123. */
void ctrl_handle_lost(struct ctrl *c, int h)
{
	if (h < 0 || h >= CTRL_HANDLES)
		return;
	ctrl_handle_close(c, h);
	c->ia4 = h;
	c->tc = 123;
	ctrl_event(c, "handle %c lost (TC 123)", 'A' + h);
	ctrl_autosub_raise(c, CTRL_AS_TCPERR);
}

int ctrl_handle_close_wanted(const struct ctrl *c, int h)
{
	return valid_handle(h) && c->h[h].open && c->h[h].close_wanted;
}

int ctrl_handle_close_by(const struct ctrl *c, int h)
{
	return ctrl_handle_close_wanted(c, h) ? c->h[h].close_by : -1;
}

void ctrl_handle_peer(struct ctrl *c, int h, int local_port, uint32_t peer_ip,
		      int peer_port)
{
	if (h < 0 || h >= CTRL_HANDLES)
		return;
	c->h[h].local_port = local_port;
	c->h[h].peer_ip = peer_ip;
	c->h[h].peer_port = peer_port;
}

/* ---- commands from a host ---------------------------------------------- */

/* One command from a host. Return 1 when DL switched to download mode. */
static int host_cmd(struct ctrl *c, int h, const char *s, int *errors)
{
	struct ctrl_xc x = {c, -1, h, -1, CTRL_ROUTE_DEFAULT, 0, 0};
	int rc;

	ctrl_buf_clear(&c->tmp);
	rc = ctrl_exec(&x, s);
	if (rc > 0 || rc == CTRL_RETRY) {
		c->tc = rc > 0 ? rc : 1;
		(*errors)++;
		ctrl_out_put(c, h, "?", 1);
		return 0;
	}
	if (x.dl) {
		c->h[h].mode = CTRL_H_DL;
		c->h[h].dl_err = 0;
		c->h[h].dl_lines = 0;
		c->h[h].dl_linelen = 0;
		ctrl_buf_clear(&c->h[h].dl);
		return 1;
	}
	if (x.route != CTRL_ROUTE_DEFAULT)
		ctrl_unsol_send(c, x.route, ctrl_buf_data(&c->tmp),
				ctrl_buf_pending(&c->tmp));
	else
		ctrl_out_put(c, h, ctrl_buf_data(&c->tmp),
			     ctrl_buf_pending(&c->tmp));
	ctrl_out_put(c, h, ":", 1);
	return 0;
}

/* Split at ';' outside quotes; stops after a DL. Return the errors. */
static int host_line(struct ctrl *c, int h, char *line)
{
	char *s = line, *e;
	int quote, errors = 0;

	for (;;) {
		for (e = s, quote = 0; *e && (quote || *e != ';'); e++)
			if (*e == '"')
				quote = !quote;
		if (*e) {
			*e = '\0';
			if (host_cmd(c, h, s, &errors))
				return errors;
			s = e + 1;
			continue;
		}
		host_cmd(c, h, s, &errors);
		return errors;
	}
}

/* ctrl_proto_host() - a complete command line from handle @h. */
int ctrl_proto_host(struct ctrl *c, int h, const char *text)
{
	struct ctrl_handle *hd = &c->h[h];
	char line[CTRL_LINE_MAX + 1];
	int i, n;

	ctrl_thread_boot(c);
	if (hd->overflow) {
		hd->overflow = 0;
		c->tc = 5;
		for (i = 0; i <= hd->semis; i++)
			ctrl_out_put(c, h, "?", 1);
		return hd->semis + 1;
	}
	if (text[0] == 0x12) {
		if (text[1] != 0x16 || text[2] != '\0') {
			c->tc = 1;
			ctrl_out_put(c, h, "?", 1);
			return 1;
		}
		n = snprintf(line, sizeof(line), "%s\r\n:", c->model);
		ctrl_out_put(c, h, line, (size_t)n);
		return 0;
	}
	snprintf(line, sizeof(line), "%s", text);
	return host_line(c, h, line);
}

/* ---- download ------------------------------------------------------------ */

static void dl_bad_line(struct ctrl *c, int h, int tc)
{
	struct ctrl_handle *hd = &c->h[h];

	if (!hd->dl_err)
		hd->dl_err = tc;
	c->tc = tc;
	ctrl_out_put(c, h, "?", 1);
}

static void dl_end_line(struct ctrl *c, int h)
{
	struct ctrl_handle *hd = &c->h[h];

	if (hd->dl_lines <= CTRL_PROG_LINES)
		hd->dl_lines++;
	if (hd->dl_linelen > CTRL_LINE_MAX || hd->dl_lines > CTRL_PROG_LINES)
		dl_bad_line(c, h, 60);
	hd->dl_linelen = 0;
	if (hd->dl_lines <= CTRL_PROG_LINES)
		ctrl_buf_put(&hd->dl, "\r", 1);
}

static void dl_finish(struct ctrl *c, int h)
{
	struct ctrl_handle *hd = &c->h[h];
	int bad_line = 0, rc;

	if (hd->dl_linelen > 0)
		dl_end_line(c, h);
	hd->mode = CTRL_H_CMD;
	ctrl_out_put(c, h, ":", 1);
	if (hd->dl_err) {
		rc = ctrl_load_program(c, "", 0, &bad_line);
		ctrl_event(c, "download refused: TC %d (program erased)",
			   hd->dl_err);
		c->tc = hd->dl_err;
		ctrl_out_put(c, h, "?", 1);
	} else {
		rc = ctrl_load_program(c, (const char *)ctrl_buf_data(&hd->dl),
				       ctrl_buf_pending(&hd->dl), &bad_line);
		ctrl_out_put(c, h, rc ? "?" : ":", 1);
	}
	ctrl_buf_clear(&hd->dl);
}

static int is_dl_end(uint8_t b)
{
	return b == '\\' || b == 0x1a || b == 0x11 || b == 0x04;
}

static void dl_byte(struct ctrl *c, int h, uint8_t b)
{
	struct ctrl_handle *hd = &c->h[h];

	if (is_dl_end(b)) {
		dl_finish(c, h);
	} else if (b == '\r') {
		dl_end_line(c, h);
	} else if (b != '\n') {
		hd->dl_linelen++;
		/* bounded: a refused download need not be kept whole */
		if (hd->dl_linelen <= CTRL_LINE_MAX + 1 &&
		    hd->dl_lines <= CTRL_PROG_LINES)
			ctrl_buf_put(&hd->dl, &b, 1);
	}
}

static void cmd_byte(struct ctrl *c, int h, uint8_t b)
{
	struct ctrl_handle *hd = &c->h[h];

	if (b == '\r') {
		hd->line[hd->len] = '\0';
		ctrl_proto_host(c, h, hd->line);
		hd->len = 0;
		hd->semis = 0;
		return;
	}
	if (b == '\n')
		return;
	if (b == ';' && hd->semis < 100000)
		hd->semis++;
	if (hd->len >= CTRL_LINE_MAX || b == '\0')
		hd->overflow = 1;
	else
		hd->line[hd->len++] = (char)b;
}

/*
 * ctrl_input() - bytes from the host on handle @h (a closed handle is
 * opened). Return: 0, or GL_ERR_ARG for a bad handle.
 */
int ctrl_input(struct ctrl *c, int h, const uint8_t *buf, size_t len)
{
	size_t i;

	if (!c || !valid_handle(h) || (!buf && len))
		return GL_ERR_ARG;
	if (!c->h[h].open)
		ctrl_handle_open(c, h);
	ctrl_thread_boot(c);
	for (i = 0; i < len; i++) {
		if (c->h[h].mode == CTRL_H_DL)
			dl_byte(c, h, buf[i]);
		else
			cmd_byte(c, h, buf[i]);
	}
	return GL_OK;
}

size_t ctrl_output(struct ctrl *c, int h, uint8_t *buf, size_t cap)
{
	if (!c || !valid_handle(h) || !buf)
		return 0;
	return ctrl_buf_take(&c->h[h].out, buf, cap);
}

size_t ctrl_output_pending(const struct ctrl *c, int h)
{
	if (!c || !valid_handle(h))
		return 0;
	return ctrl_buf_pending(&c->h[h].out);
}

/* ctrl_serial_output() - what was routed to the (absent) serial port. */
size_t ctrl_serial_output(struct ctrl *c, uint8_t *buf, size_t cap)
{
	if (!c || !buf)
		return 0;
	return ctrl_buf_take(&c->serial, buf, cap);
}

/* ctrl_proto_reset() - power cycle: every connection is dropped. */
void ctrl_proto_reset(struct ctrl *c)
{
	int h;

	for (h = 0; h < CTRL_NHANDLES; h++) {
		struct ctrl_handle *hd = &c->h[h];

		hd->mode = CTRL_H_CMD;
		hd->len = 0;
		hd->overflow = 0;
		ctrl_buf_clear(&hd->dl);
		ctrl_buf_clear(&hd->out);
		if (hd->open && h < CTRL_HANDLES) {
			hd->close_wanted = 1;
			hd->close_by = -1;
			snprintf(hd->close_why, sizeof(hd->close_why),
				 "power cycle");
		}
	}
	ctrl_buf_clear(&c->serial);
	ctrl_stream_reset(c);
}
