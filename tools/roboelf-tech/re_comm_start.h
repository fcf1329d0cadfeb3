/*
 * re_comm_start.h - the controller for the commissioning run (roboelf-tech
 * commission): the start-up's bring-up (re_start_bringup()), with the
 * discovery probe offered when the configured address does not answer,
 * then the controller halted, every motor read back off, configured and
 * read back; the relay open and off. Its program is not checked
 * (commissioning may come before the first galil-load).
 */
#ifndef RE_COMM_START_H
#define RE_COMM_START_H

#include "re_start.h"

/*
 * re_comm_start() - the above for @a (configuration and log loaded);
 * the discovery probe to @find_addr:@find_port (NULL, 0: the broadcast
 * address and Galil's port).
 * Return: 0, or EXIT_CONNECT (said on the console and in the log; also
 * when a quit signal ended the bring-up early).
 */
int re_comm_start(struct app *a, const char *find_addr, int find_port);

#endif /* RE_COMM_START_H */
