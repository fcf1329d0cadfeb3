/*
 * ctrl_cmd.h - the command table and the general commands (ctrl_cmd.c);
 * internal to the simulated controller (ctrl/), not part of its API
 * (ctrl.h).
 * It does not split statements (ctrl_exec.h).
 */
#ifndef SIM_CTRL_CMD_H
#define SIM_CTRL_CMD_H

#include "ctrl_int.h"

/* A command handler: @name the two letters, @a the argument text. */
typedef int (*ctrl_cmd_fn)(struct ctrl_xc *x, const char *name, const char *a);

/*
 * ctrl_cmd_dispatch() - run command @name (two letters) with argument text
 * @a through the command table. Return: 0 or a TC code (1: unknown
 * command, 2: program only, 3: not valid in a program).
 */
int ctrl_cmd_dispatch(struct ctrl_xc *x, const char *name, const char *a);
/* ctrl_cmd_assignable() - 1 when command @name takes the single-axis
 * "XXa=n" form, else 0. */
int ctrl_cmd_assignable(const char *name);

/*
 * ctrl_cmd_name_at() - the name of the @i-th command galil-sim runs
 * (0 <= i, alphabetical), or NULL past the end: the dispatch table, for
 * the test that holds it to the one command table (pc/dmc/dmc_cmd.h).
 */
const char *ctrl_cmd_name_at(size_t i);

#endif /* SIM_CTRL_CMD_H */
