/*
 * test_re_console.c - the periodic status output never blocks the
 * supervisor's loop: with its reader stalled (a full pipe) every status
 * frame returns at once and is counted as dropped; once the reader drains,
 * frames arrive whole again. Also the one-line format without a terminal.
 */
#include <errno.h>
#include <fcntl.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_clock.h"
#include "re_console.h"

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
	assert_string_equal(l, "ax     position   |soft  limits|   pot V expect "
			       "margin    speed state   lim mot");
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "A    -12.35 deg [-|----#-------|-] 2.500     -"
			       "      -   -1.5/s stopped -   on");
	line_of(buf, 3, l, sizeof(l));
	assert_string_equal(l, "B     49.00 deg [-|------------#-] 2.500     -"
			       "      -    0.0/s at-lim  sF  on");
	line_of(buf, 4, l, sizeof(l));
	assert_string_equal(l, "C    -52.00 mm  [#|------------|-] 2.500     -"
			       "      -    0.0/s at-lim  sR  on");
	re_console_counts(&c, 1);
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "A    -12345 cnt [-|----#-------|-] 2.500     -"
			       "      -  -1500/s stopped -   on");
	re_console_counts(&c, 0);
	re_console_units(&c, 0, "deg", 0); /* scale not known: counts */
	st.axis[0].have_soft = 0;	     /* not calibrated: '?' */
	st.axis[0].pos_pct = -1;
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "A    -12345 cnt [????????????????] 2.500     -"
			       "      -  -1500/s stopped -   on");
	st.link_ok = 0; /* the last values, marked */
	re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	line_of(buf, 3, l, sizeof(l));
	assert_string_equal(l, "B     49.00 deg [-|------------#-] 2.500     -"
			       "      -    0.0/s STALE   sF  on");
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
	event(&c, 1.5, RE_LOG_WARN, RE_EV_WATCHDOG, "watchdog: reply after 80 ms");
	event(&c, 1.6, RE_LOG_WARN, RE_EV_WATCHDOG, "watchdog: reply after 90 ms");
	c.fault[0] = '\0';
	snprintf(c.fault, sizeof(c.fault), "FAULT COMM: the link is gone. "
					   "Recovery: restart roboelf");
	event(&c, 4.25, RE_LOG_FAULT, RE_EV_LATER, "FAULT ESTOP: relay lost");
	n = re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	assert_int_equal(n, 12);
	line_of(buf, 1, l, sizeof(l));
	assert_string_equal(l, "FAULT COMM: the link is gone. Recovery: restart "
			       "roboelf");
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "    4.2 s later FAULT: FAULT ESTOP: relay lost");
	line_of(buf, 3, l, sizeof(l));
	assert_string_equal(l, "    1.6 s WARN (x2): watchdog: reply after 90 "
			       "ms");
	line_of(buf, 4, l, sizeof(l));
	assert_string_equal(l, "every fault and warning is in the log "
			       "/var/log/roboelf.log");
	for (int i = 0; i < 10; i++)
		event(&c, 5 + i, RE_LOG_WARN, RE_EV_OTHER, "x");
	/* 24 rows: 4 kept for messages and 1 spare; header, the fault's one
	 * line, column header, 3 axes and 3 lines: 9; the history gets 10:
	 * the 9 newest (of 12) and the log line */
	n = re_console_render(&c, &st, 80, 24, buf, sizeof(buf));
	assert_int_equal(n, 19);
	line_of(buf, 2, l, sizeof(l));
	assert_string_equal(l, "   14.0 s WARN: x");
	line_of(buf, 10, l, sizeof(l));
	assert_string_equal(l, "    6.0 s WARN: x");
	line_of(buf, 11, l, sizeof(l));
	assert_string_equal(l, "3 older not shown; all in the log "
			       "/var/log/roboelf.log");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_status_words),
	    cmocka_unit_test(test_units_and_bar),
	    cmocka_unit_test(test_history),
	    cmocka_unit_test(test_stalled_reader_never_blocks),
	    cmocka_unit_test(test_regular_file_appends),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
