/*
 * gload_check.c - galil-load's offline check: the preprocessed program
 * goes through the DMC linter (pc/dmc/dmc_lint.h) and each finding is
 * formatted at its source line. No rule lives here.
 */
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "dmc_lint.h"
#include "gload_check.h"

/* The program as downloaded, without the identity line: the lines joined
 * with LF. Return a malloc'd buffer (length in *@len) or NULL. */
static char *join_lines(const struct gload_prog *p, size_t *len)
{
	size_t n = 0;
	char *buf;
	int i;

	for (i = 0; i < p->nlines; i++)
		n += p->lines[i].len + 1;
	buf = malloc(n + 1);
	if (!buf)
		return NULL;
	for (n = 0, i = 0; i < p->nlines; i++) {
		memcpy(buf + n, p->lines[i].text, p->lines[i].len);
		n += p->lines[i].len;
		buf[n++] = '\n';
	}
	*len = n;
	return buf;
}

/* "FILE:LINE: rule: message", at the source line of program line @f->line
 * (line 0: the first file, "FILE: rule: message"). */
static int format_finding(const struct gload_prog *p,
			  const struct dmc_finding *f, struct gload_diags *d)
{
	const char *rule = dmc_rule(f->rule)->name;
	const struct gload_line *l, *r;

	if (f->line < 1 || f->line > p->nlines)
		return gload_diags_add(d, p->nfiles ? p->file_order[0] : -1,
				       p->nfiles ? p->files[0] : "(no files)",
				       0, "%s: %s", rule, f->msg);
	l = &p->lines[f->line - 1];
	if (f->ref_line < 1 || f->ref_line > p->nlines)
		return gload_diags_add(d, p->file_order[l->file],
				       p->files[l->file], l->src_line, "%s: %s",
				       rule, f->msg);
	r = &p->lines[f->ref_line - 1];
	return gload_diags_add(d, p->file_order[l->file], p->files[l->file],
			       l->src_line, "%s: %s (first at %s:%d)", rule,
			       f->msg, p->files[r->file], r->src_line);
}

int gload_check(const struct gload_prog *p, const struct dmc_model *m,
		struct gload_diags *d, struct gload_stats *st)
{
	struct dmc_lint r = {0};
	size_t len = 0;
	char *text = join_lines(p, &len);
	int i, n, rc = 0;

	if (st)
		memset(st, 0, sizeof(*st));
	if (!text)
		return GL_ERR_NOMEM;
	/* + 1: the identity line galil-load appends (gload_prog_finish) */
	n = dmc_lint_text(text, len, m, 1, &r);
	for (i = 0; i < r.n; i++)
		if (format_finding(p, &r.v[i], d))
			rc = GL_ERR_NOMEM;
	if (st && p->nlines > 0) {
		st->lines = r.lines;
		st->labels = r.labels;
		st->vars = r.vars;
	}
	dmc_lint_free(&r);
	free(text);
	return n < 0 || rc ? GL_ERR_NOMEM : n;
}
