/*
 * base_durable.c - durable file writing (see base_durable.h). Not a file
 * API: write-all, fsync of a directory, and the tmp + fsync + rename +
 * fsync-directory recipe built from them.
 */
#include "base_durable.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* Return -@e with errno = @e (the module's error convention). */
static int fail(int e)
{
	errno = e;
	return -e;
}

int base_write_all(int fd, const void *data, size_t len)
{
	const char *p = data;
	ssize_t n;

	while (len > 0) {
		n = write(fd, p, len);
		if (n < 0 && errno == EINTR)
			continue;
		if (n < 0)
			return fail(errno);
		if (n == 0)
			return fail(EIO);
		p += n;
		len -= (size_t)n;
	}
	return 0;
}

int base_fsync_dir(const char *path)
{
	char dir[PATH_MAX];
	const char *slash;
	int fd, rc, e = 0;

	if (!path)
		return fail(EFAULT);
	slash = strrchr(path, '/');
	if (!slash)
		snprintf(dir, sizeof(dir), ".");
	else if (slash == path)
		snprintf(dir, sizeof(dir), "/");
	else if ((size_t)(slash - path) >= sizeof(dir))
		return fail(ENAMETOOLONG);
	else
		snprintf(dir, sizeof(dir), "%.*s", (int)(slash - path), path);
	fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
	if (fd < 0)
		return fail(errno);
	rc = fsync(fd);
	if (rc != 0)
		e = errno;
	close(fd);
	return rc != 0 ? fail(e) : 0;
}

/* Create @tmp, write @len bytes, fsync, close; remove it on error. */
static int write_tmp(const char *tmp, const void *data, size_t len, mode_t mode)
{
	int fd, rc;

	fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, mode);
	if (fd < 0)
		return fail(errno);
	rc = base_write_all(fd, data, len);
	if (rc == 0 && fsync(fd) != 0)
		rc = -errno;
	if (close(fd) != 0 && rc == 0)
		rc = -errno;
	if (rc != 0) {
		unlink(tmp);
		return fail(-rc);
	}
	return 0;
}

int base_durable_write(const char *path, const void *data, size_t len,
		       mode_t mode)
{
	char tmp[PATH_MAX];
	int rc, n;

	if (!path || (!data && len > 0))
		return fail(EFAULT);
	n = snprintf(tmp, sizeof(tmp), "%s.tmp", path);
	if (n < 0 || (size_t)n >= sizeof(tmp))
		return fail(ENAMETOOLONG);
	rc = write_tmp(tmp, data, len, mode);
	if (rc != 0)
		return rc;
	if (rename(tmp, path) != 0) {
		rc = errno;
		unlink(tmp);
		return fail(rc);
	}
	return base_fsync_dir(path);
}
