/*
 * ctrl_cmd.c - the command table and the general commands (TC TH WH QZ QR
 * CF CW SB CB OB OP TI TA TB DM DA LV LA LL LS UL DL BP BN BV NO TM VF PF
 * LZ IH CN EO ID MT; DR is ctrl_stream.c). The argument parsers are in
 * ctrl_args.c.
 *
 * A command not in the table answers TC 1: nothing is accepted silently.
 */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctrl_cmd.h"
#include "ctrl_args.h"
#include "ctrl_axcmd.h"
#include "ctrl_axis.h"
#include "ctrl_buf.h"
#include "ctrl_expr.h"
#include "ctrl_flow.h"
#include "ctrl_mg.h"
#include "ctrl_prog.h"
#include "ctrl_rec.h"
#include "ctrl_store.h"
#include "ctrl_stream.h"
#include "ctrl_thread.h"
#include "ctrl_var.h"
#include "gl_record.h"

#define F_PROG	 1u /* program only: TC 2 from a host */
#define F_HOST	 2u /* host only: TC 3 in a program */
#define F_ASSIGN 4u /* takes the "XXa=n" single-axis form */

static int cmd_general(struct ctrl_xc *x, const char *name, const char *a);
static int cmd_mg(struct ctrl_xc *x, const char *name, const char *a);
static int cmd_dr(struct ctrl_xc *x, const char *name, const char *a);

struct cmd_ent {
	char name[3];
	ctrl_cmd_fn fn;
	unsigned flags;
};

#define AX ctrl_axis_cmd
#define FL ctrl_flow_cmd
#define GE cmd_general
/* clang-format off */
static const struct cmd_ent cmd_table[] = {
    {"AB", AX, 0},
    {"AC", AX, F_ASSIGN},
    {"AI", FL, F_PROG},
    {"AM", FL, F_PROG},
    {"AT", FL, F_PROG},
    {"BG", AX, 0},
    {"BL", AX, F_ASSIGN},
    {"BN", GE, 0},
    {"BP", GE, 0},
    {"BV", GE, 0},
    {"CB", GE, 0},
    {"CE", AX, F_ASSIGN},
    {"CF", GE, 0},
    {"CN", GE, 0},
    {"CO", GE, 0},
    {"CW", GE, 0},
    {"DA", GE, 0},
    {"DC", AX, F_ASSIGN},
    {"DL", GE, F_HOST},
    {"DM", GE, 0},
    {"DP", AX, F_ASSIGN},
    {"DR", cmd_dr, 0},
    {"EN", FL, F_PROG},
    {"EO", GE, 0},
    {"ER", AX, F_ASSIGN},
    {"FL", AX, F_ASSIGN},
    {"HX", FL, 0},
    {"ID", GE, 0},
    {"IF", FL, F_PROG},
    {"IH", GE, F_ASSIGN},
    {"IL", AX, F_ASSIGN},
    {"JG", AX, F_ASSIGN},
    {"JP", FL, F_PROG},
    {"JS", FL, F_PROG},
    {"KD", AX, F_ASSIGN},
    {"KI", AX, F_ASSIGN},
    {"KP", AX, F_ASSIGN},
    {"LA", GE, 0},
    {"LD", AX, F_ASSIGN},
    {"LL", GE, 0},
    {"LS", GE, F_HOST},
    {"LV", GE, 0},
    {"LZ", GE, 0},
    {"MC", FL, F_PROG},
    {"MF", FL, F_PROG | F_ASSIGN},
    {"MG", cmd_mg, 0},
    {"MO", AX, 0},
    {"MR", FL, F_PROG | F_ASSIGN},
    {"MT", AX, F_ASSIGN},
    {"NO", GE, 0},
    {"OA", AX, F_ASSIGN},
    {"OB", GE, 0},
    {"OE", AX, F_ASSIGN},
    {"OF", AX, F_ASSIGN},
    {"OP", GE, 0},
    {"OT", AX, F_ASSIGN},
    {"OV", AX, F_ASSIGN},
    {"PA", AX, F_ASSIGN},
    {"PF", GE, 0},
    {"PR", AX, F_ASSIGN},
    {"PT", AX, F_ASSIGN},
    {"QR", GE, 0},
    {"QZ", GE, 0},
    {"RE", FL, F_PROG},
    {"RI", FL, F_PROG},
    {"RP", AX, 0},
    {"SB", GE, 0},
    {"SC", AX, 0},
    {"SD", AX, F_ASSIGN},
    {"SH", AX, 0},
    {"SP", AX, F_ASSIGN},
    {"ST", AX, 0},
    {"TA", GE, 0},
    {"TB", GE, 0},
    {"TC", GE, 0},
    {"TD", AX, 0},
    {"TE", AX, 0},
    {"TH", GE, 0},
    {"TI", GE, 0},
    {"TL", AX, F_ASSIGN},
    {"TM", GE, 0},
    {"TP", AX, 0},
    {"TS", AX, 0},
    {"TT", AX, 0},
    {"TV", AX, 0},
    {"TW", AX, F_ASSIGN},
    {"UL", GE, F_HOST},
    {"VF", GE, 0},
    {"WH", GE, F_HOST},
    {"WT", FL, F_PROG},
    {"XQ", FL, 0},
    {"ZA", AX, F_ASSIGN},
    {"ZS", FL, F_PROG},
};
/* clang-format on */
#undef AX
#undef FL
#undef GE

static int ent_cmp(const void *k, const void *e)
{
	return strcmp(k, ((const struct cmd_ent *)e)->name);
}

static const struct cmd_ent *cmd_find(const char *name)
{
	return bsearch(name, cmd_table,
		       sizeof(cmd_table) / sizeof(cmd_table[0]),
		       sizeof(cmd_table[0]), ent_cmp);
}

const char *ctrl_cmd_name_at(size_t i)
{
	return i < sizeof(cmd_table) / sizeof(cmd_table[0]) ? cmd_table[i].name
							    : NULL;
}

int ctrl_cmd_assignable(const char *name)
{
	const struct cmd_ent *e = cmd_find(name);

	return e && (e->flags & F_ASSIGN);
}

/*
 * ctrl_cmd_dispatch() - run command @name with argument text @a.
 * Return: 0 or a TC code (1 for an unknown command).
 */
int ctrl_cmd_dispatch(struct ctrl_xc *x, const char *name, const char *a)
{
	const struct cmd_ent *e = cmd_find(name);

	if (!e)
		return 1;
	if ((e->flags & F_PROG) && x->thread < 0)
		return 2;
	if ((e->flags & F_HOST) && x->thread >= 0)
		return 3;
	return e->fn(x, name, a);
}

/* ---- argument helpers ----------------------------------------------- */

/* A single integer argument in [lo, hi]; @def when absent (-1: needed). */
static int int_arg(struct ctrl_xc *x, const char *a, int lo, int hi, int def,
		   int *out)
{
	double v;
	int rc;

	if (*ctrl_skip(a) == '\0') {
		if (def < lo)
			return 50;
		*out = def;
		return 0;
	}
	rc = ctrl_expr_end(x, a, &v);
	if (rc)
		return rc;
	if (v != (int)v || v < lo || v > hi)
		return 6;
	*out = (int)v;
	return 0;
}

/* ---- TC TH WH QZ QR ------------------------------------------------------ */

static int cmd_tc(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	int n, rc = int_arg(x, a, 0, 1, 0, &n);

	if (rc)
		return rc;
	if (*ctrl_skip(a) == '?')
		n = 0;
	if (n && c->tc)
		ctrl_buf_printf(&c->tmp, " %d %s\r\n", c->tc,
				ctrl_tc_text(c->tc));
	else
		ctrl_buf_printf(&c->tmp, " %d\r\n", c->tc);
	c->tc = 0;
	return 0;
}

static void ip_text(uint32_t ip, char *out, size_t cap)
{
	snprintf(out, cap, "%u,%u,%u,%u", ip >> 24, (ip >> 16) & 255,
		 (ip >> 8) & 255, ip & 255);
}

static int cmd_th(struct ctrl_xc *x)
{
	struct ctrl *c = x->c;
	char ip[24];
	int h;

	ctrl_buf_puts(&c->tmp, "CONTROLLER IP ADDRESS 127,0,0,1 "
			       "ETHERNET ADDRESS 00-50-4C-20-31-32\r\n");
	for (h = 0; h < CTRL_HANDLES; h++) {
		if (!c->h[h].open) {
			ctrl_buf_printf(&c->tmp, "IH%c AVAILABLE\r\n", 'A' + h);
			continue;
		}
		ip_text(c->h[h].peer_ip, ip, sizeof(ip));
		ctrl_buf_printf(&c->tmp,
				"IH%c %s PORT %d TO IP ADDRESS %s PORT %d\r\n",
				'A' + h, c->h[h].udp ? "UDP" : "TCP",
				c->h[h].local_port, ip, c->h[h].peer_port);
	}
	return 0;
}

static int cmd_qr(struct ctrl_xc *x, const char *a)
{
	uint8_t rec[GL_REC_MAX_BYTES];
	int n;

	if (*ctrl_skip(a))
		return 1; /* QR with block letters: not simulated */
	n = ctrl_record(x->c, rec, sizeof(rec));
	if (n <= 0)
		return 1;
	x->binary = 1;
	return ctrl_buf_put(&x->c->tmp, rec, (size_t)n) ? 1 : 0;
}

/* ---- CF CW IH -------------------------------------------------------------
 */

static int cmd_cf(struct ctrl_xc *x, const char *a)
{
	char ch;

	a = ctrl_skip(a);
	ch = *a;
	if (!ch || *ctrl_skip(a + 1))
		return ch ? 1 : 50;
	if (ch >= 'A' && ch < 'A' + CTRL_HANDLES)
		x->c->cf = ch - 'A';
	else if (ch == 'S')
		x->c->cf = CTRL_SERIAL;
	else if (ch == 'I' && x->handle >= 0 && x->handle < CTRL_HANDLES)
		x->c->cf = x->handle;
	else if (ch == 'I')
		return x->handle < 0 ? 3 : 6;
	else
		return 6;
	return 0;
}

static int cmd_cw(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	double v[2] = {0, -1};
	unsigned got = 0;
	int rc;

	a = ctrl_skip(a);
	if (*a == '?' || *a == '\0') {
		ctrl_buf_puts(&c->tmp, "Copyright (c) Galil Motion Control "
				       "(galil-sim)\r\n");
		return 0;
	}
	rc = ctrl_num_list(x, a, v, 2, &got);
	if (rc)
		return rc;
	if ((got & 1) && v[0] == 0) {
		ctrl_buf_puts(&c->tmp, "Copyright (c) Galil Motion Control "
				       "(galil-sim)\r\n");
		return 0;
	}
	if (((got & 1) && v[0] != 1 && v[0] != 2) ||
	    ((got & 2) && v[1] != 0 && v[1] != 1))
		return 6;
	if (got & 1)
		c->cw_hibit = v[0] == 1;
	if (got & 2)
		c->cw_drop = v[1] == 1;
	return 0;
}

/* Does "IH@h" sent on handle @sender name handle @i? */
static int ih_names(char h, int i, int sender)
{
	if (h == 'T')
		return i != sender;
	if (h == 'S')
		return i == sender;
	return h == 'A' + i;
}

/*
 * IHh=>r closes handles: h = A..H, S (the sender), T (every other one);
 * r = -1 the UDP ones among them, -2 the TCP ones, -3 both. The
 * network layer closes them once the sender's reply has gone
 * (ctrl_handle_close_by()); the event names the command and its sender.
 */
static int cmd_ih(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	char h, who[CTRL_WHO_LEN];
	int i;

	a = ctrl_skip(a);
	h = *a;
	a = ctrl_skip(a + 1);
	if (strncmp(a, "=>", 2))
		return 1; /* opening outgoing connections: not simulated */
	a = ctrl_skip(a + 2);
	if (strcmp(a, "-1") && strcmp(a, "-2") && strcmp(a, "-3"))
		return 6;
	if (h != 'S' && h != 'T' && (h < 'A' || h >= 'A' + CTRL_HANDLES))
		return 6;
	ctrl_xc_who(x, who, sizeof(who));
	for (i = 0; i < CTRL_HANDLES; i++) {
		struct ctrl_handle *hd = &c->h[i];

		if (!hd->open || hd->close_wanted || !ih_names(h, i, x->handle))
			continue;
		if ((a[1] == '1' && !hd->udp) || (a[1] == '2' && hd->udp))
			continue;
		hd->close_wanted = 1;
		hd->close_by = x->handle;
		snprintf(hd->close_why, sizeof(hd->close_why), "IH%c from %s",
			 h, who);
	}
	return 0;
}

/* ---- I/O ----------------------------------------------------------------- */

static int cmd_bit(struct ctrl_xc *x, const char *name, const char *a)
{
	uint32_t *o = &x->c->outputs;
	double v[2] = {0, 0};
	unsigned got = 0;
	int n, rc = ctrl_num_list(x, a, v, name[0] == 'O' ? 2 : 1, &got);

	if (rc)
		return rc;
	if (!(got & 1))
		return 50;
	n = (int)v[0];
	if (v[0] != n || n < 1 || n > CTRL_INPUTS)
		return 6;
	if (name[0] == 'S' || (name[0] == 'O' && v[1] != 0))
		*o |= 1u << (n - 1);
	else
		*o &= ~(1u << (n - 1));
	return 0;
}

static int cmd_op(struct ctrl_xc *x, const char *a)
{
	int n, rc = int_arg(x, a, 0, 65535, -1, &n);

	if (rc)
		return rc;
	x->c->outputs = (x->c->outputs & ~0xFFFFu) | (uint32_t)n;
	return 0;
}

static int cmd_ti(struct ctrl_xc *x, const char *a, int amp)
{
	int n, rc = int_arg(x, a, 0, 3, 0, &n);

	if (rc)
		return rc;
	n = amp ? (n == 0 ? x->c->ta0 : 0)
		: (int)((x->c->in.inputs >> (8 * n)) & 0xFF);
	ctrl_buf_printf(&x->c->tmp, " %d\r\n", n);
	return 0;
}

/* ---- DM DA LV LA LL ------------------------------------------------------ */

/*
 * DM name[n],name2[m] (command reference DM): each array in turn; an array
 * that exists is not re-dimensioned (ctrl_array_dim(): same size nothing,
 * another size TC 57). DM ? / DM alone answers the free array space (_DM).
 */
static int cmd_dm(struct ctrl_xc *x, const char *a)
{
	uint64_t key;
	double n;
	size_t len;
	int rc;

	a = ctrl_skip(a);
	if (*a == '?' || *a == '\0') {
		ctrl_buf_printf(&x->c->tmp, " %d\r\n",
				CTRL_ARRAY_SPACE - x->c->vars.arr_used);
		return 0;
	}
	while (*a) {
		len = ctrl_ident_len(a);
		rc = ctrl_name_key(a, len, &key);
		if (rc)
			return rc;
		a = ctrl_skip(a + len);
		if (*a++ != '[')
			return 55;
		rc = ctrl_expr(x, &a, &n);
		if (rc)
			return rc;
		a = ctrl_skip(a);
		if (*a++ != ']')
			return 55;
		if (n != (int)n)
			return 6;
		if ((x->c->cfg.deviate & CTRL_DEV_DM_EXISTS) && n >= 1 &&
		    n <= CTRL_ARRAY_SPACE && ctrl_array_find(&x->c->vars, key))
			ctrl_array_free(&x->c->vars, key); /* re-dimension */
		rc = ctrl_array_dim(&x->c->vars, key, (int)n);
		if (rc)
			return rc;
		a = ctrl_skip(a);
		if (*a == ',')
			a = ctrl_skip(a + 1);
		else if (*a)
			return 1;
	}
	return 0;
}

static int da_one(struct ctrl_vars *vs, const char *a, size_t len, int arr)
{
	uint64_t key;
	int i, slot;

	if (len == 1 && a[0] == '*') {
		for (i = 0; arr && i < CTRL_ARRAYS; i++)
			if (vs->arr[i].key)
				ctrl_array_free(vs, vs->arr[i].key);
		if (!arr) {
			memset(vs->slot, 0, sizeof(vs->slot));
			vs->count = 0;
		}
		return 0;
	}
	if (ctrl_name_key(a, len, &key))
		return 9;
	if (arr)
		return ctrl_array_free(vs, key);
	slot = ctrl_var_find(vs, key);
	if (slot < 0)
		return 9;
	/* rebuild the table: open addressing has no tombstones */
	{
		struct ctrl_var old[CTRL_VAR_SLOTS];

		memcpy(old, vs->slot, sizeof(old));
		memset(vs->slot, 0, sizeof(vs->slot));
		vs->count = 0;
		for (i = 0; i < CTRL_VAR_SLOTS; i++)
			if (old[i].key && old[i].key != key)
				ctrl_var_set(vs, old[i].key, old[i].v, NULL);
	}
	return 0;
}

/*
 * DA (command reference DA): "name" a variable, "name[]" an array, "*"
 * every variable, "*[]" every array, several separated by commas. The
 * brackets may hold anything but a comma (the reference writes "Cars[0]",
 * "*[0]"). "DA ?" answers the free array slots (_DA). An unknown variable
 * is TC 9, an unknown array TC 57 (choice: the reference is silent).
 */
static int cmd_da(struct ctrl_xc *x, const char *a)
{
	size_t len;
	int rc, arr;

	a = ctrl_skip(a);
	if (*a == '?' && *ctrl_skip(a + 1) == '\0') {
		ctrl_buf_printf(&x->c->tmp, " %d\r\n",
				ctrl_arrays_free(&x->c->vars));
		return 0;
	}
	while (*a) {
		const char *name = a;

		len = *a == '*' ? 1 : ctrl_ident_len(a);
		if (!len)
			return 1;
		arr = a[len] == '[';
		a += len;
		if (arr) {
			a += strcspn(a, "],");
			if (*a != ']')
				return 55;
			a++;
		}
		rc = da_one(&x->c->vars, name, len, arr);
		if (rc)
			return rc;
		a = ctrl_skip(a);
		if (*a == ',')
			a = ctrl_skip(a + 1);
		else if (*a)
			return 1;
	}
	return 0;
}

static int key_cmp(const void *a, const void *b)
{
	char na[CTRL_NAME_MAX + 1], nb[CTRL_NAME_MAX + 1];

	ctrl_key_name(*(const uint64_t *)a, na);
	ctrl_key_name(*(const uint64_t *)b, nb);
	return strcmp(na, nb);
}

static int cmd_lv(struct ctrl_xc *x)
{
	struct ctrl_vars *vs = &x->c->vars;
	uint64_t keys[CTRL_VARS];
	char name[CTRL_NAME_MAX + 1];
	int i, n = 0, slot;

	for (i = 0; i < CTRL_VAR_SLOTS && n < CTRL_VARS; i++)
		if (vs->slot[i].key)
			keys[n++] = vs->slot[i].key;
	qsort(keys, (size_t)n, sizeof(keys[0]), key_cmp);
	for (i = 0; i < n; i++) {
		slot = ctrl_var_find(vs, keys[i]);
		ctrl_key_name(keys[i], name);
		ctrl_buf_printf(&x->c->tmp, "%s =", name);
		ctrl_put_num(x, vs->slot[slot].v, CTRL_NUM_VF);
		ctrl_buf_puts(&x->c->tmp, "\r\n");
	}
	return 0;
}

static int cmd_la_ll(struct ctrl_xc *x, int labels)
{
	struct ctrl *c = x->c;
	char name[CTRL_NAME_MAX + 1];
	uint64_t keys[CTRL_LABELS];
	int i, n = 0;

	if (labels) {
		for (i = 0; i < c->prog.nlabels; i++)
			keys[n++] = c->prog.label[i].key;
	} else {
		for (i = 0; i < CTRL_ARRAYS; i++)
			if (c->vars.arr[i].key)
				keys[n++] = c->vars.arr[i].key;
	}
	qsort(keys, (size_t)n, sizeof(keys[0]), key_cmp);
	for (i = 0; i < n; i++) {
		ctrl_key_name(keys[i], name);
		if (labels)
			ctrl_buf_printf(&c->tmp, "#%s=%d\r\n", name,
					ctrl_prog_label(&c->prog, keys[i]));
		else
			ctrl_buf_printf(&c->tmp, "%s[%d]\r\n", name,
					ctrl_array_find(&c->vars, keys[i])->n);
	}
	return 0;
}

/* ---- program: LS UL DL BP BN BV ---------------------------------------- */

static int cmd_ls_ul(struct ctrl_xc *x, const char *a, int ul)
{
	struct ctrl *c = x->c;
	int i;

	if (*ctrl_skip(a))
		return ul ? 1 : 1; /* LS n0,n1 / UL n: not simulated */
	for (i = 0; i < c->prog.nlines; i++) {
		const char *t = c->prog.line[i];
		size_t len = strlen(t);

		if (!ul)
			ctrl_buf_printf(&c->tmp, "%d ", i);
		else if (c->cfg.deviate & CTRL_DEV_UL_TRIM)
			while (len && t[len - 1] == ' ')
				len--; /* deviation ul-trim */
		ctrl_buf_put(&c->tmp, t, len);
		ctrl_buf_puts(&c->tmp, "\r\n");
	}
	if (ul)
		ctrl_buf_put(&c->tmp, "\x1a", 1);
	return 0;
}

static int cmd_dl(struct ctrl_xc *x, const char *a)
{
	if (*ctrl_skip(a))
		return 1; /* DL n / DL #label partial downloads: no */
	if (ctrl_any_running(x->c))
		return 17;
	if (x->handle < 0 || x->handle == CTRL_PRIV_HANDLE)
		return 1; /* use ctrl_download() */
	x->dl = 1;
	return 0;
}

static int cmd_burn(struct ctrl_xc *x, const char *name, const char *a)
{
	struct ctrl *c = x->c;

	if (*ctrl_skip(a))
		return 1;
	if (name[1] != 'V' && ctrl_any_running(c) && x->thread < 0)
		return 17;
	if (name[1] == 'P')
		return ctrl_burn_program(c) ? 15 : 0;
	if (name[1] == 'N') {
		ctrl_burn_params(c);
		return 0;
	}
	return ctrl_burn_vars(c) ? 15 : 0;
}

/* ---- formats and settings -------------------------------------------- */

/* VF m.n, VF m,n (same for PF) */
static int cmd_fmt(struct ctrl_xc *x, const char *a, int *m, int *n)
{
	double v[2] = {0, -1};
	unsigned got = 0;
	int rc, mm, nn;

	a = ctrl_skip(a);
	if (*a == '?') {
		ctrl_buf_printf(&x->c->tmp, "%d.%d\r\n", *m, *n);
		return 0;
	}
	rc = ctrl_num_list(x, a, v, 2, &got);
	if (rc)
		return rc;
	mm = (int)v[0];
	nn = (got & 2) ? (int)v[1] : (int)((v[0] - mm) * 10 + 0.5);
	if (!(got & 1) || mm < 1 || mm > 10 || nn < 0 || nn > 4)
		return 6;
	*m = mm;
	*n = nn;
	return 0;
}

/* CO n: extended I/O configuration, n = 0..15 (a bit per bank of 8 from
 * I/O 17; set = outputs). Stored and reported only: the simulated extended
 * I/O are always inputs (docs/galil-sim-controller.md). */
static int cmd_co(struct ctrl_xc *x, const char *a)
{
	int n, rc;

	if (*ctrl_skip(a) == '?') {
		ctrl_buf_printf(&x->c->tmp, " %d\r\n", x->c->co);
		return 0;
	}
	rc = int_arg(x, a, 0, 15, -1, &n);
	if (rc)
		return rc;
	x->c->co = n;
	return 0;
}

static int cmd_tm(struct ctrl_xc *x, const char *a)
{
	int i, n, rc;

	if (*ctrl_skip(a) == '?') {
		ctrl_buf_printf(&x->c->tmp, " %d\r\n", x->c->sample_us);
		return 0;
	}
	rc = int_arg(x, a, 250, 5000, -1, &n);
	if (rc)
		return rc;
	for (i = 0; i < CTRL_AXES; i++)
		if (x->c->ax[i].profiling)
			return 7;
	x->c->sample_us = n;
	return 0;
}

/*
 * CN n0,n1,n2,n3,n4 (command reference CN): n0 limit switch polarity, n1
 * home input polarity (_HM), both -1 or 1; n2 latch polarity (-1, 1), n3
 * selective abort and n4 abort program end (0, 1) are stored and reported
 * only. Fields left out keep their value. CN ? answers the five.
 */
static int cmd_cn(struct ctrl_xc *x, const char *a)
{
	struct ctrl *c = x->c;
	double v[5] = {0, 0, 0, 0, 0};
	unsigned got = 0;
	int i, rc;

	if (*ctrl_skip(a) == '?') {
		ctrl_buf_printf(&c->tmp, " %d, %d, %d, %d, %d\r\n", c->cn0,
				c->cn[0], c->cn[1], c->cn[2], c->cn[3]);
		return 0;
	}
	rc = ctrl_num_list(x, a, v, 5, &got);
	if (rc)
		return rc;
	if (!got)
		return 50;
	for (i = 0; i < 5; i++) {
		if (!(got & (1u << i)))
			continue;
		if (i < 3 ? (v[i] != -1 && v[i] != 1)
			  : (v[i] != 0 && v[i] != 1))
			return 6;
	}
	for (i = 0; i < 5; i++) {
		if (!(got & (1u << i)))
			continue;
		if (i == 0)
			c->cn0 = (int)v[0];
		else
			c->cn[i - 1] = (int)v[i];
	}
	return 0;
}

static int cmd_settings(struct ctrl_xc *x, const char *name, const char *a)
{
	struct ctrl *c = x->c;
	int n, rc;

	if (!strcmp(name, "LZ")) {
		rc = int_arg(x, a, 0, 1, -1, &n);
		if (!rc)
			c->lz = n;
		return rc;
	}
	if (!strcmp(name, "EO"))
		return int_arg(x, a, 0, 1, -1, &n); /* no echo on TCP */
	return cmd_cn(x, a);
}

/*
 * ID (command reference ID: "FW, firmware revision" then one line per
 * board): the ^R^V text, the 4-axis DMC board and the AMP-43040 amplifier
 * the under-voltage status (_TA0 bit 3) belongs to. Rev numbers: choice.
 */
static int cmd_id(struct ctrl_xc *x)
{
	ctrl_buf_printf(&x->c->tmp,
			"FW, %s\r\nDMC, 4030, Rev 1\r\nAMP1, 43040, Rev 1\r\n",
			x->c->model);
	return 0;
}

static int cmd_dr(struct ctrl_xc *x, const char *name, const char *a)
{
	(void)name;
	return ctrl_stream_cmd(x, a);
}

static int cmd_mg(struct ctrl_xc *x, const char *name, const char *a)
{
	(void)name;
	return ctrl_mg(x, a);
}

static int cmd_misc(struct ctrl_xc *x, const char *name, const char *a)
{
	if (!strcmp(name, "TH"))
		return cmd_th(x);
	if (!strcmp(name, "WH")) {
		if (x->handle >= CTRL_HANDLES || x->handle < 0)
			ctrl_buf_puts(&x->c->tmp, "RS232\r\n");
		else
			ctrl_buf_printf(&x->c->tmp, "IH%c\r\n",
					'A' + x->handle);
		return 0;
	}
	if (!strcmp(name, "QZ")) {
		ctrl_buf_printf(&x->c->tmp, " %d, 52, 26, 36\r\n", CTRL_AXES);
		return 0;
	}
	if (!strcmp(name, "TB")) {
		ctrl_buf_printf(&x->c->tmp, " %d\r\n",
				ctrl_any_running(x->c) ? 128 : 0);
		return 0;
	}
	if (!strcmp(name, "LV"))
		return cmd_lv(x);
	if (!strcmp(name, "LA") || !strcmp(name, "LL"))
		return cmd_la_ll(x, name[1] == 'L');
	(void)a;
	return 1;
}

static int cmd_general(struct ctrl_xc *x, const char *name, const char *a)
{
	switch (name[0] << 8 | name[1]) {
	case 'T' << 8 | 'C': return cmd_tc(x, a);
	case 'Q' << 8 | 'R': return cmd_qr(x, a);
	case 'C' << 8 | 'F': return cmd_cf(x, a);
	case 'C' << 8 | 'W': return cmd_cw(x, a);
	case 'I' << 8 | 'H': return cmd_ih(x, a);
	case 'S' << 8 | 'B':
	case 'C' << 8 | 'B':
	case 'O' << 8 | 'B': return cmd_bit(x, name, a);
	case 'O' << 8 | 'P': return cmd_op(x, a);
	case 'T' << 8 | 'I': return cmd_ti(x, a, 0);
	case 'T' << 8 | 'A': return cmd_ti(x, a, 1);
	case 'D' << 8 | 'M': return cmd_dm(x, a);
	case 'D' << 8 | 'A': return cmd_da(x, a);
	case 'L' << 8 | 'S': return cmd_ls_ul(x, a, 0);
	case 'U' << 8 | 'L': return cmd_ls_ul(x, a, 1);
	case 'D' << 8 | 'L': return cmd_dl(x, a);
	case 'B' << 8 | 'P':
	case 'B' << 8 | 'N':
	case 'B' << 8 | 'V': return cmd_burn(x, name, a);
	case 'N' << 8 | 'O': return 0;
	case 'T' << 8 | 'M': return cmd_tm(x, a);
	case 'C' << 8 | 'O': return cmd_co(x, a);
	case 'V' << 8 | 'F': return cmd_fmt(x, a, &x->c->vf_m, &x->c->vf_n);
	case 'P' << 8 | 'F': return cmd_fmt(x, a, &x->c->pf_m, &x->c->pf_n);
	case 'L' << 8 | 'Z':
	case 'E' << 8 | 'O':
	case 'C' << 8 | 'N': return cmd_settings(x, name, a);
	case 'I' << 8 | 'D': return *ctrl_skip(a) ? 1 : cmd_id(x);
	}
	return cmd_misc(x, name, a);
}
