/*
 * gload_check.h - galil-load's offline checker: the mistakes a DMC controller
 * would reject at download or trip over at run time, found before anything
 * is sent, each reported as "FILE:LINE: message" at the source line.
 *
 * Checked on the preprocessed lines (what is downloaded), reported at the
 * source line they came from:
 *  - line length (the controller's limit applies to the downloaded line);
 *  - '\' anywhere (it ends a download early) and bytes that are not
 *    printable ASCII;
 *  - labels: '#', a letter, then letters, digits or '_', at most 7 after
 *    the '#'; only at the start of a line; no duplicates;
 *  - label references of JP, JS and XQ (also "JS #L(args)" and "JP #L,cond")
 *    that name no label;
 *  - variable names (assignment targets, DM arrays, names in expressions):
 *    a letter, then letters or digits, at most 8; not a reserved word or a
 *    two-letter command name;
 *  - lower-case commands ("bg", "mg", "if"): the controller answers '?';
 *  - a ';' after the text of a NO comment (the rest runs as commands);
 *  - IF / ELSE / ENDIF nesting;
 *  - the number of lines (with the identity line), labels and variables
 *    against the model's limits.
 * The checker does not know every command's arguments; it never reports an
 * upper-case statement it does not recognise (the controller's own download
 * check and the read-back still apply).
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
