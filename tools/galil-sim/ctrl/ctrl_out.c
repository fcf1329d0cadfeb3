/*
 * ctrl_out.c - what leaves the interpreter besides command replies: events
 * (struct ctrl_cfg.event), bytes queued for a host handle, and unsolicited
 * output routed by CF/CW.
 *
 * It is not the host protocol (framing, DL, handle life: ctrl_proto.c) and
 * formats nothing but the event line; it only queues bytes.
 */
#include <stdarg.h>
#include <stdio.h>

#include "ctrl_out.h"
#include "ctrl_buf.h"

void ctrl_event(struct ctrl *c, const char *fmt, ...)
{
	char line[200];
	va_list ap;

	if (!c->cfg.event)
		return;
	va_start(ap, fmt);
	vsnprintf(line, sizeof(line), fmt, ap);
	va_end(ap);
	c->cfg.event(c->cfg.event_ud, line);
}

void ctrl_out_put(struct ctrl *c, int h, const void *p, size_t n)
{
	struct ctrl_handle *hd = &c->h[h];

	if (ctrl_buf_pending(&hd->out) + n > CTRL_OUT_MAX) {
		ctrl_event(c, "handle %c output overflow, %zu bytes dropped",
			   'A' + h, n);
		return;
	}
	ctrl_buf_put(&hd->out, p, n);
}

/*
 * ctrl_unsol_send() - unsolicited bytes to @route (CTRL_ROUTE_DEFAULT: CF).
 * Return: 0 (sent or dropped), -1 when the FIFO is full and CW ,0 asks the
 * thread to wait.
 */
int ctrl_unsol_send(struct ctrl *c, int route, const uint8_t *p, size_t n)
{
	int h = route == CTRL_ROUTE_DEFAULT ? c->cf : route;
	uint8_t tmp[256];
	size_t k, i;

	if (h == CTRL_SERIAL || h < 0) {
		if (ctrl_buf_pending(&c->serial) + n > CTRL_SERIAL_MAX)
			ctrl_buf_clear(&c->serial);
		ctrl_buf_put(&c->serial, p, n);
		return 0;
	}
	if (!c->h[h].open)
		return 0; /* nobody there: dropped */
	if (ctrl_buf_pending(&c->h[h].out) + n > CTRL_UNSOL_FIFO)
		return c->cw_drop ? 0 : -1;
	for (k = 0; k < n; k += i) {
		for (i = 0; i < sizeof(tmp) && k + i < n; i++)
			tmp[i] =
			    c->cw_hibit ? (uint8_t)(p[k + i] | 0x80) : p[k + i];
		ctrl_out_put(c, h, tmp, i);
	}
	return 0;
}
