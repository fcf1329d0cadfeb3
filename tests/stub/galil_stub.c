/*
 * galil_stub.c - a fake Galil DMC-4030 on 127.0.0.1 that misbehaves on
 * demand (magic commands in stub_scenarios.h).
 *
 * Usage: galil-stub [-p PORT] [SCENARIO...]
 *   Binds 127.0.0.1:PORT (default 0: the kernel picks), prints exactly one
 *   line "galil-stub: listening on 127.0.0.1:<port>" on stdout when ready,
 *   and serves until SIGTERM or SIGINT (exit 0). Each SCENARIO (e.g.
 *   "DELAY 300", "SILENT") is applied to every new connection as if the
 *   client had sent "STUB <SCENARIO>" first. Diagnostics go to stderr.
 *
 * How it differs from a real DMC-4030:
 *   - It runs no program: only a small state table. Commands known:
 *     name=number, MG name|number|"text"|_BN|_CW|_TC|_XQn|_BGx|_MOx, ^R^V,
 *     QZ, QR, TC, TC0,
 *     TC1, WH, CF x, CW n, DL, UL, STUB ..., and HX ST MO SH BP BN BV XQ
 *     (accepted, no effect). Anything else is '?' with TC 1.
 *   - Values print as "% .4f" (e.g. " 5.0000"); TC1 prints "<code> <text>".
 *   - The QR record is synthetic (stub_scenarios.h); only layout 4000 with
 *     3 axes; QR takes no arguments.
 *   - DL: a rejected line (STUB DLREJECT n, or a line over 80 characters)
 *     is answered '?' at once and the download then ends with one ':' (two
 *     terminators in all; the real count is UNCONFIRMED). The old program is
 *     kept. Labels and syntax are not checked.
 *   - ';' inside "..." does not separate commands (real firmware UNCONFIRMED).
 *   - Handles A..H are the connections in order of arrival (lowest free
 *     letter); a ninth connection is closed at once. There is no UDP.
 *   - CW1 sets the high bit of messages sent with STUB MSG; the injected text
 *     of STUB UNSOL/UNSOLPRE always has it.
 *   - STUB EXTRA imitates a controller sending one terminator more than
 *     the client counted (e.g. an unexpected DL acknowledgement count).
 *   - Replies to the commands of one line are written separately,
 *     STUB_GAP_MS apart (a real controller's timing is unknown).
 */
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>
#include <arpa/inet.h>
#include <fcntl.h>

#include "base_clock.h"
#include "gl_record.h"
#include "stub_scenarios.h"

#define MAX_CLIENTS  8		  /* Ethernet handles A..H */
#define IN_MAX	     1024	  /* partial command line, bytes */
#define OUT_MAX	     (512 * 1024) /* queued output per client, bytes */
#define SEG_MAX	     8192	  /* queued writes per client */
#define PROG_MAX     (400 * 1024) /* 4000 lines of 80 characters + CR LF */
#define LINE_MAX_DMC 80
#define VARS_MAX     64
#define REPLY_MAX    (PROG_MAX + 1024)
#define PARTS_MAX    70 /* commands per line + extras */

enum mode {
	M_NORMAL,
	M_DELAY,
	M_QMARK,
	M_SPLIT1,
	M_CHUNKS,
	M_COALESCE,
	M_GARBAGE,
	M_UNSOL,
	M_UNSOLPRE,
	M_DROP,
	M_EXTRA,
	M_BADHDR,
};

struct seg {
	size_t off, len;
	int64_t due_ms;
};

struct client {
	int fd; /* -1: free slot */
	char letter;
	char in[IN_MAX];
	size_t in_len;
	uint8_t out[OUT_MAX];
	size_t out_len;
	struct seg seg[SEG_MAX];
	int seg_head, seg_n;
	enum mode next; /* one-shot mode for the next line */
	int next_arg;
	bool silent;
	int dl_reject_next; /* STUB DLREJECT n for the next DL */
	/* download in progress */
	bool dl;
	enum mode dl_mode;
	int dl_line, dl_reject;
	bool dl_rejected;
	char dl_cur[IN_MAX];
	size_t dl_cur_len;
	char dl_prog[PROG_MAX];
	size_t dl_len;
};

/* A reply under construction: bytes plus the end offset of each part. */
struct reply {
	uint8_t b[REPLY_MAX];
	size_t len;
	size_t part_end[PARTS_MAX];
	int n_parts;
};

struct var {
	char name[16];
	double v;
};

static struct {
	struct client c[MAX_CLIENTS];
	struct var vars[VARS_MAX];
	int n_vars;
	char prog[PROG_MAX]; /* lines, each ending in '\n' */
	size_t prog_len;
	int tc_code;
	const char *tc_text;
	char cf; /* handle for messages, 0 = none (serial) */
	bool cw1;
	uint32_t qr_count;
	uint32_t rng;
	char **scenarios;
	int n_scenarios;
} st;

static volatile sig_atomic_t stop;
static struct reply rb; /* one reply at a time */

/* ---- helpers ------------------------------------------------------------- */

static uint32_t rnd(void)
{
	st.rng = st.rng * 1103515245u + 12345u;
	return (st.rng >> 16) & 0x7fff;
}

static void put(struct reply *r, const void *p, size_t n)
{
	if (r->len + n > sizeof(r->b)) {
		fprintf(stderr, "galil-stub: reply too long, cut\n");
		n = sizeof(r->b) - r->len;
	}
	memcpy(r->b + r->len, p, n);
	r->len += n;
}

static void puts_r(struct reply *r, const char *s)
{
	put(r, s, strlen(s));
}

static void end_part(struct reply *r)
{
	if (r->n_parts < PARTS_MAX)
		r->part_end[r->n_parts++] = r->len;
	else
		r->part_end[PARTS_MAX - 1] = r->len;
}

static void put_number(struct reply *r, double v)
{
	char s[64];

	snprintf(s, sizeof(s), "% .4f\r\n:", v);
	puts_r(r, s);
}

static void reject(struct reply *r, int code, const char *text)
{
	st.tc_code = code;
	st.tc_text = text;
	puts_r(r, "?");
}

static struct var *var_find(const char *name, bool create)
{
	int i;

	for (i = 0; i < st.n_vars; i++)
		if (strcmp(st.vars[i].name, name) == 0)
			return &st.vars[i];
	if (!create || st.n_vars == VARS_MAX)
		return NULL;
	snprintf(st.vars[st.n_vars].name, sizeof(st.vars[0].name), "%s", name);
	st.vars[st.n_vars].v = 0;
	return &st.vars[st.n_vars++];
}

static bool parse_num(const char *s, double *v)
{
	char *end;

	if (!*s)
		return false;
	*v = strtod(s, &end);
	while (*end == ' ')
		end++;
	return *end == '\0';
}

static bool is_name(const char *s, size_t n)
{
	size_t i;

	if (n == 0 || n > 12 || !(s[0] >= 'a' && s[0] <= 'z'))
		return false;
	for (i = 1; i < n; i++)
		if (!strchr("abcdefghijklmnopqrstuvwxyz0123456789[]", s[i]))
			return false;
	return true;
}

/* ---- output queue -------------------------------------------------------- */

static void queue(struct client *c, const uint8_t *p, size_t n, int64_t due)
{
	struct seg *last =
	    c->seg_n ? &c->seg[(c->seg_head + c->seg_n - 1) % SEG_MAX] : NULL;

	if (n == 0)
		return;
	if (c->out_len + n > OUT_MAX) {
		fprintf(stderr, "galil-stub: output queue full, dropped\n");
		return;
	}
	if (last && due < last->due_ms)
		due = last->due_ms; /* never overtake an earlier reply */
	memcpy(c->out + c->out_len, p, n);
	if (c->seg_n == SEG_MAX) { /* merge into the last write */
		last->len += n;
	} else {
		c->seg[(c->seg_head + c->seg_n) % SEG_MAX] =
		    (struct seg){c->out_len, n, due};
		c->seg_n++;
	}
	c->out_len += n;
}

/* Queue @r as the mode says: parts apart, one write, bytes, chunks. */
static void schedule(struct client *c, const struct reply *r, enum mode m,
		     int delay_ms)
{
	int64_t t = base_now_ms() + (m == M_DELAY ? delay_ms : 0);
	size_t off = 0, n;
	int i;

	if (m == M_COALESCE || m == M_GARBAGE || m == M_UNSOL ||
	    (m == M_EXTRA && delay_ms == 0)) {
		queue(c, r->b, r->len, t);
		return;
	}
	if (m == M_SPLIT1 || m == M_CHUNKS) {
		for (; off < r->len; off += n) {
			n = m == M_SPLIT1 ? 1 : 1 + rnd() % 8;
			if (n > r->len - off)
				n = r->len - off;
			queue(c, r->b + off, n, t);
			t += m == M_SPLIT1 ? 1 : rnd() % 3;
		}
		return;
	}
	for (i = 0; i < r->n_parts; i++) {
		queue(c, r->b + off, r->part_end[i] - off, t);
		off = r->part_end[i];
		t += STUB_GAP_MS;
	}
	queue(c, r->b + off, r->len - off, t);
}

/* Write what is due; return false when the client must be closed. */
static bool flush_due(struct client *c, int64_t now)
{
	while (c->seg_n > 0) {
		struct seg *s = &c->seg[c->seg_head];
		ssize_t n;

		if (s->due_ms > now)
			return true;
		n = send(c->fd, c->out + s->off, s->len, MSG_NOSIGNAL);
		if (n < 0)
			return errno == EAGAIN || errno == EWOULDBLOCK;
		s->off += (size_t)n;
		s->len -= (size_t)n;
		if (s->len > 0)
			return true;
		c->seg_head = (c->seg_head + 1) % SEG_MAX;
		if (--c->seg_n == 0)
			c->out_len = 0;
	}
	return true;
}

static void client_close(struct client *c);

/* ---- commands ------------------------------------------------------------ */

static void high_bits(uint8_t *p, size_t n)
{
	size_t i;

	for (i = 0; i < n; i++)
		p[i] |= 0x80;
}

static struct client *client_by_letter(char letter)
{
	int i;

	for (i = 0; i < MAX_CLIENTS; i++)
		if (st.c[i].fd >= 0 && st.c[i].letter == letter)
			return &st.c[i];
	return NULL;
}

static void send_message(const char *text)
{
	struct client *to = st.cf ? client_by_letter(st.cf) : NULL;
	uint8_t buf[IN_MAX + 2];
	size_t n = strlen(text);

	if (!to || n > IN_MAX)
		return;
	memcpy(buf, text, n);
	memcpy(buf + n, "\r\n", 2);
	if (st.cw1)
		high_bits(buf, n + 2);
	queue(to, buf, n + 2, base_now_ms());
}

static const struct {
	const char *word;
	enum mode m;
} magic[] = {
    {"DELAY", M_DELAY},	      {"QMARK", M_QMARK},	{"SPLIT1", M_SPLIT1},
    {"CHUNKS", M_CHUNKS},     {"COALESCE", M_COALESCE}, {"GARBAGE", M_GARBAGE},
    {"UNSOLPRE", M_UNSOLPRE}, {"UNSOL", M_UNSOL},	{"DROP", M_DROP},
    {"EXTRA", M_EXTRA},	      {"BADHDR", M_BADHDR},
};

/* "STUB <word> [arg]" without the "STUB " prefix. */
static bool stub_magic(struct client *c, const char *s)
{
	size_t i, n;

	if (strncmp(s, "MSG ", 4) == 0) {
		send_message(s + 4);
		return true;
	}
	if (strcmp(s, "MSGCLOSE") == 0) {
		struct client *to = st.cf ? client_by_letter(st.cf) : NULL;

		if (to)
			client_close(to);
		return true;
	}
	if (strcmp(s, "SILENT") == 0) {
		c->silent = true;
		return true;
	}
	if (strncmp(s, "DLREJECT ", 9) == 0) {
		c->dl_reject_next = atoi(s + 9);
		return c->dl_reject_next > 0;
	}
	for (i = 0; i < sizeof(magic) / sizeof(magic[0]); i++) {
		n = strlen(magic[i].word);
		if (strncmp(s, magic[i].word, n) == 0 &&
		    (s[n] == '\0' || s[n] == ' ')) {
			c->next = magic[i].m;
			c->next_arg = atoi(s + n);
			return true;
		}
	}
	return false;
}

static void answer_record(struct reply *r, enum mode m)
{
	struct gl_record rec;
	struct var *hb = var_find("hbpc", false);
	uint8_t b[GL_REC_MAX_BYTES];
	int n;

	memset(&rec, 0, sizeof(rec));
	rec.layout = GL_LAYOUT_4000;
	rec.n_axes = 3;
	rec.sample = (uint16_t)++st.qr_count;
	rec.inputs[0] = STUB_REC_INPUTS0;
	rec.threads = STUB_REC_THREADS;
	rec.axis[0].motor_pos = STUB_REC_POS_A;
	rec.axis[1].motor_pos = STUB_REC_POS_B;
	rec.axis[2].motor_pos = STUB_REC_POS_C;
	rec.axis[0].za = hb ? (int32_t)hb->v : 0;
	rec.axis[1].za = STUB_REC_ZA_B;
	rec.axis[2].za = STUB_REC_ZA_C;
	n = gl_record_encode(&rec, b, sizeof(b));
	if (m == M_BADHDR)
		b[1] = 0x0F;
	if (n > 0)
		put(r, b, (size_t)n);
	puts_r(r, ":");
}

static void answer_mg(struct reply *r, const char *arg)
{
	size_t n = strlen(arg);
	struct var *v;
	double d;

	if (n >= 2 && arg[0] == '"' && arg[n - 1] == '"') {
		put(r, arg + 1, n - 2);
		puts_r(r, "\r\n:");
	} else if (strcmp(arg, "_BN") == 0) {
		put_number(r, STUB_SERIAL);
	} else if (strcmp(arg, "_CW") == 0) {
		put_number(r, st.cw1 ? 1 : 2);
	} else if (strcmp(arg, "_TC") == 0) {
		put_number(r, st.tc_code);
	} else if (strncmp(arg, "_XQ", 3) == 0) {
		put_number(r, -1); /* the stub runs no program threads */
	} else if (strncmp(arg, "_BG", 3) == 0 && arg[3] && !arg[4]) {
		put_number(r, 0); /* and moves no axis */
	} else if (strncmp(arg, "_MO", 3) == 0 && arg[3] && !arg[4]) {
		put_number(r, 1); /* its motors are off */
	} else if (parse_num(arg, &d)) {
		put_number(r, d);
	} else if ((v = var_find(arg, false)) != NULL) {
		put_number(r, v->v);
	} else {
		reject(r, STUB_TC_UNKNOWN, STUB_TC_UNKNOWN_TEXT);
	}
}

static void answer_tc(struct reply *r, bool text)
{
	char s[128];

	if (text && st.tc_code)
		snprintf(s, sizeof(s), "%d %s\r\n:", st.tc_code, st.tc_text);
	else
		snprintf(s, sizeof(s), "%d\r\n:", st.tc_code);
	puts_r(r, s);
}

static void answer_upload(struct reply *r)
{
	size_t i;

	for (i = 0; i < st.prog_len; i++) {
		if (st.prog[i] == '\n')
			puts_r(r, "\r\n");
		else
			put(r, &st.prog[i], 1);
	}
	puts_r(r, "\x1a:");
}

static bool answer_assign(struct reply *r, const char *cmd)
{
	const char *eq = strchr(cmd, '=');
	struct var *v;
	double d;

	if (!eq || !is_name(cmd, (size_t)(eq - cmd)) || !parse_num(eq + 1, &d))
		return false;
	{
		char name[16];

		snprintf(name, sizeof(name), "%.*s", (int)(eq - cmd), cmd);
		v = var_find(name, true);
	}
	if (!v)
		return false;
	v->v = d;
	puts_r(r, ":");
	return true;
}

static bool answer_noop(const char *cmd)
{
	static const char *const ok[] = {"HX", "ST", "MO", "SH",
					 "BP", "BN", "BV", "XQ"};
	size_t i;

	for (i = 0; i < sizeof(ok) / sizeof(ok[0]); i++)
		if (strncmp(cmd, ok[i], 2) == 0 &&
		    (cmd[2] == '\0' || strchr(" 0123456789#ABCDEFGH,", cmd[2])))
			return true;
	return false;
}

static bool answer_handles(struct client *c, struct reply *r, const char *cmd)
{
	char s[16];

	if (strcmp(cmd, "WH") == 0) {
		snprintf(s, sizeof(s), "IH%c\r\n:", c->letter);
		puts_r(r, s);
	} else if (strncmp(cmd, "CF", 2) == 0) {
		const char *a = cmd + 2 + (cmd[2] == ' ');

		if (a[0] < 'A' || a[0] > 'H' || a[1])
			return false;
		st.cf = a[0];
		puts_r(r, ":");
	} else if (strncmp(cmd, "CW", 2) == 0) {
		const char *a = cmd + 2 + (cmd[2] == ' ');

		if (*a != '1' && *a != '2')
			return false;
		st.cw1 = *a == '1';
		puts_r(r, ":");
	} else {
		return false;
	}
	return true;
}

static void dl_start(struct client *c, enum mode m);

/* One command (no ';'), trimmed. */
static void answer(struct client *c, struct reply *r, const char *cmd,
		   enum mode m)
{
	if (strncmp(cmd, STUB_PREFIX, strlen(STUB_PREFIX)) == 0) {
		if (stub_magic(c, cmd + strlen(STUB_PREFIX)))
			puts_r(r, ":");
		else
			reject(r, STUB_TC_UNKNOWN, STUB_TC_UNKNOWN_TEXT);
	} else if (cmd[0] == '\0' || answer_noop(cmd)) {
		puts_r(r, ":");
	} else if (strcmp(cmd, "\x12\x16") == 0) {
		puts_r(r, STUB_MODEL "\r\n:");
	} else if (strcmp(cmd, "QZ") == 0) {
		puts_r(r, STUB_QZ "\r\n:");
	} else if (strcmp(cmd, "QR") == 0) {
		answer_record(r, m);
	} else if (strcmp(cmd, "TC1") == 0 || strcmp(cmd, "TC") == 0 ||
		   strcmp(cmd, "TC0") == 0) {
		answer_tc(r, cmd[2] == '1');
	} else if (strncmp(cmd, "MG ", 3) == 0) {
		answer_mg(r, cmd + 3);
	} else if (strcmp(cmd, "UL") == 0) {
		answer_upload(r);
	} else if (strcmp(cmd, "DL") == 0) {
		dl_start(c, m); /* answered after the '\' */
	} else if (!answer_handles(c, r, cmd) && !answer_assign(r, cmd)) {
		reject(r, STUB_TC_UNKNOWN, STUB_TC_UNKNOWN_TEXT);
	}
}

/* ---- lines --------------------------------------------------------------- */

/* Split @line at ';' outside quotes, answer each part into rb. */
static void answer_line(struct client *c, char *line, enum mode m)
{
	char *s = line, *p;
	bool quoted = false;
	int i = 0;

	for (p = line;; p++) {
		if (*p == '"')
			quoted = !quoted;
		if ((*p == ';' && !quoted) || *p == '\0') {
			bool last = *p == '\0';
			char *b = s, *e = p;

			*p = '\0';
			while (*b == ' ')
				b++;
			while (e > b && e[-1] == ' ')
				*--e = '\0';
			if (m == M_UNSOLPRE && last) {
				uint8_t u[] = STUB_UNSOL_TEXT "\r\n";

				high_bits(u, sizeof(u) - 1);
				put(&rb, u, sizeof(u) - 1);
			}
			if (m == M_QMARK && i == 0)
				reject(&rb, STUB_TC_UNKNOWN,
				       STUB_TC_UNKNOWN_TEXT);
			else
				answer(c, &rb, b, m);
			end_part(&rb);
			i++;
			if (last)
				return;
			s = p + 1;
		}
	}
}

static void unsol_insert(struct reply *r)
{
	uint8_t u[] = STUB_UNSOL_TEXT "\r\n";
	size_t n = sizeof(u) - 1, mid = r->len / 2;

	high_bits(u, n);
	if (r->len + n > sizeof(r->b))
		return;
	memmove(r->b + mid + n, r->b + mid, r->len - mid);
	memcpy(r->b + mid, u, n);
	r->len += n;
}

static void client_close(struct client *c)
{
	if (c->fd >= 0)
		close(c->fd);
	c->fd = -1;
}

static void handle_line(struct client *c, char *line)
{
	enum mode m = c->next;
	int arg = c->next_arg;

	if (c->silent)
		return;
	c->next = M_NORMAL;
	if (m == M_DROP) {
		client_close(c);
		return;
	}
	rb.len = 0;
	rb.n_parts = 0;
	answer_line(c, line, m);
	if (m == M_GARBAGE) {
		rb.len = 0;
		put(&rb, STUB_GARBAGE_BYTES, sizeof(STUB_GARBAGE_BYTES) - 1);
	}
	if (m == M_UNSOL)
		unsol_insert(&rb);
	if (m == M_EXTRA && arg == 0)
		puts_r(&rb, ":");
	schedule(c, &rb, m, arg);
	if (m == M_EXTRA && arg > 0)
		queue(c, (const uint8_t *)":", 1, base_now_ms() + arg);
}

/* ---- download ------------------------------------------------------------ */

static void dl_start(struct client *c, enum mode m)
{
	c->dl = true;
	c->dl_mode = m;
	c->dl_line = 0;
	c->dl_reject = c->dl_reject_next;
	c->dl_reject_next = 0;
	c->dl_rejected = false;
	c->dl_cur_len = 0;
	c->dl_len = 0;
}

static void dl_line_done(struct client *c)
{
	bool bad;

	c->dl_line++;
	bad = c->dl_line == c->dl_reject || c->dl_cur_len > LINE_MAX_DMC;
	if (bad && !c->dl_rejected) {
		c->dl_rejected = true;
		st.tc_code = STUB_TC_DL;
		st.tc_text = STUB_TC_DL_TEXT;
		queue(c, (const uint8_t *)"?", 1, base_now_ms());
	}
	if (c->dl_len + c->dl_cur_len + 1 <= sizeof(c->dl_prog)) {
		memcpy(c->dl_prog + c->dl_len, c->dl_cur, c->dl_cur_len);
		c->dl_len += c->dl_cur_len;
		c->dl_prog[c->dl_len++] = '\n';
	}
	c->dl_cur_len = 0;
}

static void dl_end(struct client *c)
{
	if (c->dl_cur_len > 0)
		dl_line_done(c);
	c->dl = false;
	rb.len = 0;
	rb.n_parts = 0;
	if (!c->dl_rejected) {
		memcpy(st.prog, c->dl_prog, c->dl_len);
		st.prog_len = c->dl_len;
		puts_r(&rb, ":");
		end_part(&rb);
	}
	puts_r(&rb, ":");
	end_part(&rb);
	schedule(c, &rb, c->dl_mode, 0);
}

static void dl_byte(struct client *c, char b)
{
	if (b == '\\') {
		dl_end(c);
	} else if (b == '\r') {
		dl_line_done(c);
	} else if (b != '\n' && c->dl_cur_len < sizeof(c->dl_cur)) {
		c->dl_cur[c->dl_cur_len++] = b;
	}
}

/* ---- connections --------------------------------------------------------- */

static void client_input(struct client *c, const char *buf, size_t n)
{
	size_t i;

	for (i = 0; i < n && c->fd >= 0; i++) {
		char b = buf[i];

		if (c->dl) {
			dl_byte(c, b);
		} else if (b == '\r') {
			c->in[c->in_len] = '\0';
			c->in_len = 0;
			handle_line(c, c->in);
		} else if (b != '\n' && c->in_len + 1 < sizeof(c->in)) {
			c->in[c->in_len++] = b;
		}
	}
}

static void client_read(struct client *c)
{
	char buf[4096];
	ssize_t n = recv(c->fd, buf, sizeof(buf), 0);

	if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) {
		client_close(c);
		return;
	}
	if (n > 0)
		client_input(c, buf, (size_t)n);
}

static void client_accept(int lfd)
{
	struct client *c = NULL;
	int fd, i, one = 1;
	bool used[MAX_CLIENTS] = {false};

	fd = accept(lfd, NULL, NULL);
	if (fd < 0)
		return;
	for (i = 0; i < MAX_CLIENTS; i++)
		if (st.c[i].fd >= 0)
			used[st.c[i].letter - 'A'] = true;
	for (i = 0; i < MAX_CLIENTS && !c; i++)
		if (st.c[i].fd < 0)
			c = &st.c[i];
	if (!c) {
		close(fd); /* all 8 handles in use */
		return;
	}
	memset(c, 0, sizeof(*c));
	c->fd = fd;
	for (i = 0; used[i]; i++)
		;
	c->letter = (char)('A' + i);
	fcntl(fd, F_SETFL, O_NONBLOCK);
	setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
	for (i = 0; i < st.n_scenarios; i++)
		stub_magic(c, st.scenarios[i]);
}

/* ---- main loop ----------------------------------------------------------- */

static int poll_timeout(int64_t now)
{
	int64_t t = -1;
	int i;

	for (i = 0; i < MAX_CLIENTS; i++) {
		struct client *c = &st.c[i];
		int64_t d;

		if (c->fd < 0 || c->seg_n == 0)
			continue;
		d = c->seg[c->seg_head].due_ms - now;
		if (d < 0)
			d = 0;
		if (t < 0 || d < t)
			t = d;
	}
	return (int)t;
}

static void serve(int lfd)
{
	struct pollfd pfd[MAX_CLIENTS + 1];
	int map[MAX_CLIENTS + 1], n, i;

	while (!stop) {
		pfd[0] = (struct pollfd){.fd = lfd, .events = POLLIN};
		for (n = 1, i = 0; i < MAX_CLIENTS; i++) {
			if (st.c[i].fd < 0)
				continue;
			map[n] = i;
			pfd[n++] = (struct pollfd){
			    .fd = st.c[i].fd,
			    .events = POLLIN | (st.c[i].seg_n ? POLLOUT : 0)};
		}
		if (poll(pfd, (nfds_t)n, poll_timeout(base_now_ms())) < 0) {
			if (errno == EINTR)
				continue;
			perror("galil-stub: poll");
			return;
		}
		if (pfd[0].revents & POLLIN)
			client_accept(lfd);
		for (i = 1; i < n; i++) {
			struct client *c = &st.c[map[i]];

			if (c->fd >= 0 && (pfd[i].revents & (POLLIN | POLLHUP)))
				client_read(c);
			if (c->fd >= 0 && !flush_due(c, base_now_ms()))
				client_close(c);
		}
	}
}

static void on_signal(int sig)
{
	(void)sig;
	stop = 1;
}

static int listen_on(int port)
{
	struct sockaddr_in sa = {.sin_family = AF_INET};
	socklen_t sl = sizeof(sa);
	int fd, one = 1;

	sa.sin_port = htons((uint16_t)port);
	sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	fd = socket(AF_INET, SOCK_STREAM, 0);
	if (fd < 0)
		return -1;
	setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
	if (bind(fd, (struct sockaddr *)&sa, sizeof(sa)) < 0 ||
	    listen(fd, 16) < 0 ||
	    getsockname(fd, (struct sockaddr *)&sa, &sl) < 0) {
		close(fd);
		return -1;
	}
	printf("galil-stub: listening on 127.0.0.1:%u\n", ntohs(sa.sin_port));
	fflush(stdout);
	return fd;
}

int main(int argc, char **argv)
{
	struct sigaction sa = {.sa_handler = on_signal};
	int i, port = 0, lfd, first = 1;

	if (argc > 2 && strcmp(argv[1], "-p") == 0) {
		port = atoi(argv[2]);
		first = 3;
	}
	st.scenarios = argv + first;
	st.n_scenarios = argc - first;
	st.rng = 1;
	for (i = 0; i < MAX_CLIENTS; i++)
		st.c[i].fd = -1;
	var_find("x", true)->v = 5;
	sigaction(SIGTERM, &sa, NULL);
	sigaction(SIGINT, &sa, NULL);
	signal(SIGPIPE, SIG_IGN);
	lfd = listen_on(port);
	if (lfd < 0) {
		fprintf(stderr,
			"galil-stub: cannot listen on 127.0.0.1:%d: %s\n", port,
			strerror(errno));
		return 1;
	}
	serve(lfd);
	close(lfd);
	return 0;
}
