/*
 * ctrl_store.c - what the controller keeps: a program text loaded into
 * program memory (DL), and the program, parameters and variables burned
 * into flash (BP, BN, BV), each with its event.
 *
 * It is not the program parser (ctrl_prog.c) nor the power cycle that
 * restores the flash (ctrl.c).
 */
#include <string.h>

#include "ctrl_store.h"
#include "ctrl_out.h"
#include "ctrl_prog.h"
#include "ctrl_thread.h"
#include "ctrl_var.h"

/* ---- burning --------------------------------------------------------- */

int ctrl_burn_program(struct ctrl *c)
{
	if (ctrl_prog_copy(&c->flash.prog, &c->prog))
		return -1;
	c->flash.have_prog = 1;
	ctrl_event(c, "program burned (BP): %d lines", c->prog.nlines);
	return 0;
}

void ctrl_burn_params(struct ctrl *c)
{
	struct ctrl_flash *f = &c->flash;
	int i;

	for (i = 0; i < CTRL_AXES; i++)
		f->ax[i] = c->ax[i].p;
	f->cw_hibit = c->cw_hibit;
	f->cw_drop = c->cw_drop;
	f->cn0 = c->cn0;
	memcpy(f->cn, c->cn, sizeof(f->cn));
	f->sample_us = c->sample_us;
	f->vf_m = c->vf_m;
	f->vf_n = c->vf_n;
	f->pf_m = c->pf_m;
	f->pf_n = c->pf_n;
	f->lz = c->lz;
	f->outputs = c->outputs;
	f->have_par = 1;
	ctrl_event(c, "parameters burned (BN)");
}

int ctrl_burn_vars(struct ctrl *c)
{
	if (ctrl_vars_copy(&c->flash.vars, &c->vars))
		return -1;
	c->flash.have_vars = 1;
	ctrl_event(c, "variables burned (BV)");
	return 0;
}

/* ---- programs -------------------------------------------------------- */

/*
 * ctrl_load_program() - replace program memory; on a refused text the
 * memory is left empty. Return 0 or the TC code (TC is set too).
 */
int ctrl_load_program(struct ctrl *c, const char *text, size_t len,
		      int *bad_line)
{
	struct ctrl_prog np;
	int rc, tc;

	memset(&np, 0, sizeof(np));
	rc = ctrl_prog_load(&np, text, len, bad_line, &tc);
	ctrl_prog_free(&c->prog);
	if (rc) {
		tc = rc < 0 ? 60 : tc;
		c->tc = tc;
		ctrl_event(c,
			   "download refused: line %d TC %d %s (program "
			   "memory erased)",
			   *bad_line, tc, ctrl_tc_text(tc));
		return tc;
	}
	c->prog = np;
	ctrl_event(c, "program loaded: %d lines, %d labels", np.nlines,
		   np.nlabels);
	return 0;
}
