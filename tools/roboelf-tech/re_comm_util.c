/*
 * re_comm_util.c - what the commissioning run's steps share: the report
 * items and the small controller helpers (re_comm_util.h).
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "gl_err.h"
#include "re_comm_util.h"

enum re_comm_res re_comm_add(struct re_comm *c, const char *step,
			     const char *name, enum re_comm_res res,
			     const char *fix, const char *fmt, ...)
{
	struct re_comm_item *it;
	va_list ap;

	if (c->n >= RE_COMM_ITEMS)
		return res;
	it = &c->item[c->n++];
	snprintf(it->step, sizeof(it->step), "%s", step);
	snprintf(it->name, sizeof(it->name), "%s", name);
	it->res = res;
	snprintf(it->fix, sizeof(it->fix), "%s", fix ? fix : "");
	va_start(ap, fmt);
	vsnprintf(it->text, sizeof(it->text), fmt, ap);
	va_end(ap);
	if (res == RE_COMM_FAIL && !c->failed_step)
		c->failed_step = it->step;
	return res;
}

void rc_say(struct re_comm *c, const char *fmt, ...)
{
	char line[512];
	va_list ap;
	int n = snprintf(line, sizeof(line), "%s", RC_PROMPT);

	va_start(ap, fmt);
	vsnprintf(line + n, sizeof(line) - (size_t)n, fmt, ap);
	va_end(ap);
	if (c->ui.say)
		c->ui.say(c->ui.ud, line);
}

int rc_cmd(struct re_comm *c, const char *cmd, char *resp, size_t cap)
{
	char dummy[64];

	if (!resp) {
		resp = dummy;
		cap = sizeof(dummy);
	}
	return c->io->ops->command(c->io->ud, cmd, resp, cap, 0);
}

const char *rc_tc(struct re_comm *c, int *code)
{
	return c->io->ops->ctrl_error(c->io->ud, code);
}

int rc_num(struct re_comm *c, const char *expr, double *v)
{
	return re_io_read(c->io, expr, v, 0);
}

int rc_quit(const struct re_comm *c)
{
	return c->quit && *c->quit;
}

double rc_now_ms(struct re_comm *c)
{
	return (double)c->io->ops->now_ns(c->io->ud) / 1e6;
}

void rc_sleep_ms(struct re_comm *c, int ms)
{
	int64_t t = c->io->ops->now_ns(c->io->ud) + (int64_t)ms * 1000000;
	char hb[32];

	if (c->guard) { /* alive for #PRWD (dmc/roboelf.dmc) */
		c->hbpc = (c->hbpc + 1) % RE_HBPC_WRAP;
		snprintf(hb, sizeof(hb), "hbpc=%ld", c->hbpc);
		rc_cmd(c, hb, NULL, 0);
	}
	c->io->ops->sleep_until(c->io->ud, t);
}

int rc_guard(struct re_comm *c, int on)
{
	int rc;

	if (!on) {
		c->guard = 0;
		return rc_cmd(c, "HX0", NULL, 0) < 0 ? GL_ERR_CTRL : GL_OK;
	}
	rc = rc_cmd(c, "XQ #PRWD,0", NULL, 0);
	if (rc < 0)
		return rc;
	c->guard = 1;
	rc_sleep_ms(c, 20); /* #PRWD sets its constants, then watches */
	rc_sleep_ms(c, 20);
	return GL_OK;
}

int rc_link_fail(struct re_comm *c, const char *step, const char *what, int rc)
{
	int code = 0;
	const char *tc = rc == GL_ERR_CTRL ? rc_tc(c, &code) : "";

	if (rc == GL_ERR_CTRL)
		re_comm_add(c, step, "controller", RE_COMM_FAIL,
			    "read the command reference for that error; check "
			    "the model and firmware of the controller",
			    "%s: the controller refused it: %d %s", what, code,
			    tc);
	else
		re_comm_add(c, step, "link", RE_COMM_FAIL,
			    "check the Ethernet cable and the controller's "
			    "power, then run the commissioning again",
			    "%s: %s", what, gl_strerror(rc));
	return rc;
}

int rc_safe(struct re_comm *c)
{
	int pout = c->cfg->controller.power_output;
	int rc = rc_cmd(c, RE_STOP_ALL, NULL, 0);
	int rr = c->io->ops->relay_off(c->io->ud);
	char cb[16];

	/* the motor-power output the motion step set (SB n) is cleared too,
	 * so that the power chain is open twice, not once */
	snprintf(cb, sizeof(cb), "CB %d", pout);
	if (pout > 0 && rc_cmd(c, cb, NULL, 0) < 0 && rc >= 0)
		rc = GL_ERR_CTRL;
	return rc < 0 ? rc : rr;
}

void rc_lane_start(struct re_comm *c, struct re_comm_lanes *l)
{
	memset(l, 0, sizeof(*l));
	l->t0_ms = rc_now_ms(c);
}

void rc_lane_mark(struct re_comm *c, struct re_comm_lanes *l, unsigned mask)
{
	l->end_ms = rc_now_ms(c) - l->t0_ms;
	if (l->n < RE_COMM_LANE_N && (l->n == 0 || l->mask[l->n - 1] != mask)) {
		l->t_ms[l->n] = l->end_ms;
		l->mask[l->n++] = mask;
	}
}

void rc_lane_ask(struct re_comm *c, struct re_comm_lanes *l, const char *what)
{
	if (l->n_ask >= RE_COMM_ASK_N)
		return;
	l->ask_ms[l->n_ask] = rc_now_ms(c) - l->t0_ms;
	snprintf(l->ask[l->n_ask++], sizeof(l->ask[0]), "%s", what);
}

void rc_text_put(struct rc_text *b, const char *fmt, ...)
{
	va_list ap;
	int k;

	if (b->n >= b->cap)
		return;
	va_start(ap, fmt);
	k = vsnprintf(b->p + b->n, b->cap - b->n, fmt, ap);
	va_end(ap);
	b->n = k < 0 ? b->cap : b->n + (size_t)k;
}
