/*
 * test_sys_phases.c - "every phase supervised" (docs/supervisor.md) on the
 * whole system: galil-sim's short robot (limit switches A, B at +-10000, C
 * at +-8000 counts, so that a full calibration takes about 7 s) running
 * dmc/ (downloaded by galil-load), roboelf supervising it through the
 * virtual relay.
 *
 * One full calibration for the binary (group setup; it also measures the
 * phase boundaries from galil-sim's events), then every case on a fresh
 * galil-sim. Times are galil-sim's simulated ms (its `events` and `time`
 * answers). The cases:
 *
 *  - kill-anywhere: SIGKILL at 33 instants spread over every phase
 *    (start-up with the relay open, with it closed, the service state
 *    requested, full calibration, centring after a calibration from the
 *    file, back to safe, the arm requested, armed at rest, armed jogging,
 *    latched), then one instant per phase with the controller's motor-power
 *    output wired (power_output 3): every motor off and at rest within the
 *    controller's deadline, or off already; motor power cut as well;
 *  - freeze-anywhere: SIGSTOP for 2 s in each phase, then SIGCONT: the
 *    same deadline during the stop, then the FAULT line names the stall;
 *  - fault-anywhere: every class of the fault matrix (test_sys_faults.c)
 *    injected during a full calibration and during centring;
 *  - link loss with the amplifier model off (--no-amp-undervoltage): who
 *    stops the motors when the controller cannot see motor power go;
 *  - a wedged relay board, alone and with a fault: the stop, the FAULT
 *    line, the exit;
 *  - signals: SIGQUIT, SIGHUP, SIGTERM end in the orderly power-off,
 *    SIGTSTP is ignored;
 *  - centring from off-centre, then armed: no fault.
 *
 * A case of many instants runs them all, prints a [ MEASURE ] line for
 * each and a [  FAILS   ] line for each failed assertion, then fails.
 *
 * Environment: ROBOELF_BIN, ROBOELF_TOP (see sys_h.h), ROBOELF_KEEP=1
 * keeps the temporary directory (configurations, logs and the events of
 * every case), ROBOELF_SYS_FILTER=PATTERN runs only the matching tests.
 */
#include <math.h>
#include <poll.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "re_calfile.h"
#include "sys_h.h"

/* ---- the configuration every case uses (written by write_config()) ------ */

#define PERIOD_MS   50	 /* period_ms: P, armed */
#define NONCRIT_F   1.5	 /* watchdog.noncritical_factor */
#define CRIT_F	    2.5	 /* watchdog.critical_factor: C = 125 ms */
#define WDTO_MS	    200	 /* watchdog.controller_timeout_ms (DMC wdto) */
#define JTO_MS	    500	 /* joystick.invalid_timeout_ms */
#define VMIN_CPS    2000 /* every axis */
#define VMAX_CPS    8000
#define STEP_COUNTS 1000
#define ER_COUNTS   800 /* below the step (the program's arm check 7) */
#define NEAR_MARGIN 500 /* counts: potlo 0.125 V on C (open wiper outside) */
#define PERSIST	    1	/* persistence_cycles */
#define ALLOWED_ERR 0.5 /* allowed_error */
#define READBACK_MS 500 /* relay.readback_timeout_ms */
#define POWER_OUT   3	/* controller.power_output in the wired variant */
#define SAMPLE_MS   1	/* galil-sim's servo sample (TM 1000) */

/*
 * The controller-side deadline (docs/dmc-interface.md, fault 2): thread 0
 * sees a change of hbpc up to mainms late and checks every mainms, so it
 * switches every motor off within wdto + mainms (+ one servo sample) of
 * the last heartbeat change. A dead or frozen supervisor writes nothing
 * after the signal, so its last change is before the signal: every motor
 * must be off by
 *
 *     t_signal + WDTO_MS + SYS_MAINMS + SAMPLE_MS        (= 211 ms)
 *
 * where t_signal is galil-sim's simulated time read just after kill()
 * returned (the signal was sent in [t_before, t_signal]; see signal_at()).
 */
#define D_CTRL_MS (WDTO_MS + SYS_MAINMS + SAMPLE_MS)

/* The program opens the power output (OP 0) in the same pass as MO ABC;
 * galil-sim's plant reads the output at its next servo sample (the event
 * "power output N cleared" is "seen at the next servo sample",
 * docs/galil-sim.md): motor power is gone one sample after the motors. */
#define D_POWER_MS (D_CTRL_MS + SAMPLE_MS)

#define SLACK_MS	25  /* scheduling allowance, as test_sys_faults */
#define HOLD_MS		200 /* no motion over this after the safe state */
#define START_MS	10000
#define READY_MS	30000 /* --calibration file to Ready */
#define CAL_READY_MS	90000 /* --calibration full to Ready */
#define FAULT_WAIT_MS	8000
#define EXIT_WAIT_MS	5000
#define FREEZE_MS	2000
#define FREEZE_SLACK_MS 5    /* see check_stall_line() */
#define WEDGE_EXIT_MS	1000 /* SIGTERM to exit with a wedged relay */
#define TV_REST_MS	500  /* > tvwin (400 ms, dmc/constants.dmc) */

/* Where the off-centre robot is put before a calibration from the file,
 * so that centring is a real move (counts; inside the calibrated soft
 * limits, outside the slow zones). */
static const double off_centre[3] = {-8000, 8000, -6500};

static struct sys_env env;
static int env_ok;
static struct sys_case cs;
static char plant_path[SYS_PATH_MAX + 16];

/* Measured in the group setup's full calibration (simulated ms). */
static struct {
	double t_service; /* the service state began: motors on */
	double d_cal;	  /* service begin to the end of the service state */
	double d_centre;  /* centring from off_centre (computed) */
	double centre[3]; /* the calibrated centres */
} ref;

/* ---- failures collected over many instants ------------------------------ */

/* A case of many instants reports every failing instant, then fails. */
static char fails[16384];
static size_t nfails;

static void add_fail(const char *fmt, ...)
    __attribute__((format(printf, 1, 2)));

static void add_fail(const char *fmt, ...)
{
	size_t len = strlen(fails);
	va_list ap;

	nfails++;
	if (len + 8 >= sizeof(fails))
		return;
	fails[len++] = '\n';
	fails[len++] = ' ';
	fails[len++] = ' ';
	fails[len] = '\0';
	va_start(ap, fmt);
	vsnprintf(fails + len, sizeof(fails) - len, fmt, ap);
	va_end(ap);
}

static void reset_fails(void)
{
	fails[0] = '\0';
	nfails = 0;
}

static void check_fails(const char *what)
{
	const char *p = fails;

	if (!nfails)
		return;
	/* line by line: cmocka's message buffers are short */
	while (*p) {
		size_t n = strcspn(p + 1, "\n") + 1;

		print_message("[  FAILS   ] %s:%.*s\n", what, (int)n - 1,
			      p + 1);
		p += n;
	}
	fail_msg("%s: %zu failure(s), listed above", what, nfails);
}

/* ---- configuration, plant, rig ------------------------------------------ */

struct ph_opts {
	const char *calibration; /* "full" or "file" */
	int power_output;	 /* 0 or POWER_OUT (config and galil-sim) */
	int no_amp_uv;		 /* galil-sim --no-amp-undervoltage */
	int off_centre;		 /* put the robot at off_centre[] first */
};

static int write_text(const char *path, const char *text)
{
	FILE *f = fopen(path, "w");

	if (!f)
		return -1;
	fputs(text, f);
	return fclose(f);
}

/* The short robot's configuration (travel 20000 / 20000 / 16000). OT 1000
 * samples, so that a jam trips the position error, as test_sys_basic. */
static int write_config(const char *path, const char *log, int power_output)
{
	static const char axis_fmt[] =
	    "  - {name: %s, travel_counts: %d, vmin: %d, vmax: %d,\n"
	    "     step_counts: %d, position_error_limit_counts: %d,\n"
	    "     allowed_error: %g, persistence_cycles: %d,\n"
	    "     encoder_failure: {time_samples: 1000}}\n";
	static const char *const names[3] = {"A", "B", "C"};
	static const int travel[3] = {20000, 20000, 16000};
	char text[4096];
	int n;

	n = snprintf(text, sizeof(text),
		     "mode: development\nperiod_ms: %d\n"
		     "controller: {power_output: %d}\n"
		     "relay: {readback: true, readback_timeout_ms: %d}\n"
		     "watchdog: {noncritical_factor: %g, critical_factor: "
		     "%g,\n  controller_timeout_ms: %d}\n"
		     "joystick: {invalid_timeout_ms: %d}\n"
		     "calibration: {file: \"%s\", near_margin_counts: %d}\n"
		     "log: {path: \"%s\"}\naxes:\n",
		     PERIOD_MS, power_output, READBACK_MS, NONCRIT_F, CRIT_F,
		     WDTO_MS, JTO_MS, env.cal, NEAR_MARGIN, log);
	for (int i = 0; i < 3; i++)
		n += snprintf(text + n, sizeof(text) - (size_t)n, axis_fmt,
			      names[i], travel[i], VMIN_CPS, VMAX_CPS,
			      STEP_COUNTS, ER_COUNTS, ALLOWED_ERR, PERSIST);
	return write_text(path, text);
}

/* The figures sys_h's deadlines read, from the configuration above. */
static void env_figures(void)
{
	env.period_ms = PERIOD_MS;
	env.noncrit_factor = NONCRIT_F;
	env.crit_factor = CRIT_F;
	env.wdto_ms = WDTO_MS;
	env.jto_ms = JTO_MS;
	env.persistence = PERSIST;
	env.allowed_error = ALLOWED_ERR;
	env.vmin_cps = VMIN_CPS;
	env.vmax_cps = VMAX_CPS;
	env.step_counts = STEP_COUNTS;
	env.er_counts = ER_COUNTS;
	env.readback_timeout_ms = READBACK_MS;
}

static void seterr(struct sys_case *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void seterr(struct sys_case *c, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(c->err, sizeof(c->err), fmt, ap);
	va_end(ap);
}

static const char *tail(const struct proc *p, enum proc_stream s, size_t n)
{
	const char *t = proc_output(p, s);
	size_t len = strlen(t);

	return len > n ? t + len - n : t;
}

static int galil_load(struct sys_case *c)
{
	char bin[SYS_PATH_MAX + 16], addr[32], dmc[SYS_PATH_MAX + 8];
	char *argv[] = {
	    bin,    (char *)"-a", addr, (char *)"--start", (char *)"--config",
	    c->cfg, dmc,	  NULL};
	struct proc p;
	int rc = -1;

	snprintf(bin, sizeof(bin), "%s/galil-load", env.bin);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", c->sim.port);
	snprintf(dmc, sizeof(dmc), "%s/dmc", env.top);
	if (proc_spawn(&p, argv, NULL) < 0) {
		seterr(c, "cannot start '%s'", bin);
		return -1;
	}
	if (proc_wait_exit(&p, START_MS, NULL) < 0)
		seterr(c, "galil-load did not finish within %d ms", START_MS);
	else if (proc_exit_code(&p) != 0)
		seterr(c, "galil-load exited with %d: %s", proc_exit_code(&p),
		       tail(&p, PROC_STDERR, 600));
	else
		rc = 0;
	proc_kill(&p);
	return rc;
}

static int wait_sim_fine(struct sys_case *c, double t, int timeout_ms);

/* One host command on @fd that must answer ':'. */
static int host_cmd(struct sys_case *c, int fd, const char *cmd)
{
	if (sys_cmd(fd, cmd, 2000) == 0)
		return 0;
	seterr(c, "host command '%s' refused or unanswered", cmd);
	return -1;
}

/* Every axis at @x (encoder = reference = true position) and at rest. */
static int wait_at(struct sys_case *c, const double *x, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	char st[2048];

	for (;;) {
		int at = 0;

		if (sys_state(c, st, sizeof(st)) < 0)
			return -1;
		for (int i = 0; i < 3; i++) {
			char kp[8], kv[8];

			snprintf(kp, sizeof(kp), "%c.act", 'A' + i);
			snprintf(kv, sizeof(kv), "%c.vel", 'A' + i);
			at += fabs(sys_state_num(st, kp) - x[i]) < 2 &&
			      sys_state_num(st, kv) == 0;
		}
		if (at == 3)
			return 0;
		if (proc_now_ms() > deadline) {
			seterr(c, "the robot did not reach its start: %s", st);
			return -1;
		}
		poll(NULL, 0, 10);
	}
}

/*
 * The robot left off-centre with the controller powered (a previous session
 * jogged it there): before roboelf starts, a host halts the program, moves
 * every axis to off_centre[] with motor power on, switches the motors and
 * power off again and restarts the program. The encoders keep counting, so
 * a calibration file made at the centre still fits and centring moves.
 */
static int preposition(struct sys_case *c, int power_output)
{
	static const char *const pre[] = {"prun=0", "HX", "AB 1", "MO ABC"};
	char cmd[128];
	int fd = sys_cmd_open(c), rc = -1;
	double t;

	if (fd < 0)
		return -1;
	for (size_t i = 0; i < sizeof(pre) / sizeof(pre[0]); i++)
		if (host_cmd(c, fd, pre[i]) < 0)
			goto out;
	if (sys_ctl(c, "relay on") < 0)
		goto out;
	snprintf(cmd, sizeof(cmd), "SB %d", power_output);
	if ((power_output && host_cmd(c, fd, cmd) < 0) ||
	    host_cmd(c, fd, "SH ABC") < 0 ||
	    host_cmd(c, fd, "SP 30000,30000,30000") < 0)
		goto out;
	snprintf(cmd, sizeof(cmd), "PA %.0f,%.0f,%.0f", off_centre[0],
		 off_centre[1], off_centre[2]);
	if (host_cmd(c, fd, cmd) < 0 || host_cmd(c, fd, "BG ABC") < 0 ||
	    wait_at(c, off_centre, 5000) < 0 || host_cmd(c, fd, "MO ABC") < 0)
		goto out;
	snprintf(cmd, sizeof(cmd), "CB %d", power_output);
	if ((power_output && host_cmd(c, fd, cmd) < 0) ||
	    sys_ctl(c, "relay off") < 0 || host_cmd(c, fd, "XQ #AUTO,0") < 0)
		goto out;
	/* at rest for longer than TV's average (256 samples) and the
	 * program's tvwin (400 ms): the robot has stood still since then */
	t = sys_sim_time(c);
	if (t < 0 || wait_sim_fine(c, t + TV_REST_MS, 5000) < 0)
		goto out;
	rc = 0;
out:
	close(fd);
	return rc;
}

static int start_roboelf(struct sys_case *c, const char *calibration)
{
	char bin[SYS_PATH_MAX + 16], addr[32];
	char *argv[] = {bin,
			(char *)"-c",
			c->cfg,
			(char *)"--galil",
			addr,
			(char *)"--relay",
			c->relay_link,
			(char *)"--calibration",
			(char *)calibration,
			(char *)"--log",
			c->log,
			NULL};

	snprintf(bin, sizeof(bin), "%s/roboelf", env.bin);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", c->sim.port);
	if (proc_spawn(&c->re, argv, NULL) < 0) {
		seterr(c, "cannot start '%s'", bin);
		return -1;
	}
	c->re_up = 1;
	return 0;
}

/*
 * ph_start() - a fresh galil-sim (the short robot), dmc/ loaded and
 * started, the robot put off-centre if asked, roboelf started; returns
 * without waiting for anything of roboelf's. The control port watches
 * the program's state, fault code and the supervisor's heartbeat hbpc.
 * Return: 0, or -1 with c->err set.
 */
static int ph_start(struct sys_case *c, const struct ph_opts *o)
{
	char pout[8];
	char *extra[8];
	int n = 0;

	memset(c, 0, sizeof(*c));
	c->ctl = -1;
	c->env = &env;
	snprintf(c->sim_addr, sizeof(c->sim_addr), "127.0.0.1");
	c->id = ++env.ncase;
	snprintf(c->relay_link, sizeof(c->relay_link), "%s/relay-%d", env.dir,
		 c->id);
	snprintf(c->log, sizeof(c->log), "%s/case-%d.log", env.dir, c->id);
	snprintf(c->cfg, sizeof(c->cfg), "%s/case-%d.yaml", env.dir, c->id);
	c->bufcap = 512 * 1024;
	c->buf = malloc(c->bufcap);
	if (!c->buf || write_config(c->cfg, c->log, o->power_output) < 0) {
		seterr(c, "cannot write '%s'", c->cfg);
		return -1;
	}
	extra[n++] = (char *)"--plant";
	extra[n++] = plant_path;
	if (o->power_output) {
		snprintf(pout, sizeof(pout), "%d", o->power_output);
		extra[n++] = (char *)"--power-output";
		extra[n++] = pout;
	}
	if (o->no_amp_uv)
		extra[n++] = (char *)"--no-amp-undervoltage";
	extra[n] = NULL;
	if (proc_sim_start(&c->sim, env.bin, c->relay_link, extra, START_MS) <
	    0) {
		seterr(c, "galil-sim did not start");
		return -1;
	}
	c->sim_up = 1;
	c->ctl = proc_ctl_connect(c->sim.ctl_port, START_MS);
	if (c->ctl < 0) {
		seterr(c, "cannot connect to the control port");
		return -1;
	}
	if (galil_load(c) < 0 ||
	    (o->off_centre && preposition(c, o->power_output) < 0) ||
	    sys_ctl(c, "watch state") < 0 || sys_ctl(c, "watch fcode") < 0 ||
	    sys_ctl(c, "watch hbpc") < 0 || sys_ctl(c, "watch armreq") < 0 ||
	    sys_ctl(c, "watch mneut") < 0 || sys_events(c) < 0)
		return -1;
	return start_roboelf(c, o->calibration);
}

/* Ready within @timeout_ms, or a message with roboelf's output. */
static int wait_ready(struct sys_case *c, int timeout_ms)
{
	long long t0 = proc_now_ms(), deadline = t0 + timeout_ms;

	for (;;) {
		if (proc_wait_line(&c->re, PROC_STDOUT, "RoboELF Ready for Use",
				   20, NULL, 0) == 0) {
			c->ready_wall_s = (double)(proc_now_ms() - t0) / 1e3;
			c->t_ready_ms = sys_sim_time(c);
			/* The program moves an axis only after it has seen the
			 * joystick at neutral since arming (#MSTEP's mneut): a
			 * command pressed before its first look is ignored
			 * until released. On a loaded machine that look can
			 * come after Ready is printed; wait for it. */
			return c->t_ready_ms < 0 ||
				       sys_wait_state(c, "var.mneut", "1.0000",
						      5000) < 0
				   ? -1
				   : 0;
		}
		if (proc_find_line(&c->re, PROC_STDOUT, "FAULT ", NULL, 0) ==
			0 ||
		    c->re.out[PROC_STDOUT].fd < 0 || proc_now_ms() > deadline)
			break;
	}
	{
		char fault[1024] = "";

		proc_find_line(&c->re, PROC_STDOUT, "FAULT ", fault,
			       sizeof(fault));
		seterr(c,
		       "no 'RoboELF Ready for Use' within %d ms%s%s\n--- "
		       "stdout:\n%s",
		       timeout_ms, fault[0] ? ": " : "", fault,
		       tail(&c->re, PROC_STDOUT, 500));
	}
	return -1;
}

/* Wait until the simulated time reaches @t (2 ms polls: the instants of a
 * kill are chosen to a few ms). */
static int wait_sim_fine(struct sys_case *c, double t, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;

	for (;;) {
		double now = sys_sim_time(c);

		if (now < 0)
			return -1;
		if (now >= t)
			return 0;
		if (proc_now_ms() > deadline) {
			seterr(c, "simulated time %.0f not reached (now %.0f)",
			       t, now);
			return -1;
		}
		proc_pump(&c->re, 0);
		poll(NULL, 0, 2);
	}
}

/* Send @sig to roboelf; return the simulated time just after kill()
 * returned (the signal went between the two readings; *t_before gets the
 * first), or -1. */
static double signal_at(struct sys_case *c, int sig, double *t_before)
{
	double t0 = sys_sim_time(c), t1;

	if (t0 < 0 || proc_signal(&c->re, sig) < 0)
		return -1;
	t1 = sys_sim_time(c);
	if (t_before)
		*t_before = t0;
	return t1;
}

/* ---- the group ---------------------------------------------------------- */

static int first_event_time(struct sys_case *c, const char *prefix,
			    double after, double *t)
{
	int i = sys_event_find(c, prefix, after);

	if (i < 0)
		return -1;
	*t = c->ev[i].t_ms;
	return 0;
}

/* The phase boundaries of the reference calibration, from its events. */
static int measure_reference(struct sys_case *c)
{
	double t_off;

	if (sys_events(c) < 0 ||
	    first_event_time(c, "axis A motor on: SH (thread 0", 0,
			     &ref.t_service) < 0 ||
	    first_event_time(c, "axis A motor off: ", ref.t_service, &t_off) <
		0) {
		seterr(c, "the reference calibration's events lack the "
			  "service state");
		return -1;
	}
	ref.d_cal = t_off - ref.t_service;
	return 0;
}

/* Centring from off_centre[] at the travel speed (vmax): the longest axis
 * distance at VMAX_CPS plus the ramp (AC = 10 x the service speed). */
static int centring_time(void)
{
	struct re_calset *set = calloc(1, sizeof(*set));
	char err[512];
	double d = 0;

	if (!set ||
	    re_calfile_load(env.cal, NULL, set, err, sizeof(err)) != 0) {
		free(set);
		return -1;
	}
	for (int i = 0; i < 3; i++) {
		const struct re_caltable *t = &set->axis[i];

		ref.centre[i] = (t->soft_rev + t->soft_fwd) / 2;
		if (fabs(off_centre[i] - ref.centre[i]) > d)
			d = fabs(off_centre[i] - ref.centre[i]);
	}
	ref.d_centre = 1000.0 * d / VMAX_CPS + 1000.0 / 10.0;
	free(set);
	return 0;
}

static int calibrate(void)
{
	struct ph_opts o = {.calibration = "full"};
	struct stat st;
	int rc = -1;

	if (ph_start(&cs, &o) < 0 || wait_ready(&cs, CAL_READY_MS) < 0 ||
	    measure_reference(&cs) < 0) {
		snprintf(env.err, sizeof(env.err), "%s", cs.err);
		goto out;
	}
	env.calib_s = cs.ready_wall_s;
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, NULL) < 0 ||
	    proc_exit_code(&cs.re) != 0)
		snprintf(env.err, sizeof(env.err),
			 "roboelf did not quit cleanly after calibrating");
	else if (stat(env.cal, &st) < 0 || centring_time() < 0)
		snprintf(env.err, sizeof(env.err), "no usable '%s'", env.cal);
	else
		rc = 0;
out:
	sys_case_stop(&cs);
	return rc;
}

static int group_setup(void **state)
{
	(void)state;
	if (sys_env_init(&env) == 0) {
		env_figures();
		snprintf(plant_path, sizeof(plant_path), "%s/plant.yaml",
			 env.dir);
		if (write_text(plant_path,
			       "axes:\n"
			       "  A: {rev_limit: -10000, fwd_limit: 10000}\n"
			       "  B: {rev_limit: -10000, fwd_limit: 10000}\n"
			       "  C: {rev_limit: -8000, fwd_limit: 8000}\n") ==
			0 &&
		    calibrate() == 0)
			env_ok = 1;
	}
	print_message("[   INFO   ] full calibration %s in %.1f s: service "
		      "state %.0f ms, centring from off-centre ~%.0f ms (%s)"
		      "%s%s\n",
		      env_ok ? "done" : "FAILED", env.calib_s, ref.d_cal,
		      ref.d_centre, env.dir, env_ok ? "" : ": ",
		      env_ok ? "" : env.err);
	return 0;
}

static int group_teardown(void **state)
{
	(void)state;
	if (!env_ok)
		env.keep = 1;
	sys_env_cleanup(&env);
	return 0;
}

static int case_teardown(void **state)
{
	(void)state;
	sys_case_stop(&cs);
	return 0;
}

static void need_env(void)
{
	if (!env_ok)
		fail_msg("no calibrated environment: %s", env.err);
}

/* ---- phases and instants ------------------------------------------------ */

enum phase {
	PH_BOOT,    /* start-up, the relay open (motors off) */
	PH_RELAY,   /* start-up, relay closed, service not requested */
	PH_SVCREQ,  /* the service state requested, not yet entered */
	PH_CALIB,   /* full calibration (service state) */
	PH_CENTRE,  /* calibration from the file: check and centring */
	PH_OFF,	    /* back to safe after the service state */
	PH_ARMREQ,  /* the armed state requested, not yet entered */
	PH_ARMED,   /* armed, at rest */
	PH_JOG,	    /* armed, axis A jogging */
	PH_LATCHED, /* a fault latched */
	PH_COUNT
};

static const char *const ph_name[PH_COUNT] = {
    "start-up, relay open", "start-up, relay closed",
    "service requested",    "full calibration",
    "centring (file)",	    "back to safe",
    "arm requested",	    "armed at rest",
    "armed jogging",	    "latched",
};

/* One instant: a phase and where in it. @line: for PH_BOOT, the progress
 * line roboelf has just printed; @at_ms: ms after the phase's anchor (the
 * service state's begin, Ready, the joystick command, the FAULT line). */
struct instant {
	enum phase ph;
	const char *line;
	double at_ms;
};

#define L_POWER_ON "roboelf: motor power on (relay closed)"
#define L_ARMING   "roboelf: soft limits from the calibration; arming"
#define SVC_ON	   "axis A motor on: SH (thread 0"

static int wait_line(struct sys_case *c, const char *prefix, int timeout_ms)
{
	if (proc_wait_line(&c->re, PROC_STDOUT, prefix, timeout_ms, NULL, 0) ==
	    0)
		return 0;
	seterr(c, "no line '%s' from roboelf within %d ms\n--- stdout:\n%s",
	       prefix, timeout_ms, tail(&c->re, PROC_STDOUT, 1500));
	return -1;
}

/* Poll the state line as fast as it answers (a window of start-up is a few
 * ms wide) until the watched @var equals @value, or with @nonzero is not
 * 0, at most @timeout_ms. */
static int poll_var(struct sys_case *c, const char *var, double value,
		    int nonzero, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	char st[2048];

	for (;;) {
		double v;

		if (sys_state(c, st, sizeof(st)) < 0)
			return -1;
		v = sys_state_num(st, var);
		if (nonzero ? (v != 0 && !isnan(v)) : v == value)
			return 0;
		if (proc_now_ms() > deadline) {
			seterr(c, "%s never became %s%.0f: %s", var,
			       nonzero ? "non-zero, not " : "", value, st);
			return -1;
		}
		proc_pump(&c->re, 0);
	}
}

/*
 * The arm request sent, the armed state not entered: roboelf writes
 * "hbpc=<n>;armreq=1" after L_ARMING (and the soft-limit writes behind
 * it); the program takes armreq back to 0 within mainms and arms some
 * 30 ms later (#PCHK). So: armreq seen at 1, or hbpc changed since the
 * line, while the state is still 0.
 */
static int poll_arm_request(struct sys_case *c, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	double hb0 = NAN;
	char st[2048];

	for (;;) {
		double hb;

		if (sys_state(c, st, sizeof(st)) < 0)
			return -1;
		hb = sys_state_num(st, "var.hbpc");
		if (sys_state_num(st, "var.state") != 0) {
			seterr(c, "the arm request was missed: %s", st);
			return -1;
		}
		if (sys_state_num(st, "var.armreq") == 1 ||
		    (!isnan(hb0) && hb != hb0))
			return 0;
		hb0 = isnan(hb0) ? hb : hb0;
		if (proc_now_ms() > deadline) {
			seterr(c, "no arm request within %d ms: %s", timeout_ms,
			       st);
			return -1;
		}
	}
}

/* Drive a fresh case to the instant @in. @anchor: [out] the simulated time
 * of the phase's anchor (-1 where none). Return: 0 or -1 (c->err). */
static int reach(struct sys_case *c, const struct instant *in, int power_output,
		 double *anchor)
{
	struct ph_opts o = {.calibration = in->ph == PH_CALIB ? "full" : "file",
			    .power_output = power_output,
			    .off_centre = in->ph == PH_CENTRE};
	double t = -1;

	*anchor = -1;
	if (ph_start(c, &o) < 0)
		return -1;
	switch (in->ph) {
	case PH_BOOT: return wait_line(c, in->line, START_MS);
	case PH_RELAY: return wait_line(c, L_POWER_ON, START_MS);
	case PH_SVCREQ:
		/* the request carries the session's first heartbeat */
		return wait_line(c, "roboelf: controller configured",
				 START_MS) < 0 ||
			       poll_var(c, "var.hbpc", 0, 1, 2000) < 0
			   ? -1
			   : 0;
	case PH_CALIB:
	case PH_CENTRE:
		if (sys_wait_event(c, SVC_ON, 0, READY_MS, &t) < 0)
			return -1;
		*anchor = t;
		return wait_sim_fine(c, t + in->at_ms, READY_MS);
	case PH_OFF:
		return poll_var(c, "var.state", 3, 0, READY_MS) < 0 ||
			       poll_var(c, "var.state", 0, 0, 2000) < 0
			   ? -1
			   : 0;
	case PH_ARMREQ:
		return poll_var(c, "var.state", 3, 0, READY_MS) < 0 ||
			       wait_line(c, L_ARMING, 2000) < 0 ||
			       poll_arm_request(c, 2000) < 0
			   ? -1
			   : 0;
	case PH_ARMED:
	case PH_JOG:
	case PH_LATCHED: break;
	default: seterr(c, "bad phase %d", (int)in->ph); return -1;
	}
	if (wait_ready(c, READY_MS) < 0)
		return -1;
	t = c->t_ready_ms;
	if (in->ph == PH_JOG) {
		double t0 = sys_sim_time(c);

		if (sys_ctl(c, "joy A fwd") < 0 ||
		    sys_wait_event(c, "input: joy A fwd", t0, 2000, &t) < 0)
			return -1;
	} else if (in->ph == PH_LATCHED) {
		char line[1024];

		if (sys_ctl(c, "pot A offset 0.5") < 0 ||
		    sys_wait_fault(c, FAULT_WAIT_MS, line, sizeof(line)) < 0 ||
		    (t = sys_sim_time(c)) < 0)
			return -1;
	}
	*anchor = t;
	return wait_sim_fine(c, t + in->at_ms, 5000);
}

/* The phase the signal at @t_sig really met, from galil-sim's events (the
 * windows of start-up are a few ms wide; the test reports what it hit). */
static enum phase actual_phase(const struct sys_case *c, enum phase intent,
			       double t_sig, double hbpc)
{
	int svc = sys_event_find(c, SVC_ON, 0);
	double t_svc = svc >= 0 ? c->ev[svc].t_ms : 1e300;
	int off = sys_event_find(c, "axis A motor off", t_svc);
	int thr = sys_event_find(c, "thread 1 started", 0);

	if (intent == PH_LATCHED)
		return PH_LATCHED;
	if (sys_event_find(c, "relay on (byte", 0) < 0 ||
	    c->ev[sys_event_find(c, "relay on (byte", 0)].t_ms > t_sig)
		return PH_BOOT;
	if (t_svc > t_sig)
		return hbpc != 0 ? PH_SVCREQ : PH_RELAY;
	if (thr >= 0 && c->ev[thr].t_ms <= t_sig)
		return intent == PH_JOG ? PH_JOG : PH_ARMED;
	if (off >= 0 && c->ev[off].t_ms <= t_sig)
		/* whether armreq was written: seen by reach() */
		return intent == PH_ARMREQ ? PH_ARMREQ : PH_OFF;
	return intent == PH_CENTRE ? PH_CENTRE : PH_CALIB;
}

/* ---- after a kill or a freeze: who switched the motors off, when -------- */

struct off_result {
	int on_at_sig;	 /* some motor was on at the signal */
	int on_after;	 /* some motor was switched on after it */
	double off_ms;	 /* last motor off after the signal, ms; -1 none */
	char by[64];	 /* who switched that one off: "(thread 0 line 381)" */
	double pout_ms;	 /* "power output N cleared" after the signal; -1 */
	double fcode;	 /* the program's latched fault at the end */
	char st_d[2048]; /* the state line at D_POWER_MS (a few ms after) */
	char st[2048];	 /* the state line at the end */
};

/* "... (thread 0 line 381)" -> "thread 0 line 381" */
static void source_of(const char *text, char *by, size_t cap)
{
	const char *p = strrchr(text, '(');
	size_t n;

	if (!p) {
		snprintf(by, cap, "?");
		return;
	}
	n = strcspn(p + 1, ")");
	snprintf(by, cap, "%.*s", (int)n, p + 1);
}

/* One axis through the events: on at @t_sig, switched on after it, the
 * time and source of the last on->off after it. Return: 1 if still on. */
static int axis_walk(const struct sys_case *c, int a, double t_sig,
		     struct off_result *r, double *t_off, char *by, size_t cap)
{
	char on_p[32], off_p[32];
	int on = 0;

	snprintf(on_p, sizeof(on_p), "axis %c motor on", 'A' + a);
	snprintf(off_p, sizeof(off_p), "axis %c motor off", 'A' + a);
	*t_off = -1;
	for (size_t i = 0; i < c->nev; i++) {
		const struct sys_evt *e = &c->ev[i];

		if (!strncmp(e->text, on_p, strlen(on_p))) {
			on = 1;
			if (e->t_ms > t_sig)
				r->on_after = 1;
		} else if (!strncmp(e->text, off_p, strlen(off_p))) {
			if (on && e->t_ms >= t_sig) {
				*t_off = e->t_ms;
				source_of(e->text, by, cap);
			}
			on = 0;
		}
		if (e->t_ms <= t_sig &&
		    (i + 1 == c->nev || c->ev[i + 1].t_ms > t_sig))
			r->on_at_sig |= on;
	}
	return on;
}

/*
 * Let the controller act on its own for the deadline and the longest
 * program transition after it (a request the dead supervisor sent may
 * still switch the motors on: #SVCIN, #ARM), then read what happened.
 * Return: 0, or -1 with c->err set (a motor still on, lost events).
 */
static int analyse_off(struct sys_case *c, double t_sig, int power_output,
		       struct off_result *r)
{
	char pref[48];
	int i;

	memset(r, 0, sizeof(*r));
	r->off_ms = r->pout_ms = -1;
	if (wait_sim_fine(c, t_sig + D_POWER_MS, 5000) < 0 ||
	    sys_state(c, r->st_d, sizeof(r->st_d)) < 0 ||
	    wait_sim_fine(c, t_sig + D_CTRL_MS + 100, 5000) < 0 ||
	    sys_events(c) < 0 || sys_state(c, r->st, sizeof(r->st)) < 0)
		return -1;
	if (sys_event_find(c, "events lost", 0) >= 0) {
		seterr(c, "galil-sim lost events: no analysis possible");
		return -1;
	}
	for (int a = 0; a < 3; a++) {
		double t_off;
		char by[64] = "";

		if (axis_walk(c, a, t_sig, r, &t_off, by, sizeof(by))) {
			seterr(c,
			       "motor %c is still on %d ms after the "
			       "signal: %s",
			       'A' + a, D_CTRL_MS + 100, r->st);
			return -1;
		}
		if (t_off >= 0 && t_off - t_sig > r->off_ms) {
			r->off_ms = t_off - t_sig;
			snprintf(r->by, sizeof(r->by), "%s", by);
		}
	}
	snprintf(pref, sizeof(pref), "power output %d cleared", power_output);
	i = power_output ? sys_event_find(c, pref, t_sig) : -1;
	if (i >= 0)
		r->pout_ms = c->ev[i].t_ms - t_sig;
	r->fcode = sys_state_num(r->st, "var.fcode");
	return 0;
}

/* No axis moved (true position X.act) from the state line @st0 to now. */
static int still_since(struct sys_case *c, const char *st0)
{
	char st1[2048];

	if (sys_state(c, st1, sizeof(st1)) < 0)
		return -1;
	for (int a = 0; a < 3; a++) {
		char key[8];

		snprintf(key, sizeof(key), "%c.act", 'A' + a);
		if (sys_state_num(st0, key) != sys_state_num(st1, key)) {
			seterr(c, "axis %c moved after the deadline:\n%s\n%s",
			       'A' + a, st0, st1);
			return -1;
		}
	}
	return 0;
}

/*
 * The assertions after a kill or during a freeze (@what names it in the
 * messages): every motor that was on at the signal, or went on after it,
 * off within D_CTRL_MS, by the controller program (nobody else is left),
 * which latched WATCHDOG (2); with the power output wired, the output
 * cleared within the same deadline and motor power gone by then; then
 * every motor off and no axis moving from the deadline to the end of a
 * hold (sys_check_safe; the relay may stay on: nobody is left to open it).
 * Failures go to add_fail(). Return: 0 when all hold.
 */
static int check_off(struct sys_case *c, const char *what, double t_sig,
		     int power_output, struct off_result *r)
{
	size_t before = nfails;

	if (analyse_off(c, t_sig, power_output, r) < 0) {
		add_fail("%s: %s", what, c->err);
		return -1;
	}
	if (r->on_at_sig || r->on_after) {
		if (r->off_ms < 0 || r->off_ms > D_CTRL_MS)
			add_fail("%s: motors off %.0f ms after the signal, "
				 "deadline %d ms%s",
				 what, r->off_ms, D_CTRL_MS,
				 r->on_after ? " (the program switched them ON "
					       "after the signal)"
					     : "");
		if (strncmp(r->by, "thread ", 7))
			add_fail("%s: the last motor was switched off by '%s', "
				 "not the controller program",
				 what, r->by);
		if (r->fcode != 2)
			add_fail("%s: the program latched fault %.0f, not "
				 "WATCHDOG (2): %s",
				 what, r->fcode, r->st);
		if (power_output && (r->pout_ms < 0 || r->pout_ms > D_POWER_MS))
			add_fail("%s: power output %d cleared %.0f ms after "
				 "the signal (-1: never), deadline %d ms",
				 what, power_output, r->pout_ms, D_POWER_MS);
	}
	if (power_output && !strstr(r->st_d, " power=0 "))
		add_fail("%s: motor power not cut at the deadline (output %d "
			 "wired): %s",
			 what, power_output, r->st_d);
	if (sys_check_safe(c, 1, HOLD_MS) < 0)
		add_fail("%s: %s", what, c->err);
	else if (still_since(c, r->st_d) < 0)
		add_fail("%s: %s", what, c->err);
	return nfails == before ? 0 : -1;
}

/* ---- kill-anywhere ------------------------------------------------------ */

struct phase_stats {
	int kills, off_before; /* off_before: the motors were off already */
	double worst_ms;       /* worst time to motors off, -1 none */
	double worst_pout_ms;  /* worst time to the power output cut, -1 */
};

static void stats_add(struct phase_stats *s, const struct off_result *r)
{
	s->kills++;
	if (!r->on_at_sig && !r->on_after)
		s->off_before++;
	else if (r->off_ms > s->worst_ms)
		s->worst_ms = r->off_ms;
	if (r->pout_ms > s->worst_pout_ms)
		s->worst_pout_ms = r->pout_ms;
}

static void print_table(const char *title, const struct phase_stats *s,
			int power_output)
{
	print_message(
	    "[ MEASURE  ] %s: phase | kills | worst time to motors "
	    "off | deadline%s\n",
	    title, power_output ? " | worst power output cut | deadline" : "");
	for (int p = 0; p < PH_COUNT; p++) {
		char worst[64], pout[64] = "";

		if (!s[p].kills)
			continue;
		if (s[p].worst_ms >= 0)
			snprintf(worst, sizeof(worst), "%.0f ms%s",
				 s[p].worst_ms,
				 s[p].off_before ? " (some off already)" : "");
		else
			snprintf(worst, sizeof(worst), "off already");
		if (power_output && s[p].worst_pout_ms >= 0)
			snprintf(pout, sizeof(pout), " | %.0f ms | %d ms",
				 s[p].worst_pout_ms, D_POWER_MS);
		else if (power_output)
			snprintf(pout, sizeof(pout), " | cut already | %d ms",
				 D_POWER_MS);
		print_message("[ MEASURE  ]   %-22s | %2d | %-24s | %d ms%s\n",
			      ph_name[p], s[p].kills, worst, D_CTRL_MS, pout);
	}
}

/* The [ MEASURE ] line of one signal. */
static void measure_line(const char *sig, enum phase ph, double t_sig,
			 double jitter, double anchor,
			 const struct off_result *r)
{
	char off[160], pout[48] = "";

	if (r->on_at_sig || r->on_after)
		snprintf(off, sizeof(off),
			 "motors %s, all off %.0f ms after (%s)",
			 r->on_at_sig ? "on" : "switched on AFTER it",
			 r->off_ms, r->by);
	else
		snprintf(off, sizeof(off), "motors off already");
	if (r->pout_ms >= 0)
		snprintf(pout, sizeof(pout),
			 "; power output cleared %.0f ms after", r->pout_ms);
	print_message("[ MEASURE  ] %s in %-22s at %6.0f ms (+-%.0f), %6.0f ms "
		      "into the phase: %s%s; program fault %.0f\n",
		      sig, ph_name[ph], t_sig, jitter,
		      anchor >= 0 ? t_sig - anchor : 0.0, off, pout, r->fcode);
}

/* One kill at @in: a fresh case, the instant, SIGKILL, the checks. */
static void kill_one(const struct instant *in, int power_output,
		     struct phase_stats *stats)
{
	struct off_result r;
	double anchor, t_sig, t0;
	enum phase got;
	char what[160], st[2048];

	snprintf(what, sizeof(what), "kill in %s%s%s +%.0f ms%s",
		 ph_name[in->ph], in->line ? " at '" : "",
		 in->line ? in->line : "", in->at_ms,
		 power_output ? " (power output wired)" : "");
	if (reach(&cs, in, power_output, &anchor) < 0) {
		add_fail("%s: %s", what, cs.err);
		sys_case_stop(&cs);
		return;
	}
	if (in->ph == PH_JOG && sys_state(&cs, st, sizeof(st)) == 0 &&
	    !(fabs(sys_state_num(st, "A.vel")) > 0))
		add_fail("%s: axis A is not moving: %s", what, st);
	t_sig = signal_at(&cs, SIGKILL, &t0);
	proc_wait_exit(&cs.re, EXIT_WAIT_MS, NULL);
	if (t_sig < 0 || sys_events(&cs) < 0) {
		add_fail("%s: %s", what, cs.err);
		sys_case_stop(&cs);
		return;
	}
	check_off(&cs, what, t_sig, power_output, &r);
	got = actual_phase(&cs, in->ph, t_sig, sys_state_num(r.st, "var.hbpc"));
	if (got != in->ph && !(in->ph == PH_RELAY && got == PH_SVCREQ))
		add_fail("%s: the kill met '%s' instead", what, ph_name[got]);
	stats_add(&stats[got], &r);
	measure_line("kill", got, t_sig, t_sig - t0, anchor, &r);
	sys_case_stop(&cs);
}

/* The instants: every progress line of start-up before the relay closes;
 * the relay just closed; the service request pending; the calibration and
 * the centring at evenly spread fractions of their measured lengths; the
 * arm request pending; armed at rest spread over one supervisor period;
 * jogging spread over the jog's ramp; latched spread after the fault. */
static size_t kill_plan(struct instant *plan, size_t cap, int full)
{
	static const char *const boot[] = {
	    "roboelf: opening the E-stop relay",
	    "roboelf: connecting to the controller",
	    "roboelf: controller DMC",
	    "roboelf: calibration from the file",
	    "roboelf: halting the controller program",
	    "roboelf: controller configured",
	};
	/* the whole plan, or one instant per phase (the power output pass:
	 * start-up at "halting the controller program") */
	size_t b0 = full ? 0 : 4,
	       b1 = full ? sizeof(boot) / sizeof(boot[0]) : 5;
	int ncal = full ? 8 : 1, ncen = full ? 4 : 1, narm = full ? 4 : 1;
	int njog = full ? 4 : 1, nlat = full ? 3 : 1;
	size_t n = 0;

	for (size_t i = b0; i < b1 && n < cap; i++)
		plan[n++] = (struct instant){PH_BOOT, boot[i], 0};
	if (n + 1 < cap) {
		plan[n++] = (struct instant){PH_RELAY, NULL, 0};
		plan[n++] = (struct instant){PH_SVCREQ, NULL, 0};
	}
	for (int k = 0; k < ncal && n < cap; k++)
		plan[n++] = (struct instant){PH_CALIB, NULL,
					     ref.d_cal * (k + 0.5) / ncal};
	for (int k = 0; k < ncen && n < cap; k++)
		plan[n++] = (struct instant){PH_CENTRE, NULL,
					     ref.d_centre * (k + 0.5) / ncen};
	if (n + 1 < cap) {
		plan[n++] = (struct instant){PH_OFF, NULL, 0};
		plan[n++] = (struct instant){PH_ARMREQ, NULL, 0};
	}
	for (int k = 0; k < narm && n < cap; k++)
		plan[n++] = (struct instant){PH_ARMED, NULL,
					     100.0 + k * PERIOD_MS / narm};
	for (int k = 0; k < njog && n < cap; k++)
		plan[n++] = (struct instant){PH_JOG, NULL,
					     150.0 + k * (full ? 300.0 : 0)};
	for (int k = 0; k < nlat && n < cap; k++)
		plan[n++] = (struct instant){PH_LATCHED, NULL,
					     full ? k * 100.0 : 100.0};
	return n;
}

#if defined(__SANITIZE_ADDRESS__)
/* make asan looks for memory errors: one instant per phase (make check, and
 * the power-output pass in both: the whole plan) */
static const int plan_full = 0;
#else
static const int plan_full = 1;
#endif

static void kill_anywhere(int power_output)
{
	struct instant plan[48];
	struct phase_stats stats[PH_COUNT];
	size_t n;

	need_env();
	reset_fails();
	for (int p = 0; p < PH_COUNT; p++)
		stats[p] = (struct phase_stats){0, 0, -1, -1};
	n = kill_plan(plan, sizeof(plan) / sizeof(plan[0]),
		      !power_output && plan_full);
	for (size_t i = 0; i < n; i++)
		kill_one(&plan[i], power_output, stats);
	print_table(power_output ? "kill-anywhere, power output wired"
				 : "kill-anywhere",
		    stats, power_output);
	for (int p = 0; p < PH_COUNT; p++)
		if (!stats[p].kills && p != PH_RELAY)
			add_fail("no kill met the phase '%s'", ph_name[p]);
	check_fails(power_output ? "kill-anywhere (power output)"
				 : "kill-anywhere");
}

static void test_kill_anywhere(void **state)
{
	(void)state;
	kill_anywhere(0);
}

static void test_kill_anywhere_power_output(void **state)
{
	(void)state;
	kill_anywhere(POWER_OUT);
}

/* ---- freeze-anywhere ---------------------------------------------------- */

/* The FAULT line after a freeze must name the supervisor's own stall, at
 * least as long as the freeze, with the critical limit C, and not the
 * link. */
static void check_stall_line(const char *what, const char *line)
{
	static const char pre[] =
	    "FAULT WATCHDOG: this supervisor did not run for ";
	static const enum re_fault_id stall[] = {RE_F_STALL, RE_F_NONE};
	int n = -1, m = -1;

	if (strncmp(line, pre, strlen(pre)) ||
	    sscanf(line + strlen(pre), "%d ms (limit %d ms)", &n, &m) != 2) {
		add_fail("%s: the FAULT line does not name the stall:\n    %s",
			 what, line);
		return;
	}
	/* the freeze is timed on galil-sim's clock from just after kill()
	 * returned, and roboelf may run a moment longer before the stop
	 * takes effect: its own measure can be short of it by that much
	 * (1999 ms seen once for 2000), never by more than FREEZE_SLACK_MS */
	if (n < FREEZE_MS - FREEZE_SLACK_MS)
		add_fail("%s: stall of %d ms reported, the freeze was %d ms",
			 what, n, FREEZE_MS);
	if (m != (int)(CRIT_F * PERIOD_MS))
		add_fail("%s: limit %d ms reported, C is %d ms", what, m,
			 (int)(CRIT_F * PERIOD_MS));
	if (!strstr(line, "the PC stalled") || strstr(line, "cable") ||
	    sys_fault_match(line, -1, stall) != RE_F_STALL)
		add_fail("%s: not the stall's text and recovery:\n    %s", what,
			 line);
}

static void freeze_one(const struct instant *in)
{
	struct off_result r;
	double anchor, t_sig, t0;
	char what[160], line[1024], first[1024] = "";
	int status;

	snprintf(what, sizeof(what), "freeze in %s +%.0f ms", ph_name[in->ph],
		 in->at_ms);
	if (reach(&cs, in, 0, &anchor) < 0) {
		add_fail("%s: %s", what, cs.err);
		return;
	}
	if (in->ph == PH_LATCHED)
		proc_find_line(&cs.re, PROC_STDOUT, "FAULT ", first,
			       sizeof(first));
	t_sig = signal_at(&cs, SIGSTOP, &t0);
	if (t_sig < 0 || sys_events(&cs) < 0) {
		add_fail("%s: %s", what, cs.err);
		return;
	}
	/* while it is stopped: the controller's deadline, the safe state */
	check_off(&cs, what, t_sig, 0, &r);
	measure_line("freeze", in->ph, t_sig, t_sig - t0, anchor, &r);
	if (wait_sim_fine(&cs, t_sig + FREEZE_MS, FREEZE_MS + 3000) < 0 ||
	    signal_at(&cs, SIGCONT, NULL) < 0) {
		add_fail("%s: %s", what, cs.err);
		return;
	}
	if (in->ph == PH_LATCHED) {
		/* the first fault stays the one reported */
		if (proc_wait_line(&cs.re, PROC_STDOUT, "FAULT ", 1000, line,
				   sizeof(line)) == 0)
			add_fail("%s: a second FAULT line after the freeze:\n"
				 "    %s\n  (first: %s)",
				 what, line, first);
	} else if (sys_wait_fault(&cs, 3000, line, sizeof(line)) < 0) {
		add_fail("%s: no FAULT line within 3 s of SIGCONT; roboelf "
			 "went on%s",
			 what,
			 proc_find_line(&cs.re, PROC_STDOUT,
					"RoboELF Ready for Use", NULL, 0) == 0
			     ? " to 'RoboELF Ready for Use' and stayed armed"
			     : "");
	} else {
		print_message("[ MEASURE  ] freeze in %s: after SIGCONT: %.160s"
			      "...\n",
			      ph_name[in->ph], line);
		check_stall_line(what, line);
		if (sys_check_safe(&cs, 0, HOLD_MS) < 0)
			add_fail("%s: after SIGCONT: %s", what, cs.err);
	}
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0)
		add_fail("%s: roboelf did not exit within %d ms of SIGTERM",
			 what, EXIT_WAIT_MS);
	else if (proc_exit_code(&cs.re) != 4)
		add_fail("%s: exit code %d after SIGTERM, not 4 (latched)",
			 what, proc_exit_code(&cs.re));
}

static void test_freeze_anywhere(void **state)
{
	const struct instant plan[] = {
	    {PH_RELAY, NULL, 0},
	    {PH_SVCREQ, NULL, 0},
	    {PH_CALIB, NULL, ref.d_cal / 2},
	    {PH_CENTRE, NULL, ref.d_centre / 2},
	    {PH_ARMREQ, NULL, 0},
	    {PH_ARMED, NULL, 100},
	    {PH_JOG, NULL, 450},
	    {PH_LATCHED, NULL, 100},
	};

	(void)state;
	need_env();
	reset_fails();
	for (size_t i = 0; i < sizeof(plan) / sizeof(plan[0]); i++) {
		freeze_one(&plan[i]);
		sys_case_stop(&cs);
	}
	check_fails("freeze-anywhere");
}

/* ---- fault-anywhere ----------------------------------------------------- */

/* Deadlines, as test_sys_faults.c derives them from docs/safety.md
 * ("Deadlines"), with P the configured period (in the service state the
 * cycle runs every 10 ms, so these are upper bounds there too). */
static double P(void)
{
	return PERIOD_MS;
}

static double C(void)
{
	return CRIT_F * PERIOD_MS;
}

static double d_encpot(void)
{
	return (2.0 + PERSIST) * P();
}

static double t_tolerance(void)
{
	double tol = (1.0 + ALLOWED_ERR) * STEP_COUNTS * 1.1;

	return SYS_LOOPMS + 1000.0 * VMIN_CPS / (10.0 * VMAX_CPS) +
	       1000.0 * tol / VMIN_CPS;
}

static double d_ctrl_to_relay(void)
{
	return SYS_MAINMS + 2.0 * P();
}

static double d_jam_motors(void)
{
	return 2 * SYS_LOOPMS + 1000.0 * VMIN_CPS / (10.0 * VMAX_CPS) +
	       1000.0 * STEP_COUNTS / VMIN_CPS;
}

enum fkind {
	FK_POT_OFFSET,
	FK_POT_OPEN,
	FK_ENC_STUCK,
	FK_JAM,
	FK_JOY,
	FK_STALL,
	FK_DROP,
	FK_UNPLUG,
	FK_WRITEFAIL,
	FK_COUNT
};

struct fclass {
	const char *name;
	const char *req; /* the control request */
	int axis;	 /* the axis the FAULT line must name, -1 none */
	enum re_fault_id cal[6], ctr[6]; /* accepted: calibration, centring */
};

/* The matrix of test_sys_faults.c; the axis of a jam or a dead encoder is
 * one that moves (every axis moves in the service state). */
static const struct fclass fclasses[FK_COUNT] = {
    [FK_POT_OFFSET] = {"pot offset",
		       "pot A offset 0.5",
		       0,
		       {RE_F_CAL_ABSOLUTE, RE_F_CTRL_POTRANGE, RE_F_CAL_RANGE,
			RE_F_NONE},
		       {RE_F_ENCPOT, RE_F_NONE}},
    [FK_POT_OPEN] = {"pot open",
		     "pot C open",
		     2,
		     {RE_F_CTRL_POTRANGE, RE_F_NONE},
		     {RE_F_CTRL_POTRANGE, RE_F_NONE}},
    /* in calibration also the pot's range (16): stuck within ER of a
     * switch, the profiler stops at the switch before the error reaches
     * ER and the open loop drives the axis on past it */
    [FK_ENC_STUCK] = {"encoder stuck",
		      "enc A stuck",
		      0,
		      {RE_F_CTRL_POSERR, RE_F_CTRL_ENCODER, RE_F_MOTOR_OFF,
		       RE_F_CTRL_POTRANGE, RE_F_NONE},
		      {RE_F_ENCPOT, RE_F_CTRL_POSERR, RE_F_CTRL_ENCODER,
		       RE_F_MOTOR_OFF, RE_F_NONE}},
    [FK_JAM] = {"jammed axis",
		"block B 1",
		1,
		{RE_F_CTRL_POSERR, RE_F_CTRL_ENCODER, RE_F_MOTOR_OFF,
		 RE_F_NONE},
		{RE_F_CTRL_POSERR, RE_F_CTRL_ENCODER, RE_F_MOTOR_OFF,
		 RE_F_NONE}},
    [FK_JOY] = {"joystick invalid held",
		"joy B fwd a",
		-1,
		{RE_F_CTRL_INPUT, RE_F_NONE},
		{RE_F_CTRL_INPUT, RE_F_NONE}},
    [FK_STALL] = {"link stall",
		  "link stall",
		  -1,
		  {RE_F_WDOG_REPLY, RE_F_NONE},
		  {RE_F_WDOG_REPLY, RE_F_NONE}},
    [FK_DROP] = {"link drop",
		 "link drop",
		 -1,
		 {RE_F_COMM, RE_F_NONE},
		 {RE_F_COMM, RE_F_NONE}},
    [FK_UNPLUG] = {"relay unplug",
		   "relayfault unplug",
		   -1,
		   {RE_F_ESTOP_LOST, RE_F_NONE},
		   {RE_F_ESTOP_LOST, RE_F_NONE}},
    [FK_WRITEFAIL] = {"relay writefail",
		      "relayfault writefail",
		      -1,
		      {RE_F_ESTOP_LOST, RE_F_CTRL_POWER, RE_F_RELAY_POWER,
		       RE_F_NONE},
		      {RE_F_ESTOP_LOST, RE_F_CTRL_POWER, RE_F_RELAY_POWER,
		       RE_F_NONE}},
};

/* The potentiometer's absolute range the program checks (fault 16):
 * potlo = reverse_v - absolute_tolerance_v - near_margin_counts x gain,
 * gain = (forward_v - reverse_v) / travel_counts (pc/config/re_plan.c), with
 * the defaults 0.5 V, 0.25 V, 4.0 V and NEAR_MARGIN. roboelf refuses a
 * configuration whose potlo is below 0.1 V (an open wiper must stay a
 * fault): on the short robot potlo is 0.125 V for C, so an open wiper
 * (0 V) is outside the range. */
static int open_v_outside_range(int axis)
{
	static const double travel[3] = {20000, 20000, 16000};
	double potlo = 0.5 - 0.25 - NEAR_MARGIN * 4.0 / travel[axis];

	return 0.0 < potlo;
}

struct fdeadline {
	double relay, motors; /* from the injection, ms; < 0: none applies */
	double pc;	      /* the PC's ESTOP log entry (relay faults) */
};

static struct fdeadline fault_deadlines(enum fkind k, enum phase ph)
{
	int tables = ph == PH_CENTRE; /* the encoder/pot check can run */
	struct fdeadline d = {-1, -1, -1};
	double dm;

	switch (k) {
	case FK_POT_OFFSET:
		/* without tables only the ends of the travel and the
		 * controller's range can tell: no deadline from the injection
		 */
		if (tables)
			d = (struct fdeadline){d_encpot(),
					       d_encpot() + SYS_MAINMS, -1};
		break;
	case FK_POT_OPEN:
		/* the controller's range check (fault 16) sees an open wiper
		 * only where its reading is below potlo; else as an offset */
		if (open_v_outside_range(2))
			d = (struct fdeadline){d_ctrl_to_relay(),
					       SYS_MAINMS + 1, -1};
		else if (tables)
			d = (struct fdeadline){d_encpot(),
					       d_encpot() + SYS_MAINMS, -1};
		break;
	case FK_ENC_STUCK:
		dm = tables ? t_tolerance() + d_encpot() + SYS_MAINMS
			    : d_jam_motors();
		d = (struct fdeadline){
		    tables ? dm - SYS_MAINMS : dm + d_ctrl_to_relay(), dm, -1};
		break;
	case FK_JAM:
		dm = d_jam_motors();
		d = (struct fdeadline){dm + d_ctrl_to_relay(), dm, -1};
		break;
	case FK_JOY:
		dm = JTO_MS + 2 * SYS_LOOPMS;
		d = (struct fdeadline){dm + d_ctrl_to_relay(), dm, -1};
		break;
	case FK_STALL:
		d = (struct fdeadline){C() + P(), C() + P() + SYS_MAINMS, -1};
		break;
	case FK_DROP:
		d = (struct fdeadline){2 * P(), 2 * P() + SYS_MAINMS, -1};
		break;
	case FK_UNPLUG: d = (struct fdeadline){0, SYS_MAINMS, 2 * P()}; break;
	case FK_WRITEFAIL:
		d = (struct fdeadline){0, SYS_MAINMS, READBACK_MS + 3 * P()};
		break;
	default: break;
	}
	return d;
}

static void fmt_deadline(char *buf, size_t cap, double d)
{
	if (d >= 0)
		snprintf(buf, cap, "deadline %.0f", d);
	else
		snprintf(buf, cap, "no deadline applies");
}

/* Inject @req; return the simulated time of its event, or -1. */
static double inject(struct sys_case *c, const char *req)
{
	char want[300];
	double before = sys_sim_time(c), t;

	snprintf(want, sizeof(want), "%s%s",
		 strncmp(req, "joy ", 4) ? "inject: " : "input: ", req);
	if (before < 0 || sys_ctl(c, "%s", req) < 0 ||
	    sys_wait_event(c, want, before, 2000, &t) < 0)
		return -1;
	return t;
}

/* Every motor switched off after @after: the time, within @ms wall. */
static double wait_motors_off(struct sys_case *c, double after, int ms)
{
	long long deadline = proc_now_ms() + ms;

	for (;;) {
		double t = sys_motors_off_time(c, after);

		if (t >= 0 || proc_now_ms() > deadline)
			return t;
		poll(NULL, 0, 15);
		if (sys_events(c) < 0)
			return -1;
	}
}

/* The FAULT line is one of @ids, names its axis, and is in the log. */
static void check_fault_line(struct sys_case *c, const char *what,
			     const char *line, int axis,
			     const enum re_fault_id *ids)
{
	char logline[4096];

	if (sys_fault_match(line, axis, ids) == RE_F_NONE) {
		char pre[64], rec[512];

		sys_fault_expect(ids[0], axis, pre, sizeof(pre), rec,
				 sizeof(rec));
		add_fail("%s: unexpected FAULT line\n    got:      %s\n    "
			 "expected: %s...%s",
			 what, line, pre, rec);
	}
	if (axis >= 0) {
		char name[16];

		snprintf(name, sizeof(name), "axis %c", 'A' + axis);
		if (!strstr(line, name))
			add_fail("%s: the FAULT line does not name %s: %s",
				 what, name, line);
	}
	if (sys_log_find(c, " FAULT ", line, logline, sizeof(logline)) < 0)
		add_fail("%s: %s", what, c->err);
}

/* The supervisor's ESTOP log entry, wall ms after @w0 (relay faults). */
static double pc_estop_ms(struct sys_case *c, double w0)
{
	double w1;

	if (sys_log_time_ms(c,
			    "FAULT ESTOP: the E-stop relay stopped "
			    "answering",
			    &w1) < 0)
		return -1;
	return w1 - w0;
}

static void fault_one(enum fkind k, const struct instant *in)
{
	const struct fclass *fc = &fclasses[k];
	struct fdeadline d = fault_deadlines(k, in->ph);
	double anchor, t_inj, t_relay = -1, t_mo, w0, pc = -1;
	char what[160], line[1024];
	int status;

	snprintf(what, sizeof(what), "%s in %s +%.0f ms", fc->name,
		 ph_name[in->ph], in->at_ms);
	if (reach(&cs, in, 0, &anchor) < 0) {
		add_fail("%s: %s", what, cs.err);
		return;
	}
	w0 = sys_wall_ms();
	t_inj = inject(&cs, fc->req);
	if (t_inj < 0 ||
	    sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0) {
		add_fail("%s: %s", what, cs.err);
		return;
	}
	if (sys_wait_event(&cs, "relay off", t_inj, 3000, &t_relay) < 0)
		add_fail("%s: %s", what, cs.err);
	t_mo = wait_motors_off(&cs, t_inj, 3000);
	if (t_mo < 0)
		add_fail("%s: not every motor was switched off", what);
	if (d.pc >= 0) {
		/* the log entry may follow the controller's own fault */
		if (wait_sim_fine(&cs, t_inj + d.pc + SLACK_MS, 5000) < 0 ||
		    (pc = pc_estop_ms(&cs, w0)) < 0)
			add_fail("%s: %s", what, cs.err);
	}
	{
		char dr[32], dmo[32], dpc[64] = "";

		fmt_deadline(dr, sizeof(dr), d.relay);
		fmt_deadline(dmo, sizeof(dmo), d.motors);
		if (d.pc >= 0)
			snprintf(dpc, sizeof(dpc),
				 ", ESTOP logged %.0f ms (deadline %.0f)", pc,
				 d.pc);
		print_message("[ MEASURE  ] %s (%.0f ms into the phase): relay "
			      "off %.0f ms (%s), motors off %.0f ms (%s)%s: "
			      "%.150s...\n",
			      what, t_inj - anchor, t_relay - t_inj, dr,
			      t_mo - t_inj, dmo, dpc, line);
	}
	check_fault_line(&cs, what, line, fc->axis,
			 in->ph == PH_CENTRE ? fc->ctr : fc->cal);
	if (proc_find_line(&cs.re, PROC_STDOUT, "RoboELF Ready", NULL, 0) ==
		0 ||
	    proc_find_line(&cs.re, PROC_STDOUT, "roboelf: calibration (", NULL,
			   0) == 0)
		add_fail("%s: the calibration ended or the robot armed despite "
			 "the fault",
			 what);
	if (sys_check_safe(&cs, 0, HOLD_MS) < 0)
		add_fail("%s: %s", what, cs.err);
	if (d.relay >= 0 && t_relay - t_inj > d.relay + SLACK_MS)
		add_fail("%s: relay off after %.0f ms, deadline %.0f ms (+%d)",
			 what, t_relay - t_inj, d.relay, SLACK_MS);
	if (d.motors >= 0 && t_mo - t_inj > d.motors + SLACK_MS)
		add_fail("%s: motors off after %.0f ms, deadline %.0f ms (+%d)",
			 what, t_mo - t_inj, d.motors, SLACK_MS);
	if (d.pc >= 0 && pc > d.pc + SLACK_MS)
		add_fail("%s: ESTOP logged %.0f ms after the injection, "
			 "deadline %.0f ms",
			 what, pc, d.pc);
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0 ||
	    proc_exit_code(&cs.re) != 4)
		add_fail("%s: no exit 4 within %d ms of SIGTERM (exit %d)",
			 what, EXIT_WAIT_MS, proc_exit_code(&cs.re));
}

/* During a full calibration: class k at (k + 0.5) / FK_COUNT of the
 * measured service state, so that the classes meet its stages in turn
 * (fast toward the reverse switches, the switches, the sweep, the forward
 * switches, the move to the centre). */
static void test_fault_in_calibration(void **state)
{
	(void)state;
	need_env();
	reset_fails();
	for (int k = 0; k < FK_COUNT; k++) {
		struct instant in = {PH_CALIB, NULL,
				     ref.d_cal * (k + 0.5) / FK_COUNT};

		fault_one((enum fkind)k, &in);
		sys_case_stop(&cs);
	}
	check_fails("fault-anywhere, full calibration");
}

/* During centring from a file: at 40 % of the move, every axis at speed. */
static void test_fault_in_centring(void **state)
{
	(void)state;
	need_env();
	reset_fails();
	for (int k = 0; k < FK_COUNT; k++) {
		struct instant in = {PH_CENTRE, NULL, ref.d_centre * 0.4};

		fault_one((enum fkind)k, &in);
		sys_case_stop(&cs);
	}
	check_fails("fault-anywhere, centring");
}

/* ---- link loss with the amplifier model off ----------------------------- */

/* The first "axis X motor off" of every axis after @after: the latest
 * time, and each source ("handle A", "thread 0 line 381"). */
static double who_off(const struct sys_case *c, double after, char by[3][48])
{
	double last = -1;

	for (int a = 0; a < 3; a++) {
		char pref[32];
		int i;

		snprintf(pref, sizeof(pref), "axis %c motor off", 'A' + a);
		i = sys_event_find(c, pref, after);
		if (i < 0)
			return -1;
		source_of(c->ev[i].text, by[a], sizeof(by[a]));
		if (c->ev[i].t_ms > last)
			last = c->ev[i].t_ms;
	}
	return last;
}

/* Start armed with galil-sim's amplifiers blind to motor power
 * (--no-amp-undervoltage) and axis A jogging. */
static void start_jogging_blind(void)
{
	struct ph_opts o = {.calibration = "file", .no_amp_uv = 1};

	if (ph_start(&cs, &o) < 0 || wait_ready(&cs, READY_MS) < 0 ||
	    inject(&cs, "joy A fwd") < 0 ||
	    sys_wait_moving(&cs, 'A', 300, 5000) < 0)
		fail_msg("%s", cs.err);
}

struct link_case {
	const char *name;
	const char *req;
	int transient;	   /* "link ok" at once: only the sockets died */
	int by_supervisor; /* the supervisor's new connection stops */
	enum re_fault_id id;
	double d_relay; /* the supervisor's deadline to relay off */
};

/*
 * With the amplifier model off, cutting motor power is invisible to the
 * controller: no amplifier fault switches the motors off; only a stop
 * command (the supervisor's, over a new connection) or the controller's
 * watchdog can. Every motor must be off within the watchdog's deadline
 * after the link went (D_CTRL_MS) whoever does it; the relay opens.
 */
static void link_loss(const struct link_case *lc)
{
	char line[1024], logline[4096], by[3][48];
	enum re_fault_id ids[2] = {lc->id, RE_F_NONE};
	double t_link, t_relay, t_mo;
	int status;

	start_jogging_blind();
	if (lc->transient) {
		/* both requests back to back (well under a millisecond) */
		double t0 = sys_sim_time(&cs), t;

		t_link = -1;
		if (t0 >= 0 && sys_ctl(&cs, "%s", lc->req) == 0 &&
		    sys_ctl(&cs, "link ok") == 0 &&
		    sys_wait_event(&cs, "inject: link drop", t0, 2000, &t) == 0)
			t_link = t;
	} else {
		t_link = inject(&cs, lc->req);
	}
	if (t_link < 0 ||
	    sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0 ||
	    sys_wait_event(&cs, "relay off", t_link, 3000, &t_relay) < 0)
		fail_msg("%s: %s", lc->name, cs.err);
	t_mo = wait_motors_off(&cs, t_link, 3000);
	if (t_mo < 0 || who_off(&cs, t_link, by) < 0)
		fail_msg("%s: not every motor was switched off", lc->name);
	print_message("[ MEASURE  ] %s, amplifier model off: relay off %.0f ms"
		      " (deadline %.0f), motors off %.0f ms (deadline %d) by "
		      "A: %s, B: %s, C: %s\n[ MEASURE  ]   %s\n",
		      lc->name, t_relay - t_link, lc->d_relay, t_mo - t_link,
		      D_CTRL_MS, by[0], by[1], by[2], line);
	if (sys_log_find(&cs, " FAULT ", line, logline, sizeof(logline)) < 0)
		fail_msg("%s: %s", lc->name, cs.err);
	print_message("[ MEASURE  ]   log: ...%s\n",
		      strstr(logline, " | relay off: ")
			  ? strstr(logline, " | relay off: ")
			  : logline);
	check_fault_line(&cs, lc->name, line, -1, ids);
	for (int a = 0; a < 3; a++)
		if (strncmp(by[a], lc->by_supervisor ? "handle " : "thread 0",
			    lc->by_supervisor ? 7 : 8))
			add_fail("%s: motor %c switched off by '%s', expected "
				 "%s",
				 lc->name, 'A' + a, by[a],
				 lc->by_supervisor
				     ? "the supervisor's new connection"
				     : "the controller's watchdog (thread 0)");
	if (sys_event_find(&cs, "motor power lost (amplifiers report nothing",
			   t_link) < 0)
		add_fail("%s: no 'motor power lost' event: was the amplifier "
			 "model off?",
			 lc->name);
	if (lc->by_supervisor) {
		if (!strstr(line, "Safe state confirmed") ||
		    !strstr(logline, "delivered over a new connection"))
			add_fail("%s: the stop over a new connection is not "
				 "confirmed: %s",
				 lc->name, logline);
	} else if (!strstr(line, "NOT CONFIRMED") ||
		   !strstr(line, "stop command not delivered") ||
		   !strstr(line, "PRESS THE HARDWARE E-STOP NOW") ||
		   !strstr(logline, "over a new connection") ||
		   !strstr(logline, "motors off: NOT confirmed")) {
		add_fail("%s: the FAULT line or the log does not say that the "
			 "stop was not delivered:\n    %s",
			 lc->name, logline);
	}
	if (t_relay - t_link > lc->d_relay + SLACK_MS)
		add_fail("%s: relay off after %.0f ms, deadline %.0f ms",
			 lc->name, t_relay - t_link, lc->d_relay);
	if (t_mo - t_link > D_CTRL_MS)
		add_fail("%s: motors off after %.0f ms, deadline %d ms",
			 lc->name, t_mo - t_link, D_CTRL_MS);
	if (sys_check_safe(&cs, 0, HOLD_MS) < 0)
		add_fail("%s: %s", lc->name, cs.err);
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0 ||
	    proc_exit_code(&cs.re) != 4)
		add_fail("%s: no exit 4 within %d ms of SIGTERM", lc->name,
			 EXIT_WAIT_MS);
}

static void test_link_loss_amp_model_off(void **state)
{
	/* a drop that lasts: galil-sim closes every new connection until
	 * "link ok", so only the controller's watchdog can stop */
	const struct link_case cases[] = {
	    {"link drop (sockets reset, link back at once)", "link drop", 1, 1,
	     RE_F_COMM, 2 * P()},
	    {"link drop (lasting)", "link drop", 0, 0, RE_F_COMM, 2 * P()},
	    {"link stall", "link stall", 0, 0, RE_F_WDOG_REPLY, C() + P()},
	};

	(void)state;
	need_env();
	reset_fails();
	for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		link_loss(&cases[i]);
		sys_case_stop(&cs);
	}
	check_fails("link loss, amplifier model off");
}

/* ---- a wedged relay board ----------------------------------------------- */

/* The relay board hangs with the relay on (motor power stays on whatever
 * roboelf writes), then @fault_req (or nothing: the read-back finds the
 * board silent). The controller stop meets the fault's deadline, the FAULT
 * line says the relay open was not confirmed and asks for the hardware
 * E-stop, and roboelf still exits on SIGTERM at once with 4. */
static void wedged(const char *name, const char *fault_req, enum re_fault_id id,
		   int axis, double d_motors)
{
	enum re_fault_id ids[2] = {id, RE_F_NONE};
	struct ph_opts o = {.calibration = "file"};
	double t_w = -1, t_f, t_mo;
	long long q0;
	char line[1024], st[2048];
	int status;

	if (ph_start(&cs, &o) < 0 || wait_ready(&cs, READY_MS) < 0 ||
	    (t_w = inject(&cs, "relayfault wedge")) < 0)
		fail_msg("%s: %s", name, cs.err);
	t_f = fault_req ? inject(&cs, fault_req) : t_w;
	if (t_f < 0 ||
	    sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s: %s", name, cs.err);
	t_mo = wait_motors_off(&cs, t_f, 3000);
	if (t_mo < 0)
		fail_msg("%s: not every motor was switched off", name);
	if (sys_state(&cs, st, sizeof(st)) < 0)
		fail_msg("%s", cs.err);
	print_message("[ MEASURE  ] %s: motors off %.0f ms after the %s "
		      "(deadline %.0f); relay %s, power %s\n[ MEASURE  ]   "
		      "%s\n",
		      name, t_mo - t_f, fault_req ? "fault" : "wedge", d_motors,
		      strstr(st, " relay=on ") ? "on" : "off",
		      strstr(st, " power=1 ") ? "on" : "off", line);
	check_fault_line(&cs, name, line, axis, ids);
	if (!strstr(line, "NOT CONFIRMED: relay open not confirmed;") ||
	    !strstr(line, "PRESS THE HARDWARE E-STOP NOW"))
		add_fail("%s: the FAULT line does not say that the relay did "
			 "not open: %s",
			 name, line);
	if (t_mo - t_f > d_motors + SLACK_MS)
		add_fail("%s: motors off after %.0f ms, deadline %.0f ms", name,
			 t_mo - t_f, d_motors);
	/* the wedged board keeps motor power on: the motors are off */
	if (sys_check_safe(&cs, 1, HOLD_MS) < 0)
		add_fail("%s: %s", name, cs.err);
	/* the power-off waits relay.off_deadline_ms (50) for the relay,
	 * never for the wedged board itself */
	q0 = proc_now_ms();
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, WEDGE_EXIT_MS, &status) < 0) {
		add_fail("%s: roboelf hangs: no exit within %d ms of SIGTERM",
			 name, WEDGE_EXIT_MS);
		return;
	}
	line[0] = '\0';
	proc_find_line(&cs.re, PROC_STDOUT, "roboelf: motors off", line,
		       sizeof(line));
	print_message("[ MEASURE  ] %s: exit %d %lld ms after SIGTERM: %s\n",
		      name, proc_exit_code(&cs.re), proc_now_ms() - q0, line);
	if (proc_exit_code(&cs.re) != 4)
		add_fail("%s: exit %d, not 4", name, proc_exit_code(&cs.re));
	if (!strstr(proc_output(&cs.re, PROC_STDOUT),
		    "NOT ALL CONFIRMED: press the hardware E-stop"))
		add_fail("%s: the quit message does not ask for the hardware "
			 "E-stop",
			 name);
}

static void test_wedged_relay(void **state)
{
	(void)state;
	need_env();
	reset_fails();
	/* a fault while the board is wedged (before its read-back times
	 * out): the encoder/pot deadline of test_sys_faults */
	wedged("wedged relay, then pot offset", "pot A offset 0.5", RE_F_ENCPOT,
	       0, d_encpot() + SYS_MAINMS);
	sys_case_stop(&cs);
	/* the wedge alone: the read-back finds the board silent after R,
	 * the cycle after it acts (R + 3P, as relay writefail), plus mainms */
	wedged("wedged relay alone", NULL, RE_F_ESTOP_LOST, -1,
	       READBACK_MS + 3 * P() + SYS_MAINMS);
	sys_case_stop(&cs);
	check_fails("wedged relay");
}

/* ---- signals ------------------------------------------------------------ */

static void quit_by(int sig, const char *logged)
{
	struct ph_opts o = {.calibration = "file"};
	const char *ok = "roboelf: motors off: confirmed; motor power off "
			 "(relay): confirmed; bye";
	double t_sig = -1, t_relay, t_mo;
	char by[3][48], st[2048];
	int status;

	if (ph_start(&cs, &o) < 0 || wait_ready(&cs, READY_MS) < 0 ||
	    inject(&cs, "joy B rev") < 0 ||
	    sys_wait_moving(&cs, 'B', 300, 5000) < 0 ||
	    (t_sig = signal_at(&cs, sig, NULL)) < 0)
		fail_msg("%s: %s", logged, cs.err);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0)
		fail_msg("%s: no exit within %d ms", logged, EXIT_WAIT_MS);
	if (sys_wait_event(&cs, "relay off", t_sig, 2000, &t_relay) < 0)
		fail_msg("%s: %s", logged, cs.err);
	t_mo = wait_motors_off(&cs, t_sig, 2000);
	if (t_mo < 0 || who_off(&cs, t_sig, by) < 0)
		fail_msg("%s: not every motor was switched off", logged);
	print_message("[ MEASURE  ] %s while jogging: exit %d, motors off %.0f"
		      " ms (by %s), relay off %.0f ms after the signal\n",
		      logged, proc_exit_code(&cs.re), t_mo - t_sig, by[0],
		      t_relay - t_sig);
	assert_int_equal(proc_exit_code(&cs.re), 0);
	if (proc_find_line(&cs.re, PROC_STDOUT, ok, NULL, 0) < 0)
		fail_msg("%s: no '%s' in:\n%s", logged, ok,
			 tail(&cs.re, PROC_STDOUT, 600));
	if (proc_find_line(&cs.re, PROC_STDOUT, "FAULT ", NULL, 0) == 0)
		fail_msg("%s: a FAULT line on quit", logged);
	/* the motors off on the supervisor's request (offreq: the program's
	 * #OFF, or its own AB 1;MO ABC) before the relay opens - not by the
	 * amplifier fault the power cut would cause - and no program fault */
	for (int a = 0; a < 3; a++)
		if (strncmp(by[a], "handle ", 7) &&
		    strncmp(by[a], "thread 0 ", 9))
			fail_msg("%s: motor %c off by '%s', not on the "
				 "supervisor's request",
				 logged, 'A' + a, by[a]);
	if (t_mo > t_relay)
		fail_msg("%s: the relay opened before the motors were off",
			 logged);
	if (sys_check_safe(&cs, 0, HOLD_MS) < 0 ||
	    sys_state(&cs, st, sizeof(st)) < 0 ||
	    sys_log_find(&cs, "INFO stop: ", logged, NULL, 0) < 0)
		fail_msg("%s: %s", logged, cs.err);
	if (sys_state_num(st, "var.state") != 0 ||
	    sys_state_num(st, "var.fcode") != 0)
		fail_msg("%s: the program is not back in its safe state "
			 "without a fault: %s",
			 logged, st);
	sys_case_stop(&cs);
}

static void test_signals_quit(void **state)
{
	(void)state;
	need_env();
	quit_by(SIGQUIT, "Ctrl-\\ (SIGQUIT)");
	quit_by(SIGHUP, "SIGHUP (terminal lost)");
	quit_by(SIGTERM, "SIGTERM");
}

/* Ctrl-Z is ignored: roboelf keeps writing its heartbeat every cycle (hbpc
 * advances in every 100 ms window for 1 s), nothing trips, still armed. */
static void test_signal_tstp_ignored(void **state)
{
	struct ph_opts o = {.calibration = "file"};
	double hb0 = NAN, t0 = -1;
	char st[2048];
	int status;

	(void)state;
	need_env();
	if (ph_start(&cs, &o) < 0 || wait_ready(&cs, READY_MS) < 0 ||
	    (t0 = signal_at(&cs, SIGTSTP, NULL)) < 0)
		fail_msg("%s", cs.err);
	for (int k = 0; k <= 10; k++) {
		double hb;

		if (wait_sim_fine(&cs, t0 + k * 100.0, 2000) < 0 ||
		    sys_state(&cs, st, sizeof(st)) < 0)
			fail_msg("%s", cs.err);
		hb = sys_state_num(st, "var.hbpc");
		if (k > 0 && !(hb != hb0))
			fail_msg("SIGTSTP: hbpc did not advance from %.0f "
				 "within 100 ms (%d00 ms after): %s",
				 hb0, k, st);
		if (sys_state_num(st, "var.state") != 1)
			fail_msg("SIGTSTP: the program left the armed state: "
				 "%s",
				 st);
		hb0 = hb;
	}
	proc_pump(&cs.re, 0);
	if (proc_find_line(&cs.re, PROC_STDOUT, "FAULT ", NULL, 0) == 0)
		fail_msg("SIGTSTP: a FAULT line: %s",
			 tail(&cs.re, PROC_STDOUT, 600));
	print_message("[ MEASURE  ] SIGTSTP ignored: hbpc advanced in every "
		      "100 ms over 1 s, still armed\n");
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0)
		fail_msg("no exit within %d ms of SIGTERM", EXIT_WAIT_MS);
	assert_int_equal(proc_exit_code(&cs.re), 0);
}

/* ---- centring, then armed ----------------------------------------------- */

/*
 * A calibration from the file with the robot off-centre: the move to the
 * centre is the program's own service move; arming right after it must
 * not be taken for motion nobody commanded. Whether it is depends on the
 * order of two things within one mainms (the program releasing the axis
 * in #MVSUP, roboelf's off request after it saw the move end): the off
 * request came first in 10 of 24 runs on the development machine, but not
 * independently (runs of one binary tend to repeat the order). So the
 * scenario runs up to CENTRING_RUNS times; each must arm and stay armed.
 */
#define CENTRING_RUNS 8

static void test_centring_then_armed(void **state)
{
	struct ph_opts o = {.calibration = "file", .off_centre = 1};
	int status;

	(void)state;
	need_env();
	for (int k = 0; k < CENTRING_RUNS; k++) {
		char line[1024];
		double t = -1;

		if (ph_start(&cs, &o) < 0 || wait_ready(&cs, READY_MS) < 0 ||
		    (t = sys_sim_time(&cs)) < 0 ||
		    wait_sim_fine(&cs, t + 500, 3000) < 0)
			fail_msg("run %d: %s", k + 1, cs.err);
		proc_pump(&cs.re, 0);
		if (proc_find_line(&cs.re, PROC_STDOUT, "FAULT ", line,
				   sizeof(line)) == 0)
			fail_msg("run %d: armed after centring from (%.0f, "
				 "%.0f, %.0f), then: %s",
				 k + 1, off_centre[0], off_centre[1],
				 off_centre[2], line);
		proc_signal(&cs.re, SIGTERM);
		if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &status) < 0)
			fail_msg("no exit within %d ms of SIGTERM",
				 EXIT_WAIT_MS);
		assert_int_equal(proc_exit_code(&cs.re), 0);
		sys_case_stop(&cs);
	}
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_kill_anywhere),	 T(test_kill_anywhere_power_output),
	    T(test_freeze_anywhere),	 T(test_fault_in_calibration),
	    T(test_fault_in_centring),	 T(test_link_loss_amp_model_off),
	    T(test_wedged_relay),	 T(test_signals_quit),
	    T(test_signal_tstp_ignored), T(test_centring_then_armed),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
