/*
 * gload_diag.h - a list of "FILE:LINE: message" diagnostics collected by the
 * preprocessor and the checker, kept in source order. Nothing here prints;
 * galil-load's main() prints the list.
 */
#ifndef GLOAD_DIAG_H
#define GLOAD_DIAG_H

#include <stddef.h>

struct gload_diag {
	int file;   /* source order: file index (-1 = before files) */
	int line;   /* 1-based source line, 0 = whole file */
	int seq;    /* insertion order, ties broken by it */
	char *text; /* "FILE:LINE: message", NUL-terminated */
};

struct gload_diags {
	struct gload_diag *v;
	int n;
	int cap;
	int dropped; /* messages not stored after an allocation failure */
};

/*
 * gload_diags_add() - append one diagnostic.
 * @d: the list (zero-initialised before first use).
 * @file_idx: order key of the file (index in the program's file list, or -1
 *            for a manifest that comes before every file).
 * @path: file name printed; @line: 1-based line, or 0 to print "FILE: ".
 * @fmt: printf format of the message (lower case, no full stop).
 * Return: 0, or GL_ERR_NOMEM (the message is counted in @d->dropped).
 */
int gload_diags_add(struct gload_diags *d, int file_idx, const char *path,
		    int line, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

/* gload_diags_sort() - order by (file, line, insertion order). */
void gload_diags_sort(struct gload_diags *d);

/* gload_diags_free() - free the messages; @d is left empty and reusable. */
void gload_diags_free(struct gload_diags *d);

#endif /* GLOAD_DIAG_H */
