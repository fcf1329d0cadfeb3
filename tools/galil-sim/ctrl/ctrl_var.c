/*
 * ctrl_var.c - program variables (510, names of up to 8 characters, case
 * sensitive) and arrays (30 arrays, 24000 elements in total).
 *
 * A name is packed into a uint64_t key (one byte per character), so a
 * lookup is a multiply, a shift and an integer compare.
 */
#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#include "ctrl_var.h"
#include "dmc_text.h"

/* ctrl_ident_len() - length of the run of letters, digits and '_' at
 * @s ('_' inside a variable name runs on hardware: real-controller-
 * facts); 0 at a '_' (an operand such as _TPA starts there). */
size_t ctrl_ident_len(const char *s)
{
	size_t n = 0;

	if (s[0] == '_')
		return 0;
	while (dmc_is_name_char(s[n]))
		n++;
	return n;
}

/*
 * ctrl_name_key() - key of a variable/array/label name of @n characters.
 * Return: 0, or TC 9 (variable error) for a bad or too long name.
 */
int ctrl_name_key(const char *s, size_t n, uint64_t *key)
{
	uint64_t k = 0;
	size_t i;

	if (n < 1 || n > CTRL_NAME_MAX || !isalpha((unsigned char)s[0]))
		return 9;
	for (i = 0; i < n; i++) {
		if (!dmc_is_name_char(s[i]))
			return 9;
		k |= (uint64_t)(uint8_t)s[i] << (8 * i);
	}
	*key = k;
	return 0;
}

void ctrl_key_name(uint64_t key, char out[CTRL_NAME_MAX + 1])
{
	int i;

	for (i = 0; i < CTRL_NAME_MAX; i++)
		out[i] = (char)((key >> (8 * i)) & 0xFF);
	out[CTRL_NAME_MAX] = '\0';
}

static unsigned var_hash(uint64_t key)
{
	return (unsigned)((key * 0x9E3779B97F4A7C15ull) >> 54) &
	       (CTRL_VAR_SLOTS - 1);
}

/* ctrl_var_find() - slot of a variable, or -1. */
int ctrl_var_find(const struct ctrl_vars *vs, uint64_t key)
{
	unsigned i = var_hash(key);

	while (vs->slot[i].key) {
		if (vs->slot[i].key == key)
			return (int)i;
		i = (i + 1) & (CTRL_VAR_SLOTS - 1);
	}
	return -1;
}

/*
 * ctrl_var_set() - assign (creating the variable if needed).
 * @slot: [out] optional, the variable's slot.
 * Return: 0, or TC 67 when all variables are used.
 */
int ctrl_var_set(struct ctrl_vars *vs, uint64_t key, double v, int *slot)
{
	unsigned i = var_hash(key);

	while (vs->slot[i].key && vs->slot[i].key != key)
		i = (i + 1) & (CTRL_VAR_SLOTS - 1);
	if (!vs->slot[i].key) {
		if (vs->count >= CTRL_VARS)
			return 67;
		vs->slot[i].key = key;
		vs->count++;
	}
	vs->slot[i].v = v;
	if (slot)
		*slot = (int)i;
	return 0;
}

struct ctrl_array *ctrl_array_find(struct ctrl_vars *vs, uint64_t key)
{
	int i;

	for (i = 0; i < CTRL_ARRAYS; i++)
		if (vs->arr[i].key == key)
			return &vs->arr[i];
	return NULL;
}

/*
 * ctrl_array_free() - DA of one array.
 * Return: 0, or TC 57 when there is no such array.
 */
int ctrl_array_free(struct ctrl_vars *vs, uint64_t key)
{
	struct ctrl_array *a = ctrl_array_find(vs, key);

	if (!a)
		return 57;
	vs->arr_used -= a->n;
	free(a->v);
	memset(a, 0, sizeof(*a));
	return 0;
}

/* Number of free array slots (_DA, DA ?). */
int ctrl_arrays_free(const struct ctrl_vars *vs)
{
	int i, n = 0;

	for (i = 0; i < CTRL_ARRAYS; i++)
		n += vs->arr[i].key == 0;
	return n;
}

/*
 * ctrl_array_dim() - DM name[n]: a new array of zeros. An array of that
 * name that exists already is never re-dimensioned (the reference is
 * silent; docs/galil-sim-controller.md, difference 23): the DM is refused
 * with TC 57 whatever its size, and the array is left as it is (the
 * fail-safe reading; dmc/roboelf.dmc deallocates with DA *[] first).
 * Return: 0, TC 6 (size), TC 57 (exists), TC 66 (array space full), TC 67
 * (too many arrays).
 */
int ctrl_array_dim(struct ctrl_vars *vs, uint64_t key, int n)
{
	struct ctrl_array *a;
	int i;

	if (n < 1 || n > CTRL_ARRAY_SPACE)
		return 6;
	a = ctrl_array_find(vs, key);
	if (a)
		return 57;
	if (vs->arr_used + n > CTRL_ARRAY_SPACE)
		return 66;
	for (i = 0; i < CTRL_ARRAYS && vs->arr[i].key; i++)
		;
	if (i == CTRL_ARRAYS)
		return 67;
	a = &vs->arr[i];
	a->v = calloc((size_t)n, sizeof(double));
	if (!a->v)
		return 66;
	a->key = key;
	a->n = n;
	vs->arr_used += n;
	return 0;
}

void ctrl_vars_clear(struct ctrl_vars *vs)
{
	int i;

	for (i = 0; i < CTRL_ARRAYS; i++)
		free(vs->arr[i].v);
	memset(vs, 0, sizeof(*vs));
}

/*
 * ctrl_vars_copy() - deep copy (BV and power-up); @dst is cleared first.
 * Return: 0, or -1 when out of memory (@dst then holds no arrays).
 */
int ctrl_vars_copy(struct ctrl_vars *dst, const struct ctrl_vars *src)
{
	int i;

	ctrl_vars_clear(dst);
	memcpy(dst->slot, src->slot, sizeof(src->slot));
	dst->count = src->count;
	for (i = 0; i < CTRL_ARRAYS; i++) {
		const struct ctrl_array *a = &src->arr[i];

		if (!a->key)
			continue;
		dst->arr[i].v = malloc((size_t)a->n * sizeof(double));
		if (!dst->arr[i].v) {
			ctrl_vars_clear(dst);
			return -1;
		}
		memcpy(dst->arr[i].v, a->v, (size_t)a->n * sizeof(double));
		dst->arr[i].key = a->key;
		dst->arr[i].n = a->n;
	}
	dst->arr_used = src->arr_used;
	return 0;
}
