/*
 * gload_opts.c - galil-load's command line made into settings
 * (gload_opts.h).
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "base_paths.h"
#include "dmc_model.h"
#include "dmc_rule.h"
#include "gl_disc.h"
#include "gload_cmd.h"
#include "gload_opts.h"

int gload_opts_int(const char *s, int lo, int hi, int *out)
{
	char *end;
	long v;

	errno = 0;
	v = strtol(s, &end, 10);
	if (errno || end == s || *end || v < lo || v > hi)
		return -1;
	*out = (int)v;
	return 0;
}

static int set_start_label(struct gload_opts *o, const char *arg)
{
	size_t n;

	o->start = 1;
	if (!arg)
		arg = "AUTO";
	if (arg[0] == '#')
		arg++;
	n = strlen(arg);
	if (n > DMC_LABEL_MAX || !dmc_label_ok(arg, n))
		return -1;
	memcpy(o->start_label, arg, n + 1);
	return 0;
}

static int add_command(struct gload_opts *o, const char *cmd,
		       gload_usage_fn *usage)
{
	int rc;

	if (o->ncmds == GLOAD_MAX_COMMANDS)
		return usage("too many -c commands (at most %d)",
			     GLOAD_MAX_COMMANDS);
	rc = gload_cmd_check(cmd, usage);
	if (rc)
		return rc;
	o->cmds[o->ncmds++] = cmd;
	return 0;
}

void gload_opts_init(struct gload_opts *o)
{
	memset(o, 0, sizeof(*o));
	o->model = dmc_model_default();
	o->timeout_ms = GLOAD_DEFAULT_TIMEOUT_MS;
	o->stop_ms = GLOAD_STOP_MS;
	o->find_addr = GL_DISC_BCAST;
	o->find_port = GL_DISC_PORT;
}

int gload_opts_set(struct gload_opts *o, int ch, const char *arg,
		   gload_usage_fn *usage)
{
	switch (ch) {
	case 'a': o->addr = arg; return 0;
	case GLOAD_OPT_CHECK: o->check_only = 1; return 0;
	case 'o': o->output = arg; return 0;
	case 'f': o->force = 1; return 0;
	case GLOAD_OPT_BURN: o->burn = 1; return 0;
	case GLOAD_OPT_NO_START: o->start = 0; return 0;
	case 'c': return add_command(o, arg, usage);
	case 'h': return -1;
	case GLOAD_OPT_VERSION: o->version = 1; return 0;
	case GLOAD_OPT_DMC: o->dmc = arg; return 0;
	case GLOAD_OPT_CONFIG: o->config = arg; return 0;
	case GLOAD_OPT_VERIFY: o->verify = 1; return 0;
	case 'm':
		o->model = dmc_model_find(arg);
		return o->model ? 0
				: usage("unknown model '%s' (40x0, "
					"41x3, 21x3, 30010)",
					arg);
	case 't':
		o->timeout_set = 1;
		return gload_opts_int(arg, 1, 600000, &o->timeout_ms)
			   ? usage("invalid timeout '%s' (1..600000 "
				   "ms)",
				   arg)
			   : 0;
	case GLOAD_OPT_FIND: o->find = 1; return 0;
	case GLOAD_OPT_FIND_ADDR: o->find_addr = arg; return 0;
	case GLOAD_OPT_FIND_PORT:
		return gload_opts_int(arg, 1, 65535, &o->find_port)
			   ? usage("invalid --find-port '%s'", arg)
			   : 0;
	case GLOAD_OPT_STOP_WAIT:
		return gload_opts_int(arg, 1, 60000, &o->stop_ms)
			   ? usage("invalid --stop-wait '%s' (1..60000 "
				   "ms)",
				   arg)
			   : 0;
	case GLOAD_OPT_START:
		return set_start_label(o, arg)
			   ? usage("invalid label '%s' for --start", arg)
			   : 0;
	}
	return usage("%s", "unknown option");
}

/* Combinations that make no sense or would be unsafe. */
static int check_combination(const struct gload_opts *o, gload_usage_fn *usage)
{
	if (o->verify && (o->check_only || o->force || o->burn || o->start ||
			  o->ncmds || o->find))
		return usage("%s", "--verify only reads the controller's "
				   "program; drop --check, -f, --burn, "
				   "--start, -c and --find");
	if (o->check_only && (o->ncmds || o->burn || o->start))
		return usage("%s", "--check does not talk to a "
				   "controller; drop -c, --burn and --start");
	if (o->check_only && o->npaths == 0)
		return usage("%s", "--check needs program files");
	if (o->npaths == 0 && (o->burn || o->start || o->output))
		return usage("%s", "--burn, --start and -o need program "
				   "files (only a checked program is burned or "
				   "started)");
	if (o->find && (o->npaths || o->ncmds || o->addr || o->check_only))
		return usage("%s", "--find only lists controllers; give "
				   "it no -a, -c, --check or files");
	if (o->find)
		return 0;
	if (o->npaths == 0 && o->ncmds == 0)
		return usage("%s", "no program files and no commands");
	if (!o->check_only && !o->addr)
		return usage("%s", "no controller address (-a HOST); use "
				   "--check to check offline");
	return 0;
}

/* --dmc DIR, or with neither files nor -c commands (nor --find) the
 * default DMC directory: ./dmc, else the installed one (base_paths.h). */
static int choose_programs(struct gload_opts *o, gload_usage_fn *usage)
{
	if (o->dmc && o->npaths)
		return usage("%s", "--dmc DIR and program files: give "
				   "one or the other");
	if (o->dmc) {
		o->dmc_path[0] = (char *)o->dmc;
		o->paths = o->dmc_path;
		o->npaths = 1;
		return 0;
	}
	if (o->npaths || ((o->ncmds || o->find) && !o->version))
		return 0;
	if (base_paths_dmc_dir(o->dmc_dir, sizeof(o->dmc_dir)) < 0) {
		if (o->version)
			return 0;
		return usage("no program files and no commands, and no "
			     "DMC programs: neither dmc/MANIFEST here "
			     "nor %s/MANIFEST",
			     o->dmc_dir);
	}
	o->dmc_default = 1;
	o->dmc_path[0] = o->dmc_dir;
	o->paths = o->dmc_path;
	o->npaths = 1;
	return 0;
}

int gload_opts_finish(struct gload_opts *o, char **paths, int npaths,
		      gload_usage_fn *usage)
{
	int rc;

	o->paths = paths;
	o->npaths = npaths;
	rc = choose_programs(o, usage);
	if (rc || o->version)
		return rc;
	return check_combination(o, usage);
}
