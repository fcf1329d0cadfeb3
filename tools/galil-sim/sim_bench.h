/*
 * sim_bench.h - how fast galil-sim runs in virtual time (make bench,
 * galil-sim --bench, tests/sim/test_sim_speed).
 */
#ifndef SIM_BENCH_H
#define SIM_BENCH_H

#include <stddef.h>

/* The figure of one run. */
struct sim_bench_result {
	double sim_ms;	  /* simulated time run */
	double real_ms;	  /* wall-clock time it took */
	double speed;	  /* sim_ms / real_ms */
	unsigned threads; /* thread bits still running at the end */
	double loops;	  /* loop iterations done by all threads */
	double min_loops; /* iterations of the least served thread */
};

/*
 * sim_bench_threads() - a fresh default simulator runs a DMC program that
 * keeps @nthreads threads (1..8) busy (each counts in a tight JP loop) for
 * @sim_ms of simulated time; measure the wall-clock time.
 * @err: [out] why the run failed.
 * Return: 0, GL_ERR_CTRL (the program was refused or its threads did not
 *         all run), GL_ERR_NOMEM, GL_ERR_ARG.
 */
int sim_bench_threads(int nthreads, double sim_ms, struct sim_bench_result *out,
		      char *err, size_t errlen);

#endif /* SIM_BENCH_H */
