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

/* the name of the record of that kind at off ("" for none; "?" with the
   damage reported when off is not such a record) */
static const char *obj_name(hoff_t off, int kind)
{
    if (!off)
        return "";
    hal_obj_t *o = hal_obj_at(off, kind);
    if (!o) {
        hal_damaged("offset %u is not a %s record", off,
                    hal_kind_word(kind));
        return "?";
    }
    return o->name;
}

static int comp_id(hoff_t off)
{
    hal_comp_t *c = off ? hal_obj_at(off, K_COMP) : NULL;
    return c ? c->id : 0;
}

/* the s32 value of a function's or thread's time pin / tmax param */
static int32_t time_pin(hoff_t off)
{
    hal_pin_t *p = off ? hal_obj_at(off, K_PIN) : NULL;
    return p ? hal_pin_value(p)->s : 0;
}

static int32_t tmax_param(hoff_t off)
{
    hal_param_t *p = off ? hal_obj_at(off, K_PARAM) : NULL;
    return p ? *(int32_t *)hal_param_value(p) : 0;
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
    FOR_EACH(K_PIN, hal_pin_t, p) {
        long i = p->signal ? find_sig(ix, ns, p->signal) : -1;
        if (i >= 0 && !hal_shape_ok(K_PIN, p->type, p->dir)) {
            hal_damaged("pin '%s': type %d, direction %d", p->o.name,
                        p->type, p->dir);
            break;
        }
        if (i >= 0) {
            s->recs[i].nsub++;
            total++;
        }
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
    FOR_EACH(K_PIN, hal_pin_t, p) {
        long i = p->signal ? find_sig(ix, ns, p->signal) : -1;
        /* the list may have changed only by damage since the count */
        if (i >= 0 && s->recs[i].sub + s->recs[i].nsub < total) {
            hal_snap_t *r = &s->recs[i];
            hal_snap_sub_t *sub = &s->subs[r->sub + r->nsub++];
            sub->dir = p->dir;
            if (pool_add(s, p->o.name, &sub->name) < 0) {
                free(ix);
                return -1;
            }
        }
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
        return pool_add(s, obj_name(i->comp, K_COMP), &r->owner);
    }
    case K_PIN:
    case K_PARAM: {
        hal_item_t *it = (hal_item_t *)o;
        if (!hal_shape_ok(kind, it->type, it->dir)) {
            hal_damaged("%s '%s': type %d, direction %d",
                        hal_kind_word(kind), o->name, it->type, it->dir);
            return 0;
        }
        r->id = comp_id(it->comp);
        r->type = it->type;
        r->dir = it->dir;
        if (kind == K_PIN) {
            hal_pin_t *p = (hal_pin_t *)o;
            r->value = raw_value(p->type, hal_pin_value(p));
            if (pool_add(s, obj_name(p->signal, K_SIG), &r->link) < 0)
                return -1;
        } else {
            r->value = raw_value(it->type,
                                 hal_param_value((hal_param_t *)o));
        }
        if (it->oldname) {
            const char *old = hal_oldname_of(it);
            if (pool_add(s, old ? old : "?", &r->alias) < 0)
                return -1;
        }
        return pool_add(s, obj_name(it->comp, K_COMP), &r->owner);
    }
    case K_SIG: {
        hal_sig_t *g = (hal_sig_t *)o;
        if (!hal_shape_ok(K_SIG, g->type, 0)) {
            hal_damaged("signal '%s': type %d", o->name, g->type);
            return 0;
        }
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
        r->time = time_pin(f->time_pin);
        r->tmax = tmax_param(f->tmax_param);
        return pool_add(s, obj_name(f->comp, K_COMP), &r->owner);
    }
    case K_THREAD: {
        hal_thread_t *t = (hal_thread_t *)o;
        r->period = t->period;
        r->flags = (t->uses_fp ? 1 : 0) | (t->running ? 2 : 0);
        r->cycles = t->cycles;
        r->overruns = t->overruns;
        r->time = time_pin(t->time_pin);
        r->tmax = tmax_param(t->tmax_param);
        if (t->nfuncts < 0 || t->nfuncts > (long)HAL_WALK_MAX) {
            hal_damaged("thread '%s': %d functions", t->o.name,
                        t->nfuncts);
            break;
        }
        if (subs_reserve(s, s->nsubs + t->nfuncts) < 0)
            return -1;
        r->sub = (uint32_t)s->nsubs;
        long steps = 0;
        for (hoff_t e = t->functs; e && r->nsub < (uint32_t)t->nfuncts;) {
            hal_fentry_t *x = hal_fentry_at(t, e, &steps);
            if (!x)
                break;
            hal_snap_sub_t *sub = &s->subs[s->nsubs++];
            sub->dir = 0;
            r->nsub++;
            if (pool_add(s, obj_name(x->funct, K_FUNCT), &sub->name) < 0)
                return -1;
            e = x->next;
        }
        break;
    }
    case K_STREAM:
    case K_SHMEM:
        return pool_add(s, obj_name(((hal_owned_t *)o)->comp, K_COMP),
                        &r->owner);
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
    /* pool offset 0 is the empty string */
    s->pool = malloc(4096);
    int bad = s->pool == NULL;
    if (!bad) {
        s->pool[0] = 0;
        s->npool = 1;
        s->cappool = 4096;
    }
    if (!bad && hal_check_header() < 0)
        bad = 1;
    long steps = 0;
    for (hal_obj_t *obj = hal_walk_first(kind); obj && !bad &&
         !hal_damage_seen(); obj = hal_walk_next(kind, obj, &steps))
        bad = snap_one(s, kind, obj) < 0;
    if (!bad && !hal_damage_seen() && kind == K_SIG)
        bad = signal_pins(s) < 0;
    int damaged = hal_damage_seen();
    hal_unlock();
    if (bad || damaged) {
        hal_snapshot_free(s);
        if (damaged)
            return -EUCLEAN;
        return hal_fail(ENOMEM, "out of memory while listing HAL "
                        "instance '%s'", hal_map.name);
    }
    return 0;
}
