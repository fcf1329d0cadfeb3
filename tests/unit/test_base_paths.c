/*
 * test_base_paths.c - the installed places and absolute names
 * (base_paths.h).
 *
 * Covered: base_paths_absolute() with exact strings: an absolute name kept,
 * a relative one joined to the working directory, leading "./" dropped,
 * "." alone, the root directory and a trailing slash (no "//"), "" kept,
 * ".." left alone, a relative working directory refused, the exact size
 * limit (fits, one byte short: "" and -1); base_paths_data() and
 * base_paths_sysconf() under ROBOELF_ROOT and without it.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "base_paths.h"

/* base_paths_absolute() into a 256-byte buffer; the return checked. */
static const char *absolute(const char *cwd, const char *path, int want_rc)
{
	static char out[256];

	assert_int_equal(base_paths_absolute(cwd, path, out, sizeof(out)),
			 want_rc);
	return out;
}

static void test_absolute_joins(void **state)
{
	(void)state;
	assert_string_equal(absolute("/home/op", "roboelf.log", 0),
			    "/home/op/roboelf.log");
	assert_string_equal(absolute("/home/op", "logs/roboelf.log", 0),
			    "/home/op/logs/roboelf.log");
	assert_string_equal(
	    absolute("/home/op", "/var/log/roboelf/roboelf.log", 0),
	    "/var/log/roboelf/roboelf.log");
	assert_string_equal(absolute("/home/op", "./roboelf.log", 0),
			    "/home/op/roboelf.log");
	assert_string_equal(absolute("/home/op", "././/cal.txt", 0),
			    "/home/op/cal.txt");
	assert_string_equal(absolute("/home/op", ".", 0), "/home/op");
	assert_string_equal(absolute("/home/op", "./", 0), "/home/op");
	assert_string_equal(absolute("/home/op/", "x", 0), "/home/op/x");
	assert_string_equal(absolute("/", "roboelf.log", 0), "/roboelf.log");
	assert_string_equal(absolute("/", ".", 0), "/");
	assert_string_equal(absolute("/home/op", "../x/cal.txt", 0),
			    "/home/op/../x/cal.txt");
	assert_string_equal(absolute("/home/op", ".hidden", 0),
			    "/home/op/.hidden");
	assert_string_equal(absolute("/home/op", "", 0), "");
	assert_string_equal(absolute("", "/abs", 0), "/abs");
}

static void test_absolute_refused(void **state)
{
	char out[16];

	(void)state;
	assert_string_equal(absolute("", "roboelf.log", -1), "");
	assert_string_equal(absolute("home/op", "roboelf.log", -1), "");
	/* "/abcdefg/ghijkl": 15 bytes and the NUL fill the 16; one more
	 * byte does not fit */
	assert_int_equal(base_paths_absolute("/abcdefg", "ghijkl", out, 16), 0);
	assert_string_equal(out, "/abcdefg/ghijkl");
	assert_int_equal(base_paths_absolute("/abcdefgh", "ghijkl", out, 16),
			 -1);
	assert_string_equal(out, "");
	assert_int_equal(
	    base_paths_absolute("/x", "/abcdefghijklmnop", out, sizeof(out)),
	    -1);
	assert_string_equal(out, "");
}

static void test_installed_places(void **state)
{
	char out[256];

	(void)state;
	assert_int_equal(unsetenv(BASE_PATHS_ROOT_ENV), 0);
	assert_null(base_paths_root());
	assert_int_equal(
	    base_paths_sysconf("roboelf/roboelf.yaml", out, sizeof(out)), 0);
	assert_string_equal(out, "/etc/roboelf/roboelf.yaml");
	assert_int_equal(setenv(BASE_PATHS_ROOT_ENV, "/stage", 1), 0);
	assert_string_equal(base_paths_root(), "/stage");
	assert_int_equal(
	    base_paths_sysconf("roboelf/roboelf.yaml", out, sizeof(out)), 0);
	assert_string_equal(out, "/stage/etc/roboelf/roboelf.yaml");
	assert_int_equal(base_paths_data("", out, sizeof(out)), 0);
	assert_int_equal(strncmp(out, "/stage/", 7), 0);
	assert_int_equal(out[strlen(out) - 1] != '/', 1);
	assert_int_equal(base_paths_sysconf("roboelf/roboelf.yaml", out, 10),
			 -1);
	assert_string_equal(out, "");
	assert_int_equal(setenv(BASE_PATHS_ROOT_ENV, "", 1), 0);
	assert_null(base_paths_root());
	assert_int_equal(unsetenv(BASE_PATHS_ROOT_ENV), 0);
}

int main(void)
{
	static const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_absolute_joins),
	    cmocka_unit_test(test_absolute_refused),
	    cmocka_unit_test(test_installed_places),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
