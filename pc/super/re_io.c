/*
 * re_io.c - the real binding of struct re_io: gl_link, re_relay, re_log and
 * the monotonic clock (base_clock). See re_io.h.
 */
#define _GNU_SOURCE /* ppoll */
#include "re_io.h"

#include <errno.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base_clock.h"
#include "gl_err.h"

int64_t re_io_now_ns(void)
{
	return base_now_ns();
}

/* ---- the one look before a cycle ------------------------------ */

#define LOOK_EVENTS (POLLIN | POLLERR | POLLHUP | POLLNVAL)

static void look_forget(struct re_io_real *r)
{
	for (int i = 0; i < RE_LOOK_N; i++)
		r->look.fd[i] = -1;
}

/* The look's entry @i for descriptor @fd, taken once: true with its
 * events in @ev, or false (not looked at, taken, or another descriptor). */
static bool look_take(struct re_io_real *r, int i, int fd, short *ev)
{
	if (fd < 0 || r->look.fd[i] != fd)
		return false;
	r->look.fd[i] = -1;
	*ev = r->look.revents[i];
	return true;
}

static void look_set(struct pollfd *p, int fd, short events)
{
	p->fd = fd;
	p->events = events;
	p->revents = 0;
}

/* The descriptors of the look, -1 where there is none. */
static void look_fds(struct re_io_real *r, struct pollfd p[RE_LOOK_N])
{
	int relay, watch;

	re_relay_fds(r->relay, &relay, &watch);
	look_set(&p[RE_LOOK_CMD], gl_link_fd(r->link), POLLIN);
	look_set(&p[RE_LOOK_MSG], gl_link_msg_fd(r->link), POLLIN);
	look_set(&p[RE_LOOK_RELAY], relay, 0); /* errors and hang-up only */
	look_set(&p[RE_LOOK_WATCH], watch, POLLIN);
	look_set(&p[RE_LOOK_KEY], r->watch_key ? r->key_fd : -1, POLLIN);
}

/* Sleep until @t_ns in ppoll() over the cycle's descriptors, noting each
 * one's events; one that shows any is left out for the rest of the wait
 * (it is read in the cycle). No look when the time has already come. */
static void look_wait(struct re_io_real *r, int64_t t_ns)
{
	struct pollfd p[RE_LOOK_N];
	int fd[RE_LOOK_N];
	int64_t left;
	int looked = 0;

	look_forget(r);
	look_fds(r, p);
	for (int i = 0; i < RE_LOOK_N; i++)
		fd[i] = p[i].fd;
	while ((left = t_ns - re_io_now_ns()) > 0) {
		struct timespec ts = {(time_t)(left / BASE_NS_PER_S),
				      (long)(left % BASE_NS_PER_S)};
		int rc;

		for (int i = 0; i < RE_LOOK_N; i++)
			p[i].revents = 0;
		rc = ppoll(p, RE_LOOK_N, &ts, NULL);
		if (rc < 0 && errno != EINTR) {
			base_sleep_until_ns(t_ns); /* no look: readers look */
			return;
		}
		if (rc < 0)
			continue; /* a signal: poll again until the time */
		looked = 1;
		for (int i = 0; i < RE_LOOK_N; i++)
			if (p[i].fd >= 0 && p[i].revents) {
				r->look.revents[i] = p[i].revents;
				p[i].fd = -1;
			}
	}
	if (!looked)
		return; /* the time had come: nothing was looked at */
	for (int i = 0; i < RE_LOOK_N; i++) {
		if (fd[i] >= 0 && p[i].fd >= 0)
			r->look.revents[i] = 0;
		r->look.fd[i] = fd[i];
	}
}

int re_io_key_look(struct re_io_real *r)
{
	short ev = 0;

	if (!r->watch_key || !look_take(r, RE_LOOK_KEY, r->key_fd, &ev))
		return -1;
	return (ev & LOOK_EVENTS) != 0;
}

/* ---- the controller -------------------------------------------------- */

static int real_record(void *ud, const char *prefix, struct gl_record *rec,
		       int timeout_ms)
{
	struct re_io_real *r = ud;
	short ev = 0;
	bool idle;
	int rc;

	if (!r->link)
		return GL_ERR_CLOSED;
	idle = look_take(r, RE_LOOK_CMD, gl_link_fd(r->link), &ev) &&
	       !(ev & LOOK_EVENTS);
	r->last_run_ns = re_io_now_ns();
	rc = gl_link_record_seen(r->link, prefix, rec, timeout_ms, idle);
	r->last_run_ns = re_io_now_ns();
	return rc;
}

static int real_record_text(void *ud, const char *prefix, struct gl_record *rec,
			    char *text, size_t cap, int timeout_ms)
{
	struct re_io_real *r = ud;
	short ev = 0;
	bool idle;
	int rc;

	if (!r->link)
		return GL_ERR_CLOSED;
	idle = look_take(r, RE_LOOK_CMD, gl_link_fd(r->link), &ev) &&
	       !(ev & LOOK_EVENTS);
	r->last_run_ns = re_io_now_ns();
	rc = gl_link_record_text(r->link, prefix, rec, timeout_ms, idle, text,
				 cap);
	r->last_run_ns = re_io_now_ns();
	return rc;
}

static int real_command(void *ud, const char *cmd, char *resp, size_t cap,
			int timeout_ms)
{
	struct re_io_real *r = ud;
	int rc;

	if (!r->link)
		return GL_ERR_CLOSED;
	r->last_run_ns = re_io_now_ns();
	rc = gl_link_command(r->link, cmd, resp, cap, timeout_ms);
	r->last_run_ns = re_io_now_ns();
	return rc;
}

static int real_post(void *ud, const char *line)
{
	struct re_io_real *r = ud;

	if (!r->link)
		return GL_ERR_CLOSED;
	r->last_run_ns = re_io_now_ns();
	return gl_link_post(r->link, line);
}

static int real_collect(void *ud, char *text, size_t cap)
{
	struct re_io_real *r = ud;
	short ev = 0;

	if (!r->link)
		return GL_ERR_CLOSED;
	/* the reply's bytes are what the look saw on this socket */
	look_take(r, RE_LOOK_CMD, gl_link_fd(r->link), &ev);
	return gl_link_collect(r->link, text, cap);
}

static int real_stream(void *ud, struct gl_record *rec, int64_t now_ns)
{
	struct re_io_real *r = ud;
	int rc;

	if (!r->link)
		return GL_ERR_CLOSED;
	rc = gl_link_stream_read(r->link, rec, now_ns);
	r->last_run_ns = re_io_now_ns();
	return rc;
}

static int real_stream_counts(void *ud, uint64_t *records, uint64_t *lost)
{
	struct re_io_real *r = ud;
	struct gl_stream_stats st;

	if (!r->link || gl_link_stream_info(r->link, NULL, NULL) != 1)
		return -1;
	gl_link_stream_stats(r->link, &st);
	*records = st.accepted;
	*lost = st.lost;
	return 0;
}

static const char *real_ctrl_error(void *ud, int *code)
{
	struct re_io_real *r = ud;

	if (code)
		*code = 0;
	return r->link ? gl_link_ctrl_error(r->link, code) : "";
}

static int real_message(void *ud, char *line, size_t cap)
{
	struct re_io_real *r = ud;
	short ev = 0;

	if (!r->link)
		return GL_ERR_AGAIN;
	if (look_take(r, RE_LOOK_MSG, gl_link_msg_fd(r->link), &ev) &&
	    !(ev & LOOK_EVENTS))
		return gl_link_message_queued(r->link, line, cap);
	return gl_link_message(r->link, line, cap);
}

static int real_relay_check(void *ud, char *why, size_t cap)
{
	struct re_io_real *r = ud;
	short ev = 0, wev = POLLIN; /* watch not looked at: stat() */
	int rc, fd, wfd;

	if (!r->relay) {
		snprintf(why, cap, "relay not open");
		return GL_ERR_RELAY;
	}
	re_relay_fds(r->relay, &fd, &wfd);
	if (look_take(r, RE_LOOK_RELAY, fd, &ev)) {
		look_take(r, RE_LOOK_WATCH, wfd, &wev);
		rc = re_relay_check_seen(r->relay, ev, wev);
	} else {
		rc = re_relay_check(r->relay);
	}
	if (rc != GL_OK)
		snprintf(why, cap, "%s", re_relay_errmsg(r->relay));
	return rc;
}

static int real_relay_off(void *ud)
{
	struct re_io_real *r = ud;

	return r->relay ? re_relay_off(r->relay) : GL_ERR_RELAY;
}

static int real_relay_off_start(void *ud)
{
	struct re_io_real *r = ud;

	return r->relay ? re_relay_off_start(r->relay) : GL_ERR_RELAY;
}

static int real_relay_off_finish(void *ud, int deadline_ms)
{
	struct re_io_real *r = ud;

	return r->relay ? re_relay_off_finish(r->relay, deadline_ms)
			: GL_ERR_RELAY;
}

/* A new connection within @end_ns: refused or reset connections (the
 * network coming back, the controller's listen queue) are tried again
 * every RETRY_MS until then. */
#define RETRY_MS 10
static int open_until(struct re_io_real *r, int64_t end_ns, gl_link **l)
{
	char e[GL_ERRTEXT_LEN];
	int rc;

	for (;;) {
		int64_t left_ms = (end_ns - re_io_now_ns()) / BASE_NS_PER_MS;
		struct timespec pause = {0, RETRY_MS * BASE_NS_PER_MS};

		if (left_ms < 1)
			return GL_ERR_TIMEOUT;
		rc = gl_link_open(l, r->address, (int)left_ms, e);
		if (rc == GL_OK || rc == GL_ERR_ARG ||
		    re_io_now_ns() + RETRY_MS * BASE_NS_PER_MS >= end_ns)
			return rc;
		nanosleep(&pause, NULL);
	}
}

/* A new connection, the command on it, and it replaces the old link. A
 * connection that closes before the reply (the network just coming back)
 * is tried again within the same deadline. */
static int real_stop_fresh(void *ud, const char *cmd, char *resp, size_t cap,
			   int deadline_ms)
{
	struct re_io_real *r = ud;
	int64_t end = re_io_now_ns() + (int64_t)deadline_ms * BASE_NS_PER_MS;
	int64_t left_ms;
	gl_link *l;
	int rc;

	if (!r->address)
		return GL_ERR_CLOSED;
	for (;;) {
		struct timespec pause = {0, RETRY_MS * BASE_NS_PER_MS};

		rc = open_until(r, end, &l);
		if (rc != GL_OK)
			return rc;
		left_ms = (end - re_io_now_ns()) / BASE_NS_PER_MS;
		rc = gl_link_command(l, cmd, resp, cap,
				     left_ms > 1 ? (int)left_ms : 1);
		if (rc >= 0 || rc == GL_ERR_CTRL)
			break;
		gl_link_close(l);
		if ((rc != GL_ERR_CLOSED && rc != GL_ERR_BROKEN) ||
		    re_io_now_ns() + RETRY_MS * BASE_NS_PER_MS >= end)
			return rc;
		nanosleep(&pause, NULL);
	}
	gl_link_set_timeout(l, r->cmd_timeout_ms > 0 ? r->cmd_timeout_ms
						     : deadline_ms);
	/* the record stream was the old link's: its counters are kept for
	 * the end of the run (the new connection has no stream) */
	if (gl_link_stream_info(r->link, NULL, NULL)) {
		gl_link_stream_stats(r->link, &r->stream_was);
		r->have_stream_was = 1;
	}
	gl_link_close(r->link);
	r->link = l;
	look_forget(r); /* of the old link's descriptors */
	return rc;
}

static enum re_relay_state real_relay_state(void *ud)
{
	struct re_io_real *r = ud;

	return r->relay ? re_relay_state(r->relay) : RE_RELAY_UNKNOWN;
}

/* Inside a cycle: copy the event into the queue (no system call). */
static void logq_put(struct re_io_real *r, enum re_log_level lvl,
		     const char *text)
{
	struct re_io_logq_ent *e;

	if (r->logq_n >= RE_IO_LOGQ) {
		r->logq_dropped++;
		return;
	}
	e = &r->logq[r->logq_n++];
	e->lvl = lvl;
	clock_gettime(CLOCK_REALTIME, &e->wall);
	e->mono_ns = re_io_now_ns();
	snprintf(e->text, sizeof(e->text), "%s", text);
}

int re_io_flush_log(struct re_io_real *r)
{
	int rc = GL_OK, e;

	for (unsigned i = 0; i < r->logq_n; i++) {
		const struct re_io_logq_ent *q = &r->logq[i];

		if (!r->log || !r->log->is_open)
			break;
		e = re_log_write_at(r->log, q->lvl, &q->wall, q->mono_ns,
				    q->text);
		rc = rc ? rc : e;
	}
	r->logq_n = 0;
	if (r->logq_dropped && r->log && r->log->is_open) {
		e = re_log_msg(r->log, RE_LOG_WARN,
			       "log: %lu events dropped (more than %d "
			       "in one cycle)",
			       r->logq_dropped, RE_IO_LOGQ);
		rc = rc ? rc : e;
	}
	r->logq_dropped = 0;
	return rc;
}

static int real_log(void *ud, enum re_log_level lvl, const char *text)
{
	struct re_io_real *r = ud;

	if (!r->log || !r->log->is_open)
		return GL_OK;
	if (lvl == RE_LOG_FAULT) { /* the fault path: in order, on disk */
		re_io_flush_log(r);
		return re_log_fault(r->log, "%s", text);
	}
	if (r->defer_log) {
		logq_put(r, lvl, text);
		return GL_OK;
	}
	return re_log_msg(r->log, lvl, "%s", text);
}

static int64_t real_now_ns(void *ud)
{
	(void)ud;
	return re_io_now_ns();
}

static void real_sleep_until(void *ud, int64_t t_ns)
{
	look_wait(ud, t_ns);
}

static const struct re_io_ops real_ops = {
    .record = real_record,
    .record_text = real_record_text,
    .command = real_command,
    .post = real_post,
    .collect = real_collect,
    .stream = real_stream,
    .stream_counts = real_stream_counts,
    .ctrl_error = real_ctrl_error,
    .message = real_message,
    .relay_check = real_relay_check,
    .relay_off = real_relay_off,
    .relay_off_start = real_relay_off_start,
    .relay_off_finish = real_relay_off_finish,
    .stop_fresh = real_stop_fresh,
    .relay_state = real_relay_state,
    .log = real_log,
    .now_ns = real_now_ns,
    .sleep_until = real_sleep_until,
};

void re_io_bind(struct re_io *io, struct re_io_real *real)
{
	io->ops = &real_ops;
	io->ud = real;
	look_forget(real);
}

int re_io_logf(const struct re_io *io, enum re_log_level lvl, const char *fmt,
	       ...)
{
	char text[RE_LOG_LINE_MAX];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(text, sizeof(text), fmt, ap);
	va_end(ap);
	return io->ops->log(io->ud, lvl, text);
}

int re_io_read(const struct re_io *io, const char *expr, double *v,
	       int timeout_ms)
{
	char line[96], resp[128], *end;
	int rc;

	snprintf(line, sizeof(line), "MG %s", expr);
	rc = io->ops->command(io->ud, line, resp, sizeof(resp), timeout_ms);
	if (rc < 0)
		return rc;
	*v = strtod(resp, &end);
	if (end == resp)
		return GL_ERR_PROTO;
	while (*end == ' ' || *end == '\r' || *end == '\n')
		end++;
	return *end ? GL_ERR_PROTO : GL_OK;
}
