/*
 * ctrl_buf.c - growable byte buffers: replies and unsolicited output waiting
 * for the host, download text, the output of one statement.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctrl_buf.h"

/* Make room for n more bytes; moves unread data to the front first. */
static int buf_reserve(struct ctrl_buf *b, size_t n)
{
	size_t need, cap;
	uint8_t *p;

	if (b->start > 0 && b->start == b->len) {
		b->start = 0;
		b->len = 0;
	}
	if (b->len + n <= b->cap)
		return 0;
	if (b->start > 0) {
		memmove(b->p, b->p + b->start, b->len - b->start);
		b->len -= b->start;
		b->start = 0;
		if (b->len + n <= b->cap)
			return 0;
	}
	need = b->len + n;
	cap = b->cap ? b->cap : 256;
	while (cap < need)
		cap *= 2;
	p = realloc(b->p, cap);
	if (!p)
		return -1;
	b->p = p;
	b->cap = cap;
	return 0;
}

int ctrl_buf_put(struct ctrl_buf *b, const void *data, size_t n)
{
	if (n == 0)
		return 0;
	if (buf_reserve(b, n) < 0)
		return -1;
	memcpy(b->p + b->len, data, n);
	b->len += n;
	return 0;
}

int ctrl_buf_puts(struct ctrl_buf *b, const char *s)
{
	return ctrl_buf_put(b, s, strlen(s));
}

int ctrl_buf_printf(struct ctrl_buf *b, const char *fmt, ...)
{
	char tmp[256];
	va_list ap;
	int n;

	va_start(ap, fmt);
	n = vsnprintf(tmp, sizeof(tmp), fmt, ap);
	va_end(ap);
	if (n < 0)
		return -1;
	if ((size_t)n >= sizeof(tmp))
		n = (int)sizeof(tmp) - 1;
	return ctrl_buf_put(b, tmp, (size_t)n);
}

size_t ctrl_buf_pending(const struct ctrl_buf *b)
{
	return b->len - b->start;
}

const uint8_t *ctrl_buf_data(const struct ctrl_buf *b)
{
	static const uint8_t empty[1];

	return b->p ? b->p + b->start : empty;
}

size_t ctrl_buf_take(struct ctrl_buf *b, uint8_t *out, size_t cap)
{
	size_t n = ctrl_buf_pending(b);

	if (n > cap)
		n = cap;
	if (n)
		memcpy(out, b->p + b->start, n);
	b->start += n;
	if (b->start == b->len) {
		b->start = 0;
		b->len = 0;
	}
	return n;
}

void ctrl_buf_clear(struct ctrl_buf *b)
{
	b->start = 0;
	b->len = 0;
}

void ctrl_buf_free(struct ctrl_buf *b)
{
	free(b->p);
	b->p = NULL;
	b->start = b->len = b->cap = 0;
}
