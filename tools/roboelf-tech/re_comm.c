/*
 * re_comm.c - the commissioning run: the steps in order, the report items,
 * and the small controller helpers the step modules share.
 *
 * The run's first step checks what the run needs (the relay, the
 * controller, the program galil-load stamped) before any prompt.
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
#include "re_ctl.h"
#include "re_plan.h"

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

#define NEEDS_FIX                                                               \
	"load dmc/ with galil-load --config and the configuration this run "   \
	"uses (docs/technician.md, section 4), then run the commissioning "   \
	"again"

/* The program tried as roboelf's start-up does, motor power off: started
 * (XQ #AUTO,0: its version, its heartbeat), its parameters written and
 * read back; then halted, every motor read back off, and the controller
 * configured again (the program's start may change settings). */
static int try_program(struct re_comm *c, struct re_ctl_info *info, char *err,
		       size_t cap)
{
	struct re_plan plan;
	int rc;

	re_plan_make(c->cfg, 0, &plan);
	if ((rc = re_ctl_start_program(c->io, info, err, cap)) != GL_OK)
		return rc;
	re_plan_make(c->cfg, info->mainms, &plan);
	if ((rc = re_ctl_write_params(c->io, c->cfg, &plan, NULL, err, cap)) !=
	    GL_OK)
		return rc;
	if ((rc = re_ctl_halt(c->io, err, cap)) != GL_OK)
		return rc;
	re_plan_make(c->cfg, 0, &plan);
	return re_ctl_configure(c->io, c->cfg, &plan, err, cap);
}

/* The program galil-load stamped and sealed with this configuration: the
 * motion step and the probes' watchdog (#PRWD) run in it. */
static int needs_program(struct re_comm *c)
{
	static struct re_seal seal; /* start-up code: one run at a time */
	struct re_ctl_info info = {0};
	char err[512];
	int rc;

	if (!c->link) {
		re_comm_add(c, "needs", "program", RE_COMM_FAIL, NEEDS_FIX,
			    "no command link to read the controller's "
			    "program (UL) on");
		return GL_ERR_MISMATCH;
	}
	rc = re_ctl_check_program(c->link, c->cfg, &info, &seal, err,
				  sizeof(err));
	if (rc == GL_OK)
		rc = try_program(c, &info, err, sizeof(err));
	if (rc == GL_ERR_MISMATCH || rc == GL_ERR_TIMEOUT || rc == GL_ERR_CTRL ||
	    rc == GL_ERR_FORMAT) {
		re_comm_add(c, "needs", "program", RE_COMM_FAIL, NEEDS_FIX,
			    "%s", err);
		return GL_ERR_MISMATCH;
	}
	if (rc != GL_OK)
		return rc;
	re_comm_add(c, "needs", "program", RE_COMM_PASS, NULL,
		    "UL: galil-load's stamp %016llX matches the uploaded text "
		    "(reference UL: the program as downloaded), sealed with "
		    "the %d values of this configuration; started (XQ "
		    "#AUTO,0), its parameters read back, halted again with "
		    "every motor off",
		    (unsigned long long)info.program_id, seal.n);
	return GL_OK;
}

/* Step 1: what the run needs, before anything is asked of the technician:
 * the relay, the controller, the program (the motion step needs it; a
 * run that found it missing only at its end wasted every hand check). */
static int step_needs(struct re_comm *c)
{
	char why[256] = "";
	double serial = 0;
	int rc = c->io->ops->relay_check(c->io->ud, why, sizeof(why));

	if (rc != GL_OK) {
		re_comm_add(c, "needs", "relay", RE_COMM_FAIL,
			    "check the relay board's USB connection and "
			    "relay.port / relay.protocol in the configuration",
			    "the E-stop relay does not answer: %s", why);
		return GL_ERR_MISMATCH;
	}
	re_comm_add(c, "needs", "relay", RE_COMM_PASS, NULL,
		    "the E-stop relay answers and is off: no motor power");
	if ((rc = rc_num(c, "_BN", &serial)) != GL_OK)
		return rc;
	re_comm_add(c, "needs", "controller", RE_COMM_PASS, NULL,
		    "the controller at %s answers (MG _BN %.0f)",
		    c->cfg->controller.address, serial);
	return needs_program(c);
}

static const struct {
	const char *name;
	const char *what;
	int (*fn)(struct re_comm *c);
} steps[] = {
    {"needs", "what the run needs: the relay, the controller, the program",
     step_needs},
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
