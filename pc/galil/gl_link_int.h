/*
 * gl_link_int.h - what the parts of the link share: the handle, its two
 * channels, one exchange, and the functions one part gives the others.
 *   gl_link.c      the life cycle (open, close) and the handle's accessors;
 *                  the design decisions of the whole link (its header)
 *   gl_link_io.c   moving bytes with deadlines: one exchange on a channel
 *   gl_link_sock.c the connection: the address, the socket, its options
 *   gl_link_cmd.c  the command round trip, TC1 after '?'
 *   gl_link_ctrl.c the control-character requests, identification
 *   gl_link_rec.c  the data record (QR) and its layout (QZ)
 *   gl_link_dl.c   program download (DL) and upload (UL)
 *   gl_link_msg.c  the unsolicited message handle
 *   gl_link_post.c a line sent now, its reply collected later
 *   gl_link_udp.c  the record stream: the UDP handle, DR, the reader
 * Who uses whom: gl_link.c uses sock and io; sock uses io; cmd uses io;
 * ctrl, rec and dl use cmd and io; msg uses cmd, sock and io; post uses
 * cmd and io; udp uses rec, cmd, sock and io. No loop
 * (tests/checks/layers.sh). Not for the rest of the code base: gl_link.h
 * is the interface. Nothing here prints.
 */
#ifndef GL_LINK_INT_H
#define GL_LINK_INT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/socket.h>

#include "gl_link.h"
#include "gl_proto.h"
#include "gl_stream.h"

#define GL_LINK_MSG_READS_MAX 8 /* recv() calls per gl_link_message() */
#define GL_LINK_DGRAM_BATCH  32  /* stream datagrams a recvmmsg() */
#define GL_LINK_DGRAM_MAX    512 /* the largest record is 190 bytes */

/* One TCP connection to the controller and the parser of its bytes. */
struct gl_chan {
	int fd;
	bool broken;
	struct gl_proto p;
};

struct gl_link {
	struct gl_chan cmd, msg;
	struct sockaddr_storage addr;
	socklen_t addr_len;
	int timeout_ms;
	int dl_pace_ms; /* DL: wait per line for an early '?' */
	enum gl_rec_layout layout;
	int n_axes;
	int ctrl_code;
	char ctrl_text[GL_ERRTEXT_LEN];
	uint64_t tx_bytes, rx_bytes, round_trips;
	/* the posted lines (gl_link_post.c) whose replies are outstanding */
	int n_posted;
	uint64_t post_errors; /* posted replies set aside that were '?' */
	/* the record stream (gl_link_udp.c): fd -1 when none */
	int st_fd;
	int st_handle; /* 0..7 = A..H */
	struct gl_stream st;
	/* a batch of datagrams (recvmmsg()), here rather than on the
	 * cycle's stack */
	uint8_t st_buf[GL_LINK_DGRAM_BATCH][GL_LINK_DGRAM_MAX];
};

/* What one exchange sends and awaits. */
struct gl_xfer {
	const char *line; /* sent followed by CR */
	size_t len;
	int n_term;
	size_t bin_len;
	char *ubuf; /* non-NULL: UL reply into this buffer */
	size_t ucap;
	/* the caller polled the socket just before and it held nothing:
	 * no read before the request, none for surplus after the reply */
	bool seen_idle;
};

/* ---- gl_link_io.c: bytes and exchanges ---- */

/* gl_link_left_ms() - ms from now until @deadline (base_now_ms()), >= 0. */
int gl_link_left_ms(int64_t deadline);

/*
 * gl_link_chan_write() - send all @len bytes of @buf on @ch before
 * @deadline (counted in l->tx_bytes).
 * Return: GL_OK, GL_ERR_CLOSED, GL_ERR_TIMEOUT, GL_ERR_SYS.
 */
int gl_link_chan_write(gl_link *l, struct gl_chan *ch, const void *buf,
		       size_t len, int64_t deadline);

/*
 * gl_link_chan_read() - read what is there (one recv) into @ch's parser.
 * @deadline: < 0: do not wait. When waiting is allowed the socket is
 * polled first: a reply awaited is rarely there yet, and poll + recv is
 * one system call fewer than a recv that finds nothing, then poll, then
 * recv (the lean cycle).
 * Return: GL_OK (bytes fed), GL_ERR_AGAIN (nothing without waiting),
 *         GL_ERR_TIMEOUT, GL_ERR_CLOSED, GL_ERR_SYS.
 */
int gl_link_chan_read(gl_link *l, struct gl_chan *ch, int64_t deadline);

/*
 * gl_link_chan_fail() - mark @ch out of step for the errors that leave the
 * stream unknown (GL_ERR_TIMEOUT, _PROTO, _CLOSED, _SYS). Return: @rc.
 */
int gl_link_chan_fail(struct gl_chan *ch, int rc);

/* gl_link_chan_close() - close @ch's socket if open; its fd is then -1. */
void gl_link_chan_close(struct gl_chan *ch);

/*
 * gl_link_xfer_begin() - start exchange @x on @ch: refuse a broken channel
 * (GL_ERR_BROKEN) or a line over GL_LINE_MAX (GL_ERR_ARG), take the bytes
 * that arrived since the last reply (unless x->seen_idle), tell the parser
 * what to await, send the line and CR before @deadline.
 * Return: GL_OK or an error (the channel is broken for a stream error).
 */
int gl_link_xfer_begin(gl_link *l, struct gl_chan *ch, const struct gl_xfer *x,
		       int64_t deadline);

/*
 * gl_link_xfer_finish() - retire a complete reply (its text stays valid);
 * nothing solicited may follow. One non-blocking read first, so that
 * surplus bytes sent with the reply are seen now rather than at the next
 * call; not when the caller looks before each request itself
 * (@seen_idle: its next look, before the next request, sees them). Bytes
 * that came with the reply are seen in both cases.
 * Return: GL_OK, or GL_ERR_PROTO (surplus: the channel is broken).
 */
int gl_link_xfer_finish(gl_link *l, struct gl_chan *ch, bool seen_idle);

/*
 * gl_link_xfer_end() - wait until @deadline for the reply awaited by
 * gl_link_xfer_begin() into @r, then gl_link_xfer_finish().
 * Return: GL_OK or an error (the channel is broken for a stream error).
 */
int gl_link_xfer_end(gl_link *l, struct gl_chan *ch, const struct gl_xfer *x,
		     struct gl_reply *r, int64_t deadline);

/*
 * gl_link_xfer() - one whole exchange @x on @ch within @timeout_ms: begin
 * and end. @r: [out] the reply. Return: as gl_link_xfer_end().
 */
int gl_link_xfer(gl_link *l, struct gl_chan *ch, const struct gl_xfer *x,
		 int timeout_ms, struct gl_reply *r);

/*
 * gl_link_chan_drain_idle() - take the bytes that arrived on @ch since the
 * last reply (only unsolicited ones are allowed there), without waiting.
 * Return: GL_OK, or an error (the channel is then broken).
 */
int gl_link_chan_drain_idle(gl_link *l, struct gl_chan *ch);

/*
 * gl_link_post_settle() - before another exchange on the command handle:
 * wait until @deadline for the posted lines' replies (if any are
 * outstanding) and set them aside ('?' counted in l->post_errors).
 * Return: GL_OK, or a stream error (the channel is then broken).
 */
int gl_link_post_settle(gl_link *l, int64_t deadline);

/* ---- gl_link_sock.c: the connection ---- */

/*
 * gl_link_err_put() - format a message into @err (GL_ERRTEXT_LEN bytes);
 * nothing when @err is NULL. No return value.
 */
void gl_link_err_put(char *err, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/*
 * gl_link_sock_connect() - non-blocking connect to @sa with @deadline;
 * *@out the connected socket (close-on-exec, options of docs/link.md).
 * Return: GL_OK, GL_ERR_TIMEOUT, GL_ERR_SYS; errno is set on failure.
 */
int gl_link_sock_connect(const struct sockaddr *sa, socklen_t sl,
			 int64_t deadline, int *out);

/*
 * gl_link_connect() - resolve @addr and connect the command handle within
 * @timeout_ms; remember the address for the message handle.
 * @err: [out] optional, GL_ERRTEXT_LEN bytes: why it failed.
 * Return: GL_OK, GL_ERR_ARG, GL_ERR_SYS, GL_ERR_TIMEOUT.
 */
int gl_link_connect(gl_link *l, const char *addr, int timeout_ms, char *err);

/* ---- gl_link_cmd.c: the command round trip ---- */

/*
 * gl_link_pick_timeout() - @timeout_ms, or the link's default for 0.
 * Return: the timeout (ms), or GL_ERR_ARG when negative.
 */
int gl_link_pick_timeout(const gl_link *l, int timeout_ms);

/*
 * gl_link_count_commands() - check a command line (@len bytes) as
 * gl_link_command() documents. Return: the number of ';'-separated
 * commands (>= 1), or GL_ERR_ARG.
 */
int gl_link_count_commands(const char *cmd, size_t len);

/*
 * gl_link_fetch_tc1() - after '?': ask TC1, keep code and text.
 * Return: GL_ERR_CTRL, or TC1's own error (GL_ERR_PROTO for an answer that
 *         does not start with a number: the link is then broken).
 */
int gl_link_fetch_tc1(gl_link *l);

/* gl_link_ctrl_clear() - forget the controller's last error. */
void gl_link_ctrl_clear(gl_link *l);

/*
 * gl_link_text_out() - copy @r's text to @resp (@cap bytes, NUL-terminated;
 * NULL or @cap 0: only the length).
 * Return: the text's length (>= 0), or GL_ERR_OVERFLOW when it does not fit.
 */
int gl_link_text_out(const struct gl_reply *r, char *resp, size_t cap);

/*
 * gl_link_trim() - leave out the blanks and tabs at both ends of *@s
 * (*@len bytes): *@s and *@len are moved. No return value.
 */
void gl_link_trim(const char **s, size_t *len);

#endif /* GL_LINK_INT_H */
