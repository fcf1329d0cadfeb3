/*
 * re_ctl.h - the controller at start-up: identify it, check the program
 * galil-load stamped, close foreign Ethernet handles, configure it (command
 * timeout, extended I/O, PID gains, torque limit, position-error limit with
 * off-on-error, encoder-failure detection, acceleration and deceleration at
 * ten times the maximum velocity, soft limits), read every setting back,
 * and arm the DMC program (docs/dmc-interface.md, "Arming sequence").
 *
 * Every write is read back and compared; any difference refuses start-up
 * with a message naming the setting and both values. Nothing here prints;
 * @err gets a git-style message ("read-back of KPB differs: wrote 6, read
 * 6.125"). Start-up code: may allocate (the program upload buffer).
 */
#ifndef RE_CTL_H
#define RE_CTL_H

#include <stddef.h>
#include <stdint.h>

#include "gl_link.h"
#include "re_calfile.h"
#include "re_check.h"
#include "re_config.h"
#include "re_io.h"

#define RE_CTL_UPLOAD_MAX (4000 * 82 + 1024) /* 4000 lines of 80 + CR LF */
#define RE_CTL_SOFT_OPEN  2147483647	     /* FL/BL "no soft limit", counts */

struct re_ctl_info {
	char model[64];	     /* ^R^V, e.g. "DMC4030 Rev 1.2h-sim" */
	long serial;	     /* MG _BN */
	uint64_t program_id; /* the stamp galil-load wrote */
	int mainms;	     /* the program's #MAIN period, ms */
};

/*
 * re_ctl_identify() - identify the controller and check it is the model
 * the configuration expects; close every other Ethernet handle (IHT=>-3)
 * so nobody else commands the robot, then open the unsolicited-message
 * handle (after IHT, which would close it); upload the program and check
 * galil-load's identity stamp.
 * @info: [out] model, serial, program_id.
 * Return: GL_OK; GL_ERR_MISMATCH (wrong model, or program not stamped or
 *         changed: @err tells the operator to run galil-load); a link error.
 */
int re_ctl_identify(gl_link *l, const struct re_config *cfg,
		    struct re_ctl_info *info, char *err, size_t errlen);

/*
 * re_ctl_configure() - HX (every thread), stop and switch off every axis,
 * then write and read back: CO 0 (extended I/O as inputs), KP KI KD, TL,
 * ER, OE, OA OT OV, AC DC (10 x vmax), FL BL opened for calibration.
 * Return: GL_OK; GL_ERR_MISMATCH (a read-back differs); GL_ERR_CTRL (the
 *         controller refused a command: its TC1 text is in @err); ...
 */
int re_ctl_configure(const struct re_io *io, const struct re_config *cfg,
		     char *err, size_t errlen);

/*
 * re_ctl_set_limits() - FL/BL from the calibration (forward = soft_fwd,
 * reverse = soft_rev, rounded to counts), read back.
 * Return: GL_OK, GL_ERR_MISMATCH, or a link error.
 */
int re_ctl_set_limits(const struct re_io *io, const struct re_calset *cal,
		      char *err, size_t errlen);

/*
 * re_ctl_arm() - the arming sequence: XQ #AUTO,0; wait for state 0 and
 * the program heartbeat; write every parameter (velocities, window, step,
 * soft limits from @cal, joystick map and valid-state table, polarity,
 * invalid-input timeout, watchdog timeout) and read each back; armreq=1;
 * wait (1 s) for state 1 in the data record, writing the heartbeat.
 * @info: [in,out] mainms is filled.
 * @hbpc: [in,out] the PC heartbeat counter (continued by the cycle).
 * @fault: [out] filled when the program latched a fault instead of arming
 *         (RE_F_CTRL_PARAM with the failed check number, or another).
 * Return: GL_OK; RE_FAULT (see @fault); GL_ERR_MISMATCH (read-back);
 *         GL_ERR_TIMEOUT (no arm within 1 s); a link error.
 */
int re_ctl_arm(const struct re_io *io, const struct re_config *cfg,
	       const struct re_calset *cal, struct re_ctl_info *info,
	       long *hbpc, struct re_fault *fault, char *err, size_t errlen);

/*
 * re_ctl_stop() - stop every axis and switch the motors off (RE_STOP_ALL: AB
 * 1;MO ABC), best effort with @timeout_ms. Return: GL_OK or the link error.
 */
int re_ctl_stop(const struct re_io *io, int timeout_ms);

#endif /* RE_CTL_H */
