/*
 * test_gl_proto.c - the pure reply parser fed whole, byte by byte and in
 * random chunks (hundreds of seeds): every framing case of galil-notes.md
 * 1.3/1.5/3.2, unsolicited high-bit bytes anywhere, malformed input.
 *
 * Each case is run through run_all(): the whole-feed result is asserted
 * exactly by the test, and every other way of splitting the same bytes must
 * give the identical result.
 */
#include <errno.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "gl_err.h"
#include "gl_proto.h"
#include "gl_record.h"

#define MAX_REPLIES 8
#define MAX_UNSOL   8
#define N_SEEDS	    300

struct got_reply {
	int n_cmds, n_err, first_err;
	char text[GL_PROTO_TEXT_MAX];
	size_t text_len;
	bool truncated;
	uint8_t bin[GL_REC_MAX_BYTES];
	size_t bin_len;
	bool has_bin;
};

struct got {
	int n;
	struct got_reply r[MAX_REPLIES];
	int rc; /* last gl_proto_next() result */
	int n_unsol;
	char unsol[MAX_UNSOL][GL_PROTO_UNSOL_LINE + 1];
};

struct expect {
	int n_term;
	size_t bin_len;
};

/* Our own LCG so that seeds mean the same everywhere. */
static uint32_t lcg(uint32_t *s)
{
	*s = *s * 1103515245u + 12345u;
	return (*s >> 16) & 0x7fff;
}

static void save_reply(struct got *g, const struct gl_reply *r)
{
	struct got_reply *o;

	assert_true(g->n < MAX_REPLIES);
	o = &g->r[g->n++];
	o->n_cmds = r->n_cmds;
	o->n_err = r->n_err;
	o->first_err = r->first_err;
	o->text_len = r->text_len;
	assert_true(r->text_len < sizeof(o->text));
	memcpy(o->text, r->text, r->text_len);
	o->text[r->text_len] = '\0';
	assert_int_equal(r->text[r->text_len], '\0');
	o->truncated = r->truncated;
	o->has_bin = r->bin != NULL;
	o->bin_len = r->bin_len;
	if (r->bin)
		memcpy(o->bin, r->bin, r->bin_len);
}

/* Drain replies until the parser needs more bytes or fails. */
static int drain(struct gl_proto *p, struct got *g)
{
	struct gl_reply r;
	int rc;

	while ((rc = gl_proto_next(p, &r)) == GL_OK)
		save_reply(g, &r);
	return rc;
}

static void drain_unsol(struct gl_proto *p, struct got *g)
{
	char line[GL_PROTO_UNSOL_LINE + 1];
	int rc;

	while ((rc = gl_proto_unsol_next(p, line, sizeof(line))) >= 0) {
		assert_true(g->n_unsol < MAX_UNSOL);
		strcpy(g->unsol[g->n_unsol++], line);
	}
	assert_int_equal(rc, GL_ERR_AGAIN);
}

/*
 * Feed @in in pieces: chunk = 0 whole, 1 byte by byte, else random sizes
 * 1..17 from @seed. The result goes to @g.
 */
static void run(const void *in, size_t len, const struct expect *e, int n_e,
		int chunk, uint32_t seed, struct got *g)
{
	static struct gl_proto p;
	const uint8_t *b = in;
	size_t off = 0;
	int i;

	memset(g, 0, sizeof(*g));
	gl_proto_init(&p);
	for (i = 0; i < n_e; i++)
		assert_int_equal(gl_proto_expect(&p, e[i].n_term, e[i].bin_len),
				 GL_OK);
	g->rc = GL_ERR_AGAIN;
	while (off < len && g->rc == GL_ERR_AGAIN) {
		size_t n = chunk == 0	? len
			   : chunk == 1 ? 1
					: 1 + lcg(&seed) % 17;

		if (n > len - off)
			n = len - off;
		assert_int_equal(gl_proto_feed(&p, b + off, n), GL_OK);
		off += n;
		g->rc = drain(&p, g);
	}
	if (len == 0)
		g->rc = drain(&p, g);
	drain_unsol(&p, g);
}

static void assert_got_equal(const struct got *a, const struct got *b)
{
	int i;

	assert_int_equal(a->rc, b->rc);
	assert_int_equal(a->n, b->n);
	for (i = 0; i < a->n; i++) {
		assert_int_equal(a->r[i].n_cmds, b->r[i].n_cmds);
		assert_int_equal(a->r[i].n_err, b->r[i].n_err);
		assert_int_equal(a->r[i].first_err, b->r[i].first_err);
		assert_string_equal(a->r[i].text, b->r[i].text);
		assert_int_equal(a->r[i].truncated, b->r[i].truncated);
		assert_int_equal(a->r[i].has_bin, b->r[i].has_bin);
		assert_int_equal(a->r[i].bin_len, b->r[i].bin_len);
		assert_memory_equal(a->r[i].bin, b->r[i].bin, a->r[i].bin_len);
	}
	assert_int_equal(a->n_unsol, b->n_unsol);
	for (i = 0; i < a->n_unsol; i++)
		assert_string_equal(a->unsol[i], b->unsol[i]);
}

/* Run whole into @g, then byte by byte and N_SEEDS random chunkings. */
static void run_all(const void *in, size_t len, const struct expect *e, int n_e,
		    struct got *g)
{
	static struct got other;
	uint32_t seed;

	run(in, len, e, n_e, 0, 0, g);
	run(in, len, e, n_e, 1, 0, &other);
	assert_got_equal(g, &other);
	for (seed = 1; seed <= N_SEEDS; seed++) {
		run(in, len, e, n_e, 2, seed, &other);
		assert_got_equal(g, &other);
	}
}

static struct got g;

#define S(lit) (lit), (sizeof(lit) - 1)

/* TEST_proto_colon: a command without data answers ':' alone. */
static void test_proto_colon(void **state)
{
	const struct expect e[] = {{1, 0}};

	(void)state;
	run_all(S(":"), e, 1, &g);
	assert_int_equal(g.rc, GL_ERR_AGAIN);
	assert_int_equal(g.n, 1);
	assert_int_equal(g.r[0].n_cmds, 1);
	assert_int_equal(g.r[0].n_err, 0);
	assert_int_equal(g.r[0].first_err, -1);
	assert_string_equal(g.r[0].text, "");
	assert_false(g.r[0].has_bin);
}

/* TEST_proto_data: data, CR LF, ':' gives the data without CR LF. */
static void test_proto_data(void **state)
{
	const struct expect e[] = {{1, 0}};

	(void)state;
	run_all(S(" 5.0000\r\n:"), e, 1, &g);
	assert_int_equal(g.n, 1);
	assert_string_equal(g.r[0].text, " 5.0000");
	assert_int_equal(g.r[0].text_len, 7);
	/* multi-line data (TH) keeps the inner line ends */
	run_all(S("CONTROLLER IP\r\n IHA TCP\r\n IHB AVAILABLE\r\n:"), e, 1,
		&g);
	assert_string_equal(g.r[0].text,
			    "CONTROLLER IP\r\n IHA TCP\r\n IHB AVAILABLE");
}

/* TEST_proto_qmark: '?' alone (no CR LF) is a rejected command. */
static void test_proto_qmark(void **state)
{
	const struct expect e[] = {{1, 0}};

	(void)state;
	run_all(S("?"), e, 1, &g);
	assert_int_equal(g.n, 1);
	assert_int_equal(g.r[0].n_cmds, 1);
	assert_int_equal(g.r[0].n_err, 1);
	assert_int_equal(g.r[0].first_err, 0);
	assert_string_equal(g.r[0].text, "");
}

/* TEST_proto_multi_command: one terminator per ';' command, data joined. */
static void test_proto_multi_command(void **state)
{
	/* "x=1;MG x;foo;MG 2;y=3" */
	const struct expect e[] = {{5, 0}};

	(void)state;
	run_all(S(": 1.0000\r\n:? 2.0000\r\n::"), e, 1, &g);
	assert_int_equal(g.rc, GL_ERR_AGAIN);
	assert_int_equal(g.n, 1);
	assert_int_equal(g.r[0].n_cmds, 5);
	assert_int_equal(g.r[0].n_err, 1);
	assert_int_equal(g.r[0].first_err, 2);
	assert_string_equal(g.r[0].text, " 1.0000\r\n 2.0000");
	/* TMT's notation: blank line before the value is not data */
	run_all(S(":\r\n500.0000\r\n:"), (const struct expect[]){{2, 0}}, 1,
		&g);
	assert_string_equal(g.r[0].text, "500.0000");
	/* ':' and '?' inside a data line are data */
	run_all(S("ok? a:b\r\n:"), e, 0, &g);
	assert_int_equal(g.rc, GL_ERR_PROTO);
	run_all(S("ok? a:b\r\n:"), (const struct expect[]){{1, 0}}, 1, &g);
	assert_int_equal(g.n, 1);
	assert_int_equal(g.r[0].n_err, 0);
	assert_string_equal(g.r[0].text, "ok? a:b");
}

/* TEST_proto_several_replies: several replies in one feed, in order. */
static void test_proto_several_replies(void **state)
{
	const struct expect e[] = {{1, 0}, {1, 0}, {2, 0}, {1, 0}};

	(void)state;
	run_all(S(": 5.0000\r\n:?:DMC4030 Rev 1.2h\r\n:"), e, 4, &g);
	assert_int_equal(g.rc, GL_ERR_AGAIN);
	assert_int_equal(g.n, 4);
	assert_string_equal(g.r[0].text, "");
	assert_int_equal(g.r[0].n_err, 0);
	assert_string_equal(g.r[1].text, " 5.0000");
	assert_int_equal(g.r[2].n_cmds, 2);
	assert_int_equal(g.r[2].n_err, 1);
	assert_int_equal(g.r[2].first_err, 0);
	assert_string_equal(g.r[3].text, "DMC4030 Rev 1.2h");
}

/* A 3-axis 40x0 record whose fields hold ':' (0x3A) and high bytes. */
static size_t make_record(uint8_t *out)
{
	struct gl_record r;
	int n;

	memset(&r, 0, sizeof(r));
	r.layout = GL_LAYOUT_4000;
	r.n_axes = 3;
	r.sample = 0x3A3A;
	r.inputs[0] = 0x8D; /* CR with the high bit */
	r.inputs[1] = 0x8A; /* LF with the high bit */
	r.error_code = '?';
	r.axis[0].motor_pos = 0x3A3A3A3A;
	r.axis[1].motor_pos = (int32_t)0xBFBABFBA;
	r.axis[2].za = 0x3A8A8D3F;
	n = gl_record_encode(&r, out, GL_REC_MAX_BYTES);
	assert_int_equal(n, 190);
	return (size_t)n;
}

/* TEST_proto_record: prefix ':' then a record with ':' and 0x80+ bytes. */
static void test_proto_record(void **state)
{
	const struct expect e[] = {{2, 190}, {1, 0}};
	uint8_t rec[GL_REC_MAX_BYTES], in[512];
	struct gl_record d;
	size_t n = 0;

	(void)state;
	in[n++] = ':';
	n += make_record(rec);
	memcpy(in + 1, rec, 190);
	in[n++] = ':';
	memcpy(in + n, " 7.0000\r\n:", 10);
	n += 10;
	run_all(in, n, e, 2, &g);
	assert_int_equal(g.rc, GL_ERR_AGAIN);
	assert_int_equal(g.n, 2);
	assert_int_equal(g.r[0].n_cmds, 2);
	assert_int_equal(g.r[0].n_err, 0);
	assert_true(g.r[0].has_bin);
	assert_int_equal(g.r[0].bin_len, 190);
	assert_memory_equal(g.r[0].bin, rec, 190);
	assert_int_equal(
	    gl_record_decode(g.r[0].bin, 190, GL_LAYOUT_4000, 3, &d), GL_OK);
	assert_int_equal(d.axis[2].za, 0x3A8A8D3F);
	assert_string_equal(g.r[1].text, " 7.0000");
	assert_int_equal(g.n_unsol, 0);
}

/* TEST_proto_record_rejected: QR answered '?' (alone or after a prefix). */
static void test_proto_record_rejected(void **state)
{
	(void)state;
	run_all(S("?"), (const struct expect[]){{1, 190}}, 1, &g);
	assert_int_equal(g.n, 1);
	assert_int_equal(g.r[0].n_err, 1);
	assert_false(g.r[0].has_bin);
	run_all(S(":?"), (const struct expect[]){{2, 190}}, 1, &g);
	assert_int_equal(g.n, 1);
	assert_int_equal(g.r[0].n_err, 1);
	assert_int_equal(g.r[0].first_err, 1);
	assert_false(g.r[0].has_bin);
	/* prefix rejected, QR still answers its record */
	{
		uint8_t in[300], rec[GL_REC_MAX_BYTES];
		size_t n = 0;

		in[n++] = '?';
		make_record(rec);
		memcpy(in + n, rec, 190);
		n += 190;
		in[n++] = ':';
		run_all(in, n, (const struct expect[]){{2, 190}}, 1, &g);
		assert_int_equal(g.n, 1);
		assert_int_equal(g.r[0].first_err, 0);
		assert_true(g.r[0].has_bin);
	}
}

/* Set the high bit of every byte of @s into @out; return the length. */
static size_t high(const char *s, uint8_t *out)
{
	size_t i;

	for (i = 0; s[i]; i++)
		out[i] = (uint8_t)(s[i] | 0x80);
	return i;
}

/* TEST_proto_unsol_in_text: high-bit bytes inside a reply are split out. */
static void test_proto_unsol_in_text(void **state)
{
	const struct expect e[] = {{2, 0}, {1, 0}};
	uint8_t in[256];
	size_t n = 0;

	(void)state;
	memcpy(in + n, ": 5.", 4);
	n += 4;
	n += high("FAULT 4 2 5012\r\n", in + n);
	memcpy(in + n, "0000\r", 5);
	n += 5;
	n += high("BOO", in + n);
	memcpy(in + n, "\n:", 2);
	n += 2;
	n += high("T 1.0\r\n", in + n); /* between replies */
	memcpy(in + n, ":", 1);
	n += 1;
	n += high("ARMED\r\nPART", in + n); /* incomplete line stays */
	run_all(in, n, e, 2, &g);
	assert_int_equal(g.rc, GL_ERR_AGAIN);
	assert_int_equal(g.n, 2);
	assert_string_equal(g.r[0].text, " 5.0000");
	assert_string_equal(g.r[1].text, "");
	assert_int_equal(g.n_unsol, 3);
	assert_string_equal(g.unsol[0], "FAULT 4 2 5012");
	assert_string_equal(g.unsol[1], "BOOT 1.0");
	assert_string_equal(g.unsol[2], "ARMED");
}

/* TEST_proto_unsol_around_record: before the record and before its ':'. */
static void test_proto_unsol_around_record(void **state)
{
	const struct expect e[] = {{2, 190}};
	uint8_t in[512], rec[GL_REC_MAX_BYTES];
	size_t n = 0;

	(void)state;
	make_record(rec);
	in[n++] = ':';
	n += high("MSG A\r\n", in + n); /* between prefix ':' and record */
	memcpy(in + n, rec, 190);
	n += 190;
	n += high("MSG B\r\n", in + n); /* between record and ':' */
	in[n++] = ':';
	run_all(in, n, e, 1, &g);
	assert_int_equal(g.rc, GL_ERR_AGAIN);
	assert_int_equal(g.n, 1);
	assert_true(g.r[0].has_bin);
	assert_memory_equal(g.r[0].bin, rec, 190);
	assert_int_equal(g.n_unsol, 2);
	assert_string_equal(g.unsol[0], "MSG A");
	assert_string_equal(g.unsol[1], "MSG B");
}

/* TEST_proto_unsol_inside_record: misaligned record -> GL_ERR_PROTO. */
static void test_proto_unsol_inside_record(void **state)
{
	const struct expect e[] = {{1, 190}};
	uint8_t in[512], rec[GL_REC_MAX_BYTES];
	size_t n = 0;

	(void)state;
	make_record(rec);
	memcpy(in, rec, 100);
	n = 100;
	n += high("MSG\r\n", in + n);
	memcpy(in + n, rec + 100, 90);
	n += 90;
	in[n++] = ':';
	run_all(in, n, e, 1, &g);
	assert_int_equal(g.rc, GL_ERR_PROTO);
	assert_int_equal(g.n, 0);
}

/* TEST_proto_unsol_idle: with no reply awaited high bytes are queued. */
static void test_proto_unsol_idle(void **state)
{
	uint8_t in[64];
	size_t n;

	(void)state;
	n = high("STATE 1\r\nSTATE 2\r\n", in);
	run_all(in, n, NULL, 0, &g);
	assert_int_equal(g.rc, GL_ERR_AGAIN);
	assert_int_equal(g.n, 0);
	assert_int_equal(g.n_unsol, 2);
	assert_string_equal(g.unsol[0], "STATE 1");
	assert_string_equal(g.unsol[1], "STATE 2");
}

/* TEST_proto_malformed: each framing violation gives GL_ERR_PROTO. */
static void test_proto_malformed(void **state)
{
	const struct expect one[] = {{1, 0}};
	const struct expect qr[] = {{1, 190}};
	uint8_t in[300], rec[GL_REC_MAX_BYTES];

	(void)state;
	run_all(S(":"), one, 0, &g); /* late reply: nothing awaited */
	assert_int_equal(g.rc, GL_ERR_PROTO);
	run_all(S(": 5.0000\r\n:"), one, 1, &g); /* one reply too many */
	assert_int_equal(g.rc, GL_ERR_PROTO);
	assert_int_equal(g.n, 1);
	run_all(S(" 5\x01\r\n:"), one, 1, &g); /* control byte */
	assert_int_equal(g.rc, GL_ERR_PROTO);
	run_all(S("\x00:"), one, 1, &g); /* NUL */
	assert_int_equal(g.rc, GL_ERR_PROTO);
	run_all(S("\x1a:"), one, 1, &g); /* ^Z outside UL */
	assert_int_equal(g.rc, GL_ERR_PROTO);
	run_all(S(":"), qr, 1, &g); /* QR answered ':' only */
	assert_int_equal(g.rc, GL_ERR_PROTO);
	run_all(S("A"), qr, 1, &g); /* record must start 0x80..0x87 */
	assert_int_equal(g.rc, GL_ERR_PROTO);
	make_record(rec);
	memcpy(in, rec, 190);
	in[190] = 'x'; /* no ':' after the record */
	run_all(in, 191, qr, 1, &g);
	assert_int_equal(g.rc, GL_ERR_PROTO);
	in[2] = 189; /* length field disagrees */
	in[190] = ':';
	run_all(in, 191, qr, 1, &g);
	assert_int_equal(g.rc, GL_ERR_PROTO);
	assert_int_equal(g.n, 0);
}

/* TEST_proto_record_length_field: a record's body is taken in one copy
 * yet a length field that disagrees stops the parser right
 * after it, as byte by byte: the rest of the input is not consumed. */
static void test_proto_record_length_field(void **state)
{
	struct gl_proto *p = test_malloc(sizeof(*p));
	uint8_t in[300];
	struct gl_reply r;

	(void)state;
	in[0] = ':';
	make_record(in + 1);
	in[3] = 189;
	in[191] = ':';
	gl_proto_init(p);
	assert_int_equal(gl_proto_expect(p, 2, 190), GL_OK);
	assert_int_equal(gl_proto_feed(p, in, 192), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_ERR_PROTO);
	assert_int_equal(gl_proto_space(p), GL_PROTO_IN_MAX - (192 - 5));
	/* agreeing: the whole record, the ':' after it, nothing left */
	in[3] = 190;
	gl_proto_reset(p);
	assert_int_equal(gl_proto_expect(p, 2, 190), GL_OK);
	assert_int_equal(gl_proto_feed(p, in, 192), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_OK);
	assert_int_equal(r.bin_len, 190);
	assert_memory_equal(r.bin, in + 1, 190);
	assert_int_equal(gl_proto_space(p), GL_PROTO_IN_MAX);
	test_free(p);
}

/* TEST_proto_error_sticky: after GL_ERR_PROTO only reset helps. */
static void test_proto_error_sticky(void **state)
{
	struct gl_proto *p = test_malloc(sizeof(*p));
	struct gl_reply r;

	(void)state;
	gl_proto_init(p);
	assert_int_equal(gl_proto_expect(p, 1, 0), GL_OK);
	assert_int_equal(gl_proto_feed(p, "\x02:", 2), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_ERR_PROTO);
	assert_int_equal(gl_proto_feed(p, ":", 1), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_ERR_PROTO);
	gl_proto_reset(p);
	assert_int_equal(gl_proto_awaiting(p), 0);
	assert_int_equal(gl_proto_expect(p, 1, 0), GL_OK);
	assert_int_equal(gl_proto_feed(p, " 1\r\n:", 5), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_OK);
	assert_string_equal(r.text, " 1");
	test_free(p);
}

/* TEST_proto_upload: text up to ^Z then ':'; ':' and '?' are program text. */
static void test_proto_upload(void **state)
{
	static const char in[] = "#AUTO\r\nMG \"ok?\"\r\n:x\r\nEN\r\n\x1a:";
	struct gl_proto *p = test_malloc(sizeof(*p));
	struct gl_reply r;
	char buf[64], small[8];
	size_t i;

	(void)state;
	gl_proto_init(p);
	assert_int_equal(gl_proto_expect_upload(p, buf, sizeof(buf)), GL_OK);
	for (i = 0; i + 1 < sizeof(in); i++) {
		uint8_t b = (uint8_t)in[i];
		int rc;

		assert_int_equal(gl_proto_feed(p, &b, 1), GL_OK);
		rc = gl_proto_next(p, &r);
		assert_int_equal(rc,
				 i + 2 == sizeof(in) ? GL_OK : GL_ERR_AGAIN);
	}
	assert_ptr_equal(r.text, buf);
	assert_string_equal(buf, "#AUTO\r\nMG \"ok?\"\r\n:x\r\nEN\r\n");
	assert_false(r.truncated);
	/* too long for the buffer: cut, flagged, stream stays in step */
	assert_int_equal(gl_proto_expect_upload(p, small, sizeof(small)),
			 GL_OK);
	assert_int_equal(gl_proto_expect(p, 1, 0), GL_OK);
	assert_int_equal(gl_proto_feed(p, in, sizeof(in) - 1), GL_OK);
	assert_int_equal(gl_proto_feed(p, " 3\r\n:", 5), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_OK);
	assert_true(r.truncated);
	assert_string_equal(small, "#AUTO\r\n");
	assert_int_equal(gl_proto_next(p, &r), GL_OK);
	assert_string_equal(r.text, " 3");
	/* rejected UL */
	assert_int_equal(gl_proto_expect_upload(p, buf, sizeof(buf)), GL_OK);
	assert_int_equal(gl_proto_feed(p, "?", 1), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_OK);
	assert_int_equal(r.n_err, 1);
	/* control byte in program text */
	assert_int_equal(gl_proto_expect_upload(p, buf, sizeof(buf)), GL_OK);
	assert_int_equal(gl_proto_feed(p, "EN\x07\x1a:", 5), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_ERR_PROTO);
	test_free(p);
}

/* TEST_proto_text_truncated: longer data is cut but the reply completes. */
static void test_proto_text_truncated(void **state)
{
	static char in[GL_PROTO_TEXT_MAX + 100];
	const struct expect e[] = {{1, 0}, {1, 0}};
	size_t n = GL_PROTO_TEXT_MAX + 50;

	(void)state;
	memset(in, 'a', n);
	memcpy(in + n, "\r\n: 2\r\n:", 9);
	run_all(in, n + 9, e, 2, &g);
	assert_int_equal(g.n, 2);
	assert_true(g.r[0].truncated);
	assert_int_equal(g.r[0].text_len, GL_PROTO_TEXT_MAX - 1);
	assert_string_equal(g.r[1].text, " 2");
	assert_false(g.r[1].truncated);
}

/* TEST_proto_unsol_queue: cap overflow, long-line split, full queue. */
static void test_proto_unsol_queue(void **state)
{
	struct gl_proto *p = test_malloc(sizeof(*p));
	struct gl_reply r;
	uint8_t in[GL_PROTO_IN_MAX];
	char line[GL_PROTO_UNSOL_LINE + 1];
	size_t i;

	(void)state;
	gl_proto_init(p);
	gl_proto_set_all_unsol(p, true); /* message handle: plain bytes too */
	assert_int_equal(gl_proto_feed(p, "HELLO WORLD\r\n", 13), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_ERR_AGAIN);
	assert_int_equal(gl_proto_unsol_next(p, line, 6), GL_ERR_OVERFLOW);
	assert_string_equal(line, "HELLO");
	assert_int_equal(gl_proto_unsol_next(p, line, sizeof(line)),
			 GL_ERR_AGAIN);
	/* a 300-character line is split at GL_PROTO_UNSOL_LINE - 1 */
	memset(in, 0x80 | 'z', 300);
	in[300] = 0x8D;
	in[301] = 0x8A;
	assert_int_equal(gl_proto_feed(p, in, 302), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_ERR_AGAIN);
	assert_int_equal(gl_proto_unsol_next(p, line, sizeof(line)),
			 GL_PROTO_UNSOL_LINE - 1);
	assert_int_equal(gl_proto_unsol_next(p, line, sizeof(line)),
			 300 - (GL_PROTO_UNSOL_LINE - 1));
	/* overfill the queue: losses are counted, nothing overwritten */
	for (i = 0; i < GL_PROTO_IN_MAX; i++)
		in[i] = (uint8_t)(i % 10 == 9 ? '\n' : 'k');
	assert_int_equal(gl_proto_feed(p, in, sizeof(in)), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_ERR_AGAIN);
	assert_int_equal(p->unsol_dropped,
			 GL_PROTO_IN_MAX - GL_PROTO_UNSOL_MAX);
	for (i = 0; i < GL_PROTO_UNSOL_MAX / 10; i++)
		assert_int_equal(gl_proto_unsol_next(p, line, sizeof(line)), 9);
	test_free(p);
}

/* TEST_proto_api_limits: argument checks and buffer limits. */
static void test_proto_api_limits(void **state)
{
	struct gl_proto *p = test_malloc(sizeof(*p));
	static uint8_t big[GL_PROTO_IN_MAX + 1];
	struct gl_reply r;
	int i, n_err = -1;

	(void)state;
	gl_proto_init(p);
	assert_int_equal(gl_proto_expect(p, 0, 0), GL_ERR_ARG);
	assert_int_equal(gl_proto_expect(p, GL_PROTO_CMDS_MAX + 1, 0),
			 GL_ERR_ARG);
	assert_int_equal(gl_proto_expect(p, 1, 3), GL_ERR_ARG);
	assert_int_equal(gl_proto_expect(p, 1, GL_REC_MAX_BYTES + 1),
			 GL_ERR_ARG);
	assert_int_equal(gl_proto_expect_upload(p, NULL, 4), GL_ERR_ARG);
	for (i = 0; i < GL_PROTO_EXPECT_MAX; i++)
		assert_int_equal(gl_proto_expect(p, 2, 0), GL_OK);
	assert_int_equal(gl_proto_expect(p, 1, 0), GL_ERR_OVERFLOW);
	assert_int_equal(gl_proto_awaiting(p), GL_PROTO_EXPECT_MAX);
	assert_int_equal(gl_proto_feed(p, big, sizeof(big)), GL_ERR_OVERFLOW);
	assert_int_equal(gl_proto_space(p), GL_PROTO_IN_MAX);
	/* progress sees the early '?' of a reply still in progress */
	assert_int_equal(gl_proto_feed(p, "?", 1), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_ERR_AGAIN);
	assert_int_equal(gl_proto_progress(p, &n_err), 1);
	assert_int_equal(n_err, 1);
	assert_int_equal(gl_proto_feed(p, ":", 1), GL_OK);
	assert_int_equal(gl_proto_next(p, &r), GL_OK);
	assert_int_equal(gl_proto_progress(p, &n_err), 0);
	assert_int_equal(gl_proto_awaiting(p), GL_PROTO_EXPECT_MAX);
	assert_int_equal(gl_proto_next(p, &r), GL_ERR_AGAIN);
	assert_int_equal(gl_proto_awaiting(p), GL_PROTO_EXPECT_MAX - 1);
	test_free(p);
}

static void expect_num(const char *s, size_t len, double v, size_t used)
{
	const char *ep = NULL;
	double out = -999;

	assert_true(gl_parse_double(s, len, &ep, &out));
	assert_true(out == v);
	assert_ptr_equal(ep, s + used);
}

static void expect_bad(const char *s, size_t len, int err)
{
	double out = -999;

	errno = 0;
	assert_false(gl_parse_double(s, len, NULL, &out));
	assert_int_equal(errno, err);
	assert_true(out == -999);
}

/* TEST_proto_parse_double: Galil number replies from (buffer, length). */
static void test_proto_parse_double(void **state)
{
	(void)state;
	expect_num(" 1.0000", 7, 1.0, 7);
	expect_num("-12.5000\r\n", 10, -12.5, 8);
	expect_num(".5", 2, 0.5, 2);
	expect_num("+7", 2, 7, 2);
	expect_num("2147483647.9999", 15, 2147483647.9999, 15);
	expect_num("12345", 3, 123, 3); /* not NUL-terminated */
	expect_num("1e5", 3, 1, 1);	/* no exponent */
	expect_num("3, 52", 5, 3, 1);
	expect_bad("", 0, EINVAL);
	expect_bad("   ", 3, EINVAL);
	expect_bad("-", 1, EINVAL);
	expect_bad(".", 1, EINVAL);
	expect_bad("abc", 3, EINVAL);
	expect_bad("inf", 3, EINVAL);
	expect_num("0x10", 4, 0, 1); /* no hex: "0", then 'x' */
	expect_bad("11111111111111111111111111111111111111111", 41, ERANGE);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_proto_colon),
	    cmocka_unit_test(test_proto_data),
	    cmocka_unit_test(test_proto_qmark),
	    cmocka_unit_test(test_proto_multi_command),
	    cmocka_unit_test(test_proto_several_replies),
	    cmocka_unit_test(test_proto_record),
	    cmocka_unit_test(test_proto_record_rejected),
	    cmocka_unit_test(test_proto_unsol_in_text),
	    cmocka_unit_test(test_proto_unsol_around_record),
	    cmocka_unit_test(test_proto_unsol_inside_record),
	    cmocka_unit_test(test_proto_unsol_idle),
	    cmocka_unit_test(test_proto_malformed),
	    cmocka_unit_test(test_proto_record_length_field),
	    cmocka_unit_test(test_proto_error_sticky),
	    cmocka_unit_test(test_proto_upload),
	    cmocka_unit_test(test_proto_text_truncated),
	    cmocka_unit_test(test_proto_unsol_queue),
	    cmocka_unit_test(test_proto_api_limits),
	    cmocka_unit_test(test_proto_parse_double),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
