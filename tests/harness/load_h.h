/*
 * load_h.h - running galil-load from the loader tests (tests/load): one
 * runner instead of a copy in each test. Uses proc.h; never prints, never
 * fails the test itself (the caller asserts on the result).
 */
#ifndef LOAD_H_H
#define LOAD_H_H

#include "proc.h"

#define LOAD_H_ARGS_MAX 28 /* arguments after "-a ADDR" */

/*
 * load_h_run() - run galil-load @bin with "-a @addr" first (when @addr is
 * not NULL), then @args (NULL-terminated, at most LOAD_H_ARGS_MAX), and
 * wait at most @deadline_ms for it to exit; a process that does not exit
 * by then is killed. @p receives the process (its output for the caller).
 * Return: its exit code (>= 0); -1 when it could not be started; -2 when
 * it did not exit within @deadline_ms.
 */
int load_h_run(struct proc *p, const char *bin, const char *addr,
	       const char *const *args, int deadline_ms);

#endif /* LOAD_H_H */
