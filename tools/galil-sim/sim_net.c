/*
 * sim_net.c - galil-sim's sockets and real-time loop (see sim_net.h).
 *
 * Link faults (sim_link()): DROP closes every command connection (through
 * the disconnect callback, at once) and closes new ones as soon as they are
 * accepted; STALL reads and discards what the hosts send and sends nothing
 * (a half-open link: both directions lost), and leaves new connections in
 * the listen backlog; DELAY holds each reply back by the delay before it is
 * written.
 *
 * IH closing: a handle the controller marks (ctrl_handle_close_wanted()) is
 * closed after the reply of the IH command has gone to its sender. Opening
 * and closing a connection are events ("handle A opened from ...",
 * "handle A closed (peer)").
 */
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/timerfd.h>
#include <time.h>
#include <unistd.h>
#include <arpa/inet.h>

#include "gl_err.h"
#include "sim.h"
#include "sim_net.h"
#include "sim_relay.h"

#define NET_OUT_CAP	    65536 /* bytes queued per command connection */
#define NET_CHUNKS	    512	  /* delayed reply chunks per connection */
#define NET_CATCHUP_SAMPLES 100	  /* samples stepped per pass when late */
#define NET_READ_CHUNK	    4096
#define NET_CTL_IN	    1024 /* control request line buffer */
#define NET_POLL_MAX	    (4 + CTRL_HANDLES + SIM_NET_CONTROL_CLIENTS)

struct net_chunk {
	size_t end;	/* offset in out[] where this chunk ends */
	int64_t due_us; /* monotonic time it may be sent */
};

struct net_conn {
	int fd; /* -1 = free; slot index = controller handle */
	uint8_t out[NET_OUT_CAP];
	size_t out_len;
	struct net_chunk chunk[NET_CHUNKS];
	int nchunk;
};

struct net_client {
	int fd; /* -1 = free */
	char in[NET_CTL_IN];
	size_t in_len;
	int discarding; /* skipping the rest of an over-long line */
	char *out;	/* SIM_RESPONSE_MAX + 1 bytes */
	size_t out_len, out_sent;
};

struct sim_net {
	struct sim *sim;
	int lfd, cfd, tfd; /* command listener, control listener, timer */
	int port, control_port;
	int64_t sample_us; /* timer period in use */
	uint64_t debt;	   /* samples due but not stepped yet */
	struct net_conn conn[CTRL_HANDLES];
	struct net_client client[SIM_NET_CONTROL_CLIENTS];
	struct sim_net_stats stats;
};

static int64_t now_us(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static void set_nonblock(int fd)
{
	fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
	fcntl(fd, F_SETFD, FD_CLOEXEC);
}

static int listen_on(int port, int *bound, char *err, size_t errlen)
{
	struct sockaddr_in sa = {.sin_family = AF_INET};
	socklen_t len = sizeof(sa);
	int one = 1, fd = socket(AF_INET, SOCK_STREAM, 0);

	sa.sin_port = htons((uint16_t)port);
	sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	if (fd < 0 ||
	    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one)) < 0 ||
	    bind(fd, (struct sockaddr *)&sa, sizeof(sa)) < 0 ||
	    listen(fd, 16) < 0 ||
	    getsockname(fd, (struct sockaddr *)&sa, &len) < 0) {
		snprintf(err, errlen, "cannot listen on 127.0.0.1:%d: %s", port,
			 strerror(errno));
		if (fd >= 0)
			close(fd);
		return GL_ERR_SYS;
	}
	set_nonblock(fd);
	*bound = ntohs(sa.sin_port);
	return fd;
}

/* ---- command connections ---------------------------------------------- */

/*
 * Close the connection of handle @h. @why names the cause for the event
 * "handle A closed (<why>)"; NULL for none (an IH close: the controller
 * records "handle A closed by IHT from handle B" itself).
 */
static void conn_close(struct sim_net *n, int h, const char *why)
{
	struct net_conn *c = &n->conn[h];
	struct ctrl *ctl = sim_ctrl(n->sim);

	if (c->fd < 0)
		return;
	close(c->fd);
	c->fd = -1;
	c->out_len = 0;
	c->nchunk = 0;
	if (why && !ctrl_handle_close_wanted(ctl, h))
		sim_event(n->sim, "handle %c closed (%s)", 'A' + h, why);
	ctrl_handle_close(ctl, h);
}

/* The disconnect callback of sim.h: a link drop or a power cycle. */
static void disconnect_all(void *ud)
{
	struct sim_net *n = ud;
	const char *why = sim_link(n->sim, NULL) == SIM_LINK_DROP
			      ? "link drop"
			      : "power cycle";

	for (int h = 0; h < CTRL_HANDLES; h++)
		conn_close(n, h, why);
}

static void conn_accept(struct sim_net *n)
{
	struct sockaddr_in sa;
	socklen_t len = sizeof(sa);
	int one = 1, h, fd = accept(n->lfd, (struct sockaddr *)&sa, &len);
	char ip[INET_ADDRSTRLEN] = "?";

	if (fd < 0)
		return;
	inet_ntop(AF_INET, &sa.sin_addr, ip, sizeof(ip));
	for (h = 0; h < CTRL_HANDLES && n->conn[h].fd >= 0; h++)
		;
	if (h == CTRL_HANDLES || sim_link(n->sim, NULL) == SIM_LINK_DROP) {
		close(fd); /* all handles busy, or the link is down */
		n->stats.refused++;
		sim_event(n->sim, "connection from %s:%d refused (%s)", ip,
			  ntohs(sa.sin_port),
			  h == CTRL_HANDLES ? "all 8 handles busy"
					    : "link drop");
		return;
	}
	set_nonblock(fd);
	setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
	n->conn[h].fd = fd;
	n->conn[h].out_len = 0;
	n->conn[h].nchunk = 0;
	ctrl_handle_open(sim_ctrl(n->sim), h);
	ctrl_handle_peer(sim_ctrl(n->sim), h, n->port,
			 ntohl(sa.sin_addr.s_addr), ntohs(sa.sin_port));
	sim_event(n->sim, "handle %c opened from %s:%d", 'A' + h, ip,
		  ntohs(sa.sin_port));
}

static void conn_read(struct sim_net *n, int h)
{
	uint8_t buf[NET_READ_CHUNK];
	ssize_t r = recv(n->conn[h].fd, buf, sizeof(buf), 0);

	if (r < 0 &&
	    (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR))
		return;
	if (r <= 0) {
		conn_close(n, h, r == 0 ? "peer" : strerror(errno));
		return;
	}
	if (sim_link(n->sim, NULL) == SIM_LINK_STALL)
		return; /* lost on the wire */
	ctrl_input(sim_ctrl(n->sim), h, buf, (size_t)r);
}

/* Take the controller's output for handle h into the queue. */
static void conn_fill(struct sim_net *n, int h, int64_t now)
{
	struct net_conn *c = &n->conn[h];
	double delay_ms;
	enum sim_link link = sim_link(n->sim, &delay_ms);
	size_t got;

	if (link == SIM_LINK_STALL) {
		uint8_t sink[1024];

		while (ctrl_output(sim_ctrl(n->sim), h, sink, sizeof(sink)))
			;
		return;
	}
	if (c->nchunk == NET_CHUNKS || c->out_len == NET_OUT_CAP)
		return; /* the controller keeps it meanwhile */
	got = ctrl_output(sim_ctrl(n->sim), h, c->out + c->out_len,
			  NET_OUT_CAP - c->out_len);
	if (!got)
		return;
	c->out_len += got;
	c->chunk[c->nchunk].end = c->out_len;
	c->chunk[c->nchunk].due_us =
	    now + (link == SIM_LINK_DELAY ? (int64_t)(delay_ms * 1000) : 0);
	c->nchunk++;
}

/* Send the queued bytes whose time has come. */
static void conn_flush(struct sim_net *n, int h, int64_t now)
{
	struct net_conn *c = &n->conn[h];
	size_t ready = 0;
	ssize_t w;
	int k;

	for (k = 0; k < c->nchunk && c->chunk[k].due_us <= now; k++)
		ready = c->chunk[k].end;
	if (!ready)
		return;
	w = send(c->fd, c->out, ready, MSG_NOSIGNAL);
	if (w < 0 &&
	    (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR))
		return;
	if (w < 0) {
		conn_close(n, h, strerror(errno));
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

/* ---- control clients -------------------------------------------------- */

static void client_close(struct net_client *cl)
{
	if (cl->fd >= 0)
		close(cl->fd);
	cl->fd = -1;
	free(cl->out);
	cl->out = NULL;
}

static void client_accept(struct sim_net *n)
{
	int fd = accept(n->cfd, NULL, NULL), i;

	if (fd < 0)
		return;
	for (i = 0; i < SIM_NET_CONTROL_CLIENTS && n->client[i].fd >= 0; i++)
		;
	if (i == SIM_NET_CONTROL_CLIENTS) {
		static const char busy[] = "error: too many control clients\n";

		(void)!send(fd, busy, sizeof(busy) - 1, MSG_NOSIGNAL);
		close(fd);
		return;
	}
	memset(&n->client[i], 0, sizeof(n->client[i]));
	n->client[i].out = malloc(SIM_RESPONSE_MAX + 1);
	if (!n->client[i].out) {
		close(fd);
		n->client[i].fd = -1;
		return;
	}
	set_nonblock(fd);
	n->client[i].fd = fd;
}

static void client_answer(struct sim_net *n, struct net_client *cl, char *line)
{
	size_t len = strlen(line);

	if (len && line[len - 1] == '\r')
		line[--len] = '\0';
	if (cl->discarding) {
		snprintf(cl->out, SIM_RESPONSE_MAX,
			 "error: request too long "
			 "(at most %d bytes)",
			 SIM_REQUEST_MAX - 1);
		cl->discarding = 0;
	} else {
		sim_control(n->sim, line, cl->out, SIM_RESPONSE_MAX);
	}
	cl->out_len = strlen(cl->out);
	cl->out[cl->out_len++] = '\n';
	cl->out_sent = 0;
}

/* Answer the next complete line, if the previous answer has gone. */
static void client_process(struct sim_net *n, struct net_client *cl)
{
	char *nl;
	size_t used;

	while (cl->fd >= 0 && cl->out_len == 0) {
		nl = memchr(cl->in, '\n', cl->in_len);
		if (!nl) {
			if (cl->in_len == sizeof(cl->in)) {
				cl->discarding = 1; /* keep the tail only */
				cl->in_len = 0;
			}
			return;
		}
		*nl = '\0';
		used = (size_t)(nl - cl->in) + 1;
		client_answer(n, cl, cl->in);
		memmove(cl->in, cl->in + used, cl->in_len - used);
		cl->in_len -= used;
	}
}

static void client_read(struct sim_net *n, struct net_client *cl)
{
	ssize_t r =
	    recv(cl->fd, cl->in + cl->in_len, sizeof(cl->in) - cl->in_len, 0);

	if (r < 0 &&
	    (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR))
		return;
	if (r <= 0) {
		client_close(cl);
		return;
	}
	cl->in_len += (size_t)r;
	client_process(n, cl);
}

static void client_flush(struct sim_net *n, struct net_client *cl)
{
	ssize_t w;

	if (cl->fd < 0 || cl->out_sent == cl->out_len)
		return;
	w = send(cl->fd, cl->out + cl->out_sent, cl->out_len - cl->out_sent,
		 MSG_NOSIGNAL);
	if (w < 0 &&
	    (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR))
		return;
	if (w < 0) {
		client_close(cl);
		return;
	}
	cl->out_sent += (size_t)w;
	if (cl->out_sent == cl->out_len) {
		cl->out_len = cl->out_sent = 0;
		client_process(n, cl);
	}
}

/* ---- life cycle ------------------------------------------------------- */

int sim_net_open(struct sim_net **out, struct sim *s, int port,
		 int control_port, char *err, size_t errlen)
{
	struct sim_net *n = calloc(1, sizeof(*n));

	*out = NULL;
	if (!n) {
		snprintf(err, errlen, "out of memory");
		return GL_ERR_NOMEM;
	}
	n->sim = s;
	n->lfd = n->cfd = n->tfd = -1;
	for (int h = 0; h < CTRL_HANDLES; h++)
		n->conn[h].fd = -1;
	for (int i = 0; i < SIM_NET_CONTROL_CLIENTS; i++)
		n->client[i].fd = -1;
	n->lfd = listen_on(port, &n->port, err, errlen);
	if (n->lfd >= 0)
		n->cfd = listen_on(control_port, &n->control_port, err, errlen);
	if (n->lfd < 0 || n->cfd < 0) {
		sim_net_free(n);
		return GL_ERR_SYS;
	}
	sim_set_disconnect(s, disconnect_all, n);
	*out = n;
	return 0;
}

void sim_net_free(struct sim_net *n)
{
	if (!n)
		return;
	sim_set_disconnect(n->sim, NULL, NULL);
	for (int h = 0; h < CTRL_HANDLES; h++)
		conn_close(n, h, NULL);
	for (int i = 0; i < SIM_NET_CONTROL_CLIENTS; i++)
		client_close(&n->client[i]);
	if (n->lfd >= 0)
		close(n->lfd);
	if (n->cfd >= 0)
		close(n->cfd);
	if (n->tfd >= 0)
		close(n->tfd);
	free(n);
}

int sim_net_port(const struct sim_net *n)
{
	return n->port;
}

int sim_net_control_port(const struct sim_net *n)
{
	return n->control_port;
}

void sim_net_stats(const struct sim_net *n, struct sim_net_stats *out)
{
	*out = n->stats;
}

/* ---- the loop --------------------------------------------------------- */

/* (Re)start the sample timer at the controller's current period. */
static int timer_arm(struct sim_net *n, char *err, size_t errlen)
{
	int64_t period = (int64_t)(ctrl_sample_ms(sim_ctrl(n->sim)) * 1000);
	struct itimerspec it;
	struct timespec now;

	if (period < 100)
		period = 100; /* a sane floor: 0.1 ms */
	clock_gettime(CLOCK_MONOTONIC, &now);
	it.it_interval.tv_sec = period / 1000000;
	it.it_interval.tv_nsec = (long)(period % 1000000) * 1000;
	it.it_value = now;
	it.it_value.tv_nsec += it.it_interval.tv_nsec;
	it.it_value.tv_sec += it.it_interval.tv_sec;
	if (it.it_value.tv_nsec >= 1000000000L) {
		it.it_value.tv_nsec -= 1000000000L;
		it.it_value.tv_sec++;
	}
	if (timerfd_settime(n->tfd, TFD_TIMER_ABSTIME, &it, NULL) < 0) {
		snprintf(err, errlen, "cannot arm the sample timer: %s",
			 strerror(errno));
		return GL_ERR_SYS;
	}
	n->sample_us = (int64_t)(ctrl_sample_ms(sim_ctrl(n->sim)) * 1000);
	return 0;
}

static void timer_read(struct sim_net *n)
{
	uint64_t exp;

	if (read(n->tfd, &exp, sizeof(exp)) != (ssize_t)sizeof(exp))
		return;
	n->debt += exp;
	if (exp > 1)
		n->stats.late_wakeups++;
	if (exp > n->stats.max_due)
		n->stats.max_due = exp;
}

static void step_due(struct sim_net *n)
{
	uint64_t k =
	    n->debt < NET_CATCHUP_SAMPLES ? n->debt : NET_CATCHUP_SAMPLES;

	for (uint64_t i = 0; i < k; i++)
		sim_step(n->sim);
	n->debt -= k;
	n->stats.samples += k;
}

/* Fill @fds; @slot[i] says what fds[i] is: -1 timer, -2 command listener,
 * -3 control listener, -4 relay, 0..7 command conn, 100+i control client. */
static int build_poll(struct sim_net *n, struct pollfd *fds, int *slot)
{
	int k = 0, rfd = sim_relay_fd(sim_get_relay(n->sim));

	fds[k] = (struct pollfd){n->tfd, POLLIN, 0};
	slot[k++] = -1;
	/* connections before the listener: a close seen in the same pass
	 * frees its handle for a new connection */
	for (int h = 0; h < CTRL_HANDLES; h++) {
		if (n->conn[h].fd >= 0) {
			fds[k] = (struct pollfd){n->conn[h].fd, POLLIN, 0};
			slot[k++] = h;
		}
	}
	if (sim_link(n->sim, NULL) != SIM_LINK_STALL) {
		fds[k] = (struct pollfd){n->lfd, POLLIN, 0};
		slot[k++] = -2;
	}
	fds[k] = (struct pollfd){n->cfd, POLLIN, 0};
	slot[k++] = -3;
	if (rfd >= 0) {
		fds[k] = (struct pollfd){rfd, POLLIN, 0};
		slot[k++] = -4;
	}
	for (int i = 0; i < SIM_NET_CONTROL_CLIENTS; i++) {
		if (n->client[i].fd >= 0 && n->client[i].out_len == 0) {
			fds[k] = (struct pollfd){n->client[i].fd, POLLIN, 0};
			slot[k++] = 100 + i;
		}
	}
	return k;
}

/* A pty that fails (it should not: the slave is held open) is treated as
 * an unplugged board: motor power off, never a busy loop. */
static void relay_service(struct sim_net *n)
{
	struct sim_relay *r = sim_get_relay(n->sim);
	char err[128];

	if (sim_relay_service(r) >= 0)
		return;
	sim_event(n->sim, "relay pty failed: %s", strerror(errno));
	sim_relay_set_fault(r, SIM_RELAY_UNPLUG, err, sizeof(err));
}

static void dispatch(struct sim_net *n, int slot)
{
	switch (slot) {
	case -1: timer_read(n); break;
	case -2: conn_accept(n); break;
	case -3: client_accept(n); break;
	case -4: relay_service(n); break;
	default:
		if (slot >= 0 && slot < CTRL_HANDLES) {
			if (n->conn[slot].fd >= 0)
				conn_read(n, slot);
		} else if (slot >= 100 &&
			   slot < 100 + SIM_NET_CONTROL_CLIENTS &&
			   n->client[slot - 100].fd >= 0) {
			client_read(n, &n->client[slot - 100]);
		}
	}
}

/* Has everything the controller queued for handle @by been sent? A
 * program, the private port or a gone sender leave nothing to wait for. */
static int reply_gone(struct sim_net *n, int by)
{
	return by < 0 || by >= CTRL_HANDLES || n->conn[by].fd < 0 ||
	       (n->conn[by].out_len == 0 &&
		ctrl_output_pending(sim_ctrl(n->sim), by) == 0);
}

/* IH closing: a handle the controller wants closed is closed once the
 * reply of the IH command has been sent to its sender (IHS: to itself). */
static void close_wanted(struct sim_net *n)
{
	struct ctrl *c = sim_ctrl(n->sim);

	for (int h = 0; h < CTRL_HANDLES; h++) {
		if (n->conn[h].fd >= 0 && ctrl_handle_close_wanted(c, h) &&
		    reply_gone(n, ctrl_handle_close_by(c, h)))
			conn_close(n, h, NULL);
	}
}

static void flush_all(struct sim_net *n)
{
	int64_t now = now_us();

	for (int h = 0; h < CTRL_HANDLES; h++) {
		if (n->conn[h].fd < 0)
			continue;
		conn_fill(n, h, now);
		conn_flush(n, h, now);
	}
	close_wanted(n);
	for (int i = 0; i < SIM_NET_CONTROL_CLIENTS; i++)
		client_flush(n, &n->client[i]);
}

static int loop_once(struct sim_net *n, char *err, size_t errlen)
{
	struct pollfd fds[NET_POLL_MAX];
	int slot[NET_POLL_MAX];
	int nfds = build_poll(n, fds, slot), r;

	r = poll(fds, (nfds_t)nfds, n->debt ? 0 : -1);
	if (r < 0 && errno != EINTR) {
		snprintf(err, errlen, "poll failed: %s", strerror(errno));
		return GL_ERR_SYS;
	}
	for (int i = 0; r > 0 && i < nfds; i++) {
		if (fds[i].revents)
			dispatch(n, slot[i]);
	}
	step_due(n);
	flush_all(n);
	if ((int64_t)(ctrl_sample_ms(sim_ctrl(n->sim)) * 1000) != n->sample_us)
		return timer_arm(n, err, errlen);
	return 0;
}

int sim_net_run(struct sim_net *n, volatile sig_atomic_t *stop, char *err,
		size_t errlen)
{
	int rc;

	if (n->tfd < 0)
		n->tfd =
		    timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
	if (n->tfd < 0) {
		snprintf(err, errlen, "cannot create the sample timer: %s",
			 strerror(errno));
		return GL_ERR_SYS;
	}
	rc = timer_arm(n, err, errlen);
	while (rc == 0 && !(stop && *stop) && !sim_quit_requested(n->sim))
		rc = loop_once(n, err, errlen);
	flush_all(n); /* the "ok" to quit */
	return rc;
}
