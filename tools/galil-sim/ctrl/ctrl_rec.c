/*
 * ctrl_rec.c - the QR data record of a DMC-4030 (galil-notes.md 2.2-2.3),
 * encoded with gl_record_encode() from pc/galil/gl_record.h.
 *
 * Amplifier status (bytes 52-55) follows GalilSup's reading: byte 55 is
 * _TA0 (bit 3 = under-voltage A-D, set while motor power is off), byte 52
 * _TA3 (ELO); the other bytes stay 0.
 */
#include <math.h>
#include <string.h>

#include "ctrl_rec.h"
#include "ctrl_motion.h"
#include "gl_record.h"

static int32_t clamp32(double v)
{
	if (v > 2147483647.0)
		return INT32_MAX;
	if (v < -2147483648.0)
		return INT32_MIN;
	return (int32_t)llround(v);
}

static uint16_t axis_status(const struct ctrl_axis *a)
{
	uint16_t s = 0;

	if (a->profiling) {
		s |= GL_AXST_MOVING;
		if (a->mode == CTRL_MODE_PA || a->mode == CTRL_MODE_PR ||
		    a->mode == CTRL_MODE_PT)
			s |= GL_AXST_MODE_PAPR;
		if (a->mode == CTRL_MODE_PA || a->mode == CTRL_MODE_PT)
			s |= GL_AXST_MODE_PA;
		if (a->vel < 0)
			s |= 1u << 7;
		if (a->stopping)
			s |= GL_AXST_STOPPING;
		else if (fabs(a->vel) >= a->p.sp && a->p.sp > 0)
			s |= 1u << 5; /* slewing */
	}
	if (a->p.motor_off)
		s |= GL_AXST_MOTOR_OFF;
	return s;
}

static void axis_fill(const struct ctrl *c, int i, struct gl_rec_axis *r)
{
	const struct ctrl_axis *a = &c->ax[i];
	uint8_t sw = GL_AXSW_HOME;
	double an = c->in.an_v[i] * 3276.8; /* AQ2: +-10 V = +-32768 */

	if (!a->lim_f)
		sw |= GL_AXSW_FLS;
	if (!a->lim_r)
		sw |= GL_AXSW_RLS;
	r->status = axis_status(a);
	r->switches = sw;
	r->stop_code = (uint8_t)a->stop_code;
	r->ref_pos = clamp32(a->ref);
	r->motor_pos = clamp32(a->enc);
	r->pos_err = r->ref_pos - r->motor_pos;
	r->aux_pos = 0;
	r->velocity = clamp32(64 * ctrl_axis_tv(a, ctrl_dt(c)));
	r->torque = clamp32(a->torque / 10.0 * 32767);
	r->analog_in = (int32_t)fmax(-32768, fmin(32767, round(an)));
	r->hall = 0;
	r->za = clamp32(trunc(a->za));
	if (c->cfg.deviate & CTRL_DEV_ZA_16BIT)
		r->za = (int16_t)(uint16_t)((uint32_t)r->za & 0xffffu);
}

/* ctrl_record() - QR into @buf. Return its length or a negative gl_err. */
int ctrl_record(struct ctrl *c, uint8_t *buf, size_t cap)
{
	struct gl_record r;
	int i, n;

	memset(&r, 0, sizeof(r));
	r.layout = GL_LAYOUT_4000;
	r.n_axes = CTRL_AXES;
	r.sample = (uint16_t)(c->time & 0xFFFF);
	for (i = 0; i < 4; i++) {
		r.inputs[i] = (uint8_t)(c->in.inputs >> (8 * i));
		r.outputs[i] = (uint8_t)(c->outputs >> (8 * i));
	}
	for (i = 0; i < CTRL_HANDLES; i++)
		r.handles[i] = c->h[i].open ? (c->h[i].udp ? 1 : 2) : 0;
	r.error_code = (uint8_t)c->tc;
	for (i = 0; i < CTRL_THREADS; i++)
		if (c->th[i].running)
			r.threads |= (uint8_t)(1u << i);
	r.amp_status = (uint32_t)c->ta0 << 24;
	for (i = 0; i < CTRL_AXES; i++)
		axis_fill(c, i, &r.axis[i]);
	n = gl_record_encode(&r, buf, cap);
	if (n > 1 && (c->cfg.deviate & CTRL_DEV_QR_HEADER))
		buf[1] &= (uint8_t)~0x04u; /* deviation qr-header: 0x03 */
	return n;
}
