/*
 * galil-load - check, preprocess, download, verify, burn and start DMC
 * programs on a Galil controller; send diagnostic commands.
 *
 *   galil-load [-a HOST[:PORT]] [options] FILE.dmc...|DIR
 *
 * See docs/galil-load.1 and docs/galil-load.md. Every step that touches the
 * controller comes after the offline check has passed; a failed download or
 * read-back leaves the controller halted and empty.
 */
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base_paths.h"
#include "base_version.h"
#include "dmc_cmd.h"
#include "dmc_rule.h"
#include "gl_disc.h"
#include "gl_err.h"
#include "gl_link.h"
#include "gl_proto.h"
#include "gload_check.h"
#include "gload_dl.h"
#include "gload_prep.h"
#include "gload_seal.h"
#include "re_config.h"

#define DEFAULT_TIMEOUT_MS 5000 /* gclib's default [galil-notes 1.6] */
#define STOP_MS		   3000 /* default --stop-wait: axes stopped after ST */
#define BUSY_WATCH_MS	   250	/* a supervisor's heartbeat changes within */
#define MAX_COMMANDS	   64
#define FIND_MS		   1000 /* discovery window (GAddresses: about 1 s) */
#define FIND_MAX	   32

struct opts {
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
	const char *cmds[MAX_COMMANDS];
	int ncmds;
	char **paths;
	int npaths;
	const char *dmc;	    /* --dmc DIR */
	const char *config;	    /* --config FILE: what the seal holds */
	int version;		    /* --version */
	int dmc_default;	    /* no files given: dmc_dir was chosen */
	char *dmc_path[1];	    /* paths when --dmc or the default */
	char dmc_dir[PATH_MAX + 1]; /* the default DMC directory */
};

static const char usage_text[] =
    "usage: galil-load [-a HOST[:PORT]] [options] FILE.dmc...|DIR\n"
    "       galil-load [-a HOST[:PORT]] [options]   (the DMC programs in\n"
    "                  ./dmc, else the installed ones)\n"
    "\n"
    "  -a, --address HOST[:PORT]  controller (default port 23)\n"
    "      --check                check and preprocess only; no controller\n"
    "  -m, --model MODEL          limits of 40x0 (default), 41x3, 21x3, 30010\n"
    "  -o, --output FILE          also write the stamped program to FILE\n"
    "  -f, --force                download even if the controller already\n"
    "                             holds the same program, and even while\n"
    "                             roboelf drives the robot (halts it: axes\n"
    "                             stop, motors off, roboelf latches a fault)\n"
    "      --burn                 burn the program to flash (BP) after the\n"
    "                             read-back; #AUTO then runs at power-up\n"
    "      --start[=LABEL]        start LABEL (default AUTO) in thread 0 and\n"
    "                             confirm it runs\n"
    "      --no-start             do not start the program (the default)\n"
    "  -c, --command CMD          send CMD and print the reply (repeatable;\n"
    "                             after any download)\n"
    "  -t, --timeout MS           reply timeout (default 5000; DL, UL and BP\n"
    "                             take at least 10000)\n"
    "      --stop-wait MS         how long the axes may take to stop after ST\n"
    "                             before loading (default 3000); an axis\n"
    "                             still moving then is aborted and nothing\n"
    "                             is loaded\n"
    "      --find                 list the Galil controllers that answer on\n"
    "                             the local network (-t MS: how long to\n"
    "                             listen, default 1000); also offered when\n"
    "                             -a does not answer\n"
    "      --find-addr ADDR       where the discovery probe goes (default\n"
    "                             255.255.255.255)\n"
    "      --find-port PORT       its UDP port (default 50000)\n"
    "      --dmc DIR              the program directory (as DIR above)\n"
    "      --config FILE          the configuration the program is sealed\n"
    "                             with (default ./config/roboelf.yaml, else\n"
    "                             the installed /etc/roboelf/roboelf.yaml)\n"
    "  -h, --help                 this text\n"
    "      --version              the release, the DMC interface and the\n"
    "                             identity of the DMC programs\n"
    "\n"
    "A DIR is loaded through DIR/MANIFEST (one file name per line, '#'\n"
    "comments). Exit: 0 ok, 1 check failed, 2 usage, 3 connection,\n"
    "4 controller rejected or verify failed.\n";

static int usage_error(const char *fmt, ...)
    __attribute__((format(printf, 1, 2)));

static int usage_error(const char *fmt, ...)
{
	va_list ap;

	fprintf(stderr, "galil-load: ");
	va_start(ap, fmt);
	vfprintf(stderr, fmt, ap);
	va_end(ap);
	fprintf(stderr, "\n%s", usage_text);
	return GLOAD_EXIT_USAGE;
}

static int parse_int(const char *s, int lo, int hi, int *out)
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

static int set_start_label(struct opts *o, const char *arg)
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

/* @c with control bytes shown in caret notation (0x12 -> "^R"). */
static const char *shown(const char *c, char out[2 * GL_LINE_MAX + 8])
{
	size_t o = 0;

	for (; *c && o < 2 * GL_LINE_MAX + 4; c++) {
		unsigned char b = (unsigned char)*c;

		if (b < 0x20 || b == 0x7f) {
			out[o++] = '^';
			out[o++] = (char)(b ^ 0x40);
		} else {
			out[o++] = (char)b;
		}
	}
	out[o] = '\0';
	return out;
}

/* A control-character request: ^R^V, or ^L^K ? (the lock state); the
 * others change the controller (command reference ^R^S, ^L^K). */
static int check_ctrl_request(const char *cmd, enum gl_ctrl_kind k)
{
	char sh[2 * GL_LINE_MAX + 8];
	const char *a = cmd + 2;

	while (*a == ' ')
		a++;
	if (k == GL_CTRL_REVISION || (k == GL_CTRL_LOCK && !strcmp(a, "?")))
		return 0;
	if (k == GL_CTRL_RESET)
		return usage_error("'^R^S' (master reset: erases the "
				   "controller's EEPROM and its IP address) "
				   "is not sent by galil-load");
	if (k == GL_CTRL_LOCK)
		return usage_error("'%s': only '^L^K ?' (is the program "
				   "locked?) may be sent with -c",
				   shown(cmd, sh));
	return usage_error("'%s' holds a control character: only the "
			   "requests ^R^V and '^L^K ?' may be sent with -c",
			   shown(cmd, sh));
}

static int add_command(struct opts *o, const char *cmd)
{
	static const char *const refused[] = {"DL", "UL", "ED",
					      "QD", "QU", "QR"};
	enum gl_ctrl_kind k = gl_link_ctrl_kind(cmd);
	size_t i;

	if (o->ncmds == MAX_COMMANDS)
		return usage_error("too many -c commands (at most %d)",
				   MAX_COMMANDS);
	if (k != GL_CTRL_NONE && check_ctrl_request(cmd, k))
		return GLOAD_EXIT_USAGE;
	if (k != GL_CTRL_NONE) {
		o->cmds[o->ncmds++] = cmd;
		return 0;
	}
	if (strlen(cmd) == 0 || strlen(cmd) > GL_LINE_MAX)
		return usage_error("command '%s' is empty or longer than 80 "
				   "characters",
				   cmd);
	if (strchr(cmd, '\r') || strchr(cmd, '\n'))
		return usage_error("command '%s' holds a line end", cmd);
	for (i = 0; i < sizeof(refused) / sizeof(refused[0]); i++)
		if (!strncmp(cmd, refused[i], 2))
			return usage_error("'%s' cannot be sent with -c "
					   "(give program files to download)",
					   cmd);
	o->cmds[o->ncmds++] = cmd;
	return 0;
}

enum {
	OPT_CHECK = 256,
	OPT_BURN,
	OPT_START,
	OPT_NO_START,
	OPT_STOP_WAIT,
	OPT_FIND,
	OPT_FIND_ADDR,
	OPT_FIND_PORT,
	OPT_VERSION,
	OPT_DMC,
	OPT_CONFIG
};

static const struct option long_opts[] = {
    {"address", required_argument, NULL, 'a'},
    {"check", no_argument, NULL, OPT_CHECK},
    {"model", required_argument, NULL, 'm'},
    {"output", required_argument, NULL, 'o'},
    {"force", no_argument, NULL, 'f'},
    {"burn", no_argument, NULL, OPT_BURN},
    {"start", optional_argument, NULL, OPT_START},
    {"no-start", no_argument, NULL, OPT_NO_START},
    {"command", required_argument, NULL, 'c'},
    {"timeout", required_argument, NULL, 't'},
    {"stop-wait", required_argument, NULL, OPT_STOP_WAIT},
    {"find", no_argument, NULL, OPT_FIND},
    {"find-addr", required_argument, NULL, OPT_FIND_ADDR},
    {"find-port", required_argument, NULL, OPT_FIND_PORT},
    {"help", no_argument, NULL, 'h'},
    {"version", no_argument, NULL, OPT_VERSION},
    {"dmc", required_argument, NULL, OPT_DMC},
    {"config", required_argument, NULL, OPT_CONFIG},
    {NULL, 0, NULL, 0},
};

/* One option; return 0, -1 for --help, or an exit code. */
static int parse_opt(struct opts *o, int ch, const char *arg)
{
	switch (ch) {
	case 'a': o->addr = arg; return 0;
	case OPT_CHECK: o->check_only = 1; return 0;
	case 'o': o->output = arg; return 0;
	case 'f': o->force = 1; return 0;
	case OPT_BURN: o->burn = 1; return 0;
	case OPT_NO_START: o->start = 0; return 0;
	case 'c': return add_command(o, arg);
	case 'h': return -1;
	case OPT_VERSION: o->version = 1; return 0;
	case OPT_DMC: o->dmc = arg; return 0;
	case OPT_CONFIG: o->config = arg; return 0;
	case 'm':
		o->model = dmc_model_find(arg);
		return o->model ? 0
				: usage_error("unknown model '%s' (40x0, "
					      "41x3, 21x3, 30010)",
					      arg);
	case 't':
		o->timeout_set = 1;
		return parse_int(arg, 1, 600000, &o->timeout_ms)
			   ? usage_error("invalid timeout '%s' (1..600000 "
					 "ms)",
					 arg)
			   : 0;
	case OPT_FIND: o->find = 1; return 0;
	case OPT_FIND_ADDR: o->find_addr = arg; return 0;
	case OPT_FIND_PORT:
		return parse_int(arg, 1, 65535, &o->find_port)
			   ? usage_error("invalid --find-port '%s'", arg)
			   : 0;
	case OPT_STOP_WAIT:
		return parse_int(arg, 1, 60000, &o->stop_ms)
			   ? usage_error("invalid --stop-wait '%s' (1..60000 "
					 "ms)",
					 arg)
			   : 0;
	case OPT_START:
		return set_start_label(o, arg)
			   ? usage_error("invalid label '%s' for --start", arg)
			   : 0;
	}
	return usage_error("%s", "unknown option");
}

/* Combinations that make no sense or would be unsafe. */
static int check_combination(const struct opts *o)
{
	if (o->check_only && (o->ncmds || o->burn || o->start))
		return usage_error("%s",
				   "--check does not talk to a "
				   "controller; drop -c, --burn and --start");
	if (o->check_only && o->npaths == 0)
		return usage_error("%s", "--check needs program files");
	if (o->npaths == 0 && (o->burn || o->start || o->output))
		return usage_error("%s",
				   "--burn, --start and -o need program "
				   "files (only a checked program is burned or "
				   "started)");
	if (o->find && (o->npaths || o->ncmds || o->addr || o->check_only))
		return usage_error("%s", "--find only lists controllers; give "
					 "it no -a, -c, --check or files");
	if (o->find)
		return 0;
	if (o->npaths == 0 && o->ncmds == 0)
		return usage_error("%s", "no program files and no commands");
	if (!o->check_only && !o->addr)
		return usage_error("%s", "no controller address (-a HOST); use "
					 "--check to check offline");
	return 0;
}

/* --dmc DIR, or with neither files nor -c commands (nor --find) the
 * default DMC directory: ./dmc, else the installed one (base_paths.h). */
static int choose_programs(struct opts *o)
{
	if (o->dmc && o->npaths)
		return usage_error("%s", "--dmc DIR and program files: give "
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
		return usage_error("no program files and no commands, and no "
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

/* Return 0 to go on, -1 for --help, or an exit code. */
static int parse_args(int argc, char **argv, struct opts *o)
{
	int ch, rc;

	memset(o, 0, sizeof(*o));
	o->model = dmc_model_default();
	o->timeout_ms = DEFAULT_TIMEOUT_MS;
	o->stop_ms = STOP_MS;
	o->find_addr = GL_DISC_BCAST;
	o->find_port = GL_DISC_PORT;
	opterr = 0;
	while ((ch = getopt_long(argc, argv, ":a:m:o:fc:t:h", long_opts,
				 NULL)) != -1) {
		if (ch == '?' || ch == ':')
			return usage_error("invalid or incomplete option '%s'",
					   argv[optind - 1]);
		rc = parse_opt(o, ch, optarg);
		if (rc)
			return rc;
	}
	o->paths = argv + optind;
	o->npaths = argc - optind;
	rc = choose_programs(o);
	if (rc || o->version)
		return rc;
	return check_combination(o);
}

static void print_diags(struct gload_diags *d)
{
	int i;

	gload_diags_sort(d);
	for (i = 0; i < d->n; i++)
		fprintf(stderr, "%s\n", d->v[i].text);
	if (d->dropped)
		fprintf(stderr,
			"galil-load: %d more problems (out of memory)\n",
			d->dropped);
}

/* Write the stamped program to @path through a temporary file. */
static int write_output(const char *path, const struct gload_prog *p)
{
	char tmp[PATH_MAX];
	FILE *f;
	int ok;

	if (snprintf(tmp, sizeof(tmp), "%s.tmp%ld", path, (long)getpid()) >=
	    (int)sizeof(tmp))
		return -1;
	f = fopen(tmp, "wb");
	if (!f)
		goto out_err;
	ok = fwrite(p->text, 1, p->text_len, f) == p->text_len;
	ok = (fclose(f) == 0) && ok;
	if (ok && rename(tmp, path) == 0)
		return 0;
	unlink(tmp);
out_err:
	fprintf(stderr, "galil-load: cannot write '%s': %s\n", path,
		strerror(errno));
	return -1;
}

static void print_sizes(const struct gload_prog *p,
			const struct gload_stats *st, const struct opts *o)
{
	int files = p->nfiles - (p->seal ? 1 : 0); /* the seal is no file */

	printf("source: %d file%s%s, %ld lines, %zu bytes\n", files,
	       files == 1 ? "" : "s", p->seal ? " and the seal" : "",
	       p->src_lines, p->src_bytes);
	printf("program: %d lines, %zu bytes with the identity line '%s'\n",
	       st->lines, p->text_len, p->stamp);
	printf("check: ok (%s%s: %d/%d lines, %d/%d labels, %d/%d "
	       "variables)\n",
	       o->model->title,
	       o->model->confirmed ? "" : ", unconfirmed limits", st->lines,
	       o->model->max_lines, st->labels, o->model->max_labels, st->vars,
	       o->model->max_vars);
}

/* The seal the manifest asks for, from --config or the configuration found
 * where roboelf looks for it. Return 0 or an exit code. */
static int seal(const struct opts *o, struct gload_prog *p, int quiet)
{
	static char found[PATH_MAX + 1];
	char err[RE_CONFIG_ERR_MAX];
	const char *cfg = o->config;
	int n = 0, rc;

	if (!cfg && gload_seal_find_config(found, sizeof(found)) < 0) {
		fprintf(stderr,
			"galil-load: %s: the program is sealed with the "
			"robot's configuration, and there is none here "
			"(./config/roboelf.yaml) nor at %s: give it with "
			"--config FILE\n",
			p->seal_where, found);
		return GLOAD_EXIT_USAGE;
	}
	if (!cfg)
		cfg = found;
	rc = gload_seal_append(p, cfg, &n, err, sizeof(err));
	if (rc != GL_OK) {
		fprintf(stderr,
			"galil-load: cannot seal the program with "
			"'%s': %s\n",
			cfg, err);
		return rc == GL_ERR_CONFIG || rc == GL_ERR_SYS
			   ? GLOAD_EXIT_USAGE
			   : GLOAD_EXIT_CHECK;
	}
	if (!quiet)
		printf("sealed: %d values from %s\n", n, cfg);
	return 0;
}

/* --version: the release, the interface, and the identity a download of
 * the programs (the files given, --dmc, or the default) is stamped with. */
static int print_version(const struct opts *o)
{
	struct gload_prog p = {0};
	struct gload_diags d = {0};
	struct gload_stats st;
	int i, ok = 1;

	printf("galil-load %s (controller program interface %s, "
	       "dmc/constants.dmc vers)\n",
	       ROBOELF_VERSION, ROBOELF_DMC_VERSION);
	if (o->npaths == 0) {
		printf("DMC programs: none (neither dmc/MANIFEST here nor "
		       "%s/MANIFEST)\n",
		       o->dmc_dir);
		return 0;
	}
	for (i = 0; i < o->npaths; i++)
		if (gload_prep_path(&p, o->paths[i], &d) != GL_OK)
			ok = 0;
	if (ok && p.seal && seal(o, &p, 1) != 0)
		ok = 0;
	if (ok && (gload_check(&p, o->model, &d, &st) != 0 || d.n > 0 ||
		   gload_prog_finish(&p) != GL_OK))
		ok = 0;
	if (ok)
		printf("DMC programs: %s%s, identity '%s'\n", o->paths[0],
		       o->npaths > 1 ? " ..." : "", p.stamp);
	else
		printf("DMC programs: %s%s: do not pass the check (run "
		       "galil-load --check)\n",
		       o->paths[0], o->npaths > 1 ? " ..." : "");
	gload_diags_free(&d);
	gload_prog_free(&p);
	return 0;
}

/* Read, preprocess, check and stamp. Return 0 or an exit code. */
static int prepare(const struct opts *o, struct gload_prog *p)
{
	struct gload_diags d = {0};
	struct gload_stats st;
	int i, rc = 0, n;

	for (i = 0; i < o->npaths; i++)
		if (gload_prep_path(p, o->paths[i], &d) != GL_OK)
			rc = GLOAD_EXIT_CHECK;
	if (rc == 0 && p->seal)
		rc = seal(o, p, 0);
	if (rc == 0) {
		n = gload_check(p, o->model, &d, &st);
		if (n != 0 || d.n > 0)
			rc = GLOAD_EXIT_CHECK;
	}
	if (rc == 0 && gload_prog_finish(p) != GL_OK)
		rc = GLOAD_EXIT_CHECK;
	print_diags(&d);
	if (rc)
		fprintf(stderr,
			"galil-load: check failed (%d problem%s); "
			"nothing was sent to the controller\n",
			d.n, d.n == 1 ? "" : "s");
	gload_diags_free(&d);
	if (rc == 0 && o->start && !gload_prog_has_label(p, o->start_label)) {
		fprintf(stderr,
			"galil-load: --start: the program has no "
			"label '#%s'\n",
			o->start_label);
		rc = GLOAD_EXIT_USAGE;
	}
	if (rc == 0)
		print_sizes(p, &st, o);
	if (rc == 0 && o->output && write_output(o->output, p))
		rc = GLOAD_EXIT_CHECK;
	return rc;
}

/* The timeout of DL, UL and BP: at least GLOAD_SLOW_TIMEOUT_MS. */
static int slow_ms(const struct opts *o)
{
	return o->timeout_ms > GLOAD_SLOW_TIMEOUT_MS ? o->timeout_ms
						     : GLOAD_SLOW_TIMEOUT_MS;
}

/* Say why a link call failed; return the exit code. */
static int link_failed(gl_link *l, const char *what, int rc, int timeout_ms)
{
	int code = 0;

	if (rc == GL_ERR_CTRL) {
		const char *text = gl_link_ctrl_error(l, &code);

		fprintf(stderr, "galil-load: controller rejected %s: %d %s\n",
			what, code, text);
	} else if (rc == GL_ERR_TIMEOUT) {
		fprintf(stderr, "galil-load: no reply to %s within %d ms\n",
			what, timeout_ms);
	} else {
		fprintf(stderr, "galil-load: %s failed: %s\n", what,
			gl_strerror(rc));
	}
	return gload_exit_for(rc);
}

static int open_link(const struct opts *o, gl_link **l)
{
	char err[GL_ERRTEXT_LEN] = "";
	int rc = gl_link_open(l, o->addr, o->timeout_ms, err);

	if (rc != GL_OK) {
		fprintf(stderr, "galil-load: %s\n",
			err[0] ? err : gl_strerror(rc));
		*l = NULL;
		return GLOAD_EXIT_CONN;
	}
	return 0;
}

/* Probe the network; print what answered to @f. Return the number found
 * (>= 0) or -1 (the message is printed). */
static int find(const struct opts *o, struct gl_disc_ctrl *list, FILE *f)
{
	char err[GL_ERRTEXT_LEN] = "";
	int i, ms = o->find && o->timeout_set ? o->timeout_ms : FIND_MS;
	int n = gl_disc_probe(o->find_addr, (unsigned)o->find_port, ms, list,
			      FIND_MAX, err);

	if (n < 0) {
		fprintf(stderr, "galil-load: %s\n",
			err[0] ? err : gl_strerror(n));
		return -1;
	}
	if (n == 0)
		fprintf(stderr,
			"galil-load: no Galil controller answered the "
			"discovery probe (UDP %s:%d) within %d ms\n",
			o->find_addr, o->find_port, ms);
	for (i = 0; i < n; i++)
		fprintf(f, "%3d  %-15s  %s Rev %s\n", i + 1, list[i].addr,
			list[i].model, list[i].rev);
	return n;
}

/* -a did not answer: list the controllers that do and, on a terminal, let
 * the technician pick one (never chosen silently). Return 0 with *@l open,
 * or GLOAD_EXIT_CONN. */
static int offer_found(struct opts *o, gl_link **l)
{
	static struct gl_disc_ctrl list[FIND_MAX];
	static char chosen[sizeof(list[0].addr)];
	char line[32];
	int n, k;

	fprintf(stderr, "galil-load: Galil controllers that answer on this "
			"network:\n");
	n = find(o, list, stderr);
	if (n <= 0 || !isatty(STDIN_FILENO))
		return GLOAD_EXIT_CONN;
	fprintf(stderr, "connect to which one (1-%d, Enter: none)? ", n);
	if (!fgets(line, sizeof(line), stdin) ||
	    parse_int(strtok(line, "\n") ? line : "", 1, n, &k))
		return GLOAD_EXIT_CONN;
	snprintf(chosen, sizeof(chosen), "%s", list[k - 1].addr);
	o->addr = chosen;
	printf("connecting to %s (chosen from the list)\n", chosen);
	return open_link(o, l);
}

/* gload_dl_halt() with the controller's own number of axes. */
static int halt(gl_link *l, const struct opts *o, int *running,
		char failed[GLOAD_CMD_LEN])
{
	int axes = gl_link_axes(l);

	if (axes < 0)
		axes = 8; /* no QZ answer: every axis letter the family has */
	return gload_dl_halt(l, o->model->threads, axes, o->stop_ms, running,
			     failed, o->timeout_ms);
}

/* Leave the controller halted and empty after a failed download. */
static void erase_after_failure(gl_link **l, const struct opts *o)
{
	int rc = *l ? gload_dl_erase(*l, o->timeout_ms) : GL_ERR_CLOSED;
	char failed[GLOAD_CMD_LEN];
	int running;

	if (rc != GL_OK && rc != GL_ERR_MISMATCH) {
		gl_link_close(*l);
		*l = NULL;
		if (open_link(o, l) == 0) {
			rc = halt(*l, o, &running, failed);
			if (rc == GL_OK)
				rc = gload_dl_erase(*l, o->timeout_ms);
		}
	}
	if (rc == GL_OK)
		fprintf(stderr, "galil-load: the controller is halted and its "
				"program erased\n");
	else
		fprintf(stderr,
			"galil-load: could not erase the controller "
			"(%s): it may hold a partial program; do not start "
			"it; run galil-load again\n",
			gl_strerror(rc));
}

static void print_bad_line(const struct gload_prog *p, int bad)
{
	if (bad >= 1 && bad <= p->nlines) {
		const struct gload_line *ln = &p->lines[bad - 1];

		fprintf(stderr,
			"%s:%d: the controller rejected program line "
			"%d '%s' or a line before it\n",
			p->files[ln->file], ln->src_line, bad, ln->text);
	} else if (bad == p->nlines + 1) {
		fprintf(stderr,
			"galil-load: the controller rejected the "
			"identity line %d '%s' or a line before it\n",
			bad, p->stamp);
	} else {
		fprintf(stderr, "galil-load: the controller did not say which "
				"line it rejected\n");
	}
}

/* Download and read back. Return 0 or an exit code (controller erased). */
static int download(gl_link **l, const struct opts *o,
		    const struct gload_prog *p, char *ul)
{
	int rc, bad = 0, line = 0;

	printf("downloading %d lines to %s\n", p->nlines + 1, o->addr);
	rc = gload_dl_download(*l, p->text, p->text_len, &bad, o->timeout_ms);
	if (rc != GL_OK) {
		int ex = link_failed(*l, "the download (DL)", rc, slow_ms(o));

		if (rc == GL_ERR_CTRL)
			print_bad_line(p, bad);
		erase_after_failure(l, o);
		return ex;
	}
	rc = gload_dl_upload(*l, ul, GLOAD_UPLOAD_CAP, o->timeout_ms);
	if (rc >= 0)
		rc = gload_dl_compare(p->text, p->text_len, ul, (size_t)rc,
				      &line);
	if (rc == GL_ERR_MISMATCH)
		fprintf(stderr,
			"galil-load: verify failed: the program read "
			"back (UL) differs at line %d\n",
			line);
	else if (rc != GL_OK)
		link_failed(*l, "the read-back (UL)", rc, slow_ms(o));
	if (rc != GL_OK) {
		erase_after_failure(l, o);
		return rc == GL_ERR_MISMATCH ? GLOAD_EXIT_CTRL
					     : gload_exit_for(rc);
	}
	printf("verified: the read-back matches, identity %016llX\n",
	       (unsigned long long)p->id);
	return 0;
}

/* 1 when the controller already holds exactly this program. */
static int same_program(gl_link *l, const struct opts *o,
			const struct gload_prog *p, char *ul, int *ex)
{
	int rc, line;

	*ex = 0;
	rc = gload_dl_upload(l, ul, GLOAD_UPLOAD_CAP, o->timeout_ms);
	if (rc == GL_ERR_CTRL || rc == GL_ERR_OVERFLOW)
		return 0;
	if (rc < 0) {
		*ex = link_failed(l, "the upload (UL)", rc, slow_ms(o));
		return 0;
	}
	return gload_dl_compare(p->text, p->text_len, ul, (size_t)rc, &line) ==
	       GL_OK;
}

/* A supervisor driving the robot is not interrupted without --force. */
static int busy(gl_link *l, const struct opts *o)
{
	int state, rc = gload_dl_busy(l, BUSY_WATCH_MS, &state, o->timeout_ms);

	if (rc < 0)
		return link_failed(l, "the busy check", rc, o->timeout_ms);
	if (rc == 0)
		return 0;
	if (!o->force) {
		fprintf(stderr,
			"galil-load: the controller's program is %s and its "
			"supervisor's heartbeat is advancing: roboelf is "
			"driving the robot. Loading halts the program: every "
			"axis stops, every motor is switched off and roboelf "
			"latches a fault. Quit roboelf first, or give --force "
			"to do exactly that\n",
			state == 1 ? "armed" : "in its service state");
		return GLOAD_EXIT_BUSY;
	}
	printf("warning: --force: halting a program that roboelf drives "
	       "(%s): the axes stop, the motors go off, roboelf latches a "
	       "fault\n",
	       state == 1 ? "armed" : "service state");
	return 0;
}

static int identify_and_halt(gl_link *l, const struct opts *o)
{
	char model[128] = "", failed[GLOAD_CMD_LEN], what[GLOAD_CMD_LEN + 16];
	long serial = 0;
	int rc, running = -1;

	rc = gl_link_identify(l, model, sizeof(model), &serial);
	if (rc == GL_OK)
		printf("controller: %s, serial %ld\n", model, serial);
	else if (rc != GL_ERR_CTRL)
		return link_failed(l, "identification (^R^V, MG _BN)", rc,
				   o->timeout_ms);
	rc = busy(l, o);
	if (rc)
		return rc;
	rc = halt(l, o, &running, failed);
	if (rc == GL_ERR_MISMATCH && running == GLOAD_HALT_LATE) {
		fprintf(stderr,
			"galil-load: axis %c still moving %d ms after 'ST': "
			"aborted it (AB 1) and switched the motors off; "
			"nothing downloaded (see --stop-wait)\n",
			failed[6], o->stop_ms);
		return GLOAD_EXIT_CTRL;
	}
	if (rc == GL_ERR_TIMEOUT && !strncmp(failed, "MG _BG", 6)) {
		fprintf(stderr,
			"galil-load: axis %c still moving after 'ST' and "
			"'AB 1'; motors left on; nothing downloaded\n",
			failed[6]);
		return GLOAD_EXIT_CTRL;
	}
	if (rc == GL_ERR_MISMATCH && running < 0) {
		fprintf(stderr,
			"galil-load: a motor is still on after 'MO' "
			"('%s')\n",
			failed);
		return GLOAD_EXIT_CTRL;
	}
	if (rc == GL_ERR_MISMATCH) {
		fprintf(stderr,
			"galil-load: thread %d still runs after "
			"HX%d\n",
			running, running);
		return GLOAD_EXIT_CTRL;
	}
	snprintf(what, sizeof(what), "'%s'", failed);
	if (rc != GL_OK)
		return link_failed(l, what, rc, o->timeout_ms);
	printf("halted: threads stopped, axes stopped, motors off\n");
	return 0;
}

static int burn_and_start(gl_link *l, const struct opts *o)
{
	double xq0 = -1;
	char what[64];
	int rc;

	if (o->burn) {
		rc = gload_dl_burn(l, o->timeout_ms);
		if (rc != GL_OK)
			return link_failed(l, "the burn (BP)", rc, slow_ms(o));
		printf("burned: #AUTO runs at power-up\n");
	}
	if (!o->start)
		return 0;
	snprintf(what, sizeof(what), "'XQ #%s,0'", o->start_label);
	rc = gload_dl_start(l, o->start_label, &xq0, o->timeout_ms);
	if (rc == GL_ERR_MISMATCH) {
		fprintf(stderr,
			"galil-load: thread 0 is not running after "
			"%s (_XQ0 = -1)\n",
			what);
		return GLOAD_EXIT_CTRL;
	}
	if (rc != GL_OK)
		return link_failed(l, what, rc, o->timeout_ms);
	printf("started: #%s in thread 0 (at line %.0f)\n", o->start_label,
	       xq0);
	return 0;
}

static int load(gl_link **l, const struct opts *o, const struct gload_prog *p)
{
	char *ul = malloc(GLOAD_UPLOAD_CAP);
	int ex, same;

	if (!ul) {
		fprintf(stderr, "galil-load: out of memory\n");
		return GLOAD_EXIT_CONN;
	}
	ex = identify_and_halt(*l, o);
	if (ex)
		goto out_free;
	same = !o->force && same_program(*l, o, p, ul, &ex);
	if (ex)
		goto out_free;
	if (same)
		printf("unchanged: the controller already holds this program "
		       "(identity %016llX); not downloaded\n",
		       (unsigned long long)p->id);
	else
		ex = download(l, o, p, ul);
	if (!ex)
		ex = burn_and_start(*l, o);
out_free:
	free(ul);
	return ex;
}

/* The reply as text lines; nothing for a command that returns no data. */
static void print_reply(const char *s)
{
	if (!*s)
		return;
	for (; *s; s++)
		if (*s != '\r')
			putchar(*s);
	putchar('\n');
}

/* The RoboELF program's state: 1 armed or 3 service while it runs, else
 * -1 (no program, halted, or not ours: no "state" variable). */
static int running_state(gl_link *l, const struct opts *o)
{
	char resp[64];
	double v;
	int rc =
	    gl_link_command(l, "MG _XQ0", resp, sizeof(resp), o->timeout_ms);

	if (rc < 0 || !gl_parse_double(resp, (size_t)rc, NULL, &v) || v < 0)
		return -1;
	rc = gl_link_command(l, "MG state", resp, sizeof(resp), o->timeout_ms);
	if (rc < 0 || !gl_parse_double(resp, (size_t)rc, NULL, &v))
		return -1;
	return v == 1 || v == 3 ? (int)v : -1;
}

/* A command that writes, on a program in service or armed: refused
 * without --force (a write may change how the robot moves or is stopped;
 * docs/safety.md H12); reads (MG, TP, "KP ?,?", "name=") pass. */
static int check_write(gl_link *l, const struct opts *o, const char *c)
{
	char sh[2 * GL_LINE_MAX + 8];
	int st;

	if (dmc_cmd_line_is_read(c) || (st = running_state(l, o)) < 0)
		return 0;
	if (!o->force) {
		fprintf(stderr,
			"galil-load: '%s' writes to the controller, and its "
			"program is %s: a write could change how the robot "
			"moves or is stopped. Refused (reads such as MG, TP "
			"and 'KP ?,?' are allowed); quit roboelf first, or "
			"give --force to send it anyway (the program latches "
			"a fault if it changes a sealed value)\n",
			shown(c, sh),
			st == 1 ? "armed" : "in its service state");
		return GLOAD_EXIT_BUSY;
	}
	printf("warning: --force: sending '%s' to a program that is %s: if "
	       "it changes a sealed value, the program stops the robot and "
	       "latches fault 17, and roboelf cuts motor power\n",
	       shown(c, sh), st == 1 ? "armed" : "in its service state");
	return 0;
}

static int run_commands(gl_link *l, const struct opts *o)
{
	static char resp[64 * 1024];
	char what[2 * GL_LINE_MAX + 16], sh[2 * GL_LINE_MAX + 8];
	int i, rc, tmo;

	for (i = 0; i < o->ncmds; i++) {
		const char *c = o->cmds[i];

		/* burns and BZ pause the controller [galil-notes 1.6] */
		tmo = (c[0] == 'B' && c[1] && strchr("PNVZ", c[1]))
			  ? GLOAD_SLOW_TIMEOUT_MS
			  : o->timeout_ms;
		if (tmo < o->timeout_ms)
			tmo = o->timeout_ms;
		if ((rc = check_write(l, o, c)) != 0)
			return rc;
		if (gl_link_ctrl_kind(c) > GL_CTRL_NONE)
			rc =
			    gl_link_ctrl_request(l, c, resp, sizeof(resp), tmo);
		else
			rc = gl_link_command(l, c, resp, sizeof(resp), tmo);
		snprintf(what, sizeof(what), "'%s'", shown(c, sh));
		if (rc < 0)
			return link_failed(l, what, rc, tmo);
		print_reply(resp);
	}
	return 0;
}

int main(int argc, char **argv)
{
	struct gload_prog p = {0};
	struct opts o;
	gl_link *l = NULL;
	int ex;

	setvbuf(stdout, NULL, _IOLBF, 0);
	ex = parse_args(argc, argv, &o);
	if (ex == -1) {
		fputs(usage_text, stdout);
		return 0;
	}
	if (ex)
		return ex;
	if (base_paths_root())
		fprintf(stderr,
			"galil-load: %s=%s: the installed files are looked "
			"for under it\n",
			BASE_PATHS_ROOT_ENV, base_paths_root());
	if (o.version)
		return print_version(&o);
	if (o.dmc_default)
		printf("DMC programs: %s (no files given)\n", o.dmc_dir);
	if (o.npaths > 0)
		ex = prepare(&o, &p);
	if (ex || o.check_only)
		goto out_free;
	fflush(stdout);
	if (o.find) {
		static struct gl_disc_ctrl list[FIND_MAX];

		ex = find(&o, list, stdout) > 0 ? 0 : GLOAD_EXIT_CONN;
		goto out_free;
	}
	ex = open_link(&o, &l);
	if (ex)
		ex = offer_found(&o, &l);
	if (!ex && o.npaths > 0)
		ex = load(&l, &o, &p);
	if (!ex && l)
		ex = run_commands(l, &o);
	gl_link_close(l);
out_free:
	gload_prog_free(&p);
	return ex;
}
