/*
 * hal_shmem.c - named shared blocks: memory in the instance segment that
 * a realtime module shares with other processes (the motion module's
 * command and status channel), found by name like any other object.
 *
 * Handles pack generation and offset like stream handles, so a handle of
 * a deleted block is seen as stale.  The data is zeroed at creation and
 * aligned to 64 bytes; what goes on inside is the owner's protocol.
 */
#define _GNU_SOURCE
#include "hal_core.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define ALIGN 64

static long long handle_of(hal_shmem_t *b)
{
    return ((long long)b->o.gen << 32) | (long long)SHMOFF(b);
}

static hal_shmem_t *block_of(long long handle)
{
    hal_header_t *h = hal_map.hdr;
    if (!h || handle < 0)
        return NULL;
    hoff_t off = (hoff_t)(handle & 0xffffffffLL);
    uint32_t gen = (uint32_t)((unsigned long long)handle >> 32);
    if (off < h->heap_start || off + sizeof(hal_shmem_t) > h->heap_end)
        return NULL;
    hal_shmem_t *b = SHMPTR(off);
    if (__atomic_load_n(&b->o.kind, __ATOMIC_ACQUIRE) != K_SHMEM ||
        b->o.gen != gen)
        return NULL;
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
        (uint64_t)(hal_map.hdr->heap_end - hal_map.hdr->heap_start))
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
    ret = handle_of(b);
out:
    hal_unlock();
    return ret;
}

long long hal_shmem_attach(const char *name)
{
    if (!name || !*name)
        return hal_fail(EINVAL, "shared block name is empty");
    int r = hal_lock();
    if (r)
        return r;
    hal_shmem_t *b = hal_find(K_SHMEM, name);
    long long ret = b ? handle_of(b)
                      : hal_fail(ENOENT, "shared block '%s' not found",
                                 name);
    hal_unlock();
    return ret;
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

/* lock held: remove the blocks of a component (inst == 0) or of one of
   its instances */
void hal_shmem_delete_of(hoff_t comp, hoff_t inst)
{
    hal_header_t *h = hal_map.hdr;
    for (hoff_t o = h->list_head[K_SHMEM]; o;) {
        hal_shmem_t *b = SHMPTR(o);
        o = b->o.next;
        if (b->comp == comp && (!inst || b->inst == inst))
            hal_obj_delete(&b->o);
    }
}
