/*
 * test_base_clock.c - the monotonic clock helpers (base_clock).
 *
 * Covered: the units agree with each other, the clock never goes back,
 * base_sleep_until_ns() sleeps until (not before) its time and returns at
 * once for a past time, a signal does not cut it short, base_sleep_ms().
 * Bounds on oversleeping are generous (a loaded machine); undersleeping is
 * never allowed.
 */
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <sys/time.h>

#include <cmocka.h>

#include "base_clock.h"

#define LATE_MAX_NS (1000 * BASE_NS_PER_MS) /* oversleep tolerated (load) */

static void test_clock_units(void **state)
{
	int64_t ns0, us, ms, ns1;

	(void)state;
	assert_true(BASE_NS_PER_US == 1000);
	assert_true(BASE_NS_PER_MS == 1000 * BASE_NS_PER_US);
	assert_true(BASE_NS_PER_S == 1000 * BASE_NS_PER_MS);
	ns0 = base_now_ns();
	us = base_now_us();
	ms = base_now_ms();
	ns1 = base_now_ns();
	assert_true(ns0 > 0);
	assert_true(ns1 >= ns0);
	assert_true(us >= ns0 / BASE_NS_PER_US && us <= ns1 / BASE_NS_PER_US);
	assert_true(ms >= ns0 / BASE_NS_PER_MS && ms <= ns1 / BASE_NS_PER_MS);
}

static void test_clock_monotonic(void **state)
{
	int64_t prev = base_now_ns(), t;
	int i;

	(void)state;
	for (i = 0; i < 10000; i++) {
		t = base_now_ns();
		assert_true(t >= prev);
		prev = t;
	}
}

static void test_sleep_until(void **state)
{
	int64_t t0 = base_now_ns(), target = t0 + 20 * BASE_NS_PER_MS, t1;

	(void)state;
	base_sleep_until_ns(target);
	t1 = base_now_ns();
	assert_true(t1 >= target);
	assert_true(t1 - target < LATE_MAX_NS);
	/* a past time (and a negative one): at once */
	t0 = base_now_ns();
	base_sleep_until_ns(t0 - BASE_NS_PER_S);
	base_sleep_until_ns(-1);
	assert_true(base_now_ns() - t0 < LATE_MAX_NS);
}

static volatile sig_atomic_t alarms;

static void on_alarm(int sig)
{
	(void)sig;
	alarms++;
}

/* A signal every 2 ms does not end a 50 ms sleep early. */
static void test_sleep_signals(void **state)
{
	struct sigaction sa;
	struct itimerval it = {{0, 2000}, {0, 2000}}, off;
	int64_t target, t1;

	(void)state;
	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_alarm;
	assert_int_equal(sigaction(SIGALRM, &sa, NULL), 0); /* no SA_RESTART */
	memset(&off, 0, sizeof(off));
	alarms = 0;
	target = base_now_ns() + 50 * BASE_NS_PER_MS;
	assert_int_equal(setitimer(ITIMER_REAL, &it, NULL), 0);
	base_sleep_until_ns(target);
	t1 = base_now_ns();
	assert_int_equal(setitimer(ITIMER_REAL, &off, NULL), 0);
	assert_true(alarms > 0);
	assert_true(t1 >= target);
	target = base_now_ns() + 30 * BASE_NS_PER_MS;
	alarms = 0;
	assert_int_equal(setitimer(ITIMER_REAL, &it, NULL), 0);
	base_sleep_ms(30);
	t1 = base_now_ns();
	assert_int_equal(setitimer(ITIMER_REAL, &off, NULL), 0);
	assert_true(alarms > 0);
	assert_true(t1 >= target);
}

static void test_sleep_ms(void **state)
{
	int64_t t0 = base_now_ns(), t1;

	(void)state;
	base_sleep_ms(15);
	t1 = base_now_ns();
	assert_true(t1 - t0 >= 15 * BASE_NS_PER_MS);
	assert_true(t1 - t0 < 15 * BASE_NS_PER_MS + LATE_MAX_NS);
	t0 = base_now_ns();
	base_sleep_ms(0);
	base_sleep_ms(-5);
	assert_true(base_now_ns() - t0 < LATE_MAX_NS);
}

int main(void)
{
	static const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_clock_units),
	    cmocka_unit_test(test_clock_monotonic),
	    cmocka_unit_test(test_sleep_until),
	    cmocka_unit_test(test_sleep_signals),
	    cmocka_unit_test(test_sleep_ms),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
