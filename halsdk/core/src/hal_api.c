/*
 * hal_api.c - the C API table that component modules call through.
 */
#define _GNU_SOURCE
#include "hal_core.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

/* set by the loader while a module's setup runs: its hal_init()s are
   realtime components */
int hal_loading_rt;

int exec_start_all(int want_rt, char *note, int notelen);

static int api_comp_new(const char *name, int kind)
{
    if (kind < 0)
        kind = hal_loading_rt ? HALSDK_COMP_RT : HALSDK_COMP_USER;
    return hal_comp_new(name, kind);
}

static int api_comp_ready(int id)
{
    return hal_comp_set_ready(id, 1);
}

static int api_comp_unready(int id)
{
    return hal_comp_set_ready(id, 0);
}

static void *api_malloc(long size)
{
    extern void *hal_malloc_current(long size);
    return hal_malloc_current(size);
}

static int api_pin_alias(const char *name, const char *alias)
{
    return alias && *alias ? hal_alias(K_PIN, name, alias)
                           : hal_unalias(K_PIN, name);
}

static int api_param_alias(const char *name, const char *alias)
{
    return alias && *alias ? hal_alias(K_PARAM, name, alias)
                           : hal_unalias(K_PARAM, name);
}

static int api_export_funct(const char *name, halsdk_funct_t fn, void *arg,
                            int uses_fp, int reentrant, int owner_id)
{
    return hal_export_funct(name, fn, arg, uses_fp, reentrant, owner_id, 0);
}

static int api_create_thread(const char *name, unsigned long period,
                             int uses_fp)
{
    return hal_thread_new(name, (long)period, uses_fp, 0);
}

static int api_start_threads(void)
{
    char note[200] = "";
    int r = exec_start_all(1, note, sizeof(note));
    if (note[0])
        fprintf(stderr, "%s\n", note);
    return r;
}

static int api_set_lock(unsigned char lock)
{
    return hal_set_lock(lock);
}

static unsigned char api_get_lock(void)
{
    return hal_map.hdr ? (unsigned char)hal_map.hdr->lock : 0;
}

/* while a module sets up, its messages are kept: the loader shows them
   as the error of a failed load, or prints them after a good one */
static __thread int capturing;
static __thread char captured[4096];
static __thread size_t ncaptured;

static void api_vprint_msg(int level, const char *fmt, va_list ap)
{
    int cur = hal_map.hdr ? hal_map.hdr->msg_level : 1;
    if (level > cur)
        return;
    if (!capturing) {
        vfprintf(stderr, fmt, ap);
        return;
    }
    size_t room = sizeof(captured) - ncaptured;
    if (room <= 1)
        return;
    int n = vsnprintf(captured + ncaptured, room, fmt, ap);
    if (n > 0)
        ncaptured += (size_t)n < room ? (size_t)n : room - 1;
}

static void api_msg_capture(int on)
{
    capturing = on;
    if (on) {
        ncaptured = 0;
        captured[0] = 0;
        hal_fail(0, "%s", "");
    }
}

static const char *api_captured_msgs(void)
{
    return captured;
}

static int api_set_msg_level(int level)
{
    if (level < 0 || level > 5)
        return -EINVAL;
    if (hal_map.hdr)
        hal_map.hdr->msg_level = level;
    return 0;
}

static int api_get_msg_level(void)
{
    return hal_map.hdr ? hal_map.hdr->msg_level : 1;
}

/* the name of a component or instance of this instance, or NULL */
static const char *api_comp_name(int id)
{
    if (!hal_map.hdr || hal_lock())
        return NULL;
    hal_comp_t *c = hal_comp_by_id(id);
    hal_inst_t *i = c ? NULL : hal_inst_by_id(id);
    const char *name = c ? c->o.name : i ? i->o.name : NULL;
    hal_unlock();
    return name;
}

static long type_bytes(int type)
{
    switch (type) {
    case HALSDK_BIT: return 1;
    case HALSDK_S32: case HALSDK_U32: return 4;
    case HALSDK_FLOAT: case HALSDK_S64: case HALSDK_U64: return 8;
    default: return 0;
    }
}

/* set a param by name from a value of its type, as setp does */
static int api_param_set(const char *name, int type, const void *value)
{
    if (!name || !value)
        return hal_fail(EINVAL, "hal_param_set: no name or no value");
    if (!hal_map.hdr)
        return hal_fail(ENODEV, "no HAL instance is attached");
    int r = hal_lock();
    if (r)
        return r;
    hal_param_t *p = hal_find(K_PARAM, name);
    if (!p)
        r = hal_fail(ENOENT, "param '%s' not found", name);
    else if (p->type != type)
        r = hal_fail(EINVAL, "param '%s': type %d does not match its "
                     "type %d", name, type, p->type);
    else if (!(r = hal_check_settable(&p->o, 0))) {
        void *data = hal_param_value(p);
        if (type == HALSDK_BIT)
            *(volatile uint8_t *)data = *(const uint8_t *)value != 0;
        else
            memcpy(data, value, (size_t)type_bytes(type));
    }
    hal_unlock();
    return r;
}

/* where the value of a pin (kind 0), signal (1) or param (2) is; flag:
   a pin is linked / a signal has a writer */
static int api_value_by_name(int kind, const char *name, int *type,
                             void **data, int *flag)
{
    static const int kinds[] = {K_PIN, K_SIG, K_PARAM};
    if (!name || kind < 0 || kind > 2)
        return hal_fail(EINVAL, "hal_get_value_by_name: bad arguments");
    if (!hal_map.hdr)
        return hal_fail(ENODEV, "no HAL instance is attached");
    int r = hal_lock();
    if (r)
        return r;
    void *o = hal_find(kinds[kind], name);
    int f = 0;
    if (!o) {
        hal_unlock();
        return hal_fail(ENOENT, "%s '%s' not found",
                        kind == 0 ? "pin" : kind == 1 ? "signal" : "param",
                        name);
    }
    if (kind == 0) {
        hal_pin_t *p = o;
        *type = p->type;
        *data = (void *)hal_pin_value(p);
        f = p->signal != 0;
    } else if (kind == 1) {
        hal_sig_t *s = o;
        *type = s->type;
        *data = (void *)&s->value;
        f = s->writers > 0;
    } else {
        hal_param_t *p = o;
        *type = p->type;
        *data = hal_param_value(p);
    }
    if (flag)
        *flag = f;
    hal_unlock();
    return 0;
}

const halsdk_api halsdk_api_table = {
    .version = HALSDK_API_VERSION,
    .size = sizeof(halsdk_api),
    .comp_new = api_comp_new,
    .comp_exit = hal_comp_exit,
    .comp_ready = api_comp_ready,
    .comp_unready = api_comp_unready,
    .inst_new = hal_inst_new,
    .malloc = api_malloc,
    .pin_new = hal_pin_new,
    .param_new = hal_param_new,
    .pin_alias = api_pin_alias,
    .param_alias = api_param_alias,
    .signal_new = hal_signal_new,
    .signal_delete = hal_signal_delete,
    .link = hal_link,
    .unlink = hal_unlink,
    .export_funct = api_export_funct,
    .create_thread = api_create_thread,
    .thread_delete = hal_thread_delete,
    .add_funct_to_thread = hal_addf,
    .del_funct_from_thread = hal_delf,
    .start_threads = api_start_threads,
    .stop_threads = hal_stop_threads,
    .set_lock = api_set_lock,
    .get_lock = api_get_lock,
    .vprint_msg = api_vprint_msg,
    .set_msg_level = api_set_msg_level,
    .get_msg_level = api_get_msg_level,
    .get_time = hal_get_time,
    .get_clocks = hal_get_clocks,
    .last_error = hal_last_error,
    .stream_create = hal_stream_create,
    .stream_attach = hal_stream_attach,
    .stream_write = hal_stream_write,
    .stream_read = hal_stream_read,
    .stream_depth = hal_stream_depth,
    .stream_maxdepth = hal_stream_maxdepth,
    .stream_num_overruns = hal_stream_num_overruns,
    .stream_num_underruns = hal_stream_num_underruns,
    .stream_nelem = hal_stream_nelem,
    .stream_elem_type = hal_stream_elem_type,
    .msg_capture = api_msg_capture,
    .captured_msgs = api_captured_msgs,
    .shmem_new = hal_shmem_new,
    .shmem_attach = hal_shmem_attach,
    .shmem_ptr = hal_shmem_ptr,
    .shmem_size = hal_shmem_size,
    .symbol_export = hal_symbol_export,
    .symbol_find = hal_symbol_find,
    .symbol_drop = hal_symbol_drop,
    .symbol_user = hal_symbol_user,
    .comp_name = api_comp_name,
    .param_set = api_param_set,
    .value_by_name = api_value_by_name,
};
