/*
 * ctrl_args.c - the arguments of commands: "n,n,n" per axis (empty fields
 * skip an axis, '?' asks), the single-axis forms "A=n", "~a=n", "*=n",
 * axis masks "ABC", plain number lists, and the numbers a command prints
 * (VF/PF/LZ formats).
 *
 * It runs no command: the commands (ctrl_cmd.c, ctrl_flow.c, ctrl_axcmd.c)
 * call it. Every parser returns 0 or a TC code.
 */
#include <string.h>

#include "ctrl_args.h"
#include "ctrl_axis.h"
#include "ctrl_buf.h"
#include "ctrl_expr.h"
#include "ctrl_num.h"

/* ctrl_put_num() - one number into the output, CTRL_NUM_* format. */
int ctrl_put_num(struct ctrl_xc *x, double v, int how)
{
	struct ctrl_fmt f = {x->c->lz ? 'Z' : 'F', x->c->vf_m, x->c->vf_n};
	char num[48];

	if (how == CTRL_NUM_PF) {
		f.m = x->c->pf_m;
		f.n = x->c->pf_n;
	} else if (how == CTRL_NUM_INT) {
		f = (struct ctrl_fmt){'Z', 10, 0};
	} else if (how == CTRL_NUM_GAIN) {
		f = (struct ctrl_fmt){'Z', 10, 4};
	}
	if (ctrl_fmt_num(num, sizeof(num), v, &f) < 0)
		return 1;
	return ctrl_buf_puts(&x->c->tmp, num) ? 1 : 0;
}

/* "A=n", "~a=n", "*=n" (all axes) or "A=?" */
static int single_axis(struct ctrl_xc *x, const char *a, struct ctrl_args *o)
{
	int axis = 0, i, rc, all = *a == '*';
	double v = 0;

	if (all)
		a++;
	else if ((rc = ctrl_axis_desig(x, &a, &axis)) != 0)
		return rc;
	a = ctrl_skip(a);
	if (*a++ != '=')
		return 1;
	a = ctrl_skip(a);
	if (*a == '?' && *ctrl_skip(a + 1) == '\0')
		rc = 0, v = -1;
	else if ((rc = ctrl_expr_end(x, a, &v)) != 0)
		return rc;
	for (i = 0; i < CTRL_AXES; i++) {
		if (!all && i != axis)
			continue;
		o->set[i] = *a == '?' ? 2 : 1;
		o->v[i] = v;
	}
	o->n = CTRL_AXES;
	return 0;
}

static int is_single_axis(const char *a)
{
	const char *s = a;

	if (*s == '*')
		s++;
	else if (*s == '~' && s[1] >= 'a' && s[1] <= 'h')
		s += 2;
	else if (ctrl_axis_letter(*s) >= 0)
		s++;
	else
		return 0;
	return *ctrl_skip(s) == '=';
}

/*
 * ctrl_parse_axis_args() - "n,n,n" (empty fields skip an axis, '?' asks)
 * or the single-axis forms. Return: 0 or a TC code.
 */
int ctrl_parse_axis_args(struct ctrl_xc *x, const char *a,
			 struct ctrl_args *out)
{
	int i = 0, rc;

	memset(out, 0, sizeof(*out));
	a = ctrl_skip(a);
	if (is_single_axis(a))
		return single_axis(x, a, out);
	while (*a) {
		if (i >= CTRL_AXES)
			return 6;
		if (*a == '?') {
			out->set[i] = 2;
			a = ctrl_skip(a + 1);
		} else if (*a != ',') {
			rc = ctrl_expr(x, &a, &out->v[i]);
			if (rc)
				return rc;
			out->set[i] = 1;
			a = ctrl_skip(a);
		}
		i++;
		if (*a == ',')
			a = ctrl_skip(a + 1);
		else if (*a)
			return 1;
	}
	out->n = i;
	return 0;
}

/* ctrl_parse_mask() - "ABC", "B", "~a~b", "" (all axes). */
int ctrl_parse_mask(struct ctrl_xc *x, const char *a, unsigned *mask)
{
	int axis, rc;

	*mask = 0;
	a = ctrl_skip(a);
	if (*a == '\0') {
		*mask = (1u << CTRL_AXES) - 1;
		return 0;
	}
	while (*a) {
		rc = ctrl_axis_desig(x, &a, &axis);
		if (rc)
			return rc;
		*mask |= 1u << axis;
		a = ctrl_skip(a);
	}
	return 0;
}

/*
 * Up to @max comma-separated numbers; absent fields keep their value.
 * @present: [out] optional, bit i set when field i was given.
 */
int ctrl_num_list(struct ctrl_xc *x, const char *a, double *v, int max,
		  unsigned *present)
{
	unsigned got = 0;
	int i = 0, rc;

	a = ctrl_skip(a);
	while (*a && i < max) {
		if (*a != ',') {
			rc = ctrl_expr(x, &a, &v[i]);
			if (rc)
				return rc;
			got |= 1u << i;
			a = ctrl_skip(a);
		}
		i++;
		if (*a == ',')
			a = ctrl_skip(a + 1);
		else if (*a)
			return 1;
	}
	if (present)
		*present = got;
	return *a ? 4 : 0;
}
