/*
 * hal_check.c - the trust boundary: what the core reads from the shared
 * segment before it follows it.
 *
 * Every process attached to an instance maps the whole segment writable,
 * so a stray write from a buggy component can leave any value in any
 * offset, count or list link.  The core checks every one before use
 * (hal_off_ok, hal_block_at, hal_obj_at in hal_core.h) and reports a bad
 * one as damage: "instance NAME is damaged: what, where" (-EUCLEAN), in
 * the process that finds it, instead of a crash or an endless walk.
 *
 * The header is checked when a process maps the segment and on each
 * listing (hal_check_header); the bounds the checks use are then copied
 * into hal_map, so that no later write into the header moves them.
 */
#define _GNU_SOURCE
#include "hal_core.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static __thread int damage;     /* damage reported since the last lock */

const char *hal_kind_word(int kind)
{
    static const char *const words[K_NKINDS] = {
        "object", "component", "instance", "pin", "param", "signal",
        "function", "thread", "stream", "shared block"
    };
    return kind > 0 && kind < K_NKINDS ? words[kind] : "object";
}

uint32_t hal_kind_size(int kind)
{
    switch (kind) {
    case K_COMP: return sizeof(hal_comp_t);
    case K_INST: return sizeof(hal_inst_t);
    case K_PIN: return sizeof(hal_pin_t);
    case K_PARAM: return sizeof(hal_param_t);
    case K_SIG: return sizeof(hal_sig_t);
    case K_FUNCT: return sizeof(hal_funct_t);
    case K_THREAD: return sizeof(hal_thread_t);
    case K_STREAM: return sizeof(hal_stream_t);
    case K_SHMEM: return sizeof(hal_shmem_t);
    }
    return sizeof(hal_obj_t);
}

void hal_layout(uint64_t size, hoff_t *buckets, uint32_t *nbuckets,
                hoff_t *heap_start)
{
    /* name index: about one bucket per 1 KiB of segment */
    uint32_t nb = 1024;
    while (nb < size / 1024 && nb < (1u << 20))
        nb <<= 1;
    *buckets = (hoff_t)((sizeof(hal_header_t) + 63) & ~63UL);
    *nbuckets = nb;
    *heap_start = (hoff_t)((*buckets + nb * sizeof(hoff_t) + 63) & ~63UL);
}

int hal_damaged(const char *fmt, ...)
{
    char what[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof(what), fmt, ap);
    va_end(ap);
    damage = 0;             /* hal_fail keeps a pending damage message */
    int r = hal_fail(EUCLEAN, "instance %s is damaged: %s",
                     hal_map.name[0] ? hal_map.name : "?", what);
    damage = 1;
    return r;
}

int hal_damage_seen(void)
{
    return damage;
}

int hal_damage_take(void)
{
    int d = damage;
    damage = 0;
    return d;
}

void *hal_obj_get(hoff_t off, int kind, const char *what, const char *name)
{
    void *o = hal_obj_at(off, kind);
    if (!o)
        hal_damaged("%s%s%s%s: offset %u is not a %s record", what,
                    name ? " '" : "", name ? name : "", name ? "'" : "",
                    off, hal_kind_word(kind));
    return o;
}

void *hal_walk_next(int kind, const hal_obj_t *o, long *steps)
{
    if (!o->next)
        return NULL;
    if (hal_walk_step(steps, SHMOFF(o), o->next)) {
        hal_damaged("the %s list does not end (a cycle after '%.40s')",
                    hal_kind_word(kind), o->name);
        return NULL;
    }
    return hal_obj_get(o->next, kind, "the next record after",
                       o->name);
}

void *hal_walk_first(int kind)
{
    hoff_t off = hal_map.hdr->list_head[kind];
    return off ? hal_obj_get(off, kind, "the first record of the",
                             hal_kind_word(kind))
               : NULL;
}

/* a free list's head: 0 or a free block */
static int free_head_ok(hoff_t off, int locked)
{
    if (!off)
        return 1;
    if (!hal_off_ok(off, sizeof(hal_block_t) + 16, HAL_ALIGN))
        return 0;
    return !locked || ((hal_block_t *)SHMPTR(off))->magic == HAL_BLOCK_FREE;
}

/* the header of the mapped segment; locked: the caller holds the lock,
   so lists and counts agree */
static int check_header(int locked)
{
    hal_header_t *h = hal_map.hdr;
    hoff_t buckets, heap_start;
    uint32_t nb;
    hal_layout((uint64_t)hal_map.size, &buckets, &nb, &heap_start);
    if (h->header_size != sizeof(hal_header_t))
        return hal_damaged("header size %u, expected %zu", h->header_size,
                           sizeof(hal_header_t));
    if (h->size != (uint64_t)hal_map.size)
        return hal_damaged("header says %llu bytes, the segment has %ld",
                           (unsigned long long)h->size, hal_map.size);
    if (h->buckets != buckets || h->nbuckets != nb)
        return hal_damaged("name index at offset %u with %u buckets, "
                           "expected %u with %u", h->buckets, h->nbuckets,
                           buckets, nb);
    if (h->heap_start != heap_start || h->heap_end != hal_map.size)
        return hal_damaged("heap %u..%u, expected %u..%ld", h->heap_start,
                           h->heap_end, heap_start, hal_map.size);
    if (h->heap_top < heap_start || h->heap_top > h->heap_end ||
        (h->heap_top - heap_start) % HAL_ALIGN)
        return hal_damaged("heap top %u is outside the heap %u..%u",
                           h->heap_top, heap_start, h->heap_end);
    for (int c = 0; c < HAL_NCLASSES; c++)
        if (!free_head_ok(h->free_class[c], locked))
            return hal_damaged("free list %d starts at offset %u, not at "
                               "a free block", c, h->free_class[c]);
    if (!free_head_ok(h->free_big, locked))
        return hal_damaged("the free list of big blocks starts at offset "
                           "%u, not at a free block", h->free_big);
    for (int k = 1; k < K_NKINDS; k++) {
        const char *w = hal_kind_word(k);
        if (h->count[k] < 0 || (uint64_t)h->count[k] > HAL_WALK_MAX)
            return hal_damaged("%s count %d is impossible", w, h->count[k]);
        if (h->list_head[k] && !hal_obj_at(h->list_head[k], k))
            return hal_damaged("the %s list starts at offset %u, not at "
                               "a %s record", w, h->list_head[k], w);
        if (h->list_tail[k] && !hal_obj_at(h->list_tail[k], k))
            return hal_damaged("the %s list ends at offset %u, not at a "
                               "%s record", w, h->list_tail[k], w);
        if (locked && ((h->list_head[k] == 0) != (h->count[k] == 0) ||
                       (h->list_tail[k] == 0) != (h->count[k] == 0)))
            return hal_damaged("%s count %d does not match its list", w,
                               h->count[k]);
    }
    return 0;
}

int hal_check_header(void)
{
    if (!hal_map.hdr)
        return hal_fail(ENODEV, "no HAL instance is attached");
    return check_header(1);
}

/* a segment just mapped (hal_map.base, .hdr, .size set): check the
   header and keep the bounds the checks use */
int hal_map_checked(void)
{
    hal_header_t *h = hal_map.hdr;
    hoff_t buckets, heap_start;
    uint32_t nb;
    char name[sizeof(h->instance)];
    memcpy(name, (const char *)h->instance, sizeof(name));
    name[sizeof(name) - 1] = 0;
    for (char *p = name; *p; p++)
        if (*p < ' ' || *p >= 127)
            *p = '?';
    snprintf(hal_map.name, sizeof(hal_map.name), "%s", name);
    hal_layout((uint64_t)hal_map.size, &buckets, &nb, &heap_start);
    hal_map.heap_start = heap_start;
    hal_map.heap_end = (hoff_t)hal_map.size;
    hal_map.buckets = buckets;
    hal_map.nbuckets = nb;
    if ((uint64_t)hal_map.size > 0xF0000000UL ||
        (uint64_t)hal_map.size < (uint64_t)heap_start + 4096)
        return hal_damaged("segment size %ld is impossible", hal_map.size);
    damage = 0;
    return check_header(0);
}
