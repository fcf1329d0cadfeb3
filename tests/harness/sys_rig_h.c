/*
 * sys_rig_h.c - the short-robot rig of the phase system tests (see
 * sys_rig_h.h).
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
#include "sys_rig_h.h"

#define CAL_READY_MS 90000	     /* --calibration full to Ready */
#define TV_REST_MS   500	     /* > tvwin (400 ms, dmc/constants.dmc) */
#define PLANT_FMT    "%s/plant.yaml" /* the short robot, in the env's dir */

const double rig_off_centre[3] = {-8000, 8000, -6500};

/* ---- failures collected over many instants ------------------------------ */

/* A case of many instants reports every failing instant, then fails. */
static char fails[16384];
static size_t nfails;

void rig_fail(const char *fmt, ...)
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

void rig_fails_reset(void)
{
	fails[0] = '\0';
	nfails = 0;
}

size_t rig_fails_count(void)
{
	return nfails;
}

void rig_fails_check(const char *what)
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
static int write_config(const struct sys_env *e, const char *path,
			const char *log, int power_output, int udp_port)
{
	static const char axis_fmt[] =
	    "  - {name: %s, travel_counts: %d, vmin: %d, vmax: %d,\n"
	    "     step_counts: %d, position_error_limit_counts: %d,\n"
	    "     allowed_error: %g, persistence_cycles: %d,\n"
	    "     encoder_failure: {time_samples: 1000}}\n";
	static const char *const names[3] = {"A", "B", "C"};
	static const int travel[3] = {20000, 20000, 16000};
	const char *rec = sys_record();
	char text[4096];
	int n;

	n = snprintf(text, sizeof(text),
		     "mode: development\nperiod_ms: %d\n"
		     "controller: {power_output: %d, udp_port: %d%s%s}\n"
		     "relay: {readback: true, readback_timeout_ms: %d}\n"
		     "watchdog: {noncritical_factor: %g, critical_factor: "
		     "%g,\n  controller_timeout_ms: %d}\n"
		     "joystick: {invalid_timeout_ms: %d}\n"
		     "calibration: {file: \"%s\", near_margin_counts: %d}\n"
		     "log: {path: \"%s\"}\naxes:\n",
		     RIG_PERIOD_MS, power_output, udp_port,
		     rec ? ", record: " : "", rec ? rec : "", RIG_READBACK_MS,
		     RIG_NONCRIT_F, RIG_CRIT_F, RIG_WDTO_MS, RIG_JTO_MS, e->cal,
		     RIG_NEAR_MARGIN, log);
	for (int i = 0; i < 3; i++)
		n += snprintf(text + n, sizeof(text) - (size_t)n, axis_fmt,
			      names[i], travel[i], RIG_VMIN_CPS, RIG_VMAX_CPS,
			      RIG_STEP_COUNTS, RIG_ER_COUNTS, RIG_ALLOWED_ERR,
			      RIG_PERSIST);
	return write_text(path, text);
}

/* The figures sys_h's deadlines read, from the configuration above. */
static void env_figures(struct sys_env *e)
{
	e->period_ms = RIG_PERIOD_MS;
	e->noncrit_factor = RIG_NONCRIT_F;
	e->crit_factor = RIG_CRIT_F;
	e->wdto_ms = RIG_WDTO_MS;
	e->jto_ms = RIG_JTO_MS;
	e->persistence = RIG_PERSIST;
	e->allowed_error = RIG_ALLOWED_ERR;
	e->vmin_cps = RIG_VMIN_CPS;
	e->vmax_cps = RIG_VMAX_CPS;
	e->step_counts = RIG_STEP_COUNTS;
	e->er_counts = RIG_ER_COUNTS;
	e->readback_timeout_ms = RIG_READBACK_MS;
}

void rig_seterr(struct sys_case *c, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(c->err, sizeof(c->err), fmt, ap);
	va_end(ap);
}

const char *rig_tail(const struct proc *p, enum proc_stream s, size_t n)

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

	snprintf(bin, sizeof(bin), "%s/galil-load", c->env->bin);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", c->sim.port);
	snprintf(dmc, sizeof(dmc), "%s/dmc", c->env->top);
	if (proc_spawn(&p, argv, NULL) < 0) {
		rig_seterr(c, "cannot start '%s'", bin);
		return -1;
	}
	if (proc_wait_exit(&p, RIG_START_MS, NULL) < 0)
		rig_seterr(c, "galil-load did not finish within %d ms",
			   RIG_START_MS);
	else if (proc_exit_code(&p) != 0)
		rig_seterr(c, "galil-load exited with %d: %s",
			   proc_exit_code(&p), rig_tail(&p, PROC_STDERR, 600));
	else
		rc = 0;
	proc_kill(&p);
	return rc;
}

/* One host command on @fd that must answer ':'. */
static int host_cmd(struct sys_case *c, int fd, const char *cmd)
{
	if (sys_cmd(fd, cmd, 2000) == 0)
		return 0;
	rig_seterr(c, "host command '%s' refused or unanswered", cmd);
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
			rig_seterr(c, "the robot did not reach its start: %s",
				   st);
			return -1;
		}
		poll(NULL, 0, 10);
	}
}

/*
 * The robot left off-centre with the controller powered (a previous session
 * jogged it there): before roboelf starts, a host halts the program, moves
 * every axis to rig_off_centre[] with motor power on, switches the motors and
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
	snprintf(cmd, sizeof(cmd), "PA %.0f,%.0f,%.0f", rig_off_centre[0],
		 rig_off_centre[1], rig_off_centre[2]);
	if (host_cmd(c, fd, cmd) < 0 || host_cmd(c, fd, "BG ABC") < 0 ||
	    wait_at(c, rig_off_centre, 5000) < 0 ||
	    host_cmd(c, fd, "MO ABC") < 0)
		goto out;
	snprintf(cmd, sizeof(cmd), "CB %d", power_output);
	if ((power_output && host_cmd(c, fd, cmd) < 0) ||
	    sys_ctl(c, "relay off") < 0 || host_cmd(c, fd, "XQ #AUTO,0") < 0)
		goto out;
	/* at rest for longer than TV's average (256 samples) and the
	 * program's tvwin (400 ms): the robot has stood still since then */
	t = sys_sim_time(c);
	if (t < 0 || rig_wait_sim_fine(c, t + TV_REST_MS, 5000) < 0)
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

	snprintf(bin, sizeof(bin), "%s/roboelf", c->env->bin);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", c->sim.port);
	if (proc_spawn(&c->re, argv, NULL) < 0) {
		rig_seterr(c, "cannot start '%s'", bin);
		return -1;
	}
	c->re_up = 1;
	return 0;
}

int rig_start(struct sys_case *c, struct sys_env *e, const struct rig_opts *o)
{
	char pout[8], plant[SYS_PATH_MAX + 16];
	char *extra[10];
	int n = 0;

	memset(c, 0, sizeof(*c));
	c->ctl = -1;
	c->env = e;
	snprintf(c->sim_addr, sizeof(c->sim_addr), "127.0.0.1");
	c->id = ++e->ncase;
	snprintf(c->relay_link, sizeof(c->relay_link), "%s/relay-%d", e->dir,
		 c->id);
	snprintf(c->log, sizeof(c->log), "%s/case-%d.log", e->dir, c->id);
	snprintf(c->cfg, sizeof(c->cfg), "%s/case-%d.yaml", e->dir, c->id);
	c->bufcap = 512 * 1024;
	c->buf = malloc(c->bufcap);
	if (!c->buf) {
		rig_seterr(c, "out of memory");
		return -1;
	}
	snprintf(plant, sizeof(plant), PLANT_FMT, e->dir);
	extra[n++] = (char *)"--plant";
	extra[n++] = plant;
	if (o->power_output) {
		snprintf(pout, sizeof(pout), "%d", o->power_output);
		extra[n++] = (char *)"--power-output";
		extra[n++] = pout;
	}
	if (o->no_amp_uv)
		extra[n++] = (char *)"--no-amp-undervoltage";
	extra[n++] = (char *)"--udp-port"; /* the record stream's */
	extra[n++] = (char *)"0";
	extra[n] = NULL;
	if (proc_sim_start(&c->sim, e->bin, c->relay_link, extra,
			   RIG_START_MS) < 0) {
		rig_seterr(c, "galil-sim did not start");
		return -1;
	}
	c->sim_up = 1;
	if (write_config(e, c->cfg, c->log, o->power_output, c->sim.udp_port) <
	    0) {
		rig_seterr(c, "cannot write '%s'", c->cfg);
		return -1;
	}
	c->ctl = proc_ctl_connect(c->sim.ctl_port, RIG_START_MS);
	if (c->ctl < 0) {
		rig_seterr(c, "cannot connect to the control port");
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

int rig_wait_ready(struct sys_case *c, int timeout_ms)
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
		rig_seterr(c,
			   "no 'RoboELF Ready for Use' within %d ms%s%s\n--- "
			   "stdout:\n%s",
			   timeout_ms, fault[0] ? ": " : "", fault,
			   rig_tail(&c->re, PROC_STDOUT, 500));
	}
	return -1;
}

int rig_wait_sim_fine(struct sys_case *c, double t, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;

	for (;;) {
		double now = sys_sim_time(c);

		if (now < 0)
			return -1;
		if (now >= t)
			return 0;
		if (proc_now_ms() > deadline) {
			rig_seterr(c,
				   "simulated time %.0f not reached (now %.0f)",
				   t, now);
			return -1;
		}
		proc_pump(&c->re, 0);
		poll(NULL, 0, 2);
	}
}

double rig_signal_at(struct sys_case *c, int sig, double *t_before)
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
static int measure_reference(struct sys_case *c, struct rig_ref *ref)
{
	double t_off;

	if (sys_events(c) < 0 ||
	    first_event_time(c, "axis A motor on: SH (thread 0", 0,
			     &ref->t_service) < 0 ||
	    first_event_time(c, "axis A motor off: ", ref->t_service, &t_off) <
		0) {
		rig_seterr(c, "the reference calibration's events lack the "
			      "service state");
		return -1;
	}
	ref->d_cal = t_off - ref->t_service;
	return 0;
}

/* Centring from rig_off_centre[] at the travel speed (vmax): the longest axis
 * distance at RIG_VMAX_CPS plus the ramp (AC = 10 x the service speed). */
static int centring_time(const struct sys_env *e, struct rig_ref *ref)
{
	struct re_calset *set = calloc(1, sizeof(*set));
	char err[512];
	double d = 0;

	if (!set || re_calfile_load(e->cal, NULL, set, err, sizeof(err)) != 0) {
		free(set);
		return -1;
	}
	for (int i = 0; i < 3; i++) {
		const struct re_caltable *t = &set->axis[i];

		ref->centre[i] = (t->soft_rev + t->soft_fwd) / 2;
		if (fabs(rig_off_centre[i] - ref->centre[i]) > d)
			d = fabs(rig_off_centre[i] - ref->centre[i]);
	}
	ref->d_centre = 1000.0 * d / RIG_VMAX_CPS + 1000.0 / 10.0;
	free(set);
	return 0;
}

static int calibrate(struct sys_env *e, struct rig_ref *ref)
{
	static struct sys_case cs; /* the calibrating case */
	struct rig_opts o = {.calibration = "full"};
	struct stat st;
	int rc = -1;

	if (rig_start(&cs, e, &o) < 0 ||
	    rig_wait_ready(&cs, CAL_READY_MS) < 0 ||
	    measure_reference(&cs, ref) < 0) {
		snprintf(e->err, sizeof(e->err), "%s", cs.err);
		goto out;
	}
	e->calib_s = cs.ready_wall_s;
	proc_signal(&cs.re, SIGTERM);
	if (proc_wait_exit(&cs.re, RIG_EXIT_WAIT_MS, NULL) < 0 ||
	    proc_exit_code(&cs.re) != 0)
		snprintf(e->err, sizeof(e->err),
			 "roboelf did not quit cleanly after calibrating");
	else if (stat(e->cal, &st) < 0 || centring_time(e, ref) < 0)
		snprintf(e->err, sizeof(e->err), "no usable '%s'", e->cal);
	else
		rc = 0;
out:
	sys_case_stop(&cs);
	return rc;
}

int rig_env_ready(struct sys_env *e, struct rig_ref *ref)
{
	char plant[SYS_PATH_MAX + 16];
	int ok = 0;

	memset(ref, 0, sizeof(*ref));
	if (sys_env_init(e) == 0) {
		env_figures(e);
		snprintf(plant, sizeof(plant), PLANT_FMT, e->dir);
		if (write_text(plant,
			       "axes:\n"
			       "  A: {rev_limit: -10000, fwd_limit: 10000}\n"
			       "  B: {rev_limit: -10000, fwd_limit: 10000}\n"
			       "  C: {rev_limit: -8000, fwd_limit: 8000}\n") ==
			0 &&
		    calibrate(e, ref) == 0)
			ok = 1;
	}
	print_message("[   INFO   ] full calibration %s in %.1f s: service "
		      "state %.0f ms, centring from off-centre ~%.0f ms (%s)"
		      "%s%s\n",
		      ok ? "done" : "FAILED", e->calib_s, ref->d_cal,
		      ref->d_centre, e->dir, ok ? "" : ": ", ok ? "" : e->err);
	return ok;
}

void rig_need_env(const struct sys_env *e, int ready)
{
	if (!ready)
		fail_msg("no calibrated environment: %s", e->err);
}

/* ---- deadlines, injection, the FAULT line ------------------------------- */

double rig_p(void)
{
	return RIG_PERIOD_MS;
}

double rig_c(void)
{
	return RIG_CRIT_F * RIG_PERIOD_MS;
}

double rig_d_encpot(void)
{
	return (2.0 + RIG_PERSIST) * rig_p();
}

double rig_inject(struct sys_case *c, const char *req)
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

double rig_wait_motors_off(struct sys_case *c, double after, int ms)
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

void rig_check_fault_line(struct sys_case *c, const char *what,
			  const char *line, int axis,
			  const enum re_fault_id *ids)
{
	char logline[4096];

	if (sys_fault_match(line, axis, ids) == RE_F_NONE) {
		char pre[64], rec[512];

		sys_fault_expect(ids[0], axis, pre, sizeof(pre), rec,
				 sizeof(rec));
		rig_fail("%s: unexpected FAULT line\n    got:      %s\n    "
			 "expected: %s...%s",
			 what, line, pre, rec);
	}
	if (axis >= 0) {
		char name[16];

		snprintf(name, sizeof(name), "axis %c", 'A' + axis);
		if (!strstr(line, name))
			rig_fail("%s: the FAULT line does not name %s: %s",
				 what, name, line);
	}
	if (sys_log_find(c, " FAULT ", line, logline, sizeof(logline)) < 0)
		rig_fail("%s: %s", what, c->err);
}
