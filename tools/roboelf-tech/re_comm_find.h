/*
 * re_comm_find.h - finding the controller for the commissioning run: when
 * the configured address does not answer, the Galil controllers that answer
 * the discovery probe (pc/galil/gl_disc.h, the mechanism and its sources
 * in docs/galil-load.md) are listed for the technician to pick one.
 *
 * Only the commissioning run uses this (roboelf-tech commission, on the
 * technician's choice, never silently); roboelf's operation connects only
 * to its configured address (tests/checks/nodisc.sh). Nothing here prints.
 */
#ifndef RE_COMM_FIND_H
#define RE_COMM_FIND_H

#include <stddef.h>

#define RE_COMM_FIND_BCAST "255.255.255.255"
#define RE_COMM_FIND_PORT  50000 /* gl_disc.h: GL_DISC_PORT */
#define RE_COMM_FIND_MS	   1000
#define RE_COMM_FIND_MAX   16

/* One controller that answered: its address and what it says it is. */
struct re_comm_found {
	char addr[48]; /* e.g. "192.168.1.40" */
	char what[80]; /* e.g. "DMC4030 Rev 1.2h" */
};

/*
 * re_comm_find() - send the discovery probe to @bcast:@port and collect
 * the answers for @window_ms (a deadline).
 * @list: [out] up to @max controllers, in the order they answered.
 * @err: [out] the reason on an error (@errlen bytes).
 * Return: the number found (>= 0), or GL_ERR_ARG / GL_ERR_SYS.
 */
int re_comm_find(const char *bcast, unsigned port, int window_ms,
		 struct re_comm_found *list, int max, char *err, size_t errlen);

#endif /* RE_COMM_FIND_H */
