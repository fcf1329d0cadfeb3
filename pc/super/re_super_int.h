/*
 * re_super_int.h - the supervisor's state, private to the safety core
 * (pc/super: re_super.c, re_react.c) and its own unit test. The rest of
 * roboelf reads what it publishes (struct re_super_view, re_super.h).
 */
#ifndef RE_SUPER_INT_H
#define RE_SUPER_INT_H

#include "re_super.h"

#define RE_LATE_BIN_US 50   /* lateness histogram resolution, us */
#define RE_LATE_BINS   2001 /* 0 .. 100 ms, then one overflow bin */
#define RE_SENT_RING   64   /* heartbeats remembered for the echo */
#define RE_POST_RING   GL_LINK_POST_MAX /* posted lines outstanding */

struct re_super {
	struct re_super_view pub; /* what it publishes (re_super.h) */
	const struct re_caltable *table[RE_SUPER_AXES]; /* NULL: no check */
	/* schedule */
	int64_t t0_ns;
	int64_t deadline_ns; /* start of the next cycle */
	int64_t late_worst_ns;
	/* wake-up lateness histogram: RE_LATE_BIN_US bins, the last one
	 * counts everything later (for the exit statistics; no allocation) */
	uint32_t late_hist[RE_LATE_BINS];
	/* the supervisor's own liveness: end of the last cycle's round
	 * trip (0: none) */
	int64_t last_end_ns;
	/* watchdog */
	int64_t noncrit_ns;
	int64_t last_good_ns;
	uint64_t wd_warnings; /* every late reply */
	/* repeated warnings condensed (RE_SUPER_WD_WINDOW_MS): the window
	 * opened by the last logged one, and the late replies counted since
	 * (not logged one by one) with the worst of their ages */
	int wd_open;
	int64_t wd_open_ns;
	uint64_t wd_held;
	int64_t wd_held_worst_ns;
	struct re_alive_state alive;
	/* the last record and its checks */
	struct re_encpot_state encpot[RE_SUPER_AXES];
	/* motion cross-check: what the supervisor itself commands (service
	 * moves), when each axis was last commanded, since when it moves */
	unsigned own_mask;
	int64_t cmd_ns[RE_SUPER_AXES];
	int64_t moving_ns[RE_SUPER_AXES]; /* 0: at rest */
	/* other programs at the controller: the handles open at the start
	 * (and since), and those another program opened after it */
	unsigned handles_known;
	int have_handles;
	/* fault latch */
	struct re_confirm confirm;
	int relay_lost_logged; /* relay failure while latched, logged once */
	/* later faults and warnings for the console: a fixed ring (no
	 * allocation in the cycle), read with re_super_event() */
	struct re_event events[RE_SUPER_EVENTS];
	uint64_t event_seq; /* the newest event's seq, 0: none yet */
	/* a log entry that could not be written, kept for re_super_retry() */
	enum re_log_level pending_lvl;
	char pending[2048];
	/* flight recorder (re_super_recorder()): @rec_cycle at the
	 * end of every cycle, @rec_fault when a fault latches (its text is
	 * added to the FAULT log entry); NULL: none */
	void (*rec_cycle)(void *ud, const struct re_super_view *v);
	const char *(*rec_fault)(void *ud, const struct re_super_view *v);
	void *rec_ud;
	/* the diverse checks: the supervisor's joystick decode, and the seal
	 * read back a chunk per cycle ("hbpc=N;MG r1,...") against
	 * seal_expect (made for the state @seal_state) */
	struct re_xcheck xc;
	double seal_expect[RE_SEAL_MAX];
	int seal_state;	     /* RE_DMC_ARMED / _SERVICE / 0 */
	int state_cycles;    /* records in a row showing seal_state */
	int rb_next, rb_cur; /* next chunk to send; in the reply */
	int rb_have;	     /* rb_reply holds chunk rb_cur */
	int rb_first[RE_SEAL_MAX], rb_count[RE_SEAL_MAX];
	char rb_chunk[RE_SEAL_MAX][64];
	char rb_line[96];
	char rb_reply[512];
	/* the stream design (re_super_stream.c): the posted lines, the
	 * time of the last fresh record, and the heartbeats sent lately (for
	 * the program's echo) */
	struct {
		int64_t ns; /* when it was posted */
		int chunk;  /* its read-back chunk, -1: none */
	} out[RE_POST_RING]; /* posted lines whose replies are outstanding,
			      * oldest at out_head */
	int out_head, n_out;
	int chunk_out;	 /* a read-back chunk is among them */
	int64_t rec_ns;	 /* the last fresh record */
	struct {
		long hb;
		int64_t ns;
	} sent[RE_SENT_RING];
	unsigned sent_n; /* heartbeats sent since the phase started */
	/* scratch, preallocated */
	char prefix[32]; /* "hbpc=N" of the last request ... */
	long prefix_hb;	 /* ... its N ... */
	int prefix_len;	 /* ... and length (0: not built yet) */
	char resp[128];
	char verdict[96]; /* what the settle wait found, for the log */
	char then[160];	  /* consequences seen after the first cause */
	char msg[RE_SUPER_LINE];
	char text[2048];
};

/*
 * re_react_own_doing() - the program's latched fault @za (detail @det) is
 * the result of this supervisor's own stop: 12 (pcflt), a motor found off
 * whose stop code says a command stopped it, every amplifier without
 * power once our relay's off was confirmed (re_react.c).
 * Return: 1 or 0.
 */
int re_react_own_doing(const struct re_super *s, const struct re_za *za,
		       double det);

/*
 * re_super_hb_next() - the next heartbeat: s->pub.hbpc + 1 (mod
 * RE_HBPC_WRAP) and its command "hbpc=N" in s->prefix
 * (re_super_stream.c).
 */
void re_super_hb_next(struct re_super *s);

/*
 * re_super_stream_reset() - a phase starts (re_super_start, init): the
 * record's age counts from @now_ns, the heartbeats sent are forgotten
 * (posted lines stay outstanding).
 */
void re_super_stream_reset(struct re_super *s, int64_t now_ns);

/*
 * re_super_exchange_stream() - the cycle's exchange in the stream design
 * (re_super_cfg.stream): collect the replies to lines posted in earlier
 * cycles that are all there (a read-back chunk's text into s->rb_reply),
 * post the next heartbeat (with the next read-back chunk when none is
 * outstanding; none when RE_POST_RING lines are), read the newest record
 * of the stream (s->pub.fresh), judge the record's age against the critical
 * limit and the oldest outstanding reply's against cfg.ack_limit_ns, and
 * set s->pub.age_last_ns for the warning. Never waits.
 * Return: RE_OK, or RE_FAULT with @f filled (WDOG_STREAM, WDOG_ACK, COMM).
 */
int re_super_exchange_stream(struct re_super *s, struct re_fault *f);

/*
 * re_super_check_echo() - on a fresh record with the program's fields:
 * the heartbeat its echo names was sent at most cfg.echo_limit_ns ago
 * (a heartbeat this supervisor did not send counts as none).
 * Return: RE_OK, or RE_FAULT with @f filled (RE_F_WDOG_ECHO).
 */
int re_super_check_echo(struct re_super *s, struct re_fault *f);

#endif /* RE_SUPER_INT_H */
