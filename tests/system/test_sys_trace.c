/*
 * test_sys_trace.c - the flight recorder on the whole system:
 * galil-sim running dmc/, roboelf supervising it.
 *
 *  - a potentiometer offset step and a link stall (watchdog): the FAULT log
 *    entry names a trace; the trace is written after recorder.after_fault_s
 *    (never before: it does not exist while the entry is new), parses
 *    strictly, holds the cycles before the fault, the fault cycle (phase
 *    FAULT, the fault's id) and after_fault_s after it; its values agree
 *    with galil-sim's own record of the injection: the pot step appears in
 *    the first record the controller sampled at or after the injection's
 *    simulated time (the record's sample number is galil-sim's clock in
 *    1 ms samples), within one period of it, and no record sampled before
 *    it shows the step; after a link stall no good reply carries a record
 *    sampled after the stall began;
 *  - SIGKILL while a trace is being written (its NAME.tmp seen in the
 *    directory): every trace under a final name still parses as complete,
 *    the traces written before are byte for byte intact, and a left
 *    NAME.tmp never parses as complete unless it is complete;
 *  - roboelf-tech show-trace: exit 0, one PNG per axis plus the timing page,
 *    each a PNG (signature, IHDR 1200 x 1020, the timing page 1200 x
 *    1320); truncated, wrong-version,
 *    garbage and huge files and an empty window: exit 2 with the reason.
 *
 * Environment as the other system tests (sys_h.h); ROBOELF_SYS_FILTER.
 */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_file.h"
#include "gl_err.h"
#include "re_fault.h"
#include "re_trace.h"
#include "sys_h.h"

#define FAULT_WAIT_MS 8000
#define TRACE_WAIT_MS 10000 /* after_fault_s (2 s) plus the write */
#define EXIT_WAIT_MS  5000
#define AFTER_S	      2.0 /* recorder.after_fault_s of config/roboelf.yaml */

static struct sys_env env;
static int env_ok;
static struct sys_case cs;
static char pot_trace[SYS_PATH_MAX]; /* for the show-trace test */

static double P(void)
{
	return env.period_ms;
}

static void start(struct sys_case *c, const struct sys_opts *o)
{
	if (!env_ok)
		fail_msg("no calibrated environment: %s", env.err);
	if (sys_case_start(c, &env, o) < 0)
		fail_msg("%s", c->err);
}

/* Inject @req and return the simulated ms of galil-sim's event for it. */
static double inject(struct sys_case *c, const char *prefix, const char *req)
{
	char want[300];
	double before = sys_sim_time(c), t;

	if (before < 0 || sys_ctl(c, "%s", req) < 0)
		fail_msg("%s", c->err);
	snprintf(want, sizeof(want), "%s%s", prefix, req);
	if (sys_wait_event(c, want, before, 2000, &t) < 0)
		fail_msg("%s", c->err);
	return t;
}

/* The path the FAULT log entry names ("... | trace PATH"). */
static void fault_trace_path(struct sys_case *c, char *path, size_t cap)
{
	char line[4096];
	const char *p;

	if (sys_log_find(c, " FAULT ", "| trace ", line, sizeof(line)) < 0)
		fail_msg("%s", c->err);
	p = strstr(line, "| trace ") + 8;
	snprintf(path, cap, "%.*s", (int)strcspn(p, " |"), p);
}

/* Wait for the log line "trace: PATH written". */
static void wait_written(struct sys_case *c, const char *path, int ms)
{
	char want[SYS_PATH_MAX + 16];
	long long end = proc_now_ms() + ms;

	snprintf(want, sizeof(want), "trace: %s written", path);
	while (sys_log_find(c, want, NULL, NULL, 0) < 0) {
		if (proc_now_ms() > end)
			fail_msg("no '%s' in the log within %d ms", want, ms);
		usleep(20000);
	}
}

static int load_trace(const char *path, struct re_trace_hdr *h,
		      struct re_trace_rec **r, char *err, size_t errlen)
{
	char *buf;
	size_t len;
	int rc = base_file_read(path, RE_TRACE_MAX_BYTES, &buf, &len);

	if (rc < 0) {
		snprintf(err, errlen, "cannot read: %s", strerror(-rc));
		return rc;
	}
	rc = re_trace_parse(buf, len, h, r, err, errlen);
	free(buf);
	return rc;
}

static void must_load(const char *path, struct re_trace_hdr *h,
		      struct re_trace_rec **r)
{
	char err[512];

	if (load_trace(path, h, r, err, sizeof(err)) != GL_OK)
		fail_msg("trace '%s' refused: %s", path, err);
}

/* The record's sample number (16-bit galil-sim ms) as simulated ms, the
 * 65.536 s wrap taken nearest to @near_ms. */
static double sample_ms(int32_t sample, double near_ms)
{
	double k = round((near_ms - sample) / 65536.0);

	return sample + 65536.0 * k;
}

/* Index of the fault cycle (the first in phase FAULT); checks the header
 * and the cycles around it. */
static size_t check_fault_rows(const struct re_trace_hdr *h,
			       const struct re_trace_rec *r,
			       enum re_fault_id id)
{
	size_t f = 0;

	assert_string_equal(h->reason, "fault");
	assert_int_equal(h->have_fault, 1);
	assert_int_equal(strncmp(h->fault_text, "FAULT ", 6), 0);
	assert_string_not_equal(h->serial, "-");
	assert_float_equal(h->period_ms, P(), 1e-9);
	while (f < h->n_records && r[f].phase != RE_TPH_FAULT)
		f++;
	if (f == h->n_records)
		fail_msg("no cycle in phase FAULT among %u", h->n_records);
	print_message("[ MEASURE  ] trace: %u cycles, %zu before the fault "
		      "cycle, %.3f s after it\n",
		      h->n_records, f, r[h->n_records - 1].t_s - r[f].t_s);
	assert_int_equal(r[f].fault, id);
	assert_float_equal(r[f].t_s, h->fault_t_s, 0.5 * P() / 1000);
	assert_true(f >= 3); /* the cycles before it */
	assert_int_equal(r[f - 1].phase, RE_TPH_ARMED);
	for (size_t k = f; k < h->n_records; k++)
		assert_int_equal(r[k].phase, RE_TPH_FAULT);
	/* after_fault_s after it, to within a period and the write */
	assert_true(r[h->n_records - 1].t_s - h->fault_t_s >=
		    AFTER_S - P() / 1000);
	for (size_t k = 1; k < h->n_records; k++)
		assert_true(r[k].cycle == r[k - 1].cycle + 1);
	return f;
}

/* ---- the potentiometer step -------------------------------------------- */

static void test_trace_pot_offset(void **state)
{
	struct re_trace_hdr h;
	struct re_trace_rec *r;
	char line[1024];
	double t_inj, first_ms = -1;
	size_t f, k;

	(void)state;
	start(&cs, NULL);
	/* a second armed at rest first: history before the fault */
	if (sys_wait_sim(&cs, cs.t_ready_ms + 1000, 3000) < 0)
		fail_msg("%s", cs.err);
	t_inj = inject(&cs, "inject: ", "pot A offset 0.5");
	if (sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	fault_trace_path(&cs, pot_trace, sizeof(pot_trace));
	wait_written(&cs, pot_trace, TRACE_WAIT_MS);
	must_load(pot_trace, &h, &r);
	f = check_fault_rows(&h, r, RE_F_ENCPOT);
	assert_true(f >= 1000 / P()); /* the second before it */
	/* sampled before the injection: no step (a record sampled in the
	 * injection's own millisecond may or may not hold it) */
	for (k = 0; k < h.n_records; k++)
		if (r[k].sample >= 0 && sample_ms(r[k].sample, t_inj) < t_inj &&
		    !isnan(r[k].axis[0].pot_exp_v))
			assert_true(fabs(r[k].axis[0].pot_v -
					 r[k].axis[0].pot_exp_v) < 0.1);
	/* the step: the first record that holds it */
	for (k = 1; k < h.n_records; k++)
		if (r[k].sample >= 0 && r[k - 1].sample >= 0 &&
		    r[k].axis[0].pot_v - r[k - 1].axis[0].pot_v > 0.45)
			break;
	if (k == h.n_records)
		fail_msg("no step of 0.5 V in axis A's potentiometer in the "
			 "trace (injected at %.0f ms)",
			 t_inj);
	first_ms = sample_ms(r[k].sample, t_inj);
	print_message("[ MEASURE  ] pot step: injected at %.0f ms (galil-sim), "
		      "first in the record sampled at %.0f ms (P %.0f ms), "
		      "cycle %zu of %u, the fault cycle %zu\n",
		      t_inj, first_ms, P(), k, h.n_records, f);
	assert_true(first_ms >= t_inj && first_ms - t_inj <= P() + 1);
	assert_true(r[k].axis[0].margin_v < 0);
	assert_true(k < f);
	free(r);
	sys_case_stop(&cs);
}

/* ---- the watchdog: a link stall ----------------------------------------- */

static void test_trace_link_stall(void **state)
{
	struct re_trace_hdr h;
	struct re_trace_rec *r;
	char line[1024], path[SYS_PATH_MAX];
	double t_inj;
	size_t f, last_ok = 0;

	(void)state;
	start(&cs, NULL);
	inject(&cs, "input: ", "joy B fwd");
	if (sys_wait_moving(&cs, 'B', 200, 5000) < 0)
		fail_msg("%s", cs.err);
	t_inj = inject(&cs, "inject: ", "link stall");
	if (sys_wait_fault(&cs, FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	fault_trace_path(&cs, path, sizeof(path));
	wait_written(&cs, path, TRACE_WAIT_MS);
	must_load(path, &h, &r);
	f = check_fault_rows(&h, r, sys_stall_fault());
	assert_int_equal(r[f].link_ok, 0);
	for (size_t k = 0; k < f; k++) {
		if (!r[k].link_ok)
			continue;
		last_ok = k;
		/* a good reply carries a record sampled before the stall */
		assert_true(sample_ms(r[k].sample, t_inj) <= t_inj + 1);
	}
	/* B moved under the joystick before it */
	assert_true(r[last_ok].axis[1].moving == 1 ||
		    fabs(r[last_ok].axis[1].vel_cps) > 0);
	print_message("[ MEASURE  ] link stall at %.0f ms: last good reply "
		      "%.0f ms before the fault (critical %.0f ms)\n",
		      t_inj, 1000 * (h.fault_t_s - r[last_ok].t_s),
		      env.crit_factor * P());
	assert_true(1000 * (h.fault_t_s - r[last_ok].t_s) >=
		    env.crit_factor * P() - 1);
	free(r);
	sys_case_stop(&cs);
}

/* ---- SIGKILL while writing ---------------------------------------------- */

/* The written traces named in the log, in order. */
static int written(struct sys_case *c, char paths[][SYS_PATH_MAX], int max)
{
	char *buf, *p;
	size_t len;
	int n = 0;

	if (base_file_read(c->log, 1 << 24, &buf, &len) < 0)
		return 0;
	for (p = buf; (p = strstr(p, "trace: ")) && n < max; p += 7) {
		const char *e = strstr(p, " written (");
		const char *nl = strchr(p, '\n');

		if (e && (!nl || e < nl))
			snprintf(paths[n++], SYS_PATH_MAX, "%.*s",
				 (int)(e - p - 7), p + 7);
	}
	free(buf);
	return n;
}

static int ask_trace(struct sys_case *c, char paths[][SYS_PATH_MAX], int n)
{
	long long end = proc_now_ms() + TRACE_WAIT_MS;

	proc_signal(&c->re, SIGUSR1);
	while (written(c, paths, 8) < n + 1) {
		if (proc_now_ms() > end)
			fail_msg("SIGUSR1: no trace %d written", n + 1);
		usleep(10000);
	}
	return n + 1;
}

/* A NAME.tmp of a trace in env.dir: 1 (its name in @tmp), else 0. */
static int tmp_present(char *tmp, size_t cap)
{
	DIR *d = opendir(env.dir);
	struct dirent *e;
	int found = 0;

	while (d && !found && (e = readdir(d))) {
		size_t n = strlen(e->d_name);

		if (!strncmp(e->d_name, "roboelf-trace-", 14) && n > 8 &&
		    !strcmp(e->d_name + n - 8, ".csv.tmp")) {
			snprintf(tmp, cap, "%s/%s", env.dir, e->d_name);
			found = 1;
		}
	}
	if (d)
		closedir(d);
	return found;
}

/* Every trace under a final name in env.dir parses; returns how many. */
static int all_final_parse(void)
{
	DIR *d = opendir(env.dir);
	struct dirent *e;
	int n = 0;

	assert_non_null(d);
	while ((e = readdir(d))) {
		char path[SYS_PATH_MAX];
		size_t l = strlen(e->d_name);
		struct re_trace_hdr h;
		struct re_trace_rec *r;

		if (strncmp(e->d_name, "roboelf-trace-", 14) || l < 4 ||
		    strcmp(e->d_name + l - 4, ".csv"))
			continue;
		snprintf(path, sizeof(path), "%s/%s", env.dir, e->d_name);
		must_load(path, &h, &r);
		free(r);
		n++;
	}
	closedir(d);
	return n;
}

static void test_trace_sigkill_while_writing(void **state)
{
	static const struct sys_subst big[] = {{"seconds", "120"},
					       {NULL, NULL}};
	struct sys_opts o = {.subst = big};
	char paths[8][SYS_PATH_MAX], tmp[SYS_PATH_MAX], err[512];
	char *before[2];
	size_t blen[2], tlen;
	long long end;
	int n = 0, st, seen = 0, attempt;

	(void)state;
	start(&cs, &o);
	/* 5 s armed: a trace of some 100 cycles takes a while to write */
	if (sys_wait_sim(&cs, cs.t_ready_ms + 5000, 8000) < 0)
		fail_msg("%s", cs.err);
	n = ask_trace(&cs, paths, n);
	n = ask_trace(&cs, paths, n);
	for (int i = 0; i < 2; i++)
		assert_int_equal(
		    base_file_read(paths[i], 1 << 26, &before[i], &blen[i]), 0);
	/* the write lasts milliseconds: on a busy machine this poll may miss
	 * it (the trace is then written whole); ask again, up to 5 times */
	for (attempt = 1; attempt <= 5 && !seen; attempt++) {
		proc_signal(&cs.re, SIGUSR1);
		end = proc_now_ms() + 3000;
		while (!(seen = tmp_present(tmp, sizeof(tmp))) &&
		       proc_now_ms() < end)
			; /* tight */
	}
	proc_signal(&cs.re, SIGKILL);
	if (proc_wait_exit(&cs.re, EXIT_WAIT_MS, &st) < 0)
		fail_msg("roboelf did not die of SIGKILL");
	if (!seen)
		fail_msg("no trace being written seen within 3 s of SIGUSR1, "
			 "5 times");
	for (int i = 0; i < 2; i++) {
		char *now;
		size_t len;

		assert_int_equal(base_file_read(paths[i], 1 << 26, &now, &len),
				 0);
		assert_int_equal(len, blen[i]);
		assert_memory_equal(now, before[i], len);
		free(now);
		free(before[i]);
	}
	n = all_final_parse();
	if (access(tmp, F_OK) == 0) {
		struct re_trace_hdr h;
		struct re_trace_rec *r = NULL;
		int rc = load_trace(tmp, &h, &r, err, sizeof(err));
		char *buf;

		assert_int_equal(base_file_read(tmp, 1 << 26, &buf, &tlen), 0);
		free(buf);
		print_message("[ MEASURE  ] killed while writing: '%s' left "
			      "(%zu bytes), %s%s\n",
			      tmp, tlen, rc == GL_OK ? "complete" : "refused: ",
			      rc == GL_OK ? "" : err);
		/* complete only with every declared record and its crc */
		if (rc == GL_OK)
			assert_true(h.n_records > 0);
		free(r);
	} else {
		print_message("[ MEASURE  ] killed while writing: the "
			      "temporary file was already renamed\n");
	}
	print_message("[ MEASURE  ] %d traces under final names, all "
		      "complete; the write seen at request %d\n",
		      n, attempt - 1);
	assert_true(n >= 2);
	sys_case_stop(&cs);
}

/* ---- roboelf-tech show-trace ------------------------------------------- */

static int show(const char *path, const char *window, struct proc *p)
{
	char bin[SYS_PATH_MAX + 16];
	char *argv[6] = {bin, (char *)"show-trace", (char *)path, NULL, NULL,
			 NULL};
	int st;

	snprintf(bin, sizeof(bin), "%s/roboelf-tech", env.bin);
	if (window) {
		argv[3] = (char *)"--window";
		argv[4] = (char *)window;
	}
	memset(p, 0, sizeof(*p));
	if (proc_spawn(p, argv, NULL) < 0 || proc_wait_exit(p, 60000, &st) < 0)
		fail_msg("roboelf-tech show-trace did not finish");
	return proc_exit_code(p);
}

static void check_png(const char *path, uint32_t height)
{
	static const unsigned char sig[8] = {0x89, 'P',	 'N',  'G',
					     '\r', '\n', 0x1a, '\n'};
	unsigned char *b;
	size_t len;
	uint32_t w, h;

	if (base_file_read(path, 1 << 26, (char **)&b, &len) < 0)
		fail_msg("no PNG '%s'", path);
	assert_true(len > 33);
	assert_memory_equal(b, sig, 8);
	assert_memory_equal(b + 12, "IHDR", 4);
	w = (uint32_t)b[16] << 24 | b[17] << 16 | b[18] << 8 | b[19];
	h = (uint32_t)b[20] << 24 | b[21] << 16 | b[22] << 8 | b[23];
	assert_int_equal(w, 1200);
	assert_int_equal(h, height);
	free(b);
}

/* @path with bytes changed by @edit, written to env.dir/NAME. */
static void bad_copy(const char *name, size_t cut, const char *from,
		     const char *to, char *out, size_t cap)
{
	char *buf, *p;
	size_t len;
	FILE *f;

	assert_int_equal(base_file_read(pot_trace, 1 << 26, &buf, &len), 0);
	snprintf(out, cap, "%s/%s", env.dir, name);
	f = fopen(out, "w");
	assert_non_null(f);
	p = from ? strstr(buf, from) : NULL;
	if (p) {
		fwrite(buf, 1, (size_t)(p - buf), f);
		fputs(to, f);
		fputs(p + strlen(from), f);
	} else {
		fwrite(buf, 1, cut ? cut : len, f);
	}
	fclose(f);
	free(buf);
}

static void refused(const char *path, const char *window, const char *want)
{
	struct proc p;

	assert_int_equal(show(path, window, &p), 2);
	if (!strstr(proc_output(&p, PROC_STDERR), want))
		fail_msg("'%s': stderr '%s' does not say '%s'", path,
			 proc_output(&p, PROC_STDERR), want);
	proc_kill(&p);
}

static void test_show_trace(void **state)
{
	char png[SYS_PATH_MAX + 32], bad[SYS_PATH_MAX];
	const char *tags[] = {"A", "B", "C", "timing"};
	struct proc p;
	size_t n = strlen(pot_trace) - 4;
	int wrote = 0;

	(void)state;
	if (!pot_trace[0])
		fail_msg("no trace from test_trace_pot_offset");
	assert_int_equal(show(pot_trace, NULL, &p), 0);
	for (const char *s = proc_output(&p, PROC_STDOUT);
	     (s = strstr(s, "wrote ")); s++)
		wrote++;
	assert_int_equal(wrote, 4);
	proc_kill(&p);
	for (int i = 0; i < 4; i++) {
		snprintf(png, sizeof(png), "%.*s-%s.png", (int)n, pot_trace,
			 tags[i]);
		check_png(png, i < 3 ? 1020 : 1320); /* 3 panels, 4 */
		unlink(png);
	}
	assert_int_equal(show(pot_trace, "0:1e6", &p), 0);
	proc_kill(&p);
	refused(pot_trace, "1e6:2e6", "no cycles in the window");
	bad_copy("bad-trunc.csv", 3000, NULL, NULL, bad, sizeof(bad));
	refused(bad, NULL, "refused: line ");
	refused(bad, NULL, "truncated");
	bad_copy("bad-version.csv", 0, "roboelf-trace 1", "roboelf-trace 2",
		 bad, sizeof(bad));
	refused(bad, NULL, "refused: line 1: trace format version '2'");
	bad_copy("bad-huge.csv", 0, "# records ",
		 "# records 2000001\n# records ", bad, sizeof(bad));
	refused(bad, NULL, "more than the limit 2000000");
	refused("/etc/passwd", NULL, "refused: line 1: not a roboelf trace");
	refused("/nonexistent/trace.csv", NULL, "cannot read trace");
}

/* ---- fixtures ----------------------------------------------------------- */

static int group_setup(void **state)
{
	(void)state;
	env_ok = sys_env_ready(&env);
	return 0;
}

static int group_teardown(void **state)
{
	(void)state;
	sys_env_done(&env, env_ok);
	return 0;
}

static int case_teardown(void **state)
{
	(void)state;
	sys_case_stop(&cs);
	return 0;
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_trace_pot_offset),
	    T(test_trace_link_stall),
	    T(test_trace_sigkill_while_writing),
	    T(test_show_trace),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
