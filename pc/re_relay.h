/*
 * re_relay.h - the E-stop relay that switches motor power.
 *
 * The relay is a USB serial board (or galil-sim's virtual relay on a
 * pseudo-terminal). "On" closes the relay (motor power present); "off" opens
 * it (power cut, the safe state). Motor power is switched on only by an
 * explicit operator start-up (re_relay_on()); nothing in this module ever
 * switches it on by itself: re_relay_check() never writes a state byte, a
 * failed write is never retried as "on", and re_relay_close() leaves it off.
 *
 * Two back-ends behind one interface (docs/config.md, "relay"):
 *   serialport - libserialport, for real relays (the only one allowed in
 *                clinical mode);
 *   tty        - plain POSIX termios, for the simulator's pseudo-terminal
 *                (libserialport cannot open a pty: relays-and-serial.md).
 *
 * Errors: functions return GL_OK or a negative gl_err code (pc/gl_err.h);
 * the handle keeps a message such as
 *   "relay '/tmp/roboelf-relay': write failed: Input/output error"
 * readable with re_relay_errmsg(). Nothing here prints. Only re_relay_open()
 * allocates; on/off/check run in the supervisor's cycle without allocating.
 */
#ifndef RE_RELAY_H
#define RE_RELAY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define RE_RELAY_PATH_MAX 256 /* bytes, including the NUL */
#define RE_RELAY_CODE_MAX 16  /* bytes of one explicit on/off message */
#define RE_RELAY_ERR_MAX  512 /* bytes of the handle's error message */

/* Byte protocol of the relay board (relays-and-serial.md). */
enum re_relay_proto {
	RE_RELAY_DEVANTECH = 0, /* 1 byte: 0x64 + ch on, 0x6E + ch off */
	RE_RELAY_ICSTATION,	/* 1 byte state mask, active low; handshake
				 * 0x50/0x51 once per board power-up */
	RE_RELAY_LCUS,		/* A0 ch state sum */
	RE_RELAY_KMTRONIC,	/* FF ch state */
	RE_RELAY_EXPLICIT,	/* the on/off bytes given in the config */
};

enum re_relay_backend {
	RE_RELAY_BACKEND_AUTO = 0, /* tty for a pty (or a link to one),
				    * serialport otherwise */
	RE_RELAY_BACKEND_SERIALPORT,
	RE_RELAY_BACKEND_TTY,
};

/* What was last confirmed written to the relay. */
enum re_relay_state {
	RE_RELAY_UNKNOWN = 0, /* nothing confirmed yet, or a write failed */
	RE_RELAY_OFF,
	RE_RELAY_ON,
};

/* Everything re_relay_open() needs; built by re_config_relay_cfg(). */
struct re_relay_cfg {
	char port[RE_RELAY_PATH_MAX]; /* device path, e.g. /dev/ttyUSB0 */
	enum re_relay_proto proto;
	int channel; /* relay number on the board, 1..8 */
	enum re_relay_backend backend;
	int baud;		 /* bits/s, 8N1, no flow control */
	bool clinical;		 /* clinical mode: tty back-end refused */
	int write_timeout_ms;	 /* deadline for one message, ms */
	bool readback;		 /* Devantech: query the state (0x5B)
				  * from re_relay_check() */
	int readback_timeout_ms; /* answer deadline of that query, ms */
	/* RE_RELAY_EXPLICIT only: the complete messages. */
	uint8_t on[RE_RELAY_CODE_MAX];
	size_t on_len;
	uint8_t off[RE_RELAY_CODE_MAX];
	size_t off_len;
	/* ICStation: where the handshake of the current board power-up is
	 * recorded, so that it is never repeated (see re_relay.c). */
	char icstation_state[RE_RELAY_PATH_MAX];
};

typedef struct re_relay re_relay;

/*
 * re_relay_open() - open the relay port and send "off".
 * @out: [out] the new handle; must not be NULL; NULL on failure.
 * @cfg: [in] the relay settings; copied.
 * @err: [out] optional buffer for the reason of a failure, e.g.
 *       "relay '/dev/ttyUSB0': cannot open: No such file or directory".
 * @errlen: size of @err.
 * The relay is switched off at once (a relay left on by a crashed process is
 * not trusted). The ICStation handshake is done here when, and only when, the
 * board has not been through it since it was powered up. Allocates.
 * Return: GL_OK; GL_ERR_ARG (bad @cfg, or tty back-end in clinical mode);
 *         GL_ERR_RELAY (open, configure, handshake or the first "off"
 *         failed; the port is closed again); GL_ERR_NOMEM.
 */
int re_relay_open(re_relay **out, const struct re_relay_cfg *cfg, char *err,
		  size_t errlen);

/*
 * re_relay_on() - switch motor power on (close the relay).
 * Only for the operator's explicit start-up; never call it from a fault or
 * recovery path. Written and drained before returning.
 * Return: GL_OK; GL_ERR_RELAY (write failed or short; state UNKNOWN).
 */
int re_relay_on(re_relay *r);

/*
 * re_relay_off() - cut motor power (open the relay).
 * Always tries to write, even when an earlier call or check failed; on a
 * failed write it reopens the port once and tries again, unless the path
 * now names a different pseudo-terminal (pty numbers are reused).
 * Return: GL_OK when the message was written and drained; GL_ERR_RELAY when
 *         that could not be confirmed (the caller must then stop the motors
 *         by other means, e.g. through the controller).
 */
int re_relay_off(re_relay *r);

/*
 * re_relay_check() - is the relay link still sound? For every cycle.
 * Writes no state byte and never re-energises anything; does not block
 * (poll with timeout 0, stat, fstat, and for a Devantech read-back one query
 * byte written and its answer read without waiting). Checks: the descriptor
 * is valid, no hang-up or error is pending, the device node still exists and
 * is the same node (st_rdev, inode, change time) as the one opened, and
 * (read-back) the board reports the channel in the state last written.
 * Return: GL_OK; GL_ERR_RELAY with the reason in re_relay_errmsg().
 */
int re_relay_check(re_relay *r);

/*
 * re_relay_close() - switch the relay off, close the port and free.
 * NULL is a no-op (returns GL_OK).
 * Return: GL_OK when "off" was confirmed before closing, else GL_ERR_RELAY
 *         (the handle is freed either way).
 */
int re_relay_close(re_relay *r);

/* re_relay_state() - what was last confirmed written (UNKNOWN after a
 * failure). */
enum re_relay_state re_relay_state(const re_relay *r);

/* re_relay_errmsg() - the last error message ("" if none); never NULL. */
const char *re_relay_errmsg(const re_relay *r);

/* re_relay_backend_name() - "serialport" or "tty": the back-end in use. */
const char *re_relay_backend_name(const re_relay *r);

/*
 * re_relay_message() - the bytes that switch @cfg's channel on or off.
 * @buf: [out] at least RE_RELAY_CODE_MAX bytes.
 * Return: the message length (> 0), or GL_ERR_ARG for an invalid channel
 *         or an empty explicit message.
 */
int re_relay_message(const struct re_relay_cfg *cfg, bool on, uint8_t *buf);

/* re_relay_proto_name() - "devantech", ..., "explicit"; never NULL. */
const char *re_relay_proto_name(enum re_relay_proto proto);

#endif /* RE_RELAY_H */
