/*
 * gload_cmd.h - galil-load's -c commands: which commands may be sent (the
 * program's transfers, master reset and lock changes are not), which are
 * writes to a RoboELF program that is running (refused without --force,
 * docs/safety.md H12), and the sending itself. main.c prints the replies
 * and the warnings. Nothing here prints: a refused command is reported
 * through the caller's usage function.
 */
#ifndef GLOAD_CMD_H
#define GLOAD_CMD_H

#include <stddef.h>

#include "gl_link.h"

#define GLOAD_SHOWN_LEN (2 * GL_LINE_MAX + 8) /* bytes of a command shown */

/*
 * gload_usage_fn - how a usage error is reported: the message (lower case,
 * no full stop) from a printf format; returns the exit code to give
 * (galil-load's main() prints it with the usage text, GLOAD_EXIT_USAGE).
 */
typedef int gload_usage_fn(const char *fmt, ...)
    __attribute__((format(printf, 1, 2)));

/*
 * gload_cmd_shown() - @c with control bytes in caret notation (0x12 ->
 * "^R"), for messages.
 * @out: [out] GLOAD_SHOWN_LEN bytes; a longer result is cut.
 * Return: @out.
 */
const char *gload_cmd_shown(const char *c, char out[GLOAD_SHOWN_LEN]);

/*
 * gload_cmd_check() - may @cmd be sent with -c? A control-character request
 * only if it is ^R^V or "^L^K ?"; any other command must be 1..GL_LINE_MAX
 * characters without a line end, and not DL, UL, ED, QD, QU or QR.
 * @usage: [in] reports why not; must not be NULL.
 * Return: 0, or what @usage returned.
 */
int gload_cmd_check(const char *cmd, gload_usage_fn *usage);

/*
 * gload_cmd_timeout() - the reply timeout of command @c: @timeout_ms, and
 * at least GLOAD_SLOW_TIMEOUT_MS for the burns and BZ, which pause the
 * controller [galil-notes 1.6]. Return: ms.
 */
int gload_cmd_timeout(const char *c, int timeout_ms);

/*
 * gload_cmd_write_state() - is @c a write to a RoboELF program that runs?
 * Reads (MG, TP, "KP ?,?", "name=": dmc_cmd_line_is_read()) are not; else
 * the controller is asked (_XQ0, then the program's "state" variable,
 * each within @timeout_ms).
 * Return: the program's state, 1 armed or 3 service, when @c writes to it;
 *         -1 when @c only reads, or no program runs, or it is not ours
 *         (no "state" variable), or the question failed.
 */
int gload_cmd_write_state(gl_link *l, const char *c, int timeout_ms);

/*
 * gload_cmd_send() - send @c as a control-character request
 * (gl_link_ctrl_request()) or a command line (gl_link_command()) and read
 * its reply into @resp (@cap bytes) within @timeout_ms.
 * Return: as those: the reply's length (>= 0) or a gl_err code.
 */
int gload_cmd_send(gl_link *l, const char *c, char *resp, size_t cap,
		   int timeout_ms);

#endif /* GLOAD_CMD_H */
