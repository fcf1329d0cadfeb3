/*
 * dmc_cmd.h - the ONE table of the DMC language's two-letter commands:
 * every command galil-load accepts in a program, and which of them
 * galil-sim runs. galil-load's checker asks it whether an upper-case
 * word is a command; a test holds galil-sim's dispatch to it
 * (tests/sim/test_sim_cmdtable.c), and the commands galil-sim does not
 * run are listed in docs/galil-sim.md from it.
 *
 * Not the commands' arguments (galil-sim's ctrl_cmd) nor the limits
 * (dmc_model). Source: the DMC-4000 command reference as listed by the
 * kForth DMC grammar [galil-notes, HL], plus EN IN NO RE RI and CO.
 */
#ifndef DMC_CMD_H
#define DMC_CMD_H

#include <stddef.h>

#define DMC_CMD_SIM	1u /* galil-sim runs it (else it answers '?', TC 1) */
#define DMC_CMD_KEYWORD 2u /* a keyword the checker treats apart (IF) */
#define DMC_CMD_READ	4u /* only reports: changes nothing on the controller */

struct dmc_cmd {
	char name[3];	/* two upper-case letters */
	unsigned flags; /* DMC_CMD_* */
};

/*
 * dmc_cmd_find() - the command whose name is the two characters at @s
 * (upper case; what follows them is not looked at).
 * Return: the table entry (static), or NULL when @s holds no command.
 */
const struct dmc_cmd *dmc_cmd_find(const char *s);

/* dmc_cmd_count() - the number of entries; dmc_cmd_at() - entry @i
 * (0 <= i < dmc_cmd_count(), in alphabetical order), NULL past the end. */
size_t dmc_cmd_count(void);
const struct dmc_cmd *dmc_cmd_at(size_t i);

/*
 * dmc_cmd_line_is_read() - whether a host command line only reads: every
 * ';'-separated statement is a command marked DMC_CMD_READ (MG, TP, QR,
 * LS ...), an interrogation whose arguments are all '?' ("KP ?,?",
 * "KPA=?"), a variable read ("hbpc=" or "hbpc=?") or a control-character
 * request (^R^V). Anything else - an assignment, a setting, motion, XQ,
 * HX - writes. galil-load refuses writes on a running robot (docs/
 * galil-load.md).
 * Return: 1 or 0.
 */
int dmc_cmd_line_is_read(const char *line);

#endif /* DMC_CMD_H */
