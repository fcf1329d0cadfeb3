/*
 * re_console_words.c - the words the board and the status line show for
 * the relay, the joystick, the controller and each axis, and the
 * "moving" summary made from the axis states themselves. See
 * re_console_int.h.
 */
#include "re_console_int.h"

#include <stdio.h>
#include <string.h>

#include "re_dmcif.h"

static const char *const cmd_names[7] = {
    "none", "A fwd", "A rev", "B fwd", "B rev", "C fwd", "C rev",
};

const char *re_con_relay_text(enum re_relay_state r)
{
	switch (r) {
	case RE_RELAY_ON: return "ON";
	case RE_RELAY_OFF: return "OFF (power cut)";
	default: return "UNKNOWN";
	}
}

const char *re_con_cmd_text(int k)
{
	if (k < 0)
		return "invalid";
	return k <= 6 ? cmd_names[k] : "?";
}

void re_con_ctrl_text(const struct re_status *st, char *buf, size_t cap)
{
	int f = st->have_za ? st->za.fcode : 0;
	const char *w = re_dmc_fcode_words(f);

	if (!st->have_za)
		snprintf(buf, cap, "no data");
	else if (st->ctrl_ours) /* not a cause: the first one is above */
		snprintf(buf, cap, "stopped by the supervisor (code %d)", f);
	else if ((st->za.state == RE_DMC_FAULT || f) && st->za.faxis >= 1 &&
		 st->za.faxis <= 3)
		snprintf(buf, cap, "FAULT %s axis %c (code %d)", w ? w : "?",
			 (char)('A' + st->za.faxis - 1), f);
	else if (st->za.state == RE_DMC_FAULT || f)
		snprintf(buf, cap, "FAULT %s (code %d)", w ? w : "?", f);
	else if (st->za.state == RE_DMC_ARMED && !st->za.mneut &&
		 st->za.jcmd > 0)
		snprintf(buf, cap, "armed, release the joystick");
	else
		snprintf(buf, cap, "%s",
			 st->za.state == RE_DMC_ARMED	  ? "armed"
			 : st->za.state == RE_DMC_SERVICE ? "service"
							  : "safe");
}

void re_con_stream_text(const struct re_status *st, char *buf, size_t cap)
{
	uint64_t all = st->stream_records + st->stream_lost;

	if (!st->stream || !all)
		snprintf(buf, cap, "%s", "");
	else
		snprintf(buf, cap, ", records lost %.2f %%",
			 100.0 * (double)st->stream_lost / (double)all);
}

#define AT_SOFT_PCT 0.5	  /* within this of 0 or 100 %: at a soft limit */
#define STILL_CPS   100.0 /* |velocity| below this: not moving */

/* At a soft limit: +1 forward, -1 reverse, 0 not (or no calibration). */
static int at_soft(const struct re_axis_status *a)
{
	if (a->pos_pct < 0)
		return 0;
	if (a->pos_pct >= 100 - AT_SOFT_PCT)
		return 1;
	return a->pos_pct <= AT_SOFT_PCT ? -1 : 0;
}

const char *re_con_motion_text(const struct re_axis_status *a)
{
	if (a->motor_off)
		return "off";
	if (at_soft(a) && a->vel_cps < STILL_CPS && a->vel_cps > -STILL_CPS)
		return "at-lim";
	return a->moving ? "moving" : "stopped";
}

const char *re_con_limit_text(const struct re_axis_status *a)
{
	if (a->fwd_limit && a->rev_limit)
		return "F+R";
	if (a->fwd_limit)
		return "FWD";
	if (a->rev_limit)
		return "REV";
	return at_soft(a) > 0 ? "sF" : at_soft(a) < 0 ? "sR" : "-";
}

void re_con_moving_text(const struct re_status *st, char *buf, size_t cap)
{
	size_t n = 0;

	if (!cap)
		return;
	snprintf(buf, cap, "%s", st->link_ok ? "none" : "-");
	for (int i = 0; st->link_ok && i < st->n_axes && n < cap; i++) {
		const struct re_axis_status *a = &st->axis[i];

		if (strcmp(re_con_motion_text(a), "moving"))
			continue;
		n += (size_t)snprintf(buf + n, cap - n, "%s%s%s", n ? ", " : "",
				      st->axis_names[i],
				      a->vel_cps > 0   ? " fwd"
				      : a->vel_cps < 0 ? " rev"
						       : "");
	}
}
