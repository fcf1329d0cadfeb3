/*
 * fuzz_calfile.c - libFuzzer target: the calibration-file reader
 * (re_calfile_parse(), the buffer entry point of re_calfile_load()).
 *
 * Input: the file text. It is parsed as given, and again with its last
 * line's CRC recomputed (a last line "crc32 " + 8 hex digits gets the
 * right value) so that the fuzzer gets past the checksum into the tables.
 * Each text is read without expectations (roboelf-tech show-calibration) and
 * against a fixed expectation (controller "DMC4030-1234", axes A B C, the
 * config hash of docs/calibration-file.md). A file that parses without
 * expectations is formatted again: the text must parse back.
 */
#include <stdio.h>
#include <stdint.h>
#include <stddef.h>
#include <string.h>
#include <stdlib.h>
#include "gl_err.h"
#include "re_calfile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static struct re_calset set, set2;
static struct re_calfile_expect exp_abc;

/* CRC-32 as in docs/calibration-file.md (zlib, reflected 0xEDB88320). */
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

static void init_expect(void)
{
	int a;

	exp_abc.serial = "DMC4030-1234";
	exp_abc.n_axes = 3;
	exp_abc.config_hash = 0x5bd1e9955bd1e995ull;
	for (a = 0; a < 3; a++) {
		exp_abc.name[a][0] = (char)('A' + a);
		exp_abc.step_counts[a] = 500;
		exp_abc.check[a].noise_margin_v = 0.001;
		exp_abc.check[a].expected_range_v = 4;
		exp_abc.check[a].range_tol = 0.1;
		exp_abc.check[a].min_points = 2;
		exp_abc.check[a].max_points = RE_CAL_MAX_POINTS;
		exp_abc.check[a].step_tol_counts = 1;
	}
}

/* Parse @buf both ways; re-format what parses without expectations. */
static void parse_both(const char *buf, size_t len)
{
	char err[512], *text;
	size_t cap;
	int n;

	if (re_calfile_parse(buf, len, "fuzz.cal", &exp_abc, &set, err,
			     sizeof(err)) == GL_OK &&
	    re_calfile_parse(buf, len, "fuzz.cal", NULL, &set2, err,
			     sizeof(err)) != GL_OK)
		abort(); /* matching can only add refusals */
	if (re_calfile_parse(buf, len, "fuzz.cal", NULL, &set, err,
			     sizeof(err)) != GL_OK)
		return;
	cap = re_calfile_format_size(&set);
	text = malloc(cap);
	if (!text)
		return;
	n = re_calfile_format(&set, text, cap);
	if (n <= 0)
		abort(); /* what was read must be writable */
	if (re_calfile_parse(text, (size_t)n, "fuzz.cal", NULL, &set2, err,
			     sizeof(err)) != GL_OK)
		abort(); /* and read back */
	free(text);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	const char *buf = (const char *)data;
	char *copy, hex[9];
	size_t start;

	if (exp_abc.n_axes == 0)
		init_expect();
	parse_both(buf, size);
	/* the same text with the right CRC on a "crc32 xxxxxxxx" last line */
	if (size < 15 || buf[size - 1] != '\n' ||
	    memcmp(buf + size - 15, "crc32 ", 6) != 0 ||
	    (size > 15 && buf[size - 16] != '\n'))
		return 0;
	start = size - 15;
	copy = malloc(size);
	if (!copy)
		return 0;
	memcpy(copy, buf, size);
	snprintf(hex, sizeof(hex), "%08x", (unsigned)crc32_of(copy, start));
	memcpy(copy + start + 6, hex, 8);
	parse_both(copy, size);
	free(copy);
	return 0;
}
