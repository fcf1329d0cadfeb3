/*
 * re_check.h - the supervisor's cycle checks as pure functions: encoder
 * against potentiometer, the reply age (watchdog), the program and record
 * alive, the record's state and motors.
 *
 * Everything here works on plain structs: no I/O, no clock reads (times are
 * passed in as monotonic nanoseconds), no allocation, no printing. The
 * supervisor (re_super) calls these every cycle and acts on the verdict.
 * The fault catalogue is re_fault.h, the DMC contract re_dmcif.h, the
 * calibration-time checks re_calcheck.h. Decisions (table ends, persistence
 * counting, watchdog edges) are documented in docs/calibration-file.md,
 * section 2.
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
#include "re_dmcif.h"
#include "re_fault.h"

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

/*
 * re_caltable_ok() - @t is a usable table: not NULL, 2..RE_CAL_MAX_POINTS
 * points, a finite start and a finite step > 0 counts.
 * Return: 1 or 0.
 */
int re_caltable_ok(const struct re_caltable *t);

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

/* The two reply-age limits, ns: derived once (re_wdog_limits(), called by
 * the plan, pc/config/re_plan.c) and read from there everywhere. */
struct re_wdog_lim {
	int64_t noncrit_ns; /* above: RE_WARN (log only) */
	int64_t crit_ns;    /* above: RE_FAULT */
};

/*
 * re_wdog_limits() - the two limits in ns, rounded to the nearest ns: the
 * one place they are computed from the factors and the period.
 * Return: GL_OK, GL_ERR_ARG when period <= 0 or not 1 <= noncrit <= crit.
 */
int re_wdog_limits(const struct re_wdog_cfg *cfg, struct re_wdog_lim *out);

/*
 * re_check_reply_age() - the PC side of the watchdog (GalilWatchdog).
 * age = now_ns - last_good_ns. RE_FAULT when age > crit limit (strictly),
 * RE_WARN when age > non-critical limit, else RE_OK. At exactly 1.5 x period
 * the verdict is still RE_OK; at exactly 2.5 x period still RE_WARN.
 * @age_ns: [out] the age, may be NULL.
 * @fault: [out] RE_F_WDOG_REPLY on RE_FAULT (ms values), may be NULL.
 * Return: the verdict, or GL_ERR_ARG (not 0 < noncrit <= crit, now <
 *         last_good).
 */
int re_check_reply_age(const struct re_wdog_lim *lim, int64_t last_good_ns,
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

#endif /* RE_CHECK_H */
