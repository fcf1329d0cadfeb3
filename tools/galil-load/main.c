/*
 * galil-load - check, preprocess, download, verify, burn and start DMC
 * programs on a Galil controller; send diagnostic commands.
 *
 *   galil-load [-a HOST[:PORT]] [options] FILE.dmc...|DIR
 *
 * See docs/galil-load.1 and docs/galil-load.md. Every step that touches the
 * controller comes after the offline check has passed; a failed download or
 * read-back leaves the controller halted and empty. The controller's
 * program is read (UL) and compared before anything is halted, so that a
 * load of the program it already holds, and --verify, stop nothing.
 */
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base_paths.h"
#include "base_version.h"
#include "gl_disc.h"
#include "gl_err.h"
#include "gl_ident.h"
#include "gl_link.h"
#include "gload_check.h"
#include "gload_cmd.h"
#include "gload_dl.h"
#include "gload_opts.h"
#include "gload_prep.h"
#include "gload_seal.h"
#include "re_config.h"

#define BUSY_WATCH_MS 250  /* a supervisor's heartbeat changes within */
#define FIND_MS	      1000 /* discovery window (GAddresses: about 1 s) */
#define FIND_MAX      32

static const char usage_text[] =
    "usage: galil-load [-a HOST[:PORT]] [options] FILE.dmc...|DIR\n"
    "       galil-load [-a HOST[:PORT]] [options]   (the DMC programs in\n"
    "                  ./dmc, else the installed ones)\n"
    "\n"
    "  -a, --address HOST[:PORT]  controller (default port 23)\n"
    "      --check                check and preprocess only; no controller\n"
    "      --verify               compare the controller's program (UL)\n"
    "                             with these files; halts nothing, writes\n"
    "                             nothing (exit 6: it differs)\n"
    "  -m, --model MODEL          limits of 40x0 (default), 41x3, 21x3, 30010\n"
    "  -o, --output FILE          also write the stamped program to FILE\n"
    "  -f, --force                download even if the controller already\n"
    "                             holds the same program (without -f that\n"
    "                             program is left running), and even while\n"
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
    "4 controller rejected or verify failed, 5 roboelf drives the robot\n"
    "(no --force), 6 --verify: the controller holds another program.\n";

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

static const struct option long_opts[] = {
    {"address", required_argument, NULL, 'a'},
    {"check", no_argument, NULL, GLOAD_OPT_CHECK},
    {"model", required_argument, NULL, 'm'},
    {"output", required_argument, NULL, 'o'},
    {"force", no_argument, NULL, 'f'},
    {"burn", no_argument, NULL, GLOAD_OPT_BURN},
    {"start", optional_argument, NULL, GLOAD_OPT_START},
    {"no-start", no_argument, NULL, GLOAD_OPT_NO_START},
    {"command", required_argument, NULL, 'c'},
    {"timeout", required_argument, NULL, 't'},
    {"stop-wait", required_argument, NULL, GLOAD_OPT_STOP_WAIT},
    {"find", no_argument, NULL, GLOAD_OPT_FIND},
    {"find-addr", required_argument, NULL, GLOAD_OPT_FIND_ADDR},
    {"find-port", required_argument, NULL, GLOAD_OPT_FIND_PORT},
    {"help", no_argument, NULL, 'h'},
    {"version", no_argument, NULL, GLOAD_OPT_VERSION},
    {"dmc", required_argument, NULL, GLOAD_OPT_DMC},
    {"config", required_argument, NULL, GLOAD_OPT_CONFIG},
    {"verify", no_argument, NULL, GLOAD_OPT_VERIFY},
    {NULL, 0, NULL, 0},
};

/* Return 0 to go on, -1 for --help, or an exit code. */
static int parse_args(int argc, char **argv, struct gload_opts *o)
{
	int ch, rc;

	gload_opts_init(o);
	opterr = 0;
	while ((ch = getopt_long(argc, argv, ":a:m:o:fc:t:h", long_opts,
				 NULL)) != -1) {
		if (ch == '?' || ch == ':')
			return usage_error("invalid or incomplete option '%s'",
					   argv[optind - 1]);
		rc = gload_opts_set(o, ch, optarg, usage_error);
		if (rc)
			return rc;
	}
	return gload_opts_finish(o, argv + optind, argc - optind, usage_error);
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
			const struct gload_stats *st,
			const struct gload_opts *o)
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
static int seal(const struct gload_opts *o, struct gload_prog *p, int quiet)
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
static int print_version(const struct gload_opts *o)
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
static int prepare(const struct gload_opts *o, struct gload_prog *p)
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
static int slow_ms(const struct gload_opts *o)
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

static int open_link(const struct gload_opts *o, gl_link **l)
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
static int find(const struct gload_opts *o, struct gl_disc_ctrl *list, FILE *f)
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
static int offer_found(struct gload_opts *o, gl_link **l)
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
	    gload_opts_int(strtok(line, "\n") ? line : "", 1, n, &k))
		return GLOAD_EXIT_CONN;
	snprintf(chosen, sizeof(chosen), "%s", list[k - 1].addr);
	o->addr = chosen;
	printf("connecting to %s (chosen from the list)\n", chosen);
	return open_link(o, l);
}

/* gload_dl_halt() with the controller's own number of axes. */
static int halt(gl_link *l, const struct gload_opts *o, int *running,
		char failed[GLOAD_CMD_LEN])
{
	int axes = gl_link_axes(l);

	if (axes < 0)
		axes = 8; /* no QZ answer: every axis letter the family has */
	return gload_dl_halt(l, o->model->threads, axes, o->stop_ms, running,
			     failed, o->timeout_ms);
}

/* Leave the controller halted and empty after a failed download. */
static void erase_after_failure(gl_link **l, const struct gload_opts *o)
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
static int download(gl_link **l, const struct gload_opts *o,
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

/*
 * Read the controller's program (UL, which only reads: nothing is halted
 * first) into @ul and compare it with @p. *@line: the first differing
 * line, 0 when they are equal or the UL was refused. Return 1 the same,
 * 0 different (a refused or too long UL is never taken as the same), or
 * an exit code > 1 with the message printed (the link failed). The
 * refused UL comes back in *@refused so that --verify can say so.
 */
static int held_program(gl_link *l, const struct gload_opts *o,
			const struct gload_prog *p, char *ul, int *line,
			int *refused)
{
	int rc;

	*line = 0;
	*refused = 0;
	rc = gload_dl_upload(l, ul, GLOAD_UPLOAD_CAP, o->timeout_ms);
	if (rc == GL_ERR_CTRL || rc == GL_ERR_OVERFLOW) {
		*refused = rc;
		return 0;
	}
	if (rc < 0)
		return link_failed(l, "the upload (UL)", rc, slow_ms(o));
	rc = gload_dl_compare(p->text, p->text_len, ul, (size_t)rc, line);
	if (rc == GL_ERR_NOMEM) {
		fprintf(stderr, "galil-load: out of memory\n");
		return GLOAD_EXIT_CONN;
	}
	return rc == GL_OK;
}

/* Whether a supervisor drives the robot: 1 (*state: 1 armed, 2 service),
 * 0, or -1 with *ex the exit code of a failed check (already printed). */
static int driven(gl_link *l, const struct gload_opts *o, int *state,
		  int *ex)
{
	int rc = gload_dl_busy(l, BUSY_WATCH_MS, state, o->timeout_ms);

	if (rc < 0) {
		*ex = link_failed(l, "the busy check", rc, o->timeout_ms);
		return -1;
	}
	return rc != 0;
}

/* A supervisor driving the robot is not interrupted without --force. */
static int busy(gl_link *l, const struct gload_opts *o)
{
	int state, ex, d = driven(l, o, &state, &ex);

	if (d <= 0)
		return d < 0 ? ex : 0;
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

/* Print the controller's model and serial; a controller that refuses the
 * question (GL_ERR_CTRL) is not identified but still served. Return 0 or
 * an exit code. */
static int identify(gl_link *l, const struct gload_opts *o)
{
	char model[128] = "";
	long serial = 0;
	int rc = gl_link_identify(l, model, sizeof(model), &serial);

	if (rc == GL_OK)
		printf("controller: %s, serial %ld\n", model, serial);
	else if (rc != GL_ERR_CTRL)
		return link_failed(l, "identification (^R^V, MG _BN)", rc,
				   o->timeout_ms);
	return 0;
}

/* The halt: everything a write needs first (the busy check came before
 * the program was read). */
static int check_and_halt(gl_link *l, const struct gload_opts *o)
{
	char failed[GLOAD_CMD_LEN], what[GLOAD_CMD_LEN + 16];
	int rc, running = -1;

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

static int burn_and_start(gl_link *l, const struct gload_opts *o)
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

/*
 * The controller already holds @p: may it be left as it is? Yes without
 * --burn and --start, and with --start alone when thread 0 already runs
 * (the program the technician asked for is running). --burn needs a
 * halted program (BP is refused while one runs, TC 17), and starting a
 * thread that does not run means halting the others first, as a load
 * does. Return 1 (left as it is, said so), 0 (halt), or an exit code > 1.
 */
static int leave_running(gl_link *l, const struct gload_opts *o,
			 const struct gload_prog *p)
{
	double xq0 = -1;
	int rc;

	printf("unchanged: the controller already holds this program "
	       "(identity %016llX); not downloaded\n",
	       (unsigned long long)p->id);
	if (o->burn)
		return 0;
	if (o->start) {
		rc = gload_query_number(l, "MG _XQ0", &xq0, o->timeout_ms);
		if (rc != GL_OK)
			return link_failed(l, "'MG _XQ0'", rc, o->timeout_ms);
		if (xq0 < 0)
			return 0;
		printf("running: thread 0 already runs it (at line %.0f); "
		       "not restarted (--force halts, reloads and "
		       "restarts it)\n",
		       xq0);
	}
	printf("left running: nothing halted, nothing written\n");
	return 1;
}

/* The busy check first: a supervisor driving the robot is not disturbed
 * without --force, not even by the upload (a whole program read through
 * the controller's command interpreter would delay its cycle). Then
 * compare (UL only reads); halt and download only when the program
 * differs or with --force, so that loading the program the controller
 * already runs stops nothing. */
static int load(gl_link **l, const struct gload_opts *o,
		const struct gload_prog *p)
{
	char *ul = malloc(GLOAD_UPLOAD_CAP);
	int ex, same = 0, line, refused;

	if (!ul) {
		fprintf(stderr, "galil-load: out of memory\n");
		return GLOAD_EXIT_CONN;
	}
	ex = identify(*l, o);
	if (!ex)
		ex = busy(*l, o);
	if (!ex && !o->force) {
		same = held_program(*l, o, p, ul, &line, &refused);
		ex = same > 1 ? same : 0;
	}
	if (!ex && same) {
		ex = leave_running(*l, o, p);
		if (ex == 1) {
			ex = 0;
			goto out_free;
		}
	}
	if (!ex)
		ex = check_and_halt(*l, o);
	if (!ex && !same)
		ex = download(l, o, p, ul);
	if (!ex)
		ex = burn_and_start(*l, o);
out_free:
	free(ul);
	return ex;
}

/* --verify found a difference at @line (0: not known): say where, with the
 * file line when it is one of ours, and what the controller holds. */
static void print_difference(const struct gload_prog *p, const char *ul,
			     size_t ul_len, int line)
{
	uint64_t held = 0;
	int rc = gl_ident_verify(ul, ul_len, &held);

	if (ul_len == 0)
		fprintf(stderr, "galil-load: the controller holds no "
				"program\n");
	else if (rc == GL_OK)
		fprintf(stderr,
			"galil-load: the controller holds identity %016llX\n",
			(unsigned long long)held);
	else
		fprintf(stderr, "galil-load: the controller's program has no "
				"valid galil-load stamp\n");
	if (ul_len == 0)
		return;
	if (line >= 1 && line <= p->nlines)
		fprintf(stderr,
			"%s:%d: first difference: program line %d "
			"'%s'\n",
			p->files[p->lines[line - 1].file],
			p->lines[line - 1].src_line, line,
			p->lines[line - 1].text);
	else if (line == p->nlines + 1)
		fprintf(stderr,
			"galil-load: first difference: the identity "
			"line %d '%s'\n",
			line, p->stamp);
	else
		fprintf(stderr,
			"galil-load: first difference: line %d, after "
			"the end of these files\n",
			line);
}

/* --verify on a robot that roboelf drives: refused, since the upload would
 * delay its cycle. Return 0, GLOAD_EXIT_BUSY or another exit code. */
static int verify_idle(gl_link *l, const struct gload_opts *o)
{
	int state, ex, d = driven(l, o, &state, &ex);

	if (d <= 0)
		return d < 0 ? ex : 0;
	fprintf(stderr,
		"galil-load: the controller's program is %s and its "
		"supervisor's heartbeat is advancing: roboelf is driving the "
		"robot. --verify reads the whole program (UL), which would "
		"delay roboelf's cycle; nothing was read. Verify when roboelf "
		"has quit\n",
		state == 1 ? "armed" : "in its service state");
	return GLOAD_EXIT_BUSY;
}

/* --verify: UL and compare, nothing halted, nothing written. Return 0 (the
 * same), GLOAD_EXIT_DIFFERS, or another exit code. */
static int verify(gl_link *l, const struct gload_opts *o,
		  const struct gload_prog *p)
{
	char *ul = malloc(GLOAD_UPLOAD_CAP);
	int ex, line = 0, refused = 0;

	if (!ul) {
		fprintf(stderr, "galil-load: out of memory\n");
		return GLOAD_EXIT_CONN;
	}
	ex = identify(l, o);
	if (!ex)
		ex = verify_idle(l, o);
	if (!ex)
		ex = held_program(l, o, p, ul, &line, &refused);
	if (ex == 1) {
		printf("verified: the controller holds this program, "
		       "identity %016llX\n",
		       (unsigned long long)p->id);
		ex = 0;
	} else if (ex == 0 && refused == GL_ERR_OVERFLOW) {
		fprintf(stderr,
			"galil-load: verify: the controller's program differs "
			"from these files: it is longer than any program "
			"galil-load loads; nothing was halted or written\n");
		ex = GLOAD_EXIT_DIFFERS;
	} else if (ex == 0 && refused) {
		ex = link_failed(l, "the upload (UL)", refused, slow_ms(o));
		fprintf(stderr, "galil-load: not verified: the program could "
				"not be read; nothing was halted or written\n");
	} else if (ex == 0) {
		fprintf(stderr,
			"galil-load: verify: the controller's program differs "
			"from these files (identity %016llX)\n",
			(unsigned long long)p->id);
		print_difference(p, ul, strlen(ul), line);
		fprintf(stderr, "galil-load: nothing was halted or written; to "
				"load these files run galil-load without "
				"--verify (that halts the program)\n");
		ex = GLOAD_EXIT_DIFFERS;
	}
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

/* A command that writes, on a program in service or armed: refused
 * without --force (a write may change how the robot moves or is stopped;
 * docs/safety.md H12); reads (MG, TP, "KP ?,?", "name=") pass. */
static int check_write(gl_link *l, const struct gload_opts *o, const char *c)
{
	char sh[GLOAD_SHOWN_LEN];
	int st = gload_cmd_write_state(l, c, o->timeout_ms);

	if (st < 0)
		return 0;
	if (!o->force) {
		fprintf(stderr,
			"galil-load: '%s' writes to the controller, and its "
			"program is %s: a write could change how the robot "
			"moves or is stopped. Refused (reads such as MG, TP "
			"and 'KP ?,?' are allowed); quit roboelf first, or "
			"give --force to send it anyway (the program latches "
			"a fault if it changes a sealed value)\n",
			gload_cmd_shown(c, sh),
			st == 1 ? "armed" : "in its service state");
		return GLOAD_EXIT_BUSY;
	}
	printf("warning: --force: sending '%s' to a program that is %s: if "
	       "it changes a sealed value, the program stops the robot and "
	       "latches fault 17, and roboelf cuts motor power\n",
	       gload_cmd_shown(c, sh),
	       st == 1 ? "armed" : "in its service state");
	return 0;
}

static int run_commands(gl_link *l, const struct gload_opts *o)
{
	static char resp[64 * 1024];
	char what[2 * GL_LINE_MAX + 16], sh[GLOAD_SHOWN_LEN];
	int i, rc, tmo;

	for (i = 0; i < o->ncmds; i++) {
		const char *c = o->cmds[i];

		tmo = gload_cmd_timeout(c, o->timeout_ms);
		if ((rc = check_write(l, o, c)) != 0)
			return rc;
		rc = gload_cmd_send(l, c, resp, sizeof(resp), tmo);
		snprintf(what, sizeof(what), "'%s'", gload_cmd_shown(c, sh));
		if (rc < 0)
			return link_failed(l, what, rc, tmo);
		print_reply(resp);
	}
	return 0;
}

int main(int argc, char **argv)
{
	struct gload_prog p = {0};
	struct gload_opts o;
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
	if (!ex && o.verify)
		ex = verify(l, &o, &p);
	else if (!ex && o.npaths > 0)
		ex = load(&l, &o, &p);
	if (!ex && l)
		ex = run_commands(l, &o);
	gl_link_close(l);
out_free:
	gload_prog_free(&p);
	return ex;
}
