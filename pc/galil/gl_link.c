/*
 * gl_link.c - TCP link to a Galil DMC: connect, send, receive with deadlines.
 * This file holds the handle's life cycle (open, close) and accessors, and,
 * below, the decisions of the whole link; its parts (the byte moving, the
 * connection, commands, control requests, the record, DL/UL, messages) are
 * listed in gl_link_int.h.
 *
 * The link only moves bytes; gl_proto parses them. Decisions (fail safe):
 *
 * Out of step. After a timeout, a malformed reply, bytes left over after a
 *   complete reply, or solicited bytes arriving while no reply is awaited,
 *   the command handle is marked BROKEN: every later call returns
 *   GL_ERR_BROKEN without touching the socket, and the caller must close the
 *   link and open a new one (a new TCP connection starts with an empty
 *   stream). We do not try to resynchronise: a late ':' or a late data line
 *   cannot be told apart from the answer to a sync command, so a "resync"
 *   could itself take a late reply for an answer. After the peer closes the
 *   connection the call returns GL_ERR_CLOSED and later calls GL_ERR_BROKEN.
 * Errors. On '?' the link sends TC1 (with the link's default timeout) and
 *   keeps code and text. If TC1 itself fails, that error is returned instead
 *   (the link is then broken). A TC1 answer that does not start with a
 *   number breaks the link (GL_ERR_PROTO): it means the stream is not where
 *   we think it is.
 * Commands. A line must be 1..GL_LINE_MAX printable characters, without CR,
 *   LF, a leading, trailing or doubled ';' (the number of terminators to
 *   await would be uncertain), or an unbalanced '"'. ';' inside "..." is
 *   not counted as a separator.
 * DL. "DL" CR, every line followed by CR, then "\". The controller answers
 *   two terminators in all ('?' replacing one of them when a line is
 *   rejected; UNCONFIRMED, galil-notes 3.1). After each line the link looks
 *   (without waiting, or up to the DL pace, gl_link_set_dl_pace()) for an
 *   early '?'; when one is seen the remaining lines are not sent, "\" ends
 *   the download, and *bad_line is the last line sent: the rejected line is
 *   that one or an earlier one (the controller may answer after the link
 *   has sent more). A '?' first seen after "\" gives *bad_line = 0 (unknown).
 *   The controller never says which line it rejected, so an exact number
 *   needs pacing: with a pace longer than the controller's reply time the
 *   number is exact; a loader can re-run a failed download paced to find
 *   the line (the download failed anyway). Lines longer than GL_LINE_MAX,
 *   control bytes, bytes >= 0x80 and '\' are refused before anything is
 *   sent (GL_ERR_ARG, *bad_line exact). After a rejected DL the
 *   controller's program must be treated as invalid (it may hold the lines
 *   before the bad one).
 * QR. Unsolicited bytes before the record are recognised and queued; inside
 *   the record they cannot be (gl_proto.h): the record is misaligned and
 *   rejected (GL_ERR_PROTO, broken) because its ':' is missing or surplus
 *   bytes follow. Residual risk: if the misaligned byte happens to be ':'
 *   (1 in 256) and the surplus arrives only after the extra read done at
 *   the end of every exchange, a corrupt record is returned once and the
 *   next call fails with GL_ERR_PROTO. Keep CF on the message handle.
 * Messages. A second TCP connection to the same address; WH on it gives its
 *   handle letter, then "CF <letter>" and "CW1" go on the command handle.
 *   Unsolicited bytes that still reach the command handle are queued too and
 *   returned first by gl_link_message().
 * Layout. Learnt with QZ on the first gl_link_record() (or by
 *   gl_link_query_layout()); not at open, so that opening never depends on
 *   the controller model.
 */
#include <stdlib.h>
#include <unistd.h>

#include "gl_err.h"
#include "gl_link.h"
#include "gl_link_int.h"
#include "gl_proto.h"

int gl_link_open(gl_link **out, const char *addr, int timeout_ms,
		 char err[GL_ERRTEXT_LEN])
{
	gl_link *l;
	int rc;

	if (err)
		err[0] = '\0';
	if (!out || !addr || timeout_ms <= 0) {
		gl_link_err_put(err, "invalid argument");
		return GL_ERR_ARG;
	}
	*out = NULL;
	l = calloc(1, sizeof(*l));
	if (!l) {
		gl_link_err_put(err, "cannot open '%s': out of memory", addr);
		return GL_ERR_NOMEM;
	}
	l->cmd.fd = -1;
	l->msg.fd = -1;
	l->st_fd = -1;
	l->timeout_ms = timeout_ms;
	gl_proto_init(&l->cmd.p);
	gl_proto_init(&l->msg.p);
	rc = gl_link_connect(l, addr, timeout_ms, err);
	if (rc < 0) {
		free(l);
		return rc;
	}
	*out = l;
	return GL_OK;
}

void gl_link_close(gl_link *l)
{
	if (!l)
		return;
	gl_link_chan_close(&l->msg);
	if (l->st_fd >= 0)
		close(l->st_fd);
	if (l->cmd.fd >= 0)
		close(l->cmd.fd);
	free(l);
}

int gl_link_set_timeout(gl_link *l, int timeout_ms)
{
	if (!l || timeout_ms <= 0)
		return GL_ERR_ARG;
	l->timeout_ms = timeout_ms;
	return GL_OK;
}

const char *gl_link_ctrl_error(const gl_link *l, int *code)
{
	if (code)
		*code = l ? l->ctrl_code : 0;
	return l ? l->ctrl_text : "";
}

void gl_link_stats(const gl_link *l, uint64_t *tx_bytes, uint64_t *rx_bytes,
		   uint64_t *round_trips)
{
	if (tx_bytes)
		*tx_bytes = l ? l->tx_bytes : 0;
	if (rx_bytes)
		*rx_bytes = l ? l->rx_bytes : 0;
	if (round_trips)
		*round_trips = l ? l->round_trips : 0;
}

int gl_link_fd(const gl_link *l)
{
	return l ? l->cmd.fd : -1;
}

int gl_link_msg_fd(const gl_link *l)
{
	return l ? l->msg.fd : -1;
}

bool gl_link_broken(const gl_link *l)
{
	return !l || l->cmd.broken;
}
