/*
 * ctrl_buf.h - growable byte buffers (ctrl_buf.c); internal to the simulated
 * controller (ctrl/), not part of its API (ctrl.h).
 * It knows nothing of handles or routing (ctrl_out.h).
 */
#ifndef SIM_CTRL_BUF_H
#define SIM_CTRL_BUF_H

#include "ctrl_int.h"

/*
 * ctrl_buf_put() / ctrl_buf_puts() / ctrl_buf_printf() - append @n bytes
 * of @data, the string @s, or printf output (cut to 255 bytes) to @b,
 * growing it; the bytes are copied. A zeroed struct is an empty buffer.
 * Return: 0, or -1 when out of memory (or a format error): nothing added.
 */
int ctrl_buf_put(struct ctrl_buf *b, const void *data, size_t n);
int ctrl_buf_puts(struct ctrl_buf *b, const char *s);
int ctrl_buf_printf(struct ctrl_buf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* ctrl_buf_pending() - bytes of @b not yet taken. */
size_t ctrl_buf_pending(const struct ctrl_buf *b);
/*
 * ctrl_buf_data() - the first of the ctrl_buf_pending() unread bytes of @b,
 * valid until @b changes; never NULL (an empty buffer that never held
 * anything gives a pointer to a static empty string, not NULL + offset).
 */
const uint8_t *ctrl_buf_data(const struct ctrl_buf *b);
/*
 * ctrl_buf_take() - move up to @cap unread bytes of @b into @out (FIFO).
 * Return: the number of bytes copied.
 */
size_t ctrl_buf_take(struct ctrl_buf *b, uint8_t *out, size_t cap);
/* ctrl_buf_clear() - drop the contents of @b, keeping its memory. */
void ctrl_buf_clear(struct ctrl_buf *b);
/* ctrl_buf_free() - release the memory of @b; it is empty and usable. */
void ctrl_buf_free(struct ctrl_buf *b);

#endif /* SIM_CTRL_BUF_H */
