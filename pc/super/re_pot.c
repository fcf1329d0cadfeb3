/*
 * re_pot.c - potentiometer readings from the data record. See re_pot.h.
 */
#include "re_pot.h"

double re_pot_volts(int32_t analog_in)
{
	return (double)analog_in / RE_AN_COUNTS_PER_V;
}

/* Analog input n is in axis block n - 1 of the DMC-4030 record. */
double re_pot_of(const struct gl_record *rec, int axis, int input)
{
	int k = input >= 1 && input <= rec->n_axes ? input - 1 : axis;

	return re_pot_volts(rec->axis[k].analog_in);
}
