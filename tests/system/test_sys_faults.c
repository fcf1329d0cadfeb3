/*
 * test_sys_faults.c - the fault-injection matrix on the whole
 * system: galil-sim running dmc/ (downloaded by galil-load), roboelf
 * supervising it through the virtual relay.
 *
 * One full calibration for the binary (group setup), then every case on a
 * fresh simulator with `--calibration file`. Each case injects one fault
 * through galil-sim's control port (or by signal / a second host) and
 * asserts:
 *  - the FAULT line on roboelf's stdout: its class and its exact
 *    "Recovery:" text (re_fault_format() of the expected fault id);
 *  - the same line in the log file, at level FAULT;
 *  - the safe state: relay off (motor power cut), every motor off, and no
 *    axis moving over the following 300 ms of simulated time;
 *  - the reaction time, from the simulator's events (simulated ms from the
 *    injection to "relay off" and to the last "axis <X> motor off"), within
 *    the deadline of docs/safety.md ("Deadlines") plus SLACK_MS;
 *  - that the controller obeyed the supervisor's stop command (the log
 *    entry does not say "answered ?"), where the controller is reachable;
 *  - that every fact the FAULT line and its log entry state is true in
 *    galil-sim's event log (sys_truth_check(): class and axis of the first
 *    cause, consequences, stop delivered, relay open, power and motors
 *    off);
 *  - roboelf exits 4 (fault latched) on SIGTERM afterwards, and the FAULT
 *    entry names a flight-recorder trace that parses and holds
 *    the cycles before the fault and the fault cycle.
 *
 * Environment: ROBOELF_REPEAT=N repeats each case N times (make bench);
 * ROBOELF_REACTION_CSV=FILE appends one line per measurement to FILE;
 * ROBOELF_SYS_FILTER=PATTERN runs only the matching tests.
 */
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_file.h"
#include "gl_err.h"
#include "re_calfile.h"
#include "re_trace.h"
#include "sys_h.h"
#include "sys_truth.h"

#define SLACK_MS      25   /* scheduling allowance on a busy 2-core box */
#define HOLD_MS	      300  /* no motion over this after the safe state */
#define FAULT_WAIT_MS 8000 /* FAULT line, beyond the deadline */
#define EXIT_WAIT_MS  5000

static struct sys_env env;
static int env_ok;
static struct sys_case cs;

/* ---- deadlines (docs/safety.md, "Deadlines") ---------------------------- */

static double P(void)
{
	return env.period_ms;
}

/* Critical reply age C = critical_factor x P. */
static double C(void)
{
	return env.crit_factor * env.period_ms;
}

/* Encoder/potentiometer disagreement: the next cycle, `persistence` more
 * cycles, and one cycle of processing allowance: (2 + k) P. */
static double d_encpot(void)
{
	return (2.0 + env.persistence) * P();
}

/* Time for the axis to move the encoder/pot tolerance at vmin (the slowest
 * commanded velocity): tolerance = (1 + allowed_error) x the local pot step;
 * 10 % for the pot's bow, plus one DMC loop to start and AC to reach vmin. */
static double t_tolerance(void)
{
	double tol = (1.0 + env.allowed_error) * env.step_counts * 1.1;
	double acc = 10.0 * env.vmax_cps;

	return SYS_LOOPMS + 1000.0 * env.vmin_cps / acc +
	       1000.0 * tol / env.vmin_cps;
}

/* PC reaction to a controller-latched fault: it latches within mainms; the
 * supervisor sees it in its next record (<= P) and acts in that cycle: one
 * more P of allowance. */
static double d_ctrl_to_relay(void)
{
	return SYS_MAINMS + 2.0 * P();
}

/* ---- the common assertion ----------------------------------------------- */

struct expect {
	const char *name;
	enum re_fault_id ids[4]; /* allowed faults, RE_F_NONE ended */
	int axis;		 /* 0..2, -1 none */
	double t_inj;		 /* simulated ms of the injection */
	double d_relay;		 /* deadline to relay off, ms; < 0 none */
	double d_motors;	 /* deadline to all motors off; < 0 none */
	int relay_may_be_on;
	int link_down; /* the controller cannot be reached (link faults) */
};

struct measured {
	double relay_ms; /* -1: not measured */
	double motors_ms;
	char line[1024]; /* the FAULT line */
};

static void record(const struct expect *x, const struct measured *m)
{
	const char *csv = getenv("ROBOELF_REACTION_CSV");
	FILE *f;

	print_message("[ MEASURE  ] %s: relay off %.0f ms (deadline %.0f), "
		      "motors off %.0f ms (deadline %.0f), P %d ms\n",
		      x->name, m->relay_ms, x->d_relay, m->motors_ms,
		      x->d_motors, env.period_ms);
	if (!csv || !*csv)
		return;
	f = fopen(csv, "a");
	if (!f)
		return;
	fprintf(f, "%s,%.1f,%.1f,%.1f,%.1f,%d\n", x->name, m->relay_ms,
		m->motors_ms, x->d_relay, x->d_motors, env.period_ms);
	fclose(f);
}

/* Wait until every motor has a "motor off" event after the injection. */
static double wait_motors_off(struct sys_case *c, double after, int ms)
{
	long long deadline = proc_now_ms() + ms;

	for (;;) {
		double t = sys_motors_off_time(c, after);

		if (t >= 0 || proc_now_ms() > deadline)
			return t;
		usleep(15000);
		if (sys_events(c) < 0)
			return -1;
	}
}

/* The FAULT line must be one of x->ids, name its axis, and be logged. */
static void match_fault_line(struct sys_case *c, const struct expect *x,
			     const char *line)
{
	char logline[4096];

	if (sys_fault_match(line, x->axis, x->ids) == RE_F_NONE) {
		char pre[64], rec[512];

		sys_fault_expect(x->ids[0], x->axis, pre, sizeof(pre), rec,
				 sizeof(rec));
		fail_msg("%s: unexpected FAULT line\n  got:      %s\n  "
			 "expected: %s...%s",
			 x->name, line, pre, rec);
	}
	if (strstr(line, "axis ?") || strstr(line, "unknown"))
		fail_msg("%s: the FAULT line does not name its axis or value: "
			 "%s",
			 x->name, line);
	if (sys_log_find(c, " FAULT ", line, logline, sizeof(logline)) < 0)
		fail_msg("%s: %s", x->name, c->err);
	/* the stop and motors-off command must have been obeyed */
	if (!x->link_down && strstr(logline, "answered ?"))
		fail_msg("%s: the controller rejected the supervisor's stop "
			 "command:\n%s",
			 x->name, logline);
}

/*
 * Wait for the FAULT line, measure and record the reaction (also when the
 * line turns out wrong, so that make bench has the figure), then assert
 * the line, the log, the safe state and the deadlines.
 */
static void expect_fault(struct sys_case *c, const struct expect *x,
			 struct measured *m)
{
	char *line = m->line;
	double t;

	m->relay_ms = m->motors_ms = -1;
	if (sys_wait_fault(c, FAULT_WAIT_MS, line, sizeof(m->line)) < 0)
		fail_msg("%s: %s", x->name, c->err);
	if (!x->relay_may_be_on) {
		if (sys_wait_event(c, "relay off", x->t_inj, 3000, &t) < 0)
			fail_msg("%s: %s", x->name, c->err);
		m->relay_ms = t - x->t_inj;
	}
	t = wait_motors_off(c, x->t_inj, 3000);
	if (t < 0)
		fail_msg("%s: not every motor was switched off (no "
			 "'axis <X> motor off' event for each axis)",
			 x->name);
	m->motors_ms = t - x->t_inj;
	record(x, m);
	match_fault_line(c, x, line);
	if (sys_check_safe(c, x->relay_may_be_on, HOLD_MS) < 0)
		fail_msg("%s: %s", x->name, c->err);
	if (sys_truth_check(c, line, x->t_inj, 0) < 0)
		fail_msg("%s: %s", x->name, c->err);
	if (x->d_relay >= 0 && m->relay_ms > x->d_relay + SLACK_MS)
		fail_msg("%s: relay off after %.0f ms, deadline %.0f ms "
			 "(+%d)",
			 x->name, m->relay_ms, x->d_relay, SLACK_MS);
	if (x->d_motors >= 0 && m->motors_ms > x->d_motors + SLACK_MS)
		fail_msg("%s: motors off after %.0f ms, deadline %.0f ms "
			 "(+%d)",
			 x->name, m->motors_ms, x->d_motors, SLACK_MS);
}

/* After a fault: the operator quits; a latched fault exits 4. */
/* The flight recorder: the FAULT entry names a trace, written
 * at the latest when roboelf quit; it parses strictly and holds cycles
 * before the fault and the fault cycle (phase FAULT, the fault's id). */
static void check_trace(struct sys_case *c, const char *name)
{
	char line[4096], path[SYS_PATH_MAX], err[512], *buf;
	const char *p;
	struct re_trace_hdr h;
	struct re_trace_rec *r;
	size_t len, f = 0;

	if (sys_log_find(c, " FAULT ", "| trace ", line, sizeof(line)) < 0)
		fail_msg("%s: %s", name, c->err);
	p = strstr(line, "| trace ") + 8;
	snprintf(path, sizeof(path), "%.*s", (int)strcspn(p, " |"), p);
	if (base_file_read(path, RE_TRACE_MAX_BYTES, &buf, &len) < 0)
		fail_msg("%s: no trace '%s'", name, path);
	if (re_trace_parse(buf, len, &h, &r, err, sizeof(err)) != GL_OK)
		fail_msg("%s: trace '%s' refused: %s", name, path, err);
	free(buf);
	while (f < h.n_records && r[f].phase != RE_TPH_FAULT)
		f++;
	if (f == h.n_records || f == 0 || r[f].fault == 0)
		fail_msg("%s: trace '%s': fault cycle %zu of %u", name, path, f,
			 h.n_records);
	assert_int_equal(h.have_fault, 1);
	free(r);
}

static void quit_latched(struct sys_case *c, const char *name)
{
	int status;

	proc_signal(&c->re, SIGTERM);
	if (proc_wait_exit(&c->re, EXIT_WAIT_MS, &status) < 0)
		fail_msg("%s: roboelf did not exit within %d ms of SIGTERM",
			 name, EXIT_WAIT_MS);
	assert_int_equal(proc_exit_code(&c->re), 4);
	check_trace(c, name);
}

/* ---- fixtures ----------------------------------------------------------- */

static int group_setup(void **state)
{
	(void)state;
	env_ok = sys_env_ready(&env);
	return 0;
}

static int group_teardown(void **state)
{
	(void)state;
	sys_env_done(&env, env_ok);
	return 0;
}

static int case_teardown(void **state)
{
	(void)state;
	sys_case_stop(&cs);
	return 0;
}

static void start(struct sys_case *c, const struct sys_opts *o)
{
	if (!env_ok)
		fail_msg("no calibrated environment: %s", env.err);
	if (sys_case_start(c, &env, o) < 0)
		fail_msg("%s", c->err);
}

static int repeats(void)
{
	const char *r = getenv("ROBOELF_REPEAT");
	int n = r ? atoi(r) : 1;

	return n < 1 ? 1 : n > 1000 ? 1000 : n;
}

/* Inject @req (a control request) and return the simulated time of its
 * event ("inject: ..." or "input: ..."). */
static double inject(struct sys_case *c, const char *evt_prefix,
		     const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static double inject(struct sys_case *c, const char *evt_prefix,
		     const char *fmt, ...)
{
	char req[256], want[300];
	double before = sys_sim_time(c), t;
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(req, sizeof(req), fmt, ap);
	va_end(ap);
	if (before < 0 || sys_ctl(c, "%s", req) < 0)
		fail_msg("%s", c->err);
	snprintf(want, sizeof(want), "%s%s", evt_prefix, req);
	if (sys_wait_event(c, want, before, 2000, &t) < 0)
		fail_msg("%s", c->err);
	return t;
}

static double inject_fault(struct sys_case *c, const char *req)
{
	return inject(c, "inject: ", "%s", req);
}

static double joy(struct sys_case *c, const char *req)
{
	return inject(c, "input: ", "joy %s", req);
}

#define FOR_REPEATS(i) for (int i = 0; i < repeats(); i++)

/* ---- potentiometer ------------------------------------------------------ */

static void pot_at_rest(const char *name, const char *req, int axis,
			enum re_fault_id id)
{
	FOR_REPEATS(i)
	{
		int ctrl = id == RE_F_CTRL_POTRANGE;
		struct expect x = {.name = name,
				   .ids = {id, RE_F_NONE},
				   .axis = axis,
				   .d_relay =
				       ctrl ? d_ctrl_to_relay() : d_encpot(),
				   .d_motors = ctrl ? SYS_MAINMS + 1
						    : d_encpot() + SYS_MAINMS};
		struct measured m = {0};

		start(&cs, NULL);
		x.t_inj = inject_fault(&cs, req);
		expect_fault(&cs, &x, &m);
		quit_latched(&cs, name);
		sys_case_stop(&cs);
	}
}

static void test_pot_offset(void **state)
{
	(void)state;
	/* B, the demo's fault: the program, told to stop, finds A off
	 * first; nothing may name A */
	pot_at_rest("pot offset", "pot B offset 0.5", 1, RE_F_ENCPOT);
}

/* An open wiper reads 0 V, which no potentiometer of this robot can read:
 * the controller's range check (fault 16) names it within a main loop,
 * before the encoder/pot check would. */
static void test_pot_open(void **state)
{
	(void)state;
	pot_at_rest("pot open", "pot C open", 2, RE_F_CTRL_POTRANGE);
}

/* A frozen wiper only disagrees once the axis moves: the deadline counts
 * from the joystick command and includes moving the tolerance at vmin. */
static void test_pot_stuck(void **state)
{
	(void)state;
	FOR_REPEATS(i)
	{
		double d = t_tolerance() + d_encpot();
		struct expect x = {.name = "pot stuck",
				   .ids = {RE_F_ENCPOT, RE_F_NONE},
				   .axis = 1,
				   .d_relay = d,
				   .d_motors = d + SYS_MAINMS};
		struct measured m = {0};

		start(&cs, NULL);
		inject_fault(&cs, "pot B stuck");
		x.t_inj = joy(&cs, "B fwd");
		expect_fault(&cs, &x, &m);
		quit_latched(&cs, x.name);
		sys_case_stop(&cs);
	}
}

/* ---- encoder ------------------------------------------------------------ */

/* A dead encoder on a free axis: the servo runs the motor away; the
 * potentiometer disagrees first (or the controller's OA). */
static void test_enc_stuck(void **state)
{
	(void)state;
	FOR_REPEATS(i)
	{
		double d = t_tolerance() + d_encpot();
		struct expect x = {.name = "encoder stuck",
				   .ids = {RE_F_ENCPOT, RE_F_CTRL_ENCODER,
					   RE_F_MOTOR_OFF, RE_F_NONE},
				   .axis = 0,
				   .d_relay = d,
				   .d_motors = d + SYS_MAINMS};
		struct measured m = {0};

		start(&cs, NULL);
		inject_fault(&cs, "enc A stuck");
		x.t_inj = joy(&cs, "A fwd");
		expect_fault(&cs, &x, &m);
		quit_latched(&cs, x.name);
		sys_case_stop(&cs);
	}
}

/* The encoder slips in steps of 200 counts, 400 ms apart: each moves the
 * motor by 200 counts (below the controller's speed limit for an axis it
 * does not move: TV averages 256 ms, 200 counts < vstill 1000 counts/s x
 * 0.256 s), so the encoder/pot check alone judges: up to 93 % of its
 * tolerance nothing trips, the step past it does. */
static void test_enc_slip(void **state)
{
	(void)state;
	FOR_REPEATS(i)
	{
		double tol = (1.0 + env.allowed_error) * env.step_counts;
		int stepc = 200, n = (int)(0.95 * tol / stepc);
		struct expect x = {.name = "encoder slip",
				   .ids = {RE_F_ENCPOT, RE_F_NONE},
				   .axis = 1,
				   .d_relay = d_encpot(),
				   .d_motors = d_encpot() + SYS_MAINMS};
		struct measured m = {0};
		char req[64];

		start(&cs, NULL);
		for (int k = 1; k <= n; k++) {
			char line[512];
			double t;

			snprintf(req, sizeof(req), "enc B slip %d", k * stepc);
			t = inject_fault(&cs, req);
			if (sys_wait_sim(&cs, t + 400, 5000) < 0)
				fail_msg("%s", cs.err);
			if (proc_find_line(&cs.re, PROC_STDOUT, "FAULT ", line,
					   sizeof(line)) == 0)
				fail_msg("encoder slip of %d counts (%.0f %% "
					 "of the tolerance) tripped: %s",
					 k * stepc, 100.0 * k * stepc / tol,
					 line);
		}
		/* one more step: past the tolerance (checked strictly) */
		assert_true((n + 1) * stepc > tol);
		snprintf(req, sizeof(req), "enc B slip %d", (n + 1) * stepc);
		x.t_inj = inject_fault(&cs, req);
		expect_fault(&cs, &x, &m);
		quit_latched(&cs, x.name);
		sys_case_stop(&cs);
	}
}

/* ---- motion ------------------------------------------------------------- */

/*
 * A jammed axis: the reference runs ahead of a motor that cannot move until
 * the controller's position-error limit (ER/OE) or its encoder-failure
 * detection (OA: torque above OV for OT samples without encoder motion)
 * switches it off. The deadline covers whichever comes first: the error
 * grows at vmin to at most the tracking step, so ER (< step, arm check 7)
 * trips within step / vmin; OA within OT samples after the torque passes OV.
 */
static double d_jam_motors(void)
{
	double t_er = 1000.0 * env.step_counts / env.vmin_cps;

	return 2 * SYS_LOOPMS + 1000.0 * env.vmin_cps / (10.0 * env.vmax_cps) +
	       t_er;
}

static void test_jam(void **state)
{
	(void)state;
	FOR_REPEATS(i)
	{
		double dm = d_jam_motors();
		struct expect x = {.name = "jammed axis",
				   .ids = {RE_F_CTRL_POSERR, RE_F_CTRL_ENCODER,
					   RE_F_MOTOR_OFF, RE_F_NONE},
				   .axis = 2,
				   .d_relay = dm + d_ctrl_to_relay(),
				   .d_motors = dm};
		struct measured m = {0};

		start(&cs, NULL);
		inject_fault(&cs, "block C 1");
		x.t_inj = joy(&cs, "C fwd");
		expect_fault(&cs, &x, &m);
		quit_latched(&cs, x.name);
		sys_case_stop(&cs);
	}
}

/*
 * Encoder failure seen by the controller (OA): a dead encoder on an axis
 * that cannot move either, with a short OT (20 samples) so that OA comes
 * before the position-error limit; the supervisor reports the controller's
 * encoder failure (or, if it polls between the motor going off and the
 * program latching, the motor found off with stop code 12).
 */
static void test_encoder_failure_oa(void **state)
{
	static const struct sys_subst oa[] = {
	    {"time_samples", "20"},
	    {NULL, NULL},
	};
	struct sys_opts o = {.subst = oa};

	(void)state;
	FOR_REPEATS(i)
	{
		double e_ov = 2.0 / (4.0 * 6.0 * 10.0 / 32768.0);
		double dm = 2 * SYS_LOOPMS + 1000.0 * e_ov / env.vmin_cps + 20 +
			    1000.0 * env.vmin_cps / (10.0 * env.vmax_cps);
		struct expect x = {
		    .name = "encoder failure (OA)",
		    .ids = {RE_F_CTRL_ENCODER, RE_F_MOTOR_OFF, RE_F_NONE},
		    .axis = 0,
		    .d_relay = dm + d_ctrl_to_relay(),
		    .d_motors = dm};
		struct measured m = {0};

		start(&cs, &o);
		inject_fault(&cs, "block A 1");
		inject_fault(&cs, "enc A stuck");
		x.t_inj = joy(&cs, "A fwd");
		expect_fault(&cs, &x, &m);
		if (!strstr(proc_output(&cs.re, PROC_STDOUT), "stop code 12"))
			fail_msg("OA: the FAULT line does not name stop code "
				 "12: %s",
				 proc_output(&cs.re, PROC_STDOUT));
		quit_latched(&cs, x.name);
		sys_case_stop(&cs);
	}
}

/*
 * Limit switch reached: a calibration file whose forward soft limit of C
 * lies one step beyond the last table point (the most re_calfile accepts),
 * i.e. past the forward limit switch; the joystick drives C into it. The
 * controller stops the axis and #LIMSWI latches fault 5. Deadlines from the
 * switch becoming active.
 */
static void write_wide_calibration(char *path, size_t cap)
{
	struct re_calset *set = calloc(1, sizeof(*set));
	struct re_caltable *t;
	char err[512];

	assert_non_null(set);
	snprintf(path, cap, "%s/wide.cal", env.dir);
	if (re_calfile_load(env.cal, NULL, set, err, sizeof(err)) != 0)
		fail_msg("%s", err);
	t = &set->axis[2];
	t->soft_fwd = t->start_counts + t->n * t->step_counts;
	if (re_calfile_save(path, set, err, sizeof(err)) != 0)
		fail_msg("%s", err);
	free(set);
}

static void test_limit_switch(void **state)
{
	char path[SYS_PATH_MAX], quoted[SYS_PATH_MAX + 4];
	struct sys_subst sub[] = {{"file", quoted}, {NULL, NULL}};
	struct sys_opts o = {.subst = sub};

	(void)state;
	write_wide_calibration(path, sizeof(path));
	snprintf(quoted, sizeof(quoted), "\"%s\"", path);
	FOR_REPEATS(i)
	{
		struct expect x = {.name = "limit switch",
				   .ids = {RE_F_CTRL_LIMIT, RE_F_NONE},
				   .axis = 2,
				   .d_relay = 0,
				   .d_motors = SYS_MAINMS};
		struct measured m = {0};

		x.d_relay = SYS_MAINMS + d_ctrl_to_relay();
		start(&cs, &o);
		joy(&cs, "C fwd");
		if (sys_wait_event(&cs, "C forward limit switch active",
				   cs.t_ready_ms, 30000, &x.t_inj) < 0)
			fail_msg("%s", cs.err);
		expect_fault(&cs, &x, &m);
		if (!strstr(proc_output(&cs.re, PROC_STDOUT), "forward"))
			fail_msg("the FAULT line does not say 'forward'");
		quit_latched(&cs, x.name);
		sys_case_stop(&cs);
	}
}

/* ---- joystick ----------------------------------------------------------- */

/* An invalid state: motion stops within a DMC loop; held past the timeout
 * J, thread 1 switches the motors off within J + 2 loops; the program
 * latches within mainms, the supervisor acts in its next cycle. */
static void expect_input_fault(struct sys_case *c, const char *name,
			       double t_inj)
{
	double dm = env.jto_ms + 2 * SYS_LOOPMS;
	struct expect x = {.name = name,
			   .ids = {RE_F_CTRL_INPUT, RE_F_NONE},
			   .axis = -1,
			   .t_inj = t_inj,
			   .d_relay = dm + d_ctrl_to_relay(),
			   .d_motors = dm};
	struct measured m = {0};

	expect_fault(c, &x, &m);
	if (m.motors_ms < env.jto_ms - SYS_LOOPMS)
		fail_msg("%s: motors off after %.0f ms, before the invalid-"
			 "input timeout %d ms",
			 name, m.motors_ms, env.jto_ms);
	quit_latched(c, name);
}

/* A switch stuck closed (forced input 1 = A fwd channel a) at neutral. */
static void test_joy_stuck_channel(void **state)
{
	(void)state;
	FOR_REPEATS(i)
	{
		start(&cs, NULL);
		expect_input_fault(&cs, "joystick channel stuck",
				   inject_fault(&cs, "in 1 1"));
		sys_case_stop(&cs);
	}
}

/* While B moves, channel a of B rev breaks open: motion stops at once, and
 * the state held past the timeout is an INPUT fault. */
static void stopped_within(struct sys_case *c, char axis, double t_inj)
{
	double t, d = 2 * SYS_LOOPMS + 1000.0 / 10.0; /* loop + decel */

	if (sys_wait_stopped(c, axis, 3000, &t) < 0)
		fail_msg("%s", c->err);
	if (t - t_inj > d + SLACK_MS)
		fail_msg("axis %c stopped %.0f ms after the invalid state, "
			 "deadline %.0f ms",
			 axis, t - t_inj, d);
}

static void test_joy_invalid_timeout(void **state)
{
	(void)state;
	FOR_REPEATS(i)
	{
		double t;

		start(&cs, NULL);
		joy(&cs, "B rev");
		if (sys_wait_moving(&cs, 'B', 300, 5000) < 0)
			fail_msg("%s", cs.err);
		t = joy(&cs, "B rev b");
		stopped_within(&cs, 'B', t);
		expect_input_fault(&cs, "invalid state past timeout", t);
		sys_case_stop(&cs);
	}
}

/* A fwd held, then both A rev switches close too. */
static void test_joy_two_directions(void **state)
{
	(void)state;
	FOR_REPEATS(i)
	{
		double t;

		start(&cs, NULL);
		joy(&cs, "A fwd");
		if (sys_wait_moving(&cs, 'A', 300, 5000) < 0)
			fail_msg("%s", cs.err);
		t = inject_fault(&cs, "in 3 1");
		inject_fault(&cs, "in 4 1");
		stopped_within(&cs, 'A', t);
		expect_input_fault(&cs, "two directions", t);
		sys_case_stop(&cs);
	}
}

/* ---- supervisor and link ------------------------------------------------ */

/* SIGKILL mid-motion: nobody writes the heartbeat; the controller's own
 * watchdog stops the robot and switches the motors off within wdto +
 * mainms (+ one sample) of the last heartbeat. The relay stays as it was
 * (nobody is left to switch it): the hard-wired E-stop's job. */
static void sigkill_record(double t_kill, double t_off, double dm)
{
	struct expect x = {.name = "supervisor killed",
			   .ids = {RE_F_NONE},
			   .axis = -1,
			   .t_inj = t_kill,
			   .d_relay = -1,
			   .d_motors = dm,
			   .relay_may_be_on = 1};
	struct measured m = {.relay_ms = -1, .motors_ms = t_off - t_kill};

	record(&x, &m);
}

static void test_sigkill(void **state)
{
	(void)state;
	FOR_REPEATS(i)
	{
		double t_kill, t, dm = env.wdto_ms + SYS_MAINMS + 1;
		char st[2048];

		start(&cs, NULL);
		if (sys_ctl(&cs, "watch fcode") < 0)
			fail_msg("%s", cs.err);
		joy(&cs, "A fwd");
		if (sys_wait_moving(&cs, 'A', 500, 5000) < 0)
			fail_msg("%s", cs.err);
		t_kill = sys_sim_time(&cs);
		proc_signal(&cs.re, SIGKILL);
		proc_wait_exit(&cs.re, EXIT_WAIT_MS, NULL);
		t = wait_motors_off(&cs, t_kill, 5000);
		if (t < 0)
			fail_msg("SIGKILL: the controller did not switch every "
				 "motor off");
		sigkill_record(t_kill, t, dm);
		if (sys_check_safe(&cs, 1, HOLD_MS) < 0 ||
		    sys_state(&cs, st, sizeof(st)) < 0)
			fail_msg("%s", cs.err);
		if (sys_state_num(st, "var.fcode") != 2)
			fail_msg("the program did not latch WATCHDOG (2): %s",
				 st);
		if (t - t_kill > dm + SLACK_MS)
			fail_msg("motors off %.0f ms after SIGKILL, deadline "
				 "%.0f ms",
				 t - t_kill, dm);
		if (sys_log_find(&cs, "RoboELF Ready for Use", NULL, NULL, 0) <
		    0)
			fail_msg("%s", cs.err);
		sys_case_stop(&cs);
	}
}

/* A lost link: the supervisor cuts motor power (COMM: the connection is
 * gone; WATCHDOG: no reply within the critical limit C). */
static void link_fault(const char *name, const char *req, enum re_fault_id id,
		       double d_relay)
{
	FOR_REPEATS(i)
	{
		struct expect x = {.name = name,
				   .ids = {id, RE_F_NONE},
				   .axis = -1,
				   .d_relay = d_relay,
				   .d_motors = d_relay + SYS_MAINMS};
		struct measured m = {0};

		x.link_down = 1;
		start(&cs, NULL);
		joy(&cs, "B fwd");
		if (sys_wait_moving(&cs, 'B', 200, 5000) < 0)
			fail_msg("%s", cs.err);
		x.t_inj = inject_fault(&cs, req);
		expect_fault(&cs, &x, &m);
		quit_latched(&cs, name);
		sys_case_stop(&cs);
	}
}

static void test_link_drop(void **state)
{
	(void)state;
	link_fault("link dropped", "link drop", RE_F_COMM, 2 * P());
}

static void test_link_stall(void **state)
{
	(void)state;
	link_fault("link stalled", "link stall", sys_stall_fault(), C() + P());
}

static void test_link_latency(void **state)
{
	char req[32];

	(void)state;
	snprintf(req, sizeof(req), "link delay %.0f", 2 * C());
	link_fault("link latency", req, sys_stall_fault(), C() + P());
}

/* ---- relay -------------------------------------------------------------- */

/*
 * The relay board fails: the simulator cuts motor power itself (relay off
 * at the injection) and the controller switches the motors off (amplifier
 * fault). The supervisor must notice the lost relay: its reaction is
 * measured on the wall clock, from the injection to the log's first entry
 * naming the ESTOP fault (the FAULT entry, or "while latched" when the
 * controller's amplifier fault was latched first), deadline @d_pc_ms.
 */
static void relay_fault(const char *name, const char *req,
			const enum re_fault_id *ids, double d_pc_ms)
{
	FOR_REPEATS(i)
	{
		struct expect x = {.name = name,
				   .ids = {RE_F_NONE},
				   .axis = -1,
				   .d_relay = 0,
				   .d_motors = SYS_MAINMS};
		struct measured m = {0};
		double w0, w1;

		memcpy(x.ids, ids, sizeof(x.ids));
		start(&cs, NULL);
		w0 = sys_wall_ms();
		x.t_inj = inject_fault(&cs, req);
		expect_fault(&cs, &x, &m);
		if (sys_wait_sim(&cs, x.t_inj + d_pc_ms + SLACK_MS, 5000) < 0 ||
		    sys_log_time_ms(&cs,
				    "FAULT ESTOP: the E-stop relay stopped "
				    "answering",
				    &w1) < 0)
			fail_msg("%s: %s", name, cs.err);
		print_message(
		    "[ MEASURE  ] %s: the supervisor logged the ESTOP "
		    "fault %.0f ms after the injection (deadline "
		    "%.0f)\n",
		    name, w1 - w0, d_pc_ms);
		{
			struct expect y = x;
			struct measured pc = {.relay_ms = w1 - w0,
					      .motors_ms = m.motors_ms};
			char n2[80];

			snprintf(n2, sizeof(n2), "%s (PC)", name);
			y.name = n2;
			y.d_relay = d_pc_ms;
			record(&y, &pc);
		}
		if (w1 - w0 > d_pc_ms + SLACK_MS)
			fail_msg("%s: ESTOP logged %.0f ms after the injection,"
				 " deadline %.0f ms",
				 name, w1 - w0, d_pc_ms);
		quit_latched(&cs, name);
		sys_case_stop(&cs);
	}
}

/* Unplugged: the device node vanishes; the next cycle's check sees it. */
static void test_relay_unplug(void **state)
{
	static const enum re_fault_id ids[4] = {RE_F_ESTOP_LOST, RE_F_NONE};

	(void)state;
	relay_fault("relay unplugged", "relayfault unplug", ids, 2 * P());
}

/* The board swallows every byte: only the Devantech state query notices,
 * after its answer timeout; the amplifier fault comes first. */
static void test_relay_writefail(void **state)
{
	/* The relay drops motor power without the PC's write failing: the
	 * program sees every amplifier lose power (CTRL_POWER; RELAY_POWER
	 * when the relay's off in the reaction is not confirmed either)
	 * unless the relay read-back finds it first (ESTOP_LOST); the
	 * read-back failure is logged either way (as the fault, or "while
	 * latched"). */
	static const enum re_fault_id ids[4] = {
	    RE_F_ESTOP_LOST, RE_F_CTRL_POWER, RE_F_RELAY_POWER, RE_F_NONE};

	(void)state;
	/* R + 2P: the next state query within P, its answer timeout R, the
	 * cycle that sees it within P; plus one P of scheduling allowance, as
	 * for every PC-side deadline (docs/safety.md section 3). */
	relay_fault("relay write failing", "relayfault writefail", ids,
		    env.readback_timeout_ms + 3 * P());
}

/* ---- controller --------------------------------------------------------- */

/* Another host connects while the robot jogs and halts the motion thread
 * (HX1). The connection alone is not a fault (a second supervisor may
 * look); what it does is: the program names the halted thread, and the
 * supervisor, which saw the new handle in the data record, adds that
 * another program had connected (its handle). The axis stops within its
 * tracking step. */
static void test_foreign_connection(void **state)
{
	(void)state;
	FOR_REPEATS(i)
	{
		struct expect x = {.name = "foreign connection",
				   .ids = {RE_F_CTRL_THREAD, RE_F_NONE},
				   .axis = -1,
				   .d_relay = d_ctrl_to_relay(),
				   .d_motors = SYS_MAINMS + 1};
		struct measured m = {0};
		char st[2048];
		double a0, a1;
		int fd;

		start(&cs, NULL);
		joy(&cs, "A fwd");
		if (sys_wait_moving(&cs, 'A', 500, 5000) < 0)
			fail_msg("%s", cs.err);
		if (sys_state(&cs, st, sizeof(st)) < 0)
			fail_msg("%s", cs.err);
		a0 = sys_state_num(st, "A.act");
		x.t_inj = sys_sim_time(&cs);
		fd = sys_cmd_open(&cs);
		if (fd < 0)
			fail_msg("%s", cs.err);
		sys_cmd(fd, "HX1", 2000);
		expect_fault(&cs, &x, &m);
		close(fd);
		{
			const char *w = " Another program had connected to "
					"the controller (handle ";
			const char *p = strstr(m.line, w);

			if (!p || p[strlen(w)] < 'A' || p[strlen(w)] > 'H' ||
			    strncmp(p + strlen(w) + 1, ").", 2))
				fail_msg("the other program is not named: %s",
					 m.line);
		}
		if (sys_state(&cs, st, sizeof(st)) < 0)
			fail_msg("%s", cs.err);
		a1 = sys_state_num(st, "A.act");
		if (a1 - a0 > env.step_counts + 0.05 * env.vmax_cps)
			fail_msg("axis A ran %.0f counts after the connection "
				 "(step %d)",
				 a1 - a0, env.step_counts);
		quit_latched(&cs, x.name);
		sys_case_stop(&cs);
	}
}

/* The controller loses power and restarts: every connection closes. */
static void test_power_cycle(void **state)
{
	(void)state;
	FOR_REPEATS(i)
	{
		struct expect x = {
		    .name = "controller power cycle",
		    .ids = {RE_F_COMM, sys_stall_fault(), RE_F_NONE},
		    .axis = -1,
		    .d_relay = C() + P(),
		    .d_motors = -1};
		struct measured m = {0};
		char line[1024];
		double t;

		x.link_down = 1;
		start(&cs, NULL);
		joy(&cs, "C rev");
		if (sys_wait_moving(&cs, 'C', 200, 5000) < 0)
			fail_msg("%s", cs.err);
		x.t_inj = inject_fault(&cs, "power-cycle");
		if (sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) <
			0 ||
		    sys_wait_event(&cs, "relay off", x.t_inj, 3000, &t) < 0)
			fail_msg("%s", cs.err);
		m.relay_ms = t - x.t_inj;
		m.motors_ms = -1;
		record(&x, &m);
		match_fault_line(&cs, &x, line);
		if (sys_check_safe(&cs, 0, HOLD_MS) < 0 ||
		    sys_truth_check(&cs, line, x.t_inj, 0) < 0)
			fail_msg("%s", cs.err);
		if (m.relay_ms > x.d_relay + SLACK_MS)
			fail_msg("relay off %.0f ms after the power cycle, "
				 "deadline %.0f ms",
				 m.relay_ms, x.d_relay);
		quit_latched(&cs, x.name);
		sys_case_stop(&cs);
	}
}

/* On a quit the supervisor switches the motors off through the
 * controller before it cuts motor power: no motor may go off by the
 * amplifier fault that the power cut causes. */
static void motors_by_command(struct sys_case *c, double after)
{
	for (size_t i = 0; i < c->nev; i++)
		if (c->ev[i].t_ms >= after &&
		    !strncmp(c->ev[i].text, "axis ", 5) &&
		    strstr(c->ev[i].text, "motor off: amplifier fault"))
			fail_msg("quit: the motors were not switched off "
				 "before the relay: %s",
				 c->ev[i].text);
}

/* ---- the operator quits during motion ----------------------------------- */

static void test_operator_quit(void **state)
{
	(void)state;
	FOR_REPEATS(i)
	{
		double t_q, t, d = 2 * P();
		struct expect x = {.name = "operator quit",
				   .ids = {RE_F_NONE},
				   .axis = -1,
				   .d_relay = d,
				   .d_motors = d};
		struct measured m = {0};
		char line[2048];
		int status;

		start(&cs, NULL);
		joy(&cs, "A rev");
		if (sys_wait_moving(&cs, 'A', 500, 5000) < 0)
			fail_msg("%s", cs.err);
		t_q = sys_sim_time(&cs);
		proc_signal(&cs.re, SIGTERM);
		if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0)
			fail_msg("roboelf did not exit within %d ms of "
				 "SIGTERM",
				 EXIT_WAIT_MS);
		assert_int_equal(proc_exit_code(&cs.re), 0);
		if (proc_find_line(&cs.re, PROC_STDOUT, "FAULT ", NULL, 0) == 0)
			fail_msg("a FAULT line on a clean quit: %s",
				 proc_output(&cs.re, PROC_STDOUT));
		if (sys_wait_event(&cs, "relay off", t_q, 3000, &t) < 0)
			fail_msg("%s", cs.err);
		m.relay_ms = t - t_q;
		t = wait_motors_off(&cs, t_q, 3000);
		if (t < 0)
			fail_msg("not every motor was switched off on quit");
		m.motors_ms = t - t_q;
		if (sys_check_safe(&cs, 0, HOLD_MS) < 0)
			fail_msg("%s", cs.err);
		if (sys_log_find(&cs, "stop: ", "SIGTERM", NULL, 0) < 0)
			fail_msg("%s", cs.err);
		if (sys_log_find(&cs, "shutdown:", NULL, line, sizeof(line)) ==
		    0)
			fail_msg("quit: the stop command failed: %s", line);
		motors_by_command(&cs, t_q);
		x.t_inj = t_q;
		record(&x, &m);
		if (m.relay_ms > d + SLACK_MS || m.motors_ms > d + SLACK_MS)
			fail_msg("quit: relay off %.0f ms, motors off %.0f ms "
				 "after SIGTERM, deadline %.0f ms",
				 m.relay_ms, m.motors_ms, d);
		sys_case_stop(&cs);
	}
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_pot_offset),		T(test_pot_stuck),
	    T(test_pot_open),		T(test_enc_stuck),
	    T(test_enc_slip),		T(test_jam),
	    T(test_encoder_failure_oa), T(test_limit_switch),
	    T(test_joy_stuck_channel),	T(test_joy_invalid_timeout),
	    T(test_joy_two_directions), T(test_sigkill),
	    T(test_link_drop),		T(test_link_stall),
	    T(test_link_latency),	T(test_relay_unplug),
	    T(test_relay_writefail),	T(test_foreign_connection),
	    T(test_power_cycle),	T(test_operator_quit),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
