/*
 * test_re_console.c - the periodic status output never blocks the
 * supervisor's loop: with its reader stalled (a full pipe) every status
 * frame returns at once and is counted as dropped; once the reader drains,
 * frames arrive whole again. Also the one-line format without a terminal,
 * the board's texts (snapshots in tests/data/console/), the history's time
 * stamps, and the terminal's echo on a pseudo-terminal.
 */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_clock.h"
#include "re_console.h"
#include "re_fault.h"

static int64_t mono_ns(void)
{
	return base_now_ns();
}

/* Fill the pipe until the kernel refuses more; return the bytes written. */
static size_t fill_pipe(int wfd)
{
	static const char junk[4096];
	int fl = fcntl(wfd, F_GETFL);
	size_t total = 0;
	ssize_t n;

	fcntl(wfd, F_SETFL, fl | O_NONBLOCK);
	while ((n = write(wfd, junk, sizeof(junk))) > 0)
		total += (size_t)n;
	assert_int_equal(errno, EAGAIN);
	fcntl(wfd, F_SETFL, fl); /* the console's FILE stays blocking */
	return total;
}

static void drain_pipe(int rfd, size_t n)
{
	static char buf[4096];

	while (n > 0) {
		ssize_t r = read(rfd, buf, n < sizeof(buf) ? n : sizeof(buf));

		assert_true(r > 0);
		n -= (size_t)r;
	}
}

static void status_of(struct re_status *st)
{
	static const char *names[] = {"A", "B", "C"};

	memset(st, 0, sizeof(*st));
	st->n_axes = 3;
	for (int i = 0; i < 3; i++) {
		st->axis_names[i] = names[i];
		st->axis[i].enc_counts = 1000 * (i + 1);
	}
	st->mode_name = "development";
	st->relay = RE_RELAY_ON;
	st->link_ok = 1;
}

static void test_stalled_reader_never_blocks(void **state)
{
	static struct re_console c;
	struct re_status st;
	int p[2];
	FILE *out;
	size_t filled;
	int64_t t0, took_ns;
	char buf[1024];
	ssize_t n;

	(void)state;
	assert_int_equal(pipe(p), 0);
	out = fdopen(p[1], "w");
	assert_non_null(out);
	assert_int_equal(re_console_open(&c, out, -1), 0);
	assert_true(c.nb_fd >= 0);
	assert_int_equal(c.tty_out, 0);
	status_of(&st);
	filled = fill_pipe(p[1]);

	t0 = mono_ns();
	for (int i = 0; i < 50; i++)
		re_console_status(&c, &st, 0, 1);
	took_ns = mono_ns() - t0;
	/* a blocked write would never return: the 50 frames take
	 * microseconds; 500 ms is a generous bound for a busy machine */
	assert_true(took_ns < 500000000LL);
	assert_int_equal(c.dropped, 50);

	drain_pipe(p[0], filled);
	re_console_status(&c, &st, 0, 1);
	assert_int_equal(c.dropped, 50);
	n = read(p[0], buf, sizeof(buf) - 1);
	assert_true(n > 0);
	buf[n] = '\0';
	assert_non_null(strstr(buf, "status 0.0s mode=development relay=on "
				    "link=ok"));
	assert_non_null(strstr(buf, " B enc=2000 "));
	assert_int_equal(buf[n - 1], '\n');

	re_console_close(&c);
	assert_int_equal(c.nb_fd, -1);
	fclose(out);
	close(p[0]);
}

/* re_console_due() says when re_console_status() draws: at once, then once
 * per RE_CONSOLE_LINE_NS without a terminal (the caller fills the status
 * only then). */
static void test_status_due(void **state)
{
	static struct re_console c;
	struct re_status st;
	int p[2];
	FILE *out;
	char buf[4096];
	ssize_t n;
	int lines = 0;

	(void)state;
	assert_int_equal(pipe(p), 0);
	out = fdopen(p[1], "w");
	assert_non_null(out);
	assert_int_equal(re_console_open(&c, out, -1), 0);
	status_of(&st);
	assert_int_equal(re_console_due(&c, 5), 1);
	re_console_status(&c, &st, 5, 0);
	assert_int_equal(c.last_draw_ns, 5);
	assert_int_equal(re_console_due(&c, 5 + RE_CONSOLE_LINE_NS - 1), 0);
	re_console_status(&c, &st, 5 + RE_CONSOLE_LINE_NS - 1, 0);
	assert_int_equal(c.last_draw_ns, 5); /* not drawn */
	assert_int_equal(re_console_due(&c, 5 + RE_CONSOLE_LINE_NS), 1);
	re_console_status(&c, &st, 5 + RE_CONSOLE_LINE_NS, 0);
	assert_int_equal(c.last_draw_ns, 5 + RE_CONSOLE_LINE_NS);
	re_console_close(&c);
	fclose(out);
	n = read(p[0], buf, sizeof(buf) - 1);
	assert_true(n > 0);
	buf[n] = '\0';
	for (char *q = strstr(buf, "status "); q; q = strstr(q + 1, "status "))
		lines++;
	assert_int_equal(lines, 2);
	close(p[0]);
}

/* A regular file is never reopened (that would write from its start): the
 * frames go through the FILE and append after what is there. */
static void test_regular_file_appends(void **state)
{
	static struct re_console c;
	struct re_status st;
	char path[] = "/tmp/roboelf-console.XXXXXX", buf[2048];
	int fd = mkstemp(path);
	FILE *out;
	ssize_t n;

	(void)state;
	assert_true(fd >= 0);
	out = fdopen(fd, "w");
	assert_non_null(out);
	fputs("before\n", out);
	assert_int_equal(re_console_open(&c, out, -1), 0);
	assert_int_equal(c.nb_fd, -1);
	status_of(&st);
	re_console_status(&c, &st, 0, 1);
	re_console_close(&c);
	fclose(out);
	fd = open(path, O_RDONLY);
	assert_true(fd >= 0);
	n = read(fd, buf, sizeof(buf) - 1);
	close(fd);
	unlink(path);
	assert_true(n > 0);
	buf[n] = '\0';
	assert_int_equal(
	    strncmp(buf, "before\nstatus 0.0s mode=development", 35), 0);
	assert_int_equal(c.dropped, 0);
}

/* The words of the status line: an axis standing at its forward soft
 * limit (its tracking profiler still busy) is "at-lim" with "lim=sF", not
 * "moving"; the controller's latched fault in words. */
static void test_status_words(void **state)
{
	struct re_status st;
	char line[1024];

	(void)state;
	status_of(&st);
	st.axis[0].pos_pct = 100;
	st.axis[0].moving = 1;
	st.axis[1].pos_pct = 0.2;
	st.axis[2].pos_pct = 50;
	st.axis[2].moving = 1;
	st.axis[2].vel_cps = 900;
	st.have_za = 1;
	st.za.state = RE_DMC_FAULT;
	st.za.fcode = RE_DMC_F_ENCODER;
	st.za.faxis = 2;
	re_console_format_line(&st, line, sizeof(line));
	assert_non_null(strstr(line, " A enc=1000 pot=0.000V vel=0 at-lim "
				     "lim=sF "));
	assert_non_null(strstr(line, " B enc=2000 pot=0.000V vel=0 at-lim "
				     "lim=sR "));
	assert_non_null(strstr(line, " C enc=3000 pot=0.000V vel=900 moving "
				     "lim=- "));
	assert_non_null(strstr(line, "ctrl=\"FAULT ENCODER axis B (code "
				     "9)\""));
	/* armed with a command held since arming (mneut 0): release it */
	st.za = (struct re_za){.state = RE_DMC_ARMED, .jcmd = 1};
	re_console_format_line(&st, line, sizeof(line));
	assert_non_null(strstr(line, "ctrl=\"armed, release the joystick\""));
	st.za.mneut = 1;
	re_console_format_line(&st, line, sizeof(line));
	assert_non_null(strstr(line, "ctrl=\"armed\""));
	st.za = (struct re_za){.state = RE_DMC_ARMED}; /* before thread 1 */
	re_console_format_line(&st, line, sizeof(line));
	assert_non_null(strstr(line, "ctrl=\"armed\""));
	/* the program's fault that the supervisor's own stop caused (it
	 * found A off after B's fault had switched every motor off): said
	 * as such, never as a motor-off fault on A */
	st.za = (struct re_za){
	    .state = RE_DMC_FAULT, .fcode = RE_DMC_F_MOTOROFF, .faxis = 1};
	st.ctrl_ours = 1;
	re_console_format_line(&st, line, sizeof(line));
	assert_non_null(
	    strstr(line, "ctrl=\"stopped by the supervisor (code 10)\""));
	assert_null(strstr(line, "axis A"));
}

/* Line @n (0-based) of @text into @out (without its newline). */
static void line_of(const char *text, int n, char *out, size_t cap)
{
	const char *e;

	while (n-- > 0 && (text = strchr(text, '\n')) != NULL)
		text++;
	assert_non_null(text);
	e = strchr(text, '\n');
	assert_non_null(e);
	snprintf(out, cap, "%.*s", (int)(e - text), text);
}

/* Three calibrated axes, soft limits -49000..49000 counts, shown in deg
 * (A, B) and mm (C) at 1000 counts per unit. */
static void calibrated(struct re_console *c, struct re_status *st)
{
	status_of(st);
	for (int i = 0; i < 3; i++) {
		struct re_axis_status *a = &st->axis[i];

		a->have_soft = 1;
		a->soft_rev_counts = -49000;
		a->soft_fwd_counts = 49000;
		a->pos_pct = 50;
		a->pot_v = 2.5;
	}
	re_console_units(c, 0, "deg", 1000);
	re_console_units(c, 1, "deg", 1000);
	re_console_units(c, 2, "mm", 1000);
}

/* Positions in the robot's units, the bar with the soft limits '|' and the
 * position '#' (beyond a soft limit past its mark), counts on request and
 * where the scale is not known, '?' without a calibration. */
static void test_units_and_bar(void **state)
{
	static struct re_console c;
	static char buf[RE_CONSOLE_FRAME];
	struct re_status st;
	char l[256];

	(void)state;
	re_console_open(&c, stdout, -1);
	calibrated(&c, &st);
	st.axis[0].enc_counts = -12345;
	st.axis[0].vel_cps = -1500;
	st.axis[1].enc_counts = 49000;
	st.axis[1].pos_pct = 100;
	st.axis[2].enc_counts = -52000; /* past the reverse soft limit */
	st.axis[2].pos_pct = 0;
	assert_int_equal(re_console_render(&c, &st, 80, 24, buf, sizeof(buf)),
			 8);
	line_of(buf, 1, l, sizeof(l));
	assert_string_equal(l,
			    "ax     position   |soft  limits|   pot V expect "
			    "margin       speed state   lim");
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "A    -12.35 deg [-|----#-------|-] 2.500     -"
			       "      -  -1.5 deg/s stopped -");
	line_of(buf, 3, l, sizeof(l));
	assert_string_equal(l, "B     49.00 deg [-|------------#-] 2.500     -"
			       "      -   0.0 deg/s at-lim  sF");
	line_of(buf, 4, l, sizeof(l));
	assert_string_equal(l, "C    -52.00 mm  [#|------------|-] 2.500     -"
			       "      -   0.0 mm/s  at-lim  sR");
	/* a speed that rounds to zero is never "-0.0" */
	st.axis[2].vel_cps = -40;
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 4, l, sizeof(l));
	assert_string_equal(l, "C    -52.00 mm  [#|------------|-] 2.500     -"
			       "      -   0.0 mm/s  at-lim  sR");
	re_console_counts(&c, 1);
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "A    -12345 cnt [-|----#-------|-] 2.500     -"
			       "      - -1500 cnt/s stopped -");
	st.axis[2].vel_cps = -0.4; /* counts: never "-0" */
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 4, l, sizeof(l));
	assert_string_equal(l, "C    -52000 cnt [#|------------|-] 2.500     -"
			       "      -     0 cnt/s at-lim  sR");
	re_console_counts(&c, 0);
	re_console_units(&c, 0, "deg", 0); /* scale not known: counts */
	st.axis[0].have_soft = 0;	   /* not calibrated: '?' */
	st.axis[0].pos_pct = -1;
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "A    -12345 cnt [????????????????] 2.500     -"
			       "      - -1500 cnt/s stopped -");
	st.link_ok = 0; /* the last values, marked */
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 3, l, sizeof(l));
	assert_string_equal(l, "B     49.00 deg [-|------------#-] 2.500     -"
			       "      -   0.0 deg/s STALE   sF");
}

static void event(struct re_console *c, double t, enum re_log_level lvl,
		  enum re_event_kind kind, const char *text)
{
	struct re_event ev;

	memset(&ev, 0, sizeof(ev));
	ev.t_s = t;
	ev.level = lvl;
	ev.kind = kind;
	snprintf(ev.text, sizeof(ev.text), "%s", text);
	re_console_event(c, &ev);
}

/* The first FAULT stays under the header; below it the later faults and
 * warnings newest first (repeats of one kind folded, with a count), as
 * many as fit, and the log's path. */
static void test_history(void **state)
{
	static struct re_console c;
	static char buf[RE_CONSOLE_FRAME];
	struct re_status st;
	char l[256];
	int n;

	(void)state;
	re_console_open(&c, stdout, -1);
	c.tty_out = 1; /* the board's history, not printed lines */
	calibrated(&c, &st);
	re_console_log_path(&c, "/var/log/roboelf.log");
	event(&c, 1.5, RE_LOG_WARN, RE_EV_WATCHDOG,
	      "watchdog: reply after 80 ms");
	event(&c, 1.6, RE_LOG_WARN, RE_EV_WATCHDOG,
	      "watchdog: reply after 90 ms");
	c.fault[0] = '\0';
	snprintf(c.fault, sizeof(c.fault),
		 "FAULT COMM: the link is gone. "
		 "Recovery: restart roboelf");
	event(&c, 4.25, RE_LOG_FAULT, RE_EV_LATER, "FAULT ESTOP: relay lost");
	n = re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	assert_int_equal(n, 13);
	line_of(buf, 1, l, sizeof(l));
	assert_string_equal(l,
			    "FAULT COMM: the link is gone. Recovery: restart "
			    "roboelf");
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "[up    4.250 s] later FAULT ESTOP: relay lost");
	line_of(buf, 3, l, sizeof(l));
	assert_string_equal(l, "[up    1.600 s] WARN (x2): watchdog: reply "
			       "after 90 ms");
	line_of(buf, 4, l, sizeof(l));
	assert_string_equal(l, "every fault and warning is in the log:");
	line_of(buf, 5, l, sizeof(l)); /* whole, on its own: copied */
	assert_string_equal(l, "/var/log/roboelf.log");
	for (int i = 0; i < 10; i++)
		event(&c, 5 + i, RE_LOG_WARN, RE_EV_OTHER, "x");
	/* 24 rows: 4 kept for messages and 1 spare; header, the fault's one
	 * line, column header, 3 axes and 3 lines: 9; the history gets 10:
	 * the 8 newest (of 12) and the log's two lines */
	n = re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	assert_int_equal(n, 19);
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "[up   14.000 s] WARN: x");
	line_of(buf, 9, l, sizeof(l));
	assert_string_equal(l, "[up    7.000 s] WARN: x");
	line_of(buf, 10, l, sizeof(l));
	assert_string_equal(l, "4 older not shown; all in the log:");
	line_of(buf, 11, l, sizeof(l));
	assert_string_equal(l, "/var/log/roboelf.log");
}

/* A later fault 46 ms after the first, 12.1 s after the start: its line
 * says when it happened on the header's "up" clock, to the millisecond,
 * and nothing reads as "12.1 s after the first fault"; two entries 46 ms
 * apart are told apart. A FAULT line given without its time says so. */
static void test_history_times(void **state)
{
	static struct re_console c;
	static char buf[RE_CONSOLE_FRAME];
	struct re_status st;
	char l[256];
	FILE *devnull = fopen("/dev/null", "w");

	(void)state;
	assert_non_null(devnull);
	re_console_open(&c, devnull, -1);
	c.tty_out = 1;
	calibrated(&c, &st);
	st.uptime_s = 12.2;
	re_console_fault(&c, "FAULT ENCODER: axis A: it slipped. Recovery: "
			     "restart roboelf");
	event(&c, 12.054, RE_LOG_WARN, RE_EV_WATCHDOG,
	      "watchdog: reply after 80.2 ms");
	event(&c, 12.1, RE_LOG_FAULT, RE_EV_LATER,
	      "FAULT ESTOP: the E-stop relay stopped answering");
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 0, l, sizeof(l));
	assert_string_equal(l, "RoboELF  mode development  up 12 s  relay ON  "
			       "link ok");
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "[up   12.100 s] later FAULT ESTOP: the E-stop "
			       "relay stopped answering");
	line_of(buf, 3, l, sizeof(l));
	assert_string_equal(l, "[up   12.054 s] WARN: watchdog: reply after "
			       "80.2 ms");
	re_console_fault(&c, "FAULT COMM: the link is gone. Recovery: restart "
			     "roboelf");
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "[up        ? s] later FAULT COMM: the link is "
			       "gone. Recovery: restart roboelf");
	line_of(buf, 3, l, sizeof(l));
	assert_string_equal(l, "[up   12.100 s] later FAULT ESTOP: the E-stop "
			       "relay stopped answering");
	fclose(devnull);
}

/* Over the record stream the first line gives the share of records lost
 * since the stream opened; polling, or no record yet, nothing. */
static void test_stream_loss_shown(void **state)
{
	static struct re_console c;
	static char buf[RE_CONSOLE_FRAME];
	struct re_status st;
	char l[256];
	FILE *devnull = fopen("/dev/null", "w");

	(void)state;
	assert_non_null(devnull);
	re_console_open(&c, devnull, -1);
	c.tty_out = 1;
	calibrated(&c, &st);
	st.uptime_s = 42;
	st.stream = 1;
	st.stream_records = 9998;
	st.stream_lost = 2;
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 0, l, sizeof(l));
	assert_string_equal(l, "RoboELF  mode development  up 42 s  relay ON  "
			       "link ok, records lost 0.02 %");
	st.stream_records = 0;
	st.stream_lost = 0;
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 0, l, sizeof(l));
	assert_string_equal(l, "RoboELF  mode development  up 42 s  relay ON  "
			       "link ok");
	st.stream = 0;
	st.stream_records = 100;
	st.stream_lost = 100;
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 0, l, sizeof(l));
	assert_string_equal(l, "RoboELF  mode development  up 42 s  relay ON  "
			       "link ok");
	fclose(devnull);
}

/* Without a terminal, each later fault or warning is one line. */
static void test_event_lines(void **state)
{
	static struct re_console c;
	char buf[512];
	FILE *f = tmpfile();
	size_t n;

	(void)state;
	assert_non_null(f);
	re_console_open(&c, f, -1);
	assert_int_equal(c.tty_out, 0);
	event(&c, 2.0, RE_LOG_WARN, RE_EV_FOREIGN,
	      "another program connected to the controller (handle C)");
	event(&c, 3.0, RE_LOG_FAULT, RE_EV_LATER, "FAULT ESTOP: relay lost");
	rewind(f);
	n = fread(buf, 1, sizeof(buf) - 1, f);
	buf[n] = '\0';
	fclose(f);
	assert_string_equal(buf, "roboelf: warning: another program connected "
				 "to the controller (handle C)\n"
				 "roboelf: later FAULT ESTOP: relay lost\n");
	assert_int_equal(c.nhist, 2);
}

/* ---- the terminal's echo, on a pseudo-terminal -------------------------
 *
 * The test holds the master side (what a terminal emulator would show:
 * everything roboelf writes, and the terminal's echo of the keys typed)
 * and types there; the console has the slave as its keyboard and output.
 */

/* What the terminal shows within @ms of quiet, NUL-terminated. */
static size_t pty_shown(int m, char *buf, size_t cap, int ms)
{
	struct pollfd p = {.fd = m, .events = POLLIN};
	size_t n = 0;
	ssize_t r;

	while (n + 1 < cap && poll(&p, 1, ms) > 0) {
		r = read(m, buf + n, cap - 1 - n);
		if (r <= 0)
			break;
		n += (size_t)r;
	}
	buf[n] = '\0';
	return n;
}

/* The typist: waits until the question is on the screen, answers "y",
 * and checks that the answer is echoed. Exit 0 when it saw exactly that. */
static void typist(int m)
{
	char buf[256] = "";
	size_t n = 0;

	while (!strstr(buf, "[y/n]\r\n") &&
	       pty_shown(m, buf + n, sizeof(buf) - n, 5000) > 0)
		n = strlen(buf);
	if (strcmp(buf, "Go on? [y/n]\r\n") || write(m, "y\n", 2) != 2)
		_exit(1);
	pty_shown(m, buf, sizeof(buf), 500);
	_exit(strcmp(buf, "y\r\n") ? 2 : 0);
}

/* The settings that count (a struct termios has padding). */
static void assert_same_termios(const struct termios *a,
				const struct termios *b)
{
	assert_int_equal(a->c_iflag, b->c_iflag);
	assert_int_equal(a->c_oflag, b->c_oflag);
	assert_int_equal(a->c_cflag, b->c_cflag);
	assert_int_equal(a->c_lflag, b->c_lflag);
	assert_memory_equal(a->c_cc, b->c_cc, sizeof(a->c_cc));
	assert_int_equal(cfgetispeed(a), cfgetispeed(b));
	assert_int_equal(cfgetospeed(a), cfgetospeed(b));
}

/* Quiet: a key typed during the start-up or the calibration is not
 * echoed (nothing else of the terminal changes); a question's answer is
 * echoed while it is asked, and quiet again after it; raw mode takes over
 * from quiet; the close gives the terminal back exactly as it was. */
static void test_quiet_no_echo(void **state)
{
	static struct re_console c;
	struct termios before, t;
	char buf[256];
	int m, s, st = -1;
	pid_t pid;
	FILE *out;

	(void)state;
	assert_int_equal(openpty(&m, &s, NULL, NULL, NULL), 0);
	assert_int_equal(tcgetattr(s, &before), 0);
	assert_true(before.c_lflag & ECHO);
	out = fdopen(dup(s), "w");
	assert_non_null(out);
	re_console_open(&c, out, s);
	assert_int_equal(c.tty_in, 1);
	re_console_quiet(&c);
	assert_int_equal(tcgetattr(s, &t), 0);
	assert_int_equal(t.c_lflag & (ECHO | ECHONL), 0);
	t.c_lflag |= before.c_lflag & (ECHO | ECHONL);
	assert_same_termios(&t, &before);      /* only the echo */
	assert_int_equal(write(m, "a", 1), 1); /* during calibration */
	assert_int_equal(pty_shown(m, buf, sizeof(buf), 200), 0);

	alarm(20); /* a lost answer must fail the test, not hang it */
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0)
		typist(m);
	assert_int_equal(re_console_ask_yes(&c, "Go on?"), 1);
	assert_int_equal(waitpid(pid, &st, 0), pid);
	alarm(0);
	assert_true(WIFEXITED(st));
	assert_int_equal(WEXITSTATUS(st), 0);
	assert_int_equal(tcgetattr(s, &t), 0);
	assert_int_equal(t.c_lflag & ECHO, 0); /* quiet again */
	assert_int_equal(write(m, "b", 1), 1);
	assert_int_equal(pty_shown(m, buf, sizeof(buf), 200), 0);

	re_console_raw(&c); /* the board: from the terminal's own settings */
	assert_int_equal(tcgetattr(s, &t), 0);
	assert_int_equal(t.c_lflag & (ECHO | ICANON), 0);
	re_console_close(&c);
	assert_int_equal(tcgetattr(s, &t), 0);
	assert_same_termios(&t, &before);
	fclose(out);
	close(s);
	close(m);
}

/* ---- snapshots: the whole board at 80x24, exactly --------------------
 *
 * Each case renders the board (no colour) and compares it with
 * tests/data/console/<name>.txt byte for byte. RE_SNAPSHOT_UPDATE=1
 * rewrites the files instead (then review them with git diff).
 */

#define SNAP_DIR "tests/data/console/"

static void snapshot(struct re_console *c, const struct re_status *st,
		     const char *name)
{
	static char got[RE_CONSOLE_FRAME], want[RE_CONSOLE_FRAME];
	char path[256];
	FILE *f;
	size_t n;
	int lines = re_console_render(c, st, 80, 24, got, sizeof(got));

	assert_true(lines > 0 && lines <= 24 - 1 - RE_CONSOLE_ROOM);
	snprintf(path, sizeof(path), SNAP_DIR "%s.txt", name);
	if (getenv("RE_SNAPSHOT_UPDATE")) {
		f = fopen(path, "w");
		assert_non_null(f);
		fputs(got, f);
		fclose(f);
		return;
	}
	f = fopen(path, "r");
	if (!f)
		fail_msg("snapshot %s missing (RE_SNAPSHOT_UPDATE=1 makes it)",
			 path);
	n = fread(want, 1, sizeof(want) - 1, f);
	fclose(f);
	want[n] = '\0';
	for (int i = 0; i < lines; i++) {
		char g[256], w[256];

		line_of(got, i, g, sizeof(g));
		line_of(want, i, w, sizeof(w));
		if (strcmp(g, w))
			fail_msg("%s line %d:\n got  '%s'\n want '%s'", path,
				 i + 1, g, w);
		assert_true(strlen(g) < 80); /* never wraps */
	}
	assert_string_equal(got, want);
}

/* A robot at rest in the centre after a fault: relay off, motors off. */
static void latched_status(struct re_console *c, struct re_status *st)
{
	calibrated(c, st);
	st->uptime_s = 42.5;
	st->period_ms = 50;
	st->wd_last_ms = 50.1;
	st->wd_worst_ms = 61.2;
	st->late_last_ms = 0.2;
	st->late_worst_ms = 3.4;
	st->relay = RE_RELAY_OFF;
	st->latched = 1;
	st->have_za = 1;
	st->za.state = RE_DMC_FAULT;
	st->za.fcode = RE_DMC_F_SUPERVISOR;
	for (int i = 0; i < 3; i++) {
		struct re_axis_status *a = &st->axis[i];

		a->enc_counts = 100 * i - 100;
		a->motor_off = 1;
		a->have_expect = 1;
		a->pot_v = 2.55 + 0.001 * i;
		a->pot_expected_v = 2.55;
		a->margin_v = 0.06 - 0.001 * i;
	}
}

struct snap_case {
	const char *name;
	enum re_fault_id id;
	int axis;
	int dmc_fcode, dmc_faxis; /* the controller's own latched fault */
	int link_down;
};

/* One fault of each class, as the operator sees the board 10 s later. */
static const struct snap_case snap_cases[] = {
    {"fault-encoder", RE_F_ENCPOT, 1, RE_DMC_F_SUPERVISOR, 0, 0},
    {"fault-watchdog", RE_F_WDOG_REPLY, -1, RE_DMC_F_SUPERVISOR, 0, 1},
    {"fault-estop", RE_F_ESTOP_LOST, -1, RE_DMC_F_SUPERVISOR, 0, 0},
    {"fault-motion", RE_F_CTRL_POSERR, 0, RE_DMC_F_POSERR, 1, 0},
    {"fault-input", RE_F_CTRL_INPUT, -1, RE_DMC_F_INPUT, 0, 0},
    {"fault-comm", RE_F_COMM, -1, RE_DMC_F_SUPERVISOR, 0, 1},
    {"fault-config", RE_F_CONFIG, -1, RE_DMC_F_SUPERVISOR, 0, 0},
    {"fault-calibration", RE_F_CAL_ABORT, 2, RE_DMC_F_SUPERVISOR, 0, 0},
    {"fault-param", RE_F_CTRL_PARAM, -1, RE_DMC_F_PARAM, 0, 0},
    {"fault-limit", RE_F_CTRL_LIMIT, 2, RE_DMC_F_LIMIT, 3, 0},
    {"fault-program", RE_F_CTRL_THREAD, -1, RE_DMC_F_THREAD, 0, 0},
    {"fault-foreign", RE_F_CTRL_FOREIGN_HB, -1, RE_DMC_F_FOREIGN, 0, 0},
};

/* The values each fault's text uses (re_fault.h), fixed. */
static void snap_fault(const struct snap_case *k, struct re_fault *f)
{
	re_fault_set(f, k->id, k->axis);
	f->i[0] = 4;
	f->i[1] = 2;
	f->i[2] = 200;
	f->f[0] = 3.049;
	f->f[1] = 2.55;
	f->f[2] = 0.499;
	f->f[3] = 0.06;
	if (k->id == RE_F_ESTOP_LOST)
		snprintf(f->s, sizeof(f->s),
			 "/dev/ttyTEST0: read-back shows "
			 "channel 1 off, expected on");
	else if (k->id == RE_F_COMM)
		snprintf(f->s, sizeof(f->s), "cannot read record: timeout");
	else if (k->id == RE_F_CONFIG)
		snprintf(f->s, sizeof(f->s), "read-back of KPA differs");
	else if (k->id == RE_F_CAL_ABORT)
		snprintf(f->s, sizeof(f->s),
			 "the forward limit switch never came within 120000 "
			 "counts");
	else if (k->id == RE_F_CTRL_LIMIT)
		snprintf(f->s, sizeof(f->s), "reverse");
	if (k->id == RE_F_CTRL_LIMIT)
		f->i[0] = 3;
	if (k->id == RE_F_WDOG_REPLY) { /* ms without a reply, the limit */
		f->i[0] = 130;
		f->i[1] = 125;
	}
	if (k->id == RE_F_CTRL_POSERR)
		f->i[0] = 500;
	if (k->id == RE_F_CTRL_INPUT) /* A forward and B forward together */
		f->i[0] = 0x33;
}

/* The FAULT line as the supervisor composes it: what happened (positions
 * also in the robot's units, the configured joystick timeout), what was
 * confirmed, the recovery. */
static void snap_line(const struct re_fault *f, char *line, size_t cap)
{
	static const char *const names[] = {"A", "B", "C"};
	static const struct re_fault_units u = {
	    {"deg", "deg", "mm"}, {1000, 1000, 1000}, 500};
	char text[768], *rec;

	assert_true(re_fault_format_units(f, names, &u, text, sizeof(text)) >
		    0);
	rec = strstr(text, ". Recovery: ");
	assert_non_null(rec);
	snprintf(line, cap,
		 "%.*s. Safe state confirmed: motor power off (relay open), "
		 "motors off. %s",
		 (int)(rec - text), text, rec + 2);
}

static void test_snapshot_faults(void **state)
{
	static struct re_console c;
	struct re_status st;
	struct re_fault f;
	char line[1024];
	FILE *devnull = fopen("/dev/null", "w");

	(void)state;
	assert_non_null(devnull);
	for (size_t k = 0; k < sizeof(snap_cases) / sizeof(snap_cases[0]);
	     k++) {
		const struct snap_case *sc = &snap_cases[k];

		re_console_open(&c, devnull, -1);
		c.tty_out = 1;		     /* the board's panel and history */
		c.tty_in = 1;		     /* the keys line */
		re_console_trace_key(&c, 1); /* roboelf's recorder runs */
		re_console_log_path(&c, "/var/log/roboelf/roboelf.log");
		latched_status(&c, &st);
		st.za.fcode = sc->dmc_fcode;
		st.za.faxis = sc->dmc_faxis;
		st.link_ok = !sc->link_down;
		if (sc->id == RE_F_CTRL_LIMIT)
			st.axis[2].rev_limit = 1;
		if (sc->id == RE_F_WDOG_REPLY)
			event(&c, 30.1, RE_LOG_WARN, RE_EV_WATCHDOG,
			      "watchdog: reply after 80.2 ms (non-critical "
			      "limit 75.0 ms, critical 125.0 ms)");
		if (sc->id == RE_F_ESTOP_LOST)
			event(&c, 33.3, RE_LOG_FAULT, RE_EV_LATER,
			      "FAULT COMM: cannot read record: timeout");
		snap_fault(sc, &f);
		snap_line(&f, line, sizeof(line));
		re_console_fault(&c, line);
		snapshot(&c, &st, sc->name);
	}
	fclose(devnull);
}

/* The board in each phase: start-up (safe, no tables), the full
 * calibration, the check of the file and the move to the centre, armed
 * and driving (B forward), at a soft limit. */
static void test_snapshot_phases(void **state)
{
	static struct re_console c;
	struct re_calib_progress p;
	struct re_status st;

	(void)state;
	re_console_open(&c, stdout, -1);
	c.tty_in = 1;
	re_console_trace_key(&c, 1); /* roboelf's recorder runs */
	re_console_log_path(&c, "/var/log/roboelf/roboelf.log");
	latched_status(&c, &st);
	st.latched = 0;
	st.relay = RE_RELAY_OFF;
	st.za.state = RE_DMC_UNARMED;
	st.za.fcode = 0;
	for (int i = 0; i < 3; i++) {
		st.axis[i].have_soft = 0;
		st.axis[i].pos_pct = -1;
		st.axis[i].have_expect = 0;
	}
	snapshot(&c, &st, "phase-safe");

	memset(&p, 0, sizeof(p));
	p.active = 1;
	p.full = 1;
	p.elapsed_s = 12.2;
	p.left_s = 16.4;
	for (int i = 0; i < 3; i++) {
		p.axis[i].phase = i == 2 ? "off fwd switch" : "sweep fwd";
		p.axis[i].pct = i == 2 ? 99.4 : 31.2;
		p.axis[i].left_s = i == 2 ? 4.9 : 16.4;
		st.axis[i].motor_off = 0;
		st.axis[i].moving = 1;
		st.axis[i].vel_cps = i == 2 ? -2000 : 8000;
		st.axis[i].enc_counts = i == 2 ? 39500 : -19560;
		st.axis[i].pot_v = i == 2 ? 4.475 : 1.758;
	}
	st.relay = RE_RELAY_ON;
	st.za.state = RE_DMC_SERVICE;
	st.period_ms = 10;
	re_console_calib(&c, &p);
	snapshot(&c, &st, "phase-calibration");

	p.full = 0;
	p.elapsed_s = 1.0;
	p.left_s = 6.1;
	for (int i = 0; i < 3; i++) {
		p.axis[i].phase = "to centre";
		p.axis[i].pct = 80;
		p.axis[i].left_s = 6.1 - i;
	}
	re_console_calib(&c, &p);
	snapshot(&c, &st, "phase-file-check");

	re_console_calib(&c, NULL);
	calibrated(&c, &st);
	st.uptime_s = 61.0;
	st.period_ms = 50;
	st.wd_last_ms = 50.0;
	st.wd_worst_ms = 52.3;
	st.have_za = 1;
	st.za.state = RE_DMC_ARMED;
	st.za.jcmd = 3;
	st.za.mcmd = 3;
	st.za.mneut = 1;
	st.axis[1].moving = 1;
	st.axis[1].vel_cps = 7990;
	st.axis[1].enc_counts = 12345;
	st.axis[1].pos_pct = 62.6;
	st.axis[0].enc_counts = 49000;
	st.axis[0].pos_pct = 100;
	st.axis[0].moving = 1; /* the tracking profiler, at the limit */
	for (int i = 0; i < 3; i++) {
		st.axis[i].have_expect = 1;
		st.axis[i].pot_expected_v = st.axis[i].pot_v;
		st.axis[i].margin_v = 0.06;
	}
	snapshot(&c, &st, "phase-armed");
}

/* The per-axis state and the "moving" summary come from the same axis
 * states: an axis still running down after the joystick's release
 * (the program's command already "none") is "moving" in both; an axis
 * held against its soft limit (the command still "A fwd") is "at-lim"
 * and not in the summary. */
static void test_moving_one_source(void **state)
{
	static struct re_console c;
	static char buf[RE_CONSOLE_FRAME];
	struct re_status st;
	char l[256];

	(void)state;
	re_console_open(&c, stdout, -1);
	calibrated(&c, &st);
	st.have_za = 1;
	st.za = (struct re_za){.state = RE_DMC_ARMED, .mneut = 1};
	st.axis[1].moving = 1; /* B running down: mcmd 0 already */
	st.axis[1].vel_cps = 6800;
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 3, l, sizeof(l));
	assert_string_equal(l, "B      2.00 deg [-|------#-----|-] 2.500     -"
			       "      -   6.8 deg/s moving  -");
	line_of(buf, 6, l, sizeof(l));
	assert_string_equal(l, "controller armed  joystick none  moving B fwd");
	st.axis[1].moving = 0;
	st.axis[1].vel_cps = 0;
	st.za.jcmd = 1; /* A fwd held, A at its forward soft limit */
	st.za.mcmd = 1;
	st.axis[0].moving = 1; /* the tracking profiler stays busy there */
	st.axis[0].pos_pct = 100;
	st.axis[0].enc_counts = 49000;
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "A     49.00 deg [-|------------#-] 2.500     -"
			       "      -   0.0 deg/s at-lim  sF");
	line_of(buf, 6, l, sizeof(l));
	assert_string_equal(l, "controller armed  joystick A fwd  moving none");
	st.axis[2].moving = 1; /* two at once, one in reverse */
	st.axis[2].vel_cps = -2500;
	st.axis[1].moving = 1;
	st.axis[1].vel_cps = 900;
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 6, l, sizeof(l));
	assert_string_equal(l,
			    "controller armed  joystick A fwd  moving B fwd, "
			    "C rev");
	st.link_ok = 0; /* stale values: no summary made of them */
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 6, l, sizeof(l));
	assert_string_equal(l, "controller armed  joystick A fwd  moving -");
}

/* A key is offered only where it works: t with the flight recorder, u
 * with a unit to switch from, none without a keyboard. */
static void test_keys_offered(void **state)
{
	static struct re_console c;
	static char buf[RE_CONSOLE_FRAME];
	struct re_status st;
	char l[256];

	(void)state;
	re_console_open(&c, stdout, -1);
	calibrated(&c, &st);
	c.tty_in = 1;
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 7, l, sizeof(l));
	assert_string_equal(l, "keys: q quit  u counts"); /* no recorder */
	re_console_trace_key(&c, 1);
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 7, l, sizeof(l));
	assert_string_equal(l, "keys: q quit  t trace  u counts");
	re_console_counts(&c, 1);
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 7, l, sizeof(l));
	assert_string_equal(l, "keys: q quit  t trace  u units");
	re_console_counts(&c, 0);
	for (int i = 0; i < 3; i++) /* no scale known: counts only */
		re_console_units(&c, i, "deg", 0);
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 7, l, sizeof(l));
	assert_string_equal(l, "keys: q quit  t trace");
	c.tty_in = 0; /* the demo: roboelf's input is not a keyboard */
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 7, l, sizeof(l));
	assert_string_equal(l, "no keyboard here: Ctrl-C or SIGTERM quits");
}

#define LONG_DIR                                                               \
	"/home/operator/theatre-2/roboelf-runs/2026-11-29/"                    \
	"a-directory-with-a-rather-long-name"

/* Nothing cut, nothing split: a path wider than the terminal is printed
 * whole on a line of its own (the trace message above the board, the
 * log under the fault panel), the FAULT wrapped at word boundaries to
 * its last word. */
static void test_paths_whole(void **state)
{
	static struct re_console c;
	static char buf[RE_CONSOLE_FRAME];
	const char *path = LONG_DIR "/roboelf-trace-20261129-061500.csv";
	struct re_status st;
	char l[256], out[2048];
	FILE *f = tmpfile();
	size_t n;

	(void)state;
	assert_non_null(f);
	re_console_open(&c, f, -1);
	c.tty_out = 1; /* wrapped as on a terminal (80 wide: no size) */
	re_console_msg(&c, "roboelf: trace %s written (1200 cycles)", path);
	rewind(f);
	n = fread(out, 1, sizeof(out) - 1, f);
	out[n] = '\0';
	assert_string_equal(out, "roboelf: trace\n" LONG_DIR
				 "/roboelf-trace-20261129-061500.csv\n"
				 "  written (1200 cycles)\n");
	fclose(f);
	re_console_open(&c, stdout, -1);
	c.tty_out = 1;
	calibrated(&c, &st);
	re_console_log_path(&c, LONG_DIR "/roboelf.log");
	snprintf(c.fault, sizeof(c.fault),
		 "FAULT COMM: cannot write %s (No space left on device). "
		 "Recovery: free some space, then restart roboelf",
		 path);
	assert_int_equal(re_console_render(&c, &st, 80, 24, buf, sizeof(buf)),
			 13);
	line_of(buf, 1, l, sizeof(l));
	assert_string_equal(l, "FAULT COMM: cannot write");
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, path);
	line_of(buf, 3, l, sizeof(l));
	assert_string_equal(l, "(No space left on device). Recovery: free "
			       "some space, then restart roboelf");
	line_of(buf, 4, l, sizeof(l));
	assert_string_equal(l, "every fault and warning is in the log:");
	line_of(buf, 5, l, sizeof(l));
	assert_string_equal(l, LONG_DIR "/roboelf.log");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_status_words),
	    cmocka_unit_test(test_units_and_bar),
	    cmocka_unit_test(test_history),
	    cmocka_unit_test(test_history_times),
	    cmocka_unit_test(test_stream_loss_shown),
	    cmocka_unit_test(test_event_lines),
	    cmocka_unit_test(test_quiet_no_echo),
	    cmocka_unit_test(test_moving_one_source),
	    cmocka_unit_test(test_keys_offered),
	    cmocka_unit_test(test_paths_whole),
	    cmocka_unit_test(test_snapshot_faults),
	    cmocka_unit_test(test_snapshot_phases),
	    cmocka_unit_test(test_stalled_reader_never_blocks),
	    cmocka_unit_test(test_status_due),
	    cmocka_unit_test(test_regular_file_appends),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
