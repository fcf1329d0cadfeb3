/*
 * fuzz_gload.c - libFuzzer target: galil-load's preprocessor and checker
 * (gload_prep_buffer(), gload_check(), gload_prog_finish()), the DMC
 * linter on unprocessed text (dmc_lint_text(), as the DMC tests use it)
 * and the MANIFEST reader (gload_manifest_parse()).
 *
 * Input: [0] the model (40x0, 41x3, 21x3, 30010), then the DMC source
 * (also read as a MANIFEST).
 */
#include <stdint.h>
#include <stddef.h>
#include <string.h>
#include <stdlib.h>
#include "dmc_lint.h"
#include "dmc_model.h"
#include "gl_err.h"
#include "gload_check.h"
#include "gload_diag.h"
#include "gload_prep.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char *const models[4] = {"40x0", "41x3", "21x3", "30010"};

static void manifest(const char *buf, size_t len)
{
	char **names = NULL;
	int *lines = NULL, n, i;

	n = gload_manifest_parse(buf, len, &names, &lines);
	for (i = 0; i < n; i++)
		free(names[i]);
	free(names);
	free(lines);
}

static void prep_check(const char *buf, size_t len, const struct dmc_model *m)
{
	struct gload_prog p;
	struct gload_diags d;
	struct gload_stats st;

	memset(&p, 0, sizeof(p));
	memset(&d, 0, sizeof(d));
	if (gload_prep_buffer(&p, "fuzz.dmc", buf, len, &d) == GL_OK &&
	    gload_check(&p, m, &d, &st) >= 0 &&
	    gload_prog_finish(&p) == GL_OK) {
		if (p.text_len < p.body_len || p.text[p.text_len] != '\0')
			abort();
		(void)gload_prog_has_label(&p, "AUTO");
	}
	gload_diags_sort(&d);
	gload_diags_free(&d);
	gload_prog_free(&p);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	const struct dmc_model *m;
	const char *buf = (const char *)data + 1;
	struct dmc_lint lint;

	if (size < 1)
		return 0;
	m = dmc_model_find(models[data[0] & 3]);
	if (!m)
		abort();
	size--;
	manifest(buf, size);
	prep_check(buf, size, m);
	memset(&lint, 0, sizeof(lint));
	(void)dmc_lint_text(size ? buf : NULL, size, m, 1, &lint);
	dmc_lint_free(&lint);
	return 0;
}
