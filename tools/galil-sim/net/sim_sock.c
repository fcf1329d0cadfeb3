/*
 * sim_sock.c - galil-sim's listener and socket settings (see sim_sock.h).
 * Not a protocol and no event loop.
 */
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>
#include <arpa/inet.h>

#include "gl_err.h"
#include "sim_sock.h"

void sim_sock_nonblock(int fd)
{
	fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
	fcntl(fd, F_SETFD, FD_CLOEXEC);
}

int sim_sock_again(int err)
{
	return err == EAGAIN || err == EWOULDBLOCK || err == EINTR;
}

int sim_sock_listen(const char *addr, int port, int *bound, char *err,
		    size_t errlen)
{
	struct sockaddr_in sa = {.sin_family = AF_INET};
	socklen_t len = sizeof(sa);
	int one = 1, fd;

	addr = addr ? addr : "127.0.0.1";
	if (inet_pton(AF_INET, addr, &sa.sin_addr) != 1) {
		snprintf(err, errlen, "invalid listen address '%s'", addr);
		return GL_ERR_SYS;
	}
	sa.sin_port = htons((uint16_t)port);
	fd = socket(AF_INET, SOCK_STREAM, 0);
	if (fd < 0 ||
	    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one)) < 0 ||
	    bind(fd, (struct sockaddr *)&sa, sizeof(sa)) < 0 ||
	    listen(fd, 16) < 0 ||
	    getsockname(fd, (struct sockaddr *)&sa, &len) < 0) {
		snprintf(err, errlen, "cannot listen on %s:%d: %s", addr, port,
			 strerror(errno));
		if (fd >= 0)
			close(fd);
		return GL_ERR_SYS;
	}
	sim_sock_nonblock(fd);
	*bound = ntohs(sa.sin_port);
	return fd;
}
