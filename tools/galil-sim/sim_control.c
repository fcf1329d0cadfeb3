/*
 * sim_control.c - the control-port requests (docs/galil-sim.md, "Control
 * port"): joystick and input forcing, fault injection, state, events.
 *
 * One request is one line of space-separated words. Every answer is "ok",
 * a value, or "error: <reason>"; only "events" answers several lines, the
 * last one "end". Fault injections and operator inputs are logged as events
 * ("inject: ...", "input: ...") so that reaction times can be measured.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "sim.h"
#include "sim_int.h"
#include "sim_plant.h"
#include "sim_relay.h"

#define MAX_WORDS 8

struct out {
	char *buf;
	size_t cap, len;
};

struct request {
	const char *name;
	int min_args, max_args;
	int (*fn)(struct sim *s, char **arg, int n, struct out *o);
	const char *usage;
};

static void put(struct out *o, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void put(struct out *o, const char *fmt, ...)
{
	va_list ap;
	int n;

	if (o->len >= o->cap)
		return;
	va_start(ap, fmt);
	n = vsnprintf(o->buf + o->len, o->cap - o->len, fmt, ap);
	va_end(ap);
	if (n > 0)
		o->len += (size_t)n < o->cap - o->len ? (size_t)n
						      : o->cap - o->len - 1;
}

static int fail(struct out *o, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static int fail(struct out *o, const char *fmt, ...)
{
	va_list ap;

	o->len = 0;
	put(o, "error: ");
	va_start(ap, fmt);
	if (o->len < o->cap)
		vsnprintf(o->buf + o->len, o->cap - o->len, fmt, ap);
	va_end(ap);
	return GL_ERR_ARG;
}

static int ok(struct out *o)
{
	put(o, "ok");
	return 0;
}

static int parse_axis(const char *w, int *axis)
{
	if (strlen(w) != 1 || w[0] < 'A' || w[0] > 'C')
		return GL_ERR_ARG;
	*axis = w[0] - 'A';
	return 0;
}

static int parse_num(const char *w, double lo, double hi, double *v)
{
	char *end;

	errno = 0;
	*v = strtod(w, &end);
	if (end == w || *end || errno || !isfinite(*v) || *v < lo || *v > hi)
		return GL_ERR_ARG;
	return 0;
}

static int parse_int(const char *w, int lo, int hi, int *v)
{
	double d;

	if (parse_num(w, lo, hi, &d) < 0 || d != floor(d))
		return GL_ERR_ARG;
	*v = (int)d;
	return 0;
}

/* ---- operator inputs -------------------------------------------------- */

static int req_joy(struct sim *s, char **arg, int n, struct out *o)
{
	enum sim_plant_dir dir;
	unsigned chan = 3;
	int axis;

	if (parse_axis(arg[0], &axis) < 0)
		return fail(o, "bad axis '%s' (A, B or C)", arg[0]);
	if (!strcmp(arg[1], "fwd"))
		dir = SIM_PLANT_FWD;
	else if (!strcmp(arg[1], "rev"))
		dir = SIM_PLANT_REV;
	else if (!strcmp(arg[1], "neutral"))
		dir = SIM_PLANT_NEUTRAL;
	else
		return fail(o, "bad direction '%s' (fwd, rev or neutral)",
			    arg[1]);
	if (n == 3 &&
	    (strlen(arg[2]) != 1 || (arg[2][0] != 'a' && arg[2][0] != 'b')))
		return fail(o, "bad channel '%s' (a or b)", arg[2]);
	if (n == 3)
		chan = arg[2][0] == 'a' ? 1 : 2;
	sim_plant_set_joy(s->plant, axis, dir, chan);
	sim_event(s, "input: joy %s %s%s%s", arg[0], arg[1], n == 3 ? " " : "",
		  n == 3 ? arg[2] : "");
	return ok(o);
}

static int req_in(struct sim *s, char **arg, int n, struct out *o)
{
	int in, level;

	(void)n;
	if (parse_int(arg[0], 1, CTRL_INPUTS, &in) < 0)
		return fail(o, "bad input '%s' (1..%d)", arg[0], CTRL_INPUTS);
	if (parse_int(arg[1], 0, 1, &level) < 0)
		return fail(o, "bad level '%s' (0 or 1)", arg[1]);
	sim_plant_force_input(s->plant, in, level);
	sim_event(s, "inject: in %d %d", in, level);
	return ok(o);
}

static int req_an(struct sim *s, char **arg, int n, struct out *o)
{
	double v;
	int in;

	(void)n;
	if (parse_int(arg[0], 1, CTRL_ANALOG, &in) < 0)
		return fail(o, "bad analog input '%s' (1..%d)", arg[0],
			    CTRL_ANALOG);
	if (parse_num(arg[1], -10, 10, &v) < 0)
		return fail(o, "bad voltage '%s' (-10..10)", arg[1]);
	sim_plant_force_analog(s->plant, in, v);
	sim_event(s, "inject: an %d %.4f", in, v);
	return ok(o);
}

static int req_release(struct sim *s, char **arg, int n, struct out *o)
{
	int in, analog = !strcmp(arg[0], "an");

	(void)n;
	if (!analog && strcmp(arg[0], "in"))
		return fail(o, "bad kind '%s' (in or an)", arg[0]);
	if (parse_int(arg[1], 1, analog ? CTRL_ANALOG : CTRL_INPUTS, &in) < 0)
		return fail(o, "bad input '%s'", arg[1]);
	if (analog)
		sim_plant_release_analog(s->plant, in);
	else
		sim_plant_release_input(s->plant, in);
	sim_event(s, "inject: release %s %d", arg[0], in);
	return ok(o);
}

/* ---- sensor and mechanical faults ------------------------------------- */

static int req_pot(struct sim *s, char **arg, int n, struct out *o)
{
	const char *f = arg[1];
	double v = 0;
	int axis, with_value = !strcmp(f, "offset") || !strcmp(f, "noise");

	if (parse_axis(arg[0], &axis) < 0)
		return fail(o, "bad axis '%s' (A, B or C)", arg[0]);
	if (with_value != (n == 3))
		return fail(o, "usage: pot <A|B|C> <ok|offset V|stuck|open|"
			       "noise V>");
	if (with_value && parse_num(arg[2], !strcmp(f, "noise") ? 0 : -10,
				    !strcmp(f, "noise") ? 1 : 10, &v) < 0)
		return fail(o, "bad voltage '%s'", arg[2]);
	if (!strcmp(f, "noise"))
		sim_plant_set_pot_noise(s->plant, axis, v);
	else if (!strcmp(f, "ok"))
		sim_plant_set_pot_fault(s->plant, axis, SIM_PLANT_POT_OK, 0);
	else if (!strcmp(f, "offset"))
		sim_plant_set_pot_fault(s->plant, axis, SIM_PLANT_POT_OFFSET,
					v);
	else if (!strcmp(f, "stuck"))
		sim_plant_set_pot_fault(s->plant, axis, SIM_PLANT_POT_STUCK, 0);
	else if (!strcmp(f, "open"))
		sim_plant_set_pot_fault(s->plant, axis, SIM_PLANT_POT_OPEN, 0);
	else
		return fail(o,
			    "bad pot fault '%s' (ok, offset, stuck, open, "
			    "noise)",
			    f);
	sim_event(s, "inject: pot %s %s%s%s", arg[0], f, n == 3 ? " " : "",
		  n == 3 ? arg[2] : "");
	return ok(o);
}

static int req_enc(struct sim *s, char **arg, int n, struct out *o)
{
	enum sim_plant_enc_fault f;
	double c = 0;
	int axis;

	if (parse_axis(arg[0], &axis) < 0)
		return fail(o, "bad axis '%s' (A, B or C)", arg[0]);
	if (!strcmp(arg[1], "ok") && n == 2)
		f = SIM_PLANT_ENC_OK;
	else if (!strcmp(arg[1], "stuck") && n == 2)
		f = SIM_PLANT_ENC_STUCK;
	else if (!strcmp(arg[1], "slip") && n == 3)
		f = SIM_PLANT_ENC_SLIP;
	else
		return fail(o, "usage: enc <A|B|C> <ok|stuck|slip COUNTS>");
	if (n == 3 && parse_num(arg[2], -1e8, 1e8, &c) < 0)
		return fail(o, "bad count '%s'", arg[2]);
	sim_plant_set_enc_fault(s->plant, axis, f, c);
	sim_event(s, "inject: enc %s %s%s%s", arg[0], arg[1], n == 3 ? " " : "",
		  n == 3 ? arg[2] : "");
	return ok(o);
}

static int req_block(struct sim *s, char **arg, int n, struct out *o)
{
	int axis, on;

	(void)n;
	if (parse_axis(arg[0], &axis) < 0)
		return fail(o, "bad axis '%s' (A, B or C)", arg[0]);
	if (parse_int(arg[1], 0, 1, &on) < 0)
		return fail(o, "bad value '%s' (0 or 1)", arg[1]);
	sim_plant_set_block(s->plant, axis, on);
	sim_event(s, "inject: block %s %d", arg[0], on);
	return ok(o);
}

static int req_limit(struct sim *s, char **arg, int n, struct out *o)
{
	int axis, rev = !strcmp(arg[1], "rev"), held = !strcmp(arg[2], "press");

	(void)n;
	if (parse_axis(arg[0], &axis) < 0)
		return fail(o, "bad axis '%s' (A, B or C)", arg[0]);
	if (!rev && strcmp(arg[1], "fwd"))
		return fail(o, "bad switch '%s' (fwd or rev)", arg[1]);
	if (!held && strcmp(arg[2], "release"))
		return fail(o, "bad action '%s' (press or release)", arg[2]);
	sim_plant_hold_limit(s->plant, axis, rev, held);
	sim_event(s, "inject: limit %s %s %s", arg[0], arg[1], arg[2]);
	return ok(o);
}

/* ---- link, relay, controller ------------------------------------------ */

#define LINE_FAULT_USAGE                                                       \
	"usage: link <once|first> <delay MS|qmark|split|chunks|garbage|"       \
	"unsol|unsolpre|extra [MS]|drop|silent|dlreject N|badhdr>"

/* "link once FAULT [ARG]" / "link first FAULT [ARG]": a line fault. */
static int req_line_fault(struct sim *s, char **arg, int n, struct out *o)
{
	struct sim_line_fault f;
	const char *why;

	if (n < 2)
		return fail(o, LINE_FAULT_USAGE);
	if (sim_line_fault_parse(arg[1], n == 3 ? arg[2] : NULL, &f, &why) < 0)
		return fail(o, "line fault '%s': %s", arg[1], why);
	if (arg[0][0] == 'o')
		s->line_once = f;
	else
		s->line_first = f;
	sim_event(s, "inject: link %s %s%s%s", arg[0], arg[1],
		  n == 3 ? " " : "", n == 3 ? arg[2] : "");
	return ok(o);
}

#define LINK_USAGE "usage: link <ok|drop|stall|delay MS> [tcp|stream]"

/* A last word "tcp" or "stream" scopes the fault; it is taken off @n. */
static enum sim_link_scope link_scope(char **arg, int *n)
{
	if (*n > 1 && !strcmp(arg[*n - 1], "tcp")) {
		(*n)--;
		return SIM_SCOPE_TCP;
	}
	if (*n > 1 && !strcmp(arg[*n - 1], "stream")) {
		(*n)--;
		return SIM_SCOPE_STREAM;
	}
	return SIM_SCOPE_ALL;
}

static int req_link(struct sim *s, char **arg, int n, struct out *o)
{
	static const char *const scope_word[] = {"", " tcp", " stream"};
	enum sim_link_scope scope;
	enum sim_link l;
	double ms = 0;

	if (!strcmp(arg[0], "once") || !strcmp(arg[0], "first"))
		return req_line_fault(s, arg, n, o);
	scope = link_scope(arg, &n);
	if (!strcmp(arg[0], "ok") && n == 1 && scope == SIM_SCOPE_ALL)
		l = SIM_LINK_OK;
	else if (!strcmp(arg[0], "drop") && n == 1)
		l = SIM_LINK_DROP;
	else if (!strcmp(arg[0], "stall") && n == 1)
		l = SIM_LINK_STALL;
	else if (!strcmp(arg[0], "delay") && n == 2)
		l = SIM_LINK_DELAY;
	else
		return fail(o, LINK_USAGE);
	if (n == 2 && parse_num(arg[1], 0, 60000, &ms) < 0)
		return fail(o, "bad delay '%s' (0..60000 ms)", arg[1]);
	s->link = l;
	s->link_delay_ms = ms;
	s->link_scope = scope;
	if (l == SIM_LINK_OK) { /* and no line fault either */
		s->line_once.kind = s->line_first.kind = SIM_LINE_NONE;
		s->line_once.arg = s->line_first.arg = 0;
	}
	sim_event(s, "inject: link %s%s%s%s", arg[0], n == 2 ? " " : "",
		  n == 2 ? arg[1] : "", scope_word[scope]);
	if (l == SIM_LINK_DROP && s->disconnect)
		s->disconnect(s->disconnect_ud);
	return ok(o);
}

/* Why "relay on|off" cannot act: the board's fault. */
static const char *fault_word(const struct sim_relay *r)
{
	switch (sim_relay_get_fault(r)) {
	case SIM_RELAY_UNPLUG: return "unplugged";
	case SIM_RELAY_WEDGE: return "wedged";
	default: return "failing";
	}
}

static int req_relay(struct sim *s, char **arg, int n, struct out *o)
{
	if (n == 0) {
		put(o, "%s", sim_relay_power(s->relay) ? "on" : "off");
		return 0;
	}
	if (strcmp(arg[0], "on") && strcmp(arg[0], "off"))
		return fail(o, "usage: relay [on|off]");
	if (sim_relay_set(s->relay, !strcmp(arg[0], "on")) < 0)
		return fail(o, "relay is %s", fault_word(s->relay));
	return ok(o);
}

static int req_relayfault(struct sim *s, char **arg, int n, struct out *o)
{
	enum sim_relay_fault f;
	char err[160] = "";

	(void)n;
	if (!strcmp(arg[0], "ok"))
		f = SIM_RELAY_OK;
	else if (!strcmp(arg[0], "unplug"))
		f = SIM_RELAY_UNPLUG;
	else if (!strcmp(arg[0], "writefail"))
		f = SIM_RELAY_WRITEFAIL;
	else if (!strcmp(arg[0], "wedge"))
		f = SIM_RELAY_WEDGE;
	else
		return fail(o, "usage: relayfault <ok|unplug|writefail|wedge>");
	sim_event(s, "inject: relayfault %s", arg[0]);
	if (sim_relay_set_fault(s->relay, f, err, sizeof(err)) < 0)
		return fail(o, "%s", err);
	return ok(o);
}

static int req_power_cycle(struct sim *s, char **arg, int n, struct out *o)
{
	(void)arg;
	(void)n;
	sim_event(s, "inject: power-cycle");
	sim_power_cycle(s);
	return ok(o);
}

static int req_quit(struct sim *s, char **arg, int n, struct out *o)
{
	(void)arg;
	(void)n;
	s->quit = 1;
	return ok(o);
}

static int req_time(struct sim *s, char **arg, int n, struct out *o)
{
	char t[32];

	(void)arg;
	(void)n;
	sim_fmt_ms(t, sizeof(t), s->time_us);
	put(o, "%s", t);
	return 0;
}

/* ---- state, watch, events --------------------------------------------- */

static void put_axis(struct sim *s, int i, struct out *o)
{
	struct ctrl_axis_info ai;
	struct sim_plant_axis_state ps;
	const struct sim_plant_cfg *pc = sim_plant_get_cfg(s->plant);
	char a = (char)('A' + i);

	memset(&ai, 0, sizeof(ai));
	ctrl_axis_info(s->ctrl, i, &ai);
	sim_plant_axis(s->plant, i, &ps);
	put(o,
	    " %c.pos=%.0f %c.ref=%.0f %c.vel=%.0f %c.pot=%.4f %c.mo=%d "
	    "%c.sc=%d %c.lf=%d %c.lr=%d %c.act=%.0f",
	    a, ai.enc, a, ai.ref, a, ps.vel, a,
	    s->sense.an_v[pc->axis[i].pot.input - 1], a, ai.motor_off ? 1 : 0,
	    a, ai.stop_code, a, s->sense.fwd_limit[i], a, s->sense.rev_limit[i],
	    a, ps.pos);
}

/* "1" / "0": the plant's power output set / cleared; "-": none. */
static const char *power_output_state(struct sim *s)
{
	int n = sim_plant_get_cfg(s->plant)->power_output;

	if (n == 0)
		return "-";
	return (ctrl_outputs(s->ctrl) >> (n - 1)) & 1 ? "1" : "0";
}

static int req_state(struct sim *s, char **arg, int n, struct out *o)
{
	static const char *const links[] = {"ok", "drop", "stall", "delay"};
	unsigned th = ctrl_threads(s->ctrl);
	char t[32];
	double v;
	int any = 0;

	(void)arg;
	(void)n;
	sim_fmt_ms(t, sizeof(t), s->time_us);
	put(o, "time=%s relay=%s power=%d pout=%s link=%s threads=", t,
	    sim_relay_power(s->relay) ? "on" : "off", sim_power(s),
	    power_output_state(s), links[s->link]);
	for (int i = 0; i < CTRL_THREADS; i++) {
		if (th & (1u << i)) {
			put(o, "%s%d", any ? "," : "", i);
			any = 1;
		}
	}
	if (!any)
		put(o, "-");
	for (int i = 0; i < CTRL_AXES; i++)
		put_axis(s, i, o);
	for (int i = 0; i < s->nwatch; i++) {
		if (ctrl_get_var(s->ctrl, s->watch[i], &v) == 0)
			put(o, " var.%s=%.4f", s->watch[i], v);
		else
			put(o, " var.%s=?", s->watch[i]);
	}
	return 0;
}

static int valid_var(const char *name)
{
	size_t n = strlen(name);

	if (n == 0 || n >= SIM_WATCH_LEN)
		return 0;
	for (size_t i = 0; i < n; i++) {
		char c = name[i];

		if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
		      (c >= '0' && c <= '9') || c == '_' || c == '[' ||
		      c == ']' || c == '-'))
			return 0;
	}
	return 1;
}

static int req_watch(struct sim *s, char **arg, int n, struct out *o)
{
	(void)n;
	if (!valid_var(arg[0]))
		return fail(o, "bad variable name '%s'", arg[0]);
	for (int i = 0; i < s->nwatch; i++) {
		if (!strcmp(s->watch[i], arg[0]))
			return ok(o);
	}
	if (s->nwatch == SIM_WATCH_MAX)
		return fail(o, "too many watched variables (%d)",
			    SIM_WATCH_MAX);
	snprintf(s->watch[s->nwatch++], SIM_WATCH_LEN, "%s", arg[0]);
	return ok(o);
}

static int req_unwatch(struct sim *s, char **arg, int n, struct out *o)
{
	(void)n;
	for (int i = 0; i < s->nwatch; i++) {
		if (!strcmp(s->watch[i], arg[0])) {
			memmove(s->watch[i], s->watch[i + 1],
				(size_t)(s->nwatch - i - 1) * SIM_WATCH_LEN);
			s->nwatch--;
			return ok(o);
		}
	}
	return fail(o, "'%s' is not watched", arg[0]);
}

static int req_events(struct sim *s, char **arg, int n, struct out *o)
{
	char t[32], line[SIM_EVENT_LEN + 40];

	(void)arg;
	(void)n;
	if (s->ev_lost) {
		sim_fmt_ms(t, sizeof(t), s->time_us);
		put(o, "%s events lost: %lu\n", t, s->ev_lost);
		s->ev_lost = 0;
	}
	while (s->ev_count) {
		struct sim_evt *e = &s->ev[s->ev_head];
		int len;

		sim_fmt_ms(t, sizeof(t), e->t_us);
		len = snprintf(line, sizeof(line), "%s %s\n", t, e->text);
		if (o->len + (size_t)len + 4 >= o->cap)
			break; /* the rest waits for the next call */
		put(o, "%s", line);
		s->ev_head = (s->ev_head + 1) % SIM_EVENTS_MAX;
		s->ev_count--;
	}
	put(o, "end");
	return 0;
}

static int req_help(struct sim *s, char **arg, int n, struct out *o);

static const struct request requests[] = {
    {"joy", 2, 3, req_joy, "joy <A|B|C> <fwd|rev|neutral> [a|b]"},
    {"in", 2, 2, req_in, "in <1-32> <0|1>"},
    {"an", 2, 2, req_an, "an <1-8> <volts>"},
    {"release", 2, 2, req_release, "release <in|an> <n>"},
    {"pot", 2, 3, req_pot, "pot <A|B|C> <ok|offset V|stuck|open|noise V>"},
    {"enc", 2, 3, req_enc, "enc <A|B|C> <ok|stuck|slip COUNTS>"},
    {"block", 2, 2, req_block, "block <A|B|C> <0|1>"},
    {"limit", 3, 3, req_limit, "limit <A|B|C> <fwd|rev> <press|release>"},
    {"link", 1, 3, req_link, "link <ok|drop|stall|delay MS> [tcp|stream]"},
    {"relay", 0, 1, req_relay, "relay [on|off]"},
    {"relayfault", 1, 1, req_relayfault,
     "relayfault <ok|unplug|writefail|wedge>"},
    {"state", 0, 0, req_state, "state"},
    {"watch", 1, 1, req_watch, "watch <variable>"},
    {"unwatch", 1, 1, req_unwatch, "unwatch <variable>"},
    {"events", 0, 0, req_events, "events"},
    {"time", 0, 0, req_time, "time"},
    {"power-cycle", 0, 0, req_power_cycle, "power-cycle"},
    {"quit", 0, 0, req_quit, "quit"},
    {"help", 0, 0, req_help, "help"},
};

#define NREQUESTS (sizeof(requests) / sizeof(requests[0]))

static int req_help(struct sim *s, char **arg, int n, struct out *o)
{
	(void)s;
	(void)arg;
	(void)n;
	put(o, "requests:");
	for (size_t i = 0; i < NREQUESTS; i++)
		put(o, " %s", requests[i].name);
	return 0;
}

static int split(char *line, char **word)
{
	char *save = NULL;
	int n = 0;

	for (char *p = strtok_r(line, " \t", &save); p;
	     p = strtok_r(NULL, " \t", &save)) {
		if (n == MAX_WORDS)
			return -1;
		word[n++] = p;
	}
	return n;
}

int sim_control(struct sim *s, const char *req, char *resp, size_t cap)
{
	char line[SIM_REQUEST_MAX], *word[MAX_WORDS];
	struct out o = {resp, cap, 0};
	int n;

	if (!cap)
		return GL_ERR_ARG;
	resp[0] = '\0';
	if (strlen(req) >= sizeof(line))
		return fail(&o, "request too long (at most %d bytes)",
			    SIM_REQUEST_MAX - 1);
	strcpy(line, req);
	n = split(line, word);
	if (n < 0)
		return fail(&o, "too many words");
	if (n == 0)
		return fail(&o, "empty request (try 'help')");
	for (size_t i = 0; i < NREQUESTS; i++) {
		const struct request *r = &requests[i];

		if (strcmp(word[0], r->name))
			continue;
		if (n - 1 < r->min_args || n - 1 > r->max_args)
			return fail(&o, "usage: %s", r->usage);
		return r->fn(s, word + 1, n - 1, &o);
	}
	return fail(&o, "unknown request '%s' (try 'help')", word[0]);
}
