/*
 * test_sim_plant.c - galil-sim's robot model
 * (tools/galil-sim/plant/sim_plant.h): potentiometer curve and noise, faults,
 * motion, limit switches, joystick inputs, and the YAML plant file
 * (config/plant.yaml = built-in defaults).
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
#include "sim_plant.h"

#define DT_MS 1.0

struct fx {
	struct sim_plant_cfg cfg;
	struct sim_plant *p;
	struct ctrl_sense in;
	struct ctrl_drive out;
};

static int setup(void **state)
{
	struct fx *f = calloc(1, sizeof(*f));

	assert_non_null(f);
	sim_plant_cfg_default(&f->cfg);
	assert_int_equal(sim_plant_new(&f->p, &f->cfg), 0);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	struct fx *f = *state;

	sim_plant_free(f->p);
	free(f);
	return 0;
}

/* Run @ms samples commanding @ref on every axis with motors on. */
static void run(struct fx *f, const double ref[3], int power, double ms)
{
	for (int t = 0; t < (int)ms; t++) {
		sim_plant_sense(f->p, power, &f->in);
		for (int i = 0; i < 3; i++) {
			f->out.ref[i] = ref[i];
			f->out.motor_on[i] = 1;
		}
		sim_plant_move(f->p, &f->out, power, DT_MS);
	}
	sim_plant_sense(f->p, power, &f->in);
}

static struct sim_plant_axis_state axis(struct fx *f, int i)
{
	struct sim_plant_axis_state st;

	assert_int_equal(sim_plant_axis(f->p, i, &st), 0);
	return st;
}

/* ---- the default robot ------------------------------------------------- */

/* From the centre each axis needs >= 5 s at 8000 counts/s (the supervisor's
 * default vmax, config/roboelf.yaml) to reach either limit switch. */
static void test_default_travel_takes_5_s(void **state)
{
	struct fx *f = *state;

	for (int i = 0; i < 3; i++) {
		assert_true(f->cfg.axis[i].fwd_limit / 8000.0 >= 5.0);
		assert_true(-f->cfg.axis[i].rev_limit / 8000.0 >= 5.0);
		assert_true(f->cfg.axis[i].start == 0);
	}
	assert_true(f->cfg.axis[0].fwd_limit == 50000);
	assert_true(f->cfg.axis[2].rev_limit == -40000);
}

/* The pot reads 0.5 V at the reverse switch, 4.5 V at the forward switch
 * and rises strictly in between (and beyond, to the end stops). */
static void test_pot_monotonic_over_travel(void **state)
{
	struct fx *f = *state;

	for (int i = 0; i < 3; i++) {
		const struct sim_plant_axis_cfg *a = &f->cfg.axis[i];
		double prev = -100;

		assert_float_equal(sim_plant_pot_volts(a, a->rev_limit), 0.5,
				   1e-9);
		assert_float_equal(sim_plant_pot_volts(a, a->fwd_limit), 4.5,
				   1e-9);
		for (double x = a->rev_limit - a->end_stop;
		     x <= a->fwd_limit + a->end_stop; x += 50) {
			double v = sim_plant_pot_volts(a, x);

			assert_true(v > prev);
			prev = v;
		}
	}
}

/* The non-linearity is really there: mid-travel is off the straight line
 * by nonlinear_v. */
static void test_pot_nonlinear(void **state)
{
	struct fx *f = *state;
	const struct sim_plant_axis_cfg *a = &f->cfg.axis[0];

	assert_float_equal(sim_plant_pot_volts(a, 0), 2.5 + 0.05, 1e-9);
	assert_float_equal(sim_plant_pot_volts(a, 25000),
			   0.5 + 4.0 * 0.75 + 0.05 * sin(M_PI * 0.75), 1e-9);
}

static void noise_stats(struct fx *f, double *maxdev, double *sd)
{
	double curve = sim_plant_pot_volts(&f->cfg.axis[0], 0), s2 = 0;

	*maxdev = 0;
	for (int k = 0; k < 20000; k++) {
		double d;

		sim_plant_sense(f->p, 0, &f->in);
		d = f->in.an_v[0] - curve;
		if (fabs(d) > *maxdev)
			*maxdev = fabs(d);
		s2 += d * d;
	}
	*sd = sqrt(s2 / 20000);
}

/* Gaussian noise: sigma = bound / 3, never beyond the bound. */
static void test_pot_noise_gaussian_bounded(void **state)
{
	struct fx *f = *state;
	double maxdev, sd;

	noise_stats(f, &maxdev, &sd);
	assert_true(maxdev <= 0.002 + 1e-12);
	assert_true(maxdev > 0.0015); /* the tails do reach out */
	assert_true(sd > 0.0006 && sd < 0.00075);
}

/* Uniform noise: within +-bound, sd = bound / sqrt(3). */
static void test_pot_noise_uniform_bounded(void **state)
{
	struct fx *f = *state;
	double maxdev, sd;

	sim_plant_free(f->p);
	f->cfg.axis[0].pot.noise = SIM_PLANT_NOISE_UNIFORM;
	f->cfg.axis[0].pot.noise_v = 0.01;
	assert_int_equal(sim_plant_new(&f->p, &f->cfg), 0);
	noise_stats(f, &maxdev, &sd);
	assert_true(maxdev <= 0.01 && maxdev > 0.0099);
	assert_true(fabs(sd - 0.01 / sqrt(3)) < 0.0003);
}

/* The same seed gives the same noise; another seed does not. */
static void test_pot_noise_seeded(void **state)
{
	struct fx *f = *state;
	double a[5], b[5];
	int same = 1;

	sim_plant_seed(f->p, 7);
	for (int k = 0; k < 5; k++) {
		sim_plant_sense(f->p, 0, &f->in);
		a[k] = f->in.an_v[1];
	}
	sim_plant_seed(f->p, 7);
	for (int k = 0; k < 5; k++) {
		sim_plant_sense(f->p, 0, &f->in);
		assert_true(f->in.an_v[1] == a[k]);
	}
	sim_plant_seed(f->p, 8);
	for (int k = 0; k < 5; k++) {
		sim_plant_sense(f->p, 0, &f->in);
		b[k] = f->in.an_v[1];
		same &= b[k] == a[k];
	}
	assert_false(same);
}

/* Noise set at run time (control port "pot A noise V"). */
static void test_pot_noise_runtime(void **state)
{
	struct fx *f = *state;
	double maxdev, sd;

	assert_int_equal(sim_plant_set_pot_noise(f->p, 0, 0), 0);
	noise_stats(f, &maxdev, &sd);
	assert_true(maxdev == 0);
	assert_int_equal(sim_plant_set_pot_noise(f->p, 0, 2.0), GL_ERR_ARG);
	assert_int_equal(sim_plant_set_pot_noise(f->p, 3, 0.1), GL_ERR_ARG);
}

static void test_pot_faults(void **state)
{
	struct fx *f = *state;
	const double ref[3] = {10000, 0, 0};
	double base = sim_plant_pot_volts(&f->cfg.axis[0], 0), stuck;

	sim_plant_set_pot_noise(f->p, 0, 0);
	assert_int_equal(
	    sim_plant_set_pot_fault(f->p, 0, SIM_PLANT_POT_OFFSET, 0.3), 0);
	sim_plant_sense(f->p, 0, &f->in);
	assert_float_equal(f->in.an_v[0], base + 0.3, 1e-9);
	/* stuck: frozen at the reading, while the axis moves */
	assert_int_equal(
	    sim_plant_set_pot_fault(f->p, 0, SIM_PLANT_POT_STUCK, 0), 0);
	stuck = f->in.an_v[0];
	run(f, ref, 1, 500);
	assert_true(axis(f, 0).pos > 9000);
	assert_true(f->in.an_v[0] == stuck);
	/* open: the wiper reads open_v (0 V), no noise */
	sim_plant_set_pot_noise(f->p, 0, 0.01);
	assert_int_equal(
	    sim_plant_set_pot_fault(f->p, 0, SIM_PLANT_POT_OPEN, 0), 0);
	sim_plant_sense(f->p, 0, &f->in);
	assert_true(f->in.an_v[0] == 0.0);
	/* ok: the curve again */
	sim_plant_set_pot_noise(f->p, 0, 0);
	assert_int_equal(sim_plant_set_pot_fault(f->p, 0, SIM_PLANT_POT_OK, 0),
			 0);
	sim_plant_sense(f->p, 0, &f->in);
	assert_float_equal(f->in.an_v[0],
			   sim_plant_pot_volts(&f->cfg.axis[0], axis(f, 0).pos),
			   1e-9);
	assert_int_equal(
	    sim_plant_set_pot_fault(f->p, 0, SIM_PLANT_POT_OFFSET, NAN),
	    GL_ERR_ARG);
}

/* ---- motion ------------------------------------------------------------ */

/* With power and motor on, the motor follows the reference with its lag. */
static void test_motion_follows_reference(void **state)
{
	struct fx *f = *state;
	const double ref[3] = {1000, -2000, 300};

	run(f, ref, 1, 80); /* 25 ms at max_speed, then the lag */
	assert_float_equal(f->in.enc[0], 1000, 0.5);
	assert_float_equal(f->in.enc[1], -2000, 0.5);
	assert_float_equal(f->in.enc[2], 300, 0.5);
	assert_float_equal(axis(f, 1).pos, -2000, 1);
	/* after 2 ms with a 2 ms lag the motor has gone 1 - e^-1 of the way
	 * (within a count: the servo sees whole encoder counts) */
	run(f, (const double[3]){1020, -2000, 300}, 1, 2);
	assert_float_equal(f->in.enc[0], 1000 + 20 * (1 - exp(-1)), 1);
	assert_true(f->in.amp_power == 1);
}

/* The motor never moves faster than max_speed. */
static void test_motion_max_speed(void **state)
{
	struct fx *f = *state;
	const double ref[3] = {49000, 0, 0};
	struct sim_plant_axis_state st;

	run(f, ref, 1, 100);
	st = axis(f, 0);
	assert_float_equal(st.pos, 40000 * 0.1, 1e-6);
	assert_float_equal(st.vel, 40000, 1e-6);
}

/* No power (relay off): nothing moves, the controller is told. */
static void test_motion_needs_power(void **state)
{
	struct fx *f = *state;
	const double ref[3] = {1000, 1000, 1000};

	run(f, ref, 0, 100);
	for (int i = 0; i < 3; i++) {
		assert_true(axis(f, i).pos == 0);
		assert_true(f->in.enc[i] == 0);
	}
	assert_int_equal(f->in.amp_power, 0);
}

/* amp_undervoltage false: without power nothing moves, and the
 * amplifiers still report power to the controller. */
static void test_amp_undervoltage_off(void **state)
{
	struct fx *f = *state;
	const double ref[3] = {1000, 1000, 1000};

	sim_plant_sense(f->p, 0, &f->in);
	assert_int_equal(f->in.amp_power, 0); /* the default model */
	assert_int_equal(sim_plant_set_amp_undervoltage(f->p, 0), 0);
	assert_int_equal(sim_plant_get_cfg(f->p)->amp_undervoltage, 0);
	run(f, ref, 0, 100);
	assert_int_equal(f->in.amp_power, 1);
	for (int i = 0; i < 3; i++)
		assert_true(axis(f, i).pos == 0);
	run(f, ref, 1, 100);
	assert_int_equal(f->in.amp_power, 1);
	assert_float_equal(axis(f, 0).pos, 1000, 0.5); /* moved with power */
	assert_int_equal(sim_plant_set_amp_undervoltage(f->p, 2), GL_ERR_ARG);
	assert_int_equal(sim_plant_get_cfg(f->p)->amp_undervoltage, 0);
}

/* power_output N: motor power needs the relay and output N (bit N-1). */
static void test_power_output(void **state)
{
	struct fx *f = *state;

	assert_int_equal(sim_plant_motor_power(f->p, 1, 0), 1);
	assert_int_equal(sim_plant_motor_power(f->p, 0, 0xFF), 0);
	assert_int_equal(sim_plant_set_power_output(f->p, 3), 0);
	assert_int_equal(sim_plant_motor_power(f->p, 1, 0), 0);
	assert_int_equal(sim_plant_motor_power(f->p, 1, 0xFB), 0);
	assert_int_equal(sim_plant_motor_power(f->p, 1, 0x04), 1);
	assert_int_equal(sim_plant_motor_power(f->p, 0, 0x04), 0);
	assert_int_equal(sim_plant_set_power_output(f->p, 8), 0);
	assert_int_equal(sim_plant_motor_power(f->p, 1, 0x80), 1);
	assert_int_equal(sim_plant_set_power_output(f->p, 9), GL_ERR_ARG);
	assert_int_equal(sim_plant_set_power_output(f->p, -1), GL_ERR_ARG);
	assert_int_equal(sim_plant_get_cfg(f->p)->power_output, 8);
	assert_int_equal(sim_plant_set_power_output(f->p, 0), 0);
	assert_int_equal(sim_plant_motor_power(f->p, 1, 0), 1);
}

/* Motor off: nothing moves. */
static void test_motion_needs_motor_on(void **state)
{
	struct fx *f = *state;

	f->out.ref[0] = 5000;
	for (int t = 0; t < 50; t++)
		sim_plant_move(f->p, &f->out, 1, DT_MS);
	assert_true(axis(f, 0).pos == 0);
}

/* A jam freezes the motor: the encoder stays while the reference moves. */
static void test_block(void **state)
{
	struct fx *f = *state;
	const double ref[3] = {3000, 3000, 0};

	assert_int_equal(sim_plant_set_block(f->p, 1, 1), 0);
	run(f, ref, 1, 100);
	assert_true(f->in.enc[1] == 0);
	assert_true(axis(f, 1).blocked);
	assert_float_equal(f->in.enc[0], 3000, 0.5);
	assert_int_equal(sim_plant_set_block(f->p, 1, 0), 0);
	run(f, ref, 1, 100);
	assert_float_equal(f->in.enc[1], 3000, 0.5);
}

/* A stuck encoder: the count freezes; a servo on it runs away. */
static void test_encoder_stuck(void **state)
{
	struct fx *f = *state;
	const double ref[3] = {100, 0, 0};

	assert_int_equal(
	    sim_plant_set_enc_fault(f->p, 0, SIM_PLANT_ENC_STUCK, 0), 0);
	run(f, ref, 1, 200);
	assert_true(f->in.enc[0] == 0);
	assert_true(axis(f, 0).pos > 5000); /* ran away, pot shows it */
	assert_true(f->in.an_v[0] > sim_plant_pot_volts(&f->cfg.axis[0], 0));
}

/* A slipped encoder reads position + slip; the servo moves the motor by
 * -slip to put the count back on the reference. */
static void test_encoder_slip(void **state)
{
	struct fx *f = *state;
	const double ref[3] = {0, 0, 0};

	assert_int_equal(
	    sim_plant_set_enc_fault(f->p, 2, SIM_PLANT_ENC_SLIP, 500), 0);
	sim_plant_sense(f->p, 1, &f->in);
	assert_true(f->in.enc[2] == 500);
	run(f, ref, 1, 50);
	assert_float_equal(f->in.enc[2], 0, 0.5);
	assert_float_equal(axis(f, 2).pos, -500, 1);
	assert_int_equal(sim_plant_set_enc_fault(f->p, 2, SIM_PLANT_ENC_OK, 0),
			 0);
	sim_plant_sense(f->p, 1, &f->in);
	assert_float_equal(f->in.enc[2], -500, 1);
}

/* Limit switches turn on at their positions; the end stop holds. */
static void test_limit_switches_and_end_stop(void **state)
{
	struct fx *f = *state;
	double ref[3] = {60000, 0, -60000};

	run(f, ref, 1, 2000);
	assert_int_equal(f->in.fwd_limit[0], 1);
	assert_int_equal(f->in.rev_limit[0], 0);
	assert_float_equal(axis(f, 0).pos, 52000, 1e-9);
	assert_int_equal(f->in.rev_limit[2], 1);
	assert_float_equal(axis(f, 2).pos, -42000, 1e-9);
	assert_int_equal(f->in.fwd_limit[1] | f->in.rev_limit[1], 0);
	ref[0] = 49999;
	run(f, ref, 1, 200);
	assert_int_equal(f->in.fwd_limit[0], 0);
}

/* After a controller power-up the counters read 0 where the motors are. */
static void test_zero_encoders(void **state)
{
	struct fx *f = *state;
	const double ref[3] = {1234, 0, 0};

	run(f, ref, 1, 50);
	sim_plant_zero_encoders(f->p);
	sim_plant_sense(f->p, 1, &f->in);
	assert_true(f->in.enc[0] == 0);
	assert_float_equal(axis(f, 0).pos, 1234, 0.5);
}

/* ---- inputs ------------------------------------------------------------ */

#define BIT(n) (1u << ((n)-1))

static void test_joystick_inputs(void **state)
{
	struct fx *f = *state;

	sim_plant_sense(f->p, 0, &f->in);
	assert_int_equal(f->in.inputs, 0);
	assert_int_equal(sim_plant_set_joy(f->p, 0, SIM_PLANT_FWD, 3), 0);
	sim_plant_sense(f->p, 0, &f->in);
	assert_int_equal(f->in.inputs, BIT(1) | BIT(2));
	sim_plant_set_joy(f->p, 0, SIM_PLANT_REV, 1); /* channel a only */
	sim_plant_sense(f->p, 0, &f->in);
	assert_int_equal(f->in.inputs, BIT(3));
	sim_plant_set_joy(f->p, 2, SIM_PLANT_FWD, 2); /* C fwd, b only */
	sim_plant_sense(f->p, 0, &f->in);
	assert_int_equal(f->in.inputs, BIT(3) | BIT(18));
	sim_plant_set_joy(f->p, 1, SIM_PLANT_REV, 3);
	sim_plant_set_joy(f->p, 0, SIM_PLANT_NEUTRAL, 3);
	sim_plant_set_joy(f->p, 2, SIM_PLANT_REV, 3);
	sim_plant_sense(f->p, 0, &f->in);
	assert_int_equal(f->in.inputs, BIT(7) | BIT(8) | BIT(19) | BIT(20));
	assert_int_equal(sim_plant_set_joy(f->p, 3, SIM_PLANT_FWD, 3),
			 GL_ERR_ARG);
}

/* closed_level 0: a closed switch reads 0, an open one 1. */
static void test_joystick_active_low(void **state)
{
	struct fx *f = *state;
	uint32_t all = 0;

	for (int j = 0; j < 12; j++)
		all |= BIT(f->cfg.joy_input[j]);
	sim_plant_free(f->p);
	f->cfg.joy_closed_level = 0;
	assert_int_equal(sim_plant_new(&f->p, &f->cfg), 0);
	sim_plant_sense(f->p, 0, &f->in);
	assert_int_equal(f->in.inputs, all);
	sim_plant_set_joy(f->p, 1, SIM_PLANT_FWD, 3);
	sim_plant_sense(f->p, 0, &f->in);
	assert_int_equal(f->in.inputs, all & ~(BIT(5) | BIT(6)));
}

static void test_forced_inputs(void **state)
{
	struct fx *f = *state;

	sim_plant_set_joy(f->p, 0, SIM_PLANT_FWD, 3);
	assert_int_equal(sim_plant_force_input(f->p, 2, 0), 0);
	assert_int_equal(sim_plant_force_input(f->p, 32, 1), 0);
	sim_plant_sense(f->p, 0, &f->in);
	assert_int_equal(f->in.inputs, BIT(1) | BIT(32));
	assert_int_equal(sim_plant_release_input(f->p, 2), 0);
	sim_plant_sense(f->p, 0, &f->in);
	assert_int_equal(f->in.inputs, BIT(1) | BIT(2) | BIT(32));
	assert_int_equal(sim_plant_force_input(f->p, 33, 1), GL_ERR_ARG);
	assert_int_equal(sim_plant_force_input(f->p, 0, 1), GL_ERR_ARG);
	assert_int_equal(sim_plant_force_input(f->p, 3, 2), GL_ERR_ARG);
}

static void test_forced_analog(void **state)
{
	struct fx *f = *state;

	sim_plant_set_pot_noise(f->p, 0, 0);
	assert_int_equal(sim_plant_force_analog(f->p, 1, 7.25), 0);
	assert_int_equal(sim_plant_force_analog(f->p, 8, -3), 0);
	sim_plant_sense(f->p, 0, &f->in);
	assert_true(f->in.an_v[0] == 7.25);
	assert_true(f->in.an_v[7] == -3);
	assert_int_equal(sim_plant_release_analog(f->p, 1), 0);
	sim_plant_sense(f->p, 0, &f->in);
	assert_float_equal(f->in.an_v[0], 2.55, 1e-9);
	assert_int_equal(sim_plant_force_analog(f->p, 9, 1), GL_ERR_ARG);
	assert_int_equal(sim_plant_force_analog(f->p, 2, 10.5), GL_ERR_ARG);
}

/* ---- the plant file ---------------------------------------------------- */

static int parse(struct sim_plant_cfg *cfg, const char *text, char *err)
{
	sim_plant_cfg_default(cfg);
	return sim_plant_cfg_parse(cfg, text, strlen(text), "p.yaml", err, 256);
}

static void assert_cfg_equal(const struct sim_plant_cfg *a,
			     const struct sim_plant_cfg *b)
{
	for (int i = 0; i < 3; i++) {
		const struct sim_plant_axis_cfg *x = &a->axis[i],
						*y = &b->axis[i];

		assert_int_equal(x->rotary, y->rotary);
		assert_true(x->rev_limit == y->rev_limit);
		assert_true(x->fwd_limit == y->fwd_limit);
		assert_true(x->end_stop == y->end_stop);
		assert_true(x->start == y->start);
		assert_true(x->max_speed == y->max_speed);
		assert_true(x->lag_ms == y->lag_ms);
		assert_int_equal(x->pot.input, y->pot.input);
		assert_true(x->pot.rev_v == y->pot.rev_v);
		assert_true(x->pot.fwd_v == y->pot.fwd_v);
		assert_true(x->pot.nonlinear_v == y->pot.nonlinear_v);
		assert_true(x->pot.noise_v == y->pot.noise_v);
		assert_int_equal(x->pot.noise, y->pot.noise);
		assert_true(x->pot.open_v == y->pot.open_v);
		assert_true(x->home == y->home);
		assert_int_equal(x->encoder_reversed, y->encoder_reversed);
		assert_int_equal(x->limits_swapped, y->limits_swapped);
	}
	assert_int_equal(a->relay_wired, b->relay_wired);
	assert_int_equal(a->dead_inputs, b->dead_inputs);
	for (int j = 0; j < 12; j++)
		assert_int_equal(a->joy_input[j], b->joy_input[j]);
	assert_int_equal(a->joy_closed_level, b->joy_closed_level);
	assert_int_equal(a->seed, b->seed);
	assert_int_equal(a->amp_undervoltage, b->amp_undervoltage);
	assert_int_equal(a->power_output, b->power_output);
}

/* config/plant.yaml is the commented copy of the built-in defaults. */
static void test_config_file_is_the_default(void **state)
{
	struct sim_plant_cfg def, file;
	char err[256] = "";
	char path[512];
	const char *top = getenv("ROBOELF_TOP");

	(void)state;
	snprintf(path, sizeof(path), "%s/config/plant.yaml", top ? top : ".");
	sim_plant_cfg_default(&def);
	file = def;
	/* start from other values so that every key must be in the file */
	for (int i = 0; i < 3; i++) {
		struct sim_plant_axis_cfg *a = &file.axis[i];

		a->rotary = !a->rotary;
		a->rev_limit = -1;
		a->fwd_limit = 1;
		a->end_stop = a->start = a->max_speed = a->lag_ms = 0.5;
		a->pot.input = 4 + i;
		a->pot.rev_v = a->pot.fwd_v = a->pot.nonlinear_v = 0.25;
		a->pot.noise_v = a->pot.open_v = 0.25;
		a->pot.noise = SIM_PLANT_NOISE_UNIFORM;
		a->home = 0.5;
		a->encoder_reversed = a->limits_swapped = 1;
	}
	for (int j = 0; j < 12; j++)
		file.joy_input[j] = 21 + j % 10;
	file.relay_wired = 0;
	file.joy_closed_level = 0;
	file.seed = 99;
	file.amp_undervoltage = 0;
	file.power_output = 5;
	assert_int_equal(sim_plant_cfg_load(&file, path, err, sizeof(err)), 0);
	assert_string_equal(err, "");
	assert_cfg_equal(&file, &def);
}

static void test_config_overrides(void **state)
{
	struct sim_plant_cfg c;
	char err[256];

	(void)state;
	assert_int_equal(parse(&c,
			       "seed: 42\n"
			       "axes:\n"
			       "  B:\n"
			       "    kind: linear\n"
			       "    fwd_limit: 70000\n"
			       "    pot: {input: 5, noise: uniform}\n"
			       "joystick:\n"
			       "  closed_level: 0\n"
			       "  inputs: {C_rev: [30, 31]}\n",
			       err),
			 0);
	assert_int_equal(c.seed, 42);
	assert_int_equal(c.axis[1].rotary, 0);
	assert_true(c.axis[1].fwd_limit == 70000);
	assert_int_equal(c.axis[1].pot.input, 5);
	assert_int_equal(c.axis[1].pot.noise, SIM_PLANT_NOISE_UNIFORM);
	assert_true(c.axis[1].rev_limit == -50000); /* default kept */
	assert_int_equal(c.joy_closed_level, 0);
	assert_int_equal(c.joy_input[10], 30);
	assert_int_equal(c.joy_input[11], 31);
	assert_int_equal(c.joy_input[0], 1);
	assert_int_equal(c.amp_undervoltage, 1); /* defaults */
	assert_int_equal(c.power_output, 0);
	assert_int_equal(
	    parse(&c, "amp_undervoltage: false\npower_output: 3\n", err), 0);
	assert_int_equal(c.amp_undervoltage, 0);
	assert_int_equal(c.power_output, 3);
	assert_int_equal(parse(&c, "amp_undervoltage: true\n", err), 0);
	assert_int_equal(c.amp_undervoltage, 1);
}

struct bad_case {
	const char *text;
	const char *msg;
};

static const struct bad_case bad_cases[] = {
    {"", "p.yaml:1:1: empty plant file"},
    {"# only a comment\n", "p.yaml:1:1: empty plant file"},
    {"seeds: 3\n", "p.yaml:1:1: unknown key 'seeds'"},
    {"seed: 1\nseed: 2\n",
     "p.yaml:2:1: duplicate key 'seed' in the plant file"},
    {"- 1\n", "p.yaml:1:1: the plant file must be a mapping"},
    {"axes:\n  D: {}\n", "p.yaml:2:3: unknown axis 'D' (A, B or C)"},
    {"axes:\n  A:\n    fwd_limit: far\n",
     "p.yaml:3:16: 'fwd_limit' must be a number, not 'far'"},
    {"axes:\n  A:\n    lag: 3\n", "p.yaml:3:5: unknown key 'lag' in axes.A"},
    {"axes:\n  A:\n    pot:\n      noise: pink\n",
     "p.yaml:4:14: 'noise' must be 'gaussian' or 'uniform'"},
    {"axes:\n  A:\n    kind: circular\n",
     "p.yaml:3:11: 'kind' must be 'linear' or 'rotary'"},
    {"axes:\n  A:\n    pot: {input: 2.5}\n",
     "p.yaml:3:18: 'input' must be an integer, not '2.5'"},
    {"axes:\n  C:\n    pot: {nonlinear_v: 2}\n",
     "p.yaml:2:3: axis C: pot nonlinear_v 2 too large: the curve must "
     "be monotonic (|nonlinear_v| * pi < |fwd_v - rev_v|)"},
    {"axes:\n  C:\n    pot: {rev_v: 2, fwd_v: 2}\n",
     "p.yaml:2:3: axis C: pot needs rev_v != fwd_v, both -10..10 volts"},
    {"axes:\n  A: {home: 60000}\n",
     "p.yaml:2:3: axis A: home must lie between the limit switches"},
    {"axes:\n  A: {encoder_reversed: yes}\n",
     "p.yaml:2:25: 'encoder_reversed' must be 'false' or 'true'"},
    {"relay_wired: 0\n",
     "p.yaml:1:14: 'relay_wired' must be 'false' or 'true'"},
    {"axes:\n  B:\n    pot: {input: 1}\n",
     "p.yaml:2:3: axis B: pot input 1 already used by axis A"},
    {"axes:\n  A: {start: 60000}\n",
     "p.yaml:2:3: axis A: start must lie between the limit switches"},
    {"axes:\n  A: {rev_limit: 10}\n",
     "p.yaml:2:3: axis A: limits need rev_limit < 0 < fwd_limit (at "
     "most 1e8 counts)"},
    {"axes:\n  A: {max_speed: 0}\n",
     "p.yaml:2:3: axis A: needs 0 < max_speed <= 1e8 counts/s and "
     "0 <= lag_ms <= 1000"},
    {"joystick:\n  inputs: {A_fwd: [1, 3]}\n",
     "p.yaml:2:3: joystick input 3 used twice"},
    {"joystick:\n  inputs: {A_fwd: [1]}\n",
     "p.yaml:2:19: 'A_fwd' must be a list of two input numbers [a, b]"},
    {"joystick:\n  inputs: {A_fwd: [0, 2]}\n",
     "p.yaml:2:20: 'A_fwd' input 0 outside 1..32"},
    {"joystick:\n  inputs: {D_fwd: [9, 10]}\n",
     "p.yaml:2:12: unknown key 'D_fwd' in joystick.inputs (A_fwd A_rev "
     "B_fwd B_rev C_fwd C_rev)"},
    {"joystick:\n  closed_level: 2\n",
     "p.yaml:2:3: joystick closed_level must be 0 or 1"},
    {"seed: -1\n", "p.yaml:1:7: 'seed' must be >= 0"},
    {"amp_undervoltage: no\n",
     "p.yaml:1:19: 'amp_undervoltage' must be 'false' or 'true'"},
    {"power_output: 9\n",
     "p.yaml:1:15: power_output 9 outside 0 (none) or 1..8"},
    {"seed: 2\npower_output: -1\n",
     "p.yaml:2:15: power_output -1 outside 0 (none) or 1..8"},
    {"power_output: two\n",
     "p.yaml:1:15: 'power_output' must be an integer, not 'two'"},
    {"axes: [A]\n", "p.yaml:1:7: axes must be a mapping"},
    {"axes:\n  A:\n    fwd_limit: [1]\n",
     "p.yaml:3:16: 'fwd_limit' must be a number"},
    {"seed: 1\n  bad indent: 2\n",
     "p.yaml:2:13: mapping values are not allowed in this context"},
};

/* Every malformed file names file, line, column and the problem, and
 * leaves the configuration untouched. */
static void test_config_errors(void **state)
{
	struct sim_plant_cfg c, def;
	char err[256];

	(void)state;
	sim_plant_cfg_default(&def);
	for (size_t i = 0; i < sizeof(bad_cases) / sizeof(bad_cases[0]); i++) {
		err[0] = '\0';
		if (parse(&c, bad_cases[i].text, err) != GL_ERR_CONFIG ||
		    strcmp(err, bad_cases[i].msg))
			fail_msg("case %zu: got '%s'", i, err);
		assert_memory_equal(&c, &def, sizeof(def));
	}
}

static void test_config_missing_file(void **state)
{
	struct sim_plant_cfg c;
	char err[256];

	(void)state;
	sim_plant_cfg_default(&c);
	assert_int_equal(
	    sim_plant_cfg_load(&c, "/nonexistent/plant.yaml", err, sizeof(err)),
	    GL_ERR_CONFIG);
	assert_string_equal(err, "/nonexistent/plant.yaml:0:0: cannot open "
				 "plant file: No such file or directory");
}

#define T(name) cmocka_unit_test_setup_teardown(name, setup, teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_default_travel_takes_5_s),
	    T(test_pot_monotonic_over_travel),
	    T(test_pot_nonlinear),
	    T(test_pot_noise_gaussian_bounded),
	    T(test_pot_noise_uniform_bounded),
	    T(test_pot_noise_seeded),
	    T(test_pot_noise_runtime),
	    T(test_pot_faults),
	    T(test_motion_follows_reference),
	    T(test_motion_max_speed),
	    T(test_motion_needs_power),
	    T(test_amp_undervoltage_off),
	    T(test_power_output),
	    T(test_motion_needs_motor_on),
	    T(test_block),
	    T(test_encoder_stuck),
	    T(test_encoder_slip),
	    T(test_limit_switches_and_end_stop),
	    T(test_zero_encoders),
	    T(test_joystick_inputs),
	    T(test_joystick_active_low),
	    T(test_forced_inputs),
	    T(test_forced_analog),
	    cmocka_unit_test(test_config_file_is_the_default),
	    cmocka_unit_test(test_config_overrides),
	    cmocka_unit_test(test_config_errors),
	    cmocka_unit_test(test_config_missing_file),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
