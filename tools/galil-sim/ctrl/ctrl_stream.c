/*
 * ctrl_stream.c - DR, the data record as a stream (see ctrl_stream.h and
 * docs/galil-sim.md, "The record stream").
 *
 * The minimum interval is 2 samples: the command reference gives 8, but
 * gclib clamps its record rate to 2 for the DMC-40x0 family and GalilSup
 * restricts it to 8 only on the Econo models (galil-notes 2.6), so a
 * DMC-4030 is taken to accept DR 2. Below it: '?', TC 6. A handle that is
 * not an open UDP session: TC 133 ("Handle must be UDP", galil-notes 2.6,
 * INFERRED for recent firmware).
 */
#include <stdio.h>
#include <string.h>

#include "ctrl_stream.h"
#include "ctrl_args.h"
#include "ctrl_out.h"
#include "ctrl_rec.h"
#include "ctrl_thread.h"
#include "gl_record.h"

_Static_assert(CTRL_REC_MAX >= GL_REC_MAX_BYTES, "record queue too small");

static int is_int_in(double v, int lo, int hi)
{
	return v == (int)v && v >= lo && v <= hi;
}

/* A running stream stops, with its event: the handle it went to, why, and
 * how many records were made since the DR that started it (the test's
 * truth beside the reader's counters). */
static void stop(struct ctrl *c, const char *why)
{
	struct ctrl_stream *d = &c->dr;

	if (d->n <= 0)
		return;
	ctrl_event(c, "handle %c: data record stopped: %s; records made: %llu",
		   'A' + d->h, why, (unsigned long long)d->made);
	d->n = 0;
}

/* DR 0 from @x stops a running stream. */
static void stop_by(struct ctrl_xc *x)
{
	char who[CTRL_WHO_LEN], why[CTRL_WHO_LEN + 8];

	ctrl_xc_who(x, who, sizeof(who));
	snprintf(why, sizeof(why), "DR 0 (%s)", who);
	stop(x->c, why);
}

/* DR n0,h took effect: the interval starts again, and the count. */
static void start(struct ctrl_xc *x, int n0, int h)
{
	struct ctrl_stream *d = &x->c->dr;
	char who[CTRL_WHO_LEN];

	ctrl_xc_who(x, who, sizeof(who));
	d->n = n0;
	d->h = h;
	d->left = n0;
	d->made = 0;
	ctrl_event(x->c, "handle %c: data record every %d samples (%s)",
		   'A' + h, n0, who);
}

int ctrl_stream_cmd(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	double v[2] = {0, -1};
	unsigned got = 0;
	int rc = ctrl_num_list(x, a, v, 2, &got), h;

	if (rc)
		return rc;
	if (!(got & 1))
		return 50;
	if (!(got & 2))
		v[1] = c->cf;
	if (v[0] != 0 && !is_int_in(v[0], CTRL_DR_MIN, CTRL_DR_MAX))
		return 6;
	if (v[0] == 0 && !(got & 2)) {
		stop_by(x);
		return 0;
	}
	if (!(got & 2) && c->cf == CTRL_SERIAL)
		return 133;
	if (!is_int_in(v[1], 0, CTRL_HANDLES - 1))
		return 6;
	h = (int)v[1];
	if (v[0] != 0 && (!c->h[h].open || !c->h[h].udp))
		return 133;
	if (v[0] == 0) {
		stop_by(x);
		c->dr.h = h; /* _DR1 reads it back */
		return 0;
	}
	start(x, (int)v[0], h);
	return 0;
}

/* A download in progress on any handle pauses the stream. */
static int paused(const struct ctrl *c)
{
	for (int h = 0; h < CTRL_NHANDLES; h++)
		if (c->h[h].open && c->h[h].mode == CTRL_H_DL)
			return 1;
	return 0;
}

static void queue_record(struct ctrl *c)
{
	struct ctrl_stream *d = &c->dr;
	struct ctrl_stream_rec *r;
	int n;

	if (d->count == CTRL_DR_QUEUE) { /* net/ fell behind: oldest lost */
		d->head = (d->head + 1) % CTRL_DR_QUEUE;
		d->count--;
		d->lost++;
	}
	r = &d->q[(d->head + d->count) % CTRL_DR_QUEUE];
	n = ctrl_record(c, r->b, sizeof(r->b));
	if (n <= 0)
		return;
	r->len = (uint16_t)n;
	r->handle = d->h;
	d->count++;
	d->made++;
}

void ctrl_stream_sample(struct ctrl *c)
{
	struct ctrl_stream *d = &c->dr;

	if (d->n <= 0)
		return;
	if (paused(c)) { /* the interval starts again after the pause */
		d->left = d->n;
		return;
	}
	if (--d->left > 0)
		return;
	d->left = d->n;
	queue_record(c);
}

void ctrl_stream_handle_closed(struct ctrl *c, int h)
{
	struct ctrl_stream *d = &c->dr;

	if (d->n > 0 && d->h == h)
		stop(c, "handle closed");
	while (d->count && d->q[d->head].handle == h) {
		d->head = (d->head + 1) % CTRL_DR_QUEUE;
		d->count--;
	}
}

void ctrl_stream_reset(struct ctrl *c)
{
	stop(c, "power cycle");
	c->dr.h = 0;
	c->dr.left = 0;
	c->dr.head = c->dr.count = 0;
}

size_t ctrl_stream_take(struct ctrl *c, int *h, uint8_t *buf, size_t cap)
{
	struct ctrl_stream_rec *r;

	if (!c || !buf || !c->dr.count)
		return 0;
	r = &c->dr.q[c->dr.head];
	if (cap < r->len)
		return 0;
	memcpy(buf, r->b, r->len);
	if (h)
		*h = r->handle;
	c->dr.head = (c->dr.head + 1) % CTRL_DR_QUEUE;
	c->dr.count--;
	return r->len;
}

uint64_t ctrl_stream_lost(const struct ctrl *c)
{
	return c ? c->dr.lost : 0;
}
