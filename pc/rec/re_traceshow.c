/*
 * re_traceshow.c - print and plot a trace. See re_traceshow.h.
 */
#include "re_traceshow.h"

#include <errno.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base_file.h"
#include "gl_err.h"
#include "re_trace.h"

#define EXIT_BAD  2
#define EXIT_PLOT 3

/* The joystick switches in the order of joystick.inputs (= DMC jin[]). */
static const char *const joy_names[12] = {
    "A fwd a", "A fwd b", "A rev a", "A rev b", "B fwd a", "B fwd b",
    "B rev a", "B rev b", "C fwd a", "C fwd b", "C rev a", "C rev b"};

int re_traceshow_window(const char *s, struct re_traceshow_win *w)
{
	const char *colon = s ? strchr(s, ':') : NULL;
	char *end;

	memset(w, 0, sizeof(*w));
	if (!colon || strchr(colon + 1, ':'))
		return -1;
	if (colon > s) {
		errno = 0;
		w->from_s = strtod(s, &end);
		if (errno || end != colon)
			return -1;
		w->have_from = 1;
	}
	if (colon[1]) {
		errno = 0;
		w->to_s = strtod(colon + 1, &end);
		if (errno || *end)
			return -1;
		w->have_to = 1;
	}
	if (w->have_from && w->have_to && !(w->from_s < w->to_s))
		return -1;
	return 0;
}

int re_traceshow_pages(int n_axes)
{
	return n_axes + 1;
}

static int have_gnuplot(void)
{
	const char *path = getenv("PATH");
	char exe[4352];

	while (path && *path) {
		size_t n = strcspn(path, ":");

		snprintf(exe, sizeof(exe), "%.*s/gnuplot", (int)n,
			 n ? path : ".");
		if (access(exe, X_OK) == 0)
			return 1;
		path += n + (path[n] == ':');
	}
	return 0;
}

/* @s inside a gnuplot double-quoted string: \ and " escaped; wrapped
 * into lines of about @width characters at spaces. */
static void put_dq(FILE *gp, const char *s, int width)
{
	int col = 0;

	for (; *s; s++, col++) {
		if (*s == ' ' && col >= width) {
			fputs("\\n", gp);
			col = 0;
			continue;
		}
		if (*s == '\\' || *s == '"')
			fputc('\\', gp);
		fputc(*s, gp);
	}
}

/* @s inside a gnuplot single-quoted string ('' is a quote). */
static void put_sq(FILE *gp, const char *s)
{
	for (; *s; s++) {
		if (*s == '\'')
			fputc('\'', gp);
		fputc(*s, gp);
	}
}

/* The words of the decoded joystick command and of the program's motion
 * command (docs/dmc-interface.md, ZAC: -1 invalid, 0 none, k+1 command k). */
static const char *const cmd_words[8] = {"invalid", "none",  "A fwd", "A rev",
					 "B fwd",   "B rev", "C fwd", "C rev"};

/* Terminal, output, data settings, the window and the fault mark. */
static void page_start(FILE *gp, const char *png, const char *path,
		       const struct re_trace_hdr *h, const char *what,
		       const struct re_traceshow_win *w, int panels)
{
	char from[32] = "*", to[32] = "*";

	fprintf(gp, "reset\nset terminal png size 1200,%d noenhanced\n",
		300 * panels + 120);
	fputs("set output '", gp);
	put_sq(gp, png);
	fputs("'\nset datafile separator ','\nset datafile columnheaders\n"
	      "set grid\nset key outside right top\n"
	      "set lmargin at screen 0.20\nset rmargin at screen 0.80\n"
	      "set tmargin 2\n",
	      gp);
	if (w && w->have_from)
		snprintf(from, sizeof(from), "%.6f", w->from_s);
	if (w && w->have_to)
		snprintf(to, sizeof(to), "%.6f", w->to_s);
	fprintf(gp, "set xrange [%s:%s]\n", from, to);
	/* the fault's line through each panel, its word above the panel:
	 * never on a trace */
	if (h->have_fault)
		fprintf(gp,
			"set arrow 1 from %.6f, graph 0 to %.6f, graph 1 "
			"nohead lc rgb 'red' lw 2 front\n"
			"set label 1 'FAULT' at %.6f, graph 1 center offset "
			"0,0.7 tc rgb 'red' front\n",
			h->fault_t_s, h->fault_t_s, h->fault_t_s);
	fputs("set multiplot layout ", gp);
	fprintf(gp, "%d,1 title \"", panels);
	put_dq(gp, path, 1000);
	fprintf(gp, ": %s (%s, controller %s, period %.1f ms)", what, h->reason,
		h->serial, h->period_ms);
	if (h->have_fault) {
		fprintf(gp, "\\nat t = %.3f s: ", h->fault_t_s);
		put_dq(gp, h->fault_text, 110);
	}
	fputs("\"\nset xlabel 't, s'\n", gp);
}

/* The gnuplot variable 'file': the trace itself. */
static void plot_file(FILE *gp, const char *path)
{
	fputs("file = '", gp);
	put_sq(gp, path);
	fputs("'\n", gp);
}

/* Counts per unit of axis @a and the unit's name, when @u is the trace's
 * configuration and gives the axis a unit; else 1 and "counts". */
static double axis_scale(const struct re_trace_hdr *h, int a,
			 const struct re_traceshow_units *u, const char **unit)
{
	*unit = "counts";
	if (!u || u->config_hash != h->config_hash)
		return 1;
	for (int i = 0; i < u->n && i < RE_TRACE_AXES; i++)
		if (!strcmp(u->name[i], h->axis[a]) && u->per_unit[i] > 0) {
			*unit = u->unit[i];
			return u->per_unit[i];
		}
	return 1;
}

static void axis_page(FILE *gp, const char *path, const char *png,
		      const struct re_trace_hdr *h, int a,
		      const struct re_traceshow_win *w,
		      const struct re_traceshow_units *u)
{
	const char *x = h->axis[a], *unit;
	double per = axis_scale(h, a, u, &unit);
	char what[96];

	if (per != 1 || strcmp(unit, "counts"))
		snprintf(what, sizeof(what), "axis %s, in %s (%g counts/%s)",
			 x, unit, per, unit);
	else
		snprintf(what, sizeof(what), "axis %s, in counts", x);
	page_start(gp, png, path, h, what, w, 3);
	plot_file(gp, path);
	fprintf(gp,
		"set ylabel 'position, %s'\n"
		"plot file using 't_s':(column('%s_enc') / %.6g) with steps "
		"lw 2 title 'encoder', '' using 't_s':(column('%s_ref') / "
		"%.6g) with steps dt 2 title 'commanded (_RP)'\n",
		unit, x, per, x, per);
	fprintf(gp,
		"set ylabel 'velocity, %s/s'\n"
		"plot file using 't_s':(column('%s_vel_cps') / %.6g) with "
		"steps lw 2 title 'actual (_TV)', '' using "
		"'t_s':(column('%s_vcmd_cps') / %.6g) with steps dt 2 title "
		"'commanded'\n",
		unit, x, per, x, per);
	fprintf(
	    gp,
	    "set ylabel 'potentiometer, V'\n"
	    "plot file using 't_s':(column('%s_pot_exp_v')-column('%s_tol_v'"
	    ")):(column('%s_pot_exp_v')+column('%s_tol_v')) with "
	    "filledcurves fs transparent solid 0.3 lc rgb 'gray' title "
	    "'tolerance band', '' using 't_s':'%s_pot_exp_v' with steps dt "
	    "2 lc rgb 'black' title 'expected', '' using 't_s':'%s_pot_v' "
	    "with steps lw 2 lc rgb 'blue' title 'measured'\n",
	    x, x, x, x, x, x);
	fputs("unset multiplot\n", gp);
}

/* The joystick's switches, lane i: i + 0.8 when closed (raw bit 1). */
static void joy_panel(FILE *gp)
{
	fputs("set ylabel 'joystick switch (raw bit; up: 1)'\nset ytics (", gp);
	for (int i = 0; i < 12; i++)
		fprintf(gp, "%s'%s' %d", i ? ", " : "", joy_names[i], i);
	fputs(")\nset yrange [-0.5:12]\nplot for [i=0:11] file using "
	      "'t_s':(i + 0.8 * ((int(column('joy_raw')) >> i) & 1)) with "
	      "steps lw 2 notitle\n",
	      gp);
}

/* The decoded joystick command and the program's motion command, in
 * words: the motion command thin over the wide joystick line. */
static void cmd_panel(FILE *gp)
{
	fputs("set ylabel 'command'\nset ytics (", gp);
	for (int v = -1; v <= 6; v++)
		fprintf(gp, "%s'%s' %d", v > -1 ? ", " : "", cmd_words[v + 1],
			v);
	fputs(")\nset yrange [-1.5:6.5]\n"
	      "plot file using 't_s':'jcmd' with steps lw 6 lc rgb '#99bbff' "
	      "title 'joystick', '' using 't_s':'mcmd' with steps lw 2 lc "
	      "rgb 'black' title 'motion'\n",
	      gp);
}

/* Phase, relay and link: each on lanes of its own, a word per value. */
static void state_panel(FILE *gp)
{
	fputs("set ylabel 'state'\nset ytics ('start-up' 0, 'service' 1, "
	      "'armed' 2, 'FAULT' 3, 'relay unconfirmed' 4.5, 'relay off' "
	      "5.5, 'relay on' 6.5, 'link lost' 8, 'link ok' 9)\n"
	      "set yrange [-0.5:9.5]\n"
	      "plot file using 't_s':'phase' with steps lw 2 title 'phase', "
	      "'' using 't_s':(4.5 + column('relay')) with steps lw 2 title "
	      "'relay', '' using 't_s':(8 + column('link_ok')) with steps lw "
	      "2 title 'link'\n",
	      gp);
}

static void lanes_page(FILE *gp, const char *path, const char *png,
		       const struct re_trace_hdr *h,
		       const struct re_traceshow_win *w)
{
	page_start(gp, png, path, h, "joystick, relay, timing", w, 4);
	plot_file(gp, path);
	joy_panel(gp);
	cmd_panel(gp);
	state_panel(gp);
	fprintf(gp,
		"set ylabel 'ms'\nset ytics auto\nset yrange [0:*]\n"
		"plot file using 't_s':'age_ms' with steps lw 2 title 'reply "
		"age', '' using 't_s':'late_ms' with steps lw 2 title "
		"'lateness', %.3f with lines dt 2 lc rgb 'black' title "
		"'period'\nunset multiplot\n",
		h->period_ms);
}

/* "<path without .csv>-<tag>.png" */
static void png_name(const char *path, const char *tag, char *buf, size_t cap)
{
	size_t n = strlen(path);

	if (n > 4 && !strcmp(path + n - 4, ".csv"))
		n -= 4;
	snprintf(buf, cap, "%.*s-%s.png", (int)n, path, tag);
}

void re_traceshow_script(FILE *gp, const char *path,
			 const struct re_trace_hdr *h,
			 const struct re_traceshow_win *w,
			 const struct re_traceshow_units *u)
{
	char png[1100];

	for (int a = 0; a < h->n_axes; a++) {
		png_name(path, h->axis[a], png, sizeof(png));
		axis_page(gp, path, png, h, a, w, u);
	}
	png_name(path, "timing", png, sizeof(png));
	lanes_page(gp, path, png, h, w);
}

static int plot_pages(const char *path, const struct re_trace_hdr *h,
		      const struct re_traceshow_win *w,
		      const struct re_traceshow_units *u, FILE *out, FILE *err)
{
	char png[1100];
	FILE *gp = popen("gnuplot", "w");

	if (!gp) {
		fprintf(err, "roboelf-tech: error: cannot run gnuplot: %s\n",
			strerror(errno));
		return EXIT_PLOT;
	}
	re_traceshow_script(gp, path, h, w, u);
	if (pclose(gp) != 0) {
		fprintf(err, "roboelf-tech: error: gnuplot failed for '%s'\n",
			path);
		return EXIT_PLOT;
	}
	for (int p = 0; p <= h->n_axes; p++) {
		png_name(path, p < h->n_axes ? h->axis[p] : "timing", png,
			 sizeof(png));
		fprintf(out, "wrote %s\n", png);
	}
	return 0;
}

/* Which units the positions are drawn in, and why. */
static void say_units(const struct re_trace_hdr *h,
		      const struct re_traceshow_units *u, FILE *out)
{
	if (!u)
		fprintf(out, "positions in counts: no configuration loaded\n");
	else if (u->config_hash != h->config_hash)
		fprintf(out,
			"positions in counts: the configuration '%s' (hash "
			"%016" PRIx64 ") is not this trace's\n",
			u->config, u->config_hash);
	else
		fprintf(out,
			"positions in the console's units, from the "
			"configuration '%s' (the trace's hash)\n",
			u->config);
}

/* Cycles inside the window; the first and last time. */
static size_t in_window(const struct re_trace_rec *r, size_t n,
			const struct re_traceshow_win *w)
{
	size_t k = 0;

	for (size_t i = 0; i < n; i++)
		if ((!w || !w->have_from || r[i].t_s >= w->from_s) &&
		    (!w || !w->have_to || r[i].t_s <= w->to_s))
			k++;
	return k;
}

static void summary(const char *path, const struct re_trace_hdr *h,
		    const struct re_trace_rec *r, FILE *out)
{
	fprintf(out,
		"trace '%s': %s, written %s, controller serial %s, config "
		"hash %016" PRIx64 ", period %.3f ms, %u cycles",
		path, h->reason, h->created, h->serial, h->config_hash,
		h->period_ms, h->n_records);
	if (h->n_records)
		fprintf(out, " from t = %.3f s to %.3f s", r[0].t_s,
			r[h->n_records - 1].t_s);
	fprintf(out, "\n");
	if (h->have_fault)
		fprintf(out, "fault at t = %.3f s: %s\n", h->fault_t_s,
			h->fault_text);
}

int re_traceshow_run(const char *path, const struct re_traceshow_win *w,
		     const struct re_traceshow_units *u, FILE *out, FILE *err)
{
	struct re_trace_hdr h;
	struct re_trace_rec *r = NULL;
	char msg[512], *buf = NULL;
	size_t len, n;
	int rc = base_file_read(path, RE_TRACE_MAX_BYTES, &buf, &len);

	if (rc < 0) {
		fprintf(err,
			"roboelf-tech: error: cannot read trace '%s': %s\n",
			path,
			rc == -EFBIG ? "larger than the limit of 1 GiB"
				     : strerror(-rc));
		return EXIT_BAD;
	}
	rc = re_trace_parse(buf, len, &h, &r, msg, sizeof(msg));
	free(buf);
	if (rc != GL_OK) {
		fprintf(err, "roboelf-tech: error: trace '%s' refused: %s\n",
			path, msg);
		return EXIT_BAD;
	}
	summary(path, &h, r, out);
	say_units(&h, u, out);
	n = in_window(r, h.n_records, w);
	free(r);
	if (n == 0) {
		fprintf(
		    err,
		    "roboelf-tech: error: trace '%s': no cycles in the %s\n",
		    path,
		    w && (w->have_from || w->have_to) ? "window" : "file");
		return EXIT_BAD;
	}
	if (!have_gnuplot()) {
		fprintf(err,
			"roboelf-tech: error: gnuplot is not installed (make "
			"deps installs gnuplot-nox): no plots\n");
		return EXIT_BAD;
	}
	return plot_pages(path, &h, w, u, out, err);
}
