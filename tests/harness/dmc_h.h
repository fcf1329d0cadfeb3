/*
 * dmc_h.h - test harness for the DMC programs in dmc/ on galil-sim's
 * in-process API, in virtual time.
 *
 * It loads dmc/ the way galil-load does (files in dmc/MANIFEST order,
 * comments and blank lines stripped), downloads the result into a fresh
 * simulator, configures the controller the way the supervisor does, writes
 * the program parameters, keeps the PC heartbeat going while time advances,
 * and collects the program's unsolicited lines (MG) from handle A.
 *
 * Every function that can fail returns 0 or a negative gl_err code and puts
 * a message in h->err; tests print it with fail_msg(). Nothing here prints.
 */
#ifndef DMC_H_H
#define DMC_H_H

#include <stddef.h>

#include "gl_err.h"
#include "re_seal.h"
#include "sim.h"

#define DMC_H_AXES	3
#define DMC_H_SWITCHES	12
#define DMC_H_UNSOL_MAX 16384 /* unsolicited text kept, bytes */
#define DMC_H_PROG_MAX	65536 /* preprocessed program, bytes */

/* The program parameters (docs/dmc-interface.md), as the supervisor writes
 * them; dmc_h_params_default() fills the values the tests start from. */
struct dmc_h_params {
	double vmin[DMC_H_AXES], vmax[DMC_H_AXES]; /* counts/s */
	double wst[DMC_H_AXES], wen[DMC_H_AXES];   /* ms */
	double stp[DMC_H_AXES];			   /* counts */
	double srev[DMC_H_AXES], sfwd[DMC_H_AXES]; /* counts */
	double jin[DMC_H_SWITCHES];		   /* input numbers */
	double jval[6];				   /* codes */
	double jpol, jto, wdto;			   /* -, ms, ms */
	double er[DMC_H_AXES];			   /* controller ER, counts */
	int oe; /* controller OE for every axis */
	/* version 2.00: service state, potentiometer range, power output */
	double hbmaxd, pwrout;			      /* -, output no. */
	double potin[DMC_H_AXES];		      /* analog input no. */
	double potlo[DMC_H_AXES], pothi[DMC_H_AXES];  /* V */
	double pnlo[DMC_H_AXES], pnhi[DMC_H_AXES];    /* V */
	double svmax[DMC_H_AXES], svslow[DMC_H_AXES]; /* counts/s */
	double svdmax[DMC_H_AXES];		      /* counts */
};

struct dmc_h {
	struct sim *sim;
	struct ctrl *ctrl;
	int hb_on;		   /* 1: write hbpc every hb_period_ms */
	double hb_period_ms;	   /* 50 (the supervisor's default period) */
	double hb_next_ms;	   /* simulated time of the next write */
	long hb;		   /* last value written */
	char prog[DMC_H_PROG_MAX]; /* the program downloaded, sealed */
	size_t prog_len;
	struct re_seal seal;	     /* its seal table */
	char unsol[DMC_H_UNSOL_MAX]; /* unsolicited text, NUL-terminated */
	size_t unsol_len;
	char err[512];
};

/*
 * dmc_h_load_program() - read dmc/MANIFEST under @top (the repository
 * root; NULL: $ROBOELF_TOP or ".") and preprocess its files in order with
 * galil-load's preprocessor (gload_prep), without the identity line.
 * @out, @cap: [out] the joined program.
 * @err: [out] "PATH: reason" on failure.
 * Return: the program length, GL_ERR_NOENT (a file missing),
 * GL_ERR_OVERFLOW, GL_ERR_FORMAT (empty manifest).
 */
int dmc_h_load_program(const char *top, char *out, size_t cap, char *err,
		       size_t errlen);

/*
 * dmc_h_open() - a fresh simulator (default robot) with motor power on,
 * handle A open with CF A so the program's MG lines are collected, the
 * program downloaded (not started), heartbeat off.
 * Return: 0 or a gl_err code (message in h->err).
 */
int dmc_h_open(struct dmc_h *h);

/* dmc_h_close() - free the simulator. */
void dmc_h_close(struct dmc_h *h);

/*
 * dmc_h_cmd() - one command line through ctrl_command().
 * @resp: [out] optional reply (may be NULL).
 * Return: 0, or GL_ERR_CTRL for '?' (h->err has the line and TC1 text).
 */
int dmc_h_cmd(struct dmc_h *h, const char *line, char *resp, size_t cap);

/*
 * dmc_h_start() - "XQ #AUTO,0" and wait (<= 200 ms simulated) until the
 * program is unarmed (state 0) with its heartbeat advancing.
 * Return: 0, GL_ERR_CTRL, GL_ERR_TIMEOUT.
 */
int dmc_h_start(struct dmc_h *h);

/* dmc_h_params_default() - the parameters every test starts from: the
 * default robot's joystick map, vmax 10000/10000/8000 counts/s, vmin a
 * quarter of it, window 500..2000 ms, step 1000 counts, soft limits 5000
 * counts inside the limit switches, jto 500 ms, wdto 125 ms, ER 500, OE 1;
 * hbmaxd 5, no power output, potentiometers on inputs 1..3 with the
 * absolute range 0.25..4.75 V and the near zones below 1.0 V / above
 * 4.0 V; service speed vmax, slow speed vmax / 4, longest move 200000. */
void dmc_h_params_default(struct dmc_h_params *p);

/*
 * dmc_h_sealed_program() - the program galil-load would download with the
 * seal made from @p and the controller's settings as they are now (the
 * test's configuration stands in for roboelf.yaml).
 * @out, @cap: [out] the program text (no identity line); @seal: [out]
 * its seal table (may be NULL).
 * Return: its length, or a gl_err code (h->err).
 */
int dmc_h_sealed_program(struct dmc_h *h, const struct dmc_h_params *p,
			 char *out, size_t cap, struct re_seal *seal);

/*
 * dmc_h_configure() - what galil-load and the supervisor do before arming:
 * ER and OE on the controller; the program sealed with @p and the
 * controller's settings now (downloaded again, and restarted when it was
 * running, when that differs from the program it holds: #SEALIN sets the
 * parameters); the soft limits srev/sfwd written and read back.
 * Settings a test changes after this call are changes to the seal.
 * Return: 0 or a gl_err code.
 */
int dmc_h_configure(struct dmc_h *h, const struct dmc_h_params *p);

/*
 * dmc_h_arm() - heartbeat on, armreq=1, wait (<= 1000 ms) until state
 * leaves 0, then 30 ms more (thread 1 sees the joystick neutral before
 * the test presses it). Return: 0 when armed (state 1), GL_ERR_CTRL when
 * the program latched a fault instead (state 2), GL_ERR_TIMEOUT.
 */
int dmc_h_arm(struct dmc_h *h);

/*
 * dmc_h_service() - heartbeat on, svcreq=1, wait (<= 1000 ms) until state
 * leaves 0. Return: 0 in service (state 3), GL_ERR_CTRL when the program
 * latched a fault instead, GL_ERR_TIMEOUT.
 */
int dmc_h_service(struct dmc_h *h);

/*
 * dmc_h_move() - one service move request: axis @axis (0..2) to the
 * absolute @target (counts) at @speed (counts/s) within @limit_ms, then
 * wait (<= 3 mainms) until the program took it (mvreq back to 0).
 * Return: 0 when taken and no fault latched; GL_ERR_CTRL when a fault
 * (h->err: code, axis, detail); GL_ERR_TIMEOUT.
 */
int dmc_h_move(struct dmc_h *h, int axis, double target, double speed,
	       double limit_ms);

/*
 * dmc_h_setup() - dmc_h_open, dmc_h_start, default parameters,
 * dmc_h_configure, dmc_h_arm: an armed robot at rest.
 */
int dmc_h_setup(struct dmc_h *h);

/*
 * dmc_h_setup_with() - dmc_h_setup() with the controller settings
 * @settings (one command line, e.g. "OA 1,1,1;OT 20,20,20", or NULL) made
 * before the program is sealed and armed: the test's configuration.
 */
int dmc_h_setup_with(struct dmc_h *h, const char *settings);

/*
 * dmc_h_advance() - run @ms of simulated time; while h->hb_on, hbpc gets a
 * new value every hb_period_ms; unsolicited output is collected.
 */
void dmc_h_advance(struct dmc_h *h, double ms);

/* dmc_h_now() - simulated time, ms. */
double dmc_h_now(const struct dmc_h *h);

/* dmc_h_var() - a program variable or array element; NAN if unknown. */
double dmc_h_var(struct dmc_h *h, const char *name);

/* dmc_h_set() - ctrl_set_var(); Return: 0 or GL_ERR_NOENT. */
int dmc_h_set(struct dmc_h *h, const char *name, double v);

/* dmc_h_axis() - ctrl_axis_info() of axis 0..2 (zeroed on error). */
struct ctrl_axis_info dmc_h_axis(struct dmc_h *h, int axis);

/*
 * dmc_h_control() - one control-port request ("joy A fwd"); 0 or
 * GL_ERR_ARG (h->err holds the answer).
 */
int dmc_h_control(struct dmc_h *h, const char *req);

/*
 * dmc_h_wait_var() - advance 1 ms at a time until @name == @value (within
 * 1e-6) or @timeout_ms passed.
 * Return: simulated ms waited, or -1 on timeout.
 */
double dmc_h_wait_var(struct dmc_h *h, const char *name, double value,
		      double timeout_ms);

/*
 * dmc_h_wait_motor_off() - advance 1 ms at a time until every axis in
 * @mask (bit i = axis i) is motor-off. Return: ms waited, or -1.
 */
double dmc_h_wait_motor_off(struct dmc_h *h, unsigned mask, double timeout_ms);

/*
 * dmc_h_fault_lines() - number of "FAULT" lines received so far; the
 * first one parsed into @code, @axis, @detail (each may be NULL).
 */
int dmc_h_fault_lines(const struct dmc_h *h, int *code, int *axis,
		      double *detail);

/* dmc_h_unsol_has() - 1 if a received line starts with @prefix. */
int dmc_h_unsol_has(const struct dmc_h *h, const char *prefix);

/*
 * dmc_h_za() - the ZA fields the program published, decoded as the
 * supervisor does (docs/dmc-interface.md). Any pointer may be NULL.
 * Return: 0 or GL_ERR_NOENT (record fields not readable).
 */
struct dmc_h_za {
	long hbdmc;
	int state, fcode, faxis;
	long hb_echo; /* the accepted heartbeat's echo (program 2.23) */
	int jraw, jcmd, mcmd, mneut;
};
int dmc_h_za(struct dmc_h *h, struct dmc_h_za *za);

/*
 * cmocka fixtures (no cmocka dependency here): *state becomes a zeroed
 * struct dmc_h (dmc_h_fx_new) or an armed robot at rest (dmc_h_fx_armed,
 * dmc_h_setup()); dmc_h_fx_free closes and frees it.
 * Return: 0, or -1 (message on stderr) so that cmocka fails the test.
 */
int dmc_h_fx_new(void **state);
int dmc_h_fx_armed(void **state);
int dmc_h_fx_free(void **state);

/* DMC_H_CHECK() - in a cmocka test: fail with h->err when @expr < 0. */
#define DMC_H_CHECK(h, expr)                                                   \
	do {                                                                   \
		if ((expr) < 0)                                                \
			fail_msg("%s: %s", #expr, (h)->err);                   \
	} while (0)

/* dmc_h_ramp_vel() - the ramp's velocity formula (docs/dmc-interface.md
 * "Motion rules") at @t_ms after the
 * first sight of a command, for axis @ax of @p. */
double dmc_h_ramp_vel(const struct dmc_h_params *p, int ax, double t_ms);

#endif /* DMC_H_H */
