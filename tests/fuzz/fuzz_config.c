/*
 * fuzz_config.c - libFuzzer target: the configuration loader
 * (re_config_parse(), the buffer entry point re_config_load_file() uses).
 *
 * Input: the YAML text. A configuration that loads must also pass
 * re_config_validate() (the loader validates as it does), and its hash and
 * summary are computed (every field is read once).
 */
#include <stdint.h>
#include <stddef.h>
#include <string.h>
#include <stdlib.h>
#include "gl_err.h"
#include "re_config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct re_config cfg;
	char err[RE_CONFIG_ERR_MAX], dump[2048];
	int rc;

	memset(&cfg, 0, sizeof(cfg));
	rc = re_config_parse((const char *)data, size, "fuzz.yaml", &cfg, err,
			     sizeof(err));
	if (rc == GL_OK) {
		if (re_config_validate(&cfg, err, sizeof(err)) != GL_OK)
			abort(); /* loaded but not valid */
		(void)re_config_hash(&cfg);
		(void)re_config_dump(&cfg, dump, sizeof(dump));
	} else if (rc != GL_ERR_CONFIG && rc != GL_ERR_NOMEM) {
		abort();
	} else if (memchr(err, '\0', sizeof(err)) == NULL || err[0] == '\0') {
		abort(); /* every refusal says why */
	}
	return 0;
}
