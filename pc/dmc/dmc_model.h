/*
 * dmc_model.h - the limits of the Galil controller families a technician
 * may meet, in one place: characters per line, program lines, labels,
 * variables, threads; and the name rules every family shares. Used by
 * galil-load's checker, by galil-sim's program store and by the tests.
 *
 * Not a parser (dmc_text) and not the command list (dmc_cmd).
 * Sources: galil-notes 3.4 and the DMC-4000 user manual; values a primary
 * source did not confirm are marked (confirmed = 0) and conservative.
 */
#ifndef DMC_MODEL_H
#define DMC_MODEL_H

#define DMC_LINE_MAX  80 /* characters per line, host and program [3.4] */
#define DMC_LABEL_MAX 7	 /* characters after '#' [galil-notes 3.4] */
#define DMC_NAME_MAX  8	 /* characters in a variable or array name [3.4] */

/* The DMC-40x0 (the RoboELF DMC-4030): the model galil-sim is. */
#define DMC_40X0_LINES	 4000 /* program lines */
#define DMC_40X0_LABELS	 510
#define DMC_40X0_VARS	 510
#define DMC_40X0_THREADS 8

/* A controller family and its program limits (docs/galil-load.md). */
struct dmc_model {
	const char *name;  /* --model value: "40x0" */
	const char *title; /* in messages: "DMC-40x0" */
	int line_chars;	   /* characters per program line */
	int max_lines;	   /* program lines */
	int max_labels;
	int max_vars;	      /* scalar variables */
	int threads;	      /* program threads 0..threads-1 */
	int confirmed;	      /* 0: limits not confirmed from a primary
			       * source; conservative values */
	int label_underscore; /* 1: '_' accepted in a label after its
			       * first character (docs/galil-sim.md,
			       * "Labels with '_'") */
};

/*
 * dmc_model_find() - the model called @name ("40x0", "41x3", "21x3",
 * "30010"; also "4030" style numbers and a "DMC-"/"DMC" prefix, any case).
 * Return: the model (static, never freed), or NULL when unknown.
 */
const struct dmc_model *dmc_model_find(const char *name);

/* dmc_model_default() - the DMC-40x0 (the RoboELF DMC-4030); never NULL. */
const struct dmc_model *dmc_model_default(void);

#endif /* DMC_MODEL_H */
