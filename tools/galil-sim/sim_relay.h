/*
 * sim_relay.h - galil-sim's virtual E-stop relay: a USB relay board on a
 * pseudo-terminal that speaks one of the relay byte protocols of
 * relays-and-serial.md and switches the robot's motor power (relay 1).
 *
 * The relay starts OFF (motor power cut). The byte decoder is pure
 * (sim_relay_dec_*); struct sim_relay adds the pty, the optional symbolic
 * link, fault injection and state-change events. Nothing here prints.
 */
#ifndef SIM_RELAY_H
#define SIM_RELAY_H

#include <stddef.h>
#include <stdint.h>

enum sim_relay_proto {
	SIM_RELAY_DEVANTECH, /* 0x65 on, 0x6F off, 0x5B read states */
	SIM_RELAY_ICSTATION, /* 0x50 -> 0xAB, 0x51, then state masks */
	SIM_RELAY_LCUS,	     /* A0 01 01 A2 on, A0 01 00 A1 off */
	SIM_RELAY_KMTRONIC,  /* FF 01 01 on, FF 01 00 off, FF 01 03 read */
};

enum sim_relay_fault {
	SIM_RELAY_OK,	     /* present and obeying */
	SIM_RELAY_UNPLUG,    /* pty closed, device node and link gone */
	SIM_RELAY_WRITEFAIL, /* device present, bytes ignored, power off */
	SIM_RELAY_WEDGE,     /* device present, bytes left unread in the
			      * pty, relay state kept as it was */
};

/* The protocol state of one relay board. */
struct sim_relay_dec {
	enum sim_relay_proto proto;
	uint8_t states;	  /* bit n-1 = relay n energised */
	int stage;	  /* icstation: 0 await 0x50, 1 await 0x51, 2 run;
			   * devantech: 1 = next byte is a 0x5C mask */
	uint8_t frame[4]; /* lcus / kmtronic frame being received */
	int nframe;
};

/*
 * sim_relay_proto_parse() - "devantech", "icstation", "lcus", "kmtronic".
 * Return: 0 or GL_ERR_ARG.
 */
int sim_relay_proto_parse(const char *name, enum sim_relay_proto *out);
const char *sim_relay_proto_name(enum sim_relay_proto proto);

/* sim_relay_dec_reset() - a board just powered up: every relay off. */
void sim_relay_dec_reset(struct sim_relay_dec *d, enum sim_relay_proto proto);

/*
 * sim_relay_dec_feed() - one byte from the host.
 * @reply: [out] bytes the board answers (at most 4); @cap >= 4.
 * @note: [out] optional, set to a short text when the byte was ignored
 *        (unknown command, bad checksum), else "".
 * Return: the number of reply bytes.
 */
size_t sim_relay_dec_feed(struct sim_relay_dec *d, uint8_t b, uint8_t *reply,
			  size_t cap, const char **note);

struct sim_relay;

/*
 * sim_relay_new() - a relay board (no pty yet), every relay off.
 * @event: optional callback for each state change ("relay on (0x65)",
 *         "relay off (0x6f)", "relay unplugged" ...); one line, no newline.
 * Return: 0 or GL_ERR_NOMEM.
 */
int sim_relay_new(struct sim_relay **out, enum sim_relay_proto proto,
		  void (*event)(void *ud, const char *line), void *ud);

/* sim_relay_free() - close the pty and remove the link (if still ours). */
void sim_relay_free(struct sim_relay *r);

/*
 * sim_relay_attach() - create the pseudo-terminal (raw mode; the slave fd
 * stays open here so the master never reads EIO) and, when @link_path is
 * not NULL or "", a symbolic link to its slave. An existing symbolic link
 * at @link_path is replaced; anything else there is refused.
 * @err: [out] e.g. "refusing to replace '/tmp/x': not a symbolic link".
 * Return: 0, GL_ERR_SYS, GL_ERR_ARG (already attached or bad link).
 */
int sim_relay_attach(struct sim_relay *r, const char *link_path, char *err,
		     size_t errlen);

/* sim_relay_tty() - the slave path ("/dev/pts/N"), "" without a pty. */
const char *sim_relay_tty(const struct sim_relay *r);

/*
 * sim_relay_fd() - the master fd to poll for input: -1 without a pty, and
 * while wedged (the board reads nothing; polling would spin).
 */
int sim_relay_fd(const struct sim_relay *r);

/*
 * sim_relay_queued() - bytes the host has written that the board has not
 * read yet (FIONREAD on the master); 0 without a pty.
 */
int sim_relay_queued(const struct sim_relay *r);

/*
 * sim_relay_service() - read every pending byte from the pty (without
 * blocking), decode it, answer. Under SIM_RELAY_WRITEFAIL bytes are read
 * and discarded; under SIM_RELAY_WEDGE nothing is read.
 * Return: the number of bytes read (>= 0), or GL_ERR_SYS.
 */
int sim_relay_service(struct sim_relay *r);

/*
 * sim_relay_power() - 1 when relay 1 is energised and the board is
 * present and working (or wedged: its relays keep their state): motor
 * power is on.
 */
int sim_relay_power(const struct sim_relay *r);

/*
 * sim_relay_set() - switch relay 1 directly (control port "relay on|off").
 * Return: 0, or GL_ERR_RELAY when the board is unplugged, failing or
 * wedged.
 */
int sim_relay_set(struct sim_relay *r, int on);

/*
 * sim_relay_set_fault() - inject a fault or repair.
 * SIM_RELAY_UNPLUG closes the pty (node vanishes, host writes get EIO) and
 * removes the link; SIM_RELAY_WRITEFAIL keeps the device but ignores every
 * byte; both cut power. SIM_RELAY_WEDGE stops reading the pty: the host's
 * bytes stay queued (until its writes would block) and the relays keep
 * their state, power included. SIM_RELAY_OK plugs a fresh board back in
 * (a new pty and link if one was attached before; every relay off,
 * icstation handshake needed again) or lets a failing or wedged board obey
 * again (relays off; what was queued while wedged is discarded unread).
 * Return: 0 or GL_ERR_SYS (pty could not be recreated; @err says why).
 */
int sim_relay_set_fault(struct sim_relay *r, enum sim_relay_fault f, char *err,
			size_t errlen);
enum sim_relay_fault sim_relay_get_fault(const struct sim_relay *r);

#endif /* SIM_RELAY_H */
