/*
 * re_check.h - the supervisor's safety checks as pure functions.
 *
 * Everything here works on plain structs: no I/O, no clock reads (times are
 * passed in as monotonic nanoseconds), no allocation, no printing. The
 * supervisor (pc/roboelf.c) calls these every cycle and acts on the verdict;
 * the calibration code calls the re_cal_check_*() functions while it builds a
 * table. Decisions (table ends, persistence counting, watchdog edges) are
 * documented in docs/calibration-file.md, section 2.
 *
 * Verdicts: functions that judge return RE_OK (0), RE_WARN (1: log only) or
 * RE_FAULT (2), or a negative gl_err code (GL_ERR_ARG) for a caller bug.
 * A RE_FAULT verdict always comes with a filled struct re_fault; format it
 * with re_fault_format() into the one FAULT line the operator sees.
 */
#ifndef RE_CHECK_H
#define RE_CHECK_H

#include <limits.h>
#include <stddef.h>
#include <stdint.h>

#include "gl_record.h"

#define RE_CAL_MAX_POINTS 1024 /* points per axis table */
#define RE_CAL_MAX_AXES	  8    /* axes per calibration set */

/* How far beyond either table end the end segment is extrapolated. */
#define RE_CAL_EXTRAP_STEPS 1

enum re_verdict {
	RE_OK = 0,
	RE_WARN = 1,  /* non-critical: log, keep running */
	RE_FAULT = 2, /* latch: relay open, motors off */
};

/*
 * One axis's calibration table. Encoder positions are implicit: point i is at
 * start_counts + i * step_counts. pot_v[i] is the potentiometer in volts
 * there, strictly increasing (see re_cal_check_table()).
 */
struct re_caltable {
	int n;		     /* points, 2..RE_CAL_MAX_POINTS */
	double start_counts; /* encoder position of point 0, counts */
	double step_counts;  /* encoder step between points, counts, > 0 */
	double pot_v[RE_CAL_MAX_POINTS]; /* potentiometer, volts */
	double soft_rev;		 /* reverse soft limit (BL), counts */
	double soft_fwd;		 /* forward soft limit (FL), counts */
};

/* ---- faults ------------------------------------------------------------- */

enum re_fclass {
	RE_FC_NONE = 0,
	RE_FC_ENCODER,
	RE_FC_WATCHDOG,
	RE_FC_ESTOP,
	RE_FC_MOTION,
	RE_FC_INPUT,
	RE_FC_COMM,
	RE_FC_CONFIG,
	RE_FC_CALIBRATION,
	RE_FC_PARAM,
	RE_FC_LIMIT,
	RE_FC_PROGRAM,
	RE_FC_FOREIGN, /* another program or client at the controller */
	RE_FC_COUNT
};

/*
 * Every fault the supervisor can report. Each has one entry in the message
 * table in re_check.c: its class, a "what happened" template and a
 * "Recovery:" template. The list says which fields of struct re_fault each
 * text uses (a = axis name, i0..i3 integers, f0..f3 reals, s = text):
 *
 * ENCODER
 *   RE_F_ENCPOT          a; i0 encoder counts, i1 violating cycles;
 *                        f0 pot V, f1 expected V, f2 |diff| V, f3 tol V
 *   RE_F_ENC_OUTSIDE     a; i0 encoder counts; i1..i2 calibrated travel
 *   RE_F_CTRL_ENCODER    a; i0 stop code (controller fault 9)
 * WATCHDOG
 *   RE_F_WDOG_REPLY      i0 ms since the last good reply, i1 limit ms
 *   RE_F_WDOG_HEARTBEAT  i0 hbdmc value, i1 ms frozen, i2 limit ms
 *   RE_F_WDOG_SAMPLE     i0 sample number, i1 ms frozen, i2 limit ms
 *   RE_F_CTRL_WATCHDOG   i0 ms without hbpc change (controller fault 2)
 * ESTOP
 *   RE_F_ESTOP_LOST      s: relay port and reason
 * MOTION
 *   RE_F_MOTOR_OFF       a; i0 stop code; s: re_stop_reason()
 *   RE_F_CTRL_POSERR     a; i0 position error counts (fault 4)
 *   RE_F_CTRL_AMPERR     a; i0 stop code (fault 8, one axis)
 *   RE_F_CTRL_POWER      (fault 8 on every axis: motor power cut)
 *   RE_F_CTRL_MOTOROFF   a; i0 stop code; s: re_stop_reason() (fault 10)
 * INPUT
 *   RE_F_CTRL_INPUT      i0 raw switch word jraw (fault 3)
 * COMM
 *   RE_F_COMM            s: what failed ("cannot read record: timeout")
 *   RE_F_CTRL_TCPERR     i0 handle number _IA4 (fault 7)
 *   RE_F_RECORD          i0 ZAB, i1 ZAC: program fields out of range
 * CONFIG
 *   RE_F_CONFIG          s: what differs ("read-back of KPA differs")
 * CALIBRATION
 *   RE_F_CAL_NONMONO     a; i0 point; f0 previous V, f1 this V, f2 margin V
 *   RE_F_CAL_RANGE       a; f0 measured range V, f1 expected V, f2 tol %
 *   RE_F_CAL_POINTS      a; i0 points, i1 min, i2 max
 *   RE_F_CAL_ENCSTEP     a; i0 point; f0 advance, f1 step, f2 tol (counts)
 *   RE_F_CAL_LIMITS      a; f0 soft_rev, f1 soft_fwd, f2..f3 travel counts
 *   RE_F_CAL_ABORT       a; s: why (limit never came, position error ...)
 * PARAM
 *   RE_F_CTRL_PARAM      i0 number of the failed parameter check (fault 1)
 * LIMIT
 *   RE_F_CTRL_LIMIT      a; i0 2 forward / 3 reverse; s "forward"/"reverse"
 * PROGRAM
 *   RE_F_CTRL_CMDERR     i0 _TC error code (fault 6)
 *   RE_F_CTRL_THREAD     (fault 11: thread 1 stopped)
 *   RE_F_CTRL_SUPERVISOR (fault 12: pcflt)
 *   RE_F_CTRL_UNKNOWN    i0 fcode, i1 faxis, i2 fdet
 *   RE_F_THREAD          i0 thread number, i1 thread bits
 *   RE_F_STATE           i0 program state seen (0 = disarmed/restarted)
 *   RE_F_PROGRAM_ID      s: why the program identity check failed
 * (version 2.00 of the program and the supervisor's own cross-checks)
 *   RE_F_CTRL_UNCMD      MOTION; a; s: what moved (fault 13, detail 1, 2)
 *   RE_F_CTRL_SAFE_ON    FOREIGN; (fault 13 detail 3: a motor switched on
 *                        in the safe state)
 *   RE_F_CTRL_FOREIGN_HB FOREIGN; (fault 14 detail 1: heartbeat not ours)
 *   RE_F_CTRL_FOREIGN_SET FOREIGN; s: what was changed (fault 14 detail
 *                        3 wdto/jto, 4 OE)
 *   RE_F_CTRL_SVCMOVE    MOTION; a; s: why (fault 15, detail 1..7)
 *   RE_F_CTRL_POTRANGE   ENCODER; a; f0 volts (fault 16)
 *   RE_F_UNCMD           MOTION; a; s: what the supervisor saw
 *   RE_F_STALL           WATCHDOG; i0 ms this supervisor did not run,
 *                        i1 limit ms
 *   RE_F_RELAY_POWER     ESTOP; s: the relay's answer (power lost on
 *                        every axis while the relay was meant closed, and
 *                        the relay board does not confirm it)
 *   RE_F_CTRL_STATE      PROGRAM; i0 state seen; s: the state expected
 *   RE_F_CAL_ABSOLUTE    CALIBRATION; a; s "reverse"/"forward"; f0 pot V
 *                        at that end, f1 expected V, f2 tolerance V
 */
enum re_fault_id {
	RE_F_NONE = 0,
	RE_F_ENCPOT,
	RE_F_ENC_OUTSIDE,
	RE_F_CTRL_ENCODER,
	RE_F_WDOG_REPLY,
	RE_F_WDOG_HEARTBEAT,
	RE_F_WDOG_SAMPLE,
	RE_F_CTRL_WATCHDOG,
	RE_F_ESTOP_LOST,
	RE_F_MOTOR_OFF,
	RE_F_CTRL_POSERR,
	RE_F_CTRL_AMPERR,
	RE_F_CTRL_MOTOROFF,
	RE_F_CTRL_INPUT,
	RE_F_COMM,
	RE_F_CTRL_TCPERR,
	RE_F_RECORD,
	RE_F_CONFIG,
	RE_F_CAL_NONMONO,
	RE_F_CAL_RANGE,
	RE_F_CAL_POINTS,
	RE_F_CAL_ENCSTEP,
	RE_F_CAL_LIMITS,
	RE_F_CAL_ABORT,
	RE_F_CTRL_PARAM,
	RE_F_CTRL_LIMIT,
	RE_F_CTRL_CMDERR,
	RE_F_CTRL_THREAD,
	RE_F_CTRL_SUPERVISOR,
	RE_F_CTRL_UNKNOWN,
	RE_F_THREAD,
	RE_F_STATE,
	RE_F_PROGRAM_ID,
	RE_F_CTRL_POWER,
	RE_F_CTRL_UNCMD,
	RE_F_CTRL_SAFE_ON,
	RE_F_CTRL_FOREIGN_HB,
	RE_F_CTRL_FOREIGN_SET,
	RE_F_CTRL_SVCMOVE,
	RE_F_CTRL_POTRANGE,
	RE_F_UNCMD,
	RE_F_STALL,
	RE_F_RELAY_POWER,
	RE_F_CTRL_STATE,
	RE_F_CAL_ABSOLUTE,
	RE_F_COUNT
};

/* An integer value that is not known: printed as "unknown". */
#define RE_VAL_UNKNOWN LLONG_MIN

/* One fault, described by values; the text is made by re_fault_format(). */
struct re_fault {
	enum re_fault_id id;
	int axis;	/* 0-based axis index, -1 when none */
	long long i[4]; /* integer values, see enum re_fault_id */
	double f[4];	/* real values, see enum re_fault_id */
	char s[128];	/* free text detail, NUL-terminated */
};

/*
 * re_fault_class() - the class of a fault.
 * Return: the class, RE_FC_NONE for RE_F_NONE or an unknown id.
 */
enum re_fclass re_fault_class(enum re_fault_id id);

/*
 * re_fault_class_name() - "ENCODER", "WATCHDOG", ... ("NONE" for unknown).
 * Return: a static string, never NULL.
 */
const char *re_fault_class_name(enum re_fclass cls);

/*
 * re_fault_set() - clear @f and set its id and axis (convenience).
 * @f: [out] the fault.
 */
void re_fault_set(struct re_fault *f, enum re_fault_id id, int axis);

/*
 * re_fault_format() - the operator's FAULT line, without a newline:
 *   "FAULT <CLASS>: <what happened>. Recovery: <what to do>"
 * @f: [in] the fault.
 * @axis_names: [in] names indexed by axis, or NULL for "A", "B", "C" ...
 * @buf: [out] always NUL-terminated when @cap > 0 (truncated if too small).
 * @cap: capacity of @buf; 256 bytes is always enough for the templates with
 *       a short @f->s.
 * Return: the length written (>= 0), GL_ERR_OVERFLOW when truncated, or
 *         GL_ERR_ARG for NULL arguments or an unknown id.
 */
int re_fault_format(const struct re_fault *f, const char *const *axis_names,
		    char *buf, size_t cap);

/*
 * re_fault_what() - only the "what happened" part of the fault's text (no
 * class, no recovery), e.g. for a "FILE:LINE: <what>" message.
 * Return: as re_fault_format().
 */
int re_fault_what(const struct re_fault *f, const char *const *axis_names,
		  char *buf, size_t cap);

/*
 * re_fault_template() - the raw templates of a fault (for docs and tests).
 * @what, @recovery: [out] static strings, may be NULL.
 * Return: GL_OK or GL_ERR_ARG for an unknown id.
 */
int re_fault_template(enum re_fault_id id, const char **what,
		      const char **recovery);

/* ---- encoder / potentiometer -------------------------------------------- */

enum re_tpos {
	RE_TPOS_INSIDE = 0, /* between point 0 and point n-1 */
	RE_TPOS_EXTRAP,	    /* beyond an end by <= EXTRAP_STEPS steps */
	RE_TPOS_OUTSIDE,    /* further out: not a valid comparison */
};

struct re_expect {
	double pot_v;  /* expected potentiometer, volts */
	double step_v; /* |pot[i+1] - pot[i]| of segment seg, V */
	int seg;       /* segment index i (0..n-2) */
	enum re_tpos where;
};

/*
 * re_cal_expect() - expected potentiometer at an encoder position.
 * Linear interpolation between the two table points around @enc_counts; at
 * exactly a point, that point's value. Beyond an end by at most
 * RE_CAL_EXTRAP_STEPS steps the end segment is extrapolated (where =
 * RE_TPOS_EXTRAP); further out where = RE_TPOS_OUTSIDE and pot_v is the
 * extrapolated value all the same (informational).
 * @t: [in] the table (n >= 2, step_counts > 0).
 * @enc_counts: encoder position, counts.
 * @out: [out] the expectation.
 * Return: GL_OK, or GL_ERR_ARG for NULL, n < 2, n too big or step <= 0.
 */
int re_cal_expect(const struct re_caltable *t, double enc_counts,
		  struct re_expect *out);

/* Per-axis state of the encoder/pot check; zero it before the first cycle. */
struct re_encpot_state {
	int violations; /* consecutive violating cycles so far */
};

struct re_encpot_cfg {
	double allowed_error;	/* fraction; tolerance = (1 + it) * step_v */
	int persistence_cycles; /* violations tolerated, >= 0 */
};

struct re_encpot_result {
	struct re_expect exp;
	double diff_v;	 /* |measured - expected|, volts */
	double tol_v;	 /* (1 + allowed_error) * step_v, volts */
	double margin_v; /* tol_v - diff_v; negative while violating */
	int violating;	 /* this cycle is a violation */
	int violations;	 /* consecutive violations including this one */
};

/*
 * re_check_encpot() - one cycle of the encoder/potentiometer check, one axis.
 * A cycle violates when diff_v > tol_v (strictly), the position is
 * RE_TPOS_OUTSIDE, or a reading is not finite (NaN is never "within"). The
 * state counts consecutive violations and is reset to 0 by a cycle within
 * tolerance. The verdict is RE_FAULT when the count exceeds
 * @cfg->persistence_cycles (so persistence 1 trips on the 2nd consecutive
 * violating cycle, persistence 0 on the first); RE_OK otherwise.
 * @axis: axis index for the fault.
 * @fault: [out] filled on RE_FAULT (RE_F_ENCPOT or RE_F_ENC_OUTSIDE); may be
 *         NULL.
 * Return: RE_OK, RE_FAULT, or GL_ERR_ARG (bad table/config; state untouched).
 *         Callers must treat GL_ERR_ARG as a fault too (fail safe).
 */
int re_check_encpot(const struct re_caltable *t,
		    const struct re_encpot_cfg *cfg, int axis,
		    double enc_counts, double pot_v, struct re_encpot_state *st,
		    struct re_encpot_result *res, struct re_fault *fault);

/* ---- watchdog ------------------------------------------------------------ */

struct re_wdog_cfg {
	int64_t period_ns;     /* supervisor cycle period */
	double noncrit_factor; /* e.g. 1.5: above -> RE_WARN (log only) */
	double crit_factor;    /* e.g. 2.5: above -> RE_FAULT */
};

/*
 * re_wdog_limits() - the two limits in ns, rounded to the nearest ns.
 * Return: GL_OK, GL_ERR_ARG when period <= 0 or not 1 <= noncrit <= crit.
 */
int re_wdog_limits(const struct re_wdog_cfg *cfg, int64_t *noncrit_ns,
		   int64_t *crit_ns);

/*
 * re_check_reply_age() - the PC side of the watchdog (GalilWatchdog).
 * age = now_ns - last_good_ns. RE_FAULT when age > crit limit (strictly),
 * RE_WARN when age > non-critical limit, else RE_OK. At exactly 1.5 x period
 * the verdict is still RE_OK; at exactly 2.5 x period still RE_WARN.
 * @age_ns: [out] the age, may be NULL.
 * @fault: [out] RE_F_WDOG_REPLY on RE_FAULT (ms values), may be NULL.
 * Return: the verdict, or GL_ERR_ARG (bad cfg, now < last_good).
 */
int re_check_reply_age(const struct re_wdog_cfg *cfg, int64_t last_good_ns,
		       int64_t now_ns, int64_t *age_ns, struct re_fault *fault);

/*
 * Liveness of the controller: the program heartbeat hbdmc (ZAA) and the
 * record's sample number must change. Each is a fault when unchanged for
 * longer than its limit, measured from the time the value was first seen.
 * Feed only freshly received records (a missing reply is the reply-age
 * check's business). Zero the state (or re_alive_reset()) when the program
 * is (re)started.
 */
struct re_alive_cfg {
	int64_t hb_limit_ns;	 /* e.g. crit_factor x max(period, mainms) */
	int64_t sample_limit_ns; /* e.g. crit_factor x period */
};

struct re_alive_state {
	int seen;	     /* 0 until the first record */
	int32_t hb;	     /* last hbdmc */
	uint16_t sample;     /* last sample number */
	int64_t hb_since_ns; /* when hb took its current value */
	int64_t sample_since_ns;
};

/* re_alive_reset() - forget the history (next record starts afresh). */
void re_alive_reset(struct re_alive_state *st);

/*
 * re_check_alive() - one cycle of the liveness check.
 * RE_FAULT (RE_F_WDOG_HEARTBEAT, checked first, or RE_F_WDOG_SAMPLE) when the
 * value has been unchanged for > limit (strictly) at @now_ns.
 * Return: RE_OK, RE_FAULT or GL_ERR_ARG (NULL, limits <= 0, time going back).
 */
int re_check_alive(const struct re_alive_cfg *cfg, struct re_alive_state *st,
		   int64_t now_ns, int32_t hbdmc, uint16_t sample,
		   struct re_fault *fault);

/* ---- data record: the program's ZA fields and the axes ------------------- */

enum re_dmc_state {
	RE_DMC_UNARMED = 0, /* safe: motors off */
	RE_DMC_ARMED = 1,
	RE_DMC_FAULT = 2,
	RE_DMC_SERVICE = 3, /* supervised automatic moves (calibration) */
};

/* Controller fault codes (docs/dmc-interface.md "Fault codes"). */
enum re_dmc_fcode {
	RE_DMC_F_NONE = 0,
	RE_DMC_F_PARAM = 1,
	RE_DMC_F_WATCHDOG = 2,
	RE_DMC_F_INPUT = 3,
	RE_DMC_F_POSERR = 4,
	RE_DMC_F_LIMIT = 5,
	RE_DMC_F_CMDERR = 6,
	RE_DMC_F_TCPERR = 7,
	RE_DMC_F_AMPERR = 8,
	RE_DMC_F_ENCODER = 9,
	RE_DMC_F_MOTOROFF = 10,
	RE_DMC_F_THREAD = 11,
	RE_DMC_F_SUPERVISOR = 12,
	RE_DMC_F_UNCMD = 13,	/* motion the program did not command */
	RE_DMC_F_FOREIGN = 14,	/* heartbeat out of sequence, settings */
	RE_DMC_F_SVCMOVE = 15,	/* a service move out of its bounds */
	RE_DMC_F_POTRANGE = 16, /* potentiometer outside its range */
	RE_DMC_F_MAX = 16,
};

struct re_za {
	int32_t hbdmc; /* ZAA */
	int state;     /* ZAB % 10 */
	int fcode;     /* (ZAB / 10) % 100 */
	int faxis;     /* ZAB / 1000: 1..3 = A..C, 0 none */
	int jraw;      /* ZAC % 4096 */
	int jcmd;      /* (ZAC / 4096) % 8 - 1: -1 invalid, 0, 1..6 */
	int mcmd;      /* ZAC / 32768: 0..6 */
};

/*
 * re_za_decode() - decode ZAA, ZAB, ZAC (axes A, B, C's user fields).
 * @out: [out] filled only on success.
 * Return: GL_OK; GL_ERR_RANGE when a field is negative or a decoded value is
 *         outside its range (state > 3, fcode > 16, faxis > 3, jcmd > 6,
 *         mcmd > 6, hbdmc > 999999); GL_ERR_ARG on NULL.
 */
int re_za_decode(int32_t zaa, int32_t zab, int32_t zac, struct re_za *out);

/*
 * re_stop_reason() - text for a stop code: 8 "position error above the
 * limit", 12 "encoder failure", 15 "amplifier fault", 2 "forward limit", 3
 * "reverse limit", 4 "stop command", 7 "abort command", 6 "abort input", ...
 * Return: a static string, never NULL ("unexpected stop" for others).
 */
const char *re_stop_reason(int stop_code);

/*
 * re_fault_is_ctrl() - @id is a fault the controller program latched (one
 * that re_ctrl_fault() produces).
 * Return: 1 or 0.
 */
int re_fault_is_ctrl(enum re_fault_id id);

/*
 * re_ctrl_fault() - turn a latched controller fault (state 2) into a fault.
 * @za: [in] decoded fields; fcode, faxis used.
 * @fdet: the detail (MG fdet), or RE_VAL_UNKNOWN when not read.
 * @fault: [out] the matching RE_F_CTRL_* (RE_F_CTRL_UNKNOWN for code 0 or an
 *         unknown code); axis = faxis - 1.
 * Return: GL_OK, GL_ERR_ARG on NULL.
 */
int re_ctrl_fault(const struct re_za *za, long long fdet,
		  struct re_fault *fault);

/*
 * re_check_motors() - Check_MotorsActive: while the supervisor expects the
 * motors on, an axis with the motor-off status bit is a MOTION fault
 * (RE_F_MOTOR_OFF) naming the stop code's reason. The first such axis wins.
 * @rec: [in] the decoded record; @n_axes: axes to check (<= rec->n_axes).
 * @expect_on: 0 -> always RE_OK.
 * Return: RE_OK, RE_FAULT, GL_ERR_ARG.
 */
int re_check_motors(const struct gl_record *rec, int n_axes, int expect_on,
		    struct re_fault *fault);

/*
 * re_check_record() - every record check in priority order, for one cycle:
 *  1. ZA fields decode (RE_F_RECORD);
 *  2. controller fault latched: state 2, or fcode != 0 (latching in
 *     progress) -> re_ctrl_fault() with fdet RE_VAL_UNKNOWN;
 *  3. thread 0 must run (RE_F_THREAD);
 *  4. @expect RE_DMC_ARMED: state 1 (RE_F_STATE), thread 1 running
 *     (RE_F_THREAD), motors on (re_check_motors); @expect RE_DMC_SERVICE:
 *     state 3 (RE_F_CTRL_STATE), motors on; any other @expect (0): no more.
 * The record must have at least 3 axes (ZAA..ZAC).
 * @expect: the program state the supervisor expects (0: nothing more).
 * @za: [out] decoded fields when step 1 passed (may be NULL).
 * Return: RE_OK, RE_FAULT, GL_ERR_ARG.
 */
int re_check_record(const struct gl_record *rec, int n_axes, int expect,
		    struct re_za *za, struct re_fault *fault);

/* ---- calibration-time checks --------------------------------------------- */

struct re_calcheck_cfg {
	double noise_margin_v;	 /* rise per point must exceed it, >= 0 */
	double expected_range_v; /* pot[n-1] - pot[0] expected, > 0 */
	double range_tol;	 /* fraction of expected_range_v, e.g. 0.1 */
	int min_points;		 /* >= 2 */
	int max_points;		 /* <= RE_CAL_MAX_POINTS */
	double step_tol_counts;	 /* allowed |advance - step|, counts, >= 0 */
	/* the end values against the potentiometer's expected absolute
	 * readings there (0 tolerance: not checked) */
	double abs_first_v;   /* expected pot at point 0, V */
	double abs_last_v;    /* expected pot at point n-1, V */
	double abs_tol_v;     /* allowed |pot - expected| there, V */
};

/*
 * re_cal_check_point() - checks for point @index (>= 1) as it is recorded:
 * the encoder advanced by step +- step_tol_counts since the previous point
 * (RE_F_CAL_ENCSTEP: jammed axis, slipping encoder), and the potentiometer
 * rose by more than noise_margin_v (RE_F_CAL_NONMONO):
 *   pot_v - prev_pot_v > noise_margin_v.
 * Return: RE_OK, RE_FAULT (fault filled), GL_ERR_ARG.
 */
int re_cal_check_point(const struct re_calcheck_cfg *cfg, int axis, int index,
		       double step_counts, double prev_enc_counts,
		       double enc_counts, double prev_pot_v, double pot_v,
		       struct re_fault *fault);

/*
 * re_cal_check_table() - checks on a whole table (after calibration, and on
 * load from a file), first failure reported:
 *  - min_points <= n <= max_points (RE_F_CAL_POINTS);
 *  - step_counts > 0, values finite, strictly increasing by more than
 *    noise_margin_v (RE_F_CAL_NONMONO, point index named);
 *  - |(pot[n-1] - pot[0]) - expected| <= range_tol x expected
 *    (RE_F_CAL_RANGE);
 *  - soft limits inside the travel: start - step <= soft_rev < soft_fwd <=
 *    start + (n - 1 + 1) x step (RE_F_CAL_LIMITS);
 *  - when abs_tol_v > 0: |pot[0] - abs_first_v| <= abs_tol_v and
 *    |pot[n-1] - abs_last_v| <= abs_tol_v (RE_F_CAL_ABSOLUTE: an offset
 *    present before the sweep, a wrong pot, wrong wiring).
 * Return: RE_OK, RE_FAULT, GL_ERR_ARG (NULL or bad cfg).
 */
int re_cal_check_table(const struct re_calcheck_cfg *cfg, int axis,
		       const struct re_caltable *t, struct re_fault *fault);

#endif /* RE_CHECK_H */
