/*
 * ctrl_int.h - internals of the simulated DMC-4030 (ctrl.h), shared by the
 * ctrl_*.c files only. Nothing here is part of the public API.
 *
 * Layout of the controller (tools/galil-sim/ctrl/), in layers: a file
 * calls only files listed above it, never below, so there is no import
 * cycle:
 *   ctrl_num.c    32.16 fixed-point numbers, Galil number formats
 *   ctrl_buf.c    growable byte buffers (replies, unsolicited output)
 *   ctrl_var.c    variables and arrays
 *   ctrl_prog.c   program memory: download checks, statements, labels
 *   ctrl_out.c    events, host output queues, unsolicited routing (CF/CW)
 *   ctrl_thread.c threads as state, automatic subroutines, TC texts
 *   ctrl_motion.c profiler, servo and protection, once per sample
 *   ctrl_axis.c   axis letters, designators, parameter table, _XXa operands
 *   ctrl_oper.c   _operands
 *   ctrl_expr.c   expression evaluator (strictly left to right)
 *   ctrl_args.c   command arguments: axis fields, masks, number lists
 *   ctrl_flow.c   IF/ELSE/ENDIF JP JS EN RE ZS XQ HX and the trippoints
 *   ctrl_mg.c     MG and its formatters
 *   ctrl_axcmd.c  axis commands (SP AC ... PA PR BG ST SH MO TP ...)
 *   ctrl_rec.c    the QR data record
 *   ctrl_store.c  DL into program memory; BP BN BV into flash
 *   ctrl_cmd.c    command table and the general commands
 *   ctrl_exec.c   statement dispatch, run-time errors, the line scheduler
 *   ctrl_proto.c  host handles: framing, DL/UL
 *   ctrl.c        life cycle, ctrl_step(), power cycle
 */
#ifndef SIM_CTRL_INT_H
#define SIM_CTRL_INT_H

#include <stdint.h>
#include <stddef.h>

#include "ctrl.h"

/* Limits of a DMC-40x0 (galil-notes.md 3.4; DMC command reference). */
#define CTRL_LINE_MAX	 80    /* characters per line (host and program) */
#define CTRL_PROG_LINES	 4000  /* program lines */
#define CTRL_LABELS	 510   /* labels */
#define CTRL_VARS	 510   /* variables */
#define CTRL_VAR_SLOTS	 1024  /* hash slots, power of two > 2 * CTRL_VARS */
#define CTRL_ARRAYS	 30    /* arrays */
#define CTRL_ARRAY_SPACE 24000 /* array elements in total */
#define CTRL_STACK_DEPTH 16    /* JS nesting (TC 12) */
#define CTRL_NAME_MAX	 8     /* variable / array name characters */
#define CTRL_LABEL_MAX	 7     /* label characters after '#' */
#define CTRL_NPARAM	 8     /* ^a .. ^h */

/* Model choices (documented in docs/galil-sim-controller.md). */
#define CTRL_LINES_PER_SAMPLE 16   /* program lines per servo sample */
#define CTRL_UNSOL_FIFO	      1024 /* bytes pending on a handle = "FIFO full" */
#define CTRL_OUT_MAX	      (4u << 20) /* bytes kept for a host, at most */
#define CTRL_SERIAL_MAX	      65536 /* bytes kept for the (absent) serial port */
#define CTRL_TV_SAMPLES	      256   /* TV averaging window, samples (~0.25 s) */

#define CTRL_NHANDLES	 (CTRL_HANDLES + 1)
#define CTRL_PRIV_HANDLE CTRL_HANDLES /* ctrl_command()'s private port */
#define CTRL_SERIAL	 (-1)	      /* CF S */

/* Special statement results besides 0 (ok) and TC codes (> 0). */
#define CTRL_RETRY (-1) /* run the same statement again next sample */
#define CTRL_STOP  (-2) /* the running thread was halted (HX, AB) */

/* ---- growable buffer (ctrl_buf.c) ------------------------------------- */

struct ctrl_buf {
	uint8_t *p;
	size_t start; /* first unread byte */
	size_t len;   /* end of data */
	size_t cap;
};

/*
 * ctrl_buf_put() / ctrl_buf_puts() / ctrl_buf_printf() - append @n bytes
 * of @data, the string @s, or printf output (cut to 255 bytes) to @b,
 * growing it; the bytes are copied. A zeroed struct is an empty buffer.
 * Return: 0, or -1 when out of memory (or a format error): nothing added.
 */
int ctrl_buf_put(struct ctrl_buf *b, const void *data, size_t n);
int ctrl_buf_puts(struct ctrl_buf *b, const char *s);
int ctrl_buf_printf(struct ctrl_buf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* ctrl_buf_pending() - bytes of @b not yet taken. */
size_t ctrl_buf_pending(const struct ctrl_buf *b);
/*
 * ctrl_buf_take() - move up to @cap unread bytes of @b into @out (FIFO).
 * Return: the number of bytes copied.
 */
size_t ctrl_buf_take(struct ctrl_buf *b, uint8_t *out, size_t cap);
/* ctrl_buf_clear() - drop the contents of @b, keeping its memory. */
void ctrl_buf_clear(struct ctrl_buf *b);
/* ctrl_buf_free() - release the memory of @b; it is empty and usable. */
void ctrl_buf_free(struct ctrl_buf *b);

/* ---- numbers (ctrl_num.c) ------------------------------------------- */

#define CTRL_FX_ONE 65536.0
#define CTRL_FX_MAX 2147483647.99998474 /* $7FFFFFFF.FFFF */

/* Format of one printed number: F (leading zeros), Z (none), $ (hex). */
struct ctrl_fmt {
	char kind; /* 'F', 'Z', '$', 'S' */
	int m;	   /* digits left of the point (S: characters) */
	int n;	   /* digits right of the point */
};

/*
 * ctrl_fx() - @v on the 32.16 fixed-point grid (1/65536, rounded to
 * nearest), wrapped like a 48-bit register; NaN gives 0.
 * ctrl_fx_raw() - the same as the raw signed 48-bit value (v * 65536);
 * ctrl_fx_from_raw() - a raw value back to a double.
 */
double ctrl_fx(double v);
int64_t ctrl_fx_raw(double v);
double ctrl_fx_from_raw(int64_t raw);
/*
 * ctrl_fmt_num() - print @v in format @f ('F'/'Z': m 0..10, n 0..4; '$':
 * m 1..8, n 0..4; 'S': m 1..6 characters, @cap >= 8) into @out (@cap
 * bytes, NUL-terminated). Return: characters written (snprintf style),
 * or -1 for a bad format.
 */
int ctrl_fmt_num(char *out, size_t cap, double v, const struct ctrl_fmt *f);
/*
 * ctrl_str_value() - the value of a "string": its first 6 of @n
 * characters packed into 48 bits, the first in the top byte.
 */
double ctrl_str_value(const char *s, size_t n);

/* ---- names, variables and arrays (ctrl_var.c) ------------------------ */

struct ctrl_var {
	uint64_t key; /* packed name, 0 = free slot */
	double v;
};

struct ctrl_array {
	uint64_t key; /* 0 = free */
	int n;	      /* elements */
	double *v;
};

struct ctrl_vars {
	struct ctrl_var slot[CTRL_VAR_SLOTS];
	int count;
	struct ctrl_array arr[CTRL_ARRAYS];
	int arr_used; /* elements allocated in total */
};

/* ctrl_ident_len() - length of the run of letters and digits at @s. */
size_t ctrl_ident_len(const char *s);
/*
 * ctrl_name_key() - the key of a variable/array/label name: the @n
 * characters of @s (a letter, then letters or digits, 1..CTRL_NAME_MAX)
 * packed one byte each, first in the low byte, into @key.
 * Return: 0, or TC 9 (variable error) for a bad or too long name.
 * ctrl_key_name() - the name of @key back into @out, NUL-terminated.
 */
int ctrl_name_key(const char *s, size_t n, uint64_t *key);
void ctrl_key_name(uint64_t key, char out[CTRL_NAME_MAX + 1]);
/* ctrl_var_find() - the slot of variable @key in @vs->slot[], or -1. */
int ctrl_var_find(const struct ctrl_vars *vs, uint64_t key);
/*
 * ctrl_var_set() - assign @v to variable @key, creating it if needed.
 * @slot: [out] optional, the variable's slot.
 * Return: 0, or TC 67 when all CTRL_VARS variables are used.
 */
int ctrl_var_set(struct ctrl_vars *vs, uint64_t key, double v, int *slot);
/* ctrl_array_find() - array @key of @vs (owned by @vs), or NULL. */
struct ctrl_array *ctrl_array_find(struct ctrl_vars *vs, uint64_t key);
/*
 * ctrl_array_dim() - DM name[@n]: a new array of @n zeros. An existing
 * array is never re-dimensioned (docs/galil-sim-controller.md).
 * Return: 0, TC 6 (size), TC 57 (exists), TC 66 (array space full or out
 * of memory), TC 67 (too many arrays).
 */
int ctrl_array_dim(struct ctrl_vars *vs, uint64_t key, int n);
/* ctrl_array_free() - DA of array @key. Return: 0, or TC 57 (none). */
int ctrl_array_free(struct ctrl_vars *vs, uint64_t key);
/* ctrl_arrays_free() - how many more arrays may be dimensioned (_DA). */
int ctrl_arrays_free(const struct ctrl_vars *vs);
/* ctrl_vars_clear() - free all arrays and forget all variables of @vs. */
void ctrl_vars_clear(struct ctrl_vars *vs);
/*
 * ctrl_vars_copy() - deep copy of @src into @dst (BV and power-up); @dst
 * is cleared first. Return: 0, or -1 when out of memory (@dst then empty).
 */
int ctrl_vars_copy(struct ctrl_vars *dst, const struct ctrl_vars *src);

/* ---- program memory (ctrl_prog.c) ----------------------------------- */

enum ctrl_flow {
	CTRL_FLOW_NONE,
	CTRL_FLOW_IF,
	CTRL_FLOW_ELSE,
	CTRL_FLOW_ENDIF,
};

struct ctrl_stmt {
	int line;	  /* 0-based program line */
	uint8_t off, len; /* text within the line */
	int text;	  /* the text, NUL-terminated, in pool[] */
	uint8_t flow;	  /* enum ctrl_flow */
	int match;	  /* IF -> its ELSE/ENDIF, ELSE -> ENDIF, or -1 */
};

struct ctrl_label {
	uint64_t key;
	int line;
};

struct ctrl_prog {
	int nlines;
	char (*line)[CTRL_LINE_MAX + 1];
	int *first; /* first statement of each line */
	int nstmts;
	struct ctrl_stmt *stmt;
	int nlabels;
	struct ctrl_label *label; /* sorted by key */
	char *pool;		  /* statement texts */
	size_t pool_len, pool_cap;
};

/*
 * ctrl_prog_load() - check the program text @text (@len bytes, copied) and
 * load it into @p, which must be empty (zeroed or freed).
 * @bad_line: [out] 1-based line of the first error, 0 if none.
 * @tc: [out] its TC code (60, 61, 62 ...).
 * Return: 0, a TC code (p is then empty), or -1 when out of memory.
 */
int ctrl_prog_load(struct ctrl_prog *p, const char *text, size_t len,
		   int *bad_line, int *tc);
/* ctrl_prog_free() - release @p's memory; @p is then empty. */
void ctrl_prog_free(struct ctrl_prog *p);
/*
 * ctrl_prog_copy() - deep copy of @src over @dst (BP, power-up).
 * Return: 0, or -1 when out of memory (@dst unchanged).
 */
int ctrl_prog_copy(struct ctrl_prog *dst, const struct ctrl_prog *src);
/* ctrl_prog_label() - 0-based line of label @key in @p, or -1. */
int ctrl_prog_label(const struct ctrl_prog *p, uint64_t key);
/*
 * ctrl_prog_stmt_text() - statement @i as written in its line, into @out
 * (@cap > CTRL_LINE_MAX). Return: 0, or -1 (bad index or small @cap).
 */
int ctrl_prog_stmt_text(const struct ctrl_prog *p, int i, char *out,
			size_t cap);
/* ctrl_prog_stmt() - the text of statement @i (0 <= i < nstmts), owned by
 * @p. */
const char *ctrl_prog_stmt(const struct ctrl_prog *p, int i);

/* ---- threads and automatic subroutines ------------------------------ */

enum ctrl_wait_kind {
	CTRL_W_NONE,
	CTRL_W_UNTIL, /* WT / AT: TIME >= until */
	CTRL_W_AM,    /* profilers of mask idle */
	CTRL_W_MC,    /* AM plus encoder in position, TW timeout */
	CTRL_W_MF,    /* _TP of axis >= pos */
	CTRL_W_MR,    /* _TP of axis <= pos */
	CTRL_W_AI,    /* input at level */
	CTRL_W_RETRY, /* statement retried (MG into a full FIFO) */
};

struct ctrl_wait {
	int kind;
	int64_t until; /* sample number (W_UNTIL; W_MC timeout) */
	unsigned mask; /* axes */
	int axis, input, level;
	double pos;
};

enum ctrl_autosub {
	CTRL_AS_CMDERR,
	CTRL_AS_POSERR,
	CTRL_AS_LIMSWI,
	CTRL_AS_AMPERR,
	CTRL_AS_MCTIME,
	CTRL_AS_TCPERR,
	CTRL_AS_N,
};

enum ctrl_frame_kind {
	CTRL_FR_JS,
	CTRL_FR_AUTO,
};

struct ctrl_frame {
	int ret_pc;		  /* statement to return to, -1 = end thread */
	int kind;		  /* enum ctrl_frame_kind */
	int autosub;		  /* enum ctrl_autosub for CTRL_FR_AUTO */
	struct ctrl_wait saved;	  /* interrupted trippoint (RE1/EN1) */
	double par[CTRL_NPARAM];  /* ^a..^h of the called routine */
	int16_t ref[CTRL_NPARAM]; /* variable slot when passed by &ref */
	int npar;
};

struct ctrl_thread {
	int running;
	int pc; /* next statement */
	int depth;
	struct ctrl_frame stack[CTRL_STACK_DEPTH];
	struct ctrl_wait wait;
	int64_t at_ref;		  /* AT reference, sample number */
	double js_ret;		  /* _JS */
	double par0[CTRL_NPARAM]; /* ^a..^h outside any subroutine */
	int next_pc;		  /* set while a statement runs */
	int line;		  /* _XQn: line of the current statement */
};

/* ---- axes ----------------------------------------------------------- */

enum ctrl_mode {
	CTRL_MODE_PR,
	CTRL_MODE_PA,
	CTRL_MODE_JG,
	CTRL_MODE_PT,
};

/* Parameters BN burns (with the motor state). */
struct ctrl_axis_par {
	double sp, ac, dc, sd;		   /* counts/s, counts/s^2 */
	double kp, ki, kd, tl, il, of, ov; /* gains; volts */
	double er;			   /* counts, -1 = off */
	double fl, bl;			   /* soft limits, counts */
	int oe, oa, ot, ld;
	double tw; /* MC timeout, ms (-1 = off) */
	int motor_off;
};

struct ctrl_axis {
	struct ctrl_axis_par p;
	/* staged motion */
	double jg, pr, pa;
	int next_mode;	/* enum ctrl_mode for the next BG */
	int pt;		/* position tracking on */
	double za;	/* ZA user field */
	double pa_last; /* _PA: where motion last stopped */
	/* profiler */
	int profiling, stopping, mode;
	double ref, vel, target, stop_dec;
	/* feedback */
	double enc, offset; /* controller counts = plant + offset */
	int lim_f, lim_r;   /* switch active, after CN and LD */
	int stop_code;
	/* servo and protection */
	double err_prev, integ, torque;
	int poserr;    /* |TE| > ER latched until back below */
	int amp_fault; /* amplifier fault seen while enabled */
	int oa_cnt;
	double oa_enc0;
	double tv_ring[CTRL_TV_SAMPLES];
	int tv_i;
};

/* ---- host handles ---------------------------------------------------- */

enum ctrl_hmode {
	CTRL_H_CMD,
	CTRL_H_DL,
};

struct ctrl_handle {
	int open;
	int close_wanted;
	int close_by;	    /* handle whose IH asked, -1: none to wait for */
	char close_why[48]; /* "IHT from handle B", for the event */
	int mode;	    /* enum ctrl_hmode */
	char line[CTRL_LINE_MAX + 1];
	size_t len;	    /* characters in line */
	int overflow;	    /* line longer than CTRL_LINE_MAX */
	int semis;	    /* ';' seen in an overflowing line */
	struct ctrl_buf dl; /* download text */
	int dl_err;	    /* TC of the first bad line, 0 */
	int dl_lines;
	size_t dl_linelen;
	struct ctrl_buf out; /* bytes for the host */
	int local_port, peer_port;
	uint32_t peer_ip;
};

/* ---- what BN / BP / BV keep over a power cycle ----------------------- */

struct ctrl_flash {
	int have_prog;
	struct ctrl_prog prog;
	int have_par;
	struct ctrl_axis_par ax[CTRL_AXES];
	int cw_hibit, cw_drop, cn0, sample_us, vf_m, vf_n, pf_m, pf_n, lz;
	uint32_t outputs;
	int have_vars;
	struct ctrl_vars vars;
};

/* ---- the controller --------------------------------------------------- */

struct ctrl {
	struct ctrl_cfg cfg;
	char model[64];
	int sample_us; /* TM */
	int64_t time;  /* TIME, samples since power-up */
	int lines_per_sample;

	struct ctrl_axis ax[CTRL_AXES];
	struct ctrl_sense in;
	int zero_pending; /* define encoder zero at the next sample */
	uint32_t outputs;
	int amp_ok;  /* motor power present */
	uint8_t ta0; /* _TA0 amplifier status */
	int cn0;     /* CN limit polarity: -1 active low */
	int co;	     /* CO extended I/O configuration (stored only) */

	struct ctrl_prog prog;
	struct ctrl_vars vars;
	struct ctrl_thread th[CTRL_THREADS];
	int autosub_pend[CTRL_AS_N];
	int auto_pending; /* start #AUTO at the next sample */

	int tc;			/* TC and _TC: last error; TC clears it */
	int ed_line, ed_thread; /* _ED, _ED1 */

	int cf;		       /* unsolicited handle 0..7 or CTRL_SERIAL */
	int cw_hibit, cw_drop; /* CW 1 / CW ,1 */
	int vf_m, vf_n, pf_m, pf_n, lz;
	int ia4;	 /* _IA4: handle that lost communication */
	double axdes[8]; /* ~a .. ~h: axis numbers */
	int edepth;	 /* expression nesting, bounded */

	struct ctrl_handle h[CTRL_NHANDLES];
	struct ctrl_buf serial; /* output routed to the serial port */
	struct ctrl_buf tmp;	/* output of the running statement */
	struct ctrl_flash flash;
};

/* Context of one statement: where it came from, where output goes. */
struct ctrl_xc {
	struct ctrl *c;
	int thread; /* 0..7, or -1 for a host command */
	int handle; /* host handle, -1 from a program */
	int stmt;   /* statement index (program), else -1 */
	int route;  /* MG {Ex}: handle, CTRL_SERIAL, or -2 default */
	int binary; /* output is binary (QR): no high bit */
	int dl;	    /* DL was accepted: enter download mode */
};

#define CTRL_ROUTE_DEFAULT (-2)

#define CTRL_WHO_LEN 32
/*
 * ctrl_xc_who() - who runs the statement of @x, as events name it: "handle
 * B" (a host), "thread 0 line 57" (a program thread, 0-based line) or
 * "private port" (ctrl_command()). @buf gets at most @cap bytes
 * (CTRL_WHO_LEN is enough), NUL-terminated. In ctrl_thread.c.
 */
void ctrl_xc_who(const struct ctrl_xc *x, char *buf, size_t cap);

/* ---- axis names and operands (ctrl_axis.c) ---------------------------- */

/* ctrl_axis_letter() - axis index of A..H (X Y Z W = A B C D), or -1. */
int ctrl_axis_letter(char ch);
/*
 * ctrl_axis_desig() - one axis at *p: a letter or ~a..~h; *p moves past it
 * and @axis gets 0..CTRL_AXES-1.
 * Return: 0, TC 1 (not an axis), TC 6 (axis not on a DMC-4030).
 */
int ctrl_axis_desig(struct ctrl_xc *x, const char **p, int *axis);

/* One real-valued axis parameter (SP AC DC SD KP KI KD TL IL OF OV ER FL
 * BL TW): its range and resolution. */
struct ctrl_par_desc {
	char name[3];
	double lo, hi;
	double step;   /* resolution: values are cut to it (to zero) */
	int fmt;       /* CTRL_NUM_* for queries */
	int in_motion; /* may change while the axis profiles */
};

/* One integer axis parameter (LD OA OE OT): its range. */
struct ctrl_ipar_desc {
	char name[3];
	int lo, hi;
};

/*
 * ctrl_par_find() / ctrl_ipar_find() - the table entry of parameter @name
 * ("SP", "OE" ...), static; NULL when @name is not one.
 */
const struct ctrl_par_desc *ctrl_par_find(const char *name);
const struct ctrl_ipar_desc *ctrl_ipar_find(const char *name);
/*
 * ctrl_par_ptr() / ctrl_ipar_ptr() - where parameter @d is kept in @p
 * (units of struct ctrl_axis_par); never NULL for a table entry.
 */
double *ctrl_par_ptr(struct ctrl_axis_par *p, const struct ctrl_par_desc *d);
int *ctrl_ipar_ptr(struct ctrl_axis_par *p, const struct ctrl_ipar_desc *d);
/*
 * ctrl_axis_operand() - _XXa of axis @axis (0..CTRL_AXES-1): state (TP RP
 * TE TD TV TT TS SC MO BG LF LR HM PA PR JG PT DP ZA; counts, counts/s,
 * volts) or a parameter, into @v. Return: 0, or TC 1 (no such operand).
 */
int ctrl_axis_operand(struct ctrl *c, const char *name, int axis, double *v);

/* ---- expressions (ctrl_expr.c) ---------------------------------------- */

/*
 * ctrl_expr() - evaluate the expression at *p into @out, strictly left to
 * right; stops at the first character that is not an operator (',', ')',
 * ']', '{', end ...). Return: 0 or a TC code; *p is advanced only on
 * success.
 */
int ctrl_expr(struct ctrl_xc *x, const char **p, double *out);
/*
 * ctrl_expr_end() - the whole of @s is one expression, into @out.
 * Return: 0, TC 59 (a ')' too many), TC 1 (text after it) or the TC of
 * ctrl_expr().
 */
int ctrl_expr_end(struct ctrl_xc *x, const char *s, double *out);
/* ctrl_skip() - @s past spaces and tabs. */
const char *ctrl_skip(const char *s);
/*
 * ctrl_param_ptr() - where ^a..^h (@i 0..7) of the running thread is kept
 * (its frame, or the variable passed by &ref), owned by the controller;
 * NULL from a host or for a bad @i.
 */
double *ctrl_param_ptr(struct ctrl_xc *x, int i);

/* ---- _operands (ctrl_oper.c) ------------------------------------------ */

/*
 * ctrl_operand() - the _operand at *p ('_' included) into @out, on the
 * 32.16 grid. Return: 0 or a TC code (1: unknown); *p is advanced only on
 * success.
 */
int ctrl_operand(struct ctrl_xc *x, const char **p, double *out);

/* ---- threads and automatic subroutines (ctrl_thread.c) ----------------- */

/* ctrl_tc_text() - the TC1 text of code @tc (static), or "" if unknown. */
const char *ctrl_tc_text(int tc);
/* ctrl_any_running() - 1 when any of the 8 threads runs, else 0. */
int ctrl_any_running(const struct ctrl *c);
/*
 * ctrl_thread_start() - (re)start thread @t (0..7) at statement @pc: its
 * stack, trippoint and parameters are cleared, the AT reference is now.
 */
void ctrl_thread_start(struct ctrl *c, int t, int pc);
/*
 * ctrl_thread_halt() - stop thread @t (0..7) if it runs, with the event
 * "thread t stopped: @why"; ctrl_threads_halt_all() does it for all 8.
 */
void ctrl_thread_halt(struct ctrl *c, int t, const char *why);
void ctrl_threads_halt_all(struct ctrl *c, const char *why);
/* ctrl_thread_line() - _XQn: 0-based line of thread @t, or -1 if stopped. */
int ctrl_thread_line(const struct ctrl *c, int t);
/* ctrl_thread_waiting() - 1 when thread @t runs and waits at a trippoint. */
int ctrl_thread_waiting(const struct ctrl *c, int t);
/*
 * ctrl_autosub_raise() - mark automatic subroutine @which (enum
 * ctrl_autosub) pending; ctrl_autosubs_dispatch() enters pending ones in
 * thread 0 (by priority, #CMDERR may interrupt the others) and drops those
 * the program lacks.
 */
void ctrl_autosub_raise(struct ctrl *c, int which);
void ctrl_autosubs_dispatch(struct ctrl *c);
/* ctrl_autosub_label() - first line of #CMDERR etc. in RAM, or -1. */
int ctrl_autosub_label(const struct ctrl *c, int which);
/* ctrl_autosub_active() - 1 when thread 0 is inside @which (-1: any). */
int ctrl_autosub_active(const struct ctrl *c, int which);


/* ---- command arguments (ctrl_args.c) ---------------------------------- */

/* Arguments "n,n,n" with '?' queries and the "X=n" single axis forms. */
struct ctrl_args {
	int n;		    /* fields present (0..CTRL_AXES) */
	int set[CTRL_AXES]; /* 1 value, 2 query, 0 empty */
	double v[CTRL_AXES];
};
/*
 * ctrl_parse_axis_args() - @a as "n,n,n" (expressions; empty fields skip
 * an axis, '?' asks) or "A=n", "~a=n", "*=n", "A=?" into @out.
 * Return: 0, or a TC code (6: more fields than axes, 1: syntax, or the
 * expression's).
 */
int ctrl_parse_axis_args(struct ctrl_xc *x, const char *a,
			 struct ctrl_args *out);
/*
 * ctrl_parse_mask() - @a as axes "ABC", "B", "~a~b", or "" (all axes) into
 * @mask, bit i = axis i. Return: 0 or the TC code of ctrl_axis_desig().
 */
int ctrl_parse_mask(struct ctrl_xc *x, const char *a, unsigned *mask);
/*
 * ctrl_num_list() - up to @max comma-separated expressions of @a into
 * @v[]; absent fields keep their value. @present: [out] optional, bit i
 * set when field i was given. Return: 0, TC 4 (more than @max fields),
 * TC 1 (syntax) or the expression's TC.
 */
int ctrl_num_list(struct ctrl_xc *x, const char *a, double *v, int max,
		  unsigned *present);
#define CTRL_NUM_VF   0 /* variable format (VF, LZ) */
#define CTRL_NUM_PF   1 /* position format (PF) */
#define CTRL_NUM_INT  2 /* integer */
#define CTRL_NUM_GAIN 3 /* 4 decimals */
/*
 * ctrl_put_num() - @v appended to the statement's output (c->tmp) in format
 * @how (CTRL_NUM_*). Return: 0, or 1 when it cannot be formatted or stored.
 */
int ctrl_put_num(struct ctrl_xc *x, double v, int how);

/* ---- commands (ctrl_cmd.c, ctrl_flow.c, ctrl_axcmd.c, ctrl_mg.c) ------ */

/* A command handler: @name the two letters, @a the argument text. */
typedef int (*ctrl_cmd_fn)(struct ctrl_xc *x, const char *name, const char *a);

/*
 * ctrl_flow_cmd() - the flow and trippoint commands @name (IF ELSE ENDIF
 * JP JS EN RE RI ZS XQ HX WT AT AM MC MF MR AI) with argument text @a.
 * Return: 0 or a TC code.
 */
int ctrl_flow_cmd(struct ctrl_xc *x, const char *name, const char *a);
/*
 * ctrl_wait_done() - 1 when the trippoint of thread @t is satisfied (and
 * then cleared), else 0; an MC past its TW sets stop code 99 and raises
 * #MCTIME.
 */
int ctrl_wait_done(struct ctrl *c, struct ctrl_thread *t);
/*
 * ctrl_goto_line() - continue the running thread at program line @line
 * (0-based). Return: 0, or TC 11 (not a line of the program).
 */
int ctrl_goto_line(struct ctrl_xc *x, double line);
/* ctrl_samples() - servo samples in @ms milliseconds at the current TM,
 * rounded to nearest. */
int ctrl_samples(const struct ctrl *c, double ms);
/*
 * ctrl_axis_cmd() - the axis commands @name (parameters, PA PR JG PT DP ZA
 * BG ST AB SH MO, reports TP TE TD RP TV TT TS SC) with argument text @a;
 * replies go to the statement output. Return: 0 or a TC code.
 */
int ctrl_axis_cmd(struct ctrl_xc *x, const char *name, const char *a);
/*
 * ctrl_mg() - MG with argument text @a: the message formatted into the
 * statement output. Return: 0 or a TC code.
 */
int ctrl_mg(struct ctrl_xc *x, const char *a);
/*
 * ctrl_record() - the QR data record of @c encoded into @buf (@cap bytes).
 * Return: its length, or a negative gl_err (GL_ERR_OVERFLOW: @cap too
 * small).
 */
int ctrl_record(struct ctrl *c, uint8_t *buf, size_t cap);

/* ---- the command table (ctrl_cmd.c) ----------------------------------- */

/*
 * ctrl_cmd_dispatch() - run command @name (two letters) with argument text
 * @a through the command table. Return: 0 or a TC code (1: unknown
 * command, 2: program only, 3: not valid in a program).
 */
int ctrl_cmd_dispatch(struct ctrl_xc *x, const char *name, const char *a);
/* ctrl_cmd_assignable() - 1 when command @name takes the single-axis
 * "XXa=n" form, else 0. */
int ctrl_cmd_assignable(const char *name);

/* ---- statements (ctrl_exec.c) ----------------------------------------- */

/*
 * ctrl_exec() - run one statement @s (no ';') in the context @x; output
 * goes to c->tmp. Return: 0, a TC code, CTRL_RETRY or CTRL_STOP.
 */
int ctrl_exec(struct ctrl_xc *x, const char *s);
/*
 * ctrl_threads_run() - the program part of one servo sample: the running
 * threads get program lines round robin, c->lines_per_sample in all;
 * automatic subroutines are entered, run-time errors handled.
 */
void ctrl_threads_run(struct ctrl *c);


/* ---- output (ctrl_out.c) ---------------------------------------------- */

/*
 * ctrl_event() - format one event line (printf style, no CR LF, cut to 199
 * characters) and hand it to cfg.event; nothing when cfg.event is NULL.
 */
void ctrl_event(struct ctrl *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/*
 * ctrl_out_put() - queue @n bytes of @p for host handle @h (0..8, not
 * checked). Past CTRL_OUT_MAX bytes pending the bytes are dropped, with an
 * event. The bytes are copied; @p stays the caller's.
 */
void ctrl_out_put(struct ctrl *c, int h, const void *p, size_t n);
/*
 * ctrl_unsol_send() - unsolicited bytes to @route (a handle 0..7,
 * CTRL_SERIAL, or CTRL_ROUTE_DEFAULT: the CF handle); high bit set under
 * CW 1; a closed handle drops them. @p is copied.
 * Return: 0 (sent or dropped), -1 when the FIFO is full and CW ,0 asks the
 * thread to wait.
 */
int ctrl_unsol_send(struct ctrl *c, int route, const uint8_t *p, size_t n);

/* ---- host protocol (ctrl_proto.c) -------------------------------------- */

/*
 * ctrl_proto_reset() - power cycle: every open host handle is to be
 * closed, all host and serial output and downloads are dropped.
 */
void ctrl_proto_reset(struct ctrl *c);
/*
 * ctrl_proto_host() - a complete command line @line (no CR) from handle
 * @h (0..8): run its commands and queue their replies.
 * Return: the number of commands that answered '?'.
 */
int ctrl_proto_host(struct ctrl *c, int h, const char *line);

/* ---- motion (ctrl_motion.c) ------------------------------------------- */

/*
 * ctrl_motion_sense() - take the plant's sample @in (encoders, switches,
 * inputs, motor power); ctrl_motion_sample() - protection, profiler and
 * servo of one sample; ctrl_motion_drive() - what goes to the plant, in
 * plant coordinates, into @out.
 */
void ctrl_motion_sense(struct ctrl *c, const struct ctrl_sense *in);
void ctrl_motion_sample(struct ctrl *c);
void ctrl_motion_drive(struct ctrl *c, struct ctrl_drive *out);
/*
 * ctrl_motion_begin() - BG of axis @axis (0..2) with its staged mode.
 * @dry_run: only check. Return: 0, TC 20 (motor off), 21 (already
 * moving), 22 (a limit in the way), 7 (position tracking).
 */
int ctrl_motion_begin(struct ctrl *c, int axis, int dry_run);
/*
 * ctrl_motion_stop() - decelerate axis @axis at @dec counts/s^2, stop code
 * @code (ST: 4, which also leaves position tracking).
 */
void ctrl_motion_stop(struct ctrl *c, int axis, int code, double dec);
/*
 * ctrl_motion_abort() - AB of axis @axis: the reference stops at once
 * (event "axis A abort: AB (@who)"); with OE set the motor goes off.
 */
void ctrl_motion_abort(struct ctrl *c, int axis, const char *who);
/*
 * ctrl_motion_off() - motor off for axis @axis; @code: stop code to set
 * (-1: keep), @why: for the event.
 */
void ctrl_motion_off(struct ctrl *c, int axis, int code, const char *why);
/*
 * ctrl_motion_pt_target() - PA in position tracking: retarget axis @axis
 * to @target counts on the fly. Return: 0.
 */
int ctrl_motion_pt_target(struct ctrl *c, int axis, double target);
/* ctrl_axis_tv() - _TV of @a, counts/s, over the last CTRL_TV_SAMPLES
 * samples of @dt seconds. */
double ctrl_axis_tv(const struct ctrl_axis *a, double dt);
/* ctrl_dt() - the servo sample period in seconds (TM). */
double ctrl_dt(const struct ctrl *c);
/* ctrl_blocked_dir() - 1 when motion of @a in direction @dir (-1, 0, 1)
 * is refused by a limit switch or a soft limit (FL/BL), else 0. */
int ctrl_blocked_dir(const struct ctrl_axis *a, int dir);

/* ---- program memory and flash (ctrl_store.c) ------------------------- */

/*
 * ctrl_burn_program() / ctrl_burn_vars() - BP / BV: copy the program /
 * the variables and arrays in RAM to flash, with an event.
 * Return: 0, or -1 when out of memory (flash keeps what it had).
 */
int ctrl_burn_program(struct ctrl *c);
int ctrl_burn_vars(struct ctrl *c);
/* ctrl_burn_params() - BN: axis parameters and settings to flash. */
void ctrl_burn_params(struct ctrl *c);
/*
 * ctrl_load_program() - replace program memory with @len bytes of @text
 * (copied); on a refused text the memory is left empty, TC set, and
 * @bad_line gets the 1-based line refused. Events either way.
 * Return: 0 or the TC code (60 61 62 63 ...).
 */
int ctrl_load_program(struct ctrl *c, const char *text, size_t len,
		      int *bad_line);

/* ---- life cycle helpers (ctrl.c) -------------------------------------- */

/* ctrl_axis_defaults() - @p set to the factory settings of an axis. */
void ctrl_axis_defaults(struct ctrl_axis_par *p);

#endif /* SIM_CTRL_INT_H */
