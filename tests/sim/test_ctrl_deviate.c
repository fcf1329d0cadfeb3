/*
 * test_ctrl_deviate.c - the deliberate firmware deviations of galil-sim
 * (--deviate NAME, CTRL_DEV_* in ctrl.h): each answer with and without it,
 * so that the commissioning run can be tested against a controller that
 * answers differently from the reference.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "gl_err.h"
#include "gl_record.h"
#include "sim.h"
#include "test_ctrl_util.h"

static int setup(void **state)
{
	static struct tplant p;

	if (tp_init(&p))
		return -1;
	ctrl_handle_open(p.c, 0);
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

/* The names of --deviate and their bits; unknown names give 0. */
static void test_names(void **state)
{
	(void)state;
	assert_int_equal(sim_deviation_bit("mg-join"), CTRL_DEV_MG_JOIN);
	assert_int_equal(sim_deviation_bit("dm-exists"), CTRL_DEV_DM_EXISTS);
	assert_int_equal(sim_deviation_bit("qr-header"), CTRL_DEV_QR_HEADER);
	assert_int_equal(sim_deviation_bit("ul-trim"), CTRL_DEV_UL_TRIM);
	assert_int_equal(sim_deviation_bit("mo-moving"), CTRL_DEV_MO_MOVING);
	assert_int_equal(sim_deviation_bit("za-16bit"), CTRL_DEV_ZA_16BIT);
	assert_int_equal(sim_deviation_bit("mg"), 0);
	assert_int_equal(sim_deviation_bit(""), 0);
}

/* mg-join: negative values run together, as galil-sim did before. */
static void test_mg_join(void **state)
{
	struct tplant *p = *state;

	reply(p, "MG -1,-2", " -1.0000 -2.0000\r\n");
	ctrl_set_deviate(p->c, CTRL_DEV_MG_JOIN);
	reply(p, "MG -1,-2", "-1.0000-2.0000\r\n");
	reply(p, "MG 1,2", " 1.0000 2.0000\r\n");
	ctrl_set_deviate(p->c, 0);
}

/* dm-exists: DM of an array that exists re-dimensions it silently
 * (galil-sim refuses it with TC 57 by default). */
static void test_dm_exists(void **state)
{
	struct tplant *p = *state;
	char resp[64];

	reply(p, "DM cmqz[4]", "");
	assert_int_equal(tp_cmd(p, "DM cmqz[8]", resp, sizeof(resp)),
			 GL_ERR_CTRL);
	assert_int_equal(tp_tc(p), 57);
	reply(p, "MG cmqz[-1]", " 4.0000\r\n");
	ctrl_set_deviate(p->c, CTRL_DEV_DM_EXISTS);
	reply(p, "cmqz[0]=5", "");
	reply(p, "DM cmqz[8]", "");
	reply(p, "MG cmqz[-1],cmqz[0]", " 8.0000 0.0000\r\n");
	reply(p, "DM cmqz[8]", "");
	ctrl_set_deviate(p->c, 0);
	reply(p, "DA cmqz[]", "");
}

/* qr-header: the record's second header byte (axes present, bit n =
 * axis n) reads 0x03 instead of 0x07: axis C missing. */
static void test_qr_header(void **state)
{
	struct tplant *p = *state;
	uint8_t buf[512];
	size_t n;

	tp_send(p, 0, "QR\r");
	n = ctrl_output(p->c, 0, buf, sizeof(buf));
	assert_int_equal(n, 190 + 1);
	assert_int_equal(buf[0], 0x87);
	assert_int_equal(buf[1], 0x07);
	ctrl_set_deviate(p->c, CTRL_DEV_QR_HEADER);
	tp_send(p, 0, "QR\r");
	n = ctrl_output(p->c, 0, buf, sizeof(buf));
	assert_int_equal(n, 190 + 1);
	assert_int_equal(buf[0], 0x87);
	assert_int_equal(buf[1], 0x03);
	assert_int_equal(buf[190], ':');
	ctrl_set_deviate(p->c, 0);
}

/* ul-trim: UL drops the trailing spaces of each line. */
static void test_ul_trim(void **state)
{
	struct tplant *p = *state;

	assert_int_equal(tp_load(p, "#A  \nMG 1   \nEN\n"), 0);
	reply(p, "UL", "#A  \r\nMG 1   \r\nEN\r\n\x1a");
	ctrl_set_deviate(p->c, CTRL_DEV_UL_TRIM);
	reply(p, "UL", "#A\r\nMG 1\r\nEN\r\n\x1a");
	reply(p, "LS", "0 #A  \r\n1 MG 1   \r\n2 EN\r\n");
	ctrl_set_deviate(p->c, 0);
}

/* mo-moving: MO is accepted while the axis profiles (the reference: "Not
 * Valid while in motion", TC 7 by default) and the motor goes off. */
static void test_mo_moving(void **state)
{
	struct tplant *p = *state;
	char resp[64];

	reply(p, "SHA;JGA=1000;BGA", "::");
	tp_step(p, 10);
	assert_int_equal(tp_cmd(p, "MOA", resp, sizeof(resp)), GL_ERR_CTRL);
	assert_int_equal(tp_tc(p), 7);
	reply(p, "MG _MOA,_BGA", " 0.0000 1.0000\r\n");
	ctrl_set_deviate(p->c, CTRL_DEV_MO_MOVING);
	reply(p, "MOA", "");
	reply(p, "MG _MOA,_BGA", " 1.0000 0.0000\r\n");
	ctrl_set_deviate(p->c, 0);
}

/* Axis C's ZA in the record after "ZA ,,491519" (the program's largest
 * ZAC). */
static long qr_zac(struct tplant *p)
{
	uint8_t buf[512];
	struct gl_record r;
	size_t n;

	tp_send(p, 0, "QR\r");
	n = ctrl_output(p->c, 0, buf, sizeof(buf));
	assert_int_equal(n, 190 + 1);
	assert_int_equal(gl_record_decode(buf, 190, GL_LAYOUT_4000, 3, &r),
			 GL_OK);
	return r.axis[2].za;
}

/* za-16bit: the record's ZA keeps its low 16 bits (sign-extended); MG
 * _ZAC is unchanged. */
static void test_za_16bit(void **state)
{
	struct tplant *p = *state;

	reply(p, "ZA ,,491519", "");
	assert_int_equal(qr_zac(p), 491519);
	reply(p, "MG _ZAC", " 491519.0000\r\n");
	ctrl_set_deviate(p->c, CTRL_DEV_ZA_16BIT);
	assert_int_equal(qr_zac(p), 32767);
	reply(p, "ZA ,,98304", ""); /* 0x18000: low 16 bits 0x8000 */
	assert_int_equal(qr_zac(p), -32768);
	reply(p, "MG _ZAC", " 98304.0000\r\n");
	ctrl_set_deviate(p->c, 0);
	reply(p, "ZA ,,0", "");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_names),     cmocka_unit_test(test_mg_join),
	    cmocka_unit_test(test_dm_exists), cmocka_unit_test(test_qr_header),
	    cmocka_unit_test(test_ul_trim),   cmocka_unit_test(test_mo_moving),
	    cmocka_unit_test(test_za_16bit),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
