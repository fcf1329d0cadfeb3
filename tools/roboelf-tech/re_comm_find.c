/*
 * re_comm_find.c - the commissioning run's controller discovery
 * (re_comm_find.h), over gl_disc.
 */
#include <stdio.h>

#include "gl_disc.h"
#include "gl_err.h"
#include "re_comm_find.h"

int re_comm_find(const char *bcast, unsigned port, int window_ms,
		 struct re_comm_found *list, int max, char *err, size_t errlen)
{
	struct gl_disc_ctrl found[RE_COMM_FIND_MAX];
	char e[GL_ERRTEXT_LEN] = "";
	int n;

	if (max > RE_COMM_FIND_MAX)
		max = RE_COMM_FIND_MAX;
	n = gl_disc_probe(bcast, port, window_ms, found, max, e);
	if (n < 0) {
		snprintf(err, errlen, "%s", e[0] ? e : gl_strerror(n));
		return n;
	}
	for (int i = 0; i < n; i++) {
		snprintf(list[i].addr, sizeof(list[i].addr), "%s",
			 found[i].addr);
		snprintf(list[i].what, sizeof(list[i].what), "%s Rev %s",
			 found[i].model, found[i].rev);
	}
	return n;
}
