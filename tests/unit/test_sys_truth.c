/*
 * test_sys_truth.c - the system tests' truth check (tests/harness/
 * sys_truth) on recorded text: roboelf's FAULT lines and log entries, and
 * galil-sim's event logs, as the system tests saw them.
 *
 * Covered: a true report agrees (no mismatch); each false statement found
 * in earlier runs is caught, naming the fact, the printed and the recorded
 * value: the first cause named on the wrong axis and a consequence on an
 * axis the controller never switched off itself (B's potentiometer
 * reported as A's, on the FAULT line and on the status line's controller
 * field), "stop command not delivered" when galil-sim shows the
 * stop arrived (a new connection answered '?'; a reply held back 300 ms),
 * "motor power off" while the amplifiers kept it; what roboelf now says
 * when it cannot know (no mismatch either way); the parsers' details
 * (the log's stop time, foreign handles, motors on, bad input).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "sys_truth.h"

#define SAFE_OK                                                                \
	" Safe state confirmed: motor power off (relay open), motors off."
#define REC_POT                                                                \
	" Recovery: press the E-stop and keep it pressed, check the encoder "  \
	"and potentiometer cables of axis %c, restart roboelf and recalibrate"

/* Recorded: test_sys_faults "pot offset" on axis A (galil-sim's events
 * from the motors' switch-on to the fault). */
static const char ev_pot_a[] =
    "48 relay on (byte 0x65)\n"
    "48 amplifier power restored\n"
    "193 axis A motor on: SH (thread 0 line 150)\n"
    "193 axis B motor on: SH (thread 0 line 150)\n"
    "193 axis C motor on: SH (thread 0 line 150)\n"
    "193 thread 1 started at line 454\n"
    "248 inject: pot A offset 0.5\n"
    "346 AB 1 received (handle A)\n"
    "346 axis A motor off: abort with OE set (handle A)\n"
    "346 axis B motor off: abort with OE set (handle A)\n"
    "346 axis C motor off: abort with OE set (handle A)\n"
    "346 MO received (handle A)\n"
    "346 relay off (byte 0x6f)\n"
    "346 amplifier power lost (under-voltage)\n"
    "347 thread 1 stopped: halted by HX (thread 0 line 433)\n";

static const char line_pot_a[] =
    "FAULT ENCODER: axis A: potentiometer reads 3.049 V but 2.550 V is "
    "expected at encoder position -10 counts (-0.01 deg); they differ by "
    "0.500 V, more than the 0.059 V allowed, for 2 cycles." SAFE_OK
    " Recovery: press the E-stop and keep it pressed, check the encoder "
    "and potentiometer cables of axis A, restart roboelf and recalibrate";

static const char log_pot_a[] =
    "2026-11-29T05:22:50.963Z FAULT FAULT ENCODER: axis A: ... | relay "
    "off: confirmed | controller stop: delivered (0.1 ms) | motors off: "
    "confirmed | cycle 7, reply age 50.0 ms; A enc=-10";

/* Said and true, compared; @buf gets the mismatches. */
static int check(const char *line, const char *log, const char *ev,
		 double after, unsigned foreign, char *buf, size_t cap)
{
	struct sys_facts said, truth;

	assert_int_equal(sys_truth_said(line, log, &said), 0);
	assert_int_equal(sys_truth_true(ev, after, -1, foreign, &truth), 0);
	return sys_truth_compare(&said, &truth, buf, cap);
}

static void test_true_report_agrees(void **state)
{
	struct sys_facts said, truth;
	char buf[1024];

	(void)state;
	assert_int_equal(sys_truth_said(line_pot_a, log_pot_a, &said), 0);
	assert_string_equal(said.cls, "ENCODER");
	assert_int_equal(said.axis, 'A');
	assert_int_equal(said.then_axis, 0);
	assert_int_equal(said.delivered, SYS_YES);
	assert_int_equal(said.relay_open, SYS_YES);
	assert_int_equal(said.power_off, SYS_YES);
	assert_int_equal(said.motors_off, SYS_YES);
	assert_true(said.stop_ms == 0.1);
	assert_int_equal(sys_truth_true(ev_pot_a, 248, -1, 0, &truth), 0);
	assert_string_equal(truth.cls, "ENCODER");
	assert_int_equal(truth.axis, 'A');
	assert_string_equal(truth.first_ev, "inject: pot A offset 0.5");
	assert_string_equal(truth.stop_ev, "AB 1 received (handle A)");
	assert_int_equal(truth.delivered, SYS_YES);
	assert_int_equal(truth.relay_open, SYS_YES);
	assert_int_equal(truth.power_off, SYS_YES);
	assert_int_equal(truth.motors_off, SYS_YES);
	assert_string_equal(truth.self_off, "");
	assert_int_equal(sys_truth_compare(&said, &truth, buf, sizeof(buf)), 0);
	assert_string_equal(buf, "");
}

/* Statement a: a fault on B's potentiometer named on axis A, and the
 * controller's motor-off on A (our own stop's doing) told as a
 * consequence. */
static void test_wrong_axis_caught(void **state)
{
	static const char ev[] =
	    "193 axis A motor on: SH (thread 0 line 150)\n"
	    "193 axis B motor on: SH (thread 0 line 150)\n"
	    "193 axis C motor on: SH (thread 0 line 150)\n"
	    "248 inject: pot B offset 0.5\n"
	    "346 AB 1 received (handle A)\n"
	    "346 axis A motor off: abort with OE set (handle A)\n"
	    "346 axis B motor off: abort with OE set (handle A)\n"
	    "346 axis C motor off: abort with OE set (handle A)\n"
	    "346 relay off (byte 0x6f)\n"
	    "346 amplifier power lost (under-voltage)\n";
	char line[1024], buf[1024];

	(void)state;
	snprintf(line, sizeof(line),
		 "FAULT ENCODER: axis A: potentiometer reads 3.049 V. Then: "
		 "axis A: the controller found the motor off while armed: "
		 "abort command (stop code 7)." SAFE_OK REC_POT,
		 'A');
	assert_int_equal(check(line, NULL, ev, 248, 0, buf, sizeof(buf)), 2);
	assert_string_equal(
	    buf, "first cause's axis: roboelf printed A, galil-sim recorded B "
		 "(inject: pot B offset 0.5)\n"
		 "consequence on axis A: roboelf printed that the controller "
		 "switched it off, galil-sim recorded no motor off on A but by "
		 "a host's command (by itself: '')\n");
	/* the true line: B, no consequence */
	snprintf(line, sizeof(line),
		 "FAULT ENCODER: axis B: potentiometer reads 3.049 V." SAFE_OK
		     REC_POT,
		 'B');
	assert_int_equal(check(line, NULL, ev, 248, 0, buf, sizeof(buf)), 0);
}

/* Statement a on the status line: after B's potentiometer fault, the
 * controller's fault shown as a motor-off fault on A (our own MO ABC had
 * switched A off; the program checked A first). */
static void test_ctrl_line_caught(void **state)
{
	static const char ev[] =
	    "193 axis A motor on: SH (thread 0 line 150)\n"
	    "193 axis B motor on: SH (thread 0 line 150)\n"
	    "248 inject: pot B offset 0.5\n"
	    "346 AB 1 received (handle A)\n"
	    "346 axis A motor off: abort with OE set (handle A)\n"
	    "346 axis B motor off: abort with OE set (handle A)\n"
	    "346 relay off (byte 0x6f)\n";
	static const char line[] =
	    "FAULT ENCODER: axis B: potentiometer reads 3.049 V." SAFE_OK
	    " Recovery: x";
	static const char out_old[] =
	    "roboelf: RoboELF Ready for Use\n"
	    "status 1.0s mode=development relay=on link=ok ctrl=\"armed\" A "
	    "enc=0\n"
	    "FAULT ENCODER: axis B: potentiometer reads 3.049 V. x\n"
	    "status 2.0s mode=development relay=off link=ok ctrl=\"FAULT "
	    "MOTOR OFF axis A (code 10)\" A enc=0\n";
	static const char out_new[] =
	    "FAULT ENCODER: axis B: potentiometer reads 3.049 V. x\n"
	    "status 2.0s mode=development relay=off link=ok ctrl=\"stopped "
	    "by the supervisor (code 10)\" A enc=0\n";
	struct sys_facts said, truth;
	char buf[1024];

	(void)state;
	assert_int_equal(sys_truth_said(line, NULL, &said), 0);
	sys_truth_said_status(out_old, &said);
	assert_int_equal(said.ctrl_axis, 'A');
	assert_string_equal(said.ctrl_text, "FAULT MOTOR OFF axis A (code 10)");
	assert_int_equal(sys_truth_true(ev, 248, -1, 0, &truth), 0);
	assert_int_equal(sys_truth_compare(&said, &truth, buf, sizeof(buf)), 1);
	assert_string_equal(buf, "the controller's fault: roboelf printed "
				 "'FAULT MOTOR OFF axis A (code 10)', "
				 "galil-sim recorded the first cause on B "
				 "(inject: pot B offset 0.5) and no motor off "
				 "on A but by a host's command\n");
	assert_int_equal(sys_truth_said(line, NULL, &said), 0);
	sys_truth_said_status(out_new, &said);
	assert_int_equal(said.ctrl_axis, 0);
	assert_string_equal(said.ctrl_text,
			    "stopped by the supervisor (code 10)");
	assert_int_equal(sys_truth_compare(&said, &truth, buf, sizeof(buf)), 0);
	/* the controller's own fault on the axis of the cause is true */
	assert_int_equal(sys_truth_said(line, NULL, &said), 0);
	sys_truth_said_status("FAULT x\nstatus 3.0s ctrl=\"FAULT POT RANGE "
			      "axis B (code 16)\"\n",
			      &said);
	assert_int_equal(said.ctrl_axis, 'B');
	assert_int_equal(sys_truth_compare(&said, &truth, buf, sizeof(buf)), 0);
}

/* A consequence the controller did cause itself is true. */
static void test_true_consequence(void **state)
{
	static const char ev[] =
	    "193 axis A motor on: SH (thread 0 line 150)\n"
	    "248 inject: block A 1\n"
	    "400 axis A motor off: position error (stop code 8)\n"
	    "401 AB 1 received (handle A)\n"
	    "401 relay off (byte 0x6f)\n";
	static const char line[] =
	    "FAULT WATCHDOG: no reply. Then: axis A: position error of at "
	    "least 9 counts." SAFE_OK " Recovery: x";
	char buf[512];

	(void)state;
	assert_int_equal(check(line, NULL, ev, 248, 0, buf, sizeof(buf)), 0);
}

/* Statement b, a new connection answered '?' after the stop had stopped
 * the motors: "stop command not delivered" (the text roboelf printed). */
static void test_refused_stop_caught(void **state)
{
	static const char ev[] =
	    "193 axis A motor on: SH (thread 0 line 150)\n"
	    "193 axis B motor on: SH (thread 0 line 150)\n"
	    "193 axis C motor on: SH (thread 0 line 150)\n"
	    "900 inject: link drop\n"
	    "905 handle A closed (reset)\n"
	    "1010 handle C opened from 127.0.0.1:40000\n"
	    "1010 AB 1 received (handle C)\n"
	    "1010 axis A motor off: abort with OE set (handle C)\n"
	    "1010 axis B motor off: abort with OE set (handle C)\n"
	    "1010 axis C motor off: abort with OE set (handle C)\n"
	    "1011 relay off (byte 0x6f)\n";
	static const char old[] =
	    "FAULT COMM: communication with the controller failed: cannot "
	    "read record: connection closed by peer. NOT CONFIRMED: motor "
	    "power off (relay open) confirmed; stop command not delivered; "
	    "the controller did not answer. PRESS THE HARDWARE E-STOP NOW. "
	    "Recovery: x";
	static const char now[] =
	    "FAULT COMM: communication with the controller failed: cannot "
	    "read record: connection closed by peer. Safe state confirmed: "
	    "motor power off (relay open), motors off. Recovery: x";
	static const char now_log[] =
	    "FAULT FAULT COMM: ... | relay off: confirmed | controller stop: "
	    "delivered, answered ? (controller rejected the command) over a "
	    "new connection (101.5 ms) | motors off: confirmed";
	struct sys_facts said;
	char buf[1024];

	(void)state;
	assert_int_equal(check(old, NULL, ev, 900, 0, buf, sizeof(buf)), 1);
	assert_string_equal(buf, "stop command delivered: roboelf printed no, "
				 "galil-sim recorded yes (AB 1 received "
				 "(handle C))\n");
	assert_int_equal(sys_truth_said(now, now_log, &said), 0);
	assert_int_equal(said.delivered, SYS_YES);
	assert_true(said.stop_ms == 101.5);
	assert_int_equal(check(now, now_log, ev, 900, 0, buf, sizeof(buf)), 0);
}

/* Statement b, replies held back 300 ms: the fresh handle's AB arrived,
 * its answer came after the deadline. What roboelf now says (sent, not
 * known whether it arrived) is true either way. */
static void test_delayed_stop(void **state)
{
	static const char ev[] =
	    "193 axis A motor on: SH (thread 0 line 150)\n"
	    "900 inject: link delay 300\n"
	    "1100 handle B opened from 127.0.0.1:40002\n"
	    "1101 AB 1 received (handle B)\n"
	    "1101 axis A motor off: abort with OE set (handle B)\n"
	    "1102 relay off (byte 0x6f)\n";
	static const char old[] =
	    "FAULT WATCHDOG: no reply from the controller for 160 ms (limit "
	    "150 ms). NOT CONFIRMED: motor power off (relay open) confirmed; "
	    "stop command not delivered; the controller did not answer. "
	    "PRESS THE HARDWARE E-STOP NOW. Recovery: x";
	static const char now[] =
	    "FAULT WATCHDOG: no reply from the controller for 160 ms (limit "
	    "150 ms). NOT CONFIRMED: motor power off (relay open) confirmed; "
	    "no answer to the stop command in time (timed out): whether the "
	    "controller got it is not known; motors off not confirmed; "
	    "PRESS THE HARDWARE E-STOP NOW. Recovery: x";
	static const char no_stop[] =
	    "193 axis A motor on: SH (thread 0 line 150)\n"
	    "900 inject: link stall\n"
	    "1102 relay off (byte 0x6f)\n"
	    "1300 axis A motor off: MO (thread 0 line 88)\n";
	char buf[1024];

	(void)state;
	assert_int_equal(check(old, NULL, ev, 900, 0, buf, sizeof(buf)), 1);
	assert_non_null(strstr(buf, "stop command delivered: roboelf printed "
				    "no, galil-sim recorded yes"));
	assert_int_equal(check(now, NULL, ev, 900, 0, buf, sizeof(buf)), 0);
	assert_int_equal(check(now, NULL, no_stop, 900, 0, buf, sizeof(buf)),
			 0);
	/* "not delivered" where nothing arrived is true */
	assert_int_equal(check(old, NULL, no_stop, 900, 0, buf, sizeof(buf)),
			 0);
}

/* A foreign client's AB is not roboelf's stop. */
static void test_foreign_stop_not_ours(void **state)
{
	static const char ev[] =
	    "193 axis A motor on: SH (thread 0 line 150)\n"
	    "500 handle C opened from 127.0.0.1:40009\n"
	    "900 inject: link stall\n"
	    "950 AB 1 received (handle C)\n"
	    "950 axis A motor off: abort with OE set (handle C)\n";
	struct sys_facts truth;

	(void)state;
	assert_int_equal(sys_truth_true(ev, 900, -1, 1u << 2, &truth), 0);
	assert_int_equal(truth.delivered, SYS_NO);
	assert_string_equal(truth.stop_ev, "");
	assert_int_equal(sys_truth_true(ev, 900, -1, 0, &truth), 0);
	assert_int_equal(truth.delivered, SYS_YES);
	/* a window that ends before the stop */
	assert_int_equal(sys_truth_true(ev, 900, 940, 0, &truth), 0);
	assert_int_equal(truth.delivered, SYS_NO);
	assert_int_equal(truth.motors_off, SYS_NO);
}

/* "motor power off" while the amplifiers kept it (the relay bypassed),
 * and every motor said off while one is on. */
static void test_power_and_motors_caught(void **state)
{
	static const char ev[] =
	    "48 relay on (byte 0x65)\n"
	    "48 amplifier power restored\n"
	    "193 axis A motor on: SH (thread 0 line 150)\n"
	    "193 axis B motor on: SH (thread 0 line 150)\n"
	    "248 inject: pot A offset 0.5\n"
	    "346 AB 1 received (handle A)\n"
	    "346 axis A motor off: abort with OE set (handle A)\n"
	    "346 relay off (byte 0x6f)\n";
	char buf[1024];

	(void)state;
	assert_int_equal(
	    check(line_pot_a, log_pot_a, ev, 248, 0, buf, sizeof(buf)), 2);
	assert_string_equal(buf, "motor power off: roboelf printed yes, "
				 "galil-sim recorded no\n"
				 "every motor off: roboelf printed yes, "
				 "galil-sim recorded no\n");
}

static void test_bad_input(void **state)
{
	struct sys_facts f;

	(void)state;
	assert_int_equal(sys_truth_said("roboelf: Ready", NULL, &f), -1);
	assert_int_equal(sys_truth_said(NULL, NULL, &f), -1);
	assert_int_equal(sys_truth_true("12 ok\nnot a number\n", 0, -1, 0, &f),
			 -1);
	assert_int_equal(sys_truth_true("", 0, -1, 0, &f), 0);
	assert_int_equal(f.delivered, SYS_NO);
	assert_int_equal(f.relay_open, SYS_UNKNOWN);
	assert_int_equal(f.motors_off, SYS_UNKNOWN);
	/* a line without a stated confirmation states nothing of it */
	assert_int_equal(
	    sys_truth_said("FAULT INPUT: x. Recovery: y", NULL, &f), 0);
	assert_string_equal(f.cls, "INPUT");
	assert_int_equal(f.axis, 0);
	assert_int_equal(f.delivered, SYS_UNKNOWN);
	assert_true(f.stop_ms < 0);
}

int main(void)
{
	static const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_true_report_agrees),
	    cmocka_unit_test(test_wrong_axis_caught),
	    cmocka_unit_test(test_ctrl_line_caught),
	    cmocka_unit_test(test_true_consequence),
	    cmocka_unit_test(test_refused_stop_caught),
	    cmocka_unit_test(test_delayed_stop),
	    cmocka_unit_test(test_foreign_stop_not_ours),
	    cmocka_unit_test(test_power_and_motors_caught),
	    cmocka_unit_test(test_bad_input),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
