/* gl_disc.c - finding Galil controllers on the network; see gl_disc.h. */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "base_clock.h"
#include "gl_disc.h"
#include "gl_err.h"

#define BOOTP_MIN    240	/* fixed header + magic cookie */
#define BOOTP_COOKIE 0x63825363 /* RFC 951 / 1497 vendor area magic */

int gl_disc_request(char *buf, size_t cap)
{
	static const char rv[] = {0x12, 0x16, '\r'}; /* ^R ^V CR */

	if (!buf || cap < sizeof(rv))
		return GL_ERR_OVERFLOW;
	memcpy(buf, rv, sizeof(rv));
	return (int)sizeof(rv);
}

static int is_alpha(char c)
{
	return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z');
}

static int is_alnum(char c)
{
	return is_alpha(c) || (c >= '0' && c <= '9');
}

/* Length of the run of characters at @s (< @n) accepted by @ok. */
static size_t run_len(const char *s, size_t n, int (*ok)(char))
{
	size_t i = 0;

	while (i < n && ok(s[i]))
		i++;
	return i;
}

static int is_word(char c)
{
	return c > ' ' && c < 0x7f;
}

int gl_disc_parse_reply(const char *buf, size_t len, struct gl_disc_ctrl *out)
{
	size_t i = 0, m, r, e;

	if (!buf || !out)
		return GL_ERR_ARG;
	while (i < len && buf[i] == ' ')
		i++;
	m = run_len(buf + i, len - i, is_alnum);
	if (m == 0 || m >= sizeof(out->model) || !is_alpha(buf[i]) ||
	    len - i - m < 5 || memcmp(buf + i + m, " Rev ", 5))
		return GL_ERR_FORMAT;
	r = run_len(buf + i + m + 5, len - i - m - 5, is_word);
	if (r == 0 || r >= sizeof(out->rev))
		return GL_ERR_FORMAT;
	for (e = i + m + 5 + r; e < len; e++)
		if (buf[e] != '\r' && buf[e] != '\n' && buf[e] != ':')
			return GL_ERR_FORMAT;
	memcpy(out->model, buf + i, m);
	out->model[m] = '\0';
	memcpy(out->rev, buf + i + m + 5, r);
	out->rev[r] = '\0';
	out->serial = -1;
	return GL_OK;
}

int gl_disc_parse_bootp(const unsigned char *b, size_t len,
			struct gl_disc_ctrl *out)
{
	unsigned long cookie;

	if (!b || !out)
		return GL_ERR_ARG;
	if (len < BOOTP_MIN || b[0] != 1 || b[1] != 1 || b[2] != 6)
		return GL_ERR_FORMAT; /* BOOTREQUEST, Ethernet, 6-byte MAC */
	cookie = (unsigned long)b[236] << 24 | (unsigned long)b[237] << 16 |
		 (unsigned long)b[238] << 8 | b[239];
	if (cookie != BOOTP_COOKIE || b[28] != 0x00 || b[29] != 0x50 ||
	    b[30] != 0x4c)
		return GL_ERR_FORMAT;
	snprintf(out->addr, sizeof(out->addr), "00:50:4C:%02X:%02X:%02X", b[31],
		 b[32], b[33]);
	snprintf(out->model, sizeof(out->model), "code %u", b[31]);
	out->rev[0] = '\0';
	out->serial = (long)b[32] << 8 | b[33];
	return GL_OK;
}

/* "@what '@a:@p': strerror(errno)" into @err (optional). */
static void err_put(char *err, const char *what, const char *a, unsigned p)
{
	if (err)
		snprintf(err, GL_ERRTEXT_LEN, "%s '%s:%u': %s", what, a, p,
			 strerror(errno));
}

/* Add @c from @from unless that address already answered. */
static int add_once(struct gl_disc_ctrl *list, int n, int max,
		    struct gl_disc_ctrl *c, const struct sockaddr_in *from)
{
	int i;

	if (!inet_ntop(AF_INET, &from->sin_addr, c->addr, sizeof(c->addr)))
		return n;
	for (i = 0; i < n; i++)
		if (!strcmp(list[i].addr, c->addr))
			return n;
	if (n < max)
		list[n++] = *c;
	return n;
}

/* Read replies on @fd until @deadline_ms (base_now_ms time). */
static int collect(int fd, int64_t deadline_ms, struct gl_disc_ctrl *list,
		   int max)
{
	char buf[GL_DISC_REPLY_MAX];
	struct gl_disc_ctrl c;
	struct sockaddr_in from;
	socklen_t flen;
	int64_t left;
	ssize_t r;
	int n = 0;

	while ((left = deadline_ms - base_now_ms()) > 0) {
		struct pollfd pfd = {.fd = fd, .events = POLLIN};

		if (poll(&pfd, 1, (int)left) <= 0)
			continue; /* timeout, or EINTR: the loop checks */
		flen = sizeof(from);
		r = recvfrom(fd, buf, sizeof(buf), 0, (struct sockaddr *)&from,
			     &flen);
		if (r > 0 && gl_disc_parse_reply(buf, (size_t)r, &c) == GL_OK)
			n = add_once(list, n, max, &c, &from);
	}
	return n;
}

int gl_disc_probe(const char *bcast, unsigned port, int window_ms,
		  struct gl_disc_ctrl *list, int max, char err[GL_ERRTEXT_LEN])
{
	struct sockaddr_in to = {.sin_family = AF_INET};
	int64_t deadline = base_now_ms() + window_ms;
	char req[8];
	int fd, on = 1, n, len = gl_disc_request(req, sizeof(req));

	if (!bcast || !list || max < 1 || window_ms < 0 || port == 0 ||
	    port > 65535 || inet_pton(AF_INET, bcast, &to.sin_addr) != 1)
		return GL_ERR_ARG;
	to.sin_port = htons((unsigned short)port);
	fd = socket(AF_INET, SOCK_DGRAM, 0);
	if (fd < 0) {
		err_put(err, "cannot open a UDP socket for", bcast, port);
		return GL_ERR_SYS;
	}
	if (setsockopt(fd, SOL_SOCKET, SO_BROADCAST, &on, sizeof(on)) ||
	    sendto(fd, req, (size_t)len, 0, (struct sockaddr *)&to,
		   sizeof(to)) != len) {
		err_put(err, "cannot send the discovery probe to", bcast, port);
		close(fd);
		return GL_ERR_SYS;
	}
	n = collect(fd, deadline, list, max);
	close(fd);
	return n;
}
