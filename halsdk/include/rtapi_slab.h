/*
 * rtapi_slab.h - memory for component set-up code.  Call these only from
 * rtapi_app_main/rtapi_app_exit and EXTRA_SETUP/EXTRA_CLEANUP, never from
 * a realtime function.
 */
#ifndef RTAPI_SLAB_H
#define RTAPI_SLAB_H

#include <stdlib.h>

#include "rtapi_gfp.h"

static inline void *rtapi_kmalloc(size_t size, rtapi_gfp_t g)
{
    (void)g;
    return malloc(size);
}

static inline void *rtapi_kzalloc(size_t size, rtapi_gfp_t g)
{
    (void)g;
    return calloc(1, size);
}

static inline void *rtapi_krealloc(void *p, size_t size, rtapi_gfp_t g)
{
    (void)g;
    return realloc(p, size);
}

static inline void rtapi_kfree(void *p)
{
    free(p);
}

#endif
