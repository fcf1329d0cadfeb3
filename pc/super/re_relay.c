/*
 * re_relay.c - the E-stop relay: protocols, state, link checks.
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

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <time.h>
#include <unistd.h>

#include "base_clock.h"
#include "base_durable.h"
#include "gl_err.h"
#include "re_pathwatch.h"
#include "re_relay_be.h"

#define DEVANTECH_QUERY 0x5B /* answer: bit n-1 set = relay n on */
#define ICS_ID		0x50
#define ICS_START	0x51
#define ICS_ALL_OFF	0xFF /* active low: every relay off */
#define ICS_REPLY_MS	500  /* deadline of the identification answer */
#define PTY_MAJOR_MIN	136  /* Unix98 pty slaves: majors 136..143 */
#define PTY_MAJOR_MAX	143
#define NAP_NS		BASE_NS_PER_MS /* longest sleep while waiting */
#define FULL_CHECK_NS	BASE_NS_PER_S  /* stat() the port at least this often */
#define STALE_CHUNKS	4  /* x 16 bytes of stale input dropped per call */
#define RB_READ_MAX	16 /* answer bytes read at once by a check */

enum re_relay_op { OP_NONE = 0, OP_ON, OP_OFF };

struct re_relay {
	struct re_relay_cfg cfg;
	const struct re_relay_be_ops *ops;
	struct re_relay_io io;
	bool linked;		/* io is open */
	dev_t rdev;		/* device opened ... */
	ino_t ino;		/* ... its node (a pty number reused later */
	struct timespec ctim;	/* has the same rdev and inode) */
	struct re_pathwatch pw; /* events that may change what port names */
	int64_t next_full_ns;	/* next stat() of the port, CLOCK_MONOTONIC */
	bool node_suspect;	/* the last stat() check failed */
	enum re_relay_state state;
	uint8_t msg_on[RE_RELAY_CODE_MAX];
	uint8_t msg_off[RE_RELAY_CODE_MAX];
	size_t on_len, off_len;
	const uint8_t *out;	  /* the message being written ... */
	size_t out_len, out_done; /* ... its length, bytes accepted */
	enum re_relay_op op;	  /* switching started, not finished */
	bool on_unconfirmed;	  /* "on" handed over, not confirmed */
	bool reopen;		  /* "off" could not be written */
	int rb_due;		  /* state queries sent, not answered */
	bool rb_discard;	  /* the answers due predate a write */
	bool rb_flush;		  /* answers may be in flight that nobody
				   * awaits: drop input before a query */
	int64_t rb_sent_ns; /* the oldest query due was sent (base_now_ns) */
	int64_t rb_next_ns; /* re_relay_check()'s next query (base_now_ns) */
	char err[RE_RELAY_ERR_MAX];
};

/* ---- protocols ---- */

const char *re_relay_proto_name(enum re_relay_proto proto)
{
	switch (proto) {
	case RE_RELAY_DEVANTECH: return "devantech";
	case RE_RELAY_ICSTATION: return "icstation";
	case RE_RELAY_LCUS: return "lcus";
	case RE_RELAY_KMTRONIC: return "kmtronic";
	case RE_RELAY_EXPLICIT: return "explicit";
	}
	return "unknown";
}

int re_relay_message(const struct re_relay_cfg *cfg, bool on, uint8_t *buf)
{
	int ch = cfg->channel;
	size_t n = on ? cfg->on_len : cfg->off_len;

	if (cfg->proto == RE_RELAY_EXPLICIT) {
		if (!n || n > RE_RELAY_CODE_MAX)
			return GL_ERR_ARG;
		memcpy(buf, on ? cfg->on : cfg->off, n);
		return (int)n;
	}
	if (ch < 1 || ch > 8)
		return GL_ERR_ARG;
	switch (cfg->proto) {
	case RE_RELAY_DEVANTECH:
		buf[0] = (uint8_t)((on ? 0x64 : 0x6E) + ch);
		return 1;
	case RE_RELAY_ICSTATION:
		buf[0] = on ? (uint8_t)(ICS_ALL_OFF & ~(1u << (ch - 1)))
			    : ICS_ALL_OFF;
		return 1;
	case RE_RELAY_LCUS:
		buf[0] = 0xA0;
		buf[1] = (uint8_t)ch;
		buf[2] = on ? 1 : 0;
		buf[3] = (uint8_t)(buf[0] + buf[1] + buf[2]);
		return 4;
	case RE_RELAY_KMTRONIC:
		buf[0] = 0xFF;
		buf[1] = (uint8_t)ch;
		buf[2] = on ? 1 : 0;
		return 3;
	default: return GL_ERR_ARG;
	}
}

/* ---- helpers ---- */

static int set_err(struct re_relay *r, int rc, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int set_err(struct re_relay *r, int rc, const char *fmt, ...)
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

/* Is @st the node opened (device, inode and change time)? */
static bool same_node(const struct re_relay *r, const struct stat *st)
{
	return S_ISCHR(st->st_mode) && st->st_rdev == r->rdev &&
	       st->st_ino == r->ino && st->st_ctim.tv_sec == r->ctim.tv_sec &&
	       st->st_ctim.tv_nsec == r->ctim.tv_nsec;
}

/* ---- time ---- */

static int64_t deadline_in(int ms)
{
	return base_now_ns() + (int64_t)ms * BASE_NS_PER_MS;
}

/* Sleep NAP_NS at most, and never past @deadline. */
static void nap(int64_t deadline)
{
	int64_t t = base_now_ns() + NAP_NS;

	if (t > deadline)
		t = deadline;
	base_sleep_until_ns(t);
}

/* ---- the port and its output ---- */

static void out_set(struct re_relay *r, const uint8_t *msg, size_t len)
{
	r->out = msg;
	r->out_len = len;
	r->out_done = 0;
}

/* Open the back-end and remember which device was opened. */
static int link_open(struct re_relay *r)
{
	struct stat st;
	int rc, fd;

	/* A missing node is said plainly (libserialport would only say
	 * "not a serial port"). */
	if (stat(r->cfg.port, &st) < 0)
		return set_err(r, GL_ERR_RELAY, "cannot open: %s",
			       strerror(errno));
	rc = r->ops->open(&r->io, r->cfg.baud, r->err, sizeof(r->err));
	if (rc)
		return GL_ERR_RELAY;
	fd = r->ops->fd(&r->io);
	if (fd < 0 || fstat(fd, &st) < 0) {
		r->ops->close(&r->io);
		return set_err(r, GL_ERR_RELAY, "cannot open: no descriptor");
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
	out_set(r, NULL, 0);
	return GL_OK;
}

/* Close without waiting: a non-empty output queue is discarded first
 * (close() would wait for it up to the driver's closing_wait). */
static void link_close(struct re_relay *r)
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
static int out_push(struct re_relay *r)
{
	int n;

	if (!r->linked)
		return set_err(r, GL_ERR_SYS, "write failed: port not open");
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
static int out_wait(struct re_relay *r, const char *what, int64_t deadline,
		    int ms)
{
	int q = 0;

	for (;;) {
		if (out_push(r))
			return GL_ERR_SYS;
		if (r->out_done == r->out_len) {
			q = r->ops->queued(&r->io, r->err, sizeof(r->err));
			if (q <= 0)
				return q < 0 ? GL_ERR_SYS : GL_OK;
		}
		if (base_now_ns() >= deadline)
			break;
		nap(deadline);
	}
	if (r->out_done < r->out_len)
		return set_err(r, GL_ERR_TIMEOUT,
			       "%s not confirmed: only %zu of %zu bytes "
			       "accepted by the driver within %d ms",
			       what, r->out_done, r->out_len, ms);
	return set_err(r, GL_ERR_TIMEOUT,
		       "%s not confirmed: %d byte%s still queued after %d ms",
		       what, q, q == 1 ? "" : "s", ms);
}

/* Drop what the board sent before now (bounded). GL_OK or GL_ERR_SYS. */
static int drop_input(struct re_relay *r)
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

/* One byte within @ms: 1, 0 (none came) or GL_ERR_SYS. */
static int read_byte(struct re_relay *r, uint8_t *b, int ms)
{
	int64_t deadline = deadline_in(ms);
	int n;

	for (;;) {
		n = r->ops->read(&r->io, b, 1, r->err, sizeof(r->err));
		if (n != 0 || base_now_ns() >= deadline)
			return n;
		nap(deadline);
	}
}

/* The state query goes out (or is due): count the answer owed. */
static void rb_sent_one(struct re_relay *r)
{
	if (!r->rb_due++)
		r->rb_sent_ns = base_now_ns();
}

/* Does a state-query answer show the channel @on? */
static bool rb_shows(const struct re_relay *r, uint8_t b, bool on)
{
	return ((b >> (r->cfg.channel - 1)) & 1) == on;
}

/* The read-back of @what had no answer by its deadline: the answers stay
 * due; a query the driver never took is dropped (a lone byte). */
static int rb_timeout(struct re_relay *r, const char *what, int ms)
{
	r->rb_discard = true;
	if (r->out_done < r->out_len) {
		out_set(r, NULL, 0);
		return set_err(r, GL_ERR_TIMEOUT,
			       "%s not confirmed: the state query (0x5B) was "
			       "not accepted by the driver within %d ms",
			       what, ms);
	}
	return set_err(r, GL_ERR_TIMEOUT,
		       "%s not confirmed: no answer to the state query (0x5B) "
		       "within %d ms",
		       what, ms);
}

/*
 * Devantech read-back until @deadline: send the state query and read the
 * answers. Answers still due to queries of re_relay_check() arrive first:
 * one showing the channel @on confirms as well (only this call switches the
 * relay, so a state seen after the write started still holds); one showing
 * the other state is judged only when it must be the answer to this
 * query. On a timeout the answers stay due, timed from the oldest query,
 * so that re_relay_check() reports a silent board after
 * readback_timeout_ms.
 */
static int readback_wait(struct re_relay *r, const char *what, bool on,
			 int64_t deadline, int ms)
{
	static const uint8_t query = DEVANTECH_QUERY;
	int skip = r->rb_due, n = 0;
	uint8_t b = 0;

	if (!skip && drop_input(r))
		return GL_ERR_SYS;
	out_set(r, &query, 1);
	for (;;) {
		if (out_push(r))
			return GL_ERR_SYS;
		if (r->out == &query && r->out_done) {
			rb_sent_one(r);
			out_set(r, NULL, 0);
		}
		if (!r->out)
			n = r->ops->read(&r->io, &b, 1, r->err, sizeof(r->err));
		if (n < 0)
			return GL_ERR_SYS;
		if (n == 1 && r->rb_due)
			r->rb_due--;
		if (n == 1 && rb_shows(r, b, on)) {
			r->rb_due = 0; /* the rest, if any, agrees */
			r->rb_flush = skip > 0;
			return GL_OK;
		}
		if (n == 1 && !skip--)
			return set_err(r, GL_ERR_RELAY,
				       "%s not confirmed: read-back shows "
				       "channel %d %s",
				       what, r->cfg.channel, on ? "off" : "on");
		if (n == 1)
			continue;
		if (base_now_ns() >= deadline)
			break;
		nap(deadline);
	}
	return rb_timeout(r, what, ms);
}

/* After writing @what: sent, and read back where the board can. */
static int confirm(struct re_relay *r, const char *what, bool on,
		   int64_t deadline, int ms)
{
	int rc = out_wait(r, what, deadline, ms);

	if (rc == GL_OK && r->cfg.readback)
		rc = readback_wait(r, what, on, deadline, ms);
	return rc;
}

/* Write a message and wait until it is sent, within @ms (open only). */
static int send_wait(struct re_relay *r, const uint8_t *msg, size_t len,
		     const char *what, int ms)
{
	out_set(r, msg, len);
	return out_wait(r, what, deadline_in(ms), ms) ? GL_ERR_RELAY : GL_OK;
}

/* ---- link check ---- */

/* The device node by stat(): after a watch event, once a second, and in
 * every call while it fails. */
static int node_check(struct re_relay *r, int events)
{
	int64_t now = base_now_ns();
	struct stat st;

	if (!(events && re_pathwatch_changed(&r->pw)) && !r->node_suspect &&
	    now < r->next_full_ns)
		return GL_OK;
	r->next_full_ns = now + FULL_CHECK_NS;
	r->node_suspect = true;
	if (stat(r->cfg.port, &st) < 0)
		return set_err(r, GL_ERR_RELAY, "device node is gone: %s",
			       strerror(errno));
	if (!same_node(r, &st))
		return set_err(r, GL_ERR_RELAY,
			       "the port now names another device");
	r->node_suspect = false;
	return GL_OK;
}

/* Descriptor, hang-up and device node from a poll() of the descriptor
 * and the path's watch; no byte written. */
static int link_seen(struct re_relay *r, short fd_ev, short watch_ev)
{
	if (fd_ev & POLLNVAL)
		return set_err(r, GL_ERR_RELAY, "descriptor lost: %s",
			       strerror(EBADF));
	if (fd_ev & POLLHUP)
		return set_err(r, GL_ERR_RELAY, "link lost (hang-up)");
	if (fd_ev & POLLERR)
		return set_err(r, GL_ERR_RELAY, "link error");
	/* no watch: re_pathwatch_changed() answers 1 (stat every call) */
	return node_check(r, r->pw.fd < 0 || watch_ev != 0);
}

/* Is the port open with a descriptor? GL_OK or GL_ERR_RELAY. */
static int link_open_fd(struct re_relay *r, int *fd)
{
	if (!r->linked)
		return set_err(r, GL_ERR_RELAY, "port not open");
	*fd = r->ops->fd(&r->io);
	if (*fd < 0)
		return set_err(r, GL_ERR_RELAY, "descriptor lost: %s",
			       strerror(EBADF));
	return GL_OK;
}

/* One poll() with timeout 0 looks at the descriptor (POLLNVAL: it is
 * gone) and at the inotify watch of the path together (one
 * system call per cycle when nothing happened). */
static int link_check(struct re_relay *r)
{
	struct pollfd p[2] = {{.events = 0}, {.events = POLLIN}};
	int np;

	if (link_open_fd(r, &p[0].fd))
		return GL_ERR_RELAY;
	p[1].fd = r->pw.fd;
	np = r->pw.fd >= 0 ? 2 : 1;
	if (poll(p, (nfds_t)np, 0) < 0 && errno != EINTR)
		return set_err(r, GL_ERR_RELAY, "poll failed: %s",
			       strerror(errno));
	return link_seen(r, p[0].revents, np == 2 ? p[1].revents : 0);
}

/* Between two queries of re_relay_check(): query_ms, or less so that two
 * fit in readback_timeout_ms. */
static int64_t rb_interval_ns(const struct re_relay *r)
{
	int ms = r->cfg.readback_timeout_ms / 2;

	if (ms > r->cfg.query_ms)
		ms = r->cfg.query_ms;
	return ms > 0 ? (int64_t)ms * BASE_NS_PER_MS : 0;
}

/* The state query of re_relay_check(), when one is due (query_ms). */
static int rb_query(struct re_relay *r)
{
	static const uint8_t query = DEVANTECH_QUERY;
	int n;

	if (base_now_ns() < r->rb_next_ns)
		return GL_OK;
	r->rb_next_ns = base_now_ns() + rb_interval_ns(r);
	if (r->rb_flush && drop_input(r))
		return GL_ERR_RELAY;
	r->rb_flush = false;
	n = r->ops->write(&r->io, &query, 1, r->err, sizeof(r->err));
	if (n < 0)
		return GL_ERR_RELAY;
	if (n == 0)
		return set_err(r, GL_ERR_RELAY,
			       "the state query (0x5B) was not "
			       "accepted: output buffer full");
	rb_sent_one(r);
	r->rb_discard = false;
	return GL_OK;
}

/* One answer byte @b: the last one due is judged against the state last
 * confirmed (not while UNKNOWN, not when it predates a write); a byte
 * nobody awaits is dropped. */
static int rb_answer(struct re_relay *r, uint8_t b)
{
	bool on;

	if (!r->rb_due)
		return GL_OK;
	if (--r->rb_due || r->rb_discard || r->state == RE_RELAY_UNKNOWN)
		return GL_OK; /* an older answer, or nothing to compare */
	on = r->state == RE_RELAY_ON;
	if (!rb_shows(r, b, on))
		return set_err(r, GL_ERR_RELAY,
			       "read-back shows channel %d %s, expected %s",
			       r->cfg.channel, on ? "off" : "on",
			       on ? "on" : "off");
	return GL_OK;
}

/*
 * Devantech read-back: one step per check, never waiting. The board must
 * answer within readback_timeout_ms whatever the state. What has arrived
 * is read at once (up to RB_READ_MAX bytes): the input is then empty for
 * the next query, so no read to drop stale bytes is needed before it
 * unless answers may be in flight that nobody awaits (rb_flush). Nothing
 * is sent while a message is half written.
 */
static int readback_step(struct re_relay *r)
{
	uint8_t buf[RB_READ_MAX];
	int n, rc;

	if (!r->cfg.readback || r->out_done < r->out_len)
		return GL_OK;
	if (!r->rb_due)
		return rb_query(r);
	n = r->ops->read(&r->io, buf, sizeof(buf), r->err, sizeof(r->err));
	if (n < 0)
		return GL_ERR_RELAY;
	if (n == 0) {
		if ((base_now_ns() - r->rb_sent_ns) / BASE_NS_PER_MS <=
		    r->cfg.readback_timeout_ms)
			return GL_OK;
		return set_err(r, GL_ERR_RELAY,
			       "no answer to the state query "
			       "(0x5B) within %d ms",
			       r->cfg.readback_timeout_ms);
	}
	for (int i = 0; i < n; i++)
		if ((rc = rb_answer(r, buf[i])) != GL_OK)
			return rc;
	if (n == (int)sizeof(buf))
		r->rb_flush = true; /* more may be waiting */
	return GL_OK;
}

int re_relay_check(re_relay *r)
{
	int rc;

	if (!r)
		return GL_ERR_ARG;
	rc = link_check(r);
	if (!rc)
		rc = readback_step(r);
	return rc;
}

void re_relay_fds(const re_relay *r, int *fd, int *watch_fd)
{
	*fd = r && r->linked ? r->ops->fd(&r->io) : -1;
	*watch_fd = *fd >= 0 ? r->pw.fd : -1;
}

int re_relay_check_seen(re_relay *r, short fd_revents, short watch_revents)
{
	int fd, rc;

	if (!r)
		return GL_ERR_ARG;
	rc = link_open_fd(r, &fd);
	if (!rc)
		rc = link_seen(r, fd_revents, watch_revents);
	if (!rc)
		rc = readback_step(r);
	return rc;
}

/* ---- ICStation handshake ---- */

/* The identity of the board's current power-up: its device node. */
static int ics_identity(struct re_relay *r, char *buf, size_t cap)
{
	struct stat st;

	if (stat(r->cfg.port, &st) < 0)
		return set_err(r, GL_ERR_RELAY, "cannot open: %s",
			       strerror(errno));
	snprintf(buf, cap, "icstation rdev=%ju ino=%ju ctime=%lld.%09ld",
		 (uintmax_t)st.st_rdev, (uintmax_t)st.st_ino,
		 (long long)st.st_ctim.tv_sec, (long)st.st_ctim.tv_nsec);
	return GL_OK;
}

static bool ics_recorded(const struct re_relay *r, const char *id)
{
	char line[256];
	FILE *f = fopen(r->cfg.icstation_state, "re");
	bool same = false;

	if (!f)
		return false;
	if (fgets(line, sizeof(line), f))
		same =
		    !strncmp(line, id, strlen(id)) && line[strlen(id)] == ' ';
	fclose(f);
	return same;
}

/* Write the record durably: temporary file, fsync, rename, fsync of the
 * directory (base_durable_write). */
static int ics_record(struct re_relay *r, const char *id, uint8_t model)
{
	char text[256];
	int n;

	n = snprintf(text, sizeof(text), "%s model=0x%02X\n", id, model);
	if (n < 0 || (size_t)n >= sizeof(text))
		n = (int)strlen(text);
	if (base_durable_write(r->cfg.icstation_state, text, (size_t)n, 0644) ==
	    0)
		return GL_OK;
	return set_err(r, GL_ERR_RELAY,
		       "cannot record the icstation "
		       "handshake in '%s': %s",
		       r->cfg.icstation_state, strerror(errno));
}

static int ics_handshake(struct re_relay *r)
{
	static const uint8_t id_req = ICS_ID, start = ICS_START;
	static const uint8_t all_off = ICS_ALL_OFF;
	const int ms = r->cfg.write_timeout_ms;
	char id[160];
	uint8_t b = 0;
	int n;

	if (ics_identity(r, id, sizeof(id)))
		return GL_ERR_RELAY;
	if (ics_recorded(r, id))
		return GL_OK;
	if (drop_input(r) ||
	    send_wait(r, &id_req, 1, "icstation handshake", ms))
		return GL_ERR_RELAY;
	n = read_byte(r, &b, ICS_REPLY_MS);
	if (n != 1 || (b != 0xAB && b != 0xAD && b != 0xAC)) {
		/* 0x50 may just have switched relays on: all off, now. */
		send_wait(r, &all_off, 1, "off", r->cfg.off_deadline_ms);
		if (n == 1)
			return set_err(r, GL_ERR_RELAY,
				       "unexpected answer "
				       "0x%02X to the icstation handshake",
				       b);
		return set_err(r, GL_ERR_RELAY,
			       "no answer to the icstation "
			       "handshake within %d ms (board already "
			       "initialised?): unplug and re-plug the relay",
			       ICS_REPLY_MS);
	}
	if (send_wait(r, &start, 1, "icstation handshake", ms))
		return GL_ERR_RELAY;
	return ics_record(r, id, b);
}

/* ---- open / on / off / close ---- */

static int check_cfg(struct re_relay *r)
{
	const struct re_relay_cfg *c = &r->cfg;
	int n;

	if (!c->port[0])
		return set_err(r, GL_ERR_ARG, "no port configured");
	if (c->clinical && c->backend == RE_RELAY_BACKEND_TTY)
		return set_err(r, GL_ERR_ARG,
			       "the tty back-end is not "
			       "allowed in clinical mode");
	if (c->write_timeout_ms <= 0 || c->off_deadline_ms <= 0 ||
	    c->baud <= 0 || (c->readback && c->proto != RE_RELAY_DEVANTECH))
		return set_err(r, GL_ERR_ARG, "invalid settings");
	n = re_relay_message(c, true, r->msg_on);
	if (n > 0)
		r->on_len = (size_t)n;
	if (n > 0)
		n = re_relay_message(c, false, r->msg_off);
	if (n <= 0)
		return set_err(r, GL_ERR_ARG,
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

	out_set(r, r->msg_off, r->off_len);
	if (confirm(r, "off", false, deadline_in(ms), ms))
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
	rc = link_open(r);
	if (!rc && r->cfg.proto == RE_RELAY_ICSTATION)
		rc = ics_handshake(r);
	if (!rc)
		rc = first_off(r);
	if (rc)
		goto out_close;
	*out = r;
	return GL_OK;
out_close:
	link_close(r);
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
	out_set(r, NULL, 0);
}

int re_relay_on_start(re_relay *r)
{
	if (!r)
		return GL_ERR_ARG;
	r->op = OP_NONE;
	if (r->out_done < r->out_len)
		set_err(r, GL_ERR_RELAY,
			"on refused: the last message is not written yet");
	else if (!link_check(r))
		r->op = OP_ON;
	if (r->op != OP_ON) {
		r->state = RE_RELAY_UNKNOWN;
		return GL_ERR_RELAY;
	}
	if (r->rb_due)
		r->rb_discard = true;
	r->state = RE_RELAY_UNKNOWN;
	r->on_unconfirmed = true;
	out_set(r, r->msg_on, r->on_len);
	if (out_push(r)) {
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
	deadline = deadline_in(deadline_ms);
	r->op = OP_NONE;
	rc = confirm(r, "on", true, deadline, deadline_ms);
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
		return true; /* link_open() says why it cannot open */
	if (same_node(r, &st) || !S_ISCHR(st.st_mode) ||
	    major(st.st_rdev) < PTY_MAJOR_MIN ||
	    major(st.st_rdev) > PTY_MAJOR_MAX)
		return true;
	set_err(r, GL_ERR_RELAY, "the port now names another device");
	return false;
}

/* "off" could not be written: reopen once and hand it over again; on
 * failure keep both reasons. */
static int off_reopen(struct re_relay *r)
{
	char first[RE_RELAY_ERR_MAX], second[RE_RELAY_ERR_MAX];
	size_t skip = strlen(r->cfg.port) + 10; /* "relay '...': " */

	snprintf(first, sizeof(first), "%s", r->err);
	link_close(r);
	if (reopen_allowed(r) && !link_open(r)) {
		out_set(r, r->msg_off, r->off_len);
		if (!out_push(r))
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
		out_set(r, r->msg_off, r->off_len);
	r->reopen = out_push(r) != GL_OK;
	return r->reopen ? GL_ERR_RELAY : GL_OK;
}

int re_relay_off_finish(re_relay *r, int deadline_ms)
{
	int64_t deadline;
	bool reopened;
	int rc;

	if (!r || r->op != OP_OFF || deadline_ms < 0)
		return GL_ERR_ARG;
	deadline = deadline_in(deadline_ms);
	r->op = OP_NONE;
	reopened = r->reopen;
	r->reopen = false;
	if (reopened && off_reopen(r))
		return GL_ERR_RELAY;
	rc = confirm(r, "off", false, deadline, deadline_ms);
	if (rc == GL_ERR_SYS && !reopened) /* I/O error: reopen once */
		rc = off_reopen(r)
			 ? GL_ERR_RELAY
			 : confirm(r, "off", false, deadline, deadline_ms);
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
	link_close(r);
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
