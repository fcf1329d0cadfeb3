/*
 * re_calcheck.h - the checks calibration runs while it builds a table and
 * before it saves or uses one: each point, then the whole table (values,
 * monotony, limits, ends). Pure functions; the verdicts and struct
 * re_fault as in re_check.h.
 *
 * Not the cycle's checks (re_check) nor the calibration sequence (re_calib).
 */
#ifndef RE_CALCHECK_H
#define RE_CALCHECK_H

#include "re_check.h"

/* ---- calibration-time checks --------------------------------------------- */

struct re_calcheck_cfg {
	double noise_margin_v;	 /* rise per point must exceed it, >= 0 */
	double expected_range_v; /* pot[n-1] - pot[0] expected, > 0 */
	double range_tol;	 /* fraction of expected_range_v, e.g. 0.1 */
	int min_points;		 /* >= 2 */
	int max_points;		 /* <= RE_CAL_MAX_POINTS */
	double step_tol_counts;	 /* allowed |advance - step|, counts, >= 0 */
	/* the end values against the potentiometer's expected absolute
	 * readings there (0 tolerance: not checked) */
	double abs_first_v; /* expected pot at point 0, V */
	double abs_last_v;  /* expected pot at point n-1, V */
	double abs_tol_v;   /* allowed |pot - expected| there, V */
};

/*
 * re_cal_check_point() - checks for point @index (>= 1) as it is recorded:
 * the encoder advanced by step +- step_tol_counts since the previous point
 * (RE_F_CAL_ENCSTEP: jammed axis, slipping encoder), and the potentiometer
 * rose by more than noise_margin_v (RE_F_CAL_NONMONO):
 *   pot_v - prev_pot_v > noise_margin_v.
 * Return: RE_OK, RE_FAULT (fault filled), GL_ERR_ARG.
 */
int re_cal_check_point(const struct re_calcheck_cfg *cfg, int axis, int index,
		       double step_counts, double prev_enc_counts,
		       double enc_counts, double prev_pot_v, double pot_v,
		       struct re_fault *fault);

/*
 * re_cal_check_table() - checks on a whole table (after calibration, and on
 * load from a file), first failure reported:
 *  - min_points <= n <= max_points (RE_F_CAL_POINTS);
 *  - step_counts > 0, values finite, strictly increasing by more than
 *    noise_margin_v (RE_F_CAL_NONMONO, point index named);
 *  - |(pot[n-1] - pot[0]) - expected| <= range_tol x expected
 *    (RE_F_CAL_RANGE);
 *  - soft limits inside the travel: start - step <= soft_rev < soft_fwd <=
 *    start + (n - 1 + 1) x step (RE_F_CAL_LIMITS);
 *  - when abs_tol_v > 0: |pot[0] - abs_first_v| <= abs_tol_v and
 *    |pot[n-1] - abs_last_v| <= abs_tol_v (RE_F_CAL_ABSOLUTE: an offset
 *    present before the sweep, a wrong pot, wrong wiring).
 * Return: RE_OK, RE_FAULT, GL_ERR_ARG (NULL or bad cfg).
 */
int re_cal_check_table(const struct re_calcheck_cfg *cfg, int axis,
		       const struct re_caltable *t, struct re_fault *fault);

#endif /* RE_CALCHECK_H */
