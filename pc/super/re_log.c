/*
 * re_log.c - the failure log (see re_log.h for the rules).
 */
#include "re_log.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base_clock.h"
#include "base_durable.h"
#include "gl_err.h"

static const char *const re_log_level_names[] = {"INFO", "WARN", "FAULT"};

struct re_log_cfg re_log_cfg_default(void)
{
	struct re_log_cfg c = {10u * 1024 * 1024, 5, 1000};

	return c;
}

static int re_log_open_fd(struct re_log *lg)
{
	struct stat st;

	/* group-writable (within the umask): every operator of the group
	 * roboelf appends to the one log of /var/log/roboelf */
	lg->fd =
	    open(lg->path, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0664);
	if (lg->fd < 0)
		return GL_ERR_SYS;
	if (fstat(lg->fd, &st) != 0) {
		int e = errno;

		close(lg->fd);
		lg->fd = -1;
		errno = e;
		return GL_ERR_SYS;
	}
	lg->size = st.st_size;
	/* the directory too, so that a new entry persists (errno kept) */
	return base_fsync_dir(lg->path) == 0 ? GL_OK : GL_ERR_SYS;
}

int re_log_open(struct re_log *lg, const char *path,
		const struct re_log_cfg *cfg)
{
	struct re_log_cfg c = cfg ? *cfg : re_log_cfg_default();
	int rc;

	if (!lg || !path || !path[0] || strlen(path) >= RE_LOG_PATH_MAX - 3 ||
	    c.max_bytes < 4096 || c.keep < 1 || c.keep > 9 || c.rate_ms < 0)
		return GL_ERR_ARG;
	memset(lg, 0, sizeof(*lg));
	lg->fd = -1;
	snprintf(lg->path, sizeof(lg->path), "%s", path);
	lg->cfg = c;
	rc = re_log_open_fd(lg);
	if (rc != GL_OK) {
		if (lg->fd >= 0)
			close(lg->fd);
		lg->fd = -1;
		return rc;
	}
	lg->is_open = 1;
	return GL_OK;
}

/* All of @buf, or nothing: a line cut short (a full disk) is cut off
 * again, so that the retry writes it whole; errno is the write's. */
static int re_log_write_all(struct re_log *lg, const char *buf, size_t len)
{
	off_t start = lg->size;
	ssize_t n;

	while (len > 0) {
		n = write(lg->fd, buf, len);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0) {
			int e = n == 0 ? EIO : errno;

			if (lg->size != start && ftruncate(lg->fd, start) == 0)
				lg->size = start;
			errno = e;
			return GL_ERR_SYS;
		}
		buf += n;
		len -= (size_t)n;
		lg->size += n;
	}
	return GL_OK;
}

/* path -> path.1 -> ... -> path.keep, then a fresh path. */
static int re_log_rotate(struct re_log *lg)
{
	char from[RE_LOG_PATH_MAX + 4], to[RE_LOG_PATH_MAX + 4];
	int k, rc = GL_OK, e = 0;

	close(lg->fd);
	lg->fd = -1;
	for (k = lg->cfg.keep; k >= 1; k--) {
		if (k == 1)
			snprintf(from, sizeof(from), "%s", lg->path);
		else
			snprintf(from, sizeof(from), "%s.%c", lg->path,
				 (char)('0' + k - 1));
		snprintf(to, sizeof(to), "%s.%c", lg->path, (char)('0' + k));
		if (rename(from, to) != 0 && errno != ENOENT && !e) {
			e = errno;
			rc = GL_ERR_SYS;
		}
	}
	k = re_log_open_fd(lg); /* reopen whatever happened above */
	if (k != GL_OK)
		return k;
	errno = e;
	return rc;
}

static int re_log_put(struct re_log *lg, const char *buf, size_t len)
{
	int rc;

	if (lg->size > 0 && (size_t)lg->size + len > lg->cfg.max_bytes) {
		rc = re_log_rotate(lg);
		if (lg->fd < 0)
			return rc;
	}
	return re_log_write_all(lg, buf, len);
}

/* "2026-05-01T12:34:56.789Z FAULT " into @buf; returns its length. */
static int re_log_prefix(char *buf, size_t cap, const struct timespec *wall,
			 enum re_log_level lvl)
{
	struct tm tm;
	time_t sec = wall->tv_sec;

	if (!gmtime_r(&sec, &tm))
		memset(&tm, 0, sizeof(tm));
	return snprintf(buf, cap, "%04d-%02d-%02dT%02d:%02d:%02d.%03ldZ %s ",
			tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday,
			tm.tm_hour, tm.tm_min, tm.tm_sec,
			(long)(wall->tv_nsec / 1000000),
			re_log_level_names[lvl]);
}

/* Copy @text into @dst (cap >= 4), control characters as spaces, cut with
 * "..." when too long. Returns the length. */
static size_t re_log_clean(char *dst, size_t cap, const char *text)
{
	size_t n = 0;

	for (; *text && n < cap - 1; text++, n++) {
		unsigned char ch = (unsigned char)*text;

		dst[n] = (ch < 0x20 || ch == 0x7f) ? ' ' : (char)ch;
	}
	if (*text) {
		n = cap - 4;
		memcpy(dst + n, "...", 3);
		n += 3;
	}
	dst[n] = '\0';
	return n;
}

/* Write "last message repeated N times" if copies were suppressed. */
static int re_log_flush_repeats(struct re_log *lg, const struct timespec *wall)
{
	char buf[128];
	int n;

	if (lg->repeats == 0)
		return GL_OK;
	n = re_log_prefix(buf, sizeof(buf), wall, RE_LOG_INFO);
	n += snprintf(buf + n, sizeof(buf) - (size_t)n,
		      "last message repeated %ld time%s\n", lg->repeats,
		      lg->repeats == 1 ? "" : "s");
	lg->repeats = 0;
	return re_log_put(lg, buf, (size_t)n);
}

/* Rate limit: 1 when this INFO/WARN text is to be suppressed. */
static int re_log_suppress(struct re_log *lg, const char *clean,
			   int64_t mono_ns)
{
	int64_t window_ns = lg->cfg.rate_ms * 1000000;

	if (window_ns <= 0 || !lg->have_last || strcmp(clean, lg->last) != 0)
		return 0;
	if (mono_ns - lg->last_written_ns >= window_ns)
		return 0;
	lg->repeats++;
	return 1;
}

int re_log_write_at(struct re_log *lg, enum re_log_level lvl,
		    const struct timespec *wall, int64_t mono_ns,
		    const char *text)
{
	size_t pre, len;
	int rc;

	if (!lg || !lg->is_open || !wall || !text || (int)lvl < 0 ||
	    lvl > RE_LOG_FAULT)
		return GL_ERR_ARG;
	if (lg->fd < 0 && re_log_open_fd(lg) != GL_OK && lg->fd < 0)
		return GL_ERR_SYS; /* a failed rotation left it closed */
	pre = (size_t)re_log_prefix(lg->line, sizeof(lg->line), wall, lvl);
	len = pre + re_log_clean(lg->line + pre, RE_LOG_LINE_MAX, text);
	if (lvl != RE_LOG_FAULT && re_log_suppress(lg, lg->line + pre, mono_ns))
		return GL_OK;
	rc = re_log_flush_repeats(lg, wall);
	if (lvl != RE_LOG_FAULT) {
		memcpy(lg->last, lg->line + pre, len - pre + 1);
		lg->have_last = 1;
		lg->last_written_ns = mono_ns;
	}
	lg->line[len++] = '\n';
	if (re_log_put(lg, lg->line, len) != GL_OK)
		return GL_ERR_SYS; /* errno: the write's (ENOSPC, EIO ...) */
	if (lvl == RE_LOG_FAULT && lg->fd >= 0 && fsync(lg->fd) != 0)
		rc = GL_ERR_SYS;
	return rc;
}

static void re_log_now(struct timespec *wall, int64_t *mono_ns)
{
	clock_gettime(CLOCK_REALTIME, wall);
	*mono_ns = base_now_ns();
}

static int re_log_vwrite(struct re_log *lg, enum re_log_level lvl,
			 const char *fmt, va_list ap)
    __attribute__((format(printf, 3, 0)));

static int re_log_vwrite(struct re_log *lg, enum re_log_level lvl,
			 const char *fmt, va_list ap)
{
	struct timespec wall;
	int64_t mono;

	if (!lg || !lg->is_open || !fmt)
		return GL_ERR_ARG;
	vsnprintf(lg->text, sizeof(lg->text), fmt, ap);
	re_log_now(&wall, &mono);
	return re_log_write_at(lg, lvl, &wall, mono, lg->text);
}

int re_log_msg(struct re_log *lg, enum re_log_level lvl, const char *fmt, ...)
{
	va_list ap;
	int rc;

	va_start(ap, fmt);
	rc = re_log_vwrite(lg, lvl, fmt, ap);
	va_end(ap);
	return rc;
}

int re_log_fault(struct re_log *lg, const char *fmt, ...)
{
	va_list ap;
	int rc;

	va_start(ap, fmt);
	rc = re_log_vwrite(lg, RE_LOG_FAULT, fmt, ap);
	va_end(ap);
	return rc;
}

int re_log_sync(struct re_log *lg)
{
	struct timespec wall;
	int64_t mono;
	int rc;

	if (!lg || !lg->is_open || lg->fd < 0)
		return GL_ERR_ARG;
	re_log_now(&wall, &mono);
	rc = re_log_flush_repeats(lg, &wall);
	if (lg->fd >= 0 && fsync(lg->fd) != 0)
		rc = GL_ERR_SYS;
	return rc;
}

int re_log_close(struct re_log *lg)
{
	int rc;

	if (!lg || !lg->is_open)
		return GL_OK;
	rc = lg->fd >= 0 ? re_log_sync(lg) : GL_OK;
	if (lg->fd >= 0 && close(lg->fd) != 0 && rc == GL_OK)
		rc = GL_ERR_SYS;
	lg->fd = -1;
	lg->is_open = 0;
	return rc;
}
