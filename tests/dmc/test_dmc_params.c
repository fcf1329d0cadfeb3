/*
 * test_dmc_params.c - the parameter check at arm (docs/dmc-interface.md
 * "Parameter checks"): each broken parameter is refused with fault 1 PARAM,
 * fdet = the number of the failed check and faxis = its axis, the motors stay
 * off and one FAULT line is sent.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "dmc_h.h"

struct pcase {
	const char *what;
	const char *var; /* program parameter to break, or NULL */
	double value;
	const char *cmd; /* controller commands before arming, or NULL */
	int check, axis; /* expected fdet, faxis */
	int moving;	 /* 1: arm from service while a move of B runs */
};

/* Each case breaks one thing of the defaults (dmc_h_params_default()). */
static const struct pcase cases[] = {
    {"vmax B = 0", "vmax[1]", 0, NULL, 1, 2, 0},
    {"vmax A > SP range", "vmax[0]", 15000001, NULL, 1, 1, 0},
    {"vmax C: AC below 1024", "vmax[2]", 100, NULL, 1, 3, 0},
    {"vmin A = 0", "vmin[0]", 0, NULL, 2, 1, 0},
    {"vmin C > vmax C", "vmin[2]", 8001, NULL, 2, 3, 0},
    {"wst B < 0", "wst[1]", -1, NULL, 3, 2, 0},
    {"wen A = wst A", "wen[0]", 500, NULL, 4, 1, 0},
    {"stp C = 0", "stp[2]", 0, NULL, 5, 3, 0},
    {"srev B = sfwd B", "srev[1]", 45000, NULL, 6, 2, 0},
    {"ER B = stp B", NULL, 0, "ER ,1000", 7, 2, 0},
    {"ER C off", NULL, 0, "ER ,,-1", 7, 3, 0},
    {"OE off", NULL, 0, "OE 0,0,0", 8, 1, 0},
    {"OE C off", NULL, 0, "OE ,,0", 8, 3, 0},
    {"jin[5] = 0", "jin[5]", 0, NULL, 10, 0, 0},
    {"jin[11] = 49", "jin[11]", 49, NULL, 10, 0, 0},
    {"jin[11] = 9 (no input 9 on a DMC-4030)", "jin[11]", 9, NULL, 10, 0, 0},
    {"jin[0] = 16 (no input 16 on a DMC-4030)", "jin[0]", 16, NULL, 10, 0, 0},
    {"jin[3] = 2.5", "jin[3]", 2.5, NULL, 10, 0, 0},
    {"jin[7] = jin[2]", "jin[7]", 3, NULL, 11, 0, 0},
    {"jval[4] = 3", "jval[4]", 3, NULL, 12, 0, 0},
    {"jpol = 2", "jpol", 2, NULL, 13, 0, 0},
    {"jto = 49", "jto", 49, NULL, 14, 0, 0},
    {"jto = 5001", "jto", 5001, NULL, 14, 0, 0},
    {"wdto = 19", "wdto", 19, NULL, 15, 0, 0},
    {"wdto = 5001", "wdto", 5001, NULL, 15, 0, 0},
    {"TM 500", NULL, 0, "TM 500", 16, 0, 0},
    {"axis B moving (a service move)", NULL, 0, NULL, 17, 0, 1},
    {"pwrout = 9", "pwrout", 9, NULL, 18, 0, 0},
    {"pwrout = 1.5", "pwrout", 1.5, NULL, 18, 0, 0},
    {"potin B = 0", "potin[1]", 0, NULL, 19, 2, 0},
    {"potin C = 9", "potin[2]", 9, NULL, 19, 3, 0},
    {"potin A = 1.5", "potin[0]", 1.5, NULL, 19, 1, 0},
    {"potlo A = pnlo A", "potlo[0]", 1.0, NULL, 20, 1, 0},
    {"pnhi B = pnlo B", "pnhi[1]", 1.0, NULL, 20, 2, 0},
    {"pnhi C = pothi C", "pnhi[2]", 4.75, NULL, 20, 3, 0},
    {"svslow A = 0", "svslow[0]", 0, NULL, 21, 1, 0},
    {"svslow B > svmax B", "svslow[1]", 10001, NULL, 21, 2, 0},
    {"svdmax C = 0", "svdmax[2]", 0, NULL, 22, 3, 0},
    {"hbmaxd = 0", "hbmaxd", 0, NULL, 23, 0, 0},
    {"hbmaxd = 2.5", "hbmaxd", 2.5, NULL, 23, 0, 0},
    {"svmax A > SP range", "svmax[0]", 15000001, NULL, 24, 1, 0},
    {"svmax B: AC below 1024", "svmax[1]", 100, NULL, 21, 2, 0},
};

static void run_case(struct dmc_h *h, const struct pcase *c)
{
	struct dmc_h_params p;
	int code = -1, axis = -1;
	double det = -1;

	dmc_h_params_default(&p);
	if (dmc_h_open(h) < 0 || dmc_h_start(h) < 0 ||
	    dmc_h_configure(h, &p) < 0)
		fail_msg("%s: set-up: %s", c->what, h->err);
	if (c->var && dmc_h_set(h, c->var, c->value) < 0)
		fail_msg("%s: %s", c->what, h->err);
	if (c->cmd) {
		char cmd[80], *save = NULL;

		snprintf(cmd, sizeof(cmd), "%s", c->cmd);
		for (char *s = strtok_r(cmd, ";", &save); s;
		     s = strtok_r(NULL, ";", &save))
			if (dmc_h_cmd(h, s, NULL, 0) < 0)
				fail_msg("%s: %s", c->what, h->err);
		dmc_h_advance(h, 20);
	}
	if (c->moving &&
	    (dmc_h_service(h) < 0 || dmc_h_move(h, 1, 20000, 5000, 10000) < 0))
		fail_msg("%s: service move: %s", c->what, h->err);
	if (dmc_h_arm(h) != GL_ERR_CTRL)
		fail_msg("%s: armed (or timed out): %s", c->what, h->err);
	if (dmc_h_var(h, "fcode") != 1 || dmc_h_var(h, "fdet") != c->check ||
	    dmc_h_var(h, "faxis") != c->axis)
		fail_msg("%s: fault %g axis %g detail %g, want 1 %d %d",
			 c->what, dmc_h_var(h, "fcode"), dmc_h_var(h, "faxis"),
			 dmc_h_var(h, "fdet"), c->axis, c->check);
	assert_int_equal(dmc_h_fault_lines(h, &code, &axis, &det), 1);
	assert_int_equal(code, 1);
	assert_int_equal(axis, c->axis);
	assert_true(det == c->check);
	assert_true(dmc_h_var(h, "state") == 2);
	/* motors off, thread 1 never started, nothing moves (a service move
	 * is aborted by the latch) */
	dmc_h_advance(h, 200);
	for (int i = 0; i < DMC_H_AXES; i++)
		if (!dmc_h_axis(h, i).motor_off)
			fail_msg("%s: axis %d motor on", c->what, i);
	if (ctrl_threads(h->ctrl) != 1u)
		fail_msg("%s: threads %#x", c->what, ctrl_threads(h->ctrl));
}

/* Each broken parameter alone, from the defaults. */
static void test_each_check(void **state)
{
	struct dmc_h *h = *state;

	for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		run_case(h, &cases[i]);
		dmc_h_close(h);
	}
}

/* The defaults themselves pass (so the cases above fail for their edit). */
static void test_defaults_arm(void **state)
{
	struct dmc_h *h = *state;

	if (dmc_h_setup(h) < 0)
		fail_msg("%s", h->err);
	assert_true(dmc_h_var(h, "state") == 1);
	assert_true(dmc_h_var(h, "fcode") == 0);
}

/* An active-low joystick map (jpol 1) arms too. */
static void test_jpol1_arms(void **state)
{
	struct dmc_h *h = *state;
	struct dmc_h_params p;

	dmc_h_params_default(&p);
	p.jpol = 1;
	if (dmc_h_open(h) < 0 || dmc_h_start(h) < 0 ||
	    dmc_h_configure(h, &p) < 0)
		fail_msg("%s", h->err);
	/* released switches read high with jpol 1 */
	for (int i = 0; i < DMC_H_SWITCHES; i++) {
		char req[32];

		snprintf(req, sizeof(req), "in %d 1", (int)p.jin[i]);
		if (dmc_h_control(h, req) < 0)
			fail_msg("%s", h->err);
	}
	if (dmc_h_arm(h) < 0)
		fail_msg("%s", h->err);
	dmc_h_advance(h, 100);
	assert_true(dmc_h_var(h, "jcmd") == 0);
	assert_true(dmc_h_var(h, "state") == 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_defaults_arm, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_each_check, dmc_h_fx_new,
					    dmc_h_fx_free),
	    cmocka_unit_test_setup_teardown(test_jpol1_arms, dmc_h_fx_new,
					    dmc_h_fx_free),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
