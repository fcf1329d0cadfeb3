/*
 * gl_link.h - a TCP link to a Galil DMC controller (command handle, plus an
 * optional second handle for unsolicited messages).
 *
 * The link only moves bytes; framing is done by the pure parser in gl_proto.
 * Every call has a deadline. After a timeout or a malformed reply the link is
 * marked broken (GL_ERR_BROKEN on every later call) unless it could be
 * resynchronised, so a late reply is never taken as the answer to the next
 * command. Nothing here prints.
 */
#ifndef GL_LINK_H
#define GL_LINK_H

#include <stddef.h>
#include <stdint.h>

#include "gl_record.h"

typedef struct gl_link gl_link;

#define GL_DEFAULT_PORT 23
#define GL_ERRTEXT_LEN 128
#define GL_LINE_MAX 80		/* controller command-line limit, bytes */

/*
 * gl_link_open() - connect to HOST[:PORT] (default port 23).
 * @out: [out] the new link; must not be NULL.
 * @addr: "host", "host:port" or "[v6]:port".
 * @timeout_ms: connect timeout and the default per-call timeout.
 * @err: [out] optional buffer of GL_ERRTEXT_LEN bytes for a message such as
 *       "cannot connect to '127.0.0.1:23': Connection refused".
 * Sets TCP_NODELAY and SO_KEEPALIVE. Allocates (start-up only).
 * Return: GL_OK, GL_ERR_ARG, GL_ERR_SYS, GL_ERR_TIMEOUT, GL_ERR_NOMEM.
 */
int gl_link_open(gl_link **out, const char *addr, int timeout_ms,
		 char err[GL_ERRTEXT_LEN]);

/* gl_link_close() - close both handles and free. NULL is a no-op. */
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
 * On '?' the link asks "TC1" and keeps code and text (gl_link_ctrl_error).
 * Return: the length of @resp (>= 0); GL_ERR_CTRL; GL_ERR_TIMEOUT (the link
 *         is then broken); GL_ERR_PROTO; GL_ERR_CLOSED; GL_ERR_BROKEN;
 *         GL_ERR_OVERFLOW (reply larger than @cap; link stays in step).
 */
int gl_link_command(gl_link *l, const char *cmd, char *resp, size_t cap,
		    int timeout_ms);

/*
 * gl_link_record() - send "[prefix;]QR" and decode the binary record.
 * @prefix: optional commands sent on the same line before QR (e.g. the
 *          heartbeat "hbpc=17"), each answered by ':'; NULL for none.
 * @rec: [out] the decoded record (layout learnt from QZ at open or by
 *       gl_link_query_layout()).
 * One round trip. Return: GL_OK or an error as for gl_link_command(), or
 *         GL_ERR_RECORD for a record that does not decode.
 */
int gl_link_record(gl_link *l, const char *prefix, struct gl_record *rec,
		   int timeout_ms);

/*
 * gl_link_query_layout() - send QZ and remember the record layout.
 * Return: GL_OK or an error as for gl_link_command().
 */
int gl_link_query_layout(gl_link *l);

/*
 * gl_link_ctrl_error() - the controller's last error after GL_ERR_CTRL.
 * @code: [out] optional TC code (e.g. 1).
 * Return: the TC1 text (e.g. "Unrecognized command"), "" if none; valid
 *         until the next call on the link.
 */
const char *gl_link_ctrl_error(const gl_link *l, int *code);

/*
 * gl_link_download() - DL a program: "DL", the lines, "\", both ':' acks.
 * @prog: the program text, lines separated by CR, LF or CR LF; must not
 *        contain '\'.
 * @bad_line: [out] optional; on GL_ERR_CTRL the 1-based program line that
 *            the controller rejected (0 if unknown).
 * Return: GL_OK, GL_ERR_ARG ('\' in @prog), GL_ERR_CTRL, GL_ERR_TIMEOUT...
 */
int gl_link_download(gl_link *l, const char *prog, size_t len, int *bad_line,
		     int timeout_ms);

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
 * on the command handle.
 * Return: GL_OK or an error code.
 */
int gl_link_open_messages(gl_link *l, int timeout_ms);

/*
 * gl_link_message() - take one complete unsolicited line (high bit cleared,
 * CR LF removed). Never blocks.
 * Return: its length (>= 0), GL_ERR_AGAIN when no complete line is queued,
 *         GL_ERR_CLOSED, GL_ERR_OVERFLOW (line truncated to @cap - 1).
 */
int gl_link_message(gl_link *l, char *line, size_t cap);

/*
 * gl_link_stats() - bytes sent and received and round trips, since open.
 */
void gl_link_stats(const gl_link *l, uint64_t *tx_bytes, uint64_t *rx_bytes,
		   uint64_t *round_trips);

#endif /* GL_LINK_H */
