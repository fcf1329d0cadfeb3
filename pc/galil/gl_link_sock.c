/*
 * gl_link_sock.c - the link's connection: the controller's address split,
 * resolved and connected with a deadline, and the socket options that make
 * a lost frame or a dead controller surface quickly (docs/link.md).
 */
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link_int.h"

#define KEEPIDLE_S  2 /* TCP keepalive: idle time before probes */
#define KEEPINTVL_S 1 /* interval between probes */
#define KEEPCNT	    3 /* probes before the connection is dropped */

void gl_link_err_put(char *err, const char *fmt, ...)
{
	va_list ap;

	if (!err)
		return;
	va_start(ap, fmt);
	vsnprintf(err, GL_ERRTEXT_LEN, fmt, ap);
	va_end(ap);
}

int gl_link_addr_split(const char *addr, char *host, size_t hcap, char *port,
		       size_t pcap)
{
	const char *h = addr, *colon;
	size_t hl;

	if (*addr == '[') {
		const char *rb = strchr(addr, ']');

		if (!rb)
			return GL_ERR_ARG;
		h = addr + 1;
		hl = (size_t)(rb - h);
		colon = rb[1] == ':' ? rb + 1 : NULL;
		if (rb[1] && !colon)
			return GL_ERR_ARG;
	} else {
		colon = strrchr(addr, ':');
		if (colon && strchr(addr, ':') != colon)
			return GL_ERR_ARG; /* bare v6 needs [] */
		hl = colon ? (size_t)(colon - addr) : strlen(addr);
	}
	if (hl == 0 || hl >= hcap)
		return GL_ERR_ARG;
	memcpy(host, h, hl);
	host[hl] = '\0';
	if (!colon)
		return snprintf(port, pcap, "%d", GL_DEFAULT_PORT) < 0
			   ? GL_ERR_ARG
			   : GL_OK;
	if (!colon[1] || strlen(colon + 1) >= pcap ||
	    strspn(colon + 1, "0123456789") != strlen(colon + 1))
		return GL_ERR_ARG;
	strcpy(port, colon + 1);
	return atoi(port) > 0 && atoi(port) < 65536 ? GL_OK : GL_ERR_ARG;
}

static void sock_options(int fd)
{
	int one = 1;

	/* small command lines must leave at once, not wait for Nagle */
	setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
	/* a thin stream (one command in flight): a lost frame is resent
	 * after the route's rto_min again, not after twice the last wait, for
	 * the first retransmissions (docs/link.md); ignored where unknown */
#ifdef TCP_THIN_LINEAR_TIMEOUTS
	setsockopt(fd, IPPROTO_TCP, TCP_THIN_LINEAR_TIMEOUTS, &one,
		   sizeof(one));
#endif
	/* a dead controller or cable surfaces even while the link is idle */
	setsockopt(fd, SOL_SOCKET, SO_KEEPALIVE, &one, sizeof(one));
#ifdef TCP_KEEPIDLE
	setsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &(int){KEEPIDLE_S},
		   sizeof(int));
	setsockopt(fd, IPPROTO_TCP, TCP_KEEPINTVL, &(int){KEEPINTVL_S},
		   sizeof(int));
	setsockopt(fd, IPPROTO_TCP, TCP_KEEPCNT, &(int){KEEPCNT}, sizeof(int));
#endif
}

/* Non-blocking connect with a deadline. errno is set on failure. */
int gl_link_sock_connect(const struct sockaddr *sa, socklen_t sl,
			 int64_t deadline, int *out)
{
	struct pollfd pfd;
	int fd, rc, soerr = 0;
	socklen_t el = sizeof(soerr);

	fd = socket(sa->sa_family, SOCK_STREAM, 0);
	if (fd < 0)
		return GL_ERR_SYS;
	fcntl(fd, F_SETFD, FD_CLOEXEC);
	if (fcntl(fd, F_SETFL, O_NONBLOCK) < 0)
		goto out_close_fd;
	if (connect(fd, sa, sl) < 0 && errno != EINPROGRESS)
		goto out_close_fd;
	pfd.fd = fd;
	pfd.events = POLLOUT;
	do {
		rc = poll(&pfd, 1, gl_link_left_ms(deadline));
	} while (rc < 0 && errno == EINTR);
	if (rc == 0) {
		close(fd);
		errno = ETIMEDOUT;
		return GL_ERR_TIMEOUT;
	}
	if (rc < 0 || getsockopt(fd, SOL_SOCKET, SO_ERROR, &soerr, &el) < 0)
		goto out_close_fd;
	if (soerr) {
		errno = soerr;
		goto out_close_fd;
	}
	sock_options(fd);
	*out = fd;
	return GL_OK;

out_close_fd:
	rc = errno;
	close(fd);
	errno = rc;
	return GL_ERR_SYS;
}

/* Resolve and connect; remember the address for the message handle. */
int gl_link_connect(gl_link *l, const char *addr, int timeout_ms, char *err)
{
	char host[256], port[8];
	struct addrinfo hints = {0}, *res, *ai;
	int64_t deadline = base_now_ms() + timeout_ms;
	int rc = GL_ERR_SYS, grc;

	if (gl_link_addr_split(addr, host, sizeof(host), port, sizeof(port)) <
	    0) {
		gl_link_err_put(err, "invalid address '%s'", addr);
		return GL_ERR_ARG;
	}
	hints.ai_family = AF_UNSPEC;
	hints.ai_socktype = SOCK_STREAM;
	hints.ai_flags = AI_NUMERICSERV;
	grc = getaddrinfo(host, port, &hints, &res);
	if (grc != 0) {
		gl_link_err_put(err, "cannot resolve '%s': %s", host,
				gai_strerror(grc));
		return GL_ERR_SYS;
	}
	for (ai = res; ai; ai = ai->ai_next) {
		rc = gl_link_sock_connect(ai->ai_addr, ai->ai_addrlen, deadline,
					  &l->cmd.fd);
		if (rc == GL_OK) {
			memcpy(&l->addr, ai->ai_addr, ai->ai_addrlen);
			l->addr_len = ai->ai_addrlen;
			break;
		}
	}
	if (rc < 0)
		gl_link_err_put(err, "cannot connect to '%s': %s", addr,
				rc == GL_ERR_TIMEOUT ? "timed out"
						     : strerror(errno));
	freeaddrinfo(res);
	return rc;
}
