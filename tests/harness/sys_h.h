/*
 * sys_h.h - system-test fixture: the whole RoboELF system on one machine.
 *
 * One struct sys_env per test binary: a temporary directory, a copy of
 * config/roboelf.yaml with the calibration file and the log inside it, and
 * ONE full calibration (sys_env_calibrate()) whose file every case then
 * loads with `--calibration file`, so that a case starts in a few seconds.
 *
 * One struct sys_case per test case: a fresh galil-sim (free ports, a UDP
 * port for the record stream too, its virtual relay linked inside the
 * temporary directory), the case's own configuration (the variant, and
 * controller.udp_port galil-sim's), dmc/ checked,
 * downloaded and started with galil-load (unless no_load), and roboelf
 * started against both
 * with command-line options; the case is ready when roboelf prints
 * "RoboELF Ready for Use". The case talks to galil-sim's control port
 * (fault injection, the `state` line, the `events` log with simulated
 * times) and reads roboelf's stdout and its log file. sys_case_stop() kills
 * everything the case started, by pid.
 *
 * Times: `sim` times are galil-sim's simulated milliseconds (the `events`
 * and `time` answers), which follow the wall clock; reaction times are
 * differences of event times. Every wait has a deadline and polls at 10-20
 * ms intervals. Functions that fail put a message in ->err (tests print it
 * with fail_msg()); nothing else prints.
 *
 * Environment: ROBOELF_BIN (the binaries; default $BUILD/bin or build/bin),
 * ROBOELF_TOP (the repository root; default "."), ROBOELF_KEEP=1 keeps the
 * temporary directory, ROBOELF_SYS_RECORD=stream|poll sets
 * controller.record in every configuration written (unset: the
 * configuration's default; any other value is refused by roboelf's own
 * check of the configuration, naming it).
 */
#ifndef SYS_H_H
#define SYS_H_H

#include <stddef.h>

#include "proc.h"
#include "re_check.h"

#define SYS_PATH_MAX  512
#define SYS_DIR_MAX   64 /* the temporary directory's path */
#define SYS_ERR_MAX   1024
#define SYS_EVT_TEXT  160
#define SYS_SUBST_MAX 16   /* config substitutions per variant */
#define SYS_SIM_ARGS_MAX 40 /* extra galil-sim arguments per case */
#define SYS_STILL_CPS 1000 /* |velocity| of an axis at rest, counts/s */

/* The default timing figures of config/roboelf.yaml and dmc/constants.dmc
 * (checked against the configuration by sys_env_init()). */
#define SYS_MAINMS 10 /* DMC thread 0 period, ms */
#define SYS_LOOPMS 10 /* DMC thread 1 period, ms */

struct sys_env {
	char bin[SYS_PATH_MAX]; /* directory of the binaries */
	char top[SYS_PATH_MAX]; /* repository root */
	char dir[SYS_DIR_MAX];	/* temporary directory */
	char cfg[SYS_PATH_MAX]; /* the test configuration */
	char cal[SYS_PATH_MAX]; /* the calibration file */
	int ncase;		/* cases started (unique names) */
	double calib_s;		/* full calibration, wall s */
	char cal_from[SYS_PATH_MAX + 64]; /* the shared copy it came from */
	/* figures read from the configuration (defaults if absent) */
	int period_ms; /* P */
	double noncrit_factor, crit_factor;
	int wdto_ms;		/* controller_timeout_ms */
	int jto_ms;		/* invalid_timeout_ms */
	int persistence;	/* persistence_cycles of axis A */
	double allowed_error;	/* of axis A */
	int vmin_cps, vmax_cps; /* axis A */
	int step_counts;	/* axis A */
	int er_counts;		/* position_error_limit_counts, A */
	/* per axis: counts_per_unit and its unit ("deg", "mm"); 0: the
	 * FAULT lines give counts only */
	double per_unit[3];
	char unit[3][4];
	int readback_timeout_ms;
	int keep; /* ROBOELF_KEEP set */
	char err[SYS_ERR_MAX];
};

/*
 * sys_counts_tpl() - how a FAULT line gives an encoder position of @axis
 * (0..2), as a template piece: "{n} counts", or "{n} counts ({n} deg)"
 * when the configuration gives the axis a unit (docs/operator.md 7).
 * Return: the count of "{n}" in it (1 or 2).
 */
int sys_counts_tpl(const struct sys_env *e, int axis, char *buf, size_t cap);

/*
 * sys_counts_text() - the exact text a FAULT line gives for @counts on
 * @axis: "800 counts" or "800 counts (0.80 deg)".
 */
void sys_counts_text(const struct sys_env *e, int axis, long counts, char *buf,
		     size_t cap);

/* One "key: value" substitution in a configuration copy: the first line
 * whose text (after indentation) starts with "key:" becomes "key: value". */
struct sys_subst {
	const char *key;
	const char *value;
};

struct sys_opts {
	const char *calibration;       /* "file" (default) or "full" */
	const struct sys_subst *subst; /* config variant, {NULL} ended */
	int period_ms;		       /* 0: the configuration's */
	char *const *sim_args;	       /* extra galil-sim args, or NULL */
	char *const *re_args;	       /* extra roboelf args, or NULL */
	/* the technician's program instead (roboelf-tech): @re_args hold
	 * its command and operands; no --calibration or --period */
	int tech;
	char *const *re_env;  /* extra "NAME=value" for roboelf */
	char *const *re_wrap; /* run roboelf through this command (e.g.
				 valgrind and its options), or NULL */
	int ready_timeout_ms; /* 0: 20 s ("file"), 150 s ("full") */
	int no_ready;	      /* don't wait for Ready */
	int no_load;	      /* galil-sim left without a program (no
				 galil-load) */
	/* galil-sim elsewhere (tests/net): run it through @sim_wrap (see
	 * proc_sim_start_wrapped()) listening on every interface; roboelf and
	 * galil-load use @sim_addr, the control port @ctl_addr. NULL: local */
	char *const *sim_wrap;
	const char *sim_addr; /* dotted IPv4, NULL: 127.0.0.1 */
	const char *ctl_addr; /* dotted IPv4, NULL: 127.0.0.1 */
};

struct sys_evt {
	double t_ms; /* simulated ms */
	char text[SYS_EVT_TEXT];
};

struct sys_case {
	struct sys_env *env;
	int id;
	struct proc_sim sim;
	int sim_up;
	int ctl;	/* control-port socket, -1 */
	struct proc re; /* roboelf */
	int re_up;
	char relay_link[SYS_PATH_MAX];
	char sim_addr[16]; /* galil-sim's command-port address */
	char log[SYS_PATH_MAX];
	char cfg[SYS_PATH_MAX]; /* env->cfg or a variant */
	double t_ready_ms;	/* sim time when Ready was seen */
	double ready_wall_s;	/* roboelf start to Ready, wall s */
	struct sys_evt *ev;	/* events fetched so far */
	size_t nev, capev;
	char *buf; /* control-port answer buffer */
	size_t bufcap;
	char err[SYS_ERR_MAX];
};

/* ---- environment (per test binary) -------------------------------------- */

/*
 * sys_env_init() - find the binaries and the repository, make the temporary
 * directory, write the test configuration (config/roboelf.yaml with the
 * calibration file, the log and the ICStation state file inside it) and
 * read the timing figures from it.
 * Return: 0, or -1 with e->err set.
 */
int sys_env_init(struct sys_env *e);

/*
 * sys_env_calibrate() - one case with `--calibration full`: wait for Ready
 * (at most @timeout_ms), quit it with SIGTERM (exit 0 expected) and check
 * that the calibration file exists. e->calib_s gets the time from roboelf's
 * start to Ready. With ROBOELF_SYS_CAL=FILE set, FILE is copied instead
 * (development shortcut; calib_s stays 0). With ROBOELF_SYS_CAL_SHARE=DIR
 * (tests/run-all.sh sets it for one run), the programs of the run share one
 * calibration per configuration: the first makes it and keeps a copy in DIR,
 * the others wait for it (a lock) and copy it (e->cal_from names the copy).
 * Return: 0, or -1 with e->err set.
 */
int sys_env_calibrate(struct sys_env *e, int timeout_ms);

/* sys_env_cal_text() - what the calibration of @e was, for the INFO line:
 * "full calibration done in N s" or "... shared: copied from FILE ...".
 * Return: @buf. */
const char *sys_env_cal_text(const struct sys_env *e, char *buf, size_t cap);

/* sys_env_cleanup() - remove the temporary directory (unless ROBOELF_KEEP). */
void sys_env_cleanup(struct sys_env *e);

/*
 * sys_env_ready() - a group's set-up: sys_env_init() and a full calibration
 * (150 s at most), then an INFO line saying how it went and in how long.
 * Return: 1 when ready, 0 when not (e->err says why; the cases then fail
 * with it).
 */
int sys_env_ready(struct sys_env *e);

/* sys_env_done() - a group's tear-down: sys_env_cleanup(), but the
 * directory is kept for a look when the set-up was not @ready. */
void sys_env_done(struct sys_env *e, int ready);

/*
 * sys_record() - ROBOELF_SYS_RECORD (controller.record for every system
 * test), or NULL when unset or empty (the configuration's default).
 */
const char *sys_record(void);

/*
 * sys_stall_fault() - the fault a stalled link gives first in the design
 * sys_record() selects: RE_F_WDOG_STREAM for "stream" (the record's age),
 * else RE_F_WDOG_REPLY (the reply's age).
 */
enum re_fault_id sys_stall_fault(void);

/*
 * sys_env_write_config() - write a copy of the test configuration with
 * @subst applied to @path (and controller.record from sys_record()).
 * Return: 0, or -1 with e->err set (a key that is not found is an error).
 */
int sys_env_write_config(struct sys_env *e, const struct sys_subst *subst,
			 const char *path);

/* ---- one case ----------------------------------------------------------- */

/*
 * sys_case_start() - galil-sim, galil-load, roboelf, Ready (see above).
 * @o: [in] options, or NULL for the defaults.
 * Return: 0, or -1 with c->err set (everything started is stopped).
 */
int sys_case_start(struct sys_case *c, struct sys_env *e,
		   const struct sys_opts *o);

/*
 * sys_case_stop() - SIGKILL roboelf and galil-sim by pid, reap them, close
 * the control port, free the buffers. Safe to call twice, and on a zeroed
 * struct.
 */
void sys_case_stop(struct sys_case *c);

/*
 * sys_no_fault() - roboelf has printed no FAULT line and still runs.
 * @when: named in the error.
 * Return: 0, or -1 with c->err set (with roboelf's output).
 */
int sys_no_fault(struct sys_case *c, const char *when);

/*
 * sys_still_armed() - sys_no_fault(), and galil-sim shows the robot armed:
 * motor power on (relay on), every motor on, the program's state 1.
 * Return: 0, or -1 with c->err set (with the state seen).
 */
int sys_still_armed(struct sys_case *c, const char *when);

/*
 * sys_ctl() - one control-port request that must answer "ok".
 * Return: 0, or -1 with c->err set.
 */
int sys_ctl(struct sys_case *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/*
 * sys_ctl_ask() - one control-port request and its one-line answer.
 * Return: the answer's length, or -1 with c->err set.
 */
int sys_ctl_ask(struct sys_case *c, const char *req, char *resp, size_t cap);

/* sys_sim_time() - galil-sim's simulated ms, or -1 on error. */
double sys_sim_time(struct sys_case *c);

/*
 * sys_state() - one `state` line into @buf.
 * Return: 0 or -1 with c->err set.
 */
int sys_state(struct sys_case *c, char *buf, size_t cap);

/* sys_state_num() - a number of a state line ("A.pos"); NAN if absent. */
double sys_state_num(const char *state, const char *key);

/*
 * sys_events() - fetch the events since the last call and append them.
 * Return: the number of events now held, or -1 with c->err set.
 */
int sys_events(struct sys_case *c);

/*
 * sys_event_find() - the first held event at or after @after_ms whose text
 * starts with @prefix.
 * Return: its index, or -1.
 */
int sys_event_find(const struct sys_case *c, const char *prefix,
		   double after_ms);

/*
 * sys_wait_event() - sys_event_find(), fetching events every 15 ms for at
 * most @timeout_ms (wall).
 * @t_ms: [out] the event's simulated time.
 * Return: 0 when found, -1 on timeout or error (c->err set).
 */
int sys_wait_event(struct sys_case *c, const char *prefix, double after_ms,
		   int timeout_ms, double *t_ms);

/*
 * sys_wait_sim() - wait until the simulated time reaches @t_ms (polling
 * `time` every 10 ms), at most @timeout_ms wall. Return: 0 or -1.
 */
int sys_wait_sim(struct sys_case *c, double t_ms, int timeout_ms);

/*
 * sys_wait_state() - poll `state` every 10 ms until "@key=@value" appears
 * in it, at most @timeout_ms.
 * Return: 0 or -1 (c->err has the last line).
 */
int sys_wait_state(struct sys_case *c, const char *key, const char *value,
		   int timeout_ms);

/*
 * sys_wait_moving() - wait until axis @axis ('A'..'C') has moved at least
 * @counts from where it was at the call (true position X.act).
 * Return: 0 or -1.
 */
int sys_wait_moving(struct sys_case *c, char axis, double counts,
		    int timeout_ms);

/*
 * sys_wait_stopped() - poll `state` every 10 ms until axis @axis has
 * stopped: its reference position X.ref is the same in two state lines in
 * a row and its true velocity is below SYS_STILL_CPS (the servo's dither
 * around a count). @t_ms: [out] the simulated time of the first of the two.
 * Return: 0 or -1.
 */
int sys_wait_stopped(struct sys_case *c, char axis, int timeout_ms,
		     double *t_ms);

/*
 * sys_motors_off_time() - the time by which every motor was off after
 * @after_ms: the latest of each axis's first "axis <X> motor off" event at or
 * after @after_ms, when each axis has one and the state line shows it off.
 * Return: that time, or -1 when some axis has no such event.
 */
double sys_motors_off_time(const struct sys_case *c, double after_ms);

/*
 * sys_check_safe() - the safe state: relay off (unless @relay_may_be_on),
 * every motor off (X.mo=1), and no axis moving: the true positions X.act
 * unchanged while the simulated time advances by @hold_ms.
 * Return: 0, or -1 with c->err saying what is not safe.
 */
int sys_check_safe(struct sys_case *c, int relay_may_be_on, int hold_ms);

/*
 * sys_wait_fault() - wait for roboelf's "FAULT " line on stdout.
 * Return: 0 with @line filled, -1 on timeout (c->err set).
 */
int sys_wait_fault(struct sys_case *c, int timeout_ms, char *line, size_t cap);

/*
 * sys_fault_expect() - the FAULT line's class and recovery of @id on axis
 * @axis (-1 none), as roboelf formats them.
 * @prefix: [out] "FAULT <CLASS>: "; @recovery: [out] ". Recovery: <text>".
 * Return: 0 or -1.
 */
int sys_fault_expect(enum re_fault_id id, int axis, char *prefix, size_t pcap,
		     char *recovery, size_t rcap);

/*
 * sys_fault_match() - which of @ids (ended by RE_F_NONE) @line is: the
 * class prefix and the exact recovery text at the end of the line.
 * Return: the matching id, or RE_F_NONE.
 */
enum re_fault_id sys_fault_match(const char *line, int axis,
				 const enum re_fault_id *ids);

/*
 * sys_log_find() - the first line of the case's log file containing both
 * @a and @b (@b may be NULL).
 * Return: 0 with @line filled (if not NULL), -1 when none.
 */
int sys_log_find(struct sys_case *c, const char *a, const char *b, char *line,
		 size_t cap);

/*
 * sys_wd_warnings() - the late replies the case's log accounts for: a
 * watchdog warning logged in full ("watchdog: reply after ..." or, in the
 * stream design, "watchdog: a record or the heartbeat's reply came after
 * ...") counts 1, a summary of those counted after it ("watchdog: N more
 * late ...") N. While roboelf runs, those of the current window
 * (RE_SUPER_WD_WINDOW_MS) are not in the log yet: after a fault or a quit
 * they are.
 * @full, @sums: [out] optional: the lines of each kind.
 * Return: the count, or -1 when the log cannot be read.
 */
long sys_wd_warnings(struct sys_case *c, long *full, long *sums);

/*
 * sys_wd_counter() - the supervisor's own count of late replies, from the
 * log's "stats:" line (written at the quit: "watchdog warnings=N").
 * Return: N, or -1 when there is no such line.
 */
long sys_wd_counter(struct sys_case *c);

/*
 * sys_log_time_ms() - the wall-clock time (ms since the epoch, UTC) of the
 * first log line containing @a: its "YYYY-MM-DDTHH:MM:SS.mmmZ" stamp.
 * Return: 0 with @ms filled, -1 when there is none.
 */
int sys_log_time_ms(struct sys_case *c, const char *a, double *ms);

/* sys_wall_ms() - CLOCK_REALTIME in ms since the epoch. */
double sys_wall_ms(void);

/*
 * sys_cmd_open() - a second host connection to the controller's command
 * port (as another program would open). Return: the socket, or -1.
 */
int sys_cmd_open(struct sys_case *c);

/*
 * sys_cmd() - send "@cmd\r" on such a connection and read the answer up to
 * ':' or '?'. Return: 0 for ':', 1 for '?', -1 on error or timeout.
 */
int sys_cmd(int fd, const char *cmd, int timeout_ms);

#endif /* SYS_H_H */
