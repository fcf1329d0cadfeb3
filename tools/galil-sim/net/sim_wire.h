/*
 * sim_wire.h - what the line faults of the command port (enum
 * sim_line_kind, sim.h) do to the bytes: a command line corrupted on its
 * way to the controller, and a reply reshaped on its way back (delayed,
 * split, replaced, with an unsolicited line or a terminator added, a
 * record header changed).
 *
 * Pure: buffers in, buffers and a send schedule out. It is not the
 * connection (sim_cmdport.h decides which line a fault meets, feeds the
 * controller and queues the pieces) and it does not parse the Galil
 * language beyond finding the first command and a final QR record.
 * Nothing here prints, allocates or keeps state (the pseudo-random
 * generator's state is the caller's).
 */
#ifndef SIM_WIRE_H
#define SIM_WIRE_H

#include <stddef.h>
#include <stdint.h>

#include "sim.h"

/* SIM_LINE_GARBAGE: the reply sent instead (control bytes, a NUL, ':'). */
#define SIM_WIRE_GARBAGE     "\x01\x02garbage\x00\x1f:"
#define SIM_WIRE_GARBAGE_LEN (sizeof(SIM_WIRE_GARBAGE) - 1)
/* SIM_LINE_UNSOL, SIM_LINE_UNSOLPRE: the text inserted, followed by CR LF,
 * every byte with its high bit set (an unsolicited message). */
#define SIM_WIRE_UNSOL_TEXT "UNSOLICITED 42"
/* SIM_LINE_QMARK: the command put in place of the line's first one. */
#define SIM_WIRE_QMARK_CMD "ZZ"
/* Bytes a reshaped reply may grow by (the unsolicited line, a ':'). */
#define SIM_WIRE_GROWTH 32

/* One piece of a reshaped reply: it ends at @end and goes @delay_us late. */
struct sim_wire_piece {
	size_t end;	  /* offset in the output where the piece ends */
	int64_t delay_us; /* after the reply was ready, microseconds */
};

/*
 * sim_wire_qmark() - @line (@len bytes, its terminator excluded) with the
 * first command (up to the first ';' outside double quotes) replaced by
 * SIM_WIRE_QMARK_CMD, which the controller rejects with '?' and TC 1.
 * @out: [out] the new line (@cap bytes; not NUL-terminated).
 * Return: the new length, or 0 when it does not fit in @cap.
 */
size_t sim_wire_qmark(const char *line, size_t len, char *out, size_t cap);

/*
 * sim_wire_record_at() - where the binary QR record that ends @reply (a
 * record followed by the final ':') starts: the offset whose header (high
 * bit in byte 0, length in bytes 2..3, little-endian) spans exactly to
 * the final ':'.
 * Return: the offset, or -1 when the reply does not end with a record.
 */
long sim_wire_record_at(const uint8_t *reply, size_t len);

/*
 * sim_wire_shape() - the reply @in (@len bytes) of a line that met fault
 * @f, as it is to be sent: into @out (@cap >= @len + SIM_WIRE_GROWTH
 * bytes) and @piece (at most @npiece pieces, in order, delays not
 * decreasing; a reply with more bytes than pieces for SIM_LINE_SPLIT or
 * SIM_LINE_CHUNKS has its tail in the last piece). Faults that act on the
 * input (QMARK, DROP, SILENT, DLREJECT) leave the reply as it is, one
 * piece, no delay.
 * @rng: [in,out] the state of the pseudo-random sizes of SIM_LINE_CHUNKS.
 * Return: the number of pieces (>= 1; the output length is the last
 *         piece's end), or 0 when @cap or @npiece is too small.
 */
int sim_wire_shape(const struct sim_line_fault *f, const uint8_t *in,
		   size_t len, uint8_t *out, size_t cap,
		   struct sim_wire_piece *piece, int npiece, uint32_t *rng);

#endif /* SIM_WIRE_H */
