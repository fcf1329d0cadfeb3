/*
 * re_super.h - the supervisor's periodic cycle (robotTask::Run) and its
 * fault reaction, in every phase in which a motor can be powered.
 *
 * Every period: the supervisor's own stall checked on its monotonic clock,
 * then one round trip with the controller ("hbpc=<n>;QR"), then the checks
 * of re_check.h on the record: the reply age (PC-side watchdog), the
 * program's fields (latched controller fault, the expected state - service
 * while calibrating and centring, armed afterwards - threads, motors), the
 * program heartbeat and the record sample number advancing, encoder against
 * potentiometer per axis (once tables exist), motion only where something
 * commanded it, and the E-stop relay link.
 *
 * On the first fault, in the same cycle: the relay is told to open (never
 * waiting), "pcflt=1;AB 1;MO ABC" goes to the controller at once - over a
 * new connection within a deadline when the old one is out of step or gone
 * - then the relay's off is confirmed within its deadline, the motors' off
 * is read back, the fault is latched and the log entry written and fsync'ed
 * (a failed write is kept and retried, and shown); only then does the caller
 * print the FAULT line (re_super_fault_line()), which names the first cause
 * and says exactly what was confirmed. A latched supervisor never re-arms,
 * never switches motor power on, and keeps polling the record for the
 * status board until the operator quits.
 *
 * Deadlines are absolute (re_super_wait()); a cycle that ends after the next
 * deadline is an overrun: counted, and the schedule restarts from now rather
 * than running a burst of late cycles.
 *
 * Everything lives in struct re_super; nothing is allocated after
 * re_super_init(). Nothing here prints.
 */
#ifndef RE_SUPER_H
#define RE_SUPER_H

#include <stdint.h>

#include "gl_record.h"
#include "re_check.h"
#include "re_fault.h"
#include "re_io.h"
#include "re_pot.h"
#include "re_seal.h"
#include "re_xcheck.h"

#define RE_SUPER_AXES	   3
#define RE_SUPER_LINE	   768 /* FAULT line, bytes incl. NUL */
#define RE_SUPER_MSGS	   8   /* unsolicited lines drained per cycle */
#define RE_SUPER_EVENTS	   16  /* later faults and warnings kept */
#define RE_SUPER_EVENT_LEN 240 /* one of them, bytes incl. NUL */
/* Repeated watchdog warnings condensed: after a late reply is logged, the
 * further ones within this window are counted and logged as one summary
 * line when the window ends (or at a fault or the quit), ms. A steady
 * network delay makes a late reply nearly every cycle (about 10 lines a
 * second were seen); the log is the record of failures, and a flood of
 * identical lines hides the one that matters and fills the disk. 10 s
 * keeps that to two lines per 10 s, while the first late reply is still
 * logged at once with its age, a burst is placed in time to within 10 s,
 * and every one is counted (wd_warnings). docs/supervisor.md, "Watchdog
 * warnings". */
#define RE_SUPER_WD_WINDOW_MS 10000

/* What a kept event is about (the console folds repeats of one kind). */
enum re_event_kind {
	RE_EV_OTHER = 0,
	RE_EV_WATCHDOG, /* a late reply (non-critical) */
	RE_EV_FOREIGN,	/* another program at the controller */
	RE_EV_LATER,	/* a fault while another is latched */
	RE_EV_RELAY,	/* the relay failed while latched */
};

/* A warning or a later fault, for the console's history (also logged). */
struct re_event {
	uint64_t seq;		 /* 1, 2, ... in the order they happened */
	double t_s;		 /* since the supervisor started, s */
	enum re_log_level level; /* RE_LOG_WARN or RE_LOG_FAULT */
	enum re_event_kind kind;
	char text[RE_SUPER_EVENT_LEN];
};

struct re_super_cfg {
	int n_axes;		   /* 1..RE_SUPER_AXES */
	int64_t period_ns;	   /* cycle period */
	struct re_wdog_lim wdog;   /* reply-age limits (the plan's) */
	struct re_alive_cfg alive; /* heartbeat / sample limits */
	struct re_encpot_cfg encpot[RE_SUPER_AXES];
	const char *axis_names[RE_SUPER_AXES];
	struct re_fault_units
	    units; /* positions in FAULT lines; zero: counts */
	int pot_input[RE_SUPER_AXES]; /* analog input 1..8; 0: axis + 1 */
	int fault_cmd_timeout_ms;     /* "pcflt=1;AB 1;MO ABC" deadline */
	int fresh_stop_ms; /* the stop over a new connection: connect and
			    * reply within this, ms; 0: never tried */
	int relay_off_ms;  /* relay off confirmed within this, ms */
	/* A motor off, a stopped thread or a left state may be the first
	 * sign of a fault the program is latching itself (its ZA fields
	 * follow every mainms): after cutting power and stopping, wait up to
	 * this long for the program's own fault code, the more specific
	 * cause. 0: report at once. */
	int settle_ms;
	/* An axis moving although nothing commanded it is a fault once that
	 * has lasted this long (the program publishes its command up to
	 * mainms late), ns; 0: the check is off. */
	int64_t uncmd_grace_ns;
	const char *mode_name; /* "clinical" / "development" */
	/* the program's sealed values (re_seal.h): a fault 17 names the
	 * value, what was found and what was sealed, and the cycle reads
	 * them back (a slice per cycle) against the supervisor's own plan;
	 * NULL: by number, no read-back */
	const struct re_seal *seal;
	/* the supervisor's own decode of the joystick and its check of the
	 * motion (re_xcheck.h); NULL: off */
	const struct re_xcheck_cfg *xcheck;
	/* 1: the record arrives as a stream (the controller's DR over UDP,
	 * opened by the start-up: re_io's stream op), the heartbeat and the
	 * read-back are posted on TCP and their replies collected in the next
	 * cycle (re_io's post and collect ops): no wait in the cycle. 0: one
	 * "hbpc=N;QR" round trip per cycle. docs/link.md. */
	int stream;
	/* stream design: the program's echo of the last heartbeat it took
	 * (re_za.hb_echo) may be at most this old (the critical limit plus
	 * the program's pass and the record interval), ns; 0: not checked */
	int64_t echo_limit_ns;
	/* stream design: the oldest posted line may wait this long for its
	 * reply (the controller's TCP resends a lost one on its own timer;
	 * the echo proves the heartbeat arrived), ns; 0: not checked */
	int64_t ack_limit_ns;
};

/* Per-axis view for the status board. */
struct re_axis_status {
	int32_t enc_counts;
	double pos_pct;		/* 0..100 between the soft limits; -1 unknown */
	double soft_rev_counts; /* the soft limits (valid when have_soft) */
	double soft_fwd_counts;
	int have_soft;
	double pot_v;
	double pot_expected_v;
	double margin_v; /* tolerance - |pot - expected|; < 0 outside */
	int have_expect; /* a table is loaded and the values are valid */
	double vel_cps;	 /* counts/s */
	int moving;
	int fwd_limit; /* switch active */
	int rev_limit;
	int motor_off;
	int stop_code;
};

/* What the fault reaction could confirm (for the FAULT line and the log). */
struct re_confirm {
	int relay_rc;	/* relay off: GL_OK when confirmed */
	int stop_rc;	/* the stop command: >= 0 delivered */
	int stop_fresh; /* 1: delivered over a new connection */
	int stop_maybe; /* 1: no answer in time: whether the controller
			   got it is not known */
	int motors_rc;	/* GL_OK: every motor read back off */
	double stop_ms; /* time to deliver the stop, ms */
};

/* Everything the console shows; a snapshot made by re_super_status(). */
struct re_status {
	int n_axes;
	const char *axis_names[RE_SUPER_AXES];
	struct re_axis_status axis[RE_SUPER_AXES];
	int have_record;
	enum re_relay_state relay;
	double wd_last_ms; /* reply age at the last good reply */
	double wd_worst_ms;
	double period_ms;
	double late_last_ms; /* wake-up lateness of the last cycle */
	double late_worst_ms;
	uint64_t cycles;
	uint64_t overruns;
	uint64_t wd_warnings; /* non-critical watchdog events, each one
			       * (also those only counted in a summary) */
	int armed;
	int expect;	 /* program state expected: RE_DMC_ARMED, _SERVICE, 0 */
	int link_ok;	 /* last round trip succeeded */
	/* the record stream (record: stream) while one is open: the records
	 * its reader accepted and counted lost since it was opened */
	int stream;
	uint64_t stream_records, stream_lost;
	struct re_za za; /* program fields (valid when have_za) */
	int have_za;
	const char *mode_name;
	int latched;
	/* the controller's latched fault is the result of this supervisor's
	 * own stop (a motor found off by our MO, every amplifier without
	 * power after our relay's off; not 12, which names us itself): the
	 * board says so */
	int ctrl_ours;
	const char *fault_line; /* "" when none */
	int log_failing;	/* a log entry could not be written */
	unsigned foreign;	/* handles another program opened (1 = A) */
	double uptime_s;
};

/* What the supervisor publishes, read-only to the rest of roboelf (the
 * console, the recorder, the start-up): re_super_view(). The core keeps
 * these fields up to date itself; there is no copy to go stale. */
struct re_super_view {
	struct re_io io;
	struct re_super_cfg cfg;
	int expect;	   /* RE_DMC_ARMED, RE_DMC_SERVICE, or 0 (nothing on) */
	int armed;	   /* expect == RE_DMC_ARMED (kept for the status) */
	int64_t period_ns; /* the schedule's period (cfg or override) */
	int64_t late_last_ns;
	uint64_t cycles, overruns;
	int64_t crit_ns; /* the critical reply-age limit (the plan's) */
	int64_t age_last_ns, age_worst_ns;
	long hbpc; /* heartbeat value last written */
	/* the last record and its checks */
	struct gl_record rec;
	int have_record;
	int fresh; /* rec is new this cycle (the stream design: a cycle may
		    * find none; the round trip: every good reply) */
	int link_ok;
	struct re_za za;
	int have_za;
	struct re_encpot_result encres[RE_SUPER_AXES];
	int have_encres[RE_SUPER_AXES];
	unsigned foreign; /* handles another program opened (1 = A) */
	/* fault latch */
	int latched;
	struct re_fault fault;
	char fault_line[RE_SUPER_LINE];
	int log_failing; /* a log entry could not be written */
	int rb_n;	 /* chunks of the seal's read-back */
};

/* The supervisor's state: private to pc/super (re_super_int.h). */
struct re_super;

/*
 * re_super_new() - a zeroed supervisor, allocated once at start-up (never
 * in the cycle); re_super_init() sets it up.
 * re_super_free() - release it (NULL: nothing).
 * Return (new): the supervisor, or NULL when out of memory.
 */
struct re_super *re_super_new(void);
void re_super_free(struct re_super *s);

/*
 * re_super_view() - what @s publishes, valid as long as @s.
 */
const struct re_super_view *re_super_view(const struct re_super *s);

/*
 * re_super_init() - set up the cycle state. Computes the watchdog limits.
 * @s: [out] the supervisor.
 * @io: [in] the outside world (copied).
 * @cfg: [in] copied; axis_names and mode_name must outlive @s.
 * @tables: [in] per-axis calibration tables (must outlive @s), or NULL
 *          entries / NULL for no encoder/pot check on those axes.
 * @expect: the program state expected from the first cycle: RE_DMC_ARMED,
 *          RE_DMC_SERVICE (motors on in both), or 0 (nothing expected).
 * The first deadline is one period from now; the last good reply is taken
 * as "now".
 * Return: GL_OK or GL_ERR_ARG (bad period, axes or watchdog factors).
 */
int re_super_init(struct re_super *s, const struct re_io *io,
		  const struct re_super_cfg *cfg,
		  const struct re_caltable *const *tables, int expect);

/*
 * re_super_start() - the program entered @expect (RE_DMC_SERVICE after the
 * service request, RE_DMC_ARMED after arming): from now on the cycle checks
 * that state, the motors on, and the encoders against @tables (NULL entries
 * or NULL: no check on those axes). The schedule, the reply-age watchdog,
 * the stall reference and the liveness history restart from now; the
 * heartbeat continues from @hbpc. No-op when latched.
 */
void re_super_start(struct re_super *s, const struct re_caltable *const *tables,
		    long hbpc, int expect);

/*
 * re_super_tables() - check the encoders against @tables from now (NULL
 * entries or NULL: no check on those axes); the persistence counts restart.
 */
void re_super_tables(struct re_super *s,
		     const struct re_caltable *const *tables);

/*
 * re_super_set_period() - the schedule's period from now (calibration
 * samples every RE_CALIB_SAMPLE_MS); 0 restores the configured period. The
 * watchdog limits stay those of the configured period.
 */
void re_super_set_period(struct re_super *s, int64_t period_ns);

/*
 * re_super_own() - the supervisor itself moves the axes in @mask (bit i =
 * axis i) from now (a service move it requested), or no longer (0): an
 * axis moving outside @mask and outside the program's own command is
 * "moving although nothing commanded it".
 */
void re_super_own(struct re_super *s, unsigned mask);

/*
 * re_super_wait() - sleep until the next absolute deadline and advance it
 * by one period. A deadline already passed by a whole period or more is an
 * overrun: counted, and the schedule restarts from now.
 * Return: the lateness of this wake-up in ns (>= 0).
 */
int64_t re_super_wait(struct re_super *s);

/*
 * re_super_recorder() - the flight recorder's hooks: @cycle is
 * called at the end of every re_super_cycle() (also latched ones), after
 * any fault reaction in it; @fault when a fault latches, after the stop,
 * the relay and the motors were confirmed and before the FAULT log entry
 * is written: the text it returns (NULL: none) ends that entry, e.g. the
 * name of the trace that will hold the fault. Both run inside the cycle:
 * they must not allocate, block or do I/O. NULL hooks: no recorder.
 */
void re_super_recorder(
    struct re_super *s, void (*cycle)(void *ud, const struct re_super_view *v),
    const char *(*fault)(void *ud, const struct re_super_view *v), void *ud);

/*
 * re_super_cycle() - one cycle: round trip, checks, fault reaction.
 * While latched: only polls the record (for the status board) and never
 * acts on anything again.
 * Return: RE_OK; RE_WARN (a non-critical event: a late reply, logged or
 *         counted for the summary, see re_super_wd_flush()); RE_FAULT (a
 *         new fault was latched in this cycle: print re_super_fault_line()).
 */
int re_super_cycle(struct re_super *s);

/*
 * re_super_wd_flush() - log the late replies counted since the last logged
 * watchdog warning (RE_SUPER_WD_WINDOW_MS), if any, as one WARN line
 * "watchdog: N more late replies in the last T s (worst A ms, ...)" and
 * keep it for the console (re_super_note()); the window closes, so that
 * the next late reply is logged in full. Nothing counted: nothing logged.
 * The cycle calls it when the window ends, the fault reaction before the
 * FAULT entry, re_super_shutdown() after its stop; call it before the
 * run's last lines so the summary precedes them. No allocation, no I/O
 * but the log's.
 */
void re_super_wd_flush(struct re_super *s);

/*
 * re_super_fault() - the fault reaction, also for faults found outside the
 * cycle (start-up, calibration): relay off started, the stop sent (a new
 * connection when needed), relay off confirmed, motors read back, latch,
 * FAULT log entry fsync'ed (kept for a retry when that fails), FAULT line
 * composed with what was confirmed. A second fault while latched is only
 * logged.
 * @f: [in] the fault.
 * Return: RE_FAULT when this fault was latched, RE_OK if already latched.
 */
int re_super_fault(struct re_super *s, const struct re_fault *f);

/* re_super_fault_line() - the latched FAULT line, "" when not latched. */
const char *re_super_fault_line(const struct re_super *s);

/*
 * re_super_note() - keep @text (cut to RE_SUPER_EVENT_LEN - 1 bytes) in the
 * ring of later faults and warnings, as the newest, overwriting the oldest
 * when full. Does not log (the caller does). No allocation, no I/O.
 * @lvl: RE_LOG_WARN or RE_LOG_FAULT.
 */
void re_super_note(struct re_super *s, enum re_log_level lvl,
		   enum re_event_kind kind, const char *text);

/*
 * re_super_event() - the oldest kept event newer than @after (a seq; 0 for
 * the first). Events overwritten before they were read are skipped.
 * @out: [out] a copy.
 * Return: 1 when one was copied, 0 when none is newer.
 */
int re_super_event(const struct re_super *s, uint64_t after,
		   struct re_event *out);

/*
 * re_super_retry() - write a log entry that failed before (the FAULT entry
 * on a full disk, ...). Call it outside the cycle, e.g. once a second.
 * Return: GL_OK when nothing is pending (any more), else the log error.
 */
int re_super_retry(struct re_super *s);

/*
 * re_super_status() - fill @st from the supervisor's last cycle.
 * @st: [out]; its pointers point into @s (valid while @s is).
 */
void re_super_status(const struct re_super *s, struct re_status *st);

/*
 * re_super_shutdown() - the operator quits: ask the program back to its
 * safe state ("offreq=1"), stop motion and switch the motors off through
 * the controller ("AB 1;MO ABC"), read back that every motor is off, then
 * cut motor power (relay off, confirmed within its deadline). Every step
 * is attempted whatever fails before it.
 * @what: [out] optional, a line saying what was confirmed, for the log.
 * Return: GL_OK when everything was confirmed, else the first error.
 */
int re_super_shutdown(struct re_super *s, char *what, size_t cap);

/*
 * re_super_late_ms() - wake-up lateness percentile over every cycle so far.
 * @pct: 0 < pct <= 100 (50 for the median, 99, 100 for the maximum).
 * Return: ms, to the histogram's RE_LATE_BIN_US resolution (the upper edge
 *         of the bin); the worst lateness for pct 100; 0 with no cycle.
 */
double re_super_late_ms(const struct re_super *s, double pct);

#endif /* RE_SUPER_H */
