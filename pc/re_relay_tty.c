/*
 * re_relay_tty.c - relay back-end over a plain POSIX terminal (termios).
 *
 * For galil-sim's virtual relay, a pseudo-terminal that libserialport
 * refuses (relays-and-serial.md); works on /dev/ttyUSB* too, but clinical
 * mode never uses it. The descriptor is non-blocking; deadlines use poll().
 */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <termios.h>
#include <time.h>
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

static long ms_left(const struct timespec *deadline)
{
	struct timespec now;

	clock_gettime(CLOCK_MONOTONIC, &now);
	return (deadline->tv_sec - now.tv_sec) * 1000L +
	       (deadline->tv_nsec - now.tv_nsec) / 1000000L;
}

static void deadline_in(struct timespec *d, int ms)
{
	clock_gettime(CLOCK_MONOTONIC, d);
	d->tv_sec += ms / 1000;
	d->tv_nsec += (long)(ms % 1000) * 1000000L;
	if (d->tv_nsec >= 1000000000L) {
		d->tv_sec++;
		d->tv_nsec -= 1000000000L;
	}
}

/* Wait for @events on the descriptor until @deadline; 1 ready, 0 not. */
static int tty_wait(const struct re_relay_io *io, short events,
		    const struct timespec *deadline)
{
	struct pollfd p = {.fd = io->fd, .events = events};
	long left = deadline ? ms_left(deadline) : 0;
	int rc;

	do
		rc = poll(&p, 1, left > 0 ? (int)left : 0);
	while (rc < 0 && errno == EINTR);
	if (rc < 0)
		return -1;
	if (rc > 0 && (p.revents & (POLLERR | POLLNVAL)))
		return 1; /* let the read/write report the error */
	return rc > 0;
}

static int tty_send(struct re_relay_io *io, const uint8_t *buf, size_t len,
		    int timeout_ms, char *err, size_t errlen)
{
	struct timespec deadline;
	size_t done = 0;
	ssize_t n;

	if (io->fd < 0) {
		errno = EBADF;
		return tty_fail(io, "write failed", err, errlen);
	}
	deadline_in(&deadline, timeout_ms);
	while (done < len) {
		n = write(io->fd, buf + done, len - done);
		if (n > 0) {
			done += (size_t)n;
			continue;
		}
		if (n < 0 && errno != EAGAIN && errno != EINTR)
			return tty_fail(io, "write failed", err, errlen);
		if (timeout_ms <= 0 || ms_left(&deadline) <= 0 ||
		    tty_wait(io, POLLOUT, &deadline) <= 0)
			break;
	}
	if (done < len) {
		if (err && errlen)
			snprintf(err, errlen,
				 "relay '%s': write failed: only "
				 "%zu of %zu bytes written within %d ms",
				 io->path, done, len, timeout_ms);
		return GL_ERR_TIMEOUT;
	}
	if (timeout_ms > 0 && tcdrain(io->fd) < 0)
		return tty_fail(io, "drain failed", err, errlen);
	return GL_OK;
}

/*
 * With VMIN = VTIME = 0 a read with nothing waiting returns 0 (not EAGAIN),
 * so poll() tells "no data yet" (wait) from a hang-up (EIO).
 */
static int tty_recv(struct re_relay_io *io, uint8_t *buf, size_t len,
		    int timeout_ms, char *err, size_t errlen)
{
	struct pollfd p = {.fd = io->fd, .events = POLLIN};
	struct timespec deadline;
	ssize_t n;
	long left;

	if (io->fd < 0) {
		errno = EBADF;
		return tty_fail(io, "read failed", err, errlen);
	}
	deadline_in(&deadline, timeout_ms);
	for (;;) {
		n = read(io->fd, buf, len);
		if (n > 0)
			return (int)n;
		if (n < 0 && errno != EAGAIN && errno != EINTR)
			return tty_fail(io, "read failed", err, errlen);
		left = ms_left(&deadline);
		if (timeout_ms <= 0 || left <= 0)
			return 0;
		if (poll(&p, 1, (int)left) <= 0)
			return 0;
		if ((p.revents & (POLLHUP | POLLERR)) &&
		    !(p.revents & POLLIN)) {
			errno = EIO;
			return tty_fail(io, "read failed", err, errlen);
		}
	}
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
    .send = tty_send,
    .recv = tty_recv,
    .fd = tty_fd,
    .close = tty_close,
};
