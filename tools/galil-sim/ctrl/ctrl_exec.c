/*
 * ctrl_exec.c - one statement from a host or a program thread, and the
 * thread scheduler.
 *
 * Statement forms:
 *   #label            (program: no-op; host: TC 1)
 *   ' comment / NO    no-op
 *   name=expr         variable; name[i]=expr array element; name= or
 *                     name=? prints the value
 *   ^a=expr           subroutine parameter; ~a=expr or ~a="B" axis designator
 *   XXargs            command XX (two upper-case letters), e.g. "SHA",
 *                     "PR 1000,,3000", "PRA=1000", "KP*=0", "XQ #A,1"
 * A lower-case word that is not an assignment, an unknown command and an
 * _operand used as a command all answer TC 1.
 *
 * Timing model: each servo sample the running threads get program lines
 * round robin, one line per turn, CTRL_LINES_PER_SAMPLE lines in total
 * (ctrl_set_line_budget()). A line ends at a jump, a trippoint or the end
 * of the line; all statements of one line run in the same turn.
 */
#include <ctype.h>
#include <stdio.h>
#include <string.h>

#include "ctrl_exec.h"
#include "ctrl_axis.h"
#include "ctrl_buf.h"
#include "ctrl_cmd.h"
#include "ctrl_expr.h"
#include "ctrl_flow.h"
#include "ctrl_num.h"
#include "ctrl_out.h"
#include "ctrl_prog.h"
#include "ctrl_thread.h"
#include "ctrl_var.h"
#include "dmc_cmd.h"
#include "dmc_text.h"

/* ---- statements ------------------------------------------------------ */

static int var_query(struct ctrl_xc *x, double v)
{
	struct ctrl_fmt f = {x->c->lz ? 'Z' : 'F', x->c->vf_m, x->c->vf_n};
	char num[48];

	if (ctrl_fmt_num(num, sizeof(num), v, &f) < 0)
		return 1;
	return ctrl_buf_printf(&x->c->tmp, "%s\r\n", num) ? 1 : 0;
}

/* After "name" (or "name[i]"): "=expr", "=" or "=?". */
static int assign_rhs(struct ctrl_xc *x, const char *s, int *query, double *v)
{
	s = ctrl_skip(s);
	if (*s != '=')
		return 1;
	s = ctrl_skip(s + 1);
	*query = *s == '\0' || (*s == '?' && *ctrl_skip(s + 1) == '\0');
	if (*query)
		return 0;
	return ctrl_expr_end(x, s, v);
}

static int array_stmt(struct ctrl_xc *x, uint64_t key, const char *s)
{
	struct ctrl_array *arr = ctrl_array_find(&x->c->vars, key);
	double idx, v = 0;
	int rc, query;

	if (!arr)
		return 57;
	s = ctrl_skip(s) + 1; /* '[' */
	rc = ctrl_expr(x, &s, &idx);
	if (rc)
		return rc;
	s = ctrl_skip(s);
	if (*s != ']')
		return 55;
	if (idx < 0 || idx >= arr->n)
		return 56;
	rc = assign_rhs(x, s + 1, &query, &v);
	if (rc)
		return rc;
	if (query)
		return var_query(x, arr->v[(int)idx]);
	arr->v[(int)idx] = v;
	return 0;
}

static int var_stmt(struct ctrl_xc *x, const char *s, size_t n)
{
	struct ctrl_vars *vs = &x->c->vars;
	uint64_t key;
	double v = 0;
	int rc, query, slot;

	if (n == 4 && !strncmp(s, "TIME", 4))
		return 1;
	rc = ctrl_name_key(s, n, &key);
	if (rc)
		return rc;
	if (*ctrl_skip(s + n) == '[')
		return array_stmt(x, key, s + n);
	rc = assign_rhs(x, s + n, &query, &v);
	if (rc)
		return rc;
	if (query) {
		slot = ctrl_var_find(vs, key);
		return slot < 0 ? 1 : var_query(x, vs->slot[slot].v);
	}
	return ctrl_var_set(vs, key, v, NULL);
}

/* ^a=expr (program only) */
static int param_stmt(struct ctrl_xc *x, const char *s)
{
	double *pp = ctrl_param_ptr(x, s[1] - 'a');
	double v = 0;
	int rc, query;

	if (!pp)
		return x->thread < 0 ? 2 : 1;
	rc = assign_rhs(x, s + 2, &query, &v);
	if (rc)
		return rc;
	if (query)
		return var_query(x, *pp);
	*pp = v;
	return 0;
}

/* ~a=2 or ~a="C" */
static int axdes_stmt(struct ctrl_xc *x, const char *s)
{
	const char *r;
	double v = 0;
	int i = s[1] - 'a', rc, query;

	if (i < 0 || i > 7)
		return 1;
	r = ctrl_skip(s + 2);
	if (*r == '=' && *(r = ctrl_skip(r + 1)) == '"' &&
	    ctrl_axis_letter(r[1]) >= 0 && r[2] == '"' &&
	    *ctrl_skip(r + 3) == '\0') {
		x->c->axdes[i] = ctrl_axis_letter(r[1]);
		return 0;
	}
	rc = assign_rhs(x, s + 2, &query, &v);
	if (rc)
		return rc;
	if (query)
		return var_query(x, x->c->axdes[i]);
	if (v < 0 || v > 7 || v != (int)v)
		return 6;
	x->c->axdes[i] = v;
	return 0;
}

/* "PRA=", "IHT=" ...: a command followed by one axis/handle letter. */
static int is_axis_assign(const char *w, size_t n)
{
	char name[3];

	if (n != 3 || !isupper((unsigned char)w[0]) ||
	    !isupper((unsigned char)w[1]) || !isupper((unsigned char)w[2]))
		return 0;
	memcpy(name, w, 2);
	name[2] = '\0';
	if (!ctrl_cmd_assignable(name))
		return 0;
	return ctrl_axis_letter(w[2]) >= 0 ||
	       (!strcmp(name, "IH") && strchr("ST", w[2]));
}

/*
 * "MTA=", "VDS=": a command of the DMC table (pc/dmc/dmc_cmd.h) followed by
 * an axis or plane letter. A controller never turns these into variables;
 * those galil-sim does not run answer TC 1 (docs/galil-sim-controller.md).
 */
static int is_command_form(const char *w, size_t n)
{
	char name[3];

	if (n != 3 || !isupper((unsigned char)w[0]) ||
	    !isupper((unsigned char)w[1]) || !strchr("ABCDEFGHMNST", w[2]))
		return 0;
	memcpy(name, w, 2);
	name[2] = '\0';
	return dmc_cmd_find(name) != NULL;
}

/* "SPA?" is "SPA=?" (command reference: "n = ?" queries). */
static int axis_query(struct ctrl_xc *x, const char *s)
{
	char name[3], arg[4];

	memcpy(name, s, 2);
	name[2] = '\0';
	snprintf(arg, sizeof(arg), "%c=?", s[2]);
	return ctrl_cmd_dispatch(x, name, arg);
}

static int word_stmt(struct ctrl_xc *x, const char *s)
{
	size_t n = ctrl_ident_len(s);
	const char *after = ctrl_skip(s + n);
	char name[3];

	if ((n == 4 && !strncmp(s, "ELSE", 4)) ||
	    (n == 5 && !strncmp(s, "ENDIF", 5)))
		return ctrl_flow_cmd(x, n == 4 ? "ELSE" : "ENDIF", after);
	if (dmc_is_rem(s, n))
		return 0; /* the one REM rule (dmc_text.h) */
	if (*after == '?' && *ctrl_skip(after + 1) == '\0' &&
	    is_axis_assign(s, n))
		return axis_query(x, s);
	if ((*after == '=' || *after == '[') && !is_axis_assign(s, n) &&
	    !(n == 2 && isupper((unsigned char)s[0]) &&
	      isupper((unsigned char)s[1]))) {
		if (is_command_form(s, n))
			return 1; /* MTA=1, VDS=1: never a variable */
		return var_stmt(x, s, n);
	}
	if (n < 2 || !isupper((unsigned char)s[0]) ||
	    !isupper((unsigned char)s[1]))
		return 1;
	memcpy(name, s, 2);
	name[2] = '\0';
	return ctrl_cmd_dispatch(x, name, s + 2);
}

/*
 * ctrl_exec() - run one statement (no ';').
 * Return: 0, a TC code, CTRL_RETRY or CTRL_STOP.
 */
int ctrl_exec(struct ctrl_xc *x, const char *s)
{
	s = ctrl_skip(s);
	switch (*s) {
	case '\0':
	case '\'': return 0;
	case '#': return x->thread >= 0 ? 0 : 1;
	case '^':
		if (s[1] < 'a' || s[1] > 'h')
			return 1;
		return param_stmt(x, s);
	case '~': return axdes_stmt(x, s);
	}
	if (isalpha((unsigned char)*s))
		return word_stmt(x, s);
	return 1;
}

/* ---- errors ----------------------------------------------------------- */

static void error_message(struct ctrl *c, int stmt)
{
	char text[CTRL_LINE_MAX + 1], msg[CTRL_LINE_MAX + 24];
	int line = c->prog.stmt[stmt].line;

	if (ctrl_prog_stmt_text(&c->prog, stmt, text, sizeof(text)))
		return;
	snprintf(msg, sizeof(msg), "?%d %s\r\n", line, ctrl_skip(text));
	ctrl_unsol_send(c, CTRL_ROUTE_DEFAULT, (const uint8_t *)msg,
			strlen(msg));
}

/*
 * A statement of thread @t failed. With #CMDERR (and not already in it):
 * an erring thread other than 0 is halted, thread 0 resumes after the
 * failing statement; #CMDERR then interrupts thread 0. Without: the error
 * is printed on the unsolicited port and every thread stops (command
 * reference #CMDERR: "the program (and all threads) will stop").
 */
static void thread_error(struct ctrl *c, int t, int stmt, int tc)
{
	int line = c->prog.stmt[stmt].line;
	char why[96];

	c->tc = tc;
	c->ed_line = line;
	c->ed_thread = t;
	ctrl_event(c, "program error thread %d line %d TC %d %s", t, line, tc,
		   ctrl_tc_text(tc));
	snprintf(why, sizeof(why), "error TC %d at line %d in thread %d", tc,
		 line, t);
	if (ctrl_autosub_label(c, CTRL_AS_CMDERR) >= 0 &&
	    !ctrl_autosub_active(c, CTRL_AS_CMDERR)) {
		if (t != 0)
			ctrl_thread_halt(c, t, why);
		else
			c->th[0].pc = stmt + 1;
		ctrl_autosub_raise(c, CTRL_AS_CMDERR);
		ctrl_autosubs_dispatch(c);
		return;
	}
	error_message(c, stmt);
	ctrl_threads_halt_all(c, why);
}

/* ---- the scheduler ------------------------------------------------------ */

static void thread_end(struct ctrl *c, int t)
{
	char why[48];

	snprintf(why, sizeof(why), "end of program at line %d",
		 c->prog.nlines - 1);
	ctrl_thread_halt(c, t, why);
}

/* Run one statement of thread @t. Return 1 to go on with the line. */
static int run_stmt(struct ctrl *c, int t, int line)
{
	struct ctrl_thread *th = &c->th[t];
	struct ctrl_xc x = {c, t, -1, th->pc, CTRL_ROUTE_DEFAULT, 0, 0};
	const char *text = ctrl_prog_stmt(&c->prog, th->pc);
	int i = th->pc, rc;

	th->next_pc = i + 1;
	th->line = line;
	ctrl_buf_clear(&c->tmp);
	rc = ctrl_exec(&x, text);
	if (rc == CTRL_STOP || !th->running)
		return 0;
	if (rc == 0 && ctrl_buf_pending(&c->tmp) &&
	    ctrl_unsol_send(c, x.route, ctrl_buf_data(&c->tmp),
			    ctrl_buf_pending(&c->tmp)) < 0)
		rc = CTRL_RETRY;
	if (rc == CTRL_RETRY) {
		th->wait.kind = CTRL_W_RETRY;
		th->wait.until = c->time + 1;
		return 0;
	}
	if (rc > 0) {
		thread_error(c, t, i, rc);
		return 0;
	}
	th->pc = th->next_pc;
	if (th->pc >= c->prog.nstmts) {
		thread_end(c, t);
		return 0;
	}
	return th->wait.kind == CTRL_W_NONE && th->pc == i + 1 &&
	       c->prog.stmt[th->pc].line == line;
}

/* One line (turn) of thread @t. Return 1 if it used a line. */
static int run_line(struct ctrl *c, int t)
{
	struct ctrl_thread *th = &c->th[t];

	if (!ctrl_wait_done(c, th))
		return 0;
	if (th->pc < 0 || th->pc >= c->prog.nstmts) {
		thread_end(c, t);
		return 1;
	}
	while (run_stmt(c, t, c->prog.stmt[th->pc].line))
		;
	return 1;
}

/* ctrl_threads_run() - the program part of one servo sample. */
void ctrl_threads_run(struct ctrl *c)
{
	int budget = c->lines_per_sample, progress, t;

	ctrl_autosubs_dispatch(c);
	do {
		progress = 0;
		for (t = 0; t < CTRL_THREADS && budget > 0; t++) {
			if (!c->th[t].running || !run_line(c, t))
				continue;
			budget--;
			progress = 1;
			ctrl_autosubs_dispatch(c);
		}
	} while (progress && budget > 0);
}
