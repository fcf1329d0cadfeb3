/*
 * re_relay_sp.c - relay back-end over libserialport, for real USB relays.
 *
 * libserialport returns SP_ERR_FAIL with the OS error in errno
 * (sp_last_error_code() is errno on Unix); we format strerror(errno)
 * ourselves rather than call sp_last_error_message(), which allocates and
 * shows a stale errno after SP_ERR_ARG (relays-and-serial.md).
 *
 * Only calls that return at once are used (re_relay_be.h): sp_open leaves
 * the descriptor O_NONBLOCK, writes and reads are sp_nonblocking_*, the
 * output queue is sp_output_waiting (TIOCOUTQ) and sp_flush; never
 * sp_drain or sp_blocking_*, whose waits have no deadline or hold the
 * caller for the whole timeout.
 *
 * Also the USB serial number of a port (re_relay_usb_serial()), read the
 * way libserialport reads every port's details, for the clinical
 * start-up's check that the relay is the board bound to this robot.
 */
#include <errno.h>
#include <libserialport.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "re_relay.h"
#include "re_relay_be.h"

static const char *sp_reason(enum sp_return rc)
{
	switch (rc) {
	case SP_ERR_ARG: return "not a serial port known to libserialport";
	case SP_ERR_MEM: return "out of memory";
	case SP_ERR_SUPP: return "operation not supported";
	case SP_ERR_FAIL: return strerror(errno);
	default: return "unknown libserialport error";
	}
}

static int sp_fail(const struct re_relay_io *io, const char *what,
		   enum sp_return rc, char *err, size_t errlen)
{
	int saved = errno;

	if (err && errlen)
		snprintf(err, errlen, "relay '%s': %s: %s", io->path, what,
			 sp_reason(rc));
	errno = saved;
	return rc == SP_ERR_MEM ? GL_ERR_NOMEM : GL_ERR_SYS;
}

static enum sp_return sp_configure(struct sp_port *port, int baud)
{
	enum sp_return rc;

	rc = sp_set_baudrate(port, baud);
	if (rc == SP_OK)
		rc = sp_set_bits(port, 8);
	if (rc == SP_OK)
		rc = sp_set_parity(port, SP_PARITY_NONE);
	if (rc == SP_OK)
		rc = sp_set_stopbits(port, 1);
	if (rc == SP_OK)
		rc = sp_set_flowcontrol(port, SP_FLOWCONTROL_NONE);
	return rc;
}

/*
 * The port by the name of its device node: libserialport finds a port's
 * details under /sys/class/tty/<name after /dev/>, so a link such as
 * /dev/roboelf-relay (udev's SYMLINK) or /dev/serial/by-id/usb-... is
 * refused as "not a serial port" unless resolved first. A path that does
 * not resolve is passed as given (libserialport then says why).
 */
static enum sp_return port_by_path(const char *path, struct sp_port **port)
{
	char real[PATH_MAX];

	return sp_get_port_by_name(realpath(path, real) ? real : path, port);
}

static int spb_open(struct re_relay_io *io, int baud, char *err, size_t errlen)
{
	struct sp_port *port = NULL;
	enum sp_return rc;
	int ret;

	rc = port_by_path(io->path, &port);
	if (rc != SP_OK)
		return sp_fail(io, "cannot open", rc, err, errlen);
	rc = sp_open(port, SP_MODE_READ_WRITE);
	if (rc != SP_OK) {
		ret = sp_fail(io, "cannot open", rc, err, errlen);
		goto out_free;
	}
	rc = sp_configure(port, baud);
	if (rc != SP_OK) {
		ret = sp_fail(io, "cannot configure", rc, err, errlen);
		goto out_close;
	}
	io->port = port;
	return GL_OK;
out_close:
	sp_close(port);
out_free:
	sp_free_port(port);
	return ret;
}

/* Not open: the same message a failed call would give. */
static int spb_closed(const struct re_relay_io *io, const char *what, char *err,
		      size_t errlen)
{
	errno = EBADF;
	return sp_fail(io, what, SP_ERR_FAIL, err, errlen);
}

/*
 * libserialport 0.1.1 passes write()'s EAGAIN on as SP_ERR_FAIL (later
 * versions return 0): either way, "the driver's buffer is full".
 */
static int spb_write(struct re_relay_io *io, const uint8_t *buf, size_t len,
		     char *err, size_t errlen)
{
	enum sp_return rc;

	if (!io->port)
		return spb_closed(io, "write failed", err, errlen);
	rc = sp_nonblocking_write(io->port, buf, len);
	if (rc == SP_ERR_FAIL && (errno == EAGAIN || errno == EWOULDBLOCK))
		return 0;
	if (rc < 0)
		return sp_fail(io, "write failed", rc, err, errlen);
	return (int)rc;
}

/* TIOCOUTQ: the USB-serial driver's buffer and its transfers in flight. */
static int spb_queued(struct re_relay_io *io, char *err, size_t errlen)
{
	enum sp_return rc;

	if (!io->port)
		return spb_closed(io, "output queue unreadable", err, errlen);
	rc = sp_output_waiting(io->port);
	if (rc < 0)
		return sp_fail(io, "output queue unreadable", rc, err, errlen);
	return (int)rc;
}

static int spb_read(struct re_relay_io *io, uint8_t *buf, size_t len, char *err,
		    size_t errlen)
{
	enum sp_return rc;

	if (!io->port)
		return spb_closed(io, "read failed", err, errlen);
	rc = sp_nonblocking_read(io->port, buf, len);
	if (rc < 0)
		return sp_fail(io, "read failed", rc, err, errlen);
	return (int)rc;
}

static void spb_discard(struct re_relay_io *io)
{
	if (io->port)
		sp_flush(io->port, SP_BUF_OUTPUT);
}

static int spb_fd(const struct re_relay_io *io)
{
	int fd = -1;

	if (!io->port || sp_get_port_handle(io->port, &fd) != SP_OK)
		return -1;
	return fd;
}

static void spb_close(struct re_relay_io *io)
{
	if (!io->port)
		return;
	sp_close(io->port);
	sp_free_port(io->port);
	io->port = NULL;
}

const struct re_relay_be_ops re_relay_be_serialport = {
    .name = "serialport",
    .open = spb_open,
    .write = spb_write,
    .queued = spb_queued,
    .read = spb_read,
    .discard = spb_discard,
    .fd = spb_fd,
    .close = spb_close,
};

int re_relay_usb_serial(const char *path, char *buf, size_t cap, char *err,
			size_t errlen)
{
	struct re_relay_io io = {.path = path, .fd = -1, .port = NULL};
	struct sp_port *port = NULL;
	enum sp_return rc;
	const char *s = NULL;
	size_t len = 0;

	if (!path || !buf || !cap)
		return GL_ERR_ARG;
	buf[0] = '\0';
	rc = port_by_path(path, &port);
	if (rc != SP_OK) {
		sp_fail(&io, "cannot read its USB serial number", rc, err,
			errlen);
		return GL_ERR_RELAY;
	}
	if (sp_get_port_transport(port) == SP_TRANSPORT_USB)
		s = sp_get_port_usb_serial(port);
	if (s)
		len = strlen(s);
	if (len < cap)
		memcpy(buf, s ? s : "", len + 1);
	sp_free_port(port);
	if (len >= cap) {
		if (err && errlen)
			snprintf(err, errlen,
				 "relay '%s': its USB serial number is longer "
				 "than %zu bytes",
				 path, cap - 1);
		return GL_ERR_RELAY;
	}
	return GL_OK;
}
