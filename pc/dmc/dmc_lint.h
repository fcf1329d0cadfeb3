/*
 * dmc_lint.h - the DMC linter: the rules of dmc_rule.h applied to a
 * program text held in memory, findings out. The ONE implementation of
 * the rules: galil-load's --check formats its findings
 * (tools/galil-load/gload_check.c) and the DMC tests lint dmc/ with it
 * (tests/dmc/test_dmc_static.c), so both judge a program alike.
 *
 * Input: the program as the controller receives it (galil-load's
 * preprocessed text): lines end with LF (CR LF and CR are read too), a
 * line may hold NUL bytes. Lines whose first word is REM are skipped, and
 * so is a statement that starts with ' (a comment up to the next ';', as
 * galil-sim reads it). Each finding names its rule, its line and a
 * message (lower case, no full stop, no file name, no rule name: the
 * caller prints "FILE:LINE: rule: message").
 *
 * Pure: no I/O, no globals; memory only for the findings and tables.
 */
#ifndef DMC_LINT_H
#define DMC_LINT_H

#include <stddef.h>

#include "dmc_model.h"
#include "dmc_rule.h"

#define DMC_LINT_MSG_SIZE  200 /* bytes of a message, with its NUL */
#define DMC_LINT_NAME_SIZE 9   /* a variable's name (8 characters), NUL */
#define DMC_LINT_NOMEM	   (-1)

struct dmc_finding {
	enum dmc_rule_id rule;
	int line;     /* 1-based line of the text; 0 = the whole text */
	int ref_line; /* the earlier line it refers to (where a duplicate
		       * label was first defined), else 0 */
	int seq;      /* order of detection (ties in line order) */
	char msg[DMC_LINT_MSG_SIZE];
};

/* A variable or array the program assigns ("x=", "a[i]="), where first. */
struct dmc_target {
	char name[DMC_LINT_NAME_SIZE]; /* truncated if longer (a finding) */
	int line;		       /* 1-based line of the first one */
	int array;		       /* 1 when assigned as name[index] */
};

struct dmc_lint {
	struct dmc_finding *v; /* in line order, then detection order */
	int n, cap;
	int lines;  /* program lines, with the caller's extra lines */
	int labels; /* labels defined */
	int vars;   /* distinct scalar variables assigned */
	struct dmc_target *targets; /* every name assigned, distinct, in */
	int ntargets;		    /* order of first assignment */
};

/*
 * dmc_lint_text() - lint a program text.
 * @text: [in] the program, @len bytes (NULL only when @len is 0).
 * @m: [in] the model whose limits apply (dmc_model_find()); not NULL.
 * @extra_lines: lines the caller adds to the program before it reaches
 *               the controller (galil-load's identity line: 1), counted
 *               against the model's line limit.
 * @out: [out] zero-initialised (or after dmc_lint_free()); receives the
 *       findings, the counts and the names the program assigns (what a
 *       test of foreign writes walks). Free with dmc_lint_free().
 * Return: the number of findings (>= 0; 0 = clean), or DMC_LINT_NOMEM
 *         (@out then holds what was found before memory ran out).
 */
int dmc_lint_text(const char *text, size_t len, const struct dmc_model *m,
		  int extra_lines, struct dmc_lint *out);

/* dmc_lint_free() - free the findings and the names; @r is left zeroed
 * and reusable. */
void dmc_lint_free(struct dmc_lint *r);

#endif /* DMC_LINT_H */
