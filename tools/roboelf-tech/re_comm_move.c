/*
 * re_comm_move.c - commissioning steps 7 and 8, the only ones with motor
 * power: the relay seen switching the amplifiers' power (_TA0 bit 3, the
 * under-voltage of axes A-D on a DMC-40x0: command reference, TA), and per
 * axis a small torque-limited move each way, in which the encoder must
 * count with the motor and the potentiometer move the configured way;
 * then the firmware probes that need motion (MO refused while moving, PT).
 *
 * Each step asks the technician before the relay closes and ends with
 * rc_safe() (AB 1;MO ABC, relay off) on every path. A move is short
 * (c->move_counts), slow (RC_MOVE_CPS), torque-limited (at most
 * RC_MOVE_TL_V) and watched: with an encoder that counts against its
 * motor the servo runs away until the position error exceeds ER and OE
 * switches the motor off - the configuration's ER (below step_counts)
 * bounds how far it goes.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "re_comm.h"
#include "re_comm_steps.h"
#include "re_comm_util.h"
#include "re_ctl.h"
#include "re_dmcif.h"
#include "re_fault.h"
#include "re_plan.h"

#define TA_UNDERVOLT 8	  /* _TA0 bit 3: under-voltage, axes A-D */
#define RC_AMP_MS    1000 /* the amplifiers see power change within */
#define RC_MOVE_CPS  RE_COMM_MOVE_CPS
#define RC_MOVE_TL_V 2.0  /* torque limit during the moves, V */
#define RC_MOVE_MS   4000 /* deadline of one small move */
#define RC_SAMPLE_MS 10

/* The relay step's lanes: bit 0 the relay on (@relay), bit 1 the
 * amplifiers see power (_TA0 bit 3 clear). */
static void amp_mark(struct re_comm *c, struct re_comm_lanes *l,
		     unsigned relay, int ta0)
{
	if (l)
		rc_lane_mark(c, l, relay | (ta0 & TA_UNDERVOLT ? 0u : 2u));
}

/* Wait until _TA0 bit 3 is @want (1 set, 0 clear): the time it took,
 * ms, or -1 after RC_AMP_MS. Each reading goes to the lanes @l (NULL:
 * none) with the relay's state @relay. */
static int amp_wait(struct re_comm *c, int want, struct re_comm_lanes *l,
		    unsigned relay, double *ms, int *ta0)
{
	double t0 = rc_now_ms(c), v = 0;
	int rc;

	for (;;) {
		if ((rc = rc_num(c, "_TA0", &v)) != GL_OK)
			return rc;
		*ta0 = (int)v;
		amp_mark(c, l, relay, *ta0);
		*ms = rc_now_ms(c) - t0;
		if (((*ta0 & TA_UNDERVOLT) != 0) == want)
			return GL_OK;
		if (*ms > RC_AMP_MS) {
			*ms = -1;
			return GL_OK;
		}
		rc_sleep_ms(c, RC_SAMPLE_MS);
	}
}

/* Motor power on after the technician said yes; the power output too. */
static int power_on(struct re_comm *c, const char *why)
{
	char q[256], cmd[16];
	int pout = c->cfg->controller.power_output;

	snprintf(q, sizeof(q),
		 "motor power will be switched ON for %s (the motors stay "
		 "off until a move). Switch it on?",
		 why);
	if (!c->ui.confirm || !c->ui.confirm(c->ui.ud, q)) {
		re_comm_add(c, why, "confirm", RE_COMM_FAIL,
			    "run the commissioning again and answer y when "
			    "the robot is clear",
			    "the technician did not confirm motor power on");
		return GL_ERR_MISMATCH;
	}
	if (re_relay_on(c->relay) != GL_OK) {
		re_comm_add(c, why, "relay", RE_COMM_FAIL,
			    "check the relay board's USB connection and "
			    "relay.port / relay.protocol in the configuration",
			    "cannot switch the relay on: %s",
			    re_relay_errmsg(c->relay));
		return GL_ERR_RELAY;
	}
	c->power_on_seen = true;
	snprintf(cmd, sizeof(cmd), "SB %d", pout);
	return pout ? (rc_cmd(c, cmd, NULL, 0) < 0 ? GL_ERR_CTRL : GL_OK)
		    : GL_OK;
}

/* The relay closed and the amplifiers still see no power. */
static int close_fail(struct re_comm *c, int ta0)
{
	re_comm_add(c, "relay", "close", RE_COMM_FAIL,
		    "check the motor power supply, the relay's contacts and "
		    "controller.power_output",
		    "relay ON: the amplifiers still report under-voltage after "
		    "%d ms (MG _TA0 = %d)",
		    RC_AMP_MS, ta0);
	return GL_OK;
}

int rc_step_relay(struct re_comm *c)
{
	double ms, v = 0;
	int rc, ta0;

	rc_lane_start(c, &c->amp);
	if ((rc = rc_num(c, "_TA0", &v)) != GL_OK)
		return rc;
	amp_mark(c, &c->amp, 0, (int)v);
	if (!((int)v & TA_UNDERVOLT)) {
		re_comm_add(c, "relay", "open", RE_COMM_FAIL,
			    "wire the relay's contacts into the amplifiers' "
			    "power supply (docs/technician.md, section 3); "
			    "then the E-stop relay cuts motor power",
			    "with the relay OFF the amplifiers report power "
			    "(MG _TA0 = %d, bit 3 'under-voltage' clear; "
			    "reference: TA): the relay does not switch the "
			    "motors' power",
			    (int)v);
		return GL_OK;
	}
	re_comm_add(c, "relay", "open", RE_COMM_PASS, NULL,
		    "relay off: MG _TA0 = %d, bit 3 (under-voltage, axes "
		    "A-D; reference: TA) set: no motor power",
		    (int)v);
	if ((rc = power_on(c, "relay")) != GL_OK)
		return rc == GL_ERR_MISMATCH || rc == GL_ERR_RELAY ? GL_OK : rc;
	rc_lane_ask(c, &c->amp, "relay ON");
	if ((rc = amp_wait(c, 0, &c->amp, 1, &ms, &ta0)) != GL_OK)
		return rc;
	if (ms < 0)
		return close_fail(c, ta0);
	re_comm_add(c, "relay", "close", RE_COMM_PASS, NULL,
		    "relay ON: bit 3 of _TA0 cleared after %.0f ms", ms);
	if ((rc = c->io->ops->relay_off(c->io->ud)) != GL_OK)
		return rc;
	rc_lane_ask(c, &c->amp, "relay OFF");
	if ((rc = amp_wait(c, 1, &c->amp, 0, &ms, &ta0)) != GL_OK)
		return rc;
	if (ms < 0)
		re_comm_add(c, "relay", "reopen", RE_COMM_FAIL,
			    "the relay's contacts may be welded: replace the "
			    "relay; press the hardware E-stop meanwhile",
			    "relay OFF (confirmed by the board): the "
			    "amplifiers still report power after %d ms",
			    RC_AMP_MS);
	else
		re_comm_add(c, "relay", "reopen", RE_COMM_PASS, NULL,
			    "relay OFF: bit 3 of _TA0 set again after %.0f ms",
			    ms);
	return GL_OK;
}

/* Mean of @n readings of analog input @in, V. */
static int pot_mean(struct re_comm *c, int in, int n, double *mean)
{
	char ex[16];
	double v, sum = 0;
	int rc;

	snprintf(ex, sizeof(ex), "@AN[%d]", in);
	for (int i = 0; i < n; i++) {
		if ((rc = rc_num(c, ex, &v)) != GL_OK)
			return rc;
		sum += v;
	}
	*mean = sum / n;
	return GL_OK;
}

/* One sample of axis @x in the service state, carrying the heartbeat:
 * encoder, pot, the program's state, profiler running. */
static int move_sample(struct re_comm *c, char x, int in, double *v)
{
	char line[80], resp[160], *p, *end;
	int rc;

	c->hbpc = (c->hbpc + 1) % RE_HBPC_WRAP;
	snprintf(line, sizeof(line),
		 "hbpc=%ld;MG _TP%c;MG @AN[%d];MG state;MG _BG%c", c->hbpc, x,
		 in, x);
	if ((rc = rc_cmd(c, line, resp, sizeof(resp))) < 0)
		return rc;
	p = resp;
	for (int i = 0; i < 4; i++, p = end) {
		v[i] = strtod(p, &end);
		if (end == p)
			return GL_ERR_PROTO;
	}
	return GL_OK;
}

/* Wait @ms in the service state, the heartbeat going every sample. */
static int hb_wait(struct re_comm *c, int ax, int ms)
{
	double v[4], t0 = rc_now_ms(c);
	int rc;

	while (rc_now_ms(c) - t0 < ms) {
		rc_sleep_ms(c, RC_SAMPLE_MS);
		if ((rc = move_sample(c, (char)('A' + ax),
				      c->cfg->axes[ax].analog.input, v)) !=
		    GL_OK)
			return rc;
	}
	return GL_OK;
}

struct move_res {
	double enc0, enc1, pot0, pot1;
	double fcode, faxis; /* the fault the program latched */
	int latched, timed_out;
};

/* Ask the program for a service move of @counts on axis @ax. */
static int move_request(struct re_comm *c, int ax, double target)
{
	char cmd[80];
	int rc;

	snprintf(cmd, sizeof(cmd), "mvtg[%d]=%.0f;mvsp[%d]=%d;mvto=%d", ax,
		 target, ax, RC_MOVE_CPS, RC_MOVE_MS);
	if ((rc = rc_cmd(c, cmd, NULL, 0)) < 0)
		return rc;
	snprintf(cmd, sizeof(cmd), "mvax[0]=%d;mvax[1]=%d;mvax[2]=%d;mvreq=1",
		 ax == 0, ax == 1, ax == 2);
	return rc_cmd(c, cmd, NULL, 0) < 0 ? GL_ERR_CTRL : GL_OK;
}

/* The trace of a move asked for at @t0 (ms): the first move sets its
 * origin and start, a second one is the way back. */
static void trace_start(struct re_comm_trace *tr, int counts, double t0,
			const struct move_res *m)
{
	if (tr->n == 0) {
		tr->counts = counts;
		tr->t0_ms = t0;
		tr->enc0 = m->enc0;
		tr->pot0_v = m->pot0;
	} else if (!tr->back_i) {
		tr->back_i = tr->n;
		tr->t_back_ms = t0 - tr->t0_ms;
	}
}

/* A service move of @counts on axis @ax, sampled (into the trace when
 * @trace) until the profiler ended, a fault latched or RC_MOVE_MS. */
static int move_axis(struct re_comm *c, int ax, int counts, int trace,
		     struct move_res *m)
{
	const struct re_config_axis *a = &c->cfg->axes[ax];
	struct re_comm_trace *tr = &c->trace[ax];
	char x = (char)('A' + ax);
	double v[4], t0;
	int rc, started = 0;

	memset(m, 0, sizeof(*m));
	if ((rc = pot_mean(c, a->analog.input, 10, &m->pot0)) != GL_OK ||
	    (rc = move_sample(c, x, a->analog.input, v)) != GL_OK ||
	    (rc = move_request(c, ax, v[0] + counts)) != GL_OK)
		return rc;
	m->enc0 = v[0];
	t0 = rc_now_ms(c);
	if (trace)
		trace_start(tr, counts, t0, m);
	for (;;) {
		rc_sleep_ms(c, RC_SAMPLE_MS);
		if ((rc = move_sample(c, x, a->analog.input, v)) != GL_OK)
			return rc;
		if (trace && tr->n < RE_COMM_TRACE_N) {
			tr->t_ms[tr->n] = rc_now_ms(c) - tr->t0_ms;
			tr->enc[tr->n] = v[0];
			tr->pot_v[tr->n++] = v[1];
		}
		started |= v[3] != 0;
		m->enc1 = v[0];
		m->latched = v[2] == RE_DMC_FAULT;
		m->timed_out = rc_now_ms(c) - t0 > RC_MOVE_MS + 500;
		if ((started && v[3] == 0) || m->latched || m->timed_out)
			break;
		if (rc_quit(c))
			return GL_ERR_AGAIN;
	}
	if ((rc = hb_wait(c, ax, 100)) != GL_OK ||
	    (rc = pot_mean(c, a->analog.input, 10, &m->pot1)) != GL_OK ||
	    (rc = move_sample(c, x, a->analog.input, v)) != GL_OK)
		return rc;
	m->enc1 = v[0];
	m->latched |= v[2] == RE_DMC_FAULT;
	if (m->latched && ((rc = rc_num(c, "fcode", &m->fcode)) != GL_OK ||
			   (rc = rc_num(c, "faxis", &m->faxis)) != GL_OK))
		return rc;
	return GL_OK;
}

/* The move ended early (@m: a fault latched or the deadline passed):
 * the encoder counted against its motor, did not move, or stopped short. */
static void judge_stopped(struct re_comm *c, int ax, int counts,
			  const struct move_res *m)
{
	const struct re_config_axis *a = &c->cfg->axes[ax];
	double moved = m->enc1 - m->enc0, er = a->position_error_limit_counts;
	const char *w = re_dmc_fcode_words((int)m->fcode);
	char why[160], on[16] = "";

	if (m->faxis >= 1 && m->faxis <= RE_AXES)
		snprintf(on, sizeof(on), " on axis %s",
			 c->cfg->axes[(int)m->faxis - 1].name);
	if (m->latched)
		snprintf(why, sizeof(why),
			 "the controller program latched the fault %s%s "
			 "(code %.0f) and switched the motors off",
			 w ? w : "of an unknown code", on, m->fcode);
	else
		snprintf(why, sizeof(why), "the deadline of %d ms",
			 RC_MOVE_MS + 500);
	if (moved * counts < 0 && fabs(moved) > er / 4)
		re_comm_add(c, "motion", a->name, RE_COMM_FAIL,
			    "exchange the encoder's channels A and B "
			    "(or reverse the motor leads) of this axis",
			    "encoder reversed: asked for %+d counts, "
			    "the encoder counted %+.0f (the servo ran "
			    "away from the target) until %s: the "
			    "encoder counts against its motor",
			    counts, moved, why);
	else if (fabs(moved) < er / 4)
		re_comm_add(c, "motion", a->name, RE_COMM_FAIL,
			    "check the amplifier, the motor cable, a "
			    "brake or a jam on this axis",
			    "did not move: asked for %+d counts, the "
			    "encoder counted %+.0f before %s",
			    counts, moved, why);
	else
		re_comm_add(c, "motion", a->name, RE_COMM_FAIL,
			    "check the axis for a jam and the gains "
			    "(kp, ki, kd) and torque_limit_v",
			    "stopped short: %+.0f of %+d counts before "
			    "%s",
			    moved, counts, why);
}

/* The potentiometer against the encoder, which counted @moved of the
 * @counts asked for: reversed, not following, or as the configuration
 * expects for @counts. */
static void judge_pot(struct re_comm *c, int ax, int counts, double moved,
		      const struct move_res *m)
{
	const struct re_config_axis *a = &c->cfg->axes[ax];
	double dv = m->pot1 - m->pot0,
	       exp = (a->analog.forward_v - a->analog.reverse_v) * counts /
		     a->travel_counts;
	char fix[RE_COMM_FIX];

	snprintf(fix, sizeof(fix),
		 "exchange the potentiometer's two outer wires (supply and "
		 "ground) on analog input %d, or mount it the other way",
		 a->analog.input);
	if (dv * exp < 0 && fabs(dv) > fabs(exp) / 2)
		re_comm_add(c, "motion", a->name, RE_COMM_FAIL, fix,
			    "potentiometer reversed: %+.4f V for %+.0f counts "
			    "where the configuration (reverse_v %.2f V, "
			    "forward_v %.2f V) expects %+.4f V",
			    dv, moved, a->analog.reverse_v, a->analog.forward_v,
			    exp);
	else if (fabs(dv) < fabs(exp) / 4)
		re_comm_add(c, "motion", a->name, RE_COMM_FAIL,
			    "check the potentiometer's coupling to this axis "
			    "and analog.input",
			    "the potentiometer did not follow: %+.4f V for "
			    "%+.0f counts, %+.4f V expected",
			    dv, moved, exp);
	else
		re_comm_add(c, "motion", a->name, RE_COMM_PASS, NULL,
			    "potentiometer: %+.4f V for %+.0f counts (%+.4f V "
			    "expected from reverse_v, forward_v and "
			    "travel_counts)",
			    dv, moved, exp);
}

/* Encoder against the motor, then the potentiometer against the encoder. */
static void move_judge(struct re_comm *c, int ax, int counts,
		       const struct move_res *m)
{
	const struct re_config_axis *a = &c->cfg->axes[ax];
	double moved = m->enc1 - m->enc0;

	if (m->latched || m->timed_out) {
		judge_stopped(c, ax, counts, m);
		return;
	}
	if (fabs(moved - counts) > a->position_error_limit_counts) {
		re_comm_add(c, "motion", a->name, RE_COMM_FAIL,
			    "check the encoder's resolution and wiring",
			    "commanded %+d counts, the encoder counted %+.0f",
			    counts, moved);
		return;
	}
	re_comm_add(
	    c, "motion", a->name, RE_COMM_PASS, NULL,
	    "encoder: asked the program for %+d counts at %d counts/s, TL at "
	    "most %.1f V: counted %+.0f with the motor",
	    counts, RC_MOVE_CPS, RC_MOVE_TL_V, moved);
	judge_pot(c, ax, counts, moved, m);
}

/* Wait until the profiler of @x stopped (_BGx 0), at most 2 s. */
static int wait_stopped(struct re_comm *c, char x)
{
	char ex[8];
	double v = 1, t0 = rc_now_ms(c);
	int rc;

	snprintf(ex, sizeof(ex), "_BG%c", x);
	while ((rc = rc_num(c, ex, &v)) == GL_OK && v != 0 &&
	       rc_now_ms(c) - t0 < 2000)
		rc_sleep_ms(c, RC_SAMPLE_MS);
	return rc == GL_OK && v != 0 ? GL_ERR_TIMEOUT : rc;
}

/* MO while the profiler runs: reference (MO) "Not valid while in motion".
 * dmc/ sends AB 1 before MO ABC: safe either way. */
static int probe_mo_moving(struct re_comm *c)
{
	int code = 0, rc;
	char seen[160] = "accepted (the motor went off while moving; dmc/ "
			 "and roboelf send AB 1 first, galil-load waits for "
			 "the stop: safe)";

	if ((rc = rc_cmd(c, "SH A;SPA=1000;PRA=300;BG A", NULL, 0)) < 0)
		return rc;
	rc_sleep_ms(c, 50);
	rc = rc_cmd(c, "MO A", NULL, 0);
	if (rc == GL_ERR_CTRL) {
		const char *tc = rc_tc(c, &code);

		snprintf(seen, sizeof(seen), "?, TC1 %d %s", code, tc);
	} else if (rc < 0) {
		return rc;
	}
	re_comm_add(c, "firmware", "mo-moving",
		    rc == GL_ERR_CTRL ? RE_COMM_PASS : RE_COMM_NOTE, NULL,
		    "MO A during a 300-count move; reference (MO): not "
		    "valid while in motion; seen %s",
		    seen);
	if ((rc = rc_cmd(c, "ST A", NULL, 0)) < 0 ||
	    (rc = wait_stopped(c, 'A')) != GL_OK)
		return rc;
	return rc_cmd(c, "MO A", NULL, 0) < 0 ? GL_ERR_CTRL : GL_OK;
}

/* PT 1 on A, then PA retargets without BG (dmc/'s joystick motion). */
static int probe_pt(struct re_comm *c)
{
	double p0 = 0, p = 0, t0;
	char cmd[64];
	int rc;

	if ((rc = rc_cmd(c, "SH A;SPA=1000", NULL, 0)) < 0 ||
	    (rc = rc_num(c, "_TPA", &p0)) != GL_OK)
		return rc;
	snprintf(cmd, sizeof(cmd), "PT 1;PAA=%.0f", p0 + 300);
	rc = rc_cmd(c, cmd, NULL, 0);
	if (rc == GL_ERR_CTRL) {
		int code = 0;
		const char *tc = rc_tc(c, &code);

		re_comm_add(c, "firmware", "pt-tracking", RE_COMM_FAIL,
			    "this firmware lacks position tracking: the armed "
			    "joystick motion of dmc/ needs PT (ask Galil for a "
			    "firmware that has it)",
			    "PT 1;PAA=...; seen ?, TC1 %d %s", code, tc);
		return GL_OK;
	}
	if (rc < 0)
		return rc;
	t0 = rc_now_ms(c);
	while ((rc = rc_num(c, "_TPA", &p)) == GL_OK &&
	       fabs(p - (p0 + 300)) > 2 && rc_now_ms(c) - t0 < 1500)
		rc_sleep_ms(c, RC_SAMPLE_MS);
	if (rc != GL_OK)
		return rc;
	re_comm_add(c, "firmware", "pt-tracking",
		    fabs(p - (p0 + 300)) <= 2 ? RE_COMM_PASS : RE_COMM_FAIL,
		    "the armed joystick motion of dmc/ needs PT to retarget "
		    "the move with PA: check the firmware revision with Galil",
		    "PT 1, then PAA=%.0f without BG; reference (PT): the axis "
		    "follows each new PA target; the axis went from %.0f to "
		    "%.0f",
		    p0 + 300, p0, p);
	if ((rc = rc_cmd(c, "ST A", NULL, 0)) < 0 ||
	    (rc = wait_stopped(c, 'A')) != GL_OK)
		return rc;
	return rc_cmd(c, "MO A", NULL, 0) < 0 ? GL_ERR_CTRL : GL_OK;
}

/* TL of every axis at most RC_MOVE_TL_V (@restore 0), or back to the
 * values in @tl (@restore 1). */
static int torque(struct re_comm *c, double *tl, int restore)
{
	char cmd[80], ex[8];
	int rc, n = 0;

	for (int ax = 0; ax < RE_AXES; ax++) {
		snprintf(ex, sizeof(ex), "_TL%c", 'A' + ax);
		if (!restore && (rc = rc_num(c, ex, &tl[ax])) != GL_OK)
			return rc;
		n += snprintf(cmd + n, sizeof(cmd) - (size_t)n, "%sTL%c=%.4f",
			      ax ? ";" : "", 'A' + ax,
			      restore ? tl[ax] : fmin(tl[ax], RC_MOVE_TL_V));
	}
	return rc_cmd(c, cmd, NULL, 0) < 0 ? GL_ERR_CTRL : GL_OK;
}

/* The program started with its parameters, in the service state with
 * motor power on. */
static int enter_service(struct re_comm *c)
{
	struct re_ctl_info info = {0};
	struct re_plan plan;
	struct re_fault f;
	char err[256];
	double ms;
	int rc, ta0;

	re_plan_make(c->cfg, 0, &plan);
	if (re_ctl_start_program(c->io, &info, err, sizeof(err)) != GL_OK ||
	    (re_plan_make(c->cfg, info.mainms, &plan),
	     re_ctl_write_params(c->io, c->cfg, &plan, NULL, err,
				 sizeof(err)) != GL_OK)) {
		re_comm_add(c, "motion", "program", RE_COMM_FAIL,
			    "load dmc/ with galil-load (section 4) and run the "
			    "commissioning again",
			    "the controller program, which supervises the "
			    "moves, could not be started: %s",
			    err);
		return GL_OK;
	}
	if ((rc = power_on(c, "motion")) != GL_OK)
		return rc == GL_ERR_MISMATCH || rc == GL_ERR_RELAY ? GL_OK : rc;
	if ((rc = amp_wait(c, 0, NULL, 1, &ms, &ta0)) != GL_OK)
		return rc;
	c->hbpc = re_ctl_session();
	rc = re_ctl_service(c->io, &c->hbpc, &f, err, sizeof(err));
	if (rc == RE_FAULT)
		re_fault_what(&f, NULL, err, sizeof(err));
	if (rc == RE_FAULT || rc == GL_ERR_TIMEOUT)
		re_comm_add(c, "motion", "service", RE_COMM_FAIL,
			    "read the fault in docs/operator.md; correct the "
			    "configuration or the wiring it names",
			    "the controller program refused its service state: "
			    "%s",
			    err);
	return rc == RE_FAULT || rc == GL_ERR_TIMEOUT ? GL_OK : rc;
}

/* Each axis +move_counts and back, asked of the program. */
static int moves(struct re_comm *c)
{
	struct move_res m;
	int rc = GL_OK;

	for (int ax = 0; ax < RE_AXES && !c->failed_step; ax++) {
		rc_say(c, "axis %s: a %+d-count move and back",
		       c->cfg->axes[ax].name, c->move_counts);
		if ((rc = move_axis(c, ax, c->move_counts, 1, &m)) != GL_OK)
			return rc;
		move_judge(c, ax, c->move_counts, &m);
		if (c->failed_step ||
		    (rc = move_axis(c, ax, -c->move_counts, 1, &m)) != GL_OK)
			return rc;
	}
	return rc;
}

int rc_step_motion(struct re_comm *c)
{
	double tl[RE_AXES];
	char err[256];
	int rc;

	if ((rc = torque(c, tl, 0)) != GL_OK)
		return rc;
	rc = enter_service(c);
	if (rc == GL_OK && !c->failed_step)
		rc = moves(c);
	if (rc == GL_OK && !c->failed_step &&
	    re_ctl_off(c->io, &c->hbpc, err, sizeof(err)) != GL_OK)
		rc = GL_ERR_TIMEOUT;
	/* the bounded direct probes need the program halted, and run under
	 * its probe watchdog (#PRWD): a run that dies leaves nothing on */
	if (rc == GL_OK && !c->failed_step &&
	    (rc = re_ctl_halt(c->io, err, sizeof(err))) == GL_OK &&
	    (rc = rc_guard(c, 1)) == GL_OK) {
		if ((rc = probe_mo_moving(c)) == GL_OK)
			rc = probe_pt(c);
		if (rc_guard(c, 0) != GL_OK && rc == GL_OK)
			rc = GL_ERR_CTRL;
	}
	if (rc_safe(c) != GL_OK && rc == GL_OK)
		rc = GL_ERR_RELAY;
	if (torque(c, tl, 1) != GL_OK && rc == GL_OK)
		rc = GL_ERR_CTRL;
	return rc;
}
