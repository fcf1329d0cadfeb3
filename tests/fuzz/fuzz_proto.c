/*
 * fuzz_proto.c - libFuzzer target: the Galil reply parser (gl_proto.h).
 *
 * Input: a 6-byte header, then the bytes "received".
 *   [0] bit 7: message handle (every byte unsolicited); bits 0-1: number of
 *       replies awaited - 1
 *   [1..4] one byte per awaited reply: bits 0-2 terminators - 1; bit 6: the
 *       last command is QR (record length from bits 3-5, a size the record
 *       decoder knows); bit 7: an UL reply (caller buffer of bits 0-5 + 1
 *       bytes)
 *   [5] chunk size - 1 for feeding (0 = one byte at a time)
 * Every reply taken is checked (text NUL-terminated within its buffer), a
 * record of the right size is also decoded, numbers in the text go through
 * gl_parse_double(), and the unsolicited queue is drained.
 */
#include <stdint.h>
#include <stddef.h>
#include <string.h>
#include <stdlib.h>
#include "gl_err.h"
#include "gl_proto.h"
#include "gl_record.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define HDR 6

/* Record sizes the parser may be told to expect: layout, axes. */
static const struct {
	enum gl_rec_layout layout;
	int n_axes;
} rec_kinds[8] = {
    {GL_LAYOUT_4000, 1},  {GL_LAYOUT_4000, 3}, {GL_LAYOUT_4000, 8},
    {GL_LAYOUT_30000, 1}, {GL_LAYOUT_2103, 1}, {GL_LAYOUT_2103, 3},
    {GL_LAYOUT_2103, 8},  {GL_LAYOUT_4000, 4},
};

static char ubuf[4][65];

static void take_reply(const struct gl_reply *r, int kind)
{
	struct gl_record rec;
	const char *ep;
	double v;

	if (r->text_len && r->text[r->text_len] != '\0')
		abort();
	if (r->text_len)
		(void)gl_parse_double(r->text, r->text_len, &ep, &v);
	if (r->bin && kind >= 0)
		(void)gl_record_decode(r->bin, r->bin_len,
				       rec_kinds[kind].layout,
				       rec_kinds[kind].n_axes, &rec);
}

static void drain_unsol(struct gl_proto *p)
{
	char line[GL_PROTO_UNSOL_LINE + 1];
	int n;

	while ((n = gl_proto_unsol_next(p, line, sizeof(line))) !=
	       GL_ERR_AGAIN) {
		if (n >= 0 && line[n] != '\0')
			abort();
	}
}

static int expect_all(struct gl_proto *p, const uint8_t *data, int *kinds)
{
	int i, n = (data[0] & 3) + 1;

	for (i = 0; i < n; i++) {
		uint8_t b = data[1 + i];

		kinds[i] = -1;
		if (b & 0x80) {
			if (gl_proto_expect_upload(p, ubuf[i],
						   (size_t)(b & 0x3f) + 1))
				return -1;
		} else if (b & 0x40) {
			kinds[i] = (b >> 3) & 7;
			if (gl_proto_expect(
				p, (b & 7) + 1,
				gl_record_size(rec_kinds[kinds[i]].layout,
					       rec_kinds[kinds[i]].n_axes)))
				return -1;
		} else if (gl_proto_expect(p, (b & 7) + 1, 0)) {
			return -1;
		}
	}
	return n;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct gl_proto p;
	struct gl_reply r;
	int kinds[4], n_exp, taken = 0, rc = GL_ERR_AGAIN;
	size_t pos = HDR, chunk;

	if (size < HDR)
		return 0;
	gl_proto_init(&p);
	gl_proto_set_all_unsol(&p, (data[0] & 0x80) != 0);
	n_exp = expect_all(&p, data, kinds);
	if (n_exp < 0)
		abort(); /* valid arguments must be accepted */
	chunk = (size_t)data[5] + 1;
	while (pos < size && rc != GL_ERR_PROTO) {
		size_t n = size - pos < chunk ? size - pos : chunk;

		if (n > gl_proto_space(&p))
			n = gl_proto_space(&p);
		if (n == 0 || gl_proto_feed(&p, data + pos, n) != GL_OK)
			break;
		pos += n;
		while ((rc = gl_proto_next(&p, &r)) == GL_OK) {
			take_reply(&r, taken < n_exp ? kinds[taken] : -1);
			taken++;
		}
		drain_unsol(&p);
	}
	if (taken > n_exp || gl_proto_awaiting(&p) != n_exp - taken)
		abort(); /* more replies than announced */
	return 0;
}
