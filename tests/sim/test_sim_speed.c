/*
 * test_sim_speed.c - galil-sim in virtual time must run at least 50 times
 * faster than real time with 8 program threads busy. The figure is
 * printed; make bench prints a longer measurement (galil-sim --bench).
 *
 * The best of three 2-second runs is taken so that one descheduling on a
 * noisy 2-core machine does not fail the test. Under the sanitizers
 * (make asan), which slow everything several-fold, the floor is 10.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include <cmocka.h>

#include "sim_bench.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_UNDEFINED__)
#define SPEED_FLOOR 10.0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SPEED_FLOOR 10.0
#endif
#endif
#ifndef SPEED_FLOOR
#define SPEED_FLOOR 50.0
#endif

#define RUNS   3
#define SIM_MS 2000.0

/* The best speed of up to RUNS runs of @sim_ms with @nthreads busy. */
static double best_speed(int nthreads, double sim_ms)
{
	unsigned want = (1u << nthreads) - 1;
	struct sim_bench_result r;
	char err[256];
	double best = 0;

	for (int i = 0; i < RUNS && best < SPEED_FLOOR * 2; i++) {
		if (sim_bench_threads(nthreads, sim_ms, &r, err, sizeof(err)) <
		    0)
			fail_msg("bench: %s", err);
		assert_int_equal(r.threads & want, want);
		/* every thread really ran its loop, at least once per 10 ms */
		assert_true(r.min_loops > sim_ms / 10);
		if (r.speed > best)
			best = r.speed;
	}
	fprintf(stderr,
		"galil-sim virtual time: %.1f x real time (%d busy thread%s, "
		"best of up to %d runs of %.0f ms; floor %.0f)\n",
		best, nthreads, nthreads > 1 ? "s" : "", RUNS, sim_ms,
		SPEED_FLOOR);
	return best;
}

static void test_virtual_time_speed_8_threads(void **state)
{
	(void)state;
	assert_true(best_speed(8, SIM_MS) >= SPEED_FLOOR);
}

/* One thread only: at least as fast. */
static void test_virtual_time_speed_1_thread(void **state)
{
	(void)state;
	assert_true(best_speed(1, SIM_MS / 2) >= SPEED_FLOOR);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_virtual_time_speed_8_threads),
	    cmocka_unit_test(test_virtual_time_speed_1_thread),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
