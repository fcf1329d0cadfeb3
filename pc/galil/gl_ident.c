/* gl_ident.c - the program identity stamp; see gl_ident.h. */
#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "gl_err.h"
#include "gl_hash.h"
#include "gl_ident.h"

#define UL_END 0x1a /* Ctrl-Z: end of an upload */

/* Walks the lines of a text; the last line may lack its terminator. */
struct line_iter {
	const char *text;
	size_t len; /* up to the first 0x1A */
	size_t pos;
};

static void iter_init(struct line_iter *it, const char *text, size_t len)
{
	const char *end = len ? memchr(text, UL_END, len) : NULL;

	it->text = text;
	it->len = end ? (size_t)(end - text) : len;
	it->pos = 0;
}

/* Return 1 and the next line (without its end) in @s/@n, 0 at the end. */
static int iter_next(struct line_iter *it, const char **s, size_t *n)
{
	size_t start = it->pos;

	if (it->pos >= it->len)
		return 0;
	while (it->pos < it->len && it->text[it->pos] != '\r' &&
	       it->text[it->pos] != '\n')
		it->pos++;
	*s = it->text + start;
	*n = it->pos - start;
	if (it->pos < it->len) {
		if (it->text[it->pos] == '\r' && it->pos + 1 < it->len &&
		    it->text[it->pos + 1] == '\n')
			it->pos++;
		it->pos++;
	}
	return 1;
}

int gl_ident_normalise(const char *in, size_t len, char *out, size_t cap)
{
	struct line_iter it;
	const char *s;
	size_t n, w = 0;

	if ((!in || !out) && len > 0)
		return GL_ERR_ARG;
	iter_init(&it, in, len);
	while (iter_next(&it, &s, &n)) {
		if (w + n + 1 > cap)
			return GL_ERR_OVERFLOW;
		memmove(out + w, s, n); /* in place: out + w <= s */
		w += n;
		out[w++] = '\n';
	}
	/* drop empty lines at the end: "...x\n\n\n" -> "...x\n", "\n" -> "" */
	while (w > 0 && out[w - 1] == '\n' && (w == 1 || out[w - 2] == '\n'))
		w--;
	if (w > INT32_MAX)
		return GL_ERR_OVERFLOW;
	if (w < cap)
		out[w] = '\0';
	return (int)w;
}

uint64_t gl_ident_stamp(const char *text, size_t len,
			char line[GL_IDENT_LINE_SIZE])
{
	uint64_t h = gl_fnv1a64(GL_FNV64_INIT, text, len);

	if (line)
		snprintf(line, GL_IDENT_LINE_SIZE,
			 GL_IDENT_PREFIX "%016" PRIX64, h);
	return h;
}

static int hex_value(char c)
{
	if (c >= '0' && c <= '9')
		return c - '0';
	if (c >= 'A' && c <= 'F')
		return c - 'A' + 10;
	if (c >= 'a' && c <= 'f')
		return c - 'a' + 10;
	return -1;
}

int gl_ident_parse(const char *line, size_t len, uint64_t *id)
{
	const size_t plen = sizeof(GL_IDENT_PREFIX) - 1;
	uint64_t v = 0;
	size_t i;

	if (!line || len != plen + GL_IDENT_DIGITS ||
	    memcmp(line, GL_IDENT_PREFIX, plen) != 0)
		return GL_ERR_FORMAT;
	for (i = plen; i < len; i++) {
		int d = hex_value(line[i]);

		if (d < 0)
			return GL_ERR_FORMAT;
		v = (v << 4) | (uint64_t)d;
	}
	*id = v;
	return GL_OK;
}

/* Index of the last non-empty line, or -1 when every line is empty. */
static long last_nonempty_line(const char *text, size_t len)
{
	struct line_iter it;
	const char *s;
	size_t n;
	long i = 0, last = -1;

	iter_init(&it, text, len);
	for (; iter_next(&it, &s, &n); i++)
		if (n > 0)
			last = i;
	return last;
}

int gl_ident_verify(const char *uploaded, size_t len, uint64_t *id)
{
	struct line_iter it;
	const char *s;
	size_t n;
	uint64_t h = GL_FNV64_INIT, stamp;
	long i, last;

	if (id)
		*id = 0;
	if (!uploaded && len > 0)
		return GL_ERR_ARG;
	last = last_nonempty_line(uploaded, len);
	if (last < 0)
		return GL_ERR_FORMAT;
	iter_init(&it, uploaded, len);
	for (i = 0; i < last && iter_next(&it, &s, &n); i++) {
		h = gl_fnv1a64(h, s, n);
		h = gl_fnv1a64(h, "\n", 1);
	}
	if (!iter_next(&it, &s, &n) || gl_ident_parse(s, n, &stamp) != GL_OK)
		return GL_ERR_FORMAT;
	if (id)
		*id = stamp;
	return h == stamp ? GL_OK : GL_ERR_MISMATCH;
}
