/*
 * sim_bench.c - virtual-time speed of the simulator with busy threads.
 */
#include <stdio.h>
#include <string.h>

#include "base_clock.h"
#include "gl_err.h"
#include "sim.h"
#include "sim_bench.h"

#define BENCH_PROG_MAX 1024

static double mono_ms(void)
{
	return (double)base_now_ns() / (double)BASE_NS_PER_MS;
}

/* #GO zeroes the counters, starts threads 1..n-1, then counts too. */
static size_t bench_program(int nthreads, char *buf, size_t cap)
{
	size_t len = (size_t)snprintf(buf, cap, "EN\n#GO\n");

	for (int t = 0; t < nthreads; t++)
		len += (size_t)snprintf(buf + len, cap - len, "n%d=0\n", t);
	for (int t = 1; t < nthreads; t++)
		len += (size_t)snprintf(buf + len, cap - len, "XQ #T%d,%d\n", t,
					t);
	for (int t = 0; t < nthreads; t++)
		len +=
		    (size_t)snprintf(buf + len, cap - len,
				     "#T%d\nn%d=n%d+1\nJP #T%d\n", t, t, t, t);
	return len;
}

static int bench_start(struct sim *s, int nthreads, char *err, size_t errlen)
{
	char prog[BENCH_PROG_MAX], resp[128];
	size_t len = bench_program(nthreads, prog, sizeof(prog));
	int bad = 0;

	if (ctrl_download(sim_ctrl(s), prog, len, &bad) < 0) {
		snprintf(err, errlen, "bench program refused at line %d", bad);
		return GL_ERR_CTRL;
	}
	if (ctrl_command(sim_ctrl(s), "XQ #GO,0", resp, sizeof(resp)) < 0) {
		snprintf(err, errlen, "'XQ #GO,0' refused: %s", resp);
		return GL_ERR_CTRL;
	}
	return 0;
}

static void bench_loops(struct sim *s, int nthreads,
			struct sim_bench_result *out)
{
	char name[16];
	double v;

	out->loops = 0;
	out->min_loops = -1;
	for (int t = 0; t < nthreads; t++) {
		snprintf(name, sizeof(name), "n%d", t);
		if (ctrl_get_var(sim_ctrl(s), name, &v) < 0)
			v = 0;
		out->loops += v;
		if (out->min_loops < 0 || v < out->min_loops)
			out->min_loops = v;
	}
}

int sim_bench_threads(int nthreads, double sim_ms, struct sim_bench_result *out,
		      char *err, size_t errlen)
{
	unsigned want = (1u << nthreads) - 1;
	struct sim *s;
	double t0;
	int rc;

	memset(out, 0, sizeof(*out));
	if (nthreads < 1 || nthreads > CTRL_THREADS || !(sim_ms > 0)) {
		snprintf(err, errlen, "bad bench parameters");
		return GL_ERR_ARG;
	}
	rc = sim_new(&s, NULL, err, errlen);
	if (rc < 0)
		return rc;
	rc = bench_start(s, nthreads, err, errlen);
	if (rc == 0) {
		sim_advance_ms(s, 10); /* threads started */
		t0 = mono_ms();
		sim_advance_ms(s, sim_ms);
		out->real_ms = mono_ms() - t0;
		out->sim_ms = sim_ms;
		out->speed = out->real_ms > 0 ? sim_ms / out->real_ms : 0;
		out->threads = ctrl_threads(sim_ctrl(s));
		bench_loops(s, nthreads, out);
		if ((out->threads & want) != want) {
			snprintf(err, errlen,
				 "only threads 0x%02x of 0x%02x "
				 "ran",
				 out->threads, want);
			rc = GL_ERR_CTRL;
		}
	}
	sim_free(s);
	return rc;
}
