/*
 * re_relay_tty.c - relay back-end over a plain POSIX terminal (termios).
 *
 * For galil-sim's virtual relay, a pseudo-terminal that libserialport
 * refuses (relays-and-serial.md); works on /dev/ttyUSB* too, but clinical
 * mode never uses it. The descriptor is non-blocking and no call here
 * waits: no tcdrain() (it has no deadline); the output queue is read with
 * TIOCOUTQ and emptied with tcflush() (re_relay_be.h).
 */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include "gl_err.h"
#include "re_relay_be.h"

static speed_t tty_speed(int baud)
{
	switch (baud) {
	case 1200: return B1200;
	case 2400: return B2400;
	case 4800: return B4800;
	case 19200: return B19200;
	case 38400: return B38400;
	case 57600: return B57600;
	case 115200: return B115200;
	default: return B9600;
	}
}

static int tty_fail(const struct re_relay_io *io, const char *what, char *err,
		    size_t errlen)
{
	int saved = errno;

	if (err && errlen)
		snprintf(err, errlen, "relay '%s': %s: %s", io->path, what,
			 strerror(saved));
	errno = saved;
	return GL_ERR_SYS;
}

static int tty_open(struct re_relay_io *io, int baud, char *err, size_t errlen)
{
	struct termios t;
	int fd, saved;

	fd = open(io->path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
	if (fd < 0)
		return tty_fail(io, "cannot open", err, errlen);
	if (tcgetattr(fd, &t) < 0)
		goto out_close;
	cfmakeraw(&t);
	t.c_cflag |= CLOCAL | CREAD;
	t.c_cflag &= ~(tcflag_t)(CSTOPB | PARENB | CRTSCTS);
	t.c_iflag &= ~(tcflag_t)(IXON | IXOFF | IXANY);
	t.c_cc[VMIN] = 0;
	t.c_cc[VTIME] = 0;
	if (cfsetispeed(&t, tty_speed(baud)) < 0 ||
	    cfsetospeed(&t, tty_speed(baud)) < 0 ||
	    tcsetattr(fd, TCSANOW, &t) < 0)
		goto out_close;
	io->fd = fd;
	return GL_OK;
out_close:
	saved = errno;
	close(fd);
	errno = saved;
	return tty_fail(io, "cannot configure", err, errlen);
}

static int tty_write(struct re_relay_io *io, const uint8_t *buf, size_t len,
		     char *err, size_t errlen)
{
	ssize_t n;

	if (io->fd < 0) {
		errno = EBADF;
		return tty_fail(io, "write failed", err, errlen);
	}
	do
		n = write(io->fd, buf, len);
	while (n < 0 && errno == EINTR);
	if (n >= 0)
		return (int)n;
	if (errno == EAGAIN || errno == EWOULDBLOCK)
		return 0; /* the driver's buffer is full */
	return tty_fail(io, "write failed", err, errlen);
}

/* TIOCOUTQ: bytes the driver still holds for the wire. A pty reports 0
 * at once (its bytes go straight to the master's input); a USB-serial
 * driver counts its buffer and the transfers in flight. */
static int tty_queued(struct re_relay_io *io, char *err, size_t errlen)
{
	int n = 0;

	if (io->fd < 0) {
		errno = EBADF;
		return tty_fail(io, "output queue unreadable", err, errlen);
	}
	if (ioctl(io->fd, TIOCOUTQ, &n) < 0)
		return tty_fail(io, "output queue unreadable", err, errlen);
	return n;
}

/*
 * With VMIN = VTIME = 0 a read with nothing waiting returns 0 (or EAGAIN
 * on the non-blocking descriptor): both mean "nothing yet". A hang-up is
 * EIO here, and POLLHUP for re_relay_check().
 */
static int tty_read(struct re_relay_io *io, uint8_t *buf, size_t len, char *err,
		    size_t errlen)
{
	ssize_t n;

	if (io->fd < 0) {
		errno = EBADF;
		return tty_fail(io, "read failed", err, errlen);
	}
	do
		n = read(io->fd, buf, len);
	while (n < 0 && errno == EINTR);
	if (n >= 0)
		return (int)n;
	if (errno == EAGAIN || errno == EWOULDBLOCK)
		return 0;
	return tty_fail(io, "read failed", err, errlen);
}

static void tty_discard(struct re_relay_io *io)
{
	if (io->fd >= 0)
		tcflush(io->fd, TCOFLUSH);
}

static int tty_fd(const struct re_relay_io *io)
{
	return io->fd;
}

static void tty_close(struct re_relay_io *io)
{
	if (io->fd >= 0)
		close(io->fd);
	io->fd = -1;
}

const struct re_relay_be_ops re_relay_be_tty = {
    .name = "tty",
    .open = tty_open,
    .write = tty_write,
    .queued = tty_queued,
    .read = tty_read,
    .discard = tty_discard,
    .fd = tty_fd,
    .close = tty_close,
};
