/*
 * ctrl_int.h - the data model of the simulated DMC-4030 (ctrl.h): its
 * limits and model choices and the types of its state (struct ctrl and its
 * parts), shared by the ctrl_*.c files only. Nothing here is part of the
 * public API, and no function is declared here: each ctrl_<name>.c
 * declares its functions in ctrl_<name>.h, and a file includes the
 * headers of the files it calls.
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
 *   ctrl_stream.c DR: the data record as a stream to a UDP handle
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
#include "dmc_model.h"

/* Limits of a DMC-40x0: from the one model table (pc/dmc/dmc_model.h). */
#define CTRL_LINE_MAX	 DMC_LINE_MAX	 /* characters per line */
#define CTRL_PROG_LINES	 DMC_40X0_LINES	 /* program lines */
#define CTRL_LABELS	 DMC_40X0_LABELS /* labels */
#define CTRL_VARS	 DMC_40X0_VARS	 /* variables */
#define CTRL_VAR_SLOTS	 1024  /* hash slots, power of two > 2 * CTRL_VARS */
#define CTRL_ARRAYS	 30    /* arrays */
#define CTRL_ARRAY_SPACE 24000 /* array elements in total */
#define CTRL_STACK_DEPTH 16    /* JS nesting (TC 12) */
#define CTRL_NAME_MAX	 DMC_NAME_MAX  /* variable / array name characters */
#define CTRL_LABEL_MAX	 DMC_LABEL_MAX /* label characters after '#' */
#define CTRL_NPARAM	 8	       /* ^a .. ^h */

/* Model choices (documented in docs/galil-sim-controller.md). */
#define CTRL_LINES_PER_SAMPLE 16   /* program lines per servo sample */
#define CTRL_UNSOL_FIFO	      1024 /* bytes pending on a handle = "FIFO full" */
#define CTRL_OUT_MAX	      (4u << 20) /* bytes kept for a host, at most */
#define CTRL_SERIAL_MAX	      65536 /* bytes kept for the (absent) serial port */
#define CTRL_TV_SAMPLES	      256   /* TV averaging window, samples (~0.25 s) */
#define CTRL_DR_MIN	      2 /* DR n0 at least (gclib's DMC-40x0 clamp) */
#define CTRL_DR_MAX	      30000 /* DR n0 at most (choice) */
#define CTRL_DR_QUEUE	      64    /* stream records waiting for net/ */
#define CTRL_REC_MAX	      370   /* record bytes, >= GL_REC_MAX_BYTES */

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

/* ---- numbers (ctrl_num.c) ------------------------------------------- */

#define CTRL_FX_ONE 65536.0
#define CTRL_FX_MAX 2147483647.99998474 /* $7FFFFFFF.FFFF */

/* Format of one printed number: F (leading zeros), Z (none), $ (hex). */
struct ctrl_fmt {
	char kind; /* 'F', 'Z', '$', 'S' */
	int m;	   /* digits left of the point (S: characters) */
	int n;	   /* digits right of the point */
};

/* Number formats of the replies, for ctrl_put_num() and the parameter
 * table. */
#define CTRL_NUM_VF   0 /* variable format (VF, LZ) */
#define CTRL_NUM_PF   1 /* position format (PF) */
#define CTRL_NUM_INT  2 /* integer */
#define CTRL_NUM_GAIN 3 /* 4 decimals */

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
	double mt; /* motor type: 1 servo, -1 reversed servo, 2.. stepper */
	int oe, oa, ot, ld;
	int ce; /* encoder configuration: stored (galil-sim models quadrature)
		 */
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
	int udp; /* a UDP session (_IHh2 1), else TCP (2) */
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

/* ---- DR: records waiting to be sent (ctrl_stream.c) ------------------ */

struct ctrl_stream_rec {
	int handle; /* where it goes */
	uint16_t len;
	uint8_t b[CTRL_REC_MAX];
};

struct ctrl_stream {
	int n;	  /* _DR0: samples between records, 0 = off */
	int h;	  /* _DR1: the handle 0..7 */
	int left; /* samples until the next record */
	int head, count;
	struct ctrl_stream_rec q[CTRL_DR_QUEUE];
	uint64_t lost; /* records dropped because the queue was full */
	uint64_t made; /* records queued since the DR that started it */
};

/* ---- what BN / BP / BV keep over a power cycle ----------------------- */

struct ctrl_flash {
	int have_prog;
	struct ctrl_prog prog;
	int have_par;
	struct ctrl_axis_par ax[CTRL_AXES];
	int cw_hibit, cw_drop, cn0, cn[4], sample_us, vf_m, vf_n, pf_m, pf_n,
	    lz;
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
	int cn[4];   /* CN n1..n4: home polarity, latch, abort, abort end */
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
	struct ctrl_stream dr;	/* DR */
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

/* Bytes ctrl_xc_who() (ctrl_thread.h) needs at most. */
#define CTRL_WHO_LEN 32

#endif /* SIM_CTRL_INT_H */
