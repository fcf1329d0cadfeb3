/*
 * ctrl_flow.h - program flow and trippoint commands (ctrl_flow.c); internal
 * to the simulated controller (ctrl/), not part of its API (ctrl.h).
 * It does not schedule threads (ctrl_exec.h).
 */
#ifndef SIM_CTRL_FLOW_H
#define SIM_CTRL_FLOW_H

#include "ctrl_int.h"

/*
 * ctrl_flow_cmd() - the flow and trippoint commands @name (IF ELSE ENDIF
 * JP JS EN RE RI ZS XQ HX WT AT AM MC MF MR AI) with argument text @a.
 * Return: 0 or a TC code.
 */
int ctrl_flow_cmd(struct ctrl_xc *x, const char *name, const char *a);
/*
 * ctrl_wait_done() - 1 when the trippoint of thread @t is satisfied (and
 * then cleared), else 0; an MC past its TW sets stop code 99 and raises
 * #MCTIME.
 */
int ctrl_wait_done(struct ctrl *c, struct ctrl_thread *t);
/*
 * ctrl_goto_line() - continue the running thread at program line @line
 * (0-based). Return: 0, or TC 11 (not a line of the program).
 */
int ctrl_goto_line(struct ctrl_xc *x, double line);
/* ctrl_samples() - servo samples in @ms milliseconds at the current TM,
 * rounded to nearest. */
int ctrl_samples(const struct ctrl *c, double ms);

#endif /* SIM_CTRL_FLOW_H */
