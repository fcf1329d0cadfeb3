/*
 * re_relay.c - the E-stop relay: protocols, state, link checks.
 *
 * Safety decisions (docs/config.md, "E-stop relay"):
 * - Opening switches the relay off first; only re_relay_on() switches it
 *   on, and it refuses when the link check fails.
 * - re_relay_off() always writes, and on failure reopens the port once and
 *   writes again (but never on a different pseudo-terminal: pty numbers are
 *   reused by unrelated programs); only a written and drained message counts
 *   as "off".
 * - re_relay_check() never writes a state byte. It looks at the descriptor
 *   (fcntl, poll with timeout 0: hang-up/error), the device node (stat: still
 *   there, same st_rdev, inode and change time as at open, so a pty number
 *   reused by someone else or a re-plugged adapter is noticed) and, for
 *   Devantech boards with read-back enabled, the board's own report of its
 *   relays: the query byte 0x5B is sent in one cycle and its answer read
 *   without waiting in a later one, so the check never blocks on the 9600
 *   baud line.
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

#include "gl_err.h"
#include "re_relay_be.h"

#define DEVANTECH_QUERY 0x5B /* answer: bit n-1 set = relay n on */
#define ICS_ID		0x50
#define ICS_START	0x51
#define ICS_ALL_OFF	0xFF /* active low: every relay off */
#define ICS_REPLY_MS	500  /* deadline of the identification answer */
#define PTY_MAJOR_MIN	136  /* Unix98 pty slaves: majors 136..143 */
#define PTY_MAJOR_MAX	143

struct re_relay {
	struct re_relay_cfg cfg;
	const struct re_relay_be_ops *ops;
	struct re_relay_io io;
	bool linked;	      /* io is open */
	dev_t rdev;	      /* device opened ... */
	ino_t ino;	      /* ... its node (a pty number reused later */
	struct timespec ctim; /* has the same rdev and inode) */
	enum re_relay_state state;
	uint8_t msg_on[RE_RELAY_CODE_MAX];
	uint8_t msg_off[RE_RELAY_CODE_MAX];
	size_t on_len, off_len;
	bool rb_pending; /* query sent, answer awaited */
	bool rb_discard; /* the awaited answer predates a write */
	struct timespec rb_sent;
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

static long ms_since(const struct timespec *t)
{
	struct timespec now;

	clock_gettime(CLOCK_MONOTONIC, &now);
	return (now.tv_sec - t->tv_sec) * 1000L +
	       (now.tv_nsec - t->tv_nsec) / 1000000L;
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
	r->rb_pending = false;
	return GL_OK;
}

static void link_close(struct re_relay *r)
{
	if (r->linked)
		r->ops->close(&r->io);
	r->linked = false;
}

static int send_msg(struct re_relay *r, const uint8_t *msg, size_t len)
{
	if (!r->linked)
		return set_err(r, GL_ERR_RELAY, "write failed: port not open");
	if (r->ops->send(&r->io, msg, len, r->cfg.write_timeout_ms, r->err,
			 sizeof(r->err)))
		return GL_ERR_RELAY;
	return GL_OK;
}

/* ---- link check ---- */

/* Descriptor, hang-up and device node; no byte written. */
static int link_check(struct re_relay *r)
{
	struct pollfd p = {.events = POLLIN};
	struct stat st;
	int fd;

	if (!r->linked)
		return set_err(r, GL_ERR_RELAY, "port not open");
	fd = r->ops->fd(&r->io);
	if (fd < 0 || fcntl(fd, F_GETFD) < 0)
		return set_err(r, GL_ERR_RELAY, "descriptor lost: %s",
			       strerror(fd < 0 ? EBADF : errno));
	p.fd = fd;
	if (poll(&p, 1, 0) < 0 && errno != EINTR)
		return set_err(r, GL_ERR_RELAY, "poll failed: %s",
			       strerror(errno));
	if (p.revents & POLLHUP)
		return set_err(r, GL_ERR_RELAY, "link lost (hang-up)");
	if (p.revents & (POLLERR | POLLNVAL))
		return set_err(r, GL_ERR_RELAY, "link error");
	if (stat(r->cfg.port, &st) < 0)
		return set_err(r, GL_ERR_RELAY, "device node is gone: %s",
			       strerror(errno));
	if (!same_node(r, &st))
		return set_err(r, GL_ERR_RELAY,
			       "the port now names another device");
	return GL_OK;
}

/* Devantech read-back: one step per check, never waiting. */
static int readback_step(struct re_relay *r)
{
	static const uint8_t query = DEVANTECH_QUERY;
	uint8_t b;
	int n, bit, want;

	if (!r->cfg.readback || r->state == RE_RELAY_UNKNOWN)
		return GL_OK;
	if (!r->rb_pending) {
		while (r->ops->recv(&r->io, &b, 1, 0, r->err, sizeof(r->err)) >
		       0)
			; /* drop stale bytes */
		if (r->ops->send(&r->io, &query, 1, 0, r->err, sizeof(r->err)))
			return GL_ERR_RELAY;
		clock_gettime(CLOCK_MONOTONIC, &r->rb_sent);
		r->rb_pending = true;
		r->rb_discard = false;
		return GL_OK;
	}
	n = r->ops->recv(&r->io, &b, 1, 0, r->err, sizeof(r->err));
	if (n < 0)
		return GL_ERR_RELAY;
	if (n == 0) {
		if (ms_since(&r->rb_sent) <= r->cfg.readback_timeout_ms)
			return GL_OK;
		return set_err(r, GL_ERR_RELAY,
			       "no answer to the state query "
			       "(0x5B) within %d ms",
			       r->cfg.readback_timeout_ms);
	}
	r->rb_pending = false;
	if (r->rb_discard)
		return GL_OK;
	bit = (b >> (r->cfg.channel - 1)) & 1;
	want = r->state == RE_RELAY_ON;
	if (bit != want)
		return set_err(r, GL_ERR_RELAY,
			       "read-back shows channel %d "
			       "%s, expected %s",
			       r->cfg.channel, bit ? "on" : "off",
			       want ? "on" : "off");
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

/* Write the record atomically: temporary file, fsync, rename. */
static int ics_record(struct re_relay *r, const char *id, uint8_t model)
{
	char tmp[RE_RELAY_PATH_MAX + 8], text[256];
	int fd, n, ok;

	snprintf(tmp, sizeof(tmp), "%s.tmp", r->cfg.icstation_state);
	n = snprintf(text, sizeof(text), "%s model=0x%02X\n", id, model);
	fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
	if (fd < 0)
		goto out_fail;
	ok = write(fd, text, (size_t)n) == n && !fsync(fd);
	ok = !close(fd) && ok;
	if (ok && !rename(tmp, r->cfg.icstation_state))
		return GL_OK;
	unlink(tmp);
out_fail:
	return set_err(r, GL_ERR_RELAY,
		       "cannot record the icstation "
		       "handshake in '%s': %s",
		       r->cfg.icstation_state, strerror(errno));
}

static int ics_handshake(struct re_relay *r)
{
	static const uint8_t id_req = ICS_ID, start = ICS_START;
	static const uint8_t all_off = ICS_ALL_OFF;
	char id[160];
	uint8_t b;
	int n;

	if (ics_identity(r, id, sizeof(id)))
		return GL_ERR_RELAY;
	if (ics_recorded(r, id))
		return GL_OK;
	while (r->ops->recv(&r->io, &b, 1, 0, r->err, sizeof(r->err)) > 0)
		; /* drop stale bytes */
	if (send_msg(r, &id_req, 1))
		return GL_ERR_RELAY;
	n = r->ops->recv(&r->io, &b, 1, ICS_REPLY_MS, r->err, sizeof(r->err));
	if (n != 1 || (b != 0xAB && b != 0xAD && b != 0xAC)) {
		/* 0x50 may just have switched relays on: all off, now. */
		send_msg(r, &all_off, 1);
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
	if (send_msg(r, &start, 1))
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
	if (c->write_timeout_ms <= 0 || c->baud <= 0 ||
	    (c->readback && c->proto != RE_RELAY_DEVANTECH))
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
	rc = check_cfg(r);
	if (rc)
		goto out_free;
	r->ops = pick_backend(&r->cfg);
	rc = link_open(r);
	if (!rc && r->cfg.proto == RE_RELAY_ICSTATION)
		rc = ics_handshake(r);
	if (!rc)
		rc = send_msg(r, r->msg_off, r->off_len);
	if (rc)
		goto out_close;
	r->state = RE_RELAY_OFF;
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

int re_relay_on(re_relay *r)
{
	if (!r)
		return GL_ERR_ARG;
	if (link_check(r)) {
		r->state = RE_RELAY_UNKNOWN;
		return GL_ERR_RELAY;
	}
	if (r->rb_pending)
		r->rb_discard = true;
	if (send_msg(r, r->msg_on, r->on_len)) {
		r->state = RE_RELAY_UNKNOWN;
		return GL_ERR_RELAY;
	}
	r->state = RE_RELAY_ON;
	r->err[0] = '\0';
	return GL_OK;
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

/* Reopen once after a failed "off" and try again; keep both reasons. */
static int off_again(struct re_relay *r)
{
	char first[RE_RELAY_ERR_MAX], second[RE_RELAY_ERR_MAX];
	size_t skip = strlen(r->cfg.port) + 10; /* "relay '...': " */

	snprintf(first, sizeof(first), "%s", r->err);
	link_close(r);
	if (reopen_allowed(r) && !link_open(r) &&
	    !send_msg(r, r->msg_off, r->off_len)) {
		r->state = RE_RELAY_OFF;
		return GL_OK;
	}
	if (strlen(r->err) < skip)
		skip = 0;
	snprintf(second, sizeof(second), "%s", r->err + skip);
	snprintf(r->err, sizeof(r->err), "%.200s; reopen: %.200s", first,
		 second);
	return GL_ERR_RELAY;
}

int re_relay_off(re_relay *r)
{
	if (!r)
		return GL_ERR_ARG;
	if (r->rb_pending)
		r->rb_discard = true;
	r->state = RE_RELAY_UNKNOWN;
	if (!send_msg(r, r->msg_off, r->off_len)) {
		r->state = RE_RELAY_OFF;
		return GL_OK;
	}
	return off_again(r);
}

int re_relay_close(re_relay *r)
{
	int rc;

	if (!r)
		return GL_OK;
	rc = re_relay_off(r);
	link_close(r);
	free(r);
	return rc;
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
