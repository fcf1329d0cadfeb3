/*
 * dmc_text.c - lexical rules shared by galil-load and galil-sim. See
 * dmc_text.h.
 */
#include "dmc_text.h"

#include <string.h>

int dmc_is_name_char(char c)
{
	return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') ||
	       (c >= '0' && c <= '9') || c == '_';
}

int dmc_is_rem(const char *s, size_t n)
{
	size_t i = 0;

	while (i < n && (s[i] == ' ' || s[i] == '\t'))
		i++;
	return n - i >= 3 && memcmp(s + i, "REM", 3) == 0 &&
	       (n - i == 3 || !dmc_is_name_char(s[i + 3]));
}

int dmc_stmt_next(const char *s, size_t n, size_t *pos, size_t *start,
		  size_t *len)
{
	size_t i = *pos;
	int quote = 0;

	/* at the end: one more (empty) statement only after a final ';' */
	if (i > n || (i == n && (i == 0 || s[i - 1] != ';')))
		return 0;
	*start = i;
	for (; i < n && (quote || s[i] != ';'); i++)
		if (s[i] == '"')
			quote = !quote;
	*len = i - *start;
	*pos = i + 1;
	return 1;
}
