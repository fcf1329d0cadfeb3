/*
 * test_re_comm.c - the commissioning run's steps against a fake controller
 * and a fake clock (no galil-sim): what the technician does (or fails to
 * do) is played from the prompt callback; the words of each verdict, the
 * end of the run in the safe state after a link failure and after Ctrl-C,
 * what the run needs checked before any prompt, the report written whole
 * or not at all and a failed step's plot marked FAIL. The whole run against
 * galil-sim, with each miswiring, is tests/system/test_sys_comm.c.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "gl_err.h"
#include "re_comm.h"
#include "re_comm_report.h"
#include "re_comm_steps.h"
#include "re_config.h"

/* The fake world: digital inputs, limit switches, the clock, the log of
 * what the run sent. */
static struct {
	int in[49];	   /* level of digital input n */
	int lim_active[6]; /* A fwd, A rev, B fwd ... */
	int64_t now_ns;
	int broken_after; /* commands until the link breaks; -1 never */
	int stop_all, relay_off;
	int relay_gone; /* the relay's check fails */
	int press; /* the technician presses what is asked */
	volatile sig_atomic_t quit;
	int quit_on_press; /* set quit when asked to press */
} w;

static struct re_config cfg;

static int f_command(void *ud, const char *cmd, char *resp, size_t cap,
		     int timeout_ms)
{
	const char *p = cmd;
	size_t n = 0;

	(void)ud;
	(void)timeout_ms;
	if (w.broken_after == 0)
		return GL_ERR_BROKEN;
	if (w.broken_after > 0)
		w.broken_after--;
	if (!strcmp(cmd, RE_STOP_ALL))
		w.stop_all++;
	resp[0] = '\0';
	while ((p = strstr(p, "MG ")) != NULL) {
		int k;
		char ax, fr;
		double v = 0;

		p += 3;
		if (sscanf(p, "@IN[%d]", &k) == 1)
			v = w.in[k];
		else if (sscanf(p, "_L%c%c", &fr, &ax) == 2)
			v = !w.lim_active[2 * (ax - 'A') + (fr == 'R')];
		n += (size_t)snprintf(resp + n, cap - n, " %.4f\r\n", v);
	}
	return (int)n;
}

static const char *f_ctrl_error(void *ud, int *code)
{
	(void)ud;
	if (code)
		*code = 1;
	return "Unrecognized command";
}

static int f_relay_check(void *ud, char *why, size_t cap)
{
	(void)ud;
	snprintf(why, cap, "%s", w.relay_gone ? "the port is gone" : "");
	return w.relay_gone ? GL_ERR_RELAY : GL_OK;
}

static int f_relay_off(void *ud)
{
	(void)ud;
	w.relay_off++;
	return GL_OK;
}

static int64_t f_now(void *ud)
{
	(void)ud;
	return w.now_ns;
}

static void f_sleep_until(void *ud, int64_t t)
{
	(void)ud;
	if (t > w.now_ns)
		w.now_ns = t;
}

static const struct re_io_ops ops = {
    .command = f_command,
    .ctrl_error = f_ctrl_error,
    .relay_check = f_relay_check,
    .relay_off = f_relay_off,
    .now_ns = f_now,
    .sleep_until = f_sleep_until,
};
static const struct re_io io = {&ops, NULL};

/* The technician: presses (both channels, as wired) what is asked. */
static void tech_say(void *ud, const char *line)
{
	char ax, dir[8];
	int k, *in = cfg.joystick.inputs;

	(void)ud;
	if (sscanf(line, "commission: PRESS and hold the joystick %c %7s", &ax,
		   dir) == 2) {
		if (w.quit_on_press)
			w.quit = 1;
		k = 2 * (2 * (ax - 'A') + (dir[0] == 'r'));
		if (w.press) {
			w.in[in[k]] = 1;
			w.in[in[k + 1]] = 1;
		}
	} else if (!strncmp(line, "commission: RELEASE the joystick", 32)) {
		for (int i = 0; i < RE_JOY_INPUTS; i++)
			w.in[in[i]] = 0;
	}
}

static int setup(void **state)
{
	struct re_comm *c = calloc(1, sizeof(*c));

	if (!c)
		return -1;
	memset(&w, 0, sizeof(w));
	w.broken_after = -1;
	w.press = 1;
	re_config_defaults(&cfg);
	re_comm_init(c);
	c->io = &io;
	c->cfg = &cfg;
	c->ui.say = tech_say;
	c->wait_ms = 1000;
	c->quit = &w.quit;
	*state = c;
	return 0;
}

static int teardown(void **state)
{
	free(*state);
	return 0;
}

/* Every switch as wired: six PASS lines after the rest check. */
static void test_joystick_pass(void **state)
{
	struct re_comm *c = *state;

	assert_int_equal(rc_step_joystick(c), GL_OK);
	assert_null(c->failed_step);
	assert_int_equal(c->n, 7);
	assert_string_equal(c->item[3].name, "B forward");
	assert_string_equal(c->item[3].text,
			    "inputs 5 and 6 closed, nothing else");
}

/* Nobody presses: the deadline, and the words for it. */
static void test_joystick_nothing(void **state)
{
	struct re_comm *c = *state;

	w.press = 0;
	assert_int_equal(rc_step_joystick(c), GL_OK);
	assert_string_equal(c->failed_step, "joystick");
	assert_string_equal(c->item[1].text,
			    "nothing closed within 1 s of asking for A forward "
			    "(inputs 1 and 2)");
	/* the fake clock: the wait lasted the deadline, not longer */
	assert_true(w.now_ns >= 1000000000LL && w.now_ns < 1100000000LL);
}

/* One switch stuck closed at rest. */
static void test_joystick_stuck(void **state)
{
	struct re_comm *c = *state;

	w.in[18] = 1; /* C forward channel b */
	assert_int_equal(rc_step_joystick(c), GL_OK);
	assert_string_equal(c->item[0].text,
			    "with nothing pressed these read closed: input 18 "
			    "(C forward channel b)");
}

/* A limit switch active at rest. */
static void test_limits_rest(void **state)
{
	struct re_comm *c = *state;

	w.lim_active[3] = 1; /* B rev */
	assert_int_equal(rc_step_limits(c), GL_OK);
	assert_string_equal(c->failed_step, "limits");
	assert_string_equal(c->item[0].text,
			    "at rest the reverse limit switch of axis B reads "
			    "active");
}

/* The link breaks in a step: a FAIL item naming it; the run ends with
 * the stop sent (it fails too: the link is gone) and the relay off. */
static void test_link_breaks(void **state)
{
	struct re_comm *c = *state;

	w.broken_after = 0;
	assert_int_equal(re_comm_run(c), GL_ERR_BROKEN);
	assert_string_equal(c->failed_step, "needs");
	assert_int_equal(w.relay_off, 1);
	assert_string_equal(c->item[c->n - 2].name, "link");
	assert_string_equal(c->item[c->n - 1].name, "safe");
}

/* What the run needs comes first: a relay that does not answer, or no
 * program to read, stops the run at step 1 with the fix, before any
 * prompt to the technician. */
static void test_needs_first(void **state)
{
	struct re_comm *c = *state;

	w.relay_gone = 1;
	assert_int_equal(re_comm_run(c), GL_ERR_MISMATCH);
	assert_string_equal(c->failed_step, "needs");
	assert_string_equal(c->item[0].name, "relay");
	assert_string_equal(c->item[0].text,
			    "the E-stop relay does not answer: the port is "
			    "gone");
	assert_int_equal(w.stop_all, 1);
	re_comm_init(c);
	c->io = &io;
	c->cfg = &cfg;
	c->ui.say = tech_say;
	w.relay_gone = 0;
	w.quit_on_press = 1; /* a prompt would stop the run: none comes */
	assert_int_equal(re_comm_run(c), GL_ERR_MISMATCH);
	assert_int_equal(w.quit, 0);
	assert_string_equal(c->failed_step, "needs");
	assert_string_equal(c->item[2].name, "program");
	assert_string_equal(c->item[2].fix,
			    "load dmc/ with galil-load --config and the "
			    "configuration this run uses (docs/technician.md, "
			    "section 4), then run the commissioning again");
}

/* Ctrl-C while the technician is asked to press: interrupted, safe. */
static void test_interrupted(void **state)
{
	struct re_comm *c = *state;

	w.quit_on_press = 1;
	assert_int_equal(rc_step_joystick(c), GL_ERR_AGAIN);
	c->failed_step = NULL;
	w.quit = 1;
	assert_int_equal(re_comm_run(c), GL_ERR_AGAIN);
	assert_string_equal(c->item[c->n - 1].name, "interrupted");
	assert_int_equal(w.stop_all, 1);
	assert_int_equal(w.relay_off, 1);
}

static const char *slurp(const char *path)
{
	static char buf[65536];
	FILE *f = fopen(path, "r");
	size_t n;

	assert_non_null(f);
	n = fread(buf, 1, sizeof(buf) - 1, f);
	buf[n] = '\0';
	fclose(f);
	return buf;
}

/* A step that failed: its plot carries the red FAIL label with what was
 * seen, under the title, which leaves a line for it. */
static void test_plot_fail(void **state)
{
	struct re_comm *c = *state;
	struct re_comm_where where = {"127.0.0.1:23", "cfg.yaml",
				      "2026-11-25 08:00:00 UTC"};
	char dir[] = "/tmp/test_re_comm_XXXXXX", path[128], err[256];
	const char *gp;
	int plots = -1;

	w.press = 0;
	assert_non_null(mkdtemp(dir));
	assert_int_equal(rc_step_joystick(c), GL_OK);
	assert_int_equal(
	    re_comm_report(c, &where, dir, &plots, err, sizeof(err)), GL_OK);
	snprintf(path, sizeof(path), "%s/joystick.gp", dir);
	gp = slurp(path);
	if (!strstr(gp, "set label 99 \"FAIL: nothing closed within 1 s of "
			"asking for A forward (inputs 1 and 2)\" at screen "
			"0.02, screen 0.949 left tc rgb 'red' front\n"
			"set multiplot layout 1,1 title \"the joystick "
			"switches: up is closed\\n\"\n"))
		fail_msg("no FAIL label in\n%s", gp);
	assert_non_null(strstr(gp, "set label 1 'PRESS A forward' at "));
	unlink(path);
	snprintf(path, sizeof(path), "%s/joystick.png", dir);
	unlink(path);
	snprintf(path, sizeof(path), "%s/%s", dir, RE_COMM_REPORT_NAME);
	unlink(path);
	assert_int_equal(rmdir(dir), 0);
}

/* The report: whole, in the directory; an unwritable place refused with
 * the reason and nothing left behind. */
static void test_report(void **state)
{
	struct re_comm *c = *state;
	struct re_comm_where where = {"127.0.0.1:23", "cfg.yaml",
				      "2026-11-25 08:00:00 UTC"};
	char dir[] = "/tmp/test_re_comm_XXXXXX", path[128], err[256];
	char text[4096] = "";
	FILE *f;
	int plots = -1;

	assert_non_null(mkdtemp(dir));
	assert_int_equal(rc_step_joystick(c), GL_OK);
	assert_int_equal(
	    re_comm_report(c, &where, dir, &plots, err, sizeof(err)), GL_OK);
	assert_int_equal(plots, 1); /* the joystick's lanes */
	snprintf(path, sizeof(path), "%s/joystick.gp", dir);
	assert_null(strstr(slurp(path), "FAIL"));
	assert_non_null(strstr(slurp(path), "set label 12 'RELEASE' at "));
	unlink(path);
	snprintf(path, sizeof(path), "%s/joystick.png", dir);
	assert_int_equal(unlink(path), 0);
	snprintf(path, sizeof(path), "%s/%s", dir, RE_COMM_REPORT_NAME);
	f = fopen(path, "r");
	assert_non_null(f);
	assert_true(fread(text, 1, sizeof(text) - 1, f) > 0);
	fclose(f);
	assert_non_null(strstr(text, "result: PASSED: every step passed (7 "
				     "checks, 0 notes"));
	assert_non_null(strstr(text, "PASS  C reverse        inputs 19 and "
				     "20 closed, nothing else\n"));
	unlink(path);
	/* a file where the directory should be */
	snprintf(path, sizeof(path), "%s/file", dir);
	f = fopen(path, "w");
	assert_non_null(f);
	fclose(f);
	assert_int_equal(
	    re_comm_report(c, &where, path, &plots, err, sizeof(err)),
	    GL_ERR_SYS);
	assert_non_null(strstr(err, "/file/commissioning.txt': Not a "
				    "directory"));
	unlink(path);
	assert_int_equal(rmdir(dir), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_joystick_pass, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_joystick_nothing, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_joystick_stuck, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_limits_rest, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_link_breaks, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_needs_first, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_interrupted, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_report, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_plot_fail, setup, teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
