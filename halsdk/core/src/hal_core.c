/*
 * hal_core.c - the halsdk instance: shared memory, allocator, name index
 * and the rules for components, pins, params, signals and functions.
 *
 * Every operation that changes metadata takes the instance mutex, checks
 * all of its rules before it changes anything, and reports a violation as
 * -errno with a message naming the object (hal_last_error()).  Realtime
 * threads never take the mutex.
 */
#define _GNU_SOURCE
#include "hal_core.h"

#include <errno.h>
#include <stddef.h>
#include <fcntl.h>
#include <fnmatch.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <pwd.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

hal_map_t hal_map;

static const char *kind_word(int kind)
{
    return hal_kind_word(kind);
}

static __thread char errbuf[512];
static __thread int err_rule, err_kind;
static __thread char err_names[3][HAL_NAME_SIZE];
static int cur_owner;           /* last comp/inst created here: hal_malloc */

int hal_fail(int err, const char *fmt, ...)
{
    if (hal_damage_seen())      /* the damage is what went wrong */
        return -EUCLEAN;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(errbuf, sizeof(errbuf), fmt, ap);
    va_end(ap);
    err_rule = HAL_RULE_NONE;
    err_kind = K_NONE;
    err_names[0][0] = err_names[1][0] = err_names[2][0] = 0;
    return err > 0 ? -err : err;
}

int hal_rule(int r, int rule, int kind, const char *name0,
             const char *name1, const char *name2)
{
    const char *names[3] = {name0, name1, name2};
    if (hal_damage_seen())
        return r;
    err_rule = rule;
    err_kind = kind;
    for (int k = 0; k < 3; k++)
        snprintf(err_names[k], HAL_NAME_SIZE, "%s", names[k] ? names[k] : "");
    return r;
}

const char *hal_last_error(void)
{
    return errbuf;
}

int hal_last_rule(void)
{
    return err_rule;
}

int hal_last_kind(void)
{
    return err_kind;
}

const char *hal_last_name(int index)
{
    return index >= 0 && index < 3 ? err_names[index] : "";
}

/* the usual failures: an object not found, a lock, a duplicate name */
static int fail_not_found(int kind, const char *name)
{
    return hal_rule(hal_fail(ENOENT, "%s '%s' not found", kind_word(kind),
                             name),
                    HAL_RULE_NOT_FOUND, kind, name, NULL, NULL);
}

static int fail_locked(int kind, const char *name, const char *fmt)
{
    return hal_rule(hal_fail(EPERM, fmt, name), HAL_RULE_LOCKED, kind, name,
                    NULL, NULL);
}

static int fail_exists(int kind, const char *name, const char *fmt)
{
    return hal_rule(hal_fail(EEXIST, fmt, name), HAL_RULE_EXISTS, kind,
                    name, NULL, NULL);
}

/* the object a configuration change names, found with the lock held:
   0, or the refusal (locked against configuration, then missing) */
static int find_one_for_config(int kind, const char *name, void **found,
                               const char *locked_fmt)
{
    *found = hal_find(kind, name);
    if (hal_map.hdr->lock & HAL_LOCK_CONFIG)
        return fail_locked(kind, name, locked_fmt);
    if (!*found)
        return fail_not_found(kind, name);
    return 0;
}

/* the same for two objects: the lock, then the first missing, then the
   second */
static int find_for_config(int kind_a, const char *a, void **found_a,
                           int kind_b, const char *b, void **found_b,
                           const char *locked_fmt)
{
    int r = find_one_for_config(kind_a, a, found_a, locked_fmt);
    *found_b = hal_find(kind_b, b);
    if (r)
        return r;
    if (!*found_b)
        return fail_not_found(kind_b, b);
    return 0;
}


/* ---------------------------------------------------------------- */
/* process identity                                                 */

/* the fields of /proc/<pid>/stat after the command name (which may hold
   spaces and parentheses): from the state letter on; NULL if unreadable */
static const char *proc_stat_fields(int pid, char *buf, size_t size)
{
    char path[64];
    snprintf(path, sizeof(path), "/proc/%d/stat", pid);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return NULL;
    ssize_t n = read(fd, buf, size - 1);
    close(fd);
    if (n <= 0)
        return NULL;
    buf[n] = 0;
    char *p = strrchr(buf, ')');
    return p && p[1] == ' ' ? p + 2 : NULL;
}

uint64_t hal_proc_start_time(int pid)
{
    char buf[1024];
    const char *p = proc_stat_fields(pid, buf, sizeof(buf));
    if (!p)
        return 0;
    /* field 22 (starttime); p is at field 3 (state) */
    int field = 3;
    for (; *p && field < 22; p++)
        if (*p == ' ')
            field++;
    return strtoull(p, NULL, 10);
}

char hal_proc_state(int pid)
{
    char buf[512];
    const char *p = proc_stat_fields(pid, buf, sizeof(buf));
    return p ? *p : 0;
}

int hal_pid_alive(int pid, uint64_t start)
{
    if (pid <= 0)
        return 0;
    if (kill(pid, 0) != 0 && errno == ESRCH)
        return 0;
    uint64_t now = hal_proc_start_time(pid);
    if (now == 0)
        return 0;
    /* a zombie still has /proc entries: treat it as gone */
    char st = hal_proc_state(pid);
    if (st == 'Z' || st == 'X')
        return 0;
    return start == 0 || now == start;
}

/* ---------------------------------------------------------------- */
/* mutex                                                            */

static void recover_after_dead_holder(void);

void *(*hal_gil_release)(void);
void (*hal_gil_restore)(void *);

/*
 * How long hal_lock() waits: $HALSDK_LOCK_TIMEOUT (seconds, read on first
 * use; a value that is not a positive number is ignored) or
 * HAL_LOCK_TIMEOUT, until hal_set_lock_timeout() sets it for the process.
 */
static double lock_timeout_s = -1.0;

double hal_lock_timeout(void)
{
    if (lock_timeout_s < 0) {
        const char *env = getenv("HALSDK_LOCK_TIMEOUT");
        char *end = NULL;
        double v = env && *env ? strtod(env, &end) : 0.0;
        lock_timeout_s = (env && *env && end && *end == 0 && v > 0
                          && v <= 86400.0) ? v : HAL_LOCK_TIMEOUT;
    }
    return lock_timeout_s;
}

int hal_set_lock_timeout(double seconds)
{
    if (!(seconds > 0 && seconds <= 86400.0))
        return hal_fail(EINVAL, "lock timeout %g s is out of range "
                        "(more than 0, at most 86400 s)", seconds);
    lock_timeout_s = seconds;
    return 0;
}

/* the command name and state letter of a process, from /proc/pid/stat */
static int proc_name_state(int pid, char *comm, int len, char *state)
{
    char path[64], buf[512];
    comm[0] = 0;
    *state = 0;
    if (pid <= 0)
        return -1;
    snprintf(path, sizeof(path), "/proc/%d/stat", pid);
    int fd = open(path, O_RDONLY);
    if (fd < 0)
        return -1;
    ssize_t n = read(fd, buf, sizeof(buf) - 1);
    close(fd);
    if (n <= 0)
        return -1;
    buf[n] = 0;
    char *open_paren = strchr(buf, '(');
    char *close_paren = strrchr(buf, ')');
    if (!open_paren || !close_paren || close_paren < open_paren)
        return -1;
    int clen = (int)(close_paren - open_paren - 1);
    if (clen >= len)
        clen = len - 1;
    memcpy(comm, open_paren + 1, clen);
    comm[clen] = 0;
    if (close_paren[1] == ' ')
        *state = close_paren[2];
    return 0;
}

/* the failure of a wait for the lock that timed out: name the holder */
static int fail_lock_timeout(hal_header_t *h, double waited)
{
    int pid = __atomic_load_n(&h->lock_holder, __ATOMIC_RELAXED);
    char comm[32], state;
    if (pid <= 0)
        return hal_fail(ETIMEDOUT, "HAL instance '%s': instance lock held "
                        "by an unknown process (stopped?) for more than "
                        "%g s; gave up", h->instance, waited);
    if (proc_name_state(pid, comm, sizeof(comm), &state) < 0)
        return hal_fail(ETIMEDOUT, "HAL instance '%s': instance lock held "
                        "by pid %d (stopped?) for more than %g s; gave up",
                        h->instance, pid, waited);
    return hal_fail(ETIMEDOUT, "HAL instance '%s': instance lock held by "
                    "pid %d (%s) for more than %g s; gave up (process "
                    "'%s', state %c)", h->instance, pid,
                    state == 'T' || state == 't' ? "stopped" : "stopped?",
                    waited, comm, state ? state : '?');
}

/* the attributes of the instance mutex: shared between processes,
   robust (a dead holder does not block the others) */
static void instance_mutexattr(pthread_mutexattr_t *ma)
{
    pthread_mutexattr_init(ma);
    pthread_mutexattr_setpshared(ma, PTHREAD_PROCESS_SHARED);
    pthread_mutexattr_setrobust(ma, PTHREAD_MUTEX_ROBUST);
}

/* whether the mutex in the segment is still of the kind it was made:
   a stray write into its kind word makes glibc take it for another kind
   of mutex and abort the process inside pthread_mutex_lock */
static int mutex_kind_wanted(void)
{
    static int want = -1;
    if (want == -1) {
        pthread_mutexattr_t ma;
        pthread_mutex_t fresh;
        instance_mutexattr(&ma);
        pthread_mutex_init(&fresh, &ma);
        pthread_mutexattr_destroy(&ma);
        want = fresh.__data.__kind;
        pthread_mutex_destroy(&fresh);
    }
    return want;
}

static int mutex_kind_ok(const pthread_mutex_t *m)
{
    return __atomic_load_n(&m->__data.__kind, __ATOMIC_RELAXED) ==
           mutex_kind_wanted();
}

/* What glibc wrote into the instance mutex when this thread took it: its
   owner and its place in the thread's robust list (two pointers into
   this process).  pthread_mutex_unlock follows those pointers, so a
   stray write there by another process while this thread holds the
   mutex would crash this one; the holder puts back what is its own
   first.  The lock word itself is never put back: waiters set bits in
   it. */
static __thread struct {
    int held;
    int owner;
    __pthread_list_t list;
} mine;

static void mutex_remember(const pthread_mutex_t *m)
{
    mine.held = 1;
    mine.owner = m->__data.__owner;
    mine.list = m->__data.__list;
}

/* put back what this thread wrote into the mutex it holds; 1 when
   something had been changed */
static int mutex_repair(pthread_mutex_t *m)
{
    int changed = 0;
    if (!mutex_kind_ok(m)) {
        m->__data.__kind = mutex_kind_wanted();
        changed = 1;
    }
    if (m->__data.__owner != mine.owner) {
        m->__data.__owner = mine.owner;
        changed = 1;
    }
    if (memcmp(&m->__data.__list, &mine.list, sizeof(mine.list)) != 0) {
        m->__data.__list = mine.list;
        changed = 1;
    }
    __atomic_thread_fence(__ATOMIC_SEQ_CST);
    return changed;
}

int hal_lock(void)
{
    hal_header_t *h = hal_map.hdr;
    if (!h)
        return hal_fail(ENODEV, "no HAL instance is attached");
    hal_damage_take();          /* each operation reports its own */
    if (!mutex_kind_ok(&h->mutex))
        return hal_damaged("the instance mutex (kind %d)",
                           h->mutex.__data.__kind);
    /* A holder may be waiting for a thread cycle that runs a Python
       function: never wait for the mutex with the GIL held.  A holder
       that is stopped (SIGSTOP) or stuck must not block this process for
       ever: wait at most the lock timeout. */
    int r = pthread_mutex_trylock(&h->mutex);
    double waited = 0;
    if (r == EBUSY) {
        waited = hal_lock_timeout();
        struct timespec until;
        clock_gettime(CLOCK_MONOTONIC, &until);
        long long ns = (long long)(waited * 1e9) + until.tv_nsec;
        until.tv_sec += ns / 1000000000LL;
        until.tv_nsec = ns % 1000000000LL;
        void *gil = hal_gil_release ? hal_gil_release() : NULL;
        do
            r = pthread_mutex_clocklock(&h->mutex, CLOCK_MONOTONIC, &until);
        while (r == EINTR);
        if (gil)
            hal_gil_restore(gil);
    }
    if (r == EOWNERDEAD) {
        recover_after_dead_holder();
        pthread_mutex_consistent(&h->mutex);
        h->recovered++;
        r = 0;
    }
    if (r == ETIMEDOUT)
        return fail_lock_timeout(h, waited);
    if (r)
        return hal_fail(r, "cannot lock HAL instance '%s': %s", h->instance,
                        strerror(r));
    mutex_remember(&h->mutex);
    __atomic_store_n(&h->lock_holder, (int32_t)getpid(), __ATOMIC_RELAXED);
    return 0;
}

void hal_unlock(void)
{
    if (hal_map.hdr) {
        pthread_mutex_t *m = &hal_map.hdr->mutex;
        __atomic_store_n(&hal_map.hdr->lock_holder, 0, __ATOMIC_RELAXED);
        if (mine.held) {
            mine.held = 0;
            /* written over while held: glibc would abort or follow a
               wild pointer; what was ours goes back, and it is said */
            if (mutex_repair(m))
                hal_damaged("the instance mutex was written over while "
                            "pid %d held it (repaired)", (int)getpid());
            pthread_mutex_unlock(m);
        } else if (mutex_kind_ok(m)) {
            pthread_mutex_unlock(m);
        }
    }
}

/* test hook: hold the lock so that a test can kill the holder */
int hal_hold_lock_for_test(double seconds)
{
    int r = hal_lock();
    if (r)
        return r;
    struct timespec ts = {(time_t)seconds,
                          (long)((seconds - (long)seconds) * 1e9)};
    nanosleep(&ts, NULL);
    hal_unlock();
    return 0;
}

/* ---------------------------------------------------------------- */
/* allocator                                                        */

static inline uint32_t round16(long n)
{
    return (uint32_t)((n + 15) & ~15L);
}

/* the free block at off of a free list (exact size need if class
   cls < HAL_NCLASSES), or NULL with the damage reported */
static hal_block_t *free_block_at(hoff_t off, uint32_t need, uint32_t cls)
{
    hal_block_t *b = NULL;
    if (hal_off_ok(off, sizeof(hal_block_t), HAL_ALIGN)) {
        b = SHMPTR(off);
        if (b->magic != HAL_BLOCK_FREE ||
            b->size > hal_map.heap_end - off - sizeof(hal_block_t) ||
            (cls < HAL_NCLASSES && b->size != need) || (b->size & 15) ||
            (b->next && !hal_off_ok(b->next, sizeof(hal_block_t),
                                    HAL_ALIGN)))
            b = NULL;
    }
    if (!b)
        hal_damaged("free list %u has offset %u, not a free block", cls,
                    off);
    return b;
}

void *hal_alloc(long size, hoff_t owner)
{
    hal_header_t *h = hal_map.hdr;
    if (size <= 0 || size > (long)(hal_map.heap_end - hal_map.heap_start))
        return NULL;
    uint32_t need = round16(size);
    hal_block_t *b = NULL;
    uint32_t cls = need / 16;
    if (cls < HAL_NCLASSES && h->free_class[cls]) {
        b = free_block_at(h->free_class[cls], need, cls);
        if (!b)
            return NULL;
        h->free_class[cls] = b->next;
    } else if (cls >= HAL_NCLASSES) {
        /* first fit among the big free blocks */
        hoff_t *link = &h->free_big;
        long steps = 0;
        while (*link) {
            hal_block_t *c = free_block_at(*link, 0, cls);
            if (!c || ++steps > (long)HAL_WALK_MAX) {
                if (c)
                    hal_damaged("the free list of big blocks does not "
                                "end");
                return NULL;
            }
            if (c->size >= need) {
                *link = c->next;
                b = c;
                break;
            }
            link = &c->next;
        }
    }
    if (!b) {
        uint64_t total = sizeof(hal_block_t) + need;
        if (h->heap_top < hal_map.heap_start ||
            h->heap_top > hal_map.heap_end || (h->heap_top & 15)) {
            hal_damaged("heap top %u is outside the heap %u..%u",
                        h->heap_top, hal_map.heap_start, hal_map.heap_end);
            return NULL;
        }
        if ((uint64_t)h->heap_top + total > hal_map.heap_end)
            return NULL;
        b = SHMPTR(h->heap_top);
        h->heap_top += (hoff_t)total;
        b->size = need;
    }
    b->magic = HAL_BLOCK_USED;
    b->owner = owner;
    b->next = 0;
    h->bytes_used += sizeof(hal_block_t) + b->size;
    void *p = b + 1;
    memset(p, 0, b->size);
    return p;
}

void hal_free(void *p)
{
    hal_header_t *h = hal_map.hdr;
    if (!p)
        return;
    if (!hal_block_at(SHMOFF(p), 0)) {
        hal_damaged("offset %u to free is not a used block", SHMOFF(p));
        return;
    }
    hal_block_t *b = (hal_block_t *)p - 1;
    b->magic = HAL_BLOCK_FREE;
    h->bytes_used -= sizeof(hal_block_t) + b->size;
    uint32_t cls = b->size / 16;
    if (cls < HAL_NCLASSES) {
        b->next = h->free_class[cls];
        h->free_class[cls] = SHMOFF(b);
    } else {
        b->next = h->free_big;
        h->free_big = SHMOFF(b);
    }
}

/* memory that a component asked for: chained to its owner */
static void *alloc_for(hoff_t owner_off, long size)
{
    void *p = hal_alloc(size, owner_off);
    if (!p || !owner_off)
        return p;
    hal_block_t *b = (hal_block_t *)p - 1;
    hal_obj_t *o = SHMPTR(owner_off);
    hoff_t *head = o->kind == K_COMP ? &((hal_comp_t *)o)->mem
                                     : &((hal_inst_t *)o)->mem;
    b->next = *head;
    *head = SHMOFF(b);
    return p;
}

static void free_owned(hoff_t *head)
{
    long steps = 0;
    while (*head) {
        if (!hal_block_at((uint64_t)*head + sizeof(hal_block_t), 0) ||
            ++steps > (long)HAL_WALK_MAX) {
            hal_damaged("memory list of a component: offset %u is not a "
                        "used block", *head);
            *head = 0;          /* drop (leak) the rest */
            return;
        }
        hal_block_t *b = SHMPTR(*head);
        *head = b->next;
        hal_free(b + 1);
    }
}

/* ---------------------------------------------------------------- */
/* name index                                                       */

static int name_space(int kind)
{
    if (kind == K_PARAM)
        return K_PIN;
    if (kind == K_INST)
        return K_COMP;
    return kind;
}

static uint32_t name_hash(int space, const char *name)
{
    uint32_t x = 2166136261u ^ (uint32_t)space;
    for (const unsigned char *p = (const unsigned char *)name; *p; p++) {
        x ^= *p;
        x *= 16777619u;
    }
    return x;
}

/* the name index where attach checked it is (hal_map) */
static hoff_t *bucket(uint32_t hash)
{
    hoff_t *b = SHMPTR(hal_map.buckets);
    return &b[hash & (hal_map.nbuckets - 1)];
}

static void *find_in_space(int space, const char *name)
{
    uint32_t x = name_hash(space, name);
    long steps = 0;
    for (hoff_t o = *bucket(x); o;) {
        hal_obj_t *obj = hal_obj_at(o, K_NONE);
        if (!obj) {
            hal_damaged("name index chain of '%.40s': offset %u is not a "
                        "record", name, o);
            return NULL;
        }
        if (obj->hash == x && name_space(obj->kind) == space &&
            strcmp(obj->name, name) == 0)
            return obj;
        if (obj->hnext && hal_walk_step(&steps, o, obj->hnext)) {
            hal_damaged("name index chain of '%.40s': a cycle after '%.40s'",
                        name, obj->name);
            return NULL;
        }
        o = obj->hnext;
    }
    return NULL;
}

char *hal_oldname_of(hal_item_t *it)
{
    char *n = hal_block_at(it->oldname, HAL_NAME_SIZE);
    if (!n || n[HAL_NAME_SIZE - 1] != 0) {
        hal_damaged("%s '%s': original name at offset %u is not a name",
                    kind_word(it->o.kind), it->o.name, it->oldname);
        return NULL;
    }
    return n;
}

void *hal_find(int kind, const char *name)
{
    hal_obj_t *o = find_in_space(name_space(kind), name);
    if (o && o->kind == kind) {
        if (hal_obj_at(SHMOFF(o), kind))    /* its block holds the kind */
            return o;
        hal_damaged("%s '%s' at offset %u is too small for its kind",
                    kind_word(kind), name, SHMOFF(o));
        return NULL;
    }
    /* an aliased pin or param still answers to its original name */
    if ((kind == K_PIN || kind == K_PARAM) && hal_map.hdr->naliases > 0) {
        FOR_EACH(kind, hal_item_t, it) {
            const char *old = it->oldname ? hal_oldname_of(it) : NULL;
            if (old && strcmp(old, name) == 0)
                return it;
        }
    }
    return NULL;
}

static void index_insert(hal_obj_t *o)
{
    o->hash = name_hash(name_space(o->kind), o->name);
    hoff_t *b = bucket(o->hash);
    o->hnext = *b;
    *b = SHMOFF(o);
}

static void index_remove(hal_obj_t *o)
{
    hoff_t *link = bucket(o->hash), me = SHMOFF(o);
    long steps = 0;
    while (*link) {
        if (*link == me) {
            *link = o->hnext;
            break;
        }
        hal_obj_t *x = hal_obj_at(*link, K_NONE);
        if (!x || (x->hnext && hal_walk_step(&steps, *link, x->hnext))) {
            hal_damaged("name index chain of '%.40s': offset %u is not a "
                        "record%s", o->name, *link, x ? " (a cycle)" : "");
            break;
        }
        link = &x->hnext;
    }
    o->hnext = 0;
}

static int check_name(const char *name, const char *what);

int hal_check_name(const char *name, const char *what)
{
    int r = check_name(name, what);
    return r ? hal_rule(r, HAL_RULE_BAD_NAME, K_NONE, name ? name : "",
                        NULL, NULL)
             : 0;
}

static int check_name(const char *name, const char *what)
{
    if (!name || !*name)
        return hal_fail(EINVAL, "%s name is empty", what);
    size_t n = strnlen(name, HAL_NAME_SIZE);
    if (n > HALSDK_NAME_LEN)
        return hal_fail(EINVAL, "%s name '%.*s...' is longer than %d "
                        "characters", what, 40, name, HALSDK_NAME_LEN);
    for (const unsigned char *p = (const unsigned char *)name; *p; p++) {
        if (*p == ' ')
            return hal_fail(EINVAL, "%s name '%s' contains a blank", what,
                            name);
        if (*p < ' ' || *p >= 127)
            return hal_fail(EINVAL, "%s name '%s' contains a non-printable "
                            "or non-ASCII character", what, name);
        if (strchr("\"'#\\$[]", *p))
            return hal_fail(EINVAL, "%s name '%s' contains the character "
                            "'%c' (not allowed: blanks, quotes, #, $, [, ] "
                            "and \\)", what, name, *p);
    }
    if (name[0] == '.' || name[n - 1] == '.' || strstr(name, ".."))
        return hal_fail(EINVAL, "%s name '%s' has an empty level "
                        "(leading, trailing or doubled '.')", what, name);
    return 0;
}

/* ---------------------------------------------------------------- */
/* object records                                                   */

static void *obj_new(int kind, long size, const char *name)
{
    hal_header_t *h = hal_map.hdr;
    hal_obj_t *o = hal_alloc(size, 0);
    if (!o) {
        hal_rule(hal_fail(ENOMEM, "HAL instance is full: cannot create %s "
                          "'%s' (%llu of %llu bytes used; create the "
                          "instance with a larger size)", kind_word(kind),
                          name, (unsigned long long)h->bytes_used,
                          (unsigned long long)h->size),
                 HAL_RULE_FULL, kind, name, NULL, NULL);
        return NULL;
    }
    o->kind = (uint16_t)kind;
    o->gen = ++h->next_gen;
    snprintf(o->name, sizeof(o->name), "%s", name);
    return o;
}

/* make a filled record visible: list, index, count */
static void obj_publish(hal_obj_t *o)
{
    hal_header_t *h = hal_map.hdr;
    hoff_t me = SHMOFF(o);
    o->next = 0;
    o->prev = h->list_tail[o->kind];
    hal_obj_t *prev = o->prev ? hal_obj_get(o->prev, o->kind, "the end of "
                                            "the list of",
                                            kind_word(o->kind))
                              : NULL;
    if (prev)
        prev->next = me;
    else if (!o->prev)
        h->list_head[o->kind] = me;
    else
        o->prev = 0;
    h->list_tail[o->kind] = me;
    index_insert(o);
    h->count[o->kind]++;
    h->serial++;
}

static void obj_delete(hal_obj_t *o)
{
    hal_header_t *h = hal_map.hdr;
    index_remove(o);
    hal_obj_t *prev = o->prev ? hal_obj_get(o->prev, o->kind, "the record "
                                            "before", o->name) : NULL;
    hal_obj_t *next = o->next ? hal_obj_get(o->next, o->kind, "the record "
                                            "after", o->name) : NULL;
    if (prev)
        prev->next = o->next;
    else if (!o->prev)
        h->list_head[o->kind] = o->next;
    if (next)
        next->prev = o->prev;
    else if (!o->next)
        h->list_tail[o->kind] = o->prev;
    h->count[o->kind]--;
    h->serial++;
    o->kind = K_NONE;
    o->gen = 0;         /* stale handles see the record is gone */
    hal_free(o);
}

/* for the other parts of the core (streams) */
void *hal_obj_new(int kind, long size, const char *name)
{
    return obj_new(kind, size, name);
}

void hal_obj_publish(hal_obj_t *o)
{
    obj_publish(o);
}

void hal_obj_delete(hal_obj_t *o)
{
    obj_delete(o);
}

hal_comp_t *hal_comp_by_id(int id)
{
    FOR_EACH(K_COMP, hal_comp_t, c)
        if (c->id == id)
            return c;
    return NULL;
}

hal_inst_t *hal_inst_by_id(int id)
{
    FOR_EACH(K_INST, hal_inst_t, i)
        if (i->id == id)
            return i;
    return NULL;
}

/* owner of a new item: a comp or an inst id of this process */
static int resolve_owner(int id, hal_comp_t **comp, hal_inst_t **inst,
                         const char *what, const char *name)
{
    *inst = NULL;
    *comp = hal_comp_by_id(id);
    if (!*comp) {
        *inst = hal_inst_by_id(id);
        if (*inst)
            *comp = hal_obj_get((*inst)->comp, K_COMP, "the owner of "
                                "instance", (*inst)->o.name);
    }
    if (!*comp)
        return hal_rule(hal_fail(EINVAL, "%s '%s': no component with id "
                                 "%d", what, name, id),
                        HAL_RULE_BAD_ARG, K_NONE, name, NULL, NULL);
    if ((*comp)->pid != getpid())
        return hal_rule(hal_fail(EPERM, "%s '%s': component '%s' belongs "
                                 "to process %d", what, name,
                                 (*comp)->o.name, (*comp)->pid),
                        HAL_RULE_NOT_OWNER, K_COMP, (*comp)->o.name, name,
                        NULL);
    if ((*comp)->ready && !*inst)
        return hal_fail(EINVAL, "%s '%s': component '%s' is already "
                        "ready; items are created before hal_ready()",
                        what, name, (*comp)->o.name);
    return 0;
}

static int in_segment(const volatile void *p, long len)
{
    const char *c = (const char *)p;
    return c >= hal_map.base + sizeof(hal_header_t) &&
           c + len <= hal_map.base + hal_map.size;
}

static long type_size(int type)
{
    switch (type) {
    case HALSDK_BIT: return 1;
    case HALSDK_FLOAT: return 8;
    case HALSDK_S32: case HALSDK_U32: return 4;
    case HALSDK_S64: case HALSDK_U64: return 8;
    }
    return 0;
}

int hal_shape_ok(int kind, int type, int dir)
{
    if (!type_size(type))
        return 0;
    if (kind == K_PIN)
        return dir == HALSDK_IN || dir == HALSDK_OUT || dir == HALSDK_IO;
    if (kind == K_PARAM)
        return dir == HALSDK_RO || dir == HALSDK_RW;
    return 1;
}

static const char *type_word(int type)
{
    switch (type) {
    case HALSDK_BIT: return "bit";
    case HALSDK_FLOAT: return "float";
    case HALSDK_S32: return "s32";
    case HALSDK_U32: return "u32";
    case HALSDK_S64: return "s64";
    case HALSDK_U64: return "u64";
    }
    return "unknown";
}

/* ---------------------------------------------------------------- */
/* components and instances                                         */

int hal_comp_new(const char *name, int kind)
{
    int r = hal_check_name(name, "component");
    if (r)
        return r;
    if (kind != HALSDK_COMP_USER && kind != HALSDK_COMP_RT)
        return hal_rule(hal_fail(EINVAL, "component '%s': bad kind %d",
                                 name, kind),
                        HAL_RULE_BAD_ARG, K_COMP, name, NULL, NULL);
    if ((r = hal_lock()))
        return r;
    hal_header_t *h = hal_map.hdr;
    if (kind == HALSDK_COMP_RT && (h->lock & HAL_LOCK_LOAD)) {
        hal_unlock();
        return fail_locked(K_COMP, name, "component '%s': HAL is locked "
                           "against loading");
    }
    if (find_in_space(K_COMP, name)) {
        hal_unlock();
        return fail_exists(K_COMP, name, "duplicate component name '%s'");
    }
    hal_comp_t *c = obj_new(K_COMP, sizeof(*c), name);
    if (!c) {
        hal_unlock();
        return -ENOMEM;
    }
    c->id = h->next_id++;
    c->kind = kind;
    c->pid = getpid();
    c->pid_start = hal_proc_start_time(c->pid);
    c->base = (uint64_t)(uintptr_t)hal_map.base;
    obj_publish(&c->o);
    cur_owner = c->id;
    hal_unlock();
    return c->id;
}

int hal_comp_set_ready(int id, int ready)
{
    int r = hal_lock();
    if (r)
        return r;
    hal_comp_t *c = hal_comp_by_id(id);
    if (!c) {
        hal_unlock();
        return hal_fail(EINVAL, "no component with id %d", id);
    }
    c->ready = ready;
    hal_map.hdr->serial++;
    hal_unlock();
    return 0;
}

int hal_inst_new(const char *name, int comp_id)
{
    int r = hal_check_name(name, "instance");
    if (r)
        return r;
    if ((r = hal_lock()))
        return r;
    hal_comp_t *c = hal_comp_by_id(comp_id);
    if (!c)
        r = hal_fail(EINVAL, "instance '%s': no component with id %d",
                     name, comp_id);
    else if (c->pid != getpid())
        r = hal_rule(hal_fail(EPERM, "instance '%s': component '%s' "
                              "belongs to process %d", name, c->o.name,
                              c->pid),
                     HAL_RULE_NOT_OWNER, K_COMP, c->o.name, name, NULL);
    else if (find_in_space(K_COMP, name))
        r = fail_exists(K_INST, name, "duplicate instance name '%s'");
    if (r) {
        hal_unlock();
        return r;
    }
    hal_inst_t *i = obj_new(K_INST, sizeof(*i), name);
    if (!i) {
        hal_unlock();
        return -ENOMEM;
    }
    i->id = hal_map.hdr->next_id++;
    i->comp = SHMOFF(c);
    c->ninst++;
    obj_publish(&i->o);
    cur_owner = i->id;
    hal_unlock();
    return i->id;
}

void *hal_malloc_owned(long size, int owner_id)
{
    if (hal_lock())
        return NULL;
    hoff_t owner = 0;
    hal_comp_t *c = hal_comp_by_id(owner_id);
    hal_inst_t *i = c ? NULL : hal_inst_by_id(owner_id);
    hal_comp_t *ic = i ? hal_obj_get(i->comp, K_COMP, "the owner of "
                                     "instance", i->o.name) : NULL;
    if (c && c->pid == getpid())
        owner = SHMOFF(c);
    else if (ic && ic->pid == getpid())
        owner = SHMOFF(i);
    void *p = alloc_for(owner, size);
    if (!p)
        hal_fail(ENOMEM, "hal_malloc(%ld): HAL instance is full", size);
    hal_unlock();
    return p;
}

/* hal_malloc() has no owner argument: the memory goes to the component
   or instance this process created last */
void *hal_malloc_current(long size)
{
    return hal_malloc_owned(size, cur_owner);
}

/* ---------------------------------------------------------------- */
/* pins and params                                                  */

static void write_cell(hal_pin_t *pin, volatile void *target)
{
    hal_comp_t *c = hal_obj_get(pin->comp, K_COMP, "the owner of pin",
                                pin->o.name);
    if (!c)
        return;
    if (!hal_off_ok(pin->ptr_cell, sizeof(uint64_t), 1)) {
        hal_damaged("pin '%s': pointer cell offset %u is outside the heap",
                    pin->o.name, pin->ptr_cell);
        return;
    }
    uint64_t addr = c->base + (uint64_t)((const char *)target - hal_map.base);
    __atomic_store_n((uint64_t *)SHMPTR(pin->ptr_cell), addr,
                     __ATOMIC_RELEASE);
}

/* without the lock: a signal deleted meanwhile still has its bytes, so
   only the bounds are checked */
hal_value_t *hal_pin_value(hal_pin_t *pin)
{
    hoff_t so = pin->signal;
    if (!so)
        return &pin->dummy;
    if (hal_off_ok(so, sizeof(hal_sig_t), HAL_ALIGN))
        return &((hal_sig_t *)SHMPTR(so))->value;
    hal_damaged("pin '%s': signal offset %u is outside the heap",
                pin->o.name, so);
    return &pin->dummy;
}

/* a bad offset gives (and reports) a scratch value, never NULL: realtime
   captures read through this */
void *hal_param_value(hal_param_t *param)
{
    static hal_value_t scratch;
    if (hal_off_ok(param->data, sizeof(hal_value_t), 1))
        return SHMPTR(param->data);
    hal_damaged("param '%s': value offset %u is outside the heap",
                param->o.name, param->data);
    return &scratch;
}

/* the record of a pin or param, published; lock held.  `where` is the
   pin's pointer cell or the param's value */
static hal_item_t *item_make(int kind, const char *name, int type, int dir,
                             hal_comp_t *c, hal_inst_t *i, void *where)
{
    hal_item_t *it = obj_new(kind, kind == K_PIN ? sizeof(hal_pin_t)
                                                 : sizeof(hal_param_t), name);
    if (!it)
        return NULL;
    it->type = (int16_t)type;
    it->dir = (int16_t)dir;
    it->comp = SHMOFF(c);
    it->inst = i ? SHMOFF(i) : 0;
    if (kind == K_PIN) {
        hal_pin_t *p = (hal_pin_t *)it;
        p->ptr_cell = SHMOFF(where);
        write_cell(p, &p->dummy);
    } else {
        ((hal_param_t *)it)->data = SHMOFF(where);
    }
    obj_publish(&it->o);
    return it;
}

/* hal_pin_new and hal_param_new: every check, then the record */
static int item_add(int kind, const char *name, int type, int dir,
                    volatile void *where, int owner_id)
{
    const char *what = kind == K_PIN ? "pin" : "param";
    int r = hal_check_name(name, what);
    if (r)
        return r;
    if (!type_size(type))
        return hal_rule(hal_fail(EINVAL, "%s '%s': bad type %d", what,
                                 name, type),
                        HAL_RULE_BAD_ARG, kind, name, NULL, NULL);
    if (!hal_shape_ok(kind, type, dir))
        return hal_rule(hal_fail(EINVAL, "%s '%s': bad direction %d", what,
                                 name, dir),
                        HAL_RULE_BAD_ARG, kind, name, NULL, NULL);
    if (!hal_map.hdr)
        return hal_fail(ENODEV, "no HAL instance is attached");
    if (!in_segment(where, kind == K_PIN ? (long)sizeof(void *)
                                         : type_size(type)))
        return hal_fail(EINVAL, "%s '%s': %s is not in HAL shared memory "
                        "(allocate it with hal_malloc)", what, name,
                        kind == K_PIN ? "data_ptr_addr" : "data_addr");
    if ((r = hal_lock()))
        return r;
    hal_comp_t *c;
    hal_inst_t *i;
    if (!(r = resolve_owner(owner_id, &c, &i, what, name))) {
        if (find_in_space(K_PIN, name))
            r = fail_exists(kind, name, "duplicate pin or param name '%s'");
        else if (!item_make(kind, name, type, dir, c, i, (void *)where))
            r = -ENOMEM;
    }
    hal_unlock();
    return r;
}

int hal_pin_new(const char *name, int type, int dir, void **ptr_cell,
                int owner_id)
{
    return item_add(K_PIN, name, type, dir, ptr_cell, owner_id);
}

int hal_param_new(const char *name, int type, int dir, volatile void *data,
                  int owner_id)
{
    return item_add(K_PARAM, name, type, dir, data, owner_id);
}

/* rename a pin or param; its original name is kept for unalias */
static int rename_item(hal_obj_t *o, hoff_t *oldname, const char *alias)
{
    if (!*oldname) {
        char *keep = hal_alloc(HAL_NAME_SIZE, 0);
        if (!keep)
            return hal_fail(ENOMEM, "HAL instance is full: cannot alias "
                            "'%s'", o->name);
        memcpy(keep, o->name, HAL_NAME_SIZE);
        *oldname = SHMOFF(keep);
        hal_map.hdr->naliases++;
    }
    index_remove(o);
    snprintf(o->name, sizeof(o->name), "%s", alias);
    index_insert(o);
    hal_map.hdr->serial++;
    return 0;
}

int hal_alias(int kind, const char *name, const char *alias)
{
    int r = hal_check_name(alias, "alias");
    if (r)
        return r;
    if ((r = hal_lock()))
        return r;
    hal_obj_t *o;
    hoff_t *oldname = NULL;
    r = find_one_for_config(kind, name, (void **)&o, "cannot alias '%s': "
                            "HAL is locked against configuration");
    if (r)
        goto out;
    oldname = kind == K_PIN ? &((hal_pin_t *)o)->oldname
                            : &((hal_param_t *)o)->oldname;
    if (find_in_space(K_PIN, alias)) {
        r = fail_exists(kind, alias, "duplicate pin or param name '%s'");
        goto out;
    }
    r = rename_item(o, oldname, alias);
out:
    hal_unlock();
    return r;
}

int hal_unalias(int kind, const char *alias)
{
    int r = hal_lock();
    if (r)
        return r;
    hal_obj_t *o = hal_find(kind, alias);
    hoff_t *oldname;
    if (!o) {
        r = fail_not_found(kind, alias);
        goto out;
    }
    oldname = kind == K_PIN ? &((hal_pin_t *)o)->oldname
                            : &((hal_param_t *)o)->oldname;
    if (!*oldname) {
        /* not an alias: as if there were no such name */
        r = fail_not_found(kind, alias);
        goto out;
    }
    char *orig = hal_oldname_of((hal_item_t *)o);
    if (!orig) {
        r = -EUCLEAN;
        goto out;
    }
    if (find_in_space(K_PIN, orig)) {
        r = hal_rule(hal_fail(EEXIST, "cannot unalias '%s': its original "
                              "name '%s' is in use", alias, orig),
                     HAL_RULE_EXISTS, kind, orig, alias, NULL);
        goto out;
    }
    index_remove(o);
    memcpy(o->name, orig, HAL_NAME_SIZE);
    index_insert(o);
    hal_free(orig);
    *oldname = 0;
    hal_map.hdr->naliases--;
    hal_map.hdr->serial++;
out:
    hal_unlock();
    return r;
}

/* ---------------------------------------------------------------- */
/* signals and links                                                */

/* a new signal record, published; lock held */
static hal_sig_t *signal_make(const char *name, int type)
{
    hal_sig_t *s = obj_new(K_SIG, sizeof(*s), name);
    if (s) {
        s->type = (int16_t)type;
        obj_publish(&s->o);
    }
    return s;
}

int hal_signal_new(const char *name, int type)
{
    int r = hal_check_name(name, "signal");
    if (r)
        return r;
    if (!type_size(type))
        return hal_rule(hal_fail(EINVAL, "signal '%s': bad type %d", name,
                                 type),
                        HAL_RULE_BAD_ARG, K_SIG, name, NULL, NULL);
    if ((r = hal_lock()))
        return r;
    if (hal_map.hdr->lock & HAL_LOCK_CONFIG)
        r = fail_locked(K_SIG, name, "signal '%s': HAL is locked against "
                        "configuration");
    else if (find_in_space(K_SIG, name))
        r = fail_exists(K_SIG, name, "duplicate signal name '%s'");
    else if (!signal_make(name, type))
        r = -ENOMEM;
    hal_unlock();
    return r;
}

static void unlink_locked(hal_pin_t *p)
{
    hal_sig_t *s = hal_obj_get(p->signal, K_SIG, "the signal of pin",
                               p->o.name);
    if (!s) {
        write_cell(p, &p->dummy);
        p->signal = 0;
        return;
    }
    /* the pin keeps the last value it saw */
    p->dummy.lu = s->value.lu;
    write_cell(p, &p->dummy);
    p->signal = 0;
    if (p->dir == HALSDK_IN)
        s->readers--;
    else if (p->dir == HALSDK_OUT)
        s->writers--;
    else
        s->bidirs--;
    hal_map.hdr->serial++;
}

/* remove a pin or param: unlinked, alias name freed; lock held */
static void item_delete(hal_item_t *it)
{
    if (it->o.kind == K_PIN && ((hal_pin_t *)it)->signal)
        unlink_locked((hal_pin_t *)it);
    if (it->oldname) {
        char *old = hal_oldname_of(it);
        if (old)
            hal_free(old);
        hal_map.hdr->naliases--;
    }
    obj_delete(&it->o);
}

int hal_signal_delete(const char *name)
{
    int r = hal_lock();
    if (r)
        return r;
    hal_sig_t *s;
    r = find_one_for_config(K_SIG, name, (void **)&s, "signal '%s': HAL is "
                            "locked against configuration");
    if (!r) {
        hoff_t so = SHMOFF(s);
        FOR_EACH(K_PIN, hal_pin_t, p)
            if (p->signal == so)
                unlink_locked(p);
        obj_delete(&s->o);
    }
    hal_unlock();
    return r;
}

/* the pin linked to s that a new pin of direction dir conflicts with
   (the first by name, as halcmd reports it), or NULL; lock held */
static hal_pin_t *conflicting_pin(hal_sig_t *s, int dir)
{
    hal_pin_t *best = NULL;
    hoff_t so = SHMOFF(s);
    if (dir == HALSDK_IN)
        return NULL;
    FOR_EACH(K_PIN, hal_pin_t, q)
        if (q->signal == so &&
            (q->dir == HALSDK_OUT || (q->dir == HALSDK_IO &&
                                      dir == HALSDK_OUT)) &&
            (!best || strcmp(q->o.name, best->o.name) < 0))
            best = q;
    return best;
}

/* may pin p join signal sig_name of type `type`, that has `writers` out
   and `bidirs` io pins (of which `other` is one, maybe NULL)?  Lock held.
   The rules of a link, in the order the reference checks them. */
static int link_check(hal_pin_t *p, const char *sig_name, int type,
                      int writers, int bidirs, const char *other)
{
    const char *pin_name = p->o.name;
    if (p->signal) {
        hal_sig_t *cs = hal_obj_get(p->signal, K_SIG, "the signal of pin",
                                    pin_name);
        if (!cs)
            return -EUCLEAN;
        const char *cur = cs->o.name;
        return hal_rule(hal_fail(EBUSY, "Pin '%s' was already linked to "
                                 "signal '%s'", pin_name, cur),
                        HAL_RULE_PIN_LINKED, K_PIN, pin_name, cur,
                        sig_name);
    }
    if (p->type != type)
        return hal_rule(hal_fail(EPROTOTYPE, "Signal '%s' of type '%s' "
                                 "cannot add pin '%s' of type '%s'",
                                 sig_name, type_word(type), pin_name,
                                 type_word(p->type)),
                        HAL_RULE_TYPE_MISMATCH, K_SIG, sig_name, pin_name,
                        NULL);
    if (p->dir == HALSDK_OUT && writers > 0)
        return hal_rule(hal_fail(EBUSY, "signal '%s' already has an output "
                                 "pin, cannot add output pin '%s'",
                                 sig_name, pin_name),
                        HAL_RULE_SECOND_WRITER, K_SIG, sig_name, pin_name,
                        other);
    if (p->dir == HALSDK_OUT && bidirs > 0)
        return hal_rule(hal_fail(EBUSY, "signal '%s' has I/O pins, cannot "
                                 "add output pin '%s'", sig_name,
                                 pin_name),
                        HAL_RULE_WRITER_AND_IO, K_SIG, sig_name, pin_name,
                        other);
    if (p->dir == HALSDK_IO && writers > 0)
        return hal_rule(hal_fail(EBUSY, "signal '%s' has an output pin, "
                                 "cannot add I/O pin '%s'", sig_name,
                                 pin_name),
                        HAL_RULE_WRITER_AND_IO, K_SIG, sig_name, pin_name,
                        other);
    return 0;
}

/* link a checked pin; lock held */
static void link_locked(hal_pin_t *p, hal_sig_t *s)
{
    /* the first pin of a signal gives the signal its value */
    if (s->readers == 0 && s->writers == 0 && s->bidirs == 0)
        s->value.lu = p->dummy.lu;
    if (p->dir == HALSDK_IN)
        s->readers++;
    else if (p->dir == HALSDK_OUT)
        s->writers++;
    else
        s->bidirs++;
    p->signal = SHMOFF(s);
    write_cell(p, &s->value);
    hal_map.hdr->serial++;
}

int hal_link(const char *pin_name, const char *sig_name)
{
    int r = hal_lock();
    if (r)
        return r;
    hal_pin_t *p;
    hal_sig_t *s;
    r = find_for_config(K_PIN, pin_name, (void **)&p, K_SIG, sig_name,
                        (void **)&s, "cannot link '%s': HAL is locked "
                        "against configuration");
    if (r || p->signal == SHMOFF(s))
        goto out;           /* refused, or already there */
    hal_pin_t *other = conflicting_pin(s, p->dir);
    r = link_check(p, sig_name, s->type, s->writers, s->bidirs,
                   other ? other->o.name : NULL);
    if (!r)
        link_locked(p, s);
out:
    hal_unlock();
    return r;
}

/*
 * Link pins to a signal, creating it with the first pin's type: every
 * pin is checked against the signal and against the pins before it, and
 * nothing changes unless all may be linked.  Pins already on the signal
 * stay.  The order of the checks is the reference halcmd's.
 */
int hal_net(const char *sig_name, const char *const *pins, int npins)
{
    if (!sig_name)
        return hal_fail(EINVAL, "net: no signal name");
    int r = hal_lock();
    if (r)
        return r;
    hal_header_t *h = hal_map.hdr;
    hal_sig_t *s = hal_find(K_SIG, sig_name);
    hoff_t so = s ? SHMOFF(s) : 0;
    int type = 0, writers = 0, bidirs = 0;
    const char *writer = NULL, *bidir = NULL;
    if (hal_find(K_PIN, sig_name)) {
        r = hal_rule(hal_fail(EINVAL, "Signal name '%s' must not be the "
                              "same as a pin.  Did you omit the signal "
                              "name?", sig_name),
                     HAL_RULE_NAME_IS_PIN, K_SIG, sig_name, NULL, NULL);
        goto out;
    }
    if (npins <= 0) {
        r = hal_rule(hal_fail(EINVAL, "net '%s': no pins given", sig_name),
                     HAL_RULE_NO_PINS, K_SIG, sig_name, NULL, NULL);
        goto out;
    }
    /* each pin against the signal as it is */
    for (int k = 0; k < npins; k++) {
        hal_pin_t *p = hal_find(K_PIN, pins[k]);
        if (!p) {
            r = fail_not_found(K_PIN, pins[k]);
            goto out;
        }
        if (p->signal && p->signal == so)
            continue;
        if (!s) {
            if (p->signal)
                r = link_check(p, sig_name, p->type, 0, 0, NULL);
            if (r)
                goto out;
            continue;
        }
        hal_pin_t *other = conflicting_pin(s, p->dir);
        r = link_check(p, sig_name, s->type, s->writers, s->bidirs,
                       other ? other->o.name : NULL);
        if (r)
            goto out;
    }
    /* then against each other: one type, one writer or io pins */
    if (s) {
        type = s->type;
        writers = s->writers;
        bidirs = s->bidirs;
    } else {
        type = ((hal_pin_t *)hal_find(K_PIN, pins[0]))->type;
    }
    for (int k = 0; k < npins && !s; k++) {
        hal_pin_t *p = hal_find(K_PIN, pins[k]);
        if ((r = link_check(p, sig_name, type, 0, 0, NULL)))
            goto out;
    }
    for (int k = 0; k < npins; k++) {
        hal_pin_t *p = hal_find(K_PIN, pins[k]);
        if (p->signal && p->signal == so)
            continue;
        r = link_check(p, sig_name, type, writers, bidirs,
                       p->dir == HALSDK_OUT && writer ? writer
                       : p->dir == HALSDK_OUT ? bidir : writer);
        if (r)
            goto out;
        if (p->dir == HALSDK_OUT) {
            writers++;
            writer = p->o.name;
        } else if (p->dir == HALSDK_IO) {
            bidirs++;
            bidir = p->o.name;
        }
    }
    if (h->lock & HAL_LOCK_CONFIG) {
        r = s ? fail_locked(K_PIN, pins[0], "cannot link '%s': HAL is "
                            "locked against configuration")
              : fail_locked(K_SIG, sig_name, "signal '%s': HAL is locked "
                            "against configuration");
        goto out;
    }
    if (!s) {
        if ((r = hal_check_name(sig_name, "signal")))
            goto out;
        if (!(s = signal_make(sig_name, type))) {
            r = -ENOMEM;
            goto out;
        }
        so = SHMOFF(s);
    }
    for (int k = 0; k < npins; k++) {
        hal_pin_t *p = hal_find(K_PIN, pins[k]);
        if (p->signal != so)
            link_locked(p, s);
    }
out:
    hal_unlock();
    return r;
}

int hal_unlink(const char *pin_name)
{
    int r = hal_lock();
    if (r)
        return r;
    hal_pin_t *p;
    r = find_one_for_config(K_PIN, pin_name, (void **)&p, "cannot unlink "
                            "'%s': HAL is locked against configuration");
    if (!r && p->signal)
        unlink_locked(p);
    hal_unlock();
    return r;
}

/* may setp/sets write this record? */
int hal_check_settable(const hal_obj_t *o, int flags)
{
    hal_header_t *h = hal_map.hdr;
    if (!h)
        return hal_fail(ENODEV, "no HAL instance is attached");
    /* the type and direction say how the value is written: a stray
       write there is damage, not a value to coerce */
    if (o->kind == K_PIN || o->kind == K_PARAM) {
        const hal_item_t *it = (const hal_item_t *)o;
        if (!hal_shape_ok(o->kind, it->type, it->dir))
            return hal_damaged("%s '%s': type %d, direction %d",
                               kind_word(o->kind), o->name, it->type,
                               it->dir);
    } else if (o->kind == K_SIG &&
               !hal_shape_ok(K_SIG, ((const hal_sig_t *)o)->type, 0)) {
        return hal_damaged("signal '%s': type %d", o->name,
                           ((const hal_sig_t *)o)->type);
    }
    if (!(flags & HAL_SET_IGNORE_LOCK) && (h->lock & HAL_LOCK_PARAMS))
        return hal_rule(hal_fail(EPERM, "cannot set %s '%s': HAL is locked "
                                 "against setting values",
                                 kind_word(o->kind), o->name),
                        HAL_RULE_LOCKED, o->kind, o->name, NULL, NULL);
    if (o->kind == K_PIN) {
        const hal_pin_t *p = (const hal_pin_t *)o;
        if (p->dir == HALSDK_OUT)
            return hal_rule(hal_fail(EPERM, "pin '%s' is not writable",
                                     o->name),
                            HAL_RULE_WRITE_OUTPUT, K_PIN, o->name, NULL,
                            NULL);
        hoff_t so = p->signal;
        if (so) {
            /* no lock here: unlinked and deleted meanwhile is no damage */
            hal_sig_t *s = hal_obj_at(so, K_SIG);
            if (!s && p->signal != so)
                return hal_check_settable(o, flags);
            if (!s)
                return hal_damaged("pin '%s': signal offset %u is not a "
                                   "signal record", o->name, so);
            return hal_rule(hal_fail(EBUSY, "pin '%s' is connected to a "
                                     "signal", o->name),
                            HAL_RULE_PIN_CONNECTED, K_PIN, o->name,
                            s->o.name, NULL);
        }
    } else if (o->kind == K_PARAM) {
        if (((const hal_param_t *)o)->dir == HALSDK_RO)
            return hal_rule(hal_fail(EPERM, "param '%s' is not writable",
                                     o->name),
                            HAL_RULE_RO_PARAM, K_PARAM, o->name, NULL, NULL);
    } else if (o->kind == K_SIG) {
        /* io pins do not count, as in the reference */
        if (((const hal_sig_t *)o)->writers > 0)
            return hal_rule(hal_fail(EBUSY, "signal '%s' already has "
                                     "writer(s)", o->name),
                            HAL_RULE_SIG_HAS_WRITER, K_SIG, o->name, NULL,
                            NULL);
    } else {
        return hal_rule(hal_fail(EINVAL, "%s '%s' has no value",
                                 kind_word(o->kind), o->name),
                        HAL_RULE_BAD_ARG, o->kind, o->name, NULL, NULL);
    }
    return 0;
}

/* ---------------------------------------------------------------- */
/* functions and threads                                            */

/* a core-made pin or param (function and thread timing): its cell or
   value belongs to the owner; lock held */
static hal_pin_t *item_pin_new(const char *name, int type, int dir,
                               hal_comp_t *c, hal_inst_t *i, hoff_t owner)
{
    void *cell = alloc_for(owner, sizeof(void *));
    return cell ? (hal_pin_t *)item_make(K_PIN, name, type, dir, c, i, cell)
                : NULL;
}

static hal_param_t *item_param_new(const char *name, int type, int dir,
                                   hal_comp_t *c, hal_inst_t *i,
                                   hoff_t owner)
{
    void *data = alloc_for(owner, 8);
    return data ? (hal_param_t *)item_make(K_PARAM, name, type, dir, c, i,
                                           data)
                : NULL;
}

static int names_free(const char *base, const char *const *suffixes)
{
    char n[HAL_NAME_SIZE + 32];
    for (; *suffixes; suffixes++) {
        int len = snprintf(n, sizeof(n), "%s%s", base, *suffixes);
        if (len > HALSDK_NAME_LEN)
            return hal_fail(EINVAL, "name '%s' is longer than %d "
                            "characters", n, HALSDK_NAME_LEN);
        if (find_in_space(K_PIN, n))
            return fail_exists(K_PIN, n, "duplicate pin or param name '%s'");
    }
    return 0;
}

int hal_export_funct(const char *name, halsdk_funct_t fn, void *arg,
                     int uses_fp, int reentrant, int owner_id, int python)
{
    static const char *const sfx[] = {".time", ".tmax", ".tmax-increased",
                                      NULL};
    int r = hal_check_name(name, "function");
    if (r)
        return r;
    if (!hal_map.hdr)
        return hal_fail(ENODEV, "no HAL instance is attached");
    if (!hal_map.is_host)
        return hal_rule(hal_fail(EPERM, "function '%s': only components "
                                 "loaded in the host process (loadrt) "
                                 "export functions", name),
                        HAL_RULE_HOST_ONLY, K_FUNCT, name, NULL, NULL);
    if (!fn)
        return hal_fail(EINVAL, "function '%s': no entry point", name);
    if ((r = hal_lock()))
        return r;
    hal_comp_t *c;
    hal_inst_t *i;
    if ((r = resolve_owner(owner_id, &c, &i, "function", name)))
        goto out;
    if (find_in_space(K_FUNCT, name)) {
        r = fail_exists(K_FUNCT, name, "duplicate function name '%s'");
        goto out;
    }
    if ((r = names_free(name, sfx)))
        goto out;
    hoff_t owner = i ? SHMOFF(i) : SHMOFF(c);
    char n[HAL_NAME_SIZE + 32];
    hal_funct_t *f = obj_new(K_FUNCT, sizeof(*f), name);
    hal_pin_t *tp = NULL;
    hal_param_t *tm = NULL, *ti = NULL;
    if (f) {
        snprintf(n, sizeof(n), "%s.time", name);
        tp = item_pin_new(n, HALSDK_S32, HALSDK_OUT, c, i, owner);
    }
    if (tp) {
        snprintf(n, sizeof(n), "%s.tmax", name);
        tm = item_param_new(n, HALSDK_S32, HALSDK_RW, c, i, owner);
    }
    if (tm) {
        snprintf(n, sizeof(n), "%s.tmax-increased", name);
        ti = item_param_new(n, HALSDK_BIT, HALSDK_RO, c, i, owner);
    }
    if (!ti) {
        /* undo what was made: the instance stays as it was */
        if (tm)
            obj_delete(&tm->o);
        if (tp)
            obj_delete(&tp->o);
        if (f)
            hal_free(f);
        r = hal_fail(ENOMEM, "HAL instance is full: cannot export "
                     "function '%s'", name);
        goto out;
    }
    f->comp = SHMOFF(c);
    f->inst = i ? SHMOFF(i) : 0;
    f->uses_fp = uses_fp;
    f->reentrant = reentrant;
    f->python = python;
    f->fn = (uint64_t)(uintptr_t)fn;
    f->arg = (uint64_t)(uintptr_t)arg;
    f->time_pin = SHMOFF(tp);
    f->tmax_param = SHMOFF(tm);
    f->tmax_inc_param = SHMOFF(ti);
    obj_publish(&f->o);
out:
    hal_unlock();
    return r;
}

int hal_thread_new(const char *name, long period, int uses_fp,
                   unsigned timing_every)
{
    static const char *const sfx[] = {".time", ".tmax", NULL};
    char n[HAL_NAME_SIZE + 32];
    int r = hal_check_name(name, "thread");
    if (r)
        return r;
    if (!hal_map.hdr)
        return hal_fail(ENODEV, "no HAL instance is attached");
    if (!hal_map.is_host)
        return hal_rule(hal_fail(EPERM, "thread '%s': threads are created "
                                 "by the host process", name),
                        HAL_RULE_HOST_ONLY, K_THREAD, name, NULL, NULL);
    if (period < 1000)
        return hal_rule(hal_fail(EINVAL, "thread '%s': period %ld ns is "
                                 "shorter than 1000 ns", name, period),
                        HAL_RULE_BAD_ARG, K_THREAD, name, NULL, NULL);
    if (snprintf(n, sizeof(n), "__%s", name) > HALSDK_NAME_LEN)
        return hal_fail(EINVAL, "thread name '%s' is too long", name);
    if ((r = hal_lock()))
        return r;
    hal_header_t *h = hal_map.hdr;
    if (find_in_space(K_THREAD, name))
        r = fail_exists(K_THREAD, name, "duplicate thread name '%s'");
    else if (find_in_space(K_COMP, n))
        r = hal_rule(hal_fail(EEXIST, "thread '%s': component name '%s' is "
                              "taken", name, n),
                     HAL_RULE_EXISTS, K_COMP, n, name, NULL);
    else if (h->count[K_THREAD] >= HAL_MAX_THREADS)
        r = hal_rule(hal_fail(ENOSPC, "thread '%s': at most %d threads",
                              name, HAL_MAX_THREADS),
                     HAL_RULE_FULL, K_THREAD, name, NULL, NULL);
    else
        r = names_free(name, sfx);
    if (r)
        goto out;
    hal_comp_t *c = obj_new(K_COMP, sizeof(*c), n);
    hal_thread_t *t = c ? obj_new(K_THREAD, sizeof(*t), name) : NULL;
    if (!t) {
        if (c)
            hal_free(c);
        r = -ENOMEM;
        goto out;
    }
    c->id = h->next_id++;
    c->kind = HALSDK_COMP_RT;
    c->ready = 1;
    c->pid = getpid();
    c->pid_start = hal_proc_start_time(c->pid);
    c->base = (uint64_t)(uintptr_t)hal_map.base;
    obj_publish(&c->o);
    snprintf(n, sizeof(n), "%s.time", name);
    hal_pin_t *tp = item_pin_new(n, HALSDK_S32, HALSDK_OUT, c, NULL,
                                 SHMOFF(c));
    snprintf(n, sizeof(n), "%s.tmax", name);
    hal_param_t *tm = tp ? item_param_new(n, HALSDK_S32, HALSDK_RW, c, NULL,
                                          SHMOFF(c)) : NULL;
    if (!tm) {
        if (tp)
            obj_delete(&tp->o);
        free_owned(&c->mem);
        obj_delete(&c->o);
        hal_free(t);
        r = hal_fail(ENOMEM, "HAL instance is full: cannot create "
                     "thread '%s'", name);
        goto out;
    }
    t->period = period;
    t->uses_fp = uses_fp;
    t->timing_every = timing_every ? timing_every : 1;
    t->comp = SHMOFF(c);
    t->time_pin = SHMOFF(tp);
    t->tmax_param = SHMOFF(tm);
    /* faster threads get higher priority, as in the reference */
    t->priority = 0;
    int slot = exec_create(t);
    if (slot < 0) {
        obj_delete(&tm->o);
        obj_delete(&tp->o);
        free_owned(&c->mem);
        obj_delete(&c->o);
        hal_free(t);
        r = slot;
        goto out;
    }
    t->slot = slot;
    obj_publish(&t->o);
out:
    hal_unlock();
    return r;
}

/* the entry at off of thread t's function list, or NULL with the damage
   reported; steps counts the walk */
hal_fentry_t *hal_fentry_at(hal_thread_t *t, hoff_t off, long *steps)
{
    if (!hal_block_at(off, sizeof(hal_fentry_t)) ||
        ++*steps > (long)t->nfuncts + 1 || *steps > (long)HAL_WALK_MAX) {
        hal_damaged("thread '%s': function list entry at offset %u is "
                    "not an entry%s", t->o.name, off,
                    *steps > 1 ? " (or the list is longer than its count)"
                               : "");
        return NULL;
    }
    return SHMPTR(off);
}

/* remove every entry of a function from a thread's list */
static int drop_entries(hal_thread_t *t, hoff_t fo)
{
    int n = 0;
    hoff_t *link = &t->functs;
    long steps = 0;
    while (*link) {
        hal_fentry_t *e = hal_fentry_at(t, *link, &steps);
        if (!e) {
            *link = 0;          /* drop (leak) the rest of the list */
            break;
        }
        if (fo == 0 || e->funct == fo) {
            hal_funct_t *f = hal_obj_at(e->funct, K_FUNCT);
            if (f)
                f->users--;
            *link = e->next;
            hal_free(e);
            t->nfuncts--;
            steps--;            /* the list is one shorter: still bounded */
            n++;
        } else {
            link = &e->next;
        }
    }
    return n;
}

static void thread_delete_locked(hal_thread_t *t)
{
    exec_destroy(t->slot);
    drop_entries(t, 0);
    hal_comp_t *c = hal_obj_get(t->comp, K_COMP, "the component of thread",
                                t->o.name);
    hoff_t co = t->comp;
    FOR_EACH(K_PIN, hal_item_t, it)
        if (it->comp == co)
            item_delete(it);
    FOR_EACH(K_PARAM, hal_item_t, it)
        if (it->comp == co)
            item_delete(it);
    if (c) {
        free_owned(&c->mem);
        obj_delete(&c->o);
    }
    obj_delete(&t->o);
}

int hal_thread_delete(const char *name)
{
    int r = hal_lock();
    if (r)
        return r;
    hal_thread_t *t = hal_find(K_THREAD, name);
    if (!t)
        r = fail_not_found(K_THREAD, name);
    else if (!hal_map.is_host)
        r = hal_rule(hal_fail(EPERM, "thread '%s': only the host deletes "
                              "threads", name),
                     HAL_RULE_HOST_ONLY, K_THREAD, name, NULL, NULL);
    else if (exec_stepping())
        r = hal_fail(EBUSY, "thread '%s' is being stepped", name);
    else
        thread_delete_locked(t);
    hal_unlock();
    return r;
}

int hal_addf(const char *funct, const char *thread, int position)
{
    int r = hal_lock();
    if (r)
        return r;
    hal_funct_t *f;
    hal_thread_t *t;
    r = find_for_config(K_FUNCT, funct, (void **)&f, K_THREAD, thread,
                        (void **)&t, "addf '%s': HAL is locked against "
                        "configuration");
    if (r)
        goto out;
    if (!hal_map.is_host)
        r = hal_rule(hal_fail(EPERM, "addf '%s': only the host changes "
                              "threads", funct),
                     HAL_RULE_HOST_ONLY, K_FUNCT, funct, thread, NULL);
    else if (position == 0 || position > t->nfuncts + 1 ||
             position < -(t->nfuncts + 1))
        r = hal_rule(hal_fail(EINVAL, "addf '%s': position %d is out of "
                              "range for thread '%s' with %d functions",
                              funct, position, thread, t->nfuncts),
                     HAL_RULE_BAD_POSITION, K_FUNCT, funct, thread, NULL);
    else if (f->users > 0 && !f->reentrant)
        r = hal_rule(hal_fail(EINVAL, "function '%s' may only be added to "
                              "one thread", funct),
                     HAL_RULE_NOT_REENTRANT, K_FUNCT, funct, thread, NULL);
    else if (f->uses_fp && !t->uses_fp)
        r = hal_rule(hal_fail(EINVAL, "function '%s' needs FP, thread '%s' "
                              "has no FP", funct, thread),
                     HAL_RULE_NEEDS_FP, K_FUNCT, funct, thread, NULL);
    if (r)
        goto out;
    hal_fentry_t *e = hal_alloc(sizeof(*e), 0);
    if (!e) {
        r = hal_fail(ENOMEM, "HAL instance is full: addf '%s'", funct);
        goto out;
    }
    e->funct = SHMOFF(f);
    int index = position > 0 ? position - 1 : t->nfuncts + 1 + position;
    hoff_t *link = &t->functs;
    long steps = 0;
    for (int k = 0; k < index; k++) {
        hal_fentry_t *x = hal_fentry_at(t, *link, &steps);
        if (!x) {
            hal_free(e);
            r = -EUCLEAN;
            goto out;
        }
        link = &x->next;
    }
    e->next = *link;
    *link = SHMOFF(e);
    t->nfuncts++;
    f->users++;
    hal_map.hdr->serial++;
    r = exec_publish(t);
    if (r) {
        *link = e->next;
        hal_free(e);
        t->nfuncts--;
        f->users--;
    }
out:
    hal_unlock();
    return r;
}

int hal_delf(const char *funct, const char *thread)
{
    int r = hal_lock();
    if (r)
        return r;
    hal_funct_t *f = hal_find(K_FUNCT, funct);
    hal_thread_t *t = hal_find(K_THREAD, thread);
    if (hal_map.hdr->lock & HAL_LOCK_CONFIG)
        r = fail_locked(K_FUNCT, funct, "delf '%s': HAL is locked against "
                        "configuration");
    else if (!f)
        r = fail_not_found(K_FUNCT, funct);
    else if (f->users == 0)
        r = hal_rule(hal_fail(ENOENT, "function '%s' is not in thread '%s'",
                              funct, thread),
                     HAL_RULE_FUNCT_UNUSED, K_FUNCT, funct, thread, NULL);
    else if (!t)
        r = fail_not_found(K_THREAD, thread);
    else if (!hal_map.is_host)
        r = hal_rule(hal_fail(EPERM, "delf '%s': only the host changes "
                              "threads", funct),
                     HAL_RULE_HOST_ONLY, K_FUNCT, funct, thread, NULL);
    if (r)
        goto out;
    /* remove the first entry only, as the reference does */
    hoff_t *link = &t->functs, fo = SHMOFF(f);
    long steps = 0;
    while (*link) {
        hal_fentry_t *x = hal_fentry_at(t, *link, &steps);
        if (!x) {
            r = -EUCLEAN;
            goto out;
        }
        if (x->funct == fo)
            break;
        link = &x->next;
    }
    if (!*link) {
        r = hal_rule(hal_fail(ENOENT, "function '%s' is not in thread '%s'",
                              funct, thread),
                     HAL_RULE_NOT_IN_THREAD, K_FUNCT, funct, thread, NULL);
        goto out;
    }
    hal_fentry_t *e = SHMPTR(*link);
    *link = e->next;
    t->nfuncts--;
    f->users--;
    hal_map.hdr->serial++;
    exec_publish(t);    /* waits until no cycle uses the old list */
    hal_free(e);
out:
    hal_unlock();
    return r;
}

/* delete everything an owner (comp or inst) has; lock held */
static void delete_items_of(hoff_t comp, hoff_t inst)
{
    /* functions first, out of every thread, before their memory goes */
    FOR_EACH(K_FUNCT, hal_funct_t, f) {
        if (f->comp != comp || (inst && f->inst != inst))
            continue;
        FOR_EACH(K_THREAD, hal_thread_t, t)
            if (drop_entries(t, SHMOFF(f)))
                exec_publish(t);
    }
    FOR_EACH(K_FUNCT, hal_funct_t, f)
        if (f->comp == comp && (!inst || f->inst == inst))
            obj_delete(&f->o);
    FOR_EACH(K_PIN, hal_item_t, it)
        if (it->comp == comp && (!inst || it->inst == inst))
            item_delete(it);
    FOR_EACH(K_PARAM, hal_item_t, it)
        if (it->comp == comp && (!inst || it->inst == inst))
            item_delete(it);
    hal_delete_owned(K_STREAM, comp, inst);
    hal_delete_owned(K_SHMEM, comp, inst);
}

long long hal_handle_of(const hal_obj_t *o)
{
    return ((long long)o->gen << 32) | (long long)SHMOFF(o);
}

void *hal_handle_get(long long handle, int kind, size_t size)
{
    hal_header_t *h = hal_map.hdr;
    if (!h || handle < 0)
        return NULL;
    hoff_t off = (hoff_t)(handle & 0xffffffffLL);
    uint32_t gen = (uint32_t)((unsigned long long)handle >> 32);
    if (!hal_off_ok(off, size, HAL_ALIGN))
        return NULL;
    hal_obj_t *o = SHMPTR(off);
    if (__atomic_load_n(&o->kind, __ATOMIC_ACQUIRE) != kind ||
        o->gen != gen)
        return NULL;
    return o;
}

long long hal_handle_attach(int kind, const char *name)
{
    if (!name || !*name)
        return hal_fail(EINVAL, "%s name is empty", kind_word(kind));
    int r = hal_lock();
    if (r)
        return r;
    hal_obj_t *o = hal_find(kind, name);
    long long ret = o ? hal_handle_of(o) : fail_not_found(kind, name);
    hal_unlock();
    return ret;
}

/* streams and shared blocks begin as hal_owned_t does */
_Static_assert(offsetof(hal_stream_t, comp) == offsetof(hal_owned_t, comp)
               && offsetof(hal_stream_t, inst) == offsetof(hal_owned_t, inst)
               && offsetof(hal_shmem_t, comp) == offsetof(hal_owned_t, comp)
               && offsetof(hal_shmem_t, inst) == offsetof(hal_owned_t, inst),
               "owned objects begin with hal_owned_t");

void hal_delete_owned(int kind, hoff_t comp, hoff_t inst)
{
    FOR_EACH(kind, hal_owned_t, o)
        if (o->comp == comp && (!inst || o->inst == inst))
            hal_obj_delete(&o->o);
}

int hal_owner(int owner_id, const char *what, hoff_t *comp, hoff_t *inst)
{
    hal_comp_t *c = hal_comp_by_id(owner_id);
    *comp = *inst = 0;
    if (!c) {
        hal_inst_t *i = hal_inst_by_id(owner_id);
        if (i) {
            *inst = SHMOFF(i);
            c = hal_obj_get(i->comp, K_COMP, "the owner of instance",
                            i->o.name);
        }
    }
    if (!c)
        return hal_fail(EINVAL, "%s: no component with id %d", what,
                        owner_id);
    if (c->pid != getpid())
        return hal_fail(EPERM, "%s: component '%s' belongs to process %d",
                        what, c->o.name, c->pid);
    *comp = SHMOFF(c);
    return 0;
}

int hal_inst_delete(const char *name)
{
    int r = hal_lock();
    if (r)
        return r;
    hal_inst_t *i = hal_find(K_INST, name);
    if (!i) {
        hal_unlock();
        return fail_not_found(K_INST, name);
    }
    hal_comp_t *c = hal_obj_get(i->comp, K_COMP, "the owner of instance",
                                i->o.name);
    delete_items_of(i->comp, SHMOFF(i));
    free_owned(&i->mem);
    if (c)
        c->ninst--;
    obj_delete(&i->o);
    hal_unlock();
    return 0;
}

int hal_comp_exit(int id)
{
    /* a process ending because its host is gone or stopped: no wait for
       a lock the host may hold; the host marks the component dead when
       it runs again, and halrun -U removes a dead host's segment */
    if (!hal_map.is_host && hal_host_gone())
        return 0;
    int r = hal_lock();
    if (r)
        return r;
    hal_comp_t *c = hal_comp_by_id(id);
    if (!c) {
        hal_unlock();
        return hal_fail(EINVAL, "no component with id %d", id);
    }
    hoff_t co = SHMOFF(c);
    FOR_EACH(K_THREAD, hal_thread_t, t)
        if (t->comp == co) {
            hal_unlock();
            return hal_fail(EPERM, "component '%s' belongs to thread '%s'; "
                            "delete the thread instead", c->o.name,
                            t->o.name);
        }
    delete_items_of(co, 0);
    FOR_EACH(K_INST, hal_inst_t, i)
        if (i->comp == co) {
            free_owned(&i->mem);
            obj_delete(&i->o);
        }
    free_owned(&c->mem);
    obj_delete(&c->o);
    hal_unlock();
    return 0;
}

int hal_set_lock(unsigned char lock)
{
    int r = hal_lock();
    if (r)
        return r;
    hal_map.hdr->lock = lock;
    hal_unlock();
    return 0;
}

/* ---------------------------------------------------------------- */
/* consistency                                                      */

/* add a problem to the report: "; " between problems, "..." once full */
static void note(char *rep, int len, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void note(char *rep, int len, const char *fmt, ...)
{
    int used = (int)strlen(rep);
    if (used >= len - 4)
        return;
    if (used) {
        snprintf(rep + used, len - used, "; ");
        used += 2;
    }
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(rep + used, len - used, fmt, ap);
    va_end(ap);
    if (n >= len - used)
        snprintf(rep + len - 4, 4, "...");
}

static int fsck_kind(int kind, char *rep, int len, int *bad)
{
    hal_header_t *h = hal_map.hdr;
    int n = 0;
    hoff_t prev = 0;
    for (hoff_t o = h->list_head[kind]; o;) {
        hal_obj_t *obj = hal_obj_at(o, kind);
        if (!obj || o >= h->heap_top || obj->prev != prev ||
            n >= (long)HAL_WALK_MAX) {
            note(rep, len, "%s list broken at offset %u",
                     kind_word(kind), o);
            (*bad)++;
            return n;
        }
        if (find_in_space(name_space(kind), obj->name) != obj) {
            note(rep, len, "%s '%s' is not in the name index",
                     kind_word(kind), obj->name);
            (*bad)++;
        }
        n++;
        prev = o;
        o = obj->next;
    }
    if (n != h->count[kind] || prev != h->list_tail[kind]) {
        note(rep, len, "%s count %d but %d listed", kind_word(kind),
                 h->count[kind], n);
        (*bad)++;
    }
    return n;
}

/* sorted offsets: the index of off, or -1 */
static int cmp_hoff(const void *a, const void *b)
{
    hoff_t x = *(const hoff_t *)a, y = *(const hoff_t *)b;
    return x < y ? -1 : x > y;
}

static long index_of_off(const hoff_t *offs, long n, hoff_t off)
{
    long lo = 0, hi = n - 1;
    while (lo <= hi) {
        long mid = lo + (hi - lo) / 2;
        if (offs[mid] == off)
            return mid;
        if (offs[mid] < off)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}

/* the offsets of the first n objects of a kind's list, sorted */
static hoff_t *sorted_offsets(int kind, long n)
{
    hoff_t *offs = malloc((n ? n : 1) * sizeof(hoff_t));
    if (!offs)
        return NULL;
    long k = 0;
    for (hoff_t o = hal_map.hdr->list_head[kind]; o && k < n;
         o = ((hal_obj_t *)SHMPTR(o))->next)
        offs[k++] = o;
    qsort(offs, k, sizeof(hoff_t), cmp_hoff);
    return offs;
}

/*
 * Check the invariants; returns the number of problems (0: consistent)
 * and them in rep ("; " between them, cut with "..." when long), or -errno when it cannot check (the lock
 * timed out, no memory).  One pass over each
 * list plus a sort of the signal and function offsets: O(n log n), so
 * the lock is held briefly even for a large instance (the old pairwise
 * pin x signal and function x thread loops were quadratic).
 */
int hal_check_consistency(char *rep, int len)
{
    int bad = 0;
    rep[0] = 0;
    int r = hal_lock();
    if (r)
        return r;
    int n[K_NKINDS] = {0};
    for (int k = 1; k < K_NKINDS; k++)
        n[k] = fsck_kind(k, rep, len, &bad);
    hoff_t *sigs = sorted_offsets(K_SIG, n[K_SIG]);
    hoff_t *functs = sorted_offsets(K_FUNCT, n[K_FUNCT]);
    int32_t *cnt = calloc(3 * (size_t)(n[K_SIG] ? n[K_SIG] : 1),
                          sizeof(int32_t));
    int32_t *users = calloc(n[K_FUNCT] ? n[K_FUNCT] : 1, sizeof(int32_t));
    if (!sigs || !functs || !cnt || !users) {
        hal_unlock();
        free(sigs);
        free(functs);
        free(cnt);
        free(users);
        return hal_fail(ENOMEM, "out of memory while checking HAL "
                        "instance '%s'", hal_map.hdr->instance);
    }
    /* links: count each signal's pins by direction */
    long np = 0;
    FOR_EACH(K_PIN, hal_pin_t, p) {
        if (np++ >= n[K_PIN])
            break;
        long i = p->signal ? index_of_off(sigs, n[K_SIG], p->signal) : -1;
        if (i >= 0) {
            cnt[3 * i] += p->dir == HALSDK_IN;
            cnt[3 * i + 1] += p->dir == HALSDK_OUT;
            cnt[3 * i + 2] += p->dir == HALSDK_IO;
        }
    }
    long ns = 0;
    FOR_EACH(K_SIG, hal_sig_t, s) {
        if (ns >= n[K_SIG])
            break;
        long i = index_of_off(sigs, n[K_SIG], SHMOFF(s));
        int rd = cnt[3 * i], wr = cnt[3 * i + 1], io = cnt[3 * i + 2];
        ns++;
        if (rd != s->readers || wr != s->writers || io != s->bidirs ||
            wr > 1 || (wr && io)) {
            note(rep, len, "signal '%s' link counts are wrong",
                     s->o.name);
            bad++;
        }
    }
    np = 0;
    FOR_EACH(K_PIN, hal_pin_t, p) {
        if (np++ >= n[K_PIN])
            break;
        if (!hal_obj_at(p->comp, K_COMP)) {
            note(rep, len, "pin '%s' has no owner", p->o.name);
            bad++;
        }
        if (p->signal && index_of_off(sigs, n[K_SIG], p->signal) < 0) {
            note(rep, len, "pin '%s' is linked to a deleted signal",
                     p->o.name);
            bad++;
        }
    }
    /* thread entries: count each function's users */
    long nt = 0;
    FOR_EACH(K_THREAD, hal_thread_t, t) {
        if (nt++ >= n[K_THREAD])
            break;
        long guard = 0;
        for (hoff_t e = t->functs; e && guard++ <= n[K_FUNCT] * 64L + 64;
             e = ((hal_fentry_t *)SHMPTR(e))->next) {
            if (!hal_block_at(e, sizeof(hal_fentry_t))) {
                note(rep, len, "thread '%s' function list is broken",
                         t->o.name);
                bad++;
                break;
            }
            long i = index_of_off(functs, n[K_FUNCT],
                                  ((hal_fentry_t *)SHMPTR(e))->funct);
            if (i >= 0)
                users[i]++;
            else {
                note(rep, len, "thread '%s' calls a deleted function",
                         t->o.name);
                bad++;
            }
        }
    }
    long nf = 0;
    FOR_EACH(K_FUNCT, hal_funct_t, f) {
        if (nf++ >= n[K_FUNCT])
            break;
        long i = index_of_off(functs, n[K_FUNCT], SHMOFF(f));
        if (users[i] != f->users) {
            note(rep, len, "function '%s' has %d users, %d counted",
                     f->o.name, f->users, users[i]);
            bad++;
        }
    }
    if (hal_damage_seen()) {
        snprintf(rep, len, "%s", hal_last_error());
        bad++;
    }
    hal_unlock();
    free(sigs);
    free(functs);
    free(cnt);
    free(users);
    return bad;
}

/*
 * A process died holding the lock.  Every operation publishes its object
 * last, so the lists are whole; rebuild what can drift: the name index,
 * the counts, the tail pointers and the link counts.
 */
static void recover_after_dead_holder(void)
{
    hal_header_t *h = hal_map.hdr;
    memset(SHMPTR(hal_map.buckets), 0, hal_map.nbuckets * sizeof(hoff_t));
    for (int k = 1; k < K_NKINDS; k++) {
        hoff_t prev = 0;
        int n = 0;
        for (hoff_t o = h->list_head[k]; o;) {
            hal_obj_t *obj = hal_obj_get(o, k, "the list of",
                                         kind_word(k));
            if (!obj || n >= (long)HAL_WALK_MAX) {
                /* cut the list where it is damaged */
                if (prev)
                    ((hal_obj_t *)SHMPTR(prev))->next = 0;
                else
                    h->list_head[k] = 0;
                break;
            }
            obj->prev = prev;
            index_insert(obj);
            prev = o;
            n++;
            o = obj->next;
        }
        h->list_tail[k] = prev;
        h->count[k] = n;
    }
    h->naliases = 0;
    FOR_EACH(K_PIN, hal_item_t, it)
        h->naliases += it->oldname != 0;
    FOR_EACH(K_PARAM, hal_item_t, it)
        h->naliases += it->oldname != 0;
    FOR_EACH(K_SIG, hal_sig_t, s)
        s->readers = s->writers = s->bidirs = 0;
    FOR_EACH(K_PIN, hal_pin_t, p) {
        if (!p->signal)
            continue;
        hal_sig_t *s = hal_obj_at(p->signal, K_SIG);
        if (!s) {
            p->signal = 0;
            write_cell(p, &p->dummy);
            continue;
        }
        s->readers += p->dir == HALSDK_IN;
        s->writers += p->dir == HALSDK_OUT;
        s->bidirs += p->dir == HALSDK_IO;
    }
    h->serial++;
}

/* ---------------------------------------------------------------- */
/* instance                                                         */

/*
 * The trust boundary: a process maps only a segment that the effective
 * user owns, of mode 0600, with one link, that is a regular file and not a
 * symbolic link.  The checks are made on the opened descriptor (opened
 * with O_NOFOLLOW), so nothing can be swapped between check and map; root
 * passes every permission check, so they are explicit, not left to EACCES.
 * A refusal is -EACCES with a message naming the check, the file and its
 * owner.
 */
#define HAL_SHM_DIR "/dev/shm"

static void segment_path(char *buf, size_t n, const char *shm_name)
{
    snprintf(buf, n, HAL_SHM_DIR "/%s",
             shm_name[0] == '/' ? shm_name + 1 : shm_name);
}

/* "name (uid N)" or "uid N (no user name)" */
static void owner_words(char *buf, size_t n, uid_t uid)
{
    struct passwd pw, *res = NULL;
    char tmp[1024];
    if (getpwuid_r(uid, &pw, tmp, sizeof(tmp), &res) == 0 && res)
        snprintf(buf, n, "%s (uid %u)", res->pw_name, (unsigned)uid);
    else
        snprintf(buf, n, "uid %u (no user name)", (unsigned)uid);
}

static int untrusted(const char *path, uid_t owner, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static int untrusted(const char *path, uid_t owner, const char *fmt, ...)
{
    char why[160], who[160];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof(why), fmt, ap);
    va_end(ap);
    owner_words(who, sizeof(who), owner);
    return hal_fail(EACCES, "refusing HAL segment %s (owner %s): %s; "
                    "remove it by hand if no HAL of yours uses it", path,
                    who, why);
}

/* the checks of an opened segment; 0 or -EACCES with the message */
static int check_segment(int fd, const char *path)
{
    struct stat st;
    if (fstat(fd, &st) < 0)
        return hal_fail(errno, "cannot inspect HAL segment %s: %s", path,
                        strerror(errno));
    if (!S_ISREG(st.st_mode))
        return untrusted(path, st.st_uid, "it is not a regular file");
    if (st.st_uid != geteuid()) {
        char me[160];
        owner_words(me, sizeof(me), geteuid());
        return untrusted(path, st.st_uid, "it is not owned by this user, "
                         "%s", me);
    }
    if ((st.st_mode & 07777) != 0600)
        return untrusted(path, st.st_uid, "its mode is %04o, not 0600",
                         (unsigned)(st.st_mode & 07777));
    if (st.st_nlink != 1)
        return untrusted(path, st.st_uid, "it has %lu hard links, not 1 "
                         "(another name shares it)",
                         (unsigned long)st.st_nlink);
    return 0;
}

/*
 * Open a segment without following a symbolic link and without blocking
 * (a FIFO planted there), then check it.  The fd, or -errno with the
 * message: -ENOENT when there is nothing, -EACCES when refused.
 */
static int open_segment(const char *shm_name, int flags, char *path,
                        size_t pathsize)
{
    segment_path(path, pathsize, shm_name);
    int fd = open(path, flags | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0600);
    if (fd < 0) {
        int e = errno;
        struct stat st;
        if (e != ENOENT && lstat(path, &st) == 0) {
            if (S_ISLNK(st.st_mode))
                return untrusted(path, st.st_uid,
                                 "it is a symbolic link");
            if (!S_ISREG(st.st_mode))
                return untrusted(path, st.st_uid,
                                 "it is not a regular file");
            if (e == EACCES || e == EPERM)
                return untrusted(path, st.st_uid, "this user cannot open "
                                 "it (%s)", strerror(e));
        }
        return hal_fail(e, "cannot open HAL segment %s: %s", path,
                        strerror(e));
    }
    int r = check_segment(fd, path);
    if (r) {
        close(fd);
        return r;
    }
    return fd;
}

int hal_instance_create(const char *shm_name, const char *instance,
                        long size)
{
    if (hal_map.hdr)
        return hal_fail(EBUSY, "this process already uses HAL instance "
                        "'%s'", hal_map.hdr->instance);
    if (size <= 0)
        size = HAL_DEFAULT_SIZE;
    if (size < HAL_MIN_SIZE || size > 0xF0000000L)
        return hal_fail(EINVAL, "instance size %ld is out of range "
                        "(%ld .. %ld bytes)", size, HAL_MIN_SIZE,
                        0xF0000000L);
    size = (size + 4095) & ~4095L;
    char path[256];
    segment_path(path, sizeof(path), shm_name);
    int fd = open(path, O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_NONBLOCK
                  | O_CLOEXEC, 0600);
    if (fd < 0) {
        int e = errno;
        struct stat st;
        if (e == EEXIST && lstat(path, &st) == 0 && st.st_uid != geteuid())
            return untrusted(path, st.st_uid, "another user's file holds "
                             "the name of HAL instance '%s'", instance);
        return hal_fail(e, "cannot create HAL instance '%s' (%s): %s",
                        instance, path, strerror(e));
    }
    fchmod(fd, 0600);
    int tr = check_segment(fd, path);
    if (tr) {
        close(fd);
        return tr;
    }
    if (ftruncate(fd, size) < 0) {
        int e = errno;
        close(fd);
        shm_unlink(shm_name);
        return hal_fail(e, "cannot size HAL instance '%s': %s", instance,
                        strerror(e));
    }
    char *base = mmap(NULL, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd,
                      0);
    close(fd);
    if (base == MAP_FAILED) {
        int e = errno;
        shm_unlink(shm_name);
        return hal_fail(e, "cannot map HAL instance '%s': %s", instance,
                        strerror(e));
    }
    hal_header_t *h = (hal_header_t *)base;
    h->abi = HAL_ABI_VERSION;
    h->header_size = sizeof(*h);
    h->size = size;
    snprintf(h->instance, sizeof(h->instance), "%s", instance);
    pthread_mutexattr_t ma;
    instance_mutexattr(&ma);
    pthread_mutex_init(&h->mutex, &ma);
    pthread_mutexattr_destroy(&ma);
    h->host_pid = getpid();
    h->host_start = hal_proc_start_time(h->host_pid);
    h->host_base = (uint64_t)(uintptr_t)base;
    h->next_id = 1;
    h->msg_level = 1;
    hal_layout((uint64_t)size, &h->buckets, &h->nbuckets, &h->heap_start);
    h->heap_top = h->heap_start;
    h->heap_end = (hoff_t)size;
    hal_map.base = base;
    hal_map.hdr = h;
    hal_map.size = size;
    hal_map.is_host = 1;
    hal_map_checked();
    __atomic_store_n(&h->magic, HAL_MAGIC, __ATOMIC_RELEASE);
    return 0;
}

/*
 * What is at shm_name: 0 an instance of this ABI (host filled in),
 * -ENOENT nothing, -EAGAIN one being created (short, or magic not yet
 * written), -EPROTO not a halsdk instance, -EPROTONOSUPPORT an instance of
 * another ABI (*abi set).  The magic and the ABI are the first fields of
 * every version's header, so they are read before anything else.
 */
int hal_instance_probe(const char *shm_name, int *host_pid,
                       uint64_t *host_start, int *abi)
{
    char path[256];
    *host_pid = 0;
    *host_start = 0;
    *abi = 0;
    int fd = open_segment(shm_name, O_RDONLY, path, sizeof(path));
    if (fd < 0)
        return fd;
    hal_header_t h;
    memset(&h, 0, sizeof(h));
    ssize_t n = pread(fd, &h, sizeof(h), 0);
    close(fd);
    if (n < (ssize_t)(sizeof(h.magic) + sizeof(h.abi)) || h.magic == 0)
        return -EAGAIN;
    if (h.magic != HAL_MAGIC)
        return -EPROTO;
    *abi = (int)h.abi;
    if (h.abi != HAL_ABI_VERSION)
        return -EPROTONOSUPPORT;
    if (n < (ssize_t)sizeof(h))
        return -EAGAIN;
    *host_pid = h.host_pid;
    *host_start = h.host_start;
    return 0;
}

int hal_instance_attach(const char *shm_name)
{
    if (hal_map.hdr)
        return hal_fail(EBUSY, "this process already uses HAL instance "
                        "'%s'", hal_map.hdr->instance);
    char path[256];
    int fd = open_segment(shm_name, O_RDWR, path, sizeof(path));
    if (fd == -ENOENT)
        return hal_fail(ENOENT, "no HAL instance at %s", path);
    if (fd < 0)
        return fd;
    struct stat st;
    if (fstat(fd, &st) < 0 || st.st_size < (off_t)sizeof(hal_header_t)) {
        close(fd);
        return hal_fail(EPROTO, "%s is not a halsdk instance (too small)",
                        shm_name);
    }
    char *base = mmap(NULL, st.st_size, PROT_READ | PROT_WRITE, MAP_SHARED,
                      fd, 0);
    close(fd);
    if (base == MAP_FAILED)
        return hal_fail(errno, "cannot map %s: %s", shm_name,
                        strerror(errno));
    hal_header_t *h = (hal_header_t *)base;
    /* a creator writes the magic last: wait briefly for it */
    for (int k = 0; k < 200 && __atomic_load_n(&h->magic, __ATOMIC_ACQUIRE)
                                   != HAL_MAGIC; k++)
        usleep(5000);
    int r = 0;
    if (h->magic != HAL_MAGIC)
        r = hal_fail(EPROTO, "%s is not a halsdk instance (bad magic)",
                     shm_name);
    else if (h->abi != HAL_ABI_VERSION)
        r = hal_fail(EPROTO, "HAL instance %s has ABI version %u; this "
                     "halsdk speaks version %d", shm_name, h->abi,
                     HAL_ABI_VERSION);
    else if (h->size != (uint64_t)st.st_size)
        r = hal_fail(EPROTO, "HAL instance %s: header size %llu does not "
                     "match the segment (%lld bytes)", shm_name,
                     (unsigned long long)h->size, (long long)st.st_size);
    if (r) {
        munmap(base, st.st_size);
        return r;
    }
    hal_map.base = base;
    hal_map.hdr = h;
    hal_map.size = st.st_size;
    hal_map.is_host = 0;
    if ((r = hal_map_checked())) {
        munmap(base, st.st_size);
        memset(&hal_map, 0, sizeof(hal_map));
    }
    return r;
}

void hal_instance_detach(int unlink_shm, const char *shm_name)
{
    if (!hal_map.hdr)
        return;
    hal_unwatch_host();
    if (hal_map.is_host)
        exec_destroy_all();
    munmap(hal_map.base, hal_map.size);
    memset(&hal_map, 0, sizeof(hal_map));
    cur_owner = 0;
    if (unlink_shm && shm_name)
        shm_unlink(shm_name);
}

/* ---------------------------------------------------------------- */
/* time                                                             */

long long hal_get_time(void)
{
    hal_header_t *h = hal_map.hdr;
    if (h && h->sim_clock)
        return h->sim_time;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

long long hal_get_clocks(void)
{
#if defined(__x86_64__) || defined(__i386__)
    return (long long)__builtin_ia32_rdtsc();
#else
    return hal_get_time();
#endif
}
