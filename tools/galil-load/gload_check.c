/* gload_check.c - the offline DMC checker; see gload_check.h. */
#include <ctype.h>
#include <strings.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "dmc_cmd.h"
#include "dmc_rule.h"
#include "dmc_text.h"
#include "gload_check.h"

/*
 * Limits [galil-notes 3.4]: DMC-40x0 4000 lines, 510 variables, 510 labels,
 * 80 characters. The 41x3, 21x3 and 30010 figures are UNCONFIRMED (commonly
 * quoted 2000 lines / 254 variables; DMC-2x00 manual: 254 variables), so the
 * smaller commonly quoted values are used. Threads [3.4].
 */

/* Axis letters after a command ("KPA=10"). */
static const char axis_letters[] = "ABCDEFGHSTWXYZ";

static const char *const reserved[] = {"IF", "ELSE", "ENDIF", "TIME", "REM"};

#define NAME_CAP 64

struct sym {
	char name[NAME_CAP]; /* without '#' for labels; truncated if long */
	int idx;	     /* program line index */
	int seq;	     /* order of appearance */
	char cmd[3];	     /* for references: "JP", "JS", "XQ" */
};

struct symtab {
	struct sym *v;
	int n, cap;
};

struct chk {
	const struct gload_prog *p;
	const struct dmc_model *m;
	struct gload_diags *d;
	struct symtab labels, refs, vars;
	int *ifs; /* line index of each open IF */
	int nifs, capifs;
	int problems;
	int nomem;
};

static int is_upper(char c)
{
	return c >= 'A' && c <= 'Z';
}

static size_t word_len(const char *s, size_t n)
{
	size_t i = 0;

	while (i < n && dmc_is_name_char(s[i]))
		i++;
	return i;
}

static void report(struct chk *c, int idx, enum dmc_rule_id rule,
		   const char *fmt, ...) __attribute__((format(printf, 4, 5)));

/* One finding: "FILE:LINE: message [rule]" (dmc_rule.h). */
static void report(struct chk *c, int idx, enum dmc_rule_id rule,
		   const char *fmt, ...)
{
	const struct gload_line *l = &c->p->lines[idx];
	char msg[400];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(msg, sizeof(msg), fmt, ap);
	va_end(ap);
	if (gload_diags_add(c->d, c->p->file_order[l->file],
			    c->p->files[l->file], l->src_line, "%s [%s]", msg,
			    dmc_rule(rule)->name))
		c->nomem = 1;
	c->problems++;
}

static struct sym *sym_add(struct chk *c, struct symtab *t, const char *s,
			   size_t n, int idx)
{
	struct sym *e;

	if (t->n == t->cap) {
		int cap = t->cap ? t->cap * 2 : 64;
		struct sym *v = realloc(t->v, (size_t)cap * sizeof(*v));

		if (!v) {
			c->nomem = 1;
			return NULL;
		}
		t->v = v;
		t->cap = cap;
	}
	e = &t->v[t->n];
	memset(e, 0, sizeof(*e));
	if (n >= NAME_CAP)
		n = NAME_CAP - 1;
	memcpy(e->name, s, n);
	e->idx = idx;
	e->seq = t->n++;
	return e;
}

/* An upper-case two-letter command of the one table (dmc_cmd); the
 * keyword IF is checked apart. */
static int is_command(const char *s)
{
	const struct dmc_cmd *e;

	if (!is_upper(s[0]) || !is_upper(s[1]))
		return 0;
	e = dmc_cmd_find(s);
	return e && !(e->flags & DMC_CMD_KEYWORD);
}

/* "IF", "ELSE", "ENDIF": the keyword a word is, in any case, or NULL. */
static const char *keyword(const char *w, size_t n)
{
	static const char *const kw[] = {"IF", "ELSE", "ENDIF"};
	size_t i;

	for (i = 0; i < 3; i++)
		if (strlen(kw[i]) == n && strncasecmp(w, kw[i], n) == 0)
			return kw[i];
	return NULL;
}

/* Check one label definition "#NAME" (the whole statement). */
static void check_label_def(struct chk *c, int idx, const char *s, size_t n)
{
	size_t wl = word_len(s + 1, n - 1);

	if (wl != n - 1 || !dmc_label_ok(s + 1, wl))
		report(c, idx, DMC_R_LABEL_SYNTAX,
		       "invalid label '%.*s' (a letter, then letters or "
		       "digits)",
		       (int)n, s);
	else if (wl > DMC_LABEL_MAX)
		report(c, idx, DMC_R_LABEL_LENGTH,
		       "label '%.*s' is longer than %d characters", (int)n, s,
		       DMC_LABEL_MAX);
	sym_add(c, &c->labels, s + 1, n - 1, idx);
}

/* Variable-like names in an expression: only the length can be judged. */
static void check_expr(struct chk *c, int idx, const char *s, size_t n)
{
	size_t i = 0, wl;

	while (i < n) {
		char ch = s[i];

		if (ch == '"' || ch == '{') {
			const char *e =
			    memchr(s + i + 1, ch == '"' ? '"' : '}', n - i - 1);

			i = e ? (size_t)(e - s) + 1 : n;
		} else if (strchr("_@^~#$&", ch) ||
			   isdigit((unsigned char)ch)) {
			i++;
			i += word_len(s + i, n - i);
		} else if (isalpha((unsigned char)ch)) {
			wl = word_len(s + i, n - i);
			if (wl > DMC_NAME_MAX)
				report(c, idx, DMC_R_VAR_LENGTH,
				       "variable name '%.*s' is longer "
				       "than %d characters",
				       (int)wl, s + i, DMC_NAME_MAX);
			i += wl;
		} else {
			i++;
		}
	}
}

/* Return 1 when @w (@n chars) is a valid name; report otherwise. */
static int check_var_name(struct chk *c, int idx, const char *w, size_t n)
{
	size_t i;

	if (!dmc_var_ok(w, n)) {
		report(c, idx, DMC_R_VAR_SYNTAX,
		       "invalid variable name '%.*s' (a letter, then "
		       "letters, digits or '_')",
		       (int)n, w);
		return 0;
	}
	if (n > DMC_NAME_MAX) {
		report(c, idx, DMC_R_VAR_LENGTH,
		       "variable name '%.*s' is longer than %d "
		       "characters",
		       (int)n, w, DMC_NAME_MAX);
		return 0;
	}
	for (i = 0; i < sizeof(reserved) / sizeof(reserved[0]); i++)
		if (strlen(reserved[i]) == n && !memcmp(reserved[i], w, n)) {
			report(c, idx, DMC_R_VAR_RESERVED,
			       "variable name '%.*s' is a reserved word",
			       (int)n, w);
			return 0;
		}
	if (n == 2 && is_command(w)) {
		report(c, idx, DMC_R_VAR_COMMAND,
		       "variable name '%.*s' is a command name", (int)n, w);
		return 0;
	}
	return 1;
}

static void check_assignment(struct chk *c, int idx, const char *s, size_t n,
			     size_t wl)
{
	const char *eq = memchr(s, '=', n);
	size_t i = wl;

	while (i < n && s[i] == ' ')
		i++;
	if (check_var_name(c, idx, s, wl) && s[i] != '[')
		sym_add(c, &c->vars, s, wl, idx);
	if (eq)
		check_expr(c, idx, eq + 1, n - (size_t)(eq + 1 - s));
}

/* DM/DA arguments: "name[n],name2[m]" or "name[]". */
static void check_arrays(struct chk *c, int idx, const char *s, size_t n)
{
	size_t i = 0, wl;

	while (i < n) {
		while (i < n && (s[i] == ' ' || s[i] == ','))
			i++;
		wl = word_len(s + i, n - i);
		if (wl > 0)
			check_var_name(c, idx, s + i, wl);
		while (i < n && s[i] != ',')
			i++;
	}
}

/* Skip "(...)" with nesting; return the index after it. */
static size_t skip_parens(const char *s, size_t n, size_t i)
{
	int depth = 0;

	for (; i < n; i++) {
		if (s[i] == '(')
			depth++;
		else if (s[i] == ')' && --depth == 0)
			return i + 1;
		if (depth == 0)
			return i;
	}
	return n;
}

/* JP, JS, XQ: the label reference and a condition after ','. */
static void check_jump(struct chk *c, int idx, const char *s, size_t n)
{
	size_t i = 2, wl;
	struct sym *r;

	while (i < n && s[i] == ' ')
		i++;
	if (i >= n || s[i] != '#')
		return; /* XQ alone, XQ _ED2,_ED1,1, JP to a line */
	wl = word_len(s + i + 1, n - i - 1);
	r = sym_add(c, &c->refs, s + i + 1, wl, idx);
	if (r)
		memcpy(r->cmd, s, 2);
	i += 1 + wl;
	if (s[0] == 'J' && s[1] == 'P' && i < n && s[i] == '(')
		report(c, idx, DMC_R_JP_ARGS,
		       "'JP #%.*s(...)': JP passes no arguments (JS does)",
		       (int)wl, s + (i - wl));
	if (s[0] == 'J' && i < n && s[i] == '(')
		i = skip_parens(s, n, i);
	if (s[0] == 'J' && i < n && s[i] == ',')
		check_expr(c, idx, s + i + 1, n - i - 1);
}

static void check_if(struct chk *c, int idx, const char *kw, const char *s,
		     size_t n)
{
	if (!strcmp(kw, "IF")) {
		if (c->nifs == c->capifs) {
			int cap = c->capifs ? c->capifs * 2 : 16;
			int *v = realloc(c->ifs, (size_t)cap * sizeof(*v));

			if (!v) {
				c->nomem = 1;
				return;
			}
			c->ifs = v;
			c->capifs = cap;
		}
		c->ifs[c->nifs++] = idx;
		check_expr(c, idx, s + 2, n - 2);
	} else if (c->nifs == 0) {
		report(c, idx, DMC_R_IF_MATCH, "'%s' without 'IF'", kw);
	} else if (!strcmp(kw, "ENDIF")) {
		c->nifs--;
	}
}

/* A lower-case spelling of a command: "bg", "mg", "shAB", "if". */
static int is_lower_command(const char *w, size_t wl)
{
	char up[2];
	size_t i;

	if (wl < 2 || (is_upper(w[0]) && is_upper(w[1])))
		return 0;
	if (keyword(w, wl))
		return 1;
	up[0] = (char)toupper((unsigned char)w[0]);
	up[1] = (char)toupper((unsigned char)w[1]);
	if (!is_command(up))
		return 0;
	for (i = 2; i < wl; i++)
		if (!strchr("abcdefghABCDEFGH", w[i]))
			return 0;
	return 1;
}

/* "KPA=10", "DMx[5]": a command, not an assignment to a variable. */
static int is_command_form(const char *w, size_t wl)
{
	if (wl < 2 || !is_command(w))
		return 0;
	if ((w[0] == 'D' && (w[1] == 'M' || w[1] == 'A')))
		return 1;
	return wl == 3 && strchr(axis_letters, w[2]);
}

static void check_command(struct chk *c, int idx, const char *s, size_t n,
			  int more)
{
	if (s[0] == 'N' && s[1] == 'O') {
		size_t i = 2;

		while (i < n && s[i] == ' ')
			i++;
		if (i < n && more)
			report(c, idx, DMC_R_NO_SEMICOLON,
			       "';' ends the NO comment: the rest of "
			       "the line runs as commands");
	} else if ((s[0] == 'J' && (s[1] == 'P' || s[1] == 'S')) ||
		   (s[0] == 'X' && s[1] == 'Q')) {
		check_jump(c, idx, s, n);
	} else if (s[0] == 'D' && (s[1] == 'M' || s[1] == 'A')) {
		check_arrays(c, idx, s + 2, n - 2);
	}
}

/* "==" outside "strings" and {formats}: not a DMC operator. */
static int has_eqeq(const char *s, size_t n)
{
	for (size_t i = 0; i + 1 < n; i++) {
		if (s[i] == '"' || s[i] == '{') {
			const char *e = memchr(
			    s + i + 1, s[i] == '"' ? '"' : '}', n - i - 1);

			if (!e)
				return 0;
			i = (size_t)(e - s);
		} else if (s[i] == '=' && s[i + 1] == '=') {
			return 1;
		}
	}
	return 0;
}

/* Commands that only a host sends, and WT=n: a wrong statement that the
 * controller may take without complaint. Return 1 when reported. */
static int check_host_only(struct chk *c, int idx, const char *s, size_t n,
			   size_t wl, size_t i)
{
	if (wl == 2 && is_command(s) &&
	    ((s[0] == 'D' && s[1] == 'L') || (s[0] == 'U' && s[1] == 'L'))) {
		report(c, idx, DMC_R_DL_IN_PROGRAM,
		       "'%.2s' inside a program (a host command: it would end "
		       "or dump the program)",
		       s);
		return 1;
	}
	if (wl == 2 && s[0] == 'W' && s[1] == 'T' && i < n && s[i] == '=') {
		report(c, idx, DMC_R_WT_ASSIGN,
		       "'%.*s' does not wait (write 'WT %.*s')", (int)n, s,
		       (int)(n - i - 1), s + i + 1);
		return 1;
	}
	return 0;
}

static void check_stmt(struct chk *c, int idx, const char *s, size_t n,
		       int first, int more)
{
	size_t wl, i;
	const char *kw;

	if (s[0] == '#') {
		if (first)
			check_label_def(c, idx, s, n);
		else
			report(c, idx, DMC_R_LABEL_POSITION,
			       "label '%.*s' is not at the start of a "
			       "line",
			       (int)n, s);
		return;
	}
	if (!isalpha((unsigned char)s[0]))
		return; /* ~a=, ^a, operands: not judged */
	wl = word_len(s, n);
	for (i = wl; i < n && s[i] == ' ';)
		i++;
	if (!(wl == 2 && s[0] == 'N' && s[1] == 'O') && has_eqeq(s, n))
		report(c, idx, DMC_R_EQ_EQ,
		       "'==' is not a DMC operator ('=' compares)");
	if (check_host_only(c, idx, s, n, wl, i))
		return;
	kw = keyword(s, wl);
	if (kw && !strncmp(s, kw, wl) && (wl == 2 || i == n)) {
		check_if(c, idx, kw, s, n);
		return;
	}
	if (i < n && (s[i] == '=' || s[i] == '[') && !is_command_form(s, wl))
		check_assignment(c, idx, s, n, wl);
	else if (is_lower_command(s, wl))
		report(c, idx, DMC_R_LOWER_CASE,
		       "lower-case command '%.*s' (commands are upper "
		       "case)",
		       (int)wl, s);
	else if (n >= 2 && is_command(s))
		check_command(c, idx, s, n, more);
}

/* Split a line into statements at ';' outside strings (NO: no strings). */
static void check_statements(struct chk *c, int idx)
{
	const struct gload_line *l = &c->p->lines[idx];
	const char *s = l->text, *end = s + l->len, *st;
	int in_str, first = 1, no;

	while (s < end) {
		while (s < end && *s == ' ')
			s++;
		st = s;
		no = end - s >= 2 && s[0] == 'N' && s[1] == 'O' &&
		     (end - s == 2 || !dmc_is_name_char(s[2]));
		for (in_str = 0; s < end && (in_str || *s != ';'); s++)
			if (*s == '"' && !no)
				in_str = !in_str;
		if (s > st)
			check_stmt(c, idx, st, (size_t)(s - st), first,
				   s < end);
		first = 0;
		if (s < end)
			s++;
	}
}

static void check_chars(struct chk *c, int idx)
{
	const struct gload_line *l = &c->p->lines[idx];
	size_t i;
	int bad = 0, bslash = 0;

	if (l->len > (size_t)c->m->line_chars)
		report(c, idx, DMC_R_LINE_LENGTH,
		       "line is %zu characters long after "
		       "preprocessing (limit %d)",
		       l->len, c->m->line_chars);
	for (i = 0; i < l->len; i++) {
		unsigned char ch = (unsigned char)l->text[i];

		if (ch == '\\' && !bslash++)
			report(c, idx, DMC_R_BACKSLASH,
			       "'\\' ends the download early");
		else if ((ch < 0x20 || ch > 0x7e) && !bad++)
			report(c, idx, DMC_R_CHAR,
			       "character 0x%02X is not printable "
			       "ASCII",
			       ch);
	}
}

static int sym_cmp_name(const void *a, const void *b)
{
	const struct sym *x = a, *y = b;
	int r = strcmp(x->name, y->name);

	return r ? r : (x->seq > y->seq) - (x->seq < y->seq);
}

static int sym_cmp_seq(const void *a, const void *b)
{
	const struct sym *x = a, *y = b;

	return (x->seq > y->seq) - (x->seq < y->seq);
}

static void where(const struct chk *c, int idx, char *buf, size_t cap)
{
	const struct gload_line *l = &c->p->lines[idx];

	snprintf(buf, cap, "%s:%d", c->p->files[l->file], l->src_line);
}

static int sym_cmp_name_only(const void *a, const void *b)
{
	const struct sym *x = a, *y = b;

	return strcmp(x->name, y->name);
}

/* Count, duplicates (sorted by name, then order), then references. */
static void check_labels(struct chk *c)
{
	struct symtab *t = &c->labels;
	char at[300];
	int i, first = 0;

	if (t->n > c->m->max_labels)
		report(c, t->v[c->m->max_labels].idx, DMC_R_LABELS_LIMIT,
		       "%d labels (%s limit %d)", t->n, c->m->title,
		       c->m->max_labels);
	if (t->n > 1)
		qsort(t->v, (size_t)t->n, sizeof(*t->v), sym_cmp_name);
	for (i = 1; i < t->n; i++) {
		if (strcmp(t->v[i].name, t->v[first].name)) {
			first = i;
			continue;
		}
		where(c, t->v[first].idx, at, sizeof(at));
		report(c, t->v[i].idx, DMC_R_LABEL_DUPLICATE,
		       "duplicate label '#%s' (first at %s)", t->v[i].name, at);
	}
	for (i = 0; i < c->refs.n; i++) {
		const struct sym *r = &c->refs.v[i];

		if (t->n == 0 || !bsearch(r, t->v, (size_t)t->n, sizeof(*t->v),
					  sym_cmp_name_only))
			report(c, r->idx, DMC_R_LABEL_UNDEFINED,
			       "undefined label '#%s' in '%s'", r->name,
			       r->cmd);
	}
}

/* Distinct scalar variables, in order of first assignment. */
static void check_vars(struct chk *c)
{
	struct symtab *t = &c->vars;
	int i, n = 0;

	if (t->n > 1)
		qsort(t->v, (size_t)t->n, sizeof(*t->v), sym_cmp_name);
	for (i = 0; i < t->n; i++)
		if (i == 0 || strcmp(t->v[i].name, t->v[n - 1].name))
			t->v[n++] = t->v[i];
	t->n = n;
	if (n > 1)
		qsort(t->v, (size_t)n, sizeof(*t->v), sym_cmp_seq);
	if (n > c->m->max_vars)
		report(c, t->v[c->m->max_vars].idx, DMC_R_VARS_LIMIT,
		       "%d variables (%s limit %d)", n, c->m->title,
		       c->m->max_vars);
}

static void check_end(struct chk *c)
{
	const struct dmc_model *m = c->m;
	int total = c->p->nlines + 1; /* with the identity line */
	int i;

	for (i = 0; i < c->nifs; i++)
		report(c, c->ifs[i], DMC_R_IF_MATCH, "'IF' without 'ENDIF'");
	if (total > m->max_lines)
		report(c,
		       m->max_lines < c->p->nlines ? m->max_lines
						   : c->p->nlines - 1,
		       DMC_R_LINES_LIMIT,
		       "program is %d lines long with the identity line "
		       "(%s limit %d)",
		       total, m->title, m->max_lines);
	check_labels(c);
	check_vars(c);
}

int gload_check(const struct gload_prog *p, const struct dmc_model *m,
		struct gload_diags *d, struct gload_stats *st)
{
	struct chk c = {.p = p, .m = m, .d = d};
	int i;

	if (st)
		memset(st, 0, sizeof(*st));
	if (p->nlines == 0) {
		gload_diags_add(d, p->nfiles ? p->file_order[0] : -1,
				p->nfiles ? p->files[0] : "(no files)", 0,
				"no program lines after preprocessing [%s]",
				dmc_rule(DMC_R_EMPTY)->name);
		return 1;
	}
	for (i = 0; i < p->nlines; i++) {
		check_chars(&c, i);
		check_statements(&c, i);
	}
	check_end(&c);
	if (st) {
		st->lines = p->nlines + 1;
		st->labels = c.labels.n;
		st->vars = c.vars.n;
	}
	free(c.labels.v);
	free(c.refs.v);
	free(c.vars.v);
	free(c.ifs);
	return c.nomem ? GL_ERR_NOMEM : c.problems;
}
