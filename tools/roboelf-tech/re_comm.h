/*
 * re_comm.h - the commissioning run (roboelf-tech commission DIR): the first
 * contact with a controller and a robot, step by step, motor power off
 * until a step needs it (docs/technician.md, section 8).
 *
 * Steps, in order; the run stops at the first step that fails, with what
 * was seen, what it means and the fix:
 *   1 needs      before anything is asked of the technician: the relay
 *                answers, the controller answers, and it holds the program
 *                galil-load stamped and sealed with this configuration,
 *                which starts (the motion step runs in it)
 *   2 identity   the controller's model, firmware, serial, handles (^R^V,
 *                MG _BN, ID, TH, WH) - reported, the model checked
 *   3 firmware   every behaviour of the firmware dmc/ and the supervisor
 *                rely on, each by a probe whose expected answer is quoted
 *                from the command reference (re_comm_fw.c)
 *   4 joystick   each command's two switches asked for in turn and seen on
 *                the configured inputs (swapped pair, dead switch, wrong
 *                polarity named as such)
 *   5 pots       each potentiometer at rest: range and noise
 *   6 limits     each limit switch reads inactive at rest, then each is
 *                asked for in turn (tripped by hand) and seen on its input
 *   7 relay      the relay closes and opens motor power, seen as the
 *                amplifiers' under-voltage on the controller (_TA0 bit 3)
 *   8 motion     the controller program started and in its service state
 *                (its watchdog, bounds and fault handling on), per axis a
 *                small torque-limited move each way asked of it: the
 *                encoder counts with the motor, the potentiometer moves in
 *                the configured direction; then, with the program halted,
 *                two bounded direct probes (MO refused while moving, PT)
 * Motor power is switched on only in steps 7 and 8, each time after the
 * technician confirmed it, and is off again at the end of the step.
 *
 * The run talks to the controller through struct re_io (the supervisor's
 * binding), to the relay through re_relay, and to the technician through
 * struct re_comm_ui. Nothing here prints; the report (re_comm_report.h)
 * is written from struct re_comm afterwards. Start-up code: no cycle.
 */
#ifndef RE_COMM_H
#define RE_COMM_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>

#include "re_config.h"
#include "re_io.h"
#include "re_relay.h"

#define RE_COMM_ITEMS	96
#define RE_COMM_TEXT	384
#define RE_COMM_FIX	256
#define RE_COMM_NOISE_N 50  /* potentiometer samples at rest */
#define RE_COMM_TRACE_N 400 /* samples of one axis's move */
#define RE_COMM_IDTEXT	1024
#define RE_COMM_MOVE_CPS 2000 /* speed of a small move, counts/s */

enum re_comm_res {
	RE_COMM_PASS = 0, /* as expected */
	RE_COMM_NOTE,	  /* differs from the reference or unconfirmed, and
			   * our programs are safe on either reading */
	RE_COMM_FAIL,	  /* the run stops here */
};

/* One line of the report: a probe or a check of one step. */
struct re_comm_item {
	char step[16]; /* "identity", "firmware", ... */
	char name[48]; /* e.g. "mo-moving", "A fwd" */
	enum re_comm_res res;
	char text[RE_COMM_TEXT]; /* what was sent, expected, seen */
	char fix[RE_COMM_FIX];	 /* for a FAIL: what to do */
};

/* The technician's side: @say shows one line (a prompt or progress);
 * @confirm asks a yes/no question and returns 1 for yes, 0 for no or no
 * answer (end of input). */
struct re_comm_ui {
	void *ud;
	void (*say)(void *ud, const char *line);
	int (*confirm)(void *ud, const char *question);
};

/* One axis's small move and the way back: time (ms after the first
 * request), encoder, potentiometer; what was asked, for the plot's
 * target and expected lines. */
struct re_comm_trace {
	int n;
	int counts;	  /* the move asked for, counts (back: -counts) */
	int back_i;	  /* the first sample of the way back, 0: none */
	double t_back_ms; /* when the way back was asked for */
	double t0_ms;	  /* rc_now_ms() of the first request */
	double enc0;	  /* encoder before the move, counts */
	double pot0_v;	  /* potentiometer before the move (mean), V */
	double t_ms[RE_COMM_TRACE_N];
	double enc[RE_COMM_TRACE_N];
	double pot_v[RE_COMM_TRACE_N];
};

/* What a hand-operated step saw, as lanes: the set of switches (bit i:
 * lane i) at each change, and when the technician was asked for what;
 * times in ms from the step's start. For the step's plot. */
#define RE_COMM_LANE_N 256
#define RE_COMM_ASK_N  32
struct re_comm_lanes {
	int n, n_ask;
	double t0_ms;  /* rc_now_ms() at the step's start */
	double end_ms; /* the last sample */
	double t_ms[RE_COMM_LANE_N];
	unsigned mask[RE_COMM_LANE_N];
	double ask_ms[RE_COMM_ASK_N];
	char ask[RE_COMM_ASK_N][24];
};

struct re_comm {
	/* in */
	const struct re_io *io;
	gl_link *link; /* the same link, for UL; NULL: not probed */
	re_relay *relay;
	const struct re_config *cfg;
	struct re_comm_ui ui;
	int wait_ms;	 /* deadline of one thing the technician does */
	int move_counts; /* each small move, counts (default 2000) */
	/* non-zero: stop at the next wait (a signal handler sets it) */
	const volatile sig_atomic_t *quit;
	/* out */
	struct re_comm_item item[RE_COMM_ITEMS];
	int n;
	const char *failed_step; /* NULL when every step passed */
	bool power_on_seen;	 /* motor power was switched on */
	long hbpc;		 /* the heartbeat in the service state */
	int guard;	/* the probes run under #PRWD: every wait writes hbpc */
	char model[64]; /* in: ^R^V (re_ctl_identify()) */
	long serial;	/* in: MG _BN */
	char id_text[RE_COMM_IDTEXT]; /* ID */
	char th_text[RE_COMM_IDTEXT]; /* TH */
	double noise_v[RE_AXES][RE_COMM_NOISE_N];
	int noise_n;
	struct re_comm_trace trace[RE_AXES];
	/* the joystick's 12 switches, the 6 limit switches; the relay step:
	 * bit 0 the relay on, bit 1 the amplifiers see power */
	struct re_comm_lanes joy, lim, amp;
};

/*
 * re_comm_init() - defaults for @c: zeroed results, wait_ms 60000,
 * move_counts 2000. The caller then sets io, relay, cfg and ui.
 */
void re_comm_init(struct re_comm *c);

/*
 * re_comm_run() - every step in order, until one fails. The controller
 * must be connected and halted with every motor off (re_ctl_halt()) and
 * configured (re_ctl_configure()); the relay open and off.
 * On return the motors are off (AB 1;MO ABC sent) and the relay off, on
 * every path. c->item holds every probe and check, c->failed_step the
 * step that stopped the run.
 * Return: GL_OK when every step passed (notes allowed); GL_ERR_MISMATCH
 *         when a step failed; a link or relay error that stopped the run
 *         (also recorded as a FAIL item).
 */
int re_comm_run(struct re_comm *c);

/* re_comm_res_name() - "PASS", "NOTE" or "FAIL". */
const char *re_comm_res_name(enum re_comm_res res);

#endif /* RE_COMM_H */
