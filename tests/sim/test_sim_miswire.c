/*
 * test_sim_miswire.c - galil-sim's deliberate miswirings (--miswire SPEC,
 * plant file keys encoder_reversed, limits_swapped, relay_wired, a reversed
 * pot, joystick inputs and polarity) and the home switch, seen by the
 * controller in virtual time through the in-process simulator (sim.h),
 * each with the value the commissioning run must observe.
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

#define BIT(n) (1u << ((n)-1))

struct fx {
	struct sim *s;
	char resp[SIM_RESPONSE_MAX];
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

static void miswire(struct fx *f, const char *spec)
{
	char err[256];

	if (sim_plant_miswire(sim_get_plant(f->s), spec, err, sizeof(err)))
		fail_msg("%s: %s", spec, err);
}

static void ctl(struct fx *f, const char *req)
{
	if (sim_control(f->s, req, f->resp, sizeof(f->resp)) != 0)
		fail_msg("'%s' -> '%s'", req, f->resp);
}

/* A controller command that must be accepted. */
static void cmd(struct fx *f, const char *line)
{
	char resp[256];

	if (ctrl_command(sim_ctrl(f->s), line, resp, sizeof(resp)) != GL_OK)
		fail_msg("'%s' refused", line);
}

static double mg(struct fx *f, const char *expr)
{
	char line[128], resp[256];

	snprintf(line, sizeof(line), "MG %s", expr);
	if (ctrl_command(sim_ctrl(f->s), line, resp, sizeof(resp)) != GL_OK)
		fail_msg("'%s' refused", line);
	return strtod(resp, NULL);
}

/* Advance 1 ms at a time until @expr is non-zero; fail after @max_ms. */
static double until(struct fx *f, const char *expr, double max_ms)
{
	double t0 = sim_time_ms(f->s);

	while (mg(f, expr) == 0) {
		if (sim_time_ms(f->s) - t0 > max_ms)
			fail_msg("'%s' still 0 after %g ms", expr, max_ms);
		sim_advance_ms(f->s, 1);
	}
	return sim_time_ms(f->s) - t0;
}

static struct sim_plant_axis_state axis(struct fx *f, int i)
{
	struct sim_plant_axis_state st;

	assert_int_equal(sim_plant_axis(sim_get_plant(f->s), i, &st), 0);
	return st;
}

/* Correct wiring: PR 500 with OE 1 ER 200 arrives and stays on. */
static void test_clean_move(void **state)
{
	struct fx *f = *state;

	ctl(f, "relay on");
	sim_advance_ms(f->s, 2);
	cmd(f, "OEA=1;ERA=200;SHA;PRA=500;BGA");
	until(f, "_BGA=0", 2000);
	sim_advance_ms(f->s, 20);
	assert_int_equal((int)mg(f, "_TPA"), 500);
	assert_int_equal((int)mg(f, "_MOA"), 0);
	assert_int_equal((int)mg(f, "_SCA"), 1);
	assert_float_equal(axis(f, 0).pos, 500, 0.5);
}

/*
 * encoder-reversed:A: the servo loop runs away; the position error passes
 * ER and OE 1 switches the motor off (stop code 8). The motor went forward
 * while the controller's count went back: _TPA = -(plant position).
 */
static void test_encoder_reversed(void **state)
{
	struct fx *f = *state;
	struct sim_plant_axis_state st;

	miswire(f, "encoder-reversed:A");
	ctl(f, "relay on");
	sim_advance_ms(f->s, 2);
	cmd(f, "OEA=1;ERA=200;SHA;PRA=500;BGA");
	assert_true(until(f, "_MOA", 500) < 100);
	assert_int_equal((int)mg(f, "_SCA"), 8);
	st = axis(f, 0);
	assert_true(st.pos > 0);
	assert_int_equal((int)mg(f, "_TPA"), -(int)lround(st.pos));
	assert_true(mg(f, "_TPA") < -100);
	/* motor off: the reference follows the encoder, no error left */
	assert_int_equal((int)mg(f, "_TEA"), 0);
	/* the limit switches stay tied to the physical position */
	assert_int_equal((int)mg(f, "_LFA"), 1);
	assert_int_equal((int)mg(f, "_LRA"), 1);
}

/*
 * limits-swapped:B: driving forward onto the forward switch trips the
 * reverse limit input (_LRB = 0, _LFB = 1); the forward move is not
 * stopped by it and ends at the mechanical end stop.
 */
static void test_limits_swapped(void **state)
{
	struct fx *f = *state;

	miswire(f, "limits-swapped:B");
	ctl(f, "relay on");
	sim_advance_ms(f->s, 2);
	cmd(f, "SHB;JGB=20000;BGB");
	until(f, "_LRB=0", 5000);
	assert_int_equal((int)mg(f, "_LFB"), 1);
	assert_int_equal((int)mg(f, "_BGB"), 1);
	assert_true(axis(f, 1).fwd_limit == 1 && axis(f, 1).rev_limit == 0);
	assert_int_equal((int)mg(f, "_TSB") & 0x0C, 0x08);
	cmd(f, "STB");
	until(f, "_BGB=0", 2000);
	assert_int_equal((int)mg(f, "_SCB"), 4);
}

/* relay-unwired: the relay stays off, the motors still have power, the
 * controller sees no under-voltage and the axis moves. */
static void test_relay_unwired(void **state)
{
	struct fx *f = *state;

	sim_advance_ms(f->s, 2);
	assert_int_equal((int)mg(f, "_TA0"), 8); /* correct wiring first */
	miswire(f, "relay-unwired");
	sim_advance_ms(f->s, 2);
	assert_int_equal((int)mg(f, "_TA0") & 8, 0);
	assert_int_equal(sim_power(f->s), 1);
	cmd(f, "SHA;PRA=1000;BGA");
	until(f, "_BGA=0", 2000);
	sim_advance_ms(f->s, 20);
	assert_int_equal((int)mg(f, "_TPA"), 1000);
	assert_int_equal((int)mg(f, "_MOA"), 0);
	ctl(f, "relay on");
	ctl(f, "relay off");
	sim_advance_ms(f->s, 5);
	assert_int_equal((int)mg(f, "_TA0"), 0);
	assert_int_equal((int)mg(f, "_MOA"), 0);
}

/* pot-reversed:C: the pot reads fwd_v at the reverse switch. */
static void test_pot_reversed(void **state)
{
	struct fx *f = *state;
	const struct sim_plant_cfg *c = sim_plant_get_cfg(sim_get_plant(f->s));

	miswire(f, "pot-reversed:C");
	assert_true(c->axis[2].pot.rev_v == 4.5 && c->axis[2].pot.fwd_v == 0.5);
	assert_float_equal(sim_plant_pot_volts(&c->axis[2], -40000), 4.5, 1e-9);
	assert_float_equal(sim_plant_pot_volts(&c->axis[2], 40000), 0.5, 1e-9);
	ctl(f, "pot C noise 0");
	ctl(f, "relay on");
	sim_advance_ms(f->s, 2);
	cmd(f, "SHC;PRC=20000;BGC");
	until(f, "_BGC=0", 3000);
	sim_advance_ms(f->s, 20);
	/* forward travel lowers the reading: 2.5 V at the centre, then
	 * 2.5 - 4 * 20000/80000 V plus the bow (0.04 V * sin(3pi/4)) */
	assert_float_equal(mg(f, "@AN[3]"), 1.5 + 0.04 * sin(0.75 * M_PI),
			   2e-4);
}

/* joystick-swap:5,7: B forward channel a shows on input 7, B reverse
 * channel a on input 5. */
static void test_joystick_swap(void **state)
{
	struct fx *f = *state;

	miswire(f, "joystick-swap:5,7");
	ctl(f, "joy B fwd a");
	sim_advance_ms(f->s, 2);
	assert_int_equal((int)mg(f, "_TI0"), (int)BIT(7));
	ctl(f, "joy B rev a");
	sim_advance_ms(f->s, 2);
	assert_int_equal((int)mg(f, "_TI0"), (int)BIT(5));
}

/* dead-input:6: B forward closes both channels, input 6 stays open. */
static void test_dead_input(void **state)
{
	struct fx *f = *state;

	miswire(f, "dead-input:6");
	ctl(f, "joy B fwd");
	sim_advance_ms(f->s, 2);
	assert_int_equal((int)mg(f, "_TI0"), (int)BIT(5));
	assert_int_equal((int)mg(f, "@IN[6]"), 0);
}

/* joystick-polarity: closed_level 0, every open switch reads 1. */
static void test_joystick_polarity(void **state)
{
	struct fx *f = *state;

	miswire(f, "joystick-polarity");
	sim_advance_ms(f->s, 2);
	assert_int_equal((int)mg(f, "_TI0"), 255);
	ctl(f, "joy A fwd");
	sim_advance_ms(f->s, 2);
	assert_int_equal((int)mg(f, "_TI0"), 255 - 3);
	assert_int_equal((int)mg(f, "_TI2"), 15); /* inputs 17..20 */
}

/* The home switch changes level at home (default 0, the centre): pulled
 * up at and above, grounded below (_HM 1 / 0 with CN n1 = -1). */
static void test_home_switch(void **state)
{
	struct fx *f = *state;

	ctl(f, "relay on");
	sim_advance_ms(f->s, 2);
	assert_int_equal((int)mg(f, "_HMA"), 1);
	cmd(f, "SHA;PRA=-1000;BGA");
	until(f, "_BGA=0", 2000);
	sim_advance_ms(f->s, 20);
	assert_int_equal((int)mg(f, "_HMA"), 0);
	assert_int_equal((int)mg(f, "_TSA") & 2, 0);
	assert_int_equal(axis(f, 0).home, 1);
	cmd(f, "CN ,1");
	assert_int_equal((int)mg(f, "_HMA"), 1);
	cmd(f, "CN ,-1;PRA=1500;BGA");
	until(f, "_BGA=0", 2000);
	sim_advance_ms(f->s, 20);
	assert_int_equal((int)mg(f, "_HMA"), 1);
}

/* home: in the plant file moves the switch's edge. */
static void test_home_position_from_file(void **state)
{
	struct sim_plant_cfg c;
	struct sim_plant *p;
	struct ctrl_sense in;
	char err[256];
	const char *yaml = "axes:\n  B: {home: 5000}\n";

	(void)state;
	sim_plant_cfg_default(&c);
	assert_int_equal(
	    sim_plant_cfg_parse(&c, yaml, strlen(yaml), "p.yaml", err, 256), 0);
	assert_true(c.axis[1].home == 5000 && c.axis[0].home == 0);
	assert_int_equal(sim_plant_new(&p, &c), 0);
	sim_plant_sense(p, 1, &in);
	assert_int_equal(in.home[0], 0);
	assert_int_equal(in.home[1], 1);
	sim_plant_free(p);
}

/* The plant file's own keys give the same miswiring; rev_v > fwd_v is
 * accepted (a pot wired reversed). */
static void test_plant_file_keys(void **state)
{
	struct sim_plant_cfg c;
	char err[256];
	const char *yaml = "relay_wired: false\n"
			   "axes:\n"
			   "  A: {encoder_reversed: true}\n"
			   "  B: {limits_swapped: true}\n"
			   "  C:\n"
			   "    pot: {rev_v: 4.5, fwd_v: 0.5}\n";

	(void)state;
	sim_plant_cfg_default(&c);
	assert_int_equal(c.relay_wired, 1);
	assert_int_equal(c.axis[0].encoder_reversed, 0);
	assert_int_equal(
	    sim_plant_cfg_parse(&c, yaml, strlen(yaml), "p.yaml", err, 256), 0);
	assert_int_equal(c.relay_wired, 0);
	assert_int_equal(c.axis[0].encoder_reversed, 1);
	assert_int_equal(c.axis[1].limits_swapped, 1);
	assert_int_equal(c.axis[1].encoder_reversed, 0);
	assert_true(c.axis[2].pot.rev_v == 4.5 && c.axis[2].pot.fwd_v == 0.5);
	assert_int_equal(sim_plant_cfg_check(&c, err, sizeof(err)), 0);
}

/* Bad specs are refused with one message naming every form. */
static void test_miswire_errors(void **state)
{
	static const char *const bad[] = {
	    "encoder-reversed",	   "encoder-reversed:D",
	    "limits-swapped:AB",   "relay-unwired:A",
	    "pot-reversed:",	   "joystick-swap:5",
	    "joystick-swap:5,5",   "joystick-swap:0,7",
	    "joystick-swap:5,33",  "dead-input:6,7",
	    "dead-input:x",	   "joystick-polarity:1",
	    "encoders-reversed:A", "",
	};
	struct sim_plant_cfg c, def;
	char err[512], want[512];

	(void)state;
	sim_plant_cfg_default(&def);
	for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
		c = def;
		snprintf(
		    want, sizeof(want),
		    "bad miswiring '%s' (encoder-reversed:AXIS, "
		    "limits-swapped:AXIS, relay-unwired, pot-reversed:AXIS, "
		    "joystick-swap:N,M, dead-input:N, joystick-polarity; "
		    "AXIS A..C, inputs 1..32)",
		    bad[i]);
		assert_int_equal(sim_plant_cfg_miswire(&c, bad[i], err, 512),
				 GL_ERR_ARG);
		assert_string_equal(err, want);
		assert_memory_equal(&c, &def, sizeof(def));
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_clean_move, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_encoder_reversed, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_limits_swapped, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_relay_unwired, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_pot_reversed, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_joystick_swap, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_dead_input, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_joystick_polarity, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_home_switch, setup, teardown),
	    cmocka_unit_test(test_home_position_from_file),
	    cmocka_unit_test(test_plant_file_keys),
	    cmocka_unit_test(test_miswire_errors),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
