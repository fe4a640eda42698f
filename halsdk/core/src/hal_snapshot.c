/*
 * hal_snapshot.c - consistent listings of an instance.
 *
 * A listing copies every object of a kind, with the metadata and values
 * a front end shows (owner, type, direction, value, linked signal or
 * pins, alias, thread functions), in one pass under the instance lock.
 * Front ends then format the copy: a component loaded or unloaded by
 * another process meanwhile cannot make a listing fail half-way (the old
 * way, listing names and then looking each one up, did: "pin no longer
 * exists").  Strings go to a pool so that a record stays small.
 */
#define _GNU_SOURCE
#include "hal_core.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

/* append a string to the pool; its offset (0 is the empty string) */
static int pool_add(hal_snapshot_t *s, const char *str, uint32_t *at)
{
    size_t n = strnlen(str, HAL_NAME_SIZE - 1);
    if (n == 0) {
        *at = 0;
        return 0;
    }
    if (s->npool + (long)n + 1 > s->cappool) {
        long cap = s->cappool ? s->cappool : 4096;
        while (s->npool + (long)n + 1 > cap)
            cap *= 2;
        char *p = realloc(s->pool, cap);
        if (!p)
            return -1;
        s->pool = p;
        s->cappool = cap;
    }
    memcpy(s->pool + s->npool, str, n);
    s->pool[s->npool + n] = 0;
    *at = (uint32_t)s->npool;
    s->npool += (long)n + 1;
    return 0;
}

static hal_snap_t *rec_add(hal_snapshot_t *s)
{
    if (s->nrecs == s->caprecs) {
        long cap = s->caprecs ? s->caprecs * 2 : 64;
        hal_snap_t *r = realloc(s->recs, cap * sizeof(*r));
        if (!r)
            return NULL;
        s->recs = r;
        s->caprecs = cap;
    }
    hal_snap_t *r = &s->recs[s->nrecs++];
    memset(r, 0, sizeof(*r));
    return r;
}

static int subs_reserve(hal_snapshot_t *s, long n)
{
    if (n <= s->capsubs)
        return 0;
    hal_snap_sub_t *p = realloc(s->subs, (n ? n : 1) * sizeof(*p));
    if (!p)
        return -1;
    s->subs = p;
    s->capsubs = n;
    return 0;
}

/* the value's bytes, at the start of the 8 bytes as in memory */
static uint64_t raw_value(int type, const volatile void *p)
{
    uint64_t v = 0;
    switch (type) {
    case HALSDK_BIT: {
        uint8_t b = *(const volatile uint8_t *)p != 0;
        memcpy(&v, &b, 1);
        break;
    }
    case HALSDK_S32:
    case HALSDK_U32: {
        uint32_t u = *(const volatile uint32_t *)p;
        memcpy(&v, &u, 4);
        break;
    }
    default:
        memcpy(&v, (const void *)p, 8);
    }
    return v;
}

static const char *obj_name(hoff_t off)
{
    return off ? ((hal_obj_t *)SHMPTR(off))->name : "";
}

static int comp_id(hoff_t off)
{
    return off ? ((hal_comp_t *)SHMPTR(off))->id : 0;
}

/* signal offset -> record index, sorted by offset */
typedef struct {
    hoff_t off;
    uint32_t idx;
} sig_index_t;

static int cmp_sig_index(const void *a, const void *b)
{
    hoff_t x = ((const sig_index_t *)a)->off;
    hoff_t y = ((const sig_index_t *)b)->off;
    return x < y ? -1 : x > y;
}

static long find_sig(const sig_index_t *v, long n, hoff_t off)
{
    long lo = 0, hi = n - 1;
    while (lo <= hi) {
        long mid = lo + (hi - lo) / 2;
        if (v[mid].off == off)
            return v[mid].idx;
        if (v[mid].off < off)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}

/* the pins of every signal (lock held): O(pins log signals) */
static int signal_pins(hal_snapshot_t *s)
{
    hal_header_t *h = hal_map.hdr;
    long ns = s->nrecs;
    sig_index_t *ix = malloc((ns ? ns : 1) * sizeof(*ix));
    if (!ix)
        return -1;
    for (long k = 0; k < ns; k++) {
        ix[k].off = s->recs[k].off;
        ix[k].idx = (uint32_t)k;
    }
    qsort(ix, ns, sizeof(*ix), cmp_sig_index);
    long total = 0;
    for (hoff_t o = h->list_head[K_PIN]; o;) {
        hal_pin_t *p = SHMPTR(o);
        long i = p->signal ? find_sig(ix, ns, p->signal) : -1;
        if (i >= 0) {
            s->recs[i].nsub++;
            total++;
        }
        o = p->o.next;
    }
    if (subs_reserve(s, total) < 0) {
        free(ix);
        return -1;
    }
    long at = 0;
    for (long k = 0; k < ns; k++) {
        s->recs[k].sub = (uint32_t)at;
        at += s->recs[k].nsub;
        s->recs[k].nsub = 0;
    }
    for (hoff_t o = h->list_head[K_PIN]; o;) {
        hal_pin_t *p = SHMPTR(o);
        long i = p->signal ? find_sig(ix, ns, p->signal) : -1;
        if (i >= 0) {
            hal_snap_t *r = &s->recs[i];
            hal_snap_sub_t *sub = &s->subs[r->sub + r->nsub++];
            sub->dir = p->dir;
            if (pool_add(s, p->o.name, &sub->name) < 0) {
                free(ix);
                return -1;
            }
        }
        o = p->o.next;
    }
    s->nsubs = total;
    free(ix);
    return 0;
}

/* one record (lock held) */
static int snap_one(hal_snapshot_t *s, int kind, hal_obj_t *o)
{
    hal_snap_t *r = rec_add(s);
    if (!r)
        return -1;
    r->off = SHMOFF(o);
    r->gen = o->gen;
    if (pool_add(s, o->name, &r->name) < 0)
        return -1;
    switch (kind) {
    case K_COMP: {
        hal_comp_t *c = (hal_comp_t *)o;
        r->id = c->id;
        r->flags = (c->kind == HALSDK_COMP_RT)
            | ((c->o.flags & HAL_COMP_DEAD) ? 2 : 0);
        r->ready = c->ready;
        r->pid = c->pid;
        r->pid_start = c->pid_start;
        break;
    }
    case K_INST: {
        hal_inst_t *i = (hal_inst_t *)o;
        r->id = i->id;
        return pool_add(s, obj_name(i->comp), &r->owner);
    }
    case K_PIN:
    case K_PARAM: {
        hal_item_t *it = (hal_item_t *)o;
        r->id = comp_id(it->comp);
        r->type = it->type;
        r->dir = it->dir;
        if (kind == K_PIN) {
            hal_pin_t *p = (hal_pin_t *)o;
            r->value = raw_value(p->type, hal_pin_value(p));
            if (pool_add(s, obj_name(p->signal), &r->link) < 0)
                return -1;
        } else {
            r->value = raw_value(it->type,
                                 hal_param_value((hal_param_t *)o));
        }
        if (it->oldname && pool_add(s, (char *)SHMPTR(it->oldname),
                                    &r->alias) < 0)
            return -1;
        return pool_add(s, obj_name(it->comp), &r->owner);
    }
    case K_SIG: {
        hal_sig_t *g = (hal_sig_t *)o;
        r->type = g->type;
        r->value = raw_value(g->type, &g->value);
        r->readers = g->readers;
        r->writers = g->writers;
        r->bidirs = g->bidirs;
        break;
    }
    case K_FUNCT: {
        hal_funct_t *f = (hal_funct_t *)o;
        r->id = comp_id(f->comp);
        r->flags = (f->uses_fp ? 1 : 0) | (f->reentrant ? 2 : 0)
                   | (f->python ? 4 : 0);
        r->users = f->users;
        if (f->time_pin)
            r->time = hal_pin_value(SHMPTR(f->time_pin))->s;
        if (f->tmax_param)
            r->tmax = *(int32_t *)hal_param_value(SHMPTR(f->tmax_param));
        return pool_add(s, obj_name(f->comp), &r->owner);
    }
    case K_THREAD: {
        hal_thread_t *t = (hal_thread_t *)o;
        r->period = t->period;
        r->flags = (t->uses_fp ? 1 : 0) | (t->running ? 2 : 0);
        r->cycles = t->cycles;
        r->overruns = t->overruns;
        if (t->time_pin)
            r->time = hal_pin_value(SHMPTR(t->time_pin))->s;
        if (t->tmax_param)
            r->tmax = *(int32_t *)hal_param_value(SHMPTR(t->tmax_param));
        if (subs_reserve(s, s->nsubs + t->nfuncts) < 0)
            return -1;
        r->sub = (uint32_t)s->nsubs;
        for (hoff_t e = t->functs; e && r->nsub < (uint32_t)t->nfuncts;
             e = ((hal_fentry_t *)SHMPTR(e))->next) {
            hal_snap_sub_t *sub = &s->subs[s->nsubs++];
            sub->dir = 0;
            r->nsub++;
            if (pool_add(s, obj_name(((hal_fentry_t *)SHMPTR(e))->funct),
                         &sub->name) < 0)
                return -1;
        }
        break;
    }
    case K_STREAM:
    case K_SHMEM:
        return pool_add(s, obj_name(((hal_owned_t *)o)->comp), &r->owner);
    }
    return 0;
}

void hal_snapshot_free(hal_snapshot_t *s)
{
    free(s->recs);
    free(s->subs);
    free(s->pool);
    memset(s, 0, sizeof(*s));
}

int hal_snapshot(int kind, hal_snapshot_t *s)
{
    memset(s, 0, sizeof(*s));
    if (kind <= K_NONE || kind >= K_NKINDS)
        return hal_fail(EINVAL, "no kind of object numbered %d", kind);
    int r = hal_lock();
    if (r)
        return r;
    hal_header_t *h = hal_map.hdr;
    /* pool offset 0 is the empty string */
    s->pool = malloc(4096);
    int bad = s->pool == NULL;
    if (!bad) {
        s->pool[0] = 0;
        s->npool = 1;
        s->cappool = 4096;
    }
    for (hoff_t o = h->list_head[kind]; o && !bad;) {
        hal_obj_t *obj = SHMPTR(o);
        bad = snap_one(s, kind, obj) < 0;
        o = obj->next;
    }
    if (!bad && kind == K_SIG)
        bad = signal_pins(s) < 0;
    hal_unlock();
    if (bad) {
        hal_snapshot_free(s);
        return hal_fail(ENOMEM, "out of memory while listing HAL "
                        "instance '%s'", h->instance);
    }
    return 0;
}
