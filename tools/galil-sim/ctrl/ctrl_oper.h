/*
 * ctrl_oper.h - the _operands of expressions (ctrl_oper.c); internal to the
 * simulated controller (ctrl/), not part of its API (ctrl.h).
 * It does not evaluate expressions (ctrl_expr.h).
 */
#ifndef SIM_CTRL_OPER_H
#define SIM_CTRL_OPER_H

#include "ctrl_int.h"

/*
 * ctrl_operand() - the _operand at *p ('_' included) into @out, on the
 * 32.16 grid. Return: 0 or a TC code (1: unknown); *p is advanced only on
 * success.
 */
int ctrl_operand(struct ctrl_xc *x, const char **p, double *out);

#endif /* SIM_CTRL_OPER_H */
