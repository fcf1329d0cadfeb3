/*
 * re_calib_table.c - the table of an axis from its sweep: each sample to
 * its nearest point, each point's value the least-squares line through
 * its samples, a point without enough of them fitted from its neighbours,
 * and the table's checks (re_calcheck.h).
 */
#include "re_calib_int.h"

#include <math.h>
#include <string.h>

#include "gl_err.h"

/* Add this sample to the table point nearest to the encoder. */
void cal_accumulate(struct re_calib *c, const struct re_calib_cfg *cfg, int i)
{
	struct cal_axis *ax = &c->ax[i];
	double step = cfg->axis[i].step_counts;
	double enc = cal_enc(c, i), pot = cal_pot(c, cfg, i);
	long j = lround((enc - ax->start) / step);
	struct acc *a;
	double dx;

	if (j < 0 || j >= RE_CAL_MAX_POINTS)
		return;
	a = &ax->acc[j];
	dx = enc - (ax->start + (double)j * step);
	a->n++;
	a->sx += dx;
	a->sy += pot;
	a->sxx += dx * dx;
	a->sxy += dx * pot;
}

/* The value at a point: the least-squares line through its samples, read
 * at the point; the mean when the samples do not spread. */
static double point_value(const struct acc *a, double step, double *enc_off)
{
	double mx = a->sx / a->n, my = a->sy / a->n;
	double var = a->sxx / a->n - mx * mx;

	*enc_off = mx;
	if (a->n < 3 || var < (step / 20) * (step / 20))
		return my;
	return my - (a->sxy / a->n - mx * my) / var * mx;
}

/* @a's sums with every dx shifted by @d. */
static void acc_add_shifted(struct acc *out, const struct acc *a, double d)
{
	out->n += a->n;
	out->sx += a->sx + a->n * d;
	out->sy += a->sy;
	out->sxx += a->sxx + 2 * d * a->sx + a->n * d * d;
	out->sxy += a->sxy + d * a->sy;
}

/* Samples that do not spread over a point's window (fewer than 3, or all
 * near one edge: the PC stalled) cannot give its value at the point. */
static int sparse(const struct acc *a, double step)
{
	double mx, var;

	if (a->n < 3)
		return 1;
	mx = a->sx / a->n;
	var = a->sxx / a->n - mx * mx;
	return var < (step / 8) * (step / 8);
}

/* A point whose samples are sparse or missing (the PC stalled up to one
 * step): the line through its own and both neighbours' samples, when
 * both neighbours have some. */
static int fill_point(const struct cal_axis *ax, int j, int n, double step,
		      struct acc *out)
{
	memset(out, 0, sizeof(*out));
	if (j < 1 || j + 1 >= n || !ax->acc[j - 1].n || !ax->acc[j + 1].n)
		return -1;
	acc_add_shifted(out, &ax->acc[j - 1], -step);
	acc_add_shifted(out, &ax->acc[j], 0);
	acc_add_shifted(out, &ax->acc[j + 1], step);
	return 0;
}

int cal_build_table(struct re_calib *c, const struct re_calib_cfg *cfg, int i,
		    struct re_caltable *t, struct re_fault *f)
{
	const struct re_calib_axis_cfg *a = &cfg->axis[i];
	struct cal_axis *ax = &c->ax[i];
	double prev_enc = 0, enc_off;
	long n = lround(floor((ax->soft_fwd - ax->start) / a->step_counts)) + 1;
	struct acc filled;

	memset(t, 0, sizeof(*t));
	t->n = n > RE_CAL_MAX_POINTS ? RE_CAL_MAX_POINTS : (int)n;
	t->start_counts = ax->start;
	t->step_counts = a->step_counts;
	t->soft_rev = ax->start;
	t->soft_fwd = ax->soft_fwd;
	for (int j = 0; j < t->n; j++) {
		const struct acc *s = &ax->acc[j];
		double x = ax->start + (double)j * a->step_counts;

		if (sparse(s, a->step_counts) &&
		    fill_point(ax, j, t->n, a->step_counts, &filled) == 0) {
			s = &filled;
			c->filled++;
		} else if (s->n == 0) {
			return cal_abort(f, i,
					 "no potentiometer sample near point "
					 "%d (encoder %.0f)",
					 j, x);
		}
		t->pot_v[j] = point_value(s, a->step_counts, &enc_off);
		if (s == &filled)
			enc_off = 0; /* the line is read at the point itself */
		if (j > 0 &&
		    re_cal_check_point(&a->check, i, j, a->step_counts,
				       prev_enc, x + enc_off, t->pot_v[j - 1],
				       t->pot_v[j], f) == RE_FAULT)
			return RE_FAULT;
		prev_enc = x + enc_off;
	}
	return re_cal_check_table(&a->check, i, t, f) == RE_FAULT ? RE_FAULT
								  : GL_OK;
}
