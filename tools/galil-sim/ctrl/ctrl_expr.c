/*
 * ctrl_expr.c - DMC expressions.
 *
 * There is no operator precedence: operators apply strictly left to right,
 * parentheses override (DMC-40x0 command reference "( )": MG 1+2*3 prints
 * 9.0000). Operators: + - * / % & | = < > <= >= <>; comparisons give 1 or 0;
 * & and | work bitwise on the 48-bit fixed-point value (so they are also the
 * logical AND/OR of conditions). Primaries: numbers (12, 1.5, $1F.8),
 * "strings" of up to 6 characters, variables, array[i] (array[-1] = size),
 * @functions[x], _operands (ctrl_oper.c), TIME, ^a..^h, ~a..~h, #label (its
 * line number) and unary minus.
 *
 * Every function returns 0 or a TC code; the cursor *p moves past what was
 * consumed.
 */
#include <ctype.h>
#include <math.h>
#include <string.h>

#include "ctrl_expr.h"
#include "ctrl_num.h"
#include "ctrl_oper.h"
#include "ctrl_prog.h"
#include "ctrl_var.h"

#define EXPR_DEPTH 40 /* nested parentheses / unary signs */
#define DEG	   (M_PI / 180.0)

const char *ctrl_skip(const char *s)
{
	while (*s == ' ' || *s == '\t')
		s++;
	return s;
}

/* ctrl_param_ptr() - storage of ^a..^h for the running thread, or NULL. */
double *ctrl_param_ptr(struct ctrl_xc *x, int i)
{
	struct ctrl_thread *t;
	struct ctrl_frame *f;

	if (x->thread < 0 || i < 0 || i >= CTRL_NPARAM)
		return NULL;
	t = &x->c->th[x->thread];
	if (t->depth == 0)
		return &t->par0[i];
	f = &t->stack[t->depth - 1];
	if (f->ref[i] >= 0)
		return &x->c->vars.slot[f->ref[i]].v;
	return &f->par[i];
}

static int hexval(char ch)
{
	if (ch >= '0' && ch <= '9')
		return ch - '0';
	if (ch >= 'A' && ch <= 'F')
		return ch - 'A' + 10;
	if (ch >= 'a' && ch <= 'f')
		return ch - 'a' + 10;
	return -1;
}

/* $hex: 8 hex digits of integer, 4 of fraction, two's complement. */
static int num_hex(const char **p, double *out)
{
	const char *s = *p + 1;
	uint64_t ip = 0, fp = 0, raw;
	int n = 0, k;

	while (hexval(*s) >= 0) {
		ip = ((ip << 4) | (unsigned)hexval(*s++)) & 0xFFFFFFFFu;
		n++;
	}
	if (*s == '.')
		for (s++, k = 0; hexval(*s) >= 0; s++, k++)
			if (k < 4)
				fp |= (uint64_t)hexval(*s) << (12 - 4 * k);
	if (n == 0)
		return 1;
	raw = ip << 16 | fp; /* 48 bits, two's complement */
	*out = ctrl_fx_from_raw(raw & (1ull << 47)
				    ? (int64_t)raw - ((int64_t)1 << 48)
				    : (int64_t)raw);
	*p = s;
	return 0;
}

static int num_dec(const char **p, double *out)
{
	const char *s = *p;
	double v = 0, scale = 0.1;
	int digits = 0;

	while (isdigit((unsigned char)*s)) {
		v = v * 10 + (*s++ - '0');
		digits++;
	}
	if (*s == '.')
		for (s++; isdigit((unsigned char)*s); s++, digits++) {
			v += (*s - '0') * scale;
			scale /= 10;
		}
	if (!digits)
		return 1;
	if (v > CTRL_FX_MAX + 1)
		return 6;
	*out = ctrl_fx(v);
	*p = s;
	return 0;
}

static int str_lit(const char **p, double *out)
{
	const char *s = *p + 1, *e = strchr(s, '"');

	if (!e || e - s > 6)
		return 52;
	*out = ctrl_str_value(s, (size_t)(e - s));
	*p = e + 1;
	return 0;
}

static int bracket(struct ctrl_xc *x, const char **p, double *out)
{
	const char *s = ctrl_skip(*p);
	int rc;

	if (*s != '[')
		return 55;
	s++;
	rc = ctrl_expr(x, &s, out);
	if (rc)
		return rc;
	s = ctrl_skip(s);
	if (*s != ']')
		return 55;
	*p = s + 1;
	return 0;
}

static int func_io(struct ctrl *c, const char *f, double a, double *out)
{
	int n = (int)a;

	if (!strcmp(f, "AN")) {
		if (n < 1 || n > CTRL_ANALOG)
			return 6;
		*out = ctrl_fx(c->in.an_v[n - 1]);
		return 0;
	}
	if (n < 1 || n > CTRL_INPUTS)
		return 6;
	if (!strcmp(f, "IN"))
		*out = (c->in.inputs >> (n - 1)) & 1;
	else
		*out = (c->outputs >> (n - 1)) & 1;
	return 0;
}

static double fx_int(double v)
{
	int64_t raw = ctrl_fx_raw(v);

	raw = raw >= 0 ? raw >> 16 : -((-raw) >> 16);
	return (double)raw;
}

static int func_math(const char *f, double a, double *out)
{
	float fl;
	int32_t i32;

	if (!strcmp(f, "ABS"))
		*out = fabs(a);
	else if (!strcmp(f, "INT"))
		*out = fx_int(a);
	else if (!strcmp(f, "FRAC"))
		*out = a - fx_int(a);
	else if (!strcmp(f, "RND"))
		*out = floor(a + 0.5);
	else if (!strcmp(f, "SQR"))
		*out = sqrt(fabs(a));
	else if (!strcmp(f, "SIN"))
		*out = sin(a * DEG);
	else if (!strcmp(f, "COS"))
		*out = cos(a * DEG);
	else if (!strcmp(f, "TAN"))
		*out = tan(a * DEG);
	else if (!strcmp(f, "ATAN"))
		*out = atan(a) / DEG;
	else if (!strcmp(f, "ASIN") || !strcmp(f, "ACOS")) {
		if (a < -1 || a > 1)
			return 6;
		*out = (f[1] == 'S' ? asin(a) : acos(a)) / DEG;
	} else if (!strcmp(f, "COM")) {
		*out = (double)(int32_t) ~(uint32_t)(int32_t)fx_int(a);
	} else if (!strcmp(f, "FLOT")) {
		fl = (float)a;
		memcpy(&i32, &fl, sizeof(i32));
		*out = i32;
	} else if (!strcmp(f, "REAL")) {
		i32 = (int32_t)(uint32_t)(int64_t)fx_int(a);
		memcpy(&fl, &i32, sizeof(fl));
		*out = isfinite(fl) ? fl : 0;
	} else {
		return 57;
	}
	return 0;
}

static int func(struct ctrl_xc *x, const char **p, double *out)
{
	const char *s = *p + 1;
	char name[8];
	size_t n = 0;
	double a;
	int rc;

	while (n < sizeof(name) - 1 && isupper((unsigned char)s[n])) {
		name[n] = s[n];
		n++;
	}
	name[n] = '\0';
	s += n;
	rc = bracket(x, &s, &a);
	if (rc)
		return rc;
	if (!strcmp(name, "IN") || !strcmp(name, "OUT") || !strcmp(name, "AN"))
		rc = func_io(x->c, name, a, out);
	else
		rc = func_math(name, a, out);
	if (rc)
		return rc;
	*out = ctrl_fx(*out);
	*p = s;
	return 0;
}

static int array_elem(struct ctrl_xc *x, uint64_t key, const char **p,
		      double *out)
{
	struct ctrl_array *arr = ctrl_array_find(&x->c->vars, key);
	double idx;
	int rc, i;

	if (!arr)
		return 57;
	rc = bracket(x, p, &idx);
	if (rc)
		return rc;
	i = (int)idx;
	if (i == -1) {
		*out = arr->n;
		return 0;
	}
	if (idx < 0 || i >= arr->n)
		return 56;
	*out = arr->v[i];
	return 0;
}

/* name: a variable, name[i]: an array element, TIME: the sample counter */
static int ident(struct ctrl_xc *x, const char **p, double *out)
{
	const char *s = *p;
	size_t n = ctrl_ident_len(s);
	uint64_t key;
	int rc, slot;

	if (n == 4 && !strncmp(s, "TIME", 4)) {
		*out = (double)(int32_t)(uint32_t)x->c->time;
		*p = s + 4;
		return 0;
	}
	rc = ctrl_name_key(s, n, &key);
	if (rc)
		return rc;
	s += n;
	if (*ctrl_skip(s) == '[') {
		rc = array_elem(x, key, &s, out);
	} else {
		slot = ctrl_var_find(&x->c->vars, key);
		if (slot < 0)
			return 1;
		*out = x->c->vars.slot[slot].v;
	}
	if (!rc)
		*p = s;
	return rc;
}

static int label_line(struct ctrl_xc *x, const char **p, double *out)
{
	const char *s = *p + 1;
	size_t n = ctrl_ident_len(s);
	uint64_t key;
	int line;

	if (n < 1 || n > CTRL_LABEL_MAX || ctrl_name_key(s, n, &key))
		return 11;
	line = ctrl_prog_label(&x->c->prog, key);
	if (line < 0)
		return 10;
	*out = line;
	*p = s + n;
	return 0;
}

static int special(struct ctrl_xc *x, const char **p, double *out)
{
	const char *s = *p;
	double *pp;

	if (*s == '^') {
		pp = ctrl_param_ptr(x, s[1] - 'a');
		if (!pp)
			return 1;
		if (*ctrl_skip(s + 2) == '[')
			return 57; /* arrays passed on the stack: no */
		*out = *pp;
		*p = s + 2;
		return 0;
	}
	if (*s == '~') {
		if (s[1] < 'a' || s[1] > 'h')
			return 1;
		*out = x->c->axdes[s[1] - 'a'];
		*p = s + 2;
		return 0;
	}
	return label_line(x, p, out);
}

static int primary(struct ctrl_xc *x, const char **p, double *out)
{
	const char *s = ctrl_skip(*p);
	int rc;

	*p = s;
	switch (*s) {
	case '(':
		s++;
		rc = ctrl_expr(x, &s, out);
		if (rc)
			return rc;
		s = ctrl_skip(s);
		if (*s != ')')
			return 59;
		*p = s + 1;
		return 0;
	case '$': return num_hex(p, out);
	case '"': return str_lit(p, out);
	case '@': return func(x, p, out);
	case '_': return ctrl_operand(x, p, out);
	case '^':
	case '~':
	case '#': return special(x, p, out);
	}
	if (isdigit((unsigned char)*s) || *s == '.')
		return num_dec(p, out);
	if (isalpha((unsigned char)*s))
		return ident(x, p, out);
	return 1;
}

static int term(struct ctrl_xc *x, const char **p, double *out)
{
	const char *s = ctrl_skip(*p);
	int rc;

	if (++x->c->edepth > EXPR_DEPTH) {
		x->c->edepth--;
		return 59;
	}
	if (*s == '-' || *s == '+') {
		char sign = *s++;

		rc = term(x, &s, out);
		if (!rc && sign == '-')
			*out = ctrl_fx(-*out);
	} else {
		rc = primary(x, &s, out);
	}
	x->c->edepth--;
	if (!rc)
		*p = s;
	return rc;
}

/* Operator at *p (advanced past it), or 0. */
static int binop(const char **p)
{
	const char *s = ctrl_skip(*p);
	int op = 0;

	switch (*s) {
	case '+':
	case '-':
	case '*':
	case '/':
	case '%':
	case '&':
	case '|':
	case '=': op = *s++; break;
	case '<':
		s++;
		op = *s == '=' ? (s++, 'l') : *s == '>' ? (s++, 'n') : '<';
		break;
	case '>':
		s++;
		op = *s == '=' ? (s++, 'g') : '>';
		break;
	}
	if (op)
		*p = s;
	return op;
}

static int apply(int op, double a, double b, double *out)
{
	int64_t ra, rb;

	switch (op) {
	case '+': *out = a + b; break;
	case '-': *out = a - b; break;
	case '*': *out = a * b; break;
	case '/':
	case '%':
		if (b == 0)
			return 6; /* UNCONFIRMED: firmware result of x/0 */
		*out = op == '/' ? a / b : fmod(a, b);
		break;
	case '&':
	case '|':
		ra = ctrl_fx_raw(a);
		rb = ctrl_fx_raw(b);
		*out = ctrl_fx_from_raw(op == '&' ? ra & rb : ra | rb);
		break;
	case '=': *out = a == b; break;
	case '<': *out = a < b; break;
	case '>': *out = a > b; break;
	case 'l': *out = a <= b; break;
	case 'g': *out = a >= b; break;
	case 'n': *out = a != b; break;
	}
	*out = ctrl_fx(*out);
	return 0;
}

/*
 * ctrl_expr() - evaluate the expression at *p, left to right; stops at the
 * first character that is not an operator (',', ')', ']', '{', end ...).
 * Return: 0 or a TC code; *p is advanced only on success.
 */
int ctrl_expr(struct ctrl_xc *x, const char **p, double *out)
{
	const char *s = *p;
	double acc, rhs;
	int op, rc;

	rc = term(x, &s, &acc);
	if (rc)
		return rc;
	while ((op = binop(&s)) != 0) {
		rc = term(x, &s, &rhs);
		if (!rc)
			rc = apply(op, acc, rhs, &acc);
		if (rc)
			return rc;
	}
	*out = acc;
	*p = s;
	return 0;
}

/* ctrl_expr_end() - the whole of @s is one expression. */
int ctrl_expr_end(struct ctrl_xc *x, const char *s, double *out)
{
	int rc = ctrl_expr(x, &s, out);

	if (rc)
		return rc;
	s = ctrl_skip(s);
	if (*s == ')')
		return 59;
	return *s ? 1 : 0;
}
