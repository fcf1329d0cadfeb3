/*
 * test_sim_control.c - galil-sim's control-port requests through
 * sim_control() in virtual time: answers and errors, the state line, the
 * event log, watch, the relay and power, link and power-cycle requests, and
 * the controller seeing what the requests change.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "gl_err.h"
#include "sim.h"
#include "sim_plant.h"

struct fx {
	struct sim *s;
	char resp[SIM_RESPONSE_MAX];
	int disconnects;
};

static int setup(void **state)
{
	struct fx *f = calloc(1, sizeof(*f));
	char err[256];

	assert_non_null(f);
	assert_int_equal(sim_new(&f->s, NULL, err, sizeof(err)), 0);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	struct fx *f = *state;

	sim_free(f->s);
	free(f);
	return 0;
}

/* A request that must succeed; returns the answer. */
static const char *ctl(struct fx *f, const char *req)
{
	if (sim_control(f->s, req, f->resp, sizeof(f->resp)) != 0)
		fail_msg("'%s' -> '%s'", req, f->resp);
	return f->resp;
}

/* A request that must fail with exactly @msg. */
static void ctl_err(struct fx *f, const char *req, const char *msg)
{
	assert_int_equal(sim_control(f->s, req, f->resp, sizeof(f->resp)),
			 GL_ERR_ARG);
	assert_string_equal(f->resp, msg);
}

/* The value of @key in a state line, as a number. */
static double state_num(struct fx *f, const char *key)
{
	char pat[64];
	const char *st = ctl(f, "state"), *p;

	snprintf(pat, sizeof(pat), " %s=", key);
	p = strstr(st, pat);
	if (!p && !strncmp(st, pat + 1, strlen(pat) - 1))
		p = st - 1;
	if (!p)
		fail_msg("no '%s' in '%s'", key, st);
	return strtod(p + strlen(pat), NULL);
}

/* A controller query such as "MG @IN[1]" as a number. */
static double mg(struct fx *f, const char *cmd)
{
	char resp[128];

	if (ctrl_command(sim_ctrl(f->s), cmd, resp, sizeof(resp)) != 0)
		fail_msg("'%s' -> '%s'", cmd, resp);
	return strtod(resp, NULL);
}

/* ---- protocol ----------------------------------------------------------- */

static void test_basic_answers(void **state)
{
	struct fx *f = *state;

	assert_string_equal(ctl(f, "time"), "0");
	sim_advance_ms(f->s, 123);
	assert_string_equal(ctl(f, "time"), "123");
	assert_string_equal(ctl(f, "relay"), "off");
	assert_string_equal(
	    ctl(f, "help"),
	    "requests: joy in an release pot enc block limit link "
	    "relay relayfault state watch unwatch events time "
	    "power-cycle quit help");
	assert_string_equal(ctl(f, "  time\t"), "123");
}

static void test_errors(void **state)
{
	struct fx *f = *state;
	char big[400];

	ctl_err(f, "", "error: empty request (try 'help')");
	ctl_err(f, "fly", "error: unknown request 'fly' (try 'help')");
	ctl_err(f, "TIME", "error: unknown request 'TIME' (try 'help')");
	ctl_err(f, "time now", "error: usage: time");
	ctl_err(f, "joy A",
		"error: usage: joy <A|B|C> <fwd|rev|neutral> "
		"[a|b]");
	ctl_err(f, "joy D fwd", "error: bad axis 'D' (A, B or C)");
	ctl_err(f, "joy a fwd", "error: bad axis 'a' (A, B or C)");
	ctl_err(f, "joy A up",
		"error: bad direction 'up' (fwd, rev or "
		"neutral)");
	ctl_err(f, "joy A fwd c", "error: bad channel 'c' (a or b)");
	ctl_err(f, "in 33 1", "error: bad input '33' (1..32)");
	ctl_err(f, "in 3 2", "error: bad level '2' (0 or 1)");
	ctl_err(f, "in 1.5 1", "error: bad input '1.5' (1..32)");
	ctl_err(f, "an 9 1", "error: bad analog input '9' (1..8)");
	ctl_err(f, "an 1 11", "error: bad voltage '11' (-10..10)");
	ctl_err(f, "an 1 x", "error: bad voltage 'x' (-10..10)");
	ctl_err(f, "release out 1", "error: bad kind 'out' (in or an)");
	ctl_err(f, "release an 9", "error: bad input '9'");
	ctl_err(f, "pot A offset",
		"error: usage: pot <A|B|C> <ok|offset V|"
		"stuck|open|noise V>");
	ctl_err(f, "pot A wobble",
		"error: bad pot fault 'wobble' (ok, offset, "
		"stuck, open, noise)");
	ctl_err(f, "pot A noise 2", "error: bad voltage '2'");
	ctl_err(f, "enc B slip",
		"error: usage: enc <A|B|C> <ok|stuck|slip "
		"COUNTS>");
	ctl_err(f, "enc B slip 1e9", "error: bad count '1e9'");
	ctl_err(f, "block C 2", "error: bad value '2' (0 or 1)");
	ctl_err(f, "link wobble",
		"error: usage: link <ok|drop|stall|delay "
		"MS> [tcp|stream]");
	ctl_err(f, "link ok stream",
		"error: usage: link <ok|drop|stall|delay "
		"MS> [tcp|stream]");
	ctl_err(f, "link delay -1", "error: bad delay '-1' (0..60000 ms)");
	ctl_err(f, "relay toggle", "error: usage: relay [on|off]");
	ctl_err(f, "relayfault melt",
		"error: usage: relayfault <ok|unplug|"
		"writefail|wedge>");
	ctl_err(f, "watch bad;name", "error: bad variable name 'bad;name'");
	ctl_err(f, "unwatch x", "error: 'x' is not watched");
	ctl_err(f, "a b c d e f g h i", "error: too many words");
	memset(big, 'x', sizeof(big) - 1);
	big[sizeof(big) - 1] = '\0';
	ctl_err(f, big, "error: request too long (at most 255 bytes)");
	/* nothing was injected by the failed requests */
	assert_string_equal(ctl(f, "events"), "end");
}

static void copy(char *dst, size_t cap, const char *src)
{
	assert_true(strlen(src) < cap);
	memcpy(dst, src, strlen(src) + 1);
}

/* The state line: one line, keys in a fixed order, values as documented. */
static void test_state_line_format(void **state)
{
	static const char *const keys[] = {
	    "time",  "relay", "power", "pout",	"link",	      "threads",
	    "A.pos", "A.ref", "A.vel", "A.pot", "A.mo",	      "A.sc",
	    "A.lf",  "A.lr",  "A.act", "B.pos", "B.ref",      "B.vel",
	    "B.pot", "B.mo",  "B.sc",  "B.lf",	"B.lr",	      "B.act",
	    "C.pos", "C.ref", "C.vel", "C.pot", "C.mo",	      "C.sc",
	    "C.lf",  "C.lr",  "C.act", "var.x", "var.arr[2]",
	};
	struct fx *f = *state;
	char line[2048], *save = NULL, *tok;
	size_t k = 0;

	ctl(f, "watch x");
	ctl(f, "watch arr[2]");
	ctl(f, "watch x"); /* twice: listed once */
	sim_advance_ms(f->s, 5);
	copy(line, sizeof(line), ctl(f, "state"));
	assert_null(strchr(line, '\n'));
	for (tok = strtok_r(line, " ", &save); tok;
	     tok = strtok_r(NULL, " ", &save), k++) {
		size_t n = strlen(keys[k]);

		assert_true(k < sizeof(keys) / sizeof(keys[0]));
		if (strncmp(tok, keys[k], n) || tok[n] != '=')
			fail_msg("token %zu is '%s', want key '%s'", k, tok,
				 keys[k]);
	}
	assert_int_equal(k, sizeof(keys) / sizeof(keys[0]));
	copy(line, sizeof(line), ctl(f, "state"));
	assert_non_null(strstr(line,
			       "time=5 relay=off power=0 pout=- link=ok "
			       "threads=- A.pos=0 A.ref=0 A.vel=0 A.pot=2.5"));
	assert_non_null(strstr(line, " A.mo=1 A.sc="));
	assert_non_null(strstr(line, " var.x=? var.arr[2]=?"));
	ctl(f, "unwatch x");
	assert_null(strstr(ctl(f, "state"), "var.x="));
}

/* Watched variables show the program's value with 4 decimals. */
static void test_watch_value(void **state)
{
	struct fx *f = *state;
	char resp[64];

	ctl(f, "watch speed");
	assert_int_equal(
	    ctrl_command(sim_ctrl(f->s), "speed=12.5", resp, sizeof(resp)), 0);
	assert_non_null(strstr(ctl(f, "state"), " var.speed=12.5000"));
}

/* ---- events ------------------------------------------------------------- */

static void test_events_timestamped_and_drained(void **state)
{
	struct fx *f = *state;

	sim_advance_ms(f->s, 250);
	ctl(f, "block A 1");
	sim_advance_ms(f->s, 50);
	ctl(f, "pot B offset 0.3");
	ctl(f, "relay on");
	assert_string_equal(ctl(f, "events"), "250 inject: block A 1\n"
					      "300 inject: pot B offset 0.3\n"
					      "300 relay on (control port)\n"
					      "end");
	assert_string_equal(ctl(f, "events"), "end");
}

/* More events than the log holds: the oldest go, and the answer says how
 * many; an answer that does not fit leaves the rest for the next call. */
static void test_events_overflow_and_partial(void **state)
{
	struct fx *f = *state;
	char small[200];
	int k = -1, rest = 0;

	for (int i = 0; i < SIM_EVENTS_MAX + 52; i++)
		ctl(f, i % 2 ? "block A 1" : "block A 0");
	assert_int_equal(sim_control(f->s, "events", small, sizeof(small)), 0);
	/* event 52 is the oldest kept */
	assert_memory_equal(small, "0 events lost: 52\n0 inject: block A 0\n",
			    38);
	assert_string_equal(small + strlen(small) - 4, "\nend");
	for (const char *p = small; (p = strchr(p, '\n')); p++)
		k++; /* event lines delivered */
	assert_true(k >= 2 && k < 10);
	ctl(f, "events");
	for (const char *p = f->resp; (p = strchr(p, '\n')); p++)
		rest++;
	assert_int_equal(rest, SIM_EVENTS_MAX - k);
	assert_memory_equal(
	    f->resp, k % 2 ? "0 inject: block A 1\n" : "0 inject: block A 0\n",
	    20);
	assert_string_equal(ctl(f, "events"), "end");
}

/* ---- inputs reach the controller ---------------------------------------- */

static void test_joy_and_inputs_seen_by_controller(void **state)
{
	struct fx *f = *state;

	ctl(f, "joy A fwd");
	sim_advance_ms(f->s, 2);
	assert_true(mg(f, "MG @IN[1]") == 1 && mg(f, "MG @IN[2]") == 1);
	assert_true(mg(f, "MG @IN[3]") == 0);
	ctl(f, "joy A fwd b");
	ctl(f, "joy C rev");
	sim_advance_ms(f->s, 2);
	assert_true(mg(f, "MG @IN[1]") == 0 && mg(f, "MG @IN[2]") == 1);
	assert_true(mg(f, "MG @IN[19]") == 1 && mg(f, "MG @IN[20]") == 1);
	ctl(f, "in 2 0");
	ctl(f, "an 5 -3.25");
	sim_advance_ms(f->s, 2);
	assert_true(mg(f, "MG @IN[2]") == 0);
	assert_float_equal(mg(f, "MG @AN[5]"), -3.25, 0.001);
	ctl(f, "release in 2");
	ctl(f, "release an 5");
	ctl(f, "joy A neutral");
	sim_advance_ms(f->s, 2);
	assert_true(mg(f, "MG @IN[2]") == 0);
	assert_float_equal(mg(f, "MG @AN[5]"), 0, 0.001);
	assert_non_null(strstr(ctl(f, "events"),
			       "0 input: joy A fwd\n"
			       "2 input: joy A fwd b\n2 input: joy C rev\n"
			       "4 inject: in 2 0\n4 inject: an 5 -3.2500\n"));
}

/* Potentiometer faults show in the state line and on @AN. */
static void test_pot_fault_in_state(void **state)
{
	struct fx *f = *state;
	const struct sim_plant_cfg *pc = sim_plant_get_cfg(sim_get_plant(f->s));
	double curve = sim_plant_pot_volts(&pc->axis[1], 0);

	ctl(f, "pot B noise 0");
	ctl(f, "pot B offset 0.3");
	sim_advance_ms(f->s, 2);
	assert_float_equal(state_num(f, "B.pot"), curve + 0.3, 1e-4);
	assert_float_equal(mg(f, "MG @AN[2]"), curve + 0.3, 0.001);
	ctl(f, "pot B open");
	sim_advance_ms(f->s, 2);
	assert_float_equal(state_num(f, "B.pot"), 0, 1e-9);
	ctl(f, "pot B ok");
	sim_advance_ms(f->s, 2);
	assert_float_equal(state_num(f, "B.pot"), curve, 1e-4);
}

/* ---- relay, power, motion ------------------------------------------------ */

/* Relay on + servo: the axis follows a move; power cut: the controller
 * sees it (with OE 1 the motors go off, stop code 15) and the event log
 * says so. */
static void test_power_and_motion(void **state)
{
	struct fx *f = *state;
	char resp[128];
	struct ctrl *c = sim_ctrl(f->s);

	sim_advance_ms(f->s, 1); /* the controller's power-up sample */
	ctl(f, "relay on");
	assert_int_equal(state_num(f, "power"), 1);
	assert_int_equal(ctrl_command(c, "OE 1,1,1", resp, sizeof(resp)), 0);
	assert_int_equal(ctrl_command(c, "SH ABC", resp, sizeof(resp)), 0);
	assert_int_equal(ctrl_command(c, "PR 2000", resp, sizeof(resp)), 0);
	assert_int_equal(ctrl_command(c, "BG A", resp, sizeof(resp)), 0);
	sim_advance_ms(f->s, 2000);
	assert_float_equal(state_num(f, "A.pos"), 2000, 2);
	assert_float_equal(state_num(f, "A.act"), 2000, 2);
	assert_int_equal(state_num(f, "A.mo"), 0);
	ctl(f, "events");
	ctl(f, "relayfault unplug");
	assert_string_equal(ctl(f, "relay"), "off");
	sim_advance_ms(f->s, 20);
	assert_int_equal(state_num(f, "power"), 0);
	assert_int_equal(state_num(f, "A.mo"), 1);
	assert_non_null(strstr(ctl(f, "events"), "relay unplugged"));
	assert_non_null(strstr(f->resp, " amplifier power lost"));
	assert_non_null(strstr(f->resp, " axis A motor off: amplifier fault"));
	ctl_err(f, "relay on", "error: relay is unplugged");
	ctl(f, "relayfault ok");
	assert_string_equal(ctl(f, "relay"), "off");
	ctl(f, "relayfault writefail");
	ctl_err(f, "relay on", "error: relay is failing");
}

/* The events since the last call contain @text as a whole line. */
static int has_event(struct fx *f, const char *text)
{
	const char *ev = ctl(f, "events"), *p = ev;
	size_t n = strlen(text);

	while ((p = strstr(p, text)) != NULL) {
		if (p > ev && p[-1] == ' ' && (p[n] == '\n' || p[n] == '\0'))
			return 1;
		p += n;
	}
	return 0;
}

/* amp_undervoltage off: the relay cuts motor power, the motor stops where
 * it is, and the controller sees nothing: no under-voltage bit, no
 * #AMPERR, no stop code 15, the servo stays on; back on, it moves again. */
static void test_amp_undervoltage_off(void **state)
{
	static const char prog[] = "#AMPERR\ramperr=amperr+1\rRE\r";
	struct fx *f = *state;
	struct ctrl *c = sim_ctrl(f->s);
	char resp[128];
	double act;

	assert_int_equal(sim_plant_set_amp_undervoltage(sim_get_plant(f->s), 0),
			 0);
	assert_int_equal(ctrl_download(c, prog, strlen(prog), NULL), 0);
	sim_advance_ms(f->s, 1);
	ctl(f, "relay on");
	assert_int_equal(ctrl_command(c,
				      "amperr=0;OE 1,1,1;SH ABC;JG 2000;BG A",
				      resp, sizeof(resp)),
			 0);
	sim_advance_ms(f->s, 200);
	ctl(f, "events");
	ctl(f, "relay off");
	sim_advance_ms(f->s, 1);
	act = state_num(f, "A.act");
	sim_advance_ms(f->s, 300);
	assert_int_equal(state_num(f, "power"), 0);
	assert_float_equal(state_num(f, "A.act"), act, 0);
	assert_float_equal(state_num(f, "A.vel"), 0, 0);
	assert_int_equal(state_num(f, "A.mo"), 0);
	assert_int_equal(state_num(f, "A.sc"), 0); /* still jogging */
	assert_float_equal(mg(f, "MG _TA0"), 0, 0);
	assert_float_equal(mg(f, "MG _MOA"), 0, 0);
	assert_float_equal(mg(f, "MG _BGA"), 1, 0);
	assert_float_equal(mg(f, "MG amperr"), 0, 0);
	assert_true(state_num(f, "A.ref") - state_num(f, "A.pos") > 500);
	assert_true(has_event(f, "motor power lost (amplifiers report "
				 "nothing: under-voltage model off)"));
	ctl(f, "relay on");
	sim_advance_ms(f->s, 100);
	assert_true(state_num(f, "A.act") > act + 100);
	assert_true(has_event(f, "motor power restored (under-voltage model "
				 "off)"));
	ctl(f, "events");
	/* the same with the model on: the controller reacts */
	assert_int_equal(sim_plant_set_amp_undervoltage(sim_get_plant(f->s), 1),
			 0);
	ctl(f, "relay off");
	sim_advance_ms(f->s, 20);
	assert_float_equal(mg(f, "MG _TA0"), 8, 0);
	assert_float_equal(mg(f, "MG _SCA"), 15, 0);
	assert_float_equal(mg(f, "MG amperr"), 1, 0);
	assert_true(has_event(f, "amplifier power lost (under-voltage)"));
}

/* power_output 3: motor power needs the relay and output 3; the state
 * line shows it as pout, and each change is an event. */
static void test_power_output(void **state)
{
	struct fx *f = *state;
	struct ctrl *c = sim_ctrl(f->s);
	char resp[128];

	sim_advance_ms(f->s, 1);
	assert_non_null(strstr(ctl(f, "state"), " power=0 pout=- link="));
	assert_int_equal(sim_plant_set_power_output(sim_get_plant(f->s), 3), 0);
	ctl(f, "relay on");
	sim_advance_ms(f->s, 1);
	assert_int_equal(state_num(f, "power"), 0);
	assert_int_equal(state_num(f, "pout"), 0);
	assert_int_equal(sim_power(f->s), 0);
	ctl(f, "events");
	assert_int_equal(
	    ctrl_command(c, "SB 3;OE 1;SH A;PR 1000;BG A", resp, sizeof(resp)),
	    0);
	sim_advance_ms(f->s, 1);
	assert_int_equal(state_num(f, "power"), 1);
	assert_int_equal(state_num(f, "pout"), 1);
	assert_true(has_event(f, "power output 3 set"));
	sim_advance_ms(f->s, 500);
	assert_float_equal(state_num(f, "A.act"), 1000, 1);
	assert_int_equal(ctrl_command(c, "CB 3", resp, sizeof(resp)), 0);
	sim_advance_ms(f->s, 2);
	assert_int_equal(state_num(f, "power"), 0);
	assert_int_equal(state_num(f, "pout"), 0);
	assert_string_equal(ctl(f, "relay"), "on");
	assert_float_equal(mg(f, "MG _SCA"), 15, 0); /* the model is on */
	ctl(f, "events");
	assert_int_equal(ctrl_command(c, "OB 3,1", resp, sizeof(resp)), 0);
	sim_advance_ms(f->s, 1);
	assert_int_equal(state_num(f, "power"), 1);
	assert_int_equal(ctrl_command(c, "OP 0", resp, sizeof(resp)), 0);
	sim_advance_ms(f->s, 1);
	assert_int_equal(state_num(f, "power"), 0);
	ctl(f, "events"); /* drop the events so far */
	assert_int_equal(ctrl_command(c, "SB 3", resp, sizeof(resp)), 0);
	sim_advance_ms(f->s, 1);
	assert_true(has_event(f, "power output 3 set"));
	assert_int_equal(ctrl_command(c, "CB 3", resp, sizeof(resp)), 0);
	sim_advance_ms(f->s, 1);
	assert_true(has_event(f, "power output 3 cleared (motor power cut by "
				 "the controller)"));
	/* output set, relay off: no power */
	assert_int_equal(ctrl_command(c, "SB 3", resp, sizeof(resp)), 0);
	ctl(f, "relay off");
	sim_advance_ms(f->s, 1);
	assert_int_equal(state_num(f, "power"), 0);
	assert_int_equal(state_num(f, "pout"), 1);
}

/* A jammed axis: the reference moves on, the motor does not. */
static void test_block_stops_motor(void **state)
{
	struct fx *f = *state;
	char resp[128];
	struct ctrl *c = sim_ctrl(f->s);

	sim_advance_ms(f->s, 1); /* the controller's power-up sample */
	ctl(f, "relay on");
	ctl(f, "block B 1");
	ctrl_command(c, "SH ABC", resp, sizeof(resp));
	ctrl_command(c, "ER ,-1", resp, sizeof(resp));
	ctrl_command(c, "PR ,500", resp, sizeof(resp));
	ctrl_command(c, "BG B", resp, sizeof(resp));
	sim_advance_ms(f->s, 1000);
	assert_float_equal(state_num(f, "B.act"), 0, 1e-9);
	assert_float_equal(state_num(f, "B.pos"), 0, 1e-9);
}

/* ---- link, power cycle, quit -------------------------------------------- */

static void count_disconnect(void *ud)
{
	((struct fx *)ud)->disconnects++;
}

static void test_link_requests(void **state)
{
	struct fx *f = *state;
	double ms = -1;

	sim_set_disconnect(f->s, count_disconnect, f);
	assert_int_equal(sim_link(f->s, &ms), SIM_LINK_OK);
	ctl(f, "link delay 250");
	assert_int_equal(sim_link(f->s, &ms), SIM_LINK_DELAY);
	assert_true(ms == 250);
	assert_non_null(strstr(ctl(f, "state"), " link=delay "));
	ctl(f, "link stall");
	assert_int_equal(sim_link(f->s, NULL), SIM_LINK_STALL);
	assert_int_equal(f->disconnects, 0);
	ctl(f, "link drop");
	assert_int_equal(sim_link(f->s, NULL), SIM_LINK_DROP);
	assert_int_equal(f->disconnects, 1);
	ctl(f, "link ok");
	assert_int_equal(sim_link(f->s, NULL), SIM_LINK_OK);
	assert_string_equal(ctl(f, "events"),
			    "0 inject: link delay 250\n0 inject: link stall\n"
			    "0 inject: link drop\n0 inject: link ok\nend");
}

/* Power cycle: connections closed, RAM lost, encoders restart at 0. */
static void test_power_cycle(void **state)
{
	struct fx *f = *state;
	char resp[128];
	double v;

	sim_set_disconnect(f->s, count_disconnect, f);
	sim_advance_ms(f->s, 1); /* the controller's power-up sample */
	assert_int_equal(
	    ctrl_command(sim_ctrl(f->s), "keep=7", resp, sizeof(resp)), 0);
	ctl(f, "relay on");
	ctrl_command(sim_ctrl(f->s), "SH ABC", resp, sizeof(resp));
	ctrl_command(sim_ctrl(f->s), "PR 300", resp, sizeof(resp));
	ctrl_command(sim_ctrl(f->s), "BG A", resp, sizeof(resp));
	sim_advance_ms(f->s, 500);
	ctl(f, "events");
	ctl(f, "power-cycle");
	assert_int_equal(f->disconnects, 1);
	sim_advance_ms(f->s, 10);
	assert_int_equal(ctrl_get_var(sim_ctrl(f->s), "keep", &v),
			 GL_ERR_NOENT);
	assert_float_equal(state_num(f, "A.pos"), 0, 1e-9);
	assert_float_equal(state_num(f, "A.act"), 300, 1);
	assert_int_equal(state_num(f, "A.mo"), 1);
	assert_string_equal(ctl(f, "relay"), "on"); /* not the relay */
	assert_memory_equal(ctl(f, "events"),
			    "501 inject: power-cycle\n501 controller power "
			    "cycle\n",
			    48);
}

static void test_quit(void **state)
{
	struct fx *f = *state;

	assert_int_equal(sim_quit_requested(f->s), 0);
	assert_string_equal(ctl(f, "quit"), "ok");
	assert_int_equal(sim_quit_requested(f->s), 1);
}

#define T(name) cmocka_unit_test_setup_teardown(name, setup, teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_basic_answers),
	    T(test_errors),
	    T(test_state_line_format),
	    T(test_watch_value),
	    T(test_events_timestamped_and_drained),
	    T(test_events_overflow_and_partial),
	    T(test_joy_and_inputs_seen_by_controller),
	    T(test_pot_fault_in_state),
	    T(test_power_and_motion),
	    T(test_amp_undervoltage_off),
	    T(test_power_output),
	    T(test_block_stops_motor),
	    T(test_link_requests),
	    T(test_power_cycle),
	    T(test_quit),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
