/*
 * dmc_rule.c - the DMC linter's rule table and name rules (dmc_rule.h).
 * "CR" is the DMC-4000 command reference, "UM" the DMC-40x0 user manual.
 */
#include <ctype.h>

#include "dmc_model.h"
#include "dmc_rule.h"

static const struct dmc_rule rules[DMC_R_COUNT] = {
    [DMC_R_LINE_LENGTH] = {"line-length",
			   "UM, program format: at most 80 characters a line "
			   "(per model: dmc_model)",
			   DMC_RULE_SIM},
    [DMC_R_CHAR] = {"char-printable", "CR, DL: the program is ASCII text", 0},
    [DMC_R_BACKSLASH] = {"backslash", "CR, DL: '\\' ends the download", 0},
    [DMC_R_STRING_OPEN] = {"string-open",
			   "CR, MG: a string is enclosed in '\"'; an open one "
			   "swallows the rest of the line",
			   0},
    [DMC_R_LABEL_SYNTAX] = {"label-syntax",
			    "CR, # (label): a letter, then letters and "
			    "digits; '_' too on the DMC-40x0",
			    DMC_RULE_SIM},
    [DMC_R_LABEL_LENGTH] = {"label-length",
			    "CR, #: at most 7 characters after '#'",
			    DMC_RULE_SIM},
    [DMC_R_LABEL_POSITION] = {"label-position", "CR, #: a label starts a line",
			      0},
    [DMC_R_LABEL_DUPLICATE] = {"label-duplicate",
			       "CR, TC 61: duplicate or bad label",
			       DMC_RULE_SIM},
    [DMC_R_LABEL_UNDEFINED] = {"label-undefined",
			       "CR, JP/JS/XQ: the label must exist", 0},
    [DMC_R_VAR_SYNTAX] = {"var-syntax",
			  "UM, variables: a letter first; '_' inside is "
			  "used on hardware (real-controller-facts)",
			  0},
    [DMC_R_VAR_LENGTH] = {"var-length", "UM, variables: at most 8 characters",
			  0},
    [DMC_R_VAR_RESERVED] = {"var-reserved",
			    "UM: IF, ELSE, ENDIF, TIME, REM are reserved", 0},
    [DMC_R_VAR_COMMAND] = {"var-command",
			   "UM: a variable may not be a command name", 0},
    [DMC_R_IF_MATCH] = {"if-match",
			"CR, IF/ELSE/ENDIF: each IF ends with ENDIF", 0},
    [DMC_R_LOWER_CASE] = {"lower-case",
			  "CR: commands are upper case (lower case answers "
			  "'?')",
			  0},
    [DMC_R_NO_SEMICOLON] = {"no-semicolon",
			    "CR, NO: ';' ends the comment; the rest of the "
			    "line runs (real-controller-facts)",
			    0},
    [DMC_R_EQ_EQ] = {"eq-eq",
		     "UM, operators: '=' compares; '==' is not an operator", 0},
    [DMC_R_DL_IN_PROGRAM] = {"dl-in-program",
			     "CR, DL and UL: not valid in a program", 0},
    [DMC_R_WT_ASSIGN] = {"wt-assign", "CR, WT: 'WT n' waits; 'WT=n' does not",
			 0},
    [DMC_R_JP_ARGS] = {"jp-args",
		       "CR, JP: 'JP #str,(ex)' takes no argument list "
		       "(JS does)",
		       0},
    [DMC_R_JS_ARGS] = {"js-args",
		       "CR, JS: at most 8 arguments; an array passed by "
		       "reference has a name of 6 characters or less",
		       0},
    [DMC_R_LINES_LIMIT] = {"lines-limit",
			   "UM: program lines per model (dmc_model)",
			   DMC_RULE_SIM},
    [DMC_R_LABELS_LIMIT] = {"labels-limit", "UM: labels per model (dmc_model)",
			    DMC_RULE_SIM},
    [DMC_R_VARS_LIMIT] = {"vars-limit", "UM: variables per model (dmc_model)",
			  0},
    [DMC_R_EMPTY] = {"empty", "a program with no line", 0},
};

const struct dmc_rule *dmc_rule(enum dmc_rule_id id)
{
	return (unsigned)id < DMC_R_COUNT ? &rules[id] : NULL;
}

/* A letter, then letters or digits, and '_' when @underscore is set. */
static int label_chars_ok(const char *s, size_t n, int underscore)
{
	if (n == 0 || !isalpha((unsigned char)s[0]))
		return 0;
	for (size_t i = 1; i < n; i++)
		if (!isalnum((unsigned char)s[i]) &&
		    !(underscore && s[i] == '_'))
			return 0;
	return 1;
}

int dmc_label_ok(const char *s, size_t n)
{
	return label_chars_ok(s, n, 1);
}

int dmc_label_ok_model(const struct dmc_model *m, const char *s, size_t n)
{
	return label_chars_ok(s, n, m->label_underscore);
}

int dmc_var_ok(const char *s, size_t n)
{
	if (n == 0 || !isalpha((unsigned char)s[0]))
		return 0;
	for (size_t i = 1; i < n; i++)
		if (!isalnum((unsigned char)s[i]) && s[i] != '_')
			return 0;
	return 1;
}
