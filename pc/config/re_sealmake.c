/*
 * re_sealmake.c - the seal of a program for a configuration: the parameters
 * and controller settings taken from the configuration and the plan derived
 * from it. See re_sealmake.h.
 */
#include "re_sealmake.h"

#include <stdio.h>

#include "gl_err.h"
#include "re_plan.h"

static const char AXES[] = "ABC";

struct axis_param {
	const char *name, *what;
};

static const struct axis_param AXIS_PARAMS[] = {
    {"vmin", "minimum joystick velocity"},
    {"vmax", "maximum joystick velocity"},
    {"wst", "acceleration window start"},
    {"wen", "acceleration window end"},
    {"stp", "position-tracking step"},
    {"potin", "potentiometer input"},
    {"potlo", "potentiometer range, low end"},
    {"pothi", "potentiometer range, high end"},
    {"pnlo", "slow zone before the reverse switch"},
    {"pnhi", "slow zone before the forward switch"},
    {"svmax", "fastest service move"},
    {"svslow", "service speed near a switch"},
    {"svdmax", "longest service move"},
};
#define N_AXIS_PARAMS (sizeof(AXIS_PARAMS) / sizeof(AXIS_PARAMS[0]))

static double axis_param(const struct re_config *cfg, const struct re_plan *pl,
			 int k, int i)
{
	const struct re_config_axis *a = &cfg->axes[i];
	const struct re_plan_axis *x = &pl->axis[i];
	const double v[N_AXIS_PARAMS] = {
	    a->vmin_cps,
	    a->vmax_cps,
	    a->accel_start_ms,
	    a->accel_end_ms,
	    a->step_counts,
	    a->analog.input,
	    x->potlo_v,
	    x->pothi_v,
	    x->pnlo_v,
	    x->pnhi_v,
	    x->svmax_cps,
	    x->seek_cps,
	    (double)x->svdmax_counts,
	};

	return v[k];
}

static int add_params(struct re_seal *s, const struct re_config *cfg,
		      const struct re_plan *pl)
{
	static const double jval[6] = {3, 12, 48, 192, 768, 3072};
	char ref[RE_SEAL_REF_MAX];
	int rc = GL_OK;

	for (size_t k = 0; rc == GL_OK && k < N_AXIS_PARAMS; k++)
		for (int i = 0; rc == GL_OK && i < RE_AXES; i++) {
			snprintf(ref, sizeof(ref), "%s[%d]",
				 AXIS_PARAMS[k].name, i);
			rc = re_seal_add(s, RE_SEAL_PARAM, ref, i,
					 axis_param(cfg, pl, (int)k, i), 0,
					 AXIS_PARAMS[k].what);
		}
	for (int j = 0; rc == GL_OK && j < RE_JOY_INPUTS; j++) {
		snprintf(ref, sizeof(ref), "jin[%d]", j);
		rc = re_seal_add(s, RE_SEAL_PARAM, ref, j / 4,
				 cfg->joystick.inputs[j], 0,
				 "joystick switch input");
	}
	for (int k = 0; rc == GL_OK && k < 6; k++) {
		snprintf(ref, sizeof(ref), "jval[%d]", k);
		rc = re_seal_add(s, RE_SEAL_PARAM, ref, k / 2, jval[k], 0,
				 "joystick valid-state code");
	}
	if (rc == GL_OK)
		rc = re_seal_add(s, RE_SEAL_PARAM, "jpol", -1,
				 cfg->joystick.active_low ? 1 : 0, 0,
				 "joystick switch polarity");
	if (rc == GL_OK)
		rc = re_seal_add(s, RE_SEAL_PARAM, "jto", -1,
				 cfg->joystick.invalid_timeout_ms, 0,
				 "invalid-input timeout");
	if (rc == GL_OK)
		rc = re_seal_add(s, RE_SEAL_PARAM, "wdto", -1, pl->wdto_ms, 0,
				 "controller watchdog timeout");
	if (rc == GL_OK)
		rc = re_seal_add(s, RE_SEAL_PARAM, "hbmaxd", -1, pl->hbmaxd, 0,
				 "largest heartbeat step");
	if (rc == GL_OK)
		rc = re_seal_add(s, RE_SEAL_PARAM, "pwrout", -1, pl->pwrout, 0,
				 "motor-power output");
	/* mvto is not sealed: it belongs to each move request, as mvtg and
	 * mvsp do, and the program bounds it by the sealed svtmax */
	return rc;
}

static double setting_value(const struct re_config_axis *a, int k)
{
	const double v[] = {
	    a->kp,
	    a->ki,
	    a->kd,
	    a->torque_limit_v,
	    a->position_error_limit_counts,
	    a->off_on_error ? 1 : 0,
	    a->encoder_failure.enabled ? 1 : 0,
	    a->encoder_failure.time_samples,
	    a->encoder_failure.torque_v,
	    0, /* LD 0: both limit switches work */
	    1, /* MT 1: a servo motor */
	    0, /* CE 0: normal quadrature */
	};

	return v[k];
}

static int add_settings(struct re_seal *s, const struct re_config *cfg)
{
	char ref[RE_SEAL_REF_MAX];
	int rc = GL_OK;

	const struct re_seal_setting *st;

	for (int k = 0; rc == GL_OK && (st = re_seal_setting_at(k)); k++)
		for (int i = 0; rc == GL_OK && i < RE_AXES; i++) {
			snprintf(ref, sizeof(ref), "_%s%c", st->cmd, AXES[i]);
			rc = re_seal_add(s, RE_SEAL_SETTING, ref, i,
					 setting_value(&cfg->axes[i], k),
					 st->tol, st->what);
		}
	if (rc == GL_OK)
		rc = re_seal_add_fixed(s);
	return rc;
}

int re_seal_make(const char *body, size_t len, const struct re_config *cfg,
		 struct re_seal *out, char *err, size_t errlen)
{
	struct re_plan plan;
	double mainms = 0;
	int rc = re_seal_start(body, len, out, err, errlen);

	if (rc == GL_OK && re_seal_const(out, "mainms", &mainms) != GL_OK) {
		snprintf(err, errlen, "the program's #CONSTS has no mainms");
		return GL_ERR_FORMAT;
	}
	if (rc != GL_OK)
		return rc;
	re_plan_make(cfg, (int)mainms, &plan);
	rc = add_params(out, cfg, &plan);
	if (rc == GL_OK)
		rc = add_settings(out, cfg);
	if (rc == GL_OK)
		rc = re_seal_end(out);
	if (rc == GL_ERR_OVERFLOW)
		snprintf(err, errlen, "more than %d sealed values",
			 RE_SEAL_MAX);
	return rc;
}
