/*
 * gl_link.c - TCP link to a Galil DMC: connect, send, receive with deadlines.
 *
 * This file only moves bytes; gl_proto parses them. Decisions (fail safe):
 *
 * Out of step. After a timeout, a malformed reply, bytes left over after a
 *   complete reply, or solicited bytes arriving while no reply is awaited,
 *   the command handle is marked BROKEN: every later call returns
 *   GL_ERR_BROKEN without touching the socket, and the caller must close the
 *   link and open a new one (a new TCP connection starts with an empty
 *   stream). We do not try to resynchronise: a late ':' or a late data line
 *   cannot be told apart from the answer to a sync command, so a "resync"
 *   could itself take a late reply for an answer. After the peer closes the
 *   connection the call returns GL_ERR_CLOSED and later calls GL_ERR_BROKEN.
 * Errors. On '?' the link sends TC1 (with the link's default timeout) and
 *   keeps code and text. If TC1 itself fails, that error is returned instead
 *   (the link is then broken). A TC1 answer that does not start with a
 *   number breaks the link (GL_ERR_PROTO): it means the stream is not where
 *   we think it is.
 * Commands. A line must be 1..GL_LINE_MAX printable characters, without CR,
 *   LF, a leading, trailing or doubled ';' (the number of terminators to
 *   await would be uncertain), or an unbalanced '"'. ';' inside "..." is
 *   not counted as a separator.
 * DL. "DL" CR, every line followed by CR, then "\". The controller answers
 *   two terminators in all ('?' replacing one of them when a line is
 *   rejected; UNCONFIRMED, galil-notes 3.1). After each line the link looks
 *   (without waiting, or up to the DL pace, gl_link_set_dl_pace()) for an
 *   early '?'; when one is seen the remaining lines are not sent, "\" ends
 *   the download, and *bad_line is the last line sent: the rejected line is
 *   that one or an earlier one (the controller may answer after the link
 *   has sent more). A '?' first seen after "\" gives *bad_line = 0 (unknown).
 *   The controller never says which line it rejected, so an exact number
 *   needs pacing: with a pace longer than the controller's reply time the
 *   number is exact; a loader can re-run a failed download paced to find
 *   the line (the download failed anyway). Lines longer than GL_LINE_MAX,
 *   control bytes, bytes >= 0x80 and '\' are refused before anything is
 *   sent (GL_ERR_ARG, *bad_line exact). After a rejected DL the
 *   controller's program must be treated as invalid (it may hold the lines
 *   before the bad one).
 * QR. Unsolicited bytes before the record are recognised and queued; inside
 *   the record they cannot be (gl_proto.h): the record is misaligned and
 *   rejected (GL_ERR_PROTO, broken) because its ':' is missing or surplus
 *   bytes follow. Residual risk: if the misaligned byte happens to be ':'
 *   (1 in 256) and the surplus arrives only after the extra read done at
 *   the end of every exchange, a corrupt record is returned once and the
 *   next call fails with GL_ERR_PROTO. Keep CF on the message handle.
 * Messages. A second TCP connection to the same address; WH on it gives its
 *   handle letter, then "CF <letter>" and "CW1" go on the command handle.
 *   Unsolicited bytes that still reach the command handle are queued too and
 *   returned first by gl_link_message().
 * Layout. Learnt with QZ on the first gl_link_record() (or by
 *   gl_link_query_layout()); not at open, so that opening never depends on
 *   the controller model.
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
#include <time.h>
#include <unistd.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link.h"
#include "gl_proto.h"

#define ADDR_MAX      300  /* "host:port" as given, bytes */
#define READ_CHUNK    1024 /* bytes per recv() */
#define MSG_READS_MAX 8	   /* recv() calls per gl_link_message() */
#define KEEPIDLE_S    2	   /* TCP keepalive: idle time before probes */
#define KEEPINTVL_S   1	   /* interval between probes */
#define KEEPCNT	      3	   /* probes before the connection is dropped */

struct gl_chan {
	int fd;
	bool broken;
	struct gl_proto p;
};

struct gl_link {
	struct gl_chan cmd, msg;
	struct sockaddr_storage addr;
	socklen_t addr_len;
	int timeout_ms;
	int dl_pace_ms; /* DL: wait per line for an early '?' */
	enum gl_rec_layout layout;
	int n_axes;
	int ctrl_code;
	char ctrl_text[GL_ERRTEXT_LEN];
	uint64_t tx_bytes, rx_bytes, round_trips;
};

/* What one exchange sends and awaits. */
struct xfer {
	const char *line; /* sent followed by CR */
	size_t len;
	int n_term;
	size_t bin_len;
	char *ubuf; /* non-NULL: UL reply into this buffer */
	size_t ucap;
	/* the caller polled the socket just before and it held nothing:
	 * no read before the request, none for surplus after the reply */
	bool seen_idle;
};

/* ---- time ---------------------------------------------------------------- */

static int left_ms(int64_t deadline)
{
	int64_t d = deadline - base_now_ms();

	return d < 0 ? 0 : (int)d;
}

/* ---- sockets ------------------------------------------------------------- */

__attribute__((format(printf, 2, 3))) static void err_put(char *err,
							  const char *fmt, ...)
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
static int sock_connect(const struct sockaddr *sa, socklen_t sl,
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
		rc = poll(&pfd, 1, left_ms(deadline));
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
static int link_connect(gl_link *l, const char *addr, int timeout_ms, char *err)
{
	char host[256], port[8];
	struct addrinfo hints = {0}, *res, *ai;
	int64_t deadline = base_now_ms() + timeout_ms;
	int rc = GL_ERR_SYS, grc;

	if (gl_link_addr_split(addr, host, sizeof(host), port, sizeof(port)) <
	    0) {
		err_put(err, "invalid address '%s'", addr);
		return GL_ERR_ARG;
	}
	hints.ai_family = AF_UNSPEC;
	hints.ai_socktype = SOCK_STREAM;
	hints.ai_flags = AI_NUMERICSERV;
	grc = getaddrinfo(host, port, &hints, &res);
	if (grc != 0) {
		err_put(err, "cannot resolve '%s': %s", host,
			gai_strerror(grc));
		return GL_ERR_SYS;
	}
	for (ai = res; ai; ai = ai->ai_next) {
		rc = sock_connect(ai->ai_addr, ai->ai_addrlen, deadline,
				  &l->cmd.fd);
		if (rc == GL_OK) {
			memcpy(&l->addr, ai->ai_addr, ai->ai_addrlen);
			l->addr_len = ai->ai_addrlen;
			break;
		}
	}
	if (rc < 0)
		err_put(err, "cannot connect to '%s': %s", addr,
			rc == GL_ERR_TIMEOUT ? "timed out" : strerror(errno));
	freeaddrinfo(res);
	return rc;
}

/* ---- byte moving --------------------------------------------------------- */

static int wait_fd(int fd, short events, int64_t deadline)
{
	struct pollfd pfd = {.fd = fd, .events = events};
	int rc;

	do {
		rc = poll(&pfd, 1, left_ms(deadline));
	} while (rc < 0 && errno == EINTR);
	if (rc < 0)
		return GL_ERR_SYS;
	return rc == 0 ? GL_ERR_TIMEOUT : GL_OK;
}

static int chan_write(gl_link *l, struct gl_chan *ch, const void *buf,
		      size_t len, int64_t deadline)
{
	const char *b = buf;
	ssize_t n;
	int rc;

	while (len > 0) {
		n = send(ch->fd, b, len, MSG_NOSIGNAL);
		if (n > 0) {
			b += n;
			len -= (size_t)n;
			l->tx_bytes += (uint64_t)n;
			continue;
		}
		if (errno == EPIPE || errno == ECONNRESET)
			return GL_ERR_CLOSED;
		if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
			return GL_ERR_SYS;
		rc = wait_fd(ch->fd, POLLOUT, deadline);
		if (rc < 0)
			return rc;
	}
	return GL_OK;
}

/*
 * Read what is there (one recv) into the parser. @deadline < 0: do not wait.
 * When waiting is allowed the socket is polled first: a reply awaited is
 * rarely there yet, and poll + recv is one system call fewer than a recv
 * that finds nothing, then poll, then recv (the lean cycle).
 * Return: GL_OK (bytes fed), GL_ERR_AGAIN (nothing without waiting),
 *         GL_ERR_TIMEOUT, GL_ERR_CLOSED, GL_ERR_SYS.
 */
static int chan_read(gl_link *l, struct gl_chan *ch, int64_t deadline)
{
	uint8_t buf[READ_CHUNK];
	size_t want = gl_proto_space(&ch->p);
	ssize_t n;
	int rc;

	if (want > sizeof(buf))
		want = sizeof(buf);
	if (want == 0)
		return GL_ERR_PROTO; /* cannot happen: next() drains input */
	if (deadline >= 0) {
		rc = wait_fd(ch->fd, POLLIN, deadline);
		if (rc < 0)
			return rc;
	}
	for (;;) {
		n = recv(ch->fd, buf, want, 0);
		if (n > 0)
			break;
		if (n == 0 || errno == ECONNRESET)
			return GL_ERR_CLOSED;
		if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
			return GL_ERR_SYS;
		if (deadline < 0)
			return GL_ERR_AGAIN;
		rc = wait_fd(ch->fd, POLLIN, deadline);
		if (rc < 0)
			return rc;
	}
	l->rx_bytes += (uint64_t)n;
	return gl_proto_feed(&ch->p, buf, (size_t)n);
}

/* Mark @ch out of step for errors that leave the stream unknown. */
static int chan_fail(struct gl_chan *ch, int rc)
{
	if (rc == GL_ERR_TIMEOUT || rc == GL_ERR_PROTO || rc == GL_ERR_CLOSED ||
	    rc == GL_ERR_SYS)
		ch->broken = true;
	return rc;
}

/*
 * Before sending: take bytes that arrived since the last reply (only
 * unsolicited ones are allowed). At most MSG_READS_MAX reads, so that a
 * flood cannot hold the caller; the rest is taken with the reply.
 */
static int chan_drain_idle(gl_link *l, struct gl_chan *ch)
{
	struct gl_reply r;
	int i, rc;

	for (i = 0; i < MSG_READS_MAX; i++) {
		rc = chan_read(l, ch, -1);
		if (rc == GL_ERR_AGAIN)
			return GL_OK;
		if (rc < 0)
			return chan_fail(ch, rc);
		if (gl_proto_next(&ch->p, &r) != GL_ERR_AGAIN)
			return chan_fail(ch, GL_ERR_PROTO);
	}
	return GL_OK;
}

static int xfer_begin(gl_link *l, struct gl_chan *ch, const struct xfer *x,
		      int64_t deadline)
{
	char line[GL_LINE_MAX + 2];
	int rc;

	if (ch->broken || ch->fd < 0)
		return GL_ERR_BROKEN;
	if (x->len > GL_LINE_MAX)
		return GL_ERR_ARG;
	rc = x->seen_idle ? GL_OK : chan_drain_idle(l, ch);
	if (rc < 0)
		return rc;
	rc = x->ubuf ? gl_proto_expect_upload(&ch->p, x->ubuf, x->ucap)
		     : gl_proto_expect(&ch->p, x->n_term, x->bin_len);
	if (rc < 0)
		return rc;
	memcpy(line, x->line, x->len);
	line[x->len] = '\r';
	return chan_fail(ch, chan_write(l, ch, line, x->len + 1, deadline));
}

/*
 * After a reply: retire it (its text stays valid); nothing solicited may
 * follow. One non-blocking read first, so that surplus bytes sent with the
 * reply are seen now rather than at the next call; not when the caller
 * looks before each request itself (@seen_idle: its next look, before
 * the next request, sees them). Bytes that came with the reply are seen
 * in both cases.
 */
static int xfer_finish(gl_link *l, struct gl_chan *ch, bool seen_idle)
{
	struct gl_reply extra;

	if (!seen_idle && gl_proto_space(&ch->p) > 0)
		chan_read(l, ch, -1); /* errors show up at the next call */
	if (gl_proto_next(&ch->p, &extra) != GL_ERR_AGAIN)
		return chan_fail(ch, GL_ERR_PROTO);
	if (ch == &l->cmd)
		l->round_trips++;
	return GL_OK;
}

/* Wait for the awaited reply. */
static int xfer_end(gl_link *l, struct gl_chan *ch, const struct xfer *x,
		    struct gl_reply *r, int64_t deadline)
{
	int rc;

	while ((rc = gl_proto_next(&ch->p, r)) == GL_ERR_AGAIN) {
		rc = chan_read(l, ch, deadline);
		if (rc < 0)
			return chan_fail(ch, rc);
	}
	if (rc < 0)
		return chan_fail(ch, rc);
	return xfer_finish(l, ch, x->seen_idle);
}

static int xfer(gl_link *l, struct gl_chan *ch, const struct xfer *x,
		int timeout_ms, struct gl_reply *r)
{
	int64_t deadline = base_now_ms() + timeout_ms;
	int rc;

	rc = xfer_begin(l, ch, x, deadline);
	if (rc < 0)
		return rc;
	return xfer_end(l, ch, x, r, deadline);
}

/* ---- commands ------------------------------------------------------------ */

static int pick_timeout(const gl_link *l, int timeout_ms)
{
	if (timeout_ms < 0)
		return GL_ERR_ARG;
	return timeout_ms == 0 ? l->timeout_ms : timeout_ms;
}

/* Check a command line; return the number of ';'-separated commands. */
static int count_commands(const char *cmd, size_t len)
{
	bool quoted = false, empty = true;
	int n = 1;
	size_t i;

	if (len == 0 || len > GL_LINE_MAX)
		return GL_ERR_ARG;
	for (i = 0; i < len; i++) {
		unsigned char c = (unsigned char)cmd[i];

		if (c < 0x20 || c > 0x7e)
			return GL_ERR_ARG;
		if (c == '"')
			quoted = !quoted;
		if (c == ';' && !quoted) {
			if (empty)
				return GL_ERR_ARG;
			n++;
			empty = true;
		} else if (c != ' ') {
			empty = false;
		}
	}
	return quoted || empty || n > GL_PROTO_CMDS_MAX ? GL_ERR_ARG : n;
}

/* After '?': ask TC1, keep code and text, return GL_ERR_CTRL. */
static int fetch_tc1(gl_link *l)
{
	const struct xfer x = {.line = "TC1", .len = 3, .n_term = 1};
	struct gl_reply r;
	const char *ep;
	double code;
	size_t n;
	int rc;

	rc = xfer(l, &l->cmd, &x, l->timeout_ms, &r);
	if (rc < 0)
		return rc;
	if (r.n_err || !gl_parse_double(r.text, r.text_len, &ep, &code) ||
	    code < 0 || code > 255) {
		l->cmd.broken = true;
		return GL_ERR_PROTO;
	}
	while (*ep == ' ')
		ep++;
	n = strlen(ep);
	if (n >= sizeof(l->ctrl_text))
		n = sizeof(l->ctrl_text) - 1;
	memcpy(l->ctrl_text, ep, n);
	l->ctrl_text[n] = '\0';
	l->ctrl_code = (int)code;
	return GL_ERR_CTRL;
}

static void ctrl_clear(gl_link *l)
{
	l->ctrl_code = 0;
	l->ctrl_text[0] = '\0';
}

/* Copy reply text out; GL_ERR_OVERFLOW when it does not fit. */
static int text_out(const struct gl_reply *r, char *resp, size_t cap)
{
	size_t n = r->text_len;

	if (!resp || cap == 0)
		return r->truncated ? GL_ERR_OVERFLOW : (int)n;
	if (n >= cap)
		n = cap - 1;
	memcpy(resp, r->text, n);
	resp[n] = '\0';
	return (n < r->text_len || r->truncated) ? GL_ERR_OVERFLOW
						 : (int)r->text_len;
}

/* Send an already checked line of @n commands on the command handle. */
static int command_n(gl_link *l, const char *cmd, size_t len, int n, char *resp,
		     size_t cap, int timeout_ms)
{
	struct xfer x = {.line = cmd, .len = len, .n_term = n};
	struct gl_reply r;
	int rc;

	rc = xfer(l, &l->cmd, &x, timeout_ms, &r);
	if (rc < 0)
		return rc;
	if (r.n_err)
		return fetch_tc1(l);
	return text_out(&r, resp, cap);
}

int gl_link_command(gl_link *l, const char *cmd, char *resp, size_t cap,
		    int timeout_ms)
{
	int n, t;

	if (!l || !cmd)
		return GL_ERR_ARG;
	ctrl_clear(l);
	n = count_commands(cmd, strlen(cmd));
	t = pick_timeout(l, timeout_ms);
	if (n < 0 || t < 0)
		return GL_ERR_ARG;
	return command_n(l, cmd, strlen(cmd), n, resp, cap, t);
}

int gl_link_query_layout(gl_link *l)
{
	char qz[64];
	int rc;

	if (!l)
		return GL_ERR_ARG;
	rc = gl_link_command(l, "QZ", qz, sizeof(qz), 0);
	if (rc < 0)
		return rc;
	return gl_record_layout_from_qz(qz, (size_t)rc, &l->layout, &l->n_axes);
}

int gl_link_axes(gl_link *l)
{
	int rc;

	if (!l)
		return GL_ERR_ARG;
	if (l->layout == GL_LAYOUT_NONE && (rc = gl_link_query_layout(l)) < 0)
		return rc;
	return l->n_axes;
}

int gl_link_record(gl_link *l, const char *prefix, struct gl_record *rec,
		   int timeout_ms)
{
	return gl_link_record_seen(l, prefix, rec, timeout_ms, false);
}

int gl_link_record_seen(gl_link *l, const char *prefix, struct gl_record *rec,
			int timeout_ms, bool seen_idle)
{
	return gl_link_record_text(l, prefix, rec, timeout_ms, seen_idle, NULL,
				   0);
}

int gl_link_record_text(gl_link *l, const char *prefix, struct gl_record *rec,
			int timeout_ms, bool seen_idle, char *text, size_t cap)
{
	char line[GL_LINE_MAX + 1];
	struct xfer x = {.line = line, .seen_idle = seen_idle};
	struct gl_reply r;
	int rc, t = l ? pick_timeout(l, timeout_ms) : GL_ERR_ARG;

	if (!l || !rec || t < 0)
		return GL_ERR_ARG;
	if (l->layout == GL_LAYOUT_NONE && (rc = gl_link_query_layout(l)) < 0)
		return rc;
	ctrl_clear(l);
	/* "PREFIX;QR" by hand: this is built every cycle (no snprintf) */
	x.len = prefix ? strlen(prefix) : 0;
	if (x.len + 3 >= sizeof(line))
		return GL_ERR_ARG;
	if (prefix) {
		memcpy(line, prefix, x.len);
		line[x.len++] = ';';
	}
	memcpy(line + x.len, "QR", 3);
	x.len += 2;
	x.n_term = count_commands(line, x.len);
	x.bin_len = gl_record_size(l->layout, l->n_axes);
	if (x.n_term < 0)
		return GL_ERR_ARG;
	rc = xfer(l, &l->cmd, &x, t, &r);
	if (rc < 0)
		return rc;
	if (r.n_err)
		return fetch_tc1(l);
	if (text && cap) {
		if (r.text_len >= cap || r.truncated)
			return GL_ERR_OVERFLOW;
		memcpy(text, r.text, r.text_len);
		text[r.text_len] = '\0';
	}
	return gl_record_decode(r.bin, r.bin_len, l->layout, l->n_axes, rec);
}

/* ---- identification ------------------------------------------------------ */

static void trim(const char **s, size_t *len)
{
	while (*len > 0 && (**s == ' ' || **s == '\t')) {
		(*s)++;
		(*len)--;
	}
	while (*len > 0 && ((*s)[*len - 1] == ' ' || (*s)[*len - 1] == '\t'))
		(*len)--;
}

int gl_link_identify(gl_link *l, char *model, size_t cap, long *serial)
{
	static const char rv[] = {0x12, 0x16}; /* ^R ^V */
	const struct xfer x = {.line = rv, .len = 2, .n_term = 1};
	struct gl_reply r;
	char bn[64];
	const char *s;
	size_t n;
	double v;
	int rc;

	if (!l || !model || cap == 0 || !serial)
		return GL_ERR_ARG;
	ctrl_clear(l);
	rc = xfer(l, &l->cmd, &x, l->timeout_ms, &r);
	if (rc < 0)
		return rc;
	if (r.n_err)
		return fetch_tc1(l);
	s = r.text;
	n = r.text_len;
	trim(&s, &n);
	if (n >= cap)
		return GL_ERR_OVERFLOW;
	memcpy(model, s, n);
	model[n] = '\0';
	rc = gl_link_command(l, "MG _BN", bn, sizeof(bn), 0);
	if (rc < 0)
		return rc;
	if (!gl_parse_double(bn, (size_t)rc, NULL, &v) || v < 0 || v > 2e9)
		return GL_ERR_PROTO;
	*serial = (long)v;
	return GL_OK;
}

enum gl_ctrl_kind gl_link_ctrl_kind(const char *cmd)
{
	size_t i, n = strlen(cmd);
	enum gl_ctrl_kind k = GL_CTRL_NONE;

	if (n >= 2 && cmd[0] == 0x12 && cmd[1] == 0x16)
		k = n == 2 ? GL_CTRL_REVISION : GL_CTRL_OTHER;
	else if (n >= 2 && cmd[0] == 0x12 && cmd[1] == 0x13)
		k = n == 2 ? GL_CTRL_RESET : GL_CTRL_OTHER;
	else if (n >= 2 && cmd[0] == 0x0c && cmd[1] == 0x0b)
		k = GL_CTRL_LOCK;
	for (i = k == GL_CTRL_NONE ? 0 : 2; i < n; i++)
		if ((unsigned char)cmd[i] < 0x20 ||
		    (unsigned char)cmd[i] > 0x7e)
			return GL_CTRL_OTHER;
	return k;
}

int gl_link_ctrl_request(gl_link *l, const char *req, char *resp, size_t cap,
			 int timeout_ms)
{
	struct xfer x = {.line = req, .n_term = 1};
	struct gl_reply r;
	int rc, t = l ? pick_timeout(l, timeout_ms) : GL_ERR_ARG;

	if (!l || !req || t < 0 || strlen(req) > GL_LINE_MAX ||
	    gl_link_ctrl_kind(req) <= GL_CTRL_NONE)
		return GL_ERR_ARG;
	ctrl_clear(l);
	x.len = strlen(req);
	rc = xfer(l, &l->cmd, &x, t, &r);
	if (rc < 0)
		return rc;
	if (r.n_err)
		return fetch_tc1(l);
	return text_out(&r, resp, cap);
}

/* ---- download / upload --------------------------------------------------- */

/* Length of the line at @p (up to CR or LF) and of its line end. */
static size_t line_len(const char *p, size_t left, size_t *eol)
{
	size_t n = 0;

	while (n < left && p[n] != '\r' && p[n] != '\n')
		n++;
	*eol = 0;
	if (n < left)
		*eol =
		    (p[n] == '\r' && n + 1 < left && p[n + 1] == '\n') ? 2 : 1;
	return n;
}

/* Refuse what the controller would reject or misread; nothing is sent. */
static int dl_validate(const char *prog, size_t len, int *bad_line)
{
	size_t off = 0, n, eol, i;
	int line = 0;

	while (off < len) {
		n = line_len(prog + off, len - off, &eol);
		line++;
		for (i = 0; i < n; i++) {
			unsigned char c = (unsigned char)prog[off + i];

			if ((c < 0x20 && c != '\t') || c > 0x7e || c == '\\')
				break;
		}
		if (i < n || n > GL_LINE_MAX) {
			*bad_line = line;
			return GL_ERR_ARG;
		}
		off += n + eol;
	}
	return GL_OK;
}

/*
 * Look for an early '?', waiting up to the DL pace (0: not at all).
 * Return 1 if one was seen, 0 if not, or an error.
 */
static int dl_early_reject(gl_link *l, struct gl_reply *r, bool *done)
{
	int64_t deadline =
	    l->dl_pace_ms > 0 ? base_now_ms() + l->dl_pace_ms : -1;
	int rc, n_err = 0;

	rc = chan_read(l, &l->cmd, deadline);
	if (rc == GL_ERR_AGAIN || rc == GL_ERR_TIMEOUT)
		return 0;
	if (rc < 0)
		return chan_fail(&l->cmd, rc);
	rc = gl_proto_next(&l->cmd.p, r);
	if (rc == GL_OK) {
		*done = true;
		return r->n_err ? 1 : chan_fail(&l->cmd, GL_ERR_PROTO);
	}
	if (rc != GL_ERR_AGAIN)
		return chan_fail(&l->cmd, rc);
	gl_proto_progress(&l->cmd.p, &n_err);
	return n_err > 0;
}

/* Send the lines (each + CR); stop early on '?'. */
static int dl_send_lines(gl_link *l, const char *prog, size_t len,
			 int64_t deadline, int *bad_line, struct gl_reply *r,
			 bool *done)
{
	char buf[GL_LINE_MAX + 1];
	size_t off = 0, n, eol;
	int line = 0, rc;

	while (off < len) {
		n = line_len(prog + off, len - off, &eol);
		memcpy(buf, prog + off, n);
		buf[n] = '\r';
		rc = chan_write(l, &l->cmd, buf, n + 1, deadline);
		if (rc < 0)
			return chan_fail(&l->cmd, rc);
		line++;
		off += n + eol;
		rc = dl_early_reject(l, r, done);
		if (rc < 0)
			return rc;
		if (rc == 1) {
			*bad_line = line;
			break;
		}
	}
	return GL_OK;
}

/* DL after validation: "DL", the lines, "\\", then both terminators. */
static int dl_run(gl_link *l, const char *prog, size_t len, int *bad,
		  int timeout_ms, struct gl_reply *r)
{
	const struct xfer x = {.line = "DL", .len = 2, .n_term = 2};
	int64_t deadline = base_now_ms() + timeout_ms;
	bool done = false;
	int rc;

	rc = xfer_begin(l, &l->cmd, &x, deadline);
	if (rc < 0)
		return rc;
	rc = dl_send_lines(l, prog, len, deadline, bad, r, &done);
	if (rc < 0)
		return rc;
	rc = chan_write(l, &l->cmd, "\\", 1, deadline);
	if (rc < 0)
		return chan_fail(&l->cmd, rc);
	return done ? xfer_finish(l, &l->cmd, false)
		    : xfer_end(l, &l->cmd, &x, r, deadline);
}

int gl_link_download(gl_link *l, const char *prog, size_t len, int *bad_line,
		     int timeout_ms)
{
	struct gl_reply r;
	int rc, bad = 0, t = l ? pick_timeout(l, timeout_ms) : GL_ERR_ARG;

	if (bad_line)
		*bad_line = 0;
	if (!l || (!prog && len) || t < 0)
		return GL_ERR_ARG;
	ctrl_clear(l);
	rc = dl_validate(prog, len, &bad);
	if (rc == GL_OK)
		rc = dl_run(l, prog, len, &bad, t, &r);
	if (bad_line)
		*bad_line = bad;
	if (rc < 0)
		return rc;
	return r.n_err ? fetch_tc1(l) : GL_OK;
}

int gl_link_set_dl_pace(gl_link *l, int pace_ms)
{
	if (!l || pace_ms < 0)
		return GL_ERR_ARG;
	l->dl_pace_ms = pace_ms;
	return GL_OK;
}

int gl_link_upload(gl_link *l, char *buf, size_t cap, int timeout_ms)
{
	struct xfer x = {
	    .line = "UL", .len = 2, .n_term = 1, .ubuf = buf, .ucap = cap};
	struct gl_reply r;
	int rc, t = l ? pick_timeout(l, timeout_ms) : GL_ERR_ARG;

	if (!l || !buf || cap == 0 || t < 0)
		return GL_ERR_ARG;
	ctrl_clear(l);
	rc = xfer(l, &l->cmd, &x, t, &r);
	if (rc < 0)
		return rc;
	if (r.n_err)
		return fetch_tc1(l);
	return r.truncated ? GL_ERR_OVERFLOW : (int)r.text_len;
}

/* ---- unsolicited messages ------------------------------------------------ */

static void msg_close(gl_link *l)
{
	if (l->msg.fd >= 0)
		close(l->msg.fd);
	l->msg.fd = -1;
}

/* WH on the message handle: its letter A..H. */
static int msg_which_handle(gl_link *l, int timeout_ms, char *letter)
{
	const struct xfer x = {.line = "WH", .len = 2, .n_term = 1};
	struct gl_reply r;
	const char *s;
	size_t n;
	int rc;

	rc = xfer(l, &l->msg, &x, timeout_ms, &r);
	if (rc < 0)
		return rc;
	s = r.text;
	n = r.text_len;
	trim(&s, &n);
	if (r.n_err || n != 3 || s[0] != 'I' || s[1] != 'H' || s[2] < 'A' ||
	    s[2] > 'H')
		return GL_ERR_PROTO;
	*letter = s[2];
	return GL_OK;
}

int gl_link_open_messages(gl_link *l, int timeout_ms)
{
	char cf[8], letter = 0;
	int rc, t = l ? pick_timeout(l, timeout_ms) : GL_ERR_ARG;

	if (!l || t < 0)
		return GL_ERR_ARG;
	if (l->cmd.broken)
		return GL_ERR_BROKEN;
	msg_close(l);
	gl_proto_init(&l->msg.p);
	l->msg.broken = false;
	rc = sock_connect((struct sockaddr *)&l->addr, l->addr_len,
			  base_now_ms() + t, &l->msg.fd);
	if (rc < 0)
		return rc;
	rc = msg_which_handle(l, t, &letter);
	if (rc < 0)
		goto out_close_msg;
	snprintf(cf, sizeof(cf), "CF %c", letter);
	rc = gl_link_command(l, cf, NULL, 0, t);
	if (rc >= 0)
		rc = gl_link_command(l, "CW1", NULL, 0, t);
	if (rc < 0)
		goto out_close_msg;
	gl_proto_set_all_unsol(&l->msg.p, true);
	return GL_OK;

out_close_msg:
	msg_close(l);
	return rc;
}

/* Move whatever the message handle holds into its queue. */
static int msg_pump(gl_link *l)
{
	struct gl_reply r;
	int i, rc;

	for (i = 0; i < MSG_READS_MAX; i++) {
		rc = chan_read(l, &l->msg, -1);
		if (rc == GL_ERR_AGAIN)
			return GL_OK;
		if (rc < 0)
			return rc;
		gl_proto_next(&l->msg.p, &r); /* all bytes are unsolicited */
	}
	return GL_OK;
}

int gl_link_message_queued(gl_link *l, char *line, size_t cap)
{
	int rc;

	if (!l || !line || cap == 0)
		return GL_ERR_ARG;
	rc = gl_proto_unsol_next(&l->cmd.p, line, cap);
	if (rc != GL_ERR_AGAIN)
		return rc;
	if (l->msg.fd < 0)
		return l->msg.broken ? GL_ERR_CLOSED : GL_ERR_AGAIN;
	return gl_proto_unsol_next(&l->msg.p, line, cap);
}

int gl_link_message(gl_link *l, char *line, size_t cap)
{
	int rc = gl_link_message_queued(l, line, cap), pump;

	if (rc != GL_ERR_AGAIN || l->msg.fd < 0)
		return rc;
	pump = msg_pump(l);
	rc = gl_proto_unsol_next(&l->msg.p, line, cap);
	if (rc != GL_ERR_AGAIN || pump == GL_OK)
		return rc;
	msg_close(l);
	l->msg.broken = true;
	return pump;
}

/* ---- life cycle ---------------------------------------------------------- */

int gl_link_open(gl_link **out, const char *addr, int timeout_ms,
		 char err[GL_ERRTEXT_LEN])
{
	gl_link *l;
	int rc;

	if (err)
		err[0] = '\0';
	if (!out || !addr || timeout_ms <= 0) {
		err_put(err, "invalid argument");
		return GL_ERR_ARG;
	}
	*out = NULL;
	l = calloc(1, sizeof(*l));
	if (!l) {
		err_put(err, "cannot open '%s': out of memory", addr);
		return GL_ERR_NOMEM;
	}
	l->cmd.fd = -1;
	l->msg.fd = -1;
	l->timeout_ms = timeout_ms;
	gl_proto_init(&l->cmd.p);
	gl_proto_init(&l->msg.p);
	rc = link_connect(l, addr, timeout_ms, err);
	if (rc < 0) {
		free(l);
		return rc;
	}
	*out = l;
	return GL_OK;
}

void gl_link_close(gl_link *l)
{
	if (!l)
		return;
	msg_close(l);
	if (l->cmd.fd >= 0)
		close(l->cmd.fd);
	free(l);
}

int gl_link_set_timeout(gl_link *l, int timeout_ms)
{
	if (!l || timeout_ms <= 0)
		return GL_ERR_ARG;
	l->timeout_ms = timeout_ms;
	return GL_OK;
}

const char *gl_link_ctrl_error(const gl_link *l, int *code)
{
	if (code)
		*code = l ? l->ctrl_code : 0;
	return l ? l->ctrl_text : "";
}

void gl_link_stats(const gl_link *l, uint64_t *tx_bytes, uint64_t *rx_bytes,
		   uint64_t *round_trips)
{
	if (tx_bytes)
		*tx_bytes = l ? l->tx_bytes : 0;
	if (rx_bytes)
		*rx_bytes = l ? l->rx_bytes : 0;
	if (round_trips)
		*round_trips = l ? l->round_trips : 0;
}

int gl_link_fd(const gl_link *l)
{
	return l ? l->cmd.fd : -1;
}

int gl_link_msg_fd(const gl_link *l)
{
	return l ? l->msg.fd : -1;
}

bool gl_link_broken(const gl_link *l)
{
	return !l || l->cmd.broken;
}
