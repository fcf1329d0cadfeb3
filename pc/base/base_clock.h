/*
 * base_clock.h - the monotonic clock: read it and sleep until a time on it.
 *
 * One copy of the CLOCK_MONOTONIC helpers for the supervisor, the tools and
 * the tests. It is not a timer service or a scheduler, and it never reads the
 * wall clock (CLOCK_REALTIME): times here only measure intervals. Nothing
 * allocates, prints or keeps state; every function is async-signal-safe
 * (clock_gettime and clock_nanosleep are).
 */
#ifndef BASE_CLOCK_H
#define BASE_CLOCK_H

#include <stdint.h>

#define BASE_NS_PER_US ((int64_t)1000)	     /* ns in a microsecond */
#define BASE_NS_PER_MS ((int64_t)1000000)    /* ns in a millisecond */
#define BASE_NS_PER_S  ((int64_t)1000000000) /* ns in a second */

/*
 * base_now_ns() - CLOCK_MONOTONIC now, in ns since an arbitrary start.
 * base_now_us() - the same in whole microseconds (rounded down).
 * base_now_ms() - the same in whole milliseconds (rounded down).
 * No arguments; cannot fail (CLOCK_MONOTONIC always exists on Linux).
 */
int64_t base_now_ns(void);
int64_t base_now_us(void);
int64_t base_now_ms(void);

/*
 * base_sleep_until_ns() - sleep until CLOCK_MONOTONIC reaches @t_ns (ns, as
 * base_now_ns()). Returns at once if that time has passed; a signal does
 * not cut the sleep short (clock_nanosleep with TIMER_ABSTIME is retried on
 * EINTR, so there is no drift).
 */
void base_sleep_until_ns(int64_t t_ns);

/*
 * base_sleep_ms() - sleep for @ms milliseconds (relative; <= 0: return at
 * once), resumed after a signal until the whole time has passed.
 */
void base_sleep_ms(int ms);

#endif /* BASE_CLOCK_H */
