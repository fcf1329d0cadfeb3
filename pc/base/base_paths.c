/*
 * base_paths.c - the installed places (base_paths.h).
 */
#include "base_paths.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Set by the Makefile from PREFIX and SYSCONFDIR; these defaults are the
 * Makefile's own (PREFIX=/usr/local, SYSCONFDIR=/etc). */
#ifndef ROBOELF_DATADIR
#define ROBOELF_DATADIR "/usr/local/share/roboelf"
#endif
#ifndef ROBOELF_SYSCONFDIR
#define ROBOELF_SYSCONFDIR "/etc"
#endif

#define LOCAL_DMC "dmc"

const char *base_paths_root(void)
{
	const char *r = getenv(BASE_PATHS_ROOT_ENV);

	return r && *r ? r : NULL;
}

static int join(const char *dir, const char *name, char *out, size_t len)
{
	const char *root = base_paths_root();
	int n;

	n = snprintf(out, len, "%s%s%s%s", root ? root : "", dir,
		     *name ? "/" : "", name);
	if (n < 0 || (size_t)n >= len) {
		if (len)
			out[0] = '\0';
		return -1;
	}
	return 0;
}

int base_paths_data(const char *name, char *out, size_t len)
{
	return join(ROBOELF_DATADIR, name, out, len);
}

int base_paths_sysconf(const char *name, char *out, size_t len)
{
	return join(ROBOELF_SYSCONFDIR, name, out, len);
}

int base_paths_dmc_dir(char *out, size_t len)
{
	char manifest[4096];

	if (access(LOCAL_DMC "/MANIFEST", F_OK) == 0) {
		if (snprintf(out, len, "%s", LOCAL_DMC) >= (int)len)
			return -1;
		return 0;
	}
	if (base_paths_data(LOCAL_DMC, out, len) < 0 ||
	    snprintf(manifest, sizeof(manifest), "%s/MANIFEST", out) >=
		(int)sizeof(manifest))
		return -1;
	return access(manifest, F_OK) == 0 ? 0 : -1;
}

int base_paths_absolute(const char *cwd, const char *path, char *out,
			size_t len)
{
	size_t c = strlen(cwd);
	int n;

	if (*path == '/' || !*path) {
		n = snprintf(out, len, "%s", path);
	} else if (cwd[0] != '/') {
		n = -1;
	} else {
		while (path[0] == '.' && path[1] == '/') {
			path += 2;
			while (*path == '/')
				path++;
		}
		if (!strcmp(path, "."))
			path = "";
		while (c > 1 && cwd[c - 1] == '/')
			c--; /* "/home/x/" and "/" alike */
		n = snprintf(out, len, "%.*s%s%s", (int)c, cwd,
			     *path && cwd[c - 1] != '/' ? "/" : "", path);
	}
	if (n < 0 || (size_t)n >= len) {
		if (len)
			out[0] = '\0';
		return -1;
	}
	return 0;
}
