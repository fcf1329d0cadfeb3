/*
 * re_rt.c - real-time set-up of the supervisor thread and the host latency
 * self-test (see re_rt.h).
 */
#define _GNU_SOURCE /* sched_setaffinity, CPU_SET */
#include "re_rt.h"

#include <errno.h>
#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

/* An AddressSanitizer build maps terabytes of shadow memory: locking all
 * of it would fail or exhaust the machine, so such a build never locks. */
#if defined(__SANITIZE_ADDRESS__)
#define RT_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RT_ASAN 1
#endif
#endif
#ifndef RT_ASAN
#define RT_ASAN 0
#endif

#define NS_PER_S  1000000000LL
#define NS_PER_MS 1000000.0
#define NS_PER_US 1000LL

/* ---- set-up ----------------------------------------------------------------
 */

static int ask_fifo(int prio, struct re_rt_state *st)
{
	struct sched_param sp = {.sched_priority = prio};

	if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0) {
		st->err_fifo = errno ? errno : EPERM;
		return -1;
	}
	st->fifo = 1;
	st->priority = prio;
	return 0;
}

/* Locking is unbounded for root (CAP_IPC_LOCK) or an infinite limit. */
static int lock_unbounded(void)
{
	struct rlimit rl;

	if (geteuid() == 0)
		return 1;
	return getrlimit(RLIMIT_MEMLOCK, &rl) == 0 &&
	       rl.rlim_cur == RLIM_INFINITY;
}

static int ask_lock(struct re_rt_state *st)
{
	int future = lock_unbounded();

	if (RT_ASAN) {
		st->lock_asan = 1;
		return -1;
	}
	if (mlockall(MCL_CURRENT | (future ? MCL_FUTURE : 0)) != 0) {
		st->err_lock = errno ? errno : ENOMEM;
		return -1;
	}
	st->locked = 1;
	st->future = future;
	return 0;
}

static int ask_cpu(int cpu, struct re_rt_state *st)
{
	cpu_set_t set;

	if (cpu >= CPU_SETSIZE) {
		st->err_cpu = EINVAL;
		return -1;
	}
	CPU_ZERO(&set);
	CPU_SET(cpu, &set);
	if (sched_setaffinity(0, sizeof(set), &set) != 0) {
		st->err_cpu = errno ? errno : EINVAL;
		return -1;
	}
	st->cpu = cpu;
	return 0;
}

int re_rt_setup(const struct re_rt_cfg *cfg, struct re_rt_state *st)
{
	int rc = 0;

	memset(st, 0, sizeof(*st));
	st->cpu = -1;
	if (cfg->lock_memory && ask_lock(st) < 0)
		rc = -1;
	if (cfg->cpu >= 0 && ask_cpu(cfg->cpu, st) < 0)
		rc = -1;
	if (cfg->priority > 0 &&
	    ask_fifo(cfg->priority > RE_RT_PRIO_MAX ? RE_RT_PRIO_MAX
						    : cfg->priority,
		     st) < 0)
		rc = -1;
	return rc;
}

char *re_rt_describe(const struct re_rt_state *st, char *buf, size_t cap)
{
	char lock[96], cpu[96];

	if (st->locked)
		snprintf(lock, sizeof(lock), "memory locked%s",
			 st->future ? "" : " (current pages only)");
	else if (st->lock_asan)
		snprintf(lock, sizeof(lock),
			 "memory not locked (AddressSanitizer build)");
	else if (st->err_lock)
		snprintf(lock, sizeof(lock), "memory not locked (%s)",
			 strerror(st->err_lock));
	else
		snprintf(lock, sizeof(lock), "memory not locked");
	if (st->cpu >= 0)
		snprintf(cpu, sizeof(cpu), "pinned to CPU %d", st->cpu);
	else if (st->err_cpu)
		snprintf(cpu, sizeof(cpu), "not pinned (%s)",
			 strerror(st->err_cpu));
	else
		snprintf(cpu, sizeof(cpu), "not pinned");
	if (st->fifo)
		snprintf(buf, cap, "SCHED_FIFO %d, %s, %s", st->priority, lock,
			 cpu);
	else if (st->err_fifo)
		snprintf(buf, cap,
			 "normal scheduling (SCHED_FIFO refused: "
			 "%s), %s, %s",
			 strerror(st->err_fifo), lock, cpu);
	else
		snprintf(buf, cap, "normal scheduling (not asked), %s, %s",
			 lock, cpu);
	return buf;
}

int re_rt_min_period_ms(const struct re_rt_state *st)
{
	return st->fifo ? RE_RT_MIN_MS_WITH : RE_RT_MIN_MS_WITHOUT;
}

int re_rt_readback(int *policy, int *prio, long *vmlck_kb)
{
	struct sched_param sp;
	char line[128];
	FILE *f;

	*vmlck_kb = -1;
	*policy = sched_getscheduler(0);
	if (*policy < 0 || sched_getparam(0, &sp) != 0)
		return -1;
	*prio = sp.sched_priority;
	f = fopen("/proc/self/status", "re");
	if (!f)
		return 0;
	while (fgets(line, sizeof(line), f))
		if (sscanf(line, "VmLck: %ld kB", vmlck_kb) == 1)
			break;
	fclose(f);
	return 0;
}

/* ---- the latency probe -----------------------------------------------------
 */

static int64_t ts_ns(const struct timespec *t)
{
	return (int64_t)t->tv_sec * NS_PER_S + t->tv_nsec;
}

static struct timespec ns_ts(int64_t ns)
{
	struct timespec t = {(time_t)(ns / NS_PER_S), (long)(ns % NS_PER_S)};

	return t;
}

/* The lateness below which a share @q of the wakes fell, from @hist. */
static double hist_pct(const uint64_t *hist, uint64_t n, double q, double max)
{
	uint64_t want = (uint64_t)(q * (double)n + 0.5), acc = 0;

	if (want == 0)
		want = 1;
	for (int b = 0; b < RE_RT_HIST_BINS; b++) {
		acc += hist[b];
		if (acc >= want) {
			double up = (double)(b + 1) * RE_RT_HIST_US / 1000.0;

			return up < max ? up : max;
		}
	}
	return max;
}

int re_rt_probe_run(int64_t period_ns, int64_t duration_ns,
		    const volatile int *stop, struct re_rt_probe *out)
{
	static uint64_t hist[RE_RT_HIST_BINS + 1];
	struct timespec now, next;
	int64_t t0, deadline, late, max = 0;
	uint64_t n = 0;

	memset(out, 0, sizeof(*out));
	memset(hist, 0, sizeof(hist));
	out->period_ns = period_ns;
	if (period_ns <= 0 || clock_gettime(CLOCK_MONOTONIC, &now) != 0)
		return -1;
	t0 = ts_ns(&now);
	for (deadline = t0 + period_ns; deadline - t0 <= duration_ns;
	     deadline += period_ns) {
		int e;

		if (stop && *stop)
			break;
		next = ns_ts(deadline);
		e = clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next,
				    NULL);
		if (e == EINTR)
			continue;
		if (e != 0 || clock_gettime(CLOCK_MONOTONIC, &now) != 0) {
			errno = e ? e : errno;
			return -1;
		}
		late = ts_ns(&now) - deadline;
		if (late < 0)
			late = 0;
		if (late > max)
			max = late;
		hist[late / (RE_RT_HIST_US * NS_PER_US) < RE_RT_HIST_BINS
			 ? late / (RE_RT_HIST_US * NS_PER_US)
			 : RE_RT_HIST_BINS]++;
		out->over_1ms += late > 1000000;
		out->over_5ms += late > 5000000;
		n++;
		/* a wake later than a whole period skips the lost deadlines */
		while (deadline + period_ns < ts_ns(&now))
			deadline += period_ns;
	}
	out->wakes = n;
	out->max_ms = (double)max / NS_PER_MS;
	out->p50_ms = hist_pct(hist, n, 0.50, out->max_ms);
	out->p99_ms = hist_pct(hist, n, 0.99, out->max_ms);
	out->p999_ms = hist_pct(hist, n, 0.999, out->max_ms);
	return 0;
}

void re_rt_verdict(const struct re_rt_probe *p, int period_ms,
		   double noncritical, double critical,
		   struct re_rt_verdict *out)
{
	out->period_ms = period_ms;
	out->margin_ms = (critical - 1.0) * period_ms;
	out->safe = p->wakes > 0 && 2.0 * p->max_ms <= out->margin_ms;
	out->quiet =
	    p->wakes > 0 && p->p999_ms <= (noncritical - 1.0) * period_ms;
}
