/*
 * ctrl_mg.c - MG: "strings", expressions and formatters, comma separated.
 *
 *   {Fm.n} m digits (leading zeros) . n digits   {Zm.n} the same without
 *   leading zeros   {$m.n} hexadecimal   {Sn} the value as n characters
 *   {^n} character n   {N} no CR LF at the end   {Ex} to handle x
 *   {Pn} to serial port n (the simulator has no serial port: dropped)
 * A number format right after an expression (also after its {N}) applies
 * to that expression; anywhere else it applies to the expressions that
 * follow. Decimal numbers start with a space, negative ones then '-':
 * MG 1+2*3 prints " 9.0000", MG -1,-2 " -1.0000 -2.0000".
 */
#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#include "ctrl_mg.h"
#include "ctrl_buf.h"
#include "ctrl_expr.h"
#include "ctrl_num.h"

/* A number format "F5.2" etc. at s (after '{'); *p past the '}'. */
static int num_fmt(const char *s, const char **p, struct ctrl_fmt *f)
{
	char *e;
	long m, n = 0;

	f->kind = *s++;
	m = strtol(s, &e, 10);
	if (e == s)
		return 53;
	if (*e == '.') {
		s = e + 1;
		n = strtol(s, &e, 10);
		if (e == s)
			return 53;
	}
	if (*e != '}' || m < 0 || m > 10 || n < 0 || n > 4)
		return 53;
	f->m = (int)m;
	f->n = (int)n;
	if (f->kind == 'S' && (m < 1 || m > 6))
		return 53;
	*p = e + 1;
	return 0;
}

static int is_num_fmt(const char *s)
{
	return s[0] == '{' && strchr("FZ$S", s[1]) && s[1] &&
	       isdigit((unsigned char)s[2]);
}

/* {N} {^n} {Ex} {Pn} {Ln} */
static int other_fmt(struct ctrl_xc *x, const char *s, const char **p,
		     int *crlf)
{
	const char *e = strchr(s, '}');
	char *end;
	long v;

	if (!e)
		return 53;
	if (s[0] == 'N' && s + 1 == e) {
		*crlf = 0;
	} else if (s[0] == '^') {
		v = strtol(s + 1, &end, 10);
		if (end != e || end == s + 1 || v < 0 || v > 255)
			return 53;
		ctrl_buf_put(&x->c->tmp, &(char){(char)v}, 1);
	} else if (s[0] == 'E' && s + 2 == e && s[1] >= 'A' &&
		   s[1] < 'A' + CTRL_HANDLES) {
		x->route = s[1] - 'A';
	} else if ((s[0] == 'P' || s[0] == 'L') && s + 2 == e &&
		   isdigit((unsigned char)s[1])) {
		if (s[0] == 'P')
			x->route = CTRL_SERIAL;
	} else {
		return 53;
	}
	*p = e + 1;
	return 0;
}

/*
 * A number: a decimal one starts with a space, also before its '-' (the
 * command reference's MG examples: " 9.0000", " -90.0000"), so several
 * values stay apart. Deviation mg-join drops the space before '-'.
 */
static int put_value(struct ctrl_xc *x, double v, const struct ctrl_fmt *f)
{
	char num[64];
	int n = ctrl_fmt_num(num, sizeof(num), v, f);

	if (n < 0)
		return 53;
	if (num[0] == '-' && !(x->c->cfg.deviate & CTRL_DEV_MG_JOIN) &&
	    ctrl_buf_puts(&x->c->tmp, " "))
		return 1;
	return ctrl_buf_puts(&x->c->tmp, num) ? 1 : 0;
}

/* Formatters right after an expression: {N} and one number format. */
static int after_value(const char **p, struct ctrl_fmt *f, int *crlf)
{
	const char *s = ctrl_skip(*p);
	int rc, have_fmt = 0;

	for (;;) {
		if (s[0] == '{' && s[1] == 'N' && s[2] == '}') {
			*crlf = 0;
			s = ctrl_skip(s + 3);
		} else if (!have_fmt && is_num_fmt(s)) {
			rc = num_fmt(s + 1, &s, f);
			if (rc)
				return rc;
			have_fmt = 1;
			s = ctrl_skip(s);
		} else {
			break;
		}
	}
	*p = s;
	return 0;
}

static int mg_item(struct ctrl_xc *x, const char **p, struct ctrl_fmt *cur,
		   int *crlf)
{
	const char *s = *p, *e;
	struct ctrl_fmt f;
	double v;
	int rc;

	if (*s == '"') {
		e = strchr(s + 1, '"');
		if (!e)
			return 52;
		ctrl_buf_put(&x->c->tmp, s + 1, (size_t)(e - s - 1));
		*p = e + 1;
		return 0;
	}
	if (is_num_fmt(s))
		return num_fmt(s + 1, p, cur);
	if (*s == '{')
		return other_fmt(x, s + 1, p, crlf);
	rc = ctrl_expr(x, &s, &v);
	if (rc)
		return rc;
	f = *cur;
	rc = after_value(&s, &f, crlf);
	if (rc)
		return rc;
	*p = s;
	return put_value(x, v, &f);
}

/* ctrl_mg() - format the message into the statement output. */
int ctrl_mg(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	struct ctrl_fmt cur = {c->lz ? 'Z' : 'F', c->vf_m, c->vf_n};
	int crlf = 1, rc;

	a = ctrl_skip(a);
	while (*a) {
		if (*a == ',') {
			a = ctrl_skip(a + 1);
			continue;
		}
		rc = mg_item(x, &a, &cur, &crlf);
		if (rc)
			return rc;
		a = ctrl_skip(a);
	}
	if (crlf)
		ctrl_buf_puts(&c->tmp, "\r\n");
	return 0;
}
