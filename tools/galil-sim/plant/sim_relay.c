/*
 * sim_relay.c - the virtual E-stop relay on a pseudo-terminal.
 *
 * Protocol facts: relays-and-serial.md. Relay 1 switches motor power. The
 * slave side of the pty is kept open here for the life of the board: with
 * no slave open, a read on the master returns EIO.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdarg.h>
#include <pty.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include "gl_err.h"
#include "sim_relay.h"

#define RELAY_READ_CHUNK 256 /* bytes per read() */

struct sim_relay {
	struct sim_relay_dec dec;
	enum sim_relay_fault fault;
	int master, slave; /* -1 without a pty */
	int had_pty;	   /* recreate the pty on repair */
	char tty[64];
	char link[PATH_MAX]; /* "" = no link */
	void (*event)(void *ud, const char *line);
	void *ud;
};

/* ---- the board -------------------------------------------------------- */

static void relay_event(struct sim_relay *r, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void relay_event(struct sim_relay *r, const char *fmt, ...)
{
	char line[160];
	va_list ap;

	if (!r->event)
		return;
	va_start(ap, fmt);
	vsnprintf(line, sizeof(line), fmt, ap);
	va_end(ap);
	r->event(r->ud, line);
}

int sim_relay_new(struct sim_relay **out, enum sim_relay_proto proto,
		  void (*event)(void *ud, const char *line), void *ud)
{
	struct sim_relay *r = calloc(1, sizeof(*r));

	*out = NULL;
	if (!r)
		return GL_ERR_NOMEM;
	sim_relay_dec_reset(&r->dec, proto);
	r->master = r->slave = -1;
	r->event = event;
	r->ud = ud;
	*out = r;
	return 0;
}

/* Remove the link only while it still points at our tty. */
static void remove_link(struct sim_relay *r)
{
	char target[PATH_MAX];
	ssize_t n;

	if (!r->link[0] || !r->tty[0])
		return;
	n = readlink(r->link, target, sizeof(target) - 1);
	if (n < 0)
		return;
	target[n] = '\0';
	if (!strcmp(target, r->tty))
		unlink(r->link);
}

static void close_pty(struct sim_relay *r)
{
	remove_link(r);
	if (r->master >= 0)
		close(r->master);
	if (r->slave >= 0)
		close(r->slave);
	r->master = r->slave = -1;
	r->tty[0] = '\0';
}

void sim_relay_free(struct sim_relay *r)
{
	if (!r)
		return;
	close_pty(r);
	free(r);
}

static int make_link(struct sim_relay *r, char *err, size_t errlen)
{
	char tmp[PATH_MAX + 16];
	struct stat st;

	if (lstat(r->link, &st) == 0 && !S_ISLNK(st.st_mode)) {
		snprintf(err, errlen,
			 "refusing to replace '%s': not a "
			 "symbolic link",
			 r->link);
		return GL_ERR_ARG;
	}
	snprintf(tmp, sizeof(tmp), "%s.%ld.tmp", r->link, (long)getpid());
	unlink(tmp);
	if (symlink(r->tty, tmp) < 0 || rename(tmp, r->link) < 0) {
		snprintf(err, errlen, "cannot create link '%s': %s", r->link,
			 strerror(errno));
		unlink(tmp);
		return GL_ERR_SYS;
	}
	return 0;
}

static int open_pty(struct sim_relay *r, char *err, size_t errlen)
{
	struct termios tio;
	int rc;

	if (openpty(&r->master, &r->slave, NULL, NULL, NULL) < 0) {
		snprintf(err, errlen, "cannot create pseudo-terminal: %s",
			 strerror(errno));
		r->master = r->slave = -1;
		return GL_ERR_SYS;
	}
	/* raw: no echo of our replies back to us, no CR/LF mangling */
	if (tcgetattr(r->slave, &tio) == 0) {
		cfmakeraw(&tio);
		tcsetattr(r->slave, TCSANOW, &tio);
	}
	fcntl(r->master, F_SETFL, fcntl(r->master, F_GETFL) | O_NONBLOCK);
	fcntl(r->master, F_SETFD, FD_CLOEXEC);
	fcntl(r->slave, F_SETFD, FD_CLOEXEC);
	rc = ttyname_r(r->slave, r->tty, sizeof(r->tty));
	if (rc != 0) {
		snprintf(err, errlen, "cannot name pseudo-terminal: %s",
			 strerror(rc));
		close_pty(r);
		return GL_ERR_SYS;
	}
	if (r->link[0] && make_link(r, err, errlen) < 0) {
		r->link[0] = '\0';
		close_pty(r);
		return GL_ERR_SYS;
	}
	return 0;
}

int sim_relay_attach(struct sim_relay *r, const char *link_path, char *err,
		     size_t errlen)
{
	int rc;

	if (r->master >= 0 || r->had_pty) {
		snprintf(err, errlen, "relay pty already attached");
		return GL_ERR_ARG;
	}
	if (link_path && strlen(link_path) >= sizeof(r->link)) {
		snprintf(err, errlen, "relay link path too long");
		return GL_ERR_ARG;
	}
	snprintf(r->link, sizeof(r->link), "%s", link_path ? link_path : "");
	rc = open_pty(r, err, errlen);
	if (rc == 0)
		r->had_pty = 1;
	return rc;
}

const char *sim_relay_tty(const struct sim_relay *r)
{
	return r->tty;
}

int sim_relay_fd(const struct sim_relay *r)
{
	return r->fault == SIM_RELAY_WEDGE ? -1 : r->master;
}

int sim_relay_queued(const struct sim_relay *r)
{
	int n = 0;

	if (r->master < 0 || ioctl(r->master, FIONREAD, &n) < 0)
		return 0;
	return n;
}

int sim_relay_power(const struct sim_relay *r)
{
	return (r->fault == SIM_RELAY_OK || r->fault == SIM_RELAY_WEDGE) &&
	       (r->dec.states & 1);
}

static void feed_byte(struct sim_relay *r, uint8_t b)
{
	uint8_t reply[4];
	const char *note;
	int before = sim_relay_power(r);
	size_t n = sim_relay_dec_feed(&r->dec, b, reply, sizeof(reply), &note);

	if (n && write(r->master, reply, n) < 0)
		relay_event(r, "relay reply lost: %s", strerror(errno));
	if (*note)
		relay_event(r, "relay ignored byte 0x%02x: %s", b, note);
	if (sim_relay_power(r) != before)
		relay_event(r, "relay %s (byte 0x%02x)",
			    sim_relay_power(r) ? "on" : "off", b);
}

int sim_relay_service(struct sim_relay *r)
{
	uint8_t buf[RELAY_READ_CHUNK];
	int total = 0;
	ssize_t n;

	if (r->master < 0 || r->fault == SIM_RELAY_WEDGE)
		return 0;
	for (;;) {
		n = read(r->master, buf, sizeof(buf));
		if (n < 0 && errno == EINTR)
			continue;
		if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
			return total;
		if (n <= 0)
			return GL_ERR_SYS;
		total += (int)n;
		if (r->fault != SIM_RELAY_OK)
			continue; /* a failing board ignores bytes */
		for (ssize_t i = 0; i < n; i++)
			feed_byte(r, buf[i]);
	}
}

int sim_relay_set(struct sim_relay *r, int on)
{
	int before = sim_relay_power(r);

	if (r->fault != SIM_RELAY_OK)
		return GL_ERR_RELAY;
	if (on)
		r->dec.states |= 1;
	else
		r->dec.states &= (uint8_t)~1u;
	if (sim_relay_power(r) != before)
		relay_event(r, "relay %s (control port)", on ? "on" : "off");
	return 0;
}

/*
 * A wedged board is reset: what the host queued meanwhile is discarded
 * unread (TCIFLUSH empties the line discipline and the tty buffers still
 * on their way to it), a frame begun before the wedge is dropped, every
 * relay is off.
 */
static void unwedge(struct sim_relay *r)
{
	int before = sim_relay_power(r);

	if (r->master >= 0)
		tcflush(r->master, TCIFLUSH);
	r->dec.states = 0;
	r->dec.nframe = 0;
	if (r->dec.proto != SIM_RELAY_ICSTATION)
		r->dec.stage = 0; /* devantech: a pending 0x5C mask byte */
	r->fault = SIM_RELAY_OK;
	relay_event(r, "relay discarded the bytes queued while wedged");
	if (before)
		relay_event(r, "relay off (board reset after wedge)");
	relay_event(r, "relay obeys again (relays off)");
}

static int repair(struct sim_relay *r, char *err, size_t errlen)
{
	int rc;

	if (r->fault == SIM_RELAY_WEDGE) {
		unwedge(r);
		return 0;
	}
	if (r->fault == SIM_RELAY_UNPLUG) {
		sim_relay_dec_reset(&r->dec, r->dec.proto);
		if (r->had_pty) {
			rc = open_pty(r, err, errlen);
			if (rc < 0)
				return rc;
		}
		r->fault = SIM_RELAY_OK;
		relay_event(r, "relay plugged in%s%s", r->tty[0] ? " at " : "",
			    r->tty);
		return 0;
	}
	if (r->fault == SIM_RELAY_WRITEFAIL) {
		r->fault = SIM_RELAY_OK;
		relay_event(r, "relay obeys again (relays off)");
	}
	return 0;
}

int sim_relay_set_fault(struct sim_relay *r, enum sim_relay_fault f, char *err,
			size_t errlen)
{
	int before = sim_relay_power(r);

	if (f == SIM_RELAY_OK)
		return repair(r, err, errlen);
	if (r->fault == SIM_RELAY_UNPLUG)
		return 0; /* an unplugged board cannot also fail */
	if (f == SIM_RELAY_WEDGE) {
		if (r->fault != SIM_RELAY_WEDGE)
			relay_event(r, "relay wedged (bytes not read)");
		r->fault = SIM_RELAY_WEDGE;
		return 0; /* the relays keep their state */
	}
	r->dec.states = 0;
	if (f == SIM_RELAY_UNPLUG) {
		close_pty(r);
		r->fault = SIM_RELAY_UNPLUG;
		relay_event(r, "relay unplugged");
	} else {
		r->fault = SIM_RELAY_WRITEFAIL;
		relay_event(r, "relay write failing (bytes ignored)");
	}
	if (before)
		relay_event(r, "relay off (%s)",
			    f == SIM_RELAY_UNPLUG ? "unplugged"
						  : "board failed");
	return 0;
}

enum sim_relay_fault sim_relay_get_fault(const struct sim_relay *r)
{
	return r->fault;
}
