/*
 * test_ctrl_motion.c - motion and protection of the simulated DMC-4030:
 * trapezoidal PR moves timed against the formula, JG/ST, PT retargeting,
 * position error with OE (stop code 8), encoder failure with OA (12),
 * hardware and soft limits (2/3) with #LIMSWI, amplifier power loss (15)
 * with #AMPERR, AB (7), ST (4), and the refusals (TC 7, 20, 21, 22).
 */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "test_ctrl_util.h"

static int setup(void **state)
{
	static struct tplant p;

	if (tp_init(&p))
		return -1;
	tp_step(&p, 1);
	*state = &p;
	return 0;
}

static int teardown(void **state)
{
	tp_free(*state);
	return 0;
}

static void ok(struct tplant *p, const char *line)
{
	char resp[256];

	assert_int_equal(tp_cmd(p, line, resp, sizeof(resp)), GL_OK);
}

static void refused(struct tplant *p, const char *line, int tc)
{
	char resp[256];

	assert_int_equal(tp_cmd(p, line, resp, sizeof(resp)), GL_ERR_CTRL);
	assert_int_equal(tp_tc(p), tc);
}

/*
 * PR 10000 at SP 10000, AC = DC = 102400: accelerate 97.7 ms, cruise
 * 902.3 ms, decelerate 97.7 ms: 1097.7 ms in all (1 sample = 1 ms).
 */
static void test_pr_profile(void **state)
{
	struct tplant *p = *state;
	long t;

	ok(p, "AC 100000");
	assert_true(tp_mg(p, "_ACA") == 99328); /* rounded down to 1024s */
	ok(p, "SHA;SPA=10000;ACA=102400;DCA=102400;PRA=10000;BGA");
	tp_step(p, 500);
	assert_true(tp_mg(p, "_BGA") == 1);
	assert_true(tp_mg(p, "_SCA") == 0);
	assert_true(fabs(tp_mg(p, "_TVA") - 10000) < 50);
	t = tp_until(p, "_BGA=0", 2000);
	assert_true(t >= 0);
	t += 500;
	assert_true(labs(t - 1098) <= 3);
	assert_true(tp_mg(p, "_TPA") == 10000);
	assert_true(tp_mg(p, "_RPA") == 10000);
	assert_true(tp_mg(p, "_SCA") == 1);
	/* the same distance again: PR is kept; PA 0 goes back */
	ok(p, "BGA");
	assert_true(tp_until(p, "_BGA=0", 2000) > 1000);
	assert_true(tp_mg(p, "_TPA") == 20000);
	ok(p, "PAA=0;BGA");
	assert_true(tp_until(p, "_BGA=0", 4000) > 2000);
	assert_true(tp_mg(p, "_TPA") == 0);
}

static void test_jog_stop(void **state)
{
	struct tplant *p = *state;

	ok(p, "SH;JG ,-5000;BG B");
	tp_step(p, 500);
	assert_true(fabs(tp_mg(p, "_TVB") + 5000) < 50);
	assert_true(tp_mg(p, "_SCB") == 0);
	ok(p, "JG ,-8000"); /* new speed while jogging */
	tp_step(p, 300);
	assert_true(fabs(tp_mg(p, "_TVB") + 8000) < 50);
	ok(p, "STB");
	/* 8000 / 256000 s to stop */
	assert_true(labs(tp_until(p, "_BGB=0", 100) - 31) <= 2);
	assert_true(tp_mg(p, "_SCB") == 4);
}

/* PT: PA starts motion without BG and retargets a move on the fly. */
static void test_pt_retarget(void **state)
{
	struct tplant *p = *state;
	double at;

	ok(p, "SHA;PTA=1;PAA=10000");
	tp_step(p, 300);
	at = tp_mg(p, "_TPA");
	assert_true(at > 3000 && at < 10000);
	assert_true(tp_mg(p, "_BGA") == 1);
	ok(p, "PAA=2000"); /* behind the axis: brake, reverse, arrive */
	assert_true(tp_until(p, "_BGA=0", 3000) > 0);
	assert_true(tp_mg(p, "_TPA") == 2000);
	assert_true(tp_mg(p, "_SCA") == 1);
	ok(p, "PAA=2500");
	tp_step(p, 200);
	assert_true(tp_mg(p, "_TPA") == 2500);
	refused(p, "BGA", 7); /* only PA moves a PT axis */
	ok(p, "STA");
	assert_true(tp_mg(p, "_PTA") == 0); /* ST leaves PT mode */
	ok(p, "MOA;PTA=1");
	refused(p, "PAA=100", 20);
}

/* TE beyond ER with OE 1: motor off, stop code 8, #POSERR (thread 0
 * started for it when no program runs; RE ends it). */
static void test_oe_trip(void **state)
{
	struct tplant *p = *state;
	long t;

	assert_int_equal(tp_load(p, "EN\r#POSERR\rpe=pe+1;ax=_MOA\rRE\r"),
			 GL_OK);
	ok(p, "pe=0;ax=0;SHA;ERA=1000;OEA=1;PRA=50000;BGA");
	p->frozen[0] = 1; /* encoder stuck: jam or broken */
	t = tp_until(p, "_MOA=1", 500);
	/* the reference passes 1000 counts at sqrt(2*1000/256000) s */
	assert_true(t >= 86 && t <= 92);
	assert_true(tp_mg(p, "_SCA") == 8);
	assert_true(tp_mg(p, "_BGA") == 0);
	tp_step(p, 3);
	assert_true(tp_mg(p, "pe") == 1);
	assert_true(tp_mg(p, "ax") == 1);
	assert_int_equal(ctrl_threads(p->c), 0);
	assert_true(tp_has_event(p, "axis A motor off: position error"));
	assert_true(tp_has_event(p, "(stop code 8)"));
	/* OE 0: the motor stays on; #POSERR still runs */
	p->frozen[0] = 0;
	ok(p, "SHA;OEA=0;PRA=50000;BGA");
	p->frozen[0] = 1;
	tp_step(p, 200);
	assert_true(tp_mg(p, "_MOA") == 0);
	assert_true(tp_mg(p, "pe") == 2);
}

/* Encoder failure: torque above OV for OT samples, < 4 counts moved. */
static void test_oa_trip(void **state)
{
	struct tplant *p = *state;
	long t;

	ok(p, "SHA;ERA=-1;OAA=1;OTA=30;JGA=10000;BGA");
	tp_step(p, 1000); /* a healthy encoder: no trip */
	assert_true(tp_mg(p, "_MOA") == 0);
	p->frozen[0] = 1;
	t = tp_until(p, "_MOA=1", 200);
	assert_true(t >= 30 && t <= 60);
	assert_true(tp_mg(p, "_SCA") == 12);
	assert_true(tp_has_event(p, "encoder failure"));
	/* OA 0: no trip, the axis just builds up an error */
	p->frozen[0] = 0;
	ok(p, "SHA;OAA=0;JGA=10000;BGA");
	p->frozen[0] = 1;
	tp_step(p, 300);
	assert_true(tp_mg(p, "_MOA") == 0);
	assert_true(tp_mg(p, "_TTA") == 9.9982); /* torque at TL */
}

/* Hardware limits: stop (2 forward, 3 reverse), #LIMSWI, BG refused. */
static void test_hw_limits(void **state)
{
	struct tplant *p = *state;

	assert_int_equal(tp_load(p, "#MAIN;WT 10;JP #MAIN\r"
				    "#LIMSWI\rls=ls+1;lf=_LFA\rRE\r"),
			 GL_OK);
	ok(p, "ls=0;XQ #MAIN;SHA;JGA=5000;BGA");
	tp_step(p, 100);
	p->in.fwd_limit[0] = 1;
	tp_step(p, 1);
	assert_true(tp_mg(p, "_SCA") == 2);
	assert_true(tp_mg(p, "_LFA") == 0);
	assert_true(tp_until(p, "_BGA=0", 100) >= 0);
	tp_step(p, 2);
	assert_true(tp_mg(p, "ls") == 1);
	assert_true(tp_mg(p, "lf") == 0);
	assert_int_equal(ctrl_threads(p->c), 1u); /* #MAIN goes on */
	refused(p, "BGA", 22);
	ok(p, "PRA=100");
	refused(p, "BGA", 22);
	ok(p, "JGA=-5000;BGA"); /* away from the switch is fine */
	tp_step(p, 50);
	p->in.fwd_limit[0] = 0;
	p->in.rev_limit[0] = 1;
	tp_step(p, 1);
	assert_true(tp_mg(p, "_SCA") == 3);
	tp_step(p, 50);
	assert_true(tp_mg(p, "ls") == 2);
	assert_true(tp_has_event(p, "axis A limit forward (stop code 2)"));
	assert_true(tp_has_event(p, "axis A limit reverse (stop code 3)"));
	ok(p, "HX");
}

/* FL/BL: deceleration when the reference passes the limit, TC 22 after. */
static void test_soft_limits(void **state)
{
	struct tplant *p = *state;
	double at;

	ok(p, "SHC;FLC=2000;BLC=-1000;JGC=5000;BGC");
	assert_true(tp_until(p, "_BGC=0", 2000) > 0);
	at = tp_mg(p, "_TPC");
	assert_true(at > 2000 && at < 2000 + 60); /* v^2/2SD = 49 */
	assert_true(tp_mg(p, "_SCC") == 2);
	refused(p, "BGC", 22);
	ok(p, "PAC=-5000;BGC");
	assert_true(tp_until(p, "_BGC=0", 4000) > 0);
	assert_true(tp_mg(p, "_SCC") == 3);
	assert_true(tp_mg(p, "_TPC") < -1000);
	assert_true(tp_has_event(p, "axis C soft limit reverse"));
}

/*
 * Motor power lost: under-voltage in _TA0, #AMPERR; axes with OE set go
 * motor off with stop code 15, an axis with OE 0 stays on.
 */
static void test_amp_power(void **state)
{
	struct tplant *p = *state;

	assert_int_equal(tp_load(p, "EN\r#AMPERR\ram=am+1\rRE\r"), GL_OK);
	ok(p, "am=0;SHAB;OE 1,0;JG 1000,1000;BGAB");
	tp_step(p, 50);
	p->in.amp_power = 0;
	tp_step(p, 1);
	assert_true(tp_mg(p, "_MOA") == 1);
	assert_true(tp_mg(p, "_SCA") == 15);
	assert_true(tp_mg(p, "_MOB") == 0);
	assert_true(tp_mg(p, "_TA0&8") == 8);
	tp_step(p, 5);
	assert_true(tp_mg(p, "am") == 1);
	assert_true(tp_has_event(p, "amplifier power lost"));
	p->in.amp_power = 1;
	tp_step(p, 1);
	assert_true(tp_mg(p, "_TA0") == 0);
}

static void test_refusals(void **state)
{
	struct tplant *p = *state;

	refused(p, "BGA", 20); /* motor off */
	ok(p, "SHA;JGA=2000;BGA");
	tp_step(p, 10);
	refused(p, "BGA", 21);
	refused(p, "MOA", 7); /* MO not valid while moving */
	refused(p, "SHA", 7);
	refused(p, "PRA=5", 7);
	refused(p, "DPA=0", 7);
	ok(p, "DCA=512000"); /* DC may change while jogging */
	ok(p, "STA");
	tp_step(p, 20);
	ok(p, "PRA=100000;BGA");
	tp_step(p, 5);
	refused(p, "DCA=256000", 7); /* but not during PR/PA */
}

static void test_abort(void **state)
{
	struct tplant *p = *state;

	assert_int_equal(tp_load(p, "#A;WT 10;JP #A\r"), GL_OK);
	ok(p, "XQ #A;SHA;JGA=2000;BGA");
	tp_step(p, 20);
	ok(p, "AB 1"); /* motion only */
	assert_true(tp_mg(p, "_SCA") == 7);
	assert_true(tp_mg(p, "_BGA") == 0);
	assert_int_equal(ctrl_threads(p->c), 1u);
	ok(p, "OEA=1;JGA=2000;BGA");
	tp_step(p, 5);
	ok(p, "AB"); /* motion and program; OE: motor off */
	assert_int_equal(ctrl_threads(p->c), 0);
	assert_true(tp_mg(p, "_MOA") == 1);
	/* a bare ST from a host stops the program too, ST A does not */
	ok(p, "XQ #A;STA");
	assert_int_equal(ctrl_threads(p->c), 1u);
	ok(p, "ST");
	assert_int_equal(ctrl_threads(p->c), 0);
}

/* Is @text exactly one of the events? */
static int has_line(const struct tplant *p, const char *text)
{
	for (int i = 0; i < p->nevents; i++)
		if (!strcmp(p->events[i], text))
			return 1;
	return 0;
}

static int count_prefix(const struct tplant *p, const char *prefix)
{
	int n = 0;

	for (int i = 0; i < p->nevents; i++)
		n += !strncmp(p->events[i], prefix, strlen(prefix));
	return n;
}

static void expect_event(const struct tplant *p, const char *text)
{
	if (!has_line(p, text))
		fail_msg("no event '%s'", text);
}

/* Events of SH MO BG ST AB HX and a PT start name who commanded them: a
 * program thread and its line, a host handle, the private port. */
static void test_event_sources(void **state)
{
	static const char prog[] = "#T\rSHA\rPRA=5000\rBGA\rWT 5\rSTA\r"
				   "AMA\rSHA\rJGA=1000;BGA\rWT 5\rAB 1\r"
				   "MOA\rEN\r#L;WT 1;JP #L\r";
	struct tplant *p = *state;
	char out[256];

	assert_int_equal(tp_load(p, prog), GL_OK);
	ok(p, "XQ #T,2");
	tp_step(p, 200);
	assert_int_equal(ctrl_threads(p->c), 0);
	expect_event(p, "axis A motor on: SH (thread 2 line 1)");
	expect_event(p, "axis A begin (thread 2 line 3)");
	expect_event(p, "axis A stop: ST (thread 2 line 5)");
	expect_event(p, "axis A begin (thread 2 line 8)");
	expect_event(p, "axis A abort: AB (thread 2 line 10)");
	expect_event(p, "axis A motor off: MO (thread 2 line 11)");
	assert_int_equal(count_prefix(p, "axis A motor on"), 1);

	tp_send(p, 1, "SHB;PRB=1000;BGB;STB\r");
	assert_string_equal((tp_out(p, 1, out, sizeof(out)), out), "::::");
	expect_event(p, "axis B motor on: SH (handle B)");
	expect_event(p, "axis B begin (handle B)");
	expect_event(p, "axis B stop: ST (handle B)");
	tp_step(p, 100);
	tp_send(p, 1, "OEB=1;JGB=500;BGB;AB 1\r");
	expect_event(p, "axis B abort: AB (handle B)");
	expect_event(p, "axis B motor off: abort with OE set (handle B)");
	tp_send(p, 1, "SHC;PTC=1;PAC=100;PAC=200\r");
	expect_event(p, "axis C begin PT (handle B)");
	assert_int_equal(count_prefix(p, "axis C begin"), 1);

	ok(p, "XQ #L,1;XQ #L,3");
	tp_send(p, 1, "HX 1\r");
	expect_event(p, "thread 1 stopped: halted by HX (handle B)");
	tp_send(p, 2, "AB\r");
	expect_event(p, "thread 3 stopped: aborted by AB (handle C)");
	ok(p, "XQ #L,4;ST");
	expect_event(p, "thread 4 stopped: halted by ST (private port)");
	ok(p, "MO C");
	expect_event(p, "axis C motor off: MO (private port)");
}

/* KP KI KD TL are stored, reported, range-checked; OV <= TL. */
static void test_gains(void **state)
{
	struct tplant *p = *state;
	char resp[128];

	ok(p, "KP 1.3,2.5,3;KIB=0.5;KD*=100;TL 5");
	assert_int_equal(tp_cmd(p, "KP ?,?,?", resp, sizeof(resp)), GL_OK);
	assert_string_equal(resp, " 1.2500, 2.5000, 3.0000\r\n");
	assert_true(tp_mg(p, "_KIB") == 0.5);
	assert_true(tp_mg(p, "_KDC") == 100);
	assert_true(tp_mg(p, "_TLA") == 5);
	refused(p, "KP 2000", 6);
	refused(p, "OVA=6", 6);
	ok(p, "OVA=4");
	refused(p, "ER ,,-2", 6);
	assert_int_equal(tp_cmd(p, "ER ?,?", resp, sizeof(resp)), GL_OK);
	assert_string_equal(resp, " 16384, 16384\r\n");
}

/* MF/MR (encoder crosses), AM (profile done), MC (in position), AI. */
static void test_trippoints(void **state)
{
	struct tplant *p = *state;
	const char *prog = "#A\r"
			   "SHA;PRA=2000;BGA\r"
			   "MFA=1000;t1=_TPA\r"
			   "AMA;t2=_TPA\r"
			   "PRA=-1500;BGA\r"
			   "MRA=1200;t3=_TPA\r"
			   "MCA;t4=_TPA;t5=_BGA\r"
			   "AI 3;t6=TIME\r"
			   "AI -3;t7=TIME\r"
			   "EN\r";
	double t1, t3;

	assert_int_equal(tp_load(p, prog), GL_OK);
	ok(p, "t6=0;t7=0;XQ #A");
	tp_step(p, 2000);
	t1 = tp_mg(p, "t1");
	t3 = tp_mg(p, "t3");
	assert_true(t1 >= 1000 && t1 < 1040);
	assert_true(tp_mg(p, "t2") == 2000);
	assert_true(t3 <= 1200 && t3 > 1160);
	assert_true(tp_mg(p, "t4") == 500);
	assert_true(tp_mg(p, "t5") == 0);
	assert_true(tp_mg(p, "t6") == 0); /* still waiting for input 3 */
	p->in.inputs = 1u << 2;
	tp_step(p, 2);
	assert_true(tp_mg(p, "t6") > 0);
	assert_true(tp_mg(p, "t7") == 0);
	p->in.inputs = 0;
	tp_step(p, 2);
	assert_true(tp_mg(p, "t7") > tp_mg(p, "t6"));
	assert_int_equal(ctrl_threads(p->c), 0);
}

/* MC with the encoder short of the target: TW timeout, SC 99, #MCTIME. */
static void test_mc_timeout(void **state)
{
	struct tplant *p = *state;
	const char *prog = "#A\r"
			   "SHA;TWA=100;PRA=500;BGA\r"
			   "WT 20\r"
			   "MCA;t=TIME\r"
			   "EN\r"
			   "#MCTIME\r"
			   "mct=_SCA\r"
			   "EN\r";

	assert_int_equal(tp_load(p, prog), GL_OK);
	ok(p, "mct=0;t=0;XQ #A");
	tp_step(p, 10);
	p->frozen[0] = 1; /* the motor stops following */
	tp_step(p, 400);
	assert_true(tp_mg(p, "mct") == 99);
	assert_true(tp_mg(p, "_SCA") == 99);
	assert_true(tp_mg(p, "t") > 100);
	assert_true(tp_has_event(p, "MC timeout"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_pr_profile, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_jog_stop, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_pt_retarget, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_oe_trip, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_oa_trip, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_hw_limits, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_soft_limits, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_amp_power, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_refusals, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_abort, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_event_sources, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_gains, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_trippoints, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_mc_timeout, setup, teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
