/*
 * base_durable.h - durable file writing: a file is either wholly its old
 * contents or wholly its new ones, also after a power cut.
 *
 * The recipe: write a temporary file in the same directory, fsync it,
 * rename it over the target, fsync the directory. The pieces are public
 * too, for callers that must do something between them (re_calfile keeps
 * a backup before the rename). It is not a general file API and it takes
 * no locks: two writers of one path must be kept apart by their caller.
 * Nothing prints; errors are negative errno values (errno is set too).
 */
#ifndef BASE_DURABLE_H
#define BASE_DURABLE_H

#include <stddef.h>
#include <sys/types.h>

/*
 * base_write_all() - write all @len bytes of @data to @fd, retrying short
 * writes and EINTR. Does not fsync or close @fd (the caller owns it).
 * Return: 0; -EIO if write() wrote nothing; else the negated errno.
 */
int base_write_all(int fd, const void *data, size_t len);

/*
 * base_fsync_dir() - fsync the directory that holds @path ("." for a bare
 * name, "/" for "/name"), so that a new, renamed or removed entry @path
 * survives a power cut. @path itself need not exist.
 * Return: 0; -ENAMETOOLONG; the negated errno of open() or fsync().
 */
int base_fsync_dir(const char *path);

/*
 * base_durable_write() - replace the file @path with the @len bytes at
 * @data, durably: "@path.tmp" is created (mode @mode, less the umask; an
 * old one is truncated), written, fsynced and closed, renamed over @path,
 * and the directory is fsynced. @path never holds a partial file; on an
 * error before the rename the temporary file is removed and @path is
 * untouched.
 * Return: 0; -EFAULT for a NULL @path (or NULL @data with @len > 0);
 *         -ENAMETOOLONG when "@path.tmp" does not fit PATH_MAX; otherwise
 *         the negated errno of the step that failed. After a failed
 *         directory fsync (the only error after the rename) @path already
 *         holds the new contents.
 */
int base_durable_write(const char *path, const void *data, size_t len,
		       mode_t mode);

#endif /* BASE_DURABLE_H */
