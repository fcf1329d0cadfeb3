/*
 * test_re_calshow.c - roboelf-tech show-calibration: the printed tables and the
 * gnuplot PNG per axis (gnuplot-nox is a declared dependency: `make deps`),
 * and a corrupt file refused with the loader's message.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "gl_err.h"
#include "re_calfile.h"
#include "re_calshow.h"

struct fx {
	char dir[64];
	char path[128];
};

static int setup(void **state)
{
	static struct fx f;

	snprintf(f.dir, sizeof(f.dir), "/tmp/roboelf-calshow.XXXXXX");
	if (!mkdtemp(f.dir))
		return -1;
	snprintf(f.path, sizeof(f.path), "%s/cal.txt", f.dir);
	*state = &f;
	return 0;
}

static int teardown(void **state)
{
	struct fx *f = *state;
	char cmd[160];

	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", f->dir);
	return system(cmd) == 0 ? 0 : -1;
}

/* Three axes of 11 points, 0.5 V to 4.5 V over -5000..5000 counts. */
static void make_set(struct re_calset *s)
{
	static const char *names[] = {"A", "B", "C"};

	memset(s, 0, sizeof(*s));
	s->n_axes = 3;
	snprintf(s->serial, sizeof(s->serial), "4242");
	s->config_hash = 0x1234abcdULL;
	snprintf(s->date, sizeof(s->date), "2026-11-22T12:00:00Z");
	for (int a = 0; a < 3; a++) {
		struct re_caltable *t = &s->axis[a];

		snprintf(s->name[a], sizeof(s->name[a]), "%s", names[a]);
		t->n = 11;
		t->start_counts = -5000;
		t->step_counts = 1000;
		for (int i = 0; i < t->n; i++)
			t->pot_v[i] = 0.5 + 0.4 * i;
		t->soft_rev = -5000;
		t->soft_fwd = 5000;
	}
}

static size_t slurp(FILE *f, char *buf, size_t cap)
{
	size_t n;

	rewind(f);
	n = fread(buf, 1, cap - 1, f);
	buf[n] = '\0';
	return n;
}

/* The header, each axis's table rows, and one real PNG per axis. */
static void test_show_tables_and_plots(void **state)
{
	struct fx *f = *state;
	static struct re_calset s;
	static char text[65536];
	const double allowed[3] = {0.5, 0.5, 0.5};
	char err[256], png[256];
	unsigned char magic[8];
	FILE *out = tmpfile(), *errf = tmpfile(), *p;

	assert_non_null(out);
	assert_non_null(errf);
	make_set(&s);
	assert_int_equal(re_calfile_save(f->path, &s, err, sizeof(err)), GL_OK);
	assert_int_equal(re_calshow_print(f->path, allowed, 3, out, errf),
			 GL_OK);
	slurp(out, text, sizeof(text));
	assert_non_null(strstr(text, "controller serial 4242"));
	assert_non_null(strstr(text, "config hash 000000001234ABCD, 3 axes"));
	/* point 10 of each axis: encoder 5000, 4.5 V */
	assert_non_null(strstr(text, "     10      5000   4.5000"));
	assert_null(strstr(text, "gnuplot not installed"));
	for (int a = 0; a < 3; a++) {
		snprintf(png, sizeof(png), "%s-%c.png", f->path, 'A' + a);
		p = fopen(png, "rb");
		if (!p)
			fail_msg("no plot '%s' (is gnuplot-nox installed? "
				 "make deps)",
				 png);
		assert_int_equal(fread(magic, 1, 8, p), 8);
		fclose(p);
		assert_memory_equal(magic, "\x89PNG\r\n\x1a\n", 8);
	}
	slurp(errf, text, sizeof(text));
	assert_string_equal(text, "");
	fclose(out);
	fclose(errf);
}

/* A corrupt file: refused with the loader's message, nothing printed. */
static void test_show_corrupt(void **state)
{
	struct fx *f = *state;
	static char text[4096];
	FILE *out = tmpfile(), *errf = tmpfile(), *w;

	assert_non_null(out);
	assert_non_null(errf);
	w = fopen(f->path, "w");
	assert_non_null(w);
	fputs("roboelf-calibration 1\nnonsense\n", w);
	fclose(w);
	assert_true(re_calshow_print(f->path, NULL, 0, out, errf) < 0);
	slurp(out, text, sizeof(text));
	assert_string_equal(text, "");
	slurp(errf, text, sizeof(text));
	assert_non_null(strstr(text, "roboelf-tech: error: "));
	assert_non_null(strstr(text, "cal.txt"));
	fclose(out);
	fclose(errf);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_show_tables_and_plots, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_show_corrupt, setup, teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
