/*
 * re_comm_plot.h - the commissioning run's plots: for each plot a gnuplot
 * script with its data inside (DIR/NAME.gp, kept: `gnuplot` draws it again
 * and a test reads it) and, where gnuplot is installed, DIR/NAME.png.
 *
 *   pots-at-rest   each potentiometer at rest about the middle of its span,
 *                  with the noise limit (half the supervisor's tolerance,
 *                  peak to peak) and the allowed range in the panel's title
 *   move-AXIS      the encoder during the small move and the way back with
 *                  the start, the target and the expected path at the
 *                  asked speed; the potentiometer with the path the
 *                  configuration expects from the encoder
 *
 * A plot of the step that failed carries the label "FAIL: <what was
 * seen>" in red under its title. Every file is written whole or not at
 * all. Nothing here prints.
 */
#ifndef RE_COMM_PLOT_H
#define RE_COMM_PLOT_H

#include "re_comm.h"

/*
 * re_comm_plots() - write the scripts of run @c into the existing
 * directory @dir and draw them.
 * @drawn: [out] how many PNG files were written.
 * @undrawn: [out] how many scripts gnuplot did not draw (missing or
 *           failed), or that could not be written.
 * Return: the number of scripts written.
 */
int re_comm_plots(const struct re_comm *c, const char *dir, int *drawn,
		  int *undrawn);

#endif /* RE_COMM_PLOT_H */
