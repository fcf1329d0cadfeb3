/*
 * re_calib_int.h - what the parts of the calibration share: the working
 * state and its phases, and the functions one part gives the others.
 *   re_calib.c          the settings, the working state, full calibration
 *   re_calib_move.c     faults, supervised samples, service moves
 *   re_calib_seek.c     seeking a limit switch; the reverse one and off it
 *   re_calib_sweep.c    the sweep forward, onto the forward switch, off it
 *   re_calib_table.c    the samples into a table, and its checks
 *   re_calib_centre.c   every axis to the centre, checked on the way
 *   re_calib_verify.c   tables loaded from a file, checked on the robot
 *   re_calib_progress.c where a procedure is, for the console
 * Who uses whom: re_calib.c every part; seek uses move; sweep uses seek,
 * table and move; table and centre use move; verify uses centre and move;
 * progress uses seek. No loop (tests/checks/layers.sh). Not for the rest
 * of roboelf: re_calib.h is the interface.
 */
#ifndef RE_CALIB_INT_H
#define RE_CALIB_INT_H

#include <stdint.h>

#include "re_calib.h"

enum phase {
	PH_START,    /* nothing sent yet */
	PH_FAST_REV, /* fast toward the reverse switch, short of its zone */
	PH_TO_REV,   /* slowly onto the reverse switch */
	PH_BACK_REV, /* backing off it: then table point 0 */
	PH_SWEEP,    /* sweeping forward at vmax, short of the fwd zone */
	PH_SLOW_FWD, /* still sweeping, slowly onto the forward switch */
	PH_BACK_FWD, /* backing off it: the forward soft limit */
	PH_DONE,
	PH_CHECK,  /* a loaded file checked against the robot */
	PH_CENTRE, /* to the centre of the new (or loaded) table */
};

/* Least-squares sums of one table point's samples, dx = enc - point. */
struct acc {
	int n;
	double sx, sy, sxx, sxy;
};

struct cal_axis {
	enum phase ph;
	int64_t t_phase_ns;
	double edge; /* encoder where the switch was first seen */
	int have_edge;
	double start; /* table point 0 = reverse soft limit */
	int off_rev;  /* the sweep passed start with the switch open */
	int off_fwd;  /* the axis passed soft_fwd with that switch open */
	double soft_fwd;
	double seek_len; /* length of the bounded slow move, counts */
	double centre;	 /* PH_CENTRE: the target, counts */
	struct acc acc[RE_CAL_MAX_POINTS];
};

/* The moves requested in one sample, sent together. */
struct batch {
	unsigned mask;
	long tgt[RE_AXES];
	int sp[RE_AXES];
};

struct re_calib {
	struct cal_axis ax[RE_AXES];
	const struct gl_record *rec;
	struct re_encpot_state encpot[RE_AXES];
	struct batch b;	    /* queued, not sent yet */
	unsigned pending;   /* sent, not taken yet (mvreq still 1) */
	unsigned taken_now; /* taken after this sample's record was read:
			       that record does not show the move yet */
	int64_t sent_ns;
	int64_t t0_ns;
	int running; /* a procedure runs (for re_calib_progress()) */
	int full;
	int filled;
	char line[GL_LINE_MAX + 1];
	char resp[128];
};

/*
 * Faults (re_calib_move.c). Both fill @f and return RE_FAULT:
 * cal_abort() - RE_F_CAL_ABORT for axis @axis (-1: none), the message
 *               from @fmt;
 * cal_comm_fault() - RE_F_COMM, "@what: <the error of @rc>".
 */
int cal_abort(struct re_fault *f, int axis, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
int cal_comm_fault(struct re_fault *f, const char *what, int rc);
/*
 * Time and samples (re_calib_move.c):
 * cal_now_ns() - @io's clock, ns.
 * cal_sample() - wait for and take the next supervised sample into c->rec.
 *                Return: GL_OK; RE_FAULT (@f set, or RE_F_NONE when the
 *                sampler latched the fault and the supervisor reacted);
 *                GL_ERR_AGAIN (cfg->stop).
 * What the sample in hand says of axis @i: cal_enc() the encoder, counts;
 * cal_pot() the potentiometer, V; cal_moving(), cal_rev_switch(),
 * cal_fwd_switch() 1 when it moves, when that switch is active.
 */
int64_t cal_now_ns(const struct re_io *io);
int cal_sample(struct re_calib *c, const struct re_calib_cfg *cfg,
	       struct re_fault *f);
double cal_enc(const struct re_calib *c, int i);
double cal_pot(const struct re_calib *c, const struct re_calib_cfg *cfg, int i);
int cal_moving(const struct re_calib *c, int i);
int cal_rev_switch(const struct re_calib *c, int i);
int cal_fwd_switch(const struct re_calib *c, int i);
/*
 * Service moves (re_calib_move.c):
 * cal_move_to() - queue a move of axis @i to @target (counts) at @speed
 *                 (counts/s);
 * cal_send_batch() - send the queued moves and the request (nothing while
 *                 one is pending);
 * cal_taken() - whether the program took the pending request; a fault
 *                 when it did not within cfg->accept_ms;
 *                 both return GL_OK or RE_FAULT (@f set);
 * cal_waiting() - 1 when axis @i has a move the record in hand does not
 *                 show yet (queued, pending, or taken after it was read);
 * cal_enter() - axis @i into phase @ph, its phase clock restarted
 *                 (returns GL_OK);
 * cal_own() - the supervisor moves the axes in @mask itself from now;
 * cal_use_tables() - the supervisor checks the encoders against @set.
 */
void cal_move_to(struct re_calib *c, int i, double target, int speed);
int cal_send_batch(struct re_calib *c, const struct re_io *io,
		   const struct re_calib_cfg *cfg, struct re_fault *f);
int cal_taken(struct re_calib *c, const struct re_io *io,
	      const struct re_calib_cfg *cfg, struct re_fault *f);
int cal_waiting(const struct re_calib *c, int i);
int cal_enter(struct re_calib *c, const struct re_io *io, int i, enum phase ph);
void cal_own(const struct re_calib_cfg *cfg, unsigned mask);
void cal_use_tables(const struct re_calib_cfg *cfg,
		    const struct re_calset *set);
/*
 * Seeking a switch (re_calib_seek.c), distances in counts:
 * cal_note_edge() - remember where the switch first showed @active;
 * cal_brake_counts() - what a fast move at @speed keeps before a slow zone;
 * cal_fast_len() - how far a fast move at @speed may run before the pot
 *                 reaches @zone_v (<= 0: too close);
 * cal_fast_worth() - 1 when a fast move of @len at @fast beats going on
 *                 at @slow (@first: the first of them);
 * cal_seek_len() - the length of the bounded slow move onto a switch;
 * cal_stopped_badly() - the fault of a move that stopped before @where;
 * cal_check_at_switch() - the pot at the switch (@fwd: the forward one)
 *                 against its expected absolute value: GL_OK or RE_FAULT.
 */
void cal_note_edge(struct re_calib *c, int i, int active);
double cal_brake_counts(int speed);
double cal_fast_len(const struct re_calib_axis_cfg *a, double pot,
		    double zone_v, int speed);
int cal_fast_worth(double len, int fast, int slow, int first);
double cal_seek_len(const struct re_calib_axis_cfg *a, double pot,
		    double end_v);
int cal_stopped_badly(const struct re_calib *c, int i, const char *where,
		      struct re_fault *f);
int cal_check_at_switch(const struct re_calib *c,
			const struct re_calib_cfg *cfg, int i, int fwd,
			struct re_fault *f);
/*
 * The steps of axis @i, one per phase, run on each sample once the record
 * shows the axis's last move (re_calib.c's axis_step()). Each returns
 * GL_OK (the phase goes on, or the next one is entered with its move
 * queued) or RE_FAULT (@f set).
 * Toward the reverse switch and off it (re_calib_seek.c): cal_step_start(),
 * cal_step_fast_rev(), cal_step_to_rev(), cal_step_back_rev(), which end
 * in cal_begin_sweep() (table point 0 at @start).
 * The sweep (re_calib_sweep.c): cal_step_sweep(), cal_step_slow_fwd(),
 * cal_step_back_fwd(), and cal_sweep_sample(), the sample of a sweeping
 * axis whose move the record does not show yet.
 */
int cal_step_start(struct re_calib *c, const struct re_io *io,
		   const struct re_calib_cfg *cfg, int i);
int cal_step_fast_rev(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i,
		      struct re_fault *f);
int cal_step_to_rev(struct re_calib *c, const struct re_io *io,
		    const struct re_calib_cfg *cfg, int i, struct re_fault *f);
int cal_step_back_rev(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i,
		      struct re_fault *f);
int cal_begin_sweep(struct re_calib *c, const struct re_io *io,
		    const struct re_calib_cfg *cfg, int i, double start);
int cal_sweep_sample(struct re_calib *c, const struct re_calib_cfg *cfg, int i,
		     struct re_fault *f);
int cal_step_sweep(struct re_calib *c, const struct re_io *io,
		   const struct re_calib_cfg *cfg, int i, struct re_fault *f);
int cal_step_slow_fwd(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i,
		      struct re_fault *f);
int cal_step_back_fwd(struct re_calib *c, const struct re_io *io,
		      const struct re_calib_cfg *cfg, int i,
		      struct re_fault *f);
/*
 * The table (re_calib_table.c):
 * cal_accumulate() - the sample in hand into the sums of axis @i's
 *                 nearest table point;
 * cal_build_table() - axis @i's table @t from its sums, soft limits
 *                 included, checked point by point and whole (re_calcheck.h);
 *                 GL_OK or RE_FAULT (@f set).
 */
void cal_accumulate(struct re_calib *c, const struct re_calib_cfg *cfg, int i);
int cal_build_table(struct re_calib *c, const struct re_calib_cfg *cfg, int i,
		    struct re_caltable *t, struct re_fault *f);
/*
 * cal_to_centre() (re_calib_centre.c) - every axis to the centre of its
 * soft limits in @set at the travel speed, sampled until all stopped.
 * Return: GL_OK, RE_FAULT (@f set), GL_ERR_AGAIN (cfg->stop).
 */
int cal_to_centre(struct re_calib *c, const struct re_io *io,
		  const struct re_calib_cfg *cfg, const struct re_calset *set,
		  struct re_fault *f);

#endif /* RE_CALIB_INT_H */
