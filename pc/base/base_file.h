/*
 * base_file.h - read a whole regular file into memory.
 *
 * The one whole-file reader of the supervisor and the tools (the calibration
 * file, the configuration, the plant file, DMC sources). It is not a
 * streaming reader and it does not parse: callers parse the buffer
 * (parsers take buffers). It never prints; errors are negative errno
 * values, so each caller words its message as before.
 */
#ifndef BASE_FILE_H
#define BASE_FILE_H

#include <stddef.h>

/*
 * base_file_read() - read the whole regular file @path into a new buffer.
 * @path:      the file (opened O_RDONLY | O_CLOEXEC, links followed)
 * @max_bytes: the largest accepted size in bytes; a longer file is refused
 * @buf:       out: the contents plus a terminating NUL; the caller frees it
 *             with free(). Untouched on error.
 * @len:       out: the number of bytes read (without the NUL). A file that
 *             shrinks while it is read gives what was there.
 * Return: 0; -EFBIG when the file holds more than @max_bytes bytes;
 *         -EISDIR for a directory; -EINVAL for another kind of non-regular
 *         file (device, FIFO, socket); -ENOMEM; -EFAULT for a NULL argument;
 *         otherwise the negated errno of open(), fstat() or read() (e.g.
 *         -ENOENT, -EACCES, -EIO). errno is also set to the positive code.
 */
int base_file_read(const char *path, size_t max_bytes, char **buf, size_t *len);

#endif /* BASE_FILE_H */
