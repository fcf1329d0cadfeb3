/*
 * base_file.c - whole-file reading (see base_file.h). Not a parser and not
 * a streaming reader: one open, one allocation of the size fstat() gives
 * (grown if the file grows meanwhile, up to the caller's limit), reads
 * until end of file.
 */
#include "base_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

/* Return -@e with errno = @e (the module's error convention). */
static int fail(int e)
{
	errno = e;
	return -e;
}

/* Grow *@b to hold @want bytes plus a NUL; 0 or -ENOMEM. */
static int grow(char **b, size_t *cap, size_t want)
{
	char *nb;

	if (want + 1 <= *cap)
		return 0;
	nb = realloc(*b, want + 1);
	if (!nb)
		return -ENOMEM;
	*b = nb;
	*cap = want + 1;
	return 0;
}

/* Read @fd to its end into a new buffer of at most @max bytes; @size is the
 * expected size: one allocation of @size + 2 serves an unchanged file (the
 * spare byte lets the last read() see the end of file). */
static int read_fd(int fd, size_t size, size_t max, char **out, size_t *len)
{
	size_t cap = 0, got = 0, want = size + 1;
	char *b = NULL;
	ssize_t n;

	for (;;) {
		if (want > max + 1)
			want = max + 1; /* room to see one byte too many */
		if (grow(&b, &cap, want) != 0)
			goto fail_nomem;
		n = read(fd, b + got, cap - 1 - got);
		if (n < 0 && errno == EINTR)
			continue;
		if (n < 0)
			goto fail_errno;
		if (n == 0)
			break;
		got += (size_t)n;
		if (got > max) {
			free(b);
			return -EFBIG;
		}
		if (got == cap - 1)
			want = got + 4096; /* grew meanwhile */
	}
	b[got] = '\0';
	*out = b;
	*len = got;
	return 0;
fail_nomem:
	free(b);
	return -ENOMEM;
fail_errno:
	n = errno;
	free(b);
	return (int)-n;
}

int base_file_read(const char *path, size_t max_bytes, char **buf, size_t *len)
{
	struct stat st;
	int fd, rc;

	if (!path || !buf || !len)
		return fail(EFAULT);
	if (max_bytes > SIZE_MAX / 2)
		max_bytes = SIZE_MAX / 2; /* so that max_bytes + 2 fits */
	fd = open(path, O_RDONLY | O_CLOEXEC);
	if (fd < 0)
		return fail(errno);
	if (fstat(fd, &st) != 0)
		rc = -errno;
	else if (S_ISDIR(st.st_mode))
		rc = -EISDIR;
	else if (!S_ISREG(st.st_mode))
		rc = -EINVAL;
	else if ((unsigned long long)st.st_size > max_bytes)
		rc = -EFBIG;
	else
		rc = read_fd(fd, (size_t)st.st_size, max_bytes, buf, len);
	close(fd);
	return rc ? fail(-rc) : 0;
}
