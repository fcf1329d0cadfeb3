/*
 * test_gl_record.c - the data record decoder on hand-built fixtures for the
 * three layouts (galil-notes.md 2.2, 2.4, 2.5), short/long/corrupt records,
 * QZ parsing and encode/decode round trips.
 *
 * The fixtures are built byte by byte here from the published offsets, not
 * with gl_record_encode(), so that the decoder is checked against the
 * documentation rather than against its own inverse.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "gl_err.h"
#include "gl_record.h"

static void le16(uint8_t *p, uint32_t v)
{
	p[0] = (uint8_t)(v & 0xff);
	p[1] = (uint8_t)((v >> 8) & 0xff);
}

static void le32(uint8_t *p, uint32_t v)
{
	le16(p, v & 0xffff);
	le16(p + 2, v >> 16);
}

/* A DMC-4030 record (3 axes, 190 bytes) with distinct values everywhere. */
static void fixture_4000(uint8_t b[190])
{
	int ax;

	memset(b, 0, 190);
	b[0] = 0x87;
	b[1] = 0x07;
	le16(b + 2, 190);
	le16(b + 4, 0xBEEF); /* sample */
	b[6] = 0xA5;	     /* inputs 1-8 */
	b[7] = 0x01;	     /* inputs 9-16 */
	b[17] = 0x5A;	     /* output bank 1 */
	b[42] = 2;	     /* handle A: TCP slave */
	b[43] = 2;
	b[50] = 7;		  /* _TC */
	b[51] = 0x03;		  /* threads 0 and 1 running */
	le32(b + 52, 0x01020304); /* amplifier status */
	le32(b + 56, 9);	  /* contour segment count */
	le16(b + 60, 511);	  /* contour buffer space */
	for (ax = 0; ax < 3; ax++) {
		uint8_t *a = b + 82 + 36 * ax;

		le16(a, 0x0001 + ax);
		a[2] = (uint8_t)(0x0C + ax);
		a[3] = (uint8_t)(1 + ax);
		le32(a + 4, (uint32_t)(1000 * (ax + 1)));
		le32(a + 8, (uint32_t)(2000 * (ax + 1)));
		le32(a + 32, (uint32_t)(100 + ax));
	}
	/* axis B (offset 118): negative and high-bit values */
	le16(b + 118, 0x8001);		/* moving, motor off bit */
	b[120] = 0x08;			/* FLS high, RLS low: reverse limit */
	b[121] = 4;			/* stop code */
	le32(b + 122, (uint32_t)-1000); /* ref pos */
	le32(b + 126, 123456);		/* motor pos */
	le32(b + 130, (uint32_t)-5);	/* pos err */
	le32(b + 134, 77);		/* aux */
	le32(b + 138, 6400);		/* velocity x64 */
	le32(b + 142, (uint32_t)-3000); /* torque */
	le16(b + 146, 0xF000);		/* analog -4096 */
	b[148] = 5;			/* hall */
	le32(b + 150, 1234567);		/* ZA */
}

/* TEST_record_4000_fixture: every general field and axis B exactly. */
static void test_record_4000_fixture(void **state)
{
	uint8_t b[190];
	struct gl_record r;

	(void)state;
	fixture_4000(b);
	assert_int_equal(gl_record_decode(b, 190, GL_LAYOUT_4000, 3, &r),
			 GL_OK);
	assert_int_equal(r.layout, GL_LAYOUT_4000);
	assert_int_equal(r.n_axes, 3);
	assert_int_equal(r.length, 190);
	assert_int_equal(r.sample, 0xBEEF);
	assert_int_equal(r.inputs[0], 0xA5);
	assert_int_equal(r.inputs[1], 0x01);
	assert_int_equal(r.outputs[1], 0x5A);
	assert_int_equal(r.handles[0], 2);
	assert_int_equal(r.handles[2], 0);
	assert_int_equal(r.error_code, 7);
	assert_int_equal(r.threads, 0x03);
	assert_int_equal(r.amp_status, 0x01020304);
	assert_int_equal(r.contour_count, 9);
	assert_int_equal(r.contour_space, 511);
	assert_int_equal(r.axis[1].status, 0x8001);
	assert_true(r.axis[1].status & GL_AXST_MOVING);
	assert_true(r.axis[1].status & GL_AXST_MOTOR_OFF);
	assert_int_equal(r.axis[1].switches, GL_AXSW_FLS);
	assert_int_equal(r.axis[1].stop_code, 4);
	assert_int_equal(r.axis[1].ref_pos, -1000);
	assert_int_equal(r.axis[1].motor_pos, 123456);
	assert_int_equal(r.axis[1].pos_err, -5);
	assert_int_equal(r.axis[1].aux_pos, 77);
	assert_int_equal(r.axis[1].velocity, 6400);
	assert_int_equal(r.axis[1].torque, -3000);
	assert_int_equal(r.axis[1].analog_in, -4096);
	assert_int_equal(r.axis[1].hall, 5);
	assert_int_equal(r.axis[1].za, 1234567);
	assert_int_equal(r.axis[0].motor_pos, 2000);
	assert_int_equal(r.axis[0].za, 100);
	assert_int_equal(r.axis[2].ref_pos, 3000);
	assert_int_equal(r.axis[2].motor_pos, 6000);
	assert_int_equal(r.axis[2].za, 102);
	assert_int_equal(r.axis[2].status, 0x0003);
}

/* Decoding must fail with GL_ERR_RECORD and leave @out untouched. */
static void expect_reject(const uint8_t *b, size_t len, enum gl_rec_layout lay,
			  int n)
{
	struct gl_record r, sentinel;

	memset(&r, 0xAB, sizeof(r));
	memset(&sentinel, 0xAB, sizeof(sentinel));
	assert_int_equal(gl_record_decode(b, len, lay, n, &r), GL_ERR_RECORD);
	assert_memory_equal(&r, &sentinel, sizeof(r));
}

/* TEST_record_4000_short_long: one byte short or long is rejected whole. */
static void test_record_4000_short_long(void **state)
{
	uint8_t b[191];

	(void)state;
	fixture_4000(b);
	b[190] = 0;
	expect_reject(b, 189, GL_LAYOUT_4000, 3);
	expect_reject(b, 191, GL_LAYOUT_4000, 3);
	/* a whole record, but of 4 axes while QZ said 3 */
	expect_reject(b, 190, GL_LAYOUT_4000, 4);
}

/* TEST_record_4000_corrupt: bad header bit 7, axis mask, plane bits,
 * length field. */
static void test_record_4000_corrupt(void **state)
{
	uint8_t b[190];

	(void)state;
	fixture_4000(b);
	b[0] = 0x07; /* bit 7 missing */
	expect_reject(b, 190, GL_LAYOUT_4000, 3);
	fixture_4000(b);
	b[0] = 0x85; /* T plane missing */
	expect_reject(b, 190, GL_LAYOUT_4000, 3);
	fixture_4000(b);
	b[1] = 0x0F; /* 4 axes announced */
	expect_reject(b, 190, GL_LAYOUT_4000, 3);
	fixture_4000(b);
	le16(b + 2, 191); /* length field wrong */
	expect_reject(b, 190, GL_LAYOUT_4000, 3);
	fixture_4000(b);
	le16(b + 2, 190 + 256); /* high byte wrong */
	expect_reject(b, 190, GL_LAYOUT_4000, 3);
}

static void fixture_30000(uint8_t b[74])
{
	memset(b, 0, 74);
	b[0] = 0x85;
	b[1] = 0x01;
	le16(b + 2, 74);
	le16(b + 4, 42);
	b[6] = 0x81; /* inputs 1-8 */
	b[7] = 0x02;
	b[8] = 0x40; /* outputs 1-8 */
	b[9] = 0x00;
	b[10] = 22;   /* _TC */
	b[11] = 0x21; /* threads 0 and 5 */
	le32(b + 18, 0x00000101);
	le32(b + 22, 3);
	le16(b + 26, 100);
	le16(b + 38, 0x0010); /* status: stopping */
	b[40] = 0x0E;
	b[41] = 10; /* stop code 10 */
	le32(b + 46, (uint32_t)-2000000000);
	le32(b + 66, 0x7FFF);	    /* analog 32767, hall 0 */
	le32(b + 70, (uint32_t)-1); /* ZA */
}

/* TEST_record_30000_fixture: the single-axis layout, 74 bytes. */
static void test_record_30000_fixture(void **state)
{
	uint8_t b[75];
	struct gl_record r;

	(void)state;
	fixture_30000(b);
	assert_int_equal(gl_record_decode(b, 74, GL_LAYOUT_30000, 1, &r),
			 GL_OK);
	assert_int_equal(r.sample, 42);
	assert_int_equal(r.inputs[0], 0x81);
	assert_int_equal(r.inputs[1], 0x02);
	assert_int_equal(r.outputs[0], 0x40);
	assert_int_equal(r.error_code, 22);
	assert_int_equal(r.threads, 0x21);
	assert_int_equal(r.amp_status, 0x101);
	assert_int_equal(r.contour_count, 3);
	assert_int_equal(r.contour_space, 100);
	assert_int_equal(r.axis[0].status, GL_AXST_STOPPING);
	assert_int_equal(r.axis[0].switches, 0x0E);
	assert_int_equal(r.axis[0].stop_code, 10);
	assert_int_equal(r.axis[0].motor_pos, -2000000000);
	assert_int_equal(r.axis[0].analog_in, 32767);
	assert_int_equal(r.axis[0].za, -1);
	/* short, long, bad length field, two axes */
	expect_reject(b, 73, GL_LAYOUT_30000, 1);
	b[74] = 0;
	expect_reject(b, 75, GL_LAYOUT_30000, 1);
	expect_reject(b, 74, GL_LAYOUT_30000, 2);
	le16(b + 2, 73);
	expect_reject(b, 74, GL_LAYOUT_30000, 1);
}

static void fixture_2103(uint8_t b[128])
{
	memset(b, 0, 128);
	b[0] = 0x87;
	b[1] = 0x07;
	le16(b + 2, 128);
	le16(b + 4, 65535);
	b[15] = 0x99; /* input bank 9 */
	b[25] = 0x66; /* output bank 9 */
	b[26] = 1;    /* _TC */
	b[27] = 0x80; /* program running */
	/* axis C at 44 + 56 = 100 */
	le16(b + 100, 0x8000);
	b[102] = 0x04;
	b[103] = 0;
	le32(b + 104, 10);
	le32(b + 108, (uint32_t)-77777);
	le32(b + 112, 3);
	le32(b + 116, (uint32_t)-4);
	le32(b + 120, (uint32_t)-640);
	le16(b + 124, 0x8001); /* torque -32767 (SW) */
	le16(b + 126, 1234);   /* analog */
}

/* TEST_record_2103_fixture: 44 + 28 bytes per axis, SW torque. */
static void test_record_2103_fixture(void **state)
{
	uint8_t b[129];
	struct gl_record r;

	(void)state;
	fixture_2103(b);
	assert_int_equal(gl_record_decode(b, 128, GL_LAYOUT_2103, 3, &r),
			 GL_OK);
	assert_int_equal(r.sample, 65535);
	assert_int_equal(r.inputs[9], 0x99);
	assert_int_equal(r.outputs[9], 0x66);
	assert_int_equal(r.error_code, 1);
	assert_int_equal(r.general_status, 0x80);
	assert_int_equal(r.threads, 0);
	assert_int_equal(r.axis[2].status, GL_AXST_MOVING);
	assert_int_equal(r.axis[2].switches, GL_AXSW_RLS);
	assert_int_equal(r.axis[2].ref_pos, 10);
	assert_int_equal(r.axis[2].motor_pos, -77777);
	assert_int_equal(r.axis[2].pos_err, 3);
	assert_int_equal(r.axis[2].aux_pos, -4);
	assert_int_equal(r.axis[2].velocity, -640);
	assert_int_equal(r.axis[2].torque, -32767);
	assert_int_equal(r.axis[2].analog_in, 1234);
	assert_int_equal(r.axis[2].za, 0);
	expect_reject(b, 127, GL_LAYOUT_2103, 3);
	b[128] = 0;
	expect_reject(b, 129, GL_LAYOUT_2103, 3);
	/* same byte count as a 4000 record? 128 is not 82 + 36n: rejected */
	expect_reject(b, 128, GL_LAYOUT_4000, 3);
	b[0] = 0x86; /* S plane bit missing */
	expect_reject(b, 128, GL_LAYOUT_2103, 3);
}

static void assert_axis_equal(const struct gl_rec_axis *a,
			      const struct gl_rec_axis *b, int has_za)
{
	assert_int_equal(a->status, b->status);
	assert_int_equal(a->switches, b->switches);
	assert_int_equal(a->stop_code, b->stop_code);
	assert_int_equal(a->ref_pos, b->ref_pos);
	assert_int_equal(a->motor_pos, b->motor_pos);
	assert_int_equal(a->pos_err, b->pos_err);
	assert_int_equal(a->aux_pos, b->aux_pos);
	assert_int_equal(a->velocity, b->velocity);
	assert_int_equal(a->torque, b->torque);
	assert_int_equal(a->analog_in, b->analog_in);
	if (has_za) {
		assert_int_equal(a->hall, b->hall);
		assert_int_equal(a->za, b->za);
	}
}

/* Decode a fixture, encode the result, compare bytes with the fixture. */
static void round_trip(const uint8_t *b, size_t len, enum gl_rec_layout lay,
		       int n)
{
	struct gl_record r, r2;
	uint8_t out[GL_REC_MAX_BYTES];
	int i;

	assert_int_equal(gl_record_decode(b, len, lay, n, &r), GL_OK);
	assert_int_equal(gl_record_encode(&r, out, sizeof(out)), (int)len);
	assert_memory_equal(out, b, len);
	assert_int_equal(gl_record_decode(out, len, lay, n, &r2), GL_OK);
	for (i = 0; i < n; i++)
		assert_axis_equal(&r.axis[i], &r2.axis[i],
				  lay != GL_LAYOUT_2103);
}

/* TEST_record_round_trip: fixture -> decode -> encode is byte-identical. */
static void test_record_round_trip(void **state)
{
	uint8_t b4[190], b3[74], b2[128];

	(void)state;
	fixture_4000(b4);
	fixture_30000(b3);
	fixture_2103(b2);
	round_trip(b4, 190, GL_LAYOUT_4000, 3);
	round_trip(b3, 74, GL_LAYOUT_30000, 1);
	round_trip(b2, 128, GL_LAYOUT_2103, 3);
}

/* TEST_record_encode_8axes: the largest record, extremes of every type. */
static void test_record_encode_8axes(void **state)
{
	struct gl_record r, d;
	uint8_t out[GL_REC_MAX_BYTES];
	int i;

	(void)state;
	memset(&r, 0, sizeof(r));
	r.layout = GL_LAYOUT_4000;
	r.n_axes = 8;
	r.sample = 1;
	for (i = 0; i < 8; i++) {
		r.axis[i].motor_pos = (i & 1) ? INT32_MIN : INT32_MAX;
		r.axis[i].za = -i;
		r.axis[i].analog_in = -32768 + i;
		r.axis[i].torque = -32767;
	}
	assert_int_equal(gl_record_encode(&r, out, sizeof(out)), 370);
	assert_int_equal(out[0], 0x87);
	assert_int_equal(out[1], 0xFF);
	assert_int_equal(out[2], 370 & 0xff);
	assert_int_equal(out[3], 370 >> 8);
	assert_int_equal(gl_record_decode(out, 370, GL_LAYOUT_4000, 8, &d),
			 GL_OK);
	for (i = 0; i < 8; i++)
		assert_axis_equal(&r.axis[i], &d.axis[i], 1);
	assert_int_equal(gl_record_encode(&r, out, 369), GL_ERR_OVERFLOW);
	r.n_axes = 9;
	assert_int_equal(gl_record_encode(&r, out, sizeof(out)), GL_ERR_ARG);
	r.n_axes = 0;
	assert_int_equal(gl_record_encode(&r, out, sizeof(out)), GL_ERR_ARG);
}

/* TEST_record_sizes: 82 + 36n, 74, 44 + 28n; 0 for impossible layouts. */
static void test_record_sizes(void **state)
{
	(void)state;
	assert_int_equal(gl_record_size(GL_LAYOUT_4000, 1), 118);
	assert_int_equal(gl_record_size(GL_LAYOUT_4000, 3), 190);
	assert_int_equal(gl_record_size(GL_LAYOUT_4000, 4), 226);
	assert_int_equal(gl_record_size(GL_LAYOUT_4000, 8), 370);
	assert_int_equal(gl_record_size(GL_LAYOUT_30000, 1), 74);
	assert_int_equal(gl_record_size(GL_LAYOUT_30000, 2), 0);
	assert_int_equal(gl_record_size(GL_LAYOUT_2103, 1), 72);
	assert_int_equal(gl_record_size(GL_LAYOUT_2103, 4), 156);
	assert_int_equal(gl_record_size(GL_LAYOUT_2103, 8), 268);
	assert_int_equal(gl_record_size(GL_LAYOUT_4000, 0), 0);
	assert_int_equal(gl_record_size(GL_LAYOUT_4000, 9), 0);
	assert_int_equal(gl_record_size(GL_LAYOUT_NONE, 3), 0);
}

static void expect_qz(const char *s, int rc, enum gl_rec_layout lay, int n)
{
	enum gl_rec_layout l = GL_LAYOUT_NONE;
	int axes = -1;

	assert_int_equal(gl_record_layout_from_qz(s, strlen(s), &l, &axes), rc);
	if (rc == GL_OK) {
		assert_int_equal(l, lay);
		assert_int_equal(axes, n);
	} else {
		assert_int_equal(l, GL_LAYOUT_NONE);
		assert_int_equal(axes, -1);
	}
}

/* TEST_record_qz: QZ replies pick the layout; anything else is refused. */
static void test_record_qz(void **state)
{
	(void)state;
	expect_qz(" 3, 52, 26, 36", GL_OK, GL_LAYOUT_4000, 3);
	expect_qz("3,52,26,36\r\n", GL_OK, GL_LAYOUT_4000, 3);
	expect_qz(" 8, 52, 26, 36", GL_OK, GL_LAYOUT_4000, 8);
	expect_qz(" 1, 18, 16, 36", GL_OK, GL_LAYOUT_30000, 1);
	expect_qz(" 4, 24, 16, 28", GL_OK, GL_LAYOUT_2103, 4);
	expect_qz(" 2, 18, 16, 36", GL_ERR_RECORD, GL_LAYOUT_NONE, 0);
	expect_qz(" 9, 52, 26, 36", GL_ERR_RECORD, GL_LAYOUT_NONE, 0);
	expect_qz(" 0, 52, 26, 36", GL_ERR_RECORD, GL_LAYOUT_NONE, 0);
	expect_qz(" 3, 52, 26, 37", GL_ERR_RECORD, GL_LAYOUT_NONE, 0);
	expect_qz(" 3, 52, 26", GL_ERR_PROTO, GL_LAYOUT_NONE, 0);
	expect_qz(" 3, 52, 26, 36, 1", GL_ERR_PROTO, GL_LAYOUT_NONE, 0);
	expect_qz(" 3, 52, 26, 36x", GL_ERR_PROTO, GL_LAYOUT_NONE, 0);
	expect_qz("-3, 52, 26, 36", GL_ERR_PROTO, GL_LAYOUT_NONE, 0);
	expect_qz("", GL_ERR_PROTO, GL_LAYOUT_NONE, 0);
	expect_qz("9999999, 52, 26, 36", GL_ERR_PROTO, GL_LAYOUT_NONE, 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_record_4000_fixture),
	    cmocka_unit_test(test_record_4000_short_long),
	    cmocka_unit_test(test_record_4000_corrupt),
	    cmocka_unit_test(test_record_30000_fixture),
	    cmocka_unit_test(test_record_2103_fixture),
	    cmocka_unit_test(test_record_round_trip),
	    cmocka_unit_test(test_record_encode_8axes),
	    cmocka_unit_test(test_record_sizes),
	    cmocka_unit_test(test_record_qz),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
