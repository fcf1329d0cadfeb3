/*
 * test_base_file.c - whole-file reading (base_file_read).
 *
 * Covered: a file read whole and NUL-terminated, an empty file, exactly
 * max_bytes and one byte more (-EFBIG), a missing file (-ENOENT), a
 * directory (-EISDIR), a device (-EINVAL), an unreadable file (-EACCES,
 * unless run as root), NULL arguments; outputs untouched on error; errno
 * set to the positive code.
 */
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_file.h"

struct fix {
	char dir[64];
	char path[96];
};

static int setup(void **state)
{
	struct fix *f = calloc(1, sizeof(*f));

	if (!f)
		return -1;
	snprintf(f->dir, sizeof(f->dir), "/tmp/test_base_file.XXXXXX");
	if (!mkdtemp(f->dir)) {
		free(f);
		return -1;
	}
	snprintf(f->path, sizeof(f->path), "%s/f", f->dir);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	struct fix *f = *state;

	unlink(f->path);
	rmdir(f->dir);
	free(f);
	return 0;
}

static void put(const char *path, const char *text, size_t len)
{
	FILE *fp = fopen(path, "wb");

	assert_non_null(fp);
	assert_int_equal(fwrite(text, 1, len, fp), len);
	assert_int_equal(fclose(fp), 0);
}

static void test_read_whole(void **state)
{
	struct fix *f = *state;
	char *buf = NULL;
	size_t len = 99;

	put(f->path, "a: 1\nb\0c", 8);
	assert_int_equal(base_file_read(f->path, 100, &buf, &len), 0);
	assert_int_equal(len, 8);
	assert_memory_equal(buf, "a: 1\nb\0c", 8);
	assert_int_equal(buf[8], '\0');
	free(buf);
	put(f->path, "", 0);
	buf = NULL;
	assert_int_equal(base_file_read(f->path, 100, &buf, &len), 0);
	assert_int_equal(len, 0);
	assert_non_null(buf);
	assert_int_equal(buf[0], '\0');
	free(buf);
}

static void test_read_limit(void **state)
{
	struct fix *f = *state;
	char *buf = NULL, *keep = (char *)state;
	size_t len = 0;

	put(f->path, "0123456789", 10);
	assert_int_equal(base_file_read(f->path, 10, &buf, &len), 0);
	assert_int_equal(len, 10);
	assert_string_equal(buf, "0123456789");
	free(buf);
	buf = keep;
	len = 77;
	assert_int_equal(base_file_read(f->path, 9, &buf, &len), -EFBIG);
	assert_int_equal(errno, EFBIG);
	assert_ptr_equal(buf, keep);
	assert_int_equal(len, 77);
	assert_int_equal(base_file_read(f->path, 0, &buf, &len), -EFBIG);
}

static void test_read_errors(void **state)
{
	struct fix *f = *state;
	char *buf = NULL, missing[128];
	size_t len = 0;

	snprintf(missing, sizeof(missing), "%s/none", f->dir);
	assert_int_equal(base_file_read(missing, 10, &buf, &len), -ENOENT);
	assert_int_equal(errno, ENOENT);
	assert_int_equal(base_file_read(f->dir, 10, &buf, &len), -EISDIR);
	assert_int_equal(errno, EISDIR);
	assert_int_equal(base_file_read("/dev/null", 10, &buf, &len), -EINVAL);
	assert_int_equal(errno, EINVAL);
	assert_null(buf);
	assert_int_equal(base_file_read(NULL, 10, &buf, &len), -EFAULT);
	assert_int_equal(base_file_read(f->path, 10, NULL, &len), -EFAULT);
	assert_int_equal(base_file_read(f->path, 10, &buf, NULL), -EFAULT);
	if (geteuid() != 0) {
		put(f->path, "x", 1);
		assert_int_equal(chmod(f->path, 0), 0);
		assert_int_equal(base_file_read(f->path, 10, &buf, &len),
				 -EACCES);
		assert_null(buf);
	}
}

int main(void)
{
	static const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_read_whole, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_read_limit, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_read_errors, setup, teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
