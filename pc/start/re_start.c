/*
 * re_start.c - roboelf's start-up: the power-on order, calibration,
 * arming. See re_start.h and docs/supervisor.md.
 */
#include "re_start.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link.h"
#include "gl_route.h"
#include "re_bind.h"
#include "re_linkmeas.h"

struct re_signals re_sig;

/* ---- start-up ------------------------------------------------------------ */

void re_start_progress(struct app *a, const char *fmt, ...)
{
	char text[512];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(text, sizeof(text), fmt, ap);
	va_end(ap);
	re_console_msg(&a->con, "%s: %s", a->prog, text);
	re_log_msg(&a->log, RE_LOG_INFO, "%s", text);
	a->real.last_run_ns = re_io_now_ns();
}

static int64_t stalled_ms(const struct app *a);

int re_start_fail(struct app *a, const char *what)
{
	int64_t ms = stalled_ms(a);

	if (ms)
		re_console_msg(&a->con,
			       "%s: error: %s did not run for %lld ms "
			       "(limit %lld ms: stopped, e.g. SIGSTOP or a "
			       "debugger); then: %s",
			       a->prog, a->prog, (long long)ms,
			       (long long)re_start_stall_limit_ms(a), what);
	else
		re_console_msg(&a->con, "%s: error: %s", a->prog, what);
	re_log_msg(&a->log, RE_LOG_WARN, "start-up refused: %s%s", what,
		   ms ? " (after a stop of roboelf itself)" : "");
	return EXIT_CONNECT;
}

/* One supervisor per controller and per relay: both locks before the
 * relay is opened (opening switches it off: a second roboelf must not cut
 * the first one's motor power) and before the controller is touched. */
static int take_locks(struct app *a)
{
	char key[RE_LOCK_PATH_MAX];
	const char *port = re_config_relay_port(&a->cfg);

	if (re_lock_controller_key(a->cfg.controller.address, key,
				   sizeof(key)) != GL_OK) {
		snprintf(a->err, sizeof(a->err), "bad controller address '%s'",
			 a->cfg.controller.address);
		return re_start_fail(a, a->err);
	}
	if (re_lock_acquire(&a->lock_ctl, "controller", key, a->err,
			    sizeof(a->err)) != GL_OK)
		return re_start_fail(a, a->err);
	if (re_lock_relay_key(port, key, sizeof(key)) != GL_OK) {
		snprintf(a->err, sizeof(a->err),
			 "cannot open the E-stop relay '%s': %s (is galil-sim "
			 "running, or the relay plugged in?)",
			 port, strerror(errno));
		return re_start_fail(a, a->err);
	}
	if (re_lock_acquire(&a->lock_relay, "relay", key, a->err,
			    sizeof(a->err)) != GL_OK)
		return re_start_fail(a, a->err);
	return 0;
}

/*
 * Clinical: the relay at @port is the board bound to this robot, its USB
 * serial number relay.serial (docs/safety.md, "The relay bound to this
 * robot"). Read without opening the port, before the relay is opened: a
 * board that is not ours never receives a byte, not even "off".
 */
static int check_bound(struct app *a, const char *port)
{
	char serial[RE_BIND_SERIAL_MAX];

	if (re_relay_usb_serial(port, serial, sizeof(serial), a->err,
				sizeof(a->err)) != GL_OK ||
	    re_bind_verify(port, serial, a->cfg.relay.serial, a->err,
			   sizeof(a->err)) != GL_OK)
		return re_start_fail(a, a->err);
	re_start_progress(a,
			  "the E-stop relay '%s' is the board bound to this "
			  "robot (USB serial number '%s', relay.serial)",
			  port, serial);
	return 0;
}

/* The relay opened (which switches it off) and kept off. */
static int start_relay(struct app *a)
{
	struct re_relay_cfg rc;

	re_config_relay_cfg(&a->cfg, &rc);
	if (a->cfg.mode == RE_MODE_CLINICAL && check_bound(a, rc.port))
		return EXIT_CONNECT;
	re_start_progress(
	    a, "opening the E-stop relay '%s' (motor power stays off)",
	    rc.port);
	if (re_relay_open(&a->relay, &rc, a->err, sizeof(a->err)) != GL_OK)
		return re_start_fail(a, a->err);
	a->real.relay = a->relay;
	return 0;
}

/* The one supported network: the controller on a direct link (its own
 * interface or a cable; no gateway). Clinical: refused otherwise. */
static int check_direct(struct app *a, const struct gl_route_info *ri,
			const char *host)
{
	char what[800];

	if (!ri->gateway) {
		re_start_progress(
		    a, "route to the controller: a direct link on %s",
		    ri->ifname[0] ? ri->ifname : "an unnamed interface");
		return 0;
	}
	snprintf(what, sizeof(what),
		 "the controller '%s' is reached through a gateway (on %s): "
		 "the one supported network is a direct link, the controller "
		 "on an interface of its own or a cable (docs/technician.md)",
		 host, ri->ifname[0] ? ri->ifname : "an unnamed interface");
	if (a->cfg.mode == RE_MODE_CLINICAL)
		return re_start_fail(a, what);
	re_start_progress(a, "warning: %s", what);
	return 0;
}

/* The route's minimum retransmission time (docs/link.md): a frame lost on
 * the cable must be resent soon enough that the reply still comes within
 * the critical reply-age limit. None, or one above the limit, refuses a
 * clinical start and is a warning in development mode. A loopback
 * controller (the simulator on this PC) has no cable: not checked. */
static int check_route(struct app *a)
{
	int fd = gl_link_fd(a->real.link), ms = 0, rc;
	struct gl_route_info ri;
	int crit = (int)(a->plan.wdog.crit_ns / 1000000);
	int limit = gl_route_rto_limit_ms(crit, a->cfg.period_ms);
	char host[256], port[16], what[700];

	if (gl_route_peer_loopback(fd) == 1)
		return 0;
	if (gl_link_addr_split(a->cfg.controller.address, host, sizeof(host),
			       port, sizeof(port)) != GL_OK)
		snprintf(host, sizeof(host), "%s", a->cfg.controller.address);
	rc = gl_route_get(fd, 1000, &ri);
	ms = ri.rto_min_ms;
	if (rc == GL_OK && check_direct(a, &ri, host))
		return EXIT_CONNECT;
	if (rc == GL_OK && ms > 0 && ms <= limit) {
		re_start_progress(
		    a,
		    "route to the controller: rto_min %d ms (limit %d "
		    "ms)",
		    ms, limit);
		return 0;
	}
	if (rc != GL_OK)
		snprintf(what, sizeof(what),
			 "cannot read the route to the controller '%s': %s",
			 host,
			 rc == GL_ERR_SYS ? strerror(errno) : gl_strerror(rc));
	else
		snprintf(what, sizeof(what),
			 "the route to the controller '%s' has rto_min %d ms "
			 "(limit %d ms): one lost frame would trip WATCHDOG; "
			 "run 'ip route replace %s dev <interface> rto_min "
			 "%dms' (docs/link.md)",
			 host, ms ? ms : GL_ROUTE_DEFAULT_RTO_MIN_MS, limit,
			 host, limit < 5 ? limit : 5);
	if (a->cfg.mode == RE_MODE_CLINICAL)
		return re_start_fail(a, what);
	re_start_progress(a, "warning: %s", what);
	return 0;
}

/* Connect (@b->find on a refusal), check the route, identify, refuse a
 * controller another supervisor runs; with @b->take_over close the other
 * connections and check the program's identity and seal. */
static int start_link(struct app *a, const struct re_bringup *b)
{
	char e[GL_ERRTEXT_LEN];
	char id[256];
	gl_link *l;

	re_start_progress(a, "connecting to the controller at %s",
			  a->cfg.controller.address);
	if (gl_link_open(&l, a->cfg.controller.address,
			 a->cfg.controller.connect_timeout_ms, e) != GL_OK) {
		if (!b->find)
			return re_start_fail(a, e);
		if (b->find(a, e))
			return EXIT_CONNECT; /* said why */
		if (gl_link_open(&l, a->cfg.controller.address,
				 a->cfg.controller.connect_timeout_ms,
				 e) != GL_OK)
			return re_start_fail(a, e);
	}
	gl_link_set_timeout(l, a->cfg.controller.timeout_ms);
	a->real.link = l;
	a->real.address = a->cfg.controller.address;
	a->real.cmd_timeout_ms = a->cfg.controller.timeout_ms;
	if (check_route(a))
		return EXIT_CONNECT;
	if (re_ctl_identify(l, &a->cfg, &a->info, a->err, sizeof(a->err)) ||
	    re_ctl_check_busy(&a->io, a->cfg.watchdog.controller_timeout_ms,
			      a->err, sizeof(a->err)) ||
	    (b->take_over && re_ctl_take_over(l, &a->cfg, &a->info, &a->seal,
					      a->err, sizeof(a->err))))
		return re_start_fail(a, a->err);
	a->ctl_ours = 1;
	if (b->take_over)
		snprintf(id, sizeof(id), "%s, serial %ld, program id %016llX",
			 a->info.model, a->info.serial,
			 (unsigned long long)a->info.program_id);
	else
		snprintf(id, sizeof(id), "%s, serial %ld", a->info.model,
			 a->info.serial);
	re_start_progress(a, "controller %s", id);
	return 0;
}

int re_start_bringup(struct app *a, const struct re_bringup *b)
{
	int rc;

	/* the limits, derived once (the program's mainms is read later) */
	re_plan_make(&a->cfg, 0, &a->plan);
	rc = take_locks(a);

	re_sig.cont_real = &a->real;
	if (!rc && !re_sig.quit) {
		rc = start_relay(a);
		if (!rc && b->after)
			rc = b->after(a);
	}
	if (!rc && !re_sig.quit) {
		rc = start_link(a, b);
		if (!rc && b->after)
			rc = b->after(a);
	}
	return rc;
}

/* In development mode (the simulator, a bench) an amplifier check that
 * fails is logged; in clinical mode it refuses the start. */
static int amp_check(struct app *a, int want_on, int timeout_ms)
{
	int ta0 = 0;

	if (re_ctl_amp_power(&a->io, want_on, timeout_ms, &ta0, a->err,
			     sizeof(a->err)) == GL_OK)
		return 0;
	if (a->cfg.mode == RE_MODE_CLINICAL)
		return re_start_fail(a, a->err);
	re_console_msg(&a->con,
		       "roboelf: warning: %s (development mode: "
		       "continuing)",
		       a->err);
	re_log_msg(&a->log, RE_LOG_WARN, "%s (development mode)", a->err);
	return 0;
}

/* Halted and read back off, configured, no motor power seen, program
 * started: the controller is known safe before the relay closes. */
static int prepare_controller(struct app *a)
{
	re_plan_make(&a->cfg, 0, &a->plan);
	re_start_progress(a, "halting the controller program; every motor off");
	if (re_ctl_halt(&a->io, a->err, sizeof(a->err)) ||
	    re_ctl_configure(&a->io, &a->cfg, &a->plan, a->err, sizeof(a->err)))
		return re_start_fail(a, a->err);
	re_start_progress(a, "controller configured and read back");
	if (amp_check(a, 0, 200))
		return EXIT_CONNECT;
	if (re_ctl_start_program(&a->io, &a->info, a->err, sizeof(a->err)))
		return re_start_fail(a, a->err);
	re_plan_make(&a->cfg, a->info.mainms, &a->plan);
	return 0;
}

/* The way of the record (controller.record) and the link measured, one
 * line: in the safe state, where the program's watchdog does not run.
 * With "stream" the controller's DR stream is opened after the take-over
 * (its IHT=>-3 closed every UDP handle too) and before the cycle's first
 * record, and its first records timed. */
static int open_record(struct app *a)
{
	const struct re_config_controller *cc = &a->cfg.controller;
	struct re_linkmeas m = {0};
	gl_link *l = a->real.link;
	char line[400];
	int rc;

	if (cc->record == RE_RECORD_STREAM) {
		rc = re_linkmeas_stream(
		    l, cc->address, cc->udp_port, a->plan.stream_n0,
		    a->plan.ctl_sample_ns, &m, a->err, sizeof(a->err));
		/* opened: closed again by the power-off, on every way out */
		a->stream = gl_link_stream_info(l, NULL, NULL) == 1;
		if (rc != GL_OK)
			return re_start_fail(a, a->err);
	}
	rc = re_linkmeas_reply(l, RE_LINKMEAS_REPLIES, cc->timeout_ms, &m);
	if (rc != GL_OK) {
		snprintf(a->err, sizeof(a->err),
			 "the controller at %s did not answer 'MG TIME': %s",
			 cc->address, gl_strerror(rc));
		return re_start_fail(a, a->err);
	}
	re_linkmeas_line(&m, line, sizeof(line));
	re_start_progress(a, "%s", line);
	return 0;
}

static int power_on(struct app *a)
{
	if (re_relay_on(a->relay) != GL_OK) {
		snprintf(a->err, sizeof(a->err),
			 "cannot switch motor power on: %s",
			 re_relay_errmsg(a->relay));
		return re_start_fail(a, a->err);
	}
	a->powered = 1;
	re_start_progress(a,
			  "motor power on (relay closed); the motors are off");
	return amp_check(a, 1, 500);
}

static int init_super(struct app *a)
{
	struct re_super_cfg sc;

	re_plan_super_cfg(&a->plan, &a->cfg, a->names, &sc);
	re_plan_xcheck_cfg(&a->plan, &a->cfg, a->names, &a->xcheck);
	sc.seal = &a->seal;
	sc.xcheck = &a->xcheck;
	sc.stream = a->stream;
	a->sup = re_super_new();
	if (!a->sup || re_super_init(a->sup, &a->io, &sc, NULL, 0) != GL_OK)
		return re_start_fail(a, "cannot set up the supervisor");
	if (re_super_view(a->sup)->rb_n > 0)
		re_start_progress(
		    a,
		    "checked twice: roboelf reads the program's %d sealed "
		    "values back, all every %d cycles (%d ms), and decodes "
		    "the joystick itself",
		    a->seal.n, re_super_view(a->sup)->rb_n,
		    re_super_view(a->sup)->rb_n * a->cfg.period_ms);
	if (a->rec) { /* flight recorder */
		char serial[24];

		snprintf(serial, sizeof(serial), "%ld", a->info.serial);
		re_rec_attach(a->rec, a->sup, serial);
	}
	return 0;
}

/* The critical reply-age limit, ms: a stop longer than this is a stall. */
int64_t re_start_stall_limit_ms(const struct app *a)
{
	return (a->sup ? re_super_view(a->sup)->crit_ns
		       : a->plan.wdog.crit_ns) /
	       1000000;
}

/* The stop of a SIGCONT since the last look, when it outlasted the
 * limit: its length in ms; else 0 (and forgotten). */
static int64_t stalled_ms(const struct app *a)
{
	int64_t ms;

	if (!re_sig.continued)
		return 0;
	re_sig.continued = 0;
	ms = re_sig.cont_stop_ms;
	return ms > re_start_stall_limit_ms(a) ? ms : 0;
}

/* A stop during start-up is the cause of whatever failed after it (the
 * controller's watchdog, a command timed out): the fault says so. */
static void stall_first(struct app *a, struct re_fault *f)
{
	int64_t ms = stalled_ms(a);

	if (!ms)
		return;
	if (f->id != RE_F_NONE) {
		char what[512];

		re_fault_format_units(f, a->names,
				      a->sup ? &re_super_view(a->sup)->cfg.units
					     : NULL,
				      what, sizeof(what));
		re_log_msg(&a->log, RE_LOG_WARN,
			   "start-up: after a stop of %lld ms: %s",
			   (long long)ms, what);
	}
	re_fault_set(f, RE_F_STALL, -1);
	f->i[0] = ms;
	f->i[1] = re_start_stall_limit_ms(a);
}

static int latch(struct app *a, const struct re_fault *fault)
{
	struct re_fault f = *fault;

	re_seal_read_fault(&a->seal, &a->io, a->cfg.controller.timeout_ms, &f);
	stall_first(a, &f);
	if (f.id != RE_F_NONE && re_super_fault(a->sup, &f) == RE_FAULT)
		re_console_fault(&a->con, re_super_fault_line(a->sup));
	return EXIT_FAULT;
}

/* Between start-up steps: a stop is a fault once the supervisor exists
 * (motor power may be on), else the start is refused. */
static int check_stall(struct app *a)
{
	struct re_fault f;

	if (!re_sig.continued)
		return 0;
	if (!a->sup) {
		int64_t ms = stalled_ms(a);

		if (!ms)
			return 0;
		snprintf(a->err, sizeof(a->err),
			 "roboelf did not run for %lld ms during start-up "
			 "(limit %lld ms: stopped, e.g. SIGSTOP or a "
			 "debugger); motor power was not switched on; start "
			 "it again",
			 (long long)ms, (long long)re_start_stall_limit_ms(a));
		return re_start_fail(a, a->err);
	}
	re_fault_set(&f, RE_F_NONE, -1);
	stall_first(a, &f);
	return f.id == RE_F_NONE ? 0 : latch(a, &f);
}

/* A start-up step that failed with a message: a CONFIG fault. */
static int latch_err(struct app *a)
{
	struct re_fault f;

	re_fault_set(&f, RE_F_CONFIG, -1);
	snprintf(f.s, sizeof(f.s), "%.*s", (int)sizeof(f.s) - 1, a->err);
	return latch(a, &f);
}

/* Parameters, then the service state: from here every move is supervised
 * by the program and by the cycle. */
static int enter_service(struct app *a)
{
	struct re_fault f;
	int rc;

	if (re_ctl_write_params(&a->io, &a->cfg, &a->plan, NULL, a->err,
				sizeof(a->err)))
		return latch_err(a);
	/* the program refuses service while an axis is still moving (its
	 * check 17): a session interrupted a moment ago left TV non-zero */
	if (re_ctl_wait_still(&a->io, a->err, sizeof(a->err)) != GL_OK)
		return latch_err(a);
	a->hbpc = re_ctl_session();
	rc = re_ctl_service(&a->io, &a->hbpc, &f, a->err, sizeof(a->err));
	if (rc == RE_FAULT)
		return latch(a, &f);
	if (rc != GL_OK)
		return latch_err(a);
	re_super_start(a->sup, NULL, a->hbpc, RE_DMC_SERVICE);
	re_super_set_period(a->sup, a->plan.sample_ns);
	return 0;
}

/* ---- calibration --------------------------------------------------------- */

static void log_calibration(struct app *a, const char *how, double secs,
			    int filled)
{
	char took[32];

	for (int i = 0; i < a->cal->n_axes; i++) {
		const struct re_caltable *t = &a->cal->axis[i];

		re_log_msg(&a->log, RE_LOG_INFO,
			   "calibration (%s) axis %s: "
			   "%d points, start %.0f, step %.0f counts, soft "
			   "limits %.0f..%.0f, pot %.3f..%.3f V",
			   how, a->names[i], t->n, t->start_counts,
			   t->step_counts, t->soft_rev, t->soft_fwd,
			   t->pot_v[0], t->pot_v[t->n - 1]);
	}
	if (filled)
		re_log_msg(&a->log, RE_LOG_WARN,
			   "calibration: %d table point(s) had no sample of "
			   "their own (the PC was late) and were fitted from "
			   "their neighbours",
			   filled);
	/* under a second in ms: "0.0 s" for a robot already at its centre
	 * read like a time never measured */
	if (secs < 1.0)
		snprintf(took, sizeof(took), "%.0f ms", secs * 1000.0);
	else
		snprintf(took, sizeof(took), "%.1f s", secs);
	re_log_msg(&a->log, RE_LOG_INFO, "calibration (%s) done in %s", how,
		   took);
	re_console_msg(&a->con, "roboelf: calibration (%s) done in %s", how,
		       took);
}

static void stamp_calset(struct app *a)
{
	snprintf(a->cal->serial, sizeof(a->cal->serial), "%ld", a->info.serial);
	a->cal->config_hash = re_config_hash(&a->cfg);
	re_calfile_date(time(NULL), a->cal->date, sizeof(a->cal->date));
}

/* calibration.backup false: the save kept the previous table as FILE.bak
 * (re_calfile_save always does, atomically); remove it afterwards. */
static void drop_backup(struct app *a)
{
	char bak[RE_PATH_MAX + 8];

	if (a->cfg.calibration.backup)
		return;
	snprintf(bak, sizeof(bak), "%s.bak", a->cfg.calibration.file);
	if (unlink(bak) != 0 && errno != ENOENT)
		re_log_msg(&a->log, RE_LOG_WARN, "cannot remove '%s': %s", bak,
			   strerror(errno));
}

void re_start_show_foreign(struct app *a, unsigned mask)
{
	unsigned fresh = mask & ~a->foreign_shown;
	char hs[9];
	int n = 0;

	if (!fresh)
		return;
	a->foreign_shown |= fresh;
	for (int h = 0; h < 8; h++)
		if (fresh >> h & 1)
			hs[n++] = (char)('A' + h);
	hs[n] = '\0';
	re_console_msg(&a->con,
		       "roboelf: WARNING: another program connected to the "
		       "controller (handle %s). roboelf still supervises; if "
		       "nobody should be there, press q and find it.",
		       hs);
}

void re_start_show_events(struct app *a)
{
	struct re_event ev;

	while (a->sup && re_super_event(a->sup, a->ev_seen, &ev)) {
		a->ev_seen = ev.seq;
		re_console_event(&a->con, &ev);
	}
}

/* The calibration's sampler: one supervised cycle per sample. */
static int sample_cb(void *ud, const struct gl_record **rec)
{
	struct app *a = ud;
	struct re_calib_progress prog;
	struct re_status st;
	int v;

	if (re_sig.quit)
		return GL_ERR_AGAIN;
	/* a sample is a new record: the stream design's cycle may find none
	 * (its watchdog ends a stream that stops) */
	do {
		re_super_wait(a->sup);
		a->real.defer_log = 1; /* no file write in the cycle */
		v = re_super_cycle(a->sup);
		a->real.defer_log = 0;
	} while (v != RE_FAULT && !re_super_view(a->sup)->fresh &&
		 !re_super_view(a->sup)->latched && !re_sig.quit);
	re_start_show_foreign(a, re_super_view(a->sup)->foreign);
	re_start_show_events(a);
	re_calib_progress(a->calrun, a->calcfg, &re_super_view(a->sup)->rec,
			  re_io_now_ns(), &prog);
	re_console_calib(&a->con, &prog);
	if (re_console_due(&a->con, re_io_now_ns())) {
		re_super_status(a->sup, &st); /* only when drawn */
		re_console_status(&a->con, &st, re_io_now_ns(), 1);
	}
	re_io_flush_log(&a->real); /* after the cycle */
	if (v == RE_FAULT) {
		re_console_fault(&a->con, re_super_fault_line(a->sup));
		return RE_FAULT;
	}
	*rec = &re_super_view(a->sup)->rec;
	return GL_OK;
}

static void own_cb(void *ud, unsigned mask)
{
	struct app *a = ud;

	re_super_own(a->sup, mask);
}

static void tables_cb(void *ud, const struct re_calset *set)
{
	const struct re_caltable *t[RE_AXES];
	struct app *a = ud;

	for (int i = 0; i < RE_AXES; i++)
		t[i] = &set->axis[i];
	re_super_tables(a->sup, t);
}

static void fill_expect(struct app *a, const struct re_calib_cfg *cc,
			struct re_calfile_expect *e, char *serial)
{
	memset(e, 0, sizeof(*e));
	snprintf(serial, 32, "%ld", a->info.serial);
	e->serial = serial;
	e->n_axes = RE_AXES;
	e->config_hash = re_config_hash(&a->cfg);
	for (int i = 0; i < RE_AXES; i++) {
		snprintf(e->name[i], sizeof(e->name[i]), "%s", a->names[i]);
		e->step_counts[i] = a->cfg.axes[i].step_counts;
		e->check[i] = cc->axis[i].check;
	}
}

/* Load the tables (before anything is powered); on failure offer a full
 * calibration (terminal only). Return: 0 loaded, 1 full calibration
 * instead, EXIT_USAGE. */
static int calib_load(struct app *a)
{
	struct re_calfile_expect e;
	struct re_calib_cfg cc;
	char serial[32];

	re_calib_cfg_from(&a->cfg, &a->plan, a->names, &cc);
	re_start_progress(a, "loading calibration '%s'",
			  a->cfg.calibration.file);
	fill_expect(a, &cc, &e, serial);
	if (re_calfile_load(a->cfg.calibration.file, &e, a->cal, a->err,
			    sizeof(a->err)) == GL_OK)
		return 0;
	re_console_msg(&a->con, "roboelf: error: %s", a->err);
	re_log_msg(&a->log, RE_LOG_WARN, "calibration file refused: %s",
		   a->err);
	if (re_console_ask_yes(&a->con, "Run a full calibration instead? "
					"Every axis will move to both of its "
					"limit switches, then to the centre."))
		return 1;
	re_console_msg(&a->con, "roboelf: run again with --calibration full");
	return EXIT_USAGE;
}

/* The centre of axis @i's calibrated travel in whole counts: an integer,
 * so that a centre of -0.4 counts is said "0", never "-0". */
static long long centre_counts(const struct app *a, int i)
{
	return llround((a->cal->axis[i].soft_rev + a->cal->axis[i].soft_fwd) /
		       2);
}

/* What will move and where, said before anything moves; the choice is the
 * operator's (the prompt) or the command line's. Return: 0, EXIT_USAGE. */
static int choose_calibration(struct app *a)
{
	int how = a->calib_opt, rc;

	if (how == RE_CALIB_ASK)
		how = re_console_ask_calibration(&a->con);
	if (how != RE_CALIB_FULL && how != RE_CALIB_FILE) {
		if (re_sig.quit)
			return 0;
		re_console_msg(&a->con, "roboelf: error: no answer to the "
					"calibration question (end of input): "
					"nothing moved, motor power stays off; "
					"run again and answer f or l, or use "
					"--calibration full|file");
		re_log_msg(&a->log, RE_LOG_WARN,
			   "start-up ended: no answer to the calibration "
			   "question (end of input)");
		return EXIT_USAGE;
	}
	a->cal = calloc(1, sizeof(*a->cal));
	if (!a->cal)
		return re_start_fail(a, "out of memory");
	if (how == RE_CALIB_FILE) {
		rc = calib_load(a);
		if (rc > 1)
			return rc;
		how = rc == 1 ? RE_CALIB_FULL : how;
	}
	a->calib = how;
	if (how == RE_CALIB_FULL)
		re_start_progress(
		    a, "full calibration chosen: every axis will move to "
		       "its reverse and forward limit switches, then to "
		       "the centre of its travel");
	else
		re_start_progress(
		    a,
		    "calibration from the file: every axis will move "
		    "to the centre of its calibrated travel (A %lld, "
		    "B %lld, C %lld counts)",
		    centre_counts(a, 0), centre_counts(a, 1),
		    centre_counts(a, 2));
	return 0;
}

static void save_calibration(struct app *a)
{
	stamp_calset(a);
	if (re_calfile_save(a->cfg.calibration.file, a->cal, a->err,
			    sizeof(a->err)) != GL_OK) {
		re_console_msg(&a->con, "roboelf: warning: %s", a->err);
		re_log_msg(&a->log, RE_LOG_WARN, "calibration not saved: %s",
			   a->err);
		return;
	}
	re_start_progress(a, "calibration saved to '%s'",
			  a->cfg.calibration.file);
	drop_backup(a);
}

/* An interrupted calibration: which table is in force now - the one of
 * the file (kept, unchanged), or none (the next start needs a full
 * calibration) - on the console and in the log. */
static void say_table_in_force(struct app *a, const struct re_calib_cfg *cc)
{
	const char *file = a->cfg.calibration.file;
	struct re_calfile_expect e;
	struct re_calset *old;
	char serial[32];
	int rc;

	if (a->calib != RE_CALIB_FULL) {
		re_start_progress(
		    a,
		    "calibration interrupted: the table in force is "
		    "still the one loaded from '%s' (made %s), "
		    "unchanged",
		    file, a->cal->date);
		return;
	}
	old = calloc(1, sizeof(*old));
	fill_expect(a, cc, &e, serial);
	rc = old ? re_calfile_load(file, &e, old, a->err, sizeof(a->err))
		 : GL_ERR_NOMEM;
	if (rc == GL_OK)
		re_start_progress(
		    a,
		    "calibration interrupted: no new table; the table "
		    "in force is still the one in '%s' (made %s), "
		    "kept unchanged: the next start can load it",
		    file, old->date);
	else if (rc == GL_ERR_NOENT)
		re_start_progress(
		    a,
		    "calibration interrupted: no table is in force "
		    "('%s' does not exist): the next start needs a "
		    "full calibration",
		    file);
	else
		re_start_progress(
		    a,
		    "calibration interrupted: no table is in force "
		    "('%s' was not changed but cannot be used: %s): "
		    "the next start needs a full calibration",
		    file, a->err);
	free(old);
}

/* The chosen procedure in the service state. Return: 0, EXIT_FAULT, or
 * 0 with re_sig.quit set (interrupted). The duration said at the end is
 * the whole procedure's on the monotonic clock, the same for both kinds:
 * the check of a file and its move to the centre take time too. */
static int run_calibration(struct app *a, struct re_calib *c,
			   struct re_calib_cfg *cc)
{
	int64_t t0_ns = base_now_ns();
	struct re_fault f;
	int rc, filled = 0;

	if (a->calib == RE_CALIB_FULL) {
		re_start_progress(a, "full calibration: every axis end to end");
		rc = re_calib_full(c, &a->io, cc, a->cal, &f, NULL, &filled);
	} else {
		re_start_progress(
		    a, "checking the robot against the file, moving to "
		       "the centre");
		rc = re_calib_check_robot(c, &a->io, cc, a->cal, &f);
	}
	if (rc == RE_FAULT)
		return latch(a, &f);
	if (rc == GL_ERR_AGAIN) {
		say_table_in_force(a, cc);
		return 0;
	}
	if (rc != GL_OK) {
		snprintf(a->err, sizeof(a->err), "calibration failed: %s",
			 gl_strerror(rc));
		return latch_err(a);
	}
	log_calibration(a, a->calib == RE_CALIB_FULL ? "full" : "file",
			(double)(base_now_ns() - t0_ns) / 1e9, filled);
	return 0;
}

static int calibrate(struct app *a)
{
	struct re_calib_cfg cc;
	struct re_calib *c;
	int rc;

	if (re_calib_new(&c) != GL_OK)
		return re_start_fail(a, "out of memory");
	re_calib_cfg_from(&a->cfg, &a->plan, a->names, &cc);
	cc.stop = &re_sig.quit;
	cc.sampler = (struct re_calib_sampler){sample_cb, own_cb, tables_cb, a};
	a->calrun = c;
	a->calcfg = &cc;
	rc = run_calibration(a, c, &cc);
	a->calrun = NULL;
	a->calcfg = NULL;
	re_console_calib(&a->con, NULL);
	re_calib_free(c);
	return rc;
}

/* Back to the safe state (motors off) for the slow file I/O, then armed. */
static int arm(struct app *a)
{
	const struct re_caltable *t[RE_AXES];
	struct re_fault f;
	int rc;

	/* the cycle wrote the heartbeat since the service began: go on
	 * from its last value (a value behind it is out of sequence) */
	a->hbpc = re_super_view(a->sup)->hbpc;
	if (re_ctl_off(&a->io, &a->hbpc, a->err, sizeof(a->err)) != GL_OK)
		return latch_err(a);
	re_super_start(a->sup, NULL, a->hbpc, 0);
	if (a->calib == RE_CALIB_FULL)
		save_calibration(a);
	re_start_progress(a, "soft limits from the calibration; arming");
	rc = re_ctl_arm(&a->io, a->cal, &a->hbpc, &f, a->err, sizeof(a->err));
	if (rc == RE_FAULT)
		return latch(a, &f);
	if (rc != GL_OK)
		return latch_err(a);
	for (int i = 0; i < RE_AXES; i++)
		t[i] = &a->cal->axis[i];
	re_super_set_period(a->sup, 0);
	re_super_start(a->sup, t, a->hbpc, RE_DMC_ARMED);
	return 0;
}

typedef int (*startup_step)(struct app *a);

int re_start(struct app *a)
{
	static const startup_step steps[] = {
	    choose_calibration, prepare_controller, open_record, init_super,
	    power_on,		enter_service,	    calibrate,	 arm,
	};
	static const struct re_bringup b = {NULL, 1, check_stall};
	int rc;

	/* a key typed from here to the board must not land inside the
	 * lines said meanwhile; the questions still echo their answers, and
	 * the terminal is given back on every way out (re_app_release) */
	re_console_quiet(&a->con);
	rc = re_start_bringup(a, &b);

	/* a stop while the operator chooses is no stall: nothing is on */
	for (size_t i = 0;
	     !rc && !re_sig.quit && i < sizeof(steps) / sizeof(steps[0]); i++) {
		rc = steps[i](a);
		if (steps[i] == choose_calibration)
			re_sig.continued = 0;
		if (!rc)
			rc = check_stall(a);
	}
	return rc;
}

void re_start_show_ready(struct app *a)
{
	const struct re_super_view *s = a->sup ? re_super_view(a->sup) : NULL;
	int k;

	if (a->ready_said || !s || !s->armed || s->latched || !s->have_za ||
	    s->za.state != RE_DMC_ARMED)
		return;
	if (s->za.mneut) {
		re_console_msg(&a->con, "RoboELF Ready for Use");
		re_log_msg(&a->log, RE_LOG_INFO, "RoboELF Ready for Use");
		a->ready_said = 1;
		return;
	}
	if (a->held_said || s->za.jcmd < 1 || s->za.jcmd > 2 * RE_AXES)
		return;
	k = s->za.jcmd - 1;
	re_console_msg(&a->con,
		       "roboelf: the joystick is held (axis %s %s) since "
		       "arming: release it to neutral; nothing moves until "
		       "the controller has seen it released",
		       a->names[k / 2], k % 2 ? "reverse" : "forward");
	re_log_msg(&a->log, RE_LOG_WARN,
		   "arm: joystick held (axis %s %s) since arming; waiting for "
		   "neutral",
		   a->names[k / 2], k % 2 ? "reverse" : "forward");
	a->held_said = 1;
}
