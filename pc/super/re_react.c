/*
 * re_react.c - the supervisor's fault reaction and orderly shutdown (the
 * half of re_super.h that acts): relay off without waiting, the stop at
 * once (over a new connection when the old one is gone), the relay's off
 * confirmed within its deadline, the motors read back, the latch, the log
 * entry (kept and retried when the disk refuses it) and the FAULT line that
 * names the first cause and what was confirmed.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"
#include "re_pot.h"
#include "re_seal.h"
#include "re_super_int.h"

/* The program told to latch, and the stop (re_io.h; the DMC's own #FAULT
 * uses the same two commands), in one line: pcflt first, so that the
 * program's next pass latches 12 rather than finding our motor-off. */
#define FAULT_CMD "pcflt=1;" RE_STOP_ALL

static int64_t now_ns(const struct re_super *s)
{
	return s->pub.io.ops->now_ns(s->pub.io.ud);
}

static double ns_to_ms(int64_t ns)
{
	return (double)ns / 1e6;
}

/* ---- the log, never silently lost --------------------------------------- */

/* Write one entry; when that fails, keep it (the newest failed entry wins
 * over an older INFO one, never over a FAULT) for re_super_retry(). */
static void log_keep(struct re_super *s, enum re_log_level lvl,
		     const char *text)
{
	if (s->pub.io.ops->log(s->pub.io.ud, lvl, text) == GL_OK)
		return;
	if (s->pub.log_failing && s->pending_lvl == RE_LOG_FAULT &&
	    lvl != RE_LOG_FAULT)
		return;
	s->pub.log_failing = 1;
	s->pending_lvl = lvl;
	snprintf(s->pending, sizeof(s->pending), "%s", text);
}

/* ---- later faults and warnings, for the console ------------------------ */

void re_super_note(struct re_super *s, enum re_log_level lvl,
		   enum re_event_kind kind, const char *text)
{
	struct re_event *e = &s->events[s->event_seq % RE_SUPER_EVENTS];

	e->seq = ++s->event_seq;
	e->t_s = (double)(now_ns(s) - s->t0_ns) / 1e9;
	e->level = lvl;
	e->kind = kind;
	snprintf(e->text, sizeof(e->text), "%s", text);
}

/* ---- watchdog warnings condensed (RE_SUPER_WD_WINDOW_MS) --------------- */

/* What the summary counts, as the warning it stands for names it. */
static const char *wd_what(const struct re_super *s)
{
	if (s->pub.cfg.stream)
		return s->wd_held == 1 ? "late record or heartbeat reply"
				       : "late records or heartbeat replies";
	return s->wd_held == 1 ? "late reply" : "late replies";
}

void re_super_wd_flush(struct re_super *s)
{
	if (s->wd_held) {
		snprintf(s->text, sizeof(s->text),
			 "watchdog: %llu more %s in the last %.1f s (worst "
			 "%.1f ms, non-critical limit %.1f ms, critical %.1f "
			 "ms)",
			 (unsigned long long)s->wd_held, wd_what(s),
			 (double)(now_ns(s) - s->wd_open_ns) / 1e9,
			 ns_to_ms(s->wd_held_worst_ns), ns_to_ms(s->noncrit_ns),
			 ns_to_ms(s->pub.crit_ns));
		re_io_logf(&s->pub.io, RE_LOG_WARN, "%s", s->text);
		re_super_note(s, RE_LOG_WARN, RE_EV_WATCHDOG, s->text);
	}
	s->wd_open = 0;
	s->wd_held = 0;
	s->wd_held_worst_ns = 0;
}

int re_super_event(const struct re_super *s, uint64_t after,
		   struct re_event *out)
{
	uint64_t oldest = s->event_seq > RE_SUPER_EVENTS
			      ? s->event_seq - RE_SUPER_EVENTS + 1
			      : 1;
	uint64_t next = after + 1 > oldest ? after + 1 : oldest;

	if (next > s->event_seq)
		return 0;
	*out = s->events[(next - 1) % RE_SUPER_EVENTS];
	return 1;
}

int re_super_retry(struct re_super *s)
{
	int rc;

	if (!s->pub.log_failing)
		return GL_OK;
	rc = s->pub.io.ops->log(s->pub.io.ud, s->pending_lvl, s->pending);
	if (rc == GL_OK)
		s->pub.log_failing = 0;
	return rc;
}

/* ---- the stop ------------------------------------------------------------ */

/* The command on the link; when the link is out of step, closed or silent,
 * the same command over a new connection within cfg.fresh_stop_ms. */
static int send_stop(struct re_super *s, const char *cmd)
{
	int64_t t0 = now_ns(s);
	int rc =
	    s->pub.io.ops->command(s->pub.io.ud, cmd, s->resp, sizeof(s->resp),
				   s->pub.cfg.fault_cmd_timeout_ms);

	s->confirm.stop_fresh = 0;
	/* a command sent and not answered in time may still have arrived
	 * (a slow reply, a stalled link): "not delivered" would be a guess;
	 * so may one on a new connection that timed out (its connect or its
	 * reply: both look the same from here) */
	s->confirm.stop_maybe = rc == GL_ERR_TIMEOUT || rc == GL_ERR_PROTO;
	if ((rc == GL_ERR_BROKEN || rc == GL_ERR_CLOSED ||
	     rc == GL_ERR_TIMEOUT || rc == GL_ERR_SYS || rc == GL_ERR_PROTO) &&
	    s->pub.io.ops->stop_fresh && s->pub.cfg.fresh_stop_ms > 0) {
		rc = s->pub.io.ops->stop_fresh(s->pub.io.ud, cmd, s->resp,
					       sizeof(s->resp),
					       s->pub.cfg.fresh_stop_ms);
		s->confirm.stop_fresh = 1;
		s->confirm.stop_maybe |= rc == GL_ERR_TIMEOUT;
	}
	s->confirm.stop_ms = ns_to_ms(now_ns(s) - t0);
	return rc;
}

/* Re-read the controller's fault detail (MG fdet) for a CTRL fault. */
static void ctrl_fault_detail(struct re_super *s, struct re_fault *f)
{
	double fdet;

	if (s->pub.have_za && s->pub.za.fcode != 0 &&
	    re_io_read(&s->pub.io, "fdet", &fdet,
		       s->pub.cfg.fault_cmd_timeout_ms) == GL_OK) {
		re_ctrl_fault(&s->pub.za, (long long)fdet, f);
		re_seal_read_fault(s->pub.cfg.seal, &s->pub.io,
				   s->pub.cfg.fault_cmd_timeout_ms, f);
	}
}

/* Faults that may be the program's own fault seen half-way (motors off by
 * #JINV before #MAIN latched INPUT, thread 1 halted by #FAULT ...). */
static int may_settle(const struct re_super *s, enum re_fault_id id)
{
	return s->pub.cfg.settle_ms > 0 &&
	       (id == RE_F_MOTOR_OFF || id == RE_F_THREAD || id == RE_F_STATE ||
		id == RE_F_CTRL_STATE || id == RE_F_UNCMD);
}

/* The program's latched fault (code 0: none), read over the link. */
static int program_fault(struct re_super *s, struct re_za *za, double *det)
{
	double code = 0, axis = 0;
	int rc = re_io_read(&s->pub.io, "fcode", &code,
			    s->pub.cfg.fault_cmd_timeout_ms);

	memset(za, 0, sizeof(*za));
	*det = RE_VAL_UNKNOWN;
	if (rc != GL_OK)
		return rc;
	if (code > 0 && code < 100) {
		re_io_read(&s->pub.io, "faxis", &axis,
			   s->pub.cfg.fault_cmd_timeout_ms);
		re_io_read(&s->pub.io, "fdet", det,
			   s->pub.cfg.fault_cmd_timeout_ms);
		za->state = RE_DMC_FAULT;
		za->fcode = (int)code;
		za->faxis = axis >= 0 && axis <= 3 ? (int)axis : 0;
	}
	return GL_OK;
}

/* Poll the program's fault code for up to settle_ms; when it latched
 * one, that is the fault to report (with its axis and detail). */
static void program_verdict(struct re_super *s, struct re_fault *f)
{
	int64_t t0 = now_ns(s);
	int64_t end = t0 + (int64_t)s->pub.cfg.settle_ms * BASE_NS_PER_MS;
	struct re_za za;
	double det;
	int rc;

	do {
		rc = program_fault(s, &za, &det);
		if (rc != GL_OK) {
			snprintf(s->verdict, sizeof(s->verdict),
				 "program fault code unreadable: %s",
				 gl_strerror(rc));
			return;
		}
		if (za.fcode) {
			snprintf(s->verdict, sizeof(s->verdict),
				 "program fault %d after %.1f ms", za.fcode,
				 ns_to_ms(now_ns(s) - t0));
			re_ctrl_fault(&za, (long long)det, f);
			re_seal_read_fault(s->pub.cfg.seal, &s->pub.io,
					   s->pub.cfg.fault_cmd_timeout_ms, f);
			return;
		}
		s->pub.io.ops->sleep_until(s->pub.io.ud,
					   now_ns(s) + 2 * BASE_NS_PER_MS);
	} while (now_ns(s) < end);
	snprintf(s->verdict, sizeof(s->verdict),
		 "no program fault within %d ms", s->pub.cfg.settle_ms);
}

/* The program's latched fault as the newest record of the stream shows
 * it: 1 and @za when one is latched, else 0 (no stream, no new record). */
static int stream_fault(struct re_super *s, struct re_za *za)
{
	struct gl_record rec;

	if (!s->pub.cfg.stream || !s->pub.io.ops->stream ||
	    s->pub.io.ops->stream(s->pub.io.ud, &rec, now_ns(s)) != 1 ||
	    rec.n_axes < 3 ||
	    re_za_decode(rec.axis[0].za, rec.axis[1].za, rec.axis[2].za,
			 za) != GL_OK)
		return 0;
	return za->fcode != 0;
}

/* The stop was not delivered, so the command link cannot tell whether
 * the program was latching a fault of its own (its watchdog, when that
 * link stalled): over the stream, a route beside it, poll the records
 * for up to settle_ms; a latched fault is the one to report (its detail
 * unknown: MG fdet would need the command link). */
static void stream_verdict(struct re_super *s, struct re_fault *f)
{
	int64_t t0 = now_ns(s);
	int64_t end = t0 + (int64_t)s->pub.cfg.settle_ms * BASE_NS_PER_MS;
	struct re_za za;

	do {
		if (stream_fault(s, &za)) {
			snprintf(s->verdict, sizeof(s->verdict),
				 "program fault %d in the record stream "
				 "after %.1f ms",
				 za.fcode, ns_to_ms(now_ns(s) - t0));
			re_ctrl_fault(&za, RE_VAL_UNKNOWN, f);
			return;
		}
		s->pub.io.ops->sleep_until(s->pub.io.ud,
					   now_ns(s) + 2 * BASE_NS_PER_MS);
	} while (now_ns(s) < end);
	snprintf(s->verdict, sizeof(s->verdict),
		 "no program fault in the record stream within %d ms",
		 s->pub.cfg.settle_ms);
}

/* Stop and switch off through the controller and tell the program
 * (pcflt) - after its own verdict when it may be latching one (over the
 * stream when the stop could not be delivered). */
static int stop_controller(struct re_super *s, struct re_fault *f)
{
	int rc;

	if (!may_settle(s, f->id)) {
		rc = send_stop(s, FAULT_CMD);
		if (rc >= 0 && re_fault_is_ctrl(f->id))
			ctrl_fault_detail(s, f);
		return rc;
	}
	rc = send_stop(s, RE_STOP_ALL);
	if (rc >= 0) {
		program_verdict(s, f);
		s->pub.io.ops->command(s->pub.io.ud, "pcflt=1", s->resp,
				       sizeof(s->resp),
				       s->pub.cfg.fault_cmd_timeout_ms);
	} else if (s->pub.cfg.stream) {
		stream_verdict(s, f);
	}
	return rc;
}

/* Every motor read back off ("MG _MOA,_MOB,_MOC" all 1). */
static int motors_off(struct re_super *s)
{
	static const char *const mo[RE_SUPER_AXES] = {"_MOA", "_MOB", "_MOC"};
	double v;
	int rc;

	for (int i = 0; i < s->pub.cfg.n_axes; i++) {
		rc = re_io_read(&s->pub.io, mo[i], &v,
				s->pub.cfg.fault_cmd_timeout_ms);
		if (rc != GL_OK)
			return rc;
		if (v != 1)
			return GL_ERR_MISMATCH;
	}
	return GL_OK;
}

/* The controller answered the stop (':' or '?'): the link works. */
static int stop_answered(int stop_rc)
{
	return stop_rc >= 0 || stop_rc == GL_ERR_CTRL;
}

/* ---- root cause ---------------------------------------------------------- */

/* Motor power lost on every axis while the relay was meant closed: when
 * the relay board does not confirm its state - its off just now was not
 * confirmed, or its check fails - the relay is the cause, not the E-stop
 * button or the supply. */
static void relay_or_power(struct re_super *s, struct re_fault *f)
{
	char why[sizeof(f->s)];

	if (f->id != RE_F_CTRL_POWER)
		return;
	if (s->confirm.relay_rc != GL_OK)
		snprintf(why, sizeof(why), "its off was not confirmed: %s",
			 gl_strerror(s->confirm.relay_rc));
	else if (s->pub.io.ops->relay_check(s->pub.io.ud, why, sizeof(why)) ==
		 GL_OK)
		return;
	re_fault_set(f, RE_F_RELAY_POWER, -1);
	snprintf(f->s, sizeof(f->s), "%s", why);
}

/* The handles the program saw another program open while the motors were
 * on (fhnew, version 2.00): a connection that came and went between two
 * of our records is named too. Unreadable (link lost, an older program):
 * what this supervisor saw itself stands. */
static void foreign_from_program(struct re_super *s)
{
	double m = 0;

	if (s->confirm.stop_rc < 0)
		return;
	if (re_io_read(&s->pub.io, "fhnew", &m,
		       s->pub.cfg.fault_cmd_timeout_ms) == GL_OK &&
	    m >= 1 && m <= 255)
		s->pub.foreign |= (unsigned)m;
}

/* A program fault that our own stop caused: 12 (pcflt); a motor found
 * off (fault 10) whose stop code says nothing stopped it but a command:
 * 0 no motion ended on it yet (an axis that has not moved since the
 * program started: our AB 1 on an axis at rest leaves the code, and MO
 * never sets one), 1 at rest, 4 ST, 7 AB (a moving axis: our AB 1 comes
 * before our MO); every amplifier without power (8 on no single
 * axis) once our relay's off is confirmed. Our "pcflt=1;AB 1;MO ABC" can
 * land in the middle of the program's pass, after its pcflt check and
 * before its motor check: then the program latches 10 first; and the
 * amplifier error runs at once when our relay cuts the power, while pcflt
 * waits for the next pass. A motor the servo or an amplifier switched off
 * has its own code (8 ER, 12 OA ...) or fault. */
int re_react_own_doing(const struct re_super *s, const struct re_za *za,
		       double det)
{
	return za->fcode == RE_DMC_F_SUPERVISOR ||
	       (za->fcode == RE_DMC_F_MOTOROFF &&
		(det == 0 || det == 1 || det == 4 || det == 7)) ||
	       (za->fcode == RE_DMC_F_AMPERR && za->faxis == 0 &&
		s->confirm.relay_rc == GL_OK);
}

/* What the controller did on its own (its latched fault) when that is not
 * the cause reported nor the result of our stop: a consequence, said
 * after it. */
static void consequences(struct re_super *s, const struct re_fault *f)
{
	struct re_fault c;
	struct re_za za;
	double det;

	s->then[0] = '\0';
	/* RELAY_POWER is the program's power loss, named with its cause */
	if (s->confirm.stop_rc < 0 || re_fault_is_ctrl(f->id) ||
	    f->id == RE_F_RELAY_POWER || program_fault(s, &za, &det) != GL_OK ||
	    !za.fcode || re_react_own_doing(s, &za, det))
		return;
	re_ctrl_fault(&za, (long long)det, &c);
	if (re_fault_what_units(&c, s->pub.cfg.axis_names, &s->pub.cfg.units,
				s->then, sizeof(s->then)) == GL_ERR_ARG)
		s->then[0] = '\0';
}

/* ---- the FAULT line -------------------------------------------------------
 */

/* What is known of the stop: delivered when the controller answered it
 * (':' or '?'); sent on the link and not answered in time, not known; else
 * not delivered, with why. */
static void stop_text(const struct re_confirm *c, char *buf, size_t cap)
{
	const char *mo = c->motors_rc == GL_OK ? " motors off confirmed;"
					       : " motors off not confirmed;";

	if (c->stop_rc == GL_ERR_CTRL)
		snprintf(buf, cap,
			 " the controller answered the stop command with an "
			 "error (?);%s",
			 mo);
	else if (c->stop_rc >= 0)
		snprintf(buf, cap, "%s", mo);
	else if (c->stop_maybe)
		snprintf(buf, cap,
			 " no answer to the stop command in time (%s): "
			 "whether the controller got it is not known; motors "
			 "off not confirmed;",
			 gl_strerror(c->stop_rc));
	else
		snprintf(buf, cap,
			 " stop command not delivered (%s); motors off not "
			 "confirmed;",
			 gl_strerror(c->stop_rc));
}

/* " Safe state confirmed: ..." or " NOT CONFIRMED: ... PRESS THE HARDWARE
 * E-STOP NOW." - inserted before the recovery text. */
static size_t confirm_text(const struct re_super *s, char *buf, size_t cap)
{
	const struct re_confirm *c = &s->confirm;
	char stop[192];

	if (c->relay_rc == GL_OK && c->motors_rc == GL_OK)
		return (size_t)snprintf(
		    buf, cap,
		    " Safe state confirmed: motor power off (relay open), "
		    "motors off.");
	stop_text(c, stop, sizeof(stop));
	return (size_t)snprintf(
	    buf, cap, " NOT CONFIRMED:%s%s PRESS THE HARDWARE E-STOP NOW.",
	    c->relay_rc == GL_OK ? " motor power off (relay open) confirmed;"
				 : " relay open not confirmed;",
	    stop);
}

/* " Another program had connected to the controller (handle C)." */
static size_t foreign_text(unsigned mask, char *buf, size_t cap)
{
	char hs[9];
	int n = 0;

	for (int h = 0; h < 8; h++)
		if (mask >> h & 1)
			hs[n++] = (char)('A' + h);
	hs[n] = '\0';
	return (size_t)snprintf(buf, cap,
				" Another program had connected to the "
				"controller (handle %s).",
				hs);
}

/* "FAULT CLASS: what[. Then: consequence][. Another program ...].
 * <confirm>. Recovery: ..." */
static void compose_line(struct re_super *s)
{
	char *line = s->pub.fault_line, *rec;
	size_t cap = sizeof(s->pub.fault_line), n;
	char tail[RE_SUPER_LINE];

	if (re_fault_format_units(&s->pub.fault, s->pub.cfg.axis_names,
				  &s->pub.cfg.units, line, cap) == GL_ERR_ARG)
		snprintf(line, cap,
			 "FAULT PROGRAM: unknown fault %d. Recovery: quit, "
			 "note the log and call service",
			 (int)s->pub.fault.id);
	rec = strstr(line, ". Recovery: ");
	if (!rec)
		return;
	snprintf(tail, sizeof(tail), "%s", rec + 2);
	n = (size_t)(rec - line) + 1;
	if (s->then[0] && n < cap)
		n += (size_t)snprintf(line + n, cap - n, " Then: %s.", s->then);
	if (s->pub.foreign && n < cap)
		n += foreign_text(s->pub.foreign, line + n, cap - n);
	if (n < cap)
		n += confirm_text(s, line + n, cap - n);
	if (n < cap)
		snprintf(line + n, cap - n, " %.*s", (int)(cap - n - 2), tail);
}

/* Append the axes of the last record to the log text. */
static size_t snapshot(const struct re_super *s, char *buf, size_t cap)
{
	size_t n = 0;

	for (int i = 0; s->pub.have_record && i < s->pub.cfg.n_axes && n < cap;
	     i++) {
		const struct gl_rec_axis *a = &s->pub.rec.axis[i];

		n += (size_t)snprintf(buf + n, cap - n,
				      "; %s enc=%d ref=%d err=%d sc=%d mo=%d"
				      " an=%.4fV",
				      s->pub.cfg.axis_names[i],
				      (int)a->motor_pos, (int)a->ref_pos,
				      (int)a->pos_err, a->stop_code,
				      a->status & GL_AXST_MOTOR_OFF ? 1 : 0,
				      re_pot_volts(a->analog_in));
	}
	if (n < cap && s->pub.have_za)
		n += (size_t)snprintf(buf + n, cap - n,
				      "; dmc state=%d fcode=%d faxis=%d "
				      "hbdmc=%d jraw=%d",
				      s->pub.za.state, s->pub.za.fcode,
				      s->pub.za.faxis, (int)s->pub.za.hbdmc,
				      s->pub.za.jraw);
	return n < cap ? n : cap;
}

static const char *rc_text(int rc, const char *ok)
{
	return rc >= 0 ? ok : gl_strerror(rc);
}

/* The log's "controller stop: ...": as the FAULT line, with the error. */
static const char *stop_log(const struct re_confirm *c, char *buf, size_t cap)
{
	if (c->stop_rc >= 0)
		return "delivered";
	snprintf(buf, cap, "%s (%s)",
		 c->stop_rc == GL_ERR_CTRL ? "delivered, answered ?"
		 : c->stop_maybe	   ? "no answer in time, delivery "
					     "not known"
					   : "not delivered",
		 gl_strerror(c->stop_rc));
	return buf;
}

static void log_fault(struct re_super *s)
{
	const struct re_confirm *c = &s->confirm;
	char *t = s->text, stop[96];
	size_t cap = sizeof(s->text), n;

	n = (size_t)snprintf(
	    t, cap,
	    "%s | relay off: %s | controller stop: %s%s (%.1f ms) | motors "
	    "off: %s%s%s | cycle %llu, reply age %.1f ms",
	    s->pub.fault_line,
	    c->relay_rc == GL_OK ? "confirmed" : "NOT confirmed",
	    stop_log(c, stop, sizeof(stop)),
	    c->stop_fresh ? " over a new connection" : "", c->stop_ms,
	    c->motors_rc == GL_OK ? "confirmed" : "NOT confirmed",
	    s->verdict[0] ? " | " : "", s->verdict,
	    (unsigned long long)s->pub.cycles, ns_to_ms(s->pub.age_last_ns));
	if (n < cap)
		n += snapshot(s, t + n, cap - n);
	if (n < cap && s->rec_fault) { /* flight recorder */
		const char *note = s->rec_fault(s->rec_ud, &s->pub);

		if (note)
			snprintf(t + n, cap - n, " | %s", note);
	}
	log_keep(s, RE_LOG_FAULT, t);
}

/* ---- the reaction -------------------------------------------------------- */

static int relay_start(struct re_super *s)
{
	if (s->pub.io.ops->relay_off_start)
		return s->pub.io.ops->relay_off_start(s->pub.io.ud);
	return s->pub.io.ops->relay_off(s->pub.io.ud);
}

static int relay_finish(struct re_super *s, int start_rc)
{
	if (!s->pub.io.ops->relay_off_start || !s->pub.io.ops->relay_off_finish)
		return start_rc;
	return s->pub.io.ops->relay_off_finish(s->pub.io.ud,
					       s->pub.cfg.relay_off_ms);
}

int re_super_fault(struct re_super *s, const struct re_fault *f)
{
	struct re_fault fault = *f;
	int relay_rc;

	if (s->pub.latched) {
		re_fault_format_units(f, s->pub.cfg.axis_names,
				      &s->pub.cfg.units, s->msg,
				      sizeof(s->msg));
		re_io_logf(&s->pub.io, RE_LOG_WARN, "while latched: %s",
			   s->msg);
		re_super_note(s, RE_LOG_FAULT, RE_EV_LATER, s->msg);
		return RE_OK;
	}
	s->verdict[0] = '\0';
	memset(&s->confirm, 0, sizeof(s->confirm));
	/* 1. motor power: told to open, never waiting; 2. the stop at once */
	relay_rc = relay_start(s);
	s->confirm.stop_rc = stop_controller(s, &fault);
	/* 3. the relay's off confirmed; 4. the motors read back */
	s->confirm.relay_rc = relay_finish(s, relay_rc);
	/* a stop answered '?' reached the controller: what it did is read
	 * back like any other */
	s->confirm.motors_rc = stop_answered(s->confirm.stop_rc)
				   ? motors_off(s)
				   : s->confirm.stop_rc;
	relay_or_power(s, &fault);
	consequences(s, &fault);
	foreign_from_program(s);
	s->pub.latched = 1;
	s->pub.armed = 0;
	s->pub.fault = fault;
	compose_line(s);
	/* the late replies counted for a summary before the fault's entry:
	 * after the stop, which they must not delay */
	re_super_wd_flush(s);
	/* 5. the log entry on disk before anyone reports the relay open */
	log_fault(s);
	return RE_FAULT;
}

const char *re_super_fault_line(const struct re_super *s)
{
	return s->pub.latched ? s->pub.fault_line : "";
}

/* ---- shutdown ------------------------------------------------------------ */

int re_super_shutdown(struct re_super *s, char *what, size_t cap)
{
	int off_rc, stop_rc, mo_rc, relay_rc;

	/* the program back to its safe state, so that the motors off is not
	 * a fault to it; then the stop itself, whatever the program did */
	off_rc = s->pub.io.ops->command(s->pub.io.ud, "offreq=1", s->resp,
					sizeof(s->resp),
					s->pub.cfg.fault_cmd_timeout_ms);
	if (off_rc >= 0)
		s->pub.io.ops->sleep_until(s->pub.io.ud,
					   now_ns(s) + 25 * BASE_NS_PER_MS);
	stop_rc = send_stop(s, RE_STOP_ALL);
	mo_rc = stop_rc >= 0 ? motors_off(s) : stop_rc;
	relay_rc = relay_finish(s, relay_start(s));
	s->pub.armed = 0;
	s->pub.expect = 0;
	re_super_wd_flush(s); /* after the stop, which it must not delay */
	if (what)
		snprintf(
		    what, cap, "motors off: %s; motor power off (relay): %s",
		    mo_rc == GL_OK ? "confirmed"
				   : rc_text(mo_rc, "NOT confirmed"),
		    relay_rc == GL_OK ? "confirmed"
				      : rc_text(relay_rc, "NOT confirmed"));
	if (mo_rc != GL_OK)
		return mo_rc < 0 ? mo_rc : GL_ERR_MISMATCH;
	return relay_rc;
}
