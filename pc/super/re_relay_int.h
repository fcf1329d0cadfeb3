/*
 * re_relay_int.h - what the parts of the E-stop relay share: the handle and
 * the functions one part gives the others.
 *   re_relay.c          the back-end chosen, opening, switching on and
 *                       off, closing: the state machine and its
 *                       confirmations; the safety decisions of the whole
 *                       relay (its header)
 *   re_relay_proto.c    the byte protocols (the messages per preset)
 *   re_relay_port.c     the back-end opened and closed, a message handed to
 *                       the driver and waited for, stale input dropped
 *   re_relay_readback.c a switch confirmed; the Devantech read-back
 *   re_relay_link.c     the link check: descriptor, hang-up, device node
 *   re_relay_ics.c      the ICStation handshake, once per power-up
 *   re_relay_sp.c, re_relay_tty.c  the back-ends (re_relay_be.h)
 * Who uses whom: re_relay.c uses every part; link uses readback and port;
 * readback and ics use port; port uses the back-ends and re_pathwatch. No
 * loop (tests/checks/layers.sh). Not for the rest of the supervisor:
 * re_relay.h is the interface. Nothing here prints.
 */
#ifndef RE_RELAY_INT_H
#define RE_RELAY_INT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>

#include "re_pathwatch.h"
#include "re_relay.h"
#include "re_relay_be.h"

#define ICS_ALL_OFF   0xFF /* ICStation, active low: every relay off */
#define PTY_MAJOR_MIN 136  /* Unix98 pty slaves: majors 136..143 */
#define PTY_MAJOR_MAX 143

enum re_relay_op { OP_NONE = 0, OP_ON, OP_OFF };

struct re_relay {
	struct re_relay_cfg cfg;
	const struct re_relay_be_ops *ops;
	struct re_relay_io io;
	bool linked;		/* io is open */
	dev_t rdev;		/* device opened ... */
	ino_t ino;		/* ... its node (a pty number reused later */
	struct timespec ctim;	/* has the same rdev and inode) */
	struct re_pathwatch pw; /* events that may change what port names */
	int64_t next_full_ns;	/* next stat() of the port, CLOCK_MONOTONIC */
	bool node_suspect;	/* the last stat() check failed */
	enum re_relay_state state;
	uint8_t msg_on[RE_RELAY_CODE_MAX];
	uint8_t msg_off[RE_RELAY_CODE_MAX];
	size_t on_len, off_len;
	const uint8_t *out;	  /* the message being written ... */
	size_t out_len, out_done; /* ... its length, bytes accepted */
	enum re_relay_op op;	  /* switching started, not finished */
	bool on_unconfirmed;	  /* "on" handed over, not confirmed */
	bool reopen;		  /* "off" could not be written */
	int rb_due;		  /* state queries sent, not answered */
	bool rb_discard;	  /* the answers due predate a write */
	bool rb_flush;		  /* answers may be in flight that nobody
				   * awaits: drop input before a query */
	int64_t rb_sent_ns; /* the oldest query due was sent (base_now_ns) */
	int64_t rb_next_ns; /* re_relay_check()'s next query (base_now_ns) */
	char err[RE_RELAY_ERR_MAX];
};

/* ---- re_relay_port.c: the port and its output ---- */

/*
 * re_relay_set_err() - r->err = "relay '<port>': " and the message of @fmt.
 * Return: @rc.
 */
int re_relay_set_err(struct re_relay *r, int rc, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/*
 * re_relay_same_node() - is @st the node opened (a character device with
 * the same device, inode and change time)?
 */
bool re_relay_same_node(const struct re_relay *r, const struct stat *st);

/* re_relay_deadline_in() - base_now_ns() @ms from now, ns. */
int64_t re_relay_deadline_in(int ms);

/* re_relay_nap() - sleep 1 ms at most, and never past @deadline (ns). */
void re_relay_nap(int64_t deadline);

/*
 * re_relay_out_set() - the message being written is now @msg (@len bytes;
 * NULL, 0: none), none of it accepted yet. No return value.
 */
void re_relay_out_set(struct re_relay *r, const uint8_t *msg, size_t len);

/*
 * re_relay_link_open() - open the back-end and remember which device was
 * opened (rdev; inode and change time of the path's node); start the
 * path's watch; no read-back answer due, input to be dropped before the
 * next query, no message being written.
 * Return: GL_OK; GL_ERR_RELAY with the reason in r->err.
 */
int re_relay_link_open(struct re_relay *r);

/*
 * re_relay_link_close() - close without waiting: a non-empty output queue
 * is discarded first (close() would wait for it up to the driver's
 * closing_wait); the watch is closed. No return value.
 */
void re_relay_link_close(struct re_relay *r);

/*
 * re_relay_out_push() - hand the driver what it takes of the message now.
 * Return: GL_OK (perhaps only part of it accepted) or GL_ERR_SYS with the
 *         reason in r->err.
 */
int re_relay_out_push(struct re_relay *r);

/*
 * re_relay_out_wait() - wait until the message (@what, for the reason) is
 * accepted and the output queue is empty, until @deadline (ns; @ms from
 * the caller's start, for the reason).
 * Return: GL_OK; GL_ERR_SYS (I/O error); GL_ERR_TIMEOUT, never before
 *         @deadline; the reason in r->err.
 */
int re_relay_out_wait(struct re_relay *r, const char *what, int64_t deadline,
		      int ms);

/*
 * re_relay_drop_input() - drop what the board sent before now (at most
 * 64 bytes). Return: GL_OK or GL_ERR_SYS with the reason in r->err.
 */
int re_relay_drop_input(struct re_relay *r);

/* ---- re_relay_readback.c: confirmation and read-back ---- */

/*
 * re_relay_confirm() - after writing @what (the channel switched @on):
 * wait until it was sent, then, with read-back, until the board reports
 * it, until @deadline (ns; @ms for the reason).
 * Return: GL_OK; GL_ERR_SYS (I/O error); GL_ERR_TIMEOUT (never before
 *         @deadline); GL_ERR_RELAY (read-back shows the other state); the
 *         reason in r->err.
 */
int re_relay_confirm(struct re_relay *r, const char *what, bool on,
		     int64_t deadline, int ms);

/*
 * re_relay_readback_step() - the Devantech read-back of re_relay_check():
 * one step, never waiting (a query sent when due, or the answers that
 * have arrived judged). Nothing without read-back or while a message is
 * half written. Return: GL_OK or GL_ERR_RELAY with the reason in r->err.
 */
int re_relay_readback_step(struct re_relay *r);

/* ---- re_relay_link.c: the link check ---- */

/*
 * re_relay_link_check() - the descriptor and the path's watch in one
 * poll() with timeout 0, then hang-up, error and the device node; no byte
 * written. Return: GL_OK or GL_ERR_RELAY with the reason in r->err.
 */
int re_relay_link_check(struct re_relay *r);

/* ---- re_relay_ics.c: the ICStation handshake ---- */

/*
 * re_relay_ics_handshake() - the ICStation handshake, unless the board's
 * current power-up is recorded as done; recorded after it succeeds. A board
 * that does not answer is sent "all off" at once.
 * Return: GL_OK or GL_ERR_RELAY with the reason in r->err.
 */
int re_relay_ics_handshake(struct re_relay *r);

#endif /* RE_RELAY_INT_H */
