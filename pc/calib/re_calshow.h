/*
 * re_calshow.h - roboelf-tech show-calibration FILE: print a calibration
 * file's tables for a technician and, where gnuplot is installed, write one
 * PNG per axis (potentiometer against encoder with the run-time tolerance band:
 * a worn potentiometer shows as a kink or a flat stretch inside the band).
 *
 * Like re_console, this module prints (to the FILEs it is given).
 */
#ifndef RE_CALSHOW_H
#define RE_CALSHOW_H

#include <stdio.h>

/*
 * re_calshow_print() - load @path (intrinsic checks only, any controller),
 * print the tables on @out, plot them next to @path as "<path>-<axis>.png"
 * when gnuplot is on PATH.
 * @allowed_error: per axis, the configured allowed error (band =
 *                 (1 + allowed_error) x the local potentiometer step);
 *                 @n entries, missing axes use 0.5.
 * @err: messages ("roboelf: error: ...").
 * Return: GL_OK, or the re_calfile_load() error (printed on @err).
 */
int re_calshow_print(const char *path, const double *allowed_error, int n,
		     FILE *out, FILE *err);

#endif /* RE_CALSHOW_H */
