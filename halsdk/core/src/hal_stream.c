/*
 * hal_stream.c - streams: named single-producer single-consumer FIFOs of
 * fixed-layout records in the instance segment (sampler, streamer, the
 * Python capture API).
 *
 * Creating, finding and deleting a stream take the instance mutex.
 * Writing and reading never do: the writer owns write_idx and sampleno,
 * the reader owns read_idx, and each publishes its index with a release
 * store after it has copied the record, so the other side sees a whole
 * record once it sees the index (acquire load).  Nothing on that path
 * allocates, locks or makes a system call.
 *
 * A stream of depth D holds D - 1 records, as the reference's streams do
 * (its rings keep one slot empty): `loadrt sampler depth=D`, halstreamer
 * and the Python hal.stream see full and empty where the reference does.
 *
 * Streams are held by handle (hal_handle_get, hal_core.h).
 */
#define _GNU_SOURCE
#include "hal_core.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define RING(s) ((char *)(s) + sizeof(hal_stream_t))

int hal_stream_parse_types(const char *typestring, uint8_t *types,
                           const char *what)
{
    int n = 0;
    if (!typestring || !*typestring)
        return hal_fail(EINVAL, "%s: empty type string (one letter per "
                        "value: f float, b bit, s s32, u u32, l s64, "
                        "k u64)", what);
    for (const char *p = typestring; *p; p++) {
        int t;
        switch (*p) {
        case 'f': case 'F': t = HALSDK_FLOAT; break;
        case 'b': case 'B': t = HALSDK_BIT; break;
        case 's': case 'S': t = HALSDK_S32; break;
        case 'u': case 'U': t = HALSDK_U32; break;
        case 'l': case 'L': t = HALSDK_S64; break;
        case 'k': case 'K': t = HALSDK_U64; break;
        default:
            return hal_fail(EINVAL, "%s: unknown type '%c' in type string "
                            "'%s' (letters: f float, b bit, s s32, u u32, "
                            "l s64, k u64)", what, *p, typestring);
        }
        if (n >= HAL_STREAM_MAX_ELEMS)
            return hal_fail(EINVAL, "%s: type string '%.20s...' has more "
                            "than %d values", what, typestring,
                            HAL_STREAM_MAX_ELEMS);
        if (types)
            types[n] = (uint8_t)t;
        n++;
    }
    return n;
}

/* the stream of a handle, its geometry checked (a few compares: this is
   on the realtime path of every write and read), or NULL */
hal_stream_t *hal_stream_get(long long handle)
{
    hal_stream_t *s = hal_handle_get(handle, K_STREAM,
                                     sizeof(hal_stream_t));
    if (s && (s->nelem < 1 || s->nelem > HAL_STREAM_MAX_ELEMS ||
              s->depth < 1 || s->stride != 8 * (uint32_t)(s->nelem + 1) ||
              !hal_off_ok(SHMOFF(s), sizeof(hal_stream_t) +
                          (uint64_t)s->depth * s->stride, HAL_ALIGN))) {
        hal_damaged("stream '%.40s' at offset %u: %d values, depth %d and "
                    "stride %u do not fit", s->o.name, SHMOFF(s), s->nelem,
                    s->depth, s->stride);
        return NULL;
    }
    return s;
}

/* records a stream holds at most: the one place of that rule */
static inline uint64_t capacity(const hal_stream_t *s)
{
    return s->depth > 1 ? (uint64_t)s->depth - 1 : 0;
}

static int stale(void)
{
    return hal_fail(ENOENT, "the stream no longer exists (its component "
                    "was removed)");
}

long long hal_stream_create(const char *name, int owner_id, int depth,
                            const char *typestring)
{
    char what[HAL_NAME_SIZE + 16];
    uint8_t types[HAL_STREAM_MAX_ELEMS];
    int r = hal_check_name(name, "stream");
    if (r)
        return r;
    snprintf(what, sizeof(what), "stream '%s'", name);
    int n = hal_stream_parse_types(typestring, types, what);
    if (n < 0)
        return n;
    if (depth < 1)
        return hal_fail(EINVAL, "%s: depth %d is not a positive number of "
                        "records", what, depth);
    uint64_t stride = 8 * (uint64_t)(n + 1);
    uint64_t size = sizeof(hal_stream_t) + (uint64_t)depth * stride;
    if (!hal_map.hdr)
        return hal_fail(ENODEV, "no HAL instance is attached");
    if (size > (uint64_t)(hal_map.heap_end - hal_map.heap_start))
        return hal_fail(ENOMEM, "%s: %d records of %d values do not fit in "
                        "the HAL instance", what, depth, n);
    if ((r = hal_lock()))
        return r;
    hoff_t comp = 0, inst = 0;
    long long ret = hal_owner(owner_id, what, &comp, &inst);
    if (ret)
        goto out;
    if (hal_find(K_STREAM, name)) {
        ret = hal_fail(EEXIST, "duplicate stream name '%s'", name);
        goto out;
    }
    hal_stream_t *s = hal_obj_new(K_STREAM, (long)size, name);
    if (!s) {
        ret = -ENOMEM;
        goto out;
    }
    s->comp = comp;
    s->inst = inst;
    s->nelem = n;
    s->depth = depth;
    s->stride = (uint32_t)stride;
    memcpy(s->types, types, (size_t)n);
    hal_obj_publish(&s->o);
    ret = hal_handle_of(&s->o);
out:
    hal_unlock();
    return ret;
}

long long hal_stream_attach(const char *name)
{
    return hal_handle_attach(K_STREAM, name);
}

int hal_stream_write(long long handle, const halsdk_value_t *rec)
{
    hal_stream_t *s = hal_stream_get(handle);
    if (!s)
        return stale();
    uint64_t w = __atomic_load_n(&s->write_idx, __ATOMIC_RELAXED);
    uint64_t r = __atomic_load_n(&s->read_idx, __ATOMIC_ACQUIRE);
    if (w - r >= capacity(s)) {
        __atomic_fetch_add(&s->num_overruns, 1, __ATOMIC_RELAXED);
        return -ENOSPC;
    }
    char *slot = RING(s) + (w % (uint64_t)s->depth) * s->stride;
    uint64_t sn = __atomic_load_n(&s->sampleno, __ATOMIC_RELAXED);
    memcpy(slot, &sn, 8);
    memcpy(slot + 8, rec, (size_t)s->nelem * 8);
    __atomic_store_n(&s->sampleno, sn + 1, __ATOMIC_RELAXED);
    __atomic_store_n(&s->write_idx, w + 1, __ATOMIC_RELEASE);
    return 0;
}

int hal_stream_read(long long handle, halsdk_value_t *rec,
                    uint64_t *sampleno)
{
    hal_stream_t *s = hal_stream_get(handle);
    if (!s)
        return stale();
    uint64_t r = __atomic_load_n(&s->read_idx, __ATOMIC_RELAXED);
    uint64_t w = __atomic_load_n(&s->write_idx, __ATOMIC_ACQUIRE);
    if (r == w) {
        __atomic_fetch_add(&s->num_underruns, 1, __ATOMIC_RELAXED);
        return -EAGAIN;
    }
    const char *slot = RING(s) + (r % (uint64_t)s->depth) * s->stride;
    if (sampleno)
        memcpy(sampleno, slot, 8);
    memcpy(rec, slot + 8, (size_t)s->nelem * 8);
    __atomic_store_n(&s->read_idx, r + 1, __ATOMIC_RELEASE);
    return 0;
}

int hal_stream_depth(long long handle)
{
    hal_stream_t *s = hal_stream_get(handle);
    if (!s)
        return stale();
    uint64_t r = __atomic_load_n(&s->read_idx, __ATOMIC_ACQUIRE);
    uint64_t w = __atomic_load_n(&s->write_idx, __ATOMIC_ACQUIRE);
    return w >= r ? (int)(w - r) : 0;
}

int hal_stream_room(long long handle)
{
    hal_stream_t *s = hal_stream_get(handle);
    if (!s)
        return stale();
    uint64_t r = __atomic_load_n(&s->read_idx, __ATOMIC_ACQUIRE);
    uint64_t w = __atomic_load_n(&s->write_idx, __ATOMIC_ACQUIRE);
    uint64_t used = w >= r ? w - r : 0;
    return used >= capacity(s) ? 0 : (int)(capacity(s) - used);
}

int hal_stream_maxdepth(long long handle)
{
    hal_stream_t *s = hal_stream_get(handle);
    return s ? s->depth : stale();
}

long long hal_stream_num_overruns(long long handle)
{
    hal_stream_t *s = hal_stream_get(handle);
    return s ? (long long)__atomic_load_n(&s->num_overruns,
                                          __ATOMIC_RELAXED)
             : stale();
}

long long hal_stream_num_underruns(long long handle)
{
    hal_stream_t *s = hal_stream_get(handle);
    return s ? (long long)__atomic_load_n(&s->num_underruns,
                                          __ATOMIC_RELAXED)
             : stale();
}

int hal_stream_nelem(long long handle)
{
    hal_stream_t *s = hal_stream_get(handle);
    return s ? s->nelem : stale();
}

int hal_stream_elem_type(long long handle, int index)
{
    hal_stream_t *s = hal_stream_get(handle);
    if (!s)
        return stale();
    if (index < 0 || index >= s->nelem)
        return hal_fail(EINVAL, "stream '%s' has no value %d", s->o.name,
                        index);
    return s->types[index];
}
