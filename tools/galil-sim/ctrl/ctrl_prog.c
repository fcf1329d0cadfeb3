/*
 * ctrl_prog.c - program memory. A download is checked whole and either
 * replaces the program or is refused (the old program is then erased too,
 * see docs/galil-sim-controller.md): lines of at most 80 characters, at
 * most 4000 lines (TC 60), labels '#' + 1..7 letters, digits or '_'
 * starting with a letter (the DMC-40x0's rule, dmc_model.h), unique, at
 * most 510 (TC 61, 62).
 *
 * Each line is split into statements at ';' outside "strings"; REM makes
 * the rest of the line a comment, ' and NO only up to the next ';'.
 * IF/ELSE/ENDIF are matched once here, in program order, the way the
 * firmware skips forward at run time.
 */
#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#include "ctrl_prog.h"
#include "ctrl_var.h"
#include "dmc_model.h"
#include "dmc_rule.h"
#include "dmc_text.h"

struct split {
	const char *s;
	size_t n;
};

/* Next line of @text (CR, LF or CR LF ends a line). Return 0 at the end. */
static int next_line(const char **pos, const char *end, struct split *out)
{
	const char *s = *pos, *e = s;

	if (s >= end)
		return 0;
	while (e < end && *e != '\r' && *e != '\n')
		e++;
	out->s = s;
	out->n = (size_t)(e - s);
	if (e < end && *e == '\r')
		e++;
	if (e < end && *e == '\n')
		e++;
	*pos = e;
	return 1;
}

/* Label at the start of a line: 0 none, 1 ok (key set), or TC 61. */
static int line_label(const char *s, size_t n, uint64_t *key)
{
	size_t k;

	if (n == 0 || s[0] != '#')
		return 0;
	for (k = 1; k < n && dmc_is_name_char(s[k]); k++)
		;
	/* the characters by the DMC-40x0's rule, '_' included (dmc_model) */
	if (k - 1 < 1 || k - 1 > CTRL_LABEL_MAX ||
	    !dmc_label_ok_model(dmc_model_default(), s + 1, k - 1))
		return 61;
	if (k < n && s[k] != ';' && s[k] != ' ' && s[k] != '\'')
		return 61;
	if (ctrl_name_key(s + 1, k - 1, key))
		return 61;
	return 1;
}

static int label_cmp(const void *a, const void *b)
{
	uint64_t ka = ((const struct ctrl_label *)a)->key;
	uint64_t kb = ((const struct ctrl_label *)b)->key;

	return ka < kb ? -1 : ka > kb;
}

/* Flow kind of the statement text s[0..n). */
static int stmt_flow(const char *s, size_t n)
{
	char w[8];
	size_t i = 0, k;

	while (i < n && s[i] == ' ')
		i++;
	for (k = 0; i + k < n && k < 7 && isalnum((unsigned char)s[i + k]); k++)
		w[k] = s[i + k];
	w[k] = '\0';
	if (!strcmp(w, "ELSE"))
		return CTRL_FLOW_ELSE;
	if (!strcmp(w, "ENDIF"))
		return CTRL_FLOW_ENDIF;
	if (k >= 2 && w[0] == 'I' && w[1] == 'F') {
		i += k;
		while (i < n && s[i] == ' ')
			i++;
		if (i < n && (s[i] == '=' || s[i] == '['))
			return CTRL_FLOW_NONE; /* a variable IFxx= */
		return CTRL_FLOW_IF;
	}
	return CTRL_FLOW_NONE;
}

/* Split line @ln into statements, appending to p->stmt. */
static void split_line(struct ctrl_prog *p, int ln)
{
	const char *s = p->line[ln];
	size_t n = strlen(s), i = 0, start = 0;
	int quote = 0;

	p->first[ln] = p->nstmts;
	for (;; i++) {
		if (i < n && s[i] == '"')
			quote = !quote;
		if (i < n && (quote || s[i] != ';'))
			continue;
		if (i < n && dmc_is_rem(s + start, i - start))
			continue; /* REM runs to the end of the line */
		p->stmt[p->nstmts].line = ln;
		p->stmt[p->nstmts].off = (uint8_t)start;
		p->stmt[p->nstmts].len = (uint8_t)(i - start);
		p->stmt[p->nstmts].flow =
		    (uint8_t)stmt_flow(s + start, i - start);
		p->stmt[p->nstmts].match = -1;
		p->stmt[p->nstmts].text = (int)p->pool_len;
		memcpy(p->pool + p->pool_len, s + start, i - start);
		p->pool_len += i - start;
		p->pool[p->pool_len++] = '\0';
		p->nstmts++;
		if (i >= n)
			break;
		start = i + 1;
	}
}

/* Match IF -> ELSE/ENDIF and ELSE -> ENDIF in program order. */
static int match_ifs(struct ctrl_prog *p)
{
	int *stack, depth = 0, i;

	stack = malloc(sizeof(int) * (size_t)(p->nstmts + 1));
	if (!stack)
		return -1;
	for (i = 0; i < p->nstmts; i++) {
		struct ctrl_stmt *st = &p->stmt[i];

		if (st->flow == CTRL_FLOW_IF) {
			stack[depth++] = i;
		} else if (st->flow == CTRL_FLOW_ELSE && depth) {
			p->stmt[stack[depth - 1]].match = i;
			stack[depth - 1] = i;
		} else if (st->flow == CTRL_FLOW_ENDIF && depth) {
			p->stmt[stack[--depth]].match = i;
		}
	}
	free(stack);
	return 0;
}

static int count_lines(const char *text, size_t len, int *bad_line)
{
	const char *pos = text, *end = text + len;
	struct split l;
	int n = 0;

	while (next_line(&pos, end, &l)) {
		n++;
		if (l.n > CTRL_LINE_MAX || n > CTRL_PROG_LINES) {
			*bad_line = n;
			return -1;
		}
	}
	return n;
}

static int alloc_prog(struct ctrl_prog *p, int nlines, size_t nstmts,
		      size_t pool)
{
	memset(p, 0, sizeof(*p));
	p->line = calloc((size_t)nlines + 1, sizeof(*p->line));
	p->first = calloc((size_t)nlines + 1, sizeof(int));
	p->stmt = calloc(nstmts + 1, sizeof(*p->stmt));
	p->label = calloc(CTRL_LABELS, sizeof(*p->label));
	p->pool = malloc(pool + 1);
	p->pool_cap = pool + 1;
	if (!p->line || !p->first || !p->stmt || !p->label || !p->pool) {
		ctrl_prog_free(p);
		return -1;
	}
	return 0;
}

/* Copy the lines in and collect the labels. Return 0 or a TC. */
static int fill_lines(struct ctrl_prog *p, const char *text, size_t len,
		      int *bad_line)
{
	const char *pos = text, *end = text + len;
	struct split l;
	uint64_t key;
	int rc, i;

	while (next_line(&pos, end, &l)) {
		memcpy(p->line[p->nlines], l.s, l.n);
		p->line[p->nlines][l.n] = '\0';
		p->nlines++;
		rc = line_label(l.s, l.n, &key);
		if (rc == 0)
			continue;
		*bad_line = p->nlines;
		if (rc != 1)
			return rc;
		for (i = 0; i < p->nlabels; i++)
			if (p->label[i].key == key)
				return 61;
		if (p->nlabels >= CTRL_LABELS)
			return 62;
		p->label[p->nlabels].key = key;
		p->label[p->nlabels++].line = p->nlines - 1;
	}
	return 0;
}

/*
 * ctrl_prog_load() - check and load a program text into @p (replaced).
 * @bad_line: [out] 1-based line of the first error.
 * @tc: [out] its TC code (60, 61, 62).
 * Return: 0, a TC code (p is then empty), or -1 when out of memory.
 */
int ctrl_prog_load(struct ctrl_prog *p, const char *text, size_t len,
		   int *bad_line, int *tc)
{
	int n, i, rc;

	*bad_line = 0;
	*tc = 0;
	n = count_lines(text, len, bad_line);
	if (n < 0) {
		*tc = 60;
		return 60;
	}
	/* statements <= ';' + lines; texts <= characters + one NUL each */
	if (alloc_prog(p, n, len + (size_t)n, 2 * len + (size_t)n))
		return -1;
	rc = fill_lines(p, text, len, bad_line);
	if (rc) {
		ctrl_prog_free(p);
		*tc = rc;
		return rc;
	}
	*bad_line = 0;
	for (i = 0; i < p->nlines; i++)
		split_line(p, i);
	p->first[p->nlines] = p->nstmts;
	qsort(p->label, (size_t)p->nlabels, sizeof(*p->label), label_cmp);
	if (match_ifs(p)) {
		ctrl_prog_free(p);
		return -1;
	}
	return 0;
}

void ctrl_prog_free(struct ctrl_prog *p)
{
	free(p->line);
	free(p->first);
	free(p->stmt);
	free(p->label);
	free(p->pool);
	memset(p, 0, sizeof(*p));
}

/* ctrl_prog_copy() - deep copy (BP). Return 0 or -1 (out of memory). */
int ctrl_prog_copy(struct ctrl_prog *dst, const struct ctrl_prog *src)
{
	struct ctrl_prog tmp;

	if (alloc_prog(&tmp, src->nlines, (size_t)src->nstmts, src->pool_len))
		return -1;
	if (src->pool_len)
		memcpy(tmp.pool, src->pool, src->pool_len);
	tmp.pool_len = src->pool_len;
	if (src->nlines) {
		memcpy(tmp.line, src->line,
		       sizeof(*src->line) * (size_t)src->nlines);
		memcpy(tmp.first, src->first,
		       sizeof(int) * (size_t)(src->nlines + 1));
		memcpy(tmp.stmt, src->stmt,
		       sizeof(*src->stmt) * (size_t)src->nstmts);
	}
	if (src->nlabels)
		memcpy(tmp.label, src->label,
		       sizeof(*src->label) * (size_t)src->nlabels);
	tmp.nlines = src->nlines;
	tmp.nstmts = src->nstmts;
	tmp.nlabels = src->nlabels;
	ctrl_prog_free(dst);
	*dst = tmp;
	return 0;
}

/* ctrl_prog_label() - line of a label, or -1. */
int ctrl_prog_label(const struct ctrl_prog *p, uint64_t key)
{
	struct ctrl_label k = {key, 0}, *hit;

	if (!p->nlabels)
		return -1;
	hit = bsearch(&k, p->label, (size_t)p->nlabels, sizeof(*p->label),
		      label_cmp);
	return hit ? hit->line : -1;
}

/* ctrl_prog_stmt() - the text of statement @i (valid index). */
const char *ctrl_prog_stmt(const struct ctrl_prog *p, int i)
{
	return p->pool + p->stmt[i].text;
}

/* ctrl_prog_stmt_text() - statement @i as a string. Return 0 or -1. */
int ctrl_prog_stmt_text(const struct ctrl_prog *p, int i, char *out, size_t cap)
{
	const struct ctrl_stmt *st;

	if (i < 0 || i >= p->nstmts || cap <= CTRL_LINE_MAX)
		return -1;
	st = &p->stmt[i];
	memcpy(out, p->line[st->line] + st->off, st->len);
	out[st->len] = '\0';
	return 0;
}
