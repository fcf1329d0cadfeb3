/*
 * re_calshow.c - print and plot a calibration file. See re_calshow.h.
 */
#include "re_calshow.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gl_err.h"
#include "re_calfile.h"

#define DEFAULT_ALLOWED 0.5

/* The tolerance at point i: the step of the segment to its right (the
 * last point: to its left), as the run-time check uses it. */
static double band_v(const struct re_caltable *t, int i, double allowed)
{
	int k = i < t->n - 1 ? i : i - 1;

	return (1 + allowed) * fabs(t->pot_v[k + 1] - t->pot_v[k]);
}

static void print_axis(const struct re_calset *s, int a, double allowed,
		       FILE *out)
{
	const struct re_caltable *t = &s->axis[a];

	fprintf(out,
		"axis %s: %d points, start %.0f, step %.0f counts, soft "
		"limits %.0f..%.0f counts, pot %.4f..%.4f V, band (1 + %.2f) x "
		"step\n",
		s->name[a], t->n, t->start_counts, t->step_counts, t->soft_rev,
		t->soft_fwd, t->pot_v[0], t->pot_v[t->n - 1], allowed);
	fprintf(out, "  point   encoder    pot V   +-tol V\n");
	for (int i = 0; i < t->n; i++)
		fprintf(out, "  %5d %9.0f %8.4f %9.4f\n", i,
			t->start_counts + i * t->step_counts, t->pot_v[i],
			band_v(t, i, allowed));
}

/* gnuplot on PATH? */
static int have_gnuplot(void)
{
	const char *path = getenv("PATH");
	char dir[4096], exe[4352];

	while (path && *path) {
		size_t n = strcspn(path, ":");

		snprintf(dir, sizeof(dir), "%.*s", (int)n, path);
		snprintf(exe, sizeof(exe), "%s/gnuplot", dir[0] ? dir : ".");
		if (access(exe, X_OK) == 0)
			return 1;
		path += n + (path[n] == ':');
	}
	return 0;
}

/* Straight line through the end points: the residual shows wear. */
static double chord(const struct re_caltable *t, int i)
{
	return t->pot_v[0] +
	       (t->pot_v[t->n - 1] - t->pot_v[0]) * i / (t->n - 1);
}

/* One inline data block: x, y - @off, and the band around it. */
static void plot_data(FILE *gp, const struct re_caltable *t, double allowed,
		      int residual)
{
	for (int pass = 0; pass < 2; pass++) {
		for (int i = 0; i < t->n; i++) {
			double x = t->start_counts + i * t->step_counts;
			double y = t->pot_v[i] - (residual ? chord(t, i) : 0);
			double b = band_v(t, i, allowed);

			if (pass == 0)
				fprintf(gp, "%.0f %.5f %.5f\n", x, y - b,
					y + b);
			else
				fprintf(gp, "%.0f %.5f\n", x, y);
		}
		fprintf(gp, "e\n");
	}
}

static const char plot_cmd[] =
    "plot '-' using 1:2:3 with filledcurves fs transparent solid 0.3 "
    "title 'tolerance band', '-' using 1:2 with linespoints pt 7 ps 0.5 "
    "title '%s'\n";

static int plot_axis(const char *path, const struct re_calset *s, int a,
		     double allowed, FILE *out, FILE *err)
{
	const struct re_caltable *t = &s->axis[a];
	char png[1024];
	FILE *gp;

	snprintf(png, sizeof(png), "%s-%s.png", path, s->name[a]);
	gp = popen("gnuplot", "w");
	if (!gp) {
		fprintf(err, "roboelf-tech: warning: cannot run gnuplot\n");
		return -1;
	}
	fprintf(gp,
		"set terminal png size 900,900\nset output '%s'\n"
		"set multiplot layout 2,1 title 'axis %s: potentiometer "
		"against encoder'\nset xlabel 'encoder, counts'\n"
		"set ylabel 'potentiometer, V'\n",
		png, s->name[a]);
	fprintf(gp, plot_cmd, "table");
	plot_data(gp, t, allowed, 0);
	fprintf(gp, "set ylabel 'V minus the straight line'\n");
	fprintf(gp, plot_cmd, "deviation from the end-point line");
	plot_data(gp, t, allowed, 1);
	fprintf(gp, "unset multiplot\n");
	if (pclose(gp) != 0) {
		fprintf(err, "roboelf-tech: warning: gnuplot failed for '%s'\n",
			png);
		return -1;
	}
	fprintf(out, "wrote %s\n", png);
	return 0;
}

int re_calshow_print(const char *path, const double *allowed_error, int n,
		     FILE *out, FILE *err)
{
	static struct re_calset set;
	char msg[512];
	int rc = re_calfile_load(path, NULL, &set, msg, sizeof(msg));
	int plot;

	if (rc != GL_OK) {
		fprintf(err, "roboelf-tech: error: %s\n", msg);
		return rc;
	}
	fprintf(out,
		"calibration '%s': controller serial %s, %s, config hash "
		"%016llX, %d axes\n",
		path, set.serial, set.date, (unsigned long long)set.config_hash,
		set.n_axes);
	plot = have_gnuplot();
	for (int a = 0; a < set.n_axes; a++) {
		double allowed = a < n ? allowed_error[a] : DEFAULT_ALLOWED;

		print_axis(&set, a, allowed, out);
		if (plot)
			plot_axis(path, &set, a, allowed, out, err);
	}
	if (!plot)
		fprintf(out, "(gnuplot not installed: no plots)\n");
	return GL_OK;
}
