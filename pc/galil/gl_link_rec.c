/*
 * gl_link_rec.c - the data record over the link: "[prefix;]QR" in one
 * round trip, the binary record decoded (gl_record), its layout learnt
 * with QZ on first use. Why bytes inside a record cannot be told from
 * unsolicited ones: gl_link.c's header ("QR").
 */
#include <stdbool.h>
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_link_int.h"
#include "gl_record.h"

int gl_link_query_layout(gl_link *l)
{
	char qz[64];
	int rc;

	if (!l)
		return GL_ERR_ARG;
	rc = gl_link_command(l, "QZ", qz, sizeof(qz), 0);
	if (rc < 0)
		return rc;
	return gl_record_layout_from_qz(qz, (size_t)rc, &l->layout, &l->n_axes);
}

int gl_link_axes(gl_link *l)
{
	int rc;

	if (!l)
		return GL_ERR_ARG;
	if (l->layout == GL_LAYOUT_NONE && (rc = gl_link_query_layout(l)) < 0)
		return rc;
	return l->n_axes;
}

int gl_link_record(gl_link *l, const char *prefix, struct gl_record *rec,
		   int timeout_ms)
{
	return gl_link_record_seen(l, prefix, rec, timeout_ms, false);
}

int gl_link_record_seen(gl_link *l, const char *prefix, struct gl_record *rec,
			int timeout_ms, bool seen_idle)
{
	return gl_link_record_text(l, prefix, rec, timeout_ms, seen_idle, NULL,
				   0);
}

int gl_link_record_text(gl_link *l, const char *prefix, struct gl_record *rec,
			int timeout_ms, bool seen_idle, char *text, size_t cap)
{
	char line[GL_LINE_MAX + 1];
	struct gl_xfer x = {.line = line, .seen_idle = seen_idle};
	struct gl_reply r;
	int rc, t = l ? gl_link_pick_timeout(l, timeout_ms) : GL_ERR_ARG;

	if (!l || !rec || t < 0)
		return GL_ERR_ARG;
	if (l->layout == GL_LAYOUT_NONE && (rc = gl_link_query_layout(l)) < 0)
		return rc;
	gl_link_ctrl_clear(l);
	/* "PREFIX;QR" by hand: this is built every cycle (no snprintf) */
	x.len = prefix ? strlen(prefix) : 0;
	if (x.len + 3 >= sizeof(line))
		return GL_ERR_ARG;
	if (prefix) {
		memcpy(line, prefix, x.len);
		line[x.len++] = ';';
	}
	memcpy(line + x.len, "QR", 3);
	x.len += 2;
	x.n_term = gl_link_count_commands(line, x.len);
	x.bin_len = gl_record_size(l->layout, l->n_axes);
	if (x.n_term < 0)
		return GL_ERR_ARG;
	rc = gl_link_xfer(l, &l->cmd, &x, t, &r);
	if (rc < 0)
		return rc;
	if (r.n_err)
		return gl_link_fetch_tc1(l);
	if (text && cap) {
		if (r.text_len >= cap || r.truncated)
			return GL_ERR_OVERFLOW;
		memcpy(text, r.text, r.text_len);
		text[r.text_len] = '\0';
	}
	rc = gl_record_decode(r.bin, r.bin_len, l->layout, l->n_axes, rec);
	/* the stream never goes back behind a record read this way (e.g.
	 * the one that saw the program armed) */
	if (rc >= 0 && l->st_fd >= 0)
		gl_stream_seen(&l->st, rec->sample, base_now_ns());
	return rc;
}
