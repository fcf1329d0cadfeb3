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

#include "gload_diag.h"
#include "gload_prep.h"

#define GLOAD_LABEL_MAX 7 /* characters after '#' [galil-notes 3.4] */
#define GLOAD_VAR_MAX	8 /* characters in a variable name [3.4] */

/* A controller family and its program limits (docs/galil-load.md). */
struct gload_model {
	const char *name;  /* --model value: "40x0" */
	const char *title; /* in messages: "DMC-40x0" */
	int line_chars;	   /* characters per program line */
	int max_lines;	   /* program lines */
	int max_labels;
	int max_vars;  /* scalar variables */
	int threads;   /* program threads 0..threads-1 */
	int confirmed; /* 0: limits not confirmed from a primary
			* source; conservative values */
};

/*
 * gload_model_find() - the model called @name ("40x0", "41x3", "21x3",
 * "30010"; also "4030" style numbers and a "DMC-"/"DMC" prefix).
 * Return: the model, or NULL when unknown.
 */
const struct gload_model *gload_model_find(const char *name);

/* gload_model_default() - the DMC-40x0 (the RoboELF DMC-4030). */
const struct gload_model *gload_model_default(void);

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
int gload_check(const struct gload_prog *p, const struct gload_model *m,
		struct gload_diags *d, struct gload_stats *st);

#endif /* GLOAD_CHECK_H */
