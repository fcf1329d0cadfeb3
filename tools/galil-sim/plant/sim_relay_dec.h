/*
 * sim_relay_dec.h - the byte protocols of the USB relay boards that
 * galil-sim's virtual E-stop relay speaks (relays-and-serial.md): one byte
 * from the host in, the board's reply bytes out, relay states kept.
 *
 * Pure: it is not the pty, the symbolic link, fault injection or events
 * (sim_relay.h is the board around it). Nothing here prints or allocates.
 */
#ifndef SIM_RELAY_DEC_H
#define SIM_RELAY_DEC_H

#include <stddef.h>
#include <stdint.h>

enum sim_relay_proto {
	SIM_RELAY_DEVANTECH, /* 0x65 on, 0x6F off, 0x5B read states */
	SIM_RELAY_ICSTATION, /* 0x50 -> 0xAB, 0x51, then state masks */
	SIM_RELAY_LCUS,	     /* A0 01 01 A2 on, A0 01 00 A1 off */
	SIM_RELAY_KMTRONIC,  /* FF 01 01 on, FF 01 00 off, FF 01 03 read */
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
 * sim_relay_proto_parse() / sim_relay_proto_name() - a protocol from its
 * name ("devantech", "icstation", "lcus", "kmtronic") into @out, and the
 * name of @proto (a static string; "?" for a value out of range).
 * Return (parse): 0, or GL_ERR_ARG for an unknown name (@out untouched).
 */
int sim_relay_proto_parse(const char *name, enum sim_relay_proto *out);
const char *sim_relay_proto_name(enum sim_relay_proto proto);

/*
 * sim_relay_dec_reset() - @d (caller's storage) becomes a board speaking
 * @proto just powered up: every relay off, no frame begun.
 */
void sim_relay_dec_reset(struct sim_relay_dec *d, enum sim_relay_proto proto);

/*
 * sim_relay_dec_feed() - one byte @b from the host; relay states change in
 * @d as the protocol says.
 * @reply: [out] bytes the board answers (at most 4); @cap >= 4.
 * @note: [out] optional, set to a short text when the byte was ignored
 *        (unknown command, bad checksum), else "".
 * Return: the number of reply bytes (0 when @cap < 4: nothing decoded).
 */
size_t sim_relay_dec_feed(struct sim_relay_dec *d, uint8_t b, uint8_t *reply,
			  size_t cap, const char **note);

#endif /* SIM_RELAY_DEC_H */
