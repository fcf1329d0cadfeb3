/*
 * base_clock.c - the monotonic clock (see base_clock.h). Not a timer
 * service: two system calls and the unit conversions, nothing else.
 */
#include "base_clock.h"

#include <errno.h>
#include <time.h>

int64_t base_now_ns(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * BASE_NS_PER_S + ts.tv_nsec;
}

int64_t base_now_us(void)
{
	return base_now_ns() / BASE_NS_PER_US;
}

int64_t base_now_ms(void)
{
	return base_now_ns() / BASE_NS_PER_MS;
}

void base_sleep_until_ns(int64_t t_ns)
{
	struct timespec ts;

	if (t_ns < 0)
		t_ns = 0;
	ts.tv_sec = (time_t)(t_ns / BASE_NS_PER_S);
	ts.tv_nsec = (long)(t_ns % BASE_NS_PER_S);
	while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) ==
	       EINTR)
		;
}

void base_sleep_ms(int ms)
{
	if (ms > 0)
		base_sleep_until_ns(base_now_ns() + ms * BASE_NS_PER_MS);
}
