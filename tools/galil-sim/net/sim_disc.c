/*
 * sim_disc.c - galil-sim's discovery responder (see sim_disc.h): one UDP
 * socket, the probe recognised from the datagram's bytes, the reply built
 * once when the socket is opened.
 */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "gl_err.h"
#include "sim_disc.h"
#include "sim_sock.h"

int sim_disc_is_probe(const uint8_t *buf, size_t len)
{
	if (!buf || len < 3 || len > 4)
		return 0;
	if (buf[0] != 0x12 || buf[1] != 0x16 || buf[2] != '\r')
		return 0;
	return len == 3 || buf[3] == '\n';
}

int sim_disc_reply(const char *model, char *buf, size_t cap)
{
	size_t m = model ? strlen(model) : 0;

	if (!model || !buf || m + 3 > cap)
		return GL_ERR_OVERFLOW;
	memcpy(buf, model, m);
	memcpy(buf + m, "\r\n:", 3);
	return (int)(m + 3);
}

void sim_disc_init(struct sim_disc *d)
{
	d->fd = -1;
	d->port = 0;
	d->reply_len = 0;
}

int sim_disc_open(struct sim_disc *d, const char *addr, int port,
		  const char *model, char *err, size_t errlen)
{
	struct sockaddr_in sa = {.sin_family = AF_INET};
	socklen_t len = sizeof(sa);
	int n = sim_disc_reply(model, d->reply, sizeof(d->reply));

	addr = addr ? addr : "127.0.0.1";
	if (n < 0) {
		snprintf(err, errlen,
			 "model text too long for the discovery "
			 "reply");
		return GL_ERR_ARG;
	}
	if (port < 0 || port > 65535 ||
	    inet_pton(AF_INET, addr, &sa.sin_addr) != 1) {
		snprintf(err, errlen, "invalid discovery address '%s:%d'", addr,
			 port);
		return GL_ERR_ARG;
	}
	d->reply_len = (size_t)n;
	sa.sin_port = htons((uint16_t)port);
	d->fd = socket(AF_INET, SOCK_DGRAM, 0);
	if (d->fd < 0 || bind(d->fd, (struct sockaddr *)&sa, sizeof(sa)) < 0 ||
	    getsockname(d->fd, (struct sockaddr *)&sa, &len) < 0) {
		snprintf(err, errlen,
			 "cannot bind the discovery port %s:%d: %s", addr, port,
			 strerror(errno));
		sim_disc_close(d);
		return GL_ERR_SYS;
	}
	sim_sock_nonblock(d->fd);
	d->port = ntohs(sa.sin_port);
	return 0;
}

void sim_disc_close(struct sim_disc *d)
{
	if (d->fd >= 0)
		close(d->fd);
	d->fd = -1;
	d->port = 0;
}

/* Answer or ignore the datagram in @buf (@len: its whole length). */
static void handle(struct sim_disc *d, const uint8_t *buf, size_t len,
		   const struct sockaddr_in *from, struct sim_disc_seen *out)
{
	char a[INET_ADDRSTRLEN] = "?";

	inet_ntop(AF_INET, &from->sin_addr, a, sizeof(a));
	snprintf(out->from, sizeof(out->from), "%s:%u", a,
		 (unsigned)ntohs(from->sin_port));
	out->len = len;
	out->err = 0;
	out->outcome = SIM_DISC_IGNORED;
	if (!sim_disc_is_probe(buf, len))
		return;
	out->outcome = SIM_DISC_ANSWERED;
	if (sendto(d->fd, d->reply, d->reply_len, MSG_DONTWAIT,
		   (const struct sockaddr *)from,
		   sizeof(*from)) != (ssize_t)d->reply_len) {
		out->outcome = SIM_DISC_UNSENT;
		out->err = errno;
	}
}

int sim_disc_service(struct sim_disc *d, struct sim_disc_seen *seen)
{
	uint8_t buf[SIM_DISC_READ_MAX];
	struct sockaddr_in from;
	socklen_t flen;
	ssize_t r;
	int n = 0;

	while (d->fd >= 0 && n < SIM_DISC_BURST) {
		flen = sizeof(from);
		/* MSG_TRUNC: the whole length, so that a long datagram that
		 * begins like a probe is not taken for one */
		r = recvfrom(d->fd, buf, sizeof(buf), MSG_DONTWAIT | MSG_TRUNC,
			     (struct sockaddr *)&from, &flen);
		if (r < 0)
			break; /* nothing more waiting, or an error to drop */
		handle(d, buf, (size_t)r, &from, &seen[n++]);
	}
	return n;
}
