/*
 * test_re_seal.c - the seal table and its program part (pc/super/re_seal.h):
 * what is sealed with which value, the emitted lines (80 characters, the
 * slices, one finder line per item), the comparison roboelf makes at
 * start-up and the FAULT details it fills, its read-back while running,
 * and the refusals.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "dmc_h.h"
#include "gl_err.h"
#include "re_check.h"
#include "re_config.h"
#include "re_seal.h"
#include "re_sealmake.h"

static char body[DMC_H_PROG_MAX];
static int body_len;
static struct re_seal seal, other;
static char text[RE_SEAL_TEXT_MAX], text2[RE_SEAL_TEXT_MAX];

static int setup(void **state)
{
	char err[256];

	(void)state;
	body_len =
	    dmc_h_load_program(NULL, body, sizeof(body), err, sizeof(err));
	if (body_len < 0) {
		fprintf(stderr, "dmc/: %s\n", err);
		return -1;
	}
	return 0;
}

static void make(const struct re_config *c, struct re_seal *s, char *out)
{
	char err[256] = "";

	if (re_seal_make(body, (size_t)body_len, c, s, err, sizeof(err)))
		fail_msg("re_seal_make: %s", err);
	assert_true(re_seal_emit(s, out, RE_SEAL_TEXT_MAX) > 0);
}

static const struct re_seal_item *item(const struct re_seal *s, const char *ref,
				       int *number)
{
	for (int i = 0; i < s->n; i++)
		if (!strcmp(s->item[i].ref, ref)) {
			if (number)
				*number = i + 1;
			return &s->item[i];
		}
	fail_msg("no sealed item '%s'", ref);
	return NULL;
}

/* The defaults: what is sealed, with which value, of which kind. */
static void test_table(void **state)
{
	struct re_config c;
	const struct re_seal_item *it;
	int k;

	(void)state;
	re_config_defaults(&c);
	make(&c, &seal, text);
	it = item(&seal, "vers", &k);
	assert_int_equal(k, 1);
	assert_int_equal(it->kind, RE_SEAL_CONST);
	assert_string_equal(it->lit, "2.24");
	it = item(&seal, "rampov", NULL);
	assert_true(it->value == 1.25);
	it = item(&seal, "vmax[0]", &k);
	assert_int_equal(k, 28); /* after the 24 constants and 3 vmin */
	assert_int_equal(it->kind, RE_SEAL_PARAM);
	assert_true(it->value == c.axes[0].vmax_cps);
	assert_int_equal(it->axis, 0);
	assert_true(item(&seal, "hbmaxd", NULL)->value == 102);
	assert_true(item(&seal, "jin[11]", NULL)->value == 20);
	assert_int_equal(item(&seal, "jin[11]", NULL)->axis, 2);
	it = item(&seal, "_KPB", NULL);
	assert_int_equal(it->kind, RE_SEAL_SETTING);
	assert_true(it->tol == 0.125);
	assert_true(item(&seal, "_ERC", NULL)->tol == 0);
	assert_true(item(&seal, "_CN0", NULL)->value == -1);
	assert_true(item(&seal, "_TM", NULL)->value == 1000);
	it = item(&seal, "_FLB", NULL);
	assert_int_equal(it->kind, RE_SEAL_SESSION);
	assert_int_equal(it->shadow, 7);
	assert_int_equal(item(&seal, "vlc", NULL)->shadow, 20);
	assert_int_equal(item(&seal, "_XQ7", NULL)->kind, RE_SEAL_THREAD);
	assert_int_equal(item(&seal, "prun", &k)->kind, RE_SEAL_RUNNING);
	assert_int_equal(k, seal.n);
	/* mvto belongs to each move request: not sealed */
	for (int i = 0; i < seal.n; i++)
		assert_string_not_equal(seal.item[i].ref, "mvto");
	/* thread 1's lines: #MOTION up to the line before #POSERR */
	assert_true(seal.t1_first > 100 && seal.t1_last > seal.t1_first);
}

/* The program part: 80 characters a line, #SEALIN first, every item in
 * one check of the rotation and one finder line, nine slices. */
static void test_emit(void **state)
{
	struct re_config c;
	char line[256], want[128];
	const char *p;
	int slices = 0;

	(void)state;
	re_config_defaults(&c);
	make(&c, &seal, text);
	assert_int_equal(strncmp(text, RE_SEAL_FIRST "\n", 8), 0);
	for (p = text; *p;) {
		size_t n = strcspn(p, "\n");

		if (n > 80)
			fail_msg("line of %zu characters: %.*s", n, (int)n, p);
		snprintf(line, sizeof(line), "%.*s", (int)n, p);
		if (!strncmp(line, "#SL", 3) && line[3] >= '0' &&
		    line[3] <= '9')
			slices++;
		p += n + (p[n] == '\n');
	}
	assert_int_equal(slices, RE_SEAL_SLICES);
	assert_non_null(strstr(text, ";vmax[0]=8000;"));
	assert_non_null(strstr(text, "(vmax[0]<>8000)"));
	assert_non_null(strstr(text, "(@ABS[_KPA-6]>0.125)"));
	assert_non_null(strstr(text, "(_CN0<>(0-1))"));
	assert_non_null(strstr(text, "\nanv[0]=@AN[1];anv[1]=@AN[2];"));
	assert_non_null(strstr(text, ";ssn[7]=_FLB;"));
	assert_non_null(strstr(text, "(_TLA>5.001)"));
	for (int i = 0; i < seal.n; i++) {
		snprintf(want, sizeof(want), "\nsid=%d;sax=%d;sfv=", i + 1,
			 seal.item[i].axis + 1);
		if (!strstr(text, want))
			fail_msg("no finder line for %s", seal.item[i].ref);
	}
	assert_non_null(strstr(text, "\nJS #FAULT(17,sax,sid)\n"));
	assert_int_equal(re_seal_split(text, strlen(text)), 0);
	assert_int_equal(re_seal_split("EN\n#X\n", 6), -1);
}

/* roboelf's comparison names the first value sealed otherwise, with both
 * values; the same configuration compares equal. */
static void test_compare(void **state)
{
	struct re_config c, d;
	char err[512];

	(void)state;
	re_config_defaults(&c);
	make(&c, &seal, text);
	assert_int_equal(re_seal_compare(&seal, text, strlen(text), text,
					 strlen(text), err, sizeof(err)),
			 GL_OK);
	d = c;
	d.axes[0].vmax_cps = 6000;
	make(&d, &other, text2);
	assert_int_equal(re_seal_compare(&other, text, strlen(text), text2,
					 strlen(text2), err, sizeof(err)),
			 GL_ERR_MISMATCH);
	assert_string_equal(
	    err, "the controller's program was sealed with other values than "
		 "this configuration gives: vmax[0] (maximum joystick "
		 "velocity, axis A) is 8000 in the controller's program, 6000 "
		 "here");
	d = c;
	d.axes[1].encoder_failure.time_samples = 20;
	make(&d, &other, text2);
	assert_int_equal(re_seal_compare(&other, text, strlen(text), text2,
					 strlen(text2), err, sizeof(err)),
			 GL_ERR_MISMATCH);
	assert_string_equal(
	    err, "the controller's program was sealed with other values than "
		 "this configuration gives: _OTB (encoder-failure time, axis "
		 "B) is 100 in the controller's program, 20 here");
	d = c;
	d.axes[2].kp = 7;
	make(&d, &other, text2);
	assert_int_equal(re_seal_compare(&other, text, strlen(text), text2,
					 strlen(text2), err, sizeof(err)),
			 GL_ERR_MISMATCH);
	assert_non_null(strstr(err, "_KPC (proportional gain, axis C) is 6 in "
				    "the controller's program, 7 here"));
}

/* A fault 17 from the program filled for the FAULT line. */
static void test_fault(void **state)
{
	struct re_config c;
	struct re_fault f;
	int k = 0;

	(void)state;
	re_config_defaults(&c);
	make(&c, &seal, text);
	item(&seal, "vmax[1]", &k);
	re_fault_set(&f, RE_F_CTRL_SEAL, -1);
	f.i[0] = k;
	re_seal_fault(&seal, 40000, NAN, &f);
	assert_string_equal(f.s, "vmax[1] (maximum joystick velocity, axis B)");
	assert_int_equal(f.axis, 1);
	assert_true(f.f[0] == 40000 && f.f[1] == 8000);
	item(&seal, "srev[2]", &k);
	re_fault_set(&f, RE_F_CTRL_SEAL, -1);
	f.i[0] = k;
	re_seal_fault(&seal, -3000, -45000, &f);
	assert_true(f.f[0] == -3000 && f.f[1] == -45000);
	assert_int_equal(f.axis, 2);
	re_fault_set(&f, RE_F_CTRL_SEAL, -1);
	f.i[0] = 0;
	re_seal_fault(&seal, 1, NAN, &f);
	assert_string_equal(f.s, "an unknown sealed value (0)");
	assert_true(isnan(f.f[1]));
}

/* What cannot be sealed is refused with the reason. */
static void test_refusals(void **state)
{
	static const char no_consts[] = "EN\n#MOTION\nEN\n#POSERR\nEN\n";
	static const char bad_const[] =
	    "EN\n#CONSTS\nvers=2.20\nx=y+1\nEN\n#MOTION\nEN\n#POSERR\nEN\n";
	static const char no_motion[] = "EN\n#CONSTS\nvers=2.20\nEN\n";
	struct re_config c;
	char err[256];

	(void)state;
	re_config_defaults(&c);
	assert_int_equal(re_seal_make(no_consts, strlen(no_consts), &c, &other,
				      err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_string_equal(err, "the program has no #CONSTS");
	assert_int_equal(re_seal_make(bad_const, strlen(bad_const), &c, &other,
				      err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_string_equal(err, "cannot seal the constant 'x=y+1': #CONSTS "
				 "may only set NAME=NUMBER or NAME=0-NAME");
	assert_int_equal(re_seal_make(no_motion, strlen(no_motion), &c, &other,
				      err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_string_equal(err, "the program has no #MOTION before #POSERR");
}

/* The reply to "MG r1,...,rn" for items @first.. + @count, from @v. */
static size_t reply(const double *v, int first, int count, char *buf,
		    size_t cap)
{
	size_t n = 0;

	for (int i = first; i < first + count; i++)
		n += (size_t)snprintf(buf + n, cap - n, " %.4f", v[i]);
	return n;
}

/* The read-back: the table split into chunks that fit a line; every
 * chunk of what the plan expects holds; one value changed in a chunk is
 * that item with the value found; session items are judged only once the
 * program is in the state the plan was made for; a short reply is a
 * protocol error. */
static void test_readback(void **state)
{
	struct re_config c;
	static double want[RE_SEAL_MAX], got[RE_SEAL_MAX];
	int first[64], count[64], n, bad = 0, k = 0, total = 0;
	double found = 0;
	char buf[4096];
	size_t len;

	(void)state;
	re_config_defaults(&c);
	make(&c, &seal, text);
	re_seal_expect(&seal, 1, NULL, NULL, want);
	n = re_seal_chunks(&seal, 60, first, count, 64);
	assert_true(n > 10);
	for (int i = 0; i < n; i++) {
		char mg[128];

		assert_true(re_seal_chunk_text(&seal, first[i], count[i], mg,
					       sizeof(mg)) <= 60);
		total += count[i];
	}
	assert_int_equal(total, seal.n);
	memcpy(got, want, sizeof(got));
	item(&seal, "_XQ1", &k); /* armed: thread 1 runs its own code */
	got[k - 1] = seal.t1_first;
	for (int i = 0; i < n; i++) {
		len = reply(got, first[i], count[i], buf, sizeof(buf));
		assert_int_equal(re_seal_judge(&seal, want, first[i], count[i],
					       buf, len, 1, 1, &bad, &found),
				 RE_OK);
	}
	for (int i = 0; i < n; i++) /* thread 1 not running while armed */
		if (k - 1 >= first[i] && k - 1 < first[i] + count[i]) {
			got[k - 1] = -1;
			len = reply(got, first[i], count[i], buf, sizeof(buf));
			assert_int_equal(re_seal_judge(&seal, want, first[i],
						       count[i], buf, len, 1, 1,
						       &bad, &found),
					 RE_FAULT);
			assert_int_equal(bad, k);
			got[k - 1] = seal.t1_first;
		}
	item(&seal, "jin[0]", &k);
	for (int i = 0; i < n; i++)
		if (k - 1 >= first[i] && k - 1 < first[i] + count[i]) {
			got[k - 1] = 3;
			len = reply(got, first[i], count[i], buf, sizeof(buf));
			assert_int_equal(re_seal_judge(&seal, want, first[i],
						       count[i], buf, len, 1, 1,
						       &bad, &found),
					 RE_FAULT);
			assert_int_equal(bad, k);
			assert_true(found == 3);
			got[k - 1] = want[k - 1];
			len = reply(got, first[i], count[i], buf, sizeof(buf));
			len = (size_t)(strrchr(buf, ' ') - buf); /* one short */
			assert_int_equal(re_seal_judge(&seal, want, first[i],
						       count[i], buf, len, 1, 1,
						       &bad, &found),
					 GL_ERR_PROTO);
		}
	item(&seal, "vla", &k); /* a session item: wrong before the session */
	got[k - 1] = 0;
	for (int i = 0; i < n; i++)
		if (k - 1 >= first[i] && k - 1 < first[i] + count[i]) {
			len = reply(got, first[i], count[i], buf, sizeof(buf));
			assert_int_equal(re_seal_judge(&seal, want, first[i],
						       count[i], buf, len, 0, 1,
						       &bad, &found),
					 RE_OK);
			assert_int_equal(re_seal_judge(&seal, want, first[i],
						       count[i], buf, len, 1, 1,
						       &bad, &found),
					 RE_FAULT);
			assert_int_equal(bad, k);
		}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_readback), cmocka_unit_test(test_table),
	    cmocka_unit_test(test_emit),     cmocka_unit_test(test_compare),
	    cmocka_unit_test(test_fault),    cmocka_unit_test(test_refusals),
	};

	return cmocka_run_group_tests(tests, setup, NULL);
}
