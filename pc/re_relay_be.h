/*
 * re_relay_be.h - the relay back-ends (private to re_relay*.c).
 *
 * A back-end only moves bytes over one serial port: open, send, receive,
 * give a descriptor for the link checks, close. Protocols, state and the
 * checks live in re_relay.c. Messages are complete and name the port:
 *   "relay '/dev/ttyUSB0': cannot open: Permission denied".
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
	/* Open @io->path at @baud 8N1, raw, no flow control. */
	int (*open)(struct re_relay_io *io, int baud, char *err, size_t errlen);
	/*
	 * Send all @len bytes: @timeout_ms > 0 waits up to that long for
	 * them to be accepted, then drains them to the wire; 0 tries once
	 * without waiting or draining. GL_OK, GL_ERR_SYS (errno kept) or
	 * GL_ERR_TIMEOUT (short write), with a message.
	 */
	int (*send)(struct re_relay_io *io, const uint8_t *buf, size_t len,
		    int timeout_ms, char *err, size_t errlen);
	/* Receive up to @len bytes within @timeout_ms (0: what is there).
	 * Return the count (>= 0) or GL_ERR_SYS with a message. */
	int (*recv)(struct re_relay_io *io, uint8_t *buf, size_t len,
		    int timeout_ms, char *err, size_t errlen);
	/* The descriptor for poll/fstat, or -1. */
	int (*fd)(const struct re_relay_io *io);
	/* Close (no-op when closed). */
	void (*close)(struct re_relay_io *io);
};

extern const struct re_relay_be_ops re_relay_be_tty;
extern const struct re_relay_be_ops re_relay_be_serialport;

#endif /* RE_RELAY_BE_H */
