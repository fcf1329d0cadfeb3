/*
 * re_super.c - the supervisor's periodic cycle and fault reaction.
 * See re_super.h; the checks themselves are in re_check.c.
 */
#include "re_super.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"

#define NS_PER_MS 1000000LL
/* The stop (re_io.h; the DMC's own #FAULT uses the same two commands), and
 * the program told to latch in the same line. */
#define FAULT_CMD RE_STOP_ALL ";pcflt=1"

static int64_t now_ns(const struct re_super *s)
{
	return s->io.ops->now_ns(s->io.ud);
}

static double ns_to_ms(int64_t ns)
{
	return (double)ns / 1e6;
}

double re_pot_volts(int32_t analog_in)
{
	return (double)analog_in / RE_AN_COUNTS_PER_V;
}

/* The potentiometer of axis i: analog input n is in axis block n - 1. */
static double pot_of(const struct re_super *s, int i)
{
	int in = s->cfg.pot_input[i];
	int k = in >= 1 && in <= s->rec.n_axes ? in - 1 : i;

	return re_pot_volts(s->rec.axis[k].analog_in);
}

int re_super_init(struct re_super *s, const struct re_io *io,
		  const struct re_super_cfg *cfg,
		  const struct re_caltable *const *tables, int armed)
{
	memset(s, 0, sizeof(*s));
	if (!io || !io->ops || !cfg || cfg->n_axes < 1 ||
	    cfg->n_axes > RE_SUPER_AXES || cfg->period_ns <= 0)
		return GL_ERR_ARG;
	s->io = *io;
	s->cfg = *cfg;
	if (re_wdog_limits(&cfg->wdog, &s->noncrit_ns, &s->crit_ns) != GL_OK)
		return GL_ERR_ARG;
	for (int i = 0; tables && i < cfg->n_axes; i++)
		s->table[i] = tables[i];
	s->armed = armed;
	s->t0_ns = now_ns(s);
	s->deadline_ns = s->t0_ns + cfg->period_ns; /* no previous cycle */
	s->last_good_ns = s->t0_ns;
	re_alive_reset(&s->alive);
	return GL_OK;
}

void re_super_start(struct re_super *s, const struct re_caltable *const *tables,
		    long hbpc)
{
	if (s->latched)
		return;
	for (int i = 0; i < s->cfg.n_axes; i++) {
		s->table[i] = tables ? tables[i] : NULL;
		s->encpot[i].violations = 0;
	}
	s->armed = 1;
	s->hbpc = hbpc;
	s->last_good_ns = now_ns(s);
	s->deadline_ns = s->last_good_ns + s->cfg.period_ns;
	re_alive_reset(&s->alive);
}

int64_t re_super_wait(struct re_super *s)
{
	int64_t now = now_ns(s);
	int64_t late, bin;

	if (now > s->deadline_ns) {
		/* the last cycle ran into this one: no burst of late cycles */
		s->overruns++;
		s->deadline_ns = now;
	} else {
		s->io.ops->sleep_until(s->io.ud, s->deadline_ns);
		now = now_ns(s);
	}
	late = now - s->deadline_ns;
	if (late < 0)
		late = 0;
	s->late_last_ns = late;
	if (late > s->late_worst_ns)
		s->late_worst_ns = late;
	bin = late / (RE_LATE_BIN_US * 1000);
	s->late_hist[bin < RE_LATE_BINS - 1 ? bin : RE_LATE_BINS - 1]++;
	s->deadline_ns += s->cfg.period_ns;
	return late;
}

/* ---- fault reaction ------------------------------------------------------ */

/* Re-read the controller's fault detail (MG fdet) for a CTRL fault. */
static void ctrl_fault_detail(struct re_super *s, struct re_fault *f)
{
	double fdet;

	if (s->have_za && s->za.fcode != 0 &&
	    re_io_read(&s->io, "fdet", &fdet, s->cfg.fault_cmd_timeout_ms) ==
		GL_OK)
		re_ctrl_fault(&s->za, (long long)fdet, f);
}

/* Faults that may be the program's own fault seen half-way (motors off by
 * #JINV before #MAIN latched INPUT, thread 1 halted by #FAULT ...). */
static int may_settle(const struct re_super *s, enum re_fault_id id)
{
	return s->cfg.settle_ms > 0 &&
	       (id == RE_F_MOTOR_OFF || id == RE_F_THREAD || id == RE_F_STATE);
}

/* Poll the program's fault code for up to settle_ms; when it latched
 * one, that is the fault to report (with its axis and detail). */
static void program_verdict(struct re_super *s, struct re_fault *f)
{
	int64_t t0 = now_ns(s);
	int64_t end = t0 + (int64_t)s->cfg.settle_ms * NS_PER_MS;
	double code = 0, axis = 0, det = 0;
	struct re_za za;
	int rc;

	do {
		rc = re_io_read(&s->io, "fcode", &code,
				s->cfg.fault_cmd_timeout_ms);
		if (rc != GL_OK) {
			snprintf(s->verdict, sizeof(s->verdict),
				 "program fault code unreadable: %s",
				 gl_strerror(rc));
			return;
		}
		if (code > 0 && code < 100) {
			snprintf(s->verdict, sizeof(s->verdict),
				 "program fault %d after %.1f ms", (int)code,
				 ns_to_ms(now_ns(s) - t0));
			re_io_read(&s->io, "faxis", &axis,
				   s->cfg.fault_cmd_timeout_ms);
			re_io_read(&s->io, "fdet", &det,
				   s->cfg.fault_cmd_timeout_ms);
			memset(&za, 0, sizeof(za));
			za.state = RE_DMC_FAULT;
			za.fcode = (int)code;
			za.faxis = axis >= 0 && axis <= 3 ? (int)axis : 0;
			re_ctrl_fault(&za, (long long)det, f);
			return;
		}
		s->io.ops->sleep_until(s->io.ud, now_ns(s) + 2 * NS_PER_MS);
	} while (now_ns(s) < end);
	snprintf(s->verdict, sizeof(s->verdict),
		 "no program fault within %d ms", s->cfg.settle_ms);
}

/* Stop and switch off through the controller and tell the program
 * (pcflt) - after its own verdict when it may be latching one. */
static int stop_controller(struct re_super *s, struct re_fault *f)
{
	int rc;

	if (!may_settle(s, f->id)) {
		rc = s->io.ops->command(s->io.ud, FAULT_CMD, s->resp,
					sizeof(s->resp),
					s->cfg.fault_cmd_timeout_ms);
		if (re_fault_is_ctrl(f->id))
			ctrl_fault_detail(s, f);
		return rc;
	}
	rc = s->io.ops->command(s->io.ud, RE_STOP_ALL, s->resp, sizeof(s->resp),
				s->cfg.fault_cmd_timeout_ms);
	program_verdict(s, f);
	s->io.ops->command(s->io.ud, "pcflt=1", s->resp, sizeof(s->resp),
			   s->cfg.fault_cmd_timeout_ms);
	return rc;
}

/* Append the axes of the last record to the log text. */
static size_t snapshot(const struct re_super *s, char *buf, size_t cap)
{
	size_t n = 0;

	for (int i = 0; s->have_record && i < s->cfg.n_axes && n < cap; i++) {
		const struct gl_rec_axis *a = &s->rec.axis[i];

		n += (size_t)snprintf(buf + n, cap - n,
				      "; %s enc=%d ref=%d err=%d sc=%d mo=%d"
				      " an=%.4fV",
				      s->cfg.axis_names[i], (int)a->motor_pos,
				      (int)a->ref_pos, (int)a->pos_err,
				      a->stop_code,
				      a->status & GL_AXST_MOTOR_OFF ? 1 : 0,
				      re_pot_volts(a->analog_in));
	}
	if (n < cap && s->have_za)
		n += (size_t)snprintf(buf + n, cap - n,
				      "; dmc state=%d fcode=%d faxis=%d "
				      "hbdmc=%d jraw=%d",
				      s->za.state, s->za.fcode, s->za.faxis,
				      (int)s->za.hbdmc, s->za.jraw);
	return n < cap ? n : cap;
}

static void log_fault(struct re_super *s, int relay_rc, int cmd_rc)
{
	char *t = s->text;
	size_t cap = sizeof(s->text), n;

	n = (size_t)snprintf(
	    t, cap,
	    "%s | relay off: %s | controller stop: %s%s%s | "
	    "cycle %llu, reply age %.1f ms",
	    s->fault_line, relay_rc == GL_OK ? "confirmed" : "NOT confirmed",
	    cmd_rc >= 0 ? "ok" : gl_strerror(cmd_rc), s->verdict[0] ? "; " : "",
	    s->verdict, (unsigned long long)s->cycles,
	    ns_to_ms(s->age_last_ns));
	if (n < cap)
		snapshot(s, t + n, cap - n);
	s->io.ops->log(s->io.ud, RE_LOG_FAULT, t);
}

int re_super_fault(struct re_super *s, const struct re_fault *f)
{
	struct re_fault fault = *f;
	int relay_rc, cmd_rc;

	if (s->latched) {
		re_fault_format(f, s->cfg.axis_names, s->msg, sizeof(s->msg));
		re_io_logf(&s->io, RE_LOG_WARN, "while latched: %s", s->msg);
		return RE_OK;
	}
	s->verdict[0] = '\0';
	/* 1. cut motor power; 2. stop and switch off through the controller */
	relay_rc = s->io.ops->relay_off(s->io.ud);
	cmd_rc = stop_controller(s, &fault);
	s->latched = 1;
	s->armed = 0;
	s->fault = fault;
	if (re_fault_format(&fault, s->cfg.axis_names, s->fault_line,
			    sizeof(s->fault_line)) == GL_ERR_ARG)
		snprintf(s->fault_line, sizeof(s->fault_line),
			 "FAULT PROGRAM: unknown fault %d. Recovery: quit, "
			 "note the log and call service",
			 (int)fault.id);
	/* 3. the log entry on disk before anyone reports the relay open */
	log_fault(s, relay_rc, cmd_rc);
	return RE_FAULT;
}

const char *re_super_fault_line(const struct re_super *s)
{
	return s->latched ? s->fault_line : "";
}

/* ---- the cycle ----------------------------------------------------------- */

static int reply_timeout_ms(const struct re_super *s)
{
	int64_t left = s->last_good_ns + s->crit_ns - now_ns(s);

	if (left < NS_PER_MS)
		return 1;
	return (int)((left + NS_PER_MS - 1) / NS_PER_MS);
}

static int comm_fault(int rc, struct re_fault *f)
{
	re_fault_set(f, RE_F_COMM, -1);
	snprintf(f->s, sizeof(f->s), "cannot read the data record: %s",
		 gl_strerror(rc));
	return RE_FAULT;
}

/* The round trip and the PC-side watchdog verdict on it. */
static int exchange(struct re_super *s, struct re_fault *f)
{
	int64_t now, age = 0;
	int rc, v;

	s->hbpc = (s->hbpc + 1) % RE_HBPC_WRAP;
	snprintf(s->prefix, sizeof(s->prefix), "hbpc=%ld", s->hbpc);
	rc = s->io.ops->record(s->io.ud, s->prefix, &s->rec,
			       reply_timeout_ms(s));
	now = now_ns(s);
	s->link_ok = rc == GL_OK;
	if (rc != GL_OK && rc != GL_ERR_TIMEOUT)
		return comm_fault(rc, f);
	v = re_check_reply_age(&s->cfg.wdog, s->last_good_ns, now, &age, f);
	if (rc == GL_ERR_TIMEOUT && v != RE_FAULT) {
		/* the deadline was the critical limit: rounding aside, late */
		re_fault_set(f, RE_F_WDOG_REPLY, -1);
		f->i[0] = age / NS_PER_MS;
		f->i[1] = s->crit_ns / NS_PER_MS;
		v = RE_FAULT;
	}
	if (rc == GL_OK) {
		s->have_record = 1;
		s->last_good_ns = now;
		s->age_last_ns = age;
		if (age > s->age_worst_ns)
			s->age_worst_ns = age;
	}
	return v < 0 ? RE_OK : v;
}

static void warn_watchdog(struct re_super *s)
{
	s->wd_warnings++;
	re_io_logf(&s->io, RE_LOG_WARN,
		   "watchdog: reply after %.1f ms "
		   "(non-critical limit %.1f ms, critical %.1f ms)",
		   ns_to_ms(s->age_last_ns), ns_to_ms(s->noncrit_ns),
		   ns_to_ms(s->crit_ns));
}

static int check_relay(struct re_super *s, struct re_fault *f)
{
	char why[sizeof(f->s)];

	if (s->io.ops->relay_check(s->io.ud, why, sizeof(why)) == GL_OK)
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
	for (int i = 0; i < s->cfg.n_axes; i++) {
		const struct gl_rec_axis *a = &s->rec.axis[i];
		int v;

		s->have_encres[i] = 0;
		if (!s->table[i])
			continue;
		v = re_check_encpot(s->table[i], &s->cfg.encpot[i], i,
				    a->motor_pos, pot_of(s, i), &s->encpot[i],
				    &s->encres[i], f);
		if (v < 0)
			return check_error(f, RE_F_CONFIG, i,
					   "encoder/potentiometer check", v);
		s->have_encres[i] = 1;
		if (v == RE_FAULT)
			return RE_FAULT;
	}
	return RE_OK;
}

static void drain_messages(struct re_super *s)
{
	for (int i = 0; i < RE_SUPER_MSGS; i++) {
		int n = s->io.ops->message(s->io.ud, s->msg, sizeof(s->msg));

		if (n < 0)
			break;
		re_io_logf(&s->io, RE_LOG_INFO, "controller: %s", s->msg);
	}
}

/* Checks on a fresh record, in priority order. */
static int check_record(struct re_super *s, struct re_fault *f)
{
	int v;

	v = re_check_record(&s->rec, s->cfg.n_axes, s->armed, &s->za, f);
	s->have_za = v == RE_OK || f->id != RE_F_RECORD;
	if (v < 0)
		return check_error(f, RE_F_COMM, -1, "the record check", v);
	if (v != RE_OK)
		return v;
	v = re_check_alive(&s->cfg.alive, &s->alive, now_ns(s), s->za.hbdmc,
			   s->rec.sample, f);
	if (v == RE_FAULT)
		return v;
	return check_encpot(s, f);
}

static int latched_cycle(struct re_super *s)
{
	int rc = s->io.ops->record(s->io.ud, NULL, &s->rec,
				   (int)(s->cfg.period_ns / NS_PER_MS) + 1);
	struct re_fault scratch;

	memset(&scratch, 0, sizeof(scratch));
	s->link_ok = rc == GL_OK;
	if (rc == GL_OK) {
		struct re_encpot_state st[RE_SUPER_AXES];

		s->have_record = 1;
		s->have_za = re_check_record(&s->rec, s->cfg.n_axes, 0, &s->za,
					     &scratch) >= 0 &&
			     scratch.id != RE_F_RECORD;
		memcpy(st, s->encpot, sizeof(st));
		check_encpot(s, &scratch);
		memcpy(s->encpot, st, sizeof(st));
	}
	/* The relay stays checked while latched (it must stay off): a failure
	 * is logged once, as the operator cannot be shown a second FAULT. */
	if (!s->relay_lost_logged && check_relay(s, &scratch) == RE_FAULT) {
		s->relay_lost_logged = 1;
		re_fault_format(&scratch, s->cfg.axis_names, s->text,
				sizeof(s->text));
		re_io_logf(&s->io, RE_LOG_FAULT, "while latched: %s", s->text);
	}
	drain_messages(s);
	return RE_OK;
}

int re_super_cycle(struct re_super *s)
{
	struct re_fault f, rf;
	int v, rv, warn;

	s->cycles++;
	if (s->latched)
		return latched_cycle(s);
	memset(&f, 0, sizeof(f));
	v = exchange(s, &f);
	warn = s->link_ok && s->age_last_ns > s->noncrit_ns;
	rv = check_relay(s, &rf);
	if (rv == RE_FAULT)
		return re_super_fault(s, &rf);
	if (v == RE_FAULT)
		return re_super_fault(s, &f);
	if (warn)
		warn_watchdog(s);
	v = check_record(s, &f);
	if (v == RE_FAULT)
		return re_super_fault(s, &f);
	drain_messages(s);
	return warn ? RE_WARN : RE_OK;
}

/* ---- status and shutdown ------------------------------------------------- */

static void axis_status(const struct re_super *s, int i,
			struct re_axis_status *out)
{
	const struct gl_rec_axis *a = &s->rec.axis[i];
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
	}
	out->have_expect = s->have_encres[i];
	out->pot_expected_v = s->encres[i].exp.pot_v;
	out->margin_v = s->encres[i].margin_v;
}

void re_super_status(const struct re_super *s, struct re_status *st)
{
	memset(st, 0, sizeof(*st));
	st->n_axes = s->cfg.n_axes;
	for (int i = 0; i < s->cfg.n_axes; i++) {
		st->axis_names[i] = s->cfg.axis_names[i];
		if (s->have_record)
			axis_status(s, i, &st->axis[i]);
	}
	st->have_record = s->have_record;
	st->relay = s->io.ops->relay_state(s->io.ud);
	st->wd_last_ms = ns_to_ms(s->age_last_ns);
	st->wd_worst_ms = ns_to_ms(s->age_worst_ns);
	st->period_ms = ns_to_ms(s->cfg.period_ns);
	st->late_last_ms = ns_to_ms(s->late_last_ns);
	st->late_worst_ms = ns_to_ms(s->late_worst_ns);
	st->cycles = s->cycles;
	st->overruns = s->overruns;
	st->wd_warnings = s->wd_warnings;
	st->armed = s->armed;
	st->link_ok = s->link_ok;
	st->za = s->za;
	st->have_za = s->have_za;
	st->mode_name = s->cfg.mode_name ? s->cfg.mode_name : "";
	st->latched = s->latched;
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
		if (seen >= want)
			return (k + 1) * RE_LATE_BIN_US / 1000.0;
	}
	return ns_to_ms(s->late_worst_ns);
}

int re_super_shutdown(struct re_super *s)
{
	int rc =
	    s->io.ops->command(s->io.ud, RE_STOP_ALL, s->resp, sizeof(s->resp),
			       s->cfg.fault_cmd_timeout_ms);
	int relay_rc = s->io.ops->relay_off(s->io.ud);

	s->armed = 0;
	if (rc < 0)
		return rc;
	return relay_rc;
}
