/*
 * halsdk_api.h - the C API that compiled components use.
 *
 * The core exports one table of function pointers behind the capsule
 * "halsdk.core._core._C_API".  A component module fills its copy of the table
 * pointer once at import time (import_halsdk()) and then calls the API at
 * C speed.  hal.h and rtapi.h are thin inline wrappers over this table.
 *
 * The table only ever grows: new entries are appended and
 * HALSDK_API_VERSION is raised, so a module built against an older header
 * keeps working with a newer core.
 */
#ifndef HALSDK_API_H
#define HALSDK_API_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define HALSDK_API_VERSION 5
#define HALSDK_CAPSULE_NAME "halsdk.core._core._C_API"

/* longest object name, not counting the terminating NUL */
#define HALSDK_NAME_LEN 127

/* object types, with the reference's numeric values */
#define HALSDK_BIT 1
#define HALSDK_FLOAT 2
#define HALSDK_S32 3
#define HALSDK_U32 4
#define HALSDK_S64 6
#define HALSDK_U64 7

/* directions */
#define HALSDK_IN 16
#define HALSDK_OUT 32
#define HALSDK_IO 48
#define HALSDK_RO 64
#define HALSDK_RW 192

/* component kinds */
#define HALSDK_COMP_USER 0
#define HALSDK_COMP_RT 1

typedef void (*halsdk_funct_t)(void *arg, long period);

/* one value of a stream record (8 bytes, the member of the element type) */
typedef union {
    uint8_t b;
    int32_t s;
    uint32_t u;
    double f;
    int64_t ls;
    uint64_t lu;
} halsdk_value_t;

/* most values per stream record */
#define HALSDK_STREAM_MAX_ELEMS 256

typedef struct halsdk_api {
    int version;
    int size;                    /* sizeof(struct halsdk_api) of the core */

    /* components and instances */
    int (*comp_new)(const char *name, int kind);
    int (*comp_exit)(int comp_id);
    int (*comp_ready)(int comp_id);
    int (*comp_unready)(int comp_id);
    int (*inst_new)(const char *name, int comp_id);
    void *(*malloc)(long size);

    /* pins and params */
    int (*pin_new)(const char *name, int type, int dir,
                   void **data_ptr_addr, int owner_id);
    int (*param_new)(const char *name, int type, int dir,
                     volatile void *data_addr, int owner_id);
    int (*pin_alias)(const char *pin_name, const char *alias);
    int (*param_alias)(const char *param_name, const char *alias);

    /* signals */
    int (*signal_new)(const char *name, int type);
    int (*signal_delete)(const char *name);
    int (*link)(const char *pin_name, const char *sig_name);
    int (*unlink)(const char *pin_name);

    /* functions and threads */
    int (*export_funct)(const char *name, halsdk_funct_t funct, void *arg,
                        int uses_fp, int reentrant, int owner_id);
    int (*create_thread)(const char *name, unsigned long period_nsec,
                         int uses_fp);
    int (*thread_delete)(const char *name);
    int (*add_funct_to_thread)(const char *funct_name,
                               const char *thread_name, int position);
    int (*del_funct_from_thread)(const char *funct_name,
                                 const char *thread_name);
    int (*start_threads)(void);
    int (*stop_threads)(void);

    /* locking */
    int (*set_lock)(unsigned char lock_type);
    unsigned char (*get_lock)(void);

    /* messages, time */
    void (*vprint_msg)(int level, const char *fmt, va_list ap);
    int (*set_msg_level)(int level);
    int (*get_msg_level)(void);
    long long (*get_time)(void);
    long long (*get_clocks)(void);
    const char *(*last_error)(void);

    /* --- version 2: streams (realtime-safe FIFOs) --- */
    /* handles are >= 0; errors are -errno.  write and read never block,
       lock or allocate: -ENOSPC when full, -EAGAIN when empty */
    long long (*stream_create)(const char *name, int owner_id, int depth,
                               const char *typestring);
    long long (*stream_attach)(const char *name);
    int (*stream_write)(long long handle, const halsdk_value_t *rec);
    int (*stream_read)(long long handle, halsdk_value_t *rec,
                       uint64_t *sampleno);
    int (*stream_depth)(long long handle);
    int (*stream_maxdepth)(long long handle);
    long long (*stream_num_overruns)(long long handle);
    long long (*stream_num_underruns)(long long handle);
    int (*stream_nelem)(long long handle);
    int (*stream_elem_type)(long long handle, int index);

    /* --- version 3: the messages of a module's setup --- */
    /* msg_capture(1) keeps what rtapi_print_msg prints in this thread
       (and clears last_error) until msg_capture(0); captured_msgs()
       returns the text kept */
    void (*msg_capture)(int on);
    const char *(*captured_msgs)(void);

    /* --- version 4: named shared blocks and exported symbols --- */
    /* a block of size bytes (zeroed, 64-byte aligned) in the instance,
       found by name from any attached process and removed with its
       owner; handles are >= 0, errors -errno */
    long long (*shmem_new)(const char *name, int owner_id, long size);
    long long (*shmem_attach)(const char *name);
    void *(*shmem_ptr)(long long handle);       /* NULL: stale handle */
    long (*shmem_size)(long long handle);
    /* symbols that one realtime module offers to others in the host
       process (EXPORT_SYMBOL); find records the module that uses it,
       so that the exporter cannot be unloaded first */
    int (*symbol_export)(const char *name, void *addr, const char *module);
    void *(*symbol_find)(const char *name, const char *user_module);
    void (*symbol_drop)(const char *module);
    const char *(*symbol_user)(const char *module);

    /* --- version 5: the reference's lookups by id and by name --- */
    /* the name of a component or instance (NULL: no such id) */
    const char *(*comp_name)(int comp_id);
    /* set a param from a value of its type (0 or -errno) */
    int (*param_set)(const char *name, int type, const void *value);
    /* the type and value of a pin (kind 0), signal (1) or param (2);
       *flag: the pin is linked / the signal has a writer */
    int (*value_by_name)(int kind, const char *name, int *type,
                         void **data, int *flag);
} halsdk_api;

#ifdef __cplusplus
}
#endif

/*
 * One pointer per translation unit; import_halsdk() fills it.  A module
 * made of several C files defines HALSDK_API_EXTERN in all but one of
 * them so they share the pointer of the one that imports.
 */
#ifdef HALSDK_CORE
extern const halsdk_api halsdk_api_table;
#define HALSDK_API (&halsdk_api_table)
#else
#ifdef HALSDK_API_EXTERN
extern const halsdk_api *halsdk_api_ptr;
#else
const halsdk_api *halsdk_api_ptr;
#endif
#define HALSDK_API halsdk_api_ptr

#ifdef Py_PYTHON_H
/* Fill the table pointer; returns 0, or -1 with a Python error set. */
static inline int import_halsdk(void)
{
    PyObject *mod = PyImport_ImportModule("halsdk.core._core");
    if (!mod)
        return -1;
    Py_DECREF(mod);
    halsdk_api_ptr = (const halsdk_api *)PyCapsule_Import(
        HALSDK_CAPSULE_NAME, 0);
    if (!halsdk_api_ptr)
        return -1;
    if (halsdk_api_ptr->version < HALSDK_API_VERSION) {
        PyErr_Format(PyExc_ImportError,
                     "halsdk core API version %d is older than %d, "
                     "which this module was built for",
                     halsdk_api_ptr->version, HALSDK_API_VERSION);
        halsdk_api_ptr = NULL;
        return -1;
    }
    return 0;
}
#endif
#endif

#endif /* HALSDK_API_H */
