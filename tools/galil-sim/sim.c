/*
 * sim.c - the simulator facade: controller + plant + relay stepped together
 * in simulated time, and the event log. The control-port requests are in
 * sim_control.c.
 *
 * Time is counted in whole microseconds of simulated time (samples of
 * ctrl_sample_ms() each), so long runs do not drift.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "sim.h"
#include "sim_plant.h"
#include "sim_relay.h"
#include "sim_int.h"

/* ---- events ----------------------------------------------------------- */

static void event_put(struct sim *s, const char *text)
{
	struct sim_evt *e;

	if (s->ev_count == SIM_EVENTS_MAX) {
		s->ev_head = (s->ev_head + 1) % SIM_EVENTS_MAX;
		s->ev_count--;
		s->ev_lost++;
	}
	e = &s->ev[(s->ev_head + s->ev_count) % SIM_EVENTS_MAX];
	e->t_us = s->time_us;
	snprintf(e->text, sizeof(e->text), "%s", text);
	s->ev_count++;
	if (s->hook)
		s->hook(s->hook_ud, s->time_us / 1000.0, e->text);
}

void sim_event(struct sim *s, const char *fmt, ...)
{
	char text[SIM_EVENT_LEN];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(text, sizeof(text), fmt, ap);
	va_end(ap);
	event_put(s, text);
}

static void event_cb(void *ud, const char *line)
{
	event_put(ud, line);
}

void sim_set_event_hook(struct sim *s,
			void (*fn)(void *ud, double t_ms, const char *text),
			void *ud)
{
	s->hook = fn;
	s->hook_ud = ud;
}

/* ---- deviations -------------------------------------------------------- */

unsigned sim_deviation_bit(const char *name)
{
	static const struct {
		const char *name;
		unsigned bit;
	} dev[] = {
	    {"mg-join", CTRL_DEV_MG_JOIN},
	    {"dm-exists", CTRL_DEV_DM_EXISTS},
	    {"qr-header", CTRL_DEV_QR_HEADER},
	    {"ul-trim", CTRL_DEV_UL_TRIM},
	    {"mo-moving", CTRL_DEV_MO_MOVING},
	    {"za-16bit", CTRL_DEV_ZA_16BIT},
	};

	for (size_t i = 0; i < sizeof(dev) / sizeof(dev[0]); i++)
		if (!strcmp(name, dev[i].name))
			return dev[i].bit;
	return 0;
}

/* ---- life cycle ------------------------------------------------------- */

static int make_parts(struct sim *s, const struct sim_plant_cfg *pc,
		      long serial)
{
	struct ctrl_cfg cc = {
	    .model = SIM_MODEL,
	    .serial = serial,
	    .sample_us = SIM_SAMPLE_US,
	    .event = event_cb,
	    .event_ud = s,
	};
	int rc = sim_plant_new(&s->plant, pc);

	if (rc < 0)
		return rc;
	rc = sim_relay_new(&s->relay, SIM_RELAY_DEVANTECH, event_cb, s);
	if (rc < 0)
		return rc;
	s->ctrl = ctrl_new(&cc);
	return s->ctrl ? 0 : GL_ERR_NOMEM;
}

int sim_new(struct sim **out, const char *plant_file, char *err, size_t errlen)
{
	return sim_new_serial(out, plant_file, 0, err, errlen);
}

int sim_new_serial(struct sim **out, const char *plant_file, long serial,
		   char *err, size_t errlen)
{
	struct sim_plant_cfg pc;
	struct sim *s;
	int rc;

	*out = NULL;
	sim_plant_cfg_default(&pc);
	if (plant_file && sim_plant_cfg_load(&pc, plant_file, err, errlen) < 0)
		return GL_ERR_CONFIG;
	s = calloc(1, sizeof(*s));
	if (!s)
		return GL_ERR_NOMEM;
	s->ev = calloc(SIM_EVENTS_MAX, sizeof(*s->ev));
	rc = s->ev ? make_parts(s, &pc, serial > 0 ? serial : SIM_SERIAL)
		   : GL_ERR_NOMEM;
	if (rc < 0) {
		snprintf(err, errlen, "cannot create the simulator: %s",
			 gl_strerror(rc));
		sim_free(s);
		return rc;
	}
	sim_plant_sense(s->plant, 0, &s->sense);
	*out = s;
	return 0;
}

void sim_free(struct sim *s)
{
	if (!s)
		return;
	if (s->ctrl)
		ctrl_free(s->ctrl);
	sim_relay_free(s->relay);
	sim_plant_free(s->plant);
	free(s->ev);
	free(s);
}

const char *sim_model(const struct sim *s)
{
	(void)s; /* every simulator is the same model (make_parts()) */
	return SIM_MODEL;
}

struct ctrl *sim_ctrl(struct sim *s)
{
	return s->ctrl;
}

struct sim_plant *sim_get_plant(struct sim *s)
{
	return s->plant;
}

struct sim_relay *sim_get_relay(struct sim *s)
{
	return s->relay;
}

void sim_seed(struct sim *s, unsigned long seed)
{
	sim_plant_seed(s->plant, seed);
}

int sim_attach_relay(struct sim *s, const char *protocol, const char *link_path,
		     char *err, size_t errlen)
{
	enum sim_relay_proto proto;
	struct sim_relay *r;
	int rc;

	if (sim_relay_proto_parse(protocol, &proto) < 0) {
		snprintf(err, errlen,
			 "unknown relay protocol '%s' (devantech, "
			 "icstation, lcus, kmtronic)",
			 protocol);
		return GL_ERR_ARG;
	}
	rc = sim_relay_new(&r, proto, event_cb, s);
	if (rc < 0) {
		snprintf(err, errlen, "%s", gl_strerror(rc));
		return rc;
	}
	rc = sim_relay_attach(r, link_path, err, errlen);
	if (rc < 0) {
		sim_relay_free(r);
		return rc;
	}
	sim_relay_free(s->relay);
	s->relay = r;
	return 0;
}

/* ---- time ------------------------------------------------------------- */

/*
 * The physical limit switches, as events. (The controller's own events
 * report its reactions: motor off and why, limit stops, threads started
 * and stopped, program errors.)
 */
static void watch_changes(struct sim *s)
{
	for (int i = 0; i < CTRL_AXES; i++) {
		char a = (char)('A' + i);

		if (s->sense.fwd_limit[i] != s->prev_lf[i])
			sim_event(s, "%c forward limit switch %s", a,
				  s->sense.fwd_limit[i] ? "active"
							: "released");
		if (s->sense.rev_limit[i] != s->prev_lr[i])
			sim_event(s, "%c reverse limit switch %s", a,
				  s->sense.rev_limit[i] ? "active"
							: "released");
		s->prev_lf[i] = s->sense.fwd_limit[i];
		s->prev_lr[i] = s->sense.rev_limit[i];
	}
}

/* Motor power now: the relay, and the controller's power output if the
 * plant has one (power_output). */
static int motor_power(const struct sim *s)
{
	return sim_plant_motor_power(s->plant, sim_relay_power(s->relay),
				     ctrl_outputs(s->ctrl));
}

/*
 * The power path as events: the controller's power output changing, and,
 * with the amplifiers' under-voltage model off, motor power itself (the
 * controller then reports nothing of it).
 */
static void watch_power(struct sim *s, int power)
{
	const struct sim_plant_cfg *pc = sim_plant_get_cfg(s->plant);
	int n = pc->power_output;
	int out = n > 0 && ((ctrl_outputs(s->ctrl) >> (n - 1)) & 1);

	if (n > 0 && out != s->prev_pout)
		sim_event(s,
			  out ? "power output %d set"
			      : "power output %d cleared (motor power cut by "
				"the controller)",
			  n);
	s->prev_pout = out;
	if (!pc->amp_undervoltage && power != s->prev_power)
		sim_event(s, power ? "motor power restored (under-voltage "
				     "model off)"
				   : "motor power lost (amplifiers report "
				     "nothing: under-voltage model off)");
	s->prev_power = power;
}

void sim_step(struct sim *s)
{
	int power = motor_power(s);
	double dt_ms = ctrl_sample_ms(s->ctrl);

	watch_power(s, power);
	sim_plant_sense(s->plant, power, &s->sense);
	ctrl_step(s->ctrl, &s->sense, &s->drive);
	sim_plant_move(s->plant, &s->drive, power, dt_ms);
	watch_changes(s);
	/* at least 1 us per sample, so that time always advances */
	s->time_us += dt_ms >= 0.001 ? (int64_t)llround(dt_ms * 1000) : 1;
}

void sim_advance_ms(struct sim *s, double ms)
{
	int64_t end = s->time_us + (int64_t)llround(ms * 1000);

	while (s->time_us < end)
		sim_step(s);
}

double sim_time_ms(const struct sim *s)
{
	return s->time_us / 1000.0;
}

void sim_fmt_ms(char *buf, size_t cap, int64_t t_us)
{
	if (t_us % 1000 == 0)
		snprintf(buf, cap, "%lld", (long long)(t_us / 1000));
	else
		snprintf(buf, cap, "%.3f", t_us / 1000.0);
}

void sim_power_cycle(struct sim *s)
{
	if (s->disconnect)
		s->disconnect(s->disconnect_ud);
	sim_event(s, "controller power cycle");
	sim_plant_zero_encoders(s->plant);
	ctrl_power_cycle(s->ctrl);
}

int sim_power(const struct sim *s)
{
	return motor_power(s);
}

static const char *const line_fault_words[] = {
    "none",	"delay", "qmark", "split",  "chunks",	"garbage", "unsol",
    "unsolpre", "extra", "drop",  "silent", "dlreject", "badhdr",
};

const char *sim_line_fault_name(enum sim_line_kind kind)
{
	return kind >= SIM_LINE_NONE && kind <= SIM_LINE_BADHDR
		   ? line_fault_words[kind]
		   : "?";
}

/* The argument a line fault takes: 0 none, 1 optional ms, 2 required. */
static int line_fault_arg(enum sim_line_kind k, const char *arg, int *out,
			  const char **why)
{
	char *end;
	long v;

	*out = 0;
	if (k != SIM_LINE_DELAY && k != SIM_LINE_EXTRA &&
	    k != SIM_LINE_DLREJECT) {
		*why = "takes no argument";
		return arg ? GL_ERR_ARG : 0;
	}
	if (!arg) {
		*why = "needs an argument";
		return k == SIM_LINE_EXTRA ? 0 : GL_ERR_ARG;
	}
	errno = 0;
	v = strtol(arg, &end, 10);
	*why = k == SIM_LINE_DLREJECT ? "bad line number (1..4000)"
				      : "bad delay (0..60000 ms)";
	if (*end || end == arg || errno ||
	    (k == SIM_LINE_DLREJECT ? v < 1 || v > 4000 : v < 0 || v > 60000))
		return GL_ERR_ARG;
	*out = (int)v;
	return 0;
}

int sim_line_fault_parse(const char *word, const char *arg,
			 struct sim_line_fault *out, const char **why)
{
	int a;

	for (int k = SIM_LINE_DELAY; k <= SIM_LINE_BADHDR; k++) {
		if (strcmp(word, line_fault_words[k]))
			continue;
		if (line_fault_arg((enum sim_line_kind)k, arg, &a, why) < 0)
			return GL_ERR_ARG;
		out->kind = (enum sim_line_kind)k;
		out->arg = a;
		return 0;
	}
	*why = "unknown";
	return GL_ERR_ARG;
}

int sim_line_fault(const struct sim *s, int first, struct sim_line_fault *out)
{
	*out = first ? s->line_first : s->line_once;
	return out->kind != SIM_LINE_NONE;
}

void sim_line_fault_used(struct sim *s)
{
	s->line_once.kind = SIM_LINE_NONE;
	s->line_once.arg = 0;
}

enum sim_link sim_link(const struct sim *s, double *delay_ms)
{
	if (delay_ms)
		*delay_ms = s->link_delay_ms;
	return s->link;
}

enum sim_link sim_link_on(const struct sim *s, int stream, double *delay_ms)
{
	enum sim_link_scope other = stream ? SIM_SCOPE_TCP : SIM_SCOPE_STREAM;

	if (delay_ms)
		*delay_ms = s->link_delay_ms;
	return s->link_scope == other ? SIM_LINK_OK : s->link;
}

void sim_set_disconnect(struct sim *s, void (*fn)(void *ud), void *ud)
{
	s->disconnect = fn;
	s->disconnect_ud = ud;
}

int sim_quit_requested(const struct sim *s)
{
	return s->quit;
}
