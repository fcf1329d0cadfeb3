/*
 * re_comm.c - the commissioning run: the steps in order, the report items,
 * and the small controller helpers the step modules share.
 *
 * Safety of the run itself: it starts with every motor off and the relay
 * off (the caller halted and configured the controller); motor power is
 * switched on only inside the relay and motion steps, after the
 * technician's yes; rc_safe() (AB 1;MO ABC, relay off) ends every step
 * that switched anything on and the run itself, on every path.
 */
#include <stdio.h>
#include <string.h>

#include "gl_err.h"
#include "re_comm.h"
#include "re_comm_steps.h"
#include "re_comm_util.h"

void re_comm_init(struct re_comm *c)
{
	memset(c, 0, sizeof(*c));
	c->wait_ms = 60000;
	c->move_counts = 2000;
}

const char *re_comm_res_name(enum re_comm_res res)
{
	switch (res) {
	case RE_COMM_PASS: return "PASS";
	case RE_COMM_NOTE: return "NOTE";
	default: return "FAIL";
	}
}

static const struct {
	const char *name;
	const char *what;
	int (*fn)(struct re_comm *c);
} steps[] = {
    {"identity", "the controller's identity", rc_step_identity},
    {"firmware", "the firmware's behaviour our programs rely on",
     rc_step_firmware},
    {"joystick", "the joystick switches", rc_step_joystick},
    {"pots", "the potentiometers at rest", rc_step_pots},
    {"limits", "the limit switches", rc_step_limits},
    {"relay", "the E-stop relay and the amplifiers' power", rc_step_relay},
    {"motion", "encoders and potentiometers against the motors",
     rc_step_motion},
};

int re_comm_run(struct re_comm *c)
{
	size_t n = sizeof(steps) / sizeof(steps[0]);
	int rc = GL_OK;

	for (size_t i = 0; i < n && rc == GL_OK; i++) {
		rc_say(c, "step %zu of %zu: %s", i + 1, n, steps[i].what);
		rc = rc_quit(c) ? GL_ERR_AGAIN : steps[i].fn(c);
		if (rc == GL_OK && c->failed_step)
			rc = GL_ERR_MISMATCH;
		if (rc == GL_ERR_AGAIN && !c->failed_step)
			re_comm_add(
			    c, steps[i].name, "interrupted", RE_COMM_FAIL,
			    "run the commissioning again from the start",
			    "the run was interrupted (Ctrl-C or a "
			    "signal) during this step");
		else if (rc != GL_OK && !c->failed_step)
			rc_link_fail(c, steps[i].name, "the step", rc);
	}
	if (rc_safe(c) != GL_OK)
		re_comm_add(c, "end", "safe", RE_COMM_FAIL,
			    "press the hardware E-stop and check the relay "
			    "and the link",
			    "the motors off and the relay off were not both "
			    "confirmed at the end of the run");
	return rc;
}
