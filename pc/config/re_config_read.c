/*
 * re_config_read.c - reading a YAML document against a table of fields:
 * the messages with their file:line:column, the scalars and their
 * ranges, the mappings and sequences (re_config_int.h).
 */
#include "re_config_int.h"

#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base_file.h"
#include "base_yaml.h"
#include "gl_err.h"
#include "gl_hash.h"
#include "gl_link.h"
#include "re_rt.h"

_Static_assert(sizeof(enum re_mode) == sizeof(int) &&
		   sizeof(enum re_relay_backend) == sizeof(int) &&
		   sizeof(enum re_record) == sizeof(int),
	       "FT_ENUM stores an int");

/* ---- messages and positions ---- */

static void vformat(struct pctx *c, const yaml_mark_t *m, const char *fmt,
		    va_list ap) __attribute__((format(printf, 3, 0)));
static void vformat(struct pctx *c, const yaml_mark_t *m, const char *fmt,
		    va_list ap)
{
	base_yaml_vformat(c->err, c->errlen, c->file, m, fmt, ap);
}

int cfg_fail_at(struct pctx *c, const yaml_mark_t *m, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vformat(c, m, fmt, ap);
	va_end(ap);
	return GL_ERR_CONFIG;
}

void cfg_seen_add(struct pctx *c, const void *field, yaml_mark_t m)
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

const yaml_mark_t *cfg_seen_mark(const struct pctx *c, const void *field)
{
	int i;

	for (i = 0; i < c->nseen; i++)
		if (c->seen[i].field == field)
			return &c->seen[i].mark;
	return NULL;
}

/*
 * cfg_later_mark() - the position of whichever of @a, @b (either may be NULL)
 * was written later in the file; the root when neither was, NULL when
 * validating without a document.
 */
const yaml_mark_t *cfg_later_mark(const struct pctx *c, const void *a,
				  const void *b)
{
	const yaml_mark_t *ma = a ? cfg_seen_mark(c, a) : NULL;
	const yaml_mark_t *mb = b ? cfg_seen_mark(c, b) : NULL;

	if (!c->file)
		return NULL;
	if (ma && mb)
		return ma->index >= mb->index ? ma : mb;
	if (ma || mb)
		return ma ? ma : mb;
	return &c->root_mark;
}

/* Format a bound: integers without exponent, others with %g. */
const char *cfg_num_text(double v, char *buf, size_t cap)
{
	if (v == floor(v) && fabs(v) < 1e15)
		snprintf(buf, cap, "%.0f", v);
	else
		snprintf(buf, cap, "%g", v);
	return buf;
}

const char *cfg_node_kind(const yaml_node_t *v)
{
	if (v->type == YAML_MAPPING_NODE)
		return "a mapping";
	if (v->type == YAML_SEQUENCE_NODE)
		return "a list";
	return "a value";
}

/* The text of @v, known to be a scalar. */
const char *cfg_scalar(const yaml_node_t *v)
{
	return (const char *)v->data.scalar.value;
}

bool cfg_quoted(const yaml_node_t *v)
{
	return v->data.scalar.style != YAML_PLAIN_SCALAR_STYLE;
}

/* cfg_type_error() - "expected WHAT for 'KEY', got 'TEXT'" at the value. */
int cfg_type_error(struct pctx *c, const yaml_node_t *v, const char *what,
		   const char *key)
{
	if (v->type != YAML_SCALAR_NODE)
		return cfg_fail_at(c, &v->start_mark,
				   "expected %s for '%s', got %s", what, key,
				   cfg_node_kind(v));
	if (v->data.scalar.length == 0 && !cfg_quoted(v))
		return cfg_fail_at(c, &v->start_mark, "missing value for '%s'",
				   key);
	if (cfg_quoted(v))
		return cfg_fail_at(c, &v->start_mark,
				   "expected %s for '%s', got a quoted string",
				   what, key);
	return cfg_fail_at(c, &v->start_mark,
			   "expected %s for '%s', got '%.*s'", what, key,
			   TEXT_SHOWN, cfg_scalar(v));
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

int cfg_range_error(struct pctx *c, const yaml_mark_t *m, const char *key,
		    double min, double max, const char *got)
{
	char a[32], b[32];

	return cfg_fail_at(c, m, "'%s' must be between %s and %s, got %.*s",
			   key, cfg_num_text(min, a, sizeof(a)),
			   cfg_num_text(max, b, sizeof(b)), TEXT_SHOWN, got);
}

/*
 * cfg_get_integer() - an integer scalar that fits [lo, hi], the C type.
 * Values that do not fit are reported against the field's own range [min, max];
 * the struct-level check reports the others, so both give one message.
 */
int cfg_get_integer(struct pctx *c, yaml_node_t *v, const char *key, double min,
		    double max, long long lo, long long hi, long long *out)
{
	const char *s;
	long l;

	if (v->type != YAML_SCALAR_NODE || cfg_quoted(v))
		return cfg_type_error(c, v, "an integer", key);
	s = cfg_scalar(v);
	if (!is_int_text(s)) {
		if (is_num_text(s))
			return cfg_type_error(c, v, "an integer", key);
		return cfg_type_error(c, v, "a number", key);
	}
	if (base_yaml_long(v, &l) != 0 || l < lo || l > hi)
		return cfg_range_error(c, &v->start_mark, key, min, max, s);
	*out = l;
	return GL_OK;
}

static int get_double(struct pctx *c, yaml_node_t *v, const char *key,
		      double *out)
{
	const char *s;

	if (v->type != YAML_SCALAR_NODE || cfg_quoted(v) ||
	    !is_num_text(cfg_scalar(v)))
		return cfg_type_error(c, v, "a number", key);
	s = cfg_scalar(v);
	if (base_yaml_double(v, out) != 0)
		return cfg_fail_at(c, &v->start_mark,
				   "'%s' is out of range, got %.*s", key,
				   TEXT_SHOWN, s);
	return GL_OK;
}

static int get_bool(struct pctx *c, yaml_node_t *v, const char *key, bool *out)
{
	if (v->type == YAML_SCALAR_NODE && !cfg_quoted(v) &&
	    base_yaml_bool(v, out) == 0)
		return GL_OK;
	return cfg_type_error(c, v, "true or false", key);
}

static int get_string(struct pctx *c, yaml_node_t *v, const char *key,
		      char *dst, size_t size)
{
	size_t i, len;
	const unsigned char *s;

	if (v->type != YAML_SCALAR_NODE)
		return cfg_type_error(c, v, "a string", key);
	s = v->data.scalar.value;
	len = v->data.scalar.length;
	for (i = 0; i < len; i++)
		if (s[i] < 0x20 || s[i] == 0x7f)
			return cfg_fail_at(c, &v->start_mark,
					   "'%s' contains a control character",
					   key);
	if (len >= size)
		return cfg_fail_at(c, &v->start_mark,
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

int cfg_get_enum(struct pctx *c, yaml_node_t *v, const char *key,
		 const char *const *names, int *out)
{
	char list[96];
	int i;

	if (v->type == YAML_SCALAR_NODE) { /* "development" is fine too */
		for (i = 0; names[i]; i++) {
			if (!strcmp(cfg_scalar(v), names[i])) {
				*out = i;
				return GL_OK;
			}
		}
	}
	names_text(names, list, sizeof(list));
	if (v->type != YAML_SCALAR_NODE || (!cfg_quoted(v) && !*cfg_scalar(v)))
		return cfg_type_error(c, v, list, key);
	return cfg_fail_at(c, &v->start_mark, "'%s' must be %s, got '%.*s'",
			   key, list, TEXT_SHOWN, cfg_scalar(v));
}

/* ---- mappings ---- */

yaml_node_t *cfg_node_at(struct pctx *c, int index)
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
		rc = cfg_get_integer(c, v, f->key, f->min, f->max, INT_MIN,
				     INT_MAX, &ll);
		if (!rc)
			*(int *)dst = (int)ll;
		break;
	case FT_LONG:
		rc = cfg_get_integer(c, v, f->key, f->min, f->max, LONG_MIN,
				     LONG_MAX, &ll);
		if (!rc)
			*(long *)dst = (long)ll;
		break;
	case FT_DOUBLE: rc = get_double(c, v, f->key, dst); break;
	case FT_BOOL: rc = get_bool(c, v, f->key, dst); break;
	case FT_STR: rc = get_string(c, v, f->key, dst, f->size); break;
	case FT_ENUM:
		rc = cfg_get_enum(c, v, f->key, f->aux, &e);
		if (!rc)
			memcpy(dst, &e, sizeof(e)); /* int-sized enums */
		break;
	case FT_MAP: return cfg_parse_map(c, v, f->aux, dst, f->key);
	case FT_CUSTOM: return f->fn(c, f, v, base);
	default: return GL_ERR_ARG;
	}
	if (!rc)
		cfg_seen_add(c, dst, v->start_mark);
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
		return cfg_fail_at(c, k ? &k->start_mark : &map->start_mark,
				   "expected a key name, got %s",
				   k ? cfg_node_kind(k) : "nothing");
	if (rc == -EEXIST)
		return cfg_fail_at(c, &k->start_mark, "duplicate key '%.*s'",
				   TEXT_SHOWN, cfg_scalar(k));
	*key = k;
	return GL_OK;
}

int cfg_parse_map(struct pctx *c, yaml_node_t *map, const struct field *tab,
		  void *base, const char *key)
{
	yaml_node_pair_t *p;
	yaml_node_t *k = NULL, *v;
	const struct field *f;
	int rc;

	if (map->type != YAML_MAPPING_NODE)
		return cfg_type_error(c, map, "a mapping", key);
	for (p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top;
	     p++) {
		rc = map_key(c, map, p, &k);
		if (rc)
			return rc;
		f = field_find(tab, cfg_scalar(k));
		if (!f)
			return cfg_fail_at(c, &k->start_mark,
					   "unknown key '%.*s'", TEXT_SHOWN,
					   cfg_scalar(k));
		v = cfg_node_at(c, p->value);
		if (!v)
			return cfg_fail_at(c, &k->start_mark,
					   "missing value for '%s'", f->key);
		rc = parse_field(c, f, v, base);
		if (rc)
			return rc;
	}
	return GL_OK;
}

/* ---- values not filled in ---- */

/* Deeper than any key of the schema (axes[i].analog.input is four levels
 * down): a placeholder below sits where the schema refuses anything, and
 * the walk's recursion stays shallow whatever the nesting. */
#define FILL_DEPTH_MAX 8
#define FILL_PATH_MAX  128 /* bytes of a key path, e.g. axes[2].analog.input */
/* Room kept for the last line "... and N more" */
#define FILL_TAIL 32

/* One walk over the document: counting, or writing the lines into @out. */
struct fill {
	struct pctx *c;
	unsigned char *seen; /* per node of the document: walked already (an
			      * alias is the same node again: each is walked
			      * and reported once, the walk stays linear) */
	char *out;	     /* NULL: count only */
	size_t cap;	     /* size of @out */
	size_t used;	     /* strlen(@out) */
	bool full;	     /* a line did not fit: no more are written */
	int count;	     /* placeholders found */
	int shown;	     /* of them, written */
};

static bool is_fill_in(const yaml_node_t *v)
{
	return v->type == YAML_SCALAR_NODE &&
	       v->data.scalar.length == sizeof(RE_CONFIG_FILL_IN) - 1 &&
	       !memcmp(v->data.scalar.value, RE_CONFIG_FILL_IN,
		       sizeof(RE_CONFIG_FILL_IN) - 1);
}

/* The line of the placeholder at @v, key path @path, when it fits whole. */
static void fill_add(struct fill *f, const yaml_node_t *v, const char *path)
{
	char line[FILL_PATH_MAX + RE_PATH_MAX + 64];
	int n;

	f->count++;
	if (!f->out || f->full)
		return;
	n = snprintf(line, sizeof(line), "\n%s:%zu:%zu: '%s' is still %s",
		     f->c->file, v->start_mark.line + 1,
		     v->start_mark.column + 1, path, RE_CONFIG_FILL_IN);
	if (n < 0 || f->used + (size_t)n + FILL_TAIL >= f->cap) {
		f->full = true;
		return;
	}
	memcpy(f->out + f->used, line, (size_t)n + 1);
	f->used += (size_t)n;
	f->shown++;
}

/* Walk @v, whose key path is @path (@plen bytes used of FILL_PATH_MAX). */
static void fill_walk(struct fill *f, yaml_node_t *v, char *path, size_t plen,
		      int depth)
{
	yaml_node_pair_t *p;
	yaml_node_item_t *it;
	const char *k;

	if (!v || depth > FILL_DEPTH_MAX || f->seen[v - f->c->doc->nodes.start])
		return;
	f->seen[v - f->c->doc->nodes.start] = 1;
	if (is_fill_in(v)) {
		fill_add(f, v, path);
	} else if (v->type == YAML_MAPPING_NODE) {
		for (p = v->data.mapping.pairs.start;
		     p < v->data.mapping.pairs.top; p++) {
			k = base_yaml_scalar(cfg_node_at(f->c, p->key));
			snprintf(path + plen, FILL_PATH_MAX - plen, "%s%.*s",
				 plen ? "." : "", TEXT_SHOWN, k ? k : "?");
			fill_walk(f, cfg_node_at(f->c, p->value), path,
				  strlen(path), depth + 1);
		}
	} else if (v->type == YAML_SEQUENCE_NODE) {
		for (it = v->data.sequence.items.start;
		     it < v->data.sequence.items.top; it++) {
			snprintf(path + plen, FILL_PATH_MAX - plen, "[%d]",
				 (int)(it - v->data.sequence.items.start));
			fill_walk(f, cfg_node_at(f->c, *it), path, strlen(path),
				  depth + 1);
		}
	}
	path[plen] = '\0';
}

int cfg_fill_check(struct pctx *c, yaml_node_t *root)
{
	size_t nodes = (size_t)(c->doc->nodes.top - c->doc->nodes.start);
	struct fill f = {.c = c, .seen = calloc(nodes ? nodes : 1, 1)};
	char path[FILL_PATH_MAX] = "";
	int n;

	if (!f.seen) {
		cfg_fail_at(c, NULL, "out of memory");
		return GL_ERR_NOMEM;
	}
	/* a first walk counts, so that the header can say how many */
	fill_walk(&f, root, path, 0, 0);
	n = f.count;
	if (n)
		cfg_fail_at(c, NULL,
			    "this site's configuration is not finished: %d "
			    "value%s still %s",
			    n, n == 1 ? " is" : "s are", RE_CONFIG_FILL_IN);
	if (n && c->err && c->errlen) {
		memset(f.seen, 0, nodes);
		f.out = c->err;
		f.cap = c->errlen;
		f.used = strlen(c->err);
		f.count = 0;
		fill_walk(&f, root, path, 0, 0);
		if (f.shown < f.count)
			snprintf(c->err + f.used, c->errlen - f.used,
				 "\n... and %d more", f.count - f.shown);
	}
	free(f.seen);
	return n ? GL_ERR_CONFIG : GL_OK;
}
