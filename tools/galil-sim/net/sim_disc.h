/*
 * sim_disc.h - galil-sim's answer to the controller discovery probe that
 * galil-load --find (the discovery module of pc/galil) and Galil's own
 * tools send.
 *
 * What is documented (docs/galil-load.md, "Finding the controller"): the
 * probe goes to UDP port 50000 and the reply comes back from UDP port
 * 50000 (Galil GDK, Firewall Settings); gclib's GAddresses() lists each
 * controller as its address and its revision report ("DMC4040 Rev 1.2f").
 * The bytes are not published. We read them as pc/galil does: the probe
 * is the revision request ^R^V CR, the reply is what ^R^V answers on the
 * command port ("MODEL Rev REV" CR LF ':'), and the address is the reply's
 * source. The reply carries no serial number (MG _BN): the revision report
 * has none, and gclib's listing shows none.
 *
 * sim_disc_is_probe() and sim_disc_reply() are pure; the rest moves
 * datagrams on one non-blocking UDP socket, at most SIM_DISC_BURST per
 * call, without allocating. Nothing here prints.
 */
#ifndef SIM_DISC_H
#define SIM_DISC_H

#include <stddef.h>
#include <stdint.h>

#define SIM_DISC_REPLY_MAX 64 /* bytes of the reply, model text included */
#define SIM_DISC_READ_MAX  64 /* bytes of a datagram looked at */
#define SIM_DISC_BURST	   8  /* datagrams handled per call */

/* What became of one datagram. */
enum sim_disc_outcome {
	SIM_DISC_ANSWERED, /* a probe; the reply went */
	SIM_DISC_IGNORED,  /* not a probe; nothing sent */
	SIM_DISC_UNSENT,   /* a probe, but sendto() failed (errno kept) */
};

struct sim_disc_seen {
	enum sim_disc_outcome outcome;
	char from[24]; /* "127.0.0.1:40000" */
	size_t len;    /* the datagram's whole length, bytes */
	int err;       /* errno of SIM_DISC_UNSENT, else 0 */
};

/* The responder; embed it and use the functions below. */
struct sim_disc {
	int fd;	  /* UDP socket, -1 = off */
	int port; /* bound port number, 0 when off */
	char reply[SIM_DISC_REPLY_MAX];
	size_t reply_len;
};

/*
 * sim_disc_is_probe() - 1 when the datagram @buf of @len bytes (its whole
 * length, even if fewer bytes were read) is the discovery probe: 0x12
 * 0x16 CR, optionally followed by LF (the command port ignores an LF after
 * the CR too); else 0. Pure.
 */
int sim_disc_is_probe(const uint8_t *buf, size_t len);

/*
 * sim_disc_reply() - the reply to a probe for the controller @model (the
 * ^R^V text, e.g. "DMC4030 Rev 1.2h-sim"): "@model" CR LF ':', the bytes
 * the command port answers to ^R^V. Pure.
 * @buf: [out] @cap bytes (not NUL-terminated).
 * Return: the length, or GL_ERR_OVERFLOW (@cap too small).
 */
int sim_disc_reply(const char *model, char *buf, size_t cap);

/* sim_disc_init() - an idle responder (no socket); call it first. */
void sim_disc_init(struct sim_disc *d);

/*
 * sim_disc_open() - bind a non-blocking, close-on-exec UDP socket to
 * @addr:@port and answer as @model from then on.
 * @addr: dotted IPv4 address, NULL for 127.0.0.1. A broadcast probe
 *        (255.255.255.255) only reaches a socket bound to 0.0.0.0.
 * @port: 1..65535, or 0 for any free port (see d->port).
 * @err: [out] e.g. "cannot bind the discovery port 127.0.0.1:50000:
 *       Address already in use"; @errlen its size.
 * Return: 0, GL_ERR_ARG (bad address, or @model too long), GL_ERR_SYS.
 */
int sim_disc_open(struct sim_disc *d, const char *addr, int port,
		  const char *model, char *err, size_t errlen);

/* sim_disc_close() - close the socket (back to idle). Idle: a no-op. */
void sim_disc_close(struct sim_disc *d);

/*
 * sim_disc_service() - read the datagrams waiting (at most SIM_DISC_BURST,
 * so that a flood cannot hold up the servo loop; the rest wait for the
 * next call) and answer each probe to its sender, from the bound port.
 * Never blocks: a reply that cannot go at once is dropped (a lost UDP
 * datagram; the prober's window covers it).
 * @seen: [out] SIM_DISC_BURST entries, one per datagram, in order.
 * Return: the number of datagrams handled (0..SIM_DISC_BURST).
 */
int sim_disc_service(struct sim_disc *d, struct sim_disc_seen *seen);

#endif /* SIM_DISC_H */
