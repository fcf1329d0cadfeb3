/*
 * re_relay.c - the E-stop relay: opening, switching on and off, closing
 * (the state machine and its confirmations), and below the safety
 * decisions of the whole relay; its parts (protocols, port, read-back,
 * link check, ICStation handshake) are listed in re_relay_int.h.
 *
 * Safety decisions (docs/config.md, "E-stop relay"):
 * - Opening switches the relay off first; only re_relay_on() switches it
 *   on, and it refuses when the link check fails.
 * - Nothing waits without a deadline. Bytes are handed to the driver
 *   without waiting (the back-ends never block); re_relay_*_finish() then
 *   polls, sleeping at most 1 ms at a time, for the message to be
 *   accepted, the driver's output queue to empty and (Devantech read-back)
 *   the board's report, and gives up at its deadline with GL_ERR_TIMEOUT.
 *   An empty queue means the bytes left the PC; the USB adapter's own FIFO
 *   still needs about 1 ms per byte at 9600 baud, and only the read-back
 *   shows that the board switched.
 * - "off" always writes, and after a failed write reopens the port once
 *   and writes again (but never on a different pseudo-terminal: pty
 *   numbers are reused by unrelated programs). A deadline that passes with
 *   "off" still queued reopens nothing: the queued bytes are the safe
 *   message, and a wedged queue is not cured by a reopen. Only a confirmed
 *   message counts as "off".
 * - An "on" that was not confirmed is discarded from the output queue (it
 *   must not reach the board later), and "off" discards an unconfirmed
 *   "on" before writing.
 * - re_relay_check() never writes a state byte. It looks at the descriptor
 *   (fcntl, poll with timeout 0: hang-up/error), the device node (stat:
 *   still there, same st_rdev, inode and change time as at open, so a pty
 *   number reused by someone else or a re-plugged adapter is noticed) and,
 *   for Devantech boards with read-back enabled, the board's own report of
 *   its relays: the query byte 0x5B is sent in one cycle and its answer
 *   read without waiting in a later one, so the check never blocks on the
 *   9600 baud line. The node is stat()ed only after an inotify event that
 *   may change it (re_pathwatch.h), at least once a second, and in every
 *   call after a failed stat() check.
 * - ICStation boards take the handshake (0x50, answer 0xAB/0xAD/0xAC, then
 *   0x51) once per power-up; sent again, 0x50 is a relay state byte that
 *   switches relays 1-4, 6 and 8 ON. A board's power-up is identified by its
 *   device node (st_rdev, inode and change time: a USB-powered board is
 *   powered up when plugged in, which creates a new node), recorded in the
 *   icstation_state file after a successful handshake; the handshake is
 *   skipped when the record matches. If the board does not answer 0x50 it
 *   was already initialised: the "all off" state is sent at once and the
 *   open fails, asking the operator to re-plug the relay.
 */
#include "re_relay.h"

#include <limits.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>

#include "gl_err.h"
#include "re_pathwatch.h"
#include "re_relay_int.h"

/* A pseudo-terminal, directly or through a symbolic link? */
static bool is_pty(const char *path)
{
	char real[PATH_MAX];
	struct stat st;

	if (realpath(path, real) && !strncmp(real, "/dev/pts/", 9))
		return true;
	return !stat(path, &st) && S_ISCHR(st.st_mode) &&
	       major(st.st_rdev) >= PTY_MAJOR_MIN &&
	       major(st.st_rdev) <= PTY_MAJOR_MAX;
}

static const struct re_relay_be_ops *pick_backend(const struct re_relay_cfg *c)
{
	switch (c->backend) {
	case RE_RELAY_BACKEND_TTY: return &re_relay_be_tty;
	case RE_RELAY_BACKEND_SERIALPORT: return &re_relay_be_serialport;
	default: break;
	}
	if (!c->clinical && is_pty(c->port))
		return &re_relay_be_tty;
	return &re_relay_be_serialport;
}

static int check_cfg(struct re_relay *r)
{
	const struct re_relay_cfg *c = &r->cfg;
	int n;

	if (!c->port[0])
		return re_relay_set_err(r, GL_ERR_ARG, "no port configured");
	if (c->clinical && c->backend == RE_RELAY_BACKEND_TTY)
		return re_relay_set_err(r, GL_ERR_ARG,
					"the tty back-end is not "
					"allowed in clinical mode");
	if (c->write_timeout_ms <= 0 || c->off_deadline_ms <= 0 ||
	    c->baud <= 0 || (c->readback && c->proto != RE_RELAY_DEVANTECH))
		return re_relay_set_err(r, GL_ERR_ARG, "invalid settings");
	n = re_relay_message(c, true, r->msg_on);
	if (n > 0)
		r->on_len = (size_t)n;
	if (n > 0)
		n = re_relay_message(c, false, r->msg_off);
	if (n <= 0)
		return re_relay_set_err(r, GL_ERR_ARG,
					"invalid channel %d or empty "
					"message",
					c->channel);
	r->off_len = (size_t)n;
	return GL_OK;
}

/* The "off" of the open: as re_relay_off_finish(), without a reopen. */
static int first_off(struct re_relay *r)
{
	const int ms = r->cfg.off_deadline_ms;

	re_relay_out_set(r, r->msg_off, r->off_len);
	if (re_relay_confirm(r, "off", false, re_relay_deadline_in(ms), ms))
		return GL_ERR_RELAY;
	r->state = RE_RELAY_OFF;
	return GL_OK;
}

int re_relay_open(re_relay **out, const struct re_relay_cfg *cfg, char *err,
		  size_t errlen)
{
	struct re_relay *r;
	int rc;

	if (err && errlen)
		err[0] = '\0';
	if (!out || !cfg)
		return GL_ERR_ARG;
	*out = NULL;
	r = calloc(1, sizeof(*r));
	if (!r)
		return GL_ERR_NOMEM;
	r->cfg = *cfg;
	r->cfg.port[sizeof(r->cfg.port) - 1] = '\0';
	r->io.path = r->cfg.port;
	r->io.fd = -1;
	re_pathwatch_init(&r->pw);
	rc = check_cfg(r);
	if (rc)
		goto out_free;
	r->ops = pick_backend(&r->cfg);
	rc = re_relay_link_open(r);
	if (!rc && r->cfg.proto == RE_RELAY_ICSTATION)
		rc = re_relay_ics_handshake(r);
	if (!rc)
		rc = first_off(r);
	if (rc)
		goto out_close;
	*out = r;
	return GL_OK;
out_close:
	re_relay_link_close(r);
out_free:
	if (err && errlen)
		snprintf(err, errlen, "%s", r->err);
	free(r);
	return rc;
}

/* An "on" handed over but not confirmed must never reach the board. */
static void drop_on(struct re_relay *r)
{
	if (!r->on_unconfirmed)
		return;
	if (r->linked)
		r->ops->discard(&r->io);
	r->on_unconfirmed = false;
	re_relay_out_set(r, NULL, 0);
}

int re_relay_on_start(re_relay *r)
{
	if (!r)
		return GL_ERR_ARG;
	r->op = OP_NONE;
	if (r->out_done < r->out_len)
		re_relay_set_err(
		    r, GL_ERR_RELAY,
		    "on refused: the last message is not written yet");
	else if (!re_relay_link_check(r))
		r->op = OP_ON;
	if (r->op != OP_ON) {
		r->state = RE_RELAY_UNKNOWN;
		return GL_ERR_RELAY;
	}
	if (r->rb_due)
		r->rb_discard = true;
	r->state = RE_RELAY_UNKNOWN;
	r->on_unconfirmed = true;
	re_relay_out_set(r, r->msg_on, r->on_len);
	if (re_relay_out_push(r)) {
		drop_on(r);
		r->op = OP_NONE;
		return GL_ERR_RELAY;
	}
	return GL_OK;
}

int re_relay_on_finish(re_relay *r, int deadline_ms)
{
	int64_t deadline;
	int rc;

	if (!r || r->op != OP_ON || deadline_ms < 0)
		return GL_ERR_ARG;
	deadline = re_relay_deadline_in(deadline_ms);
	r->op = OP_NONE;
	rc = re_relay_confirm(r, "on", true, deadline, deadline_ms);
	if (rc) {
		drop_on(r);
		r->state = RE_RELAY_UNKNOWN;
		return rc == GL_ERR_TIMEOUT ? rc : GL_ERR_RELAY;
	}
	r->on_unconfirmed = false;
	r->state = RE_RELAY_ON;
	r->err[0] = '\0';
	return GL_OK;
}

int re_relay_on(re_relay *r)
{
	int rc = re_relay_on_start(r);

	return rc ? rc : re_relay_on_finish(r, r->cfg.write_timeout_ms);
}

/*
 * May "off" be retried on whatever the port names now? Not on another
 * pseudo-terminal: pty numbers are reused at once, so the path may name an
 * unrelated program's terminal (relays-and-serial.md). A real serial port
 * configured by the operator (e.g. /dev/serial/by-id/...) that was
 * re-plugged is the relay itself: sending it "off" is right.
 */
static bool reopen_allowed(struct re_relay *r)
{
	struct stat st;

	if (stat(r->cfg.port, &st) < 0)
		return true; /* re_relay_link_open() says why it cannot open */
	if (re_relay_same_node(r, &st) || !S_ISCHR(st.st_mode) ||
	    major(st.st_rdev) < PTY_MAJOR_MIN ||
	    major(st.st_rdev) > PTY_MAJOR_MAX)
		return true;
	re_relay_set_err(r, GL_ERR_RELAY, "the port now names another device");
	return false;
}

/* "off" could not be written: reopen once and hand it over again; on
 * failure keep both reasons. */
static int off_reopen(struct re_relay *r)
{
	char first[RE_RELAY_ERR_MAX], second[RE_RELAY_ERR_MAX];
	size_t skip = strlen(r->cfg.port) + 10; /* "relay '...': " */

	snprintf(first, sizeof(first), "%s", r->err);
	re_relay_link_close(r);
	if (reopen_allowed(r) && !re_relay_link_open(r)) {
		re_relay_out_set(r, r->msg_off, r->off_len);
		if (!re_relay_out_push(r))
			return GL_OK;
	}
	if (strlen(r->err) < skip)
		skip = 0;
	snprintf(second, sizeof(second), "%s", r->err + skip);
	snprintf(r->err, sizeof(r->err), "%.200s; reopen: %.200s", first,
		 second);
	return GL_ERR_RELAY;
}

int re_relay_off_start(re_relay *r)
{
	bool partial;

	if (!r)
		return GL_ERR_ARG;
	if (r->rb_due)
		r->rb_discard = true;
	r->state = RE_RELAY_UNKNOWN;
	r->op = OP_OFF;
	drop_on(r);
	/* A half-written "off" is completed, never interleaved. */
	partial =
	    r->out == r->msg_off && r->out_done > 0 && r->out_done < r->out_len;
	if (!partial)
		re_relay_out_set(r, r->msg_off, r->off_len);
	r->reopen = re_relay_out_push(r) != GL_OK;
	return r->reopen ? GL_ERR_RELAY : GL_OK;
}

int re_relay_off_finish(re_relay *r, int deadline_ms)
{
	int64_t deadline;
	bool reopened;
	int rc;

	if (!r || r->op != OP_OFF || deadline_ms < 0)
		return GL_ERR_ARG;
	deadline = re_relay_deadline_in(deadline_ms);
	r->op = OP_NONE;
	reopened = r->reopen;
	r->reopen = false;
	if (reopened && off_reopen(r))
		return GL_ERR_RELAY;
	rc = re_relay_confirm(r, "off", false, deadline, deadline_ms);
	if (rc == GL_ERR_SYS && !reopened) /* I/O error: reopen once */
		rc = off_reopen(r) ? GL_ERR_RELAY
				   : re_relay_confirm(r, "off", false, deadline,
						      deadline_ms);
	if (rc == GL_OK)
		r->state = RE_RELAY_OFF;
	return rc == GL_ERR_SYS ? GL_ERR_RELAY : rc;
}

int re_relay_off(re_relay *r)
{
	if (!r)
		return GL_ERR_ARG;
	re_relay_off_start(r); /* a failed write is retried by finish */
	return re_relay_off_finish(r, r->cfg.off_deadline_ms);
}

int re_relay_close_start(re_relay *r)
{
	if (!r)
		return GL_OK;
	/* the watch's kernel side is freed while "off" is confirmed */
	re_pathwatch_stop(&r->pw);
	return re_relay_off_start(r);
}

int re_relay_close_finish(re_relay *r, int deadline_ms)
{
	int rc;

	if (!r)
		return GL_OK;
	if (r->op != OP_OFF)
		re_relay_off_start(r);
	rc = re_relay_off_finish(r, deadline_ms < 0 ? 0 : deadline_ms);
	re_relay_link_close(r);
	free(r);
	return rc;
}

int re_relay_close(re_relay *r)
{
	if (!r)
		return GL_OK;
	re_relay_close_start(r);
	return re_relay_close_finish(r, r->cfg.off_deadline_ms);
}

enum re_relay_state re_relay_state(const re_relay *r)
{
	return r ? r->state : RE_RELAY_UNKNOWN;
}

const char *re_relay_errmsg(const re_relay *r)
{
	return r ? r->err : "relay: no handle";
}

const char *re_relay_backend_name(const re_relay *r)
{
	return r && r->ops ? r->ops->name : "none";
}
