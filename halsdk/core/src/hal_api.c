/*
 * hal_api.c - the C API table that component modules call through.
 */
#define _GNU_SOURCE
#include "hal_core.h"

#include <errno.h>
#include <stdio.h>

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
};
