/*
 * ctrl_mg.h - the MG command and its formatters (ctrl_mg.c); internal to the
 * simulated controller (ctrl/), not part of its API (ctrl.h).
 * It does not route the output (ctrl_out.h).
 */
#ifndef SIM_CTRL_MG_H
#define SIM_CTRL_MG_H

#include "ctrl_int.h"

/*
 * ctrl_mg() - MG with argument text @a: the message formatted into the
 * statement output. Return: 0 or a TC code.
 */
int ctrl_mg(struct ctrl_xc *x, const char *a);

#endif /* SIM_CTRL_MG_H */
