/*
 * dmc_text.h - the lexical rules of DMC text that galil-load and
 * galil-sim must read alike: a name character, and the REM comment.
 *
 * REM is not a controller command: gclib and galil-load strip "REM"
 * lines before a download [galil-notes 3.x, GCPP], so a real controller
 * never sees one. The one rule: REM is a comment when it is the first
 * word of the text (after blanks) and a whole word - "REMX=1" is an
 * assignment to the variable REMX, never a comment. galil-load applies
 * it to a line (it strips the line); galil-sim's program store and
 * interpreter to a statement (docs/dmc-interface.md).
 *
 * Pure: no I/O, no allocation.
 */
#ifndef DMC_TEXT_H
#define DMC_TEXT_H

#include <stddef.h>

/* dmc_is_name_char() - 1 for a letter, digit or '_', else 0. */
int dmc_is_name_char(char c);

/*
 * dmc_is_rem() - 1 when the @n bytes at @s, after leading spaces and
 * tabs, start with the whole word "REM" (followed by the end or a
 * character that is not a name character), else 0.
 */
int dmc_is_rem(const char *s, size_t n);

/*
 * dmc_stmt_next() - the next statement of the line @s (@n bytes), from
 * *@pos: statements end at ';' outside "strings". Sets *@start and *@len
 * (without the ';') and advances *@pos past the ';'.
 * Return: 1 when a statement was found, 0 at the end of the line.
 */
int dmc_stmt_next(const char *s, size_t n, size_t *pos, size_t *start,
		  size_t *len);

#endif /* DMC_TEXT_H */
