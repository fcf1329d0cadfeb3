/*
 * re_calib.h - calibration on the controller (the original's Home and
 * BuildTables, with its gaps closed): build the encoder/potentiometer tables
 * and the soft limits, or check tables loaded from a file against the robot.
 *
 * Every move is a service move: requested from the controller program
 * (mvtg, mvsp, mvax, mvreq), which checks its speed, distance, time and the
 * potentiometer's slow zones before it starts it, and supervises it while
 * it runs (docs/dmc-interface.md, the service state). Every sample is one
 * supervised cycle of the supervisor (the sampler below): the heartbeat,
 * the relay, the program's state and faults, the liveness, and once tables
 * exist the encoder against the potentiometer - the same checks as when
 * armed.
 *
 * Full calibration runs all axes at once, each through the same steps:
 *   1. toward the reverse switch: fast (travel speed) while the
 *      potentiometer's absolute reading says the switch is far, to just
 *      before the slow zone (another fast move while what the gain's
 *      tolerance left short is worth one); then slowly (seek speed) onto
 *      the switch with a bounded move that must end on it (stop code 3):
 *      a move that ends without it is "a limit switch that never came";
 *   2. back off by calibration.backoff_counts from where the switch was
 *      first seen: that position is the reverse soft limit and point 0,
 *      passed without a stop (the sweep starts on the switch) and with
 *      the switch open;
 *   3. a continuous sweep forward at vmax to just before the forward slow
 *      zone, then slowly onto the forward switch, while the data record is
 *      read every sample (10 ms): each sample (encoder, potentiometer) goes
 *      to the table point nearest to its encoder position, and each point's
 *      value is the least-squares line through its samples (within half a
 *      step), read at the point. A point without a sample of its own (a PC
 *      stall shorter than the controller watchdog loses at most one step at
 *      vmax) is fitted from the samples of both neighbours, and logged;
 *   4. back off the forward switch: the forward soft limit, passed with
 *      the switch open on the way to the centre (a move of its own when
 *      the axis rests beyond the new table's reach).
 * Then the table checks of re_calcheck.h (monotonic with the noise margin,
 * range, number of points, encoder advance, and both end values against
 * the potentiometer's expected absolute values), and every axis to the
 * centre at the travel speed, checking the potentiometer against the new
 * table on every sample. Any failure returns RE_FAULT naming the axis, the
 * point and the values; nothing is kept.
 *
 * Nothing here prints or allocates after re_calib_new().
 */
#ifndef RE_CALIB_H
#define RE_CALIB_H

#include <signal.h>
#include <stdint.h>

#include "re_calfile.h"
#include "re_calcheck.h"
#include "re_config.h"
#include "re_io.h"
#include "re_plan.h"

#define RE_CALIB_SAMPLE_MS 10 /* record period while calibrating */

struct re_calib_axis_cfg {
	int vmax_cps;	   /* sweep velocity */
	int travel_cps;	   /* moves that measure nothing */
	int seek_cps;	   /* in the slow zones near a switch */
	double gain_v;	   /* nominal pot gain, V/count */
	double pnlo_v;	   /* below: the reverse switch may be near */
	double pnhi_v;	   /* above: the forward switch may be near */
	double potlo_v;	   /* the pot's lowest possible reading */
	double pothi_v;	   /* its highest */
	int step_counts;   /* table step */
	int travel_counts; /* expected switch-to-switch travel */
	double travel_tol; /* fraction */
	int backoff_counts;
	int pot_input; /* analog input 1..8 */
	struct re_calcheck_cfg check;
	struct re_encpot_cfg encpot; /* for the move to the centre */
};

/* One supervised sample and the supervisor's view of the motion. */
struct re_calib_sampler {
	/* wait for the next sample time and run one cycle of the supervisor
	 * (heartbeat, record, every check); *rec is the fresh record.
	 * Return: GL_OK; RE_FAULT (the supervisor latched a fault and already
	 * reacted: the procedure ends); GL_ERR_AGAIN (stop requested). */
	int (*sample)(void *ud, const struct gl_record **rec);
	/* the supervisor moves the axes in @mask itself from now */
	void (*own)(void *ud, unsigned mask);
	/* from now the supervisor checks the encoders against @set's tables
	 * (the move to the centre, after a calibration or a loaded file) */
	void (*tables)(void *ud, const struct re_calset *set);
	void *ud;
};

struct re_calib_cfg {
	int n_axes;		  /* RE_AXES */
	const char *const *names; /* axis names */
	struct re_calib_axis_cfg axis[RE_AXES];
	int move_timeout_ms; /* deadline of each calibration move */
	int cmd_timeout_ms;  /* deadline of a reply */
	int accept_ms;	     /* a move request taken by the program within */
	struct re_calib_sampler sampler;
	/* optional: when it becomes non-zero (SIGTERM, Ctrl-C) the procedure
	 * stops at the next sample and returns GL_ERR_AGAIN */
	const volatile sig_atomic_t *stop;
};

/*
 * re_calib_cfg_from() - the calibration settings from the configuration,
 * including the table checks (also used to check a loaded file):
 * min/max points from travel +- tolerance, step tolerance half a step.
 * @names: [in] must outlive @out (usually built from @cfg's axis names).
 */
void re_calib_cfg_from(const struct re_config *cfg, const struct re_plan *plan,
		       const char *const *names, struct re_calib_cfg *out);

struct re_calib;

/* What a calibration is doing now, for the console (re_calib_progress()). */
struct re_calib_axis_progress {
	const char *phase; /* "to rev switch", "sweep fwd", "to centre" ... */
	double pct;	   /* position over the travel from the potentiometer
			    * (0 at the reverse switch, 100 at the forward
			    * one), clamped to 0..100; -1 unknown */
	double left_s;	   /* estimated time left for this axis, s */
};

struct re_calib_progress {
	int active; /* a procedure runs */
	int full;   /* 1: full calibration; 0: the check of the file */
	double elapsed_s;
	double left_s; /* the longest of the axes', s (they run together) */
	struct re_calib_axis_progress axis[RE_AXES];
};

/* re_calib_new() - allocate the working state. Return: GL_OK/GL_ERR_NOMEM. */
int re_calib_new(struct re_calib **out);
void re_calib_free(struct re_calib *c);

/*
 * re_calib_full() - full calibration of every axis, then to the centre.
 * @set: [out] the tables and soft limits (n_axes, names set; serial, hash
 *       and date are the caller's); cleared on failure.
 * @fault: [out] on RE_FAULT.
 * @seconds: [out] optional, the time taken.
 * @filled: [out] optional, the points fitted from their neighbours.
 * Return: GL_OK, RE_FAULT (@fault: the cause, not yet reacted to - except
 *         when the sampler latched it: then re_super already did), GL_ERR_AGAIN
 *         (stopped by cfg->stop; the axes may still be moving: the caller
 *         stops them), or GL_ERR_ARG.
 */
int re_calib_full(struct re_calib *c, const struct re_io *io,
		  const struct re_calib_cfg *cfg, struct re_calset *set,
		  struct re_fault *fault, double *seconds, int *filled);

/*
 * re_calib_progress() - where the running procedure of @c is, per axis:
 * its phase, its position over the travel and an estimate of the time
 * left (the remaining distances of this and the following phases at the
 * speeds configured for them, without acceleration), read from @rec (the
 * sample just taken, e.g. in the sampler; NULL: the procedure's last).
 * Pure: no I/O. @out->active is 0 when no procedure runs.
 * @now_ns: the io's clock.
 */
void re_calib_progress(const struct re_calib *c, const struct re_calib_cfg *cfg,
		       const struct gl_record *rec, int64_t now_ns,
		       struct re_calib_progress *out);

/*
 * re_calib_check_robot() - for tables loaded from a file: the
 * potentiometer of every axis at its present encoder position must agree
 * with the table (within the run-time tolerance), then every axis goes to
 * the centre with the check running on every sample.
 * Return: GL_OK, RE_FAULT (RE_F_CAL_ABORT naming the axis and the values,
 *         or ESTOP/COMM), GL_ERR_AGAIN (stopped by cfg->stop), GL_ERR_ARG.
 */
int re_calib_check_robot(struct re_calib *c, const struct re_io *io,
			 const struct re_calib_cfg *cfg,
			 const struct re_calset *set, struct re_fault *fault);

#endif /* RE_CALIB_H */
