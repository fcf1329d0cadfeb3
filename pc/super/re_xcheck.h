/*
 * re_xcheck.h - the supervisor's own view of the joystick and the motion,
 * a diverse check of the controller program (docs/supervisor.md, "Checked
 * twice"). The original system decoded the joystick on the PC; this one
 * lets the program decode it (dmc/roboelf.dmc #JREAD) and decodes it again
 * here from the data record's input banks with the supervisor's own wiring
 * table (roboelf.yaml), never with the program's copy:
 *
 *  - the program's decoded command (ZAC jcmd) must equal the supervisor's
 *    while the robot is armed or in service; a difference that lasts longer
 *    than the program's reporting lag is a fault naming both readings;
 *  - armed, once the program has seen the joystick neutral (mneut): the
 *    commanded axis must not run against the command, no other axis may run,
 *    and the commanded one not faster than the configured ramp allows at
 *    that time after the supervisor first saw the command (times vover),
 *    each beyond the settling that TV's 256-sample average and the braking
 *    of a stopped axis take, for two cycles.
 *
 * Pure: no I/O, no clock reads (times come in as monotonic ns), no
 * allocation, no printing.
 */
#ifndef RE_XCHECK_H
#define RE_XCHECK_H

#include <stdint.h>

#include "gl_record.h"
#include "re_dmcif.h"
#include "re_fault.h"

#define RE_XC_AXES   3
#define RE_XC_INPUTS 12

/* The program's own figures the check allows for (dmc/constants.dmc:
 * vover, vstill, tvwin), kept here as the supervisor's: test_re_xcheck
 * holds them to the program's. */
#define RE_XC_VOVER	1.25 /* a moving axis may run this x its ramp */
#define RE_XC_VSTILL	1000 /* counts/s: TV of an axis at rest */
#define RE_XC_SETTLE_MS 400  /* TV averages 256 samples; braking after */

struct re_xcheck_cfg {
	int inputs[RE_XC_INPUTS]; /* digital input of switch j (jin[j]) */
	int active_low;		  /* a closed switch reads 0 */
	int vmin_cps[RE_XC_AXES], vmax_cps[RE_XC_AXES];
	int wst_ms[RE_XC_AXES], wen_ms[RE_XC_AXES];
	/* how old the program's jcmd may be against the record's inputs:
	 * thread 1's loop, two main passes (ZAC published), one period */
	int64_t lag_ns;
	const char *axis_names[RE_XC_AXES];
};

struct re_xcheck {
	int pc_cmd;		 /* the supervisor's decode: -1, 0, 1..6 */
	int64_t pc_since_ns;	 /* when it became that */
	int64_t differ_since_ns; /* program's jcmd differs since; 0: not */
	int differ_cycles;
	int64_t still_since_ns;		   /* neutral (the PC's decode) since */
	int bad_cycles[RE_XC_AXES];	   /* consecutive cycles over a bound */
	double prev_limit_cps[RE_XC_AXES]; /* the bound before the last
					    * command change (TV settles) */
};

/*
 * re_xcheck_decode() - the joystick command from the record's input banks
 * with the supervisor's wiring: 0 neutral, k + 1 when exactly both switches
 * of command k are closed (0 A fwd, 1 A rev, 2 B fwd ... 5 C rev), -1 for
 * any other state.
 * @raw: [out] optional: bit j set when switch j is closed.
 * Return: the command; -2 for an input number outside 1..80.
 */
int re_xcheck_decode(const struct re_xcheck_cfg *c, const uint8_t banks[10],
		     int *raw);

/*
 * re_xcheck_ramp() - the joystick velocity of axis @ax @t_ms after the
 * first sight of its command: vmin until wst, linear to vmax at wen, vmax
 * after (the program's #MRAMP), counts/s.
 */
double re_xcheck_ramp(const struct re_xcheck_cfg *c, int ax, double t_ms);

/* re_xcheck_reset() - forget everything (a new session, state change). */
void re_xcheck_reset(struct re_xcheck *x, int64_t now_ns);

/*
 * re_xcheck_step() - one cycle's record.
 * @za: [in] the program's fields (state, jcmd, mneut) of @rec.
 * @f: [out] on RE_FAULT: RE_F_XC_DECODE (s: both readings),
 *     RE_F_XC_MOTION (a; s: what the axis does against what, f0 its
 *     speed counts/s, f1 the bound).
 * Return: RE_OK or RE_FAULT; GL_ERR_ARG for a NULL argument.
 */
int re_xcheck_step(struct re_xcheck *x, const struct re_xcheck_cfg *c,
		   const struct gl_record *rec, const struct re_za *za,
		   int64_t now_ns, struct re_fault *f);

/*
 * re_xcheck_cmd_text() - "axis A forward", "neutral" or "no valid command"
 * for a command as re_xcheck_decode() returns it.
 */
const char *re_xcheck_cmd_text(int cmd);

#endif /* RE_XCHECK_H */
