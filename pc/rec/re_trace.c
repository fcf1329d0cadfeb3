/*
 * re_trace.c - the trace format: writer and strict reader. See re_trace.h
 * and docs/trace-format.md.
 */
#include "re_trace.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"

/* ---- the columns ----------------------------------------------------------
 */

enum kind { K_INT, K_DBL };

struct col {
	const char *name;
	const char *unit;
	enum kind kind;
	size_t off; /* in struct re_trace_rec or struct re_trace_axis */
	int decimals;
};

#define RC(n, u, k, f, d)                                                      \
	{                                                                      \
		n, u, k, offsetof(struct re_trace_rec, f), d                   \
	}
#define AC(n, u, k, f, d)                                                      \
	{                                                                      \
		n, u, k, offsetof(struct re_trace_axis, f), d                  \
	}

static const struct col rec_cols[] = {
    RC("t_s", "s", K_DBL, t_s, 6),
    RC("cycle", "1", K_INT, cycle, 0),
    RC("phase", "1", K_INT, phase, 0),
    RC("fault", "1", K_INT, fault, 0),
    RC("relay", "1", K_INT, relay, 0),
    RC("link_ok", "1", K_INT, link_ok, 0),
    RC("age_ms", "ms", K_DBL, age_ms, 3),
    RC("late_ms", "ms", K_DBL, late_ms, 3),
    RC("hbpc", "1", K_INT, hbpc, 0),
    RC("hbdmc", "1", K_INT, hbdmc, 0),
    RC("sample", "1", K_INT, sample, 0),
    RC("joy_raw", "1", K_INT, joy_raw, 0),
    RC("jcmd", "1", K_INT, jcmd, 0),
    RC("mcmd", "1", K_INT, mcmd, 0),
    RC("dmc_state", "1", K_INT, dmc_state, 0),
    RC("fcode", "1", K_INT, fcode, 0),
};

static const struct col axis_cols[] = {
    AC("enc", "counts", K_INT, enc_counts, 0),
    AC("ref", "counts", K_INT, ref_counts, 0),
    AC("pot_v", "V", K_DBL, pot_v, 5),
    AC("pot_exp_v", "V", K_DBL, pot_exp_v, 5),
    AC("tol_v", "V", K_DBL, tol_v, 5),
    AC("margin_v", "V", K_DBL, margin_v, 5),
    AC("vcmd_cps", "counts/s", K_DBL, vcmd_cps, 1),
    AC("vel_cps", "counts/s", K_DBL, vel_cps, 1),
    AC("motor_off", "1", K_INT, motor_off, 0),
    AC("moving", "1", K_INT, moving, 0),
    AC("fwd_lim", "1", K_INT, fwd_lim, 0),
    AC("rev_lim", "1", K_INT, rev_lim, 0),
    AC("stop_code", "1", K_INT, stop_code, 0),
};

#define N_REC  (sizeof(rec_cols) / sizeof(rec_cols[0]))
#define N_AXIS (sizeof(axis_cols) / sizeof(axis_cols[0]))

/* Larger magnitudes are written as "nan": a row's length stays bounded. */
#define DBL_LIMIT 1e12
#define FIELD_MAX 24 /* "-999999999999.999999," */

int re_trace_columns(int n_axes)
{
	if (n_axes < 1 || n_axes > RE_TRACE_AXES)
		return 0;
	return (int)(N_REC + (size_t)n_axes * N_AXIS);
}

/* Column @i: its descriptor and its axis (-1 for a record column). */
static const struct col *column(int i, int *axis)
{
	if (i < (int)N_REC) {
		*axis = -1;
		return &rec_cols[i];
	}
	i -= (int)N_REC;
	*axis = i / (int)N_AXIS;
	return &axis_cols[i % (int)N_AXIS];
}

int re_trace_column_name(int i, int n_axes, const char (*axis)[RE_TRACE_NAME],
			 char *buf, size_t cap, char *unit, size_t ucap)
{
	const struct col *c;
	int a;

	if (i < 0 || i >= re_trace_columns(n_axes) || !buf || !axis)
		return GL_ERR_ARG;
	c = column(i, &a);
	if (a < 0)
		snprintf(buf, cap, "%s", c->name);
	else
		snprintf(buf, cap, "%s_%s", axis[a], c->name);
	if (unit)
		snprintf(unit, ucap, "%s", c->unit);
	return GL_OK;
}

static const void *field(const struct re_trace_rec *r, int i)
{
	int a;
	const struct col *c = column(i, &a);
	const char *base = a < 0 ? (const char *)r : (const char *)&r->axis[a];

	return base + c->off;
}

/* ---- CRC-32 (zlib's: reflected 0xEDB88320, init and xor-out ~0) -------- */

static uint32_t crc32_update(uint32_t crc, const char *buf, size_t len)
{
	static const uint32_t nib[16] = {
	    0x00000000, 0x1DB71064, 0x3B6E20C8, 0x26D930AC,
	    0x76DC4190, 0x6B6B51F4, 0x4DB26158, 0x5005713C,
	    0xEDB88320, 0xF00F9344, 0xD6D6A3E8, 0xCB61B38C,
	    0x9B64C2B0, 0x86D3D2D4, 0xA00AE278, 0xBDBDF21C};

	crc = ~crc;
	for (size_t i = 0; i < len; i++) {
		crc ^= (unsigned char)buf[i];
		crc = (crc >> 4) ^ nib[crc & 15];
		crc = (crc >> 4) ^ nib[crc & 15];
	}
	return ~crc;
}

/* ---- writer ------------------------------------------------------------- */

struct out {
	char *buf;
	size_t cap, len;
	int over;
};

static void put(struct out *o, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void put(struct out *o, const char *fmt, ...)
{
	va_list ap;
	int n;

	if (o->over)
		return;
	va_start(ap, fmt);
	n = vsnprintf(o->buf + o->len, o->cap - o->len, fmt, ap);
	va_end(ap);
	if (n < 0 || (size_t)n >= o->cap - o->len) {
		o->over = 1;
		return;
	}
	o->len += (size_t)n;
}

size_t re_trace_max_bytes(size_t n_records, int n_axes)
{
	int cols = re_trace_columns(n_axes);

	if (!cols || n_records > RE_TRACE_MAX_RECORDS)
		return 0;
	/* header lines and the text, the units and names lines, the rows */
	return 2048 + RE_TRACE_TEXT + (size_t)cols * 48 +
	       n_records * ((size_t)cols * FIELD_MAX + 1);
}

/* A word for a header line: printable, no space or comma. */
static int word_ok(const char *s, size_t max)
{
	size_t n = strnlen(s, max);

	if (n == 0 || n == max)
		return 0;
	for (size_t i = 0; i < n; i++)
		if (s[i] <= ' ' || s[i] > '~' || s[i] == ',')
			return 0;
	return 1;
}

/* The fault text: printable, one line. */
static int text_ok(const char *s)
{
	size_t n = strnlen(s, RE_TRACE_TEXT);

	if (n == 0 || n == RE_TRACE_TEXT)
		return 0;
	for (size_t i = 0; i < n; i++)
		if ((unsigned char)s[i] < ' ' || s[i] == 127)
			return 0;
	return 1;
}

static int hdr_ok(const struct re_trace_hdr *h)
{
	if (h->n_axes < 1 || h->n_axes > RE_TRACE_AXES ||
	    !word_ok(h->created, sizeof(h->created)) ||
	    !word_ok(h->reason, sizeof(h->reason)) ||
	    !word_ok(h->serial, sizeof(h->serial)) || !isfinite(h->period_ms) ||
	    h->period_ms <= 0 || h->period_ms >= DBL_LIMIT)
		return 0;
	for (int a = 0; a < h->n_axes; a++)
		if (!word_ok(h->axis[a], RE_TRACE_NAME))
			return 0;
	if (h->have_fault &&
	    (!text_ok(h->fault_text) || !isfinite(h->fault_t_s) ||
	     fabs(h->fault_t_s) >= DBL_LIMIT))
		return 0;
	return 1;
}

static void put_names(struct out *o, const struct re_trace_hdr *h, int units)
{
	char name[64], unit[16];
	int n = re_trace_columns(h->n_axes);

	put(o, "%s", units ? "# units " : "");
	for (int i = 0; i < n; i++) {
		re_trace_column_name(i, h->n_axes, h->axis, name, sizeof(name),
				     unit, sizeof(unit));
		put(o, "%s%s", i ? "," : "", units ? unit : name);
	}
	put(o, "\n");
}

static void put_header(struct out *o, const struct re_trace_hdr *h, size_t n)
{
	put(o, "%s %d\n", RE_TRACE_MAGIC, RE_TRACE_VERSION);
	put(o, "# created %s\n# reason %s\n", h->created, h->reason);
	put(o, "# config_hash %016" PRIx64 "\n", h->config_hash);
	put(o, "# controller_serial %s\n", h->serial);
	put(o, "# period_ms %.3f\n# axes", h->period_ms);
	for (int a = 0; a < h->n_axes; a++)
		put(o, " %s", h->axis[a]);
	put(o, "\n");
	if (h->have_fault)
		put(o, "# fault_t_s %.6f\n# fault_text %s\n", h->fault_t_s,
		    h->fault_text);
	else
		put(o, "# fault_t_s -\n# fault_text -\n");
	put(o, "# records %zu\n", n);
	put_names(o, h, 1);
	put_names(o, h, 0);
}

static void put_row(struct out *o, const struct re_trace_rec *r, int cols)
{
	for (int i = 0; i < cols && !o->over; i++) {
		int a;
		const struct col *c = column(i, &a);
		const void *p = field(r, i);
		const char *sep = i ? "," : "";

		if (c->kind == K_INT) {
			int32_t v;

			memcpy(&v, p, sizeof(v));
			put(o, "%s%" PRId32, sep, v);
		} else {
			double v;

			memcpy(&v, p, sizeof(v));
			if (!isfinite(v) || fabs(v) >= DBL_LIMIT)
				put(o, "%snan", sep);
			else
				put(o, "%s%.*f", sep, c->decimals, v);
		}
	}
	put(o, "\n");
}

int re_trace_write(const struct re_trace_hdr *h,
		   const struct re_trace_rec *ring, size_t ring_cap,
		   size_t first, size_t n, char *buf, size_t cap, size_t *len)
{
	struct out o = {buf, cap, 0, 0};
	int cols;

	if (!h || !buf || !len || (n && (!ring || first >= ring_cap)) ||
	    n > ring_cap || n > RE_TRACE_MAX_RECORDS || !hdr_ok(h))
		return GL_ERR_ARG;
	cols = re_trace_columns(h->n_axes);
	put_header(&o, h, n);
	for (size_t k = 0; k < n && !o.over; k++)
		put_row(&o, &ring[(first + k) % ring_cap], cols);
	if (!o.over)
		put(&o, "# end %zu records crc32 %08" PRIx32 "\n", n,
		    crc32_update(0, buf, o.len));
	if (o.over)
		return GL_ERR_OVERFLOW;
	*len = o.len;
	return GL_OK;
}

/* ---- reader ------------------------------------------------------------- */

struct in {
	const char *buf;
	size_t len, pos;
	long line;     /* number of the current line, 1-based */
	const char *l; /* the current line (not NUL-terminated) */
	size_t ll;     /* its length without the newline */
	size_t start;  /* its offset */
	char *err;
	size_t errlen;
};

static int fail(struct in *in, int rc, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static int fail(struct in *in, int rc, const char *fmt, ...)
{
	char msg[256];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(msg, sizeof(msg), fmt, ap);
	va_end(ap);
	if (in->err && in->errlen)
		snprintf(in->err, in->errlen, "line %ld: %s", in->line, msg);
	return rc;
}

/* The next line, which must end in '\n'. Return: GL_OK, 1 at the end. */
static int next_line(struct in *in)
{
	const char *nl;

	in->line++;
	if (in->pos >= in->len)
		return 1;
	in->start = in->pos;
	in->l = in->buf + in->pos;
	nl = memchr(in->l, '\n', in->len - in->pos);
	if (!nl)
		return fail(in, GL_ERR_FORMAT,
			    "truncated: the last line has no end (byte %zu)",
			    in->len);
	in->ll = (size_t)(nl - in->l);
	if (in->ll > RE_TRACE_LINE_MAX)
		return fail(in, GL_ERR_RANGE,
			    "line longer than %d bytes (byte %zu)",
			    RE_TRACE_LINE_MAX, in->start);
	if (memchr(in->l, '\0', in->ll) || memchr(in->l, '\r', in->ll))
		return fail(in, GL_ERR_FORMAT,
			    "NUL or carriage return in the line (byte %zu)",
			    in->start);
	in->pos += in->ll + 1;
	return GL_OK;
}

/* The next line must be "# @key VALUE": VALUE copied into @val. */
static int header_line(struct in *in, const char *key, char *val, size_t cap)
{
	size_t kl = strlen(key);
	int rc = next_line(in);

	if (rc == 1)
		return fail(in, GL_ERR_FORMAT, "truncated: '# %s' missing",
			    key);
	if (rc)
		return rc;
	if (in->ll < kl + 4 || memcmp(in->l, "# ", 2) ||
	    memcmp(in->l + 2, key, kl) || in->l[kl + 2] != ' ')
		return fail(in, GL_ERR_FORMAT, "expected '# %s VALUE'", key);
	if (in->ll - kl - 3 >= cap)
		return fail(in, GL_ERR_RANGE, "'%s' value too long", key);
	memcpy(val, in->l + kl + 3, in->ll - kl - 3);
	val[in->ll - kl - 3] = '\0';
	return GL_OK;
}

/* Strict numbers: [-]digits[.digits], no spaces, no exponent, no '+'. */
static int num_syntax(const char *s, size_t n, int frac_ok)
{
	size_t i = 0, d = 0;

	if (i < n && s[i] == '-')
		i++;
	for (; i < n && s[i] >= '0' && s[i] <= '9'; i++)
		d++;
	if (!d)
		return 0;
	if (i < n && s[i] == '.' && frac_ok) {
		size_t f = 0;

		for (i++; i < n && s[i] >= '0' && s[i] <= '9'; i++)
			f++;
		if (!f)
			return 0;
	}
	return i == n && n < 32;
}

static int parse_dbl(const char *s, size_t n, double *out)
{
	char tmp[32];

	if (n == 3 && !memcmp(s, "nan", 3)) {
		*out = NAN;
		return 0;
	}
	if (!num_syntax(s, n, 1))
		return -1;
	memcpy(tmp, s, n);
	tmp[n] = '\0';
	*out = strtod(tmp, NULL);
	return isfinite(*out) && fabs(*out) < DBL_LIMIT ? 0 : -1;
}

static int parse_i32(const char *s, size_t n, int32_t *out)
{
	char tmp[32];
	long long v;

	if (!num_syntax(s, n, 0) || n > 11)
		return -1;
	memcpy(tmp, s, n);
	tmp[n] = '\0';
	v = strtoll(tmp, NULL, 10);
	if (v < INT32_MIN || v > INT32_MAX)
		return -1;
	*out = (int32_t)v;
	return 0;
}

/* A word list "A B C" into the axis names. */
static int parse_axes(struct in *in, const char *v, struct re_trace_hdr *h)
{
	h->n_axes = 0;
	while (*v) {
		size_t n = strcspn(v, " ");

		if (h->n_axes == RE_TRACE_AXES || n == 0 || n >= RE_TRACE_NAME)
			return fail(in, GL_ERR_FORMAT, "bad axis list");
		memcpy(h->axis[h->n_axes], v, n);
		h->axis[h->n_axes][n] = '\0';
		if (!word_ok(h->axis[h->n_axes++], RE_TRACE_NAME))
			return fail(in, GL_ERR_FORMAT, "bad axis name");
		v += n;
		if (*v == ' ' && !*++v)
			return fail(in, GL_ERR_FORMAT, "bad axis list");
	}
	if (!h->n_axes)
		return fail(in, GL_ERR_FORMAT, "no axes");
	return GL_OK;
}

static int parse_magic(struct in *in, struct re_trace_hdr *h)
{
	char v[64];
	int rc = next_line(in);

	if (rc == 1)
		return fail(in, GL_ERR_FORMAT, "empty file: not a trace");
	if (rc)
		return rc;
	if (in->ll < sizeof(RE_TRACE_MAGIC) ||
	    memcmp(in->l, RE_TRACE_MAGIC " ", sizeof(RE_TRACE_MAGIC)))
		return fail(in, GL_ERR_FORMAT,
			    "not a roboelf trace (no '%s' line)",
			    RE_TRACE_MAGIC);
	snprintf(v, sizeof(v), "%.*s", (int)(in->ll - sizeof(RE_TRACE_MAGIC)),
		 in->l + sizeof(RE_TRACE_MAGIC));
	if (strcmp(v, "1"))
		return fail(in, GL_ERR_FORMAT,
			    "trace format version '%.16s', this roboelf "
			    "reads version %d",
			    v, RE_TRACE_VERSION);
	h->version = RE_TRACE_VERSION;
	return GL_OK;
}

/* A value that must be a word (created, reason, serial). */
static int word_field(struct in *in, const char *key, char *dst, size_t cap)
{
	int rc = header_line(in, key, dst, cap);

	if (!rc && !word_ok(dst, cap))
		return fail(in, GL_ERR_FORMAT, "bad '%s' value", key);
	return rc;
}

static int parse_fault(struct in *in, struct re_trace_hdr *h)
{
	char v[RE_TRACE_TEXT];
	int rc = header_line(in, "fault_t_s", v, sizeof(v));

	if (rc)
		return rc;
	h->have_fault = strcmp(v, "-") != 0;
	if (h->have_fault && parse_dbl(v, strlen(v), &h->fault_t_s) < 0)
		return fail(in, GL_ERR_FORMAT, "bad fault_t_s '%.32s'", v);
	rc =
	    header_line(in, "fault_text", h->fault_text, sizeof(h->fault_text));
	if (rc)
		return rc;
	if (!h->have_fault && strcmp(h->fault_text, "-"))
		return fail(in, GL_ERR_FORMAT, "fault_text without fault_t_s");
	if (h->have_fault && !text_ok(h->fault_text))
		return fail(in, GL_ERR_FORMAT, "bad fault_text");
	if (!h->have_fault)
		h->fault_text[0] = '\0';
	return GL_OK;
}

static int parse_count(struct in *in, struct re_trace_hdr *h)
{
	char v[32];
	int32_t n;
	int rc = header_line(in, "records", v, sizeof(v));

	if (rc)
		return rc;
	if (parse_i32(v, strlen(v), &n) < 0 || n < 0)
		return fail(in, GL_ERR_FORMAT, "bad record count '%s'", v);
	if (n > RE_TRACE_MAX_RECORDS)
		return fail(in, GL_ERR_RANGE,
			    "%" PRId32 " records: more than the limit %d", n,
			    RE_TRACE_MAX_RECORDS);
	/* every row holds at least one byte per column */
	if ((size_t)n * (size_t)re_trace_columns(h->n_axes) > in->len)
		return fail(in, GL_ERR_FORMAT,
			    "truncated: %" PRId32 " records cannot fit in "
			    "%zu bytes",
			    n, in->len);
	h->n_records = (uint32_t)n;
	return GL_OK;
}

/* The units and the names lines must be exactly what this version writes. */
static int parse_columns(struct in *in, const struct re_trace_hdr *h)
{
	char want[RE_TRACE_LINE_MAX + 2];
	struct out o = {want, sizeof(want), 0, 0};

	for (int units = 1; units >= 0; units--) {
		int rc = next_line(in);

		if (rc == 1)
			return fail(in, GL_ERR_FORMAT,
				    "truncated: the column list is missing");
		if (rc)
			return rc;
		o.len = 0;
		o.over = 0;
		put_names(&o, h, units);
		if (o.over || o.len - 1 != in->ll ||
		    memcmp(want, in->l, in->ll))
			return fail(in, GL_ERR_FORMAT,
				    "the %s line is not the one of version "
				    "%d with axes as declared",
				    units ? "units" : "column names",
				    RE_TRACE_VERSION);
	}
	return GL_OK;
}

static int parse_header(struct in *in, struct re_trace_hdr *h)
{
	char v[RE_TRACE_LINE_MAX + 1];
	int rc;

	if ((rc = parse_magic(in, h)) ||
	    (rc = word_field(in, "created", h->created, sizeof(h->created))) ||
	    (rc = word_field(in, "reason", h->reason, sizeof(h->reason))) ||
	    (rc = header_line(in, "config_hash", v, sizeof(v))))
		return rc;
	if (strlen(v) != 16 || strspn(v, "0123456789abcdef") != 16)
		return fail(in, GL_ERR_FORMAT, "bad config_hash");
	h->config_hash = strtoull(v, NULL, 16);
	if ((rc = word_field(in, "controller_serial", h->serial,
			     sizeof(h->serial))) ||
	    (rc = header_line(in, "period_ms", v, sizeof(v))))
		return rc;
	if (parse_dbl(v, strlen(v), &h->period_ms) < 0 || !(h->period_ms > 0))
		return fail(in, GL_ERR_FORMAT, "bad period_ms");
	if ((rc = header_line(in, "axes", v, sizeof(v))) ||
	    (rc = parse_axes(in, v, h)) || (rc = parse_fault(in, h)) ||
	    (rc = parse_count(in, h)))
		return rc;
	return parse_columns(in, h);
}

static int parse_row(struct in *in, int cols, struct re_trace_rec *r)
{
	const char *p = in->l, *end = in->l + in->ll;

	for (int i = 0; i < cols; i++) {
		int a;
		const struct col *c = column(i, &a);
		const char *q = memchr(p, ',', (size_t)(end - p));
		size_t n = (size_t)((q ? q : end) - p);
		void *dst = (char *)field(r, i);
		int bad;

		if ((i < cols - 1) != (q != NULL))
			return fail(in, GL_ERR_FORMAT, "%s columns (want %d)",
				    q ? "too many" : "too few", cols);
		if (c->kind == K_INT) {
			int32_t v;

			bad = parse_i32(p, n, &v) < 0;
			memcpy(dst, &v, sizeof(v));
		} else {
			double v = 0;

			bad = parse_dbl(p, n, &v) < 0;
			memcpy(dst, &v, sizeof(v));
		}
		if (bad)
			return fail(in, GL_ERR_FORMAT,
				    "column %d: bad value '%.*s'", i + 1,
				    (int)(n < 24 ? n : 24), p);
		p = q ? q + 1 : end;
	}
	return GL_OK;
}

static int parse_end(struct in *in, const struct re_trace_hdr *h)
{
	char want[96];
	uint32_t crc = crc32_update(0, in->buf, in->pos);
	int n, rc = next_line(in);

	if (rc == 1)
		return fail(in, GL_ERR_FORMAT,
			    "truncated: %u records and no end line",
			    h->n_records);
	if (rc)
		return rc;
	if (in->ll < 6 || memcmp(in->l, "# end ", 6))
		return fail(in, GL_ERR_FORMAT,
			    "more rows than the %u declared, or no end line",
			    h->n_records);
	n = snprintf(want, sizeof(want), "# end %u records crc32 %08" PRIx32,
		     h->n_records, crc);
	if ((size_t)n != in->ll || memcmp(want, in->l, in->ll)) {
		if (strncmp(in->l, want,
			    (size_t)(strstr(want, "crc32") - want)))
			return fail(in, GL_ERR_FORMAT,
				    "end line does not say '%.*s'",
				    (int)(strstr(want, " crc32") - want), want);
		return fail(in, GL_ERR_CRC,
			    "checksum differs (the file was changed): the "
			    "content's crc32 is %08" PRIx32,
			    crc);
	}
	if (in->pos != in->len)
		return fail(in, GL_ERR_FORMAT,
			    "data after the end line (byte %zu)", in->pos);
	return GL_OK;
}

static int parse_rows(struct in *in, const struct re_trace_hdr *h,
		      struct re_trace_rec *recs)
{
	int cols = re_trace_columns(h->n_axes);

	for (uint32_t k = 0; k < h->n_records; k++) {
		int rc = next_line(in);

		if (rc == 1)
			return fail(in, GL_ERR_FORMAT,
				    "truncated: %u of %u records", k,
				    h->n_records);
		if (rc)
			return rc;
		if (in->ll && in->l[0] == '#')
			return fail(in, GL_ERR_FORMAT,
				    "%u records where %u are declared", k,
				    h->n_records);
		rc = parse_row(in, cols, &recs[k]);
		if (rc)
			return rc;
	}
	return GL_OK;
}

int re_trace_parse(const char *buf, size_t len, struct re_trace_hdr *h,
		   struct re_trace_rec **recs, char *err, size_t errlen)
{
	struct in in = {buf, len, 0, 0, NULL, 0, 0, err, errlen};
	struct re_trace_rec *r = NULL;
	int rc;

	if (recs)
		*recs = NULL;
	if (!buf || !h || !recs)
		return GL_ERR_ARG;
	memset(h, 0, sizeof(*h));
	if (len > RE_TRACE_MAX_BYTES) {
		if (err && errlen)
			snprintf(err, errlen,
				 "byte %zu: larger than the limit of %u bytes",
				 (size_t)RE_TRACE_MAX_BYTES,
				 RE_TRACE_MAX_BYTES);
		return GL_ERR_RANGE;
	}
	rc = parse_header(&in, h);
	if (rc)
		return rc;
	if (h->n_records) {
		r = calloc(h->n_records, sizeof(*r));
		if (!r)
			return fail(&in, GL_ERR_NOMEM, "%s", strerror(ENOMEM));
	}
	rc = parse_rows(&in, h, r);
	if (!rc)
		rc = parse_end(&in, h);
	if (rc) {
		free(r);
		return rc;
	}
	*recs = r;
	return GL_OK;
}
