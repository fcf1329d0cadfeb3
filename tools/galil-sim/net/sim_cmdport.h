/*
 * sim_cmdport.h - galil-sim's Galil command port: the TCP connections that
 * are the controller's Ethernet handles A..H (slot index = handle), the
 * bytes between them and the controller (ctrl_input / ctrl_output), and
 * the link faults of sim_link() applied on the way.
 *
 * Link faults: SIM_LINK_DROP closes every connection (through the
 * disconnect callback, at once) and closes new ones as soon as they are
 * accepted; SIM_LINK_STALL reads and discards what the hosts send and sends
 * nothing (a half-open link: both directions lost), and leaves new
 * connections in the listen backlog (the loop does not poll the listener);
 * SIM_LINK_DELAY holds each reply back by the delay before it is written.
 *
 * Line faults (sim_line_fault(), docs/galil-sim.md): a connection that
 * has one waiting (its own from "link first", or the port's "link once")
 * holds the next line it begins until the line ends (CR), then the fault
 * meets it: the line is corrupted (QMARK), dropped with the connection
 * (DROP) or with everything after it (SILENT), or run and its reply
 * reshaped (sim_wire.h). DLREJECT waits for the next DL instead and
 * corrupts its line N. Lines that meet no fault go to the controller as
 * the bytes arrive, as before.
 *
 * UDP (sim_cmdport_udp_open()): the controller answers commands on a UDP
 * port too. A datagram from a peer (address and port) that has no handle
 * opens one, the lowest free (_IHh2 = 1); the commands of each datagram
 * are answered in one datagram (a datagram that does not end its line is
 * given a CR). The DR record stream (ctrl_stream_take()) goes to its UDP
 * handle, one record per datagram. A handle closes only by IH, a link
 * drop or a power cycle. Link faults are per side (sim_link_on()): the
 * TCP connections, or the UDP port (its replies and the records).
 *
 * IH closing: a handle the controller marks (ctrl_handle_close_wanted()) is
 * closed after the reply of the IH command has gone to its sender. Opening
 * and closing a connection are events ("handle A opened from ...",
 * "handle A closed (peer)").
 *
 * It is not the event loop (sim_net.h polls the descriptors and calls in
 * here), not the control port (sim_ctlport.h) and not the command language
 * (the controller parses the bytes). Nothing here prints or allocates.
 */
#ifndef SIM_CMDPORT_H
#define SIM_CMDPORT_H

#include <stddef.h>
#include <stdint.h>

#include "sim.h"

#define SIM_CMDPORT_OUT_CAP 65536 /* bytes queued per connection */
#define SIM_CMDPORT_CHUNKS  512	  /* delayed reply chunks per connection */
#define SIM_CMDPORT_LINE    256	  /* a line held for a line fault, bytes */

/* One reply chunk queued: it ends at @end in out[], may go at @due_us. */
struct sim_cmdport_chunk {
	size_t end;	/* offset in out[] where this chunk ends */
	int64_t due_us; /* monotonic time it may be sent, us */
};

/* One command connection = one controller handle. */
struct sim_cmdport_conn {
	int fd;	 /* TCP socket, -1 = none; slot index = controller handle */
	int udp; /* 1: a UDP peer holds the handle (fd stays -1) */
	uint32_t peer_ip;   /* UDP peer, host order */
	uint16_t peer_port; /* UDP peer port */
	uint8_t out[SIM_CMDPORT_OUT_CAP];
	size_t out_len;
	struct sim_cmdport_chunk chunk[SIM_CMDPORT_CHUNKS];
	int nchunk;
	/* line faults (sim.h): the one waiting for this connection's next
	 * line ("link first"), the line held until its end to meet a fault,
	 * whether the last byte given to the controller ended a line */
	struct sim_line_fault pending;
	int silent;    /* SIM_LINE_SILENT met: input read and dropped */
	int midline;   /* the controller has part of a line */
	int dl_reject; /* SIM_LINE_DLREJECT armed: this line of the next DL */
	int dl_line;   /* in a DL being watched: lines so far, else -1 */
	char line[SIM_CMDPORT_LINE];
	size_t line_len;
};

/* The command port; embed it (it is large) and use the functions below. */
struct sim_cmdport {
	struct sim *sim;  /* served, not owned */
	int lfd;	  /* listener, -1 = none */
	int port;	  /* bound port number */
	int ufd;	  /* UDP command socket, -1 = none */
	int uport;	  /* its bound port, 0 = none */
	uint64_t refused; /* connections refused (all 8 busy, link dropped) */
	uint32_t rng;	  /* SIM_LINE_CHUNKS piece sizes */
	struct sim_cmdport_conn conn[CTRL_HANDLES];
	uint8_t reply[SIM_CMDPORT_OUT_CAP]; /* a reply being reshaped */
	uint8_t shaped[SIM_CMDPORT_OUT_CAP];
};

/*
 * sim_cmdport_init() - an idle port serving @s (not owned): no listener, no
 * connection. Call it before any other sim_cmdport_* call.
 */
void sim_cmdport_init(struct sim_cmdport *cp, struct sim *s);

/*
 * sim_cmdport_listen() - bind @addr:@port (0 = any free port), listen.
 * @addr: dotted IPv4 address, NULL for 127.0.0.1.
 * @err: [out] the reason on failure; @errlen its size.
 * Return: 0 or GL_ERR_SYS.
 */
int sim_cmdport_listen(struct sim_cmdport *cp, const char *addr, int port,
		       char *err, size_t errlen);

/*
 * sim_cmdport_udp_open() - also answer commands on UDP @addr:@port (0 = any
 * free port; cp->uport tells which) and send the DR stream there.
 * @addr: dotted IPv4 address, NULL for 127.0.0.1.
 * @err: [out] the reason on failure; @errlen its size.
 * Return: 0, GL_ERR_ARG (bad address, already open) or GL_ERR_SYS.
 */
int sim_cmdport_udp_open(struct sim_cmdport *cp, const char *addr, int port,
			 char *err, size_t errlen);

/* sim_cmdport_udp_fd() - the UDP socket to poll for input, -1 = none. */
int sim_cmdport_udp_fd(const struct sim_cmdport *cp);

/*
 * sim_cmdport_udp_read() - the datagrams waiting (at most 8): each to its
 * peer's handle (opened if new: event "handle A opened from
 * 127.0.0.1:40000 (UDP)"; refused with an event when all 8 handles are
 * busy or the stream side's link is dropped), its reply queued as one
 * datagram. Under SIM_LINK_STALL on the stream side they are read and lost.
 */
void sim_cmdport_udp_read(struct sim_cmdport *cp);

/*
 * sim_cmdport_shutdown() - close every connection (no event, the
 * controller's handles closed) and the listener. The port may be
 * listened on again.
 */
void sim_cmdport_shutdown(struct sim_cmdport *cp);

/*
 * sim_cmdport_disconnect_all() - the disconnect callback of
 * sim_set_disconnect() (@ud = the struct sim_cmdport): close every
 * connection with the event "handle X closed (link drop)" or
 * "(power cycle)", after sim_link().
 */
void sim_cmdport_disconnect_all(void *ud);

/*
 * sim_cmdport_listen_fd() / sim_cmdport_fd() - the descriptors to poll for
 * input: the listener (-1 while SIM_LINK_STALL: new connections wait in the
 * backlog), and the connection of handle @h (0..CTRL_HANDLES-1; -1 when
 * the handle has none).
 */
int sim_cmdport_listen_fd(const struct sim_cmdport *cp);
int sim_cmdport_fd(const struct sim_cmdport *cp, int h);

/*
 * sim_cmdport_accept() - accept one waiting connection as the lowest free
 * handle, or refuse it (all handles busy, SIM_LINK_DROP) with an event.
 */
void sim_cmdport_accept(struct sim_cmdport *cp);

/*
 * sim_cmdport_read() - read what handle @h's host sent (without blocking)
 * and give it to the controller (dropped under SIM_LINK_STALL); a closed
 * or failed connection is closed with its event. No-op without a
 * connection.
 */
void sim_cmdport_read(struct sim_cmdport *cp, int h);

/*
 * sim_cmdport_flush() - take every handle's controller output and the DR
 * records into its queue (due at @now_us, or @now_us + the delay under
 * SIM_LINK_DELAY; discarded under SIM_LINK_STALL; each side under its own
 * sim_link_on()), send what is due (without blocking; on a UDP handle
 * each queued chunk is one datagram, and one that cannot go is lost),
 * then close the handles IH wants closed whose IH reply has gone.
 * @now_us: CLOCK_MONOTONIC time, microseconds.
 */
void sim_cmdport_flush(struct sim_cmdport *cp, int64_t now_us);

#endif /* SIM_CMDPORT_H */
