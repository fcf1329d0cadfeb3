/*
 * re_start.h - roboelf's start-up, from the locks to "RoboELF Ready for
 * Use": the power-on order (docs/supervisor.md), the calibration or the
 * check of the calibration file, the move to the centre and arming, each
 * step supervised, and a stop of roboelf itself (SIGSTOP) during it named.
 * Also the application state the start-up, the run loop and the shutdown
 * share (struct app), and what the signal handlers tell them (re_sig);
 * the bring-up (re_start_bringup()) is shared with the technician's
 * commissioning run (tools/roboelf-tech).
 *
 * Not the command lines (pc/roboelf.c, tools/roboelf-tech/main.c), the
 * signal handlers and the power-off (re_app), the run loop, nor the
 * supervisor's cycle (re_super).
 */
#ifndef RE_START_H
#define RE_START_H

#include <signal.h>
#include <stdint.h>

#include "re_calfile.h"
#include "re_calib.h"
#include "re_config.h"
#include "re_console.h"
#include "re_ctl.h"
#include "re_io.h"
#include "re_lock.h"
#include "re_log.h"
#include "re_plan.h"
#include "re_rec.h"
#include "re_relay.h"
#include "re_rt.h"
#include "re_super.h"

/* The start-up's exit codes (roboelf.1); roboelf-tech (roboelf-tech.1)
 * exits 2 and 3 too, and has its own 5 and 6 (tools/roboelf-tech). */
#define EXIT_USAGE     2
#define EXIT_CONNECT   3
#define EXIT_FAULT     4
#define DEFAULT_CONFIG "config/roboelf.yaml"
/* the installed one, under SYSCONFDIR (base_paths.h) */
#define SYSTEM_CONFIG "roboelf/roboelf.yaml"

struct app {
	const char *prog;	 /* "roboelf", "roboelf-tech": messages */
	const char *config_path; /* the configuration file in use */
	int calib_opt; /* --calibration: RE_CALIB_FULL, _FILE, or _ASK */
	struct re_config cfg;
	struct re_log log;
	struct re_console con;
	re_relay *relay;
	struct re_lock lock_ctl, lock_relay; /* one supervisor per each */
	struct re_io_real real;		     /* real.link: the command link */
	struct re_io io;
	struct re_ctl_info info;
	struct re_plan plan;
	struct re_seal seal; /* the program's sealed values (re_seal.h) */
	struct re_xcheck_cfg xcheck; /* the own joystick decode (re_xcheck.h) */
	struct re_calset *cal;
	struct re_super *sup;
	struct re_rec *rec;    /* flight recorder, NULL: none */
	struct re_rt_state rt; /* real time in force */
	const char *names[RE_AXES];
	long hbpc;
	int calib;   /* the operator's choice: RE_CALIB_FULL / _FILE */
	int powered; /* the relay was switched on at some point */
	unsigned foreign_shown;	 /* other programs' handles already shown */
	uint64_t ev_seen;	 /* the supervisor's events already shown */
	struct re_calib *calrun; /* the calibration running, or NULL */
	const struct re_calib_cfg *calcfg; /* its settings */
	int ctl_ours; /* the controller was taken over: ours to stop */
	int stream;   /* the record stream is open (controller.record) */
	/* after arming: 0 "Ready" not said yet, 1 said; held_said: the
	 * operator was told to release a joystick held at arming */
	int ready_said, held_said;
	char err[RE_CONFIG_ERR_MAX];
};

/* What the signal handlers (re_app_signals()) tell the start-up and the run
 * loop: @quit the signal that asks to quit (0: none); @continued a SIGCONT
 * came, after a stop of @cont_stop_ms ms measured from
 * @cont_real->last_run_ns (the last moment roboelf is known to have run). */
struct re_signals {
	volatile sig_atomic_t quit;
	volatile sig_atomic_t continued;
	volatile int64_t cont_stop_ms;
	struct re_io_real *volatile cont_real;
	volatile sig_atomic_t trace_asked; /* SIGUSR1: a trace now */
};
extern struct re_signals re_sig;

/*
 * re_start() - the whole start-up of @a (configuration and log already
 * loaded and open): locks, relay, controller, calibration, arming. Every
 * step is refused (exit 3, message on the console and in the log) or
 * latches a fault (exit 4) when it fails; a quit signal ends it early.
 * The terminal does not echo from here on (re_console_quiet()) but for the
 * answers to its questions; re_app_release() gives it back.
 * Return: 0 when armed (re_start_show_ready() then says "RoboELF Ready
 * for Use") or on a quit signal; EXIT_CONNECT, EXIT_USAGE or EXIT_FAULT
 * otherwise.
 */
int re_start(struct app *a);

/* How the bring-up connects: @find, on a connection refused (@why), may
 * find another controller, set a->cfg's address and return 0 (else it
 * says why and returns non-zero; NULL: the start is refused); @take_over
 * closes the other connections and checks the program's identity and
 * seal; @after runs after each stage (the stall check), or NULL. */
struct re_bringup {
	int (*find)(struct app *a, const char *why);
	int take_over;
	int (*after)(struct app *a);
};

/*
 * re_start_bringup() - the bring-up the supervised start and the
 * commissioning run share: the locks (one supervisor per controller and
 * relay), the relay opened and off, the controller connected, its route
 * checked, identified (the configured model) and not run by another
 * supervisor, then as @b says. A quit signal ends it early with 0.
 * Return: 0, or EXIT_CONNECT (said on the console and in the log).
 */
int re_start_bringup(struct app *a, const struct re_bringup *b);

/*
 * re_start_progress() - a start-up line on the console ("roboelf: ...")
 * and in the log, and roboelf known to have run now.
 * re_start_fail() - the start refused with @what, on the console and in
 * the log; a stop of roboelf just before is named first.
 * Return (fail): EXIT_CONNECT.
 */
void re_start_progress(struct app *a, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
int re_start_fail(struct app *a, const char *what);

/*
 * re_start_stall_limit_ms() - the critical reply-age limit, ms: a stop of
 * roboelf longer than this is a stall (from the supervisor once it
 * exists, else from the configuration).
 */
int64_t re_start_stall_limit_ms(const struct app *a);

/*
 * re_start_show_foreign() - another program connected to the controller
 * (@mask: its handles, bit n = handle n): not a fault (it may only look),
 * but the operator is told once per handle, on the console and in the log.
 */
void re_start_show_foreign(struct app *a, unsigned mask);

/*
 * re_start_show_events() - the supervisor's later faults and warnings not
 * shown yet go to the console's history (re_super_event(), in order).
 * No-op before the supervisor exists.
 */
void re_start_show_events(struct app *a);

/*
 * re_start_show_ready() - after each armed cycle: "RoboELF Ready for Use"
 * (console and log) once the controller's record shows that its motion
 * thread has seen the joystick neutral since arming (ZAC mneut, program
 * 2.10): from then on a command moves its axis. While the record shows a
 * command held since arming, the operator is told once to release it.
 * No-op before arming, once said, or with a fault latched.
 */
void re_start_show_ready(struct app *a);

#endif /* RE_START_H */
