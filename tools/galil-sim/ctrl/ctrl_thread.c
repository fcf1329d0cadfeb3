/*
 * ctrl_thread.c - the eight program threads as state: start, halt, the
 * _XQn queries, and the automatic subroutines (#CMDERR #POSERR #LIMSWI
 * #AMPERR #MCTIME #TCPERR: raised, then entered in thread 0); plus the TC
 * texts and the "who ran it" of a statement, which events use.
 *
 * It does not run statements (ctrl_exec.c) nor schedule lines; it never
 * parses program text.
 */
#include <stdio.h>
#include <string.h>

#include "ctrl_thread.h"
#include "ctrl_out.h"
#include "ctrl_prog.h"
#include "ctrl_var.h"

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
    {133, "Handle must be UDP"},
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
int ctrl_autosub_active(const struct ctrl *c, int which)
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
void ctrl_autosubs_dispatch(struct ctrl *c)
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
		if (ctrl_autosub_active(c, w < CTRL_AS_POSERR ? w : -1))
			continue;
		c->autosub_pend[w] = 0;
		enter_autosub(c, w, line);
	}
}

void ctrl_thread_boot(struct ctrl *c)
{
	uint64_t key;
	int line;

	if (!c->auto_pending)
		return;
	c->auto_pending = 0;
	if (ctrl_name_key("AUTO", 4, &key))
		return;
	line = ctrl_prog_label(&c->prog, key);
	if (line < 0)
		return;
	ctrl_thread_start(c, 0, c->prog.first[line]);
	ctrl_event(c, "#AUTO started in thread 0 at line %d", line);
}
