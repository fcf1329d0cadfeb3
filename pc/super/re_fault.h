/*
 * re_fault.h - the fault catalogue: every fault the supervisor can report
 * (ids, classes), the struct that carries one, and the one FAULT line the
 * operator sees with its recovery text (re_fault_format). The texts are in
 * re_fault.c's re_fault_table; docs/operator.md lists each (tests/checks/
 * docs.sh holds them together).
 *
 * Not the checks that raise faults (re_check, re_calcheck) nor the
 * controller program's fault codes (re_dmcif). Pure: no I/O, no printing.
 */
#ifndef RE_FAULT_H
#define RE_FAULT_H

#include <limits.h>
#include <stddef.h>

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
 * table in re_fault.c: its class, a "what happened" template and a
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
 *   RE_F_WDOG_STREAM     i0 ms since the last record of the stream, i1 limit
 *   RE_F_WDOG_ACK        i0 ms since the controller last acknowledged a
 *                        posted heartbeat, i1 limit ms
 *   RE_F_WDOG_ECHO       i0 ms since the heartbeat the program's record
 *                        echoes was sent (unknown: none recent), i1 limit
 *                        ms, i2 the echo (hbpc mod 10000)
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
 *   RE_F_CTRL_INPUT      i0 raw switch word jraw (fault 3), shown as
 *                        the switches closed ("{j0}"); the timeout from
 *                        struct re_fault_units ("{jto}")
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
 *   RE_F_READBACK        FOREIGN; a or -1; i0 the item; s: what it is; f0
 *                        the value read, f1 the supervisor's own (the
 *                        seal read back against its plan)
 *   RE_F_XC_DECODE       INPUT; s: the supervisor's decode of the joystick
 *                        and the program's, the switches closed, how long
 *   RE_F_XC_MOTION       MOTION; a; s: what the axis does against the
 *                        supervisor's decode; f0 its speed, f1 the bound
 *   RE_F_CTRL_SEAL       FOREIGN; a or -1; i0 the item's number; s: what
 *                        it is ("vmax[0] (maximum joystick velocity, axis
 *                        A)"); f0 the value found, f1 the sealed one
 *                        (fault 17, re_seal.h)
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
	RE_F_CTRL_SEAL,
	RE_F_READBACK,
	RE_F_XC_DECODE,
	RE_F_XC_MOTION,
	RE_F_WDOG_STREAM,
	RE_F_WDOG_ACK,
	RE_F_WDOG_ECHO,
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

/* Axes the units below can describe (as many as the axis letters). */
#define RE_FAULT_UNIT_AXES 8

/*
 * How encoder positions are also said in the robot's units:
 * per axis the unit's name ("deg", "mm") and encoder counts per unit. A
 * NULL name or counts_per_unit <= 0: counts only. In the templates,
 * "{i0c}" is "<i0> counts", followed by " (<i0 in units> <unit>)" when
 * the fault's axis has a unit; "{r12}" is " (<i1> to <i2> in units
 * <unit>)" or nothing; "{jto}" is " of <invalid_timeout_ms> ms" or
 * nothing.
 */
struct re_fault_units {
	const char *name[RE_FAULT_UNIT_AXES];
	double counts_per_unit[RE_FAULT_UNIT_AXES];
	int invalid_timeout_ms; /* joystick's, for "{jto}"; 0: not known */
};

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
 * re_fault_format_units() - re_fault_format() with positions also in the
 * units of @units (NULL: counts only, as re_fault_format()).
 * Return: as re_fault_format().
 */
int re_fault_format_units(const struct re_fault *f,
			  const char *const *axis_names,
			  const struct re_fault_units *units, char *buf,
			  size_t cap);

/*
 * re_fault_what() - only the "what happened" part of the fault's text (no
 * class, no recovery), e.g. for a "FILE:LINE: <what>" message.
 * Return: as re_fault_format().
 */
int re_fault_what(const struct re_fault *f, const char *const *axis_names,
		  char *buf, size_t cap);

/*
 * re_fault_what_units() - re_fault_what() with positions also in @units.
 * Return: as re_fault_format().
 */
int re_fault_what_units(const struct re_fault *f, const char *const *axis_names,
			const struct re_fault_units *units, char *buf,
			size_t cap);

/*
 * re_fault_template() - the raw templates of a fault (for docs and tests).
 * @what, @recovery: [out] static strings, may be NULL.
 * Return: GL_OK or GL_ERR_ARG for an unknown id.
 */
int re_fault_template(enum re_fault_id id, const char **what,
		      const char **recovery);

#endif /* RE_FAULT_H */
