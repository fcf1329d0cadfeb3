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

#include "ctrl_int.h"

static const struct {
	int tc;
	const char *text;
} tc_table[] = {
    {1, "Unrecognized command"},
    {2, "Command only valid from program"},
    {3, "Command not valid in program"},
    {4, "Operand error"},
    {5, "Input buffer full"},
    {6, "Number out of range"},
    {7, "Command not valid while running"},
    {8, "Command not valid while not running"},
    {9, "Variable error"},
    {10, "Empty program line or undefined label"},
    {11, "Invalid label or line number"},
    {12, "Subroutine more than 16 deep"},
    {13, "JG only valid when running in jog mode"},
    {16, "IP incorrect sign during position move or IP given during "
	 "forced deceleration"},
    {17, "ED, BN and DL not valid while program running"},
    {19, "Application strand already executing"},
    {20, "Begin not valid with motor off"},
    {21, "Begin not valid while running"},
    {22, "Begin not possible due to Limit Switch"},
    {50, "Not enough fields"},
    {51, "Question mark not valid"},
    {52, "Missing \" or string too long"},
    {53, "Error in {}"},
    {54, "Question mark part of string"},
    {55, "Missing [ or []"},
    {56, "Array index invalid or out of range"},
    {57, "Bad function or array"},
    {59, "Mismatched parentheses"},
    {60, "Download error - line too long or too many lines"},
    {61, "Duplicate or bad label"},
    {62, "Too many labels"},
    {63, "IF statement without ENDIF"},
    {66, "Array space full"},
    {67, "Too many arrays or variables"},
    {123, "TCP lost sync"},
    {126, "Closed Ethernet handle"},
    {134, "All motors must be in MO for this command"},
};

const char *ctrl_tc_text(int tc)
{
	size_t i;

	for (i = 0; i < sizeof(tc_table) / sizeof(tc_table[0]); i++)
		if (tc_table[i].tc == tc)
			return tc_table[i].text;
	return "";
}

/*
 * ctrl_xc_who() - who runs the statement of @x, as events name it: "handle
 * B" (a host), "thread 0 line 57" (a program thread, 0-based line) or
 * "private port" (ctrl_command()). @buf gets at most @cap bytes.
 */
void ctrl_xc_who(const struct ctrl_xc *x, char *buf, size_t cap)
{
	if (x->thread >= 0)
		snprintf(buf, cap, "thread %d line %d", x->thread,
			 x->c->th[x->thread].line);
	else if (x->handle >= 0 && x->handle < CTRL_HANDLES)
		snprintf(buf, cap, "handle %c", 'A' + x->handle);
	else
		snprintf(buf, cap, "private port");
}

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

static int word_stmt(struct ctrl_xc *x, const char *s)
{
	size_t n = ctrl_ident_len(s);
	const char *after = ctrl_skip(s + n);
	char name[3];

	if ((n == 4 && !strncmp(s, "ELSE", 4)) ||
	    (n == 5 && !strncmp(s, "ENDIF", 5)))
		return ctrl_flow_cmd(x, n == 4 ? "ELSE" : "ENDIF", after);
	if (n >= 3 && !strncmp(s, "REM", 3))
		return 0;
	if ((*after == '=' || *after == '[') && !is_axis_assign(s, n) &&
	    !(n == 2 && isupper((unsigned char)s[0]) &&
	      isupper((unsigned char)s[1])))
		return var_stmt(x, s, n);
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

/* ---- threads ----------------------------------------------------------- */

int ctrl_any_running(const struct ctrl *c)
{
	int t;

	for (t = 0; t < CTRL_THREADS; t++)
		if (c->th[t].running)
			return 1;
	return 0;
}

void ctrl_thread_start(struct ctrl *c, int t, int pc)
{
	struct ctrl_thread *th = &c->th[t];

	memset(th, 0, sizeof(*th));
	th->running = 1;
	th->pc = pc;
	th->at_ref = c->time;
	th->line = pc < c->prog.nstmts ? c->prog.stmt[pc].line : 0;
}

void ctrl_thread_halt(struct ctrl *c, int t, const char *why)
{
	struct ctrl_thread *th = &c->th[t];

	if (!th->running)
		return;
	th->running = 0;
	th->depth = 0;
	th->wait.kind = CTRL_W_NONE;
	ctrl_event(c, "thread %d stopped: %s", t, why);
}

void ctrl_threads_halt_all(struct ctrl *c, const char *why)
{
	int t;

	for (t = 0; t < CTRL_THREADS; t++)
		ctrl_thread_halt(c, t, why);
}

/* ctrl_thread_line() - _XQn: current line, or -1 when not running. */
int ctrl_thread_line(const struct ctrl *c, int t)
{
	const struct ctrl_thread *th = &c->th[t];

	if (!th->running || c->prog.nstmts == 0)
		return -1;
	return th->line;
}

int ctrl_thread_waiting(const struct ctrl *c, int t)
{
	return c->th[t].running && c->th[t].wait.kind != CTRL_W_NONE;
}

/* ---- automatic subroutines ----------------------------------------- */

static const char *const autosub_name[CTRL_AS_N] = {
    "CMDERR", "POSERR", "LIMSWI", "AMPERR", "MCTIME", "TCPERR",
};

/* ctrl_autosub_label() - line of #CMDERR etc. in the program, or -1. */
int ctrl_autosub_label(const struct ctrl *c, int which)
{
	const char *n = autosub_name[which];
	uint64_t key;

	if (ctrl_name_key(n, strlen(n), &key))
		return -1;
	return ctrl_prog_label(&c->prog, key);
}

void ctrl_autosub_raise(struct ctrl *c, int which)
{
	c->autosub_pend[which] = 1;
}

/* Is thread 0 inside automatic subroutine @which (-1: any)? */
static int in_autosub(const struct ctrl *c, int which)
{
	const struct ctrl_thread *th = &c->th[0];
	int i;

	if (!th->running)
		return 0;
	for (i = 0; i < th->depth; i++)
		if (th->stack[i].kind == CTRL_FR_AUTO &&
		    (which < 0 || th->stack[i].autosub == which))
			return 1;
	return 0;
}

static void enter_autosub(struct ctrl *c, int which, int line)
{
	struct ctrl_thread *th = &c->th[0];
	struct ctrl_frame *f;

	if (!th->running) {
		ctrl_thread_start(c, 0, c->prog.first[line]);
		th->depth = 1;
		th->stack[0].ret_pc = -1;
	} else {
		if (th->depth >= CTRL_STACK_DEPTH) {
			ctrl_event(c, "#%s not run: thread 0 stack full",
				   autosub_name[which]);
			return;
		}
		f = &th->stack[th->depth++];
		f->ret_pc = th->pc;
		f->saved = th->wait;
		th->wait.kind = CTRL_W_NONE;
		th->pc = c->prog.first[line];
	}
	f = &th->stack[th->depth - 1];
	f->kind = CTRL_FR_AUTO;
	f->autosub = which;
	f->npar = 0;
	memset(f->par, 0, sizeof(f->par));
	memset(f->ref, 0xff, sizeof(f->ref));
	ctrl_event(c, "#%s running in thread 0", autosub_name[which]);
}

/*
 * Start pending automatic subroutines in thread 0 (running or not). An
 * automatic subroutine does not interrupt another one, except #CMDERR,
 * which interrupts any but itself. Priority: the enum order.
 */
static void dispatch_autosubs(struct ctrl *c)
{
	int w, line;

	for (w = 0; w < CTRL_AS_N; w++) {
		if (!c->autosub_pend[w])
			continue;
		line = ctrl_autosub_label(c, w);
		if (line < 0) {
			c->autosub_pend[w] = 0;
			continue;
		}
		if (in_autosub(c, w < CTRL_AS_POSERR ? w : -1))
			continue;
		c->autosub_pend[w] = 0;
		enter_autosub(c, w, line);
	}
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
	    !in_autosub(c, CTRL_AS_CMDERR)) {
		if (t != 0)
			ctrl_thread_halt(c, t, why);
		else
			c->th[0].pc = stmt + 1;
		ctrl_autosub_raise(c, CTRL_AS_CMDERR);
		dispatch_autosubs(c);
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
	    ctrl_unsol_send(c, x.route, c->tmp.p + c->tmp.start,
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

	dispatch_autosubs(c);
	do {
		progress = 0;
		for (t = 0; t < CTRL_THREADS && budget > 0; t++) {
			if (!c->th[t].running || !run_line(c, t))
				continue;
			budget--;
			progress = 1;
			dispatch_autosubs(c);
		}
	} while (progress && budget > 0);
}
