/*
 * re_rec.c - the flight recorder: the ring, the dump and its writer thread.
 * See re_rec.h.
 */
#include "re_rec.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base_clock.h"
#include "base_durable.h"
#include "gl_err.h"
#include "re_pot.h"

static void *writer(void *arg);

static int64_t sup_now(const struct re_super_view *s)
{
	return s->io.ops->now_ns(s->io.ud);
}

static int alloc_buffers(struct re_rec *r, size_t cap, int n_axes)
{
	r->cap = cap;
	r->ring = calloc(cap, sizeof(*r->ring));
	r->snap = calloc(cap, sizeof(*r->snap));
	r->text_cap = re_trace_max_bytes(cap, n_axes);
	r->text = r->text_cap ? malloc(r->text_cap) : NULL;
	if (!r->ring || !r->snap || !r->text)
		return GL_ERR_NOMEM;
	return GL_OK;
}

static int fill_hdr(struct re_rec *r, const struct re_rec_cfg *cfg)
{
	struct re_trace_hdr *h = &r->hdr;

	h->version = RE_TRACE_VERSION;
	h->config_hash = cfg->config_hash;
	h->period_ms = cfg->period_ms;
	h->n_axes = cfg->n_axes;
	snprintf(h->serial, sizeof(h->serial), "-");
	for (int a = 0; a < cfg->n_axes; a++) {
		const char *n = cfg->axis_names[a];

		if (!n || !*n || strlen(n) >= RE_TRACE_NAME ||
		    strpbrk(n, " ,\t\n"))
			return GL_ERR_ARG;
		snprintf(h->axis[a], RE_TRACE_NAME, "%s", n);
	}
	snprintf(r->dir, sizeof(r->dir), "%s",
		 cfg->dir && *cfg->dir ? cfg->dir : ".");
	return GL_OK;
}

/* glibc reads the time zone on the first gmtime_r(): here, at start-up,
 * not in a fault's reaction (re_rec_fault_note()). */
static void warm_gmtime(void)
{
	time_t now = time(NULL);
	struct tm tm;

	gmtime_r(&now, &tm);
}

int re_rec_init(struct re_rec *r, const struct re_rec_cfg *cfg)
{
	double n;
	int rc;

	memset(r, 0, sizeof(*r));
	if (!cfg || cfg->n_axes < 1 || cfg->n_axes > RE_TRACE_AXES ||
	    !(cfg->period_ms > 0) || !(cfg->seconds > 0) ||
	    !(cfg->after_fault_s >= 0))
		return GL_ERR_ARG;
	if (cfg->min_period_ms < 0 || cfg->min_period_ms > cfg->period_ms)
		return GL_ERR_ARG;
	n = ceil(
	    (cfg->seconds + cfg->after_fault_s) * 1000.0 /
	    (cfg->min_period_ms > 0 ? cfg->min_period_ms : cfg->period_ms));
	if (n < 2)
		n = 2;
	if (n > RE_TRACE_MAX_RECORDS)
		return GL_ERR_ARG;
	rc = fill_hdr(r, cfg);
	if (rc == GL_OK)
		rc = alloc_buffers(r, (size_t)n, cfg->n_axes);
	if (rc != GL_OK)
		goto out_free;
	warm_gmtime();
	r->after_ns = (int64_t)llround(cfg->after_fault_s * 1e9);
	r->span_s = cfg->seconds + cfg->after_fault_s;
	pthread_mutex_init(&r->mu, NULL);
	pthread_cond_init(&r->cv, NULL);
	if (pthread_create(&r->th, NULL, writer, r) != 0) {
		rc = GL_ERR_SYS;
		goto out_sync;
	}
	r->th_up = 1;
	return GL_OK;
out_sync:
	pthread_cond_destroy(&r->cv);
	pthread_mutex_destroy(&r->mu);
out_free:
	free(r->ring);
	free(r->snap);
	free(r->text);
	memset(r, 0, sizeof(*r));
	return rc;
}

static void take_cb(void *ud, const struct re_super_view *s)
{
	re_rec_take(ud, s);
}

static const char *note_cb(void *ud, const struct re_super_view *s)
{
	return re_rec_fault_note(ud, s);
}

void re_rec_begin(struct re_rec *r, const struct re_super_view *v,
		  const char *serial)
{
	if (!r->t0_ns)
		r->t0_ns = sup_now(v);
	if (serial && *serial)
		snprintf(r->hdr.serial, sizeof(r->hdr.serial), "%s", serial);
}

void re_rec_attach(struct re_rec *r, struct re_super *s, const char *serial)
{
	re_rec_begin(r, re_super_view(s), serial);
	re_super_recorder(s, take_cb, note_cb, r);
}

/* ---- the cycle: one copy ------------------------------------------------ */

static int32_t phase_of(const struct re_super_view *s)
{
	if (s->latched)
		return RE_TPH_FAULT;
	if (s->expect == RE_DMC_ARMED)
		return RE_TPH_ARMED;
	return s->expect == RE_DMC_SERVICE ? RE_TPH_SERVICE : RE_TPH_IDLE;
}

/* dt_s: the controller's time between this record and the previous one,
 * from its sample counter (1 sample = 1 ms at TM 1000, the time unit of
 * its counts/s), so that the PC's wake-up jitter does not show as noise in
 * the commanded velocity; 0 when unknown. */
static void take_axis(struct re_rec *r, const struct re_super_view *s, int i,
		      double dt_s, struct re_trace_axis *x)
{
	const struct gl_rec_axis *a = &s->rec.axis[i];
	const struct re_encpot_result *e = &s->encres[i];

	x->enc_counts = a->motor_pos;
	x->ref_counts = a->ref_pos;
	x->pot_v = re_pot_of(&s->rec, i, s->cfg.pot_input[i]);
	x->pot_exp_v = s->have_encres[i] ? e->exp.pot_v : NAN;
	x->tol_v = s->have_encres[i] ? e->tol_v : NAN;
	x->margin_v = s->have_encres[i] ? e->margin_v : NAN;
	x->vcmd_cps =
	    dt_s > 0 ? (double)(a->ref_pos - r->prev_ref[i]) / dt_s : NAN;
	x->vel_cps = a->velocity / 64.0;
	x->motor_off = !!(a->status & GL_AXST_MOTOR_OFF);
	x->moving = !!(a->status & GL_AXST_MOVING);
	x->fwd_lim = !(a->switches & GL_AXSW_FLS);
	x->rev_lim = !(a->switches & GL_AXSW_RLS);
	x->stop_code = a->stop_code;
	r->prev_ref[i] = a->ref_pos;
}

static void take_za(const struct re_super_view *s, struct re_trace_rec *x)
{
	x->hbdmc = s->za.hbdmc;
	x->joy_raw = s->za.jraw;
	x->jcmd = s->za.jcmd;
	x->mcmd = s->za.mcmd;
	x->dmc_state = s->za.state;
	x->fcode = s->za.fcode;
}

void re_rec_take(struct re_rec *r, const struct re_super_view *s)
{
	struct re_trace_rec *x = &r->ring[r->head];
	int64_t now = sup_now(s);
	uint16_t dsamp = (uint16_t)(s->rec.sample - r->prev_sample);
	double dt_s = r->have_prev && s->have_record ? dsamp / 1000.0 : 0;

	memset(x, 0, sizeof(*x));
	x->t_s = (double)(now - r->t0_ns) / 1e9;
	x->cycle = (int32_t)s->cycles;
	x->phase = phase_of(s);
	x->fault = s->latched ? (int32_t)s->fault.id : 0;
	x->relay = (int32_t)s->io.ops->relay_state(s->io.ud);
	x->link_ok = s->link_ok;
	x->age_ms = (double)s->age_last_ns / 1e6;
	x->late_ms = (double)s->late_last_ns / 1e6;
	x->hbpc = (int32_t)s->hbpc;
	x->sample = s->have_record ? s->rec.sample : -1;
	if (s->have_za)
		take_za(s, x);
	for (int i = 0; i < s->cfg.n_axes && i < r->hdr.n_axes; i++) {
		if (s->have_record)
			take_axis(r, s, i, dt_s, &x->axis[i]);
		else
			x->axis[i].pot_v = x->axis[i].pot_exp_v =
			    x->axis[i].tol_v = x->axis[i].margin_v =
				x->axis[i].vcmd_cps = NAN;
	}
	r->have_prev = s->have_record;
	r->prev_ns = now;
	r->prev_sample = s->rec.sample;
	r->head = (r->head + 1) % r->cap;
	if (r->count < r->cap)
		r->count++;
}

/* ---- names ------------------------------------------------------------- */

/* dir/roboelf-trace-YYYYMMDD-HHMMSS[-N].csv, UTC; no system call. */
static void trace_name(struct re_rec *r, char *path, size_t cap)
{
	struct timespec ts;
	struct tm tm;
	char stamp[32];

	clock_gettime(CLOCK_REALTIME, &ts); /* vDSO: no system call */
	gmtime_r(&ts.tv_sec, &tm);	    /* no time zone file read */
	snprintf(stamp, sizeof(stamp), "%04d%02d%02d-%02d%02d%02d",
		 tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour,
		 tm.tm_min, tm.tm_sec);
	if (strcmp(stamp, r->last_stamp)) {
		snprintf(r->last_stamp, sizeof(r->last_stamp), "%s", stamp);
		r->stamp_seq = 1;
		snprintf(path, cap, "%s/roboelf-trace-%s.csv", r->dir, stamp);
		return;
	}
	snprintf(path, cap, "%s/roboelf-trace-%s-%d.csv", r->dir, stamp,
		 ++r->stamp_seq);
}

const char *re_rec_fault_note(struct re_rec *r, const struct re_super_view *s)
{
	if (r->fault_pending)
		return NULL;
	r->fault_pending = 1;
	r->fault_ns = sup_now(s);
	r->due_ns = r->fault_ns + r->after_ns;
	snprintf(r->fault_text, sizeof(r->fault_text), "%s", s->fault_line);
	for (char *p = r->fault_text; *p; p++)
		if ((unsigned char)*p < ' ' || *p == 127)
			*p = ' ';
	trace_name(r, r->fault_path, sizeof(r->fault_path));
	snprintf(r->note, sizeof(r->note), "trace %s", r->fault_path);
	return r->note;
}

/* ---- the dump ------------------------------------------------------------ */

int re_rec_dump_to(const char *path, const struct re_trace_hdr *h,
		   const struct re_trace_rec *recs, size_t n, char *text,
		   size_t cap)
{
	size_t len = 0;
	int rc = re_trace_write(h, recs, n ? n : 1, 0, n, text, cap, &len);

	if (rc != GL_OK)
		return rc;
	rc = base_durable_write(path, text, len, 0644);
	if (rc < 0) {
		errno = -rc;
		return GL_ERR_SYS;
	}
	return GL_OK;
}

static void *writer(void *arg)
{
	struct re_rec *r = arg;
	sigset_t all;

	/* signals are the main thread's (their handlers set flags): none
	 * interrupts a write here */
	sigfillset(&all);
	pthread_sigmask(SIG_BLOCK, &all, NULL);
	pthread_mutex_lock(&r->mu);
	for (;;) {
		int64_t t0;
		int rc, e;

		while (!r->job && !r->stop)
			pthread_cond_wait(&r->cv, &r->mu);
		if (!r->job)
			break;
		pthread_mutex_unlock(&r->mu);
		t0 = base_now_ns();
		rc = re_rec_dump_to(r->job_path, &r->job_hdr, r->snap,
				    r->snap_n, r->text, r->text_cap);
		e = errno;
		pthread_mutex_lock(&r->mu);
		r->done = 1;
		r->done_rc = rc;
		r->done_ms = (double)(base_now_ns() - t0) / 1e6;
		r->done_records = r->snap_n;
		snprintf(r->done_path, sizeof(r->done_path), "%s", r->job_path);
		snprintf(r->done_err, sizeof(r->done_err), "%s",
			 rc == GL_OK	    ? ""
			 : rc == GL_ERR_SYS ? strerror(e)
					    : gl_strerror(rc));
		r->written += rc == GL_OK;
		r->job = 0;
		pthread_cond_broadcast(&r->cv);
	}
	pthread_mutex_unlock(&r->mu);
	return NULL;
}

/* Copy the ring's last span_s, oldest first, and hand it to the writer.
 * Caller holds mu and the writer is idle. */
static void queue(struct re_rec *r, const char *reason, const char *path)
{
	size_t count = r->count, first, n1;
	time_t now = time(NULL);
	struct tm tm;
	double newest =
	    count ? r->ring[(r->head + r->cap - 1) % r->cap].t_s : 0;

	while (count > 1 && r->ring[(r->head + r->cap - count) % r->cap].t_s <
				newest - r->span_s - 1e-9)
		count--;
	first = (r->head + r->cap - count) % r->cap;
	n1 = r->cap - first < count ? r->cap - first : count;
	memcpy(r->snap, r->ring + first, n1 * sizeof(*r->snap));
	memcpy(r->snap + n1, r->ring, (count - n1) * sizeof(*r->snap));
	r->snap_n = count;
	r->job_hdr = r->hdr;
	gmtime_r(&now, &tm);
	strftime(r->job_hdr.created, sizeof(r->job_hdr.created),
		 "%Y-%m-%dT%H:%M:%SZ", &tm);
	snprintf(r->job_hdr.reason, sizeof(r->job_hdr.reason), "%s", reason);
	snprintf(r->job_path, sizeof(r->job_path), "%s", path);
	r->job = 1;
	pthread_cond_broadcast(&r->cv);
}

int re_rec_request(struct re_rec *r)
{
	char path[RE_REC_PATH];
	int rc = GL_OK;

	pthread_mutex_lock(&r->mu);
	if (r->job) {
		rc = GL_ERR_BUSY;
	} else {
		trace_name(r, path, sizeof(path));
		queue(r, "request", path);
	}
	pthread_mutex_unlock(&r->mu);
	return rc;
}

int re_rec_poll(struct re_rec *r, int64_t now_ns)
{
	int queued = 0;

	if (!r->ring || !r->fault_pending || now_ns < r->due_ns)
		return 0;
	pthread_mutex_lock(&r->mu);
	if (!r->job) {
		queue(r, "fault", r->fault_path);
		r->job_hdr.have_fault = 1;
		r->job_hdr.fault_t_s = (double)(r->fault_ns - r->t0_ns) / 1e9;
		snprintf(r->job_hdr.fault_text, sizeof(r->job_hdr.fault_text),
			 "%.*s", (int)sizeof(r->job_hdr.fault_text) - 1,
			 r->fault_text[0] ? r->fault_text : "FAULT");
		r->fault_pending = 0;
		queued = 1;
	}
	pthread_mutex_unlock(&r->mu);
	return queued;
}

int re_rec_done(struct re_rec *r, char *path, size_t cap, char *err,
		size_t errlen, size_t *records, double *ms)
{
	int v = 0;

	if (!r->ring)
		return 0;
	pthread_mutex_lock(&r->mu);
	if (r->done) {
		r->done = 0;
		v = r->done_rc == GL_OK ? 1 : -1;
		snprintf(path, cap, "%s", r->done_path);
		snprintf(err, errlen, "%s", r->done_err);
		if (records)
			*records = r->done_records;
		if (ms)
			*ms = r->done_ms;
	}
	pthread_mutex_unlock(&r->mu);
	return v;
}

static void wait_idle(struct re_rec *r)
{
	pthread_mutex_lock(&r->mu);
	while (r->job)
		pthread_cond_wait(&r->cv, &r->mu);
	pthread_mutex_unlock(&r->mu);
}

void re_rec_finish(struct re_rec *r)
{
	if (!r->ring)
		return;
	wait_idle(r);
	re_rec_poll(r, INT64_MAX);
	wait_idle(r);
}

void re_rec_free(struct re_rec *r)
{
	if (!r->ring)
		return;
	if (r->th_up) {
		pthread_mutex_lock(&r->mu);
		r->stop = 1;
		pthread_cond_broadcast(&r->cv);
		pthread_mutex_unlock(&r->mu);
		pthread_join(r->th, NULL);
	}
	pthread_cond_destroy(&r->cv);
	pthread_mutex_destroy(&r->mu);
	free(r->ring);
	free(r->snap);
	free(r->text);
	memset(r, 0, sizeof(*r));
}
