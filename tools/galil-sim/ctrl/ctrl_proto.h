/*
 * ctrl_proto.h - the host side of the Ethernet handles: framing, DL/UL
 * (ctrl_proto.c); internal to the simulated controller (ctrl/), not part of
 * its API (ctrl.h).
 * It knows nothing about sockets (net/).
 */
#ifndef SIM_CTRL_PROTO_H
#define SIM_CTRL_PROTO_H

#include "ctrl_int.h"

/*
 * ctrl_proto_reset() - power cycle: every open host handle is to be
 * closed, all host and serial output and downloads are dropped.
 */
void ctrl_proto_reset(struct ctrl *c);
/*
 * ctrl_proto_host() - a complete command line @line (no CR) from handle
 * @h (0..8): run its commands and queue their replies.
 * Return: the number of commands that answered '?'.
 */
int ctrl_proto_host(struct ctrl *c, int h, const char *line);

#endif /* SIM_CTRL_PROTO_H */
