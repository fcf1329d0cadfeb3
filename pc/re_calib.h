/*
 * re_calib.h - calibration on the controller (the original's Home and
 * BuildTables, with its gaps closed): build the encoder/potentiometer tables
 * and the soft limits, or check tables loaded from a file against the robot.
 *
 * Full calibration runs all axes at once, each through the same steps:
 *   1. to the reverse hard limit: a bounded relative move (PR) of the whole
 *      expected travel plus its tolerance at the axis's maximum velocity;
 *      it must end on the reverse switch (stop code 3): a move that ends
 *      without it is "a limit switch that never came";
 *   2. back off by calibration.backoff_counts: that position is the reverse
 *      soft limit and table point 0;
 *   3. a continuous sweep forward (bounded PR again) to the forward switch
 *      (stop code 2) while the data record is read every sample period
 *      (10 ms): each sample (encoder, potentiometer) goes to the table point
 *      nearest to its encoder position, and each point's value is the
 *      least-squares line through its samples (within half a step), read at
 *      the point - noise is averaged and no stop-and-go is needed;
 *   4. back off the forward switch: the forward soft limit.
 * Then the table checks of re_check.h (monotonic with the noise margin,
 * range, number of points, encoder advance), and every axis to the centre of
 * its travel, checking the potentiometer against the new table on the way.
 * Position-error (ER/OE) and encoder-failure (OA) protection stay active:
 * an axis switched off aborts. The soft limits are opened by re_ctl
 * beforehand; the DMC program is halted (HX) throughout, so its #LIMSWI and
 * #POSERR do not run (the program's own watchdog is not active either: the
 * moves are bounded, and the supervisor checks every sample).
 *
 * Every sample also checks the relay (ESTOP) and the link (COMM). Any
 * failure returns RE_FAULT with a CALIBRATION (or ESTOP, COMM) fault naming
 * the axis, the point and the values; nothing is kept.
 *
 * Nothing here prints or allocates after re_calib_new().
 */
#ifndef RE_CALIB_H
#define RE_CALIB_H

#include <signal.h>
#include <stdint.h>

#include "re_calfile.h"
#include "re_check.h"
#include "re_config.h"
#include "re_io.h"

#define RE_CALIB_SAMPLE_MS 10 /* record period while calibrating */

struct re_calib_axis_cfg {
	int vmax_cps;	   /* move and sweep velocity */
	int step_counts;   /* table step */
	int travel_counts; /* expected switch-to-switch travel */
	double travel_tol; /* fraction */
	int backoff_counts;
	int pot_input; /* analog input 1..8 */
	struct re_calcheck_cfg check;
	struct re_encpot_cfg encpot; /* for the move to the centre */
};

struct re_calib_cfg {
	int n_axes;		  /* RE_AXES */
	const char *const *names; /* axis names */
	struct re_calib_axis_cfg axis[RE_AXES];
	int move_timeout_ms; /* deadline of each calibration move */
	int cmd_timeout_ms;  /* deadline of a reply */
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
void re_calib_cfg_from(const struct re_config *cfg, const char *const *names,
		       struct re_calib_cfg *out);

struct re_calib;

/* re_calib_new() - allocate the working state. Return: GL_OK/GL_ERR_NOMEM. */
int re_calib_new(struct re_calib **out);
void re_calib_free(struct re_calib *c);

/*
 * re_calib_full() - full calibration of every axis, then to the centre.
 * @set: [out] the tables and soft limits (n_axes, names set; serial, hash
 *       and date are the caller's); cleared on failure.
 * @fault: [out] on RE_FAULT.
 * @seconds: [out] optional, the time taken.
 * Return: GL_OK, RE_FAULT, GL_ERR_AGAIN (stopped by cfg->stop; the axes
 *         may still be moving: the caller stops them), or GL_ERR_ARG.
 */
int re_calib_full(struct re_calib *c, const struct re_io *io,
		  const struct re_calib_cfg *cfg, struct re_calset *set,
		  struct re_fault *fault, double *seconds);

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
