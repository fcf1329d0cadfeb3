/*
 * ctrl_out.h - events, host output queues and unsolicited output (CF/CW)
 * (ctrl_out.c); internal to the simulated controller (ctrl/), not part of
 * its API (ctrl.h).
 * It is not the host protocol (ctrl_proto.h).
 */
#ifndef SIM_CTRL_OUT_H
#define SIM_CTRL_OUT_H

#include "ctrl_int.h"

/*
 * ctrl_event() - format one event line (printf style, no CR LF, cut to 199
 * characters) and hand it to cfg.event; nothing when cfg.event is NULL.
 */
void ctrl_event(struct ctrl *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/*
 * ctrl_out_put() - queue @n bytes of @p for host handle @h (0..8, not
 * checked). Past CTRL_OUT_MAX bytes pending the bytes are dropped, with an
 * event. The bytes are copied; @p stays the caller's.
 */
void ctrl_out_put(struct ctrl *c, int h, const void *p, size_t n);
/*
 * ctrl_unsol_send() - unsolicited bytes to @route (a handle 0..7,
 * CTRL_SERIAL, or CTRL_ROUTE_DEFAULT: the CF handle); high bit set under
 * CW 1; a closed handle drops them. @p is copied.
 * Return: 0 (sent or dropped), -1 when the FIFO is full and CW ,0 asks the
 * thread to wait.
 */
int ctrl_unsol_send(struct ctrl *c, int route, const uint8_t *p, size_t n);

#endif /* SIM_CTRL_OUT_H */
