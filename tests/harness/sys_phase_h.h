/*
 * sys_phase_h.h - the phases of the whole system on the short-robot rig
 * (sys_rig_h.h), for the tests that kill, freeze or fault it in each phase
 * (test_sys_kill, test_sys_freeze, test_sys_calfault): drive a fresh case
 * to an instant of a phase; after a signal, who switched the motors off
 * and when, and whether the controller's deadline held.
 *
 * Failures found after a signal are recorded with rig_fail(); the callers
 * report them with rig_fails_check(). Functions that return an int put a
 * message in c->err on failure.
 */
#ifndef SYS_PHASE_H_H
#define SYS_PHASE_H_H

#include "sys_h.h"
#include "sys_rig_h.h"

enum ph_phase {
	PH_BOOT,    /* start-up, the relay open (motors off) */
	PH_RELAY,   /* start-up, relay closed, service not requested */
	PH_SVCREQ,  /* the service state requested, not yet entered */
	PH_CALIB,   /* full calibration (service state) */
	PH_CENTRE,  /* calibration from the file: check and centring */
	PH_OFF,	    /* back to safe after the service state */
	PH_ARMREQ,  /* the armed state requested, not yet entered */
	PH_ARMED,   /* armed, at rest */
	PH_JOG,	    /* armed, axis A jogging */
	PH_LATCHED, /* a fault latched */
	PH_COUNT
};

/* The name of each phase in the messages and tables. */
extern const char *const ph_name[PH_COUNT];

/* The event that begins the service state (calibration, centring). */
#define PH_SVC_ON "axis A motor on: SH (thread 0"

/* One instant: a phase and where in it. @line: for PH_BOOT, the progress
 * line roboelf has just printed; @at_ms: ms after the phase's anchor (the
 * service state's begin, Ready, the joystick command, the FAULT line). */
struct ph_instant {
	enum ph_phase ph;
	const char *line;
	double at_ms;
};

/*
 * ph_reach() - start a fresh case of @e (rig_start(): the calibration in
 * full for PH_CALIB, else from the file; off-centre for PH_CENTRE; the
 * controller's power output @power_output, 0 none) and drive it to the
 * instant @in: the start-up line, the relay closed, the service request
 * (its first heartbeat), @in->at_ms into the service state, back to safe,
 * the arm request pending, or @in->at_ms after Ready, after "joy A fwd"
 * (PH_JOG) or after a pot fault's FAULT line (PH_LATCHED).
 * @anchor: [out] the simulated time of the phase's anchor, -1 where none.
 * Return: 0, or -1 with c->err set.
 */
int ph_reach(struct sys_case *c, struct sys_env *e, const struct ph_instant *in,
	     int power_output, double *anchor);

/* What happened after a kill or a freeze (ph_check_off()). */
struct ph_off {
	int on_at_sig;	 /* some motor was on at the signal */
	int on_after;	 /* some motor was switched on after it */
	double off_ms;	 /* last motor off after the signal, ms; -1 none */
	char by[64];	 /* who switched that one off: "(thread 0 line 381)" */
	double pout_ms;	 /* "power output N cleared" after the signal; -1 */
	double fcode;	 /* the program's latched fault at the end */
	char st_d[2048]; /* the state line at RIG_D_POWER_MS (a few ms after) */
	char st[2048];	 /* the state line at the end */
};

/*
 * ph_check_off() - the assertions after a kill or during a freeze at
 * @t_sig (@what names it in the messages): let the controller act on its
 * own for the deadline and the longest program transition after it, then
 * every motor that was on at the signal, or went on after it, off within
 * RIG_D_CTRL_MS, by the controller program (nobody else is left), which
 * latched WATCHDOG (2); with the power output @power_output wired (0:
 * none), the output cleared within RIG_D_POWER_MS and motor power gone by
 * then; then every motor off and no axis moving from the deadline to the
 * end of a hold (sys_check_safe(); the relay may stay on: nobody is left to
 * open it). Failures go to rig_fail().
 * @r: [out] what was found, for ph_measure_line().
 * Return: 0 when all hold, -1 when a failure was recorded.
 */
int ph_check_off(struct sys_case *c, const char *what, double t_sig,
		 int power_output, struct ph_off *r);

/*
 * ph_measure_line() - print the "[ MEASURE  ]" line of one signal @sig
 * ("kill", "freeze") in phase @ph at @t_sig (+-@jitter), @anchor the
 * phase's anchor (-1 none), with @r's findings.
 */
void ph_measure_line(const char *sig, enum ph_phase ph, double t_sig,
		     double jitter, double anchor, const struct ph_off *r);

/*
 * ph_who_off() - the first "axis X motor off" event of every axis at or
 * after @after.
 * @by: [out] each axis's source ("handle A", "thread 0 line 381").
 * Return: the latest of those times, or -1 when an axis has none.
 */
double ph_who_off(const struct sys_case *c, double after, char by[3][48]);

#endif /* SYS_PHASE_H_H */
