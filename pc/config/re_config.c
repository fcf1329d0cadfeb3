/*
 * re_config.c - the supervisor's YAML configuration (libyaml document API).
 *
 * The file is loaded into a libyaml document, then walked with the tables
 * below, which give every key its type, its place in struct re_config and
 * its range. Parsing stores values and remembers where each one was written
 * (yaml marks by field address); validation then checks ranges and
 * cross-field rules on the struct, so re_config_validate() (after command
 * line overrides) and re_config_parse() apply exactly the same rules, the
 * latter with the position of the value concerned (for a cross-field rule,
 * the later of the values involved). Everything goes into a temporary
 * struct copied out only on success.
 */
#include "re_config.h"
#include "re_rt.h"

#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "base_file.h"
#include "base_yaml.h"
#include "gl_err.h"
#include "gl_link.h"
#include "gl_hash.h"

_Static_assert(sizeof(enum re_mode) == sizeof(int) &&
		   sizeof(enum re_relay_backend) == sizeof(int),
	       "FT_ENUM stores an int");

#define CFG_FILE_MAX (1024 * 1024) /* bytes; a config is a few KiB */
#define SEEN_MAX     256	   /* values with a recorded position */
#define TEXT_SHOWN   40		   /* bytes of a bad value quoted back */

enum ftype {
	FT_INT,	   /* int, decimal */
	FT_LONG,   /* long, decimal */
	FT_DOUBLE, /* double, decimal with optional fraction/exponent */
	FT_BOOL,   /* true | false */
	FT_STR,	   /* char[size]; min = 1: must not be empty */
	FT_ENUM,   /* int-sized enum, names in aux */
	FT_MAP,	   /* nested mapping, field table in aux */
	FT_CUSTOM, /* parsed by fn */
};

struct pctx;
struct field;
typedef int (*custom_fn)(struct pctx *c, const struct field *f, yaml_node_t *v,
			 void *base);

struct field {
	const char *key;
	enum ftype type;
	size_t off;	 /* offset in the parent struct */
	double min, max; /* numbers: range; FT_STR: min 1 = required */
	size_t size;	 /* FT_STR: buffer size */
	const void *aux; /* FT_MAP: field table; FT_ENUM: names */
	custom_fn fn;	 /* FT_CUSTOM */
};

struct seen {
	const void *field; /* address inside the temporary config */
	yaml_mark_t mark;  /* where its value starts */
};

/* Parse and validation context; validation alone has no document. */
struct pctx {
	const char *file; /* NULL: messages without position */
	yaml_document_t *doc;
	struct re_config *cfg;
	yaml_mark_t root_mark; /* fallback position */
	struct seen seen[SEEN_MAX];
	int nseen;
	char *err;
	size_t errlen;
};

static const char *const mode_names[] = {"clinical", "development", NULL};
static const char *const backend_names[] = {"auto", "serialport", "tty", NULL};
static const char *const unit_names[] = {"deg", "mm", NULL};
static const char *const proto_names[] = {"devantech", "icstation", "lcus",
					  "kmtronic", NULL};
static const int bauds[] = {1200,  2400,  4800,	 9600,
			    19200, 38400, 57600, 115200};

/* ---- messages and positions ---- */

static void vformat(struct pctx *c, const yaml_mark_t *m, const char *fmt,
		    va_list ap) __attribute__((format(printf, 3, 0)));
static void vformat(struct pctx *c, const yaml_mark_t *m, const char *fmt,
		    va_list ap)
{
	base_yaml_vformat(c->err, c->errlen, c->file, m, fmt, ap);
}

/* fail_at() - message at mark @m (NULL: no position). Returns the code. */
static int fail_at(struct pctx *c, const yaml_mark_t *m, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int fail_at(struct pctx *c, const yaml_mark_t *m, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vformat(c, m, fmt, ap);
	va_end(ap);
	return GL_ERR_CONFIG;
}

static void seen_add(struct pctx *c, const void *field, yaml_mark_t m)
{
	int i;

	for (i = 0; i < c->nseen; i++) {
		if (c->seen[i].field == field) {
			c->seen[i].mark = m;
			return;
		}
	}
	if (c->nseen < SEEN_MAX) {
		c->seen[c->nseen].field = field;
		c->seen[c->nseen++].mark = m;
	}
}

static const yaml_mark_t *seen_mark(const struct pctx *c, const void *field)
{
	int i;

	for (i = 0; i < c->nseen; i++)
		if (c->seen[i].field == field)
			return &c->seen[i].mark;
	return NULL;
}

/*
 * later_mark() - the position of whichever of @a, @b (either may be NULL)
 * was written later in the file; the root when neither was, NULL when
 * validating without a document.
 */
static const yaml_mark_t *later_mark(const struct pctx *c, const void *a,
				     const void *b)
{
	const yaml_mark_t *ma = a ? seen_mark(c, a) : NULL;
	const yaml_mark_t *mb = b ? seen_mark(c, b) : NULL;

	if (!c->file)
		return NULL;
	if (ma && mb)
		return ma->index >= mb->index ? ma : mb;
	if (ma || mb)
		return ma ? ma : mb;
	return &c->root_mark;
}

/* Format a bound: integers without exponent, others with %g. */
static const char *num_text(double v, char *buf, size_t cap)
{
	if (v == floor(v) && fabs(v) < 1e15)
		snprintf(buf, cap, "%.0f", v);
	else
		snprintf(buf, cap, "%g", v);
	return buf;
}

static const char *node_kind(const yaml_node_t *v)
{
	if (v->type == YAML_MAPPING_NODE)
		return "a mapping";
	if (v->type == YAML_SEQUENCE_NODE)
		return "a list";
	return "a value";
}

/* The text of @v, known to be a scalar. */
static const char *scalar(const yaml_node_t *v)
{
	return (const char *)v->data.scalar.value;
}

static bool quoted(const yaml_node_t *v)
{
	return v->data.scalar.style != YAML_PLAIN_SCALAR_STYLE;
}

/* type_error() - "expected WHAT for 'KEY', got 'TEXT'" at the value. */
static int type_error(struct pctx *c, const yaml_node_t *v, const char *what,
		      const char *key)
{
	if (v->type != YAML_SCALAR_NODE)
		return fail_at(c, &v->start_mark,
			       "expected %s for '%s', got %s", what, key,
			       node_kind(v));
	if (v->data.scalar.length == 0 && !quoted(v))
		return fail_at(c, &v->start_mark, "missing value for '%s'",
			       key);
	if (quoted(v))
		return fail_at(c, &v->start_mark,
			       "expected %s for '%s', got a quoted string",
			       what, key);
	return fail_at(c, &v->start_mark, "expected %s for '%s', got '%.*s'",
		       what, key, TEXT_SHOWN, scalar(v));
}

/* ---- scalars ---- */

/* Plain decimal integer: [+-]digits. */
static bool is_int_text(const char *s)
{
	if (*s == '+' || *s == '-')
		s++;
	if (!*s)
		return false;
	for (; *s; s++)
		if (*s < '0' || *s > '9')
			return false;
	return true;
}

/* Decimal number: [+-](digits[.digits]|.digits)([eE][+-]digits). */
static bool is_num_text(const char *s)
{
	size_t nd = 0;

	if (*s == '+' || *s == '-')
		s++;
	for (; *s >= '0' && *s <= '9'; s++)
		nd++;
	if (*s == '.')
		for (s++; *s >= '0' && *s <= '9'; s++)
			nd++;
	if (!nd)
		return false;
	if (*s == 'e' || *s == 'E') {
		s++;
		if (*s == '+' || *s == '-')
			s++;
		if (*s < '0' || *s > '9')
			return false;
		while (*s >= '0' && *s <= '9')
			s++;
	}
	return *s == '\0';
}

static int range_error(struct pctx *c, const yaml_mark_t *m, const char *key,
		       double min, double max, const char *got)
{
	char a[32], b[32];

	return fail_at(c, m, "'%s' must be between %s and %s, got %.*s", key,
		       num_text(min, a, sizeof(a)), num_text(max, b, sizeof(b)),
		       TEXT_SHOWN, got);
}

/*
 * get_integer() - an integer scalar that fits [lo, hi], the C type. Values
 * that do not fit are reported against the field's own range [min, max];
 * the struct-level check reports the others, so both give one message.
 */
static int get_integer(struct pctx *c, yaml_node_t *v, const char *key,
		       double min, double max, long long lo, long long hi,
		       long long *out)
{
	const char *s;
	long l;

	if (v->type != YAML_SCALAR_NODE || quoted(v))
		return type_error(c, v, "an integer", key);
	s = scalar(v);
	if (!is_int_text(s)) {
		if (is_num_text(s))
			return type_error(c, v, "an integer", key);
		return type_error(c, v, "a number", key);
	}
	if (base_yaml_long(v, &l) != 0 || l < lo || l > hi)
		return range_error(c, &v->start_mark, key, min, max, s);
	*out = l;
	return GL_OK;
}

static int get_double(struct pctx *c, yaml_node_t *v, const char *key,
		      double *out)
{
	const char *s;

	if (v->type != YAML_SCALAR_NODE || quoted(v) || !is_num_text(scalar(v)))
		return type_error(c, v, "a number", key);
	s = scalar(v);
	if (base_yaml_double(v, out) != 0)
		return fail_at(c, &v->start_mark,
			       "'%s' is out of range, got %.*s", key,
			       TEXT_SHOWN, s);
	return GL_OK;
}

static int get_bool(struct pctx *c, yaml_node_t *v, const char *key, bool *out)
{
	if (v->type == YAML_SCALAR_NODE && !quoted(v) &&
	    base_yaml_bool(v, out) == 0)
		return GL_OK;
	return type_error(c, v, "true or false", key);
}

static int get_string(struct pctx *c, yaml_node_t *v, const char *key,
		      char *dst, size_t size)
{
	size_t i, len;
	const unsigned char *s;

	if (v->type != YAML_SCALAR_NODE)
		return type_error(c, v, "a string", key);
	s = v->data.scalar.value;
	len = v->data.scalar.length;
	for (i = 0; i < len; i++)
		if (s[i] < 0x20 || s[i] == 0x7f)
			return fail_at(c, &v->start_mark,
				       "'%s' contains a control character",
				       key);
	if (len >= size)
		return fail_at(c, &v->start_mark,
			       "'%s' is too long (at most %zu bytes)", key,
			       size - 1);
	memcpy(dst, s, len);
	dst[len] = '\0';
	return GL_OK;
}

/* Names listed as "a, b or c" for messages. */
static void names_text(const char *const *names, char *buf, size_t cap)
{
	size_t n = 0, i;

	buf[0] = '\0';
	for (i = 0; names[i]; i++) {
		const char *sep = !i ? "" : names[i + 1] ? ", " : " or ";

		if (n < cap)
			n += (size_t)snprintf(buf + n, cap - n, "%s%s", sep,
					      names[i]);
	}
}

static int get_enum(struct pctx *c, yaml_node_t *v, const char *key,
		    const char *const *names, int *out)
{
	char list[96];
	int i;

	if (v->type == YAML_SCALAR_NODE) { /* "development" is fine too */
		for (i = 0; names[i]; i++) {
			if (!strcmp(scalar(v), names[i])) {
				*out = i;
				return GL_OK;
			}
		}
	}
	names_text(names, list, sizeof(list));
	if (v->type != YAML_SCALAR_NODE || (!quoted(v) && !*scalar(v)))
		return type_error(c, v, list, key);
	return fail_at(c, &v->start_mark, "'%s' must be %s, got '%.*s'", key,
		       list, TEXT_SHOWN, scalar(v));
}

/* ---- mappings ---- */

static int parse_map(struct pctx *c, yaml_node_t *map, const struct field *tab,
		     void *base, const char *key);

static yaml_node_t *node_at(struct pctx *c, int index)
{
	return yaml_document_get_node(c->doc, index);
}

static int parse_field(struct pctx *c, const struct field *f, yaml_node_t *v,
		       void *base)
{
	void *dst = (char *)base + f->off;
	long long ll;
	int rc, e;

	switch (f->type) {
	case FT_INT:
		rc = get_integer(c, v, f->key, f->min, f->max, INT_MIN, INT_MAX,
				 &ll);
		if (!rc)
			*(int *)dst = (int)ll;
		break;
	case FT_LONG:
		rc = get_integer(c, v, f->key, f->min, f->max, LONG_MIN,
				 LONG_MAX, &ll);
		if (!rc)
			*(long *)dst = (long)ll;
		break;
	case FT_DOUBLE: rc = get_double(c, v, f->key, dst); break;
	case FT_BOOL: rc = get_bool(c, v, f->key, dst); break;
	case FT_STR: rc = get_string(c, v, f->key, dst, f->size); break;
	case FT_ENUM:
		rc = get_enum(c, v, f->key, f->aux, &e);
		if (!rc)
			memcpy(dst, &e, sizeof(e)); /* int-sized enums */
		break;
	case FT_MAP: return parse_map(c, v, f->aux, dst, f->key);
	case FT_CUSTOM: return f->fn(c, f, v, base);
	default: return GL_ERR_ARG;
	}
	if (!rc)
		seen_add(c, dst, v->start_mark);
	return rc;
}

static const struct field *field_find(const struct field *tab, const char *k)
{
	for (; tab->key; tab++)
		if (!strcmp(tab->key, k))
			return tab;
	return NULL;
}

/* The key node of pair @i after checking it is a string seen only once. */
static int map_key(struct pctx *c, yaml_node_t *map, yaml_node_pair_t *p,
		   yaml_node_t **key)
{
	yaml_node_t *k;
	int rc = base_yaml_key(c->doc, map, p, &k);

	if (rc == -EINVAL)
		return fail_at(c, k ? &k->start_mark : &map->start_mark,
			       "expected a key name, got %s",
			       k ? node_kind(k) : "nothing");
	if (rc == -EEXIST)
		return fail_at(c, &k->start_mark, "duplicate key '%.*s'",
			       TEXT_SHOWN, scalar(k));
	*key = k;
	return GL_OK;
}

static int parse_map(struct pctx *c, yaml_node_t *map, const struct field *tab,
		     void *base, const char *key)
{
	yaml_node_pair_t *p;
	yaml_node_t *k = NULL, *v;
	const struct field *f;
	int rc;

	if (map->type != YAML_MAPPING_NODE)
		return type_error(c, map, "a mapping", key);
	for (p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top;
	     p++) {
		rc = map_key(c, map, p, &k);
		if (rc)
			return rc;
		f = field_find(tab, scalar(k));
		if (!f)
			return fail_at(c, &k->start_mark, "unknown key '%.*s'",
				       TEXT_SHOWN, scalar(k));
		v = node_at(c, p->value);
		if (!v)
			return fail_at(c, &k->start_mark,
				       "missing value for '%s'", f->key);
		rc = parse_field(c, f, v, base);
		if (rc)
			return rc;
	}
	return GL_OK;
}

/* ---- lists (custom fields) ---- */

/* seq_items() - @v as a list of exactly @n items (n = 0: 1..max). */
static int seq_items(struct pctx *c, yaml_node_t *v, const char *key,
		     const char *what, int n, int max, int *count)
{
	int k;

	if (v->type != YAML_SEQUENCE_NODE)
		return type_error(c, v, "a list", key);
	k = (int)(v->data.sequence.items.top - v->data.sequence.items.start);
	if (n && k != n)
		return fail_at(c, &v->start_mark,
			       "'%s' must list exactly %d %s, got %d", key, n,
			       what, k);
	if (!n && (k < 1 || k > max))
		return fail_at(c, &v->start_mark,
			       "'%s' must list 1 to %d %s, got %d", key, max,
			       what, k);
	*count = k;
	return GL_OK;
}

static yaml_node_t *seq_item(struct pctx *c, yaml_node_t *v, int i)
{
	return node_at(c, v->data.sequence.items.start[i]);
}

/* An int list element; stored unchecked (validation checks the range). */
static int seq_int(struct pctx *c, yaml_node_t *seq, int i, const char *key,
		   int min, int max, int *dst)
{
	yaml_node_t *it = seq_item(c, seq, i);
	long long ll;
	int rc;

	if (!it)
		return fail_at(c, &seq->start_mark, "bad list '%s'", key);
	rc = get_integer(c, it, key, min, max, INT_MIN, INT_MAX, &ll);
	if (rc)
		return rc;
	*dst = (int)ll;
	seen_add(c, dst, it->start_mark);
	return GL_OK;
}

static int parse_inputs(struct pctx *c, const struct field *f, yaml_node_t *v,
			void *base)
{
	struct re_config_joystick *j = base;
	int i, n = 0, rc;

	rc = seq_items(c, v, f->key, "inputs", RE_JOY_INPUTS, 0, &n);
	for (i = 0; !rc && i < n; i++)
		rc = seq_int(c, v, i, f->key, 1, 48, &j->inputs[i]);
	return rc;
}

static int parse_window(struct pctx *c, const struct field *f, yaml_node_t *v,
			void *base)
{
	struct re_config_axis *a = base;
	int n = 0, rc;

	rc = seq_items(c, v, f->key, "times (start and end)", 2, 0, &n);
	if (!rc)
		rc = seq_int(c, v, 0, f->key, 0, 60000, &a->accel_start_ms);
	if (!rc)
		rc = seq_int(c, v, 1, f->key, 1, 60000, &a->accel_end_ms);
	return rc;
}

/* A list of bytes, decimal or 0x hex, each 0..255. */
static int parse_bytes(struct pctx *c, const struct field *f, yaml_node_t *v,
		       uint8_t *dst, size_t *len)
{
	yaml_node_t *it;
	unsigned long b;
	char *end;
	int i, n = 0, rc;

	rc = seq_items(c, v, f->key, "bytes", 0, RE_RELAY_CODE_MAX, &n);
	for (i = 0; !rc && i < n; i++) {
		it = seq_item(c, v, i);
		if (!it || it->type != YAML_SCALAR_NODE || quoted(it) ||
		    !*scalar(it))
			return type_error(c, it ? it : v, "a byte", f->key);
		errno = 0;
		b = strtoul(scalar(it), &end, 0);
		if (*end || errno || scalar(it)[0] == '-' ||
		    scalar(it)[0] == '+')
			return type_error(c, it, "a byte", f->key);
		if (b > 255)
			return fail_at(c, &it->start_mark,
				       "'%s' bytes must be between 0 and 255, "
				       "got %.*s",
				       f->key, TEXT_SHOWN, scalar(it));
		dst[i] = (uint8_t)b;
	}
	if (!rc) {
		*len = (size_t)n;
		seen_add(c, dst, v->start_mark);
	}
	return rc;
}

static int parse_on(struct pctx *c, const struct field *f, yaml_node_t *v,
		    void *base)
{
	struct re_config_relay *r = base;

	return parse_bytes(c, f, v, r->on, &r->on_len);
}

static int parse_off(struct pctx *c, const struct field *f, yaml_node_t *v,
		     void *base)
{
	struct re_config_relay *r = base;

	return parse_bytes(c, f, v, r->off, &r->off_len);
}

static const struct field explicit_fields[] = {
    {"on", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_on},
    {"off", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_off},
    {NULL, FT_INT, 0, 0, 0, 0, NULL, NULL},
};

/* protocol: a preset name, or {on: [bytes], off: [bytes]}. */
static int parse_protocol(struct pctx *c, const struct field *f, yaml_node_t *v,
			  void *base)
{
	struct re_config_relay *r = base;
	int e, rc;

	if (v->type == YAML_MAPPING_NODE) {
		r->on_len = r->off_len = 0;
		rc = parse_map(c, v, explicit_fields, r, f->key);
		if (rc)
			return rc;
		if (!r->on_len || !r->off_len)
			return fail_at(c, &v->start_mark,
				       "'%s' needs both 'on' and 'off' bytes",
				       f->key);
		r->protocol = RE_RELAY_EXPLICIT;
	} else {
		rc = get_enum(c, v, f->key, proto_names, &e);
		if (rc)
			return rc;
		r->protocol = (enum re_relay_proto)e;
	}
	seen_add(c, &r->protocol, v->start_mark);
	return GL_OK;
}

/* ---- the schema ---- */

/* clang-format off */
#define I(s, m, lo, hi) { #m, FT_INT, offsetof(s, m), lo, hi, 0, NULL, NULL }
#define L(s, m, lo, hi) { #m, FT_LONG, offsetof(s, m), lo, hi, 0, NULL, NULL }
#define D(s, m, lo, hi) \
	{ #m, FT_DOUBLE, offsetof(s, m), lo, hi, 0, NULL, NULL }
#define B(s, m) { #m, FT_BOOL, offsetof(s, m), 0, 0, 0, NULL, NULL }
#define S(s, m, req) \
	{ #m, FT_STR, offsetof(s, m), req, 0, sizeof(((s *)0)->m), NULL, NULL }
#define E(s, m, names, max) \
	{ #m, FT_ENUM, offsetof(s, m), 0, max, 0, names, NULL }
#define M(s, m, tab) { #m, FT_MAP, offsetof(s, m), 0, 0, 0, tab, NULL }
#define END { NULL, FT_INT, 0, 0, 0, 0, NULL, NULL }

/* YAML key -> member with another name (units in the C names only). */
#define IK(key, s, m, lo, hi) \
	{ key, FT_INT, offsetof(s, m), lo, hi, 0, NULL, NULL }

static const struct field controller_fields[] = {
	S(struct re_config_controller, address, 1),
	S(struct re_config_controller, model, 1),
	I(struct re_config_controller, timeout_ms, 5, 10000),
	I(struct re_config_controller, connect_timeout_ms, 100, 60000),
	I(struct re_config_controller, power_output, 0, 8),
	END,
};

static const struct field relay_fields[] = {
	S(struct re_config_relay, port_clinical, 0),
	S(struct re_config_relay, port_development, 0),
	{ "protocol", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_protocol },
	I(struct re_config_relay, channel, 1, 8),
	E(struct re_config_relay, backend, backend_names, 2),
	I(struct re_config_relay, baud, 1200, 115200),
	I(struct re_config_relay, write_timeout_ms, 1, 1000),
	I(struct re_config_relay, off_deadline_ms, 10, 1000),
	B(struct re_config_relay, readback),
	I(struct re_config_relay, readback_timeout_ms, 10, 5000),
	S(struct re_config_relay, icstation_state, 1),
	END,
};

static const struct field watchdog_fields[] = {
	D(struct re_config_watchdog, noncritical_factor, 1.0, 10.0),
	D(struct re_config_watchdog, critical_factor, 1.0, 20.0),
	I(struct re_config_watchdog, controller_timeout_ms, 20, 5000),
	END,
};

static const struct field joystick_fields[] = {
	{ "inputs", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_inputs },
	B(struct re_config_joystick, active_low),
	I(struct re_config_joystick, invalid_timeout_ms, 50, 5000),
	END,
};

static const struct field encfail_fields[] = {
	B(struct re_config_encoder_failure, enabled),
	I(struct re_config_encoder_failure, time_samples, 2, 32000),
	D(struct re_config_encoder_failure, torque_v, 0.0, 9.9982),
	END,
};

static const struct field analog_fields[] = {
	I(struct re_config_analog, input, 1, 8),
	D(struct re_config_analog, expected_range_v, 0.01, 20.0),
	D(struct re_config_analog, range_tolerance, 0.0, 1.0),
	D(struct re_config_analog, reverse_v, -10.0, 10.0),
	D(struct re_config_analog, forward_v, -10.0, 10.0),
	D(struct re_config_analog, absolute_tolerance_v, 0.001, 5.0),
	END,
};

static const struct field axis_fields[] = {
	S(struct re_config_axis, name, 1),
	IK("vmax", struct re_config_axis, vmax_cps, 1, 10000000),
	IK("vmin", struct re_config_axis, vmin_cps, 1, 10000000),
	{ "accel_window_ms", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_window },
	I(struct re_config_axis, step_counts, 1, 1000000),
	I(struct re_config_axis, travel_counts, 4, 100000000),
	D(struct re_config_axis, travel_tolerance, 0.0, 1.0),
	D(struct re_config_axis, kp, 0.0, 1023.875),
	D(struct re_config_axis, ki, 0.0, 255.999),
	D(struct re_config_axis, kd, 0.0, 4095.875),
	D(struct re_config_axis, torque_limit_v, 0.0, 9.9982),
	I(struct re_config_axis, position_error_limit_counts, 1, INT_MAX),
	B(struct re_config_axis, off_on_error),
	M(struct re_config_axis, encoder_failure, encfail_fields),
	M(struct re_config_axis, analog, analog_fields),
	D(struct re_config_axis, allowed_error, 0.0, 10.0),
	I(struct re_config_axis, persistence_cycles, 1, 1000),
	D(struct re_config_axis, monotonic_margin_v, 0.0, 1.0),
	E(struct re_config_axis, unit, unit_names, 1),
	D(struct re_config_axis, counts_per_unit, 0.0, 10000000.0),
	END,
};

static const struct field calibration_fields[] = {
	S(struct re_config_calibration, file, 1),
	B(struct re_config_calibration, backup),
	I(struct re_config_calibration, backoff_counts, 1, 1000000),
	I(struct re_config_calibration, move_timeout_ms, 100, 600000),
	I(struct re_config_calibration, travel_cps, 0, 10000000),
	I(struct re_config_calibration, seek_cps, 0, 10000000),
	I(struct re_config_calibration, near_margin_counts, 0, 10000000),
	END,
};

static const struct field log_fields[] = {
	S(struct re_config_log, path, 1),
	L(struct re_config_log, max_bytes, 4096, 1073741824),
	I(struct re_config_log, keep, 1, 9),
	END,
};

static const struct field recorder_fields[] = {
	D(struct re_config_recorder, seconds, 1, 120),
	D(struct re_config_recorder, after_fault_s, 0, 60),
	S(struct re_config_recorder, dir, 0),
	END,
};

static const struct field realtime_fields[] = {
	I(struct re_config_realtime, priority, 0, 99),
	I(struct re_config_realtime, cpu, -1, 1023),
	B(struct re_config_realtime, lock_memory),
	END,
};

static int parse_axes(struct pctx *c, const struct field *f, yaml_node_t *v,
		      void *base)
{
	struct re_config *cfg = base;
	yaml_node_t *it;
	int i, n = 0, rc;

	rc = seq_items(c, v, f->key, "axes (A, B, C)", RE_AXES, 0, &n);
	for (i = 0; !rc && i < n; i++) {
		it = seq_item(c, v, i);
		if (!it)
			return fail_at(c, &v->start_mark, "bad list 'axes'");
		rc = parse_map(c, it, axis_fields, &cfg->axes[i], "axes");
		if (!rc && !seen_mark(c, &cfg->axes[i].vmin_cps))
			cfg->axes[i].vmin_cps = cfg->axes[i].vmax_cps / 4;
	}
	return rc;
}

static const struct field root_fields[] = {
	E(struct re_config, mode, mode_names, 1),
	I(struct re_config, period_ms, 2, 100),
	M(struct re_config, controller, controller_fields),
	M(struct re_config, relay, relay_fields),
	M(struct re_config, watchdog, watchdog_fields),
	M(struct re_config, joystick, joystick_fields),
	{ "axes", FT_CUSTOM, 0, 0, 0, 0, NULL, parse_axes },
	M(struct re_config, calibration, calibration_fields),
	M(struct re_config, log, log_fields),
	M(struct re_config, recorder, recorder_fields),
	M(struct re_config, realtime, realtime_fields),
	END,
};
/* clang-format on */

/* ---- validation ---- */

static int check_num(struct pctx *c, const struct field *f, const void *dst)
{
	char got[32];
	double v;

	if (f->type == FT_INT)
		v = *(const int *)dst;
	else if (f->type == FT_LONG)
		v = (double)*(const long *)dst;
	else
		v = *(const double *)dst;
	if (v >= f->min && v <= f->max && !isnan(v))
		return GL_OK;
	return range_error(c, later_mark(c, dst, NULL), f->key, f->min, f->max,
			   num_text(v, got, sizeof(got)));
}

/* check_table() - ranges of the plain fields of @tab over @base. */
static int check_table(struct pctx *c, const struct field *tab,
		       const void *base)
{
	const char *dst;
	int rc = GL_OK, e;

	for (; !rc && tab->key; tab++) {
		dst = (const char *)base + tab->off;
		switch (tab->type) {
		case FT_INT:
		case FT_LONG:
		case FT_DOUBLE: rc = check_num(c, tab, dst); break;
		case FT_STR:
			if (tab->min > 0 && !dst[0])
				rc =
				    fail_at(c, later_mark(c, dst, NULL),
					    "'%s' must not be empty", tab->key);
			break;
		case FT_ENUM:
			memcpy(&e, dst, sizeof(e));
			if (e < 0 || e > (int)tab->max)
				rc = fail_at(c, later_mark(c, dst, NULL),
					     "'%s' has an invalid value",
					     tab->key);
			break;
		case FT_MAP: rc = check_table(c, tab->aux, dst); break;
		default: break;
		}
	}
	return rc;
}

/* The encoder-failure detection and the potentiometer's absolute values. */
static int check_axis_more(struct pctx *c, const struct re_config_axis *a)
{
	const struct re_config_analog *an = &a->analog;
	double span = an->forward_v - an->reverse_v;

	/* DMC-4000 command reference, OT: a non-zero KI is necessary for the
	 * encoder-failure detection (OA's page: recommended) */
	if (a->encoder_failure.enabled && a->ki <= 0)
		return fail_at(c, later_mark(c, &a->ki, &a->encoder_failure),
			       "'encoder_failure' needs a non-zero 'ki': the "
			       "controller's encoder-failure detection (OA, "
			       "OT) does not work with KI 0");
	if (span <= 2 * an->absolute_tolerance_v)
		return fail_at(c, later_mark(c, &an->forward_v, &an->reverse_v),
			       "'forward_v' (%g) must be above 'reverse_v' "
			       "(%g) by more than twice "
			       "'absolute_tolerance_v' (%g)",
			       an->forward_v, an->reverse_v,
			       an->absolute_tolerance_v);
	if ((seen_mark(c, &an->forward_v) || seen_mark(c, &an->reverse_v)) &&
	    fabs(span - an->expected_range_v) >
		an->range_tolerance * an->expected_range_v)
		return fail_at(c, later_mark(c, &an->forward_v, &an->reverse_v),
			       "'forward_v' - 'reverse_v' (%g V) must agree "
			       "with 'expected_range_v' (%g V) within "
			       "'range_tolerance'",
			       span, an->expected_range_v);
	return GL_OK;
}

static int check_axis(struct pctx *c, const struct re_config_axis *a)
{
	char got[32];
	int rc = check_table(c, axis_fields, a);

	if (rc)
		return rc;
	if (a->vmin_cps > a->vmax_cps)
		return fail_at(c, later_mark(c, &a->vmin_cps, &a->vmax_cps),
			       "'vmin' (%d) must not exceed 'vmax' (%d)",
			       a->vmin_cps, a->vmax_cps);
	if (a->accel_start_ms < 0 || a->accel_start_ms > 60000)
		return range_error(
		    c, later_mark(c, &a->accel_start_ms, NULL),
		    "accel_window_ms", 0, 60000,
		    num_text(a->accel_start_ms, got, sizeof(got)));
	if (a->accel_end_ms <= a->accel_start_ms || a->accel_end_ms > 60000)
		return fail_at(
		    c, later_mark(c, &a->accel_end_ms, &a->accel_start_ms),
		    "'accel_window_ms' end (%d) must be after its "
		    "start (%d) and at most 60000",
		    a->accel_end_ms, a->accel_start_ms);
	/* With position tracking the target is one step ahead of the
	 * encoder, so a jammed axis never builds an error above the step: ER
	 * at or above it would never trip (the DMC refuses it too, check 7). */
	if (a->position_error_limit_counts >= a->step_counts)
		return fail_at(
		    c,
		    later_mark(c, &a->position_error_limit_counts,
			       &a->step_counts),
		    "'position_error_limit_counts' (%d) must be below "
		    "'step_counts' (%d)",
		    a->position_error_limit_counts, a->step_counts);
	if (a->travel_counts / a->step_counts < 4 ||
	    a->travel_counts / a->step_counts > RE_CONFIG_POINTS_MAX)
		return fail_at(
		    c, later_mark(c, &a->travel_counts, &a->step_counts),
		    "'travel_counts' (%d) must be 4 to %d times "
		    "'step_counts' (%d)",
		    a->travel_counts, RE_CONFIG_POINTS_MAX, a->step_counts);
	return check_axis_more(c, a);
}

/* Axis names and analog inputs must differ between axes. */
static int check_axes_distinct(struct pctx *c, const struct re_config *cfg)
{
	const struct re_config_axis *a, *b;
	int i, j;

	for (j = 1; j < RE_AXES; j++) {
		for (i = 0; i < j; i++) {
			a = &cfg->axes[i];
			b = &cfg->axes[j];
			if (!strcmp(a->name, b->name))
				return fail_at(
				    c, later_mark(c, a->name, b->name),
				    "axis name '%s' is used twice", b->name);
			if (a->analog.input == b->analog.input)
				return fail_at(
				    c,
				    later_mark(c, &a->analog.input,
					       &b->analog.input),
				    "analog input %d is used by axes "
				    "'%s' and '%s'",
				    b->analog.input, a->name, b->name);
		}
	}
	return GL_OK;
}

static int check_joystick(struct pctx *c, const struct re_config_joystick *j)
{
	char got[16];
	int i, k;

	for (i = 0; i < RE_JOY_INPUTS; i++) {
		if (j->inputs[i] < 1 || j->inputs[i] > 48) {
			snprintf(got, sizeof(got), "%d", j->inputs[i]);
			return range_error(c,
					   later_mark(c, &j->inputs[i], NULL),
					   "inputs", 1, 48, got);
		}
		/* DMC-4000 command reference, @IN: "Inputs 9-16 only valid
		 * for 5-8 axis controller" - a DMC-4030 has none */
		if (j->inputs[i] >= 9 && j->inputs[i] <= 16)
			return fail_at(c, later_mark(c, &j->inputs[i], NULL),
				       "'inputs' entry %d is input %d: a "
				       "DMC-4030 has no inputs 9 to 16 (use "
				       "1..8 or 17..48)",
				       i + 1, j->inputs[i]);
		for (k = 0; k < i; k++)
			if (j->inputs[k] == j->inputs[i])
				return fail_at(
				    c,
				    later_mark(c, &j->inputs[i], &j->inputs[k]),
				    "'inputs' lists input %d twice "
				    "(entries %d and %d)",
				    j->inputs[i], k + 1, i + 1);
	}
	return GL_OK;
}

static int check_watchdog(struct pctx *c, const struct re_config *cfg)
{
	const struct re_config_watchdog *w = &cfg->watchdog;
	double crit_ms = w->critical_factor * cfg->period_ms;

	if (w->critical_factor <= w->noncritical_factor)
		return fail_at(
		    c,
		    later_mark(c, &w->critical_factor, &w->noncritical_factor),
		    "'critical_factor' (%g) must be greater than "
		    "'noncritical_factor' (%g)",
		    w->critical_factor, w->noncritical_factor);
	if (w->controller_timeout_ms < crit_ms)
		return fail_at(
		    c,
		    later_mark(c, &w->controller_timeout_ms,
			       seen_mark(c, &w->critical_factor)
				   ? (const void *)&w->critical_factor
				   : (const void *)&cfg->period_ms),
		    "'controller_timeout_ms' (%d) must be at least "
		    "'critical_factor' x 'period_ms' (%g)",
		    w->controller_timeout_ms, crit_ms);
	return GL_OK;
}

static bool baud_ok(int baud)
{
	size_t i;

	for (i = 0; i < sizeof(bauds) / sizeof(bauds[0]); i++)
		if (bauds[i] == baud)
			return true;
	return false;
}

static int check_relay(struct pctx *c, const struct re_config *cfg)
{
	const struct re_config_relay *r = &cfg->relay;

	if (!baud_ok(r->baud))
		return fail_at(c, later_mark(c, &r->baud, NULL),
			       "'baud' must be 1200, 2400, 4800, 9600, 19200, "
			       "38400, 57600 or 115200, got %d",
			       r->baud);
	if (r->protocol == RE_RELAY_EXPLICIT &&
	    (!r->on_len || r->on_len > RE_RELAY_CODE_MAX || !r->off_len ||
	     r->off_len > RE_RELAY_CODE_MAX))
		return fail_at(c, later_mark(c, r->on, r->off),
			       "'on' and 'off' must list 1 to %d bytes each",
			       RE_RELAY_CODE_MAX);
	if (r->protocol == RE_RELAY_EXPLICIT && r->on_len == r->off_len &&
	    !memcmp(r->on, r->off, r->on_len))
		return fail_at(c, later_mark(c, r->on, r->off),
			       "'on' and 'off' bytes must differ");
	if (r->readback && r->protocol != RE_RELAY_DEVANTECH)
		return fail_at(c, later_mark(c, &r->readback, &r->protocol),
			       "'readback' needs the devantech protocol");
	if (cfg->mode == RE_MODE_DEVELOPMENT && !r->port_development[0])
		return fail_at(c,
			       later_mark(c, r->port_development, &cfg->mode),
			       "'port_development' must be set in "
			       "development mode");
	return GL_OK;
}

static bool is_loopback(const char *addr)
{
	return !strncmp(addr, "127.", 4) || !strncmp(addr, "localhost", 9) ||
	       !strncmp(addr, "[::1]", 5) || !strcmp(addr, "::1");
}

/*
 * Clinical mode: a real relay through libserialport, on a device under
 * /dev (not a pseudo-terminal), and a controller that is not the local
 * simulator.
 */
static int check_clinical(struct pctx *c, const struct re_config *cfg)
{
	const struct re_config_relay *r = &cfg->relay;
	const char *port = r->port_clinical;

	if (cfg->mode != RE_MODE_CLINICAL)
		return GL_OK;
	if (!port[0])
		return fail_at(c, later_mark(c, port, &cfg->mode),
			       "'port_clinical' must be set in clinical mode");
	if (strncmp(port, "/dev/", 5) || !strncmp(port, "/dev/pts/", 9) ||
	    !strcmp(port, "/dev/ptmx") || strstr(port, "/../"))
		return fail_at(c, later_mark(c, port, &cfg->mode),
			       "'port_clinical' must be a serial device under "
			       "/dev, got '%.*s'",
			       TEXT_SHOWN, port);
	if (r->backend == RE_RELAY_BACKEND_TTY)
		return fail_at(c, later_mark(c, &r->backend, &cfg->mode),
			       "'backend' tty is not allowed in clinical mode "
			       "(a pseudo-terminal is never a real relay)");
	if (is_loopback(cfg->controller.address))
		return fail_at(
		    c, later_mark(c, cfg->controller.address, &cfg->mode),
		    "'address' %.*s is a loopback address; clinical "
		    "mode needs the real controller",
		    TEXT_SHOWN, cfg->controller.address);
	return GL_OK;
}

/* An open potentiometer wiper reads about 0 V: the lowest reading the
 * controller accepts (potlo, docs/supervisor.md) must stay above this, so
 * that an open wiper is a fault (16), not an axis at its end stop. */
#define POT_OPEN_V 0.1

/*
 * The slow speed near a switch is not faster than the travel speed; the
 * margin past a switch keeps an open potentiometer detectable.
 */
static int check_calibration(struct pctx *c, const struct re_config *cfg)
{
	const struct re_config_calibration *k = &cfg->calibration;

	if (k->seek_cps && k->travel_cps && k->seek_cps > k->travel_cps)
		return fail_at(c, later_mark(c, &k->seek_cps, &k->travel_cps),
			       "'seek_cps' (%d) must not exceed 'travel_cps' "
			       "(%d): it is the slow speed near a switch",
			       k->seek_cps, k->travel_cps);
	for (int i = 0; i < RE_AXES; i++) {
		const struct re_config_axis *a = &cfg->axes[i];
		const struct re_config_analog *an = &a->analog;
		double gain =
		    (an->forward_v - an->reverse_v) / (double)a->travel_counts;
		double room =
		    an->reverse_v - an->absolute_tolerance_v - POT_OPEN_V;
		double lo = room + POT_OPEN_V - k->near_margin_counts * gain;

		if (an->reverse_v <= POT_OPEN_V || lo >= POT_OPEN_V)
			continue;
		return fail_at(
		    c, later_mark(c, &k->near_margin_counts, &an->reverse_v),
		    "axis '%s': the lowest potentiometer reading allowed "
		    "('reverse_v' - 'absolute_tolerance_v' - "
		    "'near_margin_counts' x %.3g V/count = %.3f V) is below "
		    "%.1f V, so an open potentiometer (0 V) would look like "
		    "the axis at its end stop: make 'near_margin_counts' at "
		    "most %.0f",
		    a->name, gain, lo, POT_OPEN_V,
		    room > 0 ? floor(room / gain + 1e-9) : 0.0);
	}
	return GL_OK;
}

/* The controller address as the link will read it (gl_link_addr_split):
 * a bad port is refused here, before anything is opened. */
static int check_address(struct pctx *c, const struct re_config *cfg)
{
	char host[RE_ADDR_MAX], port[16];

	if (gl_link_addr_split(cfg->controller.address, host, sizeof(host),
			       port, sizeof(port)) == GL_OK)
		return GL_OK;
	return fail_at(c, later_mark(c, cfg->controller.address, &cfg->mode),
		       "'address' '%.*s' is not HOST, HOST:PORT or [V6]:PORT "
		       "with a port 1..65535",
		       TEXT_SHOWN, cfg->controller.address);
}

/* The time after a fault is recorded into the same ring: less than it. */
static int check_recorder(struct pctx *c, const struct re_config_recorder *r)
{
	if (r->after_fault_s < r->seconds)
		return GL_OK;
	return fail_at(c, later_mark(c, &r->seconds, &r->after_fault_s),
		       "'after_fault_s' (%g s) must be less than 'seconds' "
		       "(%g s): both are in the one ring",
		       r->after_fault_s, r->seconds);
}

/* A period under RE_RT_MIN_MS_WITHOUT needs SCHED_FIFO asked for. */
static int check_realtime(struct pctx *c, const struct re_config *cfg)
{
	if (cfg->period_ms >= RE_RT_MIN_MS_WITHOUT ||
	    cfg->realtime.priority > 0)
		return GL_OK;
	return fail_at(c,
		       later_mark(c, &cfg->period_ms, &cfg->realtime.priority),
		       "'period_ms' %d needs real-time scheduling: set "
		       "'realtime.priority' 1..99 or a period of %d ms or more",
		       cfg->period_ms, RE_RT_MIN_MS_WITHOUT);
}

static int check_all(struct pctx *c, const struct re_config *cfg)
{
	int i, rc = check_table(c, root_fields, cfg);

	if (!rc)
		rc = check_address(c, cfg);
	for (i = 0; !rc && i < RE_AXES; i++)
		rc = check_axis(c, &cfg->axes[i]);
	if (!rc)
		rc = check_axes_distinct(c, cfg);
	if (!rc)
		rc = check_calibration(c, cfg);
	if (!rc)
		rc = check_joystick(c, &cfg->joystick);
	if (!rc)
		rc = check_watchdog(c, cfg);
	if (!rc)
		rc = check_relay(c, cfg);
	if (!rc)
		rc = check_clinical(c, cfg);
	if (!rc)
		rc = check_recorder(c, &cfg->recorder);
	if (!rc)
		rc = check_realtime(c, cfg);
	return rc;
}

int re_config_validate(const struct re_config *cfg, char *err, size_t errlen)
{
	struct pctx c;

	memset(&c, 0, sizeof(c));
	c.err = err;
	c.errlen = errlen;
	if (err && errlen)
		err[0] = '\0';
	if (!cfg)
		return GL_ERR_ARG;
	return check_all(&c, cfg);
}

/* ---- defaults ---- */

static void axis_defaults(struct re_config_axis *a, int i)
{
	static const char *const names[RE_AXES] = {"A", "B", "C"};

	memset(a, 0, sizeof(*a));
	snprintf(a->name, sizeof(a->name), "%s", names[i]);
	a->vmax_cps = 8000;
	a->vmin_cps = a->vmax_cps / 4;
	a->accel_start_ms = 500;
	a->accel_end_ms = 2000;
	a->step_counts = 1000;
	a->travel_counts = i == 2 ? 80000 : 100000;
	a->travel_tolerance = 0.1;
	a->kp = 6.0;
	a->ki = 1.0;
	a->kd = 64.0;
	a->torque_limit_v = 5.0;
	a->position_error_limit_counts = 500;
	a->off_on_error = true;
	a->encoder_failure.enabled = true;
	a->encoder_failure.time_samples = 100;
	a->encoder_failure.torque_v = 2.0;
	a->analog.input = i + 1;
	a->analog.expected_range_v = 4.0;
	a->analog.range_tolerance = 0.1;
	a->analog.reverse_v = 0.5;
	a->analog.forward_v = 4.5;
	a->analog.absolute_tolerance_v = 0.25;
	a->allowed_error = 0.5;
	a->persistence_cycles = 1;
	a->monotonic_margin_v = 0.005;
	a->unit = i == 2 ? RE_UNIT_MM : RE_UNIT_DEG;
	a->counts_per_unit = 0; /* not known: the console shows counts */
}

const char *re_unit_name(enum re_unit u)
{
	return u == RE_UNIT_MM ? "mm" : "deg";
}

static void relay_defaults(struct re_config_relay *r)
{
	memset(r, 0, sizeof(*r));
	snprintf(r->port_development, sizeof(r->port_development), "%s",
		 "/tmp/roboelf-relay");
	r->protocol = RE_RELAY_DEVANTECH;
	r->channel = 1;
	r->backend = RE_RELAY_BACKEND_AUTO;
	r->baud = 9600;
	r->write_timeout_ms = 100;
	r->off_deadline_ms = 50; /* docs/config.md: 9600 baud, USB, read-back */
	r->readback = true;	 /* devantech; see auto_defaults() */
	r->readback_timeout_ms = 500;
	snprintf(r->icstation_state, sizeof(r->icstation_state), "%s",
		 "/tmp/roboelf-icstation.state");
}

void re_config_defaults(struct re_config *out)
{
	static const int joy[RE_JOY_INPUTS] = {1, 2, 3,	 4,  5,	 6,
					       7, 8, 17, 18, 19, 20};
	int i;

	memset(out, 0, sizeof(*out));
	out->mode = RE_MODE_CLINICAL;
	out->period_ms = 50;
	snprintf(out->controller.address, sizeof(out->controller.address), "%s",
		 "127.0.0.1:23023");
	snprintf(out->controller.model, sizeof(out->controller.model), "%s",
		 "DMC4030");
	out->controller.timeout_ms = 100;
	out->controller.connect_timeout_ms = 2000;
	relay_defaults(&out->relay);
	out->watchdog.noncritical_factor = 1.5;
	out->watchdog.critical_factor = 2.5;
	out->watchdog.controller_timeout_ms = 200;
	memcpy(out->joystick.inputs, joy, sizeof(joy));
	out->joystick.active_low = false;
	out->joystick.invalid_timeout_ms = 500;
	for (i = 0; i < RE_AXES; i++)
		axis_defaults(&out->axes[i], i);
	snprintf(out->calibration.file, sizeof(out->calibration.file), "%s",
		 "roboelf-calibration.txt");
	out->calibration.backup = true;
	out->calibration.backoff_counts = 500;
	out->calibration.move_timeout_ms = 30000;
	out->calibration.near_margin_counts = 2000;
	snprintf(out->log.path, sizeof(out->log.path), "%s", "roboelf.log");
	out->log.max_bytes = 10L * 1024 * 1024;
	out->log.keep = 5;
	out->recorder.seconds = 30;
	out->recorder.after_fault_s = 2;
	out->realtime.priority = 50;
	out->realtime.cpu = -1;
	out->realtime.lock_memory = true;
}

/* ---- parse ---- */

/* Say why base_yaml_load() failed, at the place libyaml gives. */
/* Where a quoted value of line @ln (@p .. @end) opens without closing on
 * that line: its 0-based column, or -1. A quote opens a value after ": ",
 * "- ", "[" or "," (a quote inside a plain value, as in don't, opens
 * nothing); '' and \" do not close. */
static long open_quote_col(const char *p, const char *end)
{
	const char *b = p;

	for (const char *q = p; q < end; q++) {
		const char *v = q;
		char quote;

		if (*q == '#' && (q == b || q[-1] == ' ' || q[-1] == '\t'))
			return -1; /* a comment */
		if (*q != ':' && *q != '-' && *q != '[' && *q != ',')
			continue;
		v = q + 1;
		if (*q != '[' && *q != ',' && (v >= end || *v != ' '))
			continue;
		while (v < end && *v == ' ')
			v++;
		if (v >= end || (*v != '"' && *v != '\''))
			continue;
		quote = *v;
		for (q = v + 1; q < end; q++) {
			if (quote == '"' && *q == '\\' && q + 1 < end)
				q++;
			else if (quote == '\'' && *q == '\'' && q + 1 < end &&
				 q[1] == '\'')
				q++;
			else if (*q == quote)
				break;
		}
		if (q >= end)
			return v - b;
	}
	return -1;
}

/* The first line up to @last (0-based) with a quote that is not closed on
 * it: a double-quoted YAML value may span lines, so libyaml reports the
 * error where the quote finally closes, often many lines later. */
static int unclosed_quote(const char *buf, size_t len, size_t last,
			  yaml_mark_t *at)
{
	const char *p = buf, *end = buf + len;

	for (size_t ln = 0; p < end && ln <= last; ln++) {
		const char *nl = memchr(p, '\n', (size_t)(end - p));
		const char *le = nl ? nl : end;
		long col = open_quote_col(p, le);

		if (col >= 0) {
			at->line = ln;
			at->column = (size_t)col;
			return 1;
		}
		p = le + 1;
	}
	return 0;
}

static int syntax_error(struct pctx *c, int rc, const struct base_yaml_error *e,
			const char *buf, size_t len)
{
	yaml_mark_t q;

	if (rc == -ENOMEM) {
		fail_at(c, NULL, "out of memory");
		return GL_ERR_NOMEM;
	}
	if (e->type != YAML_READER_ERROR &&
	    unclosed_quote(buf, len, e->mark.line, &q))
		return fail_at(c, &q,
			       "this quote is not closed on its line (the "
			       "parser then stopped at line %zu column %zu: "
			       "%s)",
			       e->mark.line + 1, e->mark.column + 1,
			       e->problem ? e->problem : "syntax error");
	if (e->context)
		return fail_at(c, &e->mark, "%s (%s at line %zu column %zu)",
			       e->problem ? e->problem : "syntax error",
			       e->context, e->context_mark.line + 1,
			       e->context_mark.column + 1);
	return fail_at(c, &e->mark, "%s",
		       e->problem ? e->problem : "syntax error");
}

/* Load the one document of @buf into @doc; a second one is an error. */
static int load_document(struct pctx *c, const char *buf, size_t len,
			 yaml_document_t *doc)
{
	struct base_yaml_error e;
	int rc = base_yaml_load(buf, len, BASE_YAML_ONE_DOC, doc, &e);

	return rc ? syntax_error(c, rc, &e, buf, len) : GL_OK;
}

/* Defaults derived from other fields; they are in range (check_table()). */
static void auto_defaults(struct pctx *c, struct re_config *cfg)
{
	int wd = 4 * cfg->period_ms;

	if (!seen_mark(c, &cfg->watchdog.controller_timeout_ms))
		cfg->watchdog.controller_timeout_ms = wd < 100 ? 100 : wd;
	/* Read-back by default wherever the protocol has it (Devantech). */
	if (!seen_mark(c, &cfg->relay.readback))
		cfg->relay.readback = cfg->relay.protocol == RE_RELAY_DEVANTECH;
}

/* Parse the loaded document into c->cfg and validate it. */
static int parse_document(struct pctx *c, yaml_document_t *doc)
{
	static const yaml_mark_t first = {0, 0, 0};
	yaml_node_t *root = yaml_document_get_root_node(doc);
	int rc;

	if (!root)
		return fail_at(c, &first, "empty configuration file");
	c->root_mark = root->start_mark;
	if (root->type != YAML_MAPPING_NODE)
		return fail_at(c, &root->start_mark,
			       "expected a mapping of settings at the top "
			       "level, got %s",
			       node_kind(root));
	rc = parse_map(c, root, root_fields, c->cfg, "configuration");
	/* The ranges first: the defaults derived from a field (4 x period_ms)
	 * may only be computed from a value in its range (a period_ms of
	 * 1326439257 overflowed int here before it was refused). */
	if (!rc)
		rc = check_table(c, root_fields, c->cfg);
	if (rc)
		return rc;
	auto_defaults(c, c->cfg);
	return check_all(c, c->cfg);
}

int re_config_parse(const char *buf, size_t len, const char *filename,
		    struct re_config *out, char *err, size_t errlen)
{
	yaml_document_t doc;
	struct pctx *c;
	int rc;

	if (err && errlen)
		err[0] = '\0';
	if (!buf || !out)
		return GL_ERR_ARG;
	/* Context and the temporary config: too big for a small stack. */
	c = calloc(1, sizeof(*c) + sizeof(*c->cfg));
	if (!c)
		return GL_ERR_NOMEM;
	c->cfg = (struct re_config *)(c + 1);
	c->file = filename ? filename : "<config>";
	c->err = err;
	c->errlen = errlen;
	c->doc = &doc;
	re_config_defaults(c->cfg);
	rc = load_document(c, buf, len, &doc);
	if (rc)
		goto out_free_ctx;
	rc = parse_document(c, &doc);
	if (!rc)
		*out = *c->cfg; /* only now: nothing half-applied */
	yaml_document_delete(&doc);
out_free_ctx:
	free(c);
	return rc;
}

int re_config_load_file(const char *path, struct re_config *out, char *err,
			size_t errlen)
{
	char *buf = NULL;
	size_t len = 0;
	int rc, e;

	rc = base_file_read(path, CFG_FILE_MAX, &buf, &len);
	if (rc != 0) {
		e = -rc;
		if (err && errlen && rc == -EISDIR)
			snprintf(
			    err, errlen,
			    "cannot read '%s': it is a directory; give the "
			    "configuration file (e.g. %s/roboelf.yaml)",
			    path, path);
		else if (err && errlen && rc == -EINVAL)
			snprintf(err, errlen,
				 "cannot read '%s': not a regular file", path);
		else if (err && errlen)
			snprintf(err, errlen, "cannot read '%s': %s", path,
				 strerror(e));
		errno = e;
		return GL_ERR_SYS;
	}
	rc = re_config_parse(buf, len, path, out, err, errlen);
	free(buf);
	return rc;
}

/* ---- derived values, hash, summary ---- */

const char *re_mode_name(enum re_mode mode)
{
	return mode == RE_MODE_DEVELOPMENT ? "development" : "clinical";
}

const char *re_config_relay_port(const struct re_config *cfg)
{
	return cfg->mode == RE_MODE_CLINICAL ? cfg->relay.port_clinical
					     : cfg->relay.port_development;
}

void re_config_relay_cfg(const struct re_config *cfg, struct re_relay_cfg *out)
{
	const struct re_config_relay *r = &cfg->relay;

	memset(out, 0, sizeof(*out));
	snprintf(out->port, sizeof(out->port), "%s", re_config_relay_port(cfg));
	out->proto = r->protocol;
	out->channel = r->channel;
	out->backend = r->backend;
	out->baud = r->baud;
	out->clinical = cfg->mode == RE_MODE_CLINICAL;
	out->write_timeout_ms = r->write_timeout_ms;
	out->off_deadline_ms = r->off_deadline_ms;
	out->readback = r->readback;
	out->readback_timeout_ms = r->readback_timeout_ms;
	/* every second cycle, as before the one look: a
	 * silent board is then found within R + 3P (docs/safety.md); 1.5
	 * periods, so that a cycle's jitter never makes it every third */
	out->query_ms = cfg->period_ms + cfg->period_ms / 2;
	memcpy(out->on, r->on, sizeof(out->on));
	out->on_len = r->on_len;
	memcpy(out->off, r->off, sizeof(out->off));
	out->off_len = r->off_len;
	snprintf(out->icstation_state, sizeof(out->icstation_state), "%s",
		 r->icstation_state);
}

uint64_t re_config_hash(const struct re_config *cfg)
{
	const struct re_config_axis *a;
	uint64_t h = GL_FNV64_INIT;
	char buf[256];
	int i, n;

	/* A canonical text form: independent of struct layout and padding. */
	for (i = 0; i < RE_AXES; i++) {
		a = &cfg->axes[i];
		n = snprintf(buf, sizeof(buf),
			     "axis %d name=%s step=%d travel=%d tt=%.6f "
			     "an=%d range=%.6f rt=%.6f err=%.6f mono=%.6f\n",
			     i, a->name, a->step_counts, a->travel_counts,
			     a->travel_tolerance, a->analog.input,
			     a->analog.expected_range_v,
			     a->analog.range_tolerance, a->allowed_error,
			     a->monotonic_margin_v);
		if (n > 0)
			h = gl_fnv1a64(h, buf,
				       (size_t)n < sizeof(buf)
					   ? (size_t)n
					   : sizeof(buf) - 1);
	}
	return h;
}

static size_t dump_axis(const struct re_config_axis *a, char *buf, size_t cap)
{
	int n = snprintf(
	    buf, cap,
	    "; axis %s: v %d..%d counts/s, window %d..%d ms, "
	    "step %d, travel %d counts, PID %g/%g/%g, TL %g V, "
	    "ER %d%s, OA %s (OT %d, OV %g V), pot AN%d %g V "
	    "+-%g %%, allowed error %g, persistence %d",
	    a->name, a->vmin_cps, a->vmax_cps, a->accel_start_ms,
	    a->accel_end_ms, a->step_counts, a->travel_counts, a->kp, a->ki,
	    a->kd, a->torque_limit_v, a->position_error_limit_counts,
	    a->off_on_error ? " OE" : "",
	    a->encoder_failure.enabled ? "on" : "off",
	    a->encoder_failure.time_samples, a->encoder_failure.torque_v,
	    a->analog.input, a->analog.expected_range_v,
	    a->analog.range_tolerance * 100.0, a->allowed_error,
	    a->persistence_cycles);

	return n > 0 ? (size_t)n : 0;
}

int re_config_dump(const struct re_config *cfg, char *buf, size_t cap)
{
	char dummy[1];
	size_t n, total;
	int i;

	if (!buf || !cap) {
		buf = dummy;
		cap = sizeof(dummy);
	}
	n = (size_t)snprintf(
	    buf, cap,
	    "mode %s, period %d ms, controller %s (%s, timeout %d ms), "
	    "relay %s (%s, channel %d, backend %s, %d baud%s), watchdog "
	    "%g/%g x period, controller watchdog %d ms, joystick inputs "
	    "%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d%s, invalid timeout %d "
	    "ms, calibration %s, log %s (%ld bytes x %d), hash %016" PRIx64,
	    re_mode_name(cfg->mode), cfg->period_ms, cfg->controller.address,
	    cfg->controller.model, cfg->controller.timeout_ms,
	    re_config_relay_port(cfg), re_relay_proto_name(cfg->relay.protocol),
	    cfg->relay.channel, backend_names[cfg->relay.backend % 3],
	    cfg->relay.baud, cfg->relay.readback ? ", read-back" : "",
	    cfg->watchdog.noncritical_factor, cfg->watchdog.critical_factor,
	    cfg->watchdog.controller_timeout_ms, cfg->joystick.inputs[0],
	    cfg->joystick.inputs[1], cfg->joystick.inputs[2],
	    cfg->joystick.inputs[3], cfg->joystick.inputs[4],
	    cfg->joystick.inputs[5], cfg->joystick.inputs[6],
	    cfg->joystick.inputs[7], cfg->joystick.inputs[8],
	    cfg->joystick.inputs[9], cfg->joystick.inputs[10],
	    cfg->joystick.inputs[11],
	    cfg->joystick.active_low ? " (active low)" : "",
	    cfg->joystick.invalid_timeout_ms, cfg->calibration.file,
	    cfg->log.path, cfg->log.max_bytes, cfg->log.keep,
	    re_config_hash(cfg));
	total = n;
	for (i = 0; i < RE_AXES; i++)
		total += dump_axis(&cfg->axes[i],
				   buf + (total < cap ? total : cap - 1),
				   total < cap ? cap - total : 1);
	return (int)total;
}
