/*
 * test_base_yaml.c - the shared libyaml pieces (base_yaml).
 *
 * Covered: a document loaded, an empty stream (no root), a syntax error
 * (position and libyaml's texts), an encoding error (position from the byte
 * offset), a second document refused only with BASE_YAML_ONE_DOC; the
 * "FILE:LINE:COLUMN: " prefix and its variants; scalar text; keys that are
 * not scalars or repeat; numbers and booleans, good and bad.
 */
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "base_yaml.h"

static int load(const char *text, int flags, yaml_document_t *doc,
		struct base_yaml_error *e)
{
	return base_yaml_load(text, strlen(text), flags, doc, e);
}

static void test_load_ok(void **state)
{
	yaml_document_t doc;
	struct base_yaml_error e;
	yaml_node_t *root;

	(void)state;
	assert_int_equal(load("a: 1\nb: [x]\n", BASE_YAML_ONE_DOC, &doc, &e),
			 0);
	root = yaml_document_get_root_node(&doc);
	assert_non_null(root);
	assert_int_equal(root->type, YAML_MAPPING_NODE);
	yaml_document_delete(&doc);
	assert_int_equal(load("", BASE_YAML_ONE_DOC, &doc, &e), 0);
	assert_null(yaml_document_get_root_node(&doc));
	yaml_document_delete(&doc);
	/* without the flag a second document is not even parsed */
	assert_int_equal(load("a: 1\n---\nb: [\n", 0, &doc, &e), 0);
	yaml_document_delete(&doc);
}

static void test_load_errors(void **state)
{
	yaml_document_t doc;
	struct base_yaml_error e;

	(void)state;
	assert_int_equal(load("a: 1\nb: [1, 2\n", 0, &doc, &e), -EBADMSG);
	assert_int_equal(e.type, YAML_PARSER_ERROR);
	assert_non_null(e.problem);
	assert_non_null(e.context);
	assert_int_equal(e.context_mark.line, 1);
	assert_int_equal(e.context_mark.column, 3);
	assert_int_equal(load("a: 1\nb: \xff\n", 0, &doc, &e), -EBADMSG);
	assert_int_equal(e.type, YAML_READER_ERROR);
	assert_int_equal(e.mark.line, 1);
	assert_int_equal(e.mark.column, 3);
	assert_int_equal(e.mark.index, 8);
	assert_int_equal(load("a: 1\n---\nb: 2\n", BASE_YAML_ONE_DOC, &doc, &e),
			 BASE_YAML_EMORE);
	assert_int_equal(e.type, YAML_NO_ERROR);
	assert_string_equal(e.problem, "only one document is allowed");
	assert_int_equal(e.mark.line, 1);
	assert_int_equal(load("a: 1\n---\nb: [\n", BASE_YAML_ONE_DOC, &doc, &e),
			 -EBADMSG);
}

static void fmt(char *err, size_t n, const char *file, const yaml_mark_t *m,
		const char *f, ...) __attribute__((format(printf, 5, 6)));
static void fmt(char *err, size_t n, const char *file, const yaml_mark_t *m,
		const char *f, ...)
{
	va_list ap;

	va_start(ap, f);
	base_yaml_vformat(err, n, file, m, f, ap);
	va_end(ap);
}

static void test_vformat(void **state)
{
	yaml_mark_t m = {10, 2, 4};
	char err[64];

	(void)state;
	fmt(err, sizeof(err), "c.yaml", &m, "bad '%s'", "x");
	assert_string_equal(err, "c.yaml:3:5: bad 'x'");
	fmt(err, sizeof(err), "c.yaml", NULL, "bad");
	assert_string_equal(err, "c.yaml: bad");
	fmt(err, sizeof(err), NULL, &m, "bad");
	assert_string_equal(err, "bad");
	fmt(err, 8, "c.yaml", &m, "bad");
	assert_string_equal(err, "c.yaml:");
	fmt(NULL, 0, "c.yaml", &m, "bad");
}

static void test_keys_and_scalars(void **state)
{
	yaml_document_t doc;
	struct base_yaml_error e;
	yaml_node_t *root, *k;
	yaml_node_pair_t *p;

	(void)state;
	assert_int_equal(load("a: 1\n[x]: 2\nb: 3\na: 4\n", 0, &doc, &e), 0);
	root = yaml_document_get_root_node(&doc);
	p = root->data.mapping.pairs.start;
	assert_int_equal(base_yaml_key(&doc, root, &p[0], &k), 0);
	assert_string_equal(base_yaml_scalar(k), "a");
	assert_int_equal(base_yaml_key(&doc, root, &p[1], &k), -EINVAL);
	assert_non_null(k);
	assert_int_equal(k->type, YAML_SEQUENCE_NODE);
	assert_null(base_yaml_scalar(k));
	assert_int_equal(base_yaml_key(&doc, root, &p[2], &k), 0);
	assert_int_equal(base_yaml_key(&doc, root, &p[3], &k), -EEXIST);
	assert_string_equal(base_yaml_scalar(k), "a");
	assert_int_equal(k->start_mark.line, 3);
	assert_null(base_yaml_scalar(NULL));
	yaml_document_delete(&doc);
}

/* The value of the only key of a one-line mapping "k: TEXT". */
static yaml_node_t *value_of(yaml_document_t *doc, const char *text)
{
	struct base_yaml_error e;
	yaml_node_t *root;

	assert_int_equal(load(text, 0, doc, &e), 0);
	root = yaml_document_get_root_node(doc);
	return yaml_document_get_node(doc,
				      root->data.mapping.pairs.start->value);
}

static void test_numbers(void **state)
{
	static const struct {
		const char *text;
		int lrc, drc;
		long l;
		double d;
	} cases[] = {
	    {"k: 42", 0, 0, 42, 42},
	    {"k: -7", 0, 0, -7, -7},
	    {"k: +3", 0, 0, 3, 3},
	    {"k: 2.5", -EINVAL, 0, 0, 2.5},
	    {"k: 1e3", -EINVAL, 0, 0, 1000},
	    {"k: '12'", 0, 0, 12, 12},
	    {"k: abc", -EINVAL, -EINVAL, 0, 0},
	    {"k: 12x", -EINVAL, -EINVAL, 0, 0},
	    {"k:", -EINVAL, -EINVAL, 0, 0},
	    {"k: [1]", -EINVAL, -EINVAL, 0, 0},
	    {"k: 99999999999999999999", -ERANGE, 0, 0, 1e20},
	    {"k: 1e999", -EINVAL, -ERANGE, 0, 0},
	    {"k: inf", -EINVAL, -ERANGE, 0, 0},
	};
	yaml_document_t doc;
	yaml_node_t *v;
	size_t i;
	long l;
	double d;

	(void)state;
	for (i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		v = value_of(&doc, cases[i].text);
		l = -1;
		d = -1;
		assert_int_equal(base_yaml_long(v, &l), cases[i].lrc);
		assert_int_equal(base_yaml_double(v, &d), cases[i].drc);
		assert_int_equal(l, cases[i].lrc ? -1 : cases[i].l);
		assert_true(d == (cases[i].drc ? -1 : cases[i].d));
		yaml_document_delete(&doc);
	}
	assert_int_equal(base_yaml_long(NULL, &l), -EINVAL);
	assert_int_equal(base_yaml_double(NULL, &d), -EINVAL);
}

static void test_bools(void **state)
{
	yaml_document_t doc;
	yaml_node_t *v;
	bool b = false;

	(void)state;
	v = value_of(&doc, "k: true");
	assert_int_equal(base_yaml_bool(v, &b), 0);
	assert_true(b);
	yaml_document_delete(&doc);
	v = value_of(&doc, "k: false");
	assert_int_equal(base_yaml_bool(v, &b), 0);
	assert_false(b);
	yaml_document_delete(&doc);
	v = value_of(&doc, "k: yes");
	b = true;
	assert_int_equal(base_yaml_bool(v, &b), -EINVAL);
	assert_true(b);
	yaml_document_delete(&doc);
	assert_int_equal(base_yaml_bool(NULL, &b), -EINVAL);
}

int main(void)
{
	static const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_load_ok),
	    cmocka_unit_test(test_load_errors),
	    cmocka_unit_test(test_vformat),
	    cmocka_unit_test(test_keys_and_scalars),
	    cmocka_unit_test(test_numbers),
	    cmocka_unit_test(test_bools),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
