/*
 * re_console.c - status board, messages, FAULT line and keyboard.
 * See re_console.h.
 */
#include "re_console.h"
#include "re_console_int.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#define BAR_WIDTH   16
#define ANSI_RED    "\033[1;31m"
#define ANSI_GREEN  "\033[32m"
#define ANSI_YELLOW "\033[33m"
#define ANSI_OFF    "\033[0m"

/* A second, non-blocking open file description of a terminal or pipe
 * @fd (reopened through /proc, so the shell's own description is left
 * blocking); -1 for anything else: a regular file does not block, and
 * reopening it would write from its start. */
static int open_nonblocking(int fd)
{
	char path[32];
	struct stat st;

	if (fd < 0 || fstat(fd, &st) < 0 ||
	    !(S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode)))
		return -1;
	snprintf(path, sizeof(path), "/proc/self/fd/%d", fd);
	return open(path, O_WRONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
}

int re_console_open(struct re_console *c, FILE *out, int in_fd)
{
	const char *term = getenv("TERM");
	const char *nc = getenv("NO_COLOR");

	memset(c, 0, sizeof(*c));
	c->out = out;
	c->out_fd = fileno(out);
	c->nb_fd = open_nonblocking(c->out_fd);
	c->in_fd = in_fd;
	c->tty_out = isatty(c->out_fd);
	c->tty_in = in_fd >= 0 && isatty(in_fd);
	c->color =
	    c->tty_out && !(nc && nc[0]) && !(term && !strcmp(term, "dumb"));
	return 0;
}

static void board_remove(struct re_console *c, FILE *out);

void re_console_close(struct re_console *c)
{
	/* no fault: the board goes (left there, its "relay ON", "on" would
	 * contradict the confirmed switch-off said above it); a latched
	 * fault: its panel stays under the last messages (relay off, motors
	 * off: still true), the whole screen scrolls again, the cursor under
	 * the board */
	if (c->tty_out && !c->fault[0])
		board_remove(c, c->out);
	if (c->tty_out && (c->board_lines || c->half)) {
		fprintf(c->out, "%s\033[r\033[%d;1H\n", c->half ? "\0338" : "",
			c->rows);
		c->board_lines = 0;
		c->half = 0;
	}
	re_console_restore(c);
	fflush(c->out);
	if (c->nb_fd >= 0)
		close(c->nb_fd);
	c->nb_fd = -1;
}

/* ---- status frames: built in c->frame, written without blocking -------- */

static void frame_add(struct re_console *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void frame_add(struct re_console *c, const char *fmt, ...)
{
	size_t cap = sizeof(c->frame) - c->frame_len;
	va_list ap;
	int n;

	va_start(ap, fmt);
	n = vsnprintf(c->frame + c->frame_len, cap, fmt, ap);
	va_end(ap);
	if (n > 0)
		c->frame_len += (size_t)n < cap ? (size_t)n : cap - 1;
}

static int count_lines(const char *buf, size_t len)
{
	int n = 0;

	for (size_t i = 0; i < len; i++)
		n += buf[i] == '\n';
	return n;
}

/* Write the frame; a short or refused write drops the rest of it. Return
 * the number of bytes that reached the output. */
static size_t frame_send(struct re_console *c)
{
	size_t len = c->frame_len;
	ssize_t n;

	c->frame_len = 0;
	fflush(c->out); /* earlier messages first */
	if (c->nb_fd < 0) {
		fwrite(c->frame, 1, len, c->out);
		fflush(c->out);
		return len;
	}
	do
		n = write(c->nb_fd, c->frame, len);
	while (n < 0 && errno == EINTR);
	if (n < (ssize_t)len)
		c->dropped++;
	return n > 0 ? (size_t)n : 0;
}

/* Before a message: the cursor back where the text flows (in the scroll
 * region above the board) if a frame was cut short after saving it. */
static void board_erase(struct re_console *c)
{
	if (c->tty_out && c->half) {
		fputs("\0338", c->out);
		c->half = 0;
	}
}

static void term_size(struct re_console *c, int *cols, int *rows);

/* The length of the next line of @text in @room columns: up to the last
 * space that fits; a word longer than @room whole (a path is never split:
 * the terminal wraps it, and a copy of it gets it whole). */
static int wrap_len(const char *text, int room)
{
	int n = (int)strlen(text), k;

	if (n <= room)
		return n;
	for (k = room; k > 0 && text[k] != ' '; k--)
		;
	if (k > 0)
		return k;
	while (text[k] && text[k] != ' ')
		k++;
	return k;
}

/* @text on the output; on a terminal wrapped at word boundaries to the
 * terminal's width (continuation lines indented by two spaces; a word
 * wider than that, a path, on a line of its own from the first column),
 * so that nothing wraps by itself but such a word; in @colour when
 * given. */
static void put_wrapped(struct re_console *c, const char *text,
			const char *colour)
{
	int cols, rows, w, first = 1;

	if (!c->tty_out) {
		fprintf(c->out, "%s\n", text);
		return;
	}
	term_size(c, &cols, &rows);
	w = cols - 1;
	while (*text || first) {
		int room = first ? w : w - 2, n;

		if (room < 20)
			room = 20;
		n = wrap_len(text, room);
		fprintf(c->out, "%s%s%.*s%s\n", first || n > room ? "" : "  ",
			colour ? colour : "", n, text, colour ? ANSI_OFF : "");
		text += n;
		while (*text == ' ')
			text++;
		first = 0;
	}
}

void re_console_msg(struct re_console *c, const char *fmt, ...)
{
	char text[2048];
	va_list ap;

	board_erase(c);
	va_start(ap, fmt);
	vsnprintf(text, sizeof(text), fmt, ap);
	va_end(ap);
	put_wrapped(c, text, NULL);
	fflush(c->out);
}

static void hist_add(struct re_console *c, const struct re_event *ev)
{
	struct re_console_event *h = &c->hist[0];

	if (c->nhist > 0 && h->kind == ev->kind && ev->kind != RE_EV_OTHER &&
	    h->level == ev->level) {
		h->count++;
	} else {
		memmove(&c->hist[1], &c->hist[0],
			sizeof(c->hist[0]) * (RE_CONSOLE_HIST - 1));
		if (c->nhist < RE_CONSOLE_HIST)
			c->nhist++;
		h->count = 1;
	}
	h->t_s = ev->t_s;
	h->level = ev->level;
	h->kind = ev->kind;
	snprintf(h->text, sizeof(h->text), "%s", ev->text);
}

/* Keep @line for the board: the first for good, later ones in the
 * history. */
static void fault_keep(struct re_console *c, const char *line)
{
	struct re_event ev;

	c->nfaults++;
	if (!c->fault[0]) {
		snprintf(c->fault, sizeof(c->fault), "%s", line);
		return;
	}
	memset(&ev, 0, sizeof(ev));
	/* its time is not given; the last board's is earlier than the fault,
	 * so it would be a wrong stamp: said as not known */
	ev.t_s = -1;
	ev.level = RE_LOG_FAULT;
	ev.kind = RE_EV_OTHER;
	snprintf(ev.text, sizeof(ev.text), "%s", line);
	hist_add(c, &ev);
}

void re_console_event(struct re_console *c, const struct re_event *ev)
{
	int fault = ev->level == RE_LOG_FAULT;
	const char *text = ev->text;

	hist_add(c, ev);
	if (c->tty_out)
		return; /* on the board */
	if (fault && !strncmp(text, "FAULT ", 6))
		text += 6;
	fprintf(c->out, "roboelf: %s%s\n",
		fault ? "later FAULT " : "warning: ", text);
	fflush(c->out);
}

void re_console_log_path(struct re_console *c, const char *path)
{
	snprintf(c->log_path, sizeof(c->log_path), "%s", path ? path : "");
}

void re_console_fault(struct re_console *c, const char *line)
{
	fault_keep(c, line);
	board_erase(c);
	put_wrapped(c, line, c->color ? ANSI_RED : NULL);
	fflush(c->out);
}

/* ---- texts ------------------------------------------------------------- */

int re_console_format_line(const struct re_status *st, char *buf, size_t cap)
{
	char ctl[48];
	size_t n;

	re_con_ctrl_text(st, ctl, sizeof(ctl));
	n = (size_t)snprintf(buf, cap,
			     "status %.1fs mode=%s relay=%s link=%s"
			     " ctrl=\"%s\"",
			     st->uptime_s, st->mode_name,
			     st->relay == RE_RELAY_ON	 ? "on"
			     : st->relay == RE_RELAY_OFF ? "off"
							 : "unknown",
			     st->link_ok ? "ok" : "down", ctl);
	for (int i = 0; i < st->n_axes && n < cap; i++) {
		const struct re_axis_status *a = &st->axis[i];

		n += (size_t)snprintf(buf + n, cap - n, " %s enc=%d pot=%.3fV",
				      st->axis_names[i], (int)a->enc_counts,
				      a->pot_v);
		if (n < cap && a->have_expect)
			n += (size_t)snprintf(buf + n, cap - n,
					      " exp=%.3fV margin=%.3fV",
					      a->pot_expected_v, a->margin_v);
		if (n < cap)
			n += (size_t)snprintf(
			    buf + n, cap - n, " vel=%.0f %s lim=%s", a->vel_cps,
			    re_con_motion_text(a), re_con_limit_text(a));
	}
	if (n < cap)
		n += (size_t)snprintf(buf + n, cap - n,
				      " wd=%.1f/%.1fms "
				      "overruns=%llu%s",
				      st->wd_last_ms, st->wd_worst_ms,
				      (unsigned long long)st->overruns,
				      st->latched ? " LATCHED" : "");
	return (int)n;
}

/* ---- the board --------------------------------------------------------- */

/* A bar over the axis's travel: the soft limits '|' one place inside each
 * end (so that an axis past one shows beyond it), the position '#'; '?'
 * throughout when no calibration gives the soft limits. */
static void soft_bar(char out[BAR_WIDTH + 3], const struct re_axis_status *a)
{
	double span = a->soft_fwd_counts - a->soft_rev_counts, x;
	int pos;

	out[0] = '[';
	out[BAR_WIDTH + 1] = ']';
	out[BAR_WIDTH + 2] = '\0';
	if (!a->have_soft || span <= 0) {
		memset(out + 1, '?', BAR_WIDTH);
		return;
	}
	memset(out + 1, '-', BAR_WIDTH);
	out[2] = '|';
	out[BAR_WIDTH - 1] = '|';
	x = 1 + (a->enc_counts - a->soft_rev_counts) / span * (BAR_WIDTH - 3);
	if (a->enc_counts < a->soft_rev_counts)
		pos = 0; /* past a soft limit: outside its mark */
	else if (a->enc_counts > a->soft_fwd_counts)
		pos = BAR_WIDTH - 1;
	else
		pos = (int)(x + 0.5);
	out[1 + pos] = '#';
}

static const char *col(const struct re_console *c, const char *code)
{
	return c->color ? code : "";
}

/* Add @text (one line, may hold colour sequences "\033[...m") to the
 * frame, cut to @width - 1 visible characters so that it never wraps; a
 * cut inside a colour ends the colour. */
static void frame_line(struct re_console *c, const char *text, int width)
{
	char out[RE_CONSOLE_FRAME / 4];
	size_t n = 0, i = 0;
	int vis = 0, colour = 0;

	while (text[i] && text[i] != '\n' && n + 8 < sizeof(out)) {
		if (text[i] == '\033') {
			size_t j = i;

			while (text[j] && text[j] != 'm')
				j++;
			if (!text[j])
				break;
			colour = strncmp(text + i, ANSI_OFF, j + 1 - i) != 0;
			memcpy(out + n, text + i, j + 1 - i);
			n += j + 1 - i;
			i = j + 1;
			continue;
		}
		if (vis >= width - 1)
			break;
		out[n++] = text[i++];
		vis++;
	}
	out[n] = '\0';
	frame_add(c, "%s%s\n", out, colour ? ANSI_OFF : "");
}

static void board_printf(struct re_console *c, int width, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void board_printf(struct re_console *c, int width, const char *fmt, ...)
{
	char line[1024];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(line, sizeof(line), fmt, ap);
	va_end(ap);
	frame_line(c, line, width);
}

/* @v, never "-0" at its printed precision (@scale 1: whole, 10: one
 * decimal, 100: two). */
static double no_neg_zero(double v, double scale)
{
	return v * scale > -0.5 && v < 0 ? 0.0 : v;
}

/* Counts in the axis's unit ("  -12.35 deg"), or as counts ("  -12345 cnt")
 * when counts are asked for or the scale is not known: 12 characters; a
 * speed (@per_s) in the same unit per second ("  5.1 deg/s", "  0.8 mm/s",
 * "  512 cnt/s"): 11. Never "-0". */
static void unit_text(const struct re_console *c, int i, double counts,
		      int per_s, char *buf, size_t cap)
{
	const struct re_console_axis *u = &c->ax[i];
	char per[16];

	if (c->counts || u->per_unit <= 0) {
		snprintf(buf, cap, per_s ? "%5.0f cnt/s" : "%8.0f cnt",
			 no_neg_zero(counts, 1));
		return;
	}
	if (!per_s) {
		snprintf(buf, cap, "%8.2f %-3s",
			 no_neg_zero(counts / u->per_unit, 100), u->unit);
		return;
	}
	snprintf(per, sizeof(per), "%s/s", u->unit);
	snprintf(buf, cap, "%5.1f %-5s", no_neg_zero(counts / u->per_unit, 10),
		 per);
}

static void board_axis(struct re_console *c, const struct re_status *st, int i,
		       int width)
{
	const struct re_axis_status *a = &st->axis[i];
	char b[BAR_WIDTH + 3], exp[48] = "    -      -", pos[40], vel[40];

	soft_bar(b, a);
	unit_text(c, i, a->enc_counts, 0, pos, sizeof(pos));
	unit_text(c, i, a->vel_cps, 1, vel, sizeof(vel));
	if (a->have_expect)
		snprintf(exp, sizeof(exp), "%5.3f %s%+6.3f%s",
			 a->pot_expected_v,
			 col(c, a->margin_v < 0 ? ANSI_RED : ""), a->margin_v,
			 col(c, a->margin_v < 0 ? ANSI_OFF : ""));
	/* the state says "off" for a motor off: no column of its own */
	board_printf(c, width, "%-2.2s %s %s %5.3f %s %s %-7s %s",
		     st->axis_names[i], pos, b, a->pot_v, exp, vel,
		     st->link_ok ? re_con_motion_text(a) : "STALE",
		     re_con_limit_text(a));
}

/* During a calibration: the axis's phase, a bar of its position over the
 * travel (0 % at the reverse switch), where it is, and its time left. */
static void board_cal_axis(struct re_console *c, const struct re_status *st,
			   int i, int width)
{
	const struct re_calib_axis_progress *p = &c->cal.axis[i];
	const struct re_axis_status *a = &st->axis[i];
	char b[BAR_WIDTH + 3], pos[40];
	int k = p->pct < 0 ? -1 : (int)(p->pct / 100 * (BAR_WIDTH - 1) + 0.5);

	b[0] = '[';
	for (int j = 0; j < BAR_WIDTH; j++)
		b[1 + j] = j == k ? '#' : k < 0 ? '?' : '-';
	b[BAR_WIDTH + 1] = ']';
	b[BAR_WIDTH + 2] = '\0';
	unit_text(c, i, a->enc_counts, 0, pos, sizeof(pos));
	board_printf(c, width, "%-2.2s %-15s %s %3.0f%% %s %5.3f %4.0f s %s",
		     st->axis_names[i], p->phase ? p->phase : "-", b,
		     p->pct < 0 ? 0 : p->pct, pos, a->pot_v, p->left_s,
		     st->link_ok ? re_con_motion_text(a) : "STALE");
}

static void board_axes(struct re_console *c, const struct re_status *st,
		       int width)
{
	if (!c->cal.active) {
		board_printf(c, width, "%-2s %12s %-18s %5s %-12s %11s %-7s %s",
			     "ax", "position", "  |soft  limits|", "pot V",
			     "expect margin", "speed", "state", "lim");
		for (int i = 0; i < st->n_axes; i++)
			board_axis(c, st, i, width);
		return;
	}
	board_printf(c, width, "%-2s %-15s %-18s %4s %12s %5s %6s %s", "ax",
		     "calibration", "[rev  travel  fwd]", "", "position",
		     "pot V", "left", "state");
	for (int i = 0; i < st->n_axes; i++)
		board_cal_axis(c, st, i, width);
}

/* Screen rows a line of @vis characters takes on a terminal @width wide. */
static int rows_of(int vis, int width)
{
	return vis <= width ? 1 : (vis + width - 1) / width;
}

/* @text (@n bytes, no colour) on a line of its own, never cut: a word
 * wider than the board (a path) takes the rows it needs. Return: those
 * rows. */
static int board_whole(struct re_console *c, int width, const char *text, int n,
		       const char *colour)
{
	if (n < width)
		board_printf(c, width, "%s%.*s%s", col(c, colour), n, text,
			     col(c, colour[0] ? ANSI_OFF : ""));
	else
		frame_add(c, "%s%.*s%s\n", col(c, colour), n, text,
			  col(c, colour[0] ? ANSI_OFF : ""));
	return rows_of(n, width);
}

/* The kept FAULT, wrapped at word boundaries (a word wider than the board
 * whole), in at most @max rows: a FAULT too long for them ends with where
 * it is whole. Return: the rows added. */
static int board_faults(struct re_console *c, int width, int max)
{
	const char *p = c->fault;
	int w = width - 1, k = 0;

	while (*p) {
		int n = wrap_len(p, w);

		if (k + rows_of(n, width) >= max && p[n]) {
			board_printf(c, width,
				     "%s(the whole FAULT is above "
				     "the board and in the log)%s",
				     col(c, ANSI_RED), col(c, ANSI_OFF));
			return k + 1;
		}
		k += board_whole(c, width, p, n, ANSI_RED);
		p += n;
		while (*p == ' ')
			p++;
	}
	return k;
}

/* When @h happened, on the clock of the header's "up" (seconds since the
 * supervisor started), to the millisecond: a stamp, never an interval,
 * so that "[up 12.100 s] later FAULT" cannot be read as "12.1 s after
 * the first fault". "?" when not known. */
static void hist_stamp(const struct re_console_event *h, char *buf, size_t cap)
{
	if (h->t_s < 0)
		snprintf(buf, cap, "[up %8s s]", "?");
	else
		snprintf(buf, cap, "[up %8.3f s]", h->t_s);
}

/* @prefix (@pvis visible characters, may hold colour) then @text wrapped
 * at word boundaries, continuation rows indented by two spaces, a word
 * wider than a row whole on its own; added to the frame when @emit.
 * Return: the screen rows it takes. */
static int board_wrap(struct re_console *c, int width, const char *prefix,
		      int pvis, const char *text, int emit)
{
	int rows = 0, first = 1;

	while (*text || first) {
		int lead = first ? pvis : 2, room = width - 1 - lead, n;

		if (room < 10)
			room = 10;
		n = wrap_len(text, room);
		if (n > room && !first)
			lead = 0; /* a path: whole, from the first column */
		if (emit && n > room)
			frame_add(c, "%s%.*s\n", first ? prefix : "", n, text);
		else if (emit)
			board_printf(c, width, "%s%.*s", first ? prefix : "  ",
				     n, text);
		rows += rows_of(lead + n, width);
		text += n;
		while (*text == ' ')
			text++;
		first = 0;
	}
	return rows;
}

/* The later faults and warnings, newest first, wrapped, in at most @room
 * rows (the last two of them the log's path, said, then whole on its
 * own). */
static void board_history(struct re_console *c, int width, int room)
{
	int left = room - 2, shown = 0;

	if (room < 2 || (!c->nhist && !c->fault[0]))
		return;
	for (int i = 0; i < c->nhist; i++, shown++) {
		const struct re_console_event *h = &c->hist[i];
		char times[16] = "", at[32], pre[96];
		const char *text = h->text;
		int fault = h->level == RE_LOG_FAULT, pvis, need;

		if (h->count > 1)
			snprintf(times, sizeof(times), " (x%u)", h->count);
		/* "FAULT COMM: ..." is shown as "later FAULT COMM: ..." */
		if (fault && !strncmp(text, "FAULT ", 6))
			text += 6;
		hist_stamp(h, at, sizeof(at));
		pvis = snprintf(pre, sizeof(pre), "%s %s%s%s ", at,
				fault ? "later FAULT" : "WARN", times,
				text == h->text ? ":" : "");
		snprintf(pre, sizeof(pre), "%s %s%s%s%s%s ", at,
			 col(c, fault ? ANSI_RED : ANSI_YELLOW),
			 fault ? "later FAULT" : "WARN", col(c, ANSI_OFF),
			 times, text == h->text ? ":" : "");
		need = board_wrap(c, width, pre, pvis, text, 0);
		if (need > left)
			break;
		board_wrap(c, width, pre, pvis, text, 1);
		left -= need;
	}
	if (!c->log_path[0])
		return;
	if (c->nhist > shown)
		board_printf(c, width, "%d older not shown; all in the log:",
			     c->nhist - shown);
	else
		board_printf(c, width,
			     "every fault and warning is in the log:");
	/* the path whole on its own line, so that it can be copied */
	board_whole(c, width, c->log_path, (int)strlen(c->log_path), "");
}

/* The terminal's size (80x24 when it cannot be read). */
static void term_size(struct re_console *c, int *cols, int *rows)
{
	struct winsize ws;

	*cols = 80;
	*rows = 24;
	if (ioctl(c->out_fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 &&
	    ws.ws_row > 0) {
		*cols = ws.ws_col;
		*rows = ws.ws_row;
	}
}

/* Key u has something to switch: counts shown, or an axis with a unit. */
static int units_key(const struct re_console *c, const struct re_status *st)
{
	for (int i = 0; i < st->n_axes && !c->counts; i++)
		if (c->ax[i].per_unit > 0)
			return 1;
	return c->counts;
}

/* The last line: what the operator can do now. During a calibration
 * only Ctrl-C is read (as a signal); the keys once the board runs, and
 * only from a terminal, each only when its action is there (t with the
 * flight recorder, u with a unit to switch). */
static void board_keys(struct re_console *c, const struct re_status *st,
		       int width)
{
	const char *latched = st->latched ? "LATCHED: every motor off; " : "";

	if (c->cal.active)
		board_printf(c, width,
			     "%s %.0f s, about %.0f s left; Ctrl-C stops it%s",
			     c->cal.full ? "calibrating" : "checking the file",
			     c->cal.elapsed_s, c->cal.left_s,
			     c->cal.full ? " (old table kept)" : "");
	else if (!c->tty_in)
		board_printf(c, width,
			     "%sno keyboard here: Ctrl-C or SIGTERM quits",
			     latched);
	else
		board_printf(c, width, "%skeys: q quit%s%s%s", latched,
			     c->trace_key ? "  t trace" : "",
			     units_key(c, st) ? "  u " : "",
			     !units_key(c, st) ? ""
			     : c->counts       ? "units"
					       : "counts");
}

/* The board's lines for a terminal @width x @rows, added to the frame. */
static void board_build(struct re_console *c, const struct re_status *st,
			int width, int rows)
{
	char ctl[64], moving[64], stream[48];
	int lines;

	re_con_ctrl_text(st, ctl, sizeof(ctl));
	re_con_stream_text(st, stream, sizeof(stream));
	board_printf(
	    c, width, "RoboELF  mode %s  up %.0f s  relay %s%s%s  link %s%s",
	    st->mode_name, st->uptime_s,
	    col(c, st->relay == RE_RELAY_ON ? ANSI_GREEN : ANSI_YELLOW),
	    re_con_relay_text(st->relay), col(c, ANSI_OFF),
	    st->link_ok ? "ok" : "DOWN (stale)", stream);
	/* the rest of the board: column header, axes, three lines; the FAULT
	 * may take the room kept for messages but one line */
	lines = 1 + 1 + st->n_axes + 3;
	lines += board_faults(c, width, rows - 1 - lines);
	board_history(c, width, rows - 1 - RE_CONSOLE_ROOM - lines);
	board_axes(c, st, width);
	board_printf(c, width,
		     "watchdog %.1f ms (worst %.1f, warn %llu) period %.0f ms "
		     "late %.1f/%.1f ms overruns %llu",
		     st->wd_last_ms, st->wd_worst_ms,
		     (unsigned long long)st->wd_warnings, st->period_ms,
		     st->late_last_ms, st->late_worst_ms,
		     (unsigned long long)st->overruns);
	re_con_moving_text(st, moving, sizeof(moving));
	board_printf(c, width, "controller %s  joystick %s  moving %s", ctl,
		     st->have_za ? re_con_cmd_text(st->za.jcmd) : "-", moving);
	board_keys(c, st, width);
}

/* The board of @n lines (@text) on the bottom of a screen of @rows, the
 * lines above it the scroll region. A taller board first scrolls the
 * text up by the lines it takes (LFs from the text cursor, then back up),
 * so that nothing written there is overwritten; a shorter one clears the
 * lines it gives back. The text cursor is saved and restored around it. */
/* Visible characters of @len bytes of @text (colour sequences skipped). */
static int vis_len(const char *text, size_t len)
{
	int vis = 0;

	for (size_t i = 0; i < len; i++) {
		if (text[i] != '\033') {
			vis++;
			continue;
		}
		while (i < len && text[i] != 'm')
			i++;
	}
	return vis;
}

/* Screen rows the lines of @text take on a terminal @width wide. */
static int board_rows(const char *text, int width)
{
	int n = 0;

	for (const char *e; (e = strchr(text, '\n')); text = e + 1)
		n += rows_of(vis_len(text, (size_t)(e - text)), width);
	return n;
}

static void board_place(struct re_console *c, const char *text, int n, int rows)
{
	int old = c->board_lines, top = rows - n + 1;

	if (c->half)
		frame_add(c, "\0338");
	for (int k = old; k < n; k++)
		frame_add(c, "\n");
	if (n > old)
		frame_add(c, "\033[%dA", n - old);
	frame_add(c, "\0337");
	if (n != old || c->redo)
		frame_add(c, "\033[1;%dr", top - 1);
	for (int r = rows - old + 1; r < top; r++)
		frame_add(c, "\033[%d;1H\033[2K", r);
	for (int r = top; r <= rows; r++)
		frame_add(c, "\033[%d;1H\033[2K", r);
	/* a line wider than the screen (a path, whole) wraps on by itself
	 * into the rows counted for it */
	for (int r = top; *text; text = strchr(text, '\n') + 1) {
		const char *e = strchr(text, '\n');

		frame_add(c, "\033[%d;1H%.*s", r, (int)(e - text), text);
		r += rows_of(vis_len(text, (size_t)(e - text)), c->cols);
	}
	frame_add(c, "\0338");
}

static void board_draw(struct re_console *c, const struct re_status *st,
		       int width, int rows)
{
	size_t start = c->frame_len, len, sent; /* a resize's reset first */
	int n;

	board_build(c, st, width, rows);
	len = c->frame_len - start;
	memcpy(c->lines, c->frame + start, len);
	c->lines[len] = '\0';
	n = board_rows(c->lines, width);
	c->frame_len = start;
	board_place(c, c->lines, n, rows);
	len = c->frame_len;
	sent = frame_send(c);
	/* cut short: the saved cursor is restored first next time, and the
	 * scroll region set again */
	c->half = sent > 0 && sent < len;
	c->redo = sent < len;
	c->board_lines = sent > 0 ? n : c->board_lines;
}

/* The board off the screen for good (too small a terminal, quitting):
 * the scroll region back to the whole screen, the board's lines cleared,
 * the cursor where the text flows. */
static void board_remove(struct re_console *c, FILE *out)
{
	if (!c->board_lines && !c->half)
		return;
	fprintf(out, "%s\0337\033[r\033[%d;1H\033[J\0338",
		c->half ? "\0338" : "", c->rows - c->board_lines + 1);
	fflush(out);
	c->board_lines = 0;
	c->half = 0;
	c->redo = 0;
}

/* Board or status lines for this terminal: too small a terminal gets the
 * lines (said once); a resize redraws the board from the top. */
static int board_fits(struct re_console *c, int *width, int *height)
{
	int cols, rows;

	term_size(c, &cols, &rows);
	*width = cols;
	*height = rows;
	if (cols < RE_CONSOLE_MIN_COLS || rows < RE_CONSOLE_MIN_ROWS) {
		if (!c->small_said++)
			re_console_msg(
			    c,
			    "roboelf: the terminal is %dx%d, smaller "
			    "than %dx%d: the status is shown as "
			    "lines",
			    cols, rows, RE_CONSOLE_MIN_COLS,
			    RE_CONSOLE_MIN_ROWS);
		board_remove(c, c->out);
		return 0;
	}
	if ((cols != c->cols || rows != c->rows) && c->board_lines) {
		/* a resize: the whole screen again, the board from scratch */
		frame_add(c, "%s\033[r\033[H\033[2J", c->half ? "\0338" : "");
		c->board_lines = 0;
		c->half = 0;
	}
	c->cols = cols;
	c->rows = rows;
	c->small_said = 0;
	return 1;
}

int re_console_due(const struct re_console *c, int64_t now_ns)
{
	int64_t gap = c->tty_out ? RE_CONSOLE_BOARD_NS : RE_CONSOLE_LINE_NS;

	return !c->last_draw_ns || now_ns - c->last_draw_ns >= gap;
}

void re_console_status(struct re_console *c, const struct re_status *st,
		       int64_t now_ns, int force)
{
	char line[1024];
	int width = 80, height = 24;

	if (!force && !re_console_due(c, now_ns))
		return;
	c->last_draw_ns = now_ns;
	if (c->tty_out && board_fits(c, &width, &height)) {
		board_draw(c, st, width, height);
		return;
	}
	re_console_format_line(st, line, sizeof(line));
	if (c->tty_out)
		frame_line(c, line, width); /* never wraps on a terminal */
	else
		frame_add(c, "%s\n", line);
	frame_send(c);
}

void re_console_units(struct re_console *c, int axis, const char *unit,
		      double counts_per_unit)
{
	if (axis < 0 || axis >= RE_SUPER_AXES)
		return;
	snprintf(c->ax[axis].unit, sizeof(c->ax[axis].unit), "%s",
		 unit ? unit : "");
	c->ax[axis].per_unit = counts_per_unit > 0 ? counts_per_unit : 0;
}

void re_console_calib(struct re_console *c, const struct re_calib_progress *p)
{
	if (p && p->active)
		c->cal = *p;
	else
		memset(&c->cal, 0, sizeof(c->cal));
}

void re_console_counts(struct re_console *c, int on)
{
	c->counts = !!on;
}

int re_console_render(struct re_console *c, const struct re_status *st,
		      int cols, int rows, char *buf, size_t cap)
{
	int color = c->color, lines;

	if (cols < RE_CONSOLE_MIN_COLS || rows < RE_CONSOLE_MIN_ROWS)
		return -1;
	c->color = 0;
	c->frame_len = 0;
	board_build(c, st, cols, rows);
	lines = count_lines(c->frame, c->frame_len);
	if (cap)
		snprintf(buf, cap, "%.*s", (int)c->frame_len, c->frame);
	c->frame_len = 0;
	c->color = color;
	return lines;
}

/* ---- questions ------------------------------------------------------------
 */

/* Read one answer line from the keyboard (cooked mode). */
static int read_answer(struct re_console *c, char *buf, size_t cap)
{
	size_t n = 0;
	char ch;

	while (n + 1 < cap) {
		ssize_t r = read(c->in_fd, &ch, 1);

		if (r <= 0)
			return n ? (int)n : -1;
		if (ch == '\n')
			break;
		buf[n++] = (char)tolower((unsigned char)ch);
	}
	buf[n] = '\0';
	while (n > 0 && isspace((unsigned char)buf[n - 1]))
		buf[--n] = '\0';
	return (int)n;
}

static enum re_calib_choice ask_calibration(struct re_console *c)
{
	char a[32];

	for (;;) {
		re_console_msg(c, "Calibration: [f]ull (move every axis "
				  "end to end) or [l]oad from file?");
		if (read_answer(c, a, sizeof(a)) < 0)
			return RE_CALIB_ASK;
		if (!strcmp(a, "f") || !strcmp(a, "full"))
			return RE_CALIB_FULL;
		if (!strcmp(a, "l") || !strcmp(a, "load") || !strcmp(a, "file"))
			return RE_CALIB_FILE;
		re_console_msg(c, "invalid answer '%s': type f or l", a);
	}
}

enum re_calib_choice re_console_ask_calibration(struct re_console *c)
{
	enum re_calib_choice k;

	if (!c->tty_in)
		return RE_CALIB_ASK;
	re_console_flush_keys(c);
	re_console_echo(c, 1);
	k = ask_calibration(c);
	re_console_echo(c, 0);
	return k;
}

static int ask_yes(struct re_console *c, const char *question)
{
	char a[32];

	for (;;) {
		re_console_msg(c, "%s [y/n]", question);
		if (read_answer(c, a, sizeof(a)) < 0)
			return 0;
		if (!strcmp(a, "y") || !strcmp(a, "yes"))
			return 1;
		if (!strcmp(a, "n") || !strcmp(a, "no"))
			return 0;
		re_console_msg(c, "invalid answer '%s': type y or n", a);
	}
}

int re_console_ask_yes(struct re_console *c, const char *question)
{
	int yes;

	if (!c->tty_in)
		return 0;
	re_console_flush_keys(c);
	re_console_echo(c, 1);
	yes = ask_yes(c, question);
	re_console_echo(c, 0);
	return yes;
}
