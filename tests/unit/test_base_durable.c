/*
 * test_base_durable.c - durable file writing (base_durable).
 *
 * Covered: a new file and a replaced one hold exactly the new bytes, with
 * the mode asked for, and no temporary file is left; an empty write; a
 * missing directory (nothing created); a target that cannot be replaced
 * (a non-empty directory: the temporary file is removed, the target
 * untouched); base_fsync_dir() on "name", "dir/name", "/name" and a
 * missing directory; base_write_all() on a pipe; NULL arguments.
 */
#include <errno.h>
#include <fcntl.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_durable.h"
#include "base_file.h"

struct fix {
	char dir[64];
	char path[96], tmp[104], sub[96], subfile[104];
};

static int setup(void **state)
{
	struct fix *f = calloc(1, sizeof(*f));

	if (!f)
		return -1;
	snprintf(f->dir, sizeof(f->dir), "/tmp/test_base_durable.XXXXXX");
	if (!mkdtemp(f->dir)) {
		free(f);
		return -1;
	}
	snprintf(f->path, sizeof(f->path), "%s/f", f->dir);
	snprintf(f->tmp, sizeof(f->tmp), "%s.tmp", f->path);
	snprintf(f->sub, sizeof(f->sub), "%s/d", f->dir);
	snprintf(f->subfile, sizeof(f->subfile), "%s/x", f->sub);
	*state = f;
	umask(022);
	return 0;
}

static int teardown(void **state)
{
	struct fix *f = *state;

	unlink(f->subfile);
	rmdir(f->sub);
	unlink(f->tmp);
	unlink(f->path);
	rmdir(f->dir);
	free(f);
	return 0;
}

static void expect_file(const char *path, const char *text, size_t n)
{
	char *buf = NULL;
	size_t len = 0;

	assert_int_equal(base_file_read(path, 1000, &buf, &len), 0);
	assert_int_equal(len, n);
	assert_memory_equal(buf, text, n);
	free(buf);
}

static void test_write_new_and_replace(void **state)
{
	struct fix *f = *state;
	struct stat st;

	assert_int_equal(base_durable_write(f->path, "first\n", 6, 0640), 0);
	expect_file(f->path, "first\n", 6);
	assert_int_equal(stat(f->path, &st), 0);
	assert_int_equal(st.st_mode & 0777, 0640);
	assert_int_equal(access(f->tmp, F_OK), -1);
	assert_int_equal(base_durable_write(f->path, "2", 1, 0644), 0);
	expect_file(f->path, "2", 1);
	assert_int_equal(access(f->tmp, F_OK), -1);
	assert_int_equal(base_durable_write(f->path, NULL, 0, 0644), 0);
	expect_file(f->path, "", 0);
}

static void test_write_errors(void **state)
{
	struct fix *f = *state;
	char missing[128];

	snprintf(missing, sizeof(missing), "%s/none/f", f->dir);
	assert_int_equal(base_durable_write(missing, "x", 1, 0644), -ENOENT);
	assert_int_equal(errno, ENOENT);
	/* a non-empty directory cannot be replaced by a file */
	assert_int_equal(mkdir(f->sub, 0755), 0);
	assert_int_equal(base_durable_write(f->subfile, "x", 1, 0644), 0);
	snprintf(f->tmp, sizeof(f->tmp), "%s.tmp", f->sub);
	assert_true(base_durable_write(f->sub, "y", 1, 0644) < 0);
	assert_int_equal(access(f->tmp, F_OK), -1);
	expect_file(f->subfile, "x", 1);
	assert_int_equal(base_durable_write(NULL, "x", 1, 0644), -EFAULT);
	assert_int_equal(base_durable_write(f->path, NULL, 1, 0644), -EFAULT);
	assert_int_equal(access(f->path, F_OK), -1);
}

static void test_write_long_name(void **state)
{
	char name[4200];

	(void)state;
	memset(name, 'a', sizeof(name) - 1);
	name[sizeof(name) - 1] = '\0';
	assert_int_equal(base_durable_write(name, "x", 1, 0644), -ENAMETOOLONG);
	assert_int_equal(base_fsync_dir(name), 0); /* a bare name: "." */
}

static void test_fsync_dir(void **state)
{
	struct fix *f = *state;
	char missing[128];

	assert_int_equal(base_fsync_dir(f->path), 0);
	assert_int_equal(base_fsync_dir("plain-name"), 0);
	assert_int_equal(base_fsync_dir("/anything"), 0);
	snprintf(missing, sizeof(missing), "%s/none/f", f->dir);
	assert_int_equal(base_fsync_dir(missing), -ENOENT);
	assert_int_equal(errno, ENOENT);
	assert_int_equal(base_fsync_dir(NULL), -EFAULT);
}

static void test_write_all(void **state)
{
	char big[100000], back[100000];
	int p[2], status;
	size_t got = 0;
	pid_t pid;
	ssize_t n;

	(void)state;
	memset(big, 'z', sizeof(big));
	assert_int_equal(pipe(p), 0);
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		close(p[0]);
		_exit(base_write_all(p[1], big, sizeof(big)) == 0 ? 0 : 1);
	}
	close(p[1]);
	while ((n = read(p[0], back + got, sizeof(back) - got)) > 0)
		got += (size_t)n;
	close(p[0]);
	assert_int_equal(waitpid(pid, &status, 0), pid);
	assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
	assert_int_equal(got, sizeof(big));
	assert_memory_equal(back, big, sizeof(big));
	assert_int_equal(base_write_all(-1, "x", 1), -EBADF);
}

int main(void)
{
	static const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_write_new_and_replace, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_write_errors, setup, teardown),
	    cmocka_unit_test(test_write_long_name),
	    cmocka_unit_test_setup_teardown(test_fsync_dir, setup, teardown),
	    cmocka_unit_test(test_write_all),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
