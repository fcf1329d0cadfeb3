/*
 * ctrl_oper.c - _operands in expressions: _XXa reads what command XX holds
 * for axis a (_TPA, _SPB, _ZAC ...; ctrl_axis_operand() in ctrl_axis.c),
 * plus the controller-wide ones (_TC, _ED, _XQn, _NO, _BN ...). Operands
 * cannot be assigned. An unknown operand is TC 1.
 */
#include <ctype.h>
#include <string.h>

#include "ctrl_oper.h"
#include "ctrl_axis.h"
#include "ctrl_num.h"
#include "ctrl_thread.h"
#include "ctrl_var.h"

static unsigned thread_mask(const struct ctrl *c)
{
	unsigned m = 0;
	int t;

	for (t = 0; t < CTRL_THREADS; t++)
		if (c->th[t].running)
			m |= 1u << t;
	return m;
}

/* Operands that take a single digit, 0..7 (threads) or 0..n. */
static int digit_op(struct ctrl_xc *x, const char *code, int d, double *v)
{
	struct ctrl *c = x->c;

	if (!strcmp(code, "XQ") && d < CTRL_THREADS)
		*v = ctrl_thread_line(c, d);
	else if (!strcmp(code, "HX") && d < CTRL_THREADS)
		*v = !c->th[d].running ? 0 : ctrl_thread_waiting(c, d) ? 2 : 1;
	else if (!strcmp(code, "ZS") && d < CTRL_THREADS)
		*v = c->th[d].depth;
	else if (!strcmp(code, "TI") && d < 4)
		*v = (c->in.inputs >> (8 * d)) & 0xFF;
	else if (!strcmp(code, "TA") && d < 4)
		*v = d == 0 ? c->ta0 : 0;
	else if (!strcmp(code, "QZ") && d < 4)
		*v = (int[]){CTRL_AXES, 52, 26, 36}[d];
	else if (!strcmp(code, "ED") && (d == 0 || d == 1 || d == 4))
		*v = d == 0 ? c->ed_line : d == 1 ? c->ed_thread : x->thread;
	else if (!strcmp(code, "DR") && d <= 1)
		*v = d == 0 ? c->dr.n : c->dr.h;
	else if (!strcmp(code, "OP") && d == 0)
		*v = c->outputs & 0xFFFF;
	else if (!strcmp(code, "CN") && d <= 4)
		*v = d == 0 ? c->cn0 : c->cn[d - 1];
	else if (!strcmp(code, "CW") && d == 4)
		*v = c->cw_drop;
	else if (!strcmp(code, "IA") && d <= 5)
		*v = (double[]){2130706433.0, 250,    CTRL_HANDLES,
				x->handle,    c->ia4, 100}[d];
	else
		return 1;
	return 0;
}

/* Operands without a suffix. */
static int plain_op(struct ctrl_xc *x, const char *code, double *v)
{
	struct ctrl *c = x->c;

	if (!strcmp(code, "TC"))
		*v = c->tc;
	else if (!strcmp(code, "ED"))
		*v = c->ed_line;
	else if (!strcmp(code, "NO"))
		*v = thread_mask(c);
	else if (!strcmp(code, "BN"))
		*v = (double)c->cfg.serial;
	else if (!strcmp(code, "BV"))
		*v = CTRL_AXES;
	else if (!strcmp(code, "TM"))
		*v = c->sample_us;
	else if (!strcmp(code, "CO"))
		*v = c->co;
	else if (!strcmp(code, "JS"))
		*v = x->thread >= 0 ? c->th[x->thread].js_ret : 0;
	else if (!strcmp(code, "CW"))
		*v = c->cw_hibit ? 1 : 2;
	else if (!strcmp(code, "CF"))
		*v = c->cf == CTRL_SERIAL ? 'S' : 'A' + c->cf;
	else if (!strcmp(code, "WH"))
		*v = x->handle;
	else if (!strcmp(code, "LZ"))
		*v = c->lz;
	else if (!strcmp(code, "UL"))
		*v = CTRL_VARS - c->vars.count;
	else if (!strcmp(code, "DL"))
		*v = CTRL_LABELS - c->prog.nlabels;
	else if (!strcmp(code, "DM"))
		*v = CTRL_ARRAY_SPACE - c->vars.arr_used;
	else if (!strcmp(code, "DA"))
		*v = ctrl_arrays_free(&c->vars);
	else if (!strcmp(code, "TB"))
		*v = (thread_mask(c) ? 128 : 0);
	else if (!strcmp(code, "RS"))
		*v = 0;
	else if (!strcmp(code, "XQ")) /* choice: _XQ is _XQ0 */
		*v = ctrl_thread_line(c, 0);
	else if (!strcmp(code, "TA")) /* choice: _TA is _TA0 */
		*v = c->ta0;
	else
		return 1;
	return 0;
}

/* _IHh0.._IHh4: h = handle letter. */
static int ih_op(struct ctrl *c, const char *rest, double *v)
{
	int h, d;

	if (strlen(rest) != 2 || rest[0] < 'A' || rest[0] > 'H' ||
	    !isdigit((unsigned char)rest[1]))
		return 1;
	h = rest[0] - 'A';
	d = rest[1] - '0';
	switch (d) {
	case 0:
		*v = c->h[h].open ? (double)(int32_t)c->h[h].peer_ip : 0;
		return 0;
	case 1: *v = c->h[h].open ? c->h[h].peer_port : 0; return 0;
	case 2: *v = c->h[h].open ? (c->h[h].udp ? 1 : 2) : 0; return 0;
	case 3:
	case 4: *v = 0; return 0;
	}
	return 1;
}

static int suffix_op(struct ctrl_xc *x, const char *code, const char *rest,
		     const char **p, double *v)
{
	const char *a = rest;
	int axis, rc;

	if (!strcmp(code, "IH"))
		return ih_op(x->c, rest, v);
	if (isdigit((unsigned char)rest[0]) && rest[1] == '\0')
		return digit_op(x, code, rest[0] - '0', v);
	if (rest[0] == '\0' && **p == '~') {
		rc = ctrl_axis_desig(x, p, &axis);
		if (rc)
			return rc;
	} else {
		if (strlen(rest) != 1)
			return 1;
		rc = ctrl_axis_desig(x, &a, &axis);
		if (rc)
			return rc;
	}
	return ctrl_axis_operand(x->c, code, axis, v);
}

/* ctrl_operand() - the _operand at *p. */
int ctrl_operand(struct ctrl_xc *x, const char **p, double *out)
{
	const char *s = *p + 1;
	size_t n = ctrl_ident_len(s);
	char code[3], rest[8];
	double v;
	int rc;

	if (n < 2 || n > 6 || !isupper((unsigned char)s[0]) ||
	    !isupper((unsigned char)s[1]))
		return 1;
	memcpy(code, s, 2);
	code[2] = '\0';
	memcpy(rest, s + 2, n - 2);
	rest[n - 2] = '\0';
	s += n;
	if (rest[0] == '\0' && *s != '~')
		rc = plain_op(x, code, &v);
	else
		rc = suffix_op(x, code, rest, &s, &v);
	if (rc)
		return rc;
	*out = ctrl_fx(v);
	*p = s;
	return 0;
}
