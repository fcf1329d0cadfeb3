/*
 * base_yaml.h - what the YAML loaders share: one libyaml document from a
 * buffer (with the position and text of a syntax error), the "FILE:LINE:
 * COLUMN: " message prefix, mapping keys (scalar, not repeated) and the
 * conversion of scalars to numbers and booleans.
 *
 * It is not a schema: which keys exist, their ranges and the wording of
 * every message stay with the loaders (re_config, sim_plant_cfg). Nothing
 * prints; errors are negative errno values, positions are libyaml's
 * 0-based marks (messages show them 1-based).
 */
#ifndef BASE_YAML_H
#define BASE_YAML_H

#include <errno.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <yaml.h>

/* Why base_yaml_load() failed, for the caller's message. */
struct base_yaml_error {
	yaml_error_type_t type;	  /* libyaml's class; YAML_NO_ERROR for
				   * BASE_YAML_EMORE */
	yaml_mark_t mark;	  /* where (0-based); for a reader error
				   * (bad encoding) made from the byte offset */
	const char *problem;	  /* libyaml's static text, NULL if none */
	const char *context;	  /* libyaml's static text, NULL if none */
	yaml_mark_t context_mark; /* where @context starts */
};

/* base_yaml_load() flag: a second document in the stream is an error. */
#define BASE_YAML_ONE_DOC 1

/* base_yaml_load() code: the stream has a second document. */
#define BASE_YAML_EMORE (-ENOTUNIQ)

/*
 * base_yaml_load() - parse the first document of the @len bytes at @buf
 * into @doc (libyaml's yaml_parser_load; @buf need not be NUL-terminated).
 * @flags: 0, or BASE_YAML_ONE_DOC to also parse the rest and refuse a
 *         second document.
 * @e:     out, on error only: type, position and text of the problem
 *         (for BASE_YAML_EMORE: mark = the second document's start).
 * Return: 0, @doc loaded: the caller owns it and frees it with
 *         yaml_document_delete() (an empty stream gives a document without
 *         a root node); on error @doc holds nothing: -ENOMEM (libyaml ran
 *         out of memory), -EBADMSG (syntax or encoding error),
 *         BASE_YAML_EMORE.
 */
int base_yaml_load(const char *buf, size_t len, int flags, yaml_document_t *doc,
		   struct base_yaml_error *e);

/*
 * base_yaml_vformat() - write "@file:LINE:COLUMN: " (1-based, from the
 * 0-based mark @m) then the printf-style message into @err (@errlen bytes,
 * always NUL-terminated, cut if too long). @m NULL: "@file: " only; @file
 * NULL: the message alone. Does nothing when @err is NULL or @errlen 0.
 */
void base_yaml_vformat(char *err, size_t errlen, const char *file,
		       const yaml_mark_t *m, const char *fmt, va_list ap)
    __attribute__((format(printf, 5, 0)));

/*
 * base_yaml_scalar() - the text of scalar node @n (NUL-terminated, owned by
 * the document), or NULL when @n is NULL or not a scalar.
 */
const char *base_yaml_scalar(const yaml_node_t *n);

/*
 * base_yaml_key() - the key node of pair @p of mapping @map in @doc, after
 * checking that it is a scalar and that no earlier pair of @map has the same
 * key text.
 * @key: out: the key node (NULL if the pair has none); set on every return.
 * Return: 0; -EINVAL when the key is missing or not a scalar; -EEXIST when
 *         an earlier key of @map has the same text.
 */
int base_yaml_key(yaml_document_t *doc, const yaml_node_t *map,
		  const yaml_node_pair_t *p, yaml_node_t **key);

/*
 * base_yaml_long() - scalar @n as a base-10 long (strtol: the whole text,
 * optional sign). base_yaml_double() - scalar @n as a finite double
 * (strtod: the whole text).
 * @out: set only on success.
 * Return: 0; -EINVAL when @n is NULL, not a scalar, empty or not wholly a
 *         number; -ERANGE when the number does not fit (long), or is out of
 *         range or not finite (double).
 */
int base_yaml_long(const yaml_node_t *n, long *out);
int base_yaml_double(const yaml_node_t *n, double *out);

/*
 * base_yaml_bool() - scalar @n as a boolean: exactly "true" or "false"
 * (any quoting style: callers that refuse quoted values check the style).
 * @out: set only on success.
 * Return: 0; -EINVAL for anything else.
 */
int base_yaml_bool(const yaml_node_t *n, bool *out);

#endif /* BASE_YAML_H */
