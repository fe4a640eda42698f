/*
 * hal.h - the HAL calls of LinuxCNC-style components, on halsdk.
 *
 * Same names, types and return conventions as the reference's documented
 * HAL API (0 or a positive id on success, a negative errno on failure);
 * each call goes through the halsdk C API table.  Differences: names may
 * be up to HAL_NAME_LEN (127) characters, and 64-bit pin types exist.
 */
#ifndef HAL_H
#define HAL_H

#include <stdarg.h>
#include <stdio.h>

#include "rtapi.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HAL_NAME_LEN HALSDK_NAME_LEN

typedef volatile bool hal_bit_t;
typedef volatile rtapi_s32 hal_s32_t;
typedef volatile rtapi_u32 hal_u32_t;
typedef volatile rtapi_s64 hal_s64_t;
typedef volatile rtapi_u64 hal_u64_t;
typedef double real_t __attribute__((aligned(8)));
typedef rtapi_u64 ireal_t __attribute__((aligned(8)));
typedef volatile real_t hal_float_t;

typedef enum {
    HAL_TYPE_UNSPECIFIED = -1,
    HAL_TYPE_UNINITIALIZED = 0,
    HAL_BIT = HALSDK_BIT,
    HAL_FLOAT = HALSDK_FLOAT,
    HAL_S32 = HALSDK_S32,
    HAL_U32 = HALSDK_U32,
    HAL_S64 = HALSDK_S64,
    HAL_U64 = HALSDK_U64
} hal_type_t;

typedef enum {
    HAL_DIR_UNSPECIFIED = -1,
    HAL_IN = HALSDK_IN,
    HAL_OUT = HALSDK_OUT,
    HAL_IO = HALSDK_IO
} hal_pin_dir_t;

typedef enum {
    HAL_RO = HALSDK_RO,
    HAL_RW = HALSDK_RW
} hal_param_dir_t;

/* any HAL value: generic code reads a pin through a pointer to this
   union with the member of the pin's type (member names as LinuxCNC's;
   ls and lu for the 64-bit types, which the reference 2.9 lacks) */
typedef union {
    hal_bit_t b;
    hal_s32_t s;
    hal_u32_t u;
    hal_float_t f;
    hal_s64_t ls;
    hal_u64_t lu;
} hal_data_u;

#define HAL_LOCK_NONE 0
#define HAL_LOCK_LOAD 1
#define HAL_LOCK_CONFIG 2
#define HAL_LOCK_PARAMS 4
#define HAL_LOCK_RUN 8
#define HAL_LOCK_TUNE (HAL_LOCK_LOAD | HAL_LOCK_CONFIG)
#define HAL_LOCK_ALL 255

/* components */
static inline int hal_init(const char *name)
{
    return HALSDK_API->comp_new(name, -1);
}
static inline int hal_exit(int comp_id)
{
    return HALSDK_API->comp_exit(comp_id);
}
static inline int hal_ready(int comp_id)
{
    return HALSDK_API->comp_ready(comp_id);
}
static inline int hal_unready(int comp_id)
{
    return HALSDK_API->comp_unready(comp_id);
}
static inline int hal_set_unready(int comp_id)
{
    return HALSDK_API->comp_unready(comp_id);
}
/* the name of a component (or instance) of the instance, or NULL */
static inline char *hal_comp_name(int comp_id)
{
    return (char *)HALSDK_API->comp_name(comp_id);
}
static inline void *hal_malloc(long int size)
{
    return HALSDK_API->malloc(size);
}

/* pins */
static inline int hal_pin_new(const char *name, hal_type_t type,
                              hal_pin_dir_t dir, void **data_ptr_addr,
                              int comp_id)
{
    return HALSDK_API->pin_new(name, type, dir, data_ptr_addr, comp_id);
}

#define HALSDK_PIN_NEW_(tn, ctype, htype)                                  \
    static inline int hal_pin_##tn##_new(const char *name,                \
                                          hal_pin_dir_t dir,              \
                                          ctype **data_ptr_addr,          \
                                          int comp_id)                    \
    {                                                                     \
        return HALSDK_API->pin_new(name, htype, dir,                      \
                                   (void **)data_ptr_addr, comp_id);      \
    }                                                                     \
    static inline int hal_pin_##tn##_newf(hal_pin_dir_t dir,              \
                                           ctype **data_ptr_addr,         \
                                           int comp_id, const char *fmt,  \
                                           ...)                           \
        __attribute__((format(printf, 4, 5)));                            \
    static inline int hal_pin_##tn##_newf(hal_pin_dir_t dir,              \
                                           ctype **data_ptr_addr,         \
                                           int comp_id, const char *fmt,  \
                                           ...)                           \
    {                                                                     \
        char name[HAL_NAME_LEN + 2];                                      \
        va_list ap;                                                       \
        va_start(ap, fmt);                                                \
        int n = vsnprintf(name, sizeof(name), fmt, ap);                   \
        va_end(ap);                                                       \
        if (n > HAL_NAME_LEN) {                                           \
            rtapi_print_msg(RTAPI_MSG_ERR, "HAL: pin name '%s' is too "    \
                            "long\n", name);                              \
            return -ENOMEM;                                               \
        }                                                                 \
        return HALSDK_API->pin_new(name, htype, dir,                      \
                                   (void **)data_ptr_addr, comp_id);      \
    }

HALSDK_PIN_NEW_(bit, hal_bit_t, HAL_BIT)
HALSDK_PIN_NEW_(float, hal_float_t, HAL_FLOAT)
HALSDK_PIN_NEW_(s32, hal_s32_t, HAL_S32)
HALSDK_PIN_NEW_(u32, hal_u32_t, HAL_U32)
HALSDK_PIN_NEW_(s64, hal_s64_t, HAL_S64)
HALSDK_PIN_NEW_(u64, hal_u64_t, HAL_U64)

/* params */
static inline int hal_param_new(const char *name, hal_type_t type,
                                hal_param_dir_t dir,
                                volatile void *data_addr, int comp_id)
{
    return HALSDK_API->param_new(name, type, dir, data_addr, comp_id);
}

#define HALSDK_PARAM_NEW_(tn, ctype, htype)                                \
    static inline int hal_param_##tn##_new(const char *name,              \
                                            hal_param_dir_t dir,          \
                                            ctype *data_addr,             \
                                            int comp_id)                  \
    {                                                                     \
        return HALSDK_API->param_new(name, htype, dir, data_addr,         \
                                     comp_id);                            \
    }                                                                     \
    static inline int hal_param_##tn##_newf(hal_param_dir_t dir,          \
                                             ctype *data_addr,            \
                                             int comp_id,                 \
                                             const char *fmt, ...)        \
        __attribute__((format(printf, 4, 5)));                            \
    static inline int hal_param_##tn##_newf(hal_param_dir_t dir,          \
                                             ctype *data_addr,            \
                                             int comp_id,                 \
                                             const char *fmt, ...)        \
    {                                                                     \
        char name[HAL_NAME_LEN + 2];                                      \
        va_list ap;                                                       \
        va_start(ap, fmt);                                                \
        int n = vsnprintf(name, sizeof(name), fmt, ap);                   \
        va_end(ap);                                                       \
        if (n > HAL_NAME_LEN) {                                           \
            rtapi_print_msg(RTAPI_MSG_ERR, "HAL: param name '%s' is too "  \
                            "long\n", name);                              \
            return -ENOMEM;                                               \
        }                                                                 \
        return HALSDK_API->param_new(name, htype, dir, data_addr,         \
                                     comp_id);                            \
    }

HALSDK_PARAM_NEW_(bit, hal_bit_t, HAL_BIT)
HALSDK_PARAM_NEW_(float, hal_float_t, HAL_FLOAT)
HALSDK_PARAM_NEW_(s32, hal_s32_t, HAL_S32)
HALSDK_PARAM_NEW_(u32, hal_u32_t, HAL_U32)
HALSDK_PARAM_NEW_(s64, hal_s64_t, HAL_S64)
HALSDK_PARAM_NEW_(u64, hal_u64_t, HAL_U64)

/* set a param by name, as setp does: its type must match and it must
   be writable */
static inline int hal_param_set(const char *name, hal_type_t type,
                                void *value_addr)
{
    return HALSDK_API->param_set(name, type, value_addr);
}
static inline int hal_param_bit_set(const char *name, int value)
{
    rtapi_u8 v = value != 0;
    return HALSDK_API->param_set(name, HAL_BIT, &v);
}
static inline int hal_param_float_set(const char *name, double value)
{
    return HALSDK_API->param_set(name, HAL_FLOAT, &value);
}
static inline int hal_param_u32_set(const char *name, unsigned long value)
{
    rtapi_u32 v = (rtapi_u32)value;
    return HALSDK_API->param_set(name, HAL_U32, &v);
}
static inline int hal_param_s32_set(const char *name, signed long value)
{
    rtapi_s32 v = (rtapi_s32)value;
    return HALSDK_API->param_set(name, HAL_S32, &v);
}

/* where the value of a pin, signal or param is, and its type; 0, or a
   negative errno (the reference returns -1) */
static inline int hal_get_pin_value_by_name(const char *name,
                                            hal_type_t *type,
                                            hal_data_u **data,
                                            bool *connected)
{
    int t, f;
    void *d;
    int r = HALSDK_API->value_by_name(0, name, &t, &d, &f);
    if (r == 0) {
        *type = (hal_type_t)t;
        *data = (hal_data_u *)d;
        if (connected)
            *connected = f;
    }
    return r;
}
static inline int hal_get_signal_value_by_name(const char *name,
                                               hal_type_t *type,
                                               hal_data_u **data,
                                               bool *has_writers)
{
    int t, f;
    void *d;
    int r = HALSDK_API->value_by_name(1, name, &t, &d, &f);
    if (r == 0) {
        *type = (hal_type_t)t;
        *data = (hal_data_u *)d;
        if (has_writers)
            *has_writers = f;
    }
    return r;
}
static inline int hal_get_param_value_by_name(const char *name,
                                              hal_type_t *type,
                                              hal_data_u **data)
{
    int t;
    void *d;
    int r = HALSDK_API->value_by_name(2, name, &t, &d, NULL);
    if (r == 0) {
        *type = (hal_type_t)t;
        *data = (hal_data_u *)d;
    }
    return r;
}

/* aliases: an empty or NULL alias removes the alias */
static inline int hal_pin_alias(const char *pin_name, const char *alias)
{
    return HALSDK_API->pin_alias(pin_name, alias);
}
static inline int hal_param_alias(const char *param_name, const char *alias)
{
    return HALSDK_API->param_alias(param_name, alias);
}

/* signals */
static inline int hal_signal_new(const char *name, hal_type_t type)
{
    return HALSDK_API->signal_new(name, type);
}
static inline int hal_signal_delete(const char *name)
{
    return HALSDK_API->signal_delete(name);
}
static inline int hal_link(const char *pin_name, const char *sig_name)
{
    return HALSDK_API->link(pin_name, sig_name);
}
static inline int hal_unlink(const char *pin_name)
{
    return HALSDK_API->unlink(pin_name);
}

/* functions and threads */
static inline int hal_export_funct(const char *name,
                                   void (*funct)(void *, long), void *arg,
                                   int uses_fp, int reentrant, int comp_id)
{
    return HALSDK_API->export_funct(name, funct, arg, uses_fp, reentrant,
                                    comp_id);
}

static inline int hal_export_functf(void (*funct)(void *, long), void *arg,
                                    int uses_fp, int reentrant, int comp_id,
                                    const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));
static inline int hal_export_functf(void (*funct)(void *, long), void *arg,
                                    int uses_fp, int reentrant, int comp_id,
                                    const char *fmt, ...)
{
    char name[HAL_NAME_LEN + 2];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(name, sizeof(name), fmt, ap);
    va_end(ap);
    if (n > HAL_NAME_LEN)
        return -ENOMEM;
    return HALSDK_API->export_funct(name, funct, arg, uses_fp, reentrant,
                                    comp_id);
}

static inline int hal_create_thread(const char *name,
                                    unsigned long period_nsec, int uses_fp)
{
    return HALSDK_API->create_thread(name, period_nsec, uses_fp);
}
static inline int hal_thread_delete(const char *name)
{
    return HALSDK_API->thread_delete(name);
}
static inline int hal_add_funct_to_thread(const char *funct_name,
                                          const char *thread_name,
                                          int position)
{
    return HALSDK_API->add_funct_to_thread(funct_name, thread_name,
                                           position);
}
static inline int hal_del_funct_from_thread(const char *funct_name,
                                            const char *thread_name)
{
    return HALSDK_API->del_funct_from_thread(funct_name, thread_name);
}
static inline int hal_start_threads(void)
{
    return HALSDK_API->start_threads();
}
static inline int hal_stop_threads(void)
{
    return HALSDK_API->stop_threads();
}

/* a component that can make instances at run time: halcmd's
   'newinst COMP NAME [k=v ...]' calls make(NAME, "k=v ...") in the
   host.  Defined in the module's entry code (c_module.c). */
typedef int (*constructor)(char *prefix, char *arg);
typedef int (*hal_constructor_t)(const char *prefix, const char *arg);
extern int hal_set_constructor(int comp_id, constructor make);

/* halsdk additions: instances made at run time (newinst), and the
   message of the last failed call */
static inline int halsdk_inst_new(const char *name, int comp_id)
{
    return HALSDK_API->inst_new(name, comp_id);
}
static inline const char *halsdk_last_error(void)
{
    return HALSDK_API->last_error();
}

/* streams (halsdk): realtime-safe single-producer single-consumer FIFOs
   of records, one value (halsdk_value_t) per letter of the type string
   (f float, b bit, s s32, u u32, l s64, k u64).  A stream of depth D
   holds D - 1 records, as the reference's.  A handle is >= 0. */
typedef long long halsdk_stream_t;
static inline halsdk_stream_t halsdk_stream_create(const char *name,
                                                   int owner_id, int depth,
                                                   const char *typestring)
{
    return HALSDK_API->stream_create(name, owner_id, depth, typestring);
}
static inline halsdk_stream_t halsdk_stream_attach(const char *name)
{
    return HALSDK_API->stream_attach(name);
}
static inline int halsdk_stream_write(halsdk_stream_t s,
                                      const halsdk_value_t *rec)
{
    return HALSDK_API->stream_write(s, rec);
}
static inline int halsdk_stream_read(halsdk_stream_t s, halsdk_value_t *rec,
                                     rtapi_u64 *sampleno)
{
    return HALSDK_API->stream_read(s, rec, (uint64_t *)sampleno);
}
static inline int halsdk_stream_depth(halsdk_stream_t s)
{
    return HALSDK_API->stream_depth(s);
}
static inline int halsdk_stream_maxdepth(halsdk_stream_t s)
{
    return HALSDK_API->stream_maxdepth(s);
}
static inline long long halsdk_stream_num_overruns(halsdk_stream_t s)
{
    return HALSDK_API->stream_num_overruns(s);
}
static inline long long halsdk_stream_num_underruns(halsdk_stream_t s)
{
    return HALSDK_API->stream_num_underruns(s);
}
static inline int halsdk_stream_nelem(halsdk_stream_t s)
{
    return HALSDK_API->stream_nelem(s);
}
static inline int halsdk_stream_elem_type(halsdk_stream_t s, int index)
{
    return HALSDK_API->stream_elem_type(s, index);
}

static inline int hal_set_lock(unsigned char lock_type)
{
    return HALSDK_API->set_lock(lock_type);
}
static inline unsigned char hal_get_lock(void)
{
    return HALSDK_API->get_lock();
}

#ifdef __cplusplus
}
#endif

#endif /* HAL_H */
