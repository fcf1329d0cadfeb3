/*
 * test_re_traceshow.c - the gnuplot script of roboelf-tech show-trace, as
 * text (no gnuplot run; test_sys_trace draws a real trace): the commands
 * in words, phase, relay and link on lanes of their own, the fault's word
 * above the panels, positions in the console's units (deg, mm) when the
 * configuration is the trace's, in counts otherwise.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "re_trace.h"
#include "re_traceshow.h"

static char *script_of(const struct re_traceshow_units *u)
{
	static struct re_trace_hdr h;
	char *text = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&text, &len);

	memset(&h, 0, sizeof(h));
	h.version = RE_TRACE_VERSION;
	snprintf(h.reason, sizeof(h.reason), "fault");
	snprintf(h.serial, sizeof(h.serial), "403001");
	h.config_hash = 0x8604de435a5f9618ULL;
	h.period_ms = 10;
	h.n_axes = 3;
	snprintf(h.axis[0], sizeof(h.axis[0]), "A");
	snprintf(h.axis[1], sizeof(h.axis[1]), "B");
	snprintf(h.axis[2], sizeof(h.axis[2]), "C");
	h.have_fault = 1;
	h.fault_t_s = 12.5;
	snprintf(h.fault_text, sizeof(h.fault_text), "FAULT ENCODER: axis B");
	assert_non_null(f);
	re_traceshow_script(f, "/tmp/t.csv", &h, NULL, u);
	fclose(f);
	return text;
}

static void has(const char *text, const char *want)
{
	if (!strstr(text, want))
		fail_msg("the script lacks\n%s\nin\n%s", want, text);
}

static const struct re_traceshow_units units = {
    "cfg.yaml",	     0x8604de435a5f9618ULL, 3,
    {"A", "B", "C"}, {"deg", "deg", "mm"},  {1000, 1000, 1000}};

/* The timing page: words for the commands, a lane per state, the fault's
 * label above the panel (graph 1, raised), no code ranges. */
static void test_timing_words(void **state)
{
	char *t = script_of(&units);

	(void)state;
	has(t, "set output '/tmp/t-timing.png'\n");
	has(t, "set ylabel 'command'\nset ytics ('invalid' -1, 'none' 0, "
	       "'A fwd' 1, 'A rev' 2, 'B fwd' 3, 'B rev' 4, 'C fwd' 5, "
	       "'C rev' 6)\nset yrange [-1.5:6.5]\n");
	has(t, "title 'joystick', '' using 't_s':'mcmd' with steps lw 2 lc "
	       "rgb 'black' title 'motion'\n");
	has(t, "set ylabel 'state'\nset ytics ('start-up' 0, 'service' 1, "
	       "'armed' 2, 'FAULT' 3, 'relay unconfirmed' 4.5, 'relay off' "
	       "5.5, 'relay on' 6.5, 'link lost' 8, 'link ok' 9)\n");
	has(t, "set label 1 'FAULT' at 12.500000, graph 1 center offset 0,0.7 "
	       "tc rgb 'red' front\n");
	has(t, "set lmargin at screen 0.20\n");
	assert_null(strstr(t, "0..6"));
	assert_null(strstr(t, "graph 0.93"));
	free(t);
}

/* Positions as the console shows them: deg for A and B, mm for C. */
static void test_units(void **state)
{
	char *t = script_of(&units);

	(void)state;
	has(t, "axis A, in deg (1000 counts/deg) (fault, controller 403001");
	has(t, "set ylabel 'position, deg'\nplot file using "
	       "'t_s':(column('A_enc') / 1000) with steps lw 2 title "
	       "'encoder', '' using 't_s':(column('A_ref') / 1000) with "
	       "steps dt 2 title 'commanded (_RP)'\n");
	has(t, "set ylabel 'velocity, deg/s'\n");
	has(t, "set ylabel 'position, mm'\nplot file using "
	       "'t_s':(column('C_enc') / 1000)");
	assert_null(strstr(t, "position, counts"));
	assert_null(strstr(t, "counts/s"));
	free(t);
}

/* Another configuration (or none): counts, said in the title. */
static void test_other_config(void **state)
{
	struct re_traceshow_units other = units;
	char *t;

	(void)state;
	other.config_hash ^= 1;
	t = script_of(&other);
	has(t, "axis B, in counts (fault");
	has(t, "set ylabel 'position, counts'\nplot file using "
	       "'t_s':(column('B_enc') / 1) with steps");
	assert_null(strstr(t, "deg"));
	free(t);
	t = script_of(NULL);
	has(t, "set ylabel 'velocity, counts/s'\n");
	free(t);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_timing_words),
	    cmocka_unit_test(test_units),
	    cmocka_unit_test(test_other_config),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
