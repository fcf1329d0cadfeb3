/*
 * ctrl_flow.c - program flow and trippoints: IF ELSE ENDIF JP JS EN RE RI
 * ZS XQ HX WT AT AM MC MF MR AI.
 *
 * A trippoint parks the thread (struct ctrl_wait) with its pc already on
 * the next statement; ctrl_wait_done() releases it. An automatic
 * subroutine saves the parked trippoint in its frame: RE1/RI1/EN1 restore
 * it, RE/RI/EN clear it (the thread goes on at once).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ctrl_flow.h"
#include "ctrl_args.h"
#include "ctrl_expr.h"
#include "ctrl_out.h"
#include "ctrl_thread.h"
#include "ctrl_var.h"

static struct ctrl_thread *cur(struct ctrl_xc *x)
{
	return &x->c->th[x->thread];
}

/* ctrl_samples() - samples in @ms milliseconds at the current TM. */
int ctrl_samples(const struct ctrl *c, double ms)
{
	return (int)llround(ms * 1000.0 / c->sample_us);
}

/* ctrl_goto_line() - continue the running thread at program line @line. */
int ctrl_goto_line(struct ctrl_xc *x, double line)
{
	int ln = (int)line;

	if (line != ln || ln < 0 || ln >= x->c->prog.nlines)
		return 11;
	cur(x)->next_pc = x->c->prog.first[ln];
	return 0;
}

/* ---- IF / ELSE / ENDIF ------------------------------------------------ */

static int cmd_if(struct ctrl_xc *x, const char *a)
{
	const struct ctrl_stmt *st = &x->c->prog.stmt[x->stmt];
	double v;
	int rc = ctrl_expr_end(x, a, &v);

	if (rc)
		return rc;
	if (v != 0)
		return 0;
	if (st->match < 0)
		return 63;
	cur(x)->next_pc = st->match + 1;
	return 0;
}

static int cmd_else(struct ctrl_xc *x)
{
	const struct ctrl_stmt *st = &x->c->prog.stmt[x->stmt];

	if (st->match < 0)
		return 63;
	cur(x)->next_pc = st->match + 1;
	return 0;
}

/* ---- JP / JS ------------------------------------------------------------ */

/* ",cond" after a jump target: 1 when absent or true. */
static int jump_cond(struct ctrl_xc *x, const char *s, int *take)
{
	double v;
	int rc;

	s = ctrl_skip(s);
	*take = 1;
	if (*s == '\0')
		return 0;
	if (*s != ',')
		return 1;
	rc = ctrl_expr_end(x, s + 1, &v);
	if (!rc)
		*take = v != 0;
	return rc;
}

static int cmd_jp(struct ctrl_xc *x, const char *a)
{
	double line;
	int rc, take = 0;

	rc = ctrl_expr(x, &a, &line);
	if (!rc)
		rc = jump_cond(x, a, &take);
	if (rc || !take)
		return rc;
	return ctrl_goto_line(x, line);
}

/* "(1,&var,x+2)" into a frame; by-reference needs an existing variable. */
static int js_args(struct ctrl_xc *x, const char **p, struct ctrl_frame *f)
{
	const char *s = ctrl_skip(*p + 1);
	uint64_t key;
	size_t n;
	int rc;

	while (*s != ')') {
		if (f->npar >= CTRL_NPARAM)
			return 4;
		if (*s == '&') {
			n = ctrl_ident_len(s + 1);
			rc = ctrl_name_key(s + 1, n, &key);
			if (rc)
				return rc;
			f->ref[f->npar] =
			    (int16_t)ctrl_var_find(&x->c->vars, key);
			if (f->ref[f->npar] < 0)
				return 1;
			s += n + 1;
		} else {
			rc = ctrl_expr(x, &s, &f->par[f->npar]);
			if (rc)
				return rc;
		}
		f->npar++;
		s = ctrl_skip(s);
		if (*s == ',')
			s = ctrl_skip(s + 1);
		else if (*s != ')')
			return *s ? 1 : 59;
	}
	*p = s + 1;
	return 0;
}

static int cmd_js(struct ctrl_xc *x, const char *a)
{
	struct ctrl_thread *t = cur(x);
	struct ctrl_frame f;
	double line;
	int rc, take = 0;

	memset(&f, 0, sizeof(f));
	memset(f.ref, 0xff, sizeof(f.ref));
	rc = ctrl_expr(x, &a, &line);
	if (rc)
		return rc;
	a = ctrl_skip(a);
	if (*a == '(') {
		rc = js_args(x, &a, &f);
		if (rc)
			return rc;
	}
	rc = jump_cond(x, a, &take);
	if (rc || !take)
		return rc;
	if (t->depth >= CTRL_STACK_DEPTH)
		return 12;
	f.ret_pc = t->next_pc;
	f.kind = CTRL_FR_JS;
	rc = ctrl_goto_line(x, line);
	if (rc)
		return rc;
	t->stack[t->depth++] = f;
	return 0;
}

/* ---- EN / RE / RI / ZS ------------------------------------------------- */

/* Return from a subroutine; @restore: RE1/EN1 restore the trippoint. */
static int do_return(struct ctrl_xc *x, int restore, int has_ret, double ret)
{
	struct ctrl_thread *t = cur(x);
	struct ctrl_frame *f;
	char why[48];

	if (t->depth == 0) {
		snprintf(why, sizeof(why), "EN at line %d",
			 x->c->prog.stmt[x->stmt].line);
		ctrl_thread_halt(x->c, x->thread, why);
		return 0;
	}
	f = &t->stack[--t->depth];
	t->js_ret = has_ret ? ret : 0;
	if (f->ret_pc < 0) {
		ctrl_thread_halt(x->c, x->thread, "automatic subroutine done");
		return 0;
	}
	t->next_pc = f->ret_pc;
	if (f->kind == CTRL_FR_AUTO)
		t->wait = restore ? f->saved : (struct ctrl_wait){0};
	return 0;
}

static int cmd_en(struct ctrl_xc *x, const char *a)
{
	double v[3] = {0, 0, 0};
	unsigned got = 0;
	int rc = ctrl_num_list(x, a, v, 3, &got);

	if (rc)
		return rc;
	return do_return(x, v[0] != 0, (got & 4) != 0, v[2]);
}

static int cmd_re(struct ctrl_xc *x, const char *a)
{
	double v = 0;
	int rc = ctrl_num_list(x, a, &v, 1, NULL);

	return rc ? rc : do_return(x, v != 0, 0, 0);
}

static int cmd_zs(struct ctrl_xc *x, const char *a)
{
	struct ctrl_thread *t = cur(x);
	double v = 0;
	int rc = ctrl_num_list(x, a, &v, 1, NULL);

	if (rc)
		return rc;
	if (v == 0)
		t->depth = 0;
	else if (v == 1 && t->depth > 0)
		t->depth--;
	else if (v != 1)
		return 6;
	return 0;
}

/* ---- XQ / HX ------------------------------------------------------------- */

static int cmd_xq(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	double v[3] = {0, 0, 0};
	int rc = ctrl_num_list(x, a, v, 3, NULL), t, line;

	if (rc)
		return rc;
	line = (int)v[0];
	t = (int)v[1];
	if (v[1] != t || t < 0 || t >= CTRL_THREADS)
		return 6;
	if (c->prog.nlines == 0)
		return 10;
	if (v[0] != line || line < 0 || line >= c->prog.nlines)
		return 11;
	if (c->th[t].running && v[2] != 1)
		return 19;
	ctrl_thread_start(c, t, c->prog.first[line]);
	if (t == x->thread)
		c->th[t].next_pc = c->th[t].pc;
	ctrl_event(c, "thread %d started at line %d", t, line);
	return 0;
}

static int cmd_hx(struct ctrl_xc *x, const char *a)
{
	char who[CTRL_WHO_LEN], why[CTRL_WHO_LEN + 16];
	double v = -1;
	int rc;

	ctrl_xc_who(x, who, sizeof(who));
	snprintf(why, sizeof(why), "halted by HX (%s)", who);
	if (*ctrl_skip(a) == '\0') {
		ctrl_threads_halt_all(x->c, why);
		return 0;
	}
	rc = ctrl_num_list(x, a, &v, 1, NULL);
	if (rc)
		return rc;
	if (v != (int)v || v < 0 || v >= CTRL_THREADS)
		return 6;
	ctrl_thread_halt(x->c, (int)v, why);
	return 0;
}

/* ---- trippoints --------------------------------------------------------- */

static void park(struct ctrl_xc *x, const struct ctrl_wait *w)
{
	struct ctrl_thread *t = cur(x);

	t->wait = *w;
	ctrl_wait_done(x->c, t); /* already satisfied? go on */
}

/* WT n[,1] and AT n[,1]: milliseconds, or samples with ",1". */
static int cmd_time(struct ctrl_xc *x, const char *a, int at)
{
	struct ctrl_thread *t = cur(x);
	struct ctrl_wait w = {CTRL_W_UNTIL, 0, 0, 0, 0, 0, 0};
	double v[2] = {0, 0};
	int64_t n;
	int rc = ctrl_num_list(x, a, v, 2, NULL);

	if (rc)
		return rc;
	if (*ctrl_skip(a) == '\0')
		return 39;
	n = v[1] == 1 ? (int64_t)fabs(v[0]) : ctrl_samples(x->c, fabs(v[0]));
	if (!at) {
		if (v[0] < 0)
			return 6;
		w.until = x->c->time + n;
	} else if (v[0] == 0) {
		t->at_ref = x->c->time;
		return 0;
	} else {
		w.until = t->at_ref + n;
		if (v[0] < 0)
			t->at_ref += n;
	}
	park(x, &w);
	return 0;
}

static int cmd_am(struct ctrl_xc *x, const char *a, int mc)
{
	struct ctrl_wait w = {mc ? CTRL_W_MC : CTRL_W_AM, -1, 0, 0, 0, 0, 0};
	int rc = ctrl_parse_mask(x, a, &w.mask);

	if (rc)
		return rc;
	park(x, &w);
	return 0;
}

static int cmd_mfr(struct ctrl_xc *x, const char *a, int fwd)
{
	struct ctrl_wait w = {fwd ? CTRL_W_MF : CTRL_W_MR, 0, 0, 0, 0, 0, 0};
	struct ctrl_args args;
	int rc = ctrl_parse_axis_args(x, a, &args), i, n = 0;

	if (rc)
		return rc;
	for (i = 0; i < CTRL_AXES; i++) {
		if (args.set[i] == 2)
			return 51;
		if (args.set[i] == 1) {
			w.axis = i;
			w.pos = args.v[i];
			n++;
		}
	}
	if (n != 1)
		return n ? 4 : 50;
	park(x, &w);
	return 0;
}

static int cmd_ai(struct ctrl_xc *x, const char *a)
{
	struct ctrl_wait w = {CTRL_W_AI, 0, 0, 0, 0, 0, 0};
	double v = 0;
	int rc = ctrl_expr_end(x, a, &v);

	if (rc)
		return rc;
	if (v != (int)v || v == 0 || fabs(v) > CTRL_INPUTS)
		return 6;
	w.input = (int)fabs(v);
	w.level = v > 0;
	park(x, &w);
	return 0;
}

static int mc_done(struct ctrl *c, struct ctrl_wait *w)
{
	double tw = -1;
	int i, inpos = 1;

	for (i = 0; i < CTRL_AXES; i++) {
		const struct ctrl_axis *ax = &c->ax[i];

		if (!(w->mask & (1u << i)))
			continue;
		if (ax->profiling) {
			w->until = -1;
			return 0;
		}
		if (fabs(ax->ref - ax->enc) >= 1)
			inpos = 0;
		if (ax->p.tw > tw)
			tw = ax->p.tw;
	}
	if (inpos)
		return 1;
	if (tw < 0)
		return 0; /* TW -1: no timeout */
	if (w->until < 0)
		w->until = c->time + ctrl_samples(c, tw);
	if (c->time < w->until)
		return 0;
	for (i = 0; i < CTRL_AXES; i++)
		if (w->mask & (1u << i))
			c->ax[i].stop_code = 99;
	ctrl_event(c, "MC timeout (stop code 99)");
	ctrl_autosub_raise(c, CTRL_AS_MCTIME);
	return 1;
}

/* ctrl_wait_done() - is the trippoint of @t satisfied? Clears it if so. */
int ctrl_wait_done(struct ctrl *c, struct ctrl_thread *t)
{
	struct ctrl_wait *w = &t->wait;
	int i, done = 1;

	switch (w->kind) {
	case CTRL_W_UNTIL:
	case CTRL_W_RETRY: done = c->time >= w->until; break;
	case CTRL_W_AM:
		for (i = 0; i < CTRL_AXES; i++)
			if ((w->mask & (1u << i)) && c->ax[i].profiling)
				done = 0;
		break;
	case CTRL_W_MC: done = mc_done(c, w); break;
	case CTRL_W_MF: done = c->ax[w->axis].enc >= w->pos; break;
	case CTRL_W_MR: done = c->ax[w->axis].enc <= w->pos; break;
	case CTRL_W_AI:
		done = (int)((c->in.inputs >> (w->input - 1)) & 1) == w->level;
		break;
	}
	if (done)
		w->kind = CTRL_W_NONE;
	return done;
}

/*
 * ctrl_flow_cmd() - the flow and trippoint commands (program only; the
 * command table refuses them from a host with TC 2).
 */
int ctrl_flow_cmd(struct ctrl_xc *x, const char *name, const char *a)
{
	if (!strcmp(name, "XQ"))
		return cmd_xq(x, a);
	if (!strcmp(name, "HX"))
		return cmd_hx(x, a);
	if (x->thread < 0)
		return 2;
	if (!strcmp(name, "IF"))
		return cmd_if(x, a);
	if (!strcmp(name, "ELSE"))
		return cmd_else(x);
	if (!strcmp(name, "ENDIF"))
		return *ctrl_skip(a) ? 1 : 0;
	if (!strcmp(name, "JP"))
		return cmd_jp(x, a);
	if (!strcmp(name, "JS"))
		return cmd_js(x, a);
	if (!strcmp(name, "EN"))
		return cmd_en(x, a);
	if (!strcmp(name, "RE") || !strcmp(name, "RI"))
		return cmd_re(x, a);
	if (!strcmp(name, "ZS"))
		return cmd_zs(x, a);
	if (!strcmp(name, "WT") || !strcmp(name, "AT"))
		return cmd_time(x, a, name[0] == 'A');
	if (!strcmp(name, "AM") || !strcmp(name, "MC"))
		return cmd_am(x, a, name[0] == 'M');
	if (!strcmp(name, "MF") || !strcmp(name, "MR"))
		return cmd_mfr(x, a, name[1] == 'F');
	if (!strcmp(name, "AI"))
		return cmd_ai(x, a);
	return 1;
}
