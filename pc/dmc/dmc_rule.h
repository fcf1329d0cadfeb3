/*
 * dmc_rule.h - the ONE table of the DMC linter's rules: each rule's name
 * (printed with every finding, "FILE:LINE: rule: message"), the source it
 * rests on, and what it guards against. The linter (dmc_lint.h) applies
 * them, galil-load's checker prints its findings
 * (tools/galil-load/gload_check.c), docs/galil-load.md lists the table (a
 * test holds them equal), and galil-sim's download refuses what the rules
 * marked DMC_RULE_SIM refuse (TC 60/61/62), so the checker and the
 * simulated firmware agree (tests/load/test_gload_lint.c).
 *
 * Pure data; no I/O.
 */
#ifndef DMC_RULE_H
#define DMC_RULE_H

#include <stddef.h>

enum dmc_rule_id {
	DMC_R_LINE_LENGTH,
	DMC_R_CHAR,
	DMC_R_BACKSLASH,
	DMC_R_STRING_OPEN,
	DMC_R_LABEL_SYNTAX,
	DMC_R_LABEL_LENGTH,
	DMC_R_LABEL_POSITION,
	DMC_R_LABEL_DUPLICATE,
	DMC_R_LABEL_UNDEFINED,
	DMC_R_VAR_SYNTAX,
	DMC_R_VAR_LENGTH,
	DMC_R_VAR_RESERVED,
	DMC_R_VAR_COMMAND,
	DMC_R_IF_MATCH,
	DMC_R_LOWER_CASE,
	DMC_R_NO_SEMICOLON,
	DMC_R_EQ_EQ,
	DMC_R_DL_IN_PROGRAM,
	DMC_R_WT_ASSIGN,
	DMC_R_JP_ARGS,
	DMC_R_JS_ARGS,
	DMC_R_LINES_LIMIT,
	DMC_R_LABELS_LIMIT,
	DMC_R_VARS_LIMIT,
	DMC_R_EMPTY,
	DMC_R_COUNT
};

#define DMC_RULE_SIM 1u /* galil-sim refuses it at download too */

struct dmc_rule {
	const char *name;   /* e.g. "label-syntax" */
	const char *source; /* the reference it rests on */
	unsigned flags;	    /* DMC_RULE_* */
};

/*
 * dmc_rule() - the rule @id (0 <= id < DMC_R_COUNT); NULL otherwise.
 * The entries are static and never change.
 */
const struct dmc_rule *dmc_rule(enum dmc_rule_id id);

struct dmc_model;

/*
 * dmc_label_ok() - 1 when the @n bytes at @s are a label name (without
 * the '#') that some model accepts by its characters: a letter, then
 * letters, digits or '_'. 0 otherwise. For a command-line label, before
 * the model is known; a program's labels are judged per model by
 * dmc_label_ok_model(). The length (DMC_LABEL_MAX, dmc_model.h) is
 * judged apart, by its own rule.
 */
int dmc_label_ok(const char *s, size_t n);

/*
 * dmc_label_ok_model() - dmc_label_ok() for the model @m (not NULL): a
 * letter, then letters or digits (command reference, #), and '_' too when
 * @m->label_underscore is set. Return 1 when valid, else 0.
 */
int dmc_label_ok_model(const struct dmc_model *m, const char *s, size_t n);

/*
 * dmc_var_ok() - 1 when the @n bytes at @s are a valid variable name by
 * its characters: a letter, then letters, digits or '_' (the user
 * manual's rule plus '_', which production programs use on hardware:
 * real-controller-facts). The length is judged apart. 0 otherwise.
 */
int dmc_var_ok(const char *s, size_t n);

#endif /* DMC_RULE_H */
