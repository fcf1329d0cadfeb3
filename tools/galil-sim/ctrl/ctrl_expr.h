/*
 * ctrl_expr.h - DMC expressions, evaluated strictly left to right
 * (ctrl_expr.c); internal to the simulated controller (ctrl/), not part of
 * its API (ctrl.h).
 * It runs no command (ctrl_cmd.h).
 */
#ifndef SIM_CTRL_EXPR_H
#define SIM_CTRL_EXPR_H

#include "ctrl_int.h"

/*
 * ctrl_expr() - evaluate the expression at *p into @out, strictly left to
 * right; stops at the first character that is not an operator (',', ')',
 * ']', '{', end ...). Return: 0 or a TC code; *p is advanced only on
 * success.
 */
int ctrl_expr(struct ctrl_xc *x, const char **p, double *out);
/*
 * ctrl_expr_end() - the whole of @s is one expression, into @out.
 * Return: 0, TC 59 (a ')' too many), TC 1 (text after it) or the TC of
 * ctrl_expr().
 */
int ctrl_expr_end(struct ctrl_xc *x, const char *s, double *out);
/* ctrl_skip() - @s past spaces and tabs. */
const char *ctrl_skip(const char *s);
/*
 * ctrl_param_ptr() - where ^a..^h (@i 0..7) of the running thread is kept
 * (its frame, or the variable passed by &ref), owned by the controller;
 * NULL from a host or for a bad @i.
 */
double *ctrl_param_ptr(struct ctrl_xc *x, int i);

#endif /* SIM_CTRL_EXPR_H */
