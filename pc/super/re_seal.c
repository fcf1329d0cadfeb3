/*
 * re_seal.c - the sealed values and their program part. See re_seal.h and
 * docs/dmc-interface.md ("The seal").
 */
#include "re_seal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "re_check.h"

#define LINE_MAX_CHARS 80	  /* one program line [galil-notes 3.4] */
#define SOFT_WIDE      2000000000 /* srev/sfwd before calibration */
#define CONSTS_LABEL   "#CONSTS"
#define T1_LABEL       "#MOTION" /* thread 1's code starts here */
#define T1_END_LABEL   "#POSERR" /* and ends before this */
#define ITEMS_PER_LINE 6	 /* checks joined on one line, at most */
#define SLF_SELF       3	 /* #SLF's lines where thread 0 finds itself */
#define SLF_WAIT_MS    10	 /* #SLW: a stray thread's look period, ms */

static const char AXES[] = "ABC";

static void seterr(char *err, size_t len, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void seterr(char *err, size_t len, const char *fmt, ...)
{
	va_list ap;

	if (!err || !len)
		return;
	va_start(ap, fmt);
	vsnprintf(err, len, fmt, ap);
	va_end(ap);
}

/* A value as the program writes it: 4 decimals at most, no trailing
 * zeros, never "-0" (the supervisor's read-back formats the same way). */
static void fmt_num(char *buf, size_t cap, double v)
{
	char *p;

	snprintf(buf, cap, "%.4f", v);
	for (p = buf + strlen(buf) - 1; *p == '0'; p--)
		*p = '\0';
	if (*p == '.')
		*p = '\0';
	if (!strcmp(buf, "-0"))
		snprintf(buf, cap, "0");
}

/* ---- building the table --------------------------------------------------
 */

static struct re_seal_item *add(struct re_seal *s, enum re_seal_kind kind,
				const char *ref, int axis, const char *what)
{
	struct re_seal_item *it;

	if (s->n >= RE_SEAL_MAX)
		return NULL;
	it = &s->item[s->n++];
	memset(it, 0, sizeof(*it));
	it->kind = kind;
	snprintf(it->ref, sizeof(it->ref), "%.*s", RE_SEAL_REF_MAX - 1, ref);
	it->axis = axis;
	it->shadow = -1;
	it->what = what;
	return it;
}

static int add_value(struct re_seal *s, enum re_seal_kind kind, const char *ref,
		     int axis, double v, double tol, const char *what)
{
	struct re_seal_item *it = add(s, kind, ref, axis, what);

	if (!it)
		return GL_ERR_OVERFLOW;
	fmt_num(it->lit, sizeof(it->lit), v);
	it->value = strtod(it->lit, NULL);
	it->tol = tol;
	return GL_OK;
}

/* The line @n (0-based) of @body: its start, and its length in @len. */
static const char *line_at(const char *body, size_t blen, int n, size_t *len)
{
	const char *p = body, *end = body + blen, *nl;

	for (int i = 0; i < n && p < end; i++) {
		nl = memchr(p, '\n', (size_t)(end - p));
		p = nl ? nl + 1 : end;
	}
	if (p >= end)
		return NULL;
	nl = memchr(p, '\n', (size_t)(end - p));
	*len = nl ? (size_t)(nl - p) : (size_t)(end - p);
	return p;
}

/* The program line number of label @label, or -1. */
static int label_line(const char *body, size_t blen, const char *label)
{
	size_t n = strlen(label), len;
	const char *p;

	for (int i = 0; (p = line_at(body, blen, i, &len)) != NULL; i++)
		if (len >= n && !memcmp(p, label, n) &&
		    (len == n || p[n] == ';'))
			return i;
	return -1;
}

/* One statement of #CONSTS: NAME=NUMBER or NAME=0-NAME (a negated
 * constant defined before it). */
static int add_const(struct re_seal *s, const char *st, size_t len, char *err,
		     size_t errlen)
{
	char buf[64], *eq, *end;
	double v;

	if (len >= sizeof(buf))
		goto bad;
	memcpy(buf, st, len);
	buf[len] = '\0';
	eq = strchr(buf, '=');
	if (!eq || eq == buf || eq - buf >= RE_SEAL_REF_MAX)
		goto bad;
	*eq++ = '\0';
	v = strtod(eq, &end);
	if (end == eq || *end) {
		int found = 0;

		if (strncmp(eq, "0-", 2) != 0)
			goto bad;
		for (int i = 0; i < s->n && !found; i++)
			if (s->item[i].kind == RE_SEAL_CONST &&
			    !strcmp(s->item[i].ref, eq + 2)) {
				v = -s->item[i].value;
				found = 1;
			}
		if (!found)
			goto bad;
	}
	return add_value(s, RE_SEAL_CONST, buf, -1, v, 0, "program constant");
bad:
	seterr(err, errlen,
	       "cannot seal the constant '%.*s': #CONSTS may only set NAME="
	       "NUMBER or NAME=0-NAME",
	       (int)len, st);
	return GL_ERR_FORMAT;
}

/* Every statement of #CONSTS, up to its EN. */
static int add_consts(struct re_seal *s, const char *body, size_t blen,
		      char *err, size_t errlen)
{
	int first = label_line(body, blen, CONSTS_LABEL), rc = GL_OK;
	const char *p, *q, *e;
	size_t len;

	if (first < 0) {
		seterr(err, errlen, "the program has no %s", CONSTS_LABEL);
		return GL_ERR_FORMAT;
	}
	for (int i = first + 1; rc == GL_OK; i++) {
		p = line_at(body, blen, i, &len);
		if (!p || (len == 2 && !memcmp(p, "EN", 2)))
			break;
		for (e = p + len; rc == GL_OK && p < e; p = q + 1) {
			q = memchr(p, ';', (size_t)(e - p));
			if (!q)
				q = e;
			rc = add_const(s, p, (size_t)(q - p), err, errlen);
		}
	}
	return rc;
}

/* The controller settings the program relies on, per axis: the command,
 * its resolution on the controller (KP, KD in 1/8; a read-back within it
 * is what the controller stores), and what it is. AC and DC, set by the
 * program itself at service and arm entry, are session values. */
static const struct re_seal_setting SETTINGS[] = {
    {"KP", 0.125, "proportional gain"},
    {"KI", 0.001, "integral gain"},
    {"KD", 0.125, "derivative gain"},
    {"TL", -0.001, "torque limit"}, /* tol < 0: an upper bound */
    {"ER", 0, "position-error limit"},
    {"OE", 0, "off-on-error"},
    {"OA", 0, "encoder-failure detection"},
    {"OT", 0, "encoder-failure time"},
    {"OV", 0.001, "encoder-failure torque"},
    {"LD", 0, "limit switches disabled"},
    {"MT", 0, "motor type"},
    {"CE", 0, "encoder configuration"},
};
#define N_SETTINGS ((int)(sizeof(SETTINGS) / sizeof(SETTINGS[0])))

const struct re_seal_setting *re_seal_setting_at(int k)
{
	return k >= 0 && k < N_SETTINGS ? &SETTINGS[k] : NULL;
}

int re_seal_add_fixed(struct re_seal *s)
{
	/* CN -1: a limit switch reads 0 while active, as #LIMCHK assumes */
	int rc = add_value(s, RE_SEAL_SETTING, "_CN0", -1, -1, 0,
			   "limit switch polarity");

	if (rc == GL_OK)
		rc = add_value(s, RE_SEAL_SETTING, "_TM", -1, 1000, 0,
			       "servo sample period");
	return rc;
}

/* The session's values, copied into ssn[] at service and arm entry. */
static int add_session(struct re_seal *s)
{
	/* a name, its form (a: array srev[0]; U: axis letter _FLA; l: lower
	 * case letter vla) and what it is */
	static const struct {
		const char *name;
		char form;
		const char *what;
	} ses[] = {
	    {"srev", 'a', "reverse soft limit"},
	    {"sfwd", 'a', "forward soft limit"},
	    {"_FL", 'U', "forward soft limit (FL)"},
	    {"_BL", 'U', "reverse soft limit (BL)"},
	    {"_AC", 'U', "acceleration"},
	    {"_DC", 'U', "deceleration"},
	    {"vl", 'l', "speed limit the program guards"},
	};
	char ref[RE_SEAL_REF_MAX];
	int k = 0;

	for (size_t j = 0; j < sizeof(ses) / sizeof(ses[0]); j++)
		for (int i = 0; i < RE_AXES; i++, k++) {
			struct re_seal_item *it;

			if (ses[j].form == 'a')
				snprintf(ref, sizeof(ref), "%s[%d]",
					 ses[j].name, i);
			else
				snprintf(ref, sizeof(ref), "%s%c", ses[j].name,
					 ses[j].form == 'U' ? AXES[i]
							    : 'a' + i);
			it = add(s, RE_SEAL_SESSION, ref, i, ses[j].what);
			if (!it)
				return GL_ERR_OVERFLOW;
			it->shadow = k;
		}
	return GL_OK;
}

static int add_threads(struct re_seal *s)
{
	char ref[RE_SEAL_REF_MAX];

	for (int t = 1; t < 8; t++) {
		snprintf(ref, sizeof(ref), "_XQ%d", t);
		if (!add(s, RE_SEAL_THREAD, ref, -1,
			 t == 1 ? "thread 1 (only #MOTION while armed)"
				: "a program thread the program never starts"))
			return GL_ERR_OVERFLOW;
	}
	if (!add(s, RE_SEAL_RUNNING, "prun", -1, "the program's running mark"))
		return GL_ERR_OVERFLOW;
	s->item[s->n - 1].value = 1;
	snprintf(s->item[s->n - 1].lit, RE_SEAL_LIT_MAX, "1");
	return GL_OK;
}

int re_seal_start(const char *body, size_t len, struct re_seal *out, char *err,
		  size_t errlen)
{
	memset(out, 0, sizeof(*out));
	out->t1_first = label_line(body, len, T1_LABEL);
	out->t1_last = label_line(body, len, T1_END_LABEL) - 1;
	for (size_t i = 0; i < len; i++)
		out->body_lines += body[i] == '\n';
	if (len && body[len - 1] != '\n')
		out->body_lines++;
	if (out->t1_first < 0 || out->t1_last < out->t1_first) {
		seterr(err, errlen, "the program has no %s before %s", T1_LABEL,
		       T1_END_LABEL);
		return GL_ERR_FORMAT;
	}
	return add_consts(out, body, len, err, errlen);
}

int re_seal_add(struct re_seal *s, enum re_seal_kind kind, const char *ref,
		int axis, double value, double tol, const char *what)
{
	if (kind != RE_SEAL_PARAM && kind != RE_SEAL_SETTING)
		return GL_ERR_ARG;
	return add_value(s, kind, ref, axis, value, tol, what);
}

int re_seal_end(struct re_seal *s)
{
	int rc = add_session(s);

	return rc == GL_OK ? add_threads(s) : rc;
}

int re_seal_const(const struct re_seal *s, const char *name, double *value)
{
	for (int i = 0; i < s->n; i++)
		if (s->item[i].kind == RE_SEAL_CONST &&
		    !strcmp(s->item[i].ref, name)) {
			*value = s->item[i].value;
			return GL_OK;
		}
	return GL_ERR_NOENT;
}

/* ---- the program part ----------------------------------------------------
 */

struct emit {
	char *out;
	size_t cap, len;
	int over;
	int lines; /* whole lines emitted so far */
};

static void put(struct emit *e, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void put(struct emit *e, const char *fmt, ...)
{
	va_list ap;
	int n;

	if (e->over)
		return;
	va_start(ap, fmt);
	n = vsnprintf(e->out + e->len, e->cap - e->len, fmt, ap);
	va_end(ap);
	if (n < 0 || (size_t)n >= e->cap - e->len) {
		e->over = 1;
		return;
	}
	for (const char *c = e->out + e->len; *c; c++)
		e->lines += *c == '\n';
	e->len += (size_t)n;
}

/* A literal in an expression: a negative one as (0-N), since a unary minus
 * after a comparison is not documented for the firmware. */
static void expr_lit(const char *lit, char *buf, size_t cap)
{
	if (lit[0] == '-')
		snprintf(buf, cap, "(0-%s)", lit + 1);
	else
		snprintf(buf, cap, "%s", lit);
}

/* The condition that is true when item @it does not hold. */
static void cond(const struct re_seal *s, const struct re_seal_item *it,
		 char *buf, size_t cap)
{
	char lit[RE_SEAL_LIT_MAX + 4];
	const char *ref = it->ref;

	expr_lit(it->lit, lit, sizeof(lit));
	switch (it->kind) {
	case RE_SEAL_SETTING:
		if (it->tol < 0) { /* at most the sealed value (TL) */
			char lim[RE_SEAL_LIT_MAX];

			fmt_num(lim, sizeof(lim), it->value - it->tol);
			snprintf(buf, cap, "(%s>%s)", ref, lim);
			break;
		}
		if (it->tol > 0) {
			snprintf(buf, cap, "(@ABS[%s-%s]>%g)", ref, lit,
				 it->tol);
			break;
		}
		/* fall through */
	case RE_SEAL_CONST:
	case RE_SEAL_PARAM:
	case RE_SEAL_RUNNING: snprintf(buf, cap, "(%s<>%s)", ref, lit); break;
	case RE_SEAL_SESSION:
		snprintf(buf, cap, "(%s<>ssn[%d])", ref, it->shadow);
		break;
	case RE_SEAL_THREAD:
		if (!strcmp(it->ref + strlen(it->ref) - 1, "1"))
			snprintf(buf, cap,
				 "((%s>=0)&((state<>1)|(%s<%d)|(%s>%d)))", ref,
				 ref, s->t1_first, ref, s->t1_last);
		else
			snprintf(buf, cap, "(%s>=0)", ref);
		break;
	}
}

/* Whether item @it is checked in the session states only (its shadow is
 * taken at service or arm entry). */
static int session_only(const struct re_seal_item *it)
{
	return it->kind == RE_SEAL_SESSION;
}

#define PREFIX "JS #SLF,"
/* the session items hold only where #SEALS took them: sses (1 in states 1
 * and 3), set by #SEAL and #SEALA when they start */
#define SES_PREFIX "JS #SLF,sses&"

/* The check lines: up to ITEMS_PER_LINE conditions joined with | on one
 * line "JS #SLF,...", at most 80 characters; session items apart, behind
 * (state=1)|(state=3). Returns the number of lines written to @lines. */
static int check_lines(const struct re_seal *s,
		       char lines[][LINE_MAX_CHARS + 1], int max)
{
	char c[LINE_MAX_CHARS + 1], line[LINE_MAX_CHARS + 1];
	int n = 0, in_line = 0, ses = -1;

	line[0] = '\0';
	for (int i = 0; i <= s->n; i++) {
		const struct re_seal_item *it = i < s->n ? &s->item[i] : NULL;
		int flush = !it;

		if (it) {
			size_t pre = session_only(it) ? strlen(SES_PREFIX) + 1
						      : strlen(PREFIX);

			cond(s, it, c, sizeof(c));
			flush =
			    in_line == ITEMS_PER_LINE ||
			    (in_line && session_only(it) != ses) ||
			    pre + strlen(line) + 1 + strlen(c) > LINE_MAX_CHARS;
		}
		if (flush && in_line) {
			if (n >= max)
				return -1;
			if (ses)
				snprintf(lines[n++], LINE_MAX_CHARS + 1,
					 "%s(%s)", SES_PREFIX, line);
			else
				snprintf(lines[n++], LINE_MAX_CHARS + 1, "%s%s",
					 PREFIX, line);
			line[0] = '\0';
			in_line = 0;
		}
		if (!it)
			break;
		if (in_line)
			strcat(line, "|");
		strcat(line, c);
		in_line++;
		ses = session_only(it);
	}
	return n;
}

static void emit_sealin(struct emit *e, const struct re_seal *s)
{
	char line[LINE_MAX_CHARS + 1] = "", st[48];

	put(e, "%s\n", RE_SEAL_FIRST);
	for (int i = 0; i < s->n; i++) {
		if (s->item[i].kind != RE_SEAL_PARAM)
			continue;
		snprintf(st, sizeof(st), "%s=%s", s->item[i].ref,
			 s->item[i].lit);
		if (line[0] && strlen(line) + 1 + strlen(st) > LINE_MAX_CHARS) {
			put(e, "%s\n", line);
			line[0] = '\0';
		}
		if (line[0])
			strcat(line, ";");
		strcat(line, st);
	}
	if (line[0])
		put(e, "%s\n", line);
	put(e, "sls=0;sses=0;sall=0;sid=0;sax=0;sfv=0\n");
	put(e, "sq1=-1;sq2=-1;sq3=-1;sq4=-1;sq5=-1;sq6=-1;sq7=-1\nEN\n");
}

static void emit_seals(struct emit *e, const struct re_seal *s)
{
	char line[LINE_MAX_CHARS + 1] = "", st[48];

	put(e, "#SEALS\n");
	for (int i = 0; i < s->n; i++) {
		if (s->item[i].kind != RE_SEAL_SESSION)
			continue;
		snprintf(st, sizeof(st), "ssn[%d]=%s", s->item[i].shadow,
			 s->item[i].ref);
		if (line[0] && strlen(line) + 1 + strlen(st) > LINE_MAX_CHARS) {
			put(e, "%s\n", line);
			line[0] = '\0';
		}
		if (line[0])
			strcat(line, ";");
		strcat(line, st);
	}
	if (line[0])
		put(e, "%s\n", line);
	put(e, "EN\n");
}

/* The threads 2..7 on one check line. */
static const char *threads_line(void)
{
	return PREFIX "(_XQ2>=0)|(_XQ3>=0)|(_XQ4>=0)|(_XQ5>=0)|(_XQ6>=0)|"
		      "(_XQ7>=0)";
}

/* #SEAL: one slice per call (sls rotates); #SEALA: every slice; #SEALC:
 * the slice slk; #SL0..: the slices. */
static void emit_checks(struct emit *e, const struct re_seal *s,
			char lines[][LINE_MAX_CHARS + 1], int n)
{
	int k = n < RE_SEAL_SLICES ? n : RE_SEAL_SLICES, at = 0;

	/* #SEALP, from #GUARD every pass: the potentiometers read through
	 * their sealed inputs (a potin[] written from outside changes
	 * nothing; the rotation names it), and a thread of another program */
	put(e, "#SEALP\n");
	for (int i = 0, first = 1; i < s->n; i++)
		if (!strncmp(s->item[i].ref, "potin[", 6)) {
			put(e, "%sanv[%d]=@AN[%s]", first ? "" : ";",
			    s->item[i].axis, s->item[i].lit);
			first = 0;
		}
	put(e, "\n%s\n", threads_line());
	for (int i = 0; i < s->n; i++)
		if (!strcmp(s->item[i].ref, "_XQ1")) {
			char c[LINE_MAX_CHARS + 1];

			cond(s, &s->item[i], c, sizeof(c));
			put(e, "%s%s\n", PREFIX, c);
		}
	put(e, "EN\n");
	/* #SEAL: slice sls (rotating), one line of jumps; each slice ends
	 * with EN, or goes on to the next one for #SEALA (sall=1) */
	/* the slice number starts again from 0 when it is outside 0..k-1
	 * or not whole: a written sls never skips a slice for long */
	put(e, "#SEAL\nsls=@INT[sls]+1;sses=(state=1)|(state=3);sall=0\n");
	put(e, "JP #SEALB,(sls>=0)&(sls<%d)\nsls=0\n#SEALB\n", k);
	for (int j = 0; j < k; j++)
		put(e, "JP #SL%d,sls=%d%s", j, j,
		    (j % 5 == 4 || j == k - 1) ? "\n" : ";");
	put(e, "EN\n#SEALA\nsall=1;sses=(state=1)|(state=3)\nJP #SL0\n");
	for (int j = 0; j < k; j++) {
		int upto = (int)((long)n * (j + 1) / k);

		put(e, "#SL%d\n", j);
		for (; at < upto; at++)
			put(e, "%s\n", lines[at]);
		if (j < k - 1)
			put(e, "JP #SL%d,sall=1\n", j + 1);
		put(e, "EN\n");
	}
}

/* The thread items' operands as #SLF took them: _XQn -> sqn. */
static void thread_alias(const struct re_seal_item *it, struct re_seal_item *a)
{
	*a = *it;
	if (it->kind == RE_SEAL_THREAD)
		snprintf(a->ref, sizeof(a->ref), "sq%s", it->ref + 3);
}

/* #SLF: stop the motion at once; take the threads' lines (sq1..sq7) and
 * halt every thread but this one's caller, thread 0 (this program's code
 * running in another thread too would share the finder's variables);
 * then find the first item that does not hold (its number, axis 1..3 or
 * 0, the value found) and latch fault 17. */
static void emit_find(struct emit *e, const struct re_seal *s)
{
	char c[LINE_MAX_CHARS + 1];

	/* the line of #SLF: thread 0 running the test line finds itself
	 * within its first SLF_SELF lines (_XQ0 the line it runs or the
	 * next); any other thread finds thread 0 elsewhere and waits at
	 * #SLW, where thread 0's next look finds it (halting itself here
	 * would end it before thread 0 could name it) */
	int slf = s->body_lines + e->lines;

	put(e, "#SLF\nAB 1;MO ABC;OP 0\n");
	put(e, "JP #SLW,(_XQ0<%d)|(_XQ0>%d)\n", slf, slf + SLF_SELF);
	put(e,
	    "sq1=_XQ1;sq2=_XQ2;sq3=_XQ3;sq4=_XQ4;sq5=_XQ5;sq6=_XQ6;sq7=_XQ7\n");
	put(e, "HX1;HX2;HX3;HX4;HX5;HX6;HX7\n");
	for (int i = 0; i < s->n; i++) {
		struct re_seal_item a;
		const struct re_seal_item *it = &a;

		thread_alias(&s->item[i], &a);
		cond(s, it, c, sizeof(c));
		if (session_only(it))
			put(e, "sid=%d;sax=%d;sfv=%s;JP #SLX,sses&%s\n", i + 1,
			    it->axis + 1, it->ref, c);
		else
			put(e, "sid=%d;sax=%d;sfv=%s;JP #SLX,%s\n", i + 1,
			    it->axis + 1, it->ref, c);
	}
	put(e, "sid=0;sax=0;sfv=0\n#SLX\nJS #FAULT(17,sax,sid)\nEN\n");
	/* #SLW: a thread other than 0 keeps the motion stopped until thread
	 * 0 halts it (SLF_WAIT_MS between looks) */
	put(e, "#SLW\nAB 1;MO ABC;OP 0\nWT %d\nJP #SLW\n", SLF_WAIT_MS);
}

int re_seal_emit(const struct re_seal *s, char *out, size_t cap)
{
	static char lines[RE_SEAL_MAX][LINE_MAX_CHARS + 1];
	struct emit e = {out, cap, 0, 0, 0};
	int n;

	if (!cap)
		return GL_ERR_OVERFLOW;
	out[0] = '\0';
	n = check_lines(s, lines, RE_SEAL_MAX);
	if (n < 0)
		return GL_ERR_OVERFLOW;
	emit_sealin(&e, s);
	emit_seals(&e, s);
	emit_checks(&e, s, lines, n);
	emit_find(&e, s);
	return e.over ? GL_ERR_OVERFLOW : (int)e.len;
}

void re_seal_describe(const struct re_seal *s, int number, char *buf,
		      size_t cap)
{
	const struct re_seal_item *it;

	if (number < 1 || number > s->n) {
		snprintf(buf, cap, "an unknown sealed value (%d)", number);
		return;
	}
	it = &s->item[number - 1];
	if (it->axis >= 0)
		snprintf(buf, cap, "%s (%s, axis %c)", it->ref, it->what,
			 AXES[it->axis]);
	else
		snprintf(buf, cap, "%s (%s)", it->ref, it->what);
}

long re_seal_split(const char *text, size_t len)
{
	size_t n = strlen(RE_SEAL_FIRST);
	const char *p = text, *end = text + len;

	while (p < end) {
		const char *nl = memchr(p, '\n', (size_t)(end - p));
		size_t l = nl ? (size_t)(nl - p) : (size_t)(end - p);

		if (l == n && !memcmp(p, RE_SEAL_FIRST, n))
			return (long)(p - text);
		p = nl ? nl + 1 : end;
	}
	return -1;
}

void re_seal_fault(const struct re_seal *s, double found, double sealed,
		   struct re_fault *f)
{
	long long k = f->i[0];
	const struct re_seal_item *it;

	re_seal_describe(s, (int)k, f->s, sizeof(f->s));
	f->f[0] = found;
	f->f[1] = NAN;
	if (k < 1 || k > s->n)
		return;
	it = &s->item[k - 1];
	f->axis = it->axis;
	f->f[1] = it->kind == RE_SEAL_SESSION  ? sealed
		  : it->kind == RE_SEAL_THREAD ? -1
					       : it->value;
}

/* @n (@nl bytes) in @h (@hl bytes), or NULL. */
static const char *find(const char *h, size_t hl, const char *n, size_t nl)
{
	for (size_t i = 0; nl <= hl && i <= hl - nl; i++)
		if (h[i] == n[0] && !memcmp(h + i, n, nl))
			return h + i;
	return NULL;
}

/* The finder's line of item @i (what #SLF holds for it), no line end. */
static void finder_line(const struct re_seal *s, int i, char *buf, size_t cap)
{
	char c[LINE_MAX_CHARS + 1];
	struct re_seal_item a;

	thread_alias(&s->item[i], &a);
	cond(s, &a, c, sizeof(c));
	snprintf(buf, cap, "sid=%d;sax=%d;sfv=%s;JP #SLX,%s%s", i + 1,
		 a.axis + 1, a.ref, session_only(&a) ? "sses&" : "", c);
}

/* The literal item @it has in the finder line @line (to its end, @end):
 * after "REF<>" or "[REF-", "(0-N)" read as -N. */
static void lit_in(const struct re_seal_item *it, const char *line,
		   const char *end, char *out, size_t cap)
{
	char key[RE_SEAL_REF_MAX + 4];
	const char *p, *q;
	size_t n = strlen(it->ref);

	snprintf(out, cap, "?");
	snprintf(key, sizeof(key), "%s<>", it->ref);
	p = strstr(line, key);
	if (!p || p > end) {
		snprintf(key, sizeof(key), "[%s-", it->ref);
		p = strstr(line, key);
		n++;
	}
	if (!p || p > end)
		return;
	p += n + (key[n] == '-' ? 1 : 2);
	if (!strncmp(p, "(0-", 3)) {
		for (q = p + 3; q < end && *q != ')'; q++)
			;
		snprintf(out, cap, "-%.*s", (int)(q - p - 3), p + 3);
		return;
	}
	for (q = p; q < end && *q != ')' && *q != ']'; q++)
		;
	snprintf(out, cap, "%.*s", (int)(q - p), p);
}

int re_seal_compare(const struct re_seal *s, const char *have, size_t hlen,
		    const char *want, size_t wlen, char *err, size_t errlen)
{
	char line[LINE_MAX_CHARS * 2], key[24], theirs[32], what[160];

	if (hlen == wlen && !memcmp(have, want, hlen))
		return GL_OK;
	/* the first item whose finder line the controller's program lacks:
	 * the value it was sealed with differs (or the item is new) */
	for (int i = 0; i < s->n; i++) {
		const char *p, *nl;

		finder_line(s, i, line, sizeof(line));
		if (find(have, hlen, line, strlen(line)))
			continue;
		re_seal_describe(s, i + 1, what, sizeof(what));
		snprintf(key, sizeof(key), "\nsid=%d;", i + 1);
		p = find(have, hlen, key, strlen(key));
		nl = p ? memchr(p + 1, '\n', hlen - (size_t)(p + 1 - have))
		       : NULL;
		if (p && nl && s->item[i].kind != RE_SEAL_SESSION) {
			lit_in(&s->item[i], p + 1, nl, theirs, sizeof(theirs));
			seterr(err, errlen,
			       "the controller's program was sealed with other "
			       "values than this configuration gives: %s is %s "
			       "in the controller's program, %s here",
			       what, theirs, s->item[i].lit);
		} else {
			seterr(err, errlen,
			       "the controller's program was sealed with other "
			       "values than this configuration gives, from %s "
			       "on",
			       what);
		}
		return GL_ERR_MISMATCH;
	}
	seterr(err, errlen,
	       "the controller's program holds the seal in another form than "
	       "this roboelf makes it (another release of galil-load?)");
	return GL_ERR_MISMATCH;
}

void re_seal_read_fault(const struct re_seal *s, const struct re_io *io,
			int timeout_ms, struct re_fault *f)
{
	double found = NAN, sealed = NAN;
	long long k = f->i[0];
	char ref[RE_SEAL_REF_MAX];

	if (!s || f->id != RE_F_CTRL_SEAL)
		return;
	if (re_io_read(io, "sfv", &found, timeout_ms) != GL_OK)
		found = NAN;
	if (k >= 1 && k <= s->n && s->item[k - 1].shadow >= 0) {
		snprintf(ref, sizeof(ref), "ssn[%d]", s->item[k - 1].shadow);
		if (re_io_read(io, ref, &sealed, timeout_ms) != GL_OK)
			sealed = NAN;
	}
	re_seal_fault(s, found, sealed, f);
}

/* ---- the supervisor's read-back ---------------------------------------- */

#define SOFT_OPEN 2147483647.0 /* FL/BL opened (re_ctl.h RE_CTL_SOFT_OPEN) */

static int item_index(const struct re_seal *s, const char *ref)
{
	for (int i = 0; i < s->n; i++)
		if (!strcmp(s->item[i].ref, ref))
			return i;
	return -1;
}

static double value_of(const struct re_seal *s, const char *ref)
{
	int i = item_index(s, ref);

	return i >= 0 ? s->item[i].value : NAN;
}

/* A session item's value for @state: its name and axis say which. */
static double session_value(const struct re_seal *s,
			    const struct re_seal_item *it, int state,
			    const double *rev, const double *fwd)
{
	char ref[RE_SEAL_REF_MAX];
	double speed, acfact = value_of(s, "acfact");
	int i = it->axis;

	snprintf(ref, sizeof(ref), "%s[%d]", state == 1 ? "vmax" : "svmax", i);
	speed = value_of(s, ref);
	if (!strncmp(it->ref, "srev", 4))
		return rev ? floor(rev[i] + 0.5) : -SOFT_WIDE;
	if (!strncmp(it->ref, "sfwd", 4))
		return fwd ? floor(fwd[i] + 0.5) : SOFT_WIDE;
	if (!strncmp(it->ref, "_FL", 3))
		return fwd && state == 1 ? floor(fwd[i] + 0.5) : SOFT_OPEN;
	if (!strncmp(it->ref, "_BL", 3))
		return rev && state == 1 ? floor(rev[i] + 0.5) : -SOFT_OPEN;
	if (!strncmp(it->ref, "_AC", 3) || !strncmp(it->ref, "_DC", 3))
		return floor(acfact * speed / 1024) * 1024;
	return speed; /* vla vlb vlc */
}

void re_seal_expect(const struct re_seal *s, int state, const double *soft_rev,
		    const double *soft_fwd, double *out)
{
	for (int i = 0; i < s->n; i++) {
		const struct re_seal_item *it = &s->item[i];

		switch (it->kind) {
		case RE_SEAL_SESSION:
			out[i] =
			    session_value(s, it, state, soft_rev, soft_fwd);
			break;
		case RE_SEAL_THREAD: out[i] = -1; break;
		default: out[i] = it->value; break;
		}
	}
}

/* Whether @v read for item @it differs from @want. */
static int differs(const struct re_seal *s, const struct re_seal_item *it,
		   double want, double v, int state)
{
	if (it->kind == RE_SEAL_THREAD) {
		if (!strcmp(it->ref, "_XQ1") && state == 1)
			return v < s->t1_first || v > s->t1_last;
		return v >= 0;
	}
	if (it->tol < 0) /* an upper bound */
		return v > want - it->tol + 1e-6;
	return fabs(v - want) >
	       (it->tol > 0 ? it->tol : 0) + 1e-3 + 1e-6 * fabs(want);
}

int re_seal_judge(const struct re_seal *s, const double *expect, int first,
		  int count, const char *text, size_t len, int session_ok,
		  int state, int *bad, double *found)
{
	const char *p = text, *end = text + len;
	char num[40];

	for (int k = 0; k < count; k++) {
		const struct re_seal_item *it = &s->item[first + k];
		size_t n = 0;
		double v;
		char *e;

		while (p < end &&
		       (*p == ' ' || *p == '\r' || *p == '\n' || *p == ','))
			p++;
		while (p < end && n + 1 < sizeof(num) && *p != ' ' &&
		       *p != '\r' && *p != '\n' && *p != ',')
			num[n++] = *p++;
		num[n] = '\0';
		v = strtod(num, &e);
		if (!n || *e)
			return GL_ERR_PROTO;
		if (it->kind == RE_SEAL_SESSION && !session_ok)
			continue;
		if (differs(s, it, expect[first + k], v, state)) {
			*bad = first + k + 1;
			*found = v;
			return RE_FAULT;
		}
	}
	return RE_OK;
}

int re_seal_chunk_text(const struct re_seal *s, int first, int count, char *buf,
		       size_t cap)
{
	size_t n = (size_t)snprintf(buf, cap, "MG ");

	for (int k = 0; k < count && n < cap; k++)
		n += (size_t)snprintf(buf + n, cap - n, "%s%s", k ? "," : "",
				      s->item[first + k].ref);
	return n < cap ? (int)n : GL_ERR_OVERFLOW;
}

int re_seal_chunks(const struct re_seal *s, size_t max_chars, int *first,
		   int *count, int cap)
{
	int n = 0;

	for (int i = 0; i < s->n;) {
		size_t len = 3 + strlen(s->item[i].ref);
		int c = 1;

		if (n >= cap || len > max_chars)
			return GL_ERR_OVERFLOW;
		while (i + c < s->n &&
		       len + 1 + strlen(s->item[i + c].ref) <= max_chars)
			len += 1 + strlen(s->item[i + c++].ref);
		first[n] = i;
		count[n++] = c;
		i += c;
	}
	return n;
}
