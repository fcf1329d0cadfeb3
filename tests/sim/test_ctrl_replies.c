/*
 * test_ctrl_replies.c - replies of the simulated DMC-4030 that host code and
 * the commissioning run read, each as the DMC-4000 command reference shows
 * it: MG of several values, formats after {N}, {$m.n} overflow,
 * TS of an idle axis and its bits, _HM and CN, TH of a connected handle,
 * "SPA?" queries, MT ?, CN ?, _XQ and _TA without index, ID, and RS / TR
 * refused with TC 1 (not simulated).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
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

static void reply(struct tplant *p, const char *cmd, const char *want)
{
	char resp[1024];

	if (tp_cmd(p, cmd, resp, sizeof(resp)) != GL_OK)
		fail_msg("'%s' refused", cmd);
	if (strcmp(resp, want))
		fail_msg("'%s' gave '%s', want '%s'", cmd, resp, want);
}

/* '?' and TC1 "1 Unrecognized command". */
static void refused(struct tplant *p, const char *cmd)
{
	char resp[256];

	assert_int_equal(tp_cmd(p, cmd, resp, sizeof(resp)), GL_ERR_CTRL);
	reply(p, "TC1", " 1 Unrecognized command\r\n");
}

/* Reference MG/@ASIN examples: " 0.0000 1.0000 2.0000", " -90.0000": every
 * number has its sign position, so values split on white space. */
static void test_mg_several_values(void **state)
{
	struct tplant *p = *state;

	reply(p, "MG -1,-1", " -1.0000 -1.0000\r\n");
	reply(p, "MG 0,1,2", " 0.0000 1.0000 2.0000\r\n");
	reply(p, "MG _XQ0,_XQ1", " -1.0000 -1.0000\r\n");
	reply(p, "MG \"x=\",-2.5", "x= -2.5000\r\n");
	reply(p, "MG -3{Z4.1},4{F2.0}", " -3.0 04\r\n");
}

/* A format after {N} still applies to the value before them. */
static void test_format_after_n(void **state)
{
	struct tplant *p = *state;

	reply(p, "MG 5{N}{F3.0}", " 005");
	reply(p, "MG 5{F3.0}{N}", " 005");
	reply(p, "MG 5{N}", " 5.0000");
	reply(p, "MG 5{N}{$2.0}", "$05");
}

/* {$m.n} too big saturates as {Fm.n} does; negatives show two's
 * complement digits (reference TP: PF-6.0 prints -10 as $FFFFF6). */
static void test_hex_overflow(void **state)
{
	struct tplant *p = *state;

	reply(p, "MG 12345{F3.0}", " 999\r\n");
	reply(p, "MG 300{$2.0}", "$FF\r\n");
	reply(p, "MG 255{$2.0}", "$FF\r\n");
	reply(p, "MG 254{$2.0}", "$FE\r\n");
	reply(p, "MG 4096.5{$3.1}", "$FFF.F\r\n");
	reply(p, "MG -10{$6.0}", "$FFFFF6\r\n");
	reply(p, "MG 31{$4.0}", "$001F\r\n");
}

/*
 * TS (reference TS: bit 7 moving, 6 error over ER, 5 motor off, 3 forward
 * limit inactive, 2 reverse limit inactive, 1 home switch, 0 latch not
 * armed): an idle servoed axis reads 15 as the reference example, with
 * the motor off 47; an active limit clears its bit.
 */
static void test_ts_idle(void **state)
{
	struct tplant *p = *state;

	reply(p, "TS A", " 47\r\n");
	reply(p, "SH A", "");
	reply(p, "TS A", " 15\r\n");
	reply(p, "MG _TSA", " 15.0000\r\n");
	p->in.fwd_limit[0] = 1;
	tp_step(p, 1);
	reply(p, "TS A", " 7\r\n");
	p->in.fwd_limit[0] = 0;
	p->in.rev_limit[0] = 1;
	tp_step(p, 1);
	reply(p, "TS A", " 11\r\n");
	p->in.rev_limit[0] = 0;
	p->in.home[0] = 1; /* home input grounded */
	tp_step(p, 1);
	reply(p, "TS A", " 13\r\n");
	p->in.home[0] = 0;
	tp_step(p, 1);
	reply(p, "MO A", "");
}

/* _HM (reference HM/CN): CN n1 = -1 (default) 1 when pulled up, 0 when
 * grounded; CN n1 = 1 inverts; CN ? answers all five fields. */
static void test_home_and_cn(void **state)
{
	struct tplant *p = *state;

	reply(p, "CN ?", " -1, -1, -1, 0, 0\r\n");
	reply(p, "MG _HMA,_HMB", " 1.0000 1.0000\r\n");
	p->in.home[1] = 1;
	tp_step(p, 1);
	reply(p, "MG _HMA,_HMB", " 1.0000 0.0000\r\n");
	reply(p, "CN ,1", "");
	reply(p, "MG _HMA,_HMB,_CN0,_CN1", " 0.0000 1.0000 -1.0000 1.0000\r\n");
	reply(p, "CN ?", " -1, 1, -1, 0, 0\r\n");
	reply(p, "CN 1,-1,1,1,1", "");
	reply(p, "CN ?", " 1, -1, 1, 1, 1\r\n");
	assert_int_equal(tp_cmd(p, "CN ,2", NULL, 0), GL_ERR_CTRL);
	assert_int_equal(tp_tc(p), 6);
	reply(p, "CN -1,-1,-1,0,0", "");
	p->in.home[1] = 0;
	tp_step(p, 1);
}

/* TH of a connected handle (reference TH, galil-notes 1.1 example). */
static void test_th_peer(void **state)
{
	struct tplant *p = *state;
	char buf[2048];

	ctrl_handle_open(p->c, 0);
	ctrl_handle_peer(p->c, 0, 23, 0xC0A80201u, 49328);
	tp_send(p, 0, "TH\r");
	tp_out(p, 0, buf, sizeof(buf));
	assert_non_null(strstr(buf, "\r\nIHA TCP PORT 23 TO IP ADDRESS "
				    "192,168,2,1 PORT 49328\r\n"));
	assert_non_null(strstr(buf, "\r\nIHB AVAILABLE\r\n"));
	tp_send(p, 0, "MG _IHA1,_IHA2\r");
	tp_out(p, 0, buf, sizeof(buf));
	assert_string_equal(buf, " 49328.0000 2.0000\r\n:");
	ctrl_handle_close(p->c, 0);
}

/* "SPA?" is "SPA=?"; MT ? and CN ? answer; _XQ = _XQ0, _TA = _TA0. */
static void test_queries(void **state)
{
	struct tplant *p = *state;

	reply(p, "SPA=1000", "");
	reply(p, "SPA?", " 1000\r\n");
	reply(p, "SPA=?", " 1000\r\n");
	reply(p, "ACB?", " 256000\r\n");
	reply(p, "MT ?", " 1\r\n");
	reply(p, "MT ?,?,?", " 1, 1, 1\r\n");
	reply(p, "MTC=?", " 1\r\n");
	reply(p, "MG _MTA", " 1.0000\r\n");
	/* the motor type is settable (a stale tool's MT -1 reverses the
	 * servo: the seal catches it) */
	reply(p, "MTA=-1", "");
	reply(p, "MG _MTA", " -1.0000\r\n");
	reply(p, "MT 1", "");
	reply(p, "MG _XQ,_TA", " -1.0000 0.0000\r\n");
	p->in.amp_power = 0;
	tp_step(p, 1);
	reply(p, "MG _TA,_TA0", " 8.0000 8.0000\r\n");
	p->in.amp_power = 1;
	tp_step(p, 1);
	assert_int_equal(tp_load(p, "#A\nWT 1000\nEN\n"), 0);
	reply(p, "XQ #A", "");
	tp_step(p, 2);
	reply(p, "MG _XQ,_XQ0", " 1.0000 1.0000\r\n");
	reply(p, "HX", "");
	reply(p, "SPA=25000", "");
}

/* ID (reference ID: "FW, ..." then one line per board). */
static void test_id(void **state)
{
	struct tplant *p = *state;

	reply(p, "ID",
	      "FW, DMC4030 Rev 1.2h-sim\r\nDMC, 4030, Rev 1\r\n"
	      "AMP1, 43040, Rev 1\r\n");
	refused(p, "ID 1");
}

/* RS and TR are not simulated: refused, never pretended. */
static void test_rs_tr_refused(void **state)
{
	struct tplant *p = *state;

	refused(p, "RS");
	refused(p, "RS -1");
	refused(p, "TR 1");
	refused(p, "TR 0");
	reply(p, "MG _RS", " 0.0000\r\n");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_mg_several_values),
	    cmocka_unit_test(test_format_after_n),
	    cmocka_unit_test(test_hex_overflow),
	    cmocka_unit_test(test_ts_idle),
	    cmocka_unit_test(test_home_and_cn),
	    cmocka_unit_test(test_th_peer),
	    cmocka_unit_test(test_queries),
	    cmocka_unit_test(test_id),
	    cmocka_unit_test(test_rs_tr_refused),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
