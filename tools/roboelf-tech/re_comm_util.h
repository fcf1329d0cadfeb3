/*
 * re_comm_util.h - the small controller helpers the commissioning run's
 * steps share (re_comm_fw.c, re_comm_wire.c, re_comm_move.c). Not for use
 * outside the re_comm modules.
 */
#ifndef RE_COMM_UTIL_H
#define RE_COMM_UTIL_H

#include "re_comm.h"

/* A text being written into a fixed buffer (the report, a plot's script). */
struct rc_text {
	char *p;
	size_t n, cap; /* bytes written, the buffer's size */
};

/*
 * rc_text_put() - append printf-style text to @b. Once the buffer is full
 * (b->n >= b->cap) nothing more is written: the writer checks b->n < b->cap
 * at the end to know the text is whole.
 */
void rc_text_put(struct rc_text *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* Technician-facing prompts start with this (tests wait for it). */
#define RC_PROMPT "commission: "

/*
 * re_comm_add() - append a report item (printf-style text); the fix may be
 * NULL. Returns @res, so that a check can `return re_comm_add(...)`.
 * An item beyond RE_COMM_ITEMS is dropped (the count stays).
 */
enum re_comm_res re_comm_add(struct re_comm *c, const char *step,
			     const char *name, enum re_comm_res res,
			     const char *fix, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));

/*
 * rc_say() - one line to the technician (printf-style), prefixed with
 * RC_PROMPT. No return value.
 */
void rc_say(struct re_comm *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/*
 * rc_cmd() - one command line through c->io; @resp may be NULL.
 * Return: the reply length (>= 0) or the link's error (GL_ERR_CTRL: the
 *         controller answered '?', rc_tc() has its TC1).
 */
int rc_cmd(struct re_comm *c, const char *cmd, char *resp, size_t cap);

/*
 * rc_tc() - the controller's TC1 text after GL_ERR_CTRL (never NULL) and
 * its code in @code (may be NULL).
 */
const char *rc_tc(struct re_comm *c, int *code);

/*
 * rc_num() - the one number "MG @expr" answers. Return: as re_io_read().
 */
int rc_num(struct re_comm *c, const char *expr, double *v);

/* rc_quit() - the run was asked to stop (c->quit set): waits return
 * GL_ERR_AGAIN, which re_comm_run() reports as an interruption. */
int rc_quit(const struct re_comm *c);

/* rc_sleep_ms() - wait @ms through the io's clock. */
void rc_sleep_ms(struct re_comm *c, int ms);

/* rc_now_ms() - the io's monotonic clock, ms. */
double rc_now_ms(struct re_comm *c);

/*
 * rc_link_fail() - record a FAIL item for a link or controller error @rc
 * met in @step while doing @what. Return: @rc.
 */
int rc_link_fail(struct re_comm *c, const char *step, const char *what, int rc);

/*
 * rc_safe() - stop every axis and switch the motors off (AB 1;MO ABC), then
 * the relay off (confirmed within its deadline) and the configured
 * motor-power output cleared (CB n). Best effort on every
 * path. Return: GL_OK when both were confirmed, else the first error.
 */
int rc_safe(struct re_comm *c);

/*
 * rc_guard() - the direct probes under the program's probe watchdog:
 * @on 1 starts #PRWD in thread 0 (the program halted) and makes every
 * rc_sleep_ms() write the next hbpc first, so that a commissioning run that
 * dies mid-probe leaves the motors on at most wdto + mainms; @on 0 ends it
 * (HX0).
 * Return: GL_OK, or the link's error (GL_ERR_CTRL: no #PRWD, load dmc/).
 */
int rc_guard(struct re_comm *c, int on);

/*
 * rc_lane_start() - @l starts now (cleared). rc_lane_mark() - the set
 * @mask seen now: kept when it differs from the last one (the end time
 * moves on anyway). rc_lane_ask() - the technician is asked for @what now.
 * Entries beyond the arrays are dropped.
 */
void rc_lane_start(struct re_comm *c, struct re_comm_lanes *l);
void rc_lane_mark(struct re_comm *c, struct re_comm_lanes *l, unsigned mask);
void rc_lane_ask(struct re_comm *c, struct re_comm_lanes *l, const char *what);

#endif /* RE_COMM_UTIL_H */
