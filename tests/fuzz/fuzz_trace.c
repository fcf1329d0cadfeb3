/*
 * fuzz_trace.c - libFuzzer target: the flight recorder's trace reader
 * (re_trace_parse(), the buffer entry point of roboelf-tech show-trace).
 *
 * Input: the trace text. It is parsed as given, and again with the CRC of
 * its end line recomputed (a line "# end N records crc32 " + 8 hex digits
 * gets the CRC of every byte before it) so the fuzzer can reach a complete
 * parse. A trace that parses is written again with re_trace_write(): the
 * text must parse back to the same number of records.
 */
#include <stdio.h>
#include <stdint.h>
#include <stddef.h>
#include <string.h>
#include <stdlib.h>
#include "gl_err.h"
#include "re_trace.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* CRC-32 as in docs/trace-format.md (zlib, reflected 0xEDB88320). */
static uint32_t crc32_of(const char *buf, size_t len)
{
	uint32_t crc = 0xffffffffu;
	size_t i;
	int k;

	for (i = 0; i < len; i++) {
		crc ^= (uint8_t)buf[i];
		for (k = 0; k < 8; k++)
			crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
	}
	return ~crc;
}

static void rewrite(const struct re_trace_hdr *h,
		    const struct re_trace_rec *recs)
{
	static const struct re_trace_rec none;
	struct re_trace_hdr h2;
	struct re_trace_rec *r2 = NULL;
	size_t cap = re_trace_max_bytes(h->n_records, h->n_axes), len;
	char err[256], *buf;

	if (cap == 0)
		abort(); /* a parsed header is in range */
	buf = malloc(cap);
	if (!buf)
		return;
	if (re_trace_write(h, h->n_records ? recs : &none,
			   h->n_records ? h->n_records : 1, 0, h->n_records,
			   buf, cap, &len) != GL_OK)
		abort(); /* what was read must be writable */
	if (re_trace_parse(buf, len, &h2, &r2, err, sizeof(err)) != GL_OK ||
	    h2.n_records != h->n_records || h2.n_axes != h->n_axes)
		abort(); /* and read back */
	free(r2);
	free(buf);
}

static void parse(const char *buf, size_t len)
{
	struct re_trace_hdr h;
	struct re_trace_rec *recs = NULL;
	char err[256];

	if (re_trace_parse(buf, len, &h, &recs, err, sizeof(err)) == GL_OK)
		rewrite(&h, recs);
	free(recs);
}

/* Offset of the 8 hex digits of the end line's crc32, or 0. */
static size_t crc_field(const char *buf, size_t len)
{
	size_t i, start = 0;

	for (i = 0; i + 1 < len; i++) /* start of the last non-empty line */
		if (buf[i] == '\n')
			start = i + 1;
	if (len - start < 6 + 15 || memcmp(buf + start, "# end ", 6) != 0)
		return 0;
	for (i = start; i + 15 <= len; i++)
		if (memcmp(buf + i, " crc32 ", 7) == 0)
			return i + 7;
	return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	const char *buf = (const char *)data;
	size_t at, start;
	char *copy, hex[9];

	parse(buf, size);
	at = crc_field(buf, size);
	if (at == 0)
		return 0;
	for (start = at; start > 0 && buf[start - 1] != '\n';)
		start--;
	copy = malloc(size);
	if (!copy)
		return 0;
	memcpy(copy, buf, size);
	snprintf(hex, sizeof(hex), "%08x", (unsigned)crc32_of(copy, start));
	memcpy(copy + at, hex, 8);
	parse(copy, size);
	free(copy);
	return 0;
}
