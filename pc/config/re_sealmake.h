/*
 * re_sealmake.h - the seal (re_seal.h) of a program for a configuration:
 * one generator for galil-load, roboelf and the DMC tests. Pure: no I/O,
 * no printing, no allocation.
 */
#ifndef RE_SEALMAKE_H
#define RE_SEALMAKE_H

#include <stddef.h>

#include "re_config.h"
#include "re_seal.h"

/*
 * re_seal_make() - the seal of the program @body (the preprocessed program
 * text up to, not including, the seal part: its #CONSTS and the lines of
 * #MOTION .. #POSERR) for the configuration @cfg, with the plan derived for
 * the program's own mainms: re_seal_start(), the parameters and settings
 * from @cfg, re_seal_end().
 * @out: [out] the table; item i (0-based) is the program's item i + 1.
 * @err: [out] on failure, e.g. "the program has no #CONSTS".
 * Return: GL_OK; GL_ERR_FORMAT (a constant that is not a number or 0-NAME,
 *         a label missing, no mainms); GL_ERR_OVERFLOW (too many items).
 */
int re_seal_make(const char *body, size_t len, const struct re_config *cfg,
		 struct re_seal *out, char *err, size_t errlen);

#endif /* RE_SEALMAKE_H */
