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
 * Every operation is bounded: nothing waits without a deadline (no drain,
 * no blocking read or write). Switching is split in two so that a caller
 * can do other work (stop the controller) while the bytes travel:
 *   re_relay_off_start()  - hands the "off" bytes to the driver, never
 *                           waits; what the driver does not accept at
 *                           once is retried by ...
 *   re_relay_off_finish() - ... which waits, with sleeps of at most 1 ms,
 *                           until every byte was accepted, the driver's
 *                           output queue is empty and (Devantech with
 *                           read-back) the board reports the relay off,
 *                           or until its deadline: GL_ERR_TIMEOUT.
 * re_relay_off() is both with relay.off_deadline_ms; the same pairs exist
 * for "on" (deadline relay.write_timeout_ms) and for closing.
 *
 * Errors: functions return GL_OK or a negative gl_err code (pc/galil/gl_err.h);
 * the handle keeps a message such as
 *   "relay '/tmp/roboelf-relay': write failed: Input/output error"
 *   "relay '/dev/ttyUSB0': off not confirmed: 1 byte still queued after
 *    50 ms"
 * readable with re_relay_errmsg(). Nothing here prints. re_relay_open()
 * allocates, and so does the reopen after a failed "off" (libserialport);
 * on/off/check in the supervisor's cycle do not allocate.
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
	RE_RELAY_UNKNOWN = 0, /* nothing confirmed yet: switching started
			       * and not (yet) confirmed, a write failed, or
			       * its deadline passed */
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
	int write_timeout_ms;	 /* deadline of "on" and of the ICStation
				  * handshake bytes, ms */
	int off_deadline_ms;	 /* deadline of every "off" (open, off,
				  * close), ms */
	bool readback;		 /* Devantech: query the state (0x5B)
				  * from re_relay_check() */
	int readback_timeout_ms; /* answer deadline of that query, ms */
	int query_ms;		 /* re_relay_check() queries at most this
				  * often (roboelf: 1.5 periods, every second
				  * cycle; 0: in every check), and at least
				  * twice within readback_timeout_ms, ms */
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
 * The first "off" is confirmed as re_relay_off_finish() does, within
 * off_deadline_ms (without the reopen).
 * Return: GL_OK; GL_ERR_ARG (bad @cfg, or tty back-end in clinical mode);
 *         GL_ERR_RELAY (open, configure, handshake or the first "off"
 *         failed or was not confirmed; the port is closed again);
 *         GL_ERR_NOMEM.
 */
int re_relay_open(re_relay **out, const struct re_relay_cfg *cfg, char *err,
		  size_t errlen);

/*
 * re_relay_on_start() - start switching motor power on (close the relay).
 * Only for the operator's explicit start-up; never call it from a fault or
 * recovery path. Refused when re_relay_check() fails or an earlier message
 * is still half written. Never waits. The state is UNKNOWN until
 * re_relay_on_finish() confirms.
 * Return: GL_OK (call re_relay_on_finish()); GL_ERR_ARG (@r NULL);
 *         GL_ERR_RELAY (refused, or the write failed; nothing is retried).
 */
int re_relay_on_start(re_relay *r);

/*
 * re_relay_on_finish() - confirm the "on" started by re_relay_on_start().
 * @deadline_ms: how long to wait from this call, ms (>= 0; 0: look once).
 * Waits (sleeps of at most 1 ms) until the message was accepted, the
 * output queue is empty and, with read-back, the board reports the channel
 * on. On any failure the output queue is discarded, so that an "on" that
 * was not confirmed never reaches the board later.
 * Return: GL_OK (state ON); GL_ERR_TIMEOUT (not confirmed within
 *         @deadline_ms, never earlier: "on not confirmed: ..."); GL_ERR_RELAY
 *         (I/O error, or read-back shows the channel off); GL_ERR_ARG (no
 *         "on" started, or @deadline_ms < 0). State UNKNOWN on failure.
 */
int re_relay_on_finish(re_relay *r, int deadline_ms);

/*
 * re_relay_on() - re_relay_on_start() and re_relay_on_finish() with the
 * configured write_timeout_ms. Return: as those.
 */
int re_relay_on(re_relay *r);

/*
 * re_relay_off_start() - start cutting motor power (open the relay).
 * Never waits: hands the "off" bytes to the driver; bytes it does not
 * accept at once, and a write that failed, are retried by
 * re_relay_off_finish(), which must follow. An "on" not yet confirmed is
 * discarded first. The state is UNKNOWN until confirmed.
 * Return: GL_OK; GL_ERR_RELAY (the write failed: re_relay_off_finish()
 *         reopens the port once and writes again); GL_ERR_ARG (@r NULL).
 */
int re_relay_off_start(re_relay *r);

/*
 * re_relay_off_finish() - confirm the "off" started by re_relay_off_start().
 * @deadline_ms: how long to wait from this call, ms (>= 0; 0: look once).
 * After a failed write it first reopens the port once and writes again,
 * unless the path now names a different pseudo-terminal (pty numbers are
 * reused). Then it waits (sleeps of at most 1 ms) until every byte was
 * accepted, the output queue is empty and, with read-back, the board
 * reports the channel off. Bytes still queued at the deadline stay queued:
 * they are the safe message.
 * Return: GL_OK (state OFF); GL_ERR_TIMEOUT (not confirmed within
 *         @deadline_ms, never earlier, e.g. "off not confirmed: 1 byte
 *         still queued after 50 ms"); GL_ERR_RELAY (write or reopen failed,
 *         or read-back shows the channel on); GL_ERR_ARG (no "off" started,
 *         or @deadline_ms < 0). On failure the state is UNKNOWN and the
 *         caller must stop the motors by other means (the controller).
 *         The reopen's system calls (open, tcsetattr) are not bounded by
 *         @deadline_ms; it only follows a failed write (adapter gone).
 */
int re_relay_off_finish(re_relay *r, int deadline_ms);

/*
 * re_relay_off() - re_relay_off_start() and re_relay_off_finish() with the
 * configured off_deadline_ms. Always tries to write, even when an earlier
 * call or check failed.
 * Return: as re_relay_off_finish().
 */
int re_relay_off(re_relay *r);

/*
 * re_relay_check() - is the relay link still sound? For every cycle.
 * Writes no state byte and never re-energises anything; does not block
 * (one poll with timeout 0 of the descriptor and the path's inotify watch,
 * a non-blocking read of inotify events when it has some, and for a
 * Devantech read-back one query byte written every query_ms and
 * its answer read without waiting). Checks: the descriptor is valid, no
 * hang-up or error is pending, the device node still exists and is the
 * same node (st_rdev, inode, change time) as the one opened, and
 * (read-back) the board reports the channel in the state last confirmed.
 * The node is stat()ed after an inotify event on the path, its links or
 * the node (re_pathwatch.h), and at least once a second (an ancestor
 * directory renamed is not watched); after a failed stat() check, in
 * every call until it passes again.
 * Return: GL_OK; GL_ERR_RELAY with the reason in re_relay_errmsg().
 */
int re_relay_check(re_relay *r);

/*
 * re_relay_fds() - the descriptors re_relay_check() looks at, for a
 * caller that polls them itself (re_relay_check_seen()).
 * @fd: [out] the port (poll it for errors and hang-up only: events 0);
 * @watch_fd: [out] the path's inotify watch (POLLIN), -1 when none.
 * Both are -1 when the port is not open. No return value.
 */
void re_relay_fds(const re_relay *r, int *fd, int *watch_fd);

/*
 * re_relay_check_seen() - re_relay_check() with the poll() already done
 * by the caller (one look per cycle over every descriptor).
 * @fd_revents, @watch_revents: what that poll, of re_relay_fds()' @fd
 *       (events 0) and @watch_fd (POLLIN), returned for them just before.
 * Return: as re_relay_check().
 */
int re_relay_check_seen(re_relay *r, short fd_revents, short watch_revents);

/*
 * re_relay_close_start() - re_relay_off_start(), for re_relay_close_finish().
 * NULL is a no-op. Return: as re_relay_off_start(); GL_OK for NULL.
 */
int re_relay_close_start(re_relay *r);

/*
 * re_relay_close_finish() - confirm "off" (starting it if
 * re_relay_close_start() was not called), close the port and free.
 * @deadline_ms: for the "off", as re_relay_off_finish() (< 0 is taken as
 *               0: the handle is freed anyway).
 * An output queue still holding bytes at the deadline is discarded before
 * the port is closed: close() of a real serial port would otherwise wait
 * for it up to the driver's closing_wait (30 s by default). NULL is a no-op.
 * Return: GL_OK when "off" was confirmed, else its error (the handle is
 *         freed either way).
 */
int re_relay_close_finish(re_relay *r, int deadline_ms);

/*
 * re_relay_close() - re_relay_close_start() and re_relay_close_finish() with
 * the configured off_deadline_ms. NULL is a no-op (returns GL_OK).
 * Return: GL_OK when "off" was confirmed before closing, else its error
 *         (the handle is freed either way).
 */
int re_relay_close(re_relay *r);

/* re_relay_state() - what was last confirmed (UNKNOWN while switching,
 * and after a failure or an unconfirmed switch). */
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

/*
 * re_relay_usb_serial() - the USB serial number of the serial port @path
 * (a link such as /dev/roboelf-relay is followed to its node), as
 * libserialport reads it from sysfs; the port is not opened and nothing is
 * written to it, so that a board that is not the relay never receives a
 * byte (clinical start-up, re_bind_verify()).
 * @buf: [out] the serial number, NUL-terminated; "" when the port is not a
 *       USB device or has no serial number. @cap: its size.
 * @err: [out] optional, e.g. "relay '/dev/roboelf-relay': cannot read its
 *       USB serial number: not a serial port known to libserialport".
 * Allocates (libserialport), for start-up only.
 * Return: GL_OK; GL_ERR_RELAY (not a port libserialport knows, or a serial
 *         number that does not fit @cap); GL_ERR_ARG (NULL, @cap 0).
 */
int re_relay_usb_serial(const char *path, char *buf, size_t cap, char *err,
			size_t errlen);

#endif /* RE_RELAY_H */
