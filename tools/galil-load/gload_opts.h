/*
 * gload_opts.h - galil-load's command line made into settings: each
 * option's value checked, the -c commands checked (gload_cmd.h), the
 * program files chosen (--dmc, or the default DMC directory: ./dmc, else
 * the installed one, base_paths.h) and the combinations that make no sense
 * or would be unsafe refused. main.c holds the option table and the usage
 * text (docs/galil-load.1) and runs getopt_long() over them. Nothing here
 * prints: a usage error is reported through the caller's usage function.
 */
#ifndef GLOAD_OPTS_H
#define GLOAD_OPTS_H

#include <limits.h>

#include "dmc_model.h"
#include "gload_cmd.h"

#define GLOAD_DEFAULT_TIMEOUT_MS 5000 /* gclib's default [galil-notes 1.6] */
#define GLOAD_STOP_MS		 3000 /* default --stop-wait: stopped after ST */
#define GLOAD_MAX_COMMANDS	 64   /* -c commands, at most */

/* The options without a short letter, as getopt_long() returns them. */
enum gload_opt {
	GLOAD_OPT_CHECK = 256,
	GLOAD_OPT_BURN,
	GLOAD_OPT_START,
	GLOAD_OPT_NO_START,
	GLOAD_OPT_STOP_WAIT,
	GLOAD_OPT_FIND,
	GLOAD_OPT_FIND_ADDR,
	GLOAD_OPT_FIND_PORT,
	GLOAD_OPT_VERSION,
	GLOAD_OPT_DMC,
	GLOAD_OPT_CONFIG,
	GLOAD_OPT_VERIFY
};

/* What the command line asks for (the defaults: gload_opts_init()). */
struct gload_opts {
	const char *addr;
	const struct dmc_model *model;
	int check_only;
	int burn;
	int start;
	int force;
	int timeout_ms;
	int stop_ms;
	int timeout_set;
	int find;
	const char *find_addr;
	int find_port;
	char start_label[DMC_LABEL_MAX + 1];
	const char *output;
	const char *cmds[GLOAD_MAX_COMMANDS];
	int ncmds;
	char **paths;
	int npaths;
	const char *dmc;	    /* --dmc DIR */
	const char *config;	    /* --config FILE: what the seal holds */
	int version;		    /* --version */
	int verify;		    /* --verify: compare, never write */
	int dmc_default;	    /* no files given: dmc_dir was chosen */
	char *dmc_path[1];	    /* paths when --dmc or the default */
	char dmc_dir[PATH_MAX + 1]; /* the default DMC directory */
};

/*
 * gload_opts_init() - @o with every default: model 40x0, timeout
 * GLOAD_DEFAULT_TIMEOUT_MS, --stop-wait GLOAD_STOP_MS, the discovery probe
 * to GL_DISC_BCAST port GL_DISC_PORT, nothing else set. No return value.
 */
void gload_opts_init(struct gload_opts *o);

/*
 * gload_opts_set() - apply one option that getopt_long() returned.
 * @ch: the short option letter (a m o f c t h) or a GLOAD_OPT_* value.
 * @arg: its argument (optarg), NULL when it has none.
 * @usage: [in] reports a bad value; must not be NULL.
 * Return: 0, -1 for --help, or what @usage returned (also for an unknown
 *         @ch: "unknown option").
 */
int gload_opts_set(struct gload_opts *o, int ch, const char *arg,
		   gload_usage_fn *usage);

/*
 * gload_opts_finish() - after the options: @paths (@npaths of them) are
 * the file arguments (they stay the caller's). Chooses the programs
 * (--dmc DIR, or with neither files nor -c commands nor --find the default
 * DMC directory) and, unless --version was given, refuses the combinations
 * that make no sense or would be unsafe.
 * Return: 0, or what @usage returned.
 */
int gload_opts_finish(struct gload_opts *o, char **paths, int npaths,
		      gload_usage_fn *usage);

/*
 * gload_opts_int() - @s as a decimal int within @lo..@hi into *@out.
 * Return: 0, or -1 (not a number, trailing characters, out of range).
 */
int gload_opts_int(const char *s, int lo, int hi, int *out);

#endif /* GLOAD_OPTS_H */
