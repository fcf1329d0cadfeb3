/*
 * ctrl_motion.h - profiler, servo and protection of the axes, once per
 * sample (ctrl_motion.c); internal to the simulated controller (ctrl/), not
 * part of its API (ctrl.h).
 * It parses no command (ctrl_axcmd.h).
 */
#ifndef SIM_CTRL_MOTION_H
#define SIM_CTRL_MOTION_H

#include "ctrl_int.h"

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

#endif /* SIM_CTRL_MOTION_H */
