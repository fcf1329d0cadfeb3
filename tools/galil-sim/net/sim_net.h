/*
 * sim_net.h - galil-sim in real time: the controller's TCP command port (up
 * to 8 connections, each an Ethernet handle of the controller), the
 * control port (text requests of sim_control()), and the virtual relay's
 * pty, served by one thread that steps the simulator against the wall
 * clock.
 *
 * Timing model: a timerfd on CLOCK_MONOTONIC with absolute expiries fires
 * every servo sample; one poll() waits for it and for every socket. Each
 * wake-up steps as many samples as are due (a late wake-up catches up, at
 * most NET_CATCHUP_SAMPLES per pass so that I/O is still served), then
 * moves bytes. Commands are executed as they arrive, between samples, as
 * the controller's command interpreter does. Both ports bind 127.0.0.1
 * unless told otherwise; the UDP discovery responder (sim_disc.h) is off
 * unless sim_net_open_disc() is called. Nothing here prints.
 *
 * This is the loop and the server's life cycle only: the command port's
 * connections and link faults are sim_cmdport.h, the control port's line
 * framing sim_ctlport.h, the listener sim_sock.h.
 */
#ifndef SIM_NET_H
#define SIM_NET_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#include "sim.h"

struct sim_net;

struct sim_net_stats {
	uint64_t samples;      /* servo samples stepped */
	uint64_t late_wakeups; /* wake-ups that found > 1 sample due */
	uint64_t max_due;      /* most samples due at one wake-up */
	uint64_t refused;      /* command connections refused (all 8 busy,
				* or link dropped) */
};

/*
 * sim_net_open() - bind the command port @port and the control port
 * @control_port on @addr (0 = any free port) and listen; the server
 * becomes @s's disconnect callback (sim_set_disconnect()).
 * @out: [out] the server (owned by the caller: sim_net_free()), NULL on
 *       failure.
 * @s: the simulator served (not owned; it must outlive the server).
 * @addr: dotted IPv4 address to listen on ("0.0.0.0": every interface), or
 *        NULL for 127.0.0.1.
 * @err: [out] e.g. "cannot listen on 127.0.0.1:23023: Address already in
 *       use"; @errlen its size.
 * Return: 0, GL_ERR_SYS, GL_ERR_NOMEM.
 */
int sim_net_open(struct sim_net **out, struct sim *s, const char *addr,
		 int port, int control_port, char *err, size_t errlen);

/*
 * sim_net_free() - close every socket and the timer, and stop being @n's
 * simulator's disconnect callback. NULL is a no-op.
 */
void sim_net_free(struct sim_net *n);

/*
 * sim_net_port() / sim_net_control_port() - the bound port numbers of the
 * command port and of the control port (1..65535).
 */
int sim_net_port(const struct sim_net *n);
int sim_net_control_port(const struct sim_net *n);

/*
 * sim_net_open_disc() - also answer the controller discovery probe on UDP
 * @addr:@port (sim_disc.h) with the model text of @n's simulator (its
 * ^R^V answer, sim_model()). Each datagram becomes an event:
 * "discovery: answered 127.0.0.1:40000", "discovery: ignored 2 bytes from
 * 127.0.0.1:40000 (not ^R^V CR)".
 * @addr: dotted IPv4 address, NULL for 127.0.0.1.
 * @port: 0 = any free port (sim_net_disc_port() tells which).
 * @err: [out] the reason on failure; @errlen its size.
 * Return: 0, GL_ERR_ARG (bad address, or already open), GL_ERR_SYS.
 */
int sim_net_open_disc(struct sim_net *n, const char *addr, int port, char *err,
		      size_t errlen);

/* sim_net_disc_port() - the bound discovery port, 0 when it is off. */
int sim_net_disc_port(const struct sim_net *n);

/*
 * sim_net_open_udp() - also answer commands on UDP @addr:@port, where UDP
 * handles open and the DR record stream goes (sim_cmdport.h).
 * @addr: dotted IPv4 address, NULL for 127.0.0.1.
 * @port: 0 = any free port (sim_net_udp_port() tells which).
 * @err: [out] the reason on failure; @errlen its size.
 * Return: 0, GL_ERR_ARG (bad address, or already open), GL_ERR_SYS.
 */
int sim_net_open_udp(struct sim_net *n, const char *addr, int port, char *err,
		     size_t errlen);

/* sim_net_udp_port() - the bound UDP command port, 0 when it is off. */
int sim_net_udp_port(const struct sim_net *n);

/*
 * sim_net_run() - serve in real time until the "quit" request or until
 * *@stop becomes non-zero (set it from a signal handler; NULL = never).
 * What is queued is flushed once more before it returns (the "ok" of quit).
 * @err: [out] the reason on failure; @errlen its size.
 * Return: 0, or GL_ERR_SYS (poll or the timer failed).
 */
int sim_net_run(struct sim_net *n, volatile sig_atomic_t *stop, char *err,
		size_t errlen);

/* sim_net_stats() - copy the loop figures since sim_net_open() to @out. */
void sim_net_stats(const struct sim_net *n, struct sim_net_stats *out);

#endif /* SIM_NET_H */
