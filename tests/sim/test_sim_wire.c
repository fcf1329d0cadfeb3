/*
 * test_sim_wire.c - what galil-sim's line faults do to the bytes
 * (tools/galil-sim/net/sim_wire.h), on buffers: the first command
 * corrupted (quotes respected), a final QR record found, and every reply
 * reshaping with its pieces and delays.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "gl_err.h"
#include "sim.h"
#include "sim_wire.h"

#define CAP 512

/* A reply ":" + a 10-byte record (header 0x87, length 10) + ":". */
static size_t record_reply(uint8_t *r)
{
	memset(r, 0, 12);
	r[0] = ':';
	r[1] = 0x87;
	r[3] = 10;
	r[11] = ':';
	return 12;
}

static int shape(enum sim_line_kind k, int arg, const void *in, size_t len,
		 uint8_t *out, struct sim_wire_piece *piece)
{
	struct sim_line_fault f = {k, arg};
	uint32_t rng = 1;

	return sim_wire_shape(&f, in, len, out, CAP, piece, 64, &rng);
}

static void test_qmark(void **state)
{
	char out[64];
	size_t n;

	(void)state;
	n = sim_wire_qmark("MG 1;MG 2", 9, out, sizeof(out));
	assert_int_equal(n, 7);
	assert_memory_equal(out, "ZZ;MG 2", 7);
	n = sim_wire_qmark("MG \"a;b\";x=1", 12, out, sizeof(out));
	assert_int_equal(n, 6);
	assert_memory_equal(out, "ZZ;x=1", 6);
	n = sim_wire_qmark("QR", 2, out, sizeof(out));
	assert_int_equal(n, 2);
	assert_memory_equal(out, "ZZ", 2);
	assert_int_equal(sim_wire_qmark("MG 1;MG 2", 9, out, 4), 0);
}

static void test_record_at(void **state)
{
	uint8_t r[16];
	size_t n = record_reply(r);

	(void)state;
	assert_int_equal(sim_wire_record_at(r, n), 1);
	assert_int_equal(
	    sim_wire_record_at((const uint8_t *)" 1.0000\r\n:", 10), -1);
	r[11] = '?';
	assert_int_equal(sim_wire_record_at(r, n), -1);
}

static void test_shape_simple(void **state)
{
	struct sim_wire_piece p[64];
	uint8_t out[CAP];

	(void)state;
	assert_int_equal(shape(SIM_LINE_DELAY, 250, "ab:", 3, out, p), 1);
	assert_int_equal(p[0].end, 3);
	assert_int_equal(p[0].delay_us, 250000);
	assert_memory_equal(out, "ab:", 3);
	assert_int_equal(shape(SIM_LINE_GARBAGE, 0, "ab:", 3, out, p), 1);
	assert_int_equal(p[0].end, SIM_WIRE_GARBAGE_LEN);
	assert_memory_equal(out, SIM_WIRE_GARBAGE, SIM_WIRE_GARBAGE_LEN);
	assert_int_equal(shape(SIM_LINE_EXTRA, 0, "ab:", 3, out, p), 1);
	assert_int_equal(p[0].end, 4);
	assert_memory_equal(out, "ab::", 4);
	assert_int_equal(shape(SIM_LINE_EXTRA, 100, "ab:", 3, out, p), 2);
	assert_int_equal(p[0].end, 3);
	assert_int_equal(p[0].delay_us, 0);
	assert_int_equal(p[1].end, 4);
	assert_int_equal(p[1].delay_us, 100000);
	assert_int_equal(shape(SIM_LINE_QMARK, 0, "ab:", 3, out, p), 1);
	assert_int_equal(p[0].end, 3);
	assert_int_equal(p[0].delay_us, 0);
}

static void test_shape_pieces(void **state)
{
	static const char reply[] = " 1.0000\r\n:";
	struct sim_wire_piece p[64];
	uint8_t out[CAP];
	size_t prev = 0;
	int k;

	(void)state;
	k = shape(SIM_LINE_SPLIT, 0, reply, 10, out, p);
	assert_int_equal(k, 10);
	for (int i = 0; i < k; i++) {
		assert_int_equal(p[i].end, (size_t)i + 1);
		assert_int_equal(p[i].delay_us, (int64_t)i * 1000);
	}
	k = shape(SIM_LINE_CHUNKS, 0, reply, 10, out, p);
	assert_true(k >= 2 && k <= 10);
	for (int i = 0; i < k; i++) {
		assert_true(p[i].end > prev && p[i].end - prev <= 8);
		assert_true(i == 0 || p[i].delay_us >= p[i - 1].delay_us);
		prev = p[i].end;
	}
	assert_int_equal(prev, 10);
	assert_memory_equal(out, reply, 10);
	/* more bytes than pieces: the tail goes in the last one */
	{
		struct sim_line_fault f = {SIM_LINE_SPLIT, 0};
		uint32_t rng = 1;

		assert_int_equal(sim_wire_shape(&f, (const uint8_t *)reply, 10,
						out, CAP, p, 4, &rng),
				 4);
		assert_int_equal(p[3].end, 10);
	}
}

static void test_shape_unsol_badhdr(void **state)
{
	struct sim_wire_piece p[64];
	uint8_t in[16], out[CAP];
	size_t n = record_reply(in);

	(void)state;
	assert_int_equal(shape(SIM_LINE_UNSOLPRE, 0, in, n, out, p), 1);
	assert_int_equal(p[0].end, n + 16);
	assert_int_equal(out[0], ':');
	assert_int_equal(out[1], 'U' | 0x80);
	assert_int_equal(out[16], '\n' | 0x80);
	assert_int_equal(out[17], 0x87);
	assert_int_equal(shape(SIM_LINE_UNSOL, 0, "abcd", 4, out, p), 1);
	assert_int_equal(p[0].end, 20);
	assert_memory_equal(out, "ab", 2);
	assert_int_equal(out[2], 'U' | 0x80);
	assert_memory_equal(out + 18, "cd", 2);
	assert_int_equal(shape(SIM_LINE_BADHDR, 0, in, n, out, p), 1);
	assert_int_equal(out[2], 0x0F);
	assert_memory_equal(out + 3, in + 3, n - 3);
	/* too little room: nothing */
	{
		struct sim_line_fault f = {SIM_LINE_UNSOL, 0};
		uint32_t rng = 1;

		assert_int_equal(sim_wire_shape(&f, in, n, out, n, p, 64, &rng),
				 0);
	}
}

static void test_line_fault_words(void **state)
{
	struct sim_line_fault f = {SIM_LINE_NONE, 0};
	const char *why = NULL;

	(void)state;
	assert_int_equal(sim_line_fault_parse("extra", NULL, &f, &why), 0);
	assert_int_equal(f.kind, SIM_LINE_EXTRA);
	assert_int_equal(f.arg, 0);
	assert_int_equal(sim_line_fault_parse("dlreject", "7", &f, &why), 0);
	assert_int_equal(f.kind, SIM_LINE_DLREJECT);
	assert_int_equal(f.arg, 7);
	assert_int_equal(sim_line_fault_parse("delay", "60001", &f, &why),
			 GL_ERR_ARG);
	assert_string_equal(why, "bad delay (0..60000 ms)");
	assert_int_equal(f.kind, SIM_LINE_DLREJECT); /* untouched */
	assert_int_equal(sim_line_fault_parse("none", NULL, &f, &why),
			 GL_ERR_ARG);
	assert_string_equal(why, "unknown");
	for (int k = SIM_LINE_DELAY; k <= SIM_LINE_BADHDR; k++) {
		const char *w = sim_line_fault_name((enum sim_line_kind)k);
		const char *arg =
		    k == SIM_LINE_DELAY || k == SIM_LINE_DLREJECT ? "1" : NULL;

		assert_int_equal(sim_line_fault_parse(w, arg, &f, &why), 0);
		assert_int_equal(f.kind, k);
	}
	assert_string_equal(sim_line_fault_name((enum sim_line_kind)99), "?");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_qmark),
	    cmocka_unit_test(test_record_at),
	    cmocka_unit_test(test_shape_simple),
	    cmocka_unit_test(test_shape_pieces),
	    cmocka_unit_test(test_shape_unsol_badhdr),
	    cmocka_unit_test(test_line_fault_words),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
