/*
 * hal_core.h - layout of a halsdk instance in shared memory, and the
 * operations of the core on it.
 *
 * Everything in the segment refers to everything else by offset from the
 * start of the segment (hoff_t, 0 meaning none), so any process can map it
 * at any address.  The only raw pointers stored in the segment are the
 * component-owned pin pointer cells (written in the owning process's
 * address space, from the base address that process recorded in its
 * component) and the function entry points, which only the host calls.
 */
#ifndef HAL_CORE_H
#define HAL_CORE_H

#define HALSDK_CORE
#include "halsdk_api.h"

#include <pthread.h>
#include <stdint.h>
#include <sys/types.h>

#define HAL_MAGIC 0x31304b4453474c48ULL   /* "HLGSDK01" */
#define HAL_ABI_VERSION 4
#define HAL_NAME_SIZE (HALSDK_NAME_LEN + 1)
#define HAL_DEFAULT_SIZE (160L * 1024 * 1024)
#define HAL_MIN_SIZE (1L * 1024 * 1024)
#define HAL_MAX_THREADS 64

typedef uint32_t hoff_t;

typedef union {
    volatile uint8_t b;
    volatile int32_t s;
    volatile uint32_t u;
    volatile double f;
    volatile int64_t ls;
    volatile uint64_t lu;
} hal_value_t;

enum hal_kind {
    K_NONE = 0, K_COMP, K_INST, K_PIN, K_PARAM, K_SIG, K_FUNCT, K_THREAD,
    K_STREAM, K_SHMEM,
    K_NKINDS
};

/* lock levels, as the reference numbers them */
#define HAL_LOCK_NONE 0
#define HAL_LOCK_LOAD 1
#define HAL_LOCK_CONFIG 2
#define HAL_LOCK_PARAMS 4
#define HAL_LOCK_RUN 8
#define HAL_LOCK_ALL 255

/* common head of every named object */
typedef struct {
    hoff_t next, prev;          /* list of its kind, in creation order */
    hoff_t hnext;               /* hash chain */
    uint16_t kind;
    uint16_t flags;
    uint32_t hash;
    uint32_t gen;               /* unique per record; 0 once freed */
    char name[HAL_NAME_SIZE];
} hal_obj_t;

/* hal_comp_t o.flags: the process of the userspace component has ended
   (hal_liveness.c) */
#define HAL_COMP_DEAD 0x0001

typedef struct {
    hal_obj_t o;
    int32_t id;
    int32_t kind;               /* HALSDK_COMP_USER or HALSDK_COMP_RT */
    int32_t ready;
    int32_t pid;
    uint64_t pid_start;         /* start time of pid, to detect reuse */
    uint64_t base;              /* owner's mapping address of the segment */
    hoff_t mem;                 /* blocks from hal_malloc, newest first */
    int32_t ninst;
} hal_comp_t;

typedef struct {
    hal_obj_t o;
    int32_t id;
    hoff_t comp;
    hoff_t mem;
} hal_inst_t;

/* pins and params begin alike (hal_item_t), so that code reading their
   owner, type or alias can treat them as one */
#define HAL_ITEM_HEAD                                                     \
    hal_obj_t o;                                                          \
    hoff_t comp, inst;                                                    \
    hoff_t oldname;             /* original name while aliased */         \
    int16_t type, dir

typedef struct {
    HAL_ITEM_HEAD;
} hal_item_t;

typedef struct {
    HAL_ITEM_HEAD;
    hoff_t ptr_cell;            /* where the owner's pointer to data lives */
    hoff_t signal;
    hal_value_t dummy;          /* the value while unlinked */
} hal_pin_t;

typedef struct {
    HAL_ITEM_HEAD;
    hoff_t data;
} hal_param_t;

typedef struct {
    hal_obj_t o;
    int16_t type, pad;
    int32_t readers, writers, bidirs;
    hal_value_t value;
} hal_sig_t;

typedef struct {
    hal_obj_t o;
    hoff_t comp, inst;
    int32_t uses_fp, reentrant, users;
    int32_t python;             /* 1: a Python callable, not realtime */
    uint64_t fn, arg;           /* host addresses */
    hoff_t time_pin, tmax_param, tmax_inc_param;
} hal_funct_t;

typedef struct {
    hoff_t next;
    hoff_t funct;
} hal_fentry_t;

typedef struct {
    hal_obj_t o;
    int64_t period;
    int32_t uses_fp, priority;
    int32_t running;
    int32_t slot;               /* index of the host's executor */
    uint32_t timing_every;      /* per-function timing every N cycles */
    hoff_t comp;
    hoff_t functs;              /* list of hal_fentry_t, in call order */
    int32_t nfuncts;
    hoff_t time_pin, tmax_param;
    uint64_t cycles, overruns;
} hal_thread_t;

/*
 * A stream: a single-producer single-consumer FIFO of records (hal_stream.c).
 * The ring follows the record in the same block.  A record is one 64-bit
 * sample number followed by nelem 8-byte values.  The indices only grow;
 * slot = index % depth; it holds depth - 1 records (hal_stream.c).  Only
 * the writer stores write_idx and sampleno, only the reader stores
 * read_idx.
 */
#define HAL_STREAM_MAX_ELEMS 256

typedef struct {
    hal_obj_t o;
    hoff_t comp, inst;          /* owner: deleted with it */
    int32_t nelem, depth;
    uint32_t stride;            /* bytes per record */
    uint32_t pad;
    uint8_t types[HAL_STREAM_MAX_ELEMS];
    uint64_t num_overruns;      /* writes that found the FIFO full */
    uint64_t num_underruns;     /* reads that found it empty */
    uint64_t sampleno;          /* records written */
    uint64_t write_idx __attribute__((aligned(64)));
    uint64_t read_idx __attribute__((aligned(64)));
    uint64_t pad2 __attribute__((aligned(64)));
} hal_stream_t;

/*
 * A named shared block (hal_shmem.c): size bytes at offset data (64-byte
 * aligned) that any attached process finds by name; deleted with its
 * owner.
 */
typedef struct {
    hal_obj_t o;
    hoff_t comp, inst;          /* owner: deleted with it */
    hoff_t data;
    uint32_t pad;
    uint64_t size;
} hal_shmem_t;

/* an allocated block; the user data follows the header */
typedef struct {
    uint32_t size;              /* usable bytes */
    uint32_t magic;
    hoff_t owner;               /* comp or inst owning it, 0: the core */
    hoff_t next;                /* next block of the owner, or free list */
} hal_block_t;

#define HAL_BLOCK_USED 0x55534544u
#define HAL_BLOCK_FREE 0x46524545u
#define HAL_NCLASSES 64         /* exact-size free lists up to 1 KiB */

typedef struct {
    uint64_t magic;             /* written last at creation */
    uint32_t abi;
    uint32_t header_size;
    uint64_t size;
    char instance[64];

    pthread_mutex_t mutex;      /* robust, process-shared: metadata */
    int32_t host_pid;
    int32_t pad0;
    uint64_t host_start;
    uint64_t host_base;
    uint32_t serial;            /* bumped on every metadata change */
    uint32_t next_gen;
    uint32_t lock;

    int32_t next_id;
    int32_t msg_level;

    hoff_t heap_start, heap_top, heap_end;
    hoff_t free_class[HAL_NCLASSES];
    hoff_t free_big;
    uint64_t bytes_used;

    hoff_t list_head[K_NKINDS], list_tail[K_NKINDS];
    int32_t count[K_NKINDS];

    hoff_t buckets;
    uint32_t nbuckets;

    int32_t sim_clock;          /* 1 while time is simulated by stepping */
    int64_t sim_time;
    int32_t threads_running;
    int32_t recovered;          /* times a dead lock holder was cleaned up */
    int32_t naliases;           /* pins and params that have an alias */
    int32_t lock_holder;        /* pid holding the mutex, 0: none (ABI 4) */
} hal_header_t;

/* a mapping of an instance in this process; heap_start, heap_end and
   name are copies of header fields checked when the segment was mapped
   (hal_check.c), so that no later stray write to the header moves the
   bounds the checks below use */
typedef struct {
    char *base;
    hal_header_t *hdr;
    long size;
    int is_host;
    hoff_t heap_start, heap_end;
    hoff_t buckets;
    uint32_t nbuckets;
    char name[64];
} hal_map_t;

extern hal_map_t hal_map;       /* the instance this process uses */

#define SHMPTR(off) ((void *)(hal_map.base + (off)))
#define SHMOFF(ptr) ((hoff_t)((char *)(ptr) - hal_map.base))

/*
 * The trust boundary (hal_check.c).  Every process attached to an
 * instance can write anywhere in its segment, so a buggy component can
 * leave any offset or count there.  Every offset read from the segment
 * is checked with these before it is followed: inside the heap, aligned,
 * in a used block and, for an object, of the kind expected.  A failed
 * check reports "instance NAME is damaged: what, where" (hal_damaged,
 * -EUCLEAN) instead of following the offset.  Walks of lists are bounded
 * by HAL_WALK_MAX steps, so that a cycle ends as damage too.  The
 * realtime paths (a thread's cycle, pins read through their pointers,
 * stream records) use only what was checked when they were configured.
 */
#define HAL_ALIGN 16            /* blocks and the records in them */

/* [off, off + size) lies inside the heap and off is a multiple of align
   (a power of two) */
static inline int hal_off_ok(uint64_t off, uint64_t size, uint32_t align)
{
    return off >= hal_map.heap_start && size <= hal_map.heap_end &&
           off <= hal_map.heap_end - size && (off & (align - 1)) == 0;
}

/* the used block whose data starts at off and holds at least size
   bytes, or NULL */
static inline void *hal_block_at(uint64_t off, uint64_t size)
{
    if (off < (uint64_t)hal_map.heap_start + 16 ||
        !hal_off_ok(off, size, HAL_ALIGN))
        return NULL;
    const hal_block_t *b = (const hal_block_t *)SHMPTR(off) - 1;
    if (b->magic != HAL_BLOCK_USED || b->size < size ||
        b->size > hal_map.heap_end - off)
        return NULL;
    return SHMPTR(off);
}

/* smallest record of each kind (hal_check.c) */
uint32_t hal_kind_size(int kind);

/* the record of that kind (K_NONE: of any kind) at off, its block used
   and its name terminated, or NULL */
static inline void *hal_obj_at(uint64_t off, int kind)
{
    if (kind < 0 || kind >= K_NKINDS)
        return NULL;
    const hal_obj_t *o = hal_block_at(off, hal_kind_size(kind));
    if (!o || o->name[HAL_NAME_SIZE - 1] != 0)
        return NULL;
    if (kind ? o->kind != kind : o->kind == 0 || o->kind >= K_NKINDS)
        return NULL;
    return (void *)o;
}

/* a walk of a list of the segment takes at most this many steps */
#define HAL_WALK_MAX ((hal_map.heap_end - hal_map.heap_start) / 32 + 1)

/*
 * One step of a walk along links in the segment, from the record at
 * offset at to the one at next: 1 when next closes a cycle or the walk
 * grew longer than HAL_WALK_MAX.  Cycles are found as Brent's algorithm
 * finds them: the walk keeps the record it was at after 1, 2, 4, 8 ...
 * steps, and a link back to it is a cycle, so a cycle ends the walk
 * after about twice the list's length.  *state starts at 0; it packs the
 * kept offset (high 32 bits) and the step count (low 32 bits).
 */
static inline int hal_walk_step(long *state, uint32_t at, uint32_t next)
{
    unsigned long st = (unsigned long)*state;
    unsigned long n = (st & 0xffffffffUL) + 1;
    uint32_t kept = (uint32_t)(st >> 32);
    if (next == kept || n > (unsigned long)HAL_WALK_MAX)
        return 1;
    if ((n & (n - 1)) == 0)
        kept = at;
    *state = (long)(((unsigned long)kept << 32) | n);
    return 0;
}

/* report damage: returns -EUCLEAN, the message "instance NAME is damaged:
   " and what fmt says.  Until the next hal_lock() (or hal_damage_take),
   failures keep this message: an operation that stops at damage reports
   the damage, not "not found". */
int hal_damaged(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
int hal_damage_seen(void);      /* damage reported since the last lock */
int hal_damage_take(void);      /* the same, and forget it */
/* the record of that kind at off, or NULL with the damage reported:
   "what" (e.g. "pin 'x' signal") "offset N is not a kind" */
void *hal_obj_get(hoff_t off, int kind, const char *what, const char *name);
/* the header checks (each listing, lock held): 0 or hal_damaged's */
int hal_check_header(void);
/* a segment just mapped (hal_map.base, .hdr, .size set): check its
   header (without the lock) and set the bounds above; 0 or damage */
int hal_map_checked(void);
/* where a segment of size bytes has its name index and heap */
void hal_layout(uint64_t size, hoff_t *buckets, uint32_t *nbuckets,
                hoff_t *heap_start);
const char *hal_kind_word(int kind);
/* list walks: the first record of a kind's list, and the one after o,
   or NULL at the end or with the damage reported; steps counts the
   walk's steps against HAL_WALK_MAX */
void *hal_walk_first(int kind);
void *hal_walk_next(int kind, const hal_obj_t *o, long *steps);

/* each record of a kind's list, checked (hal_walk_first/next); the body
   may delete var */
#define FOR_EACH(kind, type, var)                                         \
    for (long var##_n = 0; var##_n == 0; var##_n = -1)                    \
        for (type *var = hal_walk_first(kind), *var##_nx = NULL;          \
             var && ((var##_nx = hal_walk_next(kind, &var->o,             \
                                               &var##_n)), 1);            \
             var = var##_nx)

/*
 * The rules of HAL.  A failing operation reports -errno, a message naming
 * the objects (hal_last_error) and the rule it enforces (hal_last_rule),
 * with the kind of the first object and up to three object names
 * (hal_last_name), in the order given here.  Front ends turn the rule and
 * the names into their own words (halcmd: the reference's).  This enum is
 * the only list of HAL rules; halsdk.errors.Rule mirrors it.
 */
enum hal_rule {
    HAL_RULE_NONE = 0,          /* success, or a failure without a rule */
    HAL_RULE_NOT_FOUND,         /* object (of hal_last_kind) */
    HAL_RULE_EXISTS,            /* name (of hal_last_kind) */
    HAL_RULE_BAD_NAME,          /* name */
    HAL_RULE_LOCKED,            /* object (of hal_last_kind) */
    HAL_RULE_PIN_LINKED,        /* pin, its signal, the signal asked for */
    HAL_RULE_TYPE_MISMATCH,     /* signal, pin */
    HAL_RULE_SECOND_WRITER,     /* signal, out pin, the writer there */
    HAL_RULE_WRITER_AND_IO,     /* signal, pin, the pin it conflicts with */
    HAL_RULE_NAME_IS_PIN,       /* signal: net's signal name is a pin */
    HAL_RULE_NO_PINS,           /* signal: net without pins */
    HAL_RULE_SIG_HAS_WRITER,    /* signal: sets of a driven signal */
    HAL_RULE_WRITE_OUTPUT,      /* pin: setp of an out pin */
    HAL_RULE_PIN_CONNECTED,     /* pin, signal: setp of a linked pin */
    HAL_RULE_RO_PARAM,          /* param: setp of a read-only param */
    HAL_RULE_NOT_REENTRANT,     /* function, thread */
    HAL_RULE_NEEDS_FP,          /* function, thread */
    HAL_RULE_BAD_POSITION,      /* function, thread */
    HAL_RULE_FUNCT_UNUSED,      /* function: delf of one in no thread */
    HAL_RULE_NOT_IN_THREAD,     /* function, thread */
    HAL_RULE_HOST_ONLY,         /* object: only the host may do it */
    HAL_RULE_NOT_OWNER,         /* component: of another process */
    HAL_RULE_FULL,              /* object: the instance is full */
    HAL_RULE_BAD_ARG,           /* object: a bad type, direction, size */
    HAL_RULE_NRULES
};

/* error reporting: returns -err and keeps a message (rule NONE) */
int hal_fail(int err, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* attach a rule to the failure r that hal_fail just made; returns r */
int hal_rule(int r, int rule, int kind, const char *name0,
             const char *name1, const char *name2);
const char *hal_last_error(void);
int hal_last_rule(void);
int hal_last_kind(void);
const char *hal_last_name(int index);      /* "" when absent */

/* instance */
int hal_instance_create(const char *shm_name, const char *instance,
                        long size);
int hal_instance_attach(const char *shm_name);
void hal_instance_detach(int unlink_shm, const char *shm_name);
int hal_instance_probe(const char *shm_name, int *host_pid,
                       uint64_t *host_start, int *abi);
uint64_t hal_proc_start_time(int pid);
int hal_pid_alive(int pid, uint64_t start);
/* the state letter of process pid (man 5 proc: R, S, D, T, t, Z...),
   0 when it cannot be read */
char hal_proc_state(int pid);

/* mutex: hal_lock() waits at most hal_lock_timeout() seconds (default
   HAL_LOCK_TIMEOUT, or $HALSDK_LOCK_TIMEOUT), then fails with ETIMEDOUT
   naming the holder.  The realtime threads never take it. */
#define HAL_LOCK_TIMEOUT 5.0
int hal_lock(void);
double hal_lock_timeout(void);
int hal_set_lock_timeout(double seconds);
/* set by the Python binding: drop and retake the GIL around a wait */
extern void *(*hal_gil_release)(void);
extern void (*hal_gil_restore)(void *);
void hal_unlock(void);
int hal_hold_lock_for_test(double seconds);

/* memory */
void *hal_alloc(long size, hoff_t owner);
void hal_free(void *p);

/* lookup */
void *hal_find(int kind, const char *name);
hal_comp_t *hal_comp_by_id(int id);
hal_inst_t *hal_inst_by_id(int id);
int hal_check_name(const char *name, const char *what);

/* operations, each takes the lock itself; return 0/id or -errno */
int hal_comp_new(const char *name, int kind);
int hal_comp_exit(int id);
int hal_comp_set_ready(int id, int ready);
int hal_inst_new(const char *name, int comp_id);
int hal_inst_delete(const char *name);
void *hal_malloc_owned(long size, int owner_id);
int hal_pin_new(const char *name, int type, int dir, void **ptr_cell,
                int owner_id);
int hal_param_new(const char *name, int type, int dir,
                  volatile void *data, int owner_id);
int hal_alias(int kind, const char *name, const char *alias);
int hal_unalias(int kind, const char *alias);
int hal_signal_new(const char *name, int type);
int hal_signal_delete(const char *name);
int hal_link(const char *pin_name, const char *sig_name);
int hal_net(const char *sig_name, const char *const *pins, int npins);
int hal_unlink(const char *pin_name);
int hal_export_funct(const char *name, halsdk_funct_t fn, void *arg,
                     int uses_fp, int reentrant, int owner_id, int python);
int hal_thread_new(const char *name, long period, int uses_fp,
                   unsigned timing_every);
int hal_thread_delete(const char *name);
int hal_addf(const char *funct, const char *thread, int position);
int hal_delf(const char *funct, const char *thread);
int hal_stop_threads(void);
int hal_set_lock(unsigned char lock);
/* may setp/sets write this pin, param or signal record?  0 or -errno;
   HAL_SET_IGNORE_LOCK skips the params lock (halcmd's setp and sets do,
   as the reference's) */
#define HAL_SET_IGNORE_LOCK 1
int hal_check_settable(const hal_obj_t *o, int flags);
int hal_check_consistency(char *report, int len);

/* streams (hal_stream.c); handles pack (gen << 32) | offset */
void *hal_obj_new(int kind, long size, const char *name);
void hal_obj_publish(hal_obj_t *o);
void hal_obj_delete(hal_obj_t *o);
long long hal_stream_create(const char *name, int owner_id, int depth,
                            const char *typestring);
long long hal_stream_attach(const char *name);
hal_stream_t *hal_stream_get(long long handle);
int hal_stream_write(long long handle, const halsdk_value_t *rec);
int hal_stream_read(long long handle, halsdk_value_t *rec,
                    uint64_t *sampleno);
int hal_stream_depth(long long handle);
int hal_stream_maxdepth(long long handle);
int hal_stream_room(long long handle);
long long hal_stream_num_overruns(long long handle);
long long hal_stream_num_underruns(long long handle);
int hal_stream_nelem(long long handle);
int hal_stream_elem_type(long long handle, int index);
int hal_stream_parse_types(const char *typestring, uint8_t *types,
                           const char *what);

/*
 * Objects a component owns and other code holds by handle (streams,
 * shared blocks) begin with hal_owned_t.  A handle packs generation and
 * offset, (gen << 32) | off, so a handle of a deleted object is seen as
 * stale instead of reading whatever was allocated in its place.
 */
typedef struct {
    hal_obj_t o;
    hoff_t comp, inst;          /* owner: deleted with it */
} hal_owned_t;

long long hal_handle_of(const hal_obj_t *o);
void *hal_handle_get(long long handle, int kind, size_t size);  /* or NULL */
long long hal_handle_attach(int kind, const char *name);  /* takes the lock */
void hal_delete_owned(int kind, hoff_t comp, hoff_t inst);  /* lock held */

/* lock held: the component (and instance, if owner_id is one) that
   owner_id names, which must belong to this process; 0 or -errno with
   the error set, the message starting with what */
int hal_owner(int owner_id, const char *what, hoff_t *comp, hoff_t *inst);

/* named shared blocks (hal_shmem.c) */
long long hal_shmem_new(const char *name, int owner_id, long size);
long long hal_shmem_attach(const char *name);
void *hal_shmem_ptr(long long handle);
long hal_shmem_size(long long handle);

/* symbols between realtime modules (hal_symbol.c) */
int hal_symbol_export(const char *name, void *addr, const char *module);
void *hal_symbol_find(const char *name, const char *user);
void hal_symbol_drop(const char *module);
const char *hal_symbol_user(const char *module);

/*
 * Listings (hal_snapshot.c): every object of a kind copied in one pass
 * under the lock.  Strings are offsets into pool (0: none / empty); the
 * pins of a signal and the functions of a thread are subs[sub ..
 * sub + nsub - 1].  Per kind: id is the component or instance id (pins,
 * params, functions: the owner's id); flags: component 1 realtime, 2 dead;
 * function 1 uses_fp, 2 reentrant, 4 Python; thread 1 uses_fp, 2 running.
 */
typedef struct {
    hoff_t off;
    uint32_t gen;
    uint32_t name, owner, link, alias;  /* link: a pin's signal; alias:
                                           the original name */
    int32_t id, type, dir, flags;
    int32_t ready, pid, users, time, tmax;
    int32_t readers, writers, bidirs;
    uint32_t sub, nsub;
    int64_t period;
    uint64_t pid_start, cycles, overruns;
    uint64_t value;                     /* the value's bytes */
} hal_snap_t;

typedef struct {
    uint32_t name;
    int32_t dir;
} hal_snap_sub_t;

typedef struct {
    hal_snap_t *recs;
    long nrecs, caprecs;
    hal_snap_sub_t *subs;
    long nsubs, capsubs;
    char *pool;
    long npool, cappool;
} hal_snapshot_t;

int hal_snapshot(int kind, hal_snapshot_t *snap);   /* takes the lock */
void hal_snapshot_free(hal_snapshot_t *snap);

/* values */
/* a type (and, for a pin or param, a direction) that a record of that
   kind may have */
int hal_shape_ok(int kind, int type, int dir);
/* the original name of an aliased pin or param, or NULL with the damage
   reported */
char *hal_oldname_of(hal_item_t *it);
/* the entry at off of a thread's function list, or NULL with the damage
   reported; steps counts the walk against the thread's nfuncts */
hal_fentry_t *hal_fentry_at(hal_thread_t *t, hoff_t off, long *steps);
hal_value_t *hal_pin_value(hal_pin_t *pin);
void *hal_param_value(hal_param_t *param);

/* time */
long long hal_get_time(void);
long long hal_get_clocks(void);

/* liveness (hal_liveness.c) */
int hal_pidfd_open(int pid);                /* -1 and errno on failure */
/* an attached process: watch the host; end_process: when it ends, say so
   on stderr (as who) and SIGTERM this process */
int hal_watch_host(int end_process, const char *who);
void hal_unwatch_host(void);
int hal_host_gone(void);                    /* its pid once ended, else 0 */
/* a started program (pid child) gets SIGTERM when the host ends: a small
   guard process waits on pidfds of both, for programs that
   PR_SET_PDEATHSIG cannot cover (started by an attached process or off
   the host's main thread) */
int hal_guard_child(int child);
/* the host: a userspace component whose process ended is marked dead
   and its out pins set to zero; takes the lock */
int hal_comp_mark_dead(int id);

/* executor (hal_thread.c) */
int exec_create(hal_thread_t *t);
void exec_destroy(int slot);
void exec_destroy_all(void);
int exec_publish(hal_thread_t *t);
int exec_start(int slot, int want_rt, char *note, int notelen);
void exec_stop(int slot);
int exec_run_cycles(int slot, long n);
int exec_step_all(long n);
int exec_start_all(int want_rt, char *note, int notelen);
void *hal_malloc_current(long size);
int exec_stepping(void);
extern int hal_loading_rt;

#endif /* HAL_CORE_H */
