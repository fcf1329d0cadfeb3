/*
 * re_console.h - the operator's console: start-up progress lines, the
 * status board, the FAULT line, the keyboard (q to quit) and the
 * calibration question.
 *
 * On a terminal: a status board redrawn in place at most 10 times a second
 * (per axis the position in the robot's units - degrees for A and B, mm
 * for C, from the configuration's counts_per_unit; encoder counts when
 * asked for (re_console_counts(), key u) or when the scale is not known -
 * a bar over the travel with the soft limits marked '|', potentiometer
 * volts against the expected value and the margin left, speed in the
 * same unit per second (deg/s, mm/s, cnt/s), motion state (one source
 * with the "moving" summary: re_console_int.h), limit switches; relay
 * state, watchdog latency
 * last/worst, loop period, lateness and overruns, controller fault,
 * operating mode).
 * The board is drawn at absolute positions on the bottom lines of the
 * screen, and the lines above it are made the terminal's scroll region:
 * messages (progress, warnings), and the text of any other program
 * writing to the same terminal (the demo's narration), scroll there above
 * the board and are never erased by it. The cursor is saved before and
 * restored after every frame, so it always stays in that region. The first
 * FAULT line is also kept on the board, in a panel under the header, until the
 * program ends, so it cannot scroll away; below it the history of later
 * faults and warnings (re_console_event()), newest first, as many as fit
 * (repeats of one kind folded into one line with a count), each stamped
 * with when it happened on the header's "up" clock ("[up 12.100 s]": a
 * time since the start, never an interval since the first fault), and
 * the log file's path (re_console_log_path()) on a line of its own. The FAULT
 * is wrapped at word boundaries, whole (in the rows the board can spare); a
 * path wider than the terminal is printed whole on a line of its own (the
 * terminal wraps it, a copy gets it whole), its rows counted; every other
 * board line is cut to the terminal's width (never wraps). Messages above
 * the board are wrapped the same way. A terminal narrower than
 * RE_CONSOLE_MIN_COLS or lower than RE_CONSOLE_MIN_ROWS gets the status lines
 * instead, said once; a resize redraws the board from the top of the screen.
 * Colour only on a terminal and only when NO_COLOR is unset (no-color.org) and
 * TERM is not "dumb". The keyboard is in raw mode (no echo, no line buffering)
 * from re_console_raw() to re_console_close(), and does not echo from
 * re_console_quiet() on (the start-up and the calibration) but for the
 * answer to a question.
 *
 * Not on a terminal: one "status ..." line per second, no escape codes.
 *
 * The periodic status (board or line) runs in the supervisor's loop, so it
 * must never block it: each frame is built in a fixed buffer and written
 * through a second, non-blocking open file description of the output (a
 * terminal or a pipe). A terminal or reader that stops draining (a frozen
 * SSH session, a paused pager) makes frames drop (counted in @dropped), not
 * the safety cycle stop. Messages and the FAULT line are written blocking:
 * they happen at start-up, at quit, or after the safe state is reached.
 * Raw mode also turns off XON/XOFF, so Ctrl-S cannot freeze the board.
 *
 * This is the only supervisor module that prints.
 */
#ifndef RE_CONSOLE_H
#define RE_CONSOLE_H

#include <stdint.h>
#include <stdio.h>
#include <termios.h>

#include "re_calib.h"
#include "re_super.h"

#define RE_CONSOLE_BOARD_NS 100000000LL	 /* >= 100 ms between redraws */
#define RE_CONSOLE_LINE_NS  1000000000LL /* 1 s between status lines */
#define RE_CONSOLE_FRAME    4096	 /* one status frame, bytes */
#define RE_CONSOLE_FAULT    512		 /* the first FAULT line kept, bytes */
#define RE_CONSOLE_HIST	    16		 /* later faults and warnings kept */
#define RE_CONSOLE_ROOM                                                        \
	4		       /* screen lines left above the board for        \
				* messages (the demo's narration) */
#define RE_CONSOLE_MIN_COLS 60 /* narrower: status lines, no board */
#define RE_CONSOLE_MIN_ROWS 16 /* lower: status lines, no board */

/* How an axis is shown: @unit "deg"/"mm", @per_unit counts per unit (0:
 * not known, counts shown). */
struct re_console_axis {
	char unit[8];
	double per_unit;
};

struct re_console {
	FILE *out; /* stdout */
	int out_fd;
	int in_fd;   /* keyboard, -1 when none */
	int tty_out; /* @out is a terminal: status board */
	int tty_in;  /* @in_fd is a terminal: raw keys, questions */
	int color;
	int raw;	 /* raw mode (termios changed; restore on close) */
	int quiet;	 /* no echo (termios changed; restore on close) */
	int board_lines; /* lines of the board now on screen (at the bottom,
			  * under the scroll region); 0: none */
	int half;	 /* the last frame was cut short: its saved cursor
			  * must be restored before anything else */
	int redo;	 /* ... and the scroll region set again */
	int64_t last_draw_ns;
	struct termios saved; /* the terminal before raw mode */
	int nb_fd;	      /* non-blocking description of @out, or -1 */
	uint64_t dropped;     /* status frames not (fully) written */
	size_t frame_len;
	char frame[RE_CONSOLE_FRAME];
	char lines[RE_CONSOLE_FRAME]; /* the board's text, before positioning */
	int cols, rows;		      /* the terminal at the last board */
	int small_said;		      /* "terminal too small" was said */
	char fault[RE_CONSOLE_FAULT]; /* the first FAULT, kept on the board */
	struct re_console_event {
		double t_s; /* since the supervisor started, s; < 0 unknown */
		enum re_log_level level;
		enum re_event_kind kind;
		unsigned count; /* folded repeats of this kind */
		char text[RE_SUPER_EVENT_LEN];
	} hist[RE_CONSOLE_HIST]; /* newest first */
	int nhist;
	char log_path[256]; /* shown under the history; "" none */
	uint64_t nfaults;   /* FAULT lines shown in all */
	struct re_console_axis ax[RE_SUPER_AXES];
	int counts;		      /* show encoder counts instead of units */
	int trace_key;		      /* key t writes a trace (a recorder) */
	struct re_calib_progress cal; /* cal.active: calibration lines */
};

enum re_calib_choice {
	RE_CALIB_ASK = 0,
	RE_CALIB_FULL,
	RE_CALIB_FILE,
};

/*
 * re_console_open() - set up the console on @out (and keyboard @in_fd,
 * -1 for none). Reads NO_COLOR and TERM.
 * Return: 0 (never fails; without a terminal it degrades to plain lines).
 */
int re_console_open(struct re_console *c, FILE *out, int in_fd);

/*
 * re_console_quiet() - from now on the terminal does not echo what is
 * typed (line editing, Ctrl-C and the rest unchanged), so that a key typed
 * during the start-up or the calibration cannot land inside the lines
 * roboelf prints; the keys stay unread and re_console_raw() drops them. A
 * question (re_console_ask_calibration(), re_console_ask_yes()) echoes its
 * answer while it waits for it. Restored by re_console_close() and
 * re_console_restore(); re_console_raw() takes over from it. No-op without
 * a terminal or when the terminal's settings cannot be read.
 */
void re_console_quiet(struct re_console *c);

/*
 * re_console_raw() - put the keyboard in raw mode (no echo, one key at a
 * time) for the run loop. Restored by re_console_close() and
 * re_console_restore(). No-op without a terminal.
 */
void re_console_raw(struct re_console *c);

/*
 * re_console_echo() - the echo of an answer while a question waits for it
 * (@on 1: the terminal's own settings), quiet again after it (@on 0). Only
 * while quiet (re_console_quiet()) and not raw; a no-op otherwise.
 */
void re_console_echo(struct re_console *c, int on);

/*
 * re_console_flush_keys() - drop every key typed but not read yet, so that
 * nothing typed in one phase acts in the next (keys typed during the
 * calibration, before a question, before a fault). No-op without a
 * terminal. Called by re_console_raw() and before each question.
 */
void re_console_flush_keys(struct re_console *c);

/* re_console_restore() - give the terminal back its settings (idempotent;
 * async-signal-safe enough to call on the way out). */
void re_console_restore(struct re_console *c);

/*
 * re_console_close() - restore the terminal and flush. The board is erased
 * (its values would be stale once roboelf ends) unless a fault was shown:
 * then the board with its fault panel stays, the cursor under it.
 */
void re_console_close(struct re_console *c);

/*
 * re_console_msg() - one message line above the board (start-up progress,
 * warnings, "RoboELF Ready for Use"). A trailing newline is added.
 */
void re_console_msg(struct re_console *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/*
 * re_console_fault() - the FAULT line, exactly as given, on one line (in
 * red on a colour terminal), above the board; flushed at once. On a
 * terminal it is also kept for the board's fault panel: the first one
 * for good, later ones in the history (newest first).
 */
void re_console_fault(struct re_console *c, const char *line);

/*
 * re_console_event() - a later fault or a warning (@ev) for the board's
 * history, newest first; one of the same kind as the newest folds into it
 * (its text replaced, a count kept). Without a terminal it is printed as
 * one line ("roboelf: warning: ..." / "roboelf: later FAULT ESTOP: ...").
 */
void re_console_event(struct re_console *c, const struct re_event *ev);

/* re_console_log_path() - the log file named under the history. */
void re_console_log_path(struct re_console *c, const char *path);

/*
 * re_console_calib() - while a calibration (or the check of a file and
 * the move to the centre) runs, the board shows per axis its phase, a bar
 * of its position over the travel and the time left, instead of the axis
 * lines; @p copied. NULL (or @p->active 0): the axis lines again.
 */
void re_console_calib(struct re_console *c, const struct re_calib_progress *p);

/*
 * re_console_units() - show axis @axis (0-based, < RE_SUPER_AXES) in
 * @unit ("deg", "mm"; cut to 7 bytes) with @counts_per_unit encoder
 * counts per unit; 0 (or less): the scale is not known, counts are shown.
 */
void re_console_units(struct re_console *c, int axis, const char *unit,
		      double counts_per_unit);

/*
 * re_console_trace_key() - @on: key t writes a trace (the flight recorder
 * runs), so the board offers it; 0 (the default): t is not shown. Key u
 * is shown only when an axis has a unit to switch from (re_console_units())
 * and q only when there is a keyboard, so that no key is offered that does
 * nothing.
 */
void re_console_trace_key(struct re_console *c, int on);

/*
 * re_console_counts() - @on: show encoder counts (and counts/s) on the
 * board instead of the units; 0: the units again. The next frame shows it.
 */
void re_console_counts(struct re_console *c, int on);

/*
 * re_console_render() - the board for @st as it would be drawn on a
 * terminal of @cols x @rows, without colour or cursor movements (pure
 * apart from @c's kept faults and settings; for tests and snapshots).
 * @buf: [out] NUL-terminated lines, each ending in '\n'.
 * Return: the number of lines, or -1 when @cols x @rows is below the
 *         board's minimum (the status line is used there).
 */
int re_console_render(struct re_console *c, const struct re_status *st,
		      int cols, int rows, char *buf, size_t cap);

/*
 * re_console_status() - show @st: redraw the board when at least
 * RE_CONSOLE_BOARD_NS passed since the last redraw (@force: now), or print
 * one status line per RE_CONSOLE_LINE_NS without a terminal.
 * @now_ns: monotonic time.
 */
void re_console_status(struct re_console *c, const struct re_status *st,
		       int64_t now_ns, int force);

/*
 * re_console_due() - would re_console_status(@c, ..., @now_ns, 0) draw?
 * The caller fills the status only then (it is drawn at most
 * every RE_CONSOLE_BOARD_NS, the cycle runs far more often).
 * Return: 1 when a frame is due, 0 when not.
 */
int re_console_due(const struct re_console *c, int64_t now_ns);

/*
 * re_console_key() - one key from the keyboard if one is waiting (never
 * blocks). Return: the character, 0 when none, -1 at end of input.
 */
int re_console_key(struct re_console *c);

/*
 * re_console_ask_calibration() - ask "full or file" on the terminal until a
 * valid answer (f/full, l/file/load), or end of input.
 * Return: RE_CALIB_FULL, RE_CALIB_FILE, or RE_CALIB_ASK when no terminal or
 *         end of input (the caller then exits 2).
 */
enum re_calib_choice re_console_ask_calibration(struct re_console *c);

/*
 * re_console_ask_yes() - ask a yes/no question on the terminal.
 * Return: 1 yes, 0 no or no terminal / end of input.
 */
int re_console_ask_yes(struct re_console *c, const char *question);

/*
 * re_console_format_line() - the one-line status (also used without a
 * terminal), e.g. "status 12.3s relay=on link=ok A enc=120 pct=50.1
 * pot=2.512V exp=2.510V margin=0.058V vel=0 ..." (pure, for tests).
 * Return: the length (as snprintf).
 */
int re_console_format_line(const struct re_status *st, char *buf, size_t cap);

#endif /* RE_CONSOLE_H */
