/*
 * ctrl_axis.c - an axis as the language names and reads it: axis letters
 * and designators (A..H, X Y Z W, ~a..~h), the table of axis parameters
 * (SP AC DC ... TW, LD OA OE OT: ranges, resolutions, formats) and the
 * _XXa operands that read an axis's parameters and state.
 *
 * It does not change an axis (the axis commands, ctrl_axcmd.c) nor move
 * one (ctrl_motion.c).
 */
#include <math.h>
#include <string.h>

#include "ctrl_axis.h"
#include "ctrl_motion.h"

/* ctrl_axis_letter() - axis index of A..H (X Y Z W = A B C D), or -1. */
int ctrl_axis_letter(char ch)
{
	static const char xyzw[] = "XYZW";
	const char *q;

	if (ch >= 'A' && ch <= 'H')
		return ch - 'A';
	q = ch ? strchr(xyzw, ch) : NULL;
	return q ? (int)(q - xyzw) : -1;
}

/*
 * ctrl_axis_desig() - one axis at *p: a letter or ~a..~h.
 * Return: 0, TC 1 (not an axis), TC 6 (axis not on a DMC-4030).
 */
int ctrl_axis_desig(struct ctrl_xc *x, const char **p, int *axis)
{
	const char *s = *p;
	int a;

	if (*s == '~') {
		if (s[1] < 'a' || s[1] > 'h')
			return 1;
		a = (int)x->c->axdes[s[1] - 'a'];
		s += 2;
	} else {
		a = ctrl_axis_letter(*s);
		if (a < 0)
			return 1;
		s++;
	}
	if (a < 0 || a >= CTRL_AXES)
		return 6;
	*axis = a;
	*p = s;
	return 0;
}

/* ---- the parameter table ------------------------------------------------ */

static const struct ctrl_par_desc par_table[] = {
    {"AC", 1024, 1073740800, 1024, CTRL_NUM_INT, 1},
    {"BL", -2147483648.0, 2147483647, 1, CTRL_NUM_PF, 1},
    {"DC", 1024, 1073740800, 1024, CTRL_NUM_INT, 0},
    {"ER", -1, 2147483647, 1, CTRL_NUM_INT, 1},
    {"FL", -2147483648.0, 2147483647, 1, CTRL_NUM_PF, 1},
    {"IL", -9.9982, 9.9982, 0, CTRL_NUM_GAIN, 1},
    {"KD", 0, 4095.875, 0.125, CTRL_NUM_GAIN, 1},
    {"KI", 0, 255.999, 0, CTRL_NUM_GAIN, 1},
    {"KP", 0, 1023.875, 0.125, CTRL_NUM_GAIN, 1},
    {"MT", -2.5, 2.5, 0.5, CTRL_NUM_PF, 0},
    {"OF", -9.9982, 9.9982, 0, CTRL_NUM_GAIN, 1},
    {"OV", 0, 9.9982, 0, CTRL_NUM_GAIN, 1},
    {"SD", 1024, 1073740800, 1024, CTRL_NUM_INT, 1},
    {"SP", 0, 15000000, 2, CTRL_NUM_INT, 1},
    {"TL", 0, 9.9982, 0, CTRL_NUM_GAIN, 1},
    {"TW", -1, 32767, 1, CTRL_NUM_INT, 1},
};

static const struct ctrl_ipar_desc ipar_table[] = {
    {"CE", 0, 15}, {"LD", 0, 3}, {"OA", 0, 1}, {"OE", 0, 3}, {"OT", 1, 32000},
};

const struct ctrl_par_desc *ctrl_par_find(const char *name)
{
	size_t i;

	for (i = 0; i < sizeof(par_table) / sizeof(par_table[0]); i++)
		if (!strcmp(par_table[i].name, name))
			return &par_table[i];
	return NULL;
}

const struct ctrl_ipar_desc *ctrl_ipar_find(const char *name)
{
	size_t i;

	for (i = 0; i < sizeof(ipar_table) / sizeof(ipar_table[0]); i++)
		if (!strcmp(ipar_table[i].name, name))
			return &ipar_table[i];
	return NULL;
}

double *ctrl_par_ptr(struct ctrl_axis_par *p, const struct ctrl_par_desc *d)
{
	switch (d->name[0] << 8 | d->name[1]) {
	case 'A' << 8 | 'C': return &p->ac;
	case 'B' << 8 | 'L': return &p->bl;
	case 'D' << 8 | 'C': return &p->dc;
	case 'E' << 8 | 'R': return &p->er;
	case 'F' << 8 | 'L': return &p->fl;
	case 'I' << 8 | 'L': return &p->il;
	case 'K' << 8 | 'D': return &p->kd;
	case 'K' << 8 | 'I': return &p->ki;
	case 'K' << 8 | 'P': return &p->kp;
	case 'M' << 8 | 'T': return &p->mt;
	case 'O' << 8 | 'F': return &p->of;
	case 'O' << 8 | 'V': return &p->ov;
	case 'S' << 8 | 'D': return &p->sd;
	case 'S' << 8 | 'P': return &p->sp;
	case 'T' << 8 | 'L': return &p->tl;
	default: return &p->tw;
	}
}

int *ctrl_ipar_ptr(struct ctrl_axis_par *p, const struct ctrl_ipar_desc *d)
{
	switch (d->name[0] << 8 | d->name[1]) {
	case 'C' << 8 | 'E': return &p->ce;
	case 'L' << 8 | 'D': return &p->ld;
	case 'O' << 8 | 'A': return &p->oa;
	case 'O' << 8 | 'E': return &p->oe;
	default: return &p->ot;
	}
}

/* ---- operands ------------------------------------------------------------ */

/*
 * _HMa (command reference HM, CN): with CN n1 = -1 (default) 1 while the
 * home input is pulled up (not active), 0 while grounded; CN n1 = 1
 * inverts it.
 */
int ctrl_axis_home(const struct ctrl *c, int i)
{
	int grounded = c->in.home[i] != 0;

	return c->cn[0] == 1 ? grounded : !grounded;
}

static int switches(const struct ctrl *c, int i, int ts)
{
	const struct ctrl_axis *ax = &c->ax[i];
	double te = round(ax->ref) - round(ax->enc);
	int v = ctrl_axis_home(c, i) ? 0x02 : 0;

	if (ts)
		v |= 0x01; /* TS: latch not armed (no latch simulated) */

	if (!ax->lim_f)
		v |= 0x08;
	if (!ax->lim_r)
		v |= 0x04;
	if (ts) {
		if (ax->profiling)
			v |= 0x80;
		if (ax->p.er >= 0 && fabs(te) > ax->p.er)
			v |= 0x40;
		if (ax->p.motor_off)
			v |= 0x20;
	}
	return v;
}

/*
 * ctrl_axis_operand() - _XXa: state (TP RP TE TD TV TT TS SC MO BG LF LR
 * HM PA PR JG PT DP ZA) or a parameter. Return 0 or TC 1.
 */
int ctrl_axis_operand(struct ctrl *c, const char *n, int i, double *v)
{
	const struct ctrl_axis *ax = &c->ax[i];
	const struct ctrl_par_desc *d = ctrl_par_find(n);
	const struct ctrl_ipar_desc *id = ctrl_ipar_find(n);

	if (d)
		*v = *ctrl_par_ptr((struct ctrl_axis_par *)&ax->p, d);
	else if (id)
		*v = *ctrl_ipar_ptr((struct ctrl_axis_par *)&ax->p, id);
	else if (!strcmp(n, "TP") || !strcmp(n, "DP"))
		*v = round(ax->enc);
	else if (!strcmp(n, "RP"))
		*v = round(ax->ref);
	else if (!strcmp(n, "TE"))
		*v = round(ax->ref) - round(ax->enc);
	else if (!strcmp(n, "TD"))
		*v = 0;
	else if (!strcmp(n, "TV"))
		*v = round(ctrl_axis_tv(ax, ctrl_dt(c)));
	else if (!strcmp(n, "TT"))
		*v = ax->torque;
	else if (!strcmp(n, "TS"))
		*v = switches(c, i, 1);
	else if (!strcmp(n, "SC"))
		*v = ax->stop_code;
	else if (!strcmp(n, "MO"))
		*v = ax->p.motor_off;
	else if (!strcmp(n, "BG"))
		*v = ax->profiling;
	else if (!strcmp(n, "LF"))
		*v = !ax->lim_f;
	else if (!strcmp(n, "LR"))
		*v = !ax->lim_r;
	else if (!strcmp(n, "HM"))
		*v = ctrl_axis_home(c, i);
	else if (!strcmp(n, "PA"))
		*v = ax->pa_last;
	else if (!strcmp(n, "PR"))
		*v = ax->pr;
	else if (!strcmp(n, "JG"))
		*v = fabs(ax->jg);
	else if (!strcmp(n, "PT"))
		*v = ax->pt;
	else if (!strcmp(n, "ZA"))
		*v = ax->za;
	else
		return 1;
	return 0;
}
