/*
 * hal_thread.c - the host's thread executor.
 *
 * Each HAL thread has an executor in the host process: a list of function
 * entry points (host addresses, resolved once when the list changes) and,
 * when started, a pthread that runs the list every period.  A cycle takes
 * no lock, allocates nothing and never touches Python (unless the user put
 * a Python function in the list).
 *
 * The list is replaced, never edited: addf/delf build a new list, swap the
 * pointer, then wait until no cycle still uses the old one (the executor's
 * epoch is odd while a cycle runs) before freeing it.
 *
 * Per-function timing needs a timestamp per function, which costs as much
 * as a trivial function; so functions are timed on every timing_every-th
 * cycle (1: every cycle), while the thread's own time is taken every cycle.
 */
#define _GNU_SOURCE
#include "hal_core.h"

#include <errno.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

typedef struct {
    halsdk_funct_t fn;
    void *arg;
    volatile int32_t **time_cell;
    volatile int32_t *tmax;
    volatile uint8_t *tmax_inc;
} xentry_t;

typedef struct {
    int n;
    xentry_t e[];
} xlist_t;

typedef struct {
    int used;
    hal_thread_t *t;
    _Atomic(xlist_t *) list;
    _Atomic uint64_t epoch;     /* odd while a cycle runs */
    pthread_t tid;
    int started;
    atomic_int stop;
    long period;
    unsigned every, countdown;
    volatile int32_t **time_cell;
    volatile int32_t *tmax;
    int64_t sim_next;
} executor_t;

static executor_t execs[HAL_MAX_THREADS];
static int started_rt;          /* scheduling asked for by the last start */
static void assign_priorities(void);
static double ns_per_tick = 1.0;
static int ticks_calibrated;
static atomic_int stepping;

/* ---------------------------------------------------------------- */

static void calibrate_ticks(void)
{
    if (ticks_calibrated)
        return;
#if defined(__x86_64__) || defined(__i386__)
    struct timespec a, b, d = {0, 20000000};
    clock_gettime(CLOCK_MONOTONIC, &a);
    uint64_t t0 = __builtin_ia32_rdtsc();
    nanosleep(&d, NULL);
    clock_gettime(CLOCK_MONOTONIC, &b);
    uint64_t t1 = __builtin_ia32_rdtsc();
    double ns = (b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec);
    if (t1 > t0)
        ns_per_tick = ns / (double)(t1 - t0);
#endif
    ticks_calibrated = 1;
}

static inline uint64_t ticks(void)
{
#if defined(__x86_64__) || defined(__i386__)
    return __builtin_ia32_rdtsc();
#else
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000ULL + ts.tv_nsec;
#endif
}

static inline int32_t tick_ns(uint64_t d)
{
    double ns = (double)d * ns_per_tick;
    return ns > 2147483647.0 ? 2147483647 : (int32_t)ns;
}

/* one cycle of a thread: the realtime path.  It never calls hal_lock()
   (nor anything that does): a process stopped while it holds the
   instance lock cannot stall a thread, and the lock's timeout (hal_lock)
   concerns metadata changes and listings only. */
static void run_cycle(executor_t *x)
{
    atomic_fetch_add_explicit(&x->epoch, 1, memory_order_seq_cst);
    xlist_t *l = atomic_load_explicit(&x->list, memory_order_seq_cst);
    long period = x->period;
    uint64_t start = ticks(), end;
    if (--x->countdown == 0) {
        x->countdown = x->every;
        uint64_t prev = start;
        for (int i = 0; i < l->n; i++) {
            xentry_t *e = &l->e[i];
            e->fn(e->arg, period);
            uint64_t now = ticks();
            int32_t ns = tick_ns(now - prev);
            **e->time_cell = ns;
            if (ns > *e->tmax) {
                *e->tmax = ns;
                *e->tmax_inc = 1;
            } else {
                *e->tmax_inc = 0;
            }
            prev = now;
        }
        end = prev;
    } else {
        for (int i = 0; i < l->n; i++)
            l->e[i].fn(l->e[i].arg, period);
        end = ticks();
    }
    int32_t ns = tick_ns(end - start);
    **x->time_cell = ns;
    if (ns > *x->tmax)
        *x->tmax = ns;
    x->t->cycles++;
    atomic_fetch_add_explicit(&x->epoch, 1, memory_order_release);
}

/* ---------------------------------------------------------------- */

static xlist_t *empty_list(void)
{
    return calloc(1, sizeof(xlist_t));
}

/* the cells a cycle writes its timing to, checked once here so that the
   cycle itself checks nothing: 0, or -EUCLEAN with the damage reported */
static int timing_cells(const char *name, hoff_t time_pin, hoff_t tmax,
                        hoff_t tmax_inc, volatile int32_t ***time_cell,
                        volatile int32_t **tmax_out,
                        volatile uint8_t **tmax_inc_out)
{
    hal_pin_t *tp = hal_obj_get(time_pin, K_PIN, "the .time pin of", name);
    hal_param_t *tm = tp ? hal_obj_get(tmax, K_PARAM, "the .tmax param of",
                                       name) : NULL;
    hal_param_t *ti = tm && tmax_inc_out
                      ? hal_obj_get(tmax_inc, K_PARAM, "the "
                                    ".tmax-increased param of", name)
                      : NULL;
    if (!tm || (tmax_inc_out && !ti))
        return -EUCLEAN;
    if (!hal_off_ok(tp->ptr_cell, sizeof(void *), 1) ||
        !hal_off_ok(tm->data, sizeof(int32_t), 1) ||
        (ti && !hal_off_ok(ti->data, 1, 1)))
        return hal_damaged("the timing pins of '%s' point outside the "
                           "heap", name);
    *time_cell = (volatile int32_t **)SHMPTR(tp->ptr_cell);
    *tmax_out = SHMPTR(tm->data);
    if (tmax_inc_out)
        *tmax_inc_out = SHMPTR(ti->data);
    return 0;
}

int exec_create(hal_thread_t *t)
{
    for (int s = 0; s < HAL_MAX_THREADS; s++) {
        executor_t *x = &execs[s];
        if (x->used)
            continue;
        xlist_t *l = empty_list();
        if (!l)
            return hal_fail(ENOMEM, "thread '%s': out of memory",
                            t->o.name);
        memset(x, 0, sizeof(*x));
        x->used = 1;
        x->t = t;
        atomic_store(&x->list, l);
        x->period = t->period;
        x->every = t->timing_every;
        x->countdown = 1;
        if (timing_cells(t->o.name, t->time_pin, t->tmax_param, 0,
                         &x->time_cell, &x->tmax, NULL)) {
            free(atomic_exchange(&x->list, NULL));
            x->used = 0;
            return -EUCLEAN;
        }
        x->sim_next = -1;
        /* threads made while HAL runs start at once */
        if (hal_map.hdr->threads_running) {
            assign_priorities();
            int r = exec_start(s, started_rt, NULL, 0);
            if (r) {
                free(atomic_exchange(&x->list, NULL));
                x->used = 0;
                return r;
            }
        }
        return s;
    }
    return hal_fail(ENOSPC, "thread '%s': no free executor", t->o.name);
}

/* wait until no cycle can still be using a list swapped out before */
static int wait_grace(executor_t *x)
{
    uint64_t e = atomic_load(&x->epoch);
    if (!(e & 1))
        return 0;
    for (int k = 0; k < 40000; k++) {           /* up to ~2 s */
        if (atomic_load(&x->epoch) != e)
            return 0;
        usleep(50);
    }
    return -1;
}

/* a thread record's executor slot is read from the segment: the
   executor, or NULL for a slot out of range (damage) */
static executor_t *exec_at(int slot)
{
    return slot >= 0 && slot < HAL_MAX_THREADS ? &execs[slot] : NULL;
}

void exec_stop(int slot)
{
    executor_t *x = exec_at(slot);
    if (!x || !x->used || !x->started)
        return;
    atomic_store(&x->stop, 1);
    pthread_join(x->tid, NULL);
    x->started = 0;
    x->t->running = 0;
}

void exec_destroy(int slot)
{
    executor_t *x = exec_at(slot);
    if (!x) {
        hal_damaged("a thread has executor slot %d", slot);
        return;
    }
    if (!x->used)
        return;
    exec_stop(slot);
    xlist_t *l = atomic_exchange(&x->list, NULL);
    if (wait_grace(x) == 0)
        free(l);
    x->used = 0;
}

/* the host is leaving its instance: no executor may outlive it */
void exec_destroy_all(void)
{
    for (int s = 0; s < HAL_MAX_THREADS; s++)
        exec_destroy(s);
}

int exec_publish(hal_thread_t *t)
{
    if (!hal_map.is_host)
        return 0;
    executor_t *x = exec_at(t->slot);
    if (!x)
        return hal_damaged("thread '%s' has executor slot %d", t->o.name,
                           t->slot);
    if (!x->used || x->t != t)
        return hal_fail(EINVAL, "thread '%s' has no executor", t->o.name);
    if (t->nfuncts < 0 || t->nfuncts > (long)HAL_WALK_MAX)
        return hal_damaged("thread '%s' has %d functions", t->o.name,
                           t->nfuncts);
    xlist_t *l = malloc(sizeof(xlist_t) + t->nfuncts * sizeof(xentry_t));
    if (!l)
        return hal_fail(ENOMEM, "thread '%s': out of memory", t->o.name);
    int n = 0;
    for (hoff_t eo = t->functs; eo;) {
        /* checked here, once, so that the cycle checks nothing */
        hal_fentry_t *fe = hal_block_at(eo, sizeof(hal_fentry_t));
        hal_funct_t *f = NULL;
        if (!fe || n >= t->nfuncts)
            hal_damaged("thread '%s': function list entry %d at offset %u "
                        "is not an entry (or the list is longer than its "
                        "count %d)", t->o.name, n, eo, t->nfuncts);
        else
            f = hal_obj_get(fe->funct, K_FUNCT, "a function of thread",
                            t->o.name);
        xentry_t *e = f ? &l->e[n] : NULL;
        if (!e || timing_cells(f->o.name, f->time_pin, f->tmax_param,
                               f->tmax_inc_param, &e->time_cell, &e->tmax,
                               &e->tmax_inc)) {
            free(l);
            return -EUCLEAN;
        }
        e->fn = (halsdk_funct_t)(uintptr_t)f->fn;
        e->arg = (void *)(uintptr_t)f->arg;
        n++;
        eo = fe->next;
    }
    l->n = n;
    xlist_t *old = atomic_exchange(&x->list, l);
    /* a stuck function keeps the old list alive: leak it, never free it
       under a running cycle */
    if (wait_grace(x) == 0)
        free(old);
    return 0;
}

/* ---------------------------------------------------------------- */
/* realtime mode                                                    */

static void ts_add(struct timespec *ts, long ns)
{
    ts->tv_nsec += ns;
    while (ts->tv_nsec >= 1000000000L) {
        ts->tv_nsec -= 1000000000L;
        ts->tv_sec++;
    }
}

static int ts_before(const struct timespec *a, const struct timespec *b)
{
    return a->tv_sec < b->tv_sec ||
           (a->tv_sec == b->tv_sec && a->tv_nsec < b->tv_nsec);
}

/* how far behind a thread may fall and still run its missed cycles */
#define CATCHUP_NS 100000000LL

static long long ts_minus(const struct timespec *a, const struct timespec *b)
{
    return (a->tv_sec - b->tv_sec) * 1000000000LL + (a->tv_nsec - b->tv_nsec);
}

/*
 * Cycle k is due at start + k * period.  A cycle that is due when the
 * previous one ends (the thread woke late, or a cycle ran long) runs at
 * once, back to back, as the reference's executor does: a step generator
 * then makes every step it was asked for.  Each cycle that starts a whole
 * period or more after it was due counts as an overrun.  Past CATCHUP_NS
 * behind (a stopped process, a debugger, a suspended machine) the missed
 * cycles are dropped rather than run in a burst: they count as overruns
 * and the schedule starts again from now.
 */
static void *thread_main(void *arg)
{
    executor_t *x = arg;
    struct timespec next, now;
    clock_gettime(CLOCK_MONOTONIC, &next);
    while (!atomic_load_explicit(&x->stop, memory_order_relaxed)) {
        ts_add(&next, x->period);
        /* sleep in slices so that stop is seen within 50 ms */
        for (;;) {
            clock_gettime(CLOCK_MONOTONIC, &now);
            if (!ts_before(&now, &next))
                break;
            struct timespec slice = now;
            ts_add(&slice, 50000000L);
            const struct timespec *until = ts_before(&next, &slice)
                                           ? &next : &slice;
            clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, until, NULL);
            if (atomic_load_explicit(&x->stop, memory_order_relaxed))
                return NULL;
        }
        long long late = ts_minus(&now, &next);
        if (late >= x->period) {
            if (late > CATCHUP_NS) {
                x->t->overruns += (uint64_t)(late / x->period) + 1;
                next = now;
            } else {
                x->t->overruns++;
            }
        }
        run_cycle(x);
    }
    return NULL;
}

int exec_start(int slot, int want_rt, char *note, int notelen)
{
    executor_t *x = exec_at(slot);
    if (!x || !x->used || x->started)
        return 0;
    calibrate_ticks();
    atomic_store(&x->stop, 0);
    x->countdown = 1;
    int r = -1;
    if (want_rt) {
        pthread_attr_t a;
        struct sched_param sp;
        pthread_attr_init(&a);
        pthread_attr_setinheritsched(&a, PTHREAD_EXPLICIT_SCHED);
        pthread_attr_setschedpolicy(&a, SCHED_FIFO);
        sp.sched_priority = x->t->priority;
        pthread_attr_setschedparam(&a, &sp);
        r = pthread_create(&x->tid, &a, thread_main, x);
        pthread_attr_destroy(&a);
        if (r && note && !note[0])
            snprintf(note, notelen, "Note: Using POSIX non-realtime "
                     "(SCHED_FIFO not permitted: %s)", strerror(r));
    }
    if (r) {
        r = pthread_create(&x->tid, NULL, thread_main, x);
        if (r)
            return hal_fail(r, "thread '%s': cannot start: %s",
                            x->t->o.name, strerror(r));
    }
    x->started = 1;
    x->t->running = 1;
    return 0;
}

/* may the threads start now? */
static int start_allowed(void)
{
    if (!hal_map.is_host)
        return hal_rule(hal_fail(EPERM, "only the host process starts "
                                 "threads"),
                        HAL_RULE_HOST_ONLY, K_THREAD, NULL, NULL, NULL);
    if (hal_map.hdr->lock & HAL_LOCK_RUN)
        return hal_rule(hal_fail(EPERM, "HAL is locked against starting "
                                 "threads"),
                        HAL_RULE_LOCKED, K_THREAD, NULL, NULL, NULL);
    if (atomic_load(&stepping))
        return hal_fail(EBUSY, "threads are being stepped");
    return 0;
}

int hal_stop_threads(void)
{
    if (!hal_map.is_host)
        return hal_rule(hal_fail(EPERM, "only the host process stops "
                                 "threads"),
                        HAL_RULE_HOST_ONLY, K_THREAD, NULL, NULL, NULL);
    if (hal_map.hdr->lock & HAL_LOCK_RUN)
        return hal_rule(hal_fail(EPERM, "HAL is locked against stopping "
                                 "threads"),
                        HAL_RULE_LOCKED, K_THREAD, NULL, NULL, NULL);
    for (int s = 0; s < HAL_MAX_THREADS; s++)
        exec_stop(s);
    hal_map.hdr->threads_running = 0;
    return 0;
}

/* faster threads get higher priority, as in the reference */
static void assign_priorities(void)
{
    for (int s = 0; s < HAL_MAX_THREADS; s++) {
        executor_t *x = &execs[s];
        if (!x->used)
            continue;
        int faster = 0;
        for (int o = 0; o < HAL_MAX_THREADS; o++)
            faster += execs[o].used && execs[o].period < x->period;
        x->t->priority = 90 - faster > 1 ? 90 - faster : 1;
    }
}

/* start every thread */
int exec_start_all(int want_rt, char *note, int notelen)
{
    int r = start_allowed();
    if (r)
        return r;
    assign_priorities();
    started_rt = want_rt;
    /* best effort: without the privilege the threads run all the same */
    if (want_rt && getenv("HALSDK_NO_MLOCK") == NULL)
        mlockall(MCL_CURRENT | MCL_FUTURE);
    for (int s = 0; s < HAL_MAX_THREADS; s++) {
        if (!execs[s].used)
            continue;
        r = exec_start(s, want_rt, note, notelen);
        if (r) {
            hal_stop_threads();
            return r;
        }
    }
    hal_map.hdr->threads_running = 1;
    hal_map.hdr->sim_clock = 0;
    return 0;
}

/* ---------------------------------------------------------------- */
/* deterministic stepping                                           */

static int begin_stepping(void)
{
    if (!hal_map.is_host)
        return hal_fail(EPERM, "only the host process steps threads");
    if (hal_map.hdr->threads_running)
        return hal_fail(EBUSY, "threads are running in realtime; stop "
                        "them before stepping");
    int expected = 0;
    if (!atomic_compare_exchange_strong(&stepping, &expected, 1))
        return hal_fail(EBUSY, "threads are already being stepped");
    calibrate_ticks();
    hal_map.hdr->sim_clock = 1;
    return 0;
}

static void end_stepping(void)
{
    atomic_store(&stepping, 0);
}

int exec_stepping(void)
{
    return atomic_load(&stepping);
}

/* run one thread n cycles; the simulated clock follows it */
int exec_run_cycles(int slot, long n)
{
    executor_t *x = exec_at(slot);
    if (!x)
        return hal_damaged("a thread has executor slot %d", slot);
    if (!x->used)
        return hal_fail(EINVAL, "no such thread executor");
    int r = begin_stepping();
    if (r)
        return r;
    hal_header_t *h = hal_map.hdr;
    for (long k = 0; k < n; k++) {
        h->sim_time += x->period;
        run_cycle(x);
    }
    x->sim_next = h->sim_time + x->period;
    end_stepping();
    return 0;
}

/*
 * Advance the simulated clock by n periods of the fastest thread, running
 * every thread whose cycle falls due, in time order; at equal times the
 * faster thread runs first (it has the higher priority).
 */
int exec_step_all(long n)
{
    int r = begin_stepping();
    if (r)
        return r;
    hal_header_t *h = hal_map.hdr;
    long base = 0;
    for (int s = 0; s < HAL_MAX_THREADS; s++) {
        executor_t *x = &execs[s];
        if (!x->used)
            continue;
        if (!base || x->period < base)
            base = x->period;
        if (x->sim_next <= h->sim_time)
            x->sim_next = h->sim_time + x->period;
    }
    if (!base) {
        end_stepping();
        return hal_fail(ENOENT, "there are no threads to step");
    }
    int64_t end = h->sim_time + (int64_t)n * base;
    for (;;) {
        executor_t *due = NULL;
        for (int s = 0; s < HAL_MAX_THREADS; s++) {
            executor_t *x = &execs[s];
            if (!x->used)
                continue;
            if (!due || x->sim_next < due->sim_next ||
                (x->sim_next == due->sim_next && x->period < due->period))
                due = x;
        }
        if (due->sim_next > end)
            break;
        h->sim_time = due->sim_next;
        run_cycle(due);
        due->sim_next += due->period;
    }
    h->sim_time = end;
    end_stepping();
    return 0;
}
