/* gload_diag.c - the diagnostics list; see gload_diag.h. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "gl_err.h"
#include "gload_diag.h"

static int diags_grow(struct gload_diags *d)
{
	int cap = d->cap ? d->cap * 2 : 16;
	struct gload_diag *v;

	v = realloc(d->v, (size_t)cap * sizeof(*v));
	if (!v)
		return GL_ERR_NOMEM;
	d->v = v;
	d->cap = cap;
	return GL_OK;
}

__attribute__((format(printf, 3, 0))) static char *
format_text(const char *path, int line, const char *fmt, va_list ap)
{
	char msg[512];
	char *text;
	int n;

	vsnprintf(msg, sizeof(msg), fmt, ap);
	if (line > 0)
		n = snprintf(NULL, 0, "%s:%d: %s", path, line, msg);
	else
		n = snprintf(NULL, 0, "%s: %s", path, msg);
	text = malloc((size_t)n + 1);
	if (!text)
		return NULL;
	if (line > 0)
		snprintf(text, (size_t)n + 1, "%s:%d: %s", path, line, msg);
	else
		snprintf(text, (size_t)n + 1, "%s: %s", path, msg);
	return text;
}

int gload_diags_add(struct gload_diags *d, int file_idx, const char *path,
		    int line, const char *fmt, ...)
{
	struct gload_diag *g;
	va_list ap;
	char *text;

	if (d->n == d->cap && diags_grow(d) != GL_OK) {
		d->dropped++;
		return GL_ERR_NOMEM;
	}
	va_start(ap, fmt);
	text = format_text(path, line, fmt, ap);
	va_end(ap);
	if (!text) {
		d->dropped++;
		return GL_ERR_NOMEM;
	}
	g = &d->v[d->n];
	g->file = file_idx;
	g->line = line;
	g->seq = d->n;
	g->text = text;
	d->n++;
	return GL_OK;
}

static int diag_cmp(const void *a, const void *b)
{
	const struct gload_diag *x = a, *y = b;

	if (x->file != y->file)
		return x->file < y->file ? -1 : 1;
	if (x->line != y->line)
		return x->line < y->line ? -1 : 1;
	return (x->seq > y->seq) - (x->seq < y->seq);
}

void gload_diags_sort(struct gload_diags *d)
{
	if (d->n > 1)
		qsort(d->v, (size_t)d->n, sizeof(*d->v), diag_cmp);
}

void gload_diags_free(struct gload_diags *d)
{
	int i;

	for (i = 0; i < d->n; i++)
		free(d->v[i].text);
	free(d->v);
	d->v = NULL;
	d->n = d->cap = d->dropped = 0;
}
