/*
 * rtapi.h - the RTAPI calls of LinuxCNC-style realtime code, on halsdk.
 *
 * Components written for the reference's RTAPI compile against this
 * header unchanged.  Realtime code runs in the halsdk host process on its
 * pthreads; messages go to stderr, filtered by the message level.
 *
 * What the reference declares here and halsdk does not provide (tasks,
 * semaphores, fifos, interrupts, port I/O, running programs as root) is
 * left undeclared on purpose: a module that calls it fails to compile
 * with the name of the call.  docs/compat.md lists every name.
 */
#ifndef RTAPI_H
#define RTAPI_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "halsdk_api.h"
#include "halsdk_module.h"
#include "rtapi_stdint.h"
#include "rtapi_bool.h"
#include "rtapi_errno.h"

#ifdef __cplusplus
#define RTAPI_BEGIN_DECLS extern "C" {
#define RTAPI_END_DECLS }
#else
#define RTAPI_BEGIN_DECLS
#define RTAPI_END_DECLS
#endif

RTAPI_BEGIN_DECLS

#define RTAPI_SUCCESS 0
#define RTAPI_NAME_LEN 31

/* the uses_fp argument of the reference's task calls (and of
   hal_create_thread) */
#define RTAPI_NO_FP 0
#define RTAPI_USES_FP 1

typedef enum {
    RTAPI_MSG_NONE = 0,
    RTAPI_MSG_ERR,
    RTAPI_MSG_WARN,
    RTAPI_MSG_INFO,
    RTAPI_MSG_DBG,
    RTAPI_MSG_ALL
} msg_level_t;

typedef void (*rtapi_msg_handler_t)(msg_level_t level, const char *fmt,
                                    va_list ap);

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

/* the C library's, which are safe in the host's realtime threads */
static inline int rtapi_vsnprintf(char *buf, unsigned long int size,
                                  const char *fmt, va_list ap)
{
    return vsnprintf(buf, size, fmt, ap);
}

static inline int rtapi_snprintf(char *buf, unsigned long int size,
                                 const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static inline int rtapi_snprintf(char *buf, unsigned long int size,
                                 const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, size, fmt, ap);
    va_end(ap);
    return n;
}

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

/* busy-wait on the real clock: short hardware delays only; at most
   rtapi_delay_max() nanoseconds */
static inline long int rtapi_delay_max(void)
{
    return 10000;
}

static inline void rtapi_delay(long int nsec)
{
    struct timespec a, b;
    if (nsec > rtapi_delay_max())
        nsec = rtapi_delay_max();
    clock_gettime(CLOCK_MONOTONIC, &a);
    do
        clock_gettime(CLOCK_MONOTONIC, &b);
    while ((b.tv_sec - a.tv_sec) * 1000000000L + (b.tv_nsec - a.tv_nsec)
           < nsec);
}

/* shared memory blocks, found by key from any process attached to the
   instance.  module_id is the id hal_init() returned (the block goes
   with that component); a second rtapi_shmem_new() of a key, in any
   module or process, gets the same block.  The functions live in the
   module's entry code (halsdk/core/src/c_module.c). */
extern int rtapi_shmem_new(int key, int module_id, unsigned long int size);
extern int rtapi_shmem_delete(int shmem_id, int module_id);
extern int rtapi_shmem_getptr(int shmem_id, void **ptr);

/* the host is a normal process: no kernel modules, and no promise of
   hard realtime (its threads use SCHED_FIFO when allowed) */
static inline int rtapi_is_kernelspace(void)
{
    return 0;
}

static inline int rtapi_is_realtime(void)
{
    return 0;
}

/* I/O regions are a kernel matter: granted, as the reference does in
   user space */
#define rtapi_request_region(base, size, name) ((void *)-1)
#define rtapi_release_region(base, size) ((void)0)

static inline long int simple_strtol(const char *nptr, char **endptr,
                                     int base)
{
    return strtol(nptr, endptr, base);
}

/* module information and parameters.  Each MODULE_* use makes its own
   (unused) string, so a comp may repeat in its code section what
   halcompile writes for its author, description and license */
#define RTAPI_STRINGIFY(x) #x
#define HALSDK_CAT2_(a, b) a##b
#define HALSDK_CAT_(a, b) HALSDK_CAT2_(a, b)
#define HALSDK_MODINFO_(tag, s)                                           \
    __attribute__((used)) static const char                               \
        HALSDK_CAT_(halsdk_##tag##_, __COUNTER__)[] = s
#define MODULE_LICENSE(s) HALSDK_MODINFO_(license, s)
#define MODULE_AUTHOR(s) HALSDK_MODINFO_(author, s)
#define MODULE_DESCRIPTION(s) HALSDK_MODINFO_(description, s)
#define MODULE_SUPPORTED_DEVICE(s) HALSDK_MODINFO_(device, s)
#define MODULE_INFO(tag, s)
#define MODULE_PARM_DESC(var, s)

#ifndef KERNEL_VERSION
#define KERNEL_VERSION(a, b, c) (((a) << 16) + ((b) << 8) + (c))
#endif
#ifndef LINUX_VERSION_CODE
#define LINUX_VERSION_CODE 0
#endif

/* module parameters: each one registers itself, when the module is
   loaded, in the table that the module's entry code reads to apply the
   parameters of a loadrt line before rtapi_app_main() runs */
#define HALSDK_MP_(var, kind, count, desc)                                 \
    static void __attribute__((constructor)) halsdk_mp_reg_##var(void)     \
    {                                                                      \
        halsdk_modparam_register(#var, kind, (void *)&(var), count, desc); \
    }

#define RTAPI_MP_INT(var, desc) HALSDK_MP_(var, 'i', 1, desc)
#define RTAPI_MP_LONG(var, desc) HALSDK_MP_(var, 'l', 1, desc)
#define RTAPI_MP_STRING(var, desc) HALSDK_MP_(var, 's', 1, desc)
/* type: "i", "l" or "s" */
#define RTAPI_MP_ARRAY(type, var, num, desc)                               \
    HALSDK_MP_(var, (char)((type)[0] - 'a' + 'A'), num, desc)
#define RTAPI_MP_ARRAY_INT(var, num, desc) HALSDK_MP_(var, 'I', num, desc)
#define RTAPI_MP_ARRAY_LONG(var, num, desc) HALSDK_MP_(var, 'L', num, desc)
#define RTAPI_MP_ARRAY_STRING(var, num, desc) HALSDK_MP_(var, 'S', num, desc)

/* offer sym (a function or variable of this module) to the modules
   loaded after it; they find it with halsdk_symbol_find("sym") */
#define EXPORT_SYMBOL(sym)                                                 \
    static void __attribute__((constructor)) halsdk_sym_reg_##sym(void)    \
    {                                                                      \
        halsdk_symbol_register(#sym, (void *)&(sym));                      \
    }
#define EXPORT_SYMBOL_GPL(sym) EXPORT_SYMBOL(sym)

/* the address a loaded module exported as name, or NULL; records that
   this module uses that one (which then cannot be unloaded first) */
#define halsdk_symbol_find(name) \
    (HALSDK_API->symbol_find((name), halsdk_module_name))

RTAPI_END_DECLS

#endif /* RTAPI_H */
