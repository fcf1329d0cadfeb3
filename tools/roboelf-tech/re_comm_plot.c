/*
 * re_comm_plot.c - the commissioning run's plots (re_comm_plot.h): each
 * script written with base_durable_write(), then drawn by gnuplot into
 * "NAME.png.tmp", renamed when gnuplot succeeded.
 */
#include "re_comm_plot.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "base_durable.h"
#include "re_comm_util.h"

#define SCRIPT_MAX (64 * 1024)
#define PLOT_W	   900
#define MOVE_H	   700		    /* a move's page, pixels */
#define LANES_H(n) (300 + 40 * (n)) /* a page of @n lanes */

/* @s as the inside of a gnuplot double-quoted string: \ and " escaped,
 * wrapped at a space after @width characters (a "\n" in the string). */
static void put_dq(struct rc_text *b, const char *s, int width)
{
	int col = 0;

	for (; *s; s++, col++) {
		if (*s == ' ' && col >= width) {
			rc_text_put(b, "\\n");
			col = 0;
			continue;
		}
		rc_text_put(b, "%s%c", *s == '\\' || *s == '"' ? "\\" : "", *s);
	}
}

/* @s as the inside of a gnuplot single-quoted string ('' is a quote). */
static void put_sq(struct rc_text *b, const char *s)
{
	for (; *s; s++)
		rc_text_put(b, "%s%c", *s == '\'' ? "'" : "", *s);
}

/* The FAIL item of step @step named @name (any name: NULL), or NULL. */
static const struct re_comm_item *fail_of(const struct re_comm *c,
					  const char *step, const char *name)
{
	for (int i = 0; i < c->n && i < RE_COMM_ITEMS; i++) {
		const struct re_comm_item *it = &c->item[i];

		if (it->res == RE_COMM_FAIL && !strcmp(it->step, step) &&
		    (!name || !strcmp(it->name, name)))
			return it;
	}
	return NULL;
}

#define FAIL_WRAP 80 /* characters of a FAIL label's line */

/* The lines put_dq() makes of @s wrapped at FAIL_WRAP. */
static int fail_lines(const char *s)
{
	int lines = 1, col = 0;

	for (; *s; s++, col++)
		if (*s == ' ' && col >= FAIL_WRAP) {
			lines++;
			col = 0;
		}
	return lines;
}

/* The red "FAIL: <text>" under the title line of a page @height pixels
 * high, for the panels that follow until unset; the page's title then
 * carries fail_pad() blank lines, so that nothing is drawn under it. */
static void put_fail(struct rc_text *b, const struct re_comm_item *it,
		     int height)
{
	rc_text_put(b, "set label 99 \"FAIL: ");
	put_dq(b, it->text, FAIL_WRAP);
	rc_text_put(b,
		    "\" at screen 0.02, screen %.3f left tc rgb 'red' front\n",
		    1 - 40.0 / height);
}

/* The blank lines a page title carries for a FAIL label (@it, NULL:
 * none), as gnuplot string text. */
static void fail_pad(struct rc_text *b, const struct re_comm_item *it)
{
	for (int i = it ? fail_lines(it->text) : 0; i > 0; i--)
		rc_text_put(b, "\\n");
}

/* Write @dir/@name.gp and draw it into @dir/@name.png (@height pixels).
 * Return: 1 drawn, 0 written but not drawn, -1 not written. */
static int emit(const char *dir, const char *name, const struct rc_text *script,
		int height)
{
	static char cmd[4096];
	char gp[1024], png[1024], tmp[1100];
	struct rc_text b = {cmd, 0, sizeof(cmd)};
	FILE *f;

	snprintf(gp, sizeof(gp), "%s/%s.gp", dir, name);
	snprintf(png, sizeof(png), "%s/%s.png", dir, name);
	snprintf(tmp, sizeof(tmp), "%s.tmp", png);
	if (script->n >= script->cap ||
	    base_durable_write(gp, script->p, script->n, 0644) != 0)
		return -1;
	rc_text_put(&b, "set terminal png size %d,%d noenhanced\nset output '",
		    PLOT_W, height);
	put_sq(&b, tmp);
	rc_text_put(&b, "'\nload '");
	put_sq(&b, gp);
	rc_text_put(&b, "'\nunset multiplot\nset output\n");
	if (b.n >= b.cap || !(f = popen("gnuplot 2>/dev/null", "w")))
		return 0;
	fputs(cmd, f);
	if (pclose(f) != 0) {
		unlink(tmp);
		return 0;
	}
	return rename(tmp, png) == 0 ? 1 : 0;
}

/* The supervisor's tolerance at the table step, V (as the pots step). */
static double pot_tol_v(const struct re_config_axis *a)
{
	return a->allowed_error * a->analog.expected_range_v * a->step_counts /
	       a->travel_counts;
}

/* One panel of pots-at-rest: axis @ax about the middle of its span, mV,
 * with the noise limit's lines. */
static void noise_panel(const struct re_comm *c, int ax, struct rc_text *b)
{
	const struct re_config_axis *a = &c->cfg->axes[ax];
	double mn = 1e9, mx = -1e9, sum = 0, half = pot_tol_v(a) / 4 * 1e3;
	double lo = fmin(a->analog.reverse_v, a->analog.forward_v) -
		    a->analog.absolute_tolerance_v;
	double hi = fmax(a->analog.reverse_v, a->analog.forward_v) +
		    a->analog.absolute_tolerance_v;

	for (int i = 0; i < c->noise_n; i++) {
		mn = fmin(mn, c->noise_v[ax][i]);
		mx = fmax(mx, c->noise_v[ax][i]);
		sum += c->noise_v[ax][i];
	}
	rc_text_put(b, "$pot%s << EOD\n", a->name);
	for (int i = 0; i < c->noise_n; i++)
		rc_text_put(b, "%d %.3f\n", i,
			    (c->noise_v[ax][i] - (mn + mx) / 2) * 1e3);
	rc_text_put(b,
		    "EOD\nset title 'axis %s, analog input %d: %.4f V mean, "
		    "%.1f mV peak to peak; allowed range %.3f..%.3f V'\n",
		    a->name, a->analog.input, sum / c->noise_n, (mx - mn) * 1e3,
		    lo, hi);
	rc_text_put(
	    b,
	    "plot $pot%s using 1:2 with linespoints title 'reading', "
	    "%.3f with lines dt 2 lc rgb 'red' title 'noise limit: %.1f mV "
	    "peak to peak (half the tolerance)', %.3f with lines dt 2 lc "
	    "rgb 'red' notitle\n",
	    a->name, half, 2 * half, -half);
}

static int plot_noise(const struct re_comm *c, const char *dir, int *drawn)
{
	static char text[SCRIPT_MAX];
	struct rc_text b = {text, 0, sizeof(text)};
	const struct re_comm_item *f = fail_of(c, "pots", NULL);
	int r;

	if (c->noise_n < 2)
		return 0;
	rc_text_put(&b,
		    "# roboelf-tech commission: the potentiometers at rest\n"
		    "set key outside below\nset grid\n"
		    "set offsets 0, 0, graph 0.15, graph 0.15\n"
		    "set xlabel 'sample (10 ms apart plus the reply time)'\n"
		    "set ylabel 'mV from the middle'\n");
	if (f)
		put_fail(&b, f, 300 * RE_AXES + 60);
	rc_text_put(&b,
		    "set multiplot layout %d,1 title \"potentiometers at rest, "
		    "motor power off: %d readings of each",
		    RE_AXES, c->noise_n);
	fail_pad(&b, f);
	rc_text_put(&b, "\"\n");
	for (int ax = 0; ax < RE_AXES; ax++) {
		noise_panel(c, ax, &b);
		if (f && ax == 0)
			rc_text_put(&b, "unset label 99\n");
	}
	rc_text_put(&b, "unset multiplot\n");
	r = emit(dir, "pots-at-rest", &b, 300 * RE_AXES + 60);
	*drawn += r > 0;
	return r >= 0 ? 1 : -1;
}

/* The end of the time axis of a move's plot: its last sample, or the
 * end of the way back asked for when later. */
static double move_end_ms(const struct re_comm_trace *t, double cps)
{
	double end = t->t_ms[t->n - 1];

	if (t->back_i)
		end = fmax(end,
			   t->t_back_ms + fabs((double)t->counts) / cps * 1e3);
	return end;
}

/* The encoder's data, and the path asked for: at @cps from the start to
 * the target, there until the way back, and back at @cps. */
static void move_data(const struct re_comm_trace *t, double cps, double slope,
		      struct rc_text *b)
{
	double ramp_ms = fabs((double)t->counts) / cps * 1e3;
	double target = t->enc0 + t->counts;

	rc_text_put(b, "$enc << EOD\n");
	for (int i = 0; i < t->n; i++)
		rc_text_put(b, "%.1f %.0f %.4f %.4f\n", t->t_ms[i], t->enc[i],
			    t->pot_v[i],
			    t->pot0_v + (t->enc[i] - t->enc0) * slope);
	rc_text_put(b, "EOD\n$asked << EOD\n0 %.0f\n%.1f %.0f\n", t->enc0,
		    ramp_ms, target);
	if (t->back_i)
		rc_text_put(b, "%.1f %.0f\n%.1f %.0f\n", t->t_back_ms, target,
			    t->t_back_ms + ramp_ms, t->enc0);
	else
		rc_text_put(b, "%.1f %.0f\n", t->t_ms[t->n - 1], target);
	rc_text_put(b, "EOD\n");
}

/* The encoder's panel of a move: the trace, the path asked for, the
 * target and the start. */
static void enc_panel(const struct re_comm_trace *t, struct rc_text *b)
{
	rc_text_put(
	    b,
	    "set title 'the encoder against the motor'\n"
	    "set ylabel 'encoder, counts'\n"
	    "plot $enc using 1:2 with lines lw 2 title 'encoder', "
	    "$asked using 1:2 with lines dt 2 lc rgb 'black' title "
	    "'expected: %d counts/s to the target%s', "
	    "%.0f with lines dt 3 lc rgb 'dark-green' title 'target %+d "
	    "counts (%.0f)', %.0f with lines dt 3 lc rgb 'gray' title "
	    "'start (%.0f)'\n",
	    RE_COMM_MOVE_CPS, t->back_i ? " and back" : "", t->enc0 + t->counts,
	    t->counts, t->enc0 + t->counts, t->enc0, t->enc0);
}

static int plot_move(const struct re_comm *c, int ax, const char *dir,
		     int *drawn)
{
	static char text[SCRIPT_MAX];
	const struct re_config_axis *a = &c->cfg->axes[ax];
	const struct re_comm_trace *t = &c->trace[ax];
	const struct re_comm_item *f = fail_of(c, "motion", a->name);
	double slope =
	    (a->analog.forward_v - a->analog.reverse_v) / a->travel_counts;
	struct rc_text b = {text, 0, sizeof(text)};
	char name[32];
	int r;

	if (t->n < 2)
		return 0;
	rc_text_put(&b, "# roboelf-tech commission: axis %s, the small move\n",
		    a->name);
	move_data(t, RE_COMM_MOVE_CPS, slope, &b);
	rc_text_put(&b,
		    "set key outside below\nset grid\n"
		    "set offsets 0, 0, graph 0.15, graph 0.15\n"
		    "set xrange [0:%.0f]\n"
		    "set xlabel 'ms after the move was asked for'\n",
		    move_end_ms(t, RE_COMM_MOVE_CPS));
	if (f)
		put_fail(&b, f, MOVE_H);
	rc_text_put(
	    &b,
	    "set multiplot layout 2,1 title \"axis %s: %+d counts at %d "
	    "counts/s and %s",
	    a->name, t->counts, RE_COMM_MOVE_CPS,
	    t->back_i ? "the way back" : "no way back (the run stopped)");
	fail_pad(&b, f);
	rc_text_put(&b, "\"\n");
	enc_panel(t, &b);
	if (f)
		rc_text_put(&b, "unset label 99\n");
	rc_text_put(
	    &b,
	    "set title 'the potentiometer against the encoder: %+.4f "
	    "mV/count expected'\n"
	    "set ylabel 'potentiometer, V'\n"
	    "plot $enc using 1:3 with lines lw 2 title 'analog input %d', "
	    "$enc using 1:4 with lines dt 2 lc rgb 'black' title 'expected: "
	    "(forward_v - reverse_v) / travel_counts'\nunset multiplot\n",
	    slope * 1e3, a->analog.input);
	snprintf(name, sizeof(name), "move-%s", a->name);
	r = emit(dir, name, &b, MOVE_H);
	*drawn += r > 0;
	return r >= 0 ? 1 : -1;
}

/* A hand-operated step: what it saw of each lane (names @lane, @nl of
 * them) and when the technician was asked for what. */
struct lanes_plot {
	const char *name, *step, *title;
	const struct re_comm_lanes *l;
	int nl;
	char lane[RE_JOY_INPUTS][48];
};

static void lanes_data(const struct lanes_plot *p, struct rc_text *b)
{
	const struct re_comm_lanes *l = p->l;

	rc_text_put(b, "$lanes << EOD\n");
	for (int i = 0; i <= l->n; i++) {
		unsigned m = l->mask[i < l->n ? i : l->n - 1];

		rc_text_put(b, "%.1f", i < l->n ? l->t_ms[i] : l->end_ms);
		for (int k = 0; k < p->nl; k++)
			rc_text_put(b, " %u", (m >> k) & 1u);
		rc_text_put(b, "\n");
	}
	rc_text_put(b, "EOD\n");
}

static int plot_lanes(const struct re_comm *c, const struct lanes_plot *p,
		      const char *dir, int *drawn)
{
	static char text[SCRIPT_MAX];
	const struct re_comm_item *f = fail_of(c, p->step, NULL);
	struct rc_text b = {text, 0, sizeof(text)};
	int r;

	if (p->l->n < 1)
		return 0;
	rc_text_put(&b, "# roboelf-tech commission: %s\n", p->title);
	lanes_data(p, &b);
	rc_text_put(&b,
		    "set tmargin 9\nset grid xtics\n"
		    "set xlabel 'ms after the step began'\n"
		    "set yrange [-0.5:%d]\nset ytics (",
		    p->nl);
	for (int k = 0; k < p->nl; k++)
		rc_text_put(&b, "%s'%s' %d.4", k ? ", " : "", p->lane[k], k);
	rc_text_put(&b, ")\n");
	for (int i = 0; i < p->l->n_ask; i++)
		rc_text_put(
		    &b,
		    "set arrow %d from %.1f, graph 0 to %.1f, graph 1 nohead "
		    "lc rgb 'gray'\nset label %d '%s' at %.1f, graph 1 rotate "
		    "by 60 left offset 0,0.5\n",
		    i + 1, p->l->ask_ms[i], p->l->ask_ms[i], i + 1,
		    p->l->ask[i], p->l->ask_ms[i]);
	if (f)
		put_fail(&b, f, LANES_H(p->nl));
	rc_text_put(&b, "set multiplot layout 1,1 title \"%s", p->title);
	fail_pad(&b, f);
	rc_text_put(
	    &b,
	    "\"\nplot for [k=0:%d] $lanes using 1:(k + 0.8 * column(k + "
	    "2)) with steps lw 2 notitle\nunset multiplot\n",
	    p->nl - 1);
	r = emit(dir, p->name, &b, LANES_H(p->nl));
	*drawn += r > 0;
	return r >= 0 ? 1 : -1;
}

/* The joystick, limit-switch and relay steps' plots. */
static void plot_hand_steps(const struct re_comm *c, const char *dir,
			    int *drawn, int *n, int *undrawn)
{
	static const char *const sw[] = {"fwd a", "fwd b", "rev a", "rev b"};
	static struct lanes_plot p[3];
	int r;

	p[0] = (struct lanes_plot){
	    "joystick", "joystick",    "the joystick switches: up is closed",
	    &c->joy,	RE_JOY_INPUTS, {{0}}};
	for (int k = 0; k < RE_JOY_INPUTS; k++)
		snprintf(p[0].lane[k], sizeof(p[0].lane[k]), "%c %s (input %d)",
			 'A' + k / 4, sw[k % 4], c->cfg->joystick.inputs[k]);
	p[1] = (struct lanes_plot){
	    "limits", "limits",	   "the limit switches: up is active",
	    &c->lim,  2 * RE_AXES, {{0}}};
	for (int k = 0; k < 2 * RE_AXES; k++)
		snprintf(p[1].lane[k], sizeof(p[1].lane[k]), "%c %s (_L%c%c)",
			 'A' + k / 2, k % 2 ? "rev" : "fwd", k % 2 ? 'R' : 'F',
			 'A' + k / 2);
	p[2] = (struct lanes_plot){
	    "relay", "relay", "the E-stop relay and the amplifiers' power",
	    &c->amp, 2,	      {{0}}};
	snprintf(p[2].lane[0], sizeof(p[2].lane[0]), "relay ON");
	snprintf(p[2].lane[1], sizeof(p[2].lane[1]),
		 "power (_TA0 bit 3 clear)");
	for (int i = 0; i < 3; i++) {
		r = plot_lanes(c, &p[i], dir, drawn);
		*n += r > 0;
		*undrawn += r < 0;
	}
}

int re_comm_plots(const struct re_comm *c, const char *dir, int *drawn,
		  int *undrawn)
{
	int n = 0, r;

	*drawn = 0;
	*undrawn = 0;
	plot_hand_steps(c, dir, drawn, &n, undrawn);
	r = plot_noise(c, dir, drawn);
	n += r > 0;
	*undrawn += r < 0;
	for (int ax = 0; ax < RE_AXES; ax++) {
		r = plot_move(c, ax, dir, drawn);
		n += r > 0;
		*undrawn += r < 0;
	}
	*undrawn += n - *drawn;
	return n;
}
