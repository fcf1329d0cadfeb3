/*
 * re_config_int.h - what the parts of the configuration loader share
 * (re_config.c, re_config_read.c, re_config_schema.c, re_config_check.c):
 * the field table's types, the parse context, and the reader's functions.
 * Not for the rest of roboelf: re_config.h is the interface.
 */
#ifndef RE_CONFIG_INT_H
#define RE_CONFIG_INT_H

#include <stdbool.h>
#include <stddef.h>
#include <yaml.h>

#include "re_config.h"

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

/* The names of the enumerations, NULL-ended, and the relay's baud rates. */
extern const char *const cfg_mode_names[];
extern const char *const cfg_backend_names[];
extern const char *const cfg_unit_names[];
extern const char *const cfg_record_names[];
extern const char *const cfg_proto_names[];
extern const int cfg_bauds[8];

/* cfg_fail_at() - message at mark @m (NULL: no position). Returns the code. */
int cfg_fail_at(struct pctx *c, const yaml_mark_t *m, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/*
 * The reader (re_config_read.c). Each returns GL_OK or GL_ERR_CONFIG with
 * the message, at the value's file:line:column, in @c->err:
 * cfg_get_enum() - @v one of @names (NULL-ended): its index in *@out.
 * cfg_get_integer() - @v a whole number within @min..@max (and @lo..@hi).
 * cfg_parse_map() - the mapping @map walked with @tab into @base (@key: the
 *                   mapping's own key, for messages).
 * cfg_range_error(), cfg_type_error() - the message of a value out of its
 *                   range or of the wrong kind (@got: the text found).
 * Without a return code:
 * cfg_seen_add(), cfg_seen_mark() - where the value of the field at @field
 *                   was written (NULL: not seen); cfg_later_mark() the later
 *                   of two.
 * cfg_node_at(), cfg_node_kind(), cfg_scalar(), cfg_quoted() - a document's
 *                   node by index, its kind in words, its scalar text (NULL:
 *                   not a scalar), whether it was quoted.
 * cfg_num_text() - @v as the shortest exact text, in @buf.
 */
int cfg_get_enum(struct pctx *c, yaml_node_t *v, const char *key,
		 const char *const *names, int *out);
int cfg_get_integer(struct pctx *c, yaml_node_t *v, const char *key, double min,
		    double max, long long lo, long long hi, long long *out);
const yaml_mark_t *cfg_later_mark(const struct pctx *c, const void *a,
				  const void *b);
yaml_node_t *cfg_node_at(struct pctx *c, int index);
const char *cfg_node_kind(const yaml_node_t *v);
const char *cfg_num_text(double v, char *buf, size_t cap);
int cfg_parse_map(struct pctx *c, yaml_node_t *map, const struct field *tab,
		  void *base, const char *key);
bool cfg_quoted(const yaml_node_t *v);
int cfg_range_error(struct pctx *c, const yaml_mark_t *m, const char *key,
		    double min, double max, const char *got);
const char *cfg_scalar(const yaml_node_t *v);
void cfg_seen_add(struct pctx *c, const void *field, yaml_mark_t m);
const yaml_mark_t *cfg_seen_mark(const struct pctx *c, const void *field);
int cfg_type_error(struct pctx *c, const yaml_node_t *v, const char *what,
		   const char *key);
/*
 * cfg_fill_check() - every RE_CONFIG_FILL_IN scalar under @root (of
 * @c->doc), quoted or not, wherever the schema could take a value
 * (re_config_read.c); one met again through an alias counts once.
 * Return: GL_OK when there is none; GL_ERR_CONFIG with the header line and
 * one line per value, in file order, in @c->err (re_config_parse());
 * GL_ERR_NOMEM.
 */
int cfg_fill_check(struct pctx *c, yaml_node_t *root);
/*
 * The schema (re_config_schema.c): cfg_root_fields, the whole file's
 * table, cfg_axis_fields, one axis's (the defaults are there too:
 * re_config_defaults()).
 */
extern const struct field cfg_axis_fields[];
extern const struct field cfg_root_fields[];
/*
 * The validation (re_config_check.c): cfg_check_all() - every rule on
 * @cfg; cfg_check_table() - the ranges of @tab's fields in @base.
 * Return: GL_OK, or GL_ERR_CONFIG with the message in @c->err.
 */
int cfg_check_all(struct pctx *c, const struct re_config *cfg);
int cfg_check_table(struct pctx *c, const struct field *tab, const void *base);

#endif /* RE_CONFIG_INT_H */
