/*
 * fuzz_record.c - libFuzzer target: the QR/DR data record decoder and the
 * QZ layout reader (gl_record.h).
 *
 * Input: [0] layout (0..3, GL_LAYOUT_NONE included), [1] axis count
 * (0..15, so invalid counts are tried too), then the record bytes. The
 * same bytes after [1] are also given to gl_record_layout_from_qz() as QZ
 * text. A record that decodes is encoded again: decode(encode(r)) must
 * encode to the same bytes (the encoder and decoder agree).
 */
#include <stdint.h>
#include <stddef.h>
#include <string.h>
#include <stdlib.h>
#include "gl_err.h"
#include "gl_record.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void round_trip(const struct gl_record *r1)
{
	static uint8_t b2[GL_REC_MAX_BYTES], b3[GL_REC_MAX_BYTES];
	struct gl_record r2;
	int n2, n3;

	n2 = gl_record_encode(r1, b2, sizeof(b2));
	if (n2 <= 0)
		abort(); /* a decoded record must encode */
	if (gl_record_decode(b2, (size_t)n2, r1->layout, r1->n_axes, &r2))
		abort(); /* what the encoder writes must decode */
	n3 = gl_record_encode(&r2, b3, sizeof(b3));
	if (n3 != n2 || memcmp(b2, b3, (size_t)n2) != 0)
		abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct gl_record rec;
	enum gl_rec_layout layout, qz_layout;
	int n_axes, qz_axes;

	if (size < 2)
		return 0;
	layout = (enum gl_rec_layout)(data[0] & 3);
	n_axes = data[1] & 15;
	(void)gl_record_layout_from_qz((const char *)data + 2, size - 2,
				       &qz_layout, &qz_axes);
	memset(&rec, 0, sizeof(rec));
	if (gl_record_decode(data + 2, size - 2, layout, n_axes, &rec) ==
	    GL_OK) {
		if (rec.layout != layout || rec.n_axes != n_axes ||
		    gl_record_size(layout, n_axes) != size - 2)
			abort();
		round_trip(&rec);
	}
	return 0;
}
