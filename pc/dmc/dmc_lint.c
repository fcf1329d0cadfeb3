/*
 * dmc_lint.c - the DMC linter; see dmc_lint.h, and dmc_rule.c for the
 * rules and their sources. Limits per model come from dmc_model.
 */
#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "dmc_cmd.h"
#include "dmc_lint.h"
#include "dmc_text.h"

/* Axis letters after a command ("KPA=10"). */
static const char axis_letters[] = "ABCDEFGHSTWXYZ";

static const char *const reserved[] = {"IF", "ELSE", "ENDIF", "TIME", "REM"};

#define NAME_CAP     64
#define JS_ARGS_MAX  8 /* CR, JS: ^a..^h */
#define JS_ARRAY_MAX 6 /* CR, JS: an array passed by reference */

struct sym {
	char name[NAME_CAP]; /* without '#' for labels; truncated if long */
	int line;	     /* 1-based line */
	int seq;	     /* order of appearance */
	char cmd[3];	     /* for references: "JP", "JS", "XQ" */
};

struct symtab {
	struct sym *v;
	int n, cap;
};

struct lint {
	const struct dmc_model *m;
	struct dmc_lint *r;
	struct symtab labels, refs, vars, targets;
	int *ifs; /* line of each open IF */
	int nifs, capifs;
	int nlines;
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

static void report(struct lint *c, int line, int ref, enum dmc_rule_id rule,
		   const char *fmt, ...) __attribute__((format(printf, 5, 6)));

static void report(struct lint *c, int line, int ref, enum dmc_rule_id rule,
		   const char *fmt, ...)
{
	struct dmc_lint *r = c->r;
	struct dmc_finding *f;
	va_list ap;

	if (r->n == r->cap) {
		int cap = r->cap ? r->cap * 2 : 16;
		struct dmc_finding *v = realloc(r->v, (size_t)cap * sizeof(*v));

		if (!v) {
			c->nomem = 1;
			return;
		}
		r->v = v;
		r->cap = cap;
	}
	f = &r->v[r->n];
	f->rule = rule;
	f->line = line;
	f->ref_line = ref;
	f->seq = r->n++;
	va_start(ap, fmt);
	vsnprintf(f->msg, sizeof(f->msg), fmt, ap);
	va_end(ap);
}

static struct sym *sym_add(struct lint *c, struct symtab *t, const char *s,
			   size_t n, int line)
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
	e->line = line;
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

/* Index after the closing @close of the "string" or {format} opening at
 * @i, or @n when it is not closed. */
static size_t skip_quoted(const char *s, size_t n, size_t i)
{
	const char *e = memchr(s + i + 1, s[i] == '"' ? '"' : '}', n - i - 1);

	return e ? (size_t)(e - s) + 1 : n;
}

/* Check one label definition "#NAME" (the whole statement). */
static void check_label_def(struct lint *c, int line, const char *s, size_t n)
{
	size_t wl = word_len(s + 1, n - 1);

	if (wl != n - 1 || !dmc_label_ok_model(c->m, s + 1, wl))
		report(c, line, 0, DMC_R_LABEL_SYNTAX,
		       "invalid label '%.*s' (a letter, then letters or "
		       "digits)",
		       (int)n, s);
	else if (wl > DMC_LABEL_MAX)
		report(c, line, 0, DMC_R_LABEL_LENGTH,
		       "label '%.*s' is longer than %d characters", (int)n, s,
		       DMC_LABEL_MAX);
	sym_add(c, &c->labels, s + 1, n - 1, line);
}

/* Variable-like names in an expression: only the length can be judged. */
static void check_expr(struct lint *c, int line, const char *s, size_t n)
{
	size_t i = 0, wl;

	while (i < n) {
		char ch = s[i];

		if (ch == '"' || ch == '{') {
			i = skip_quoted(s, n, i);
		} else if (strchr("_@^~#$&", ch) ||
			   isdigit((unsigned char)ch)) {
			i++;
			i += word_len(s + i, n - i);
		} else if (isalpha((unsigned char)ch)) {
			wl = word_len(s + i, n - i);
			if (wl > DMC_NAME_MAX)
				report(c, line, 0, DMC_R_VAR_LENGTH,
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
static int check_var_name(struct lint *c, int line, const char *w, size_t n)
{
	size_t i;

	if (!dmc_var_ok(w, n)) {
		report(c, line, 0, DMC_R_VAR_SYNTAX,
		       "invalid variable name '%.*s' (a letter, then "
		       "letters, digits or '_')",
		       (int)n, w);
		return 0;
	}
	if (n > DMC_NAME_MAX) {
		report(c, line, 0, DMC_R_VAR_LENGTH,
		       "variable name '%.*s' is longer than %d characters",
		       (int)n, w, DMC_NAME_MAX);
		return 0;
	}
	for (i = 0; i < sizeof(reserved) / sizeof(reserved[0]); i++)
		if (strlen(reserved[i]) == n && !memcmp(reserved[i], w, n)) {
			report(c, line, 0, DMC_R_VAR_RESERVED,
			       "variable name '%.*s' is a reserved word",
			       (int)n, w);
			return 0;
		}
	if (n == 2 && is_command(w)) {
		report(c, line, 0, DMC_R_VAR_COMMAND,
		       "variable name '%.*s' is a command name", (int)n, w);
		return 0;
	}
	return 1;
}

static void check_assignment(struct lint *c, int line, const char *s, size_t n,
			     size_t wl)
{
	const char *eq = memchr(s, '=', n);
	size_t i = wl;

	while (i < n && s[i] == ' ')
		i++;
	if (check_var_name(c, line, s, wl)) {
		struct sym *e = sym_add(c, &c->targets, s, wl, line);

		if (e && s[i] == '[')
			e->cmd[0] = '[';
		if (s[i] != '[')
			sym_add(c, &c->vars, s, wl, line);
	}
	if (eq)
		check_expr(c, line, eq + 1, n - (size_t)(eq + 1 - s));
}

/* DM/DA arguments: "name[n],name2[m]" or "name[]". */
static void check_arrays(struct lint *c, int line, const char *s, size_t n)
{
	size_t i = 0, wl;

	while (i < n) {
		while (i < n && (s[i] == ' ' || s[i] == ','))
			i++;
		wl = word_len(s + i, n - i);
		if (wl > 0)
			check_var_name(c, line, s + i, wl);
		while (i < n && s[i] != ',')
			i++;
	}
}

/* The argument list "(a,b,...)" at @s[@i]: count the arguments and judge
 * the arrays passed ("name" in quotes). Return the index after it. */
static size_t check_js_args(struct lint *c, int line, const char *s, size_t n,
			    size_t i, size_t wl)
{
	size_t start = i, e;
	int depth = 0, args = 0;

	for (; i < n; i++) {
		if (s[i] == '"') {
			e = skip_quoted(s, n, i);
			if (s[e - 1] == '"' && e - i - 2 > JS_ARRAY_MAX)
				report(c, line, 0, DMC_R_JS_ARGS,
				       "array '%.*s' passed on the JS stack "
				       "has a name longer than %d characters",
				       (int)(e - i - 2), s + i + 1,
				       JS_ARRAY_MAX);
			i = e - 1;
		} else if (s[i] == '(') {
			depth++;
		} else if (s[i] == ')' && --depth == 0) {
			break;
		} else if (s[i] == ',' && depth == 1) {
			args++;
		}
	}
	if (i > start + 1)
		args++; /* a non-empty list: one more argument than commas */
	if (args > JS_ARGS_MAX)
		report(c, line, 0, DMC_R_JS_ARGS,
		       "'JS #%.*s' passes %d arguments (at most %d: ^a..^h)",
		       (int)wl, s + start - wl, args, JS_ARGS_MAX);
	return i < n ? i + 1 : n;
}

/* JP, JS, XQ: the label reference, arguments and a condition after ','. */
static void check_jump(struct lint *c, int line, const char *s, size_t n)
{
	size_t i = 2, wl;
	struct sym *r;

	while (i < n && s[i] == ' ')
		i++;
	if (i >= n || s[i] != '#')
		return; /* XQ alone, XQ _ED2,_ED1,1, JP to a line */
	wl = word_len(s + i + 1, n - i - 1);
	r = sym_add(c, &c->refs, s + i + 1, wl, line);
	if (r)
		memcpy(r->cmd, s, 2);
	i += 1 + wl;
	if (s[0] == 'J' && s[1] == 'P' && i < n && s[i] == '(') {
		const char *e = memchr(s + i, ')', n - i);
		size_t al = e ? (size_t)(e - s) + 1 - i : n - i;

		report(c, line, 0, DMC_R_JP_ARGS,
		       "'JP #%.*s%.*s': JP takes no arguments (JS does)",
		       (int)wl, s + (i - wl), (int)al, s + i);
	}
	if (s[0] == 'J' && i < n && s[i] == '(')
		i = check_js_args(c, line, s, n, i, wl);
	if (s[0] == 'J' && i < n && s[i] == ',')
		check_expr(c, line, s + i + 1, n - i - 1);
}

static void check_if(struct lint *c, int line, const char *kw, const char *s,
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
		c->ifs[c->nifs++] = line;
		check_expr(c, line, s + 2, n - 2);
	} else if (c->nifs == 0) {
		report(c, line, 0, DMC_R_IF_MATCH, "'%s' without 'IF'", kw);
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

static void check_command(struct lint *c, int line, const char *s, size_t n)
{
	if ((s[0] == 'J' && (s[1] == 'P' || s[1] == 'S')) ||
	    (s[0] == 'X' && s[1] == 'Q'))
		check_jump(c, line, s, n);
	else if (s[0] == 'D' && (s[1] == 'M' || s[1] == 'A'))
		check_arrays(c, line, s + 2, n - 2);
}

/* "==" outside "strings" and {formats}: not a DMC operator. */
static int has_eqeq(const char *s, size_t n)
{
	for (size_t i = 0; i + 1 < n; i++) {
		if (s[i] == '"' || s[i] == '{')
			i = skip_quoted(s, n, i) - 1;
		else if (s[i] == '=' && s[i + 1] == '=')
			return 1;
	}
	return 0;
}

/* Commands that only a host sends, and WT=n: a wrong statement that the
 * controller may take without complaint. Return 1 when reported. */
static int check_host_only(struct lint *c, int line, const char *s, size_t n,
			   size_t wl, size_t i)
{
	if (wl == 2 && is_command(s) &&
	    ((s[0] == 'D' && s[1] == 'L') || (s[0] == 'U' && s[1] == 'L'))) {
		report(c, line, 0, DMC_R_DL_IN_PROGRAM,
		       "'%.2s' inside a program (a host command: it would end "
		       "or dump the program)",
		       s);
		return 1;
	}
	if (wl == 2 && s[0] == 'W' && s[1] == 'T' && i < n && s[i] == '=') {
		report(c, line, 0, DMC_R_WT_ASSIGN,
		       "'%.*s' does not wait (write 'WT %.*s')", (int)n, s,
		       (int)(n - i - 1), s + i + 1);
		return 1;
	}
	return 0;
}

static void check_stmt(struct lint *c, int line, const char *s, size_t n,
		       int first)
{
	size_t wl, i;
	const char *kw;

	if (s[0] == '#') {
		if (first)
			check_label_def(c, line, s, n);
		else
			report(c, line, 0, DMC_R_LABEL_POSITION,
			       "label '%.*s' is not at the start of a line",
			       (int)n, s);
		return;
	}
	if (!isalpha((unsigned char)s[0]))
		return; /* ~a=, ^a, operands: not judged */
	wl = word_len(s, n);
	for (i = wl; i < n && s[i] == ' ';)
		i++;
	if (has_eqeq(s, n))
		report(c, line, 0, DMC_R_EQ_EQ,
		       "'==' is not a DMC operator ('=' compares)");
	if (check_host_only(c, line, s, n, wl, i))
		return;
	kw = keyword(s, wl);
	if (kw && !strncmp(s, kw, wl) && (wl == 2 || i == n)) {
		check_if(c, line, kw, s, n);
		return;
	}
	if (i < n && (s[i] == '=' || s[i] == '[') && !is_command_form(s, wl))
		check_assignment(c, line, s, n, wl);
	else if (is_lower_command(s, wl))
		report(c, line, 0, DMC_R_LOWER_CASE,
		       "lower-case command '%.*s' (commands are upper case)",
		       (int)wl, s);
	else if (n >= 2 && is_command(s))
		check_command(c, line, s, n);
}

/* A comment statement: NO (a whole word) or '. It runs to the next ';'
 * and '"' opens no string in it. */
static int is_comment(const char *s, size_t n)
{
	if (n >= 1 && s[0] == '\'')
		return 1;
	return n >= 2 && s[0] == 'N' && s[1] == 'O' &&
	       (n == 2 || !dmc_is_name_char(s[2]));
}

/*
 * A NO comment with text, then ';' and more: the rest runs (the command
 * reference's NO and ';' pages; docs/galil-sim.md). When the rest starts
 * with a comment of its own ("NO a; NO b"), nothing runs yet: that
 * comment is judged as the next statement.
 */
static void check_no_rest(struct lint *c, int line, const char *st,
			  const char *s, const char *end)
{
	const char *t = st + 2, *r = s + 1;

	while (t < s && *t == ' ')
		t++;
	while (r < end && *r == ' ')
		r++;
	if (st[0] == 'N' && t < s && r < end &&
	    !is_comment(r, (size_t)(end - r)))
		report(c, line, 0, DMC_R_NO_SEMICOLON,
		       "';' ends the NO comment: '%.*s' runs as commands",
		       (int)(end - r), r);
}

/* Split a line into statements at ';' outside strings (comments: none). */
static void check_statements(struct lint *c, int line, const char *s, size_t n)
{
	const char *end = s + n, *st;
	int in_str, first = 1, comment;

	while (s < end) {
		while (s < end && *s == ' ')
			s++;
		st = s;
		comment = is_comment(s, (size_t)(end - s));
		for (in_str = 0; s < end && (in_str || *s != ';'); s++)
			if (*s == '"' && !comment)
				in_str = !in_str;
		if (in_str)
			report(c, line, 0, DMC_R_STRING_OPEN,
			       "missing closing '\"'");
		if (comment && s < end)
			check_no_rest(c, line, st, s, end);
		else if (s > st && !comment)
			check_stmt(c, line, st, (size_t)(s - st), first);
		first = 0;
		if (s < end)
			s++;
	}
}

/*
 * A tab inside a "string": no reference says the firmware keeps it, and
 * Galil's own downloader replaces every tab before it sends a program, so
 * it is refused like any control character, with the documented way to
 * print one (MG's {^n}: docs/galil-sim.md).
 */
static void report_char(struct lint *c, int line, unsigned char ch, int in_str)
{
	if (ch == '\t' && in_str)
		report(c, line, 0, DMC_R_CHAR,
		       "tab inside a string is not known to reach the "
		       "firmware (print one with {^9})");
	else
		report(c, line, 0, DMC_R_CHAR,
		       "character 0x%02X is not printable ASCII", ch);
}

static void check_chars(struct lint *c, int line, const char *s, size_t n)
{
	size_t i;
	int bad = 0, bslash = 0, in_str = 0;

	if (n > (size_t)c->m->line_chars)
		report(c, line, 0, DMC_R_LINE_LENGTH,
		       "line is %zu characters long (%s limit %d)", n,
		       c->m->title, c->m->line_chars);
	for (i = 0; i < n; i++) {
		unsigned char ch = (unsigned char)s[i];

		in_str ^= ch == '"';
		if (ch == '\\' && !bslash++)
			report(c, line, 0, DMC_R_BACKSLASH,
			       "'\\' ends the download early");
		else if ((ch < 0x20 || ch > 0x7e) && !bad++)
			report_char(c, line, ch, in_str);
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

static int sym_cmp_name_only(const void *a, const void *b)
{
	const struct sym *x = a, *y = b;

	return strcmp(x->name, y->name);
}

/* Count, duplicates (sorted by name, then order), then references. */
static void check_labels(struct lint *c)
{
	struct symtab *t = &c->labels;
	int i, first = 0;

	if (t->n > c->m->max_labels)
		report(c, t->v[c->m->max_labels].line, 0, DMC_R_LABELS_LIMIT,
		       "%d labels (%s limit %d)", t->n, c->m->title,
		       c->m->max_labels);
	if (t->n > 1)
		qsort(t->v, (size_t)t->n, sizeof(*t->v), sym_cmp_name);
	for (i = 1; i < t->n; i++) {
		if (strcmp(t->v[i].name, t->v[first].name)) {
			first = i;
			continue;
		}
		report(c, t->v[i].line, t->v[first].line, DMC_R_LABEL_DUPLICATE,
		       "duplicate label '#%s'", t->v[i].name);
	}
	for (i = 0; i < c->refs.n; i++) {
		const struct sym *r = &c->refs.v[i];

		if (t->n == 0 || !bsearch(r, t->v, (size_t)t->n, sizeof(*t->v),
					  sym_cmp_name_only))
			report(c, r->line, 0, DMC_R_LABEL_UNDEFINED,
			       "undefined label '#%s' in '%s'", r->name,
			       r->cmd);
	}
}

/* Distinct scalar variables, in order of first assignment. */
static void check_vars(struct lint *c)
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
		report(c, t->v[c->m->max_vars].line, 0, DMC_R_VARS_LIMIT,
		       "%d variables (%s limit %d)", n, c->m->title,
		       c->m->max_vars);
}

/* The names assigned, distinct, in order of first assignment, copied out
 * (@c->r->targets). */
static void list_targets(struct lint *c)
{
	struct symtab *t = &c->targets;
	struct dmc_lint *r = c->r;
	int i, n = 0;

	if (t->n > 1)
		qsort(t->v, (size_t)t->n, sizeof(*t->v), sym_cmp_name);
	for (i = 0; i < t->n; i++)
		if (i == 0 || strcmp(t->v[i].name, t->v[n - 1].name))
			t->v[n++] = t->v[i];
	if (n > 1)
		qsort(t->v, (size_t)n, sizeof(*t->v), sym_cmp_seq);
	if (n == 0)
		return;
	r->targets = calloc((size_t)n, sizeof(*r->targets));
	if (!r->targets) {
		c->nomem = 1;
		return;
	}
	for (i = 0; i < n; i++) {
		snprintf(r->targets[i].name, sizeof(r->targets[i].name), "%s",
			 t->v[i].name);
		r->targets[i].line = t->v[i].line;
		r->targets[i].array = t->v[i].cmd[0] == '[';
	}
	r->ntargets = n;
}

/* What can only be judged on the whole program. */
static void check_end(struct lint *c, int extra_lines)
{
	const struct dmc_model *m = c->m;
	int total = c->nlines + extra_lines;
	int i;

	for (i = 0; i < c->nifs; i++)
		report(c, c->ifs[i], 0, DMC_R_IF_MATCH, "'IF' without 'ENDIF'");
	if (total > m->max_lines)
		report(c,
		       m->max_lines < c->nlines ? m->max_lines + 1 : c->nlines,
		       0, DMC_R_LINES_LIMIT,
		       "program is %d lines long (%s limit %d)", total,
		       m->title, m->max_lines);
	check_labels(c);
	check_vars(c);
	list_targets(c);
}

/* The next line of @text from *@pos (LF, CR LF or CR ends it). */
static int next_line(const char *text, size_t len, size_t *pos, const char **s,
		     size_t *n)
{
	size_t i = *pos;

	if (i >= len)
		return 0;
	*s = text + i;
	while (i < len && text[i] != '\n' && text[i] != '\r')
		i++;
	*n = (size_t)(text + i - *s);
	if (i < len && text[i] == '\r' && i + 1 < len && text[i + 1] == '\n')
		i += 2;
	else if (i < len)
		i++;
	*pos = i;
	return 1;
}

static int finding_cmp(const void *a, const void *b)
{
	const struct dmc_finding *x = a, *y = b;

	if (x->line != y->line)
		return (x->line > y->line) - (x->line < y->line);
	return (x->seq > y->seq) - (x->seq < y->seq);
}

int dmc_lint_text(const char *text, size_t len, const struct dmc_model *m,
		  int extra_lines, struct dmc_lint *out)
{
	struct lint c = {.m = m, .r = out};
	size_t pos = 0, n;
	const char *s;

	memset(out, 0, sizeof(*out));
	while (next_line(text, len, &pos, &s, &n)) {
		c.nlines++;
		if (dmc_is_rem(s, n))
			continue;
		check_chars(&c, c.nlines, s, n);
		check_statements(&c, c.nlines, s, n);
	}
	if (c.nlines == 0)
		report(&c, 0, 0, DMC_R_EMPTY, "no program lines");
	else
		check_end(&c, extra_lines);
	out->lines = c.nlines + extra_lines;
	out->labels = c.labels.n;
	out->vars = c.vars.n;
	if (out->n > 1)
		qsort(out->v, (size_t)out->n, sizeof(*out->v), finding_cmp);
	free(c.labels.v);
	free(c.refs.v);
	free(c.vars.v);
	free(c.targets.v);
	free(c.ifs);
	return c.nomem ? DMC_LINT_NOMEM : out->n;
}

void dmc_lint_free(struct dmc_lint *r)
{
	free(r->v);
	free(r->targets);
	memset(r, 0, sizeof(*r));
}
