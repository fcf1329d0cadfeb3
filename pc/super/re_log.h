/*
 * re_log.h - the failure log: one timestamped line per event.
 *
 * Line format (docs/calibration-file.md, section 3):
 *   2026-05-01T12:34:56.789Z WARN watchdog: reply after 80 ms (limit 75 ms)
 * i.e. ISO 8601 UTC wall-clock time with milliseconds, a level (INFO, WARN,
 * FAULT), the text (newlines and control characters become spaces).
 *
 * - Every line goes to the file with one write(2) (no stdio buffering).
 * - re_log_fault() also fsyncs the file before it returns, so the entry is on
 *   disk before the caller reports the relay open.
 * - Size is bounded: a line that would take the file past max_bytes first
 *   rotates path -> path.1 -> path.2 ... path.<keep> (the oldest dropped).
 * - Rate limit: an INFO/WARN event whose text equals the previous INFO/WARN
 *   event and comes less than rate_ms after the last written copy is not
 *   written, only counted. Before the next line of any kind (and on sync and
 *   close) a line "INFO last message repeated N times" reports the count
 *   ("1 time" for one).
 *   FAULT lines are never suppressed.
 * - No allocation after re_log_open(); the caller owns struct re_log.
 * - Never prints; returns gl_err codes (GL_ERR_SYS keeps errno).
 */
#ifndef RE_LOG_H
#define RE_LOG_H

#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>
#include <time.h>

#define RE_LOG_PATH_MAX 512
#define RE_LOG_LINE_MAX 2048 /* longer texts are cut, ending in "..." */

enum re_log_level {
	RE_LOG_INFO = 0,
	RE_LOG_WARN,
	RE_LOG_FAULT,
};

struct re_log_cfg {
	size_t max_bytes; /* rotate before exceeding, >= 4096 */
	int keep;	  /* rotated files kept, 1..9; default 5 */
	int64_t rate_ms;  /* identical INFO/WARN window, 0 = off */
};

/* The log handle; treat the fields as private. Zero it or re_log_open() it. */
struct re_log {
	int is_open; /* 1 between open and close */
	int fd;
	char path[RE_LOG_PATH_MAX];
	struct re_log_cfg cfg;
	off_t size; /* current file size, bytes */
	/* rate limiting */
	char last[RE_LOG_LINE_MAX]; /* text of the last INFO/WARN event */
	int have_last;
	int64_t last_written_ns; /* mono time of last written copy */
	long repeats;		 /* suppressed copies not yet reported */
	char line[RE_LOG_LINE_MAX + 64]; /* line assembly buffer */
	char text[RE_LOG_LINE_MAX];	 /* printf buffer */
};

/*
 * re_log_cfg_default() - 10 MiB, keep 5, rate 1000 ms.
 */
struct re_log_cfg re_log_cfg_default(void);

/*
 * re_log_open() - open (create, append) the log file.
 * @lg: [out] the handle.
 * @path: the file; its directory must exist. Length < RE_LOG_PATH_MAX - 3.
 * @cfg: [in] limits, NULL for the defaults.
 * Return: GL_OK, GL_ERR_ARG (bad path or cfg), GL_ERR_SYS (errno kept).
 */
int re_log_open(struct re_log *lg, const char *path,
		const struct re_log_cfg *cfg);

/*
 * re_log_write_at() - write one event with explicit times (for tests; the
 * other functions call it with the current clocks).
 * @lvl: level; RE_LOG_FAULT is synced (fsync) before returning.
 * @wall: [in] UTC wall-clock time for the timestamp.
 * @mono_ns: monotonic time for the rate limit.
 * @text: the event text.
 * Return: GL_OK (also when suppressed by the rate limit), GL_ERR_ARG,
 *         GL_ERR_SYS (errno kept; e.g. disk full; the handle stays usable).
 */
int re_log_write_at(struct re_log *lg, enum re_log_level lvl,
		    const struct timespec *wall, int64_t mono_ns,
		    const char *text);

/*
 * re_log_msg() - printf-style INFO or WARN event at the current time.
 * Return: as re_log_write_at().
 */
int re_log_msg(struct re_log *lg, enum re_log_level lvl, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/*
 * re_log_fault() - printf-style FAULT event: written, then fsync'ed, before
 * returning. Never rate limited.
 * Return: as re_log_write_at().
 */
int re_log_fault(struct re_log *lg, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/*
 * re_log_sync() - report pending repeats and fsync the file.
 * Return: GL_OK, GL_ERR_ARG (not open), GL_ERR_SYS.
 */
int re_log_sync(struct re_log *lg);

/*
 * re_log_close() - report pending repeats, fsync and close. Safe on a closed
 * or zeroed handle (returns GL_OK; a zeroed handle's fd 0 is not closed).
 * Return: GL_OK or GL_ERR_SYS (the handle is closed anyway).
 */
int re_log_close(struct re_log *lg);

#endif /* RE_LOG_H */
