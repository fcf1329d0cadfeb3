/*
 * re_rt.h - the supervisor's real-time set-up and the host latency
 * self-test (docs/supervisor.md "Real time").
 *
 * re_rt_setup() asks, for the calling thread only, for what the
 * configuration's `realtime` section names: SCHED_FIFO at a priority,
 * locked memory (mlockall), a CPU. Each part that the kernel refuses is
 * recorded with its errno, never printed; the caller says what is in force
 * and refuses periods that need more than it got (re_rt_min_period_ms()).
 *
 * re_rt_probe_run() is the idea of cyclictest built in: a loop that sleeps
 * to absolute deadlines (clock_nanosleep, CLOCK_MONOTONIC) and records how
 * late each wake-up is in a fixed histogram (no allocation). The verdict
 * (re_rt_verdict()) gives the shortest period whose reply-age limits hold
 * with that lateness.
 */
#ifndef RE_RT_H
#define RE_RT_H

#include <stddef.h>
#include <stdint.h>

#define RE_RT_PRIO_MAX	     99
#define RE_RT_MIN_MS_WITHOUT 10	  /* shortest period without SCHED_FIFO, ms */
#define RE_RT_MIN_MS_WITH    2	  /* shortest period the config allows, ms */
#define RE_RT_HIST_US	     10	  /* histogram bin width, us */
#define RE_RT_HIST_BINS	     5000 /* 0 .. 50 ms; later wakes: overflow */
#define RE_RT_DESCRIBE_MAX   256

/* What re_rt_setup() should ask for (the config's `realtime` section). */
struct re_rt_cfg {
	int priority;	 /* SCHED_FIFO 1..99; 0: keep the normal policy */
	int cpu;	 /* pin the calling thread to this CPU; -1: no */
	int lock_memory; /* mlockall() */
};

/* What is in force after re_rt_setup(); errno 0 = granted or not asked. */
struct re_rt_state {
	int fifo;     /* SCHED_FIFO in force */
	int priority; /* its priority */
	int locked;   /* memory locked (MCL_CURRENT, + MCL_FUTURE if future) */
	int future;   /* MCL_FUTURE too */
	int cpu;      /* pinned CPU, -1: none */
	int err_fifo, err_lock, err_cpu; /* errno of a refused request */
	int lock_asan; /* not locked: an AddressSanitizer build (re_rt.c) */
};

/* Wake-up lateness figures of one probe run. */
struct re_rt_probe {
	int64_t period_ns;
	uint64_t wakes;
	double p50_ms, p99_ms, p999_ms, max_ms;
	uint64_t over_1ms, over_5ms; /* wakes later than 1 ms / 5 ms */
};

/* The verdict for one candidate period. */
struct re_rt_verdict {
	int period_ms;
	double margin_ms; /* (critical - 1) x P: what lateness may use */
	int safe;	  /* worst lateness x 2 <= margin */
	int quiet;	  /* p99.9 <= (noncritical - 1) x P: no warnings */
};

/*
 * re_rt_setup() - apply @cfg to the calling thread (other threads keep
 * their policy). Memory is locked with MCL_FUTURE too only when locking is
 * unbounded for this process (RLIMIT_MEMLOCK infinite or CAP_IPC_LOCK, as
 * root), so that a later allocation can never fail for the lock's sake.
 * @cfg: [in] what to ask for.
 * @st: [out] what is in force and why not.
 * An AddressSanitizer build never locks (its shadow memory is terabytes).
 * Return: 0 when everything asked for is in force, -1 when any part was
 *         refused (@st says which). Never prints.
 */
int re_rt_setup(const struct re_rt_cfg *cfg, struct re_rt_state *st);

/*
 * re_rt_describe() - one line for the log and the console, e.g.
 * "SCHED_FIFO 50, memory locked, not pinned" or "normal scheduling
 * (SCHED_FIFO 50 refused: Operation not permitted), memory locked".
 * Return: @buf.
 */
char *re_rt_describe(const struct re_rt_state *st, char *buf, size_t cap);

/*
 * re_rt_min_period_ms() - the shortest supervisor period allowed with
 * @st: RE_RT_MIN_MS_WITH under SCHED_FIFO, else RE_RT_MIN_MS_WITHOUT
 * (an ordinary scheduler wakes a 2-5 ms loop late enough to trip the
 * reply-age watchdog: docs/supervisor.md).
 */
int re_rt_min_period_ms(const struct re_rt_state *st);

/*
 * re_rt_readback() - what the kernel reports for the calling thread:
 * its policy and priority (sched_getscheduler, sched_getparam) and the
 * locked memory of the process (VmLck in /proc/self/status).
 * @policy: [out] SCHED_FIFO, SCHED_OTHER...; @prio: [out]; @vmlck_kb: [out]
 *          -1 when /proc cannot be read.
 * Return: 0, or -1 when the policy cannot be read.
 */
int re_rt_readback(int *policy, int *prio, long *vmlck_kb);

/*
 * re_rt_probe_run() - sleep to absolute deadlines every @period_ns for
 * @duration_ns and record the lateness of each wake-up.
 * @stop: [in] optional; the loop ends early when *@stop becomes non-zero
 *        (a signal handler's flag).
 * @out: [out] the figures.
 * Return: 0, or -1 (errno set) if the clock cannot be read or slept on.
 */
int re_rt_probe_run(int64_t period_ns, int64_t duration_ns,
		    const volatile int *stop, struct re_rt_probe *out);

/*
 * re_rt_verdict() - judge period @period_ms against the lateness in @p
 * with the watchdog factors: the reply age is about P + lateness, so
 * lateness may use (critical - 1) x P before a WATCHDOG fault and
 * (noncritical - 1) x P before a warning. Safe when twice the worst
 * lateness seen fits the first (a short test does not see the whole tail).
 * @out: [out] the verdict.
 */
void re_rt_verdict(const struct re_rt_probe *p, int period_ms,
		   double noncritical, double critical,
		   struct re_rt_verdict *out);

#endif
