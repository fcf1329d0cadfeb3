/*
 * dmc_cmd.c - the DMC command table. See dmc_cmd.h.
 */
#include "dmc_cmd.h"

#include <stdlib.h>
#include <string.h>

/* clang-format off */
static const struct dmc_cmd table[] = {
    {"AB", DMC_CMD_SIM},
    {"AC", DMC_CMD_SIM},
    {"AD", 0},
    {"AF", 0},
    {"AG", 0},
    {"AI", DMC_CMD_SIM},
    {"AL", 0},
    {"AM", DMC_CMD_SIM},
    {"AO", 0},
    {"AP", 0},
    {"AQ", 0},
    {"AR", 0},
    {"AS", 0},
    {"AT", DMC_CMD_SIM},
    {"AU", 0},
    {"AV", 0},
    {"AZ", 0},
    {"BA", 0},
    {"BC", 0},
    {"BD", 0},
    {"BG", DMC_CMD_SIM},
    {"BI", 0},
    {"BK", 0},
    {"BL", DMC_CMD_SIM},
    {"BM", 0},
    {"BN", DMC_CMD_SIM},
    {"BP", DMC_CMD_SIM},
    {"BR", 0},
    {"BT", 0},
    {"BV", DMC_CMD_SIM},
    {"BW", 0},
    {"BX", 0},
    {"BZ", 0},
    {"CA", 0},
    {"CB", DMC_CMD_SIM},
    {"CC", 0},
    {"CD", 0},
    {"CE", DMC_CMD_SIM},
    {"CF", DMC_CMD_SIM},
    {"CI", 0},
    {"CM", 0},
    {"CN", DMC_CMD_SIM},
    {"CO", DMC_CMD_SIM},
    {"CR", 0},
    {"CS", 0},
    {"CW", DMC_CMD_SIM},
    {"DA", DMC_CMD_SIM},
    {"DC", DMC_CMD_SIM},
    {"DE", 0},
    {"DH", 0},
    {"DL", DMC_CMD_SIM},
    {"DM", DMC_CMD_SIM},
    {"DP", DMC_CMD_SIM},
    {"DR", DMC_CMD_SIM},
    {"DT", 0},
    {"DV", 0},
    {"EA", 0},
    {"EB", 0},
    {"EC", 0},
    {"ED", 0},
    {"EG", 0},
    {"EI", 0},
    {"EM", 0},
    {"EN", DMC_CMD_SIM},
    {"EO", DMC_CMD_SIM},
    {"EP", 0},
    {"EQ", 0},
    {"ER", DMC_CMD_SIM},
    {"ES", 0},
    {"ET", 0},
    {"EW", 0},
    {"EY", 0},
    {"FA", 0},
    {"FE", 0},
    {"FI", 0},
    {"FL", DMC_CMD_SIM},
    {"FV", 0},
    {"GA", 0},
    {"GD", 0},
    {"GM", 0},
    {"GP", 0},
    {"GR", 0},
    {"HM", 0},
    {"HS", 0},
    {"HV", 0},
    {"HX", DMC_CMD_SIM},
    {"IA", 0},
    {"ID", DMC_CMD_SIM | DMC_CMD_READ},
    {"IF", DMC_CMD_KEYWORD | DMC_CMD_SIM},
    {"IH", DMC_CMD_SIM},
    {"II", 0},
    {"IK", 0},
    {"IL", DMC_CMD_SIM},
    {"IN", 0},
    {"IP", 0},
    {"IT", 0},
    {"JG", DMC_CMD_SIM},
    {"JP", DMC_CMD_SIM},
    {"JS", DMC_CMD_SIM},
    {"KD", DMC_CMD_SIM},
    {"KI", DMC_CMD_SIM},
    {"KP", DMC_CMD_SIM},
    {"KS", 0},
    {"LA", DMC_CMD_SIM | DMC_CMD_READ},
    {"LC", 0},
    {"LD", DMC_CMD_SIM},
    {"LE", 0},
    {"LF", 0},
    {"LI", 0},
    {"LL", DMC_CMD_SIM},
    {"LM", 0},
    {"LR", 0},
    {"LS", DMC_CMD_SIM | DMC_CMD_READ},
    {"LV", DMC_CMD_SIM | DMC_CMD_READ},
    {"LZ", DMC_CMD_SIM},
    {"MB", 0},
    {"MC", DMC_CMD_SIM},
    {"ME", 0},
    {"MF", DMC_CMD_SIM},
    {"MG", DMC_CMD_SIM | DMC_CMD_READ},
    {"MO", DMC_CMD_SIM},
    {"MR", DMC_CMD_SIM},
    {"MT", DMC_CMD_SIM},
    {"MU", 0},
    {"MW", 0},
    {"NB", 0},
    {"NF", 0},
    {"NO", DMC_CMD_SIM},
    {"NZ", 0},
    {"OA", DMC_CMD_SIM},
    {"OB", DMC_CMD_SIM},
    {"OC", 0},
    {"OE", DMC_CMD_SIM},
    {"OF", DMC_CMD_SIM},
    {"OP", DMC_CMD_SIM},
    {"OT", DMC_CMD_SIM},
    {"OV", DMC_CMD_SIM},
    {"PA", DMC_CMD_SIM},
    {"PF", DMC_CMD_SIM},
    {"PL", 0},
    {"PR", DMC_CMD_SIM},
    {"PT", DMC_CMD_SIM},
    {"PV", 0},
    {"PW", 0},
    {"QD", 0},
    {"QH", DMC_CMD_READ},
    {"QQ", 0},
    {"QR", DMC_CMD_SIM | DMC_CMD_READ},
    {"QS", 0},
    {"QU", DMC_CMD_READ},
    {"QZ", DMC_CMD_SIM | DMC_CMD_READ},
    {"RA", 0},
    {"RC", 0},
    {"RD", 0},
    {"RE", DMC_CMD_SIM},
    {"RI", DMC_CMD_SIM},
    {"RL", DMC_CMD_READ},
    {"RP", DMC_CMD_SIM | DMC_CMD_READ},
    {"RS", 0},
    {"SA", 0},
    {"SB", DMC_CMD_SIM},
    {"SC", DMC_CMD_SIM | DMC_CMD_READ},
    {"SD", DMC_CMD_SIM},
    {"SH", DMC_CMD_SIM},
    {"SL", 0},
    {"SM", 0},
    {"SP", DMC_CMD_SIM},
    {"ST", DMC_CMD_SIM},
    {"TA", DMC_CMD_SIM | DMC_CMD_READ},
    {"TB", DMC_CMD_SIM | DMC_CMD_READ},
    {"TC", DMC_CMD_SIM | DMC_CMD_READ},
    {"TD", DMC_CMD_SIM | DMC_CMD_READ},
    {"TE", DMC_CMD_SIM | DMC_CMD_READ},
    {"TH", DMC_CMD_SIM | DMC_CMD_READ},
    {"TI", DMC_CMD_SIM | DMC_CMD_READ},
    {"TK", 0},
    {"TL", DMC_CMD_SIM},
    {"TM", DMC_CMD_SIM},
    {"TN", 0},
    {"TP", DMC_CMD_SIM | DMC_CMD_READ},
    {"TR", 0},
    {"TS", DMC_CMD_SIM | DMC_CMD_READ},
    {"TT", DMC_CMD_SIM | DMC_CMD_READ},
    {"TV", DMC_CMD_SIM | DMC_CMD_READ},
    {"TW", DMC_CMD_SIM},
    {"TZ", 0},
    {"UI", 0},
    {"UL", DMC_CMD_SIM | DMC_CMD_READ},
    {"US", 0},
    {"VA", 0},
    {"VD", 0},
    {"VE", 0},
    {"VF", DMC_CMD_SIM},
    {"VM", 0},
    {"VP", 0},
    {"VR", 0},
    {"VS", 0},
    {"VV", 0},
    {"WH", DMC_CMD_SIM | DMC_CMD_READ},
    {"WT", DMC_CMD_SIM},
    {"XQ", DMC_CMD_SIM},
    {"YA", 0},
    {"YB", 0},
    {"YC", 0},
    {"YR", 0},
    {"YS", 0},
    {"ZA", DMC_CMD_SIM},
    {"ZS", DMC_CMD_SIM},
};
/* clang-format on */

#define N_CMDS (sizeof(table) / sizeof(table[0]))

static int cmp(const void *k, const void *e)
{
	return strncmp(k, ((const struct dmc_cmd *)e)->name, 2);
}

const struct dmc_cmd *dmc_cmd_find(const char *s)
{
	if (!s[0] || !s[1])
		return NULL;
	return bsearch(s, table, N_CMDS, sizeof(table[0]), cmp);
}

size_t dmc_cmd_count(void)
{
	return N_CMDS;
}

const struct dmc_cmd *dmc_cmd_at(size_t i)
{
	return i < N_CMDS ? &table[i] : NULL;
}

/* The end of the statement at @s: the next ';' outside a string. */
static const char *stmt_end(const char *s)
{
	int q = 0;

	for (; *s && (q || *s != ';'); s++)
		if (*s == '"')
			q = !q;
	return s;
}

/* Whether the statement [s, e) only reads: a command marked
 * DMC_CMD_READ, an interrogation (every argument '?': "KP ?,?",
 * "KPA=?"), a variable read ("name=" or "name=?"), or a control
 * character request (^R^V). */
static int stmt_is_read(const char *s, const char *e)
{
	const struct dmc_cmd *c;
	const char *eq;
	int only_q = 1, any = 0;

	while (s < e && *s == ' ')
		s++;
	while (e > s && e[-1] == ' ')
		e--;
	if (s == e || (unsigned char)*s < 0x20)
		return 1;
	eq = memchr(s, '=', (size_t)(e - s));
	if (eq) {
		for (const char *p = eq + 1; p < e; p++)
			if (*p != ' ' && *p != '?')
				return 0;
		return 1;
	}
	c = (e - s >= 2) ? dmc_cmd_find(s) : NULL;
	if (!c)
		return 0;
	if (c->flags & DMC_CMD_READ)
		return 1;
	for (const char *p = s + 2; p < e; p++) {
		if (*p == '?')
			any = 1;
		else if (*p != ' ' && *p != ',')
			only_q = 0;
	}
	return any && only_q;
}

int dmc_cmd_line_is_read(const char *line)
{
	for (const char *s = line;;) {
		const char *e = stmt_end(s);

		if (!stmt_is_read(s, e))
			return 0;
		if (!*e)
			return 1;
		s = e + 1;
	}
}
