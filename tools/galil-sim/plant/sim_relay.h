/*
 * sim_relay.h - galil-sim's virtual E-stop relay: a USB relay board on a
 * pseudo-terminal that speaks one of the relay byte protocols of
 * relays-and-serial.md and switches the robot's motor power (relay 1).
 *
 * The relay starts OFF (motor power cut). The byte decoder is pure and
 * lives in sim_relay_dec.h; struct sim_relay adds the pty, the optional
 * symbolic link, fault injection and state-change events. Nothing here
 * prints.
 */
#ifndef SIM_RELAY_H
#define SIM_RELAY_H

#include <stddef.h>
#include <stdint.h>

#include "sim_relay_dec.h"

enum sim_relay_fault {
	SIM_RELAY_OK,	     /* present and obeying */
	SIM_RELAY_UNPLUG,    /* pty closed, device node and link gone */
	SIM_RELAY_WRITEFAIL, /* device present, bytes ignored, power off */
	SIM_RELAY_WEDGE,     /* device present, bytes left unread in the
			      * pty, relay state kept as it was */
};

struct sim_relay;

/*
 * sim_relay_new() - a relay board speaking @proto (no pty yet), every
 * relay off. @out: [out] the board, owned by the caller (sim_relay_free()).
 * @event: optional callback for each state change ("relay on (0x65)",
 *         "relay off (0x6f)", "relay unplugged" ...); one line, no newline.
 * Return: 0 or GL_ERR_NOMEM.
 */
int sim_relay_new(struct sim_relay **out, enum sim_relay_proto proto,
		  void (*event)(void *ud, const char *line), void *ud);

/*
 * sim_relay_free() - close the pty, remove the link (if it still points at
 * our pty) and free @r. NULL is a no-op.
 */
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

/*
 * sim_relay_tty() - the slave path ("/dev/pts/N"), "" without a pty; owned
 * by @r, valid until the next fault injection or sim_relay_free().
 */
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

/* sim_relay_get_fault() - the fault injected now (SIM_RELAY_OK: none). */
enum sim_relay_fault sim_relay_get_fault(const struct sim_relay *r);

#endif /* SIM_RELAY_H */
