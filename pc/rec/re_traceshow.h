/*
 * re_traceshow.h - roboelf-tech show-trace FILE [--window FROM:TO]: check a
 * trace strictly (re_trace_parse()), print its summary and write its PNG
 * pages with gnuplot, which reads the trace file itself (the format is
 * plain CSV to it): one page per axis (position, velocity, potentiometer
 * measured against expected with the tolerance band) and one page of
 * lanes and timing (joystick switches, commands, phase, relay, link; reply
 * age and lateness). The fault instant is marked with its text on every
 * panel.
 *
 * Like re_calshow, this module prints (to the FILEs it is given).
 */
#ifndef RE_TRACESHOW_H
#define RE_TRACESHOW_H

#include <stdio.h>

/* The time window, on the trace's t_s axis (s). */
struct re_traceshow_win {
	int have_from, have_to;
	double from_s, to_s;
};

/*
 * re_traceshow_window() - parse "FROM:TO" (either may be empty; seconds on
 * the t_s axis, decimals allowed; FROM < TO when both are given).
 * Return: 0, or -1 for anything else.
 */
int re_traceshow_window(const char *s, struct re_traceshow_win *w);

/*
 * re_traceshow_pages() - the number of PNG pages for @n_axes axes.
 */
int re_traceshow_pages(int n_axes);

/*
 * re_traceshow_run() - load @path, print its summary on @out, write the
 * pages as "<path without .csv>-<axis>.png" and "...-timing.png" next to
 * it and name them on @out.
 * @w: [in] the window, or NULL for all of it.
 * @err: messages ("roboelf: error: ...").
 * Return: 0; 2 for a file that is refused (its reason on @err, naming the
 *         line), an empty window, or no gnuplot; 3 when gnuplot failed.
 */
int re_traceshow_run(const char *path, const struct re_traceshow_win *w,
		     FILE *out, FILE *err);

#endif /* RE_TRACESHOW_H */
