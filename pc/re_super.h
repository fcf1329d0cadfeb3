/*
 * re_super.h - the supervisor's periodic cycle (robotTask::Run) and its
 * fault reaction.
 *
 * Every period: one round trip with the controller ("hbpc=<n>;QR"), then the
 * checks of re_check.h on the record: the reply age (PC-side watchdog), the
 * program's fields (latched controller fault, state, threads, motors), the
 * program heartbeat and the record sample number advancing, encoder against
 * potentiometer per axis, and the E-stop relay link. On the first fault, in
 * the same cycle: relay off (motor power cut) first, then "AB 1;MO ABC;
 * pcflt=1" through the controller (best effort, bounded time), latch, and
 * the log entry written and fsync'ed; only then does the caller print the
 * FAULT line (re_super_fault_line()). A latched supervisor never re-arms,
 * never switches motor power on, and keeps polling the record for the status
 * board until the operator quits.
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
#include "re_io.h"

#define RE_SUPER_AXES 3
#define RE_SUPER_LINE 512 /* FAULT line, bytes incl. NUL */
#define RE_SUPER_MSGS 8	  /* unsolicited lines drained per cycle */

/* AQ2 (default): analog inputs read +-10 V as +-32768 counts. */
#define RE_AN_COUNTS_PER_V 3276.8

struct re_super_cfg {
	int n_axes;		   /* 1..RE_SUPER_AXES */
	int64_t period_ns;	   /* cycle period */
	struct re_wdog_cfg wdog;   /* reply-age limits */
	struct re_alive_cfg alive; /* heartbeat / sample limits */
	struct re_encpot_cfg encpot[RE_SUPER_AXES];
	const char *axis_names[RE_SUPER_AXES];
	int pot_input[RE_SUPER_AXES]; /* analog input 1..8; 0: axis + 1 */
	int fault_cmd_timeout_ms;     /* "AB 1;MO ABC;pcflt=1" deadline */
	/* A motor off, a stopped thread or a left state may be the first
	 * sign of a fault the program is latching itself (its ZA fields
	 * follow every mainms): after cutting power and stopping, wait up to
	 * this long for the program's own fault code, the more specific
	 * cause. 0: report at once. */
	int settle_ms;
	const char *mode_name; /* "clinical" / "development" */
};

/* Per-axis view for the status board. */
struct re_axis_status {
	int32_t enc_counts;
	double pos_pct; /* 0..100 between the soft limits; -1 unknown */
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
	uint64_t wd_warnings; /* non-critical watchdog events */
	int armed;
	int link_ok;	 /* last round trip succeeded */
	struct re_za za; /* program fields (valid when have_za) */
	int have_za;
	const char *mode_name;
	int latched;
	const char *fault_line; /* "" when none */
	double uptime_s;
};

#define RE_LATE_BIN_US 50   /* lateness histogram resolution, us */
#define RE_LATE_BINS   2001 /* 0 .. 100 ms, then one overflow bin */

struct re_super {
	struct re_io io;
	struct re_super_cfg cfg;
	const struct re_caltable *table[RE_SUPER_AXES]; /* NULL: no check */
	int armed; /* the program is armed: motors on */
	/* schedule */
	int64_t t0_ns;
	int64_t deadline_ns; /* start of the next cycle */
	int64_t late_last_ns, late_worst_ns;
	uint64_t cycles, overruns;
	/* wake-up lateness histogram: RE_LATE_BIN_US bins, the last one
	 * counts everything later (for the exit statistics; no allocation) */
	uint32_t late_hist[RE_LATE_BINS];
	/* watchdog */
	int64_t noncrit_ns, crit_ns;
	int64_t last_good_ns;
	int64_t age_last_ns, age_worst_ns;
	uint64_t wd_warnings;
	long hbpc; /* heartbeat value last written */
	struct re_alive_state alive;
	/* the last record and its checks */
	struct gl_record rec;
	int have_record;
	int link_ok;
	struct re_za za;
	int have_za;
	struct re_encpot_state encpot[RE_SUPER_AXES];
	struct re_encpot_result encres[RE_SUPER_AXES];
	int have_encres[RE_SUPER_AXES];
	/* fault latch */
	int latched;
	struct re_fault fault;
	char fault_line[RE_SUPER_LINE];
	int relay_lost_logged; /* relay failure while latched, logged once */
	/* scratch, preallocated */
	char prefix[32];
	char resp[128];
	char verdict[64]; /* what the settle wait found, for the log */
	char msg[RE_SUPER_LINE];
	char text[1536];
};

/*
 * re_super_init() - set up the cycle state. Computes the watchdog limits.
 * @s: [out] the supervisor.
 * @io: [in] the outside world (copied).
 * @cfg: [in] copied; axis_names and mode_name must outlive @s.
 * @tables: [in] per-axis calibration tables (must outlive @s), or NULL
 *          entries / NULL for no encoder/pot check on those axes.
 * @armed: 1 when the program is armed (motors expected on).
 * The first deadline is one period from now; the last good reply is taken
 * as "now".
 * Return: GL_OK or GL_ERR_ARG (bad period, axes or watchdog factors).
 */
int re_super_init(struct re_super *s, const struct re_io *io,
		  const struct re_super_cfg *cfg,
		  const struct re_caltable *const *tables, int armed);

/*
 * re_super_start() - the program is armed: from now on the cycle expects
 * the motors on and checks the encoders against @tables (NULL entries: no
 * check on that axis). The schedule, the reply-age watchdog and the
 * liveness history restart from now; the heartbeat continues from @hbpc.
 * No-op when latched.
 */
void re_super_start(struct re_super *s, const struct re_caltable *const *tables,
		    long hbpc);

/*
 * re_super_wait() - sleep until the next absolute deadline and advance it
 * by one period. A deadline already passed by a whole period or more is an
 * overrun: counted, and the schedule restarts from now.
 * Return: the lateness of this wake-up in ns (>= 0).
 */
int64_t re_super_wait(struct re_super *s);

/*
 * re_super_cycle() - one cycle: round trip, checks, fault reaction.
 * While latched: only polls the record (for the status board) and never
 * acts on anything again.
 * Return: RE_OK; RE_WARN (a non-critical event was logged); RE_FAULT (a new
 *         fault was latched in this cycle: print re_super_fault_line()).
 */
int re_super_cycle(struct re_super *s);

/*
 * re_super_fault() - the fault reaction, also for faults found outside the
 * cycle (start-up, calibration): relay off, "AB 1;MO ABC;pcflt=1", latch,
 * FAULT log entry fsync'ed, FAULT line composed. A second fault while
 * latched is only logged.
 * @f: [in] the fault.
 * Return: RE_FAULT when this fault was latched, RE_OK if already latched.
 */
int re_super_fault(struct re_super *s, const struct re_fault *f);

/* re_super_fault_line() - the latched FAULT line, "" when not latched. */
const char *re_super_fault_line(const struct re_super *s);

/*
 * re_super_status() - fill @st from the supervisor's last cycle.
 * @st: [out]; its pointers point into @s (valid while @s is).
 */
void re_super_status(const struct re_super *s, struct re_status *st);

/*
 * re_super_shutdown() - the operator quits: stop motion and switch the
 * motors off through the controller ("AB 1;MO ABC"), then cut motor power
 * (relay off). Both are attempted whatever fails.
 * Return: GL_OK, or the first error (the caller logs it).
 */
int re_super_shutdown(struct re_super *s);

/* re_pot_volts() - analog input counts (AQ2) to volts. */
double re_pot_volts(int32_t analog_in);

/*
 * re_super_late_ms() - wake-up lateness percentile over every cycle so far.
 * @pct: 0 < pct <= 100 (50 for the median, 99, 100 for the maximum).
 * Return: ms, to the histogram's RE_LATE_BIN_US resolution (the upper edge
 *         of the bin); the worst lateness for pct 100; 0 with no cycle.
 */
double re_super_late_ms(const struct re_super *s, double pct);

#endif /* RE_SUPER_H */
