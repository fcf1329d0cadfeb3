/*
 * re_console_int.h - what the console's files share and nobody else uses:
 * the board's words (re_console_words.c), one source for each state shown.
 */
#ifndef RE_CONSOLE_INT_H
#define RE_CONSOLE_INT_H

#include <stddef.h>

#include "re_super.h"

/* re_con_relay_text() - the relay's state in words ("ON", "OFF (power
 * cut)", "UNKNOWN"). */
const char *re_con_relay_text(enum re_relay_state r);

/* re_con_cmd_text() - a joystick command in words ("none", "A fwd", ...,
 * "invalid" for a negative one). */
const char *re_con_cmd_text(int k);

/*
 * re_con_ctrl_text() - the controller program's state in words: "armed",
 * "safe", a latched fault by its name and axis letter, its code after
 * ("FAULT ENCODER axis B (code 9)").
 * @buf: [out] NUL-terminated, cut to @cap.
 */
void re_con_ctrl_text(const struct re_status *st, char *buf, size_t cap);

/*
 * re_con_stream_text() - the record stream's loss for the board's first
 * line: ", records lost 0.02 %" (lost / (accepted + lost), while a stream
 * is open and has had a record), else "" (polling, or none yet).
 * @buf: [out] NUL-terminated, cut to @cap.
 */
void re_con_stream_text(const struct re_status *st, char *buf, size_t cap);

/* re_con_motion_text() - what axis @a does now: "off", "at-lim",
 * "moving", "stopped" (never "moving" at a soft limit or motor off). */
const char *re_con_motion_text(const struct re_axis_status *a);

/* re_con_limit_text() - the limit switches (FWD, REV, F+R) or a soft
 * limit reached (sF, sR), else "-". */
const char *re_con_limit_text(const struct re_axis_status *a);

/*
 * re_con_moving_text() - the board's "moving" summary, made from the
 * same per-axis states as the axis lines (re_con_motion_text() and the
 * sign of the velocity) so that the two cannot disagree: "none", "B fwd",
 * "A rev, B fwd"; "-" when the link is down.
 * @buf: [out] NUL-terminated, cut to @cap.
 */
void re_con_moving_text(const struct re_status *st, char *buf, size_t cap);

#endif /* RE_CONSOLE_INT_H */
