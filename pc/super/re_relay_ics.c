/*
 * re_relay_ics.c - the ICStation handshake (0x50, its answer, 0x51), done
 * once per power-up of the board: the power-up identified by the device
 * node and recorded durably in the icstation_state file (why: re_relay.c's
 * header).
 */
#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "base_clock.h"
#include "base_durable.h"
#include "gl_err.h"
#include "re_relay_int.h"

#define ICS_ID	     0x50
#define ICS_START    0x51
#define ICS_REPLY_MS 500 /* deadline of the identification answer */

/* One byte within @ms: 1, 0 (none came) or GL_ERR_SYS. */
static int read_byte(struct re_relay *r, uint8_t *b, int ms)
{
	int64_t deadline = re_relay_deadline_in(ms);
	int n;

	for (;;) {
		n = r->ops->read(&r->io, b, 1, r->err, sizeof(r->err));
		if (n != 0 || base_now_ns() >= deadline)
			return n;
		re_relay_nap(deadline);
	}
}

/* Write a message and wait until it is sent, within @ms (open only). */
static int send_wait(struct re_relay *r, const uint8_t *msg, size_t len,
		     const char *what, int ms)
{
	re_relay_out_set(r, msg, len);
	return re_relay_out_wait(r, what, re_relay_deadline_in(ms), ms)
		   ? GL_ERR_RELAY
		   : GL_OK;
}

/* The identity of the board's current power-up: its device node. */
static int ics_identity(struct re_relay *r, char *buf, size_t cap)
{
	struct stat st;

	if (stat(r->cfg.port, &st) < 0)
		return re_relay_set_err(r, GL_ERR_RELAY, "cannot open: %s",
					strerror(errno));
	snprintf(buf, cap, "icstation rdev=%ju ino=%ju ctime=%lld.%09ld",
		 (uintmax_t)st.st_rdev, (uintmax_t)st.st_ino,
		 (long long)st.st_ctim.tv_sec, (long)st.st_ctim.tv_nsec);
	return GL_OK;
}

static bool ics_recorded(const struct re_relay *r, const char *id)
{
	char line[256];
	FILE *f = fopen(r->cfg.icstation_state, "re");
	bool same = false;

	if (!f)
		return false;
	if (fgets(line, sizeof(line), f))
		same =
		    !strncmp(line, id, strlen(id)) && line[strlen(id)] == ' ';
	fclose(f);
	return same;
}

/* Write the record durably: temporary file, fsync, rename, fsync of the
 * directory (base_durable_write). */
static int ics_record(struct re_relay *r, const char *id, uint8_t model)
{
	char text[256];
	int n;

	n = snprintf(text, sizeof(text), "%s model=0x%02X\n", id, model);
	if (n < 0 || (size_t)n >= sizeof(text))
		n = (int)strlen(text);
	if (base_durable_write(r->cfg.icstation_state, text, (size_t)n, 0644) ==
	    0)
		return GL_OK;
	return re_relay_set_err(r, GL_ERR_RELAY,
				"cannot record the icstation "
				"handshake in '%s': %s",
				r->cfg.icstation_state, strerror(errno));
}

int re_relay_ics_handshake(struct re_relay *r)
{
	static const uint8_t id_req = ICS_ID, start = ICS_START;
	static const uint8_t all_off = ICS_ALL_OFF;
	const int ms = r->cfg.write_timeout_ms;
	char id[160];
	uint8_t b = 0;
	int n;

	if (ics_identity(r, id, sizeof(id)))
		return GL_ERR_RELAY;
	if (ics_recorded(r, id))
		return GL_OK;
	if (re_relay_drop_input(r) ||
	    send_wait(r, &id_req, 1, "icstation handshake", ms))
		return GL_ERR_RELAY;
	n = read_byte(r, &b, ICS_REPLY_MS);
	if (n != 1 || (b != 0xAB && b != 0xAD && b != 0xAC)) {
		/* 0x50 may just have switched relays on: all off, now. */
		send_wait(r, &all_off, 1, "off", r->cfg.off_deadline_ms);
		if (n == 1)
			return re_relay_set_err(
			    r, GL_ERR_RELAY,
			    "unexpected answer "
			    "0x%02X to the icstation handshake",
			    b);
		return re_relay_set_err(
		    r, GL_ERR_RELAY,
		    "no answer to the icstation "
		    "handshake within %d ms (board already "
		    "initialised?): unplug and re-plug the relay",
		    ICS_REPLY_MS);
	}
	if (send_wait(r, &start, 1, "icstation handshake", ms))
		return GL_ERR_RELAY;
	return ics_record(r, id, b);
}
