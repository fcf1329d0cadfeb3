/*
 * re_super.c - the supervisor's periodic cycle: schedule, round trip,
 * checks, status. See re_super.h; the checks themselves are in re_check.c,
 * the fault reaction in re_react.c.
 */
#include "re_super_int.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"

static int64_t now_ns(const struct re_super *s)
{
	return s->pub.io.ops->now_ns(s->pub.io.ud);
}

static double ns_to_ms(int64_t ns)
{
	return (double)ns / 1e6;
}

static double pot_of(const struct re_super *s, int i)
{
	return re_pot_of(&s->pub.rec, i, s->pub.cfg.pot_input[i]);
}

/* The read-back's chunks ("MG r1,...", each fitting the line after the
 * heartbeat "hbpc=999999999;" and before ";QR"), and the expectation for
 * the safe state. */
static int readback_init(struct re_super *s)
{
	const size_t room = GL_LINE_MAX - sizeof("hbpc=999999999;;QR") + 1;
	int n;

	if (!s->pub.cfg.seal || !s->pub.io.ops->record_text)
		return GL_OK;
	n = re_seal_chunks(s->pub.cfg.seal, room < 63 ? room : 63, s->rb_first,
			   s->rb_count, RE_SEAL_MAX);
	if (n < 0)
		return n;
	for (int k = 0; k < n; k++)
		if (re_seal_chunk_text(s->pub.cfg.seal, s->rb_first[k],
				       s->rb_count[k], s->rb_chunk[k],
				       sizeof(s->rb_chunk[k])) < 0)
			return GL_ERR_OVERFLOW;
	s->pub.rb_n = n;
	re_seal_expect(s->pub.cfg.seal, 0, NULL, NULL, s->seal_expect);
	return GL_OK;
}

struct re_super *re_super_new(void)
{
	return calloc(1, sizeof(struct re_super));
}

void re_super_free(struct re_super *s)
{
	free(s);
}

const struct re_super_view *re_super_view(const struct re_super *s)
{
	return &s->pub;
}

int re_super_init(struct re_super *s, const struct re_io *io,
		  const struct re_super_cfg *cfg,
		  const struct re_caltable *const *tables, int expect)
{
	memset(s, 0, sizeof(*s));
	if (!io || !io->ops || !cfg || cfg->n_axes < 1 ||
	    cfg->n_axes > RE_SUPER_AXES || cfg->period_ns <= 0)
		return GL_ERR_ARG;
	s->pub.io = *io;
	s->pub.cfg = *cfg;
	if (cfg->wdog.noncrit_ns <= 0 ||
	    cfg->wdog.crit_ns < cfg->wdog.noncrit_ns)
		return GL_ERR_ARG;
	s->noncrit_ns = cfg->wdog.noncrit_ns;
	s->pub.crit_ns = cfg->wdog.crit_ns;
	for (int i = 0; tables && i < cfg->n_axes; i++)
		s->table[i] = tables[i];
	s->pub.expect = expect;
	s->pub.armed = expect == RE_DMC_ARMED;
	s->pub.period_ns = cfg->period_ns;
	s->t0_ns = now_ns(s);
	s->deadline_ns = s->t0_ns + cfg->period_ns; /* no previous cycle */
	s->last_good_ns = s->t0_ns;
	re_super_stream_reset(s, s->t0_ns);
	re_alive_reset(&s->alive);
	re_xcheck_reset(&s->xc, s->t0_ns);
	return readback_init(s);
}

/* What the read-back expects from now on: the session's values of
 * @expect, with the soft limits of @tables (armed) or wide open. */
static void seal_expect(struct re_super *s,
			const struct re_caltable *const *tables, int expect)
{
	double rev[RE_SUPER_AXES], fwd[RE_SUPER_AXES];
	int have = tables && expect == RE_DMC_ARMED;

	if (!s->pub.rb_n)
		return;
	for (int i = 0; have && i < s->pub.cfg.n_axes; i++) {
		have = tables[i] != NULL;
		if (have) {
			rev[i] = tables[i]->soft_rev;
			fwd[i] = tables[i]->soft_fwd;
		}
	}
	re_seal_expect(s->pub.cfg.seal, expect, have ? rev : NULL,
		       have ? fwd : NULL, s->seal_expect);
	s->seal_state = expect;
	s->state_cycles = 0;
	s->rb_have = 0;
}

void re_super_start(struct re_super *s, const struct re_caltable *const *tables,
		    long hbpc, int expect)
{
	if (s->pub.latched)
		return;
	for (int i = 0; i < s->pub.cfg.n_axes; i++) {
		s->table[i] = tables ? tables[i] : NULL;
		s->encpot[i].violations = 0;
		s->moving_ns[i] = 0;
	}
	s->pub.expect = expect;
	s->pub.armed = expect == RE_DMC_ARMED;
	s->own_mask = 0;
	seal_expect(s, tables, expect);
	re_xcheck_reset(&s->xc, now_ns(s));
	/* the handles known stay from the first record on (just after the
	 * take-over closed the others): a program that connects between two
	 * phases, e.g. just before the first armed cycle, is still new */
	s->pub.hbpc = hbpc;
	s->last_good_ns = now_ns(s);
	/* the stall check counts from here: a stall before the first cycle
	 * is one too */
	s->last_end_ns = s->last_good_ns;
	s->deadline_ns = s->last_good_ns + s->pub.period_ns;
	re_super_stream_reset(s, s->last_good_ns);
	re_alive_reset(&s->alive);
}

void re_super_tables(struct re_super *s,
		     const struct re_caltable *const *tables)
{
	for (int i = 0; i < s->pub.cfg.n_axes; i++) {
		s->table[i] = tables ? tables[i] : NULL;
		s->encpot[i].violations = 0;
	}
}

void re_super_set_period(struct re_super *s, int64_t period_ns)
{
	s->pub.period_ns = period_ns > 0 ? period_ns : s->pub.cfg.period_ns;
	s->deadline_ns = now_ns(s) + s->pub.period_ns;
}

void re_super_own(struct re_super *s, unsigned mask)
{
	int64_t now = now_ns(s);

	for (int i = 0; i < s->pub.cfg.n_axes; i++)
		if ((s->own_mask | mask) >> i & 1)
			s->cmd_ns[i] = now;
	s->own_mask = mask;
}

int64_t re_super_wait(struct re_super *s)
{
	int64_t now = now_ns(s);
	int64_t late, bin;

	if (now > s->deadline_ns) {
		/* the last cycle ran into this one: no burst of late cycles */
		s->pub.overruns++;
		s->deadline_ns = now;
	} else {
		s->pub.io.ops->sleep_until(s->pub.io.ud, s->deadline_ns);
		now = now_ns(s);
	}
	late = now - s->deadline_ns;
	if (late < 0)
		late = 0;
	s->pub.late_last_ns = late;
	if (late > s->late_worst_ns)
		s->late_worst_ns = late;
	bin = late / (RE_LATE_BIN_US * 1000);
	s->late_hist[bin < RE_LATE_BINS - 1 ? bin : RE_LATE_BINS - 1]++;
	s->deadline_ns += s->pub.period_ns;
	return late;
}

/* ---- the cycle ----------------------------------------------------------- */

static int reply_timeout_ms(const struct re_super *s)
{
	int64_t left = s->last_good_ns + s->pub.crit_ns - now_ns(s);

	if (left < BASE_NS_PER_MS)
		return 1;
	return (int)((left + BASE_NS_PER_MS - 1) / BASE_NS_PER_MS);
}

static int comm_fault(int rc, struct re_fault *f)
{
	re_fault_set(f, RE_F_COMM, -1);
	snprintf(f->s, sizeof(f->s), "cannot read the data record: %s",
		 gl_strerror(rc));
	return RE_FAULT;
}

/* The supervisor itself did not run for longer than the critical limit
 * (SIGSTOP, a debugger, an overloaded PC): that, measured on its own
 * monotonic clock, is the cause - not the link, and not the controller's
 * watchdog that tripped meanwhile. */
static int check_stall(struct re_super *s, struct re_fault *f)
{
	int64_t gap;

	if (!s->last_end_ns)
		return RE_OK;
	gap = now_ns(s) - s->last_end_ns;
	if (gap <= s->pub.crit_ns)
		return RE_OK;
	re_fault_set(f, RE_F_STALL, -1);
	f->i[0] = gap / BASE_NS_PER_MS;
	f->i[1] = s->pub.crit_ns / BASE_NS_PER_MS;
	return RE_FAULT;
}

/* The round trip with the next chunk of the seal read back on the same
 * line: "hbpc=N;MG r1,...,rn;QR". */
static int record_readback(struct re_super *s, int tmo)
{
	size_t n = (size_t)s->prefix_len, m = strlen(s->rb_chunk[s->rb_next]);
	int rc;

	memcpy(s->rb_line, s->prefix, n);
	s->rb_line[n] = ';';
	memcpy(s->rb_line + n + 1, s->rb_chunk[s->rb_next], m + 1);
	rc = s->pub.io.ops->record_text(s->pub.io.ud, s->rb_line, &s->pub.rec,
					s->rb_reply, sizeof(s->rb_reply), tmo);
	s->rb_have = rc == GL_OK;
	s->rb_cur = s->rb_next;
	s->rb_next = (s->rb_next + 1) % s->pub.rb_n;
	return rc;
}

/* The round trip and the PC-side watchdog verdict on it. */
static int exchange(struct re_super *s, struct re_fault *f)
{
	int64_t now, age = 0, t0 = now_ns(s), over;
	int rc, v, tmo = reply_timeout_ms(s);

	re_super_hb_next(s);
	rc = s->pub.rb_n ? record_readback(s, tmo)
			 : s->pub.io.ops->record(s->pub.io.ud, s->prefix,
						 &s->pub.rec, tmo);
	now = now_ns(s);
	s->pub.link_ok = rc == GL_OK;
	/* The round trip waits at most tmo: a return later than that by more
	 * than the critical limit means this process did not run meanwhile
	 * (stopped inside the wait), whatever the link did. */
	over = now - t0 - (int64_t)tmo * BASE_NS_PER_MS;
	if (over > s->pub.crit_ns) {
		/* Reported from t0, the last moment it is known to have
		 * run: 'over' alone would leave out the part of the stop
		 * that fell inside the wait (a 2 s SIGSTOP read 1924 ms). */
		re_fault_set(f, RE_F_STALL, -1);
		f->i[0] = (now - t0) / BASE_NS_PER_MS;
		f->i[1] = s->pub.crit_ns / BASE_NS_PER_MS;
		return RE_FAULT;
	}
	if (rc != GL_OK && rc != GL_ERR_TIMEOUT)
		return comm_fault(rc, f);
	v = re_check_reply_age(&s->pub.cfg.wdog, s->last_good_ns, now, &age, f);
	if (v < 0) {
		re_fault_set(f, RE_F_WDOG_REPLY, -1);
		f->i[0] = RE_VAL_UNKNOWN;
		f->i[1] = s->pub.crit_ns / BASE_NS_PER_MS;
		v = RE_FAULT;
	}
	if (rc == GL_ERR_TIMEOUT && v != RE_FAULT) {
		/* the deadline was the critical limit: rounding aside, late */
		re_fault_set(f, RE_F_WDOG_REPLY, -1);
		f->i[0] = age / BASE_NS_PER_MS;
		f->i[1] = s->pub.crit_ns / BASE_NS_PER_MS;
		v = RE_FAULT;
	}
	s->pub.fresh = rc == GL_OK;
	if (rc == GL_OK) {
		s->pub.have_record = 1;
		s->last_good_ns = now;
		s->pub.age_last_ns = age;
		if (age > s->pub.age_worst_ns)
			s->pub.age_worst_ns = age;
	}
	return v;
}

/* A late reply (non-critical): counted; logged and shown when it is the
 * first since the window closed (which opens one), else held for the
 * summary with the worst age (re_super_wd_flush(), re_react.c: the fault
 * reaction and the shutdown flush it too). */
static void warn_watchdog(struct re_super *s)
{
	s->wd_warnings++;
	if (s->wd_open) {
		s->wd_held++;
		if (s->pub.age_last_ns > s->wd_held_worst_ns)
			s->wd_held_worst_ns = s->pub.age_last_ns;
		return;
	}
	s->wd_open = 1;
	s->wd_open_ns = now_ns(s);
	snprintf(s->text, sizeof(s->text),
		 "watchdog: %s after %.1f ms "
		 "(non-critical limit %.1f ms, critical %.1f ms)",
		 s->pub.cfg.stream ? "a record or the heartbeat's reply came"
				   : "reply",
		 ns_to_ms(s->pub.age_last_ns), ns_to_ms(s->noncrit_ns),
		 ns_to_ms(s->pub.crit_ns));
	re_io_logf(&s->pub.io, RE_LOG_WARN, "%s", s->text);
	re_super_note(s, RE_LOG_WARN, RE_EV_WATCHDOG, s->text);
}

/* The window of condensed warnings ends RE_SUPER_WD_WINDOW_MS after the
 * warning that opened it: checked each cycle, before this cycle's own. */
static void wd_window(struct re_super *s)
{
	if (s->wd_open && now_ns(s) - s->wd_open_ns >=
			      (int64_t)RE_SUPER_WD_WINDOW_MS * BASE_NS_PER_MS)
		re_super_wd_flush(s);
}

static int check_relay(struct re_super *s, struct re_fault *f)
{
	char why[sizeof(f->s)];

	if (s->pub.io.ops->relay_check(s->pub.io.ud, why, sizeof(why)) == GL_OK)
		return RE_OK;
	re_fault_set(f, RE_F_ESTOP_LOST, -1);
	snprintf(f->s, sizeof(f->s), "%s", why);
	return RE_FAULT;
}

/* A check that cannot run is a fault, never a pass (fail safe). */
static int check_error(struct re_fault *f, enum re_fault_id id, int axis,
		       const char *what, int err)
{
	re_fault_set(f, id, axis);
	snprintf(f->s, sizeof(f->s), "%s could not run: %s", what,
		 gl_strerror(err));
	return RE_FAULT;
}

static int check_encpot(struct re_super *s, struct re_fault *f)
{
	for (int i = 0; i < s->pub.cfg.n_axes; i++) {
		const struct gl_rec_axis *a = &s->pub.rec.axis[i];
		int v;

		s->pub.have_encres[i] = 0;
		if (!s->table[i])
			continue;
		v = re_check_encpot(s->table[i], &s->pub.cfg.encpot[i], i,
				    a->motor_pos, pot_of(s, i), &s->encpot[i],
				    &s->pub.encres[i], f);
		if (v < 0)
			return check_error(f, RE_F_CONFIG, i,
					   "encoder/potentiometer check", v);
		s->pub.have_encres[i] = 1;
		if (v == RE_FAULT)
			return RE_FAULT;
	}
	return RE_OK;
}

/* The axis the program's joystick command (k + 1) moves, or -1. */
static int cmd_axis(int cmd)
{
	return cmd >= 1 && cmd <= 6 ? (cmd - 1) / 2 : -1;
}

/* Motion only where commanded: an axis whose profiler runs must be the one
 * the program's command moves (armed: mcmd or jcmd), or one the supervisor
 * moves itself (service), or have been one of those within the grace (the
 * program publishes its command up to mainms late; a stopped axis still
 * decelerates). */
static int check_uncmd(struct re_super *s, struct re_fault *f)
{
	int64_t now = now_ns(s);

	if (!s->pub.cfg.uncmd_grace_ns || !s->pub.have_za)
		return RE_OK;
	for (int i = 0; i < s->pub.cfg.n_axes; i++) {
		int moving = !!(s->pub.rec.axis[i].status & GL_AXST_MOVING);

		if ((s->own_mask >> i & 1) || cmd_axis(s->pub.za.mcmd) == i ||
		    cmd_axis(s->pub.za.jcmd) == i)
			s->cmd_ns[i] = now;
		if (!moving) {
			s->moving_ns[i] = 0;
			continue;
		}
		if (!s->moving_ns[i])
			s->moving_ns[i] = now;
		if (now - s->cmd_ns[i] <= s->pub.cfg.uncmd_grace_ns ||
		    now - s->moving_ns[i] <= s->pub.cfg.uncmd_grace_ns)
			continue;
		re_fault_set(f, RE_F_UNCMD, i);
		snprintf(
		    f->s, sizeof(f->s),
		    "its profiler runs, seen by the supervisor for %.0f ms",
		    ns_to_ms(now - s->moving_ns[i]));
		return RE_FAULT;
	}
	return RE_OK;
}

/* Another program connected (a handle open that was not at the start):
 * not itself a fault - a second supervisor or galil-load may look - but
 * logged and shown, and named in a fault that follows. */
static void watch_handles(struct re_super *s)
{
	unsigned mask = 0, fresh;
	char hs[9];
	int n = 0;

	for (int h = 0; h < 8; h++)
		if (s->pub.rec.handles[h])
			mask |= 1u << h;
	if (!s->have_handles) {
		s->handles_known = mask;
		s->have_handles = 1;
		return;
	}
	fresh = mask & ~s->handles_known;
	s->handles_known = mask;
	if (!fresh)
		return;
	s->pub.foreign |= fresh;
	for (int h = 0; h < 8; h++)
		if (fresh >> h & 1)
			hs[n++] = (char)('A' + h);
	hs[n] = '\0';
	snprintf(s->text, sizeof(s->text),
		 "another program connected to the controller (handle %s)", hs);
	re_io_logf(&s->pub.io, RE_LOG_WARN, "%s", s->text);
	re_super_note(s, RE_LOG_WARN, RE_EV_FOREIGN, s->text);
}

static void drain_messages(struct re_super *s)
{
	for (int i = 0; i < RE_SUPER_MSGS; i++) {
		int n = s->pub.io.ops->message(s->pub.io.ud, s->msg,
					       sizeof(s->msg));

		if (n < 0)
			break;
		re_io_logf(&s->pub.io, RE_LOG_INFO, "controller: %s", s->msg);
	}
}

/* The chunk of the seal this reply read back, against the supervisor's
 * own plan; the session's values only once the program has shown the
 * state they were made for in two records in a row. */
static int check_readback(struct re_super *s, struct re_fault *f)
{
	int bad = 0, v;
	double found = 0;

	if (!s->pub.rb_n || !s->rb_have || !s->pub.have_za)
		return RE_OK;
	s->state_cycles = s->seal_state && s->pub.za.state == s->seal_state
			      ? s->state_cycles + 1
			      : 0;
	v = re_seal_judge(s->pub.cfg.seal, s->seal_expect,
			  s->rb_first[s->rb_cur], s->rb_count[s->rb_cur],
			  s->rb_reply, strlen(s->rb_reply),
			  s->state_cycles >= 2, s->pub.za.state, &bad, &found);
	if (v == GL_ERR_PROTO)
		return check_error(f, RE_F_COMM, -1, "the seal's read-back", v);
	if (v != RE_FAULT)
		return RE_OK;
	re_fault_set(f, RE_F_READBACK, -1);
	f->i[0] = bad;
	re_seal_fault(s->pub.cfg.seal, found, s->seal_expect[bad - 1], f);
	f->id = RE_F_READBACK;
	return RE_FAULT;
}

/* Checks on a fresh record, in priority order. */
static int check_record(struct re_super *s, struct re_fault *f)
{
	int v;

	v = re_check_record(&s->pub.rec, s->pub.cfg.n_axes, s->pub.expect,
			    &s->pub.za, f);
	s->pub.have_za = v == RE_OK || f->id != RE_F_RECORD;
	if (v < 0)
		return check_error(f, RE_F_COMM, -1, "the record check", v);
	if (v != RE_OK)
		return v;
	v = re_check_alive(&s->pub.cfg.alive, &s->alive, now_ns(s),
			   s->pub.za.hbdmc, s->pub.rec.sample, f);
	if (v < 0)
		return check_error(f, RE_F_WDOG_HEARTBEAT, -1,
				   "the liveness check", v);
	if (v == RE_FAULT)
		return v;
	v = check_encpot(s, f);
	if (v == RE_FAULT)
		return v;
	v = s->pub.cfg.stream ? RE_OK : check_readback(s, f);
	if (v == RE_FAULT || !s->pub.expect)
		return v;
	v = check_uncmd(s, f);
	if (v == RE_FAULT || !s->pub.cfg.xcheck)
		return v;
	v = re_xcheck_step(&s->xc, s->pub.cfg.xcheck, &s->pub.rec, &s->pub.za,
			   now_ns(s), f);
	return v < 0 ? check_error(f, RE_F_CONFIG, -1, "the joystick decode", v)
		     : v;
}

/* The record while latched: the stream's newest (none new: the last
 * one stays), or a round trip. */
static int latched_record(struct re_super *s)
{
	int rc;

	if (!s->pub.cfg.stream)
		return s->pub.io.ops->record(
		    s->pub.io.ud, NULL, &s->pub.rec,
		    (int)(s->pub.period_ns / BASE_NS_PER_MS) + 1);
	rc = s->pub.io.ops->stream(s->pub.io.ud, &s->pub.rec, now_ns(s));
	return rc == 1 ? GL_OK : rc == 0 ? GL_ERR_AGAIN : rc;
}

/* The stream design's checks: those of a record only on a fresh one (a
 * cycle without one judged only its age), the echo, and the read-back
 * whose reply was collected this cycle. */
static int stream_checks(struct re_super *s, struct re_fault *f)
{
	int v = RE_OK;

	if (s->pub.fresh)
		v = check_record(s, f);
	if (v != RE_FAULT)
		v = re_super_check_echo(s, f);
	if (v != RE_FAULT)
		v = check_readback(s, f);
	return v;
}

static int latched_cycle(struct re_super *s)
{
	int rc = latched_record(s);
	struct re_fault scratch;

	memset(&scratch, 0, sizeof(scratch));
	s->pub.link_ok = rc == GL_OK || rc == GL_ERR_AGAIN;
	s->pub.fresh = rc == GL_OK;
	if (rc == GL_OK) {
		struct re_encpot_state st[RE_SUPER_AXES];

		s->pub.have_record = 1;
		s->pub.have_za =
		    re_check_record(&s->pub.rec, s->pub.cfg.n_axes, 0,
				    &s->pub.za, &scratch) >= 0 &&
		    scratch.id != RE_F_RECORD;
		memcpy(st, s->encpot, sizeof(st));
		check_encpot(s, &scratch);
		memcpy(s->encpot, st, sizeof(st));
	}
	/* The relay stays checked while latched (it must stay off): a failure
	 * is logged once, as the operator cannot be shown a second FAULT. */
	if (!s->relay_lost_logged && check_relay(s, &scratch) == RE_FAULT) {
		s->relay_lost_logged = 1;
		re_fault_format_units(&scratch, s->pub.cfg.axis_names,
				      &s->pub.cfg.units, s->text,
				      sizeof(s->text));
		re_io_logf(&s->pub.io, RE_LOG_WARN, "while latched: %s",
			   s->text);
		re_super_note(s, RE_LOG_FAULT, RE_EV_RELAY, s->text);
	}
	drain_messages(s);
	return RE_OK;
}

static int cycle_checks(struct re_super *s)
{
	struct re_fault f, rf;
	int v, rv, warn;

	memset(&f, 0, sizeof(f));
	if (check_stall(s, &f) == RE_FAULT)
		return re_super_fault(s, &f);
	v = s->pub.cfg.stream ? re_super_exchange_stream(s, &f)
			      : exchange(s, &f);
	/* the next cycle's stall gap counts from here, the last moment this
	 * process is known to have run with a fresh exchange: a stop in the
	 * rest of this cycle is in it too */
	s->last_end_ns = now_ns(s);
	warn = s->pub.link_ok && s->pub.age_last_ns > s->noncrit_ns;
	if (s->pub.link_ok && (!s->pub.cfg.stream || s->pub.fresh))
		watch_handles(s);
	rv = check_relay(s, &rf);
	if (rv == RE_FAULT)
		return re_super_fault(s, &rf);
	if (v == RE_FAULT)
		return re_super_fault(s, &f);
	wd_window(s);
	if (warn)
		warn_watchdog(s);
	v = s->pub.cfg.stream ? stream_checks(s, &f) : check_record(s, &f);
	if (v == RE_FAULT)
		return re_super_fault(s, &f);
	drain_messages(s);
	return warn ? RE_WARN : RE_OK;
}

/* flight recorder: the hooks, and the one call per cycle */
void re_super_recorder(
    struct re_super *s, void (*cycle)(void *ud, const struct re_super_view *v),
    const char *(*fault)(void *ud, const struct re_super_view *v), void *ud)
{
	s->rec_cycle = cycle;
	s->rec_fault = fault;
	s->rec_ud = ud;
}

int re_super_cycle(struct re_super *s)
{
	int v;

	s->pub.cycles++;
	if (s->pub.latched) {
		v = latched_cycle(s);
	} else {
		v = cycle_checks(s);
		if (s->pub.latched)
			s->last_end_ns = 0;
	}
	if (s->rec_cycle) /* flight recorder: a copy, no I/O */
		s->rec_cycle(s->rec_ud, &s->pub);
	return v;
}

/* ---- status ------------------------------------------------------------- */

static void axis_status(const struct re_super *s, int i,
			struct re_axis_status *out)
{
	const struct gl_rec_axis *a = &s->pub.rec.axis[i];
	const struct re_caltable *t = s->table[i];

	out->enc_counts = a->motor_pos;
	out->pot_v = pot_of(s, i);
	out->vel_cps = a->velocity / 64.0;
	out->moving = !!(a->status & GL_AXST_MOVING);
	out->fwd_limit = !(a->switches & GL_AXSW_FLS);
	out->rev_limit = !(a->switches & GL_AXSW_RLS);
	out->motor_off = !!(a->status & GL_AXST_MOTOR_OFF);
	out->stop_code = a->stop_code;
	out->pos_pct = -1;
	if (t && t->soft_fwd > t->soft_rev) {
		double p = (a->motor_pos - t->soft_rev) /
			   (t->soft_fwd - t->soft_rev) * 100.0;

		out->pos_pct = p < 0 ? 0 : p > 100 ? 100 : p;
		out->soft_rev_counts = t->soft_rev;
		out->soft_fwd_counts = t->soft_fwd;
		out->have_soft = 1;
	}
	out->have_expect = s->pub.have_encres[i];
	out->pot_expected_v = s->pub.encres[i].exp.pot_v;
	out->margin_v = s->pub.encres[i].margin_v;
}

/* The program's latched fault came from our stop: after a fault of our
 * own finding (not one the program latched first), the record's stop
 * code of the axis it names stands for its detail. Fault 12 (our pcflt)
 * says so in its own name already. */
static int ctrl_ours(const struct re_super *s)
{
	const struct re_za *za = &s->pub.za;
	double det = 0;

	if (!s->pub.latched || re_fault_is_ctrl(s->pub.fault.id) ||
	    !s->pub.have_za || !za->fcode || za->fcode == RE_DMC_F_SUPERVISOR)
		return 0;
	if (za->faxis >= 1 && za->faxis <= s->pub.cfg.n_axes &&
	    s->pub.have_record)
		det = s->pub.rec.axis[za->faxis - 1].stop_code;
	return re_react_own_doing(s, za, det);
}

void re_super_status(const struct re_super *s, struct re_status *st)
{
	memset(st, 0, sizeof(*st));
	st->n_axes = s->pub.cfg.n_axes;
	for (int i = 0; i < s->pub.cfg.n_axes; i++) {
		st->axis_names[i] = s->pub.cfg.axis_names[i];
		if (s->pub.have_record)
			axis_status(s, i, &st->axis[i]);
	}
	st->have_record = s->pub.have_record;
	st->relay = s->pub.io.ops->relay_state(s->pub.io.ud);
	st->wd_last_ms = ns_to_ms(s->pub.age_last_ns);
	st->wd_worst_ms = ns_to_ms(s->pub.age_worst_ns);
	st->period_ms = ns_to_ms(s->pub.period_ns);
	st->late_last_ms = ns_to_ms(s->pub.late_last_ns);
	st->late_worst_ms = ns_to_ms(s->late_worst_ns);
	st->cycles = s->pub.cycles;
	st->overruns = s->pub.overruns;
	st->wd_warnings = s->wd_warnings;
	st->armed = s->pub.armed;
	st->expect = s->pub.expect;
	st->log_failing = s->pub.log_failing;
	st->foreign = s->pub.foreign;
	st->link_ok = s->pub.link_ok;
	st->stream = s->pub.cfg.stream && s->pub.io.ops->stream_counts &&
		     s->pub.io.ops->stream_counts(s->pub.io.ud,
						  &st->stream_records,
						  &st->stream_lost) == 0;
	st->za = s->pub.za;
	st->have_za = s->pub.have_za;
	st->mode_name = s->pub.cfg.mode_name ? s->pub.cfg.mode_name : "";
	st->latched = s->pub.latched;
	st->ctrl_ours = ctrl_ours(s);
	st->fault_line = re_super_fault_line(s);
	st->uptime_s = (double)(now_ns(s) - s->t0_ns) / 1e9;
}

double re_super_late_ms(const struct re_super *s, double pct)
{
	uint64_t n = 0, want, seen = 0;
	int k;

	for (k = 0; k < RE_LATE_BINS; k++)
		n += s->late_hist[k];
	if (n == 0)
		return 0;
	if (pct >= 100)
		return ns_to_ms(s->late_worst_ns);
	want = (uint64_t)ceil((double)n * pct / 100.0);
	for (k = 0; k < RE_LATE_BINS - 1; k++) {
		seen += s->late_hist[k];
		if (seen >=
		    want) /* the bin's upper edge, never past the worst */
			return fmin((k + 1) * RE_LATE_BIN_US / 1000.0,
				    ns_to_ms(s->late_worst_ns));
	}
	return ns_to_ms(s->late_worst_ns);
}
