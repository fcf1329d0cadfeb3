/*
 * ctrl_axis.c - an axis as the language names and reads it: axis letters
 * and designators (A..H, X Y Z W, ~a..~h).
 *
 * It does not change an axis (the axis commands, ctrl_axcmd.c) nor move
 * one (ctrl_motion.c).
 */
#include <string.h>

#include "ctrl_int.h"

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
