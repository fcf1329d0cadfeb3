/*
 * sim_plant_miswire.c - galil-sim --miswire SPEC: a deliberate wiring
 * mistake applied to a plant configuration, so that the commissioning run
 * can be tested against each (docs/galil-sim.md, "Miswiring").
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "sim_plant.h"

/* "A".."C" after the ':' of @arg. Return the axis or -1. */
static int axis_arg(const char *arg)
{
	if (arg && arg[0] >= 'A' && arg[0] < 'A' + SIM_PLANT_AXES && !arg[1])
		return arg[0] - 'A';
	return -1;
}

/* A digital input number 1..CTRL_INPUTS at @s, up to @end. */
static int input_arg(const char *s, char **end)
{
	long v;

	if (!s || *s < '0' || *s > '9')
		return -1;
	v = strtol(s, end, 10);
	return v >= 1 && v <= CTRL_INPUTS ? (int)v : -1;
}

/* The switches wired to inputs @a and @b exchange places. */
static void joystick_swap(struct sim_plant_cfg *cfg, int a, int b)
{
	for (int j = 0; j < SIM_PLANT_SWITCHES; j++) {
		if (cfg->joy_input[j] == a)
			cfg->joy_input[j] = b;
		else if (cfg->joy_input[j] == b)
			cfg->joy_input[j] = a;
	}
}

static int per_axis(struct sim_plant_cfg *cfg, const char *what,
		    const char *arg)
{
	int ax = axis_arg(arg);
	struct sim_plant_axis_cfg *a;
	double v;

	if (ax < 0)
		return -1;
	a = &cfg->axis[ax];
	if (!strcmp(what, "encoder-reversed"))
		a->encoder_reversed = !a->encoder_reversed;
	else if (!strcmp(what, "limits-swapped"))
		a->limits_swapped = !a->limits_swapped;
	else {
		v = a->pot.rev_v;
		a->pot.rev_v = a->pot.fwd_v;
		a->pot.fwd_v = v;
	}
	return 0;
}

static int inputs(struct sim_plant_cfg *cfg, const char *what, const char *arg)
{
	char *end = NULL;
	int a = input_arg(arg, &end), b;

	if (a < 0)
		return -1;
	if (!strcmp(what, "dead-input")) {
		if (*end)
			return -1;
		cfg->dead_inputs |= 1u << (a - 1);
		return 0;
	}
	if (*end != ',' || (b = input_arg(end + 1, &end)) < 0 || *end || a == b)
		return -1;
	joystick_swap(cfg, a, b);
	return 0;
}

int sim_plant_cfg_miswire(struct sim_plant_cfg *cfg, const char *spec,
			  char *err, size_t errlen)
{
	char what[32];
	const char *colon = strchr(spec, ':'), *arg = colon ? colon + 1 : NULL;
	size_t n = colon ? (size_t)(colon - spec) : strlen(spec);
	struct sim_plant_cfg c = *cfg;
	int rc = -1;

	if (n >= sizeof(what))
		n = sizeof(what) - 1;
	memcpy(what, spec, n);
	what[n] = '\0';
	if (!strcmp(what, "encoder-reversed") ||
	    !strcmp(what, "limits-swapped") || !strcmp(what, "pot-reversed"))
		rc = per_axis(&c, what, arg);
	else if (!strcmp(what, "joystick-swap") || !strcmp(what, "dead-input"))
		rc = inputs(&c, what, arg);
	else if (!strcmp(what, "relay-unwired") && !arg) {
		c.relay_wired = 0;
		rc = 0;
	} else if (!strcmp(what, "joystick-polarity") && !arg) {
		c.joy_closed_level = !c.joy_closed_level;
		rc = 0;
	}
	if (rc < 0) {
		snprintf(
		    err, errlen,
		    "bad miswiring '%s' (encoder-reversed:AXIS, "
		    "limits-swapped:AXIS, relay-unwired, pot-reversed:AXIS, "
		    "joystick-swap:N,M, dead-input:N, joystick-polarity; "
		    "AXIS A..C, inputs 1..%d)",
		    spec, CTRL_INPUTS);
		return GL_ERR_ARG;
	}
	*cfg = c;
	return 0;
}
