/*
 * re_relay_proto.c - the byte protocols of the relay boards: the message
 * that switches a channel on or off, per preset or as configured
 * (relays-and-serial.md), and the protocols' names. Pure: no I/O.
 */
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "gl_err.h"
#include "re_relay_int.h"

const char *re_relay_proto_name(enum re_relay_proto proto)
{
	switch (proto) {
	case RE_RELAY_DEVANTECH: return "devantech";
	case RE_RELAY_ICSTATION: return "icstation";
	case RE_RELAY_LCUS: return "lcus";
	case RE_RELAY_KMTRONIC: return "kmtronic";
	case RE_RELAY_EXPLICIT: return "explicit";
	}
	return "unknown";
}

int re_relay_message(const struct re_relay_cfg *cfg, bool on, uint8_t *buf)
{
	int ch = cfg->channel;
	size_t n = on ? cfg->on_len : cfg->off_len;

	if (cfg->proto == RE_RELAY_EXPLICIT) {
		if (!n || n > RE_RELAY_CODE_MAX)
			return GL_ERR_ARG;
		memcpy(buf, on ? cfg->on : cfg->off, n);
		return (int)n;
	}
	if (ch < 1 || ch > 8)
		return GL_ERR_ARG;
	switch (cfg->proto) {
	case RE_RELAY_DEVANTECH:
		buf[0] = (uint8_t)((on ? 0x64 : 0x6E) + ch);
		return 1;
	case RE_RELAY_ICSTATION:
		buf[0] = on ? (uint8_t)(ICS_ALL_OFF & ~(1u << (ch - 1)))
			    : ICS_ALL_OFF;
		return 1;
	case RE_RELAY_LCUS:
		buf[0] = 0xA0;
		buf[1] = (uint8_t)ch;
		buf[2] = on ? 1 : 0;
		buf[3] = (uint8_t)(buf[0] + buf[1] + buf[2]);
		return 4;
	case RE_RELAY_KMTRONIC:
		buf[0] = 0xFF;
		buf[1] = (uint8_t)ch;
		buf[2] = on ? 1 : 0;
		return 3;
	default: return GL_ERR_ARG;
	}
}
