/*
 * sim_cmdport.c - galil-sim's Galil command port (see sim_cmdport.h): the
 * handles' connections, their reply queues and the link faults.
 */
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>
#include <arpa/inet.h>

#include "base_clock.h"
#include "gl_record.h"
#include "gl_err.h"
#include "sim.h"
#include "sim_cmdport.h"
#include "sim_sock.h"
#include "sim_wire.h"

#define CMDPORT_READ_CHUNK 4096 /* bytes per recv() */
#define CMDPORT_DL_BAD_LEN 100	/* SIM_LINE_DLREJECT: an over-long line */
#define CMDPORT_UDP_BURST  8	/* datagrams read per wake-up */

/* Does a host (a TCP connection or a UDP peer) hold this handle? */
static int conn_used(const struct sim_cmdport_conn *c)
{
	return c->fd >= 0 || c->udp;
}

/* The link fault this handle's side sees (sim_link_on()). */
static enum sim_link conn_link(const struct sim_cmdport *cp,
			       const struct sim_cmdport_conn *c,
			       double *delay_ms)
{
	return sim_link_on(cp->sim, c->udp, delay_ms);
}

void sim_cmdport_init(struct sim_cmdport *cp, struct sim *s)
{
	memset(cp, 0, sizeof(*cp));
	cp->sim = s;
	cp->lfd = -1;
	cp->ufd = -1;
	cp->rng = 1;
	for (int h = 0; h < CTRL_HANDLES; h++) {
		cp->conn[h].fd = -1;
		cp->conn[h].dl_line = -1;
	}
}

int sim_cmdport_listen(struct sim_cmdport *cp, const char *addr, int port,
		       char *err, size_t errlen)
{
	cp->lfd = sim_sock_listen(addr, port, &cp->port, err, errlen);
	return cp->lfd < 0 ? GL_ERR_SYS : 0;
}

/*
 * Close the connection of handle @h. @why names the cause for the event
 * "handle A closed (<why>)"; NULL for none (an IH close: the controller
 * records "handle A closed by IHT from handle B" itself).
 */
static void conn_close(struct sim_cmdport *cp, int h, const char *why)
{
	struct sim_cmdport_conn *c = &cp->conn[h];
	struct ctrl *ctl = sim_ctrl(cp->sim);

	if (!conn_used(c))
		return;
	if (c->fd >= 0)
		close(c->fd);
	c->fd = -1;
	c->udp = 0;
	c->out_len = 0;
	c->nchunk = 0;
	if (why && !ctrl_handle_close_wanted(ctl, h))
		sim_event(cp->sim, "handle %c closed (%s)", 'A' + h, why);
	ctrl_handle_close(ctl, h);
}

void sim_cmdport_shutdown(struct sim_cmdport *cp)
{
	for (int h = 0; h < CTRL_HANDLES; h++)
		conn_close(cp, h, NULL);
	if (cp->lfd >= 0)
		close(cp->lfd);
	cp->lfd = -1;
	if (cp->ufd >= 0)
		close(cp->ufd);
	cp->ufd = -1;
	cp->uport = 0;
}

void sim_cmdport_disconnect_all(void *ud)
{
	struct sim_cmdport *cp = ud;
	int drop = sim_link(cp->sim, NULL) == SIM_LINK_DROP;

	for (int h = 0; h < CTRL_HANDLES; h++) {
		/* a drop scoped to one side leaves the other side's handles */
		if (drop && conn_link(cp, &cp->conn[h], NULL) != SIM_LINK_DROP)
			continue;
		conn_close(cp, h, drop ? "link drop" : "power cycle");
	}
}

int sim_cmdport_listen_fd(const struct sim_cmdport *cp)
{
	return sim_link_on(cp->sim, 0, NULL) == SIM_LINK_STALL ? -1 : cp->lfd;
}

int sim_cmdport_fd(const struct sim_cmdport *cp, int h)
{
	return h >= 0 && h < CTRL_HANDLES ? cp->conn[h].fd : -1;
}

/* A fresh handle @h: empty queues, its "link first" fault armed. */
static void conn_reset(struct sim_cmdport *cp, int h)
{
	struct sim_cmdport_conn *c = &cp->conn[h];

	c->out_len = 0;
	c->nchunk = 0;
	sim_line_fault(cp->sim, 1, &c->pending);
	c->silent = c->midline = c->dl_reject = 0;
	c->dl_line = -1;
	c->line_len = 0;
}

void sim_cmdport_accept(struct sim_cmdport *cp)
{
	struct sockaddr_in sa;
	socklen_t len = sizeof(sa);
	int one = 1, h, fd = accept(cp->lfd, (struct sockaddr *)&sa, &len);
	char ip[INET_ADDRSTRLEN] = "?";

	if (fd < 0)
		return;
	inet_ntop(AF_INET, &sa.sin_addr, ip, sizeof(ip));
	for (h = 0; h < CTRL_HANDLES && conn_used(&cp->conn[h]); h++)
		;
	if (h == CTRL_HANDLES ||
	    sim_link_on(cp->sim, 0, NULL) == SIM_LINK_DROP) {
		close(fd); /* all handles busy, or the link is down */
		cp->refused++;
		sim_event(cp->sim, "connection from %s:%d refused (%s)", ip,
			  ntohs(sa.sin_port),
			  h == CTRL_HANDLES ? "all 8 handles busy"
					    : "link drop");
		return;
	}
	sim_sock_nonblock(fd);
	setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
	conn_reset(cp, h);
	cp->conn[h].fd = fd;
	ctrl_handle_open(sim_ctrl(cp->sim), h);
	ctrl_handle_peer(sim_ctrl(cp->sim), h, cp->port,
			 ntohl(sa.sin_addr.s_addr), ntohs(sa.sin_port));
	sim_event(cp->sim, "handle %c opened from %s:%d", 'A' + h, ip,
		  ntohs(sa.sin_port));
}

static void conn_input(struct sim_cmdport *cp, int h, const uint8_t *buf,
		       size_t len);

void sim_cmdport_read(struct sim_cmdport *cp, int h)
{
	uint8_t buf[CMDPORT_READ_CHUNK];
	ssize_t r;

	if (h < 0 || h >= CTRL_HANDLES || cp->conn[h].fd < 0)
		return;
	r = recv(cp->conn[h].fd, buf, sizeof(buf), 0);
	if (r < 0 && sim_sock_again(errno))
		return;
	if (r <= 0) {
		conn_close(cp, h, r == 0 ? "peer" : strerror(errno));
		return;
	}
	if (sim_link_on(cp->sim, 0, NULL) == SIM_LINK_STALL)
		return; /* lost on the wire */
	conn_input(cp, h, buf, (size_t)r);
}

/* Queue @n bytes due at @due_us (the last chunk grows when all are used). */
static void conn_queue(struct sim_cmdport_conn *c, const uint8_t *p, size_t n,
		       int64_t due_us)
{
	if (!n || c->out_len + n > SIM_CMDPORT_OUT_CAP)
		return;
	memcpy(c->out + c->out_len, p, n);
	c->out_len += n;
	if (c->nchunk == SIM_CMDPORT_CHUNKS) {
		c->chunk[c->nchunk - 1].end = c->out_len;
		return;
	}
	c->chunk[c->nchunk++] = (struct sim_cmdport_chunk){c->out_len, due_us};
}

/* Take the controller's output for handle h into the queue. */
static void conn_fill(struct sim_cmdport *cp, int h, int64_t now)
{
	struct sim_cmdport_conn *c = &cp->conn[h];
	double delay_ms;
	enum sim_link link = conn_link(cp, c, &delay_ms);
	size_t got;

	if (link == SIM_LINK_STALL) {
		uint8_t sink[1024];

		while (ctrl_output(sim_ctrl(cp->sim), h, sink, sizeof(sink)))
			;
		return;
	}
	if (c->nchunk == SIM_CMDPORT_CHUNKS ||
	    c->out_len == SIM_CMDPORT_OUT_CAP)
		return; /* the controller keeps it meanwhile */
	got = ctrl_output(sim_ctrl(cp->sim), h, c->out + c->out_len,
			  SIM_CMDPORT_OUT_CAP - c->out_len);
	if (!got)
		return;
	c->out_len += got;
	c->chunk[c->nchunk].end = c->out_len;
	c->chunk[c->nchunk].due_us =
	    now + (link == SIM_LINK_DELAY ? (int64_t)(delay_ms * 1000) : 0);
	c->nchunk++;
}

/* Send the queued bytes whose time has come. */
static void conn_flush(struct sim_cmdport *cp, int h, int64_t now)
{
	struct sim_cmdport_conn *c = &cp->conn[h];
	size_t ready = 0;
	ssize_t w;
	int k;

	for (k = 0; k < c->nchunk && c->chunk[k].due_us <= now; k++)
		ready = c->chunk[k].end;
	if (!ready)
		return;
	w = send(c->fd, c->out, ready, MSG_NOSIGNAL);
	if (w < 0 && sim_sock_again(errno))
		return;
	if (w < 0) {
		conn_close(cp, h, strerror(errno));
		return;
	}
	memmove(c->out, c->out + w, c->out_len - (size_t)w);
	c->out_len -= (size_t)w;
	for (k = 0; k < c->nchunk && c->chunk[k].end <= (size_t)w; k++)
		;
	memmove(c->chunk, c->chunk + k,
		(size_t)(c->nchunk - k) * sizeof(c->chunk[0]));
	c->nchunk -= k;
	for (k = 0; k < c->nchunk; k++)
		c->chunk[k].end -= (size_t)w;
}

/* ---- line faults ------------------------------------------------------ */

/* Reshape the reply of the line just run under @f and queue its pieces. */
static void conn_shape(struct sim_cmdport *cp, int h,
		       const struct sim_line_fault *f)
{
	struct sim_cmdport_conn *c = &cp->conn[h];
	struct sim_wire_piece piece[SIM_CMDPORT_CHUNKS];
	int64_t now = base_now_us(), late = 0;
	double delay_ms;
	size_t got, room = SIM_CMDPORT_OUT_CAP - c->out_len, prev = 0;
	int k;

	if (room <= SIM_WIRE_GROWTH || c->nchunk > SIM_CMDPORT_CHUNKS - 2)
		return; /* no room: conn_fill() sends it unshaped */
	if (conn_link(cp, c, &delay_ms) == SIM_LINK_DELAY)
		late = (int64_t)(delay_ms * 1000);
	got = ctrl_output(sim_ctrl(cp->sim), h, cp->reply,
			  room - SIM_WIRE_GROWTH);
	k = sim_wire_shape(f, cp->reply, got, cp->shaped, sizeof(cp->shaped),
			   piece, SIM_CMDPORT_CHUNKS - c->nchunk, &cp->rng);
	if (k == 0) { /* cannot happen with the room checked: never lose it */
		conn_queue(c, cp->reply, got, now + late);
		return;
	}
	for (int i = 0; i < k; i++) {
		conn_queue(c, cp->shaped + prev, piece[i].end - prev,
			   now + late + piece[i].delay_us);
		prev = piece[i].end;
	}
}

/* Run the held line (@len bytes, its end included) under fault @f. */
static void line_run(struct sim_cmdport *cp, int h,
		     const struct sim_line_fault *f, size_t len)
{
	struct sim_cmdport_conn *c = &cp->conn[h];
	struct ctrl *ctl = sim_ctrl(cp->sim);
	char q[SIM_CMDPORT_LINE + 8];
	size_t n;

	switch (f->kind) {
	case SIM_LINE_DROP: conn_close(cp, h, "line fault drop"); return;
	case SIM_LINE_SILENT: c->silent = 1; return;
	case SIM_LINE_NONE:
	case SIM_LINE_DLREJECT:
		ctrl_input(ctl, h, (const uint8_t *)c->line, len);
		return;
	case SIM_LINE_QMARK:
		n = sim_wire_qmark(c->line, len - 1, q, sizeof(q) - 1);
		q[n++] = '\r';
		ctrl_input(ctl, h, (const uint8_t *)q, n);
		return;
	default:
		conn_fill(cp, h, base_now_us()); /* what came before */
		ctrl_input(ctl, h, (const uint8_t *)c->line, len);
		conn_shape(cp, h, f);
	}
}

/* Is the held line (@len bytes, CR included) a DL command? */
static int is_dl(const char *line, size_t len)
{
	size_t i = 0;

	while (i < len && line[i] == ' ')
		i++;
	return len - i >= 3 && line[i] == 'D' && line[i + 1] == 'L' &&
	       line[i + 2] && strchr("\r #", line[i + 2]);
}

/* A held line of a watched download: line dl_reject is corrupted. */
static void dl_line_end(struct sim_cmdport *cp, int h, size_t len)
{
	struct sim_cmdport_conn *c = &cp->conn[h];
	char bad[CMDPORT_DL_BAD_LEN + 1];

	if (c->line[len - 1] != '\r') { /* the download's end */
		c->dl_line = -1;
		c->dl_reject = 0;
	} else if (++c->dl_line == c->dl_reject) {
		sim_event(cp->sim, "handle %c: line fault dlreject at line %d",
			  'A' + h, c->dl_line);
		memset(bad, 'X', CMDPORT_DL_BAD_LEN);
		bad[CMDPORT_DL_BAD_LEN] = '\r';
		ctrl_input(sim_ctrl(cp->sim), h, (const uint8_t *)bad,
			   sizeof(bad));
		return;
	}
	ctrl_input(sim_ctrl(cp->sim), h, (const uint8_t *)c->line, len);
}

/* A held line has ended: the fault waiting for it meets it. */
static void line_end(struct sim_cmdport *cp, int h)
{
	struct sim_cmdport_conn *c = &cp->conn[h];
	struct sim_line_fault f = {SIM_LINE_NONE, 0};
	size_t len = c->line_len;

	c->line_len = 0;
	c->midline = 0;
	if (c->dl_line >= 0) {
		dl_line_end(cp, h, len);
		return;
	}
	if (c->pending.kind != SIM_LINE_NONE) {
		f = c->pending;
		c->pending.kind = SIM_LINE_NONE;
	} else if (sim_line_fault(cp->sim, 0, &f)) {
		sim_line_fault_used(cp->sim);
	}
	if (f.kind != SIM_LINE_NONE)
		sim_event(cp->sim, "handle %c: line fault %s", 'A' + h,
			  sim_line_fault_name(f.kind));
	if (f.kind == SIM_LINE_DLREJECT)
		c->dl_reject = f.arg;
	if (c->dl_reject && is_dl(c->line, len))
		c->dl_line = 0;
	line_run(cp, h, &f, len);
}

/* Is a fault waiting for the next line this connection begins? */
static int fault_waiting(const struct sim_cmdport *cp,
			 const struct sim_cmdport_conn *c)
{
	struct sim_line_fault f;

	return c->pending.kind != SIM_LINE_NONE || c->dl_reject ||
	       sim_line_fault(cp->sim, 0, &f);
}

static int is_line_end(const struct sim_cmdport_conn *c, uint8_t b)
{
	return b == '\r' || (c->dl_line >= 0 && (b == '\\' || b == 0x1a ||
						 b == 0x11 || b == 0x04));
}

/*
 * Bytes from handle @h's host: to the controller as they come, except a
 * line a fault waits for, held until its end (line_end()).
 */
static void conn_input(struct sim_cmdport *cp, int h, const uint8_t *buf,
		       size_t len)
{
	struct sim_cmdport_conn *c = &cp->conn[h];
	struct ctrl *ctl = sim_ctrl(cp->sim);
	size_t n;
	int end;

	while (len && conn_used(c) && !c->silent) {
		for (n = 0; n < len && !is_line_end(c, buf[n]); n++)
			;
		end = n < len;
		n += (size_t)end;
		if (c->line_len == 0 && (c->midline || !fault_waiting(cp, c))) {
			ctrl_input(ctl, h, buf, n);
			c->midline = !end;
		} else if (c->line_len + n > sizeof(c->line)) {
			/* too long to hold: the controller gets it as is */
			ctrl_input(ctl, h, (const uint8_t *)c->line,
				   c->line_len);
			ctrl_input(ctl, h, buf, n);
			c->line_len = 0;
			c->midline = !end;
		} else {
			memcpy(c->line + c->line_len, buf, n);
			c->line_len += n;
			if (end)
				line_end(cp, h);
		}
		buf += n;
		len -= n;
	}
}

/* Has everything the controller queued for handle @by been sent? A
 * program, the private port or a gone sender leave nothing to wait for. */
static int reply_gone(struct sim_cmdport *cp, int by)
{
	return by < 0 || by >= CTRL_HANDLES || !conn_used(&cp->conn[by]) ||
	       (cp->conn[by].out_len == 0 &&
		ctrl_output_pending(sim_ctrl(cp->sim), by) == 0);
}

/* IH closing: a handle the controller wants closed is closed once the
 * reply of the IH command has been sent to its sender (IHS: to itself). */
static void close_wanted(struct sim_cmdport *cp)
{
	struct ctrl *c = sim_ctrl(cp->sim);

	for (int h = 0; h < CTRL_HANDLES; h++) {
		if (conn_used(&cp->conn[h]) && ctrl_handle_close_wanted(c, h) &&
		    reply_gone(cp, ctrl_handle_close_by(c, h)))
			conn_close(cp, h, NULL);
	}
}

/* ---- UDP: handles, replies and the record stream ----------------------- */

int sim_cmdport_udp_open(struct sim_cmdport *cp, const char *addr, int port,
			 char *err, size_t errlen)
{
	struct sockaddr_in sa = {.sin_family = AF_INET};
	socklen_t len = sizeof(sa);

	addr = addr ? addr : "127.0.0.1";
	if (cp->ufd >= 0 || port < 0 || port > 65535 ||
	    inet_pton(AF_INET, addr, &sa.sin_addr) != 1) {
		snprintf(err, errlen, "invalid UDP port '%s:%d'", addr, port);
		return GL_ERR_ARG;
	}
	sa.sin_port = htons((uint16_t)port);
	cp->ufd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
	if (cp->ufd < 0 ||
	    bind(cp->ufd, (struct sockaddr *)&sa, sizeof(sa)) < 0 ||
	    getsockname(cp->ufd, (struct sockaddr *)&sa, &len) < 0) {
		snprintf(err, errlen, "cannot bind the UDP port %s:%d: %s",
			 addr, port, strerror(errno));
		if (cp->ufd >= 0)
			close(cp->ufd);
		cp->ufd = -1;
		return GL_ERR_SYS;
	}
	sim_sock_nonblock(cp->ufd);
	cp->uport = ntohs(sa.sin_port);
	return 0;
}

int sim_cmdport_udp_fd(const struct sim_cmdport *cp)
{
	return cp->ufd;
}

/* The handle of the UDP peer @sa: its own, or the lowest free one opened
 * for it. Return: the handle, or -1 (refused, with its event). */
static int udp_handle(struct sim_cmdport *cp, const struct sockaddr_in *sa)
{
	uint32_t ip = ntohl(sa->sin_addr.s_addr);
	uint16_t port = ntohs(sa->sin_port);
	char a[INET_ADDRSTRLEN] = "?";
	int h;

	for (h = 0; h < CTRL_HANDLES; h++)
		if (cp->conn[h].udp && cp->conn[h].peer_ip == ip &&
		    cp->conn[h].peer_port == port)
			return h;
	inet_ntop(AF_INET, &sa->sin_addr, a, sizeof(a));
	for (h = 0; h < CTRL_HANDLES && conn_used(&cp->conn[h]); h++)
		;
	if (h == CTRL_HANDLES ||
	    sim_link_on(cp->sim, 1, NULL) == SIM_LINK_DROP) {
		cp->refused++;
		sim_event(cp->sim, "datagram from %s:%d refused (%s)", a, port,
			  h == CTRL_HANDLES ? "all 8 handles busy"
					    : "link drop");
		return -1;
	}
	conn_reset(cp, h);
	cp->conn[h].udp = 1;
	cp->conn[h].peer_ip = ip;
	cp->conn[h].peer_port = port;
	ctrl_handle_open_udp(sim_ctrl(cp->sim), h);
	ctrl_handle_peer(sim_ctrl(cp->sim), h, cp->uport, ip, port);
	sim_event(cp->sim, "handle %c opened from %s:%d (UDP)", 'A' + h, a,
		  port);
	return h;
}

/* A datagram ends its line: a CR is added when its last line has none. */
static size_t udp_terminate(uint8_t *buf, size_t len)
{
	size_t e = len;

	while (e && buf[e - 1] == '\n')
		e--;
	if (e == 0 || buf[e - 1] != '\r')
		buf[len++] = '\r';
	return len;
}

void sim_cmdport_udp_read(struct sim_cmdport *cp)
{
	uint8_t buf[CMDPORT_READ_CHUNK + 1];
	struct sockaddr_in sa;
	socklen_t sl;
	ssize_t r;
	int h;

	for (int i = 0; cp->ufd >= 0 && i < CMDPORT_UDP_BURST; i++) {
		sl = sizeof(sa);
		r = recvfrom(cp->ufd, buf, CMDPORT_READ_CHUNK, 0,
			     (struct sockaddr *)&sa, &sl);
		if (r < 0)
			return; /* nothing more (or an error: the next poll) */
		if (sim_link_on(cp->sim, 1, NULL) == SIM_LINK_STALL)
			continue; /* lost on the wire */
		if ((h = udp_handle(cp, &sa)) < 0)
			continue;
		conn_input(cp, h, buf, udp_terminate(buf, (size_t)r));
		/* this datagram's reply is one datagram of its own */
		if (cp->conn[h].udp)
			conn_fill(cp, h, base_now_us());
	}
}

/* The DR records the controller made: one chunk (datagram) each, for an
 * open UDP handle; under the stream side's stall or drop they are lost. */
static void stream_fill(struct sim_cmdport *cp, int64_t now)
{
	uint8_t rec[GL_REC_MAX_BYTES];
	double delay_ms;
	size_t n;
	int h;

	while (
	    (n = ctrl_stream_take(sim_ctrl(cp->sim), &h, rec, sizeof(rec)))) {
		enum sim_link l = sim_link_on(cp->sim, 1, &delay_ms);

		if (h < 0 || h >= CTRL_HANDLES || !cp->conn[h].udp ||
		    l == SIM_LINK_STALL || l == SIM_LINK_DROP)
			continue;
		conn_queue(&cp->conn[h], rec, n,
			   now + (l == SIM_LINK_DELAY
				      ? (int64_t)(delay_ms * 1000)
				      : 0));
	}
}

/* Send the due chunks of UDP handle @h, each as one datagram. */
static void udp_flush(struct sim_cmdport *cp, int h, int64_t now)
{
	struct sim_cmdport_conn *c = &cp->conn[h];
	struct sockaddr_in sa = {.sin_family = AF_INET};
	size_t start = 0;
	int k;

	sa.sin_addr.s_addr = htonl(c->peer_ip);
	sa.sin_port = htons(c->peer_port);
	for (k = 0; k < c->nchunk && c->chunk[k].due_us <= now; k++) {
		if (sendto(cp->ufd, c->out + start, c->chunk[k].end - start,
			   MSG_NOSIGNAL, (struct sockaddr *)&sa,
			   sizeof(sa)) < 0 &&
		    sim_sock_again(errno))
			break; /* the socket is full: try again later */
		start = c->chunk[k].end; /* sent, or lost as on a network */
	}
	memmove(c->out, c->out + start, c->out_len - start);
	c->out_len -= start;
	memmove(c->chunk, c->chunk + k,
		(size_t)(c->nchunk - k) * sizeof(c->chunk[0]));
	c->nchunk -= k;
	for (k = 0; k < c->nchunk; k++)
		c->chunk[k].end -= start;
}

void sim_cmdport_flush(struct sim_cmdport *cp, int64_t now_us)
{
	for (int h = 0; h < CTRL_HANDLES; h++) {
		if (!conn_used(&cp->conn[h]))
			continue;
		conn_fill(cp, h, now_us);
	}
	stream_fill(cp, now_us);
	for (int h = 0; h < CTRL_HANDLES; h++) {
		if (cp->conn[h].udp)
			udp_flush(cp, h, now_us);
		else if (cp->conn[h].fd >= 0)
			conn_flush(cp, h, now_us);
	}
	close_wanted(cp);
}
