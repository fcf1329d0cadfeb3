/*
 * ctrl_num.h - Galil 32.16 fixed-point numbers and their printed formats
 * (ctrl_num.c); internal to the simulated controller (ctrl/), not part of
 * its API (ctrl.h).
 * It does not parse numbers in expressions (ctrl_expr.h).
 */
#ifndef SIM_CTRL_NUM_H
#define SIM_CTRL_NUM_H

#include "ctrl_int.h"

/*
 * ctrl_fx() - @v on the 32.16 fixed-point grid (1/65536, rounded to
 * nearest), wrapped like a 48-bit register; NaN gives 0.
 * ctrl_fx_raw() - the same as the raw signed 48-bit value (v * 65536);
 * ctrl_fx_from_raw() - a raw value back to a double.
 */
double ctrl_fx(double v);
int64_t ctrl_fx_raw(double v);
double ctrl_fx_from_raw(int64_t raw);
/*
 * ctrl_fmt_num() - print @v in format @f ('F'/'Z': m 0..10, n 0..4; '$':
 * m 1..8, n 0..4; 'S': m 1..6 characters, @cap >= 8) into @out (@cap
 * bytes, NUL-terminated). Return: characters written (snprintf style),
 * or -1 for a bad format.
 */
int ctrl_fmt_num(char *out, size_t cap, double v, const struct ctrl_fmt *f);
/*
 * ctrl_str_value() - the value of a "string": its first 6 of @n
 * characters packed into 48 bits, the first in the top byte.
 */
double ctrl_str_value(const char *s, size_t n);

#endif /* SIM_CTRL_NUM_H */
