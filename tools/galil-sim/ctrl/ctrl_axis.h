/*
 * ctrl_axis.h - axis letters and designators, the axis parameter table, the
 * _XXa operands (ctrl_axis.c); internal to the simulated controller (ctrl/),
 * not part of its API (ctrl.h).
 * It changes no axis (ctrl_axcmd.h, ctrl_motion.h).
 */
#ifndef SIM_CTRL_AXIS_H
#define SIM_CTRL_AXIS_H

#include "ctrl_int.h"

/* ctrl_axis_letter() - axis index of A..H (X Y Z W = A B C D), or -1. */
int ctrl_axis_letter(char ch);
/*
 * ctrl_axis_desig() - one axis at *p: a letter or ~a..~h; *p moves past it
 * and @axis gets 0..CTRL_AXES-1.
 * Return: 0, TC 1 (not an axis), TC 6 (axis not on a DMC-4030).
 */
int ctrl_axis_desig(struct ctrl_xc *x, const char **p, int *axis);

/* One real-valued axis parameter (SP AC DC SD KP KI KD TL IL OF OV ER FL
 * BL TW): its range and resolution. */
struct ctrl_par_desc {
	char name[3];
	double lo, hi;
	double step;   /* resolution: values are cut to it (to zero) */
	int fmt;       /* CTRL_NUM_* for queries */
	int in_motion; /* may change while the axis profiles */
};

/* One integer axis parameter (LD OA OE OT): its range. */
struct ctrl_ipar_desc {
	char name[3];
	int lo, hi;
};

/*
 * ctrl_par_find() / ctrl_ipar_find() - the table entry of parameter @name
 * ("SP", "OE" ...), static; NULL when @name is not one.
 */
const struct ctrl_par_desc *ctrl_par_find(const char *name);
const struct ctrl_ipar_desc *ctrl_ipar_find(const char *name);
/*
 * ctrl_par_ptr() / ctrl_ipar_ptr() - where parameter @d is kept in @p
 * (units of struct ctrl_axis_par); never NULL for a table entry.
 */
double *ctrl_par_ptr(struct ctrl_axis_par *p, const struct ctrl_par_desc *d);
int *ctrl_ipar_ptr(struct ctrl_axis_par *p, const struct ctrl_ipar_desc *d);
/*
 * ctrl_axis_home() - _HM of axis @i (0..CTRL_AXES-1): the home input of the
 * last sample read through CN n1 (-1: 1 = pulled up, 0 = grounded).
 */
int ctrl_axis_home(const struct ctrl *c, int i);
/*
 * ctrl_axis_operand() - _XXa of axis @axis (0..CTRL_AXES-1): state (TP RP
 * TE TD TV TT TS SC MO BG LF LR HM MT PA PR JG PT DP ZA; counts, counts/s,
 * volts) or a parameter, into @v. Return: 0, or TC 1 (no such operand).
 */
int ctrl_axis_operand(struct ctrl *c, const char *name, int axis, double *v);

#endif /* SIM_CTRL_AXIS_H */
