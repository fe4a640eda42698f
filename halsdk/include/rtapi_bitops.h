/*
 * rtapi_bitops.h - atomic operations on bit nr of a bitmap of unsigned
 * longs: safe between threads and between processes sharing the map.
 */
#ifndef RTAPI_BITOPS_H
#define RTAPI_BITOPS_H

#include <limits.h>
#include <stddef.h>

#define RTAPI_LONG_BIT (CHAR_BIT * sizeof(unsigned long))

#define RTAPI_BITWORD_(nr, addr)                                           \
    ((volatile unsigned long *)(addr) + (size_t)(nr) / RTAPI_LONG_BIT)
#define RTAPI_BITMASK_(nr) (1UL << ((size_t)(nr) % RTAPI_LONG_BIT))

static inline void set_bit(int nr, volatile void *addr)
{
    __atomic_fetch_or(RTAPI_BITWORD_(nr, addr), RTAPI_BITMASK_(nr),
                      __ATOMIC_SEQ_CST);
}

static inline void clear_bit(int nr, volatile void *addr)
{
    __atomic_fetch_and(RTAPI_BITWORD_(nr, addr), ~RTAPI_BITMASK_(nr),
                       __ATOMIC_SEQ_CST);
}

static inline int test_bit(int nr, const volatile void *addr)
{
    return (__atomic_load_n(RTAPI_BITWORD_(nr, addr), __ATOMIC_SEQ_CST)
            & RTAPI_BITMASK_(nr)) != 0;
}

/* the bit's old value */
static inline long test_and_set_bit(int nr, volatile void *addr)
{
    return (__atomic_fetch_or(RTAPI_BITWORD_(nr, addr), RTAPI_BITMASK_(nr),
                              __ATOMIC_SEQ_CST) & RTAPI_BITMASK_(nr)) != 0;
}

static inline long test_and_clear_bit(int nr, volatile void *addr)
{
    return (__atomic_fetch_and(RTAPI_BITWORD_(nr, addr),
                               ~RTAPI_BITMASK_(nr), __ATOMIC_SEQ_CST)
            & RTAPI_BITMASK_(nr)) != 0;
}

#endif
