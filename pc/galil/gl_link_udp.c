/*
 * gl_link_udp.c - the controller's data record as a stream (DR over a UDP
 * handle; galil-notes 1.1, 2.6; docs/link.md, "The record as a stream"):
 * the UDP socket, its handle letter (WH on it), DR on the command handle,
 * and the reading of the datagrams through the reader gl_stream. The
 * socket is connect()ed to the controller's address and UDP port, so the
 * kernel drops datagrams from anyone else; gl_stream checks the sender
 * again and judges every record by its own sample number.
 */
#define _GNU_SOURCE /* recvmmsg() */
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link_int.h"

#define WH_RESEND_MS 20 /* UDP may lose WH or its answer: ask again */

/* The controller's address with @port. */
static void udp_peer(const gl_link *l, int port, struct sockaddr_storage *ss)
{
	*ss = l->addr;
	if (ss->ss_family == AF_INET)
		((struct sockaddr_in *)ss)->sin_port = htons((uint16_t)port);
	else
		((struct sockaddr_in6 *)ss)->sin6_port = htons((uint16_t)port);
}

/* The letter of "IHx" at the start of a WH answer (blanks first). */
static int wh_letter(const uint8_t *b, size_t n)
{
	size_t i = 0;

	while (i < n && b[i] == ' ')
		i++;
	if (n - i < 3 || b[i] != 'I' || b[i + 1] != 'H' || b[i + 2] < 'A' ||
	    b[i + 2] > 'H')
		return GL_ERR_PROTO;
	return b[i + 2] - 'A';
}

/* WH on the UDP socket, resent until answered or @deadline (ms). */
static int udp_which_handle(int fd, int64_t deadline)
{
	uint8_t b[GL_LINK_DGRAM_MAX];
	struct pollfd p = {.fd = fd, .events = POLLIN};
	ssize_t n;
	int rc;

	for (;;) {
		int64_t next = base_now_ms() + WH_RESEND_MS;

		if (send(fd, "WH\r", 3, MSG_NOSIGNAL) < 0 && errno != EAGAIN &&
		    errno != ECONNREFUSED)
			return GL_ERR_SYS;
		if (next > deadline)
			next = deadline;
		rc = poll(&p, 1, gl_link_left_ms(next));
		if (rc < 0 && errno != EINTR)
			return GL_ERR_SYS;
		if (rc > 0) {
			n = recv(fd, b, sizeof(b), MSG_DONTWAIT);
			if (n > 0)
				return wh_letter(b, (size_t)n);
		}
		if (base_now_ms() >= deadline)
			return GL_ERR_TIMEOUT;
	}
}

/* The socket, connected to the controller's UDP port. */
static int udp_socket(gl_link *l, int port, int *out)
{
	struct sockaddr_storage ss;
	socklen_t sl = l->addr_len;
	int fd;

	udp_peer(l, port, &ss);
	fd = socket(ss.ss_family, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
	if (fd < 0)
		return GL_ERR_SYS;
	if (connect(fd, (struct sockaddr *)&ss, sl) < 0) {
		close(fd);
		return GL_ERR_SYS;
	}
	*out = fd;
	return GL_OK;
}

static void stream_drop(gl_link *l)
{
	if (l->st_fd >= 0)
		close(l->st_fd);
	l->st_fd = -1;
}

/* The reader, for the controller's address and UDP port. */
static int stream_reader(gl_link *l, int port, unsigned n0, int64_t sample_ns)
{
	struct sockaddr_storage ss;
	struct gl_stream_peer peer;
	int rc;

	udp_peer(l, port, &ss);
	rc = gl_stream_peer_from_sockaddr((struct sockaddr *)&ss, l->addr_len,
					  &peer);
	if (rc < 0)
		return rc;
	return gl_stream_init(&l->st, &peer, l->layout, l->n_axes, n0,
			      sample_ns, base_now_ns());
}

int gl_link_stream_open(gl_link *l, int udp_port, unsigned n0_samples,
			int64_t sample_ns, int timeout_ms,
			char err[GL_ERRTEXT_LEN])
{
	char dr[32];
	int rc, h, t = l ? gl_link_pick_timeout(l, timeout_ms) : GL_ERR_ARG;
	int64_t deadline = base_now_ms() + (t > 0 ? t : 0);

	if (err)
		err[0] = '\0';
	if (!l || t < 0 || udp_port < 1 || udp_port > 65535 || n0_samples < 2 ||
	    n0_samples >= GL_STREAM_HORIZON_SAMPLES || sample_ns <= 0)
		return GL_ERR_ARG;
	if (l->st_fd >= 0)
		gl_link_stream_close(l, t);
	if ((rc = gl_link_axes(l)) < 0) {
		gl_link_err_put(err, "cannot learn the record layout (QZ): %s",
				gl_strerror(rc));
		return rc;
	}
	if ((rc = stream_reader(l, udp_port, n0_samples, sample_ns)) < 0) {
		gl_link_err_put(err, "the record layout has no stream reader");
		return rc;
	}
	if ((rc = udp_socket(l, udp_port, &l->st_fd)) < 0) {
		gl_link_err_put(err, "cannot open a UDP socket: %s",
				strerror(errno));
		return rc;
	}
	h = udp_which_handle(l->st_fd, deadline);
	if (h < 0) {
		gl_link_err_put(err, h == GL_ERR_TIMEOUT
					 ? "no answer to WH on UDP port %d"
					 : "WH on UDP port %d: not a handle",
				udp_port);
		stream_drop(l);
		return h;
	}
	snprintf(dr, sizeof(dr), "DR %u,%d", n0_samples, h);
	rc = gl_link_command(l, dr, NULL, 0, gl_link_left_ms(deadline) + 1);
	if (rc < 0) {
		gl_link_err_put(err, "'%s' refused: %s%s%s", dr,
				gl_strerror(rc), rc == GL_ERR_CTRL ? ": " : "",
				rc == GL_ERR_CTRL ? l->ctrl_text : "");
		/* the handle WH opened stays open on the controller else
		 * (best effort: the refusal is what is reported) */
		if (rc == GL_ERR_CTRL) {
			snprintf(dr, sizeof(dr), "IH%c=>-1", 'A' + h);
			gl_link_command(l, dr, NULL, 0, 0);
		}
		stream_drop(l);
		return rc;
	}
	l->st_handle = h;
	/* the age counts from DR: the first record comes n0 samples later */
	l->st.last_ns = base_now_ns();
	return GL_OK;
}

int gl_link_stream_read(gl_link *l, struct gl_record *rec, int64_t now_ns)
{
	uint8_t(*b)[GL_LINK_DGRAM_MAX];
	struct mmsghdr m[GL_LINK_DGRAM_BATCH];
	struct iovec v[GL_LINK_DGRAM_BATCH];
	struct gl_stream_peer from;
	int fresh = 0, n;

	if (!l || !rec || l->st_fd < 0)
		return GL_ERR_ARG;
	b = l->st_buf;
	from = l->st.ctrl; /* connected: only the controller's get here */
	memset(m, 0, sizeof(m));
	for (int i = 0; i < GL_LINK_DGRAM_BATCH; i++) {
		v[i].iov_base = b[i];
		v[i].iov_len = GL_LINK_DGRAM_MAX;
		m[i].msg_hdr.msg_iov = &v[i];
		m[i].msg_hdr.msg_iovlen = 1;
	}
	/* a batch a system call: at 50 ms a cycle finds about 25 */
	for (int got = 0; got < GL_LINK_STREAM_READS_MAX; got += n) {
		n = recvmmsg(l->st_fd, m, GL_LINK_DGRAM_BATCH, MSG_DONTWAIT,
			     NULL);
		if (n < 0) {
			if (errno == EAGAIN || errno == EWOULDBLOCK)
				break;
			if (errno == EINTR || errno == ECONNREFUSED) {
				n = 0; /* an ICMP error: the stream judges */
				continue;
			}
			return GL_ERR_SYS;
		}
		for (int i = 0; i < n; i++) {
			l->rx_bytes += m[i].msg_len;
			if (gl_stream_feed(&l->st, b[i], m[i].msg_len, &from,
					   now_ns, rec) == GL_STREAM_ACCEPTED)
				fresh = 1;
		}
		if (n < GL_LINK_DGRAM_BATCH)
			break;
	}
	return fresh;
}

int64_t gl_link_stream_age_ns(const gl_link *l, int64_t now_ns)
{
	if (!l || l->st_fd < 0)
		return GL_ERR_ARG;
	return gl_stream_age_ns(&l->st, now_ns);
}

void gl_link_stream_stats(const gl_link *l, struct gl_stream_stats *out)
{
	if (!out)
		return;
	if (!l || l->st_fd < 0)
		memset(out, 0, sizeof(*out));
	else
		*out = l->st.stats;
}

int gl_link_stream_info(const gl_link *l, int *handle, unsigned *n0)
{
	if (!l || l->st_fd < 0)
		return 0;
	if (handle)
		*handle = l->st_handle;
	if (n0)
		*n0 = l->st.n0_samples;
	return 1;
}

int gl_link_stream_fd(const gl_link *l)
{
	return l ? l->st_fd : -1;
}

int gl_link_stream_close(gl_link *l, int timeout_ms)
{
	int rc;
	char ih[16];

	if (!l || l->st_fd < 0)
		return GL_OK;
	/* the stream stopped, then its UDP handle closed on the controller
	 * (a UDP handle has no connection to lose: it would stay open) */
	snprintf(ih, sizeof(ih), "DR 0;IH%c=>-1", 'A' + l->st_handle);
	rc = gl_link_command(l, ih, NULL, 0, timeout_ms);
	stream_drop(l);
	return rc < 0 ? rc : GL_OK;
}
