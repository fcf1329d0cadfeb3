/*
 * gl_link.h - a TCP link to a Galil DMC controller (command handle, plus an
 * optional second handle for unsolicited messages).
 *
 * The link only moves bytes; framing is done by the pure parser in gl_proto.
 * Every call has a deadline. After a timeout, a malformed reply, bytes beyond
 * the awaited reply, or a closed connection the link is marked broken
 * (GL_ERR_BROKEN on every later call, gl_link_broken() true): it is never
 * resynchronised, so a late reply is never taken as the answer to the next
 * command. Close it and open a new link. Nothing here prints; no allocation
 * after gl_link_open(). Rationale and protocol choices: gl_link.c header.
 */
#ifndef GL_LINK_H
#define GL_LINK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gl_record.h"

typedef struct gl_link gl_link;

#define GL_DEFAULT_PORT 23
#define GL_ERRTEXT_LEN	128
#define GL_LINE_MAX	80 /* controller command-line limit, bytes */
/* datagrams per gl_link_stream_read(): more than a socket's default
 * receive buffer (208 KB) holds of 190-byte records (about 270), so that
 * after a pause (between two phases) the newest record is reached in one
 * call, not the oldest of a backlog */
#define GL_LINK_STREAM_READS_MAX 1024
/* posted lines whose replies may be outstanding at once (gl_link_post()):
 * at the shortest cycle (2 ms) 512 ms of heartbeats, past a resend of the
 * controller's TCP (200 ms at least, 400 ms for a second one) */
#define GL_LINK_POST_MAX 256

/*
 * gl_link_open() - connect to HOST[:PORT] (default port 23).
 * @out: [out] the new link; must not be NULL.
 * @addr: "host", "host:port" or "[v6]:port".
 * @timeout_ms: connect timeout and the default per-call timeout.
 * @err: [out] optional buffer of GL_ERRTEXT_LEN bytes for a message such as
 *       "cannot connect to '127.0.0.1:23': Connection refused".
 * Sets TCP_NODELAY, TCP_THIN_LINEAR_TIMEOUTS and SO_KEEPALIVE (docs/link.md).
 * Allocates (start-up only).
 * Return: GL_OK, GL_ERR_ARG, GL_ERR_SYS, GL_ERR_TIMEOUT, GL_ERR_NOMEM.
 */
int gl_link_open(gl_link **out, const char *addr, int timeout_ms,
		 char err[GL_ERRTEXT_LEN]);

/*
 * gl_link_addr_split() - split a controller address as gl_link_open() does.
 * @addr: "host", "host:port", "[v6]" or "[v6]:port"; a bare IPv6 address
 *        (more than one ':') needs the brackets.
 * @host: [out] the host without brackets, NUL-terminated; @hcap bytes.
 * @port: [out] the port as written (digits only, 1..65535), or
 *        GL_DEFAULT_PORT when none is given; @pcap bytes.
 * Return: GL_OK, or GL_ERR_ARG for anything gl_link_open() refuses as
 *         "invalid address" (empty host or port, a bad port, too long).
 */
int gl_link_addr_split(const char *addr, char *host, size_t hcap, char *port,
		       size_t pcap);

/*
 * gl_link_close() - close both handles and free @l (the caller's pointer is
 * then invalid). NULL is a no-op. No return value.
 */
void gl_link_close(gl_link *l);

/*
 * gl_link_set_timeout() - change the default per-call timeout (ms > 0).
 * Return: GL_OK or GL_ERR_ARG.
 */
int gl_link_set_timeout(gl_link *l, int timeout_ms);

/*
 * gl_link_command() - send one command line and read its reply.
 * @cmd: the command without terminator, at most GL_LINE_MAX bytes; may hold
 *       several ';'-separated commands (one terminator each is awaited).
 * @resp: [out] the data before the final ':' of every command, joined,
 *        with trailing CR LF and the ':' removed; NUL-terminated.
 * @cap: capacity of @resp.
 * @timeout_ms: deadline for the whole reply; 0 = the link default.
 *       Refused (GL_ERR_ARG, nothing sent): empty, control or non-ASCII
 *       bytes, an empty command (";;", leading or trailing ';'), an odd
 *       number of '"'. ';' inside "..." does not separate commands.
 * @resp: [out] optional (NULL: only the length is returned).
 * On '?' the link asks "TC1" and keeps code and text (gl_link_ctrl_error);
 * if TC1 itself fails its error is returned and the link is broken.
 * Return: the length of the data (>= 0); GL_ERR_ARG; GL_ERR_CTRL;
 *         GL_ERR_TIMEOUT, GL_ERR_PROTO, GL_ERR_CLOSED, GL_ERR_SYS (the
 *         link is then broken); GL_ERR_BROKEN; GL_ERR_OVERFLOW (data
 *         larger than @cap, cut to @cap - 1 bytes; link stays in step).
 */
int gl_link_command(gl_link *l, const char *cmd, char *resp, size_t cap,
		    int timeout_ms);

/*
 * gl_link_record() - send "[prefix;]QR" and decode the binary record.
 * @prefix: optional commands sent on the same line before QR (e.g. the
 *          heartbeat "hbpc=17"), each answered by ':'; NULL for none.
 * @rec: [out] the decoded record; untouched on error. The layout is learnt
 *       with QZ on the first call (or by gl_link_query_layout()).
 * One round trip (plus QZ the first time). The whole line is at most
 * GL_LINE_MAX bytes. Return: GL_OK or an error as for gl_link_command(), or
 *         GL_ERR_RECORD for a record that does not decode (link in step).
 */
int gl_link_record(gl_link *l, const char *prefix, struct gl_record *rec,
		   int timeout_ms);

/*
 * gl_link_record_seen() - gl_link_record() for a caller that looks at the
 * command socket itself before each request (poll() of gl_link_fd()).
 * @seen_idle: true when that look, just before this call, showed no input
 *             (nor an error or hang-up): the read that looks for stray
 *             bytes before the request and the one that looks for surplus
 *             after the reply are left out (two system calls fewer per
 *             cycle). Surplus that came with the reply is still found;
 *             later surplus is found by the caller's next look, before the
 *             next request. false: exactly gl_link_record().
 * Return: as gl_link_record().
 */
int gl_link_record_seen(gl_link *l, const char *prefix, struct gl_record *rec,
			int timeout_ms, bool seen_idle);

/*
 * gl_link_record_text() - gl_link_record_seen() whose prefix may hold
 * commands that answer data (e.g. "hbpc=17;MG vmax[0],_KPA"): their text
 * goes to @text (NUL-terminated, at most @cap - 1 bytes; the final CR LF
 * removed), the record is decoded as usual.
 * Return: as gl_link_record(); GL_ERR_OVERFLOW when the text did not fit.
 */
int gl_link_record_text(gl_link *l, const char *prefix, struct gl_record *rec,
			int timeout_ms, bool seen_idle, char *text, size_t cap);

/*
 * gl_link_ctrl_request() - send a control-character request of the command
 * reference and read its reply: ^R^V (0x12 0x16, firmware revision), ^R^S
 * (0x12 0x13, master reset) or ^L^K (0x0C 0x0B, lock; printable arguments
 * may follow, e.g. " ?"). Policy (which of them a program may send) is the
 * caller's; see gl_link_ctrl_kind().
 * @req: the request bytes, NUL-terminated, at most GL_LINE_MAX bytes.
 * @resp, @cap, @timeout_ms: as for gl_link_command().
 * Return: as for gl_link_command(); GL_ERR_ARG (nothing sent) for anything
 *         that is not one of the requests above.
 */
int gl_link_ctrl_request(gl_link *l, const char *req, char *resp, size_t cap,
			 int timeout_ms);

/* The control-character requests of the command reference. */
enum gl_ctrl_kind {
	GL_CTRL_NONE = 0,     /* no control character at all */
	GL_CTRL_REVISION = 1, /* ^R^V alone */
	GL_CTRL_RESET = 2,    /* ^R^S alone: master reset (erases EEPROM) */
	GL_CTRL_LOCK = 3,     /* ^L^K, then printable arguments */
	GL_CTRL_OTHER = -1,   /* a control byte anywhere else */
};

/*
 * gl_link_ctrl_kind() - classify @cmd (NUL-terminated): which control-
 * character request it is (pure, no I/O). A command without control bytes
 * is GL_CTRL_NONE; a control byte that is not the start of one of the three
 * requests (or ^R^V / ^R^S followed by anything) is GL_CTRL_OTHER.
 */
enum gl_ctrl_kind gl_link_ctrl_kind(const char *cmd);

/*
 * gl_link_query_layout() - send QZ and remember the record layout.
 * Return: GL_OK or an error as for gl_link_command().
 */
int gl_link_query_layout(gl_link *l);

/*
 * gl_link_axes() - the controller's number of axes (QZ), asked once and
 * remembered. Return: 1..8, or a link error.
 */
int gl_link_axes(gl_link *l);

/*
 * gl_link_ctrl_error() - the controller's last error after GL_ERR_CTRL.
 * @code: [out] optional TC code (e.g. 1).
 * Return: the TC1 text (e.g. "Unrecognized command"), "" if none; valid
 *         until the next call on the link.
 */
const char *gl_link_ctrl_error(const gl_link *l, int *code);

/*
 * gl_link_download() - DL a program: "DL", the lines, "\", both ':' acks.
 * @prog: the program text, lines separated by CR, LF or CR LF; every line
 *        at most GL_LINE_MAX printable characters (TAB allowed), no '\'.
 * @bad_line: [out] optional; on GL_ERR_ARG the 1-based line refused before
 *            anything was sent (exact); on GL_ERR_CTRL the last line sent
 *            when the controller's '?' was seen - the rejected line is that
 *            one or an earlier one - or 0 when the '?' came after the "\".
 *            See gl_link_set_dl_pace() for an exact number.
 * After GL_ERR_CTRL the controller's program must be treated as invalid.
 * Return: GL_OK, GL_ERR_ARG, GL_ERR_CTRL (TC1 kept), GL_ERR_TIMEOUT,
 *         GL_ERR_PROTO, GL_ERR_CLOSED, GL_ERR_BROKEN.
 */
int gl_link_download(gl_link *l, const char *prog, size_t len, int *bad_line,
		     int timeout_ms);

/*
 * gl_link_set_dl_pace() - after each DL line wait up to @pace_ms for an
 * early '?' (0, the default: do not wait). With a pace longer than the
 * controller's reply time *bad_line is exact, at @pace_ms per line.
 * Return: GL_OK or GL_ERR_ARG.
 */
int gl_link_set_dl_pace(gl_link *l, int pace_ms);

/*
 * gl_link_upload() - UL the program: text up to 0x1A, then ':'.
 * @buf: [out] the program, lines separated by CR LF as sent, NUL-terminated.
 * Return: the length (>= 0) or an error code (GL_ERR_OVERFLOW if too large).
 */
int gl_link_upload(gl_link *l, char *buf, size_t cap, int timeout_ms);

/*
 * gl_link_identify() - model/firmware from ^R^V and serial from MG _BN.
 * @model: [out] e.g. "DMC4030 Rev 1.2h"; @serial: [out] e.g. 12345.
 * Return: GL_OK or an error as for gl_link_command().
 */
int gl_link_identify(gl_link *l, char *model, size_t cap, long *serial);

/*
 * gl_link_open_messages() - open the second (unsolicited) handle to the same
 * controller, find its handle letter with WH, send "CF <letter>" and "CW1"
 * on the command handle. Calling it again reopens the handle.
 * @timeout_ms: connect and each exchange; 0 = the link default.
 * Return: GL_OK or an error code (the message handle is then closed).
 */
int gl_link_open_messages(gl_link *l, int timeout_ms);

/*
 * gl_link_message() - take one complete unsolicited line (high bit cleared,
 * CR LF removed). Never blocks. Lines that reached the command handle come
 * first, then those of the message handle. Lines over GL_PROTO_UNSOL_LINE
 * (256) bytes are split; when a queue is full, new characters are dropped.
 * Return: its length (>= 0), GL_ERR_AGAIN when no complete line is queued,
 *         GL_ERR_CLOSED (the message handle was closed by the peer),
 *         GL_ERR_OVERFLOW (line truncated to @cap - 1), GL_ERR_SYS.
 */
int gl_link_message(gl_link *l, char *line, size_t cap);

/*
 * gl_link_message_queued() - as gl_link_message(), but only lines already
 * received: no system call. For a caller that polled gl_link_msg_fd() just
 * before and saw no input (one look per cycle).
 * Return: as gl_link_message(), never GL_ERR_SYS.
 */
int gl_link_message_queued(gl_link *l, char *line, size_t cap);

/*
 * gl_link_stats() - traffic since gl_link_open().
 * @tx_bytes: [out] optional, bytes sent; @rx_bytes: [out] optional, bytes
 * received; @round_trips: [out] optional, command-handle replies completed.
 * A NULL @l gives zeros. No return value; cannot fail.
 */
void gl_link_stats(const gl_link *l, uint64_t *tx_bytes, uint64_t *rx_bytes,
		   uint64_t *round_trips);

/*
 * gl_link_fd() - the command socket, for poll() in an event loop only (never
 * read or write it). Return: the descriptor, or -1.
 */
int gl_link_fd(const gl_link *l);

/*
 * gl_link_msg_fd() - the message socket (gl_link_open_messages()), for
 * poll() only, as gl_link_fd(). Return: the descriptor, or -1 when none.
 */
int gl_link_msg_fd(const gl_link *l);

/*
 * gl_link_broken() - true once the command handle is out of step (after
 * GL_ERR_TIMEOUT, GL_ERR_PROTO, GL_ERR_CLOSED or GL_ERR_SYS): close the link
 * and open a new one.
 */
bool gl_link_broken(const gl_link *l);

/* ---- the pipelined line and the record stream (docs/link.md, "The
 * record as a stream") ---- */

struct gl_stream_stats;

/*
 * gl_link_post() - send one command line on the command handle and return
 * without waiting for its reply; gl_link_collect() takes the replies
 * later, in order. Up to GL_LINK_POST_MAX lines may be outstanding. The
 * line is checked as by gl_link_command(); the send does not wait (the
 * socket's buffer takes a line of GL_LINE_MAX bytes at once unless the
 * peer stopped reading).
 * Return: GL_OK (sent whole); GL_ERR_BUSY (GL_LINK_POST_MAX outstanding:
 *         nothing sent); GL_ERR_ARG; GL_ERR_BROKEN; GL_ERR_TIMEOUT when the
 *         socket did not take the whole line at once (the link is then
 *         broken: a peer that stopped reading); GL_ERR_CLOSED, GL_ERR_SYS.
 */
int gl_link_post(gl_link *l, const char *cmd);

/*
 * gl_link_collect() - take the reply to the oldest outstanding posted
 * line if it is all there, without waiting (reads what the socket holds).
 * Call it again for the next.
 * @text: [out] optional (NULL or @cap 0): the reply's data text,
 *        NUL-terminated, as gl_link_command() gives it.
 * Return: the text's length (>= 0) when the reply is complete (the line is
 *         then no longer outstanding); GL_ERR_AGAIN (not complete yet);
 *         GL_ERR_NOENT (nothing outstanding: none posted, or another
 *         exchange took the replies, gl_link_posted()); GL_ERR_CTRL after
 *         '?' (when it was the last outstanding, TC1 is asked with the
 *         link's default timeout, as for a command; else no TC1 text, and
 *         it is counted in gl_link_post_errors()); GL_ERR_OVERFLOW; a
 *         stream error (the link is broken).
 */
int gl_link_collect(gl_link *l, char *text, size_t cap);

/*
 * gl_link_posted() - how many posted lines' replies are outstanding (0
 * also for NULL). Any other exchange on the command handle first waits,
 * within its own deadline, for those replies and sets them aside (a '?'
 * in one is counted in gl_link_post_errors()).
 */
int gl_link_posted(const gl_link *l);

/*
 * gl_link_post_errors() - posted replies set aside by another exchange
 * that were '?' (0 for NULL): the caller that never collected them learns
 * of them here.
 */
uint64_t gl_link_post_errors(const gl_link *l);

/*
 * gl_link_stream_open() - start the controller's data record stream to
 * this PC: a UDP socket connected to the controller's address and
 * @udp_port (the kernel then drops datagrams of any other sender), "WH"
 * sent on it (resent every 20 ms until answered: UDP may lose it) for its
 * handle letter, then "DR @n0_samples,<handle>" on the command handle;
 * the reader (gl_stream) starts with the link's layout (QZ first if not
 * known). Call after any "IHT=>-3" (which closes UDP handles too).
 * Opening again closes the old stream first.
 * @udp_port: the controller's UDP command port (60007 on a DMC-40x0).
 * @n0_samples: samples between two records, 2..16383.
 * @sample_ns: one controller sample in ns (> 0), for the reader.
 * @timeout_ms: for the whole opening; 0 = the link default.
 * @err: [out] optional, GL_ERRTEXT_LEN bytes: what failed, in words.
 * Return: GL_OK; GL_ERR_ARG; GL_ERR_TIMEOUT (no answer to WH); GL_ERR_CTRL
 *         (DR refused: gl_link_ctrl_error()); GL_ERR_PROTO (WH's answer is
 *         not a handle); GL_ERR_SYS. On error no stream is open.
 */
int gl_link_stream_open(gl_link *l, int udp_port, unsigned n0_samples,
			int64_t sample_ns, int timeout_ms,
			char err[GL_ERRTEXT_LEN]);

/*
 * gl_link_stream_read() - read every datagram the stream socket holds
 * (without waiting; at most GL_LINK_STREAM_READS_MAX per call: the whole
 * receive buffer), judge each (gl_stream_feed()), and decode the
 * newest accepted one into @rec.
 * @now_ns: monotonic time now (base_clock), the reception time.
 * Return: 1 when @rec holds a record newer than the last call's; 0 when
 *         none arrived (or only dropped ones); GL_ERR_ARG (no stream);
 *         GL_ERR_SYS.
 */
int gl_link_stream_read(gl_link *l, struct gl_record *rec, int64_t now_ns);

/*
 * gl_link_stream_age_ns() - ns since the last accepted record (since the
 * stream opened when none was) at @now_ns; GL_ERR_ARG without a stream.
 */
int64_t gl_link_stream_age_ns(const gl_link *l, int64_t now_ns);

/*
 * gl_link_stream_stats() - the reader's counters (gl_stream.h) into @out;
 * zeros without a stream. No return value.
 */
void gl_link_stream_stats(const gl_link *l, struct gl_stream_stats *out);

/*
 * gl_link_stream_info() - the stream's parameters: @handle (0..7 = A..H)
 * and @n0 (samples), each optional. Return: 1 when a stream is open, 0
 * when not (nothing written).
 */
int gl_link_stream_info(const gl_link *l, int *handle, unsigned *n0);

/*
 * gl_link_stream_fd() - the stream's socket, for poll() only; -1 when none.
 */
int gl_link_stream_fd(const gl_link *l);

/*
 * gl_link_stream_close() - "DR 0;IH<h>=>-1" on the command handle (the
 * stream stopped and its UDP handle closed on the controller; within
 * @timeout_ms, 0 = default; its failure is returned but the socket is
 * closed anyway) and close the stream's socket. No stream: GL_OK.
 */
int gl_link_stream_close(gl_link *l, int timeout_ms);

#endif /* GL_LINK_H */
