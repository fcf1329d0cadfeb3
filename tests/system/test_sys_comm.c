/*
 * test_sys_comm.c - the commissioning run (roboelf-tech commission DIR)
 * against galil-sim: a clean robot passes every step with its report and
 * plots; each miswiring galil-sim can model (--miswire) is found at the
 * right step with the right words; a controller that answers differently
 * from the reference (--deviate) is named in the report.
 *
 * The test plays the technician: it reads roboelf-tech's prompts
 * ("commission: PRESS and hold the joystick B forward ...", "TRIP the
 * forward limit switch of axis A ...", "... [y/N]") and answers through
 * galil-sim's control port (joy, limit) and roboelf-tech's stdin (y).
 *
 * ROBOELF_SYS_FILTER=PATTERN runs only the matching tests.
 *
 * roboelf supervises, and nothing else: given one of the options that
 * moved to roboelf-tech it exits 2 with one line naming the command.
 * roboelf-tech's command line, and bind-relay refusing a serial number
 * before anything is written (the rest of bind-relay: test_re_bind).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "proc.h"
#include "sys_h.h"

#define RUN_TIMEOUT_MS 120000

static struct sys_env env;

static int setup(void **state)
{
	(void)state;
	if (sys_env_init(&env) < 0) {
		fprintf(stderr, "setup: %s\n", env.err);
		return -1;
	}
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	sys_env_cleanup(&env);
	return 0;
}

/* Answer one prompt line as the technician would. */
static int technician(struct sys_case *c, const char *line)
{
	char ax, dir[8];

	if (sscanf(line, "commission: PRESS and hold the joystick %c %7s", &ax,
		   dir) == 2)
		return sys_ctl(c, "joy %c %s", ax,
			       !strcmp(dir, "forward") ? "fwd" : "rev");
	if (sscanf(line, "commission: RELEASE the joystick %c", &ax) == 1)
		return sys_ctl(c, "joy %c neutral", ax);
	if (sscanf(line, "commission: TRIP the %7s limit switch of axis %c",
		   dir, &ax) == 2)
		return sys_ctl(c, "limit %c %s press", ax,
			       !strcmp(dir, "forward") ? "fwd" : "rev");
	if (sscanf(line, "commission: RELEASE the %7s limit switch of axis %c",
		   dir, &ax) == 2)
		return sys_ctl(c, "limit %c %s release", ax,
			       !strcmp(dir, "forward") ? "fwd" : "rev");
	if (strstr(line, "[y/N]"))
		return proc_write(&c->re, "y\n");
	return 0;
}

/* Play the technician until roboelf-tech prints a line starting with @stop
 * (returns 0) or, with @stop NULL, until it exits (returns its exit code).
 * *@pos: how far roboelf-tech's output was read. */
static int drive(struct sys_case *c, const char *stop, size_t *pos)
{
	long long end = proc_now_ms() + RUN_TIMEOUT_MS;
	int status = 0;

	while (proc_now_ms() < end) {
		const char *out, *nl;

		proc_pump(&c->re, 20);
		out = proc_output(&c->re, PROC_STDOUT);
		while ((nl = strchr(out + *pos, '\n')) != NULL) {
			char line[512];
			size_t n = (size_t)(nl - (out + *pos));

			snprintf(line, sizeof(line), "%.*s", (int)n,
				 out + *pos);
			*pos += n + 1;
			if (stop && !strncmp(line, stop, strlen(stop)))
				return 0;
			if (technician(c, line) < 0)
				fail_msg("technician: %s", c->err);
		}
		if (!stop && proc_wait_exit(&c->re, 0, &status) == 0)
			return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
	}
	fail_msg("roboelf-tech commission: no %s within %d s",
		 stop ? stop : "exit", RUN_TIMEOUT_MS / 1000);
	return -1;
}

/* Play the technician until roboelf-tech exits; its exit code. */
static int run_comm(struct sys_case *c)
{
	size_t pos = 0;

	return drive(c, NULL, &pos);
}

/* Start galil-sim (with @sim_args), galil-load and roboelf-tech commission. */
static int start(struct sys_case *c, char *const *sim_args, char *dir,
		 size_t cap)
{
	static int n;
	struct sys_opts o = {0};
	char *re_args[5];

	snprintf(dir, cap, "%s/comm-%d", env.dir, ++n);
	re_args[0] = (char *)"commission";
	re_args[1] = dir;
	re_args[2] = (char *)"--wait";
	re_args[3] = (char *)"5";
	re_args[4] = NULL;
	o.sim_args = sim_args;
	o.re_args = re_args;
	o.tech = 1;
	o.no_ready = 1;
	if (sys_case_start(c, &env, &o) < 0)
		fail_msg("case start: %s", c->err);
	return 0;
}

static char *slurp(const char *path)
{
	static char buf[65536];
	FILE *f = fopen(path, "r");
	size_t n;

	if (!f)
		return NULL;
	n = fread(buf, 1, sizeof(buf) - 1, f);
	buf[n] = '\0';
	fclose(f);
	return buf;
}

/* @dir/@name.gp holds the text @fmt makes. */
static void script_has(const char *dir, const char *name, const char *fmt,
		       ...) __attribute__((format(printf, 3, 4)));

static void script_has(const char *dir, const char *name, const char *fmt,
		       ...)
{
	char path[600], want[1024];
	const char *gp;
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(want, sizeof(want), fmt, ap);
	va_end(ap);
	snprintf(path, sizeof(path), "%s/%s.gp", dir, name);
	gp = slurp(path);
	if (!gp)
		fail_msg("no script %s", path);
	if (!strstr(gp, want))
		fail_msg("%s lacks\n%s\nin\n%.3000s", path, want, gp);
}

/* The plots' scripts: only the one of the failed step (@fail_plot, NULL:
 * none) carries the FAIL label, with the start of @why (the failed
 * check's words, up to where its label wraps). */
static void check_scripts(const char *dir, const char *fail_plot,
			  const char *why)
{
	static const char *const plots[] = {"joystick", "limits",
					    "relay",	"pots-at-rest",
					    "move-A",	"move-B",
					    "move-C"};
	char path[600], want[160];

	const char *fix = why ? strstr(why, " - fix:") : NULL;
	int n = why ? (fix ? (int)(fix - why) : (int)strlen(why)) : 0;

	snprintf(want, sizeof(want), "set label 99 \"FAIL: %.*s", n < 75 ? n : 75,
		 why ? why : "");
	for (size_t i = 0; i < sizeof(plots) / sizeof(plots[0]); i++) {
		const char *gp;
		int mine = fail_plot && !strcmp(plots[i], fail_plot);

		snprintf(path, sizeof(path), "%s/%s.gp", dir, plots[i]);
		gp = slurp(path);
		if (mine && (!gp || !strstr(gp, want)))
			fail_msg("%s lacks\n%s\nin\n%.3000s", path, want,
				 gp ? gp : "(no file)");
		if (!mine && gp && strstr(gp, "FAIL"))
			fail_msg("%s has a FAIL mark:\n%.3000s", path, gp);
	}
}

static int is_png(const char *dir, const char *name)
{
	char path[600], head[8] = {0};
	FILE *f;
	size_t n;

	snprintf(path, sizeof(path), "%s/%s", dir, name);
	f = fopen(path, "rb");
	if (!f)
		return 0;
	n = fread(head, 1, sizeof(head), f);
	fclose(f);
	return n == 8 && !memcmp(head, "\x89PNG\r\n\x1a\n", 8);
}

/* Every step passes on the default robot; report, plots, safe at the end. */
static void test_clean_robot(void **state)
{
	struct sys_case c;
	char dir[256], st[4096], path[320];
	const char *rep;

	(void)state;
	start(&c, NULL, dir, sizeof(dir));
	assert_int_equal(run_comm(&c), 0);
	assert_int_equal(proc_find_line(&c.re, PROC_STDOUT,
					"commission: PASSED: every step passed",
					NULL, 0),
			 0);
	snprintf(path, sizeof(path), "%s/commissioning.txt", dir);
	rep = slurp(path);
	assert_non_null(rep);
	assert_non_null(strstr(rep, "result: PASSED"));
	assert_null(strstr(rep, "FAIL "));
	assert_non_null(strstr(rep, "motor power switched on during the run: "
				    "yes"));
	assert_non_null(strstr(rep, "PASS  B forward        inputs 5 and 6 "
				    "closed, nothing else"));
	assert_non_null(strstr(rep, "PASS  C rev            _LRC read 0 "
				    "(active) while the reverse limit switch "
				    "of axis C was held, nothing else"));
	assert_non_null(strstr(rep, "PASS  close            relay ON: bit 3 "
				    "of _TA0 cleared after"));
	assert_non_null(strstr(rep, "PASS  pt-tracking"));
	assert_non_null(strstr(rep, "PASS  za-range         ZA ,,491519, then "
				    "MG _ZAC and QR; reference (ZA; the "
				    "record's user field, 4 bytes signed): "
				    "491519 in both; seen 491519 and 491519 "
				    "(put back to 0)"));
	assert_non_null(strstr(rep, "PASS  program          UL: galil-load's "
				    "stamp "));
	assert_non_null(strstr(rep, "plots: 7 PNG file(s) in "));
	assert_non_null(
	    strstr(rep, "encoder: asked the program for +2000 counts"));
	assert_true(is_png(dir, "pots-at-rest.png"));
	assert_true(is_png(dir, "move-A.png"));
	assert_true(is_png(dir, "move-B.png"));
	assert_true(is_png(dir, "move-C.png"));
	assert_true(is_png(dir, "joystick.png"));
	assert_true(is_png(dir, "limits.png"));
	assert_true(is_png(dir, "relay.png"));
	check_scripts(dir, NULL, NULL);
	/* each passing plot carries its limits, its targets, what was asked */
	script_has(dir, "pots-at-rest",
		   "%.3f with lines dt 2 lc rgb 'red' title 'noise limit: "
		   "%.1f mV peak to peak (half the tolerance)', %.3f with "
		   "lines dt 2 lc rgb 'red' notitle\n",
		   5.0, 10.0, -5.0);
	script_has(dir, "move-A",
		   "set multiplot layout 2,1 title \"axis A: +2000 counts at "
		   "2000 counts/s and the way back\"\n");
	script_has(dir, "move-B",
		   "$asked using 1:2 with lines dt 2 lc rgb 'black' title "
		   "'expected: 2000 counts/s to the target and back', %s",
		   "");
	script_has(dir, "move-C", "lc rgb 'dark-green' title 'target +2000 "
				  "counts (");
	script_has(dir, "move-A",
		   "set title 'the potentiometer against the encoder: +0.0400 "
		   "mV/count expected'\n");
	script_has(dir, "move-A",
		   "title 'expected: (forward_v - reverse_v) / "
		   "travel_counts'\n");
	script_has(dir, "joystick", "'PRESS B forward' at ");
	script_has(dir, "limits", "'TRIP C rev' at ");
	script_has(dir, "relay", "'relay OFF' at ");
	/* the run leaves the robot safe: relay off, every motor off */
	assert_true(sys_state(&c, st, sizeof(st)) >= 0);
	assert_non_null(strstr(st, " relay=off "));
	assert_true(sys_state_num(st, "A.mo") == 1 &&
		    sys_state_num(st, "B.mo") == 1 &&
		    sys_state_num(st, "C.mo") == 1);
	sys_case_stop(&c);
}

/* galil-sim holding no program: the run stops at its first step, before
 * any prompt, with the reason and the fix (exit 5); nothing else said. */
static void test_no_program(void **state)
{
	struct sys_case c;
	struct sys_opts o = {0};
	char dir[256], *re_args[] = {(char *)"commission", dir, (char *)"--wait",
				     (char *)"5", NULL};
	static const char why[] = "the controller holds no program stamped by "
				  "galil-load: run galil-load with dmc/ first";
	static const char fix[] =
	    "load dmc/ with galil-load --config and the configuration this "
	    "run uses (docs/technician.md, section 4), then run the "
	    "commissioning again";
	char want[4096], path[320];
	const char *out, *rep;
	size_t pos = 0;

	(void)state;
	snprintf(dir, sizeof(dir), "%s/comm-noprog", env.dir);
	o.re_args = re_args;
	o.tech = 1;
	o.no_ready = 1;
	o.no_load = 1;
	if (sys_case_start(&c, &env, &o) < 0)
		fail_msg("case start: %s", c.err);
	assert_int_equal(drive(&c, NULL, &pos), 5);
	out = proc_output(&c.re, PROC_STDOUT);
	snprintf(want, sizeof(want),
		 "roboelf-tech: opening the E-stop relay '%s' (motor power "
		 "stays off)\n"
		 "roboelf-tech: connecting to the controller at %s:%d\n"
		 "roboelf-tech: controller DMC4030 Rev 1.2h-sim, serial "
		 "403001\n"
		 "roboelf-tech: halting the controller program; every motor "
		 "off\n"
		 "roboelf-tech: controller configured and read back; motor "
		 "power off\n"
		 "commission: step 1 of 8: what the run needs: the relay, the "
		 "controller, the program\n"
		 "commission: FAILED at step needs (program): %s - fix: %s\n"
		 "commission: report %s/commissioning.txt, 0 plot(s)\n"
		 "roboelf-tech: the E-stop relay was never switched on; the amplifiers report no motor power; bye\n",
		 c.relay_link, c.sim_addr, c.sim.port, why, fix, dir);
	if (strcmp(out, want) != 0)
		fail_msg("stdout\n%s\nnot\n%s", out, want);
	snprintf(path, sizeof(path), "%s/commissioning.txt", dir);
	rep = slurp(path);
	assert_non_null(rep);
	snprintf(want, sizeof(want),
		 "\n== needs\n"
		 "PASS  relay            the E-stop relay answers and is off: "
		 "no motor power\n"
		 "PASS  controller       the controller at %s:%d answers (MG "
		 "_BN 403001)\n"
		 "FAIL  program          %s\n"
		 "      fix: %s\n\n== the controller reports of itself\n",
		 c.sim_addr, c.sim.port, why, fix);
	if (!strstr(rep, want))
		fail_msg("the report lacks\n%s\nin\n%s", want, rep);
	assert_non_null(strstr(rep, "motor power switched on during the run: "
				    "never\n"));
	sys_case_stop(&c);
}

/* SIGKILL while the controller program moves axis B for the
 * commissioning: its watchdog stops the move and switches every motor off
 * within its deadline (wdto + one main-loop pass + a sample + slack). */
static void test_kill_during_move(void **state)
{
	static const double at[] = {300, 1100, 1900}; /* counts into the move */
	double deadline = env.wdto_ms + SYS_MAINMS + 1 + 25;

	(void)state;
	for (size_t k = 0; k < sizeof(at) / sizeof(at[0]); k++) {
		struct sys_case c;
		char dir[256], st[4096];
		double t_sig, off = -1, b0;
		long long end;
		size_t pos = 0;

		start(&c, NULL, dir, sizeof(dir));
		assert_int_equal(drive(&c,
				       "commission: axis B: a +2000-count "
				       "move",
				       &pos),
				 0);
		assert_true(sys_state(&c, st, sizeof(st)) >= 0);
		b0 = sys_state_num(st, "B.pos");
		end = proc_now_ms() + 5000;
		while (sys_state(&c, st, sizeof(st)) >= 0 &&
		       sys_state_num(st, "B.pos") < b0 + at[k] &&
		       proc_now_ms() < end)
			;
		assert_true(sys_state_num(st, "B.pos") >= b0 + at[k]);
		t_sig = sys_sim_time(&c);
		assert_int_equal(proc_signal(&c.re, SIGKILL), 0);
		proc_wait_exit(&c.re, 2000, NULL);
		end = proc_now_ms() + 2000;
		while (off < 0 && proc_now_ms() < end) {
			assert_true(sys_events(&c) >= 0);
			off = sys_motors_off_time(&c, t_sig);
		}
		print_message("[ MEASURE ] kill %.0f counts into B's move: "
			      "motors off %.0f ms after the kill (deadline "
			      "%.0f)\n",
			      at[k], off - t_sig, deadline);
		assert_true(off >= t_sig);
		assert_true(off - t_sig <= deadline);
		if (sys_check_safe(&c, 1, 200) < 0)
			fail_msg("%s", c.err);
		sys_case_stop(&c);
	}
}

/* One galil-sim option, the line roboelf-tech must end with, its exit code. */
struct wrong {
	const char *opt, *arg;
	int exit;
	const char *line;   /* the console's verdict (prefix) */
	const char *report; /* a line of the report (substring), or NULL */
	const char *plot;   /* the failed step's plot, or NULL */
};

#if defined(__SANITIZE_ADDRESS__)
/* make asan looks for memory errors: every other case (make check: all) */
static const size_t wrong_stride = 2;
#else
static const size_t wrong_stride = 1;
#endif

static const struct wrong wrongs[] = {
    {"--miswire", "joystick-swap:5,7", 5,
     "commission: FAILED at step joystick (B forward): swapped pair: input 5 "
     "(B forward channel a) did not close and input 7 (B reverse channel a) "
     "did: the switch of B forward channel a is wired to input 7 - fix: "
     "exchange the wires on inputs 5 and 7 (or the two numbers in "
     "joystick.inputs)",
     NULL, "joystick"},
    {"--miswire", "dead-input:6", 5,
     "commission: FAILED at step joystick (B forward): dead switch: input 6 "
     "(B forward channel b) did not close; the other channel did - fix: ",
     NULL, "joystick"},
    {"--miswire", "joystick-polarity", 5,
     "commission: FAILED at step joystick (polarity): with nothing pressed "
     "all 12 joystick inputs read 1, which the configuration (active_low: "
     "false) takes for closed: the polarity is the wrong way round - fix: "
     "set joystick.active_low: true",
     NULL, "joystick"},
    {"--miswire", "limits-swapped:B", 5,
     "commission: FAILED at step limits (B fwd): swapped: the forward limit "
     "switch of axis B was held and the controller saw the reverse limit "
     "switch of axis B - fix: exchange the forward and reverse limit switch "
     "wires of that axis",
     NULL, "limits"},
    {"--miswire", "relay-unwired", 5,
     "commission: FAILED at step relay (open): with the relay OFF the "
     "amplifiers report power (MG _TA0 = 0, bit 3 'under-voltage' clear; "
     "reference: TA): the relay does not switch the motors' power",
     NULL, "relay"},
    {"--miswire", "encoder-reversed:A", 5,
     "commission: FAILED at step motion (A): encoder reversed: asked for "
     "+2000 counts, the encoder counted -",
     NULL, "move-A"},
    {"--miswire", "pot-reversed:C", 5,
     "commission: FAILED at step motion (C): potentiometer reversed: -0.",
     NULL, "move-C"},
    {"--deviate", "mg-join", 0, "commission: PASSED: every step passed",
     "NOTE  mg-separate      sent 'MG -1,-2'; reference (MG): each number "
     "keeps its sign position (' -1.0000 -2.0000'); seen '-1.0000-2.0000' "
     "(roboelf and galil-load read one value per MG: safe)", NULL},
    {"--deviate", "mo-moving", 0, "commission: PASSED: every step passed",
     "NOTE  mo-moving        MO A during a 300-count move; reference (MO): "
     "not valid while in motion; seen accepted (the motor went off while "
     "moving; dmc/ and roboelf send AB 1 first, galil-load waits for the "
     "stop: safe)", NULL},
    {"--deviate", "dm-exists", 0, "commission: PASSED: every step passed",
     "NOTE  dm-exists        DM cmqz[4] twice; reference (DM): silent on an "
     "array that exists (UNCONFIRMED); first ':', second ':'; dmc/ "
     "deallocates every array first (DA *[]): safe on either", NULL},
    {"--deviate", "za-16bit", 5,
     "commission: FAILED at step firmware (za-range): ZA ,,491519, then MG "
     "_ZAC and QR; reference (ZA; the record's user field, 4 bytes signed): "
     "491519 in both; seen 491519 and 32767 (put back to 0)",
     NULL, NULL},
    {"--deviate", "qr-header", 5,
     "commission: FAILED at step firmware (qr-record): QR; reference (QR, "
     "QZ): a record of the announced length whose header names axes A-C; "
     "the record did not decode",
     NULL, NULL},
};

/* The farewell states only what is known of motor power, and that is
 * true in galil-sim (its state line's motor power, "power="): "the E-stop
 * relay was never switched on" with what the amplifiers report
 * (relay-unwired: motor power, the relay bypassed), never "motor power
 * was never switched on". */
static void farewell_true(struct sys_case *c, const struct wrong *w)
{
	static const char never[] = "roboelf-tech: the E-stop relay was never "
				    "switched on";
	const char *out = proc_output(&c->re, PROC_STDOUT), *p;
	char st[4096];
	double power;

	if (strstr(out, "motor power was never switched on"))
		fail_msg("%s %s: a farewell states what is not known:\n%s",
			 w->opt, w->arg, out);
	if (!strcmp(w->arg, "relay-unwired") &&
	    !strstr(out, "roboelf-tech: the E-stop relay was never switched "
			 "on, yet the amplifiers report motor power (MG _TA0 "
			 "= 0, no under-voltage): the relay does not switch "
			 "it; "))
		fail_msg("%s %s: no '%s, yet the amplifiers report motor "
			 "power ...' in:\n%s",
			 w->opt, w->arg, never, out);
	p = strstr(out, never);
	if (!p)
		return;
	if (sys_state(c, st, sizeof(st)) < 0)
		fail_msg("%s %s: %s", w->opt, w->arg, c->err);
	power = sys_state_num(st, "power");
	p += strlen(never);
	if ((!strncmp(p, ", yet the amplifiers report motor power", 39) &&
	     power != 1) ||
	    (!strncmp(p, "; the amplifiers report no motor power", 38) &&
	     power != 0))
		fail_msg("%s %s: the farewell '%.200s' is false: galil-sim's "
			 "state: %s",
			 w->opt, w->arg, p - strlen(never), st);
}

/* Each miswiring and deviation galil-sim models, found at its step. */
static void test_wrong_robot(void **state)
{
	(void)state;
	for (size_t k = 0; k < sizeof(wrongs) / sizeof(wrongs[0]);
	     k += wrong_stride) {
		const struct wrong *w = &wrongs[k];
		char *args[] = {(char *)w->opt, (char *)w->arg, NULL};
		char dir[256], path[320], line[1024];
		const char *rep;
		struct sys_case c;

		print_message("[ CASE     ] %s %s\n", w->opt, w->arg);
		start(&c, args, dir, sizeof(dir));
		assert_int_equal(run_comm(&c), w->exit);
		if (proc_find_line(&c.re, PROC_STDOUT, w->line, line,
				   sizeof(line)) != 0)
			fail_msg("%s %s: no line '%s' in:\n%s", w->opt, w->arg,
				 w->line, proc_output(&c.re, PROC_STDOUT));
		snprintf(path, sizeof(path), "%s/commissioning.txt", dir);
		rep = slurp(path);
		assert_non_null(rep);
		if (w->report && !strstr(rep, w->report))
			fail_msg("%s %s: the report lacks '%s':\n%s", w->opt,
				 w->arg, w->report, rep);
		check_scripts(dir, w->plot,
			      w->plot ? strstr(w->line, "): ") + 3 : NULL);
		farewell_true(&c, w);
		sys_case_stop(&c);
	}
}

/* A controller of our own on loopback answering the discovery probe
 * (^R^V CR, docs/galil-load.md) with a revision report. */
struct lsn {
	int fd, port, probes;
	pthread_t th;
};

static void *lsn_main(void *arg)
{
	static const char reply[] = "DMC4030 Rev 1.2h-lsn\r\n:";
	struct lsn *s = arg;
	struct pollfd pfd = {.fd = s->fd, .events = POLLIN};
	struct sockaddr_in from;
	socklen_t flen;
	char b[64];
	ssize_t n;

	while (poll(&pfd, 1, 10000) == 1) {
		flen = sizeof(from);
		n = recvfrom(s->fd, b, sizeof(b), 0, (struct sockaddr *)&from,
			     &flen);
		if (n <= 0)
			break;
		if (n == 3 && !memcmp(b, "\x12\x16\r", 3)) {
			s->probes++;
			sendto(s->fd, reply, strlen(reply), 0,
			       (struct sockaddr *)&from, flen);
		}
	}
	return NULL;
}

/* The configured address does not answer: the commissioning run lists the
 * controllers that answer the discovery probe, and without a terminal to
 * pick one it stops (exit 3): it never connects elsewhere by itself. */
static void test_find_controller(void **state)
{
	struct sockaddr_in a = {.sin_family = AF_INET};
	socklen_t len = sizeof(a);
	struct lsn l = {0};
	char dir[256], port[16], line[512];
	char *re_args[] = {(char *)"commission",
			   dir,
			   (char *)"--galil",
			   (char *)"127.0.0.1:1",
			   (char *)"--find-addr",
			   (char *)"127.0.0.1",
			   (char *)"--find-port",
			   port,
			   NULL};
	struct sys_opts o = {0};
	struct sys_case c;
	int status = -1;

	(void)state;
	l.fd = socket(AF_INET, SOCK_DGRAM, 0);
	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	assert_true(l.fd >= 0);
	assert_int_equal(bind(l.fd, (struct sockaddr *)&a, sizeof(a)), 0);
	assert_int_equal(getsockname(l.fd, (struct sockaddr *)&a, &len), 0);
	l.port = ntohs(a.sin_port);
	snprintf(port, sizeof(port), "%d", l.port);
	assert_int_equal(pthread_create(&l.th, NULL, lsn_main, &l), 0);
	snprintf(dir, sizeof(dir), "%s/comm-find", env.dir);
	o.re_args = re_args;
	o.tech = 1;
	o.no_ready = 1;
	if (sys_case_start(&c, &env, &o) < 0)
		fail_msg("case start: %s", c.err);
	assert_int_equal(proc_wait_exit(&c.re, 20000, &status), 0);
	assert_true(WIFEXITED(status));
	assert_int_equal(WEXITSTATUS(status), 3);
	if (proc_find_line(&c.re, PROC_STDOUT,
			   "  1) 127.0.0.1  DMC4030 Rev "
			   "1.2h-lsn",
			   line, sizeof(line)) != 0)
		fail_msg("no list in:\n%s", proc_output(&c.re, PROC_STDOUT));
	assert_int_equal(proc_find_line(&c.re, PROC_STDOUT,
					"roboelf-tech: error: the configured "
					"controller does not answer; the "
					"controllers listed above do: run "
					"again with --galil ADDRESS",
					NULL, 0),
			 0);
	assert_int_equal(l.probes, 1);
	sys_case_stop(&c);
	shutdown(l.fd, SHUT_RDWR);
	pthread_join(l.th, NULL);
	close(l.fd);
}

/* Run @argv (its program in env.bin) to its end; its exit code, and its
 * stderr in @err. */
static int run_to_end(char **argv, char *err, size_t cap)
{
	char bin[SYS_PATH_MAX + 16];
	struct proc p;
	int status = -1, rc;

	snprintf(bin, sizeof(bin), "%s/%s", env.bin, argv[0]);
	argv[0] = bin;
	if (proc_spawn(&p, argv, NULL) < 0)
		fail_msg("cannot start %s", bin);
	if (proc_wait_exit(&p, 10000, &status) < 0) {
		proc_kill(&p);
		fail_msg("%s did not end", bin);
	}
	rc = proc_exit_code(&p);
	snprintf(err, cap, "%s", proc_output(&p, PROC_STDERR));
	proc_kill(&p);
	return rc;
}

/* roboelf given an option of roboelf-tech: exit 2, one line naming the
 * command that does it now, nothing started. */
static void test_moved_options(void **state)
{
	static const char *const moved[][2] = {
	    {"--commission=x", "roboelf-tech commission DIR"},
	    {"--show-calibration=x", "roboelf-tech show-calibration FILE"},
	    {"--show-trace=x", "roboelf-tech show-trace FILE"},
	    {"--check-host", "roboelf-tech check-host"},
	    {"--check-host=5", "roboelf-tech check-host"},
	    {"--window=1:2", "roboelf-tech show-trace FILE --window FROM:TO"},
	    {"--wait=5", "roboelf-tech commission DIR --wait S"},
	    {"--find-addr=x", "roboelf-tech commission DIR --find-addr A"},
	    {"--find-port=1", "roboelf-tech commission DIR --find-port P"},
	};
	char err[1024], want[256], opt[64];

	(void)state;
	for (size_t i = 0; i < sizeof(moved) / sizeof(moved[0]); i++) {
		char *argv[] = {(char *)"roboelf", (char *)moved[i][0], NULL};

		snprintf(opt, sizeof(opt), "%.*s",
			 (int)strcspn(moved[i][0], "="), moved[i][0]);
		snprintf(want, sizeof(want),
			 "roboelf: error: %s is not roboelf's: roboelf "
			 "supervises, and nothing else; run %s (the "
			 "technician's program)\n",
			 opt, moved[i][1]);
		assert_int_equal(run_to_end(argv, err, sizeof(err)), 2);
		if (strcmp(err, want) != 0)
			fail_msg("%s: stderr\n%s\nnot\n%s", moved[i][0], err,
				 want);
	}
}

/* roboelf-tech's command line: check-host=S and check-host S the same
 * time rule, an unknown command or a missing operand refused (exit 2). */
static void test_tech_usage(void **state)
{
	static const struct {
		const char *a1, *a2, *err;
	} bad[] = {
	    {"check-host=0", NULL,
	     "roboelf-tech: error: invalid check-host time '0': must be "
	     "1..3600 s\n"},
	    {"check-host", "3601",
	     "roboelf-tech: error: invalid check-host time '3601': must be "
	     "1..3600 s\n"},
	    {"check-host=1", "2",
	     "roboelf-tech: error: check-host takes at most a time in s\n"},
	    {"show-trace", NULL,
	     "roboelf-tech: error: show-trace takes one file (roboelf-tech "
	     "--help)\n"},
	    {"supervise", NULL,
	     "roboelf-tech: error: unknown command 'supervise': commission, "
	     "show-calibration, show-trace, check-host or bind-relay\n"},
	    {"bind-relay", "x",
	     "roboelf-tech: error: bind-relay takes no operand (roboelf-tech "
	     "--help)\n"},
	    {"--bind-relay", "x",
	     "roboelf-tech: error: bind-relay takes no operand (roboelf-tech "
	     "--help)\n"},
	};
	char err[1024];

	(void)state;
	for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
		char *argv[] = {(char *)"roboelf-tech", (char *)bad[i].a1,
				(char *)bad[i].a2, NULL};

		assert_int_equal(run_to_end(argv, err, sizeof(err)), 2);
		if (strcmp(err, bad[i].err) != 0)
			fail_msg("%s %s: stderr\n%s\nnot\n%s", bad[i].a1,
				 bad[i].a2 ? bad[i].a2 : "", err, bad[i].err);
	}
}

/* roboelf-tech bind-relay with a serial number a udev rule cannot hold:
 * refused (exit 3) whatever ports this machine has (libserialport's
 * listing reads sysfs and opens none), and no rules file written. */
static void test_bind_relay_refused(void **state)
{
	char dir[] = "/tmp/test_sys_comm.XXXXXX", rules[64], err[1024];
	char *argv[] = {(char *)"roboelf-tech",
			(char *)"bind-relay",
			(char *)"--serial",
			(char *)"A\"1",
			(char *)"--rules-file",
			rules,
			NULL};

	(void)state;
	assert_non_null(mkdtemp(dir));
	snprintf(rules, sizeof(rules), "%s/60-roboelf-relay.rules", dir);
	assert_int_equal(run_to_end(argv, err, sizeof(err)), 3);
	assert_string_equal(err, "roboelf-tech: error: serial number 'A\"1' "
				 "has a character not allowed in a udev rule "
				 "('\"' at position 2): only letters, digits, "
				 "'.', '_', '-' and ':'\n");
	assert_int_equal(access(rules, F_OK), -1);
	assert_int_equal(rmdir(dir), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_moved_options),
	    cmocka_unit_test(test_tech_usage),
	    cmocka_unit_test(test_bind_relay_refused),
	    cmocka_unit_test(test_no_program),
	    cmocka_unit_test(test_clean_robot),
	    cmocka_unit_test(test_kill_during_move),
	    cmocka_unit_test(test_wrong_robot),
	    cmocka_unit_test(test_find_controller),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, setup, teardown);
}
