/*
 * test_sys_hostile.c - another client writes to the controller while
 * roboelf drives the armed robot (docs/safety.md H12): each write of the
 * review that found the protection rewritable, sent from a raw TCP client
 * on the controller's command port, some while the joystick jogs axis A.
 * Each must end in the safe state with a FAULT line that names a value the
 * write changed, within the seal's bound: the program checks every sealed
 * value within RE_SEAL_SLICES main passes, roboelf sees the latch in its
 * next record and cuts motor power (relay off), and reads every value back
 * itself within about a second.
 *
 * Also galil-load -c with writes on the armed robot: refused, nothing
 * changed, the robot still armed.
 *
 * Each case prints one "[ ROW      ]" line: write | caught by | relay off
 * ms after the write | the FAULT line (docs/safety.md, the closing note).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "re_seal.h"
#include "sys_h.h"
#include "sys_truth.h"

#define SLACK_MS      25  /* scheduling allowance on a busy 2-core box */
#define HOLD_MS	      300 /* no motion over this after the safe state */
#define FAULT_WAIT_MS 5000
#define TRAVEL_BOUND  1500 /* counts axis A may run after the write */

static struct sys_env env;
static int env_ok;

/* The relay off after a write, at the latest: the program finds the value
 * within RE_SEAL_SLICES passes (plus the pass under way), roboelf sees
 * the latch in its next record and settles on the program's verdict,
 * then cuts power: (slices + 1) mainms + 2 P + settle. */
static double d_write_to_relay(void)
{
	return (RE_SEAL_SLICES + 1) * SYS_MAINMS + 2.0 * env.period_ms +
	       (2 * SYS_MAINMS + 5) + SLACK_MS;
}

struct hcase {
	const char *write;    /* one line from the other client */
	int jog;	      /* 1: the joystick jogs A forward meanwhile */
	const char *named[4]; /* the FAULT line names one of these */
	double bound_ms;      /* relay off after the write; 0: the seal's */
	double travel;	      /* counts A may run after it; 0: TRAVEL_BOUND */
};

/* A fresh armed robot, a raw client's write, the FAULT, the safe state. */
static void hostile(const struct hcase *h)
{
	struct sys_case c;
	char line[2048], row[2600];
	double t0, t_relay, a0, a1;
	double bound = h->bound_ms > 0 ? h->bound_ms : d_write_to_relay();
	double travel = h->travel > 0 ? h->travel : TRAVEL_BOUND;
	int fd, named = -1;
	char st[2048];

	if (!env_ok)
		fail_msg("no calibrated environment: %s", env.err);
	if (sys_case_start(&c, &env, NULL) < 0)
		fail_msg("case start: %s", c.err);
	if (h->jog) {
		if (sys_ctl(&c, "joy A fwd") < 0 ||
		    sys_wait_moving(&c, 'A', 300, 3000) < 0)
			fail_msg("jogging A: %s", c.err);
	}
	if (sys_state(&c, st, sizeof(st)) < 0)
		fail_msg("%s", c.err);
	a0 = sys_state_num(st, "A.act");
	fd = sys_cmd_open(&c);
	if (fd < 0)
		fail_msg("%s", c.err);
	t0 = sys_sim_time(&c);
	(void)sys_cmd(fd, h->write, 1000);
	if (sys_wait_fault(&c, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("'%s': no FAULT line: %s", h->write, c.err);
	if (sys_wait_event(&c, "relay off", t0, 3000, &t_relay) < 0)
		fail_msg("'%s': no relay off: %s", h->write, c.err);
	if (sys_ctl(&c, "joy A neutral") < 0 ||
	    sys_check_safe(&c, 0, HOLD_MS) < 0)
		fail_msg("'%s': not safe: %s", h->write, c.err);
	if (sys_truth_check(&c, line, t0, 0) < 0)
		fail_msg("'%s': %s", h->write, c.err);
	if (sys_state(&c, st, sizeof(st)) < 0)
		fail_msg("%s", c.err);
	a1 = sys_state_num(st, "A.act");
	for (int k = 0; k < 4 && h->named[k]; k++)
		if (strstr(line, h->named[k]))
			named = k;
	snprintf(row, sizeof(row),
		 "%s | armed%s | relay off %.0f ms "
		 "(bound %.0f), A ran %.0f counts | %s",
		 h->write, h->jog ? ", A jogging" : "", t_relay - t0, bound,
		 a1 - a0, line);
	print_message("[ ROW      ] %s\n", row);
	close(fd);
	sys_case_stop(&c);
	if (named < 0)
		fail_msg("the FAULT line names none of the values written: %s",
			 line);
	if (strncmp(line, "FAULT FOREIGN: ", 15) &&
	    strncmp(line, "FAULT INPUT: ", 13) &&
	    strncmp(line, "FAULT MOTION: ", 14))
		fail_msg("not a FOREIGN, INPUT or MOTION fault: %s", line);
	if (t_relay - t0 > bound)
		fail_msg("relay off %.0f ms after the write (bound %.0f)",
			 t_relay - t0, bound);
	if (a1 - a0 > travel || a0 - a1 > TRAVEL_BOUND / 10)
		fail_msg("axis A ran %.0f counts after the write", a1 - a0);
}

/* The joystick's wiring swapped (A forward would run A backwards). */
static void test_jin_swapped(void **state)
{
	static const struct hcase h = {"jin[0]=3;jin[1]=4;jin[2]=1;jin[3]=2",
				       1,
				       {"jin[0]", "jin[1]", "jin[2]", "jin[3]"},
				       0,
				       0};

	(void)state;
	hostile(&h);
}

/* The speed limits raised while A jogs. */
static void test_speed_raised(void **state)
{
	static const struct hcase h = {"vla=100000;vmax[0]=40000",
				       1,
				       {"vla", "vmax[0]", NULL, NULL},
				       0,
				       0};

	(void)state;
	hostile(&h);
}

/* The ramp removed. */
static void test_ramp_removed(void **state)
{
	static const struct hcase h = {"wst[0]=0;wen[0]=1;vmin[0]=8000",
				       0,
				       {"wst[0]", "wen[0]", "vmin[0]", NULL},
				       0,
				       0};

	(void)state;
	hostile(&h);
}

/* The position-error and encoder-failure protections loosened. */
static void test_protections_loosened(void **state)
{
	static const struct hcase h = {
	    "ER 30000,30000,30000;OA 0,0,0;TL 9.99,9.99,9.99",
	    0,
	    {"_ERA", "_OAA", "_TLA", "_ERB"},
	    0,
	    0};

	(void)state;
	hostile(&h);
}

/* The soft limit, FL and the limit switches disabled. */
static void test_limits_opened(void **state)
{
	static const struct hcase h = {
	    "sfwd[0]=2000000000;FL 2147483647,2147483647,2147483647;LD 3,3,3",
	    1,
	    {"sfwd[0]", "_FLA", "_LDA", NULL},
	    0,
	    0};

	(void)state;
	hostile(&h);
}

/* The controller's watchdog stretched, with its copy. */
static void test_watchdog_stretched(void **state)
{
	static const struct hcase h = {
	    "wdto=5000;wdtoa=5000", 0, {"wdto", NULL, NULL, NULL}, 0, 0};

	(void)state;
	hostile(&h);
}

/* The heartbeat's sequence window opened. */
static void test_heartbeat_window(void **state)
{
	static const struct hcase h = {
	    "hbmaxd=999999999", 0, {"hbmaxd", NULL, NULL, NULL}, 0, 0};

	(void)state;
	hostile(&h);
}

/* The motion thread started a second time. */
static void test_second_motion_thread(void **state)
{
	static const struct hcase h = {
	    "XQ #MOTION,2", 1, {"_XQ2", NULL, NULL, NULL}, 0, 0};

	(void)state;
	hostile(&h);
}

/* Gains, limit polarity, limit switches: one setting at a time. */
static void test_settings(void **state)
{
	static const struct hcase h[] = {
	    {"KP 1000,1000,1000", 0, {"_KPA", NULL, NULL, NULL}, 0, 0},
	    {"CN 1", 0, {"_CN0", NULL, NULL, NULL}, 0, 0},
	    {"LD 3,3,3", 0, {"_LDA", NULL, NULL, NULL}, 0, 0},
	    {"DC 1024,1024,1024", 0, {"_DCA", NULL, NULL, NULL}, 0, 0},
	};

	(void)state;
	for (size_t k = 0; k < sizeof(h) / sizeof(h[0]); k++)
		hostile(&h[k]);
}

/* Ownership forged and the speed limit raised, then B moved: named as B's
 * limit or B's motion, never as axis A. */
static void test_ownership_forged(void **state)
{
	static const struct hcase h = {"own[1]=1;vlb=100000;PR ,-3000;BG B",
				       0,
				       {"vlb", "axis B", NULL, NULL},
				       0,
				       0};

	(void)state;
	hostile(&h);
}

/* The program's own state rewritten: the ramp's time base moved back, so
 * the program would start A's rise at once. The program bounds the rise
 * (rampov x the slope from the speed A runs at); roboelf's own ramp check,
 * from its own first sight of the command, stops it: the speed must pass
 * vover x the ramp beyond TV's 256-sample average, for two cycles
 * (bound: 1 s). */
static void test_ramp_time_base(void **state)
{
	static const struct hcase h = {
	    "tcmd=-1000000", 1, {"ramp", NULL, NULL, NULL}, 1000, 3000};

	(void)state;
	hostile(&h);
}

/* An idle axis's ownership forged, then moved by the client at the speed
 * the program allows it: the program takes the move for its own; roboelf
 * sees an axis run that no command moves. */
static void test_owned_move(void **state)
{
	static const struct hcase h = {
	    "own[1]=1;PR ,-3000;BG B", 0, {"axis B", "B:", NULL, NULL}, 0, 0};

	(void)state;
	hostile(&h);
}

/* galil-load -c with writes on the armed robot: refused (exit 5), nothing
 * written, the robot still armed and jogging; a read passes. */
static void test_galil_load_refused(void **state)
{
	struct sys_case c;
	char bin[SYS_PATH_MAX + 16], addr[32];
	char *argv[] = {bin,
			(char *)"-a",
			addr,
			(char *)"-c",
			(char *)"hbmaxd=999999999",
			(char *)"-c",
			(char *)"jin[0]=3;jin[1]=4",
			NULL};
	char *reads[] = {bin,	       (char *)"-a",	    addr,
			 (char *)"-c", (char *)"MG hbmaxd", NULL};
	struct proc p;

	(void)state;
	if (!env_ok)
		fail_msg("no calibrated environment: %s", env.err);
	if (sys_case_start(&c, &env, NULL) < 0)
		fail_msg("case start: %s", c.err);
	snprintf(bin, sizeof(bin), "%s/galil-load", env.bin);
	snprintf(addr, sizeof(addr), "%s:%d", c.sim_addr, c.sim.port);
	assert_int_equal(proc_spawn(&p, argv, NULL), 0);
	assert_int_equal(proc_wait_exit(&p, 10000, NULL), 0);
	assert_int_equal(proc_exit_code(&p), 5);
	assert_string_equal(
	    proc_output(&p, PROC_STDERR),
	    "galil-load: 'hbmaxd=999999999' writes to the controller, and its "
	    "program is armed: a write could change how the robot moves or "
	    "is stopped. Refused (reads such as MG, TP and 'KP ?,?' are "
	    "allowed); quit roboelf first, or give --force to send it anyway "
	    "(the program latches a fault if it changes a sealed value)\n");
	proc_kill(&p);
	assert_int_equal(proc_spawn(&p, reads, NULL), 0);
	assert_int_equal(proc_wait_exit(&p, 10000, NULL), 0);
	assert_int_equal(proc_exit_code(&p), 0);
	assert_string_equal(proc_output(&p, PROC_STDOUT), " 102.0000\n");
	proc_kill(&p);
	if (sys_ctl(&c, "watch state") < 0 || sys_ctl(&c, "joy A fwd") < 0 ||
	    sys_wait_moving(&c, 'A', 300, 3000) < 0 ||
	    sys_still_armed(&c, "after galil-load's refusal") < 0)
		fail_msg("%s", c.err);
	sys_case_stop(&c);
}

static int group_setup(void **state)
{
	(void)state;
	env_ok = sys_env_ready(&env);
	return 0;
}

static int group_teardown(void **state)
{
	(void)state;
	sys_env_done(&env, env_ok);
	return 0;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_jin_swapped),
	    cmocka_unit_test(test_speed_raised),
	    cmocka_unit_test(test_ramp_removed),
	    cmocka_unit_test(test_protections_loosened),
	    cmocka_unit_test(test_limits_opened),
	    cmocka_unit_test(test_watchdog_stretched),
	    cmocka_unit_test(test_heartbeat_window),
	    cmocka_unit_test(test_second_motion_thread),
	    cmocka_unit_test(test_settings),
	    cmocka_unit_test(test_ownership_forged),
	    cmocka_unit_test(test_ramp_time_base),
	    cmocka_unit_test(test_owned_move),
	    cmocka_unit_test(test_galil_load_refused),
	};

	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
