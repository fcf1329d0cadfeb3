/*
 * re_pot.h - the potentiometer readings in the controller's data record:
 * analog input counts to volts, and which analog input belongs to which
 * axis. Pure: no I/O, no state.
 *
 * It is not the encoder/potentiometer cross-check (re_check) nor the
 * calibration tables (re_calfile); both use it, as do the supervisor's
 * cycle (re_super), its fault reaction (re_react) and the calibration
 * (re_calib).
 */
#ifndef RE_POT_H
#define RE_POT_H

#include <stdint.h>

#include "gl_record.h"

/* AQ2 (default): analog inputs read +-10 V as +-32768 counts. */
#define RE_AN_COUNTS_PER_V 3276.8

/*
 * re_pot_volts() - analog input counts (AQ2) to volts.
 * Return: @analog_in / RE_AN_COUNTS_PER_V, V.
 */
double re_pot_volts(int32_t analog_in);

/*
 * re_pot_of() - the potentiometer of axis @axis in @rec, volts: analog
 * input @input (1..n_axes: its axis block), or the axis's own block when
 * @input is out of that range. @axis must be below rec->n_axes.
 */
double re_pot_of(const struct gl_record *rec, int axis, int input);

#endif /* RE_POT_H */
