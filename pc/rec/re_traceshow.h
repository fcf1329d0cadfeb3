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

#include <stdint.h>
#include <stdio.h>

#include "re_trace.h"

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

/* How positions are shown, as the console shows them (deg, mm): from a
 * configuration (@config, its hash @config_hash), per axis by name its
 * unit and counts per unit (0: counts). Used only for a trace whose
 * configuration hash is @config_hash; any other trace is drawn in counts. */
struct re_traceshow_units {
	const char *config;
	uint64_t config_hash;
	int n;
	char name[RE_TRACE_AXES][RE_TRACE_NAME];
	char unit[RE_TRACE_AXES][8];
	double per_unit[RE_TRACE_AXES];
};

/*
 * re_traceshow_script() - the gnuplot script of every page of the trace
 * @path (header @h) into @gp: a page per axis, positions and velocities
 * in @u's units where they apply (NULL: counts), and the timing page
 * (joystick switches, the commands in words, phase, relay and link on
 * lanes of their own, reply age and lateness); the fault line and its
 * label above each panel. Each page goes to "<path without .csv>-<tag>.png".
 * @w: [in] the window, or NULL for all of it.
 */
void re_traceshow_script(FILE *gp, const char *path,
			 const struct re_trace_hdr *h,
			 const struct re_traceshow_win *w,
			 const struct re_traceshow_units *u);

/*
 * re_traceshow_run() - load @path, print its summary on @out, write the
 * pages (re_traceshow_script()) with gnuplot next to it and name them on
 * @out; say which units the positions are in.
 * @w: [in] the window, or NULL for all of it.
 * @u: [in] the units (NULL: counts).
 * @err: messages ("roboelf: error: ...").
 * Return: 0; 2 for a file that is refused (its reason on @err, naming the
 *         line), an empty window, or no gnuplot; 3 when gnuplot failed.
 */
int re_traceshow_run(const char *path, const struct re_traceshow_win *w,
		     const struct re_traceshow_units *u, FILE *out, FILE *err);

#endif /* RE_TRACESHOW_H */
