/*
 * test_re_rt.c - the real-time set-up and the host latency probe.
 *
 * With permission (root, as in CI): SCHED_FIFO at the asked priority and
 * locked memory are in force, read back from the kernel (sched_getscheduler
 * and VmLck in /proc/self/status). Without (a child that drops to user
 * 65534 with RLIMIT_RTPRIO 0): the refusal, its errno and its words. The
 * probe's figures and the verdict's arithmetic.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <sched.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "re_rt.h"

#if defined(__SANITIZE_ADDRESS__)
#define ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ASAN 1
#endif
#endif
#ifndef ASAN
#define ASAN 0
#endif

static void back_to_normal(void)
{
	struct sched_param sp = {.sched_priority = 0};

	sched_setscheduler(0, SCHED_OTHER, &sp);
	munlockall();
}

/* SCHED_FIFO 50 is permitted to root (CAP_SYS_NICE) or with
 * RLIMIT_RTPRIO >= 50; CI runs as root. */
static int permitted(void)
{
	struct rlimit rl;

	return geteuid() == 0 ||
	       (getrlimit(RLIMIT_RTPRIO, &rl) == 0 && rl.rlim_cur >= 50);
}

static void test_rt_granted(void **state)
{
	struct re_rt_cfg cfg = {50, -1, 1};
	struct re_rt_state st;
	char d[RE_RT_DESCRIBE_MAX];
	int pol, prio;
	long kb;

	(void)state;
	if (!permitted()) { /* an ordinary user: the refusal instead */
		assert_int_equal(re_rt_setup(&cfg, &st), -1);
		assert_int_equal(st.err_fifo, EPERM);
		return;
	}
	assert_int_equal(re_rt_setup(&cfg, &st), ASAN ? -1 : 0);
	assert_int_equal(re_rt_readback(&pol, &prio, &kb), 0);
	assert_int_equal(pol, SCHED_FIFO);
	assert_int_equal(prio, 50);
	assert_int_equal(st.fifo, 1);
	assert_int_equal(st.err_fifo, 0);
	assert_int_equal(re_rt_min_period_ms(&st), RE_RT_MIN_MS_WITH);
	re_rt_describe(&st, d, sizeof(d));
	if (ASAN) {
		assert_int_equal(st.locked, 0);
		assert_string_equal(d, "SCHED_FIFO 50, memory not locked "
				       "(AddressSanitizer build), not pinned");
	} else {
		assert_int_equal(st.locked, 1);
		assert_int_equal(st.future, 1);
		assert_true(kb > 0);
		assert_string_equal(d, "SCHED_FIFO 50, memory locked, not "
				       "pinned");
	}
	back_to_normal();
}

static void test_rt_pinned(void **state)
{
	struct re_rt_cfg cfg = {0, 0, 0};
	struct re_rt_state st;
	char d[RE_RT_DESCRIBE_MAX];
	cpu_set_t set;

	(void)state;
	assert_int_equal(re_rt_setup(&cfg, &st), 0);
	assert_int_equal(st.cpu, 0);
	assert_int_equal(sched_getaffinity(0, sizeof(set), &set), 0);
	assert_int_equal(CPU_COUNT(&set), 1);
	assert_true(CPU_ISSET(0, &set));
	assert_string_equal(re_rt_describe(&st, d, sizeof(d)),
			    "normal scheduling (not asked), memory not "
			    "locked, pinned to CPU 0");
	assert_int_equal(re_rt_min_period_ms(&st), RE_RT_MIN_MS_WITHOUT);
	/* a CPU that does not exist is refused with its errno */
	cfg.cpu = 1000;
	assert_int_equal(re_rt_setup(&cfg, &st), -1);
	assert_int_equal(st.cpu, -1);
	assert_int_equal(st.err_cpu, EINVAL);
	CPU_ZERO(&set);
	for (int i = 0; i < CPU_SETSIZE; i++)
		CPU_SET(i, &set);
	sched_setaffinity(0, sizeof(set), &set);
}

/* In a child without the right: user 65534 and RLIMIT_RTPRIO 0. The child
 * exits 0 when everything is as expected, else the number of the check. */
static int refused_child(void)
{
	struct rlimit rl = {0, 0};
	struct re_rt_cfg cfg = {50, -1, 0};
	struct re_rt_state st;
	char d[RE_RT_DESCRIBE_MAX];
	int pol, prio;
	long kb;

	if (setrlimit(RLIMIT_RTPRIO, &rl) != 0)
		return 10;
	if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0))
		return 11;
	if (re_rt_setup(&cfg, &st) != -1)
		return 1;
	if (st.fifo || st.err_fifo != EPERM)
		return 2;
	if (re_rt_readback(&pol, &prio, &kb) != 0 || pol == SCHED_FIFO)
		return 3;
	if (re_rt_min_period_ms(&st) != RE_RT_MIN_MS_WITHOUT)
		return 4;
	re_rt_describe(&st, d, sizeof(d));
	if (strcmp(d, "normal scheduling (SCHED_FIFO refused: Operation not "
		      "permitted), memory not locked, not pinned"))
		return 5;
	return 0;
}

static void test_rt_refused(void **state)
{
	int status;
	pid_t pid;

	(void)state;
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0)
		_exit(refused_child());
	assert_int_equal(waitpid(pid, &status, 0), pid);
	assert_true(WIFEXITED(status));
	assert_int_equal(WEXITSTATUS(status), 0);
}

static void test_probe_figures(void **state)
{
	struct re_rt_probe p;

	(void)state;
	assert_int_equal(re_rt_probe_run(1000000, 200000000, NULL, &p), 0);
	/* 200 deadlines; a wake later than a period skips the lost ones */
	assert_true(p.wakes >= 100 && p.wakes <= 200);
	assert_true(p.p50_ms <= p.p99_ms && p.p99_ms <= p.p999_ms &&
		    p.p999_ms <= p.max_ms);
	assert_true(p.over_5ms <= p.over_1ms && p.over_1ms <= p.wakes);
	assert_int_equal(re_rt_probe_run(0, 1000000, NULL, &p), -1);
}

static void test_probe_stop(void **state)
{
	static volatile int stop = 1;
	struct re_rt_probe p;

	(void)state;
	assert_int_equal(re_rt_probe_run(1000000, 10000000000LL, &stop, &p), 0);
	assert_int_equal(p.wakes, 0);
}

static void test_verdict(void **state)
{
	struct re_rt_probe p = {.wakes = 1000, .p999_ms = 0.9, .max_ms = 3.0};
	struct re_rt_verdict v;

	(void)state;
	/* 2 ms, factors 1.5 / 2.5: lateness may use 3.0 ms; 2 x 3.0 > 3.0 */
	re_rt_verdict(&p, 2, 1.5, 2.5, &v);
	assert_int_equal(v.period_ms, 2);
	assert_true(v.margin_ms == 3.0);
	assert_int_equal(v.safe, 0);
	assert_int_equal(v.quiet, 1); /* 0.9 <= 0.5 x 2 */
	/* 4 ms: 6.0 ms allowed, exactly 2 x 3.0: safe */
	re_rt_verdict(&p, 4, 1.5, 2.5, &v);
	assert_true(v.margin_ms == 6.0);
	assert_int_equal(v.safe, 1);
	/* p99.9 above (noncritical - 1) x P: warnings to expect */
	p.p999_ms = 2.5;
	re_rt_verdict(&p, 4, 1.5, 2.5, &v);
	assert_int_equal(v.quiet, 0);
	/* no wake-up measured: nothing is safe */
	p.wakes = 0;
	re_rt_verdict(&p, 100, 1.5, 2.5, &v);
	assert_int_equal(v.safe, 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_rt_granted),
	    cmocka_unit_test(test_rt_pinned),
	    cmocka_unit_test(test_rt_refused),
	    cmocka_unit_test(test_probe_figures),
	    cmocka_unit_test(test_probe_stop),
	    cmocka_unit_test(test_verdict),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
