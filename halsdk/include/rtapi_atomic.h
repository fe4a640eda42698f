/* rtapi_atomic.h - C11 atomics (atomic_load, atomic_store, memory_order_*)
   for realtime code shared with other threads or processes */
#ifndef RTAPI_ATOMIC_H
#define RTAPI_ATOMIC_H
#define RTAPI_USE_STDATOMIC
#include <stdatomic.h>
#endif
