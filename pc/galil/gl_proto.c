/*
 * gl_proto.c - the pure Galil reply parser (framing rules in gl_proto.h).
 *
 * gl_proto_next() runs a byte-at-a-time state machine over the buffered
 * input. Each state has its own small step function; step functions return
 * 0 (continue), 1 (the reply is complete) or GL_ERR_PROTO. A record's body
 * (known length, any byte value) is taken in one copy of what has arrived
 * instead (byte by byte it was half of the supervisor cycle's
 * instructions), with the same checks at the same byte.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "gl_proto.h"

enum {
	ST_IDLE,       /* no reply in progress */
	ST_TEXT,       /* text replies and terminators */
	ST_BIN_SYNC,   /* QR: waiting for the record's first byte */
	ST_BIN_BODY,   /* QR: record bytes, taken by length */
	ST_BIN_END,    /* QR: waiting for the ':' after the record */
	ST_UPLOAD,     /* UL: text up to 0x1A */
	ST_UPLOAD_END, /* UL: waiting for the ':' after 0x1A */
};

#define CTRL_Z	      0x1A
#define REC_FIRST_MIN 0x80 /* record byte 0: bit 7 + block bits 0..2 */
#define REC_FIRST_MAX 0x87
#define NUM_MAX	      40 /* longest number gl_parse_double() takes */

/* ---- unsolicited queue --------------------------------------------------- */

static void ring_put(struct gl_proto *p, char c)
{
	if (p->u_len == GL_PROTO_UNSOL_MAX) {
		p->unsol_dropped++;
		return;
	}
	p->unsol[(p->u_head + p->u_len) % GL_PROTO_UNSOL_MAX] = c;
	p->u_len++;
}

/* Queue one unsolicited character (high bit already cleared). */
static void unsol_push(struct gl_proto *p, uint8_t c)
{
	if (c == '\r' || c == 0)
		return;
	if (c != '\n' && p->u_line_len >= GL_PROTO_UNSOL_LINE - 1) {
		ring_put(p, '\n'); /* split an over-long line */
		p->u_line_len = 0;
	}
	ring_put(p, (char)c);
	p->u_line_len = c == '\n' ? 0 : p->u_line_len + 1;
}

int gl_proto_unsol_next(struct gl_proto *p, char *line, size_t cap)
{
	size_t i, n = 0, end;

	if (!p || !line || cap == 0)
		return GL_ERR_ARG;
	for (end = 0; end < p->u_len; end++)
		if (p->unsol[(p->u_head + end) % GL_PROTO_UNSOL_MAX] == '\n')
			break;
	if (end == p->u_len)
		return GL_ERR_AGAIN;
	for (i = 0; i < end; i++) {
		char c = p->unsol[(p->u_head + i) % GL_PROTO_UNSOL_MAX];

		if (n + 1 < cap)
			line[n++] = c;
	}
	line[n] = '\0';
	p->u_head = (p->u_head + end + 1) % GL_PROTO_UNSOL_MAX;
	p->u_len -= end + 1;
	return n < end ? GL_ERR_OVERFLOW : (int)n;
}

/* ---- set-up -------------------------------------------------------------- */

void gl_proto_init(struct gl_proto *p)
{
	memset(p, 0, sizeof(*p));
	p->state = ST_IDLE;
	p->first_err = -1;
	p->text = p->text_store;
	p->text_cap = sizeof(p->text_store);
}

void gl_proto_reset(struct gl_proto *p)
{
	bool all = p->all_unsol;

	gl_proto_init(p);
	p->all_unsol = all;
}

void gl_proto_set_all_unsol(struct gl_proto *p, bool on)
{
	p->all_unsol = on;
}

static int expect_push(struct gl_proto *p, const struct gl_proto_expect *e)
{
	if (p->exp_n == GL_PROTO_EXPECT_MAX)
		return GL_ERR_OVERFLOW;
	p->exp[(p->exp_head + p->exp_n) % GL_PROTO_EXPECT_MAX] = *e;
	p->exp_n++;
	return GL_OK;
}

int gl_proto_expect(struct gl_proto *p, int n_terminators, size_t binary_len)
{
	struct gl_proto_expect e = {0};

	if (!p || n_terminators < 1 || n_terminators > GL_PROTO_CMDS_MAX)
		return GL_ERR_ARG;
	if (binary_len != 0 &&
	    (binary_len < 4 || binary_len > GL_REC_MAX_BYTES))
		return GL_ERR_ARG;
	e.n_term = n_terminators;
	e.bin_len = binary_len;
	return expect_push(p, &e);
}

int gl_proto_expect_upload(struct gl_proto *p, char *buf, size_t cap)
{
	struct gl_proto_expect e = {0};

	if (!p || !buf || cap == 0)
		return GL_ERR_ARG;
	e.n_term = 1;
	e.upload = true;
	e.buf = buf;
	e.cap = cap;
	return expect_push(p, &e);
}

size_t gl_proto_space(const struct gl_proto *p)
{
	return GL_PROTO_IN_MAX - (p->in_len - p->in_pos);
}

int gl_proto_feed(struct gl_proto *p, const void *buf, size_t len)
{
	if (!p || (!buf && len > 0))
		return GL_ERR_ARG;
	if (len > gl_proto_space(p))
		return GL_ERR_OVERFLOW;
	if (p->in_len + len > GL_PROTO_IN_MAX) {
		memmove(p->in, p->in + p->in_pos, p->in_len - p->in_pos);
		p->in_len -= p->in_pos;
		p->in_pos = 0;
	}
	if (len > 0)
		memcpy(p->in + p->in_len, buf, len);
	p->in_len += len;
	return GL_OK;
}

int gl_proto_progress(const struct gl_proto *p, int *n_err)
{
	bool active = p->state != ST_IDLE && !p->done;

	if (n_err)
		*n_err = active ? p->n_err : 0;
	return active ? p->cmd : 0;
}

int gl_proto_awaiting(const struct gl_proto *p)
{
	return p->exp_n;
}

/* ---- the reply being parsed ---------------------------------------------- */

static const struct gl_proto_expect *cur(const struct gl_proto *p)
{
	return &p->exp[p->exp_head];
}

static void reply_start(struct gl_proto *p)
{
	const struct gl_proto_expect *e = cur(p);

	p->cmd = 0;
	p->n_err = 0;
	p->first_err = -1;
	p->line_start = true;
	p->cmd_data = false;
	p->truncated = false;
	p->bin_n = 0;
	p->text = e->buf ? e->buf : p->text_store;
	p->text_cap = e->buf ? e->cap : sizeof(p->text_store);
	p->text_len = 0;
	p->text[0] = '\0';
	if (e->upload)
		p->state = ST_UPLOAD;
	else if (e->bin_len && e->n_term == 1)
		p->state = ST_BIN_SYNC;
	else
		p->state = ST_TEXT;
}

static void text_put(struct gl_proto *p, uint8_t b)
{
	if (p->text_len + 1 >= p->text_cap) {
		p->truncated = true;
		return;
	}
	p->text[p->text_len++] = (char)b;
	p->text[p->text_len] = '\0';
}

static bool text_byte_ok(uint8_t b)
{
	return b == '\t' || (b >= 0x20 && b < 0x7f);
}

/* A ':' or '?' ends the current command. Return 1 when it was the last. */
static int terminate(struct gl_proto *p, bool rejected)
{
	const struct gl_proto_expect *e = cur(p);

	if (rejected) {
		p->n_err++;
		if (p->first_err < 0)
			p->first_err = p->cmd;
	}
	p->cmd++;
	p->line_start = true;
	p->cmd_data = false;
	if (p->cmd == e->n_term)
		return 1;
	if (e->bin_len && p->cmd == e->n_term - 1)
		p->state = ST_BIN_SYNC;
	return 0;
}

/* ---- step functions, one per state --------------------------------------- */

static int step_text(struct gl_proto *p, uint8_t b)
{
	if (p->line_start && (b == ':' || b == '?'))
		return terminate(p, b == '?');
	if (b == '\r' || b == '\n') {
		/* skip blank lines before a command's data; keep line ends */
		if (p->cmd_data)
			text_put(p, b);
		p->line_start = true;
		return 0;
	}
	if (!text_byte_ok(b))
		return GL_ERR_PROTO;
	text_put(p, b);
	p->cmd_data = true;
	p->line_start = false;
	return 0;
}

static int step_bin_sync(struct gl_proto *p, uint8_t b)
{
	if (b >= REC_FIRST_MIN && b <= REC_FIRST_MAX) {
		p->bin[0] = b;
		p->bin_n = 1;
		p->state = ST_BIN_BODY;
		return 0;
	}
	if (b == '?')
		return terminate(p, true);
	return GL_ERR_PROTO;
}

/* ST_BIN_BODY, for every buffered byte at once (record bytes may have any
 * value, so there is nothing to look at but the length): one copy up to the
 * end of the length field, checked once it is complete (the input consumed
 * just up to it), and one of the rest of the record. */
static int step_bin_run(struct gl_proto *p)
{
	size_t want = cur(p)->bin_len, n = want - p->bin_n;
	size_t avail = p->in_len - p->in_pos;

	if (p->bin_n < 4 && n > 4 - p->bin_n)
		n = 4 - p->bin_n;
	if (n > avail)
		n = avail;
	memcpy(p->bin + p->bin_n, p->in + p->in_pos, n);
	p->in_pos += n;
	p->bin_n += n;
	if (p->bin_n == 4 && (size_t)(p->bin[2] | (p->bin[3] << 8)) != want)
		return GL_ERR_PROTO; /* length field disagrees */
	if (p->bin_n == want)
		p->state = ST_BIN_END;
	return 0;
}

static int step_upload(struct gl_proto *p, uint8_t b)
{
	if (b == '?' && p->text_len == 0 && !p->truncated)
		return terminate(p, true);
	if (b == CTRL_Z) {
		p->state = ST_UPLOAD_END;
		return 0;
	}
	if (b != '\r' && b != '\n' && !text_byte_ok(b))
		return GL_ERR_PROTO;
	text_put(p, b);
	return 0;
}

static int step(struct gl_proto *p, uint8_t b)
{
	bool high = (b & 0x80) != 0;

	if (p->all_unsol ||
	    (high && p->state != ST_BIN_BODY &&
	     !(p->state == ST_BIN_SYNC && b <= REC_FIRST_MAX))) {
		unsol_push(p, b & 0x7f);
		return 0;
	}
	switch (p->state) {
	case ST_TEXT: return step_text(p, b);
	case ST_BIN_SYNC: return step_bin_sync(p, b);
	case ST_BIN_END: return b == ':' ? terminate(p, false) : GL_ERR_PROTO;
	case ST_UPLOAD: return step_upload(p, b);
	case ST_UPLOAD_END:
		return b == ':' ? terminate(p, false) : GL_ERR_PROTO;
	default: break; /* ST_BIN_BODY is step_bin_run()'s */
	}
	return GL_ERR_PROTO; /* solicited byte while no reply is awaited */
}

static void reply_fill(struct gl_proto *p, struct gl_reply *r)
{
	const struct gl_proto_expect *e = cur(p);

	if (!e->upload) {
		while (p->text_len > 0 && (p->text[p->text_len - 1] == '\n' ||
					   p->text[p->text_len - 1] == '\r'))
			p->text[--p->text_len] = '\0';
	}
	r->n_cmds = p->cmd;
	r->n_err = p->n_err;
	r->first_err = p->first_err;
	r->text = p->text;
	r->text_len = p->text_len;
	r->truncated = p->truncated;
	r->bin = (e->bin_len && p->bin_n == e->bin_len) ? p->bin : NULL;
	r->bin_len = r->bin ? p->bin_n : 0;
}

/* Retire the reply returned by the previous call. */
static void reply_retire(struct gl_proto *p)
{
	p->done = false;
	p->state = ST_IDLE;
	p->exp_head = (p->exp_head + 1) % GL_PROTO_EXPECT_MAX;
	p->exp_n--;
}

int gl_proto_next(struct gl_proto *p, struct gl_reply *reply)
{
	int rc;

	if (!p || !reply)
		return GL_ERR_ARG;
	if (p->error)
		return p->error;
	if (p->done)
		reply_retire(p);
	while (p->in_pos < p->in_len) {
		if (p->state == ST_IDLE && p->exp_n > 0)
			reply_start(p);
		if (p->state == ST_BIN_BODY && !p->all_unsol)
			rc = step_bin_run(p); /* the same, at once */
		else
			rc = step(p, p->in[p->in_pos++]);
		if (rc < 0) {
			p->error = rc;
			return rc;
		}
		if (rc == 1) {
			reply_fill(p, reply);
			p->done = true;
			return GL_OK;
		}
	}
	return GL_ERR_AGAIN;
}

/* ---- numbers ------------------------------------------------------------- */

/* Length of "[+-]digits[.digits]" at @s; 0 if there is no digit. */
static size_t number_span(const char *s, size_t len)
{
	size_t i = 0, digits = 0;

	if (i < len && (s[i] == '+' || s[i] == '-'))
		i++;
	for (; i < len && s[i] >= '0' && s[i] <= '9'; i++)
		digits++;
	if (i < len && s[i] == '.') {
		i++;
		for (; i < len && s[i] >= '0' && s[i] <= '9'; i++)
			digits++;
	}
	return digits ? i : 0;
}

bool gl_parse_double(const char *buf, size_t len, const char **ep, double *out)
{
	char tmp[NUM_MAX + 1];
	size_t i = 0, n;
	double v;
	char *end;

	if (!buf || !out) {
		errno = EINVAL;
		return false;
	}
	while (i < len && (buf[i] == ' ' || buf[i] == '\t'))
		i++;
	n = number_span(buf + i, len - i);
	if (n == 0) {
		errno = EINVAL;
		return false;
	}
	if (n > NUM_MAX) {
		errno = ERANGE;
		return false;
	}
	memcpy(tmp, buf + i, n);
	tmp[n] = '\0';
	errno = 0;
	v = strtod(tmp, &end);
	if (errno == ERANGE || end != tmp + n) {
		errno = errno == ERANGE ? ERANGE : EINVAL;
		return false;
	}
	*out = v;
	if (ep)
		*ep = buf + i + n;
	return true;
}
