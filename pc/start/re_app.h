/*
 * re_app.h - the shell the operator's program (roboelf) and the
 * technician's program (roboelf-tech) share, so that neither copies the
 * other: the signal handlers, finding and loading the configuration with
 * the command line's overrides, the log, --version, and the power-off and
 * release at the end. Messages go to stderr before the console exists and
 * to the console and the log after; each starts with the program's name
 * (struct app's @prog).
 */
#ifndef RE_APP_H
#define RE_APP_H

#include "re_start.h"

/* What both programs take from their command lines. */
struct re_app_args {
	const char *config;  /* -c, or the one found (re_app_find_config) */
	int config_searched; /* no -c: re_app_find_config() chose it */
	const char *galil;   /* --galil: the controller's address */
	const char *relay;   /* --relay: the relay's port for this mode */
	const char *log;     /* --log: the failure log */
	int period_ms;	     /* --period, 0: the configuration's */
	const char *dmc;     /* --dmc: the programs --version names */
};

/*
 * re_app_signals() - every signal a terminal or a person can send ends in
 * the orderly shutdown (re_sig.quit): Ctrl-C, Ctrl-\, SIGTERM, SIGHUP;
 * Ctrl-Z and background terminal I/O are ignored; a closed pipe is an
 * error return; SIGCONT measures a stop (re_sig.continued); SIGUSR1 asks
 * for a trace (re_sig.trace_asked).
 */
void re_app_signals(void);

/*
 * re_app_root_note() - when ROBOELF_ROOT is set, say so on stderr:
 * "PROG: ROBOELF_ROOT=DIR: the installed files are looked for under it".
 */
void re_app_root_note(const char *prog);

/*
 * re_app_system_config() - the installed configuration,
 * SYSCONFDIR/roboelf/roboelf.yaml (under ROBOELF_ROOT when set); "" when
 * the path does not fit.
 * re_app_find_config() - without -c: ./config/roboelf.yaml (the source
 * tree), else the installed one; sets @g->config and @g->config_searched.
 */
const char *re_app_system_config(void);
void re_app_find_config(struct re_app_args *g);

/*
 * re_app_load_config() - @a->cfg from @g's file with @g's overrides,
 * validated (also: the analog inputs in the DMC-4030 record, no
 * ROBOELF_ROOT in clinical mode); the axis names in @a->names.
 * Return: 0, or -1 (said on stderr).
 */
int re_app_load_config(struct app *a, struct re_app_args *g);

/*
 * re_app_open_log() - the failure log of @a->cfg, opened, with the start
 * and the configuration written first.
 * Return: 0, or -1 (said on stderr).
 */
int re_app_open_log(struct app *a, const struct re_app_args *g);

/*
 * re_app_print_version() - --version: the release, the DMC interface, and
 * the configuration and DMC programs this program would use from here.
 * Return: 0.
 */
int re_app_print_version(const char *prog, struct re_app_args *g);

/*
 * re_app_power_off() - the reverse of power-on: the program back to its
 * safe state, every motor off and read back (re_super_shutdown(), or a
 * stop when there is no supervisor yet and the controller is ours), the
 * relay off and closed, the link closed; what was confirmed said on the
 * console and in the log (@latched: a fault was latched).
 */
void re_app_power_off(struct app *a, int latched);

/*
 * re_app_release() - after re_app_power_off(): the locks, the console, the
 * log, the supervisor and the tables released.
 */
void re_app_release(struct app *a);

#endif /* RE_APP_H */
