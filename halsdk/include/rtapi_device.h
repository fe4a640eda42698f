/*
 * rtapi_device.h - a named device record, as drivers ported from the
 * kernel keep one.  Registering does nothing in the halsdk host;
 * unregistering calls the record's release function.
 */
#ifndef RTAPI_DEVICE_H
#define RTAPI_DEVICE_H

#include <stdarg.h>
#include <stdio.h>

#include "rtapi.h"

RTAPI_BEGIN_DECLS

#define RTAPI_DEVICE_NAME_LEN 47

struct rtapi_device {
    char name[RTAPI_DEVICE_NAME_LEN + 1];
    void (*release)(struct rtapi_device *dev);
};

static inline int rtapi_dev_set_name(struct rtapi_device *dev,
                                     const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static inline int rtapi_dev_set_name(struct rtapi_device *dev,
                                     const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(dev->name, sizeof(dev->name), fmt, ap);
    va_end(ap);
    return n;
}

static inline int rtapi_device_register(struct rtapi_device *dev)
{
    (void)dev;
    return 0;
}

static inline void rtapi_device_unregister(struct rtapi_device *dev)
{
    if (dev->release)
        dev->release(dev);
}

RTAPI_END_DECLS

#endif
