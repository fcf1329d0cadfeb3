/* gload_prep.c - the preprocessor and the manifest; see gload_prep.h. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "base_file.h"
#include "dmc_text.h"
#include "gl_err.h"
#include "gload_prep.h"

static int is_blank(char c)
{
	return c == ' ' || c == '\t';
}

/* A statement starting at @s is a NO comment: "NO" not followed by a name
 * character (NOx=1 is an assignment to the variable NOx). */
static int is_no_stmt(const char *s, size_t n)
{
	return n >= 2 && s[0] == 'N' && s[1] == 'O' &&
	       (n == 2 || !dmc_is_name_char(s[2]));
}

static size_t trim_end(const char *out, size_t o)
{
	while (o > 0 && is_blank(out[o - 1]))
		o--;
	return o;
}

/*
 * Strip one source line into @out (capacity >= @n). Return the new length.
 * A string left open runs to the end of the line (the linter reports it:
 * rule string-open, pc/dmc/dmc_lint.h).
 */
static size_t strip_line(const char *s, size_t n, char *out)
{
	size_t i, o = 0;
	int in_str = 0, in_no = 0, at_start = 1;

	for (i = 0; i < n; i++) {
		char c = s[i];

		if (in_str) {
			out[o++] = c;
			in_str = c != '"';
			continue;
		}
		if (at_start && is_blank(c))
			continue;
		if (at_start)
			in_no = is_no_stmt(s + i, n - i);
		at_start = 0;
		/* a ' inside a NO comment is comment text, not a ' comment:
		 * what follows the NO's ';' still runs and is sent */
		if (c == '\'' && !in_no)
			break;
		if (c == ';') {
			o = trim_end(out, o);
			at_start = 1;
			in_no = 0;
		}
		in_str = c == '"' && !in_no;
		out[o++] = c == '\t' ? ' ' : c;
	}
	o = trim_end(out, o);
	while (!in_str && o > 0 && out[o - 1] == ';')
		o = trim_end(out, o - 1);
	return o;
}

static int prog_grow(struct gload_prog *p)
{
	int cap = p->cap ? p->cap * 2 : 256;
	struct gload_line *v;

	v = realloc(p->lines, (size_t)cap * sizeof(*v));
	if (!v)
		return GL_ERR_NOMEM;
	p->lines = v;
	p->cap = cap;
	return GL_OK;
}

static int prog_add_line(struct gload_prog *p, const char *text, size_t len,
			 int src_line)
{
	struct gload_line *l;
	char *t;

	if (p->nlines == p->cap && prog_grow(p) != GL_OK)
		return GL_ERR_NOMEM;
	t = malloc(len + 1);
	if (!t)
		return GL_ERR_NOMEM;
	memcpy(t, text, len);
	t[len] = '\0';
	l = &p->lines[p->nlines++];
	l->text = t;
	l->len = len;
	l->file = p->nfiles - 1;
	l->src_line = src_line;
	return GL_OK;
}

static int prog_add_file(struct gload_prog *p, const char *path)
{
	char **files;
	int *order;
	char *copy = strdup(path);

	if (!copy)
		return GL_ERR_NOMEM;
	files = realloc(p->files, (size_t)(p->nfiles + 1) * sizeof(*files));
	if (!files)
		goto out_free_copy;
	p->files = files;
	order =
	    realloc(p->file_order, (size_t)(p->nfiles + 1) * sizeof(*order));
	if (!order)
		goto out_free_copy;
	p->file_order = order;
	p->files[p->nfiles] = copy;
	p->file_order[p->nfiles] = p->order++;
	p->nfiles++;
	return GL_OK;

out_free_copy:
	free(copy);
	return GL_ERR_NOMEM;
}

/* Next line of @buf from *@pos (LF, CR LF or CR); 0 at the end. */
static int next_src_line(const char *buf, size_t len, size_t *pos,
			 const char **s, size_t *n)
{
	size_t i = *pos;

	if (i >= len)
		return 0;
	*s = buf + i;
	while (i < len && buf[i] != '\n' && buf[i] != '\r')
		i++;
	*n = (size_t)(buf + i - *s);
	if (i < len && buf[i] == '\r' && i + 1 < len && buf[i + 1] == '\n')
		i++;
	*pos = i < len ? i + 1 : i;
	return 1;
}

int gload_prep_buffer(struct gload_prog *p, const char *path, const char *buf,
		      size_t len, struct gload_diags *d)
{
	const char *s;
	size_t n, pos = 0, olen;
	char *out = malloc(len + 1);
	int line = 0, rc = GL_ERR_NOMEM;

	(void)d; /* nothing to report today: see gload_prep.h */
	if (!out || prog_add_file(p, path) != GL_OK)
		goto out_free;
	p->src_bytes += len;
	while (next_src_line(buf, len, &pos, &s, &n)) {
		line++;
		if (dmc_is_rem(s, n))
			continue;
		olen = strip_line(s, n, out);
		if (olen > 0 && prog_add_line(p, out, olen, line) != GL_OK)
			goto out_free;
	}
	p->src_lines += line;
	rc = GL_OK;
out_free:
	free(out);
	return rc;
}

/* Read a whole file into a malloc'd buffer (NUL-terminated). */
/* The whole file (pc/base), NUL-terminated; *err the errno on failure
 * (EFBIG above GLOAD_FILE_MAX). */
static int read_file(const char *path, char **buf, size_t *len, int *err)
{
	int rc = base_file_read(path, (size_t)GLOAD_FILE_MAX, buf, len);

	*err = rc < 0 ? -rc : 0;
	return rc < 0 ? GL_ERR_NOENT : GL_OK;
}

static int prep_file(struct gload_prog *p, const char *path, int mline,
		     const char *mpath, struct gload_diags *d)
{
	char *buf;
	size_t len;
	int err, rc;

	if (read_file(path, &buf, &len, &err) != GL_OK) {
		if (mpath)
			gload_diags_add(d, p->order, mpath, mline,
					"cannot open '%s': %s", path,
					strerror(err));
		else
			gload_diags_add(d, p->order, path, 0,
					"cannot open '%s': %s", path,
					strerror(err));
		p->order++;
		return err == ENOMEM ? GL_ERR_NOMEM : GL_ERR_NOENT;
	}
	rc = gload_prep_buffer(p, path, buf, len, d);
	free(buf);
	return rc;
}

static int manifest_push(char ***names, int **lines, int n, const char *s,
			 size_t len, int line)
{
	char **nv = realloc(*names, (size_t)(n + 1) * sizeof(*nv));
	int *lv;

	if (!nv)
		return GL_ERR_NOMEM;
	*names = nv;
	lv = realloc(*lines, (size_t)(n + 1) * sizeof(*lv));
	if (!lv)
		return GL_ERR_NOMEM;
	*lines = lv;
	nv[n] = strndup(s, len);
	if (!nv[n])
		return GL_ERR_NOMEM;
	lv[n] = line;
	return GL_OK;
}

int gload_manifest_parse(const char *buf, size_t len, char ***names,
			 int **lines)
{
	const char *s, *e;
	size_t pos = 0, n;
	int count = 0, line = 0, *lv = NULL;
	char **nv = NULL;

	while (next_src_line(buf, len, &pos, &s, &n)) {
		line++;
		e = memchr(s, '#', n);
		if (!e)
			e = s + n;
		while (s < e && is_blank(*s))
			s++;
		while (e > s && is_blank(e[-1]))
			e--;
		if (e == s)
			continue;
		if (manifest_push(&nv, &lv, count, s, (size_t)(e - s), line))
			goto out_nomem;
		count++;
	}
	*names = nv;
	if (lines)
		*lines = lv;
	else
		free(lv);
	return count;

out_nomem:
	while (count > 0)
		free(nv[--count]);
	free(nv);
	free(lv);
	return GL_ERR_NOMEM;
}

static char *join_path(const char *dir, const char *name)
{
	size_t dl = strlen(dir);
	int slash = dl > 0 && dir[dl - 1] == '/';
	char *s;

	if (name[0] == '/')
		return strdup(name);
	s = malloc(dl + strlen(name) + 2);
	if (s)
		sprintf(s, slash ? "%s%s" : "%s/%s", dir, name);
	return s;
}

static void free_names(char **names, int n)
{
	while (n > 0)
		free(names[--n]);
	free(names);
}

static int prep_dir(struct gload_prog *p, const char *dir,
		    struct gload_diags *d)
{
	char *mpath = join_path(dir, GLOAD_MANIFEST), *buf = NULL, *fpath;
	char **names = NULL;
	int *mlines = NULL, n = 0, i, err, rc = GL_ERR_NOMEM;
	size_t len;

	if (!mpath)
		return GL_ERR_NOMEM;
	if (read_file(mpath, &buf, &len, &err) != GL_OK) {
		gload_diags_add(d, p->order++, dir, 0, "cannot open '%s': %s",
				mpath, strerror(err));
		rc = GL_ERR_NOENT;
		goto out_free;
	}
	n = gload_manifest_parse(buf, len, &names, &mlines);
	if (n < 0)
		goto out_free;
	rc = GL_OK;
	if (n == 0) {
		gload_diags_add(d, p->order++, mpath, 0, "lists no files");
		rc = GL_ERR_FORMAT;
	}
	for (i = 0; i < n && rc != GL_ERR_NOMEM; i++) {
		int r;

		if (!strcmp(names[i], GLOAD_SEAL_ENTRY)) {
			snprintf(p->seal_where, sizeof(p->seal_where), "%s:%d",
				 mpath, mlines[i]);
			if (i != n - 1) {
				gload_diags_add(d, p->order++, mpath, mlines[i],
						"%s must be the last entry",
						GLOAD_SEAL_ENTRY);
				rc = GL_ERR_FORMAT;
			}
			p->seal = 1;
			continue;
		}
		fpath = join_path(dir, names[i]);
		r = fpath ? prep_file(p, fpath, mlines[i], mpath, d)
			  : GL_ERR_NOMEM;
		if (r != GL_OK)
			rc = r;
		free(fpath);
	}
out_free:
	free_names(names, n > 0 ? n : 0);
	free(mlines);
	free(buf);
	free(mpath);
	return rc;
}

int gload_prep_path(struct gload_prog *p, const char *path,
		    struct gload_diags *d)
{
	struct stat st;

	if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
		return prep_dir(p, path, d);
	return prep_file(p, path, 0, NULL, d);
}

int gload_prog_finish(struct gload_prog *p)
{
	size_t len = 0, o = 0;
	int i;

	for (i = 0; i < p->nlines; i++)
		len += p->lines[i].len + 1;
	free(p->text);
	p->text = malloc(len + GL_IDENT_LINE_SIZE + 1);
	if (!p->text)
		return GL_ERR_NOMEM;
	for (i = 0; i < p->nlines; i++) {
		memcpy(p->text + o, p->lines[i].text, p->lines[i].len);
		o += p->lines[i].len;
		p->text[o++] = '\n';
	}
	p->body_len = o;
	p->id = gl_ident_stamp(p->text, o, p->stamp);
	o += (size_t)sprintf(p->text + o, "%s\n", p->stamp);
	p->text_len = o;
	return GL_OK;
}

int gload_prog_has_label(const struct gload_prog *p, const char *name)
{
	size_t n = strlen(name);
	int i;

	for (i = 0; i < p->nlines; i++) {
		const struct gload_line *l = &p->lines[i];

		if (l->len > n && l->text[0] == '#' &&
		    !memcmp(l->text + 1, name, n) &&
		    (l->len == n + 1 || l->text[n + 1] == ';'))
			return 1;
	}
	return 0;
}

void gload_prog_free(struct gload_prog *p)
{
	int i;

	for (i = 0; i < p->nlines; i++)
		free(p->lines[i].text);
	for (i = 0; i < p->nfiles; i++)
		free(p->files[i]);
	free(p->lines);
	free(p->files);
	free(p->file_order);
	free(p->text);
	memset(p, 0, sizeof(*p));
}
