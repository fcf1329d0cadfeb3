/*
 * test_re_io.c - the log queue of the real io (no file write in
 * the cycle): INFO/WARN events logged while defer_log is set leave the file
 * untouched until re_io_flush_log(), which writes them in order with the
 * times they happened at; an overflow is counted and said; a FAULT flushes
 * the queue first and is on disk at once.
 *
 * And the one look before a cycle: the wait (ops->sleep_until)
 * is a ppoll() over the cycle's descriptors that ends at its deadline, not
 * before, whatever shows input; what it saw is handed out once
 * (re_io_key_look: 1 input, 0 none, -1 not looked at).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base_clock.h"

#include <cmocka.h>

#include "gl_err.h"
#include "re_io.h"
#include "re_log.h"

static char dir[64], path[128];
static struct re_log lg;
static struct re_io_real real;
static struct re_io io;

static int setup(void **state)
{
	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/test_re_io.XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	snprintf(path, sizeof(path), "%s/roboelf.log", dir);
	memset(&lg, 0, sizeof(lg));
	memset(&real, 0, sizeof(real));
	if (re_log_open(&lg, path, NULL) != GL_OK)
		return -1;
	real.log = &lg;
	re_io_bind(&io, &real);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	re_log_close(&lg);
	unlink(path);
	rmdir(dir);
	return 0;
}

static off_t file_size(void)
{
	struct stat st;

	return stat(path, &st) == 0 ? st.st_size : -1;
}

/* The log's lines without their time stamps ("LEVEL text\n" each). */
static void lines(char *out, size_t cap)
{
	char line[4096];
	FILE *f = fopen(path, "r");
	size_t n = 0;

	assert_non_null(f);
	out[0] = '\0';
	while (fgets(line, sizeof(line), f)) {
		const char *sp = strchr(line, ' ');

		assert_non_null(sp);
		n += (size_t)snprintf(out + n, cap - n, "%s", sp + 1);
	}
	fclose(f);
}

static void test_deferred_until_flush(void **state)
{
	char buf[4096];

	(void)state;
	real.defer_log = 1;
	assert_int_equal(re_io_logf(&io, RE_LOG_WARN, "watchdog: reply %d", 1),
			 GL_OK);
	assert_int_equal(re_io_logf(&io, RE_LOG_INFO, "controller: %s", "hi"),
			 GL_OK);
	assert_int_equal(file_size(), 0); /* nothing written in the cycle */
	real.defer_log = 0;
	assert_int_equal(re_io_flush_log(&real), GL_OK);
	lines(buf, sizeof(buf));
	assert_string_equal(buf, "WARN watchdog: reply 1\n"
				 "INFO controller: hi\n");
	/* a second flush writes nothing more */
	assert_int_equal(re_io_flush_log(&real), GL_OK);
	lines(buf, sizeof(buf));
	assert_string_equal(buf, "WARN watchdog: reply 1\n"
				 "INFO controller: hi\n");
}

static void test_overflow_said(void **state)
{
	char buf[8192], want[8192];
	size_t n = 0;

	(void)state;
	real.defer_log = 1;
	for (int i = 0; i < RE_IO_LOGQ + 4; i++)
		re_io_logf(&io, RE_LOG_WARN, "event %d", i);
	assert_int_equal(file_size(), 0);
	real.defer_log = 0;
	assert_int_equal(re_io_flush_log(&real), GL_OK);
	for (int i = 0; i < RE_IO_LOGQ; i++)
		n += (size_t)snprintf(want + n, sizeof(want) - n,
				      "WARN event %d\n", i);
	snprintf(want + n, sizeof(want) - n,
		 "WARN log: 4 events dropped (more than %d in one cycle)\n",
		 RE_IO_LOGQ);
	lines(buf, sizeof(buf));
	assert_string_equal(buf, want);
}

static void test_fault_flushes_first(void **state)
{
	char buf[4096];

	(void)state;
	real.defer_log = 1;
	re_io_logf(&io, RE_LOG_WARN, "watchdog: late");
	assert_int_equal(re_io_logf(&io, RE_LOG_FAULT, "FAULT X: y"), GL_OK);
	/* on disk at once, after what was queued before it */
	lines(buf, sizeof(buf));
	assert_string_equal(buf, "WARN watchdog: late\n"
				 "FAULT FAULT X: y\n");
	re_io_logf(&io, RE_LOG_WARN, "while latched: z");
	real.defer_log = 0;
	re_io_flush_log(&real);
	lines(buf, sizeof(buf));
	assert_string_equal(buf, "WARN watchdog: late\n"
				 "FAULT FAULT X: y\n"
				 "WARN while latched: z\n");
}

static void test_not_deferred(void **state)
{
	char buf[4096];

	(void)state;
	re_io_logf(&io, RE_LOG_INFO, "at once");
	lines(buf, sizeof(buf));
	assert_string_equal(buf, "INFO at once\n");
}

/* Wait @ms through the io: the ms it took. */
static double wait_ms(int ms)
{
	int64_t t0 = base_now_ns();

	io.ops->sleep_until(io.ud, t0 + ms * BASE_NS_PER_MS);
	return (double)(base_now_ns() - t0) / 1e6;
}

static void test_look(void **state)
{
	int pfd[2];
	double ms;

	(void)state;
	assert_int_equal(pipe(pfd), 0);
	real.key_fd = pfd[0];
	real.watch_key = 1;
	/* nothing typed: looked at, nothing; taken once */
	ms = wait_ms(30);
	assert_true(ms >= 30 && ms < 30 + 15);
	assert_int_equal(re_io_key_look(&real), 0);
	assert_int_equal(re_io_key_look(&real), -1);
	/* a key waiting: the wait still ends at its deadline (the descriptor
	 * is left out once seen, no busy loop), and the key is said */
	assert_int_equal(write(pfd[1], "q", 1), 1);
	ms = wait_ms(30);
	assert_true(ms >= 30 && ms < 30 + 15);
	assert_int_equal(re_io_key_look(&real), 1);
	assert_int_equal(re_io_key_look(&real), -1);
	/* a deadline already passed: no look */
	io.ops->sleep_until(io.ud, base_now_ns() - BASE_NS_PER_MS);
	assert_int_equal(re_io_key_look(&real), -1);
	/* the keyboard not watched: never looked at */
	real.watch_key = 0;
	wait_ms(5);
	assert_int_equal(re_io_key_look(&real), -1);
	close(pfd[0]);
	close(pfd[1]);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_deferred_until_flush, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_overflow_said, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_fault_flushes_first, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_not_deferred, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_look, setup, teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
