/*
 * sys_exact_h.h - the fixture of the system tests that assert the exact
 * text the operator sees ("one master, and faults that name their real
 * cause": test_sys_second, test_sys_foreign, test_sys_jam,
 * test_sys_firstcause, test_sys_logfull), on galil-sim running dmc/
 * (downloaded by galil-load) with roboelf supervising it through the
 * virtual relay.
 *
 * One full calibration per test program (sx_group_setup(); when its first
 * try fails, a second one gives the cases their file, and the failure is
 * still reported), then every case on a fresh galil-sim with
 * `--calibration file` (sx_start()). Every roboelf started here gets
 * ROBOELF_LOCK_DIR inside the temporary directory.
 *
 * Each case asserts the whole line (sx_expect_text(): in a template "{n}"
 * stands for a number, "{t}" for a local time, "{s}" for a text) and the
 * reaction time from galil-sim's events (simulated ms) against the
 * deadlines of docs/safety.md section 3 plus SX_SLACK_MS. Each case fills
 * a row of the summary table (sx_row_begin() ...) and prints a
 * "[ MEASURE  ]" line; the group's tear-down prints the table: case |
 * outcome | reaction | exact FAULT line or message.
 *
 * Built on sys_h.h. Unlike sys_h, these helpers fail the running cmocka
 * test themselves (fail_msg(), which does not return) and print through
 * cmocka, as the tests did: they link only into cmocka test programs.
 */
#ifndef SYS_EXACT_H_H
#define SYS_EXACT_H_H

#include <stddef.h>

#include "sys_h.h"

#define SX_SLACK_MS	 25   /* scheduling allowance (docs/safety.md, 3) */
#define SX_HOLD_MS	 300  /* no motion over this after the safe state */
#define SX_FAULT_WAIT_MS 8000 /* a FAULT line, beyond any deadline */
#define SX_EXIT_WAIT_MS	 5000 /* roboelf exits after SIGTERM */
#define SX_TEXT_MAX	 2048

/* Recovery texts and confirmations, as roboelf prints them
 * (pc/super/re_fault.c, pc/super/re_react.c; docs/operator.md section 7). */
#define SX_SAFE_OK                                                             \
	" Safe state confirmed: motor power off (relay open), motors off."
/* The sentence that names another program's connection (%c: its handle). */
#define SX_OTHER_PROG                                                          \
	" Another program had connected to the controller (handle %c)."

/* ---- the summary table -------------------------------------------------- */

/* One row of the summary table. */
struct sx_row {
	char name[48];
	char outcome[160];
	char reaction[320];
	char text[SX_TEXT_MAX];
};

/*
 * sx_row_begin() - a new row named @name, "FAILED" until sx_row_pass(): a
 * failed case leaves it so. Beyond 40 rows a spare row is reused (not
 * printed).
 * Return: the row, never NULL.
 */
struct sx_row *sx_row_begin(const char *name);

/* sx_row_reaction() - the row's reaction (printf-style), also printed as
 * a "[ MEASURE  ] <name>: <reaction>" line. */
void sx_row_reaction(struct sx_row *r, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* sx_row_text() - the row's exact FAULT line or message. */
void sx_row_text(struct sx_row *r, const char *text);

/* sx_row_pass() - the row's outcome (printf-style): the case passed. */
void sx_row_pass(struct sx_row *r, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* ---- exact texts -------------------------------------------------------- */

/*
 * sx_expect_text() - fail the test (named @what) unless @line is exactly
 * @tpl, where "{n}" stands for one number, "{t}" for a local time
 * "YYYY-MM-DD HH:MM:SS" and "{s}" for a non-empty text; the message shows
 * where they part.
 * @num: [out] the numbers matched, up to @max (may be NULL when @max is 0).
 * Return: the count of numbers matched.
 */
int sx_expect_text(const char *what, const char *tpl, const char *line,
		   double *num, int max);

/* ---- the group and its cases -------------------------------------------- */

/* A test program's fixture (sx_group_setup()). */
struct sx_fixture {
	struct sys_env *env;
	int ok; /* calibrated: the cases can run */
	/* the first full calibration's failure, or "", and its FAULT line
	 * from its log, or "" */
	char cal_fail[SYS_ERR_MAX], cal_line[SX_TEXT_MAX];
	/* the lock directory of this "host", and one of another host */
	char lock_dir[SYS_PATH_MAX], lock_dir2[SYS_PATH_MAX + 8];
	/* "ROBOELF_LOCK_DIR=" each of them, for a roboelf's environment */
	char lock_env[SYS_PATH_MAX + 32], lock_env2[SYS_PATH_MAX + 40];
	char *re_env[2]; /* {lock_env, NULL} */
};

/*
 * sx_group_setup() - a group's set-up: sys_env_init(@env), the two lock
 * directories (ROBOELF_LOCK_DIR set to the first for this process and its
 * children), one full calibration and, when it fails, a second one (the
 * first's failure kept in @fx->cal_fail); then an INFO line. @fx keeps
 * @env.
 * Return: 0 (the cases fail with @env->err when @fx->ok is 0).
 */
int sx_group_setup(struct sx_fixture *fx, struct sys_env *env);

/*
 * sx_group_teardown() - a group's tear-down: print the summary table,
 * remove the lock directories and the temporary directory (kept when the
 * calibration failed).
 * @first_cal_tested: 1 when the program reports the first calibration's
 * failure in a test of its own (test_full_calibration); 0: the tear-down
 * reports it.
 * Return: 0, or -1 (cmocka then fails the group) when the first
 * calibration failed and @first_cal_tested is 0: the second try never
 * hides a failed calibration.
 */
int sx_group_teardown(struct sx_fixture *fx, int first_cal_tested);

/*
 * sx_start_with() - sys_case_start() with @o and the lock directory in
 * roboelf's environment; fails the test when the group is not calibrated
 * or the case does not start.
 */
void sx_start_with(struct sys_case *c, struct sx_fixture *fx,
		   struct sys_opts *o);

/* sx_start() - the first roboelf, armed (sx_start_with(), default
 * options); its heartbeat, state and fault watched (watch state, fcode,
 * fdet, hbpc). Fails the test when it cannot. */
void sx_start(struct sys_case *c, struct sx_fixture *fx);

/* ---- deadlines (docs/safety.md, section 3) ------------------------------ */

/* sx_p() - P, the configured period, ms. */
double sx_p(const struct sys_env *env);

/* sx_d_ctrl_to_relay() - a fault the controller latches reaches the relay
 * within M + 2P, ms. */
double sx_d_ctrl_to_relay(const struct sys_env *env);

/* ---- events and the state line ------------------------------------------ */

/*
 * sx_wait_event() - wait for an event at or after @after starting with
 * @prefix and, when @sub is not NULL, containing @sub, fetching events
 * every 15 ms and pumping roboelf's output; fails the test after
 * @timeout_ms (wall).
 * Return: its index in c->ev.
 */
int sx_wait_event(struct sys_case *c, const char *prefix, const char *sub,
		  double after, int timeout_ms);

/*
 * sx_wait_motors_off() - every motor switched off after @after
 * (sys_motors_off_time()); fails the test when not within @ms (wall).
 * Return: the time of the last one (simulated ms).
 */
double sx_wait_motors_off(struct sys_case *c, double after, int ms);

/* sx_state_num() - a number of a fresh state line ("A.act"); fails the
 * test when there is none. */
double sx_state_num(struct sys_case *c, const char *key);

/*
 * sx_handle_of() - the handle letter galil-sim gave the connection @fd
 * ("handle C opened from 127.0.0.1:<its port>", at or after @after); fails
 * the test when that event does not come within 3 s.
 * @t: [out] the event's time.
 * Return: the letter.
 */
char sx_handle_of(struct sys_case *c, int fd, double after, double *t);

/*
 * sx_inject() - send the control request @req and wait for its event
 * (@evt, "inject: " or "input: ", then @req); fails the test when either
 * fails.
 * Return: the event's simulated time.
 */
double sx_inject(struct sys_case *c, const char *evt, const char *req);

/* ---- FAULT lines -------------------------------------------------------- */

/*
 * sx_not_own_request() - fail the test when the FAULT @line names the
 * supervisor's own fault request (pcflt=1, the program's fault 12) as a
 * consequence: docs/supervisor.md, fault reaction step 5, names as "Then:"
 * only a fault the controller latched by itself.
 */
void sx_not_own_request(const char *line);

/*
 * sx_tpl_encpot() - the ENCODER pot/encoder FAULT line of @axis as a
 * template into @tpl; its numbers are pot, expected, position[, in units],
 * difference, allowed, cycles.
 * Return: how many numbers the position takes (1, or 2 with a unit).
 */
int sx_tpl_encpot(const struct sys_env *env, char *tpl, size_t cap, int axis);

/*
 * sx_check_encpot_units() - fail the test unless the position of an
 * ENCODER pot/encoder line (matched by sx_tpl_encpot() with @k numbers for
 * it, into @num) in units is the one in counts, to 2 decimals.
 */
void sx_check_encpot_units(const struct sys_env *env, const double *num, int k,
			   int axis, const char *line);

#endif /* SYS_EXACT_H_H */
