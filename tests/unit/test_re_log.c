/*
 * test_re_log.c - the failure log (pc/super/re_log.c): exact line format, the
 * fsync of FAULT entries (fsync is wrapped with -Wl,--wrap=fsync to see that
 * it is called on the log after the line was written), rotation at the size
 * limit, the rate limit of repeated events, and bad arguments.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cmocka.h>

#include "gl_err.h"
#include "re_log.h"

#define MS 1000000LL

/* ---- fsync wrapper -------------------------------------------------------*/

int __real_fsync(int fd);
int __wrap_fsync(int fd);

static int fsync_calls;
static int fsync_last_fd;
static off_t fsync_size_at_call; /* file size when fsync was called */

int __wrap_fsync(int fd)
{
	struct stat st;

	fsync_calls++;
	fsync_last_fd = fd;
	fsync_size_at_call = fstat(fd, &st) == 0 ? st.st_size : -1;
	return __real_fsync(fd);
}

/* ---- helpers
 * ---------------------------------------------------------------*/

static char dir[64];
static char path[128];
static struct re_log lg;

static int setup(void **state)
{
	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/test_re_log.XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	snprintf(path, sizeof(path), "%s/roboelf.log", dir);
	memset(&lg, 0, sizeof(lg));
	return 0;
}

static int teardown(void **state)
{
	char p[160];
	int k;

	(void)state;
	re_log_close(&lg);
	unlink(path);
	for (k = 1; k <= 9; k++) {
		snprintf(p, sizeof(p), "%s.%d", path, k);
		unlink(p);
	}
	rmdir(dir);
	return 0;
}

/* Whole file into buf (NUL-terminated); returns its length or -1. */
static long slurp(const char *p, char *buf, size_t cap)
{
	int fd = open(p, O_RDONLY);
	ssize_t n, got = 0;

	if (fd < 0)
		return -1;
	while ((n = read(fd, buf + got, cap - 1 - (size_t)got)) > 0)
		got += n;
	close(fd);
	buf[got] = '\0';
	return (long)got;
}

static const struct timespec t0 = {1777638896, 789123456};

static int wr(enum re_log_level lvl, int64_t mono_ms, const char *text)
{
	return re_log_write_at(&lg, lvl, &t0, mono_ms * MS, text);
}

/* ---- tests
 * -------------------------------------------------------------------*/

static void test_line_format(void **state)
{
	char buf[8192];
	char big[3000];

	(void)state;
	assert_int_equal(re_log_open(&lg, path, NULL), GL_OK);
	assert_int_equal(wr(RE_LOG_INFO, 0, "roboelf 1.0 started"), GL_OK);
	assert_int_equal(wr(RE_LOG_WARN, 1, "reply after 80 ms"), GL_OK);
	assert_int_equal(wr(RE_LOG_FAULT, 2, "FAULT ESTOP: x.\nRecovery:\ty"),
			 GL_OK);
	assert_true(slurp(path, buf, sizeof(buf)) > 0);
	assert_string_equal(
	    buf,
	    "2026-05-01T12:34:56.789Z INFO roboelf 1.0 started\n"
	    "2026-05-01T12:34:56.789Z WARN reply after 80 ms\n"
	    "2026-05-01T12:34:56.789Z FAULT FAULT ESTOP: x. Recovery: y\n");
	/* Over-long text is cut and ends in "..." on one line. */
	memset(big, 'x', sizeof(big) - 1);
	big[sizeof(big) - 1] = '\0';
	assert_int_equal(wr(RE_LOG_INFO, 3, big), GL_OK);
	slurp(path, buf, sizeof(buf));
	{
		const char *last = strstr(buf, "FAULT FAULT");
		const char *l4 = strchr(last, '\n') + 1;
		size_t len = strlen(l4);

		assert_int_equal(len, 25 + 5 + RE_LOG_LINE_MAX - 1 + 1);
		assert_memory_equal(l4 + len - 5, "x...\n", 5);
	}
}

static void test_printf_wrappers(void **state)
{
	char buf[1024];

	(void)state;
	assert_int_equal(re_log_open(&lg, path, NULL), GL_OK);
	assert_int_equal(
	    re_log_msg(&lg, RE_LOG_INFO, "axis %s: %d points", "B", 512),
	    GL_OK);
	assert_true(slurp(path, buf, sizeof(buf)) > 0);
	/* "YYYY-MM-DDTHH:MM:SS.mmmZ INFO axis B: 512 points\n" */
	assert_int_equal(strlen(buf), 24 + 6 + 18 + 1);
	assert_int_equal(buf[4], '-');
	assert_int_equal(buf[10], 'T');
	assert_int_equal(buf[19], '.');
	assert_int_equal(buf[23], 'Z');
	assert_string_equal(buf + 24, " INFO axis B: 512 points\n");
}

static void test_fault_is_fsynced(void **state)
{
	char buf[1024];
	long len;

	(void)state;
	assert_int_equal(re_log_open(&lg, path, NULL), GL_OK);
	fsync_calls = 0;
	assert_int_equal(re_log_msg(&lg, RE_LOG_WARN, "not synced"), GL_OK);
	assert_int_equal(fsync_calls, 0);
	assert_int_equal(re_log_fault(&lg, "FAULT %s: relay lost", "ESTOP"),
			 GL_OK);
	/* fsync was called once, on the log, after the line was written. */
	assert_int_equal(fsync_calls, 1);
	assert_int_equal(fsync_last_fd, lg.fd);
	len = slurp(path, buf, sizeof(buf));
	assert_int_equal(fsync_size_at_call, len);
	/* Readable through another descriptor without closing the log. */
	assert_non_null(strstr(buf, " FAULT FAULT ESTOP: relay lost\n"));
	assert_int_equal(re_log_msg(&lg, RE_LOG_FAULT, "fault %d", 2), GL_OK);
	assert_int_equal(fsync_calls, 2);
}

/*
 * The disk fills in the middle of a FAULT line (RLIMIT_FSIZE 20 bytes
 * above the file: write() stores 20 bytes, then fails with EFBIG): the
 * call fails with errno EFBIG (not fsync's), the 20 bytes are cut off
 * again, fsync is not called; once there is room the same entry is
 * written whole, exactly once.
 */
static void test_partial_write_rolled_back(void **state)
{
	struct rlimit old, lim;
	char before[1024], buf[2048];
	long n0;
	int rc, e;

	(void)state;
	assert_int_equal(re_log_open(&lg, path, NULL), GL_OK);
	assert_int_equal(wr(RE_LOG_INFO, 0, "start"), GL_OK);
	n0 = slurp(path, before, sizeof(before));
	assert_true(n0 > 0);
	assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
	signal(SIGXFSZ, SIG_IGN);
	lim = old;
	lim.rlim_cur = (rlim_t)n0 + 20;
	assert_int_equal(setrlimit(RLIMIT_FSIZE, &lim), 0);
	fsync_calls = 0;
	errno = 0;
	rc = wr(RE_LOG_FAULT, 10, "FAULT ESTOP: the relay does not answer");
	e = errno;
	assert_int_equal(setrlimit(RLIMIT_FSIZE, &old), 0);
	signal(SIGXFSZ, SIG_DFL);
	assert_int_equal(rc, GL_ERR_SYS);
	assert_int_equal(e, EFBIG);
	assert_int_equal(fsync_calls, 0);
	assert_int_equal(slurp(path, buf, sizeof(buf)), n0);
	assert_string_equal(buf, before);
	/* room again: the retry writes it whole */
	assert_int_equal(
	    wr(RE_LOG_FAULT, 20, "FAULT ESTOP: the relay does not answer"),
	    GL_OK);
	assert_int_equal(fsync_calls, 1);
	slurp(path, buf, sizeof(buf));
	assert_string_equal(buf + n0 + 24,
			    " FAULT FAULT ESTOP: the relay does not answer\n");
	assert_int_equal(lg.size, (off_t)strlen(buf));
}

static void test_rotation(void **state)
{
	const struct re_log_cfg cfg = {4096, 2, 0};
	char buf[8192], p1[160], p2[160], p3[160], text[100];
	struct stat st;
	int k, first, last;

	(void)state;
	snprintf(p1, sizeof(p1), "%s.1", path);
	snprintf(p2, sizeof(p2), "%s.2", path);
	snprintf(p3, sizeof(p3), "%s.3", path);
	assert_int_equal(re_log_open(&lg, path, &cfg), GL_OK);
	/* Each line: 25 + 5 + 64 + 1 = 95 bytes; 43 lines fit in 4096. */
	for (k = 0; k < 43; k++) {
		snprintf(text, sizeof(text), "event %05d %52s", k, "");
		assert_int_equal(wr(RE_LOG_INFO, k, text), GL_OK);
	}
	assert_int_equal(stat(path, &st), 0);
	assert_int_equal(st.st_size, 43 * 95);
	assert_int_not_equal(access(p1, F_OK), 0); /* not yet rotated */
	assert_int_equal(wr(RE_LOG_INFO, 43, "event 00043"), GL_OK);
	assert_int_equal(stat(p1, &st), 0);
	assert_int_equal(st.st_size, 43 * 95);
	assert_int_equal(stat(path, &st), 0);
	assert_int_equal(st.st_size, 25 + 5 + 11 + 1);
	/* Many more: never more than keep files, none above the limit. */
	for (k = 44; k < 400; k++) {
		snprintf(text, sizeof(text), "event %05d %52s", k, "");
		assert_int_equal(wr(RE_LOG_INFO, k, text), GL_OK);
	}
	assert_int_not_equal(access(p3, F_OK), 0);
	assert_int_equal(stat(p2, &st), 0);
	assert_true(st.st_size <= 4096);
	assert_int_equal(stat(p1, &st), 0);
	assert_true(st.st_size <= 4096);
	/* The newest lines are in path, the ones before in path.1. */
	slurp(path, buf, sizeof(buf));
	assert_int_equal(sscanf(strstr(buf, "event "), "event %d", &first), 1);
	assert_int_equal(sscanf(strrchr(buf, 'v') - 1, "event %d", &last), 1);
	assert_int_equal(last, 399);
	slurp(p1, buf, sizeof(buf));
	assert_int_equal(sscanf(strrchr(buf, 'v') - 1, "event %d", &last), 1);
	assert_int_equal(last, first - 1);
}

static void test_rate_limit(void **state)
{
	char buf[4096];
	int k;

	(void)state;
	assert_int_equal(re_log_open(&lg, path, NULL), GL_OK);
	/* 20 per second for 1 s: first written, 19 suppressed (0..950 ms). */
	for (k = 0; k < 20; k++)
		assert_int_equal(wr(RE_LOG_WARN, k * 50, "late reply"), GL_OK);
	assert_int_equal(wr(RE_LOG_WARN, 999, "late reply"), GL_OK);
	slurp(path, buf, sizeof(buf));
	assert_string_equal(buf, "2026-05-01T12:34:56.789Z WARN late reply\n");
	/* 1000 ms after the last written copy: the count, then the line. */
	assert_int_equal(wr(RE_LOG_WARN, 1000, "late reply"), GL_OK);
	/* A different event reports nothing pending (none suppressed). */
	assert_int_equal(wr(RE_LOG_WARN, 1001, "other"), GL_OK);
	assert_int_equal(wr(RE_LOG_WARN, 1002, "other"), GL_OK);
	assert_int_equal(wr(RE_LOG_WARN, 1003, "other"), GL_OK);
	/* A fault flushes the count and is never suppressed itself. */
	assert_int_equal(wr(RE_LOG_FAULT, 1004, "boom"), GL_OK);
	assert_int_equal(wr(RE_LOG_FAULT, 1005, "boom"), GL_OK);
	/* Identical again after the fault: still within "other"'s window. */
	assert_int_equal(wr(RE_LOG_WARN, 1006, "other"), GL_OK);
	assert_int_equal(re_log_close(&lg), GL_OK); /* reports pending */
	slurp(path, buf, sizeof(buf));
	{
		const char *p = buf;
		const char *want[] = {
		    "WARN late reply",
		    "INFO last message repeated 20 times",
		    "WARN late reply",
		    "WARN other",
		    "INFO last message repeated 2 times",
		    "FAULT boom",
		    "FAULT boom",
		    "INFO last message repeated 1 time\n",
		};
		size_t k2;

		for (k2 = 0; k2 < sizeof(want) / sizeof(want[0]); k2++) {
			assert_int_equal(
			    strncmp(p + 25, want[k2], strlen(want[k2])), 0);
			p = strchr(p, '\n') + 1;
		}
		assert_string_equal(p, "");
	}
}

static void test_rate_limit_off(void **state)
{
	const struct re_log_cfg cfg = {1 << 20, 3, 0};
	char buf[4096];

	(void)state;
	assert_int_equal(re_log_open(&lg, path, &cfg), GL_OK);
	assert_int_equal(wr(RE_LOG_WARN, 0, "a"), GL_OK);
	assert_int_equal(wr(RE_LOG_WARN, 0, "a"), GL_OK);
	assert_int_equal(wr(RE_LOG_WARN, 0, "a"), GL_OK);
	slurp(path, buf, sizeof(buf));
	assert_int_equal(strlen(buf), 3 * (25 + 5 + 1 + 1));
}

static void test_bad_args(void **state)
{
	struct re_log_cfg cfg = re_log_cfg_default();
	char longp[RE_LOG_PATH_MAX];
	struct re_log z;

	(void)state;
	assert_int_equal(cfg.max_bytes, 10u * 1024 * 1024);
	assert_int_equal(cfg.keep, 5);
	assert_int_equal(cfg.rate_ms, 1000);
	cfg.keep = 0;
	assert_int_equal(re_log_open(&lg, path, &cfg), GL_ERR_ARG);
	cfg.keep = 10;
	assert_int_equal(re_log_open(&lg, path, &cfg), GL_ERR_ARG);
	cfg = re_log_cfg_default();
	cfg.max_bytes = 4095;
	assert_int_equal(re_log_open(&lg, path, &cfg), GL_ERR_ARG);
	memset(longp, 'a', sizeof(longp) - 1);
	longp[sizeof(longp) - 1] = '\0';
	assert_int_equal(re_log_open(&lg, longp, NULL), GL_ERR_ARG);
	assert_int_equal(re_log_open(&lg, "/nonexistent-dir/x.log", NULL),
			 GL_ERR_SYS);
	assert_int_equal(errno, ENOENT);
	assert_int_equal(re_log_write_at(&lg, RE_LOG_INFO, &t0, 0, "x"),
			 GL_ERR_ARG); /* not open */
	assert_int_equal(re_log_open(&lg, path, NULL), GL_OK);
	assert_int_equal(
	    re_log_write_at(&lg, (enum re_log_level)7, &t0, 0, "x"),
	    GL_ERR_ARG);
	assert_int_equal(re_log_close(&lg), GL_OK);
	assert_int_equal(re_log_close(&lg), GL_OK); /* twice */
	memset(&z, 0, sizeof(z));
	assert_int_equal(re_log_close(&z), GL_OK); /* zeroed: fd 0 kept */
	assert_int_not_equal(fcntl(0, F_GETFD), -1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_line_format, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_printf_wrappers, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_fault_is_fsynced, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_partial_write_rolled_back,
					    setup, teardown),
	    cmocka_unit_test_setup_teardown(test_rotation, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_rate_limit, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_rate_limit_off, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_bad_args, setup, teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
