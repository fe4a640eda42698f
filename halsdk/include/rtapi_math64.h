/* rtapi_math64.h - 64-bit by 32-bit division, as RTAPI code calls it */
#ifndef RTAPI_MATH64_H
#define RTAPI_MATH64_H

#include "rtapi_stdint.h"

static inline rtapi_u64 rtapi_div_u64_rem(rtapi_u64 dividend,
                                          rtapi_u32 divisor,
                                          rtapi_u32 *remainder)
{
    *remainder = (rtapi_u32)(dividend % divisor);
    return dividend / divisor;
}

static inline rtapi_u64 rtapi_div_u64(rtapi_u64 dividend, rtapi_u32 divisor)
{
    return dividend / divisor;
}

static inline rtapi_s64 rtapi_div_s64_rem(rtapi_s64 dividend,
                                          rtapi_s32 divisor,
                                          rtapi_s32 *remainder)
{
    *remainder = (rtapi_s32)(dividend % divisor);
    return dividend / divisor;
}

static inline rtapi_s64 rtapi_div_s64(rtapi_s64 dividend, rtapi_s32 divisor)
{
    return dividend / divisor;
}

#endif
