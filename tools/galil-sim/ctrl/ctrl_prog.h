/*
 * ctrl_prog.h - program memory: download checks, statements, labels
 * (ctrl_prog.c); internal to the simulated controller (ctrl/), not part of
 * its API (ctrl.h).
 * It runs nothing (ctrl_exec.h) and keeps no flash (ctrl_store.h).
 */
#ifndef SIM_CTRL_PROG_H
#define SIM_CTRL_PROG_H

#include "ctrl_int.h"

/*
 * ctrl_prog_load() - check the program text @text (@len bytes, copied) and
 * load it into @p, which must be empty (zeroed or freed).
 * @bad_line: [out] 1-based line of the first error, 0 if none.
 * @tc: [out] its TC code (60, 61, 62 ...).
 * Return: 0, a TC code (p is then empty), or -1 when out of memory.
 */
int ctrl_prog_load(struct ctrl_prog *p, const char *text, size_t len,
		   int *bad_line, int *tc);
/* ctrl_prog_free() - release @p's memory; @p is then empty. */
void ctrl_prog_free(struct ctrl_prog *p);
/*
 * ctrl_prog_copy() - deep copy of @src over @dst (BP, power-up).
 * Return: 0, or -1 when out of memory (@dst unchanged).
 */
int ctrl_prog_copy(struct ctrl_prog *dst, const struct ctrl_prog *src);
/* ctrl_prog_label() - 0-based line of label @key in @p, or -1. */
int ctrl_prog_label(const struct ctrl_prog *p, uint64_t key);
/*
 * ctrl_prog_stmt_text() - statement @i as written in its line, into @out
 * (@cap > CTRL_LINE_MAX). Return: 0, or -1 (bad index or small @cap).
 */
int ctrl_prog_stmt_text(const struct ctrl_prog *p, int i, char *out,
			size_t cap);
/* ctrl_prog_stmt() - the text of statement @i (0 <= i < nstmts), owned by
 * @p. */
const char *ctrl_prog_stmt(const struct ctrl_prog *p, int i);

#endif /* SIM_CTRL_PROG_H */
