/*
 * gl_proto.h - the pure Galil reply parser: bytes in, replies out.
 *
 * The hiredis shape: the caller says what the next reply looks like
 * (gl_proto_expect), feeds whatever bytes arrived (gl_proto_feed), and asks
 * for the next complete reply (gl_proto_next). No sockets, no allocation:
 * every buffer lives in struct gl_proto, which the caller embeds.
 *
 * Framing (galil-notes.md 1.3, 1.5, 3.2):
 *   - one terminator per ';'-separated command: ':' success, '?' rejected;
 *   - data, CR LF, then ':'. A ':' or '?' is a terminator only at the start
 *     of a command's reply or of a line; inside a line it is data (so
 *     MG "ok?" is not taken for an error). Consequence: a reply whose data
 *     does not end in CR LF (host "MG x {N}") never completes and times out;
 *   - QR: the last command's reply is a binary record of a known length,
 *     taken by length (record bytes may be >= 0x80 or ':'), then ':';
 *   - UL: text up to 0x1A, then ':'.
 * Unsolicited bytes (high bit set, CW1) may appear anywhere in text: they
 * are moved, high bit cleared, into a queue of lines split at CR LF. Before
 * a binary record they are recognised because a record's first byte is
 * 0x80..0x87 (bit 7 + block bits), which is not a printable character with
 * the high bit set. Inside a record body they cannot be told from record
 * bytes: the record is then misaligned and its trailing ':' is missing, which
 * is reported as GL_ERR_PROTO (the caller also treats bytes left over after a
 * complete reply as GL_ERR_PROTO, see gl_link.c).
 *
 * Any framing violation makes the parser return GL_ERR_PROTO until
 * gl_proto_reset(): after it the byte stream cannot be trusted.
 */
#ifndef GL_PROTO_H
#define GL_PROTO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gl_record.h"

#define GL_PROTO_IN_MAX	    4096 /* bytes buffered between feed and next */
#define GL_PROTO_TEXT_MAX   2048 /* default reply text capacity, bytes */
#define GL_PROTO_UNSOL_MAX  2048 /* unsolicited queue, bytes */
#define GL_PROTO_UNSOL_LINE 256	 /* longer unsolicited lines are split */
#define GL_PROTO_EXPECT_MAX 264 /* replies awaited at once (posted lines) */
#define GL_PROTO_CMDS_MAX   64	 /* terminators per reply */

/* A complete reply; pointers stay valid until the next gl_proto_next(). */
struct gl_reply {
	int n_cmds;	  /* terminators received (as expected) */
	int n_err;	  /* how many of them were '?' */
	int first_err;	  /* 0-based command index of the first '?', or -1 */
	const char *text; /* data bytes, NUL-terminated, final CR LF removed */
	size_t text_len;  /* bytes stored in @text */
	bool truncated;	  /* data did not fit; @text holds the first part */
	const uint8_t *bin; /* the binary record, NULL if none */
	size_t bin_len;	    /* its length in bytes */
};

struct gl_proto_expect {
	int n_term;	/* terminators awaited */
	size_t bin_len; /* > 0: last command returns a record */
	bool upload;	/* UL: text up to 0x1A, then ':' */
	char *buf;	/* text buffer (NULL: the parser's own) */
	size_t cap;	/* its capacity */
};

/* Parser state. Treat as opaque; visible only so it can be embedded. */
struct gl_proto {
	uint8_t in[GL_PROTO_IN_MAX];
	size_t in_pos, in_len;
	struct gl_proto_expect exp[GL_PROTO_EXPECT_MAX];
	int exp_head, exp_n;
	bool all_unsol; /* every byte is unsolicited (message handle) */
	int error;	/* sticky GL_ERR_PROTO */
	/* the reply being parsed */
	int state, cmd, n_err, first_err;
	bool line_start, cmd_data, done;
	char text_store[GL_PROTO_TEXT_MAX];
	char *text;
	size_t text_cap, text_len;
	bool truncated;
	uint8_t bin[GL_REC_MAX_BYTES];
	size_t bin_n;
	/* unsolicited ring of characters; '\n' ends a line */
	char unsol[GL_PROTO_UNSOL_MAX];
	size_t u_head, u_len, u_line_len;
	uint64_t unsol_dropped; /* characters lost because the queue was full */
};

/*
 * gl_proto_init() - initialise @p, owned by the caller (empty, no reply
 * awaited, nothing allocated). No return value.
 */
void gl_proto_init(struct gl_proto *p);

/*
 * gl_proto_reset() - forget buffered input, awaited replies, the sticky
 * error and queued unsolicited text.
 */
void gl_proto_reset(struct gl_proto *p);

/*
 * gl_proto_set_all_unsol() - treat every byte as unsolicited (the second,
 * message-only handle), whether or not its high bit is set.
 */
void gl_proto_set_all_unsol(struct gl_proto *p, bool on);

/*
 * gl_proto_expect() - announce the next reply (queued after earlier ones).
 * @n_terminators: number of ';'-separated commands sent (1..GL_PROTO_CMDS_MAX).
 * @binary_len: 0, or the record length when the last command is QR
 *              (<= GL_REC_MAX_BYTES).
 * Return: GL_OK, GL_ERR_ARG, GL_ERR_OVERFLOW (too many awaited replies).
 */
int gl_proto_expect(struct gl_proto *p, int n_terminators, size_t binary_len);

/*
 * gl_proto_expect_upload() - announce a UL reply whose text is stored in the
 * caller's @buf (capacity @cap >= 1, NUL-terminated; longer text sets
 * reply.truncated).
 * Return: GL_OK, GL_ERR_ARG, GL_ERR_OVERFLOW.
 */
int gl_proto_expect_upload(struct gl_proto *p, char *buf, size_t cap);

/*
 * gl_proto_space() - room in @p's input buffer.
 * Return: how many bytes gl_proto_feed() accepts now (0 when full).
 */
size_t gl_proto_space(const struct gl_proto *p);

/*
 * gl_proto_feed() - append received bytes. Nothing is parsed until
 * gl_proto_next().
 * Return: GL_OK; GL_ERR_OVERFLOW when @len > gl_proto_space() (nothing is
 *         taken); GL_ERR_ARG on NULL with @len > 0.
 */
int gl_proto_feed(struct gl_proto *p, const void *buf, size_t len);

/*
 * gl_proto_next() - parse buffered bytes up to the end of the next reply.
 * @reply: [out] filled on GL_OK.
 * Unsolicited bytes met on the way are queued (gl_proto_unsol_next).
 * Return: GL_OK (one reply; call again for the next), GL_ERR_AGAIN (need
 *         more bytes, or no reply awaited and only unsolicited bytes seen),
 *         GL_ERR_PROTO (framing violated, including solicited bytes when no
 *         reply is awaited; sticky until gl_proto_reset()).
 */
int gl_proto_next(struct gl_proto *p, struct gl_reply *reply);

/*
 * gl_proto_progress() - terminators seen so far in the reply being parsed
 * (used by DL to notice an early '?').
 * @n_err: [out] optional, how many of them were '?'.
 * Return: the count (0 when no reply is in progress).
 */
int gl_proto_progress(const struct gl_proto *p, int *n_err);

/*
 * gl_proto_awaiting() - replies announced with gl_proto_expect*() that
 * gl_proto_next() has not returned yet.
 * Return: that number (>= 0).
 */
int gl_proto_awaiting(const struct gl_proto *p);

/*
 * gl_proto_unsol_next() - take one complete unsolicited line (high bit
 * cleared, CR LF removed). Never blocks.
 * @line: [out] NUL-terminated; @cap >= 1.
 * Return: its length; GL_ERR_AGAIN when no complete line is queued;
 *         GL_ERR_OVERFLOW when the line was cut to @cap - 1 bytes (the rest
 *         is discarded); GL_ERR_ARG.
 */
int gl_proto_unsol_next(struct gl_proto *p, char *line, size_t cap);

/*
 * gl_parse_double() - parse a decimal number from a buffer (git style).
 * Accepts leading blanks, an optional sign, digits with an optional
 * fraction (" 1.0000", "-12.5", ".5"); no exponent, hex, inf or nan.
 * @ep: [out] optional, the first byte after the number.
 * @out: [out] the value, set on success only.
 * Return: true on success; false with errno = EINVAL (no number) or
 *         ERANGE (more than 40 characters or out of double range).
 */
bool gl_parse_double(const char *buf, size_t len, const char **ep, double *out);

#endif /* GL_PROTO_H */
