/*
 * test_dmc_hostile.c - a client writes every variable the program assigns
 * (the names come from the program itself, dmc/ as galil-load sends it,
 * through the linter's list of assignment targets), every element of each
 * array, in four phases: armed at rest, armed while A jogs up its ramp, in
 * service at rest, in service while A makes a move. Each write must be
 * caught - a fault naming the variable (fault 17 with its seal item, or
 * the older fault 14 for wdto and jto) within the seal's bound - or the
 * variable is in the list of docs/safety.md ("Variables a client may write
 * unnoticed") and the write changes nothing that matters: the axes end
 * where they end without the write, the motors are in the same state, and
 * with the heartbeat stopped the motors go off when they would have.
 *
 * The list is held to the program: a listed name the program no longer
 * assigns fails, and so does a listed name every write of which is
 * caught. A new variable is tested without editing this file.
 *
 * HOSTILE_LIST=1 prints every case's outcome. Under the sanitizers
 * (make asan) two of the six values are written, to bound its time.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "dmc_h.h"
#include "dmc_lint.h"

#define LIST_MAX    160
#define ELEM_MAX    32	/* elements of one array tried at most */
#define WINDOW_MS   400 /* after the write, before the heartbeat stops */
#define POS_TOL	    2	/* counts: the same end as without the write */
#define ARM_JOG_MS  60	/* the write comes this far up A's ramp */
#define SVC_MOVE_MS 80	/* ... this far into the service move */
#define HB_LATE_MS  2	/* the motors go off no later than without it */
#define CHANGES	    6	/* values written in place of each one */

enum phase { ARMED, JOGGING, SERVICE, MOVING, PHASES };

static const char *const phase_name[PHASES] = {
    "armed", "armed, A jogging", "in service", "in service, A moving"};

/* What the list allows a write of a name to change (its last column). */
enum allow {
	ALLOW_NONE,  /* nothing: the outcome is the phase's own, or safer */
	ALLOW_WDTO,  /* the motors off up to wdto + mainms later when the
		      * supervisor dies (a heartbeat the program takes) */
	ALLOW_RAMP,  /* the jogging axis rises from the write at rampov
		      * times the configured slope, up to vmax */
	ALLOW_STATE, /* another state the program allows (a request) */
};

static const char *const allow_word[] = {"none", "wdto", "ramp", "state"};

/* The list of docs/safety.md: names a client may write unnoticed. */
struct list {
	char name[LIST_MAX][DMC_LINT_NAME_SIZE];
	enum allow allow[LIST_MAX];
	int caught[LIST_MAX]; /* cases of it that were caught */
	int tried[LIST_MAX];
	int n;
};

/* What a phase ends in: axis positions, motors, when they go off. */
struct outcome {
	double pos[DMC_H_AXES];
	int motor_off[DMC_H_AXES];
	double state;
	double off_ms; /* after the heartbeat stopped; -1: never (bound) */
};

static char top[1024];
static struct list list;
static struct outcome ref[PHASES];
static double died_ref[PHASES]; /* ms: motors off, supervisor dead */
#if defined(__SANITIZE_ADDRESS__)
/* make asan looks for memory errors: two of the values (make check: all) */
static const int values_tried = 2;
#else
static const int values_tried = CHANGES;
#endif
static int verbose;

/* The allowance in the last cell of @row ("... | wdto |"). */
static int row_allow(const char *row, enum allow *a)
{
	const char *e = strrchr(row, '|'), *b;
	char word[16];
	size_t n;

	if (!e)
		return -1;
	for (b = e; b > row && b[-1] != '|'; b--)
		;
	while (*b == ' ' || *b == '`')
		b++;
	for (n = 0; b + n < e && b[n] != ' ' && b[n] != '`'; n++)
		;
	if (n == 0 || n >= sizeof(word))
		return -1;
	snprintf(word, sizeof(word), "%.*s", (int)n, b);
	for (size_t i = 0; i < sizeof(allow_word) / sizeof(*allow_word); i++)
		if (!strcmp(word, allow_word[i])) {
			*a = (enum allow)i;
			return 0;
		}
	return -1;
}

/* Read docs/safety.md's list: rows "| `name` `name2` | ... | allowance |"
 * under the heading that names it. */
static void read_list(void)
{
	char path[1100], line[1024];
	FILE *f;
	int in = 0, lineno = 0;

	snprintf(path, sizeof(path), "%s/docs/safety.md", top);
	f = fopen(path, "r");
	if (!f)
		fail_msg("%s: cannot open", path);
	while (fgets(line, sizeof(line), f)) {
		char *b = line + 1, *cell_end;
		enum allow a = ALLOW_NONE;

		lineno++;
		if (line[0] == '#')
			in = strstr(line, "Variables a client may write "
					  "unnoticed") != NULL;
		if (!in || strncmp(line, "| `", 3))
			continue;
		if (row_allow(line, &a) < 0)
			fail_msg(
			    "%s:%d: no allowance (%s, %s, %s or %s) in the "
			    "last cell",
			    path, lineno, allow_word[0], allow_word[1],
			    allow_word[2], allow_word[3]);
		cell_end = strchr(b, '|');
		while ((b = strchr(b, '`')) && b < cell_end) {
			char *e = strchr(b + 1, '`');

			if (!e || e - b - 1 >= DMC_LINT_NAME_SIZE ||
			    list.n == LIST_MAX)
				fail_msg("%s:%d: bad name", path, lineno);
			snprintf(list.name[list.n], DMC_LINT_NAME_SIZE, "%.*s",
				 (int)(e - b - 1), b + 1);
			list.allow[list.n++] = a;
			b = e + 1;
		}
	}
	fclose(f);
	if (list.n == 0)
		fail_msg("%s: no list 'Variables a client may write "
			 "unnoticed'",
			 path);
}

static int listed(const char *name)
{
	for (int i = 0; i < list.n; i++)
		if (!strcmp(list.name[i], name))
			return i;
	return -1;
}

static double mg(struct dmc_h *h, const char *expr, int *ok)
{
	char line[64], resp[64];

	snprintf(line, sizeof(line), "MG %s", expr);
	*ok = dmc_h_cmd(h, line, resp, sizeof(resp)) >= 0;
	return *ok ? atof(resp) : NAN;
}

/* A fresh robot brought to @ph. */
static void enter(struct dmc_h *h, enum phase ph)
{
	struct dmc_h_params p;

	dmc_h_params_default(&p);
	DMC_H_CHECK(h, dmc_h_open(h));
	DMC_H_CHECK(h, dmc_h_start(h));
	DMC_H_CHECK(h, dmc_h_cmd(h, "TL 5,5,5", NULL, 0));
	DMC_H_CHECK(h, dmc_h_configure(h, &p));
	DMC_H_CHECK(h, ph <= JOGGING ? dmc_h_arm(h) : dmc_h_service(h));
	if (ph == JOGGING) {
		DMC_H_CHECK(h, dmc_h_control(h, "joy A fwd"));
		dmc_h_advance(h, ARM_JOG_MS);
	} else if (ph == MOVING) {
		DMC_H_CHECK(h, dmc_h_move(h, 0, 20000, 5000, 10000));
		dmc_h_advance(h, SVC_MOVE_MS);
	}
}

/* Where the axes are now (the instant of the write). */
static void where(struct dmc_h *h, double pos[DMC_H_AXES])
{
	for (int i = 0; i < DMC_H_AXES; i++)
		pos[i] = dmc_h_axis(h, i).enc;
}

/* After the write: the window, then the heartbeat stops; how long until
 * every motor is off (0 when they already are). */
static void finish(struct dmc_h *h, struct outcome *o)
{
	dmc_h_advance(h, WINDOW_MS);
	for (int i = 0; i < DMC_H_AXES; i++) {
		struct ctrl_axis_info a = dmc_h_axis(h, i);

		o->pos[i] = a.enc;
		o->motor_off[i] = a.motor_off;
	}
	o->state = dmc_h_var(h, "state");
	h->hb_on = 0;
	o->off_ms = dmc_h_wait_motor_off(h, 7, 2 * dmc_h_var(h, "wdto") + 500);
}

/* The supervisor dies at the instant of the write: how long until every
 * motor is off (-1: not within twice the watchdog). */
static double died_at_write(struct dmc_h *h)
{
	h->hb_on = 0;
	return dmc_h_wait_motor_off(h, 7, 2 * dmc_h_var(h, "wdto") + 500);
}

/* The seal item named @name, or -1. */
static int seal_item(const struct dmc_h *h, const char *name)
{
	for (int k = 0; k < h->seal.n; k++)
		if (!strcmp(h->seal.item[k].ref, name))
			return k;
	return -1;
}

/* Whether the fault latched names @el: fault 17 with its seal item, or
 * the older check's fault 14 detail 3 for wdto and jto. */
static int names_it(struct dmc_h *h, const char *el)
{
	double code = dmc_h_var(h, "fcode"), det = dmc_h_var(h, "fdet");
	int k = seal_item(h, el);

	if (!strcmp(el, "wdto") || !strcmp(el, "jto"))
		return code == 14 && det == 3;
	return k >= 0 && code == 17 && det == k + 1;
}

/* Wait (at most @bound ms) for a fault to latch: fcode set and every
 * motor off. Return: ms waited, or -1. */
static double wait_fault(struct dmc_h *h, double bound)
{
	double t0 = dmc_h_now(h);

	for (;;) {
		int off = 1;

		for (int i = 0; i < DMC_H_AXES; i++)
			off &= dmc_h_axis(h, i).motor_off;
		if (dmc_h_var(h, "fcode") != 0 && dmc_h_var(h, "state") == 2 &&
		    off)
			return dmc_h_now(h) - t0;
		if (dmc_h_now(h) - t0 >= bound)
			return -1;
		dmc_h_advance(h, 1);
	}
}

/* Whether outcome @o, from axes at @w at the write, is the phase's own
 * (@r) or a safer one: each axis where it would be or short of it on the
 * same side (never past it, never the other way), a motor off where it
 * would be on (never the reverse), the motors off as soon after the
 * heartbeat stops. @a widens it: @late_ms later (ALLOW_WDTO), axis A up
 * to @travel counts (ALLOW_RAMP), another state (ALLOW_STATE). Else @why
 * says what differs. */
static int no_worse(const struct outcome *o, const struct outcome *r,
		    const double w[DMC_H_AXES], enum allow a, double late_ms,
		    double travel, char *why, size_t cap)
{
	int all_off = 1;

	for (int i = 0; i < DMC_H_AXES; i++) {
		double d = o->pos[i] - w[i], dr = r->pos[i] - w[i];

		if (a == ALLOW_RAMP && i == 0 && travel > fabs(dr))
			dr = dr < 0 ? -travel : travel;
		all_off &= o->motor_off[i];
		if (fabs(d) > POS_TOL &&
		    (d * dr <= 0 || fabs(d) > fabs(dr) + POS_TOL)) {
			snprintf(why, cap,
				 "axis %c went %+.0f counts (allowed: %+.0f)",
				 'A' + i, d, dr);
			return 0;
		}
		if (!o->motor_off[i] && r->motor_off[i]) {
			snprintf(why, cap, "axis %c's motor is on", 'A' + i);
			return 0;
		}
	}
	if (o->state != r->state && !all_off &&
	    !(a == ALLOW_STATE && o->state >= 0 && o->state <= 3)) {
		snprintf(why, cap,
			 "state %g (without the write: %g), a motor "
			 "on",
			 o->state, r->state);
		return 0;
	}
	if (a != ALLOW_WDTO)
		late_ms = 0;
	if (o->off_ms < 0 || o->off_ms > r->off_ms + HB_LATE_MS + late_ms) {
		snprintf(why, cap,
			 "with the heartbeat stopped the motors went off "
			 "after %.0f ms (without the write: %.0f, allowed "
			 "%.0f later)",
			 o->off_ms, r->off_ms, HB_LATE_MS + late_ms);
		return 0;
	}
	return 1;
}

/* The farthest axis A can go in @ms from speed @v0 (counts/s) when its
 * speed rises at rampov times the configured slope up to vmax: what a
 * write of the ramp's time base can do (ALLOW_RAMP). */
static double ramp_travel(struct dmc_h *h, double v0, double ms)
{
	struct dmc_h_params p;
	double slope, v, d = 0;

	dmc_h_params_default(&p);
	slope = dmc_h_var(h, "rampov") * (p.vmax[0] - p.vmin[0]) /
		(p.wen[0] - p.wst[0]); /* counts/s per ms */
	for (double t = 0; t < ms; t++) {
		v = v0 + (slope * t);
		d += (v < p.vmax[0] ? v : p.vmax[0]) / 1000;
	}
	return d;
}

/* The values a write puts in place of @v: one more, far ahead (a time in
 * the future), the other of 0 and 1, half a unit more (a counter that is
 * never whole again), the opposite sign, far negative (a counter far from
 * its range); the first values_tried of them. Return: how many (distinct,
 * none equal to @v). */
static int changes(double v, double out[CHANGES])
{
	double c[CHANGES] = {v + 1,   v + 1000000, v != 0 ? 0 : 1,
			     v + 0.5, -v,	   -1000000};
	int n = 0;

	for (int i = 0; i < values_tried; i++) {
		int dup = c[i] == v;

		for (int j = 0; j < n; j++)
			dup |= out[j] == c[i];
		if (!dup)
			out[n++] = c[i];
	}
	return n;
}

enum verdict { CAUGHT_NAMED, CAUGHT, UNNOTICED, UNCHANGED };

/* Element @el (a name, or name[i]) written with @nv in @ph, the
 * supervisor alive (@died 0: the outcome over the window against the
 * phase's own) or dying at the write (1: the motors off as soon). Fails
 * when the write is neither caught nor listed and harmless. */
static enum verdict one_case(const char *el, const char *base, double nv,
			     enum phase ph, int died)
{
	struct dmc_h *h = calloc(1, sizeof(*h));
	struct outcome o;
	char cmd[64], why[200];
	double bound, t, v, w[DMC_H_AXES];
	enum verdict vd = UNNOTICED;
	int ok, li = listed(base);
	enum allow a = li >= 0 ? list.allow[li] : ALLOW_NONE;
	double late, v0;

	assert_non_null(h);
	enter(h, ph);
	bound = (RE_SEAL_SLICES + 1) * dmc_h_var(h, "mainms") + 2;
	v = mg(h, el, &ok);
	if (!ok)
		v = 0; /* not yet assigned in this phase */
	late = dmc_h_var(h, "wdto") + dmc_h_var(h, "mainms");
	v0 = dmc_h_var(h, "vcur");
	where(h, w);
	snprintf(cmd, sizeof(cmd), "%s=%.4f", el, nv);
	if (dmc_h_cmd(h, cmd, NULL, 0) < 0 || (mg(h, el, &ok) == v && ok)) {
		/* the controller refused the value or kept its own (out of
		 * range, a saturated integer) */
		vd = UNCHANGED;
		goto out;
	}
	if (died) {
		if (a != ALLOW_WDTO)
			late = 0;
		t = died_at_write(h);
		if (t < 0 || t > died_ref[ph] + HB_LATE_MS + late)
			fail_msg("'%s' (%g) %s, the supervisor dying at the "
				 "write: the motors went off after %.0f ms "
				 "(without the write: %.0f, allowed %.0f "
				 "later)",
				 cmd, v, phase_name[ph], t, died_ref[ph],
				 HB_LATE_MS + late);
		goto out;
	}
	t = wait_fault(h, bound);
	if (t >= 0)
		vd = names_it(h, el) ? CAUGHT_NAMED : CAUGHT;
	if (verbose)
		print_message("%-10s %-22s %10g -> %-10g %s (fault %g/%g)\n",
			      el, phase_name[ph], v, nv,
			      vd == CAUGHT_NAMED ? "caught, named"
			      : vd == CAUGHT	 ? "caught"
						 : "unnoticed",
			      dmc_h_var(h, "fcode"), dmc_h_var(h, "fdet"));
	if (vd != UNNOTICED)
		goto out;
	if (li < 0)
		fail_msg("'%s' (%g) %s: no fault within %.0f ms, and '%s' is "
			 "not in docs/safety.md's list",
			 cmd, v, phase_name[ph], bound, base);
	finish(h, &o);
	if (!no_worse(&o, &ref[ph], w, a, late,
		      ph == JOGGING
			  ? (ramp_travel(h, v0, WINDOW_MS + bound) * 1.01) +
				POS_TOL
			  : 0,
		      why, sizeof(why)))
		fail_msg("'%s' (%g) %s, unnoticed: %s", cmd, v, phase_name[ph],
			 why);
out:
	dmc_h_close(h);
	free(h);
	return vd;
}

/* Every element of every name the program assigns, in @ph. */
static void every_name(enum phase ph)
{
	struct dmc_h *h = calloc(1, sizeof(*h));
	struct dmc_lint lint = {0};
	int ncases = 0, nnamed = 0, ncaught = 0;

	assert_non_null(h);
	enter(h, ph);
	assert_true(dmc_lint_text(h->prog, h->prog_len, dmc_model_find("40x0"),
				  1, &lint) >= 0);
	assert_true(lint.ntargets > 20);
	for (int k = 0; k < lint.ntargets; k++) {
		const struct dmc_target *tg = &lint.targets[k];
		char el[32];
		double v, nv[CHANGES];
		int ok, n;

		for (int i = 0; i < (tg->array ? ELEM_MAX : 1); i++) {
			if (tg->array)
				snprintf(el, sizeof(el), "%s[%d]", tg->name, i);
			else
				snprintf(el, sizeof(el), "%s", tg->name);
			v = mg(h, el, &ok);
			if (!ok && tg->array)
				break; /* past the array's end */
			if (!ok)
				v = 0; /* not yet assigned in this phase */
			n = changes(v, nv);
			for (int j = 0; j < n; j++) {
				enum verdict vd =
				    one_case(el, tg->name, nv[j], ph, 0);
				int li = listed(tg->name);

				if (vd == UNNOTICED)
					one_case(el, tg->name, nv[j], ph, 1);
				if (vd == UNCHANGED)
					continue;
				ncases++;
				nnamed += vd == CAUGHT_NAMED;
				ncaught += vd != UNNOTICED;
				if (li >= 0) {
					list.tried[li]++;
					list.caught[li] += vd != UNNOTICED;
				}
			}
		}
	}
	print_message("measured: %s, %d writes to %d names: %d caught (%d "
		      "by a fault naming the value), %d unnoticed and "
		      "harmless\n",
		      phase_name[ph], ncases, lint.ntargets, ncaught, nnamed,
		      ncases - ncaught);
	dmc_lint_free(&lint);
	dmc_h_close(h);
	free(h);
}

static int phases_done;

static void test_armed(void **state)
{
	(void)state;
	every_name(ARMED);
	phases_done++;
}

static void test_jogging(void **state)
{
	(void)state;
	every_name(JOGGING);
	phases_done++;
}

static void test_service(void **state)
{
	(void)state;
	every_name(SERVICE);
	phases_done++;
}

static void test_moving(void **state)
{
	(void)state;
	every_name(MOVING);
	phases_done++;
}

/* The list is the program's: each name is one the program assigns, and
 * one that some write leaves uncaught (else it belongs to the caught). */
static void test_list_held(void **state)
{
	struct dmc_h *h = calloc(1, sizeof(*h));
	struct dmc_lint lint = {0};
	char why[256] = "";

	(void)state;
	assert_non_null(h);
	enter(h, ARMED);
	assert_true(dmc_lint_text(h->prog, h->prog_len, dmc_model_find("40x0"),
				  1, &lint) >= 0);
	for (int i = 0; i < list.n && !why[0]; i++) {
		int k;

		for (k = 0; k < lint.ntargets; k++)
			if (!strcmp(lint.targets[k].name, list.name[i]))
				break;
		if (k == lint.ntargets)
			snprintf(why, sizeof(why),
				 "docs/safety.md lists '%s', which the "
				 "program does not assign",
				 list.name[i]);
		/* with a part of the values (make asan) a listed name may
		 * be caught every time: only the full set says it is stale */
		else if (phases_done == PHASES && values_tried == CHANGES &&
			 list.tried[i] && list.caught[i] == list.tried[i])
			snprintf(why, sizeof(why),
				 "docs/safety.md lists '%s' as unnoticed, and "
				 "all %d writes of it were caught",
				 list.name[i], list.tried[i]);
	}
	dmc_lint_free(&lint);
	dmc_h_close(h);
	free(h);
	if (why[0])
		fail_msg("%s", why);
	assert_int_equal(phases_done, PHASES);
}

static int group_setup(void **state)
{
	const char *t = getenv("ROBOELF_TOP");

	(void)state;
	snprintf(top, sizeof(top), "%s", t && *t ? t : ".");
	verbose = getenv("HOSTILE_LIST") != NULL;
	read_list();
	for (int ph = 0; ph < PHASES; ph++) {
		struct dmc_h *h = calloc(1, sizeof(*h));

		if (!h)
			return -1;
		enter(h, (enum phase)ph);
		/* as long as a write that is not caught waits for a fault */
		dmc_h_advance(h, (RE_SEAL_SLICES + 1) * dmc_h_var(h, "mainms") +
				     2);
		finish(h, &ref[ph]);
		dmc_h_close(h);
		enter(h, (enum phase)ph);
		died_ref[ph] = died_at_write(h);
		dmc_h_close(h);
		free(h);
		if (ref[ph].off_ms < 0 || died_ref[ph] < 0)
			return -1;
	}
	return 0;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_armed),     cmocka_unit_test(test_jogging),
	    cmocka_unit_test(test_service),   cmocka_unit_test(test_moving),
	    cmocka_unit_test(test_list_held),
	};

	return cmocka_run_group_tests(tests, group_setup, NULL);
}
