/*
 * load_h.c - run galil-load for the loader tests. See load_h.h.
 */
#include "load_h.h"

#include <stddef.h>

int load_h_run(struct proc *p, const char *bin, const char *addr,
	       const char *const *args, int deadline_ms)
{
	char *argv[LOAD_H_ARGS_MAX + 4];
	int n = 0, status;

	argv[n++] = (char *)bin;
	if (addr) {
		argv[n++] = (char *)"-a";
		argv[n++] = (char *)addr;
	}
	for (int i = 0; i < LOAD_H_ARGS_MAX && args[i]; i++)
		argv[n++] = (char *)args[i];
	argv[n] = NULL;
	if (proc_spawn(p, argv, NULL) != 0)
		return -1;
	if (proc_wait_exit(p, deadline_ms, &status) != 0) {
		proc_kill(p);
		return -2;
	}
	return proc_exit_code(p);
}
