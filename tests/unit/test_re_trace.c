/*
 * test_re_trace.c - the trace format (pc/rec/re_trace.c): the exact text of a
 * small trace (its CRC checked against zlib's crc32 value computed outside
 * this test), a round trip through a wrapped ring, every refusal with its
 * exact message and line (truncated, wrong version, garbage, huge counts,
 * bad values, changed bytes, data after the end), the writer's refusals,
 * and a deterministic fuzz: 10000 random mutations of a valid trace, each
 * either refused or accepted, the same way twice, and an accepted one is
 * exactly what the writer makes of what was read.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "gl_err.h"
#include "re_trace.h"

static char buf[256 * 1024];
static char buf2[256 * 1024];
static char err[512];

static void hdr_fill(struct re_trace_hdr *h, int n_axes, int fault)
{
	static const char *names[] = {"A", "B", "C"};

	memset(h, 0, sizeof(*h));
	snprintf(h->created, sizeof(h->created), "2026-11-25T08:50:48Z");
	snprintf(h->reason, sizeof(h->reason), fault ? "fault" : "request");
	h->config_hash = 0x0123456789abcdefULL;
	snprintf(h->serial, sizeof(h->serial), "12345");
	h->period_ms = 10;
	h->n_axes = n_axes;
	for (int a = 0; a < n_axes && a < RE_TRACE_AXES; a++)
		snprintf(h->axis[a], RE_TRACE_NAME, "%s", names[a]);
	h->have_fault = fault;
	if (fault) {
		h->fault_t_s = 0.02;
		snprintf(h->fault_text, sizeof(h->fault_text),
			 "FAULT POTENTIOMETER: axis A, difference 0.5 V");
	}
}

static void rec_fill(struct re_trace_rec *r, int k)
{
	memset(r, 0, sizeof(*r));
	r->t_s = 0.01 * k;
	r->cycle = k;
	r->phase = k < 2 ? RE_TPH_ARMED : RE_TPH_FAULT;
	r->relay = 1;
	r->link_ok = 1;
	r->age_ms = 1.25;
	r->late_ms = 0.0625;
	r->hbpc = 100 + k;
	r->hbdmc = 7;
	r->sample = 65535 - k;
	r->joy_raw = 4095;
	r->jcmd = -1;
	for (int a = 0; a < RE_TRACE_AXES; a++) {
		struct re_trace_axis *x = &r->axis[a];

		x->enc_counts = -1000 * (a + 1) - k;
		x->ref_counts = 2147483647;
		x->pot_v = 2.5 + 0.5 * k;
		x->pot_exp_v = a == 2 ? NAN : 2.5;
		x->tol_v = a == 2 ? NAN : 0.0625;
		x->margin_v = a == 2 ? NAN : 0.0625 - 0.5 * k;
		x->vcmd_cps = -1234.5;
		x->vel_cps = 1e13; /* beyond the limit: written as nan */
		x->motor_off = k >= 2;
		x->stop_code = 4;
	}
}

static size_t small_trace(char *out, size_t cap, int n, int n_axes)
{
	struct re_trace_hdr h;
	struct re_trace_rec r[8];
	size_t len = 0;

	hdr_fill(&h, n_axes, 1);
	for (int k = 0; k < n; k++)
		rec_fill(&r[k], k);
	assert_int_equal(re_trace_write(&h, r, 8, 0, (size_t)n, out, cap, &len),
			 GL_OK);
	return len;
}

/* The exact text of a one-axis, two-record trace. */
static void test_exact_text(void **state)
{
	static const char want[] =
	    "# roboelf-trace 1\n"
	    "# created 2026-11-25T08:50:48Z\n"
	    "# reason fault\n"
	    "# config_hash 0123456789abcdef\n"
	    "# controller_serial 12345\n"
	    "# period_ms 10.000\n"
	    "# axes A\n"
	    "# fault_t_s 0.020000\n"
	    "# fault_text FAULT POTENTIOMETER: axis A, difference 0.5 V\n"
	    "# records 2\n"
	    "# units s,1,1,1,1,1,ms,ms,1,1,1,1,1,1,1,1,counts,counts,V,V,V,V,"
	    "counts/s,counts/s,1,1,1,1,1\n"
	    "t_s,cycle,phase,fault,relay,link_ok,age_ms,late_ms,hbpc,hbdmc,"
	    "sample,joy_raw,jcmd,mcmd,dmc_state,fcode,A_enc,A_ref,A_pot_v,"
	    "A_pot_exp_v,A_tol_v,A_margin_v,A_vcmd_cps,A_vel_cps,A_motor_off,"
	    "A_moving,A_fwd_lim,A_rev_lim,A_stop_code\n"
	    "0.000000,0,2,0,1,1,1.250,0.062,100,7,65535,4095,-1,0,0,0,-1000,"
	    "2147483647,2.50000,2.50000,0.06250,0.06250,-1234.5,nan,0,0,0,0,"
	    "4\n"
	    "0.010000,1,2,0,1,1,1.250,0.062,101,7,65534,4095,-1,0,0,0,-1001,"
	    "2147483647,3.00000,2.50000,0.06250,-0.43750,-1234.5,nan,0,0,0,0,"
	    "4\n";
	size_t len = small_trace(buf, sizeof(buf), 2, 1);

	(void)state;
	assert_true(len > sizeof(want) - 1);
	assert_memory_equal(buf, want, sizeof(want) - 1);
	/* zlib.crc32(want) == 0x9f121eea, computed with Python's zlib */
	assert_string_equal(buf + sizeof(want) - 1,
			    "# end 2 records crc32 9f121eea\n");
}

/* Written from a wrapped ring, read back: the same values (to the written
 * precision), in ring order. */
static void test_round_trip(void **state)
{
	struct re_trace_hdr h, got;
	struct re_trace_rec ring[5], *r = NULL;
	size_t len;

	(void)state;
	hdr_fill(&h, 3, 0);
	for (int k = 0; k < 5; k++)
		rec_fill(&ring[(k + 3) % 5], k); /* oldest at index 3 */
	assert_int_equal(
	    re_trace_write(&h, ring, 5, 3, 5, buf, sizeof(buf), &len), GL_OK);
	assert_int_equal(re_trace_parse(buf, len, &got, &r, err, sizeof(err)),
			 GL_OK);
	assert_int_equal(got.n_records, 5);
	assert_int_equal(got.n_axes, 3);
	assert_string_equal(got.axis[2], "C");
	assert_int_equal(got.have_fault, 0);
	assert_string_equal(got.reason, "request");
	assert_true(got.config_hash == 0x0123456789abcdefULL);
	for (int k = 0; k < 5; k++) {
		assert_int_equal(r[k].cycle, k);
		assert_int_equal(r[k].sample, 65535 - k);
		assert_float_equal(r[k].t_s, 0.01 * k, 1e-9);
		assert_int_equal(r[k].axis[1].enc_counts, -2000 - k);
		assert_float_equal(r[k].axis[0].pot_v, 2.5 + 0.5 * k, 1e-9);
		assert_true(isnan(r[k].axis[2].pot_exp_v));
		assert_true(isnan(r[k].axis[0].vel_cps));
		assert_int_equal(r[k].axis[2].motor_off, k >= 2);
	}
	free(r);
}

/* Parse @text; expect @rc and exactly @msg. */
static void refused(const char *text, size_t len, int rc, const char *msg)
{
	struct re_trace_hdr h;
	struct re_trace_rec *r = (struct re_trace_rec *)1;

	err[0] = '\0';
	assert_int_equal(re_trace_parse(text, len, &h, &r, err, sizeof(err)),
			 rc);
	assert_null(r);
	assert_string_equal(err, msg);
}

/* Replace the first @from in buf (len) by @to into buf2. */
static size_t edit(size_t len, const char *from, const char *to)
{
	char *p;
	size_t off, fl = strlen(from), tl = strlen(to);

	buf[len] = '\0';
	p = strstr(buf, from);
	assert_non_null(p);
	off = (size_t)(p - buf);
	memcpy(buf2, buf, off);
	memcpy(buf2 + off, to, tl);
	memcpy(buf2 + off + tl, p + fl, len - off - fl);
	return len - fl + tl;
}

static void test_refuse_truncated(void **state)
{
	size_t len = small_trace(buf, sizeof(buf), 3, 2);
	char msg[128];
	const char *end = strstr(buf, "# end");

	(void)state;
	refused(buf, 0, GL_ERR_FORMAT, "line 1: empty file: not a trace");
	/* cut inside the end line */
	snprintf(msg, sizeof(msg),
		 "line 16: truncated: the last line has no end (byte %zu)",
		 len - 3);
	refused(buf, len - 3, GL_ERR_FORMAT, msg);
	/* cut just before the end line */
	refused(buf, (size_t)(end - buf), GL_ERR_FORMAT,
		"line 16: truncated: 3 records and no end line");
	/* cut after two rows */
	refused(buf, (size_t)(strstr(buf, "\n0.020000") - buf) + 1,
		GL_ERR_FORMAT, "line 15: truncated: 2 of 3 records");
	/* inside the header */
	refused(buf, (size_t)(strstr(buf, "# axes") - buf), GL_ERR_FORMAT,
		"line 7: truncated: '# axes' missing");
}

static void test_refuse_version_garbage(void **state)
{
	char msg[128];
	size_t len = small_trace(buf, sizeof(buf), 3, 2), n;
	static const char garbage[] = "\x89PNG\r\n\x1a\n\0\0\0\rIHDR";

	(void)state;
	n = edit(len, "roboelf-trace 1", "roboelf-trace 2");
	refused(buf2, n, GL_ERR_FORMAT,
		"line 1: trace format version '2', this roboelf reads "
		"version 1");
	refused(garbage, sizeof(garbage) - 1, GL_ERR_FORMAT,
		"line 1: NUL or carriage return in the line (byte 0)");
	refused("t_s,cycle\n1,2\n", 14, GL_ERR_FORMAT,
		"line 1: not a roboelf trace (no '# roboelf-trace' line)");
	n = edit(len, "# period_ms 10.000", "# period_ms 1e1");
	refused(buf2, n, GL_ERR_FORMAT, "line 6: bad period_ms");
	n = edit(len, "A_enc", "A_encoder");
	refused(buf2, n, GL_ERR_FORMAT,
		"line 12: the column names line is not the one of version 1 "
		"with axes as declared");
	n = edit(len, "\n0.010000,1,", "\n0.010000,x,");
	refused(buf2, n, GL_ERR_FORMAT, "line 14: column 2: bad value 'x'");
	n = edit(len, ",4\n0.020000,", ",4,0\n0.020000,");
	refused(buf2, n, GL_ERR_FORMAT, "line 14: too many columns (want 42)");
	n = edit(len, "\n0.010000,1,", "\n0.010000,2,");
	refused(buf2, n, GL_ERR_CRC,
		"line 16: checksum differs (the file was changed): the "
		"content's crc32 is f5eea98e");
	memcpy(buf2, buf, len);
	memcpy(buf2 + len, "x\n", 2);
	snprintf(msg, sizeof(msg),
		 "line 16: data after the end line (byte %zu)", len);
	refused(buf2, len + 2, GL_ERR_FORMAT, msg);
}

static void test_refuse_huge(void **state)
{
	char msg[128];
	size_t len = small_trace(buf, sizeof(buf), 3, 2), n;

	(void)state;
	n = edit(len, "# records 3", "# records 2000001");
	refused(buf2, n, GL_ERR_RANGE,
		"line 10: 2000001 records: more than the limit 2000000");
	n = edit(len, "# records 3", "# records 99999");
	snprintf(msg, sizeof(msg),
		 "line 10: truncated: 99999 records cannot fit in %zu bytes",
		 n);
	refused(buf2, n, GL_ERR_FORMAT, msg);
	n = edit(len, "# records 3", "# records 99999999999");
	refused(buf2, n, GL_ERR_FORMAT,
		"line 10: bad record count '99999999999'");
	refused(buf, (size_t)RE_TRACE_MAX_BYTES + 1, GL_ERR_RANGE,
		"byte 1073741824: larger than the limit of 1073741824 bytes");
	memset(buf2, 'x', 5000);
	memcpy(buf2, "# roboelf-trace 1\n", 18);
	buf2[5000] = '\n';
	refused(buf2, 5001, GL_ERR_RANGE,
		"line 2: line longer than 4096 bytes (byte 18)");
}

/* The writer refuses what it cannot write faithfully. */
static void test_write_refusals(void **state)
{
	struct re_trace_hdr h;
	struct re_trace_rec r[2];
	size_t len;

	(void)state;
	rec_fill(&r[0], 0);
	rec_fill(&r[1], 1);
	hdr_fill(&h, 3, 1);
	assert_int_equal(re_trace_write(&h, r, 2, 0, 2, buf, 100, &len),
			 GL_ERR_OVERFLOW);
	assert_int_equal(re_trace_write(&h, r, 2, 2, 2, buf, sizeof(buf), &len),
			 GL_ERR_ARG);
	assert_int_equal(re_trace_write(&h, r, 2, 0, 3, buf, sizeof(buf), &len),
			 GL_ERR_ARG);
	snprintf(h.axis[1], RE_TRACE_NAME, "B,x");
	assert_int_equal(re_trace_write(&h, r, 2, 0, 2, buf, sizeof(buf), &len),
			 GL_ERR_ARG);
	hdr_fill(&h, 3, 1);
	h.fault_text[3] = '\n';
	assert_int_equal(re_trace_write(&h, r, 2, 0, 2, buf, sizeof(buf), &len),
			 GL_ERR_ARG);
	hdr_fill(&h, 4, 0);
	assert_int_equal(re_trace_write(&h, r, 2, 0, 2, buf, sizeof(buf), &len),
			 GL_ERR_ARG);
	assert_true(re_trace_max_bytes(2, 3) >= 2048);
	assert_int_equal(re_trace_max_bytes(2, 0), 0);
}

/* xorshift64*: deterministic, the same mutations on every run. */
static uint64_t rnd_state = 0x9E3779B97F4A7C15ULL;

static uint64_t rnd(void)
{
	rnd_state ^= rnd_state >> 12;
	rnd_state ^= rnd_state << 25;
	rnd_state ^= rnd_state >> 27;
	return rnd_state * 2685821657736338717ULL;
}

static const char interesting[] = ",.-0123456789\n#na ";

static size_t mutate(const char *in, size_t len, char *out, size_t cap)
{
	int n = 1 + (int)(rnd() % 4);

	memcpy(out, in, len);
	for (int i = 0; i < n && len > 1; i++) {
		size_t p = (size_t)(rnd() % len);

		switch (rnd() % 5) {
		case 0: out[p] = (char)rnd(); break;
		case 1:
			out[p] = interesting[rnd() % (sizeof(interesting) - 1)];
			break;
		case 2: len = p; break; /* truncate */
		case 3:			/* delete a byte */
			memmove(out + p, out + p + 1, len - p - 1);
			len--;
			break;
		default: /* duplicate a stretch */
			if (len + 64 < cap) {
				size_t k = (size_t)(rnd() % 64);

				if (p + k > len)
					k = len - p;
				memmove(out + p + k, out + p, len - p);
				len += k;
			}
		}
	}
	return len;
}

/* 10000 mutations: never a crash (run under make asan too), the same
 * verdict twice, and an accepted trace is the writer's own text. */
static void test_fuzz(void **state)
{
	static char mut[64 * 1024], again[64 * 1024];
	size_t len = small_trace(buf, sizeof(buf), 6, 3);
	int accepted = 0, refused_n = 0;

	(void)state;
	for (int it = 0; it < 10000; it++) {
		struct re_trace_hdr h, h2;
		struct re_trace_rec *r = NULL, *r2 = NULL;
		size_t n = mutate(buf, len, mut, sizeof(mut)), n2;
		int rc = re_trace_parse(mut, n, &h, &r, err, sizeof(err));
		int rc2 = re_trace_parse(mut, n, &h2, &r2, err, sizeof(err));

		assert_int_equal(rc, rc2);
		if (rc == GL_OK) {
			accepted++;
			assert_int_equal(re_trace_write(&h, r, h.n_records, 0,
							h.n_records, again,
							sizeof(again), &n2),
					 GL_OK);
			assert_int_equal(n2, n);
			assert_memory_equal(again, mut, n);
		} else {
			refused_n++;
			assert_null(r);
			assert_true(strncmp(err, "line ", 5) == 0 ||
				    strncmp(err, "byte ", 5) == 0);
		}
		free(r);
		free(r2);
	}
	print_message("[ FUZZ     ] 10000 mutations: %d accepted, %d "
		      "refused\n",
		      accepted, refused_n);
	assert_int_equal(accepted + refused_n, 10000);
	assert_true(refused_n > 9000);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_exact_text),
	    cmocka_unit_test(test_round_trip),
	    cmocka_unit_test(test_refuse_truncated),
	    cmocka_unit_test(test_refuse_version_garbage),
	    cmocka_unit_test(test_refuse_huge),
	    cmocka_unit_test(test_write_refusals),
	    cmocka_unit_test(test_fuzz),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
