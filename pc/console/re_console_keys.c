/*
 * re_console_keys.c - the keyboard: the terminal's modes (quiet during the
 * start-up, raw under the board, given back on every exit), the board's
 * keys, the echo of an answer. See re_console.h.
 */
#include "re_console.h"

#include <poll.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

/* The terminal's own settings, kept once before the first change, so
 * that every later change starts from them and the restore gives them
 * back. Return: 0, or -1 when they cannot be read. */
static int term_save(struct re_console *c)
{
	if (c->raw || c->quiet)
		return 0;
	return tcgetattr(c->in_fd, &c->saved) < 0 ? -1 : 0;
}

/* The terminal's own settings without the echo (of the newline too):
 * the line discipline, Ctrl-C and the rest stay as they were. */
static int set_quiet(const struct re_console *c)
{
	struct termios t = c->saved;

	t.c_lflag &= ~(tcflag_t)(ECHO | ECHONL);
	return tcsetattr(c->in_fd, TCSANOW, &t);
}

void re_console_quiet(struct re_console *c)
{
	if (!c->tty_in || c->raw || c->quiet || term_save(c) < 0)
		return;
	if (set_quiet(c) == 0)
		c->quiet = 1;
}

void re_console_raw(struct re_console *c)
{
	struct termios t;

	if (!c->tty_in || c->raw || term_save(c) < 0)
		return;
	t = c->saved;
	t.c_lflag &= ~(tcflag_t)(ICANON | ECHO);
	t.c_iflag &= ~(tcflag_t)IXON; /* Ctrl-S must not freeze the board */
	t.c_cc[VMIN] = 0;
	t.c_cc[VTIME] = 0;
	/* TCSAFLUSH: what was typed before (during the calibration) is
	 * dropped, never read as a key of the run */
	if (tcsetattr(c->in_fd, TCSAFLUSH, &t) == 0)
		c->raw = 1;
}

void re_console_flush_keys(struct re_console *c)
{
	if (c->tty_in)
		tcflush(c->in_fd, TCIFLUSH);
}

void re_console_restore(struct re_console *c)
{
	if (c->raw || c->quiet) {
		tcsetattr(c->in_fd, TCSANOW, &c->saved);
		c->raw = 0;
		c->quiet = 0;
	}
}

int re_console_key(struct re_console *c)
{
	struct pollfd p = {.fd = c->in_fd, .events = POLLIN};
	unsigned char ch;
	ssize_t n;

	if (c->in_fd < 0 || !c->tty_in)
		return 0;
	if (poll(&p, 1, 0) <= 0)
		return 0;
	n = read(c->in_fd, &ch, 1);
	if (n == 0)
		return -1;
	return n == 1 ? ch : 0;
}

/* An answer is seen as it is typed, also while the console is quiet:
 * the terminal's own settings for the question (@on), quiet again after
 * it. */
void re_console_echo(struct re_console *c, int on)
{
	if (!c->quiet || c->raw)
		return;
	if (on)
		tcsetattr(c->in_fd, TCSANOW, &c->saved);
	else
		set_quiet(c);
}

void re_console_trace_key(struct re_console *c, int on)
{
	c->trace_key = !!on;
}
