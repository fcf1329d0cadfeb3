/*
 * sys_truth.c - roboelf's stated facts against galil-sim's event log. See
 * sys_truth.h.
 */
#include "sys_truth.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "proc.h"
#include "sys_h.h"

#define WAIT_MS 1000 /* for the log to show a fact roboelf stated */

static void facts_init(struct sys_facts *f)
{
	memset(f, 0, sizeof(*f));
	f->stop_ms = -1;
}

/* ---- what roboelf said ---------------------------------------------------
 */

/* "axis X:" or "axis X " at @p: X, else 0. */
static char axis_at(const char *p)
{
	if (strncmp(p, "axis ", 5) || p[5] < 'A' || p[5] > 'H' ||
	    (p[6] != ':' && p[6] != ' '))
		return 0;
	return p[5];
}

/* The confirmation's clauses (re_react.c confirm_text()). */
static void said_confirm(const char *line, struct sys_facts *o)
{
	if (strstr(line, " Safe state confirmed: motor power off (relay "
			 "open), motors off.")) {
		o->relay_open = o->power_off = SYS_YES;
		o->motors_off = o->delivered = SYS_YES;
		return;
	}
	if (strstr(line, " motor power off (relay open) confirmed;"))
		o->relay_open = o->power_off = SYS_YES;
	if (strstr(line, " stop command not delivered"))
		o->delivered = SYS_NO;
	if (strstr(line, " the controller answered the stop command with "
			 "an error (?);"))
		o->delivered = SYS_YES;
	if (strstr(line, " motors off confirmed;"))
		o->motors_off = o->delivered = SYS_YES;
}

/* The log entry's "| controller stop: delivered (1.2 ms) |". */
static void said_log(const char *entry, struct sys_facts *o)
{
	const char *p = strstr(entry, "| controller stop: ");
	const char *ms;

	if (!p)
		return;
	p += strlen("| controller stop: ");
	if (!strncmp(p, "delivered", 9) && o->delivered == SYS_UNKNOWN)
		o->delivered = SYS_YES;
	else if (!strncmp(p, "not delivered", 13) &&
		 o->delivered == SYS_UNKNOWN)
		o->delivered = SYS_NO;
	ms = strstr(p, " ms)");
	if (ms && (!strchr(p, '|') || ms < strchr(p, '|'))) {
		const char *q = ms;

		while (q > p && q[-1] != '(')
			q--;
		o->stop_ms = strtod(q, NULL);
	}
}

int sys_truth_said(const char *line, const char *log_entry,
		   struct sys_facts *out)
{
	const char *p = strstr(line ? line : "", "FAULT "), *colon, *then;

	facts_init(out);
	if (!p)
		return -1;
	p += 6;
	colon = strstr(p, ": ");
	if (!colon || colon - p >= (long)sizeof(out->cls))
		return -1;
	snprintf(out->cls, sizeof(out->cls), "%.*s", (int)(colon - p), p);
	out->axis = axis_at(colon + 2);
	then = strstr(colon, " Then: ");
	if (then)
		out->then_axis = axis_at(then + 7);
	said_confirm(line, out);
	if (log_entry)
		said_log(log_entry, out);
	return 0;
}

/* One status line's ctrl="...": its text, and the axis a FAULT names. */
static void said_ctrl(const char *l, size_t n, struct sys_facts *o)
{
	const char *q = strstr(l, " ctrl=\""), *e, *ax;

	if (!q || q >= l + n)
		return;
	q += 7;
	e = strchr(q, '"');
	if (!e || e > l + n)
		return;
	snprintf(o->ctrl_text, sizeof(o->ctrl_text), "%.*s", (int)(e - q), q);
	ax = strstr(o->ctrl_text, " axis ");
	if (!strncmp(o->ctrl_text, "FAULT ", 6) && ax && ax[6] >= 'A' &&
	    ax[6] <= 'H' && ax[7] == ' ')
		o->ctrl_axis = ax[6];
}

/* The line after the one at @p, or NULL. */
static const char *next_line(const char *p)
{
	const char *nl = strchr(p, '\n');

	return nl ? nl + 1 : NULL;
}

void sys_truth_said_status(const char *stdout_text, struct sys_facts *out)
{
	const char *p = stdout_text;

	while (p && *p && strncmp(p, "FAULT ", 6))
		p = next_line(p);
	for (; p && *p && !out->ctrl_axis; p = next_line(p)) {
		const char *nl = strchr(p, '\n');

		if (!strncmp(p, "status ", 7))
			said_ctrl(p, nl ? (size_t)(nl - p) : strlen(p), out);
	}
}

/* ---- what galil-sim recorded -------------------------------------------- */

/* The class a fault injected this way is reported in, "" when it depends. */
static const char *inject_class(const char *what)
{
	if (!strncmp(what, "pot ", 4))
		return "ENCODER";
	if (!strncmp(what, "limit ", 6))
		return "LIMIT";
	return "";
}

/* "inject: pot B offset 0.5": the axis the injection names. */
static void true_inject(const char *text, struct sys_facts *o)
{
	const char *w = text + strlen("inject: ");
	const char *sp = strchr(w, ' ');

	if (o->first_ev[0] || !sp)
		return;
	snprintf(o->first_ev, sizeof(o->first_ev), "%s", text);
	snprintf(o->cls, sizeof(o->cls), "%s", inject_class(w));
	if ((!strncmp(w, "pot ", 4) || !strncmp(w, "enc ", 4) ||
	     !strncmp(w, "block ", 6) || !strncmp(w, "limit ", 6)) &&
	    sp[1] >= 'A' && sp[1] <= 'H' && (sp[2] == ' ' || !sp[2]))
		o->axis = sp[1];
}

/* The handle letter of "(handle B)" in @text, or 0. */
static char handle_of(const char *text)
{
	const char *h = strstr(text, "(handle ");

	return h && h[8] >= 'A' && h[8] <= 'H' && h[9] == ')' ? h[8] : 0;
}

/* An event that shows a host's stop arriving: "AB 1 received (handle
 * B)", "MO received (handle B)", an axis aborted or switched off by a
 * handle. */
static void true_stop(const char *text, unsigned foreign, struct sys_facts *o)
{
	char h = handle_of(text);

	if (!h || (foreign >> (h - 'A') & 1) || o->stop_ev[0])
		return;
	if (!strncmp(text, "AB ", 3) || !strncmp(text, "MO received", 11) ||
	    (!strncmp(text, "axis ", 5) &&
	     (strstr(text, " abort: AB (") || strstr(text, " motor off: "))))
		snprintf(o->stop_ev, sizeof(o->stop_ev), "%s", text);
}

/* One event at @t: the state it changes, and the window's facts. */
static void true_event(double t, const char *text, double after,
		       unsigned foreign, struct sys_facts *o, int motor[8])
{
	int in = t >= after;
	char ax = axis_at(text);

	if (!strncmp(text, "relay on", 8))
		o->relay_open = SYS_NO;
	else if (!strncmp(text, "relay off", 9))
		o->relay_open = SYS_YES;
	else if (!strncmp(text, "amplifier power lost", 20))
		o->power_off = SYS_YES;
	else if (!strncmp(text, "amplifier power restored", 24))
		o->power_off = SYS_NO;
	else if (in && !strncmp(text, "inject: ", 8))
		true_inject(text, o);
	if (!strcmp(text, "power cycle")) /* the DMC starts motors off */
		for (int i = 0; i < 8; i++)
			motor[i] = motor[i] ? 2 : 0;
	if (ax && strstr(text, " motor on: "))
		motor[ax - 'A'] = 1;
	if (ax && strstr(text, " motor off: ")) {
		motor[ax - 'A'] = 2;
		if (in && !handle_of(text) && !strchr(o->self_off, ax) &&
		    strlen(o->self_off) < sizeof(o->self_off) - 1)
			strncat(o->self_off, &ax, 1);
	}
	if (in)
		true_stop(text, foreign, o);
}

int sys_truth_true(const char *events, double after_ms, double until_ms,
		   unsigned foreign, struct sys_facts *out)
{
	int motor[8] = {0}; /* 0 never seen, 1 on, 2 off */
	const char *p = events, *end;
	char text[SYS_TRUTH_TEXT];

	facts_init(out);
	for (; p && *p; p = end) {
		char *rest;
		double t = strtod(p, &rest);
		const char *nl = strchr(p, '\n');

		end = nl ? nl + 1 : p + strlen(p);
		if (rest == p || *rest != ' ')
			return -1;
		if (until_ms >= 0 && t > until_ms)
			break;
		snprintf(text, sizeof(text), "%.*s",
			 (int)(end - rest - 1 - !!nl), rest + 1);
		true_event(t, text, after_ms, foreign, out, motor);
	}
	out->delivered = out->stop_ev[0] ? SYS_YES : SYS_NO;
	for (int i = 0; i < 8; i++) {
		if (motor[i] == 1)
			out->motors_off = SYS_NO;
		else if (motor[i] == 2 && out->motors_off == SYS_UNKNOWN)
			out->motors_off = SYS_YES;
	}
	return 0;
}

/* ---- the comparison ------------------------------------------------------
 */

static const char *tri(enum sys_tri v)
{
	return v == SYS_YES ? "yes" : v == SYS_NO ? "no" : "unknown";
}

static int add(char *buf, size_t cap, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static int add(char *buf, size_t cap, const char *fmt, ...)
{
	size_t n = strlen(buf);
	va_list ap;

	if (n + 1 >= cap)
		return 1;
	va_start(ap, fmt);
	vsnprintf(buf + n, cap - n, fmt, ap);
	va_end(ap);
	return 1;
}

static int cmp_tri(const char *fact, enum sys_tri said, enum sys_tri truth,
		   const char *ev, char *buf, size_t cap)
{
	if (said == SYS_UNKNOWN || truth == SYS_UNKNOWN || said == truth)
		return 0;
	return add(buf, cap,
		   "%s: roboelf printed %s, galil-sim recorded %s%s%s%s\n",
		   fact, tri(said), tri(truth), ev && ev[0] ? " (" : "",
		   ev ? ev : "", ev && ev[0] ? ")" : "");
}

int sys_truth_compare(const struct sys_facts *said,
		      const struct sys_facts *truth, char *buf, size_t cap)
{
	int n = 0;

	buf[0] = '\0';
	if (truth->cls[0] && said->cls[0] && strcmp(said->cls, truth->cls))
		n += add(buf, cap,
			 "fault class: roboelf printed %s, galil-sim recorded "
			 "%s (%s)\n",
			 said->cls, truth->cls, truth->first_ev);
	if (truth->axis && said->axis && said->axis != truth->axis)
		n += add(buf, cap,
			 "first cause's axis: roboelf printed %c, galil-sim "
			 "recorded %c (%s)\n",
			 said->axis, truth->axis, truth->first_ev);
	if (said->then_axis && !strchr(truth->self_off, said->then_axis))
		n += add(buf, cap,
			 "consequence on axis %c: roboelf printed that the "
			 "controller switched it off, galil-sim recorded no "
			 "motor off on %c but by a host's command (by itself: "
			 "'%s')\n",
			 said->then_axis, said->then_axis, truth->self_off);
	if (said->ctrl_axis && said->ctrl_axis != truth->axis &&
	    !strchr(truth->self_off, said->ctrl_axis))
		n += add(buf, cap,
			 "the controller's fault: roboelf printed '%s', "
			 "galil-sim recorded the first cause %s%c (%s) and no "
			 "motor off on %c but by a host's command\n",
			 said->ctrl_text, truth->axis ? "on " : "",
			 truth->axis ? truth->axis : '-', truth->first_ev,
			 said->ctrl_axis);
	n += cmp_tri("stop command delivered", said->delivered,
		     truth->delivered, truth->stop_ev, buf, cap);
	n += cmp_tri("relay open", said->relay_open, truth->relay_open, NULL,
		     buf, cap);
	n += cmp_tri("motor power off", said->power_off, truth->power_off, NULL,
		     buf, cap);
	n += cmp_tri("every motor off", said->motors_off, truth->motors_off,
		     NULL, buf, cap);
	return n;
}

/* ---- on a running case -------------------------------------------------- */

char *sys_truth_events(const struct sys_case *c)
{
	size_t cap = c->nev * (SYS_EVT_TEXT + 24) + 1, n = 0;
	char *buf = malloc(cap);

	if (!buf)
		return NULL;
	buf[0] = '\0';
	for (size_t i = 0; i < c->nev; i++)
		n += (size_t)snprintf(buf + n, cap - n, "%.3f %s\n",
				      c->ev[i].t_ms, c->ev[i].text);
	return buf;
}

/* Compare once; @msg gets the mismatches. Return: their number, -1. */
static int check_once(struct sys_case *c, const struct sys_facts *said,
		      double after_ms, unsigned foreign, char *msg, size_t cap)
{
	struct sys_facts truth;
	char *ev;
	int n;

	if (sys_events(c) < 0)
		return -1;
	if (!(ev = sys_truth_events(c))) {
		snprintf(c->err, SYS_ERR_MAX, "truth: out of memory");
		return -1;
	}
	n = sys_truth_true(ev, after_ms, -1, foreign, &truth);
	free(ev);
	if (n < 0) {
		snprintf(c->err, SYS_ERR_MAX, "truth: a bad event line");
		return -1;
	}
	return sys_truth_compare(said, &truth, msg, cap);
}

int sys_truth_check(struct sys_case *c, const char *line, double after_ms,
		    unsigned foreign)
{
	char entry[4096], msg[1024];
	struct sys_facts said;
	long long deadline = proc_now_ms() + WAIT_MS;
	int n;

	if (sys_log_find(c, " FAULT ", line, entry, sizeof(entry)) < 0)
		entry[0] = '\0';
	if (sys_truth_said(line, entry[0] ? entry : NULL, &said) < 0) {
		snprintf(c->err, SYS_ERR_MAX, "truth: not a FAULT line: %s",
			 line);
		return -1;
	}
	sys_truth_said_status(proc_output(&c->re, PROC_STDOUT), &said);
	/* handles opened after Ready and before the fault: the test's own
	 * clients (roboelf opens a new one only to stop); before Ready (a
	 * fault in the start-up) roboelf's own are opening */
	if (c->t_ready_ms > 0)
		foreign |= sys_truth_foreign(c, c->t_ready_ms, after_ms);
	while ((n = check_once(c, &said, after_ms, foreign, msg, sizeof(msg))) >
		   0 &&
	       proc_now_ms() < deadline)
		usleep(15000);
	if (n < 0) /* c->err says why */
		return -1;
	if (n == 0)
		return 0;
	snprintf(c->err, SYS_ERR_MAX,
		 "truth: roboelf stated %d fact(s) that galil-sim's log "
		 "contradicts:\n%.500s  FAULT line: %.400s",
		 n, msg, line);
	return -1;
}

unsigned sys_truth_foreign(const struct sys_case *c, double from_ms,
			   double to_ms)
{
	unsigned m = 0;

	for (size_t i = 0; i < c->nev; i++) {
		const char *t = c->ev[i].text;

		if (c->ev[i].t_ms >= from_ms && c->ev[i].t_ms <= to_ms &&
		    !strncmp(t, "handle ", 7) && t[7] >= 'A' && t[7] <= 'H' &&
		    !strncmp(t + 8, " opened", 7))
			m |= 1u << (t[7] - 'A');
	}
	return m;
}
