/*
 * re_relay_be.h - the relay back-ends (private to re_relay*.c).
 *
 * A back-end only moves bytes over one serial port, and never waits: open,
 * write what the driver accepts now, tell how many bytes are still queued
 * for the wire, read what has arrived, discard the output queue, give a
 * descriptor for the link checks, close. Deadlines, protocols, state and the
 * checks live in re_relay.c and its parts (re_relay_int.h). Messages are
 * complete and name the port:
 *   "relay '/dev/ttyUSB0': cannot open: Permission denied".
 *
 * Why nothing here may block (docs/config.md, "E-stop relay behaviour"):
 * the relay is switched off on the supervisor's fault path. tcdrain() and
 * sp_drain() wait without a deadline for a queue that a wedged USB adapter
 * or a pty nobody reads never empties, and close() of a real serial port
 * waits up to the driver's closing_wait (30 s by default) for queued bytes.
 */
#ifndef RE_RELAY_BE_H
#define RE_RELAY_BE_H

#include <stddef.h>
#include <stdint.h>

struct sp_port;

struct re_relay_io {
	const char *path;     /* the port, owned by the relay handle */
	int fd;		      /* tty: the descriptor; -1 when closed */
	struct sp_port *port; /* serialport: the port; NULL when closed */
};

struct re_relay_be_ops {
	const char *name;
	/* Open @io->path at @baud 8N1, raw, no flow control, non-blocking.
	 * GL_OK or GL_ERR_SYS / GL_ERR_NOMEM with a message. */
	int (*open)(struct re_relay_io *io, int baud, char *err, size_t errlen);
	/* Hand the driver what it accepts now: the count accepted (>= 0; 0
	 * when its buffer is full) or GL_ERR_SYS (errno kept) with a
	 * message. */
	int (*write)(struct re_relay_io *io, const uint8_t *buf, size_t len,
		     char *err, size_t errlen);
	/* Bytes still in the driver's output queue (>= 0), or GL_ERR_SYS
	 * with a message. */
	int (*queued)(struct re_relay_io *io, char *err, size_t errlen);
	/* Read what has arrived: the count (>= 0; 0 when nothing) or
	 * GL_ERR_SYS with a message. */
	int (*read)(struct re_relay_io *io, uint8_t *buf, size_t len, char *err,
		    size_t errlen);
	/* Discard the output queue: bytes not yet sent are never sent. */
	void (*discard)(struct re_relay_io *io);
	/* The descriptor for poll/fstat, or -1. */
	int (*fd)(const struct re_relay_io *io);
	/* Close (no-op when closed). re_relay_port.c discards a non-empty
	 * output queue first, so that close() has nothing to wait for. */
	void (*close)(struct re_relay_io *io);
};

extern const struct re_relay_be_ops re_relay_be_tty;
extern const struct re_relay_be_ops re_relay_be_serialport;

#endif /* RE_RELAY_BE_H */
