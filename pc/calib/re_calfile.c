/*
 * re_calfile.c - calibration file: format, parse, atomic save, load.
 *
 * The format is in docs/calibration-file.md. Numbers are written with the
 * shortest "%.Ng" (N = 15..17) that reads back to the same double, so a
 * save/load round trip is exact. The C locale is assumed (the supervisor
 * never calls setlocale()).
 */
#include "re_calfile.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base_durable.h"
#include "base_file.h"
#include "gl_err.h"

#define RE_CALFILE_MAGIC    "roboelf-calibration"
#define RE_CALFILE_PER_LINE 8	/* potentiometer values per "pot" line */
#define RE_CALFILE_LINE_MAX 512 /* longest line accepted, bytes */

void (*re_calfile_save_hook)(int step);

/* ---- small helpers -------------------------------------------------------*/

/*
 * CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320, initial and final
 * value 0xFFFFFFFF) - the same as zlib's crc32(). Bitwise: a 1 MiB file takes
 * a few ms at start-up, and libre needs no extra link dependency. Checked in
 * the tests against the standard check value crc("123456789") = 0xCBF43926.
 */
static uint32_t re_crc32(const char *buf, size_t len)
{
	uint32_t crc = 0xFFFFFFFFu;
	size_t i;
	int b;

	for (i = 0; i < len; i++) {
		crc ^= (unsigned char)buf[i];
		for (b = 0; b < 8; b++)
			crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
	}
	return crc ^ 0xFFFFFFFFu;
}

static void re_err(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void re_err(char *err, size_t errlen, const char *fmt, ...)
{
	va_list ap;

	if (!err || errlen == 0)
		return;
	va_start(ap, fmt);
	vsnprintf(err, errlen, fmt, ap);
	va_end(ap);
}

static int re_name_ok(const char *s)
{
	size_t n = strnlen(s, RE_CAL_NAME_MAX);

	if (n == 0 || n >= RE_CAL_NAME_MAX)
		return 0;
	for (; *s; s++)
		if (!((*s >= 'A' && *s <= 'Z') || (*s >= 'a' && *s <= 'z') ||
		      (*s >= '0' && *s <= '9') || *s == '_' || *s == '-'))
			return 0;
	return 1;
}

static int re_serial_ok(const char *s)
{
	size_t n = strnlen(s, RE_CAL_SERIAL_MAX);

	if (n == 0 || n >= RE_CAL_SERIAL_MAX)
		return 0;
	for (; *s; s++)
		if (*s <= ' ' || *s > '~')
			return 0;
	return 1;
}

/* "YYYY-MM-DDTHH:MM:SSZ" exactly (digits where digits belong). */
static int re_date_ok(const char *s)
{
	static const char pat[] = "dddd-dd-ddTdd:dd:ddZ";
	size_t i;

	if (strnlen(s, RE_CAL_DATE_MAX) != sizeof(pat) - 1)
		return 0;
	for (i = 0; i < sizeof(pat) - 1; i++)
		if (pat[i] == 'd' ? (s[i] < '0' || s[i] > '9') : s[i] != pat[i])
			return 0;
	return 1;
}

/* Shortest of %.15g, %.16g, %.17g that reads back exactly. */
static void re_fmt_double(char *tmp, size_t cap, double v)
{
	int prec;

	for (prec = 15; prec < 17; prec++) {
		snprintf(tmp, cap, "%.*g", prec, v);
		if (strtod(tmp, NULL) == v)
			return;
	}
	snprintf(tmp, cap, "%.17g", v);
}

int re_calfile_date(time_t t, char *buf, size_t cap)
{
	struct tm tm;

	if (!buf)
		return GL_ERR_ARG;
	if (!gmtime_r(&t, &tm))
		return GL_ERR_RANGE;
	if (cap < 21 || strftime(buf, cap, "%Y-%m-%dT%H:%M:%SZ", &tm) != 20)
		return cap ? (buf[0] = '\0', GL_ERR_OVERFLOW) : GL_ERR_OVERFLOW;
	return GL_OK;
}

/* ---- format --------------------------------------------------------------*/

struct re_wbuf {
	char *buf;
	size_t cap;
	size_t len;
	int over;
};

static void re_put(struct re_wbuf *w, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void re_put(struct re_wbuf *w, const char *fmt, ...)
{
	va_list ap;
	int n;

	if (w->over)
		return;
	va_start(ap, fmt);
	n = vsnprintf(w->buf + w->len, w->cap - w->len, fmt, ap);
	va_end(ap);
	if (n < 0 || (size_t)n >= w->cap - w->len) {
		w->over = 1;
		return;
	}
	w->len += (size_t)n;
}

static int re_table_valid(const struct re_caltable *t)
{
	int k;

	if (t->n < 2 || t->n > RE_CAL_MAX_POINTS || !isfinite(t->step_counts) ||
	    t->step_counts <= 0 || !isfinite(t->start_counts) ||
	    !isfinite(t->soft_rev) || !isfinite(t->soft_fwd))
		return 0;
	for (k = 0; k < t->n; k++)
		if (!isfinite(t->pot_v[k]))
			return 0;
	return 1;
}

static int re_set_valid(const struct re_calset *set)
{
	int a;

	if (set->n_axes < 1 || set->n_axes > RE_CAL_MAX_AXES ||
	    !re_serial_ok(set->serial) || !re_date_ok(set->date))
		return 0;
	for (a = 0; a < set->n_axes; a++)
		if (!re_name_ok(set->name[a]) || !re_table_valid(&set->axis[a]))
			return 0;
	return 1;
}

static void re_put_num(struct re_wbuf *w, const char *key, double v)
{
	char tmp[40];

	re_fmt_double(tmp, sizeof(tmp), v);
	re_put(w, "%s %s\n", key, tmp);
}

static void re_format_axis(struct re_wbuf *w, const char *name,
			   const struct re_caltable *t)
{
	char tmp[40];
	int k;

	re_put(w, "axis %s\n", name);
	re_put_num(w, "step", t->step_counts);
	re_put_num(w, "start", t->start_counts);
	re_put_num(w, "soft-rev", t->soft_rev);
	re_put_num(w, "soft-fwd", t->soft_fwd);
	re_put(w, "points %d\n", t->n);
	for (k = 0; k < t->n; k++) {
		re_fmt_double(tmp, sizeof(tmp), t->pot_v[k]);
		re_put(w, "%s%s", k % RE_CALFILE_PER_LINE ? " " : "pot ", tmp);
		if (k % RE_CALFILE_PER_LINE == RE_CALFILE_PER_LINE - 1 ||
		    k == t->n - 1)
			re_put(w, "\n");
	}
}

size_t re_calfile_format_size(const struct re_calset *set)
{
	size_t size = 1024;
	int a, n;

	if (!set || set->n_axes < 1 || set->n_axes > RE_CAL_MAX_AXES)
		return size;
	for (a = 0; a < set->n_axes; a++) {
		n = set->axis[a].n;
		if (n < 0 || n > RE_CAL_MAX_POINTS)
			n = RE_CAL_MAX_POINTS;
		/* 24 chars + separator per value, "pot \n" per line */
		size += 256 + (size_t)n * 25 +
			(size_t)(n / RE_CALFILE_PER_LINE + 1) * 5;
	}
	return size;
}

int re_calfile_format(const struct re_calset *set, char *buf, size_t cap)
{
	struct re_wbuf w = {buf, cap, 0, 0};
	int a;

	if (!set || !buf || cap == 0)
		return GL_ERR_ARG;
	buf[0] = '\0';
	if (!re_set_valid(set))
		return GL_ERR_ARG;
	re_put(&w, "# RoboELF calibration tables; format in "
		   "docs/calibration-file.md\n");
	re_put(&w, "# do not edit: the crc32 line protects the content\n");
	re_put(&w, "%s %d\n", RE_CALFILE_MAGIC, RE_CALFILE_VERSION);
	re_put(&w, "serial %s\n", set->serial);
	re_put(&w, "date %s\n", set->date);
	re_put(&w, "config-hash %016llx\n",
	       (unsigned long long)set->config_hash);
	re_put(&w, "axes %d\n", set->n_axes);
	for (a = 0; a < set->n_axes; a++)
		re_format_axis(&w, set->name[a], &set->axis[a]);
	if (!w.over)
		re_put(&w, "crc32 %08lx\n",
		       (unsigned long)re_crc32(buf, w.len));
	if (w.over) {
		buf[0] = '\0';
		return GL_ERR_OVERFLOW;
	}
	return (int)w.len;
}

/* ---- parse ---------------------------------------------------------------*/

struct re_parser {
	const char *buf;
	size_t len;
	size_t pos;
	int line; /* number of the line in line[] */
	const char *file;
	char *err;
	size_t errlen;
	char text[RE_CALFILE_LINE_MAX]; /* the current line, NUL-terminated */
	char *args;			/* after the keyword and one space */
};

static int re_perr(struct re_parser *p, int rc, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static int re_perr(struct re_parser *p, int rc, const char *fmt, ...)
{
	char msg[256];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(msg, sizeof(msg), fmt, ap);
	va_end(ap);
	re_err(p->err, p->errlen, "%s:%d: %s", p->file, p->line, msg);
	return rc;
}

/* Read the next line into p->text; GL_ERR_FORMAT at the end or if too long. */
static int re_next_line(struct re_parser *p)
{
	const char *nl;
	size_t n;

	p->line++;
	if (p->pos >= p->len)
		return re_perr(p, GL_ERR_FORMAT, "truncated: unexpected end");
	nl = memchr(p->buf + p->pos, '\n', p->len - p->pos);
	n = (size_t)(nl - (p->buf + p->pos)); /* nl exists: checked upfront */
	if (n >= sizeof(p->text))
		return re_perr(p, GL_ERR_FORMAT, "line too long (%zu bytes)",
			       n);
	memcpy(p->text, p->buf + p->pos, n);
	p->text[n] = '\0';
	if (strlen(p->text) != n)
		return re_perr(p, GL_ERR_FORMAT, "NUL byte in line");
	p->pos += n + 1;
	return GL_OK;
}

/* Next line must be "<key> <args>"; p->args points at the arguments. */
static int re_expect_key(struct re_parser *p, const char *key)
{
	size_t k = strlen(key);
	int rc = re_next_line(p);

	if (rc != GL_OK)
		return rc;
	if (strncmp(p->text, key, k) != 0 || p->text[k] != ' ' ||
	    p->text[k + 1] == '\0') {
		char *sp = strchr(p->text, ' ');

		if (sp)
			*sp = '\0';
		return re_perr(p, GL_ERR_FORMAT, "expected '%s', found '%s'",
			       key, p->text);
	}
	p->args = p->text + k + 1;
	return GL_OK;
}

/* A strict decimal number: digits, sign, '.', exponent; no inf/nan/hex. */
static int re_parse_num(struct re_parser *p, const char *tok, double *out)
{
	const char *c;
	char *end;

	for (c = tok; *c; c++)
		if (!strchr("0123456789+-.eE", *c))
			break;
	errno = 0;
	*out = strtod(tok, &end);
	if (*c || c == tok || *end || errno == ERANGE || !isfinite(*out))
		return re_perr(p, GL_ERR_FORMAT, "invalid number '%s'", tok);
	return GL_OK;
}

static int re_parse_int(struct re_parser *p, const char *tok, long lo, long hi,
			int *out)
{
	char *end;
	long v;

	errno = 0;
	v = strtol(tok, &end, 10);
	if (tok[0] < '0' || tok[0] > '9' || *end || errno)
		return re_perr(p, GL_ERR_FORMAT, "invalid integer '%s'", tok);
	if (v < lo || v > hi)
		return re_perr(p, GL_ERR_FORMAT, "%ld out of range %ld..%ld", v,
			       lo, hi);
	*out = (int)v;
	return GL_OK;
}

static int re_key_num(struct re_parser *p, const char *key, double *out)
{
	int rc = re_expect_key(p, key);

	return rc != GL_OK ? rc : re_parse_num(p, p->args, out);
}

/* "pot v v v ..." lines until t->n values; exactly 8 per full line. */
static int re_parse_pots(struct re_parser *p, struct re_caltable *t)
{
	char *tok, *save;
	int k = 0, want, got, rc;

	while (k < t->n) {
		want = t->n - k < RE_CALFILE_PER_LINE ? t->n - k
						      : RE_CALFILE_PER_LINE;
		rc = re_expect_key(p, "pot");
		if (rc != GL_OK)
			return rc;
		got = 0;
		for (tok = strtok_r(p->args, " ", &save); tok;
		     tok = strtok_r(NULL, " ", &save)) {
			if (got == want)
				return re_perr(p, GL_ERR_FORMAT,
					       "more than %d values", want);
			rc = re_parse_num(p, tok, &t->pot_v[k + got]);
			if (rc != GL_OK)
				return rc;
			got++;
		}
		if (got != want)
			return re_perr(p, GL_ERR_FORMAT,
				       "%d values, expected %d", got, want);
		k += got;
	}
	return GL_OK;
}

/* Line numbers of entries, for messages after parsing. */
struct re_axis_lines {
	int axis, step, soft, points;
};

struct re_hdr_lines {
	int serial, hash, axes;
};

static int re_parse_axis(struct re_parser *p, struct re_calset *out, int a,
			 struct re_axis_lines *ln)
{
	struct re_caltable *t = &out->axis[a];
	int rc;

	rc = re_expect_key(p, "axis");
	if (rc != GL_OK)
		return rc;
	if (!re_name_ok(p->args))
		return re_perr(p, GL_ERR_FORMAT, "invalid axis name '%s'",
			       p->args);
	snprintf(out->name[a], sizeof(out->name[a]), "%s", p->args);
	ln->axis = p->line;
	if ((rc = re_key_num(p, "step", &t->step_counts)) != GL_OK)
		return rc;
	ln->step = p->line;
	if (t->step_counts <= 0)
		return re_perr(p, GL_ERR_FORMAT, "step must be > 0");
	if ((rc = re_key_num(p, "start", &t->start_counts)) != GL_OK ||
	    (rc = re_key_num(p, "soft-rev", &t->soft_rev)) != GL_OK)
		return rc;
	ln->soft = p->line;
	if ((rc = re_key_num(p, "soft-fwd", &t->soft_fwd)) != GL_OK ||
	    (rc = re_expect_key(p, "points")) != GL_OK ||
	    (rc = re_parse_int(p, p->args, 2, RE_CAL_MAX_POINTS, &t->n)))
		return rc;
	ln->points = p->line;
	return re_parse_pots(p, t);
}

static int re_parse_hash(struct re_parser *p, uint64_t *out)
{
	size_t i;

	if (strlen(p->args) != 16)
		return re_perr(p, GL_ERR_FORMAT,
			       "config-hash must be 16 hex "
			       "digits");
	*out = 0;
	for (i = 0; i < 16; i++) {
		char c = p->args[i];
		int d = c >= '0' && c <= '9'   ? c - '0'
			: c >= 'a' && c <= 'f' ? c - 'a' + 10
					       : -1;

		if (d < 0)
			return re_perr(p, GL_ERR_FORMAT,
				       "config-hash must be "
				       "16 lower-case hex digits");
		*out = *out << 4 | (uint64_t)d;
	}
	return GL_OK;
}

static int re_parse_header(struct re_parser *p, struct re_calset *out,
			   struct re_hdr_lines *hl)
{
	int rc, version;

	do { /* comment lines only at the top */
		rc = re_next_line(p);
		if (rc != GL_OK)
			return rc;
	} while (p->text[0] == '#');
	p->line--;
	p->pos -= strlen(p->text) + 1;
	if ((rc = re_expect_key(p, RE_CALFILE_MAGIC)) != GL_OK ||
	    (rc = re_parse_int(p, p->args, 0, INT_MAX, &version)) != GL_OK)
		return rc;
	if (version != RE_CALFILE_VERSION)
		return re_perr(p, GL_ERR_FORMAT,
			       "unsupported format version "
			       "%d (expected %d)",
			       version, RE_CALFILE_VERSION);
	if ((rc = re_expect_key(p, "serial")) != GL_OK)
		return rc;
	if (!re_serial_ok(p->args))
		return re_perr(p, GL_ERR_FORMAT, "invalid serial number");
	hl->serial = p->line;
	snprintf(out->serial, sizeof(out->serial), "%s", p->args);
	if ((rc = re_expect_key(p, "date")) != GL_OK)
		return rc;
	if (!re_date_ok(p->args))
		return re_perr(p, GL_ERR_FORMAT,
			       "invalid date '%s' (expected "
			       "YYYY-MM-DDTHH:MM:SSZ)",
			       p->args);
	snprintf(out->date, sizeof(out->date), "%s", p->args);
	if ((rc = re_expect_key(p, "config-hash")) != GL_OK ||
	    (rc = re_parse_hash(p, &out->config_hash)) != GL_OK)
		return rc;
	hl->hash = p->line;
	if ((rc = re_expect_key(p, "axes")) != GL_OK)
		return rc;
	hl->axes = p->line;
	return re_parse_int(p, p->args, 1, RE_CAL_MAX_AXES, &out->n_axes);
}

/*
 * The last line must be "crc32 XXXXXXXX\n" and match the CRC of everything
 * before it. Sets p->len to the length of the protected part.
 */
static int re_check_crc(struct re_parser *p)
{
	const char *last;
	size_t start, i;
	unsigned long want;
	char *end;
	uint32_t got;

	p->line = 1;
	for (start = 0; start + 1 < p->len; start++)
		if (p->buf[start] == '\n')
			p->line++;
	if (p->len == 0 || p->buf[p->len - 1] != '\n')
		return re_perr(p, GL_ERR_FORMAT,
			       "truncated: no newline at the "
			       "end of the file");
	for (start = p->len - 1; start > 0 && p->buf[start - 1] != '\n';)
		start--;
	last = p->buf + start;
	if (p->len - start != 15 || strncmp(last, "crc32 ", 6) != 0)
		return re_perr(p, GL_ERR_FORMAT,
			       "truncated: the last line is "
			       "not the 'crc32' line");
	for (i = 6; i < 14; i++)
		if (!((last[i] >= '0' && last[i] <= '9') ||
		      (last[i] >= 'a' && last[i] <= 'f')))
			return re_perr(p, GL_ERR_FORMAT, "invalid crc32 line");
	want = strtoul(last + 6, &end, 16);
	got = re_crc32(p->buf, start);
	if (got != want)
		return re_perr(p, GL_ERR_CRC,
			       "bad CRC: the file says %08lx, "
			       "its content gives %08lx",
			       want, (unsigned long)got);
	p->len = start;
	return GL_OK;
}

/* ---- matching and table checks -------------------------------------------*/

static int re_match(struct re_parser *p, const struct re_calfile_expect *exp,
		    const struct re_calset *set, const struct re_hdr_lines *hl,
		    const struct re_axis_lines *ln)
{
	int a;

	p->line = hl->serial;
	if (strcmp(set->serial, exp->serial) != 0)
		return re_perr(p, GL_ERR_MISMATCH,
			       "calibrated on controller "
			       "'%s', this controller is '%s'",
			       set->serial, exp->serial);
	p->line = hl->axes;
	if (set->n_axes != exp->n_axes)
		return re_perr(p, GL_ERR_MISMATCH,
			       "%d axes in the file, the "
			       "configuration has %d",
			       set->n_axes, exp->n_axes);
	for (a = 0; a < set->n_axes; a++) {
		p->line = ln[a].axis;
		if (exp->name[a][0] && strcmp(exp->name[a], set->name[a]))
			return re_perr(p, GL_ERR_MISMATCH,
				       "axis %d is '%s' in "
				       "the file, '%s' in the configuration",
				       a + 1, set->name[a], exp->name[a]);
		p->line = ln[a].step;
		if (set->axis[a].step_counts != exp->step_counts[a])
			return re_perr(p, GL_ERR_MISMATCH,
				       "axis %s: step %g "
				       "counts in the file, %g in the "
				       "configuration",
				       set->name[a], set->axis[a].step_counts,
				       exp->step_counts[a]);
	}
	return GL_OK;
}

/* Line of the first problem named by a table-check fault. */
static int re_fault_line(const struct re_fault *f,
			 const struct re_axis_lines *ln)
{
	switch (f->id) {
	case RE_F_CAL_NONMONO:
		return ln->points + 1 + (int)(f->i[0] / RE_CALFILE_PER_LINE);
	case RE_F_CAL_LIMITS: return ln->soft;
	default: return ln->points;
	}
}

static int re_check_tables(struct re_parser *p,
			   const struct re_calfile_expect *exp,
			   const struct re_calset *set,
			   const struct re_axis_lines *ln)
{
	const char *names[RE_CAL_MAX_AXES];
	struct re_calcheck_cfg c;
	struct re_fault f;
	char what[256];
	int a, v;

	for (a = 0; a < set->n_axes; a++)
		names[a] = set->name[a];
	for (a = 0; a < set->n_axes; a++) {
		const struct re_caltable *t = &set->axis[a];

		if (exp) {
			c = exp->check[a];
		} else { /* intrinsic: strictly increasing, limits */
			memset(&c, 0, sizeof(c));
			c.expected_range_v = t->pot_v[t->n - 1] - t->pot_v[0];
			if (!(c.expected_range_v > 0))
				c.expected_range_v = 1;
			c.range_tol = 1e9;
			c.min_points = 2;
			c.max_points = RE_CAL_MAX_POINTS;
		}
		v = re_cal_check_table(&c, a, t, &f);
		if (v == GL_ERR_ARG) { /* a caller bug, not the file's */
			re_err(p->err, p->errlen,
			       "invalid table check configuration for axis %s",
			       set->name[a]);
			return GL_ERR_ARG;
		}
		if (v == RE_OK)
			continue;
		re_fault_what(&f, names, what, sizeof(what));
		p->line = re_fault_line(&f, &ln[a]);
		return re_perr(p, GL_ERR_RANGE, "%s", what);
	}
	return GL_OK;
}

static int re_parse_all(struct re_parser *p,
			const struct re_calfile_expect *exp,
			struct re_calset *out)
{
	struct re_axis_lines ln[RE_CAL_MAX_AXES] = {{0, 0, 0, 0}};
	struct re_hdr_lines hl = {0, 0, 0};
	int a, rc;

	rc = re_check_crc(p);
	if (rc != GL_OK)
		return rc;
	p->line = 0;
	rc = re_parse_header(p, out, &hl);
	if (rc != GL_OK)
		return rc;
	for (a = 0; a < out->n_axes; a++) {
		rc = re_parse_axis(p, out, a, &ln[a]);
		if (rc != GL_OK)
			return rc;
	}
	if (p->pos != p->len) {
		rc = re_next_line(p);
		return rc ? rc
			  : re_perr(p, GL_ERR_FORMAT,
				    "unexpected line "
				    "before the crc32 line");
	}
	if (exp) {
		rc = re_match(p, exp, out, &hl, ln);
		if (rc != GL_OK)
			return rc;
		p->line = hl.hash;
		if (out->config_hash != exp->config_hash)
			return re_perr(p, GL_ERR_MISMATCH,
				       "made with another "
				       "configuration (config-hash %016llx, "
				       "expected %016llx)",
				       (unsigned long long)out->config_hash,
				       (unsigned long long)exp->config_hash);
	}
	return re_check_tables(p, exp, out, ln);
}

int re_calfile_parse(const char *buf, size_t len, const char *filename,
		     const struct re_calfile_expect *exp, struct re_calset *out,
		     char *err, size_t errlen)
{
	struct re_parser p;
	int rc;

	if (err && errlen)
		err[0] = '\0';
	if (!out)
		return GL_ERR_ARG;
	memset(out, 0, sizeof(*out));
	if (!buf || !filename ||
	    (exp && (!exp->serial || exp->n_axes < 1 ||
		     exp->n_axes > RE_CAL_MAX_AXES))) {
		re_err(err, errlen, "invalid arguments");
		return GL_ERR_ARG;
	}
	memset(&p, 0, sizeof(p));
	p.buf = buf;
	p.len = len;
	p.file = filename;
	p.err = err;
	p.errlen = errlen;
	rc = re_parse_all(&p, exp, out);
	if (rc != GL_OK)
		memset(out, 0, sizeof(*out));
	return rc;
}

/* ---- save and load -------------------------------------------------------*/

static void re_hook(int step)
{
	if (re_calfile_save_hook)
		re_calfile_save_hook(step);
}

/* Write @buf to @tmp and fsync it. */
static int re_write_tmp(const char *tmp, const char *buf, size_t len, char *err,
			size_t errlen)
{
	int fd, e;

	fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
	if (fd < 0) {
		e = errno;
		re_err(err, errlen, "cannot create '%s': %s", tmp, strerror(e));
		errno = e;
		return GL_ERR_SYS;
	}
	if (base_write_all(fd, buf, len) != 0 || fsync(fd) != 0) {
		e = errno;
		close(fd);
		unlink(tmp);
		re_err(err, errlen, "cannot write '%s': %s", tmp, strerror(e));
		errno = e;
		return GL_ERR_SYS;
	}
	if (close(fd) != 0) {
		e = errno;
		unlink(tmp);
		re_err(err, errlen, "cannot write '%s': %s", tmp, strerror(e));
		errno = e;
		return GL_ERR_SYS;
	}
	return GL_OK;
}

/*
 * Keep the current @path as @bak without ever removing @path: hard-link it
 * to @baktmp, then rename that over @bak (atomic replacement of the backup).
 */
static int re_keep_backup(const char *path, const char *bak, const char *baktmp,
			  char *err, size_t errlen)
{
	int e;

	if (unlink(baktmp) != 0 && errno != ENOENT)
		goto fail;
	if (link(path, baktmp) != 0) {
		if (errno == ENOENT)
			return GL_OK; /* first save: nothing to keep */
		goto fail;
	}
	if (rename(baktmp, bak) != 0)
		goto fail_unlink;
	return GL_OK;
fail_unlink:
	e = errno;
	unlink(baktmp);
	errno = e;
fail:
	e = errno;
	re_err(err, errlen, "cannot keep '%s' as '%s': %s", path, bak,
	       strerror(e));
	errno = e;
	return GL_ERR_SYS;
}

struct re_save_names {
	char tmp[PATH_MAX], bak[PATH_MAX], baktmp[PATH_MAX];
};

static int re_save_names_make(struct re_save_names *nm, const char *path)
{
	size_t n = strlen(path);

	if (n == 0 || n + 9 >= PATH_MAX || path[n - 1] == '/')
		return GL_ERR_ARG;
	snprintf(nm->tmp, sizeof(nm->tmp), "%s.tmp", path);
	snprintf(nm->bak, sizeof(nm->bak), "%s.bak", path);
	snprintf(nm->baktmp, sizeof(nm->baktmp), "%s.bak.tmp", path);
	return GL_OK;
}

static int re_save_text(const char *path, const char *text, size_t len,
			char *err, size_t errlen)
{
	struct re_save_names nm;
	int rc, e;

	if (re_save_names_make(&nm, path) != GL_OK) {
		re_err(err, errlen, "invalid path '%s'", path);
		return GL_ERR_ARG;
	}
	rc = re_write_tmp(nm.tmp, text, len, err, errlen);
	if (rc != GL_OK)
		return rc;
	re_hook(1);
	rc = re_keep_backup(path, nm.bak, nm.baktmp, err, errlen);
	if (rc != GL_OK)
		goto remove_tmp;
	re_hook(2);
	if (rename(nm.tmp, path) != 0) {
		e = errno;
		re_err(err, errlen, "cannot rename '%s' to '%s': %s", nm.tmp,
		       path, strerror(e));
		errno = e;
		rc = GL_ERR_SYS;
		goto remove_tmp;
	}
	re_hook(3);
	if (base_fsync_dir(path) != 0) {
		e = errno;
		re_err(err, errlen, "cannot sync the directory of '%s': %s",
		       path, strerror(e));
		errno = e;
		return GL_ERR_SYS;
	}
	re_hook(4);
	return GL_OK;
remove_tmp:
	e = errno;
	unlink(nm.tmp);
	errno = e;
	return rc;
}

int re_calfile_save(const char *path, const struct re_calset *set, char *err,
		    size_t errlen)
{
	size_t cap;
	char *buf;
	int len, rc;

	if (err && errlen)
		err[0] = '\0';
	if (!path || !set) {
		re_err(err, errlen, "invalid arguments");
		return GL_ERR_ARG;
	}
	cap = re_calfile_format_size(set);
	buf = malloc(cap);
	if (!buf) {
		re_err(err, errlen, "cannot save '%s': out of memory", path);
		return GL_ERR_NOMEM;
	}
	len = re_calfile_format(set, buf, cap);
	if (len < 0) {
		re_err(err, errlen,
		       "cannot save '%s': invalid calibration "
		       "data",
		       path);
		rc = len == GL_ERR_OVERFLOW ? GL_ERR_OVERFLOW : GL_ERR_ARG;
		goto free_buf;
	}
	rc = re_save_text(path, buf, (size_t)len, err, errlen);
free_buf:
	free(buf);
	return rc;
}

/* Errors of base_file_read() that come from reading, not from opening. */
static bool re_read_errno(int e)
{
	return e == EIO || e == EOVERFLOW;
}

/* Read the whole file into a new buffer (base_file_read), saying why not
 * in @err as "cannot open", "not a calibration file" or "cannot read". */
static int re_read_file(const char *path, char **out, size_t *len, char *err,
			size_t errlen)
{
	int rc = base_file_read(path, RE_CALFILE_MAX_BYTES, out, len);

	if (rc == 0)
		return GL_OK;
	if (rc == -EFBIG || rc == -EISDIR || rc == -EINVAL) {
		re_err(err, errlen,
		       "'%s' is not a calibration file (not a "
		       "regular file or larger than %d bytes)",
		       path, RE_CALFILE_MAX_BYTES);
		return GL_ERR_FORMAT;
	}
	if (rc == -ENOMEM) {
		re_err(err, errlen, "cannot read '%s': out of memory", path);
		return GL_ERR_NOMEM;
	}
	re_err(err, errlen, "cannot %s '%s': %s",
	       re_read_errno(-rc) ? "read" : "open", path, strerror(-rc));
	errno = -rc;
	return rc == -ENOENT ? GL_ERR_NOENT : GL_ERR_SYS;
}

int re_calfile_load(const char *path, const struct re_calfile_expect *exp,
		    struct re_calset *out, char *err, size_t errlen)
{
	char *buf = NULL;
	size_t len = 0;
	int rc;

	if (err && errlen)
		err[0] = '\0';
	if (!path || !out) {
		re_err(err, errlen, "invalid arguments");
		return GL_ERR_ARG;
	}
	memset(out, 0, sizeof(*out));
	rc = re_read_file(path, &buf, &len, err, errlen);
	if (rc != GL_OK)
		return rc;
	rc = re_calfile_parse(buf, len, path, exp, out, err, errlen);
	free(buf);
	return rc;
}
