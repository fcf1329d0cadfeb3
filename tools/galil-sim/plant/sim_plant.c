/*
 * sim_plant.c - the simulated robot: kinematics, sensors, faults.
 *
 * The motion model is a velocity-mode servo closed on the encoder count:
 * velocity = (ref - encoder) / lag, limited to max_speed, with the true
 * position clamped to the mechanical end stops. With a healthy encoder this
 * is a first-order lag behind the controller's reference; with a slipped
 * encoder the motor really moves by the slip; with a stuck encoder the motor
 * runs away as a real servo does; a jam freezes the motor. The YAML loader
 * for the plant file is in sim_plant_cfg.c.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "sim_plant.h"

#define POT_RAIL_V 10.0 /* analog inputs read +-10 V (AQ2) */

struct plant_axis {
	double pos;	  /* true position, counts from centre */
	double vel;	  /* counts/s over the last sample */
	double origin;	  /* position where the encoder read 0 */
	double enc_stuck; /* frozen count (SIM_PLANT_ENC_STUCK) */
	double slip;	  /* counts (SIM_PLANT_ENC_SLIP) */
	enum sim_plant_enc_fault enc_fault;
	enum sim_plant_pot_fault pot_fault;
	double pot_offset_v;
	double pot_stuck_v;
	double pot_v;	/* last reading */
	double noise_v; /* current noise bound */
	int blocked;
	int held[2]; /* [0] forward, [1] reverse switch tripped by hand */
};

struct sim_plant {
	struct sim_plant_cfg cfg;
	struct plant_axis ax[SIM_PLANT_AXES];
	int joy_closed[SIM_PLANT_SWITCHES];
	uint32_t in_forced; /* bit n-1: input n forced */
	uint32_t in_level;  /* forced levels */
	unsigned an_forced; /* bit n-1: analog n forced */
	double an_v[CTRL_ANALOG];
	uint64_t rng; /* xorshift64* state */
};

static const struct sim_plant_axis_cfg default_axis[SIM_PLANT_AXES] = {
    {1,
     -50000,
     50000,
     2000,
     0,
     40000,
     2,
     0,
     0,
     0,
     {1, 0.5, 4.5, 0.05, 0.002, SIM_PLANT_NOISE_GAUSSIAN, 0.0}},
    {1,
     -50000,
     50000,
     2000,
     0,
     40000,
     2,
     0,
     0,
     0,
     {2, 0.5, 4.5, 0.05, 0.002, SIM_PLANT_NOISE_GAUSSIAN, 0.0}},
    {0,
     -40000,
     40000,
     2000,
     0,
     30000,
     2,
     0,
     0,
     0,
     {3, 0.5, 4.5, 0.04, 0.002, SIM_PLANT_NOISE_GAUSSIAN, 0.0}},
};

static const int default_joy[SIM_PLANT_SWITCHES] = {1, 2, 3,  4,  5,  6,
						    7, 8, 17, 18, 19, 20};

void sim_plant_cfg_default(struct sim_plant_cfg *cfg)
{
	memset(cfg, 0, sizeof(*cfg));
	memcpy(cfg->axis, default_axis, sizeof(default_axis));
	memcpy(cfg->joy_input, default_joy, sizeof(default_joy));
	cfg->joy_closed_level = 1;
	cfg->seed = 1;
	cfg->amp_undervoltage = 1;
	cfg->power_output = 0;
	cfg->relay_wired = 1;
	cfg->dead_inputs = 0;
}

static int check_pot(const struct sim_plant_pot_cfg *pot, char *err,
		     size_t errlen)
{
	if (pot->input < 1 || pot->input > CTRL_ANALOG) {
		snprintf(err, errlen, "pot input %d outside 1..%d", pot->input,
			 CTRL_ANALOG);
		return GL_ERR_CONFIG;
	}
	if (!(pot->fwd_v != pot->rev_v) || fabs(pot->rev_v) > POT_RAIL_V ||
	    fabs(pot->fwd_v) > POT_RAIL_V) {
		snprintf(err, errlen,
			 "pot needs rev_v != fwd_v, both -10..10 volts");
		return GL_ERR_CONFIG;
	}
	if (!(fabs(pot->nonlinear_v) * M_PI < fabs(pot->fwd_v - pot->rev_v))) {
		snprintf(err, errlen,
			 "pot nonlinear_v %g too large: the curve must be "
			 "monotonic (|nonlinear_v| * pi < |fwd_v - rev_v|)",
			 pot->nonlinear_v);
		return GL_ERR_CONFIG;
	}
	if (!(pot->noise_v >= 0 && pot->noise_v <= 1.0) ||
	    fabs(pot->open_v) > POT_RAIL_V) {
		snprintf(
		    err, errlen,
		    "pot needs 0 <= noise_v <= 1 and |open_v| <= 10 volts");
		return GL_ERR_CONFIG;
	}
	return 0;
}

static int check_axis(const struct sim_plant_axis_cfg *a, char *err,
		      size_t errlen)
{
	if (!(a->rev_limit < 0 && a->fwd_limit > 0) || a->fwd_limit > 1e8 ||
	    a->rev_limit < -1e8) {
		snprintf(err, errlen,
			 "limits need rev_limit < 0 < fwd_limit "
			 "(at most 1e8 counts)");
		return GL_ERR_CONFIG;
	}
	if (!(a->end_stop >= 0 && a->end_stop <= 1e7)) {
		snprintf(err, errlen, "end_stop must be 0..1e7 counts");
		return GL_ERR_CONFIG;
	}
	if (!(a->start > a->rev_limit && a->start < a->fwd_limit)) {
		snprintf(err, errlen,
			 "start must lie between the limit "
			 "switches");
		return GL_ERR_CONFIG;
	}
	if (!(a->home >= a->rev_limit && a->home <= a->fwd_limit)) {
		snprintf(err, errlen,
			 "home must lie between the limit switches");
		return GL_ERR_CONFIG;
	}
	if ((a->encoder_reversed != 0 && a->encoder_reversed != 1) ||
	    (a->limits_swapped != 0 && a->limits_swapped != 1)) {
		snprintf(err, errlen,
			 "encoder_reversed and limits_swapped must be true "
			 "or false");
		return GL_ERR_CONFIG;
	}
	if (!(a->max_speed > 0 && a->max_speed <= 1e8) ||
	    !(a->lag_ms >= 0 && a->lag_ms <= 1000)) {
		snprintf(err, errlen,
			 "needs 0 < max_speed <= 1e8 counts/s and "
			 "0 <= lag_ms <= 1000");
		return GL_ERR_CONFIG;
	}
	return check_pot(&a->pot, err, errlen);
}

static int check_joy(const struct sim_plant_cfg *cfg, char *err, size_t errlen)
{
	for (int j = 0; j < SIM_PLANT_SWITCHES; j++) {
		int in = cfg->joy_input[j];

		if (in < 1 || in > CTRL_INPUTS) {
			snprintf(err, errlen, "joystick input %d outside 1..%d",
				 in, CTRL_INPUTS);
			return GL_ERR_CONFIG;
		}
		for (int k = 0; k < j; k++) {
			if (cfg->joy_input[k] == in) {
				snprintf(err, errlen,
					 "joystick input %d used "
					 "twice",
					 in);
				return GL_ERR_CONFIG;
			}
		}
	}
	if (cfg->joy_closed_level != 0 && cfg->joy_closed_level != 1) {
		snprintf(err, errlen, "joystick closed_level must be 0 or 1");
		return GL_ERR_CONFIG;
	}
	return 0;
}

static int check_power(const struct sim_plant_cfg *cfg, char *err,
		       size_t errlen)
{
	if (cfg->amp_undervoltage != 0 && cfg->amp_undervoltage != 1) {
		snprintf(err, errlen, "amp_undervoltage must be true or false");
		return GL_ERR_CONFIG;
	}
	if (cfg->relay_wired != 0 && cfg->relay_wired != 1) {
		snprintf(err, errlen, "relay_wired must be true or false");
		return GL_ERR_CONFIG;
	}
	if (cfg->power_output < 0 ||
	    cfg->power_output > SIM_PLANT_POWER_OUTPUTS) {
		snprintf(err, errlen,
			 "power_output %d outside 0 (none) or 1..%d",
			 cfg->power_output, SIM_PLANT_POWER_OUTPUTS);
		return GL_ERR_CONFIG;
	}
	return 0;
}

int sim_plant_cfg_check(const struct sim_plant_cfg *cfg, char *err,
			size_t errlen)
{
	char msg[160];

	for (int i = 0; i < SIM_PLANT_AXES; i++) {
		if (check_axis(&cfg->axis[i], msg, sizeof(msg)) < 0) {
			snprintf(err, errlen, "axis %c: %s", 'A' + i, msg);
			return GL_ERR_CONFIG;
		}
		for (int k = 0; k < i; k++) {
			if (cfg->axis[k].pot.input == cfg->axis[i].pot.input) {
				snprintf(err, errlen,
					 "axis %c: pot input %d "
					 "already used by axis %c",
					 'A' + i, cfg->axis[i].pot.input,
					 'A' + k);
				return GL_ERR_CONFIG;
			}
		}
	}
	if (check_power(cfg, err, errlen) < 0)
		return GL_ERR_CONFIG;
	return check_joy(cfg, err, errlen);
}

/* ---- noise ------------------------------------------------------------ */

static uint64_t rng_next(uint64_t *s)
{
	uint64_t x = *s;

	x ^= x >> 12;
	x ^= x << 25;
	x ^= x >> 27;
	*s = x;
	return x * 0x2545F4914F6CDD1DULL;
}

/* uniform in (0, 1) */
static double rng_unit(uint64_t *s)
{
	return ((double)(rng_next(s) >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

static double noise_sample(struct sim_plant *p, enum sim_plant_noise kind,
			   double bound_v)
{
	double g;

	if (bound_v <= 0)
		return 0;
	if (kind == SIM_PLANT_NOISE_UNIFORM)
		return bound_v * (2 * rng_unit(&p->rng) - 1);
	/* Box-Muller, one value per call; sigma = bound / 3, clipped */
	g = sqrt(-2 * log(rng_unit(&p->rng))) *
	    cos(2 * M_PI * rng_unit(&p->rng));
	g *= bound_v / 3;
	if (g > bound_v)
		g = bound_v;
	if (g < -bound_v)
		g = -bound_v;
	return g;
}

void sim_plant_seed(struct sim_plant *p, unsigned long seed)
{
	/* splitmix64 of the seed, never 0 */
	uint64_t z = (uint64_t)seed + 0x9E3779B97F4A7C15ULL;

	z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
	z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
	z ^= z >> 31;
	p->rng = z ? z : 1;
}

/* ---- life cycle ------------------------------------------------------- */

int sim_plant_new(struct sim_plant **out, const struct sim_plant_cfg *cfg)
{
	char msg[200];
	struct sim_plant *p;

	*out = NULL;
	if (sim_plant_cfg_check(cfg, msg, sizeof(msg)) < 0)
		return GL_ERR_CONFIG;
	p = calloc(1, sizeof(*p));
	if (!p)
		return GL_ERR_NOMEM;
	p->cfg = *cfg;
	for (int i = 0; i < SIM_PLANT_AXES; i++) {
		p->ax[i].pos = cfg->axis[i].start;
		p->ax[i].noise_v = cfg->axis[i].pot.noise_v;
		p->ax[i].pot_v =
		    sim_plant_pot_volts(&cfg->axis[i], p->ax[i].pos);
	}
	sim_plant_seed(p, cfg->seed);
	*out = p;
	return 0;
}

void sim_plant_free(struct sim_plant *p)
{
	free(p);
}

const struct sim_plant_cfg *sim_plant_get_cfg(const struct sim_plant *p)
{
	return &p->cfg;
}

/* ---- sensors ---------------------------------------------------------- */

double sim_plant_pot_volts(const struct sim_plant_axis_cfg *ax,
			   double pos_counts)
{
	const struct sim_plant_pot_cfg *pot = &ax->pot;
	double u =
	    (pos_counts - ax->rev_limit) / (ax->fwd_limit - ax->rev_limit);
	double v = pot->rev_v + (pot->fwd_v - pot->rev_v) * u +
		   pot->nonlinear_v * sin(M_PI * u);

	if (v > POT_RAIL_V)
		v = POT_RAIL_V;
	if (v < -POT_RAIL_V)
		v = -POT_RAIL_V;
	return v;
}

/* The count register: against the motor when the encoder is reversed. */
static double encoder_count(const struct plant_axis *a, int reversed)
{
	double x = reversed ? a->origin - a->pos : a->pos - a->origin;

	switch (a->enc_fault) {
	case SIM_PLANT_ENC_STUCK: return a->enc_stuck;
	case SIM_PLANT_ENC_SLIP: return round(x + a->slip);
	default: return round(x);
	}
}

static double axis_count(const struct sim_plant *p, int i)
{
	return encoder_count(&p->ax[i], p->cfg.axis[i].encoder_reversed);
}

static double pot_reading(struct sim_plant *p, int i)
{
	struct plant_axis *a = &p->ax[i];
	const struct sim_plant_axis_cfg *ac = &p->cfg.axis[i];
	double v;

	switch (a->pot_fault) {
	case SIM_PLANT_POT_STUCK: return a->pot_stuck_v;
	case SIM_PLANT_POT_OPEN: return ac->pot.open_v;
	default: break;
	}
	v = sim_plant_pot_volts(ac, a->pos) +
	    noise_sample(p, ac->pot.noise, a->noise_v);
	if (a->pot_fault == SIM_PLANT_POT_OFFSET)
		v += a->pot_offset_v;
	if (v > POT_RAIL_V)
		v = POT_RAIL_V;
	if (v < -POT_RAIL_V)
		v = -POT_RAIL_V;
	return v;
}

static uint32_t input_word(const struct sim_plant *p)
{
	uint32_t w = 0;

	for (int j = 0; j < SIM_PLANT_SWITCHES; j++) {
		int level = p->joy_closed[j] ? p->cfg.joy_closed_level
					     : !p->cfg.joy_closed_level;

		if (level)
			w |= 1u << (p->cfg.joy_input[j] - 1);
	}
	if (p->cfg.joy_closed_level) /* dead inputs read the open level */
		w &= ~p->cfg.dead_inputs;
	else
		w |= p->cfg.dead_inputs;
	return (w & ~p->in_forced) | (p->in_level & p->in_forced);
}

void sim_plant_sense(struct sim_plant *p, int power, struct ctrl_sense *out)
{
	memset(out, 0, sizeof(*out));
	for (int i = 0; i < SIM_PLANT_AXES; i++) {
		const struct sim_plant_axis_cfg *ac = &p->cfg.axis[i];
		struct plant_axis *a = &p->ax[i];

		/* the physical switches (a hand-held one too), then the wiring
		 */
		int fwd = a->pos >= ac->fwd_limit || a->held[0],
		    rev = a->pos <= ac->rev_limit || a->held[1];

		out->enc[i] = axis_count(p, i);
		out->fwd_limit[i] = ac->limits_swapped ? rev : fwd;
		out->rev_limit[i] = ac->limits_swapped ? fwd : rev;
		out->home[i] = a->pos < ac->home;
		a->pot_v = pot_reading(p, i);
		out->an_v[ac->pot.input - 1] = a->pot_v;
	}
	for (int n = 0; n < CTRL_ANALOG; n++) {
		if (p->an_forced & (1u << n))
			out->an_v[n] = p->an_v[n];
	}
	out->inputs = input_word(p);
	out->amp_power = power || !p->cfg.amp_undervoltage;
}

int sim_plant_motor_power(const struct sim_plant *p, int relay_on,
			  uint32_t outputs)
{
	int n = p->cfg.power_output;

	return (relay_on || !p->cfg.relay_wired) &&
	       (n == 0 || ((outputs >> (n - 1)) & 1));
}

int sim_plant_miswire(struct sim_plant *p, const char *spec, char *err,
		      size_t errlen)
{
	struct sim_plant_cfg c = p->cfg;
	int rc = sim_plant_cfg_miswire(&c, spec, err, errlen);

	if (rc)
		return rc;
	if (sim_plant_cfg_check(&c, err, errlen) < 0)
		return GL_ERR_ARG;
	p->cfg = c;
	return 0;
}

int sim_plant_set_amp_undervoltage(struct sim_plant *p, int on)
{
	if (on != 0 && on != 1)
		return GL_ERR_ARG;
	p->cfg.amp_undervoltage = on;
	return 0;
}

int sim_plant_set_power_output(struct sim_plant *p, int output)
{
	if (output < 0 || output > SIM_PLANT_POWER_OUTPUTS)
		return GL_ERR_ARG;
	p->cfg.power_output = output;
	return 0;
}

/* ---- motion ----------------------------------------------------------- */

static void move_axis(struct sim_plant *p, int i, const struct ctrl_drive *d,
		      int power, double dt_ms)
{
	const struct sim_plant_axis_cfg *ac = &p->cfg.axis[i];
	struct plant_axis *a = &p->ax[i];
	double dx, lim, lo, hi, old = a->pos;

	if (dt_ms <= 0)
		return;
	if (power && d->motor_on[i] && !a->blocked) {
		/* the motor turns the way the controller's error says */
		dx = d->ref[i] - axis_count(p, i);
		if (ac->lag_ms > 0)
			dx *= 1 - exp(-dt_ms / ac->lag_ms);
		lim = ac->max_speed * dt_ms / 1000;
		if (dx > lim)
			dx = lim;
		if (dx < -lim)
			dx = -lim;
		lo = ac->rev_limit - ac->end_stop;
		hi = ac->fwd_limit + ac->end_stop;
		a->pos += dx;
		if (a->pos > hi)
			a->pos = hi;
		if (a->pos < lo)
			a->pos = lo;
	}
	a->vel = (a->pos - old) * 1000 / dt_ms;
}

void sim_plant_move(struct sim_plant *p, const struct ctrl_drive *drive,
		    int power, double dt_ms)
{
	for (int i = 0; i < SIM_PLANT_AXES; i++)
		move_axis(p, i, drive, power, dt_ms);
}

/* ---- faults and inputs ------------------------------------------------ */

int sim_plant_set_pot_fault(struct sim_plant *p, int axis,
			    enum sim_plant_pot_fault f, double offset_v)
{
	if (axis < 0 || axis >= SIM_PLANT_AXES || !isfinite(offset_v) ||
	    f < SIM_PLANT_POT_OK || f > SIM_PLANT_POT_OPEN)
		return GL_ERR_ARG;
	p->ax[axis].pot_fault = f;
	p->ax[axis].pot_offset_v = f == SIM_PLANT_POT_OFFSET ? offset_v : 0;
	p->ax[axis].pot_stuck_v = p->ax[axis].pot_v;
	return 0;
}

int sim_plant_set_pot_noise(struct sim_plant *p, int axis, double noise_v)
{
	if (axis < 0 || axis >= SIM_PLANT_AXES ||
	    !(noise_v >= 0 && noise_v <= 1.0))
		return GL_ERR_ARG;
	p->ax[axis].noise_v = noise_v;
	return 0;
}

int sim_plant_set_enc_fault(struct sim_plant *p, int axis,
			    enum sim_plant_enc_fault f, double slip_counts)
{
	struct plant_axis *a;

	if (axis < 0 || axis >= SIM_PLANT_AXES || !isfinite(slip_counts) ||
	    fabs(slip_counts) > 1e8 || f < SIM_PLANT_ENC_OK ||
	    f > SIM_PLANT_ENC_SLIP)
		return GL_ERR_ARG;
	a = &p->ax[axis];
	a->enc_stuck = axis_count(p, axis);
	a->enc_fault = f;
	a->slip = f == SIM_PLANT_ENC_SLIP ? round(slip_counts) : 0;
	return 0;
}

int sim_plant_set_block(struct sim_plant *p, int axis, int blocked)
{
	if (axis < 0 || axis >= SIM_PLANT_AXES)
		return GL_ERR_ARG;
	p->ax[axis].blocked = blocked ? 1 : 0;
	return 0;
}

int sim_plant_hold_limit(struct sim_plant *p, int axis, int reverse, int held)
{
	if (axis < 0 || axis >= SIM_PLANT_AXES)
		return GL_ERR_ARG;
	p->ax[axis].held[reverse ? 1 : 0] = held ? 1 : 0;
	return 0;
}

int sim_plant_set_joy(struct sim_plant *p, int axis, enum sim_plant_dir dir,
		      unsigned chan)
{
	int fwd = 4 * axis, rev = 4 * axis + 2;

	if (axis < 0 || axis >= SIM_PLANT_AXES || chan > 3 ||
	    dir < SIM_PLANT_NEUTRAL || dir > SIM_PLANT_REV)
		return GL_ERR_ARG;
	for (int c = 0; c < 2; c++) {
		int closed = (chan >> c) & 1;

		p->joy_closed[fwd + c] = dir == SIM_PLANT_FWD && closed;
		p->joy_closed[rev + c] = dir == SIM_PLANT_REV && closed;
	}
	return 0;
}

int sim_plant_force_input(struct sim_plant *p, int n, int level)
{
	if (n < 1 || n > CTRL_INPUTS || (level != 0 && level != 1))
		return GL_ERR_ARG;
	p->in_forced |= 1u << (n - 1);
	if (level)
		p->in_level |= 1u << (n - 1);
	else
		p->in_level &= ~(1u << (n - 1));
	return 0;
}

int sim_plant_release_input(struct sim_plant *p, int n)
{
	if (n < 1 || n > CTRL_INPUTS)
		return GL_ERR_ARG;
	p->in_forced &= ~(1u << (n - 1));
	return 0;
}

int sim_plant_force_analog(struct sim_plant *p, int n, double volts)
{
	if (n < 1 || n > CTRL_ANALOG || !(fabs(volts) <= POT_RAIL_V))
		return GL_ERR_ARG;
	p->an_forced |= 1u << (n - 1);
	p->an_v[n - 1] = volts;
	return 0;
}

int sim_plant_release_analog(struct sim_plant *p, int n)
{
	if (n < 1 || n > CTRL_ANALOG)
		return GL_ERR_ARG;
	p->an_forced &= ~(1u << (n - 1));
	return 0;
}

void sim_plant_zero_encoders(struct sim_plant *p)
{
	for (int i = 0; i < SIM_PLANT_AXES; i++) {
		p->ax[i].origin = p->ax[i].pos;
		p->ax[i].enc_stuck = 0;
	}
}

int sim_plant_axis(const struct sim_plant *p, int axis,
		   struct sim_plant_axis_state *out)
{
	const struct plant_axis *a;

	if (axis < 0 || axis >= SIM_PLANT_AXES)
		return GL_ERR_ARG;
	a = &p->ax[axis];
	out->pos = a->pos;
	out->vel = a->vel;
	out->enc = axis_count(p, axis);
	out->pot_v = a->pot_v;
	out->fwd_limit = a->pos >= p->cfg.axis[axis].fwd_limit || a->held[0];
	out->rev_limit = a->pos <= p->cfg.axis[axis].rev_limit || a->held[1];
	out->home = a->pos < p->cfg.axis[axis].home;
	out->blocked = a->blocked;
	out->pot_fault = a->pot_fault;
	out->enc_fault = a->enc_fault;
	return 0;
}
