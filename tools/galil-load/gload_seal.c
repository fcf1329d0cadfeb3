/*
 * gload_seal.c - the seal from the configuration. See gload_seal.h.
 */
#include "gload_seal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base_paths.h"
#include "gl_err.h"
#include "re_config.h"
#include "re_seal.h"
#include "re_sealmake.h"

#define SOURCE_CONFIG "config/roboelf.yaml"
#define SYSTEM_CONFIG "roboelf/roboelf.yaml"

int gload_seal_find_config(char *out, size_t len)
{
	if (access(SOURCE_CONFIG, F_OK) == 0) {
		snprintf(out, len, "%s", SOURCE_CONFIG);
		return 0;
	}
	if (base_paths_sysconf(SYSTEM_CONFIG, out, len) < 0)
		return -1;
	return access(out, F_OK) == 0 ? 0 : -1;
}

/* The program read so far, each line ending with LF. */
static char *body_text(const struct gload_prog *p, size_t *len)
{
	size_t n = 0, o = 0;
	char *t;

	for (int i = 0; i < p->nlines; i++)
		n += p->lines[i].len + 1;
	t = malloc(n + 1);
	if (!t)
		return NULL;
	for (int i = 0; i < p->nlines; i++) {
		memcpy(t + o, p->lines[i].text, p->lines[i].len);
		o += p->lines[i].len;
		t[o++] = '\n';
	}
	t[o] = '\0';
	*len = o;
	return t;
}

int gload_seal_append(struct gload_prog *p, const char *config, int *nitems,
		      char *err, size_t errlen)
{
	struct re_config *cfg = malloc(sizeof(*cfg));
	struct re_seal *s = malloc(sizeof(*s));
	char *text = malloc(RE_SEAL_TEXT_MAX), *body = NULL, name[300];
	struct gload_diags d = {0};
	size_t blen = 0;
	int rc = GL_ERR_NOMEM, n;

	if (!cfg || !s || !text || !(body = body_text(p, &blen)))
		goto out_free;
	rc = re_config_load_file(config, cfg, err, errlen);
	if (rc != GL_OK)
		goto out_free;
	rc = re_seal_make(body, blen, cfg, s, err, errlen);
	if (rc != GL_OK)
		goto out_free;
	n = re_seal_emit(s, text, RE_SEAL_TEXT_MAX);
	if (n < 0) {
		snprintf(err, errlen, "the seal does not fit in %d bytes",
			 RE_SEAL_TEXT_MAX);
		rc = n;
		goto out_free;
	}
	snprintf(name, sizeof(name), "seal from %s", config);
	rc = gload_prep_buffer(p, name, text, (size_t)n, &d);
	*nitems = s->n;
out_free:
	gload_diags_free(&d);
	free(body);
	free(text);
	free(s);
	free(cfg);
	return rc;
}
