/*
 * gload_prep.h - galil-load's preprocessor: read the DMC source files (or a
 * directory's MANIFEST), strip what the controller does not need, keep the
 * source file and line of every remaining line, and stamp the result with
 * its identity (pc/galil/gl_ident.h).
 *
 * Rules (docs/galil-load.md, "Preprocessing"), applied to each source line:
 *  1. a line whose first word is REM is dropped;
 *  2. a ' outside a "string" starts a comment that runs to the end of the
 *     line; it is removed;
 *  3. tabs outside strings become spaces; spaces at the start and end of the
 *     line and around ';' separators (outside strings) are removed, and so
 *     are ';' at the end of the line;
 *  4. a line left empty is dropped.
 * Inside a NO statement '"' does not open a string (the controller ignores
 * everything up to the next ';'). Nothing else changes: spaces inside a
 * statement, case and NO comments stay as written. The files are joined in
 * the order given. Lines are separated by LF, CR LF or CR.
 *
 * Nothing here prints: problems go to a struct gload_diags.
 */
#ifndef GLOAD_PREP_H
#define GLOAD_PREP_H

#include <stddef.h>
#include <stdint.h>

#include "gl_ident.h"
#include "gload_diag.h"

#define GLOAD_MANIFEST	 "MANIFEST"
#define GLOAD_SEAL_ENTRY "@seal" /* manifest entry: the seal goes here */
#define GLOAD_FILE_MAX	 (4L * 1024 * 1024) /* bytes; far above 4000 x 80 */

/* One preprocessed line and where it came from. */
struct gload_line {
	char *text; /* NUL-terminated (may hold NUL bytes: use len) */
	size_t len;
	int file;     /* index in gload_prog.files */
	int src_line; /* 1-based line in that file */
};

struct gload_prog {
	char **files; /* source paths as printed in messages */
	int nfiles;
	int order;	 /* next diagnostic order key (gload_diag.file) */
	int *file_order; /* order key of each file */
	struct gload_line *lines; /* preprocessed lines, without the stamp */
	int nlines;
	int cap;
	size_t src_bytes; /* size before preprocessing */
	long src_lines;
	char *text; /* after gload_prog_finish(): every line + the
		     * stamp line, each ending with one LF */
	size_t text_len;
	size_t body_len; /* bytes of @text before the stamp line */
	uint64_t id;	 /* identity (hash of the body) */
	char stamp[GL_IDENT_LINE_SIZE];
	/* the manifest's last entry is GLOAD_SEAL_ENTRY: the seal generated
	 * from the configuration follows the files (gload_seal.h) */
	int seal;
	char seal_where[128]; /* "dmc/MANIFEST:3", for messages */
};

/*
 * gload_prep_buffer() - preprocess one source file held in memory and
 * append its lines to @p.
 * @p: the program (zero-initialised before the first call).
 * @path: the name used in messages (copied).
 * @buf: [in] the file's bytes, @len of them.
 * @d: [out] problems found; none today (an open string is the linter's
 *     finding string-open), kept so that callers need not change.
 * Return: GL_OK (even with diagnostics), or GL_ERR_NOMEM.
 */
int gload_prep_buffer(struct gload_prog *p, const char *path, const char *buf,
		      size_t len, struct gload_diags *d);

/*
 * gload_prep_path() - read a .dmc file, or a directory's MANIFEST and the
 * files it lists in order, and preprocess them into @p. A manifest whose
 * last entry is GLOAD_SEAL_ENTRY sets @p->seal (the caller appends the
 * seal); anywhere else that entry is an error.
 * @path: a file or a directory.
 * @d: [out] "cannot open 'x': reason", "DIR/MANIFEST:3: cannot open ...",
 *     "DIR/MANIFEST:2: @seal must be the last entry".
 * Return: GL_OK, GL_ERR_NOENT (something could not be read; see @d),
 *         GL_ERR_FORMAT (an empty manifest), GL_ERR_NOMEM.
 */
int gload_prep_path(struct gload_prog *p, const char *path,
		    struct gload_diags *d);

/*
 * gload_manifest_parse() - the file names listed in a MANIFEST: one per
 * line; '#' starts a comment; blank lines are ignored; spaces around a name
 * are removed.
 * @names: [out] a malloc'd array of malloc'd names (free each, then it).
 * @lines: [out] optional malloc'd array with the manifest line of each name.
 * Return: the number of names (>= 0), or GL_ERR_NOMEM.
 */
int gload_manifest_parse(const char *buf, size_t len, char ***names,
			 int **lines);

/*
 * gload_prog_finish() - join the lines, compute the identity and append the
 * stamp line: fills text, text_len, body_len, id and stamp.
 * Return: GL_OK or GL_ERR_NOMEM.
 */
int gload_prog_finish(struct gload_prog *p);

/*
 * gload_prog_has_label() - whether a line of @p defines the label @name
 * (without '#'). Return: 1 or 0.
 */
int gload_prog_has_label(const struct gload_prog *p, const char *name);

/* gload_prog_free() - free everything; @p is left zeroed. */
void gload_prog_free(struct gload_prog *p);

#endif /* GLOAD_PREP_H */
