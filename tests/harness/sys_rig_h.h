/*
 * sys_rig_h.h - the short-robot rig of the "every phase supervised" system
 * tests (docs/supervisor.md): test_sys_kill, test_sys_freeze,
 * test_sys_calfault, test_sys_unconfirmed, test_sys_signals and
 * test_sys_centring.
 *
 * galil-sim's short robot (limit switches A, B at +-10000, C at +-8000
 * counts, so that a full calibration takes about 7 s) running dmc/
 * (downloaded by galil-load), roboelf supervising it through the virtual
 * relay, with one configuration (the RIG_* figures below). One full
 * calibration per test program (rig_env_ready(); it also measures the phase
 * boundaries from galil-sim's events), then every case on a fresh
 * galil-sim (rig_start()). Times are galil-sim's simulated ms (its `events`
 * and `time` answers).
 *
 * A case of many instants collects its failures (rig_fail()) and reports
 * them all at its end (rig_fails_check()).
 *
 * Built on sys_h.h (struct sys_env, struct sys_case). Functions that return
 * an int put a message in c->err on failure; rig_fails_check() and
 * rig_need_env() fail the running cmocka test themselves, so this module
 * links only into cmocka test programs.
 */
#ifndef SYS_RIG_H_H
#define SYS_RIG_H_H

#include <stddef.h>

#include "re_check.h"
#include "sys_h.h"

/* ---- the configuration every case uses ---------------------------------- */

#define RIG_PERIOD_MS	50   /* period_ms: P, armed */
#define RIG_NONCRIT_F	1.5  /* watchdog.noncritical_factor */
#define RIG_CRIT_F	2.5  /* watchdog.critical_factor: C = 125 ms */
#define RIG_WDTO_MS	200  /* watchdog.controller_timeout_ms (DMC wdto) */
#define RIG_JTO_MS	500  /* joystick.invalid_timeout_ms */
#define RIG_VMIN_CPS	2000 /* every axis */
#define RIG_VMAX_CPS	8000
#define RIG_STEP_COUNTS 1000
#define RIG_ER_COUNTS	800 /* below the step (the program's arm check 7) */
/* counts: potlo 0.125 V on C (open wiper outside) */
#define RIG_NEAR_MARGIN 500
#define RIG_PERSIST	1   /* persistence_cycles */
#define RIG_ALLOWED_ERR 0.5 /* allowed_error */
#define RIG_READBACK_MS 500 /* relay.readback_timeout_ms */
#define RIG_POWER_OUT	3   /* controller.power_output in the wired variant */
#define RIG_SAMPLE_MS	1   /* galil-sim's servo sample (TM 1000) */

/*
 * The controller-side deadline (docs/dmc-interface.md, fault 2): thread 0
 * sees a change of hbpc up to mainms late and checks every mainms, so it
 * switches every motor off within wdto + mainms (+ one servo sample) of
 * the last heartbeat change. A dead or frozen supervisor writes nothing
 * after the signal, so its last change is before the signal: every motor
 * must be off by
 *
 *     t_signal + RIG_WDTO_MS + SYS_MAINMS + RIG_SAMPLE_MS        (= 211 ms)
 *
 * where t_signal is galil-sim's simulated time read just after kill()
 * returned (the signal was sent in [t_before, t_signal]; see
 * rig_signal_at()).
 */
#define RIG_D_CTRL_MS (RIG_WDTO_MS + SYS_MAINMS + RIG_SAMPLE_MS)

/* The program opens the power output (OP 0) in the same pass as MO ABC;
 * galil-sim's plant reads the output at its next servo sample (the event
 * "power output N cleared" is "seen at the next servo sample",
 * docs/galil-sim.md): motor power is gone one sample after the motors. */
#define RIG_D_POWER_MS (RIG_D_CTRL_MS + RIG_SAMPLE_MS)

#define RIG_SLACK_MS	  25  /* scheduling allowance, as test_sys_faults */
#define RIG_HOLD_MS	  200 /* no motion over this after the safe state */
#define RIG_START_MS	  10000
#define RIG_READY_MS	  30000 /* --calibration file to Ready */
#define RIG_FAULT_WAIT_MS 8000
#define RIG_EXIT_WAIT_MS  5000

/* Where the off-centre robot is put before a calibration from the file,
 * so that centring is a real move (counts; inside the calibrated soft
 * limits, outside the slow zones). */
extern const double rig_off_centre[3];

/* Measured in the group setup's full calibration (simulated ms). */
struct rig_ref {
	double t_service; /* the service state began: motors on */
	double d_cal;	  /* service begin to the end of the service state */
	double d_centre;  /* centring from rig_off_centre (computed) */
	double centre[3]; /* the calibrated centres */
};

/* How rig_start() sets up a case. */
struct rig_opts {
	const char *calibration; /* "full" or "file" */
	int power_output;	 /* 0 or RIG_POWER_OUT (config and galil-sim) */
	int no_amp_uv;		 /* galil-sim --no-amp-undervoltage */
	int off_centre;		 /* put the robot at rig_off_centre[] first */
};

/* ---- failures collected over many instants ------------------------------ */

/*
 * rig_fail() - record one failure of the running case (printf-style); the
 * case goes on. At most 16 KiB of messages are kept; every one is counted.
 */
void rig_fail(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* rig_fails_reset() - forget the failures recorded so far. */
void rig_fails_reset(void);

/* rig_fails_count() - the failures recorded since rig_fails_reset(). */
size_t rig_fails_count(void);

/*
 * rig_fails_check() - when failures were recorded: print each as a
 * "[  FAILS   ] @what: ..." line and fail the running cmocka test
 * (fail_msg(), which does not return). Otherwise nothing.
 */
void rig_fails_check(const char *what);

/* ---- the group ---------------------------------------------------------- */

/*
 * rig_env_ready() - a group's set-up: sys_env_init() with the RIG_*
 * figures, the short robot's plant file, one full calibration (@e->cal
 * written) with its phase boundaries measured into @ref, then an INFO line
 * saying how it went. Tear down with sys_env_done().
 * Return: 1 when ready, 0 when not (@e->err says why).
 */
int rig_env_ready(struct sys_env *e, struct rig_ref *ref);

/*
 * rig_need_env() - in a test: fail it (fail_msg()) with @e->err unless the
 * group set-up was @ready.
 */
void rig_need_env(const struct sys_env *e, int ready);

/* ---- one case ----------------------------------------------------------- */

/*
 * rig_start() - a fresh galil-sim (the short robot, @o's options), dmc/
 * loaded and started, the robot put off-centre if asked, roboelf started
 * with @o->calibration; returns without waiting for anything of roboelf's.
 * The control port watches the program's state, fault code, the
 * supervisor's heartbeat hbpc, armreq and mneut. @c is cleared first and
 * belongs to @e; stop it with sys_case_stop().
 * Return: 0, or -1 with c->err set.
 */
int rig_start(struct sys_case *c, struct sys_env *e, const struct rig_opts *o);

/*
 * rig_wait_ready() - "RoboELF Ready for Use" within @timeout_ms, then the
 * program's first look at the joystick at neutral (var.mneut = 1): a
 * command sent before that look would be ignored. Sets c->ready_wall_s and
 * c->t_ready_ms.
 * Return: 0, or -1 with c->err set (a FAULT line, or roboelf's output).
 */
int rig_wait_ready(struct sys_case *c, int timeout_ms);

/*
 * rig_wait_sim_fine() - wait until the simulated time reaches @t, polling
 * every 2 ms (the instants of a kill are chosen to a few ms), pumping
 * roboelf's output, at most @timeout_ms wall.
 * Return: 0, or -1 with c->err set.
 */
int rig_wait_sim_fine(struct sys_case *c, double t, int timeout_ms);

/*
 * rig_signal_at() - send @sig to roboelf.
 * @t_before: [out] the simulated time just before kill(), or NULL.
 * Return: the simulated time just after kill() returned (the signal went
 * between the two readings), or -1.
 */
double rig_signal_at(struct sys_case *c, int sig, double *t_before);

/*
 * rig_inject() - send the control request @req (a joystick command "joy
 * ..." or a fault injection) and wait for its event ("input: " or
 * "inject: " then @req).
 * Return: the event's simulated time, or -1 with c->err set.
 */
double rig_inject(struct sys_case *c, const char *req);

/*
 * rig_wait_motors_off() - wait up to @ms wall until every motor was
 * switched off after @after (sys_motors_off_time()).
 * Return: that time (simulated ms), or -1.
 */
double rig_wait_motors_off(struct sys_case *c, double after, int ms);

/*
 * rig_check_fault_line() - record a failure (rig_fail(), named @what)
 * unless the FAULT @line is one of @ids (ended by RE_F_NONE), names axis
 * @axis (-1: none to name) and is in the case's log.
 */
void rig_check_fault_line(struct sys_case *c, const char *what,
			  const char *line, int axis,
			  const enum re_fault_id *ids);

/*
 * rig_tail() - the last @n bytes of roboelf's (or any process's) stream
 * @s, for messages.
 */
const char *rig_tail(const struct proc *p, enum proc_stream s, size_t n);

/* rig_seterr() - printf-style message into c->err. */
void rig_seterr(struct sys_case *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* ---- deadlines (docs/safety.md, "Deadlines"), from the RIG_* figures ---- */

/* rig_p() - P, the configured period, ms (in the service state the cycle
 * runs every 10 ms, so deadlines in P are upper bounds there too). */
double rig_p(void);

/* rig_c() - C, the critical reply-age limit: critical_factor x P, ms. */
double rig_c(void);

/* rig_d_encpot() - the encoder/potentiometer check's deadline (2 + k) P,
 * ms. */
double rig_d_encpot(void);

#endif /* SYS_RIG_H_H */
