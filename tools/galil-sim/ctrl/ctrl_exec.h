/*
 * ctrl_exec.h - one statement, and the line scheduler of the threads
 * (ctrl_exec.c); internal to the simulated controller (ctrl/), not part of
 * its API (ctrl.h).
 * It does not frame host input (ctrl_proto.h).
 */
#ifndef SIM_CTRL_EXEC_H
#define SIM_CTRL_EXEC_H

#include "ctrl_int.h"

/*
 * ctrl_exec() - run one statement @s (no ';') in the context @x; output
 * goes to c->tmp. Return: 0, a TC code, CTRL_RETRY or CTRL_STOP.
 */
int ctrl_exec(struct ctrl_xc *x, const char *s);
/*
 * ctrl_threads_run() - the program part of one servo sample: the running
 * threads get program lines round robin, c->lines_per_sample in all;
 * automatic subroutines are entered, run-time errors handled.
 */
void ctrl_threads_run(struct ctrl *c);

#endif /* SIM_CTRL_EXEC_H */
