/*
 * re_ctl.h - the controller in the supervisor's start-up and shutdown order
 * (docs/supervisor.md, "Power-on and power-off order"): identify it, refuse
 * it when another supervisor runs it, close foreign Ethernet handles, check
 * the program galil-load stamped, halt it and read the motors back off,
 * configure it (extended I/O, PID gains, torque limit, position-error limit
 * with off-on-error, encoder-failure detection, acceleration, soft limits),
 * check the amplifiers' view of motor power, start the program, write its
 * parameters, and move it between its states (service, armed, safe)
 * (docs/dmc-interface.md).
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
#include "re_plan.h"
#include "re_seal.h"

#define RE_CTL_UPLOAD_MAX (4000 * 82 + 1024) /* 4000 lines of 80 + CR LF */
#define RE_CTL_SOFT_OPEN  2147483647	     /* FL/BL "no soft limit", counts */

struct re_ctl_info {
	char model[64];	     /* ^R^V, e.g. "DMC4030 Rev 1.2h-sim" */
	long serial;	     /* MG _BN */
	uint64_t program_id; /* the stamp galil-load wrote */
	int mainms;	     /* the program's #MAIN period, ms */
};

/*
 * re_ctl_identify() - identify the controller (^R^V, MG _BN) and check it is
 * the model the configuration expects. Touches nothing on the controller.
 * @info: [out] model, serial.
 * Return: GL_OK; GL_ERR_MISMATCH (wrong model); a link error.
 */
int re_ctl_identify(gl_link *l, const struct re_config *cfg,
		    struct re_ctl_info *info, char *err, size_t errlen);

/*
 * re_ctl_check_busy() - refuse a controller that another supervisor is
 * running: a program running (_XQ0) in state 1 (armed) or 3 (service)
 * whose heartbeat hbpc changes within @wdto_ms + 50 ms. A program in those
 * states whose heartbeat does not change is an orphan (its own watchdog
 * stops it): not busy. Nothing is written to the controller.
 * Return: GL_OK; GL_ERR_BUSY (@err says who and what to do); a link error.
 */
int re_ctl_check_busy(const struct re_io *io, int wdto_ms, char *err,
		      size_t errlen);

/*
 * re_ctl_take_over() - close every other Ethernet handle (IHT=>-3) so that
 * nobody else commands the robot, then open the unsolicited-message handle
 * (after IHT, which would close it); upload the program, check
 * galil-load's identity stamp, and that the program is sealed with exactly
 * the values @cfg gives (re_seal.h).
 * @info: [in,out] program_id filled.
 * @seal: [out] the seal table (the program's and this configuration's).
 * Return: GL_OK; GL_ERR_MISMATCH (program not stamped, changed, or sealed
 *         with other values: @err names the first and tells the operator to
 *         run galil-load); a link error.
 */
int re_ctl_take_over(gl_link *l, const struct re_config *cfg,
		     struct re_ctl_info *info, struct re_seal *seal, char *err,
		     size_t errlen);

/*
 * re_ctl_check_program() - what re_ctl_take_over() checks of the program,
 * touching no handle: upload it (UL), check galil-load's identity stamp
 * and that it is sealed with exactly the values @cfg gives. The program
 * may run or be halted; nothing is written.
 * @info: [in,out] program_id filled. @seal: [out] the seal table.
 * Return: as re_ctl_take_over() after its handles.
 */
int re_ctl_check_program(gl_link *l, const struct re_config *cfg,
			 struct re_ctl_info *info, struct re_seal *seal,
			 char *err, size_t errlen);

/*
 * re_ctl_halt() - make the controller safe before anything else: prun=0
 * (the program is halted on purpose), HX (every thread), AB 1;MO ABC, and
 * read back every motor off (_MOA.._MOC = 1).
 * Return: GL_OK; GL_ERR_MISMATCH (a motor still on); a link error.
 */
int re_ctl_halt(const struct re_io *io, char *err, size_t errlen);

/*
 * re_ctl_configure() - write and read back: CO 0 (extended I/O as inputs),
 * KP KI KD, TL, ER, OE, OA OT OV, AC DC (10 x the service speed), FL BL
 * opened for calibration. The program must be halted (re_ctl_halt()).
 * Return: GL_OK; GL_ERR_MISMATCH (a read-back differs); GL_ERR_CTRL (the
 *         controller refused a command: its TC1 text is in @err); ...
 */
int re_ctl_configure(const struct re_io *io, const struct re_config *cfg,
		     const struct re_plan *plan, char *err, size_t errlen);

/*
 * re_ctl_amp_power() - wait until the controller's amplifier status shows
 * motor power as wanted: under-voltage (TA0 bit 3, axes A-D on a DMC-40x0)
 * set when @want_on is 0, clear when 1; at most @timeout_ms.
 * @ta0: [out] the last TA0 read (may be NULL).
 * Return: GL_OK; GL_ERR_TIMEOUT (@err says what was seen); a link error.
 */
int re_ctl_amp_power(const struct re_io *io, int want_on, int timeout_ms,
		     int *ta0, char *err, size_t errlen);

/*
 * re_ctl_start_program() - XQ #AUTO,0, wait (1 s) for state 0 and the
 * program heartbeat advancing; read mainms; the program's vers must be
 * ROBOELF_DMC_VERSION (the record fields this roboelf decodes).
 * @info: [in,out] mainms filled.
 * Return: GL_OK; GL_ERR_TIMEOUT (the program did not start);
 *         GL_ERR_MISMATCH (another version: @err says to run galil-load);
 *         a link error.
 */
int re_ctl_start_program(const struct re_io *io, struct re_ctl_info *info,
			 char *err, size_t errlen);

/*
 * re_ctl_write_params() - write the session's parameters, the soft limits
 * (from @cal, or wide open before calibration when @cal is NULL) and the
 * service moves' time limit, and read every parameter back against @plan:
 * velocities, window, step, joystick map and valid-state table, polarity,
 * invalid-input timeout, watchdog timeout, heartbeat step, power output,
 * potentiometer inputs and zones, service speeds and the longest service
 * move, which the program sets itself from its seal (#SEALIN: the supervisor
 * checks them by its own read-back). Lines of at most 80 characters.
 * Return: GL_OK; GL_ERR_MISMATCH (read-back); a link error.
 */
int re_ctl_write_params(const struct re_io *io, const struct re_config *cfg,
			const struct re_plan *plan, const struct re_calset *cal,
			char *err, size_t errlen);

/*
 * re_ctl_wait_still() - wait up to 1 s until every axis is at rest as the
 * program's check 17 (#PCHK, before service and at arm) judges it: |_TVx|
 * at most vstill. TV averages 256 samples, so an axis stopped a moment
 * ago (the previous session interrupted while it moved) still shows speed.
 * Return: GL_OK; GL_ERR_TIMEOUT with @err naming the axis and its TV; a
 *         link error.
 */
int re_ctl_wait_still(const struct re_io *io, char *err, size_t errlen);

/*
 * re_ctl_service() - enter the service state: hbpc=<@hbpc>, svcreq=1, then
 * records (QR) carrying the heartbeat every 10 ms until the program shows
 * state 3 (1 s).
 * @hbpc: [in,out] the session's heartbeat (continued by the cycle).
 * @fault: [out] when the program latched a fault instead (RE_F_CTRL_PARAM
 *         with the failed check number, or another).
 * Return: GL_OK; RE_FAULT; GL_ERR_TIMEOUT; a link error.
 */
int re_ctl_service(const struct re_io *io, long *hbpc, struct re_fault *fault,
		   char *err, size_t errlen);

/*
 * re_ctl_set_limits() - FL/BL from the calibration (forward = soft_fwd,
 * reverse = soft_rev, rounded to counts), read back.
 * Return: GL_OK, GL_ERR_MISMATCH, or a link error.
 */
int re_ctl_set_limits(const struct re_io *io, const struct re_calset *cal,
		      char *err, size_t errlen);

/*
 * re_ctl_arm() - arm from the safe state: FL/BL and srev/sfwd from @cal
 * (read back), every axis at rest (TV of each at most the program's vstill,
 * within 1 s: the arm check 17), armreq=1, records carrying the heartbeat
 * until state 1 (1 s).
 * Return: as re_ctl_service().
 */
int re_ctl_arm(const struct re_io *io, const struct re_calset *cal, long *hbpc,
	       struct re_fault *fault, char *err, size_t errlen);

/*
 * re_ctl_off() - back to the safe state in order: offreq=1, then wait
 * (200 ms) for state 0 or a latched state, the heartbeat continuing.
 * Return: GL_OK (state 0 or 2); GL_ERR_TIMEOUT; a link error.
 */
int re_ctl_off(const struct re_io *io, long *hbpc, char *err, size_t errlen);

/*
 * re_ctl_stop() - stop every axis and switch the motors off (RE_STOP_ALL: AB
 * 1;MO ABC), best effort with @timeout_ms. Return: GL_OK or the link error.
 */
int re_ctl_stop(const struct re_io *io, int timeout_ms);

/*
 * re_ctl_session() - a random heartbeat start in 1 .. RE_HBPC_WRAP - 1, so
 * that a value another writer sends is out of the session's sequence.
 */
long re_ctl_session(void);

#endif /* RE_CTL_H */
