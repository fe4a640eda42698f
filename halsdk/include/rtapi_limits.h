/* rtapi_limits.h - INT_MAX and friends for realtime code */
#ifndef RTAPI_LIMITS_H
#define RTAPI_LIMITS_H
#include <limits.h>
#endif
