/*
 * ctrl_store.h - DL into program memory; BP BN BV into flash (ctrl_store.c);
 * internal to the simulated controller (ctrl/), not part of its API
 * (ctrl.h).
 * It is not the program parser (ctrl_prog.h) nor the power cycle (ctrl.c).
 */
#ifndef SIM_CTRL_STORE_H
#define SIM_CTRL_STORE_H

#include "ctrl_int.h"

/*
 * ctrl_burn_program() / ctrl_burn_vars() - BP / BV: copy the program /
 * the variables and arrays in RAM to flash, with an event.
 * Return: 0, or -1 when out of memory (flash keeps what it had).
 */
int ctrl_burn_program(struct ctrl *c);
int ctrl_burn_vars(struct ctrl *c);
/* ctrl_burn_params() - BN: axis parameters and settings to flash. */
void ctrl_burn_params(struct ctrl *c);
/*
 * ctrl_load_program() - replace program memory with @len bytes of @text
 * (copied); on a refused text the memory is left empty, TC set, and
 * @bad_line gets the 1-based line refused. Events either way.
 * Return: 0 or the TC code (60 61 62 63 ...).
 */
int ctrl_load_program(struct ctrl *c, const char *text, size_t len,
		      int *bad_line);

#endif /* SIM_CTRL_STORE_H */
