/*
 * sim_ctlport.h - galil-sim's control port: up to SIM_CTLPORT_CLIENTS TCP
 * clients sending one text request per line; each line goes to
 * sim_control() and its answer goes back followed by '\n', one request at
 * a time per client (the next line is read after the answer has gone).
 * A line longer than SIM_REQUEST_MAX - 1 bytes is answered
 * "error: request too long (at most N bytes)".
 *
 * It is the line framing, not the requests: those are sim_control()'s
 * (sim.h, docs/galil-sim.md). Not the event loop (sim_net.h) and not the
 * command port (sim_cmdport.h). Nothing here prints.
 */
#ifndef SIM_CTLPORT_H
#define SIM_CTLPORT_H

#include <stddef.h>

#include "sim.h"

#define SIM_CTLPORT_CLIENTS 4	 /* simultaneous control connections */
#define SIM_CTLPORT_IN	    1024 /* request line buffer, bytes */

/* One control connection. */
struct sim_ctlport_client {
	int fd; /* -1 = free */
	char in[SIM_CTLPORT_IN];
	size_t in_len;
	int discarding; /* skipping the rest of an over-long line */
	char *out;	/* SIM_RESPONSE_MAX + 1 bytes while connected */
	size_t out_len, out_sent;
};

/* The control port; embed it and use the functions below. */
struct sim_ctlport {
	struct sim *sim; /* served, not owned */
	int lfd;	 /* listener, -1 = none */
	int port;	 /* bound port number */
	struct sim_ctlport_client client[SIM_CTLPORT_CLIENTS];
};

/*
 * sim_ctlport_init() - an idle port serving @s (not owned): no listener,
 * no client. Call it before any other sim_ctlport_* call.
 */
void sim_ctlport_init(struct sim_ctlport *cp, struct sim *s);

/*
 * sim_ctlport_listen() - bind @addr:@port (0 = any free port), listen.
 * @addr: dotted IPv4 address, NULL for 127.0.0.1.
 * @err: [out] the reason on failure; @errlen its size.
 * Return: 0 or GL_ERR_SYS.
 */
int sim_ctlport_listen(struct sim_ctlport *cp, const char *addr, int port,
		       char *err, size_t errlen);

/* sim_ctlport_shutdown() - close every client (freeing its answer buffer)
 * and the listener. */
void sim_ctlport_shutdown(struct sim_ctlport *cp);

/*
 * sim_ctlport_fd() - the descriptor of client @i (0..SIM_CTLPORT_CLIENTS-1)
 * to poll for input: -1 when the slot is free or its last answer has not
 * gone yet.
 */
int sim_ctlport_fd(const struct sim_ctlport *cp, int i);

/*
 * sim_ctlport_accept() - accept one waiting client; a fifth one is sent
 * "error: too many control clients" and closed, as is one whose answer
 * buffer (SIM_RESPONSE_MAX + 1 bytes, heap, outside the servo loop)
 * cannot be allocated.
 */
void sim_ctlport_accept(struct sim_ctlport *cp);

/*
 * sim_ctlport_read() - read what client @i sent (without blocking) and
 * answer its next complete line; a closed connection frees the slot.
 * No-op for a free slot.
 */
void sim_ctlport_read(struct sim_ctlport *cp, int i);

/*
 * sim_ctlport_flush() - send what is left of every client's answer
 * (without blocking); a client whose answer has gone has its next line
 * answered.
 */
void sim_ctlport_flush(struct sim_ctlport *cp);

#endif /* SIM_CTLPORT_H */
