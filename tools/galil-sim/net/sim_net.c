/*
 * sim_net.c - galil-sim's real-time server loop (see sim_net.h): the sample
 * timer, one poll() over every descriptor, stepping the simulator, and
 * handing readiness to the command port (sim_cmdport.h), the control port
 * (sim_ctlport.h) and the relay pty (sim_relay.h).
 *
 * The link faults and IH closing are the command port's; the control
 * requests are sim_control()'s.
 */
#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/timerfd.h>
#include <time.h>
#include <unistd.h>

#include "base_clock.h"
#include "gl_err.h"
#include "sim.h"
#include "sim_cmdport.h"
#include "sim_ctlport.h"
#include "sim_disc.h"
#include "sim_net.h"
#include "sim_relay.h"

#define NET_CATCHUP_SAMPLES 100 /* samples stepped per pass when late */
#define NET_POLL_MAX	    (6 + CTRL_HANDLES + SIM_CTLPORT_CLIENTS)

struct sim_net {
	struct sim *sim;
	int tfd;	   /* sample timer */
	int64_t sample_us; /* timer period in use */
	uint64_t debt;	   /* samples due but not stepped yet */
	struct sim_cmdport cmd;
	struct sim_ctlport ctl;
	struct sim_disc disc; /* off unless sim_net_open_disc() */
	struct sim_net_stats stats;
};

/* ---- life cycle ------------------------------------------------------- */

int sim_net_open(struct sim_net **out, struct sim *s, const char *addr,
		 int port, int control_port, char *err, size_t errlen)
{
	struct sim_net *n = calloc(1, sizeof(*n));

	*out = NULL;
	if (!n) {
		snprintf(err, errlen, "out of memory");
		return GL_ERR_NOMEM;
	}
	n->sim = s;
	n->tfd = -1;
	sim_cmdport_init(&n->cmd, s);
	sim_ctlport_init(&n->ctl, s);
	sim_disc_init(&n->disc);
	if (sim_cmdport_listen(&n->cmd, addr, port, err, errlen) < 0 ||
	    sim_ctlport_listen(&n->ctl, addr, control_port, err, errlen) < 0) {
		sim_net_free(n);
		return GL_ERR_SYS;
	}
	sim_set_disconnect(s, sim_cmdport_disconnect_all, &n->cmd);
	*out = n;
	return 0;
}

void sim_net_free(struct sim_net *n)
{
	if (!n)
		return;
	sim_set_disconnect(n->sim, NULL, NULL);
	sim_cmdport_shutdown(&n->cmd);
	sim_ctlport_shutdown(&n->ctl);
	sim_disc_close(&n->disc);
	if (n->tfd >= 0)
		close(n->tfd);
	free(n);
}

int sim_net_port(const struct sim_net *n)
{
	return n->cmd.port;
}

int sim_net_control_port(const struct sim_net *n)
{
	return n->ctl.port;
}

int sim_net_open_disc(struct sim_net *n, const char *addr, int port, char *err,
		      size_t errlen)
{
	if (n->disc.fd >= 0) {
		snprintf(err, errlen, "the discovery port is open already");
		return GL_ERR_ARG;
	}
	return sim_disc_open(&n->disc, addr, port, sim_model(n->sim), err,
			     errlen);
}

int sim_net_disc_port(const struct sim_net *n)
{
	return n->disc.port;
}

int sim_net_open_udp(struct sim_net *n, const char *addr, int port, char *err,
		     size_t errlen)
{
	return sim_cmdport_udp_open(&n->cmd, addr, port, err, errlen);
}

int sim_net_udp_port(const struct sim_net *n)
{
	return n->cmd.uport;
}

void sim_net_stats(const struct sim_net *n, struct sim_net_stats *out)
{
	*out = n->stats;
	out->refused = n->cmd.refused;
}

/* ---- the loop --------------------------------------------------------- */

/* (Re)start the sample timer at the controller's current period. */
static int timer_arm(struct sim_net *n, char *err, size_t errlen)
{
	int64_t period = (int64_t)(ctrl_sample_ms(sim_ctrl(n->sim)) * 1000);
	struct itimerspec it;
	int64_t first_ns;

	if (period < 100)
		period = 100; /* a sane floor: 0.1 ms */
	first_ns = base_now_ns() + period * BASE_NS_PER_US;
	it.it_interval.tv_sec = period / 1000000;
	it.it_interval.tv_nsec = (long)(period % 1000000) * 1000;
	it.it_value.tv_sec = (time_t)(first_ns / BASE_NS_PER_S);
	it.it_value.tv_nsec = (long)(first_ns % BASE_NS_PER_S);
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
 * -3 control listener, -4 relay, -5 discovery, -6 UDP command port, 0..7
 * command conn, 100+i control client. */
static int build_poll(struct sim_net *n, struct pollfd *fds, int *slot)
{
	int k = 0, fd, rfd = sim_relay_fd(sim_get_relay(n->sim));

	fds[k] = (struct pollfd){n->tfd, POLLIN, 0};
	slot[k++] = -1;
	/* connections before the listener: a close seen in the same pass
	 * frees its handle for a new connection */
	for (int h = 0; h < CTRL_HANDLES; h++) {
		if ((fd = sim_cmdport_fd(&n->cmd, h)) >= 0) {
			fds[k] = (struct pollfd){fd, POLLIN, 0};
			slot[k++] = h;
		}
	}
	if ((fd = sim_cmdport_listen_fd(&n->cmd)) >= 0) {
		fds[k] = (struct pollfd){fd, POLLIN, 0};
		slot[k++] = -2;
	}
	fds[k] = (struct pollfd){n->ctl.lfd, POLLIN, 0};
	slot[k++] = -3;
	if (rfd >= 0) {
		fds[k] = (struct pollfd){rfd, POLLIN, 0};
		slot[k++] = -4;
	}
	if (n->disc.fd >= 0) {
		fds[k] = (struct pollfd){n->disc.fd, POLLIN, 0};
		slot[k++] = -5;
	}
	if ((fd = sim_cmdport_udp_fd(&n->cmd)) >= 0) {
		fds[k] = (struct pollfd){fd, POLLIN, 0};
		slot[k++] = -6;
	}
	for (int i = 0; i < SIM_CTLPORT_CLIENTS; i++) {
		if ((fd = sim_ctlport_fd(&n->ctl, i)) >= 0) {
			fds[k] = (struct pollfd){fd, POLLIN, 0};
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

/* Answer the discovery probes waiting; each datagram is an event, so that
 * a test (and --verbose) sees an ignored one as well as an answered one. */
static void disc_service(struct sim_net *n)
{
	struct sim_disc_seen seen[SIM_DISC_BURST];
	int k = sim_disc_service(&n->disc, seen);

	for (int i = 0; i < k; i++) {
		const struct sim_disc_seen *d = &seen[i];

		if (d->outcome == SIM_DISC_ANSWERED)
			sim_event(n->sim, "discovery: answered %s", d->from);
		else if (d->outcome == SIM_DISC_UNSENT)
			sim_event(n->sim,
				  "discovery: reply to %s not sent (%s)",
				  d->from, strerror(d->err));
		else
			sim_event(n->sim,
				  "discovery: ignored %zu bytes from %s (not "
				  "^R^V CR)",
				  d->len, d->from);
	}
}

static void dispatch(struct sim_net *n, int slot)
{
	switch (slot) {
	case -1: timer_read(n); break;
	case -2: sim_cmdport_accept(&n->cmd); break;
	case -3: sim_ctlport_accept(&n->ctl); break;
	case -4: relay_service(n); break;
	case -5: disc_service(n); break;
	case -6: sim_cmdport_udp_read(&n->cmd); break;
	default:
		if (slot >= 0 && slot < CTRL_HANDLES)
			sim_cmdport_read(&n->cmd, slot);
		else if (slot >= 100)
			sim_ctlport_read(&n->ctl, slot - 100);
	}
}

static void flush_all(struct sim_net *n)
{
	sim_cmdport_flush(&n->cmd, base_now_us());
	sim_ctlport_flush(&n->ctl);
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
