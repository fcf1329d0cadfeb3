/*
 * re_app.c - the shell roboelf and roboelf-tech share. See re_app.h.
 */
#include "re_app.h"

#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base_clock.h"
#include "base_paths.h"
#include "base_version.h"
#include "gl_err.h"
#include "gl_link.h"

static void on_signal(int sig)
{
	re_sig.quit = sig;
}

/* SIGUSR1: write a trace of the flight recorder now. */
static void on_usr1(int sig)
{
	(void)sig;
	re_sig.trace_asked = 1;
}

/* A stop (SIGSTOP, a debugger) during start-up: the cycle measures its own
 * gaps, but start-up is a sequence of waits and commands. SIGCONT says
 * the process was stopped; the stop lasted from the last moment it is
 * known to have run (a link call's start or end) to the SIGCONT. */
static void on_cont(int sig)
{
	int64_t now, from;

	(void)sig;
	now = base_now_ns();
	from = re_sig.cont_real ? re_sig.cont_real->last_run_ns : now;
	re_sig.cont_stop_ms = (now - from) / 1000000;
	re_sig.continued = 1;
}

/* Every signal a terminal or a person can send ends in the orderly
 * shutdown (the safe state), never in a kill or a freeze with power on:
 * Ctrl-C, Ctrl-\, SIGTERM and a lost terminal (SIGHUP) quit; Ctrl-Z and
 * background terminal I/O are ignored; a closed pipe is an error return. */
void re_app_signals(void)
{
	static const int quit[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
	static const int ignore[] = {SIGPIPE, SIGTSTP, SIGTTIN, SIGTTOU};
	struct sigaction sa;

	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal;
	sigemptyset(&sa.sa_mask);
	for (size_t i = 0; i < sizeof(quit) / sizeof(quit[0]); i++)
		sigaction(quit[i], &sa, NULL);
	sa.sa_handler = on_cont;
	sa.sa_flags = SA_RESTART;
	sigaction(SIGCONT, &sa, NULL);
	sa.sa_handler = on_usr1;
	sigaction(SIGUSR1, &sa, NULL);
	sa.sa_flags = 0;
	sa.sa_handler = SIG_IGN;
	for (size_t i = 0; i < sizeof(ignore) / sizeof(ignore[0]); i++)
		sigaction(ignore[i], &sa, NULL);
}

/* The installed configuration: SYSCONFDIR/roboelf/roboelf.yaml, under
 * ROBOELF_ROOT when that is set (base_paths.h); "" when it does not fit. */
const char *re_app_system_config(void)
{
	static char path[RE_PATH_MAX];

	if (!path[0])
		base_paths_sysconf(SYSTEM_CONFIG, path, sizeof(path));
	return path;
}

static void apply_overrides(struct app *a, const struct re_app_args *g)
{
	struct re_config *c = &a->cfg;
	char *port = c->mode == RE_MODE_CLINICAL ? c->relay.port_clinical
						 : c->relay.port_development;

	if (g->galil)
		snprintf(c->controller.address, sizeof(c->controller.address),
			 "%s", g->galil);
	if (g->relay)
		snprintf(port, RE_PATH_MAX, "%s", g->relay);
	if (g->period_ms)
		c->period_ms = g->period_ms;
	if (g->log)
		snprintf(c->log.path, sizeof(c->log.path), "%s", g->log);
}

static int check_analog(const struct re_config *c, char *err, size_t len)
{
	for (int i = 0; i < RE_AXES; i++) {
		if (c->axes[i].analog.input > RE_AXES) {
			snprintf(err, len,
				 "axis '%s': analog input %d is not "
				 "in the DMC-4030 data record (use 1..%d)",
				 c->axes[i].name, c->axes[i].analog.input,
				 RE_AXES);
			return GL_ERR_CONFIG;
		}
	}
	return GL_OK;
}

/* Without -c: ./config/roboelf.yaml (the source tree), then the
 * installed SYSCONFDIR/roboelf/roboelf.yaml; the first that exists. */
void re_app_find_config(struct re_app_args *g)
{
	if (g->config)
		return;
	g->config_searched = 1;
	g->config = access(DEFAULT_CONFIG, F_OK) == 0 ||
			    access(re_app_system_config(), F_OK) != 0
			? DEFAULT_CONFIG
			: re_app_system_config();
}

/* --version: the release, the DMC interface, and the files this roboelf
 * would use from here: its configuration and the DMC programs that go
 * with it (--dmc, else ./dmc, else the installed ones). */
int re_app_print_version(const char *prog, struct re_app_args *o)
{
	char dir[RE_PATH_MAX], manifest[RE_PATH_MAX + 16];

	printf("%s %s (controller program interface %s, "
	       "dmc/constants.dmc vers)\n",
	       prog, ROBOELF_VERSION, ROBOELF_DMC_VERSION);
	re_app_find_config(o);
	if (!o->config_searched)
		printf("configuration: %s (-c)\n", o->config);
	else if (access(o->config, F_OK) == 0)
		printf("configuration: %s\n", o->config);
	else
		printf("configuration: none (neither %s here nor %s)\n",
		       DEFAULT_CONFIG, re_app_system_config());
	if (o->dmc) {
		snprintf(manifest, sizeof(manifest), "%s/MANIFEST", o->dmc);
		printf("DMC programs: %s (--dmc%s)\n", o->dmc,
		       access(manifest, F_OK) == 0 ? ""
						   : "; it has no MANIFEST");
	} else if (base_paths_dmc_dir(dir, sizeof(dir)) == 0) {
		printf("DMC programs: %s\n", dir);
	} else {
		printf("DMC programs: none (neither dmc/MANIFEST here nor "
		       "%s/MANIFEST)\n",
		       dir);
	}
	return 0;
}

/* The log, the calibration file and the traces named in full from here
 * on: relative names resolved against the directory the program was
 * started in, once, before anything is opened (re_config_absolute()).
 * Return: 0, or -1 (said on stderr). */
static int absolute_paths(struct app *a)
{
	char cwd[PATH_MAX];

	if (!getcwd(cwd, sizeof(cwd)))
		cwd[0] = '\0'; /* only an error for a relative name */
	if (re_config_absolute(&a->cfg, cwd, a->err, sizeof(a->err)) == GL_OK)
		return 0;
	fprintf(stderr, "%s: error: %s\n", a->prog, a->err);
	return -1;
}

int re_app_load_config(struct app *a, struct re_app_args *g)
{
	re_app_find_config(g);
	if (re_config_load_file(g->config, &a->cfg, a->err, sizeof(a->err)) !=
	    GL_OK) {
		fprintf(stderr, "%s\n", a->err);
		if (errno == ENOENT && g->config_searched)
			fprintf(stderr,
				"%s: no configuration: neither '%s' (in "
				"this directory) nor '%s' exists; give one "
				"with -c FILE\n",
				a->prog, DEFAULT_CONFIG,
				re_app_system_config());
		return -1;
	}
	apply_overrides(a, g);
	if (a->cfg.mode == RE_MODE_CLINICAL && base_paths_root()) {
		fprintf(stderr,
			"%s: error: %s is set: refused in clinical mode "
			"(it is for testing a staged installation); unset it\n",
			a->prog, BASE_PATHS_ROOT_ENV);
		return -1;
	}
	if (absolute_paths(a) < 0)
		return -1;
	if (re_config_validate(&a->cfg, a->err, sizeof(a->err)) != GL_OK ||
	    check_analog(&a->cfg, a->err, sizeof(a->err)) != GL_OK) {
		fprintf(stderr, "%s: error: %s\n", a->prog, a->err);
		return -1;
	}
	for (int i = 0; i < RE_AXES; i++)
		a->names[i] = a->cfg.axes[i].name;
	return 0;
}

int re_app_open_log(struct app *a, const struct re_app_args *g)
{
	struct re_log_cfg lc = re_log_cfg_default();
	char dump[1536];
	int rc;

	/* the log, its rotations and the calibration file are shared by the
	 * operators' group (/var/log/roboelf and /var/lib/roboelf, mode
	 * 2770): group write is kept whatever the login's umask */
	umask(umask(0) & ~(mode_t)S_IWGRP);
	lc.max_bytes = (size_t)a->cfg.log.max_bytes;
	lc.keep = a->cfg.log.keep; /* 1..9, checked by the config loader */
	rc = re_log_open(&a->log, a->cfg.log.path, &lc);
	if (rc != GL_OK) {
		fprintf(stderr, "%s: error: cannot open log '%s': %s\n",
			a->prog, a->cfg.log.path,
			rc == GL_ERR_SYS ? strerror(errno) : gl_strerror(rc));
		return -1;
	}
	re_log_msg(&a->log, RE_LOG_INFO, "start: %s, config '%s'", a->prog,
		   g->config);
	re_config_dump(&a->cfg, dump, sizeof(dump));
	re_log_msg(&a->log, RE_LOG_INFO, "config: %s", dump);
	return 0;
}

/* The relay never closed: what the amplifiers say of motor power (MG
 * _TA0 bit 3, under-voltage), when the controller is ours and answers;
 * "" when not known (the relay's state says nothing of wiring that
 * bypasses it). */
static void amp_said(struct app *a, char *buf, size_t cap)
{
	double ta0;

	buf[0] = '\0';
	if (!a->real.link || !a->ctl_ours ||
	    re_io_read(&a->io, "_TA0", &ta0, a->cfg.controller.timeout_ms) !=
		GL_OK)
		return;
	if ((long)ta0 & 8)
		snprintf(buf, cap, "; the amplifiers report no motor power");
	else
		snprintf(buf, cap,
			 ", yet the amplifiers report motor power (MG _TA0 = "
			 "%ld, no under-voltage): the relay does not switch it",
			 (long)ta0);
}

/* Power-off, the reverse of power-on: the program back to its safe
 * state, every motor off and read back, then the relay off and closed.
 * What was confirmed is said, on the screen and in the log. */
void re_app_power_off(struct app *a, int latched)
{
	char what[192] = "", amp[128] = "";
	int rc = GL_OK;

	if (!a->powered)
		amp_said(a, amp, sizeof(amp));
	if (a->sup)
		rc = re_super_shutdown(a->sup, what, sizeof(what));
	else if (a->real.link && a->ctl_ours)
		rc = re_ctl_stop(&a->io, a->cfg.controller.timeout_ms);
	/* refused (busy, not identified): somebody else's, left alone */
	if (a->relay && re_relay_close(a->relay) != GL_OK)
		rc = rc ? rc : GL_ERR_RELAY;
	a->relay = a->real.relay = NULL;
	/* "DR 0": the controller stops sending (a link reopened by the
	 * fault path has no stream: nothing to close) */
	if (a->stream && a->real.link && a->ctl_ours &&
	    gl_link_stream_info(a->real.link, NULL, NULL) == 1)
		gl_link_stream_close(a->real.link,
				     a->cfg.controller.timeout_ms);
	a->stream = 0;
	gl_link_close(a->real.link);
	a->real.link = NULL;
	if (!a->powered) {
		re_console_msg(&a->con,
			       "%s: the E-stop relay was never "
			       "switched on%s; %s",
			       a->prog, amp,
			       latched ? "a fault was latched" : "bye");
		re_log_msg(&a->log, RE_LOG_INFO, "stop: relay never on%s", amp);
		return;
	}
	if (!what[0])
		snprintf(what, sizeof(what), "motors off: %s",
			 rc == GL_OK ? "confirmed" : gl_strerror(rc));
	re_console_msg(&a->con, "%s: %s%s; %s", a->prog, what,
		       rc == GL_OK ? ""
				   : " - NOT ALL CONFIRMED: press the hardware "
				     "E-stop",
		       latched ? "a fault was latched" : "bye");
	re_log_msg(&a->log, rc == GL_OK ? RE_LOG_INFO : RE_LOG_WARN,
		   "stop: %s%s", what, latched ? " (fault latched)" : "");
}

void re_app_release(struct app *a)
{
	re_lock_release(&a->lock_relay);
	re_lock_release(&a->lock_ctl);
	re_console_close(&a->con);
	re_log_close(&a->log);
	re_super_free(a->sup);
	free(a->cal);
	a->sup = NULL;
	a->cal = NULL;
}

void re_app_root_note(const char *prog)
{
	if (base_paths_root())
		fprintf(stderr,
			"%s: %s=%s: the installed files are looked for under "
			"it\n",
			prog, BASE_PATHS_ROOT_ENV, base_paths_root());
}
