/*
 * gload_check.h - galil-load's offline check: the mistakes a DMC controller
 * would reject at download or trip over at run time, found before anything
 * is sent. The rules are the DMC front end's linter (pc/dmc/dmc_lint.h,
 * table in pc/dmc/dmc_rule.c, listed in docs/galil-load.md); this module
 * runs it on the preprocessed lines (what is downloaded, plus the identity
 * line against the model's line limit) and reports each finding at the
 * source line it came from, as "FILE:LINE: rule: message".
 */
#ifndef GLOAD_CHECK_H
#define GLOAD_CHECK_H

#include "dmc_model.h"
#include "gload_diag.h"
#include "gload_prep.h"

/* What the checker counted, for the summary line. */
struct gload_stats {
	int lines; /* downloaded lines, with the identity line */
	int labels;
	int vars; /* distinct scalar variables assigned */
};

/*
 * gload_check() - check a preprocessed program.
 * @p: [in] the program (gload_prog_finish() not required).
 * @m: [in] the model whose limits apply.
 * @d: [out] one diagnostic per problem, at the source line.
 * @st: [out] optional counts.
 * Return: the number of problems found (>= 0; 0 = clean), or GL_ERR_NOMEM.
 */
int gload_check(const struct gload_prog *p, const struct dmc_model *m,
		struct gload_diags *d, struct gload_stats *st);

#endif /* GLOAD_CHECK_H */
