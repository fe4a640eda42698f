/*
 * hal_shmem.c - named shared blocks: memory in the instance segment that
 * a realtime module shares with other processes (the motion module's
 * command and status channel), found by name like any other object.
 *
 * Blocks are held by handle (hal_handle_get, hal_core.h).  The data is
 * zeroed at creation and aligned to 64 bytes; what goes on inside is the
 * owner's protocol.
 */
#define _GNU_SOURCE
#include "hal_core.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define ALIGN 64

static hal_shmem_t *block_of(long long handle)
{
    hal_shmem_t *b = hal_handle_get(handle, K_SHMEM, sizeof(hal_shmem_t));
    if (b && (b->data < SHMOFF(b) + sizeof(hal_shmem_t) ||
              !hal_off_ok(b->data, b->size, ALIGN))) {
        hal_damaged("shared block '%.40s': %llu bytes at offset %u are "
                    "outside the heap", b->o.name,
                    (unsigned long long)b->size, b->data);
        return NULL;
    }
    return b;
}

long long hal_shmem_new(const char *name, int owner_id, long size)
{
    char what[HAL_NAME_SIZE + 24];
    int r = hal_check_name(name, "shared block");
    if (r)
        return r;
    snprintf(what, sizeof(what), "shared block '%s'", name);
    if (!hal_map.hdr)
        return hal_fail(ENODEV, "no HAL instance is attached");
    if (size < 1 || (uint64_t)size + sizeof(hal_shmem_t) + ALIGN >
        (uint64_t)(hal_map.heap_end - hal_map.heap_start))
        return hal_fail(size < 1 ? EINVAL : ENOMEM, "%s: size %ld does "
                        "not fit in the HAL instance", what, size);
    if ((r = hal_lock()))
        return r;
    hoff_t comp = 0, inst = 0;
    long long ret = hal_owner(owner_id, what, &comp, &inst);
    if (ret)
        goto out;
    if (hal_find(K_SHMEM, name)) {
        ret = hal_fail(EEXIST, "duplicate shared block name '%s'", name);
        goto out;
    }
    hal_shmem_t *b = hal_obj_new(K_SHMEM,
                                 (long)(sizeof(hal_shmem_t) + ALIGN + size),
                                 name);
    if (!b) {
        ret = -ENOMEM;
        goto out;
    }
    hoff_t data = SHMOFF(b) + (hoff_t)sizeof(hal_shmem_t);
    data = (data + ALIGN - 1) & ~(hoff_t)(ALIGN - 1);
    memset(SHMPTR(data), 0, (size_t)size);
    b->comp = comp;
    b->inst = inst;
    b->data = data;
    b->size = (uint64_t)size;
    hal_obj_publish(&b->o);
    ret = hal_handle_of(&b->o);
out:
    hal_unlock();
    return ret;
}

long long hal_shmem_attach(const char *name)
{
    return hal_handle_attach(K_SHMEM, name);
}

void *hal_shmem_ptr(long long handle)
{
    hal_shmem_t *b = block_of(handle);
    return b ? SHMPTR(b->data) : NULL;
}

long hal_shmem_size(long long handle)
{
    hal_shmem_t *b = block_of(handle);
    return b ? (long)b->size : -ENOENT;
}
