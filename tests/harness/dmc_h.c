/*
 * dmc_h.c - test harness for the DMC programs on galil-sim (see dmc_h.h).
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dmc_h.h"
#include "gl_err.h"
#include "gload_diag.h"
#include "gload_prep.h"
#include "re_seal.h"
#include "re_sealmake.h"

#define UNSOL_HANDLE 0	/* handle A: CF A, the program's MG lines */
#define QR_HANDLE    1	/* handle B: QR for the ZA fields */
#define REC_AXIS0    82 /* DMC-40x0 record: first axis block */
#define REC_AXIS_LEN 36
#define REC_ZA	     32 /* ZA inside an axis block (SL) */

/* ---- preprocessing ------------------------------------------------------ */

static const char *top_dir(const char *top)
{
	const char *env = getenv("ROBOELF_TOP");

	if (top)
		return top;
	return env && *env ? env : ".";
}

int dmc_h_load_program(const char *top, char *out, size_t cap, char *err,
		       size_t errlen)
{
	struct gload_prog p;
	struct gload_diags d;
	char path[512];
	int rc;

	memset(&p, 0, sizeof(p));
	memset(&d, 0, sizeof(d));
	snprintf(path, sizeof(path), "%s/dmc", top_dir(top));
	/* galil-load's own preprocessor: the tests run, byte for byte, the
	 * program galil-load downloads (without its identity line) */
	rc = gload_prep_path(&p, path, &d);
	if (rc == GL_OK)
		rc = gload_prog_finish(&p);
	if (rc != GL_OK) {
		snprintf(err, errlen, "%s",
			 d.n > 0 ? d.v[0].text : gl_strerror(rc));
	} else if (p.body_len + 1 > cap) {
		rc = GL_ERR_OVERFLOW;
	} else {
		memcpy(out, p.text, p.body_len);
		out[p.body_len] = '\0';
		rc = (int)p.body_len;
	}
	gload_prog_free(&p);
	gload_diags_free(&d);
	return rc;
}

/* The parameters of @p as re_seal_make() adds them from a configuration
 * (same order, same items), so that the tests run the seal galil-load
 * writes, made from the test's own values. */
static int seal_params(struct re_seal *s, const struct dmc_h_params *p)
{
	const struct {
		const char *name;
		const double *v;
	} ax[] = {
	    {"vmin", p->vmin},	   {"vmax", p->vmax},	{"wst", p->wst},
	    {"wen", p->wen},	   {"stp", p->stp},	{"potin", p->potin},
	    {"potlo", p->potlo},   {"pothi", p->pothi}, {"pnlo", p->pnlo},
	    {"pnhi", p->pnhi},	   {"svmax", p->svmax}, {"svslow", p->svslow},
	    {"svdmax", p->svdmax},
	};
	const struct {
		const char *name;
		double v;
	} one[] = {{"jpol", p->jpol},
		   {"jto", p->jto},
		   {"wdto", p->wdto},
		   {"hbmaxd", p->hbmaxd},
		   {"pwrout", p->pwrout}};
	char ref[RE_SEAL_REF_MAX];
	int rc = GL_OK;

	for (size_t k = 0; rc == GL_OK && k < sizeof(ax) / sizeof(ax[0]); k++)
		for (int i = 0; rc == GL_OK && i < DMC_H_AXES; i++) {
			snprintf(ref, sizeof(ref), "%s[%d]", ax[k].name, i);
			rc = re_seal_add(s, RE_SEAL_PARAM, ref, i, ax[k].v[i],
					 0, "test parameter");
		}
	for (int j = 0; rc == GL_OK && j < DMC_H_SWITCHES; j++) {
		snprintf(ref, sizeof(ref), "jin[%d]", j);
		rc = re_seal_add(s, RE_SEAL_PARAM, ref, j / 4, p->jin[j], 0,
				 "test parameter");
	}
	for (int k = 0; rc == GL_OK && k < 6; k++) {
		snprintf(ref, sizeof(ref), "jval[%d]", k);
		rc = re_seal_add(s, RE_SEAL_PARAM, ref, k / 2, p->jval[k], 0,
				 "test parameter");
	}
	for (size_t k = 0; rc == GL_OK && k < sizeof(one) / sizeof(one[0]); k++)
		rc = re_seal_add(s, RE_SEAL_PARAM, one[k].name, -1, one[k].v, 0,
				 "test parameter");
	return rc;
}

/* The controller's settings as the simulator holds them now: the seal
 * takes what the test configured. */
static int seal_settings(struct dmc_h *h, struct re_seal *s)
{
	const struct re_seal_setting *st;
	char ref[RE_SEAL_REF_MAX], cmd[32], resp[64];
	int rc = GL_OK;

	for (int k = 0; rc == GL_OK && (st = re_seal_setting_at(k)); k++)
		for (int i = 0; rc == GL_OK && i < DMC_H_AXES; i++) {
			snprintf(ref, sizeof(ref), "_%s%c", st->cmd, 'A' + i);
			snprintf(cmd, sizeof(cmd), "MG %s", ref);
			rc = dmc_h_cmd(h, cmd, resp, sizeof(resp));
			if (rc == 0)
				rc = re_seal_add(s, RE_SEAL_SETTING, ref, i,
						 strtod(resp, NULL), st->tol,
						 st->what);
		}
	return rc == GL_OK ? re_seal_add_fixed(s) : rc;
}

int dmc_h_sealed_program(struct dmc_h *h, const struct dmc_h_params *p,
			 char *out, size_t cap, struct re_seal *seal)
{
	static char body[DMC_H_PROG_MAX];
	static struct re_seal s;
	int n = dmc_h_load_program(NULL, body, sizeof(body), h->err,
				   sizeof(h->err)),
	    rc, m;

	if (n < 0)
		return n;
	rc = re_seal_start(body, (size_t)n, &s, h->err, sizeof(h->err));
	if (rc == GL_OK)
		rc = seal_params(&s, p);
	if (rc == GL_OK)
		rc = seal_settings(h, &s);
	if (rc == GL_OK)
		rc = re_seal_end(&s);
	if (rc != GL_OK)
		return rc;
	if ((size_t)n + 1 > cap)
		return GL_ERR_OVERFLOW;
	memcpy(out, body, (size_t)n);
	m = re_seal_emit(&s, out + n, cap - (size_t)n);
	if (m < 0) {
		snprintf(h->err, sizeof(h->err), "the seal does not fit");
		return m;
	}
	if (seal)
		*seal = s;
	return n + m;
}

/* ---- simulator set-up -----------------------------------------------------
 */

static void drain(struct dmc_h *h)
{
	uint8_t buf[512];
	size_t n;

	while ((n = ctrl_output(h->ctrl, UNSOL_HANDLE, buf, sizeof(buf))) > 0) {
		for (size_t i = 0; i < n; i++) {
			char c = (char)(buf[i] & 0x7f);

			if (c == '\r' || c == '\0')
				continue;
			if (h->unsol_len + 1 < sizeof(h->unsol))
				h->unsol[h->unsol_len++] = c;
		}
		h->unsol[h->unsol_len] = '\0';
	}
}

int dmc_h_cmd(struct dmc_h *h, const char *line, char *resp, size_t cap)
{
	char r[256], tc[128] = "";

	if (ctrl_command(h->ctrl, line, r, sizeof(r)) == 0) {
		if (resp)
			snprintf(resp, cap, "%s", r);
		return 0;
	}
	ctrl_command(h->ctrl, "TC1", tc, sizeof(tc));
	snprintf(h->err, sizeof(h->err), "'%s' rejected: %s", line, tc);
	if (resp)
		snprintf(resp, cap, "%s", r);
	return GL_ERR_CTRL;
}

int dmc_h_control(struct dmc_h *h, const char *req)
{
	char resp[200];

	if (sim_control(h->sim, req, resp, sizeof(resp)) < 0) {
		snprintf(h->err, sizeof(h->err), "control '%s': %s", req, resp);
		return GL_ERR_ARG;
	}
	return 0;
}

/* ER and OE on the controller, as the supervisor configures them. */
static int write_settings(struct dmc_h *h, const struct dmc_h_params *p)
{
	char line[80];
	int rc;

	snprintf(line, sizeof(line), "ER %g,%g,%g", p->er[0], p->er[1],
		 p->er[2]);
	if ((rc = dmc_h_cmd(h, line, NULL, 0)) < 0)
		return rc;
	snprintf(line, sizeof(line), "OE %d,%d,%d", p->oe, p->oe, p->oe);
	return dmc_h_cmd(h, line, NULL, 0);
}

int dmc_h_open(struct dmc_h *h)
{
	static char prog[DMC_H_PROG_MAX];
	struct dmc_h_params p;
	int n, bad = 0, rc;

	memset(h, 0, sizeof(*h));
	h->hb_period_ms = 50;
	rc = sim_new(&h->sim, NULL, h->err, sizeof(h->err));
	if (rc < 0)
		return rc;
	h->ctrl = sim_ctrl(h->sim);
	ctrl_handle_open(h->ctrl, UNSOL_HANDLE);
	ctrl_handle_open(h->ctrl, QR_HANDLE);
	if ((rc = dmc_h_control(h, "relay on")) < 0 ||
	    (rc = dmc_h_cmd(h, "CF A", NULL, 0)) < 0)
		return rc;
	/* sealed with the default parameters and the controller's settings
	 * as the defaults configure them (ER, OE): dmc_h_configure() seals
	 * the program again with the test's own */
	dmc_h_params_default(&p);
	if ((rc = write_settings(h, &p)) < 0)
		return rc;
	n = dmc_h_sealed_program(h, &p, prog, sizeof(prog), &h->seal);
	if (n < 0)
		return n;
	/* the controller has been on for a while before the download: its
	 * power-up (#AUTO of an empty memory) is over */
	sim_advance_ms(h->sim, 10);
	if (ctrl_download(h->ctrl, prog, (size_t)n, &bad) < 0) {
		snprintf(h->err, sizeof(h->err),
			 "download rejected at program line %d", bad);
		return GL_ERR_CTRL;
	}
	sim_advance_ms(h->sim, 1);
	h->prog_len = (size_t)n;
	memcpy(h->prog, prog, (size_t)n);
	return 0;
}

void dmc_h_close(struct dmc_h *h)
{
	if (h->sim)
		sim_free(h->sim);
	h->sim = NULL;
	h->ctrl = NULL;
}

/* ---- time -----------------------------------------------------------------
 */

double dmc_h_now(const struct dmc_h *h)
{
	return sim_time_ms(h->sim);
}

void dmc_h_advance(struct dmc_h *h, double ms)
{
	double end = dmc_h_now(h) + ms;

	while (dmc_h_now(h) < end - 1e-9) {
		double now = dmc_h_now(h), step = end - now;

		if (h->hb_on) {
			if (now >= h->hb_next_ms - 1e-9) {
				ctrl_set_var(h->ctrl, "hbpc", (double)++h->hb);
				h->hb_next_ms = now + h->hb_period_ms;
			}
			if (h->hb_next_ms - now < step)
				step = h->hb_next_ms - now;
		}
		sim_advance_ms(h->sim, step);
		drain(h);
	}
}

double dmc_h_var(struct dmc_h *h, const char *name)
{
	double v;

	return ctrl_get_var(h->ctrl, name, &v) == 0 ? v : NAN;
}

int dmc_h_set(struct dmc_h *h, const char *name, double v)
{
	if (ctrl_set_var(h->ctrl, name, v) < 0) {
		snprintf(h->err, sizeof(h->err), "cannot set '%s'", name);
		return GL_ERR_NOENT;
	}
	return 0;
}

struct ctrl_axis_info dmc_h_axis(struct dmc_h *h, int axis)
{
	struct ctrl_axis_info ai;

	if (ctrl_axis_info(h->ctrl, axis, &ai) < 0)
		memset(&ai, 0, sizeof(ai));
	return ai;
}

double dmc_h_wait_var(struct dmc_h *h, const char *name, double value,
		      double timeout_ms)
{
	double t0 = dmc_h_now(h);

	for (;;) {
		double v = dmc_h_var(h, name);

		if (!isnan(v) && fabs(v - value) < 1e-6)
			return dmc_h_now(h) - t0;
		if (dmc_h_now(h) - t0 >= timeout_ms)
			return -1;
		dmc_h_advance(h, 1);
	}
}

double dmc_h_wait_motor_off(struct dmc_h *h, unsigned mask, double timeout_ms)
{
	double t0 = dmc_h_now(h);

	for (;;) {
		int all = 1;

		for (int i = 0; i < DMC_H_AXES; i++)
			if ((mask & (1u << i)) && !dmc_h_axis(h, i).motor_off)
				all = 0;
		if (all)
			return dmc_h_now(h) - t0;
		if (dmc_h_now(h) - t0 >= timeout_ms)
			return -1;
		dmc_h_advance(h, 1);
	}
}

/* ---- program start, parameters, arming ---------------------------------- */

int dmc_h_start(struct dmc_h *h)
{
	int rc = dmc_h_cmd(h, "XQ #AUTO,0", NULL, 0);
	double hb0;

	if (rc < 0)
		return rc;
	/* #INIT done when the heartbeat exists */
	for (double t0 = dmc_h_now(h);
	     isnan(dmc_h_var(h, "hbdmc")) || dmc_h_var(h, "state") != 0;) {
		if (dmc_h_now(h) - t0 > 200) {
			snprintf(h->err, sizeof(h->err),
				 "program did not start");
			return GL_ERR_TIMEOUT;
		}
		dmc_h_advance(h, 1);
	}
	dmc_h_advance(h, 20); /* past #INIT after a restart too */
	hb0 = dmc_h_var(h, "hbdmc");
	dmc_h_advance(h, 50);
	if (!(dmc_h_var(h, "hbdmc") > hb0)) {
		snprintf(h->err, sizeof(h->err), "hbdmc does not advance");
		return GL_ERR_TIMEOUT;
	}
	return 0;
}

void dmc_h_params_default(struct dmc_h_params *p)
{
	static const double jin[DMC_H_SWITCHES] = {1, 2, 3,  4,	 5,  6,
						   7, 8, 17, 18, 19, 20};
	static const double vmax[DMC_H_AXES] = {10000, 10000, 8000};
	static const double lim[DMC_H_AXES] = {50000, 50000, 40000};

	memset(p, 0, sizeof(*p));
	for (int i = 0; i < DMC_H_AXES; i++) {
		p->vmax[i] = vmax[i];
		p->vmin[i] = vmax[i] / 4;
		p->wst[i] = 500;
		p->wen[i] = 2000;
		p->stp[i] = 1000;
		p->srev[i] = -(lim[i] - 5000);
		p->sfwd[i] = lim[i] - 5000;
		p->er[i] = 500;
	}
	memcpy(p->jin, jin, sizeof(jin));
	for (int k = 0, v = 3; k < 6; k++, v *= 4)
		p->jval[k] = v;
	p->jpol = 0;
	p->jto = 500;
	p->wdto = 125;
	p->oe = 1;
	p->hbmaxd = 5;
	p->pwrout = 0;
	for (int i = 0; i < DMC_H_AXES; i++) {
		p->potin[i] = i + 1;
		p->potlo[i] = 0.25;
		p->pothi[i] = 4.75;
		p->pnlo[i] = 1.0;
		p->pnhi[i] = 4.0;
		p->svmax[i] = vmax[i];
		p->svslow[i] = vmax[i] / 4;
		p->svdmax[i] = 4 * lim[i];
	}
}

static int set_checked(struct dmc_h *h, const char *name, double v)
{
	double back;

	if (ctrl_set_var(h->ctrl, name, v) < 0 ||
	    ctrl_get_var(h->ctrl, name, &back) < 0 || fabs(back - v) > 1e-4) {
		snprintf(h->err, sizeof(h->err), "cannot set '%s' to %g", name,
			 v);
		return GL_ERR_MISMATCH;
	}
	return 0;
}

static int set_array(struct dmc_h *h, const char *name, const double *v, int n)
{
	char el[32];
	int rc;

	for (int i = 0; i < n; i++) {
		snprintf(el, sizeof(el), "%s[%d]", name, i);
		if ((rc = set_checked(h, el, v[i])) < 0)
			return rc;
	}
	return 0;
}

int dmc_h_configure(struct dmc_h *h, const struct dmc_h_params *p)
{
	static char prog[DMC_H_PROG_MAX];
	static struct re_seal seal;
	int n, bad = 0, rc, running;

	if ((rc = write_settings(h, p)) < 0)
		return rc;

	n = dmc_h_sealed_program(h, p, prog, sizeof(prog), &seal);
	if (n < 0)
		return n;
	/* the program holds the test's parameters as its seal: loaded again
	 * (and restarted when it ran) when they are not the ones it holds */
	if ((size_t)n != h->prog_len || memcmp(prog, h->prog, (size_t)n)) {
		running = (ctrl_threads(h->ctrl) & 1u) != 0;
		if ((rc = dmc_h_cmd(h, "prun=0;HX", NULL, 0)) < 0)
			return rc;
		if (ctrl_download(h->ctrl, prog, (size_t)n, &bad) < 0) {
			snprintf(h->err, sizeof(h->err),
				 "download rejected at program line %d", bad);
			return GL_ERR_CTRL;
		}
		h->prog_len = (size_t)n;
		memcpy(h->prog, prog, (size_t)n);
		h->seal = seal;
		if (running && (rc = dmc_h_start(h)) < 0)
			return rc;
	}
	/* the session's values: the soft limits */
	if ((rc = set_array(h, "srev", p->srev, DMC_H_AXES)) < 0 ||
	    (rc = set_array(h, "sfwd", p->sfwd, DMC_H_AXES)) < 0)
		return rc;
	return 0;
}

/* Set @req to 1 with the heartbeat on, wait for @want (or a latch). */
static int request_state(struct dmc_h *h, const char *req, double want)
{
	double t0 = dmc_h_now(h);
	int rc;

	h->hb_on = 1;
	h->hb_next_ms = t0;
	dmc_h_advance(h, 1);
	if ((rc = dmc_h_set(h, req, 1)) < 0)
		return rc;
	while (dmc_h_now(h) - t0 < 1000) {
		double st = dmc_h_var(h, "state");

		if (st == want)
			return 0;
		if (st == 2) {
			dmc_h_advance(h, 10); /* the FAULT line */
			snprintf(
			    h->err, sizeof(h->err),
			    "%s refused: fault %g axis %g detail %g line %g",
			    req, dmc_h_var(h, "fcode"), dmc_h_var(h, "faxis"),
			    dmc_h_var(h, "fdet"), dmc_h_var(h, "fline"));
			return GL_ERR_CTRL;
		}
		dmc_h_advance(h, 1);
	}
	snprintf(h->err, sizeof(h->err), "%s: state %g after 1000 ms", req,
		 dmc_h_var(h, "state"));
	return GL_ERR_TIMEOUT;
}

int dmc_h_service(struct dmc_h *h)
{
	return request_state(h, "svcreq", 3);
}

int dmc_h_move(struct dmc_h *h, int axis, double target, double speed,
	       double limit_ms)
{
	char name[32];
	double t0;
	int rc = 0;

	for (int i = 0; i < DMC_H_AXES && rc == 0; i++) {
		snprintf(name, sizeof(name), "mvax[%d]", i);
		rc = dmc_h_set(h, name, i == axis);
	}
	snprintf(name, sizeof(name), "mvtg[%d]", axis);
	if (rc == 0)
		rc = dmc_h_set(h, name, target);
	snprintf(name, sizeof(name), "mvsp[%d]", axis);
	if (rc == 0)
		rc = dmc_h_set(h, name, speed);
	if (rc == 0)
		rc = dmc_h_set(h, "mvto", limit_ms);
	if (rc == 0)
		rc = dmc_h_set(h, "mvreq", 1);
	if (rc < 0)
		return rc;
	t0 = dmc_h_now(h);
	while (dmc_h_var(h, "mvreq") != 0 && dmc_h_now(h) - t0 < 30)
		dmc_h_advance(h, 1);
	if (dmc_h_var(h, "state") == 2) {
		snprintf(h->err, sizeof(h->err),
			 "move refused: fault %g axis %g detail %g",
			 dmc_h_var(h, "fcode"), dmc_h_var(h, "faxis"),
			 dmc_h_var(h, "fdet"));
		return GL_ERR_CTRL;
	}
	if (dmc_h_var(h, "mvreq") != 0) {
		snprintf(h->err, sizeof(h->err), "move not taken in 30 ms");
		return GL_ERR_TIMEOUT;
	}
	return 0;
}

int dmc_h_arm(struct dmc_h *h)
{
	int rc = request_state(h, "armreq", 1);

	if (rc == 0)
		dmc_h_advance(h, 30); /* thread 1 runs and sees neutral */
	return rc;
}

int dmc_h_setup_with(struct dmc_h *h, const char *settings)
{
	struct dmc_h_params p;
	int rc;

	dmc_h_params_default(&p);
	if ((rc = dmc_h_open(h)) < 0 || (rc = dmc_h_start(h)) < 0)
		return rc;
	if (settings && (rc = dmc_h_cmd(h, settings, NULL, 0)) < 0)
		return rc;
	if ((rc = dmc_h_configure(h, &p)) < 0 || (rc = dmc_h_arm(h)) < 0)
		return rc;
	return 0;
}

int dmc_h_setup(struct dmc_h *h)
{
	return dmc_h_setup_with(h, NULL);
}

/* ---- what the program reported --------------------------------------------
 */

int dmc_h_fault_lines(const struct dmc_h *h, int *code, int *axis,
		      double *detail)
{
	const char *p = h->unsol;
	int n = 0;

	while (*p) {
		const char *eol = strchr(p, '\n');

		if (!eol)
			break; /* a partial line is not a line yet */
		if (!strncmp(p, "FAULT", 5)) {
			if (n++ == 0) {
				char *e;
				double c = strtod(p + 5, &e);
				double a = strtod(e, &e);
				double d = strtod(e, &e);

				if (code)
					*code = (int)c;
				if (axis)
					*axis = (int)a;
				if (detail)
					*detail = d;
			}
		}
		p = eol + 1;
	}
	return n;
}

int dmc_h_unsol_has(const struct dmc_h *h, const char *prefix)
{
	size_t n = strlen(prefix);

	for (const char *p = h->unsol; *p;) {
		const char *eol = strchr(p, '\n');

		while (*p == ' ')
			p++;
		if (!strncmp(p, prefix, n))
			return 1;
		if (!eol)
			break;
		p = eol + 1;
	}
	return 0;
}

static long rd_sl(const uint8_t *b)
{
	uint32_t u = (uint32_t)b[0] | ((uint32_t)b[1] << 8) |
		     ((uint32_t)b[2] << 16) | ((uint32_t)b[3] << 24);

	return (long)(int32_t)u;
}

int dmc_h_za(struct dmc_h *h, struct dmc_h_za *za)
{
	static const uint8_t qr[] = "QR\r";
	uint8_t rec[512];
	size_t n = 0, got;
	long zb, zc;

	/* the reply comes at once: the interpreter answers between samples */
	ctrl_input(h->ctrl, QR_HANDLE, qr, sizeof(qr) - 1);
	while ((got = ctrl_output(h->ctrl, QR_HANDLE, rec + n,
				  sizeof(rec) - n)) > 0)
		n += got;
	if (n < REC_AXIS0 + 3 * REC_AXIS_LEN + 1 || rec[n - 1] != ':' ||
	    (size_t)(rec[2] | (rec[3] << 8)) != n - 1) {
		snprintf(h->err, sizeof(h->err), "QR: %zu bytes", n);
		return GL_ERR_NOENT;
	}
	za->hbdmc = rd_sl(rec + REC_AXIS0 + REC_ZA);
	zb = rd_sl(rec + REC_AXIS0 + REC_AXIS_LEN + REC_ZA);
	zc = rd_sl(rec + REC_AXIS0 + 2 * REC_AXIS_LEN + REC_ZA);
	za->state = (int)(zb % 10);
	za->fcode = (int)(zb / 10 % 100);
	za->faxis = (int)(zb / 1000 % 10);
	za->hb_echo = zb / 10000;
	za->jraw = (int)(zc % 4096);
	za->jcmd = (int)(zc / 4096 % 8) - 1;
	za->mcmd = (int)(zc / 32768 % 8);
	za->mneut = (int)(zc / 262144);
	return 0;
}

double dmc_h_ramp_vel(const struct dmc_h_params *p, int ax, double t_ms)
{
	if (t_ms < p->wst[ax])
		return p->vmin[ax];
	if (t_ms >= p->wen[ax])
		return p->vmax[ax];
	return p->vmin[ax] + (p->vmax[ax] - p->vmin[ax]) * (t_ms - p->wst[ax]) /
				 (p->wen[ax] - p->wst[ax]);
}

/* ---- cmocka fixtures --------------------------------------------------------
 */

int dmc_h_fx_new(void **state)
{
	*state = calloc(1, sizeof(struct dmc_h));
	return *state ? 0 : -1;
}

int dmc_h_fx_armed(void **state)
{
	struct dmc_h *h;

	if (dmc_h_fx_new(state) < 0)
		return -1;
	h = *state;
	if (dmc_h_setup(h) < 0) {
		fprintf(stderr, "set-up: %s\n", h->err);
		return -1;
	}
	return 0;
}

int dmc_h_fx_free(void **state)
{
	struct dmc_h *h = *state;

	if (h)
		dmc_h_close(h);
	free(h);
	*state = NULL;
	return 0;
}
