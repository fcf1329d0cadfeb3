/*
 * gload_dl.h - the steps galil-load takes on a controller, each on an open
 * gl_link: halt, download, read back and compare, erase, burn, start, and
 * numeric queries. galil-load's main() strings them together and prints; the
 * steps never print.
 *
 * Read-back comparison: both texts are put in the normal form of gl_ident.h
 * (CR LF and CR -> LF, cut at 0x1A, empty lines at the end dropped, last
 * line ends with LF) and must then be equal byte for byte.
 */
#ifndef GLOAD_DL_H
#define GLOAD_DL_H

#include <stddef.h>

#include "gl_link.h"

/* Process exit codes (docs/galil-load.1). */
enum gload_exit {
	GLOAD_EXIT_OK = 0,
	GLOAD_EXIT_CHECK = 1, /* the offline check (or reading input) failed */
	GLOAD_EXIT_USAGE = 2, /* bad command line */
	GLOAD_EXIT_CONN = 3,  /* no connection, or the controller stopped
			       * answering */
	GLOAD_EXIT_CTRL = 4,  /* the controller rejected something, or the
			       * read-back / start confirmation failed */
	GLOAD_EXIT_BUSY = 5,  /* a supervisor drives the robot (no --force) */
	GLOAD_EXIT_DIFFERS = 6, /* --verify: the controller holds another
				 * program (nothing was written) */
};

#define GLOAD_SLOW_TIMEOUT_MS 10000	    /* DL, UL, BP [galil-notes 1.6] */
#define GLOAD_UPLOAD_CAP      (512u * 1024) /* > 4000 lines x 82 bytes */
#define GLOAD_CMD_LEN	      24

/*
 * gload_exit_for() - the exit code for a gl_err code from a link call:
 * GL_ERR_CTRL, GL_ERR_MISMATCH -> GLOAD_EXIT_CTRL; GL_ERR_ARG (the link
 * refused to send a malformed command) -> GLOAD_EXIT_USAGE; other errors ->
 * GLOAD_EXIT_CONN; GL_OK and counts -> GLOAD_EXIT_OK.
 */
int gload_exit_for(int err);

/*
 * gload_query_number() - send @cmd (e.g. "MG _XQ0") and parse the reply as
 * one number. Return: GL_OK, GL_ERR_PROTO (not a number), or the link error.
 */
int gload_query_number(gl_link *l, const char *cmd, double *v, int timeout_ms);

/*
 * gload_dl_busy() - is a supervisor driving the robot? The RoboELF program
 * runs (_XQ0 >= 0) in its armed (1) or service (3) state and its heartbeat
 * hbpc changes within @watch_ms. A controller without that program, or one
 * whose heartbeat stands still (its supervisor died: the program's own
 * watchdog stops the robot), is not busy.
 * @state: [out] the program's state when busy (1 or 3), else -1.
 * Return: 1 busy, 0 not, or a link error.
 */
int gload_dl_busy(gl_link *l, int watch_ms, int *state, int timeout_ms);

/* gload_dl_halt()'s *running when an axis did not stop in time. */
#define GLOAD_HALT_LATE (-2)

/*
 * gload_dl_halt() - make the controller safe to load: prun=0 (the RoboELF
 * program's automatic routines then only make safe: docs/dmc-interface.md),
 * stop every program thread (HX0..HXn-1), stop the axes (ST, decelerating),
 * wait until no profiler runs (_BGx = 0 on every axis, at most @stop_ms),
 * switch the motors off (MO: the controller refuses it while an axis
 * moves, command reference MO "Not Valid while in motion", TC 7) and read
 * every motor back off (_MOx = 1); then confirm with MG _XQn that no thread
 * runs. An axis still moving @stop_ms after ST is stopped at once (AB 1,
 * motion only), waited for again, the motors switched off, and the halt
 * fails (GLOAD_HALT_LATE): something kept it moving, so nothing is loaded.
 * @threads: number of threads of the model (8 on a DMC-40x0).
 * @axes: number of axes to stop and read back (3 on a DMC-4030).
 * @stop_ms: how long the axes may take to stop after ST.
 * @running: [out] on GL_ERR_MISMATCH, the thread still running (>= 0), -1
 *           when a motor is still on, GLOAD_HALT_LATE when an axis did not
 *           stop after ST within @stop_ms (@failed is then "MG _BGx" of the
 *           first such axis).
 * @failed: [out] the command that failed (or found the thread running),
 *          e.g. "MG _XQ3"; GLOAD_CMD_LEN bytes.
 * Return: GL_OK, GL_ERR_MISMATCH, GL_ERR_TIMEOUT (an axis still moves even
 *         after AB 1; @failed names it), or a link error (GL_ERR_CTRL: see
 *         gl_link_ctrl_error()).
 */
int gload_dl_halt(gl_link *l, int threads, int axes, int stop_ms, int *running,
		  char failed[GLOAD_CMD_LEN], int timeout_ms);

/*
 * gload_dl_compare() - compare the program meant (@want) with the one read
 * back (@got) in normal form.
 * @line: [out] on GL_ERR_MISMATCH, the first differing line (1-based).
 * Return: GL_OK, GL_ERR_MISMATCH or GL_ERR_NOMEM.
 */
int gload_dl_compare(const char *want, size_t wlen, const char *got,
		     size_t glen, int *line);

/*
 * gload_dl_upload() - UL the controller's program into @buf (capacity @cap,
 * NUL-terminated) and normalise it in place.
 * Return: its normal-form length (>= 0) or a link error.
 */
int gload_dl_upload(gl_link *l, char *buf, size_t cap, int timeout_ms);

/*
 * gload_dl_download() - DL @text (@len bytes, LF line ends, no '\').
 * @bad_line: [out] on GL_ERR_CTRL, the 1-based line of @text the controller
 *            rejected (0 if unknown).
 * Return: GL_OK or a link error.
 */
int gload_dl_download(gl_link *l, const char *text, size_t len, int *bad_line,
		      int timeout_ms);

/*
 * gload_dl_erase() - download an empty program and confirm by UL that the
 * controller holds nothing.
 * Return: GL_OK, GL_ERR_MISMATCH (something is still there), link error.
 */
int gload_dl_erase(gl_link *l, int timeout_ms);

/*
 * gload_dl_burn() - BP: burn the program to flash (so #AUTO runs at power
 * up). Uses at least GLOAD_SLOW_TIMEOUT_MS.
 * Return: GL_OK or a link error.
 */
int gload_dl_burn(gl_link *l, int timeout_ms);

/*
 * gload_dl_start() - "XQ #@label,0", then confirm with MG _XQ0 that thread
 * 0 runs.
 * @label: without '#', e.g. "AUTO".
 * @xq0: [out] optional, the _XQ0 value read (-1 = not running).
 * Return: GL_OK, GL_ERR_MISMATCH (thread 0 not running), a link error.
 */
int gload_dl_start(gl_link *l, const char *label, double *xq0, int timeout_ms);

#endif /* GLOAD_DL_H */
