/*
 * re_plan.h - every limit the supervisor and the controller program work
 * with, derived in one place from the configuration (and, once known, the
 * program's own period mainms). Pure: no I/O, no allocation, no printing.
 *
 * Units: counts, counts/s, ms, volts. The potentiometer zones assume a pot
 * that rises with the encoder (reverse_v < forward_v; the configuration
 * loader enforces it): below pnlo the reverse switch may be near, above
 * pnhi the forward one; outside potlo..pothi the pot reads something it
 * cannot read on this robot (docs/dmc-interface.md, #GUARD and #MVGO).
 */
#ifndef RE_PLAN_H
#define RE_PLAN_H

#include <stdint.h>

#include "re_config.h"
#include "re_super.h"

struct re_plan_axis {
	double gain_v_per_count; /* nominal pot gain, V/count, > 0 */
	double margin_v;	 /* near_margin_counts in volts */
	double potlo_v, pothi_v; /* the pot's absolute range (DMC potlo/hi) */
	/* how far the slow zones reach before the earliest place a switch
	 * can be (reverse_v + absolute_tolerance_v): one program pass and
	 * the braking distance at svmax, plus monotonic_margin_v for the
	 * pot's noise, and never less than margin_v, V */
	double zone_v;
	double pnlo_v, pnhi_v; /* slow zones (DMC pnlo, pnhi) */
	int vmax_cps;	       /* joystick and sweep speed */
	int travel_cps;	       /* moves that measure nothing */
	int seek_cps;	       /* in the slow zones (DMC svslow) */
	int svmax_cps;	       /* any service move (DMC svmax) */
	long svdmax_counts;    /* longest service move (DMC svdmax) */
};

struct re_plan {
	struct re_plan_axis axis[RE_AXES];
	int mainms;	     /* the program's period, ms (0: not known yet) */
	int wdto_ms;	     /* controller watchdog (DMC wdto) */
	int hbmaxd;	     /* largest heartbeat step (DMC hbmaxd) */
	int pwrout;	     /* motor-power output (DMC pwrout), 0: none */
	int move_timeout_ms; /* one service move (DMC mvto) */
	int64_t period_ns;   /* supervisor cycle */
	int64_t sample_ns;   /* cycle while calibrating: the period
			      * or RE_PLAN_SAMPLE_MS, the shorter */
	struct re_wdog_lim wdog; /* reply-age limits: the one derivation */
	int64_t hb_limit_ns;	 /* program heartbeat frozen: fault */
	int64_t sample_limit_ns; /* record sample number frozen: fault */
	int64_t uncmd_grace_ns;	 /* motion not commanded: fault after */
	int settle_ms;		 /* wait for the program's own verdict */
	int fresh_stop_ms;	 /* the stop over a new connection */
	int relay_off_ms;	 /* relay off confirmed within */
	int64_t ctl_sample_ns;	 /* one controller servo sample, ns */
	unsigned stream_n0;	 /* samples between two streamed records
				  * (DR n0): a quarter of the fastest
				  * cycle (sample_ns), at least 2 */
	int64_t echo_limit_ns;	 /* the program's heartbeat echo: fault
				  * when older (stream design) */
};

#define RE_PLAN_SAMPLE_MS 10 /* the cycle while calibrating, ms */
/* The stream design: the oldest heartbeat line may wait this long for its
 * reply. Longer than the critical limit on purpose: a real controller's
 * TCP resends a lost reply on its own timer (200 ms at least, doubled for
 * a second loss), and the program's echo in the record already proves the
 * heartbeat's arrival within the critical limit; past 1 s the command
 * connection is stalled (docs/link.md). */
#define RE_PLAN_ACK_LIMIT_MS 1000
/* One servo sample of a DMC-40x0 at TM 1000, the only TM the program
 * accepts (its seal, re_seal.c): 1000/1024 ms = 976 562.5 ns, rounded
 * (galil-notes 1.7; docs/dmc-interface.md). galil-sim's is 1 ms: the
 * stream's interval there is 2.4 % longer than the plan says. */
#define RE_PLAN_CTL_SAMPLE_NS 976563
#define RE_PLAN_STREAM_N0_MIN 2 /* the shortest DR interval (docs/link.md) */

/*
 * re_plan_make() - derive the plan from @cfg (validated) and @mainms (the
 * program's period read at start-up; 0 when not known yet: the limits that
 * depend on it use the constants' default 10 ms).
 * @out: [out] the plan.
 */
void re_plan_make(const struct re_config *cfg, int mainms, struct re_plan *out);

/*
 * re_plan_stream_n0() - the record stream's interval (DR n0) for a cycle
 * of @period_ns and a controller sample of @sample_ns: a quarter of the
 * period in whole samples, at least RE_PLAN_STREAM_N0_MIN (a lost record
 * then costs a quarter of a cycle; docs/link.md). At 976 563 ns: 50 ms
 * gives 12, 10 ms gives 2, 2 ms gives 2.
 * Return: n0 >= 2 (also for a non-positive argument).
 */
unsigned re_plan_stream_n0(int64_t period_ns, int64_t sample_ns);

/*
 * re_plan_super_cfg() - the supervisor's settings from the plan.
 * @names: [in] the axis names (must outlive @out).
 * @out: [out] filled completely.
 */
void re_plan_super_cfg(const struct re_plan *p, const struct re_config *cfg,
		       const char *const *names, struct re_super_cfg *out);

/*
 * re_plan_xcheck_cfg() - the settings of the supervisor's own joystick
 * decode and motion check (re_xcheck.h): the wiring, the ramps, and the
 * program's reporting lag (loopms + 2 mainms + the period).
 * @names: [in] the axis names (must outlive @out).
 */
void re_plan_xcheck_cfg(const struct re_plan *p, const struct re_config *cfg,
			const char *const *names, struct re_xcheck_cfg *out);

#endif /* RE_PLAN_H */
