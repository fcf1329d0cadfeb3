/*
 * sim_cmdport.c - galil-sim's Galil command port (see sim_cmdport.h): the
 * handles' connections, their reply queues and the link faults.
 */
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>
#include <arpa/inet.h>

#include "gl_err.h"
#include "sim.h"
#include "sim_cmdport.h"
#include "sim_sock.h"

#define CMDPORT_READ_CHUNK 4096 /* bytes per recv() */

void sim_cmdport_init(struct sim_cmdport *cp, struct sim *s)
{
	memset(cp, 0, sizeof(*cp));
	cp->sim = s;
	cp->lfd = -1;
	for (int h = 0; h < CTRL_HANDLES; h++)
		cp->conn[h].fd = -1;
}

int sim_cmdport_listen(struct sim_cmdport *cp, int port, char *err,
		       size_t errlen)
{
	cp->lfd = sim_sock_listen(port, &cp->port, err, errlen);
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

	if (c->fd < 0)
		return;
	close(c->fd);
	c->fd = -1;
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
}

void sim_cmdport_disconnect_all(void *ud)
{
	struct sim_cmdport *cp = ud;
	const char *why = sim_link(cp->sim, NULL) == SIM_LINK_DROP
			      ? "link drop"
			      : "power cycle";

	for (int h = 0; h < CTRL_HANDLES; h++)
		conn_close(cp, h, why);
}

int sim_cmdport_listen_fd(const struct sim_cmdport *cp)
{
	return sim_link(cp->sim, NULL) == SIM_LINK_STALL ? -1 : cp->lfd;
}

int sim_cmdport_fd(const struct sim_cmdport *cp, int h)
{
	return h >= 0 && h < CTRL_HANDLES ? cp->conn[h].fd : -1;
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
	for (h = 0; h < CTRL_HANDLES && cp->conn[h].fd >= 0; h++)
		;
	if (h == CTRL_HANDLES || sim_link(cp->sim, NULL) == SIM_LINK_DROP) {
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
	cp->conn[h].fd = fd;
	cp->conn[h].out_len = 0;
	cp->conn[h].nchunk = 0;
	ctrl_handle_open(sim_ctrl(cp->sim), h);
	ctrl_handle_peer(sim_ctrl(cp->sim), h, cp->port,
			 ntohl(sa.sin_addr.s_addr), ntohs(sa.sin_port));
	sim_event(cp->sim, "handle %c opened from %s:%d", 'A' + h, ip,
		  ntohs(sa.sin_port));
}

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
	if (sim_link(cp->sim, NULL) == SIM_LINK_STALL)
		return; /* lost on the wire */
	ctrl_input(sim_ctrl(cp->sim), h, buf, (size_t)r);
}

/* Take the controller's output for handle h into the queue. */
static void conn_fill(struct sim_cmdport *cp, int h, int64_t now)
{
	struct sim_cmdport_conn *c = &cp->conn[h];
	double delay_ms;
	enum sim_link link = sim_link(cp->sim, &delay_ms);
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

/* Has everything the controller queued for handle @by been sent? A
 * program, the private port or a gone sender leave nothing to wait for. */
static int reply_gone(struct sim_cmdport *cp, int by)
{
	return by < 0 || by >= CTRL_HANDLES || cp->conn[by].fd < 0 ||
	       (cp->conn[by].out_len == 0 &&
		ctrl_output_pending(sim_ctrl(cp->sim), by) == 0);
}

/* IH closing: a handle the controller wants closed is closed once the
 * reply of the IH command has been sent to its sender (IHS: to itself). */
static void close_wanted(struct sim_cmdport *cp)
{
	struct ctrl *c = sim_ctrl(cp->sim);

	for (int h = 0; h < CTRL_HANDLES; h++) {
		if (cp->conn[h].fd >= 0 && ctrl_handle_close_wanted(c, h) &&
		    reply_gone(cp, ctrl_handle_close_by(c, h)))
			conn_close(cp, h, NULL);
	}
}

void sim_cmdport_flush(struct sim_cmdport *cp, int64_t now_us)
{
	for (int h = 0; h < CTRL_HANDLES; h++) {
		if (cp->conn[h].fd < 0)
			continue;
		conn_fill(cp, h, now_us);
		conn_flush(cp, h, now_us);
	}
	close_wanted(cp);
}
