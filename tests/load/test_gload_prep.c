/*
 * test_gload_prep.c - galil-load's preprocessor: exact output for the good
 * fixtures (one file, and a directory with a MANIFEST and CR LF lines), the
 * stripping rules line by line, the source line kept for each output line,
 * the sizes before and after, and the identity stamp appended.
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
#include "gload_prep.h"

#define GOOD "tests/data/dmc_good/"

/* FNV-1a 64, written out here independently of pc/galil/gl_hash.c. */
static uint64_t fnv(const char *s, size_t n)
{
	uint64_t h = 14695981039346656037ULL;

	while (n--) {
		h ^= (unsigned char)*s++;
		h *= 1099511628211ULL;
	}
	return h;
}

static char *slurp(const char *path)
{
	FILE *f = fopen(path, "rb");
	char *buf = calloc(1, 65536);
	size_t n;

	assert_non_null(f);
	assert_non_null(buf);
	n = fread(buf, 1, 65535, f);
	buf[n] = '\0';
	fclose(f);
	return buf;
}

/* The expected text plus its stamp line. */
static char *stamped(const char *body)
{
	size_t n = strlen(body);
	char *s = malloc(n + 32);

	assert_non_null(s);
	sprintf(s, "%sNO ID %016llX\n", body, (unsigned long long)fnv(body, n));
	return s;
}

/* clean.dmc preprocesses to exactly clean.expected + the stamp. */
static void test_clean_file(void **state)
{
	struct gload_prog p = {0};
	struct gload_diags d = {0};
	char *body = slurp(GOOD "clean.expected"), *want = stamped(body);

	(void)state;
	assert_int_equal(gload_prep_path(&p, GOOD "clean.dmc", &d), GL_OK);
	assert_int_equal(d.n, 0);
	assert_int_equal(gload_prog_finish(&p), GL_OK);
	assert_int_equal(p.text_len, strlen(want));
	assert_memory_equal(p.text, want, p.text_len);
	assert_int_equal(p.body_len, strlen(body));
	assert_true(p.id == fnv(body, strlen(body)));
	/* sizes before (wc -c, wc -l) and after */
	assert_int_equal(p.src_bytes, 685);
	assert_int_equal(p.src_lines, 26);
	assert_int_equal(p.nlines, 18);
	/* where lines came from: "#AUTO" is source line 8, "sum=^a+^b" 25 */
	assert_string_equal(p.lines[1].text, "#AUTO");
	assert_int_equal(p.lines[1].src_line, 8);
	assert_string_equal(p.lines[16].text, "sum=^a+^b");
	assert_int_equal(p.lines[16].src_line, 25);
	assert_true(gload_prog_has_label(&p, "add"));
	assert_true(gload_prog_has_label(&p, "AUTO"));
	assert_false(gload_prog_has_label(&p, "AUT"));
	assert_false(gload_prog_has_label(&p, "auto"));
	gload_prog_free(&p);
	free(body);
	free(want);
}

/* A directory: MANIFEST order, CR LF source, file and line of each line. */
static void test_manifest_dir(void **state)
{
	static const char body[] = "limit=500\nperiod=20\nEN\n#AUTO\n"
				   "x=limit*2\nWT period\nEN\n";
	struct gload_prog p = {0};
	struct gload_diags d = {0};
	char *want = stamped(body);

	(void)state;
	assert_int_equal(gload_prep_path(&p, GOOD "split", &d), GL_OK);
	assert_int_equal(d.n, 0);
	assert_int_equal(gload_prog_finish(&p), GL_OK);
	assert_string_equal(p.text, want);
	assert_int_equal(p.nfiles, 2);
	assert_string_equal(p.files[0], GOOD "split/constants.dmc");
	assert_string_equal(p.files[1], GOOD "split/program.dmc");
	assert_int_equal(p.lines[1].file, 0);
	assert_int_equal(p.lines[1].src_line, 4); /* period=20 */
	assert_int_equal(p.lines[2].file, 1);
	assert_int_equal(p.lines[2].src_line, 2); /* EN */
	assert_int_equal(p.src_lines, 4 + 6);
	gload_prog_free(&p);
	free(want);
}

struct strip_case {
	const char *in;
	const char *out; /* "" = the line is dropped */
};

static const struct strip_case strips[] = {
    {"  x=1  ", "x=1"},
    {"x=1 ; y=2 ;", "x=1;y=2"},
    {"x=1;;y=2", "x=1;;y=2"},
    {"MG \"don't\" ' comment", "MG \"don't\""},
    {"MG \"a ; b\"", "MG \"a ; b\""},
    {"\tIF (x=1)\t' tab", "IF (x=1)"},
    {"MG \"tab\there\"", "MG \"tab\there\""},
    {"#LOOP   ' the loop", "#LOOP"},
    /* a ' in NO text is comment text: the statements after ';' are
     * still sent (and the linter reports them: rule no-semicolon) */
    {"NO it's here", "NO it's here"},
    {"NO it's a note ; ST", "NO it's a note;ST"},
    {"NO say \"hi; x=1", "NO say \"hi;x=1"},
    {"NOTE=\"a'b\"", "NOTE=\"a'b\""},
    {"REM anything 'at all' \"", ""},
    {"   REM indented", ""},
    {"REM", ""},
    {"REMARK=1", "REMARK=1"},
    {"x=1 REM not a comment here", "x=1 REM not a comment here"},
    {";;;", ""},
    {"' only a comment", ""},
    {"   ", ""},
    {"SH A ;  ' motors on", "SH A"},
};

/* Each rule of the preprocessor, one line at a time. */
static void test_strip_rules(void **state)
{
	size_t i;

	(void)state;
	for (i = 0; i < sizeof(strips) / sizeof(strips[0]); i++) {
		struct gload_prog p = {0};
		struct gload_diags d = {0};

		gload_prep_buffer(&p, "t.dmc", strips[i].in,
				  strlen(strips[i].in), &d);
		assert_int_equal(d.n, 0);
		if (strips[i].out[0] == '\0') {
			if (p.nlines != 0)
				fail_msg("'%s' -> '%s', want dropped",
					 strips[i].in, p.lines[0].text);
		} else {
			assert_int_equal(p.nlines, 1);
			if (strcmp(p.lines[0].text, strips[i].out))
				fail_msg("'%s' -> '%s', want '%s'",
					 strips[i].in, p.lines[0].text,
					 strips[i].out);
		}
		gload_prog_free(&p);
	}
}

/* CR, LF and CR LF line ends, and no end on the last line. */
static void test_line_ends(void **state)
{
	static const char src[] = "EN\r#A\r\nx=1\n\ny=2";
	struct gload_prog p = {0};
	struct gload_diags d = {0};

	(void)state;
	gload_prep_buffer(&p, "e.dmc", src, sizeof(src) - 1, &d);
	assert_int_equal(p.nlines, 4);
	assert_string_equal(p.lines[0].text, "EN");
	assert_string_equal(p.lines[1].text, "#A");
	assert_string_equal(p.lines[2].text, "x=1");
	assert_string_equal(p.lines[3].text, "y=2");
	assert_int_equal(p.lines[3].src_line, 5);
	assert_int_equal(p.src_lines, 5);
	assert_int_equal(p.src_bytes, sizeof(src) - 1);
	assert_int_equal(gload_prog_finish(&p), GL_OK);
	assert_memory_equal(p.text, "EN\n#A\nx=1\ny=2\nNO ID ", 20);
	gload_prog_free(&p);
}

/* An unclosed string runs to the end of the line: its ' is no comment
 * and the text is kept (the linter reports it: rule string-open, in
 * test_gload_lint and test_gload_check). */
static void test_open_quote(void **state)
{
	static const char src[] = "EN\n\nMG \"abc ' not a comment\n";
	struct gload_prog p = {0};
	struct gload_diags d = {0};

	(void)state;
	gload_prep_buffer(&p, "q.dmc", src, sizeof(src) - 1, &d);
	assert_int_equal(d.n, 0);
	assert_string_equal(p.lines[1].text, "MG \"abc ' not a comment");
	gload_diags_free(&d);
	gload_prog_free(&p);
}

/* MANIFEST: names, comments, blanks, spaces, CR LF, line numbers. */
static void test_manifest_parse(void **state)
{
	static const char m[] = "# comment\n a.dmc \n\nb.dmc # x\r\n#\n"
				"c d.dmc";
	char **names = NULL;
	int *lines = NULL, n, i;

	(void)state;
	n = gload_manifest_parse(m, sizeof(m) - 1, &names, &lines);
	assert_int_equal(n, 3);
	assert_string_equal(names[0], "a.dmc");
	assert_string_equal(names[1], "b.dmc");
	assert_string_equal(names[2], "c d.dmc");
	assert_int_equal(lines[0], 2);
	assert_int_equal(lines[1], 4);
	assert_int_equal(lines[2], 6);
	for (i = 0; i < n; i++)
		free(names[i]);
	free(names);
	free(lines);
	assert_int_equal(gload_manifest_parse("# only\n\n", 8, &names, &lines),
			 0);
	free(names);
	free(lines);
}

/* Missing files: the message names the file and the reason. */
static void test_missing(void **state)
{
	struct gload_prog p = {0};
	struct gload_diags d = {0};

	(void)state;
	assert_int_equal(gload_prep_path(&p, "tests/data/no-such.dmc", &d),
			 GL_ERR_NOENT);
	assert_int_equal(d.n, 1);
	assert_string_equal(d.v[0].text,
			    "tests/data/no-such.dmc: cannot open "
			    "'tests/data/no-such.dmc': No such file or "
			    "directory");
	gload_diags_free(&d);
	assert_int_equal(gload_prep_path(&p, "tests/data", &d), GL_ERR_NOENT);
	assert_string_equal(d.v[0].text,
			    "tests/data: cannot open 'tests/data/MANIFEST': No "
			    "such file or directory");
	gload_diags_free(&d);
	gload_prog_free(&p);
}

/* A file above GLOAD_FILE_MAX is refused, not read into memory. */
static void test_too_large(void **state)
{
	char path[] = "/tmp/gload_bigXXXXXX", want[128];
	struct gload_prog p = {0};
	struct gload_diags d = {0};
	int fd = mkstemp(path);

	(void)state;
	assert_true(fd >= 0);
	assert_int_equal(ftruncate(fd, GLOAD_FILE_MAX + 1), 0);
	close(fd);
	assert_int_equal(gload_prep_path(&p, path, &d), GL_ERR_NOENT);
	snprintf(want, sizeof(want), "%s: cannot open '%s': File too large",
		 path, path);
	assert_int_equal(d.n, 1);
	assert_string_equal(d.v[0].text, want);
	unlink(path);
	gload_diags_free(&d);
	gload_prog_free(&p);
}

/* Several files join in order; the stamp covers all of them. */
static void test_join_files(void **state)
{
	struct gload_prog p = {0};
	struct gload_diags d = {0};

	(void)state;
	gload_prep_buffer(&p, "c.dmc", "k=1 ' const\n", 12, &d);
	gload_prep_buffer(&p, "p.dmc", "EN\n#AUTO\nx=k\n", 13, &d);
	assert_int_equal(gload_prog_finish(&p), GL_OK);
	assert_int_equal(p.nlines, 4);
	assert_int_equal(p.lines[0].file, 0);
	assert_int_equal(p.lines[3].file, 1);
	assert_int_equal(p.lines[3].src_line, 3);
	assert_true(p.id == fnv("k=1\nEN\n#AUTO\nx=k\n", 17));
	gload_prog_free(&p);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_clean_file),
	    cmocka_unit_test(test_manifest_dir),
	    cmocka_unit_test(test_strip_rules),
	    cmocka_unit_test(test_line_ends),
	    cmocka_unit_test(test_open_quote),
	    cmocka_unit_test(test_manifest_parse),
	    cmocka_unit_test(test_missing),
	    cmocka_unit_test(test_join_files),
	    cmocka_unit_test(test_too_large),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
