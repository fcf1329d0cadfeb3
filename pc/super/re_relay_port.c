/*
 * re_relay_port.c - the relay's port and its output: the back-end opened
 * (the device node remembered) and closed without waiting, a message
 * handed to the driver and waited for with a deadline, sleeping at most
 * 1 ms at a time, stale input dropped (the decisions: re_relay.c's header).
 */
#include <errno.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "base_clock.h"
#include "gl_err.h"
#include "re_pathwatch.h"
#include "re_relay_int.h"

#define NAP_NS	     BASE_NS_PER_MS /* longest sleep while waiting */
#define STALE_CHUNKS 4 /* x 16 bytes of stale input dropped per call */

int re_relay_set_err(struct re_relay *r, int rc, const char *fmt, ...)
{
	va_list ap;
	int n;

	n = snprintf(r->err, sizeof(r->err), "relay '%s': ", r->cfg.port);
	va_start(ap, fmt);
	if (n > 0 && (size_t)n < sizeof(r->err))
		vsnprintf(r->err + n, sizeof(r->err) - (size_t)n, fmt, ap);
	va_end(ap);
	return rc;
}

/* Is @st the node opened (device, inode and change time)? */
bool re_relay_same_node(const struct re_relay *r, const struct stat *st)
{
	return S_ISCHR(st->st_mode) && st->st_rdev == r->rdev &&
	       st->st_ino == r->ino && st->st_ctim.tv_sec == r->ctim.tv_sec &&
	       st->st_ctim.tv_nsec == r->ctim.tv_nsec;
}

int64_t re_relay_deadline_in(int ms)
{
	return base_now_ns() + (int64_t)ms * BASE_NS_PER_MS;
}

/* Sleep NAP_NS at most, and never past @deadline. */
void re_relay_nap(int64_t deadline)
{
	int64_t t = base_now_ns() + NAP_NS;

	if (t > deadline)
		t = deadline;
	base_sleep_until_ns(t);
}

void re_relay_out_set(struct re_relay *r, const uint8_t *msg, size_t len)
{
	r->out = msg;
	r->out_len = len;
	r->out_done = 0;
}

/* Open the back-end and remember which device was opened. */
int re_relay_link_open(struct re_relay *r)
{
	struct stat st;
	int rc, fd;

	/* A missing node is said plainly (libserialport would only say
	 * "not a serial port"). */
	if (stat(r->cfg.port, &st) < 0)
		return re_relay_set_err(r, GL_ERR_RELAY, "cannot open: %s",
					strerror(errno));
	rc = r->ops->open(&r->io, r->cfg.baud, r->err, sizeof(r->err));
	if (rc)
		return GL_ERR_RELAY;
	fd = r->ops->fd(&r->io);
	if (fd < 0 || fstat(fd, &st) < 0) {
		r->ops->close(&r->io);
		return re_relay_set_err(r, GL_ERR_RELAY,
					"cannot open: no descriptor");
	}
	r->rdev = st.st_rdev;
	r->linked = true;
	if (!stat(r->cfg.port, &st)) {
		r->ino = st.st_ino;
		r->ctim = st.st_ctim;
	}
	/* Without a watch every check stat()s; the first check stat()s
	 * anyway (the node may have changed before the watch existed). */
	re_pathwatch_open(&r->pw, r->cfg.port);
	r->next_full_ns = 0;
	r->node_suspect = false;
	r->rb_due = 0;
	r->rb_flush = true;
	re_relay_out_set(r, NULL, 0);
	return GL_OK;
}

/* Close without waiting: a non-empty output queue is discarded first
 * (close() would wait for it up to the driver's closing_wait). */
void re_relay_link_close(struct re_relay *r)
{
	if (r->linked) {
		if (r->ops->queued(&r->io, NULL, 0) != 0)
			r->ops->discard(&r->io);
		r->ops->close(&r->io);
	}
	r->linked = false;
	re_pathwatch_close(&r->pw);
}

/* Hand the driver what it takes of the message now: GL_OK (perhaps only
 * part of it) or GL_ERR_SYS with the message. */
int re_relay_out_push(struct re_relay *r)
{
	int n;

	if (!r->linked)
		return re_relay_set_err(r, GL_ERR_SYS,
					"write failed: port not open");
	while (r->out_done < r->out_len) {
		n = r->ops->write(&r->io, r->out + r->out_done,
				  r->out_len - r->out_done, r->err,
				  sizeof(r->err));
		if (n < 0)
			return GL_ERR_SYS;
		if (n == 0)
			break; /* the driver's buffer is full: later */
		r->out_done += (size_t)n;
	}
	return GL_OK;
}

/*
 * Wait until the message (@what) is accepted and the output queue is
 * empty, until @deadline (@ms from the caller's start, for the message).
 * Return: GL_OK; GL_ERR_SYS (I/O error); GL_ERR_TIMEOUT, never before
 * @deadline.
 */
int re_relay_out_wait(struct re_relay *r, const char *what, int64_t deadline,
		      int ms)
{
	int q = 0;

	for (;;) {
		if (re_relay_out_push(r))
			return GL_ERR_SYS;
		if (r->out_done == r->out_len) {
			q = r->ops->queued(&r->io, r->err, sizeof(r->err));
			if (q <= 0)
				return q < 0 ? GL_ERR_SYS : GL_OK;
		}
		if (base_now_ns() >= deadline)
			break;
		re_relay_nap(deadline);
	}
	if (r->out_done < r->out_len)
		return re_relay_set_err(
		    r, GL_ERR_TIMEOUT,
		    "%s not confirmed: only %zu of %zu bytes "
		    "accepted by the driver within %d ms",
		    what, r->out_done, r->out_len, ms);
	return re_relay_set_err(
	    r, GL_ERR_TIMEOUT,
	    "%s not confirmed: %d byte%s still queued after %d ms", what, q,
	    q == 1 ? "" : "s", ms);
}

/* Drop what the board sent before now (bounded). GL_OK or GL_ERR_SYS. */
int re_relay_drop_input(struct re_relay *r)
{
	uint8_t junk[16];
	int i, n;

	for (i = 0; i < STALE_CHUNKS; i++) {
		n = r->ops->read(&r->io, junk, sizeof(junk), r->err,
				 sizeof(r->err));
		if (n <= 0)
			return n < 0 ? GL_ERR_SYS : GL_OK;
	}
	return GL_OK;
}
