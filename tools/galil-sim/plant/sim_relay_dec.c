/*
 * sim_relay_dec.c - the byte decoders of the virtual relay board's
 * protocols (see sim_relay_dec.h). Pure: no pty, no I/O, no events; the
 * board around it is sim_relay.c.
 *
 * Protocol facts: relays-and-serial.md.
 */
#include <string.h>

#include "gl_err.h"
#include "sim_relay_dec.h"

#define ICSTATION_ID 0xAB /* ICSE012A */

static const char *const proto_names[] = {"devantech", "icstation", "lcus",
					  "kmtronic"};

int sim_relay_proto_parse(const char *name, enum sim_relay_proto *out)
{
	for (int i = 0; i < 4; i++) {
		if (!strcmp(name, proto_names[i])) {
			*out = (enum sim_relay_proto)i;
			return 0;
		}
	}
	return GL_ERR_ARG;
}

const char *sim_relay_proto_name(enum sim_relay_proto proto)
{
	return proto >= 0 && proto < 4 ? proto_names[proto] : "?";
}

void sim_relay_dec_reset(struct sim_relay_dec *d, enum sim_relay_proto proto)
{
	memset(d, 0, sizeof(*d));
	d->proto = proto;
}

/* ---- decoders: one byte in, reply bytes out ---------------------------- */

static size_t feed_devantech(struct sim_relay_dec *d, uint8_t b, uint8_t *reply,
			     const char **note)
{
	if (d->stage == 1) { /* the mask after 0x5C */
		d->states = b;
		d->stage = 0;
		return 0;
	}
	if (b == 0x5B) {
		reply[0] = d->states;
		return 1;
	}
	if (b == 0x5C)
		d->stage = 1;
	else if (b == 0x64)
		d->states = 0xFF;
	else if (b >= 0x65 && b <= 0x6C)
		d->states |= (uint8_t)(1u << (b - 0x65));
	else if (b == 0x6E)
		d->states = 0;
	else if (b >= 0x6F && b <= 0x76)
		d->states &= (uint8_t) ~(1u << (b - 0x6F));
	else
		*note = "unknown devantech command";
	return 0;
}

static size_t feed_icstation(struct sim_relay_dec *d, uint8_t b, uint8_t *reply,
			     const char **note)
{
	switch (d->stage) {
	case 0:
		if (b != 0x50) {
			*note = "icstation byte before the 0x50 handshake";
			return 0;
		}
		d->stage = 1;
		reply[0] = ICSTATION_ID;
		return 1;
	case 1:
		if (b == 0x51)
			d->stage = 2;
		else
			*note = "icstation byte before 0x51";
		return 0;
	default:
		/* every byte is the whole state, active low */
		d->states = (uint8_t)~b;
		return 0;
	}
}

static size_t feed_frame(struct sim_relay_dec *d, uint8_t b, uint8_t *reply,
			 const char **note)
{
	int lcus = d->proto == SIM_RELAY_LCUS;
	uint8_t start = lcus ? 0xA0 : 0xFF;
	int len = lcus ? 4 : 3;
	uint8_t *f = d->frame;

	if (d->nframe == 0 && b != start) {
		*note = "byte outside a frame";
		return 0;
	}
	f[d->nframe++] = b;
	if (d->nframe < len)
		return 0;
	d->nframe = 0;
	if (f[1] != 0x01 || (lcus && (uint8_t)(f[0] + f[1] + f[2]) != f[3])) {
		*note = lcus ? "bad lcus frame (channel or checksum)"
			     : "kmtronic frame for another relay";
		return 0;
	}
	if (f[2] == 0x00 || f[2] == 0x01) {
		d->states = (uint8_t)((d->states & ~1u) | f[2]);
		return 0;
	}
	if (!lcus && f[2] == 0x03) {
		reply[0] = 0xFF;
		reply[1] = 0x01;
		reply[2] = d->states & 1;
		return 3;
	}
	*note = "unknown relay state command";
	return 0;
}

size_t sim_relay_dec_feed(struct sim_relay_dec *d, uint8_t b, uint8_t *reply,
			  size_t cap, const char **note)
{
	const char *dummy;

	if (!note)
		note = &dummy;
	*note = "";
	if (cap < 4)
		return 0;
	switch (d->proto) {
	case SIM_RELAY_DEVANTECH: return feed_devantech(d, b, reply, note);
	case SIM_RELAY_ICSTATION: return feed_icstation(d, b, reply, note);
	default: return feed_frame(d, b, reply, note);
	}
}
