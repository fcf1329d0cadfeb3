/*
 * test_re_calib.c - the calibration procedure (re_calib) against a small
 * fake controller and robot behind struct re_io, in fake time: three axes
 * between limit switches at +-50000 counts, potentiometers 0.5..4.5 V with
 * a sine bow, and the program's service moves (mvtg, mvsp, mvax, mvreq),
 * with the program's rule that a fast move toward a switch whose slow zone
 * the potentiometer is in is refused. The sampler stands in for the
 * supervisor's cycle. Covers a clean calibration (table values, soft
 * limits, centre, time, never fast in a slow zone), a limit switch that
 * never comes, a non-monotonic potentiometer, a wrong range, an offset
 * present before the sweep, a PC stall during the sweep, a fault the
 * supervisor latched, the stop flag, and the check of loaded tables
 * against the robot. The same procedure runs on galil-sim in the system
 * tests.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "gl_err.h"
#include "re_calib.h"
#include "re_super.h"

#define MS    1000000LL
#define LIMIT 50000.0

struct fax {
	double pos, target, v, sp;
	int moving, stop_code, motor_on;
	int no_fwd_switch; /* the switch never closes */
	double enc_offset; /* encoder origin shift */
	/* a sticky switch: once closed it opens only this many counts back
	 * from its place (0: at once); rev_on, fwd_on: what it reads */
	double rev_stuck, fwd_stuck;
	int rev_on, fwd_on;
};

static struct {
	int64_t now, last_step;
	struct fax ax[3];
	double gain[3];	      /* pot volts per full travel */
	double dip_at, dip_v; /* non-monotonic stretch on axis C */
	int trip_axis;	      /* motor off (stop code 8) at trip_pos */
	double trip_pos;
	double pot_offset[3]; /* added to every reading */
	int n_records;
	char last_cmd[96];
	/* the program's service move request */
	double mvtg[3], mvsp[3];
	int mvax[3];
	int fast_in_zone; /* a fast move toward a near switch was seen */
	int64_t stall_at, stall_ns; /* the sampler stalls once */
	int late_begin;	      /* the program begins a requested move only when
				 the PC asks "MG mvreq" (after its record) */
	int req_waiting;      /* mvreq=1 sent, not begun (late_begin) */
	int sampler_fault_at; /* the sampler reports RE_FAULT */
} fk;

#define PNLO 0.83 /* the plan's slow zones for this robot (V) */
#define PNHI 4.17
#define SEEK 4000 /* counts/s */

static double pot_volts(int i, double pos)
{
	double u = (pos + LIMIT) / (2 * LIMIT);
	double v = 0.5 + fk.gain[i] * u + 0.05 * sin(M_PI * u);

	if (i == 2 && fk.dip_v != 0 && fabs(pos - fk.dip_at) < 1500)
		v -= fk.dip_v;
	return v + fk.pot_offset[i];
}

/* The program's rule (#MVSUP): never fast toward a near switch. */
static void zone_rule(int i)
{
	const struct fax *a = &fk.ax[i];
	double pot = pot_volts(i, a->pos);
	int toward_rev = a->target<a->pos, toward_fwd = a->target> a->pos;

	if (a->moving && a->v > SEEK &&
	    ((toward_rev && pot < PNLO) || (toward_fwd && pot > PNHI)))
		fk.fast_in_zone = 1;
}

static int fwd_active(const struct fax *a)
{
	return !a->no_fwd_switch && a->pos >= LIMIT;
}

static void stop(struct fax *a, int code)
{
	a->moving = 0;
	a->stop_code = code;
}

/* Move axis i for dt seconds at its speed toward its target. */
static void move_axis(int i, double dt)
{
	struct fax *a = &fk.ax[i];
	double d = a->target - a->pos, s = a->v * dt;

	if (!a->moving)
		return;
	zone_rule(i);
	if (!a->motor_on) {
		stop(a, a->stop_code);
		return;
	}
	a->pos += fabs(d) <= s ? d : (d > 0 ? s : -s);
	if (a->pos <= -LIMIT && d < 0) {
		a->pos = -LIMIT;
		stop(a, 3);
	} else if (fwd_active(a) && d > 0) {
		a->pos = LIMIT;
		stop(a, 2);
	} else if (a->pos == a->target) {
		stop(a, 1);
	}
	if (fk.trip_axis == i + 1 && a->pos >= fk.trip_pos) {
		a->motor_on = 0;
		stop(a, 8);
	}
}

static void plant_run(void)
{
	while (fk.last_step + MS <= fk.now) {
		for (int i = 0; i < 3; i++)
			move_axis(i, 0.001);
		fk.last_step += MS;
	}
}

static void begin(int i)
{
	if (fk.ax[i].motor_on && fk.ax[i].target != fk.ax[i].pos) {
		fk.ax[i].moving = 1;
		fk.ax[i].v = fk.ax[i].sp;
		fk.ax[i].stop_code = 0;
	}
}

/* "name[i]=value" of the service move request. */
static int assign(const char *c)
{
	int i;
	double v;
	char name[8];

	if (sscanf(c, "%7[a-z][%d]=%lf", name, &i, &v) != 3 || i < 0 || i > 2)
		return GL_ERR_CTRL;
	if (!strcmp(name, "mvtg"))
		fk.mvtg[i] = v;
	else if (!strcmp(name, "mvsp"))
		fk.mvsp[i] = v;
	else if (!strcmp(name, "mvax"))
		fk.mvax[i] = v != 0;
	else
		return GL_ERR_CTRL;
	return GL_OK;
}

static int one_cmd(const char *c)
{
	if (!strcmp(c, "mvreq=1") && fk.late_begin) {
		fk.req_waiting = 1;
		return GL_OK;
	}
	if (!strcmp(c, "MG mvreq") && fk.req_waiting) {
		int rc;

		fk.req_waiting = 0;
		fk.late_begin = 0;
		rc = one_cmd("mvreq=1");
		fk.late_begin = 1;
		return rc;
	}
	if (!strcmp(c, "mvreq=1")) {
		for (int i = 0; i < 3; i++) {
			if (!fk.mvax[i])
				continue;
			fk.ax[i].target = fk.mvtg[i] - fk.ax[i].enc_offset;
			fk.ax[i].sp = fk.mvsp[i];
			begin(i);
		}
		return GL_OK;
	}
	if (!strcmp(c, "MG mvreq"))
		return GL_OK;
	return assign(c);
}

static int f_command(void *ud, const char *cmd, char *resp, size_t cap,
		     int timeout_ms)
{
	char buf[128], *save = NULL;

	(void)ud;
	(void)timeout_ms;
	plant_run();
	snprintf(fk.last_cmd, sizeof(fk.last_cmd), "%s", cmd);
	snprintf(buf, sizeof(buf), "%s", cmd);
	for (char *c = strtok_r(buf, ";", &save); c;
	     c = strtok_r(NULL, ";", &save))
		if (one_cmd(c) != GL_OK)
			return GL_ERR_CTRL;
	if (cap)
		snprintf(resp, cap, "%s",
			 strcmp(cmd, "MG mvreq") ? "" : " 0.0000");
	return 0;
}

/* What the switches read: closed at their place, open again only
 * rev_stuck / fwd_stuck counts back from it. */
static void switch_readings(struct fax *a)
{
	if (a->pos <= -LIMIT)
		a->rev_on = 1;
	else if (a->pos > -LIMIT + a->rev_stuck)
		a->rev_on = 0;
	if (fwd_active(a))
		a->fwd_on = 1;
	else if (a->pos < LIMIT - a->fwd_stuck)
		a->fwd_on = 0;
}

static int f_record(void *ud, const char *prefix, struct gl_record *rec,
		    int timeout_ms)
{
	(void)ud;
	(void)prefix;
	(void)timeout_ms;
	plant_run();
	fk.n_records++;
	memset(rec, 0, sizeof(*rec));
	rec->layout = GL_LAYOUT_4000;
	rec->n_axes = 3;
	for (int i = 0; i < 3; i++) {
		const struct fax *a = &fk.ax[i];
		struct gl_rec_axis *r = &rec->axis[i];

		r->motor_pos = (int32_t)lround(a->pos + a->enc_offset);
		r->status = (uint16_t)((a->moving ? GL_AXST_MOVING : 0) |
				       (a->motor_on ? 0 : GL_AXST_MOTOR_OFF));
		r->stop_code = (uint8_t)a->stop_code;
		switch_readings(&fk.ax[i]);
		r->switches = (uint8_t)((a->fwd_on ? 0 : GL_AXSW_FLS) |
					(a->rev_on ? 0 : GL_AXSW_RLS));
		r->analog_in =
		    (int32_t)lround(pot_volts(i, a->pos) * RE_AN_COUNTS_PER_V);
	}
	return GL_OK;
}

static const char *f_ctrl_error(void *ud, int *code)
{
	(void)ud;
	if (code)
		*code = 1;
	return "Unrecognized command";
}

static int f_message(void *ud, char *line, size_t cap)
{
	(void)ud;
	(void)line;
	(void)cap;
	return GL_ERR_AGAIN;
}

static int f_relay_check(void *ud, char *why, size_t cap)
{
	(void)ud;
	(void)why;
	(void)cap;
	return GL_OK;
}

static int f_relay_off(void *ud)
{
	(void)ud;
	return GL_OK;
}

static int f_relay_off_start(void *ud)
{
	(void)ud;
	return GL_OK;
}

static int f_relay_off_finish(void *ud, int deadline_ms)
{
	(void)ud;
	(void)deadline_ms;
	return GL_OK;
}

static enum re_relay_state f_relay_state(void *ud)
{
	(void)ud;
	return RE_RELAY_ON;
}

static int f_log(void *ud, enum re_log_level lvl, const char *text)
{
	(void)ud;
	(void)lvl;
	(void)text;
	return GL_OK;
}

static int64_t f_now(void *ud)
{
	(void)ud;
	return fk.now;
}

static void f_sleep_until(void *ud, int64_t t)
{
	(void)ud;
	if (t > fk.now)
		fk.now = t;
}

static const struct re_io_ops ops = {
    .record = f_record,
    .command = f_command,
    .ctrl_error = f_ctrl_error,
    .message = f_message,
    .relay_check = f_relay_check,
    .relay_off = f_relay_off,
    .relay_off_start = f_relay_off_start,
    .relay_off_finish = f_relay_off_finish,
    .relay_state = f_relay_state,
    .log = f_log,
    .now_ns = f_now,
    .sleep_until = f_sleep_until,
};

static const struct re_io io = {&ops, NULL};
static struct gl_record rec;

/* The supervisor's cycle, in short: every 10 ms a record (once, a stall
 * of fk.stall_ns at fk.stall_at); RE_FAULT once fk.n_records passes
 * fk.sampler_fault_at. */
static int f_sample(void *ud, const struct gl_record **out)
{
	(void)ud;
	f_sleep_until(NULL, fk.now + 10 * MS);
	if (fk.stall_ns && fk.now >= fk.stall_at) {
		f_sleep_until(NULL, fk.now + fk.stall_ns);
		fk.stall_ns = 0;
	}
	f_record(NULL, NULL, &rec, 0);
	if (fk.sampler_fault_at && fk.n_records > fk.sampler_fault_at)
		return RE_FAULT;
	*out = &rec;
	return GL_OK;
}
static const char *const names[3] = {"A", "B", "C"};
static struct re_calib_cfg cfg;
static struct re_calib *cal;
static struct re_calset set;
static volatile sig_atomic_t stop_flag;

static int setup(void **state)
{
	(void)state;
	memset(&fk, 0, sizeof(fk));
	fk.now = fk.last_step = 1000 * MS;
	for (int i = 0; i < 3; i++) {
		fk.gain[i] = 4.0;
		fk.ax[i].pos = i * 10000.0 - 10000; /* anywhere */
		fk.ax[i].motor_on = 1;		    /* the service state */
	}
	memset(&cfg, 0, sizeof(cfg));
	cfg.n_axes = 3;
	cfg.names = names;
	cfg.move_timeout_ms = 30000;
	cfg.cmd_timeout_ms = 100;
	for (int i = 0; i < 3; i++) {
		struct re_calib_axis_cfg *a = &cfg.axis[i];

		a->vmax_cps = 8000;
		a->travel_cps = 8000;
		a->seek_cps = SEEK;
		a->gain_v = 4.0 / 100000;
		a->pnlo_v = PNLO;
		a->pnhi_v = PNHI;
		a->potlo_v = 0.17;
		a->pothi_v = 4.83;
		a->step_counts = 1000;
		a->travel_counts = 100000;
		a->travel_tol = 0.1;
		a->backoff_counts = 500;
		a->pot_input = i + 1;
		a->check.noise_margin_v = 0.005;
		a->check.expected_range_v = 4.0;
		a->check.range_tol = 0.1;
		a->check.min_points = 89;
		a->check.max_points = 111;
		a->check.step_tol_counts = 999;
		a->check.abs_first_v = 0.5 + 500 * a->gain_v;
		a->check.abs_last_v = 4.5 - 500 * a->gain_v;
		a->check.abs_tol_v = 0.25;
		a->encpot.allowed_error = 0.5;
		a->encpot.persistence_cycles = 1;
	}
	cfg.accept_ms = 50;
	cfg.sampler = (struct re_calib_sampler){f_sample, NULL, NULL, NULL};
	stop_flag = 0;
	cfg.stop = &stop_flag;
	return re_calib_new(&cal);
}

static int teardown(void **state)
{
	(void)state;
	re_calib_free(cal);
	return 0;
}

/* All three axes in one run: 100 points each from -49500 to +49500, the
 * values on the potentiometer curve, every axis at the centre, < 29 s. */
static void test_calib_clean(void **state)
{
	struct re_fault f;
	double secs = 0;
	int filled = -1;

	if (state && *state)
		fk.late_begin = 1;

	int rc = re_calib_full(cal, &io, &cfg, &set, &f, &secs, &filled);

	if (rc != GL_OK)
		fail_msg("rc %d fault %d axis %d: %s", rc, f.id, f.axis, f.s);
	assert_int_equal(filled, 0);
	assert_int_equal(fk.fast_in_zone, 0);
	assert_int_equal(set.n_axes, 3);
	for (int i = 0; i < 3; i++) {
		const struct re_caltable *t = &set.axis[i];

		assert_int_equal(t->n, 100);
		assert_true(fabs(t->start_counts + 49500) <= 1);
		assert_true(fabs(t->soft_fwd - 49500) <= 1);
		assert_true(fabs(t->soft_rev - t->start_counts) < 0.5);
		for (int j = 0; j < t->n; j++)
			assert_true(
			    fabs(t->pot_v[j] -
				 pot_volts(i, t->start_counts + j * 1000.0)) <
			    0.0005);
		assert_true(fabs(fk.ax[i].pos) <= 1);
		assert_string_equal(set.name[i], names[i]);
	}
	print_message("calibration took %.2f s (fake time)\n", secs);
	/* 2 x 100000 counts at 8000 counts/s is 25 s; the slow zones (this
	 * robot's PNLO/PNHI: 8250 counts each before the switch, at half
	 * speed) and what the fast moves keep before them add the rest */
	assert_true(secs > 25 && secs < 29);
}

/* re_calib_progress() from inside the sampler, as roboelf's board does. */
static struct {
	const char *seen[16]; /* axis A's phases, in order, each once */
	int n_seen;
	double first_left_s, mid_total_s; /* estimates: at the start and at
					   * 15 s (elapsed + left) */
	int samples;
	double pct_min, pct_max;
} pg;

static int p_sample(void *ud, const struct gl_record **out)
{
	struct re_calib_progress p;
	int rc = f_sample(ud, out);

	re_calib_progress(cal, &cfg, &rec, fk.now, &p);
	assert_int_equal(p.active, 1);
	assert_int_equal(p.full, 1);
	if (pg.samples++ == 0)
		pg.first_left_s = p.left_s;
	if (!pg.mid_total_s && p.elapsed_s >= 15)
		pg.mid_total_s = p.elapsed_s + p.left_s;
	if (!pg.n_seen || strcmp(pg.seen[pg.n_seen - 1], p.axis[0].phase))
		pg.seen[pg.n_seen++ & 15] = p.axis[0].phase;
	pg.pct_min = fmin(pg.pct_min, p.axis[0].pct);
	pg.pct_max = fmax(pg.pct_max, p.axis[0].pct);
	return rc;
}

/* The board's calibration progress: axis A goes through every phase in
 * order, its position over the travel from 0 % to 100 %, and the time
 * left estimated within 5 % of what the calibration really took (fake
 * time, at its start and half-way: this robot has no acceleration, which
 * the estimate leaves out too); nothing once it has ended. */
static void test_calib_progress(void **state)
{
	static const char *const want[] = {
	    "starting",	       "to rev switch", "onto rev switch", "sweep fwd",
	    "onto fwd switch", "table built",	"to centre",
	};
	struct re_calib_progress p;
	struct re_fault f;
	double secs = 0;

	(void)state;
	memset(&pg, 0, sizeof(pg));
	pg.pct_min = 100;
	re_calib_progress(cal, &cfg, NULL, fk.now, &p);
	assert_int_equal(p.active, 0);
	cfg.sampler.sample = p_sample;
	assert_int_equal(re_calib_full(cal, &io, &cfg, &set, &f, &secs, NULL),
			 GL_OK);
	assert_int_equal(pg.n_seen, 7);
	for (int i = 0; i < 7; i++)
		assert_string_equal(pg.seen[i], want[i]);
	assert_true(pg.pct_min < 1 && pg.pct_max > 99);
	print_message("took %.1f s; estimated %.1f s at the start, %.1f s at "
		      "15 s\n",
		      secs, pg.first_left_s, pg.mid_total_s);
	assert_true(fabs(pg.first_left_s - secs) < 0.05 * secs);
	assert_true(fabs(pg.mid_total_s - secs) < 0.05 * secs);
	re_calib_progress(cal, &cfg, NULL, fk.now, &p);
	assert_int_equal(p.active, 0);
}

/* The program takes each move request (mvreq 0) only after the sample's
 * record was read, so that record shows the axis at rest, its last stop
 * code (0 at power-up): the procedure must not judge the move by it (it
 * once aborted "stopped before the slow zone ... still running"). The
 * result is that of the clean calibration. */
static void test_calib_taken_after_record(void **state)
{
	static int late = 1;
	void *st = &late;

	(void)state;
	test_calib_clean(&st);
}

/* The PC stalls for 150 ms during the sweep (shorter than the controller
 * watchdog), at 8 instants 20 ms apart: at 8000 counts/s the gap of 1280
 * counts leaves the points beside it with samples at one edge only, or
 * none; such a point is fitted from its and both neighbours' samples, and
 * every table still matches the curve. */
static void test_calib_pc_stall(void **state)
{
	struct re_fault f;
	int total = 0;

	(void)state;
	for (int k = 0; k < 8; k++) {
		int filled = -1;

		teardown(NULL);
		setup(NULL);
		fk.stall_at = fk.now + (12000 + 20 * k) * MS; /* sweeping */
		fk.stall_ns = 150 * MS;
		if (re_calib_full(cal, &io, &cfg, &set, &f, NULL, &filled))
			fail_msg("stall %d: fault %d axis %d: %s", k, f.id,
				 f.axis, f.s);
		/* all three axes sweep at once: per axis at most the points
		 * on both sides of the gap */
		assert_true(filled >= 0 && filled <= 6);
		total += filled;
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < set.axis[i].n; j++)
				assert_true(
				    fabs(set.axis[i].pot_v[j] -
					 pot_volts(i, set.axis[i].start_counts +
							  j * 1000.0)) < 0.002);
	}
	assert_true(total >= 1);
}

/* A 0.5 V offset on B's potentiometer from the start: it reads 1.0 V at
 * the reverse switch where 0.5 +- 0.25 V is expected - named there, before
 * the sweep. */
static void test_calib_offset_before(void **state)
{
	struct re_fault f;

	(void)state;
	fk.pot_offset[1] = 0.5;
	assert_int_equal(re_calib_full(cal, &io, &cfg, &set, &f, NULL, NULL),
			 RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_ABSOLUTE);
	assert_int_equal(f.axis, 1);
	assert_string_equal(f.s, "reverse");
	assert_true(fabs(f.f[0] - 1.0) < 0.01);
	assert_true(fabs(f.f[1] - 0.5) < 1e-9);
	assert_true(fabs(f.f[2] - 0.25) < 1e-9);
	assert_int_equal(set.n_axes, 0);
}

/* The forward switch of B never closes: the bounded sweep ends without it. */
static void test_calib_switch_never_comes(void **state)
{
	struct re_fault f;

	(void)state;
	fk.ax[1].no_fwd_switch = 1;
	assert_int_equal(re_calib_full(cal, &io, &cfg, &set, &f, NULL, NULL),
			 RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_ABORT);
	assert_int_equal(f.axis, 1);
	assert_non_null(strstr(f.s, "the forward limit switch never came "
				    "within "));
	assert_int_equal(set.n_axes, 0);
}

/* A dip in C's potentiometer: not rising at a point. */
/* A switch that stays closed past the back-off (stuck, or the back-off
 * too short for it): the reverse one, seen on the sweep's way out of it;
 * nothing is kept. */
static void test_calib_rev_switch_stuck(void **state)
{
	struct re_fault f;

	(void)state;
	fk.ax[0].rev_stuck = 700;
	assert_int_equal(re_calib_full(cal, &io, &cfg, &set, &f, NULL, NULL),
			 RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_ABORT);
	assert_int_equal(f.axis, 0);
	assert_string_equal(f.s, "still on the reverse limit switch after "
				 "backing off 500 counts");
	assert_int_equal(set.n_axes, 0);
	assert_true(fk.ax[0].pos > -49500 && fk.ax[0].pos < -49300);
}

/* The forward one, seen on the move to the centre. */
static void test_calib_fwd_switch_stuck(void **state)
{
	struct re_fault f;

	(void)state;
	fk.ax[2].fwd_stuck = 600;
	assert_int_equal(re_calib_full(cal, &io, &cfg, &set, &f, NULL, NULL),
			 RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_ABORT);
	assert_int_equal(f.axis, 2);
	assert_string_equal(f.s, "still on the forward limit switch after "
				 "backing off 500 counts");
	assert_int_equal(set.n_axes, 0);
	assert_true(fk.ax[2].pos < 49500 && fk.ax[2].pos > 49400);
}

static void test_calib_nonmonotonic(void **state)
{
	struct re_fault f;

	(void)state;
	fk.dip_at = 10000;
	fk.dip_v = 0.1;
	assert_int_equal(re_calib_full(cal, &io, &cfg, &set, &f, NULL, NULL),
			 RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_NONMONO);
	assert_int_equal(f.axis, 2);
	assert_int_equal(f.i[0], 58); /* point at +8500 counts */
}

/* A's potentiometer spans 3 V instead of 4 V +- 10 %: with the absolute
 * check off, the range check names it; with it on, the forward switch
 * reading (3.5 V for 4.5 +- 0.25 V) does, earlier. */
static void test_calib_wrong_range(void **state)
{
	struct re_fault f;

	(void)state;
	fk.gain[0] = 3.0;
	assert_int_equal(re_calib_full(cal, &io, &cfg, &set, &f, NULL, NULL),
			 RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_ABSOLUTE);
	assert_int_equal(f.axis, 0);
	assert_string_equal(f.s, "forward");
	teardown(NULL);
	setup(NULL);
	fk.gain[0] = 3.0;
	for (int i = 0; i < 3; i++)
		cfg.axis[i].check.abs_tol_v = 0;
	assert_int_equal(re_calib_full(cal, &io, &cfg, &set, &f, NULL, NULL),
			 RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_RANGE);
	assert_int_equal(f.axis, 0);
}

/* The supervisor's cycle latched a fault (a motor off, the relay, ...):
 * the procedure ends at once with RE_FAULT and a fault id RE_F_NONE (the
 * supervisor reacted already), nothing kept. */
static void test_calib_supervisor_fault(void **state)
{
	struct re_fault f;

	(void)state;
	fk.sampler_fault_at = 300;
	assert_int_equal(re_calib_full(cal, &io, &cfg, &set, &f, NULL, NULL),
			 RE_FAULT);
	assert_int_equal(f.id, RE_F_NONE);
	assert_int_equal(fk.n_records, 301);
	assert_int_equal(set.n_axes, 0);
}

/* SIGTERM during calibration: stop at the next sample. */
static void test_calib_stop_flag(void **state)
{
	struct re_fault f;

	(void)state;
	stop_flag = 1;
	assert_int_equal(re_calib_full(cal, &io, &cfg, &set, &f, NULL, NULL),
			 GL_ERR_AGAIN);
	assert_int_equal(set.n_axes, 0);
}

/* Loaded tables: accepted where the robot agrees, then to the centre;
 * refused when the encoder origin moved (controller restarted). */
static void test_calib_check_robot(void **state)
{
	static struct re_calset saved;
	struct re_fault f;

	(void)state;
	assert_int_equal(re_calib_full(cal, &io, &cfg, &saved, &f, NULL, NULL),
			 GL_OK);
	fk.ax[0].pos = 20000;
	assert_int_equal(re_calib_check_robot(cal, &io, &cfg, &saved, &f),
			 GL_OK);
	assert_true(fabs(fk.ax[0].pos) <= 1);
	fk.ax[1].enc_offset = 20000; /* encoders restarted elsewhere */
	assert_int_equal(re_calib_check_robot(cal, &io, &cfg, &saved, &f),
			 RE_FAULT);
	assert_int_equal(f.id, RE_F_CAL_ABORT);
	assert_int_equal(f.axis, 1);
	assert_non_null(strstr(f.s, "does not match the robot"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_calib_clean, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_calib_progress, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_calib_taken_after_record,
					    setup, teardown),
	    cmocka_unit_test_setup_teardown(test_calib_switch_never_comes,
					    setup, teardown),
	    cmocka_unit_test_setup_teardown(test_calib_rev_switch_stuck, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_calib_fwd_switch_stuck, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_calib_nonmonotonic, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_calib_wrong_range, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_calib_supervisor_fault, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_calib_pc_stall, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_calib_offset_before, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_calib_stop_flag, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_calib_check_robot, setup,
					    teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
