/*
 * re_calib_move.c - what every phase of the calibration is made of: its
 * faults, the supervised sample and what it says of an axis, and the
 * service moves (queued, sent together, taken by the controller program).
 */
#include "re_calib_int.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"
#include "re_pot.h"

int cal_abort(struct re_fault *f, int axis, const char *fmt, ...)
{
	va_list ap;

	re_fault_set(f, RE_F_CAL_ABORT, axis);
	va_start(ap, fmt);
	vsnprintf(f->s, sizeof(f->s), fmt, ap);
	va_end(ap);
	return RE_FAULT;
}

int cal_comm_fault(struct re_fault *f, const char *what, int rc)
{
	re_fault_set(f, RE_F_COMM, -1);
	snprintf(f->s, sizeof(f->s), "%s: %s", what, gl_strerror(rc));
	return RE_FAULT;
}

int64_t cal_now_ns(const struct re_io *io)
{
	return io->ops->now_ns(io->ud);
}

static int send(struct re_calib *c, const struct re_io *io,
		const struct re_calib_cfg *cfg, struct re_fault *f)
{
	int rc = io->ops->command(io->ud, c->line, c->resp, sizeof(c->resp),
				  cfg->cmd_timeout_ms);

	if (rc == GL_ERR_CTRL) {
		re_fault_set(f, RE_F_CAL_ABORT, -1);
		snprintf(f->s, sizeof(f->s), "the controller refused '%s': %s",
			 c->line, io->ops->ctrl_error(io->ud, NULL));
		return RE_FAULT;
	}
	if (rc == GL_ERR_TIMEOUT) {
		/* no reply within the command's deadline: the same cause as a
		 * record without reply in the cycle (a stalled link), named
		 * the same way */
		re_fault_set(f, RE_F_WDOG_REPLY, -1);
		f->i[0] = cfg->cmd_timeout_ms;
		f->i[1] = cfg->cmd_timeout_ms;
		return RE_FAULT;
	}
	return rc < 0 ? cal_comm_fault(f, "command failed", rc) : GL_OK;
}

/* The next supervised sample. A fault the sampler latched is passed on
 * as RE_F_NONE (the supervisor reacted to it already). */
int cal_sample(struct re_calib *c, const struct re_calib_cfg *cfg,
	       struct re_fault *f)
{
	int rc;

	if (cfg->stop && *cfg->stop)
		return GL_ERR_AGAIN;
	c->taken_now = 0; /* this record follows every acceptance so far */
	rc = cfg->sampler.sample(cfg->sampler.ud, &c->rec);
	if (rc == RE_FAULT)
		re_fault_set(f, RE_F_NONE, -1);
	else if (rc == GL_OK && c->rec->n_axes < cfg->n_axes)
		return cal_comm_fault(f, "data record", GL_ERR_RECORD);
	return rc;
}

double cal_enc(const struct re_calib *c, int i)
{
	return c->rec->axis[i].motor_pos;
}

double cal_pot(const struct re_calib *c, const struct re_calib_cfg *cfg, int i)
{
	return re_pot_of(c->rec, i, cfg->axis[i].pot_input);
}

int cal_moving(const struct re_calib *c, int i)
{
	return !!(c->rec->axis[i].status & GL_AXST_MOVING);
}

int cal_rev_switch(const struct re_calib *c, int i)
{
	return !(c->rec->axis[i].switches & GL_AXSW_RLS);
}

int cal_fwd_switch(const struct re_calib *c, int i)
{
	return !(c->rec->axis[i].switches & GL_AXSW_FLS);
}

/* Queue a move of axis i to @target at @speed (sent by cal_send_batch()). */
void cal_move_to(struct re_calib *c, int i, double target, int speed)
{
	c->b.mask |= 1u << i;
	c->b.tgt[i] = lround(target);
	c->b.sp[i] = speed;
}

static int append(char *line, size_t cap, const char *item)
{
	if (strlen(line) + strlen(item) + 1 > cap - 1)
		return -1;
	if (line[0])
		strcat(line, ";");
	strcat(line, item);
	return 0;
}

/* Send the queued moves: the targets and speeds, then the request. The
 * program takes it in its next pass (mvreq back to 0); cal_taken() asks at
 * every following sample, so the cycle stays periodic meanwhile. */
int cal_send_batch(struct re_calib *c, const struct re_io *io,
		   const struct re_calib_cfg *cfg, struct re_fault *f)
{
	char item[48];
	int rc = GL_OK;

	if (!c->b.mask || c->pending)
		return GL_OK;
	c->line[0] = '\0';
	for (int i = 0; rc == GL_OK && i < RE_AXES; i++) {
		if (!(c->b.mask >> i & 1))
			continue;
		snprintf(item, sizeof(item), "mvtg[%d]=%ld;mvsp[%d]=%d", i,
			 c->b.tgt[i], i, c->b.sp[i]);
		if (append(c->line, sizeof(c->line), item) < 0) {
			rc = send(c, io, cfg, f);
			snprintf(c->line, sizeof(c->line), "%s", item);
		}
	}
	if (rc == GL_OK && c->line[0])
		rc = send(c, io, cfg, f);
	snprintf(c->line, sizeof(c->line),
		 "mvax[0]=%u;mvax[1]=%u;mvax[2]=%u;"
		 "mvreq=1",
		 c->b.mask & 1, c->b.mask >> 1 & 1, c->b.mask >> 2 & 1);
	if (rc == GL_OK)
		rc = send(c, io, cfg, f);
	c->pending = c->b.mask;
	c->sent_ns = cal_now_ns(io);
	c->b.mask = 0;
	return rc;
}

/* Is the sent request taken? A refused one is a fault the program
 * latched: the supervisor's next sample reports it. */
int cal_taken(struct re_calib *c, const struct re_io *io,
	      const struct re_calib_cfg *cfg, struct re_fault *f)
{
	double req = 1;
	int rc;

	if (!c->pending)
		return GL_OK;
	rc = re_io_read(io, "mvreq", &req, cfg->cmd_timeout_ms);
	if (rc < 0)
		return cal_comm_fault(f, "move request", rc);
	if (req == 0) {
		c->taken_now = c->pending;
		c->pending = 0;
		return GL_OK;
	}
	if (cal_now_ns(io) - c->sent_ns >
	    (int64_t)cfg->accept_ms * BASE_NS_PER_MS)
		return cal_abort(f, -1,
				 "the controller program did not take a move "
				 "request within %d ms",
				 cfg->accept_ms);
	return GL_OK;
}

/* An axis with a move queued, not yet taken, or taken only after the
 * record in hand was read: that record does not show the move, so its
 * phase must not judge it (it would see "stopped" before the start). */
int cal_waiting(const struct re_calib *c, int i)
{
	return ((c->b.mask | c->pending | c->taken_now) >> i) & 1;
}

int cal_enter(struct re_calib *c, const struct re_io *io, int i, enum phase ph)
{
	c->ax[i].ph = ph;
	c->ax[i].t_phase_ns = cal_now_ns(io);
	c->ax[i].have_edge = 0;
	return GL_OK;
}

void cal_own(const struct re_calib_cfg *cfg, unsigned mask)
{
	if (cfg->sampler.own)
		cfg->sampler.own(cfg->sampler.ud, mask);
}

void cal_use_tables(const struct re_calib_cfg *cfg, const struct re_calset *set)
{
	if (cfg->sampler.tables)
		cfg->sampler.tables(cfg->sampler.ud, set);
}
