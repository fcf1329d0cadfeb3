/*
 * test_gload_ident.c - the program identity stamp (pc/galil/gl_ident.c) that
 * galil-load appends and roboelf checks at start-up, the normal form of a
 * program text, and galil-load's read-back comparison (gload_dl_compare),
 * which uses that normal form.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "gl_err.h"
#include "gl_hash.h"
#include "gl_ident.h"
#include "gload_dl.h"

/* The published FNV-1a 64 test vectors, through the stamp. */
static void test_stamp_vectors(void **state)
{
	char line[GL_IDENT_LINE_SIZE];

	(void)state;
	assert_true(gl_ident_stamp("", 0, line) == 0xcbf29ce484222325ULL);
	assert_string_equal(line, "NO ID CBF29CE484222325");
	assert_true(gl_ident_stamp("a", 1, line) == 0xaf63dc4c8601ec8cULL);
	assert_string_equal(line, "NO ID AF63DC4C8601EC8C");
	assert_true(gl_ident_stamp("foobar", 6, NULL) == 0x85944171f73967e8ULL);
	assert_int_equal(GL_IDENT_LINE_SIZE, 23);
}

/* Build "body + stamp line" with the given line end. */
static char *make_program(const char *body_lf, const char *eol)
{
	char line[GL_IDENT_LINE_SIZE];
	char *out = calloc(1, 1024), *o = out;
	const char *s;

	assert_non_null(out);
	gl_ident_stamp(body_lf, strlen(body_lf), line);
	for (s = body_lf; *s; s++) {
		if (*s == '\n')
			o += sprintf(o, "%s", eol);
		else
			*o++ = *s;
	}
	sprintf(o, "%s%s", line, eol);
	return out;
}

/* What the controller uploads (CR LF, Ctrl-Z) verifies; so do CR and LF. */
static void test_verify_ok(void **state)
{
	static const char body[] = "EN\n#AUTO\nMG \"hi\"\nEN\n";
	const uint64_t want = gl_fnv1a64(GL_FNV64_INIT, body, strlen(body));
	static const char *const eols[] = {"\r\n", "\r", "\n"};
	uint64_t id;
	size_t i;

	(void)state;
	for (i = 0; i < 3; i++) {
		char *prog = make_program(body, eols[i]);

		strcat(prog, "\x1a:junk after the end mark");
		id = 0;
		assert_int_equal(gl_ident_verify(prog, strlen(prog), &id),
				 GL_OK);
		assert_true(id == want);
		free(prog);
	}
}

/* Trailing empty lines, lower-case hex, a stamp with an empty body. */
static void test_verify_variants(void **state)
{
	char prog[128];
	uint64_t id;

	(void)state;
	snprintf(prog, sizeof(prog), "EN\r\nNO ID %016llx\r\n\r\n\r\n",
		 (unsigned long long)gl_fnv1a64(GL_FNV64_INIT, "EN\n", 3));
	assert_int_equal(gl_ident_verify(prog, strlen(prog), &id), GL_OK);
	assert_int_equal(gl_ident_verify("NO ID CBF29CE484222325", 22, &id),
			 GL_OK);
	assert_true(id == GL_FNV64_INIT);
}

/* One byte changed, a line added or removed: mismatch, stamp reported. */
static void test_verify_mismatch(void **state)
{
	char *prog = make_program("EN\n#AUTO\nx=1\nEN\n", "\r\n");
	char *p;
	uint64_t id = 0, want;

	(void)state;
	assert_int_equal(gl_ident_verify(prog, strlen(prog), &want), GL_OK);
	p = strstr(prog, "x=1");
	p[2] = '2';
	assert_int_equal(gl_ident_verify(prog, strlen(prog), &id),
			 GL_ERR_MISMATCH);
	assert_true(id == want);
	p[2] = '1';
	strstr(prog, "#AUTO")[1] = 'a'; /* case matters */
	assert_int_equal(gl_ident_verify(prog, strlen(prog), &id),
			 GL_ERR_MISMATCH);
	free(prog);
	prog = make_program("EN\n#AUTO\nx=1\nEN\n", "\n");
	/* an empty line inside the body changes the hash */
	memmove(prog + 3, prog + 2, strlen(prog + 2) + 1);
	prog[2] = '\n';
	assert_int_equal(gl_ident_verify(prog, strlen(prog), &id),
			 GL_ERR_MISMATCH);
	free(prog);
}

/* No stamp, a malformed stamp, a stamp not last, nothing at all. */
static void test_verify_format(void **state)
{
	static const char *const bad[] = {
	    "",
	    "\x1a:",
	    "\r\n\r\n",
	    "EN\r\n#AUTO\r\n",
	    "EN\r\nNO ID 0123456789ABCDE\r\n",	 /* 15 digits */
	    "EN\r\nNO ID 0123456789ABCDEF0\r\n", /* 17 digits */
	    "EN\r\nNO ID  123456789ABCDEF\r\n",	 /* two spaces */
	    "EN\r\nNO ID 0123456789ABCDEG\r\n",	 /* not hex */
	    "EN\r\nNO ID 0123456789ABCDEF \r\n", /* trailing space */
	    "EN\r\nno id 0123456789ABCDEF\r\n",
	    "NO ID 0123456789ABCDEF\r\nEN\r\n", /* not the last line */
	};
	uint64_t id = 1;
	size_t i;

	(void)state;
	for (i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
		if (gl_ident_verify(bad[i], strlen(bad[i]), &id) !=
		    GL_ERR_FORMAT)
			fail_msg("case %zu accepted", i);
		assert_true(id == 0);
	}
	assert_int_equal(gl_ident_verify(NULL, 3, &id), GL_ERR_ARG);
	assert_int_equal(gl_ident_verify(NULL, 0, NULL), GL_ERR_FORMAT);
}

struct norm_case {
	const char *in;
	size_t len;
	const char *out;
};

#define NC(in, out)                                                            \
	{                                                                      \
		in, sizeof(in) - 1, out                                        \
	}

static const struct norm_case norms[] = {
    NC("a\r\nb\rc\n", "a\nb\nc\n"),
    NC("a", "a\n"),
    NC("", ""),
    NC("\n\n", ""),
    NC("\r\n", ""),
    NC("a\n\n\n", "a\n"),
    NC("a\r\n\r\n\r\n", "a\n"),
    NC("a\n\nb", "a\n\nb\n"),
    NC("a\x1a b\n", "a\n"),
    NC("a\r\n\x1a:", "a\n"),
    NC("\x1a", ""),
    NC(" a \r\n", " a \n"),
    NC("a\r\r\nb", "a\n\nb\n"),
};

/* The normal form, also computed in place. */
static void test_normalise(void **state)
{
	char buf[64];
	size_t i;
	int n;

	(void)state;
	for (i = 0; i < sizeof(norms) / sizeof(norms[0]); i++) {
		n = gl_ident_normalise(norms[i].in, norms[i].len, buf,
				       sizeof(buf));
		assert_int_equal(n, strlen(norms[i].out));
		assert_memory_equal(buf, norms[i].out, (size_t)n);
		memcpy(buf, norms[i].in, norms[i].len);
		n = gl_ident_normalise(buf, norms[i].len, buf,
				       norms[i].len + 1);
		assert_int_equal(n, strlen(norms[i].out));
		assert_memory_equal(buf, norms[i].out, (size_t)n);
	}
	assert_int_equal(gl_ident_normalise("abc", 3, buf, 3), GL_ERR_OVERFLOW);
	assert_int_equal(gl_ident_normalise(NULL, 1, buf, 8), GL_ERR_ARG);
}

/* Read-back comparison: equal modulo line ends, else the first line. */
static void test_compare(void **state)
{
	static const char want[] = "EN\n#AUTO\nx=1\nEN\n";
	int line = 0;

	(void)state;
	assert_int_equal(gload_dl_compare(want, strlen(want),
					  "EN\r\n#AUTO\r\nx=1\r\nEN\r\n\x1a",
					  22, &line),
			 GL_OK);
	assert_int_equal(gload_dl_compare(want, strlen(want),
					  "EN\r\n#AUTO\r\nx=2\r\nEN\r\n", 21,
					  &line),
			 GL_ERR_MISMATCH);
	assert_int_equal(line, 3);
	assert_int_equal(gload_dl_compare(want, strlen(want),
					  "EN\r\n#AUTO\r\nx=1\r\nEN\r\nEN\r\n",
					  25, &line),
			 GL_ERR_MISMATCH);
	assert_int_equal(line, 5);
	assert_int_equal(
	    gload_dl_compare(want, strlen(want), "EN\r\n#AUTO", 9, &line),
	    GL_ERR_MISMATCH);
	assert_int_equal(line, 3);
	assert_int_equal(gload_dl_compare(want, strlen(want), "", 0, &line),
			 GL_ERR_MISMATCH);
	assert_int_equal(line, 1);
	/* a space changed inside a line is a difference */
	assert_int_equal(gload_dl_compare(want, strlen(want),
					  "EN\n#AUTO\nx=1 \nEN\n", 17, &line),
			 GL_ERR_MISMATCH);
	assert_int_equal(line, 3);
}

/* Exit codes for link errors. */
static void test_exit_codes(void **state)
{
	(void)state;
	assert_int_equal(gload_exit_for(GL_OK), 0);
	assert_int_equal(gload_exit_for(12), 0);
	assert_int_equal(gload_exit_for(GL_ERR_CTRL), 4);
	assert_int_equal(gload_exit_for(GL_ERR_MISMATCH), 4);
	assert_int_equal(gload_exit_for(GL_ERR_TIMEOUT), 3);
	assert_int_equal(gload_exit_for(GL_ERR_CLOSED), 3);
	assert_int_equal(gload_exit_for(GL_ERR_BROKEN), 3);
	assert_int_equal(gload_exit_for(GL_ERR_PROTO), 3);
	assert_int_equal(gload_exit_for(GL_ERR_SYS), 3);
	assert_int_equal(gload_exit_for(GL_ERR_ARG), 2);
}

/* Random uploads never crash the verifier; the answer is one of three. */
static void test_verify_random(void **state)
{
	static const char alphabet[] =
	    "NO ID 0123456789ABCDEFabcdef\r\n\x1a:;#";
	char buf[200], line[GL_IDENT_LINE_SIZE];
	unsigned seed = 99;
	int i, j, n, rc;
	uint64_t id;

	(void)state;
	for (i = 0; i < 5000; i++) {
		n = (int)((seed = seed * 1103515245u + 12345u) >> 16) % 150;
		for (j = 0; j < n; j++) {
			seed = seed * 1103515245u + 12345u;
			buf[j] =
			    alphabet[(seed >> 16) % (sizeof(alphabet) - 1)];
		}
		if (i % 2) { /* half of them with a valid stamp appended */
			gl_ident_stamp(buf, (size_t)n, line);
			n += snprintf(buf + n, sizeof(buf) - (size_t)n, "%s",
				      line);
		}
		rc = gl_ident_verify(buf, (size_t)n, &id);
		assert_true(rc == GL_OK || rc == GL_ERR_MISMATCH ||
			    rc == GL_ERR_FORMAT);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_stamp_vectors),
	    cmocka_unit_test(test_verify_ok),
	    cmocka_unit_test(test_verify_variants),
	    cmocka_unit_test(test_verify_mismatch),
	    cmocka_unit_test(test_verify_format),
	    cmocka_unit_test(test_normalise),
	    cmocka_unit_test(test_compare),
	    cmocka_unit_test(test_exit_codes),
	    cmocka_unit_test(test_verify_random),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
