/*
 * ctrl_thread.h - the program threads as state and the automatic subroutines
 * (ctrl_thread.c); internal to the simulated controller (ctrl/), not part of
 * its API (ctrl.h).
 * It runs no statement (ctrl_exec.h).
 */
#ifndef SIM_CTRL_THREAD_H
#define SIM_CTRL_THREAD_H

#include "ctrl_int.h"

/*
 * ctrl_xc_who() - who runs the statement of @x, as events name it: "handle
 * B" (a host), "thread 0 line 57" (a program thread, 0-based line) or
 * "private port" (ctrl_command()). @buf gets at most @cap bytes
 * (CTRL_WHO_LEN is enough), NUL-terminated.
 */
void ctrl_xc_who(const struct ctrl_xc *x, char *buf, size_t cap);
/* ctrl_tc_text() - the TC1 text of code @tc (static), or "" if unknown. */
const char *ctrl_tc_text(int tc);
/*
 * ctrl_thread_boot() - the end of power-up: #AUTO of the program in memory
 * starts in thread 0, once. Called at the first sample and before the first
 * host byte or download, whichever comes first: a controller answers the
 * host only once booted, so a download that arrives before the first sample
 * meets the program as booted and is never followed by its own #AUTO
 * starting by itself.
 */
void ctrl_thread_boot(struct ctrl *c);

/* ctrl_any_running() - 1 when any of the 8 threads runs, else 0. */
int ctrl_any_running(const struct ctrl *c);
/*
 * ctrl_thread_start() - (re)start thread @t (0..7) at statement @pc: its
 * stack, trippoint and parameters are cleared, the AT reference is now.
 */
void ctrl_thread_start(struct ctrl *c, int t, int pc);
/*
 * ctrl_thread_halt() - stop thread @t (0..7) if it runs, with the event
 * "thread t stopped: @why"; ctrl_threads_halt_all() does it for all 8.
 */
void ctrl_thread_halt(struct ctrl *c, int t, const char *why);
void ctrl_threads_halt_all(struct ctrl *c, const char *why);
/* ctrl_thread_line() - _XQn: 0-based line of thread @t, or -1 if stopped. */
int ctrl_thread_line(const struct ctrl *c, int t);
/* ctrl_thread_waiting() - 1 when thread @t runs and waits at a trippoint. */
int ctrl_thread_waiting(const struct ctrl *c, int t);
/*
 * ctrl_autosub_raise() - mark automatic subroutine @which (enum
 * ctrl_autosub) pending; ctrl_autosubs_dispatch() enters pending ones in
 * thread 0 (by priority, #CMDERR may interrupt the others) and drops those
 * the program lacks.
 */
void ctrl_autosub_raise(struct ctrl *c, int which);
void ctrl_autosubs_dispatch(struct ctrl *c);
/* ctrl_autosub_label() - first line of #CMDERR etc. in RAM, or -1. */
int ctrl_autosub_label(const struct ctrl *c, int which);
/* ctrl_autosub_active() - 1 when thread 0 is inside @which (-1: any). */
int ctrl_autosub_active(const struct ctrl *c, int which);

#endif /* SIM_CTRL_THREAD_H */
