/*
 * base_yaml.c - the libyaml pieces the YAML loaders share (see
 * base_yaml.h). Not a schema walker: no key tables, no message wording.
 */
#include "base_yaml.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Reader errors carry a byte offset only: turn it into line and column. */
static yaml_mark_t offset_mark(const char *buf, size_t len, size_t off)
{
	yaml_mark_t m = {0, 0, 0};
	size_t i;

	for (i = 0; i < off && i < len; i++) {
		if (buf[i] == '\n') {
			m.line++;
			m.column = 0;
		} else {
			m.column++;
		}
	}
	m.index = off;
	return m;
}

/* Fill @e from the parser's error; return the code. */
static int parse_error(const yaml_parser_t *p, const char *buf, size_t len,
		       struct base_yaml_error *e)
{
	e->type = p->error;
	e->mark = p->problem_mark;
	if (p->error == YAML_READER_ERROR)
		e->mark = offset_mark(buf, len, p->problem_offset);
	e->problem = p->problem;
	e->context = p->context;
	e->context_mark = p->context_mark;
	return p->error == YAML_MEMORY_ERROR ? -ENOMEM : -EBADMSG;
}

/* After the first document: is the rest empty? 0 or a code. */
static int no_second(yaml_parser_t *p, const char *buf, size_t len,
		     struct base_yaml_error *e)
{
	yaml_document_t extra;
	int rc = 0;

	if (!yaml_parser_load(p, &extra))
		return parse_error(p, buf, len, e);
	if (yaml_document_get_root_node(&extra)) {
		e->type = YAML_NO_ERROR;
		e->mark = extra.start_mark;
		e->problem = "only one document is allowed";
		rc = BASE_YAML_EMORE;
	}
	yaml_document_delete(&extra);
	return rc;
}

int base_yaml_load(const char *buf, size_t len, int flags, yaml_document_t *doc,
		   struct base_yaml_error *e)
{
	yaml_parser_t p;
	int rc = 0;

	memset(e, 0, sizeof(*e));
	if (!yaml_parser_initialize(&p)) {
		e->type = YAML_MEMORY_ERROR;
		return -ENOMEM;
	}
	yaml_parser_set_input_string(&p, (const unsigned char *)buf, len);
	if (!yaml_parser_load(&p, doc)) {
		rc = parse_error(&p, buf, len, e);
		goto out_parser;
	}
	if ((flags & BASE_YAML_ONE_DOC) && yaml_document_get_root_node(doc)) {
		rc = no_second(&p, buf, len, e);
		if (rc)
			yaml_document_delete(doc);
	}
out_parser:
	yaml_parser_delete(&p);
	return rc;
}

void base_yaml_vformat(char *err, size_t errlen, const char *file,
		       const yaml_mark_t *m, const char *fmt, va_list ap)
{
	int n = 0;

	if (!err || !errlen)
		return;
	err[0] = '\0';
	if (file && m)
		n = snprintf(err, errlen, "%s:%zu:%zu: ", file, m->line + 1,
			     m->column + 1);
	else if (file)
		n = snprintf(err, errlen, "%s: ", file);
	if (n < 0 || (size_t)n >= errlen)
		return;
	vsnprintf(err + n, errlen - (size_t)n, fmt, ap);
}

const char *base_yaml_scalar(const yaml_node_t *n)
{
	return n && n->type == YAML_SCALAR_NODE
		   ? (const char *)n->data.scalar.value
		   : NULL;
}

int base_yaml_key(yaml_document_t *doc, const yaml_node_t *map,
		  const yaml_node_pair_t *p, yaml_node_t **key)
{
	const yaml_node_pair_t *q;
	yaml_node_t *k = yaml_document_get_node(doc, p->key);
	const char *s = base_yaml_scalar(k), *o;

	*key = k;
	if (!s)
		return -EINVAL;
	for (q = map->data.mapping.pairs.start; q < p; q++) {
		o = base_yaml_scalar(yaml_document_get_node(doc, q->key));
		if (o && !strcmp(o, s))
			return -EEXIST;
	}
	return 0;
}

int base_yaml_long(const yaml_node_t *n, long *out)
{
	const char *s = base_yaml_scalar(n);
	char *end;
	long v;

	if (!s || !*s)
		return -EINVAL;
	errno = 0;
	v = strtol(s, &end, 10);
	if (*end)
		return -EINVAL;
	if (errno == ERANGE)
		return -ERANGE;
	*out = v;
	return 0;
}

int base_yaml_double(const yaml_node_t *n, double *out)
{
	const char *s = base_yaml_scalar(n);
	char *end;
	double v;

	if (!s || !*s)
		return -EINVAL;
	errno = 0;
	v = strtod(s, &end);
	if (*end)
		return -EINVAL;
	if (errno == ERANGE || !isfinite(v))
		return -ERANGE;
	*out = v;
	return 0;
}

int base_yaml_bool(const yaml_node_t *n, bool *out)
{
	const char *s = base_yaml_scalar(n);

	if (s && !strcmp(s, "true"))
		*out = true;
	else if (s && !strcmp(s, "false"))
		*out = false;
	else
		return -EINVAL;
	return 0;
}
