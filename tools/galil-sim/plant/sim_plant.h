/*
 * sim_plant.h - the simulated RoboELF robot behind galil-sim's controller:
 * three axes between hard limit switches, motors that servo on their
 * encoders, potentiometers on analog inputs, 12 joystick switches on digital
 * inputs, and motor power switched by the E-stop relay.
 *
 * The plant is sampled once per servo sample: sim_plant_sense() produces
 * what the controller reads (struct ctrl_sense), then sim_plant_move()
 * applies what the controller commands (struct ctrl_drive) for one sample.
 * Positions are in encoder counts measured from the centre of travel, speeds
 * in counts/s, voltages in volts. Nothing here prints.
 */
#ifndef SIM_PLANT_H
#define SIM_PLANT_H

#include <stddef.h>
#include <stdint.h>

#include "ctrl.h"

#define SIM_PLANT_AXES	   3  /* A, B, C */
#define SIM_PLANT_SWITCHES 12 /* 6 commands x 2 redundant channels */

enum sim_plant_noise {
	SIM_PLANT_NOISE_GAUSSIAN, /* sigma = noise_v / 3, clipped at noise_v */
	SIM_PLANT_NOISE_UNIFORM,  /* uniform in [-noise_v, +noise_v] */
};

/* Potentiometer of one axis. */
struct sim_plant_pot_cfg {
	int input;	    /* analog input 1..8 */
	double rev_v;	    /* volts at the reverse limit switch */
	double fwd_v;	    /* volts at the forward limit switch (!= rev_v;
			       below rev_v: a pot wired reversed) */
	double nonlinear_v; /* amplitude of the sine bow, volts */
	double noise_v;	    /* noise bound, volts (>= 0) */
	enum sim_plant_noise noise;
	double open_v; /* reading with the wiper open, volts */
};

/* One axis. */
struct sim_plant_axis_cfg {
	int rotary;	  /* 1 rotary, 0 linear (informational) */
	double rev_limit; /* reverse limit switch position, counts */
	double fwd_limit; /* forward limit switch position, counts */
	double end_stop;  /* mechanical end beyond each switch, counts */
	double start;	  /* position at start-up, counts */
	double max_speed; /* fastest the motor turns, counts/s */
	double lag_ms;	  /* servo first-order lag, ms (0 = none) */
	/* home switch: grounded (active) below this position, pulled up at
	 * and above it; rev_limit..fwd_limit, counts (default 0 = centre) */
	double home;
	/* miswiring (0 = wired right): the encoder counts against the motor
	 * (the controller reads -x for a plant position x); the forward switch
	 * wired to the reverse limit input and the reverse one to the forward
	 * input */
	int encoder_reversed;
	int limits_swapped;
	struct sim_plant_pot_cfg pot;
};

/*
 * The whole robot. Joystick switch j = 2k + c (command k: 0 A fwd, 1 A rev,
 * 2 B fwd, 3 B rev, 4 C fwd, 5 C rev; channel c: 0 a, 1 b), the numbering
 * of docs/dmc-interface.md.
 */
struct sim_plant_cfg {
	struct sim_plant_axis_cfg axis[SIM_PLANT_AXES];
	int joy_input[SIM_PLANT_SWITCHES]; /* digital input 1..32 */
	int joy_closed_level; /* @IN level of a closed switch: 1 or 0 */
	unsigned long seed;   /* noise generator seed */
	/* 1: the amplifiers report a loss of motor power to the controller
	 * (under-voltage); 0: they keep quiet (logic supply kept) */
	int amp_undervoltage;
	/* 0: none; 1..SIM_PLANT_POWER_OUTPUTS: a controller digital output
	 * that must be set, besides the relay, for motor power */
	int power_output;
	/* 1: the relay board switches the amplifiers' motor power; 0
	 * (miswired): motor power stays on whatever the relay does */
	int relay_wired;
	/* inputs that never close (miswired): bit n-1 = input n reads the
	 * open level of a joystick switch (galil-sim --miswire dead-input:N) */
	uint32_t dead_inputs;
};

#define SIM_PLANT_POWER_OUTPUTS 8 /* power_output: outputs 1..8 */

enum sim_plant_pot_fault {
	SIM_PLANT_POT_OK,
	SIM_PLANT_POT_OFFSET, /* reading + offset volts */
	SIM_PLANT_POT_STUCK,  /* frozen at the reading when injected */
	SIM_PLANT_POT_OPEN,   /* wiper open: reads open_v, no noise */
};

enum sim_plant_enc_fault {
	SIM_PLANT_ENC_OK,
	SIM_PLANT_ENC_STUCK, /* count frozen at the value when injected */
	SIM_PLANT_ENC_SLIP,  /* count = position + slip counts */
};

enum sim_plant_dir {
	SIM_PLANT_NEUTRAL,
	SIM_PLANT_FWD,
	SIM_PLANT_REV,
};

/* Snapshot of one axis. */
struct sim_plant_axis_state {
	double pos;   /* true mechanical position, counts from centre */
	double vel;   /* true velocity over the last sample, counts/s */
	double enc;   /* encoder count register */
	double pot_v; /* last potentiometer reading, volts */
	int fwd_limit, rev_limit; /* switch active (physically) */
	int home;		  /* home switch active (grounded) */
	int blocked;		  /* mechanical jam injected */
	enum sim_plant_pot_fault pot_fault;
	enum sim_plant_enc_fault enc_fault;
};

struct sim_plant;

/*
 * sim_plant_cfg_default() - fill @cfg (caller's storage) with the built-in
 * default robot (the values of config/plant.yaml).
 */
void sim_plant_cfg_default(struct sim_plant_cfg *cfg);

/*
 * sim_plant_cfg_parse() - override @cfg with the YAML plant text @buf.
 * @cfg: [in,out] usually the defaults; left untouched on error.
 * @buf, @len: the YAML text and its length in bytes (not NUL-terminated
 *        necessarily; not kept).
 * @name: file name used in messages.
 * @err: [out] "NAME:LINE:COLUMN: message" on error; @errlen its size.
 * Unknown keys, duplicate keys, an empty document, wrong types and values
 * out of range are errors. Return: 0 or GL_ERR_CONFIG.
 */
int sim_plant_cfg_parse(struct sim_plant_cfg *cfg, const char *buf, size_t len,
			const char *name, char *err, size_t errlen);

/*
 * sim_plant_cfg_load() - sim_plant_cfg_parse() on the contents of @path
 * (the file name in messages is @path).
 * @cfg: [in,out] as for sim_plant_cfg_parse(). @err: [out], @errlen.
 * Return: 0 or GL_ERR_CONFIG ("PATH:0:0: cannot read ..." when unreadable).
 */
int sim_plant_cfg_load(struct sim_plant_cfg *cfg, const char *path, char *err,
		       size_t errlen);

/*
 * sim_plant_cfg_check() - range checks of a whole configuration.
 * @err: [out] a message naming the field; @errlen its size.
 * Return: 0 or GL_ERR_CONFIG.
 */
int sim_plant_cfg_check(const struct sim_plant_cfg *cfg, char *err,
			size_t errlen);

/*
 * sim_plant_cfg_miswire() - apply one miswiring @spec to @cfg (galil-sim
 * --miswire): "encoder-reversed:A", "limits-swapped:B", "relay-unwired",
 * "pot-reversed:C" (rev_v and fwd_v exchanged), "joystick-swap:5,7" (the
 * switches wired to inputs 5 and 7 exchange inputs; an input with no
 * switch takes the other's), "dead-input:6" (input 6 never closes),
 * "joystick-polarity" (closed_level inverted).
 * @cfg: [in,out] left untouched on error. @err: [out] the reason, @errlen.
 * Return: 0 or GL_ERR_ARG.
 */
int sim_plant_cfg_miswire(struct sim_plant_cfg *cfg, const char *spec,
			  char *err, size_t errlen);

/*
 * sim_plant_miswire() - sim_plant_cfg_miswire() on the configuration of a
 * running robot @p (the change applies from the next sample).
 * Return: 0 or GL_ERR_ARG (@err says why; nothing changed).
 */
int sim_plant_miswire(struct sim_plant *p, const char *spec, char *err,
		      size_t errlen);

/*
 * sim_plant_new() / sim_plant_free() - a robot at its start positions,
 * joysticks neutral, no fault, encoders reading 0 at the centre of travel;
 * and its release (NULL is a no-op).
 * @out: [out] the robot, owned by the caller (sim_plant_free()); NULL on
 *       failure. @cfg: copied, not kept.
 * Return: 0, GL_ERR_CONFIG (cfg fails sim_plant_cfg_check), GL_ERR_NOMEM.
 */
int sim_plant_new(struct sim_plant **out, const struct sim_plant_cfg *cfg);
void sim_plant_free(struct sim_plant *p);

/* sim_plant_get_cfg() - the configuration in use (owned by @p). */
const struct sim_plant_cfg *sim_plant_get_cfg(const struct sim_plant *p);

/* sim_plant_seed() - restart the noise generator from @seed. */
void sim_plant_seed(struct sim_plant *p, unsigned long seed);

/*
 * sim_plant_sense() - what the controller reads now: encoders, limit
 * and home switches (through the miswiring of the configuration), analog
 * inputs (pots + forced values), digital inputs (joystick
 * switches + forced levels), and what the amplifiers report as amp_power:
 * @power (motor power present), or always 1 when amp_undervoltage is 0.
 * Draws new noise.
 */
void sim_plant_sense(struct sim_plant *p, int power, struct ctrl_sense *out);

/*
 * sim_plant_motor_power() - 1 when the motors have power: the relay is on
 * (@relay_on; ignored when relay_wired is 0) and, when power_output is
 * configured, that bit of the controller's digital outputs @outputs (bit n-1 =
 * output n) is set.
 */
int sim_plant_motor_power(const struct sim_plant *p, int relay_on,
			  uint32_t outputs);

/*
 * sim_plant_set_amp_undervoltage() / sim_plant_set_power_output() -
 * override amp_undervoltage (0 or 1) and power_output (0..8) of the
 * configuration (galil-sim --no-amp-undervoltage, --power-output N).
 * Return: 0 or GL_ERR_ARG for a value out of range.
 */
int sim_plant_set_amp_undervoltage(struct sim_plant *p, int on);
int sim_plant_set_power_output(struct sim_plant *p, int output);

/*
 * sim_plant_move() - one sample of @dt_ms under the controller's @drive.
 * An axis moves only with its motor on, @power present and no jam: the
 * motor servos its encoder count onto drive->ref with the configured lag
 * (velocity = error / lag), limited to max_speed and to the end stops.
 */
void sim_plant_move(struct sim_plant *p, const struct ctrl_drive *drive,
		    int power, double dt_ms);

/*
 * sim_plant_pot_volts() - the noiseless potentiometer curve of @ax at
 * position @pos_counts: linear from rev_v at the reverse switch to fwd_v at
 * the forward switch plus nonlinear_v * sin(pi * u), u = 0..1 over that
 * travel, clamped to +-10 V. Monotonic when |nonlinear_v| * pi < fwd_v -
 * rev_v (enforced by sim_plant_cfg_check()).
 */
double sim_plant_pot_volts(const struct sim_plant_axis_cfg *ax,
			   double pos_counts);

/*
 * Faults of one axis (@axis 0..2): sim_plant_set_pot_fault() with
 * @offset_v the offset in volts (finite; used by SIM_PLANT_POT_OFFSET
 * only; STUCK freezes the last reading); sim_plant_set_pot_noise() the
 * noise bound @noise_v in volts (0..1); sim_plant_set_enc_fault() with
 * @slip_counts the offset in counts (|slip| <= 1e8, rounded; used by
 * SIM_PLANT_ENC_SLIP only; STUCK freezes the count); sim_plant_set_block()
 * a jam (non-zero) or none (0).
 * Return: 0, or GL_ERR_ARG for an axis, fault or value out of range
 * (nothing changed).
 */
int sim_plant_set_pot_fault(struct sim_plant *p, int axis,
			    enum sim_plant_pot_fault f, double offset_v);
int sim_plant_set_pot_noise(struct sim_plant *p, int axis, double noise_v);
int sim_plant_set_enc_fault(struct sim_plant *p, int axis,
			    enum sim_plant_enc_fault f, double slip_counts);
int sim_plant_set_block(struct sim_plant *p, int axis, int blocked);

/*
 * sim_plant_hold_limit() - a person trips the forward (@reverse 0) or the
 * reverse (@reverse 1) limit switch of @axis by hand (@held 1) or lets it
 * go (0): the switch reads active wherever the axis is (the commissioning
 * run asks for each switch in turn).
 * Return: 0, or GL_ERR_ARG for an axis out of range.
 */
int sim_plant_hold_limit(struct sim_plant *p, int axis, int reverse, int held);

/*
 * sim_plant_set_joy() - set the switches of @axis (0..2): @dir with channel
 * mask @chan (bit 0 = a, bit 1 = b; 3 = both) closed, every other switch of
 * that axis open. SIM_PLANT_NEUTRAL opens all four.
 * Return: 0, or GL_ERR_ARG for an axis, direction or mask out of range.
 */
int sim_plant_set_joy(struct sim_plant *p, int axis, enum sim_plant_dir dir,
		      unsigned chan);

/*
 * sim_plant_force_input() / sim_plant_release_input() - digital input @n
 * (1..32) forced to @level (0 or 1, overriding the joystick model), or
 * given back to the model.
 * Return: 0, or GL_ERR_ARG for @n or @level out of range.
 */
int sim_plant_force_input(struct sim_plant *p, int n, int level);
int sim_plant_release_input(struct sim_plant *p, int n);
/*
 * sim_plant_force_analog() / sim_plant_release_analog() - analog input @n
 * (1..8) forced to @volts (-10..10), or given back to the model.
 * Return: 0, or GL_ERR_ARG for @n or @volts out of range.
 */
int sim_plant_force_analog(struct sim_plant *p, int n, double volts);
int sim_plant_release_analog(struct sim_plant *p, int n);

/*
 * sim_plant_zero_encoders() - the controller powered up: every encoder
 * count register restarts at 0 at the current position (a stuck encoder
 * stays stuck, at 0; a slip offset is kept).
 */
void sim_plant_zero_encoders(struct sim_plant *p);

/*
 * sim_plant_axis() - copy the state of axis @axis (0..2) to @out.
 * Return: 0, or GL_ERR_ARG for an axis out of range.
 */
int sim_plant_axis(const struct sim_plant *p, int axis,
		   struct sim_plant_axis_state *out);

#endif /* SIM_PLANT_H */
