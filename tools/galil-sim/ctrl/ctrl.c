/*
 * ctrl.c - the simulated DMC-4030: life cycle, one servo sample, the
 * simulated power cycle (which restores what ctrl_store.c burned), and the
 * small public getters.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctrl_buf.h"
#include "ctrl_exec.h"
#include "ctrl_motion.h"
#include "ctrl_num.h"
#include "ctrl_out.h"
#include "ctrl_prog.h"
#include "ctrl_proto.h"
#include "ctrl_store.h"
#include "ctrl_stream.h"
#include "ctrl_thread.h"
#include "ctrl_var.h"
#include "gl_err.h"

#define DEFAULT_MODEL "DMC4030 Rev 1.2h-sim"

/* ctrl_axis_defaults() - factory settings (DMC-40x0 command reference). */
static void ctrl_axis_defaults(struct ctrl_axis_par *p)
{
	memset(p, 0, sizeof(*p));
	p->sp = 25000;
	p->ac = 256000;
	p->dc = 256000;
	p->sd = 256000;
	p->kp = 6;
	p->kd = 64;
	p->mt = 1;
	p->tl = 9.9982;
	p->il = 9.9982;
	p->ov = 0.9438;
	p->er = 16384;
	p->fl = 2147483647.0;
	p->bl = -2147483648.0;
	p->ot = 30;
	p->tw = 32766;
	p->motor_off = 1; /* simulator choice: see the docs */
}

static void settings_defaults(struct ctrl *c)
{
	const struct ctrl_flash *f = &c->flash;
	int i;

	c->cf = CTRL_SERIAL;
	c->cw_hibit = f->have_par ? f->cw_hibit : 0;
	c->cw_drop = f->have_par ? f->cw_drop : 0;
	c->cn0 = f->have_par ? f->cn0 : -1;
	for (i = 0; i < 4; i++) /* CN defaults: -1, -1, 0, 0 */
		c->cn[i] = f->have_par ? f->cn[i] : i < 2 ? -1 : 0;
	c->sample_us = f->have_par	      ? f->sample_us
		       : c->cfg.sample_us > 0 ? c->cfg.sample_us
					      : 1000;
	c->vf_m = f->have_par ? f->vf_m : 10;
	c->vf_n = f->have_par ? f->vf_n : 4;
	c->pf_m = f->have_par ? f->pf_m : 10;
	c->pf_n = f->have_par ? f->pf_n : 0;
	c->lz = f->have_par ? f->lz : 1;
	c->outputs = f->have_par ? f->outputs : 0;
	for (i = 0; i < 8; i++)
		c->axdes[i] = i;
}

static void axes_power_up(struct ctrl *c)
{
	int i;

	for (i = 0; i < CTRL_AXES; i++) {
		struct ctrl_axis *a = &c->ax[i];

		memset(a, 0, sizeof(*a));
		if (c->flash.have_par)
			a->p = c->flash.ax[i];
		else
			ctrl_axis_defaults(&a->p);
		a->jg = 25000;
		a->next_mode = CTRL_MODE_PR;
	}
}

/* RAM as after power-up: burned program, parameters and variables. */
static void power_up(struct ctrl *c)
{
	c->time = 0;
	memset(c->th, 0, sizeof(c->th));
	memset(c->autosub_pend, 0, sizeof(c->autosub_pend));
	c->tc = 0;
	c->ed_line = 0;
	c->ed_thread = -1;
	c->ia4 = -1;
	c->ta0 = 0;
	settings_defaults(c);
	axes_power_up(c);
	ctrl_prog_free(&c->prog);
	if (c->flash.have_prog && ctrl_prog_copy(&c->prog, &c->flash.prog))
		ctrl_event(c, "power-up: cannot restore the burned program");
	ctrl_vars_clear(&c->vars);
	if (c->flash.have_vars && ctrl_vars_copy(&c->vars, &c->flash.vars))
		ctrl_event(c, "power-up: cannot restore the burned variables");
	c->zero_pending = 1;
	c->auto_pending = 1;
	ctrl_proto_reset(c);
}

struct ctrl *ctrl_new(const struct ctrl_cfg *cfg)
{
	struct ctrl *c = calloc(1, sizeof(*c));

	if (!c)
		return NULL;
	if (cfg)
		c->cfg = *cfg;
	snprintf(c->model, sizeof(c->model), "%s",
		 c->cfg.model ? c->cfg.model : DEFAULT_MODEL);
	c->cfg.model = c->model;
	c->lines_per_sample = CTRL_LINES_PER_SAMPLE;
	power_up(c);
	return c;
}

void ctrl_free(struct ctrl *c)
{
	int h;

	if (!c)
		return;
	ctrl_prog_free(&c->prog);
	ctrl_prog_free(&c->flash.prog);
	ctrl_vars_clear(&c->vars);
	ctrl_vars_clear(&c->flash.vars);
	for (h = 0; h < CTRL_NHANDLES; h++) {
		ctrl_buf_free(&c->h[h].out);
		ctrl_buf_free(&c->h[h].dl);
	}
	ctrl_buf_free(&c->serial);
	ctrl_buf_free(&c->tmp);
	free(c);
}

void ctrl_step(struct ctrl *c, const struct ctrl_sense *in,
	       struct ctrl_drive *out)
{
	if (!c || !in || !out)
		return;
	ctrl_motion_sense(c, in);
	ctrl_motion_sample(c);
	ctrl_thread_boot(c);
	ctrl_threads_run(c);
	ctrl_motion_drive(c, out);
	c->time++;
	ctrl_stream_sample(c);
}

double ctrl_sample_ms(const struct ctrl *c)
{
	return c ? c->sample_us / 1000.0 : 1.0;
}

void ctrl_set_line_budget(struct ctrl *c, int lines_per_sample)
{
	if (!c)
		return;
	if (lines_per_sample < 1)
		lines_per_sample = 1;
	if (lines_per_sample > 1000)
		lines_per_sample = 1000;
	c->lines_per_sample = lines_per_sample;
}

/* ---- power ---------------------------------------------------------- */

void ctrl_power_cycle(struct ctrl *c)
{
	if (!c)
		return;
	ctrl_event(c, "power cycle");
	power_up(c);
}

int ctrl_download(struct ctrl *c, const char *text, size_t len, int *bad_line)
{
	int bad = 0;

	if (!c || (!text && len))
		return GL_ERR_ARG;
	ctrl_thread_boot(c);
	if (ctrl_any_running(c)) {
		c->tc = 17;
		return GL_ERR_CTRL;
	}
	if (ctrl_load_program(c, text ? text : "", len, &bad)) {
		if (bad_line)
			*bad_line = bad;
		return GL_ERR_CTRL;
	}
	return GL_OK;
}

int ctrl_command(struct ctrl *c, const char *line, char *resp, size_t cap)
{
	struct ctrl_handle *hd;
	size_t n = 0;
	int errors;

	if (!c || !line)
		return GL_ERR_ARG;
	hd = &c->h[CTRL_PRIV_HANDLE];
	if (!hd->open)
		ctrl_handle_open(c, CTRL_PRIV_HANDLE);
	ctrl_buf_clear(&hd->out);
	if (strlen(line) > CTRL_LINE_MAX) {
		hd->overflow = 1;
		hd->semis = 0;
	}
	errors = ctrl_proto_host(c, CTRL_PRIV_HANDLE, line);
	if (resp && cap) {
		n = ctrl_buf_take(&hd->out, (uint8_t *)resp, cap - 1);
		if (n && resp[n - 1] == ':')
			n--;
		resp[n] = '\0';
	}
	ctrl_buf_clear(&hd->out);
	return errors ? GL_ERR_CTRL : GL_OK;
}

/* ---- variables and state ----------------------------------------------- */

/* "name" or "name[i]": the storage, or NULL. */
static double *var_ref(struct ctrl *c, const char *name, int create)
{
	size_t n = ctrl_ident_len(name);
	struct ctrl_array *arr;
	uint64_t key;
	char *end;
	long i;
	int slot;

	if (ctrl_name_key(name, n, &key))
		return NULL;
	if (name[n] == '[') {
		arr = ctrl_array_find(&c->vars, key);
		i = strtol(name + n + 1, &end, 10);
		if (!arr || end == name + n + 1 || strcmp(end, "]") || i < 0 ||
		    i >= arr->n)
			return NULL;
		return &arr->v[i];
	}
	if (name[n] != '\0')
		return NULL;
	slot = ctrl_var_find(&c->vars, key);
	if (slot < 0 && create && !ctrl_var_set(&c->vars, key, 0, &slot))
		return &c->vars.slot[slot].v;
	return slot < 0 ? NULL : &c->vars.slot[slot].v;
}

int ctrl_get_var(const struct ctrl *c, const char *name, double *v)
{
	double *p;

	if (!c || !name || !v)
		return GL_ERR_ARG;
	p = var_ref((struct ctrl *)c, name, 0);
	if (!p)
		return GL_ERR_NOENT;
	*v = *p;
	return GL_OK;
}

int ctrl_set_var(struct ctrl *c, const char *name, double v)
{
	double *p;

	if (!c || !name)
		return GL_ERR_ARG;
	p = var_ref(c, name, 1);
	if (!p)
		return GL_ERR_NOENT;
	*p = ctrl_fx(v);
	return GL_OK;
}

int ctrl_axis_info(const struct ctrl *c, int axis, struct ctrl_axis_info *out)
{
	const struct ctrl_axis *a;

	if (!c || !out || axis < 0 || axis >= CTRL_AXES)
		return GL_ERR_ARG;
	a = &c->ax[axis];
	out->ref = a->ref;
	out->enc = a->enc;
	out->vel = a->vel;
	out->motor_off = a->p.motor_off;
	out->moving = a->profiling;
	out->stop_code = a->stop_code;
	out->fwd_limit = a->lim_f;
	out->rev_limit = a->lim_r;
	return GL_OK;
}

uint32_t ctrl_outputs(const struct ctrl *c)
{
	return c ? c->outputs : 0;
}

unsigned ctrl_threads(const struct ctrl *c)
{
	unsigned m = 0;
	int t;

	if (!c)
		return 0;
	for (t = 0; t < CTRL_THREADS; t++)
		if (c->th[t].running)
			m |= 1u << t;
	return m;
}

void ctrl_set_deviate(struct ctrl *c, unsigned dev_bits)
{
	c->cfg.deviate = dev_bits;
}
