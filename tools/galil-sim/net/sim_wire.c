/*
 * sim_wire.c - the line faults' effect on the bytes (see sim_wire.h).
 * Not the connection and not the controller.
 */
#include <string.h>

#include "sim.h"
#include "sim_wire.h"

#define SPLIT_GAP_US 1000 /* SIM_LINE_SPLIT: between bytes */

size_t sim_wire_qmark(const char *line, size_t len, char *out, size_t cap)
{
	size_t first = 0, n = sizeof(SIM_WIRE_QMARK_CMD) - 1;
	int quoted = 0;

	for (; first < len && (quoted || line[first] != ';'); first++)
		quoted ^= line[first] == '"';
	if (n + len - first > cap)
		return 0;
	memcpy(out, SIM_WIRE_QMARK_CMD, n);
	memcpy(out + n, line + first, len - first);
	return n + len - first;
}

long sim_wire_record_at(const uint8_t *reply, size_t len)
{
	if (len < 5 || reply[len - 1] != ':')
		return -1;
	for (size_t s = 0; s + 4 < len; s++) {
		size_t rlen = (size_t)reply[s + 2] | (size_t)reply[s + 3] << 8;

		if ((reply[s] & 0x80) && rlen >= 4 && s + rlen + 1 == len)
			return (long)s;
	}
	return -1;
}

static uint32_t rnd(uint32_t *state)
{
	*state = *state * 1103515245u + 12345u;
	return (*state >> 16) & 0x7fff;
}

/* Insert the unsolicited line at @at of @out (length @len). */
static size_t insert_unsol(uint8_t *out, size_t len, size_t at)
{
	static const char text[] = SIM_WIRE_UNSOL_TEXT "\r\n";
	size_t n = sizeof(text) - 1;

	memmove(out + at + n, out + at, len - at);
	for (size_t i = 0; i < n; i++)
		out[at + i] = (uint8_t)text[i] | 0x80;
	return len + n;
}

/* SPLIT and CHUNKS: pieces of 1 byte 1 ms apart, or 1..8 bytes 0..2 ms. */
static int cut(const struct sim_line_fault *f, size_t len,
	       struct sim_wire_piece *piece, int npiece, uint32_t *rng)
{
	int64_t t = 0;
	size_t off = 0, n;
	int k = 0;

	while (off < len && k < npiece) {
		n = f->kind == SIM_LINE_SPLIT ? 1 : 1 + rnd(rng) % 8;
		if (n > len - off || k == npiece - 1)
			n = len - off;
		off += n;
		piece[k++] = (struct sim_wire_piece){off, t};
		t += f->kind == SIM_LINE_SPLIT ? SPLIT_GAP_US
					       : (int64_t)(rnd(rng) % 3) * 1000;
	}
	return k;
}

int sim_wire_shape(const struct sim_line_fault *f, const uint8_t *in,
		   size_t len, uint8_t *out, size_t cap,
		   struct sim_wire_piece *piece, int npiece, uint32_t *rng)
{
	long rec;

	if (cap < len + SIM_WIRE_GROWTH || npiece < 2)
		return 0;
	memcpy(out, in, len);
	piece[0] = (struct sim_wire_piece){len, 0};
	switch (f->kind) {
	case SIM_LINE_DELAY: piece[0].delay_us = (int64_t)f->arg * 1000; break;
	case SIM_LINE_SPLIT:
	case SIM_LINE_CHUNKS: return len ? cut(f, len, piece, npiece, rng) : 1;
	case SIM_LINE_GARBAGE:
		memcpy(out, SIM_WIRE_GARBAGE, SIM_WIRE_GARBAGE_LEN);
		piece[0].end = SIM_WIRE_GARBAGE_LEN;
		break;
	case SIM_LINE_UNSOL:
		piece[0].end = insert_unsol(out, len, len / 2);
		break;
	case SIM_LINE_UNSOLPRE:
		rec = sim_wire_record_at(in, len);
		piece[0].end =
		    insert_unsol(out, len, rec < 0 ? 0 : (size_t)rec);
		break;
	case SIM_LINE_EXTRA:
		out[len] = ':';
		if (f->arg == 0) {
			piece[0].end = len + 1;
			break;
		}
		piece[1] =
		    (struct sim_wire_piece){len + 1, (int64_t)f->arg * 1000};
		return 2;
	case SIM_LINE_BADHDR:
		rec = sim_wire_record_at(in, len);
		if (rec >= 0)
			out[rec + 1] = 0x0F; /* axes A..D present */
		break;
	default: break;
	}
	return 1;
}
