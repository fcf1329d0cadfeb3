/*
 * ctrl_var.h - program variables and arrays, by packed name (ctrl_var.c);
 * internal to the simulated controller (ctrl/), not part of its API
 * (ctrl.h).
 * It does not evaluate names in expressions (ctrl_expr.h).
 */
#ifndef SIM_CTRL_VAR_H
#define SIM_CTRL_VAR_H

#include "ctrl_int.h"

/* ctrl_ident_len() - length of the run of letters, digits and '_' at @s
 * (0 when @s starts with '_': an operand). */
size_t ctrl_ident_len(const char *s);
/*
 * ctrl_name_key() - the key of a variable/array/label name: the @n
 * characters of @s (a letter, then letters or digits, 1..CTRL_NAME_MAX)
 * packed one byte each, first in the low byte, into @key.
 * Return: 0, or TC 9 (variable error) for a bad or too long name.
 * ctrl_key_name() - the name of @key back into @out, NUL-terminated.
 */
int ctrl_name_key(const char *s, size_t n, uint64_t *key);
void ctrl_key_name(uint64_t key, char out[CTRL_NAME_MAX + 1]);
/* ctrl_var_find() - the slot of variable @key in @vs->slot[], or -1. */
int ctrl_var_find(const struct ctrl_vars *vs, uint64_t key);
/*
 * ctrl_var_set() - assign @v to variable @key, creating it if needed.
 * @slot: [out] optional, the variable's slot.
 * Return: 0, or TC 67 when all CTRL_VARS variables are used.
 */
int ctrl_var_set(struct ctrl_vars *vs, uint64_t key, double v, int *slot);
/* ctrl_array_find() - array @key of @vs (owned by @vs), or NULL. */
struct ctrl_array *ctrl_array_find(struct ctrl_vars *vs, uint64_t key);
/*
 * ctrl_array_dim() - DM name[@n]: a new array of @n zeros. An existing
 * array is never re-dimensioned (docs/galil-sim-controller.md).
 * Return: 0, TC 6 (size), TC 57 (exists), TC 66 (array space full or out
 * of memory), TC 67 (too many arrays).
 */
int ctrl_array_dim(struct ctrl_vars *vs, uint64_t key, int n);
/* ctrl_array_free() - DA of array @key. Return: 0, or TC 57 (none). */
int ctrl_array_free(struct ctrl_vars *vs, uint64_t key);
/* ctrl_arrays_free() - how many more arrays may be dimensioned (_DA). */
int ctrl_arrays_free(const struct ctrl_vars *vs);
/* ctrl_vars_clear() - free all arrays and forget all variables of @vs. */
void ctrl_vars_clear(struct ctrl_vars *vs);
/*
 * ctrl_vars_copy() - deep copy of @src into @dst (BV and power-up); @dst
 * is cleared first. Return: 0, or -1 when out of memory (@dst then empty).
 */
int ctrl_vars_copy(struct ctrl_vars *dst, const struct ctrl_vars *src);

#endif /* SIM_CTRL_VAR_H */
