/*
 * re_plan.c - the limits derived from the configuration. See re_plan.h and
 * docs/supervisor.md ("Limits and where they come from").
 */
#include "re_plan.h"

#include <math.h>
#include <string.h>

#include "base_clock.h"

#define MAINMS_DEFAULT 10 /* dmc/constants.dmc */
#define ACFACT	       10 /* dmc/constants.dmc: AC = DC = 10 x speed */
#define DECEL_MS       (1000 / ACFACT) /* full speed to rest, ms */
#define PERIOD_MIN_MS  2 /* the shortest period_ms (re_config.c) */

static int max3(int a, int b, int c)
{
	int m = a > b ? a : b;

	return m > c ? m : c;
}

/* The counts a service move at @svmax_cps still runs once in the slow
 * zone: one program pass (@mainms) before the program sees it there, and
 * its braking distance at the configured acceleration (AC = DC = ACFACT
 * x speed: speed / (2 ACFACT)). For vmax 8000, mainms 10: 80 + 400. */
static double stop_counts(int svmax_cps, int mainms)
{
	return svmax_cps * (mainms / 1000.0) + svmax_cps / (2.0 * ACFACT);
}

static void plan_axis(const struct re_config *cfg, int i, int mainms,
		      struct re_plan_axis *o)
{
	const struct re_config_axis *a = &cfg->axes[i];
	const struct re_config_analog *an = &a->analog;
	const struct re_config_calibration *c = &cfg->calibration;
	double tol = an->absolute_tolerance_v;

	o->gain_v_per_count =
	    (an->forward_v - an->reverse_v) / (double)a->travel_counts;
	o->margin_v = c->near_margin_counts * o->gain_v_per_count;
	o->vmax_cps = a->vmax_cps;
	o->travel_cps = c->travel_cps ? c->travel_cps : a->vmax_cps;
	o->seek_cps = c->seek_cps ? c->seek_cps : a->vmax_cps / 2;
	if (o->seek_cps < 1)
		o->seek_cps = 1;
	o->svmax_cps = max3(o->travel_cps, o->seek_cps, a->vmax_cps);
	if (o->seek_cps > o->svmax_cps)
		o->seek_cps = o->svmax_cps;
	/* past a switch the axis can go as far as its end stop: the margin
	 * covers that (and the pot's own tolerance covers the switch) */
	o->potlo_v = an->reverse_v - tol - o->margin_v;
	o->pothi_v = an->forward_v + tol + o->margin_v;
	/* the slow zone, before the earliest place the switch can be: what
	 * a fast move the program finds there (one pass late) still runs,
	 * plus the pot's noise; never less than near_margin_counts (a margin
	 * for what the model leaves out: a slower pass on a loaded
	 * controller, the analog input's filter) */
	o->zone_v = stop_counts(o->svmax_cps, mainms) * o->gain_v_per_count +
		    a->monotonic_margin_v;
	if (o->zone_v < o->margin_v)
		o->zone_v = o->margin_v;
	o->pnlo_v = an->reverse_v + tol + o->zone_v;
	o->pnhi_v = an->forward_v - tol - o->zone_v;
	o->svdmax_counts =
	    lround(a->travel_counts * (1 + a->travel_tolerance)) +
	    2L * c->backoff_counts + 2L * c->near_margin_counts;
}

void re_plan_make(const struct re_config *cfg, int mainms, struct re_plan *out)
{
	int64_t p_ns = (int64_t)cfg->period_ms * BASE_NS_PER_MS;
	int ms = mainms > 0 ? mainms : MAINMS_DEFAULT;
	int fastest = cfg->period_ms < RE_PLAN_SAMPLE_MS ? cfg->period_ms
							 : RE_PLAN_SAMPLE_MS;
	double crit = cfg->watchdog.critical_factor;

	memset(out, 0, sizeof(*out));
	for (int i = 0; i < RE_AXES; i++)
		plan_axis(cfg, i, ms, &out->axis[i]);
	out->mainms = mainms;
	out->wdto_ms = cfg->watchdog.controller_timeout_ms;
	/* every write adds 1; the program sees at most this many writes
	 * between two passes before its own watchdog would trip anyway. At
	 * the shortest period the configuration allows, not the configured
	 * one: hbmaxd is sealed in the program (re_seal.h), and a --period
	 * must not change it */
	out->hbmaxd = (out->wdto_ms + PERIOD_MIN_MS - 1) / PERIOD_MIN_MS + 2;
	out->pwrout = cfg->controller.power_output;
	out->move_timeout_ms = cfg->calibration.move_timeout_ms;
	out->period_ns = p_ns;
	/* never slower than the period: the watchdog limits are the
	 * period's */
	out->sample_ns = (int64_t)fastest * BASE_NS_PER_MS;
	re_wdog_limits(
	    &(struct re_wdog_cfg){p_ns, cfg->watchdog.noncritical_factor, crit},
	    &out->wdog);
	/* the record's sample number frozen for longer than the critical
	 * reply age: the controller's clock has stopped */
	out->sample_limit_ns = out->wdog.crit_ns;
	out->hb_limit_ns = (int64_t)(crit * (double)(ms * BASE_NS_PER_MS > p_ns
							 ? ms * BASE_NS_PER_MS
							 : p_ns));
	/* the program publishes a fault within one mainms of latching it */
	out->settle_ms = 2 * ms + 5;
	/* the program publishes its command up to mainms late, the record
	 * is up to a period old, and a stopped axis still decelerates */
	out->uncmd_grace_ns =
	    (int64_t)(2 * ms + DECEL_MS + 50) * BASE_NS_PER_MS + 2 * p_ns;
	out->fresh_stop_ms = 2 * cfg->controller.timeout_ms;
	out->relay_off_ms = cfg->relay.off_deadline_ms;
	out->ctl_sample_ns = RE_PLAN_CTL_SAMPLE_NS;
	/* from the fastest cycle (the calibration's, when shorter than the
	 * period): every cycle of every phase finds a fresh record */
	out->stream_n0 = re_plan_stream_n0(out->sample_ns, out->ctl_sample_ns);
	/* the program takes a heartbeat within two passes (its check, then
	 * the pass that publishes ZA), the stream carries it within n0
	 * samples, and the record waits up to a period to be read: the
	 * echo's age may exceed the critical limit by that (so a delay
	 * trips it as it trips the round trip: past the critical limit) */
	out->echo_limit_ns = out->wdog.crit_ns + p_ns +
			     2LL * ms * BASE_NS_PER_MS +
			     (int64_t)out->stream_n0 * out->ctl_sample_ns;
}

unsigned re_plan_stream_n0(int64_t period_ns, int64_t sample_ns)
{
	int64_t n0;

	if (period_ns <= 0 || sample_ns <= 0)
		return RE_PLAN_STREAM_N0_MIN;
	/* a lost record costs a quarter of a cycle, not a whole one */
	n0 = period_ns / 4 / sample_ns;
	return n0 < RE_PLAN_STREAM_N0_MIN ? RE_PLAN_STREAM_N0_MIN
					  : (unsigned)n0;
}

void re_plan_super_cfg(const struct re_plan *p, const struct re_config *cfg,
		       const char *const *names, struct re_super_cfg *out)
{
	memset(out, 0, sizeof(*out));
	out->n_axes = RE_AXES;
	out->period_ns = p->period_ns;
	out->wdog = p->wdog;
	out->alive.sample_limit_ns = p->sample_limit_ns;
	out->alive.hb_limit_ns = p->hb_limit_ns;
	for (int i = 0; i < RE_AXES; i++) {
		out->encpot[i].allowed_error = cfg->axes[i].allowed_error;
		out->encpot[i].persistence_cycles =
		    cfg->axes[i].persistence_cycles;
		out->axis_names[i] = names[i];
		if (cfg->axes[i].counts_per_unit > 0) {
			out->units.name[i] = re_unit_name(cfg->axes[i].unit);
			out->units.counts_per_unit[i] =
			    cfg->axes[i].counts_per_unit;
		}
		out->pot_input[i] = cfg->axes[i].analog.input;
	}
	out->units.invalid_timeout_ms = cfg->joystick.invalid_timeout_ms;
	out->fault_cmd_timeout_ms = cfg->controller.timeout_ms;
	out->fresh_stop_ms = p->fresh_stop_ms;
	out->relay_off_ms = p->relay_off_ms;
	out->echo_limit_ns = p->echo_limit_ns;
	out->ack_limit_ns = (int64_t)RE_PLAN_ACK_LIMIT_MS * BASE_NS_PER_MS;
	out->settle_ms = p->settle_ms;
	out->uncmd_grace_ns = p->uncmd_grace_ns;
	out->mode_name =
	    cfg->mode == RE_MODE_CLINICAL ? "clinical" : "development";
}

void re_plan_xcheck_cfg(const struct re_plan *p, const struct re_config *cfg,
			const char *const *names, struct re_xcheck_cfg *out)
{
	int ms = p->mainms > 0 ? p->mainms : MAINMS_DEFAULT;

	memset(out, 0, sizeof(*out));
	for (int j = 0; j < RE_JOY_INPUTS; j++)
		out->inputs[j] = cfg->joystick.inputs[j];
	out->active_low = cfg->joystick.active_low ? 1 : 0;
	for (int i = 0; i < RE_AXES; i++) {
		out->vmin_cps[i] = cfg->axes[i].vmin_cps;
		out->vmax_cps[i] = cfg->axes[i].vmax_cps;
		out->wst_ms[i] = cfg->axes[i].accel_start_ms;
		out->wen_ms[i] = cfg->axes[i].accel_end_ms;
		out->axis_names[i] = names[i];
	}
	/* thread 1's loop (loopms = mainms in dmc/constants.dmc), two main
	 * passes until ZAC carries it, one period until the record */
	out->lag_ns = (int64_t)3 * ms * BASE_NS_PER_MS + p->period_ns;
}
