/*
 * gload_seal.h - the seal: the program part that holds every value which
 * decides how the robot moves or is stopped as a literal, generated from
 * the configuration (pc/super/re_seal.h, docs/dmc-interface.md "The seal") and
 * appended where the manifest says GLOAD_SEAL_ENTRY. roboelf regenerates it
 * from its own configuration and refuses a controller whose program was
 * sealed with other values.
 *
 * Nothing here prints.
 */
#ifndef GLOAD_SEAL_H
#define GLOAD_SEAL_H

#include <stddef.h>

#include "gload_prep.h"

/*
 * gload_seal_find_config() - the configuration to seal with when none is
 * given: ./config/roboelf.yaml (the source tree), else the installed one
 * (base_paths_sysconf("roboelf/roboelf.yaml")), as roboelf looks for it.
 * @out: [out] the path chosen (the installed one when neither exists).
 * Return: 0 when the file exists, -1 when not.
 */
int gload_seal_find_config(char *out, size_t len);

/*
 * gload_seal_append() - load the configuration @config, build the seal of
 * the program read so far (@p's lines), and preprocess it into @p as the
 * file "seal from CONFIG".
 * @nitems: [out] the number of sealed values.
 * @err: [out] "CONFIG:12:3: ..." (the configuration's own error) or what
 *       the program lacks.
 * Return: GL_OK; GL_ERR_CONFIG; GL_ERR_SYS (the file cannot be read);
 *         GL_ERR_FORMAT; GL_ERR_OVERFLOW; GL_ERR_NOMEM.
 */
int gload_seal_append(struct gload_prog *p, const char *config, int *nitems,
		      char *err, size_t errlen);

#endif /* GLOAD_SEAL_H */
