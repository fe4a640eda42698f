/*
 * rtapi.h - the RTAPI calls of LinuxCNC-style realtime code, on halsdk.
 *
 * Components written for the reference's RTAPI compile against this
 * header unchanged.  Realtime code runs in the halsdk host process on its
 * pthreads; messages go to stderr, filtered by the message level.
 */
#ifndef RTAPI_H
#define RTAPI_H

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "halsdk_api.h"
#include "rtapi_stdint.h"
#include "rtapi_bool.h"
#include "rtapi_errno.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RTAPI_SUCCESS 0
#define RTAPI_NAME_LEN 31

typedef enum {
    RTAPI_MSG_NONE = 0,
    RTAPI_MSG_ERR,
    RTAPI_MSG_WARN,
    RTAPI_MSG_INFO,
    RTAPI_MSG_DBG,
    RTAPI_MSG_ALL
} msg_level_t;

static inline void rtapi_print_msg(msg_level_t level, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static inline void rtapi_print_msg(msg_level_t level, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    HALSDK_API->vprint_msg((int)level, fmt, ap);
    va_end(ap);
}

static inline void rtapi_print(const char *fmt, ...)
    __attribute__((format(printf, 1, 2)));
static inline void rtapi_print(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    HALSDK_API->vprint_msg(RTAPI_MSG_NONE, fmt, ap);
    va_end(ap);
}

#define rtapi_snprintf snprintf
#define rtapi_vsnprintf vsnprintf

static inline int rtapi_set_msg_level(int level)
{
    return HALSDK_API->set_msg_level(level);
}

static inline int rtapi_get_msg_level(void)
{
    return HALSDK_API->get_msg_level();
}

/* nanoseconds; simulated time while the instance is being stepped */
static inline long long int rtapi_get_time(void)
{
    return HALSDK_API->get_time();
}

static inline long long int rtapi_get_clocks(void)
{
    return HALSDK_API->get_clocks();
}

/* busy-wait on the real clock: short hardware delays only */
static inline void rtapi_delay(long int nsec)
{
    struct timespec a, b;
    clock_gettime(CLOCK_MONOTONIC, &a);
    do
        clock_gettime(CLOCK_MONOTONIC, &b);
    while ((b.tv_sec - a.tv_sec) * 1000000000L + (b.tv_nsec - a.tv_nsec)
           < nsec);
}

static inline long int rtapi_delay_max(void)
{
    return 10000;
}

#ifdef __cplusplus
}
#endif

#endif /* RTAPI_H */
