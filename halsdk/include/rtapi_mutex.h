/*
 * rtapi_mutex.h - a one-word lock (an unsigned long, 0 when free) that
 * works between realtime functions, setup code and other processes
 * sharing the word.  rtapi_mutex_try() and rtapi_mutex_give() never
 * block and may be called from realtime functions; rtapi_mutex_get()
 * waits (yielding the processor), so call it from setup code only.
 */
#ifndef RTAPI_MUTEX_H
#define RTAPI_MUTEX_H

#include <sched.h>

#include "rtapi_bitops.h"

typedef unsigned long rtapi_mutex_t;

/* release the lock, whoever holds it */
static inline void rtapi_mutex_give(unsigned long *mutex)
{
    test_and_clear_bit(0, mutex);
}

/* take the lock if it is free: 0, or non-zero when someone holds it */
static inline int rtapi_mutex_try(unsigned long *mutex)
{
    return (int)test_and_set_bit(0, mutex);
}

/* take the lock, waiting for it */
static inline void rtapi_mutex_get(unsigned long *mutex)
{
    while (test_and_set_bit(0, mutex))
        sched_yield();
}

#endif
