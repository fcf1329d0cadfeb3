/*
 * test_ctrl_util.h - a trivial plant around ctrl.h for the controller
 * tests: the encoder follows the reference while the motor is on (unless
 * the test freezes it), limit switches and inputs are set by the test.
 * Events are kept so tests can assert on them.
 */
#ifndef TEST_CTRL_UTIL_H
#define TEST_CTRL_UTIL_H

#include <stdio.h>
#include <string.h>

#include "ctrl.h"
#include "gl_err.h"

#define TP_EVENTS 256

struct tplant {
	struct ctrl *c;
	struct ctrl_sense in;
	struct ctrl_drive out;
	int frozen[CTRL_AXES]; /* encoder stuck */
	char events[TP_EVENTS][200];
	int nevents;
	long samples;
};

static inline void tp_event(void *ud, const char *line)
{
	struct tplant *p = ud;

	if (p->nevents < TP_EVENTS)
		snprintf(p->events[p->nevents++], sizeof(p->events[0]), "%s",
			 line);
}

static inline int tp_init(struct tplant *p)
{
	struct ctrl_cfg cfg;

	memset(p, 0, sizeof(*p));
	memset(&cfg, 0, sizeof(cfg));
	cfg.model = "DMC4030 Rev 1.2h-sim";
	cfg.serial = 4242;
	cfg.sample_us = 1000;
	cfg.event = tp_event;
	cfg.event_ud = p;
	p->c = ctrl_new(&cfg);
	p->in.amp_power = 1;
	return p->c ? 0 : -1;
}

static inline void tp_free(struct tplant *p)
{
	ctrl_free(p->c);
	p->c = NULL;
}

/* Run @n servo samples; the encoder of a powered motor follows. */
static inline void tp_step(struct tplant *p, int n)
{
	int i, a;

	for (i = 0; i < n; i++) {
		ctrl_step(p->c, &p->in, &p->out);
		p->samples++;
		for (a = 0; a < CTRL_AXES; a++)
			if (p->out.motor_on[a] && p->in.amp_power &&
			    !p->frozen[a])
				p->in.enc[a] = p->out.ref[a];
	}
}

/* One command line; the reply (without the final ':') into @resp. */
static inline int tp_cmd(struct tplant *p, const char *line, char *resp,
			 size_t cap)
{
	return ctrl_command(p->c, line, resp, cap);
}

/* The value printed by "MG expr". */
static inline double tp_mg(struct tplant *p, const char *expr)
{
	char line[100], resp[200];
	double v = -99999;

	snprintf(line, sizeof(line), "MG %s", expr);
	if (ctrl_command(p->c, line, resp, sizeof(resp)) == GL_OK)
		sscanf(resp, "%lf", &v);
	return v;
}

static inline int tp_tc(struct tplant *p)
{
	return (int)tp_mg(p, "_TC");
}

static inline int tp_load(struct tplant *p, const char *prog)
{
	int bad = 0;

	return ctrl_download(p->c, prog, strlen(prog), &bad);
}

/* Run until expression @cond (MG) is non-zero, at most @max samples. */
static inline long tp_until(struct tplant *p, const char *cond, long max)
{
	long n;

	for (n = 0; n < max; n++) {
		if (tp_mg(p, cond) != 0)
			return n;
		tp_step(p, 1);
	}
	return -1;
}

static inline int tp_has_event(const struct tplant *p, const char *needle)
{
	int i;

	for (i = 0; i < p->nevents; i++)
		if (strstr(p->events[i], needle))
			return 1;
	return 0;
}

/* Everything waiting on handle @h, as a C string (binary-safe length). */
static inline size_t tp_out(struct tplant *p, int h, char *buf, size_t cap)
{
	size_t n = ctrl_output(p->c, h, (uint8_t *)buf, cap - 1);

	buf[n] = '\0';
	return n;
}

static inline void tp_send(struct tplant *p, int h, const char *s)
{
	ctrl_input(p->c, h, (const uint8_t *)s, strlen(s));
}

#endif /* TEST_CTRL_UTIL_H */
