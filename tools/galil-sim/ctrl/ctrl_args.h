/*
 * ctrl_args.h - the arguments of commands and the numbers they print
 * (ctrl_args.c); internal to the simulated controller (ctrl/), not part of
 * its API (ctrl.h).
 * It runs no command (ctrl_cmd.h).
 */
#ifndef SIM_CTRL_ARGS_H
#define SIM_CTRL_ARGS_H

#include "ctrl_int.h"

/* Arguments "n,n,n" with '?' queries and the "X=n" single axis forms. */
struct ctrl_args {
	int n;		    /* fields present (0..CTRL_AXES) */
	int set[CTRL_AXES]; /* 1 value, 2 query, 0 empty */
	double v[CTRL_AXES];
};
/*
 * ctrl_parse_axis_args() - @a as "n,n,n" (expressions; empty fields skip
 * an axis, '?' asks) or "A=n", "~a=n", "*=n", "A=?" into @out.
 * Return: 0, or a TC code (6: more fields than axes, 1: syntax, or the
 * expression's).
 */
int ctrl_parse_axis_args(struct ctrl_xc *x, const char *a,
			 struct ctrl_args *out);
/*
 * ctrl_parse_mask() - @a as axes "ABC", "B", "~a~b", or "" (all axes) into
 * @mask, bit i = axis i. Return: 0 or the TC code of ctrl_axis_desig().
 */
int ctrl_parse_mask(struct ctrl_xc *x, const char *a, unsigned *mask);
/*
 * ctrl_num_list() - up to @max comma-separated expressions of @a into
 * @v[]; absent fields keep their value. @present: [out] optional, bit i
 * set when field i was given. Return: 0, TC 4 (more than @max fields),
 * TC 1 (syntax) or the expression's TC.
 */
int ctrl_num_list(struct ctrl_xc *x, const char *a, double *v, int max,
		  unsigned *present);
/*
 * ctrl_put_num() - @v appended to the statement's output (c->tmp) in format
 * @how (CTRL_NUM_*). Return: 0, or 1 when it cannot be formatted or stored.
 */
int ctrl_put_num(struct ctrl_xc *x, double v, int how);

#endif /* SIM_CTRL_ARGS_H */
