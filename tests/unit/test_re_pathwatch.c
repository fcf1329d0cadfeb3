/*
 * test_re_pathwatch.c - inotify watches on a path, its links and its node,
 * in a temporary directory (ordinary files stand in for device nodes).
 *
 * Covered: a change of the link, of the node, of the directory holding the
 * link is reported; the traffic of unrelated files in the same directories
 * is not; chains of links; limits and failures; a watch that watches
 * nothing answers "changed" (its caller then stat()s every time).
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
#include <unistd.h>

#include <cmocka.h>

#include "gl_err.h"
#include "re_pathwatch.h"

struct fix {
	char dir[64];
	char node[128], link[128], other[128], sub[128];
	struct re_pathwatch pw;
};

static void touch(const char *path)
{
	int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);

	assert_true(fd >= 0);
	close(fd);
}

static int setup(void **state)
{
	struct fix *f = calloc(1, sizeof(*f));

	assert_non_null(f);
	strcpy(f->dir, "/tmp/h4pw.XXXXXX");
	assert_non_null(mkdtemp(f->dir));
	snprintf(f->node, sizeof(f->node), "%s/node", f->dir);
	snprintf(f->link, sizeof(f->link), "%s/link", f->dir);
	snprintf(f->other, sizeof(f->other), "%s/other", f->dir);
	snprintf(f->sub, sizeof(f->sub), "%s/sub", f->dir);
	touch(f->node);
	assert_int_equal(symlink("node", f->link), 0); /* relative */
	re_pathwatch_init(&f->pw);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	struct fix *f = *state;
	char cmd[160];

	re_pathwatch_close(&f->pw);
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", f->dir);
	assert_int_equal(system(cmd), 0);
	free(f);
	return 0;
}

/* Watching nothing: always "changed"; close is idempotent. */
static void test_pw_not_watching(void **state)
{
	struct fix *f = *state;

	assert_int_equal(f->pw.fd, -1);
	assert_int_equal(re_pathwatch_changed(&f->pw), 1);
	re_pathwatch_close(&f->pw);
	re_pathwatch_close(&f->pw);
	assert_int_equal(re_pathwatch_changed(&f->pw), 1);
}

/* Through a relative link: 2 entries and the node; quiet until the node's
 * mode changes. Unrelated files in the directory are not reported. */
static void test_pw_link_and_node(void **state)
{
	struct fix *f = *state;

	assert_int_equal(re_pathwatch_open(&f->pw, f->link), GL_OK);
	assert_int_equal(f->pw.n, 3);
	assert_string_equal(f->pw.w[0].name, "link");
	assert_string_equal(f->pw.w[1].name, "node");
	assert_string_equal(f->pw.w[2].name, "");
	assert_int_equal(re_pathwatch_changed(&f->pw), 0);
	touch(f->other); /* created, written, closed */
	assert_int_equal(rename(f->other, f->sub), 0);
	assert_int_equal(unlink(f->sub), 0);
	assert_int_equal(re_pathwatch_changed(&f->pw), 0);
	assert_int_equal(chmod(f->node, 0600), 0);
	assert_int_equal(re_pathwatch_changed(&f->pw), 1);
	assert_int_equal(re_pathwatch_changed(&f->pw), 0); /* consumed */
}

/* The link replaced by rename (as galil-sim and the tests do). */
static void test_pw_link_retargeted(void **state)
{
	struct fix *f = *state;

	assert_int_equal(re_pathwatch_open(&f->pw, f->link), GL_OK);
	touch(f->other);
	assert_int_equal(symlink("other", f->sub), 0);
	assert_int_equal(re_pathwatch_changed(&f->pw), 0);
	assert_int_equal(rename(f->sub, f->link), 0);
	assert_int_equal(re_pathwatch_changed(&f->pw), 1);
}

/* The node removed; the directory holding the path moved. */
static void test_pw_node_gone_dir_moved(void **state)
{
	struct fix *f = *state;
	char moved[96];

	assert_int_equal(re_pathwatch_open(&f->pw, f->node), GL_OK);
	assert_int_equal(f->pw.n, 2);
	assert_int_equal(unlink(f->node), 0);
	assert_int_equal(re_pathwatch_changed(&f->pw), 1);
	touch(f->node);
	assert_int_equal(re_pathwatch_open(&f->pw, f->node), GL_OK);
	assert_int_equal(re_pathwatch_changed(&f->pw), 0);
	snprintf(moved, sizeof(moved), "%s.moved", f->dir);
	assert_int_equal(rename(f->dir, moved), 0);
	assert_int_equal(re_pathwatch_changed(&f->pw), 1);
	assert_int_equal(rename(moved, f->dir), 0);
}

/* Limits: a chain of RE_PATHWATCH_LINKS links is watched, one more is
 * refused; a missing path is a system error; both leave nothing open. */
static void test_pw_limits(void **state)
{
	struct fix *f = *state;
	char name[160], target[16];
	int i;

	for (i = 1; i <= RE_PATHWATCH_LINKS; i++) {
		snprintf(name, sizeof(name), "%s/l%d", f->dir, i);
		snprintf(target, sizeof(target), i == 1 ? "node" : "l%d",
			 i - 1);
		assert_int_equal(symlink(target, name), 0);
	}
	assert_int_equal(re_pathwatch_open(&f->pw, name), GL_OK);
	assert_int_equal(f->pw.n, RE_PATHWATCH_LINKS + 2);
	snprintf(name, sizeof(name), "%s/l%d", f->dir, i);
	snprintf(target, sizeof(target), "l%d", i - 1);
	assert_int_equal(symlink(target, name), 0);
	assert_int_equal(re_pathwatch_open(&f->pw, name), GL_ERR_OVERFLOW);
	assert_int_equal(f->pw.fd, -1);
	assert_int_equal(re_pathwatch_changed(&f->pw), 1);
	snprintf(name, sizeof(name), "%s/none", f->dir);
	errno = 0;
	assert_int_equal(re_pathwatch_open(&f->pw, name), GL_ERR_SYS);
	assert_int_equal(errno, ENOENT);
	assert_int_equal(f->pw.fd, -1);
}

#define T(fn) cmocka_unit_test_setup_teardown(fn, setup, teardown)

int main(void)
{
	static const struct CMUnitTest tests[] = {
	    T(test_pw_not_watching),	T(test_pw_link_and_node),
	    T(test_pw_link_retargeted), T(test_pw_node_gone_dir_moved),
	    T(test_pw_limits),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
