/*
 * hal_liveness.c - processes notice the death of the processes they
 * depend on (DESIGN.md section 11).
 *
 * An attached process that owns userspace components (a loadusr program,
 * a driver) watches the host: a thread of its own waits on a pidfd of the
 * host process, which the kernel makes readable the moment the host ends,
 * however it ends.  No Python, no lock and no GIL is needed on that path,
 * so it works while the program's main loop is C code.  When the host is
 * gone the thread records it (hal_host_gone), and, when asked to, writes
 * one line naming the instance and the host's pid to stderr and sends
 * SIGTERM to its own process: what a normal host exit would have sent
 * (halrun ends its loadusr programs with SIGTERM), so a program goes to
 * its safe state and ends on the path it already has for SIGTERM.
 *
 * Kernels without pidfd_open (before 5.3) fall back to looking at the
 * host's pid every 20 ms.
 *
 * The host, for its part, marks a userspace component whose process has
 * ended: hal_comp_mark_dead (called by the host's watcher thread in
 * halsdk.core.instance, which waits on pidfds of the components' pids).
 */

#include "hal_core.h"
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/eventfd.h>
#include <sys/syscall.h>
#include <unistd.h>

int hal_pidfd_open(int pid)
{
#ifdef SYS_pidfd_open
    return (int)syscall(SYS_pidfd_open, pid, 0);
#else
    (void)pid;
    errno = ENOSYS;
    return -1;
#endif
}

/* ---------------------------------------------------------------- */
/* the attached process watches its host                            */

static pthread_mutex_t watch_mx = PTHREAD_MUTEX_INITIALIZER;
static pthread_t watch_thread;
static int watch_running;
static int watch_wake = -1;             /* eventfd: stop watching */
static volatile int watch_end;          /* SIGTERM this process on death */
static volatile int host_gone;          /* pid of the host that ended */
static int watch_pid;
static uint64_t watch_start;
static char watch_who[64];
static char watch_label[64];

static int said;                        /* the line was written */

/* the line on stderr, once, whoever sees the end first */
static void say_host_ended(void)
{
    if (__atomic_exchange_n(&said, 1, __ATOMIC_ACQ_REL))
        return;
    char line[256];
    int n = snprintf(line, sizeof(line), "%s: HAL instance '%s': its host "
                     "(pid %d) is gone; ending (pid %d)\n", watch_who,
                     watch_label, watch_pid, (int)getpid());
    if (n > 0) {
        ssize_t w = write(2, line, n < (int)sizeof(line) ? (size_t)n
                                                          : sizeof(line) - 1);
        (void)w;
    }
}

static void host_ended(void)
{
    host_gone = watch_pid;
    if (!watch_end)
        return;
    say_host_ended();
    /* to the main thread (its tid is the pid): a blocking call there is
       interrupted, so a Python handler runs at once */
    pid_t me = getpid();
    if (syscall(SYS_tgkill, me, me, SIGTERM) != 0)
        kill(me, SIGTERM);
}

static void *watch_main(void *arg)
{
    (void)arg;
    int pfd = hal_pidfd_open(watch_pid);
    if (pfd >= 0 && !hal_pid_alive(watch_pid, watch_start)) {
        /* the pid was reused (or ended) before the pidfd was opened */
        close(pfd);
        host_ended();
        return NULL;
    }
    struct pollfd fds[2] = {{watch_wake, POLLIN, 0}, {pfd, POLLIN, 0}};
    for (;;) {
        int n = poll(fds, pfd >= 0 ? 2 : 1, pfd >= 0 ? -1 : 20);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            break;
        }
        if (fds[0].revents)
            break;                      /* detached: stop watching */
        if (pfd >= 0 ? fds[1].revents != 0
                     : !hal_pid_alive(watch_pid, watch_start)) {
            host_ended();
            break;
        }
    }
    if (pfd >= 0)
        close(pfd);
    return NULL;
}

/* a forked child has no watch thread: forget the parent's */
static void watch_forget_in_child(void)
{
    pthread_mutex_t fresh = PTHREAD_MUTEX_INITIALIZER;
    watch_mx = fresh;
    if (watch_running && watch_wake >= 0)
        close(watch_wake);
    watch_wake = -1;
    watch_running = 0;
    watch_end = 0;
}

static void watch_register_atfork(void)
{
    pthread_atfork(NULL, NULL, watch_forget_in_child);
}

int hal_watch_host(int end_process, const char *who)
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, watch_register_atfork);
    hal_header_t *h = hal_map.hdr;
    if (!h)
        return hal_fail(ENODEV, "no HAL instance is attached");
    if (hal_map.is_host)
        return 0;                       /* the host watches nobody */
    pthread_mutex_lock(&watch_mx);
    if (end_process) {
        watch_end = 1;
        snprintf(watch_who, sizeof(watch_who), "%s",
                 who && *who ? who : "halsdk");
    }
    int r = 0;
    if (!watch_running) {
        watch_pid = h->host_pid;
        watch_start = h->host_start;
        snprintf(watch_label, sizeof(watch_label), "%s", h->instance);
        host_gone = 0;
        said = 0;
        watch_wake = eventfd(0, EFD_CLOEXEC);
        if (watch_wake < 0) {
            r = hal_fail(errno, "cannot watch the HAL host: %s",
                         strerror(errno));
            goto out;
        }
        /* signals go to the process's other threads, never this one */
        sigset_t all, old;
        sigfillset(&all);
        pthread_sigmask(SIG_SETMASK, &all, &old);
        int e = pthread_create(&watch_thread, NULL, watch_main, NULL);
        pthread_sigmask(SIG_SETMASK, &old, NULL);
        if (e) {
            close(watch_wake);
            watch_wake = -1;
            r = hal_fail(e, "cannot watch the HAL host: %s", strerror(e));
            goto out;
        }
        watch_running = 1;
    }
out:
    pthread_mutex_unlock(&watch_mx);
    return r;
}

void hal_unwatch_host(void)
{
    pthread_mutex_lock(&watch_mx);
    if (watch_running) {
        /* ending because the host ended, before the watch saw it (the
           SIGTERM of PR_SET_PDEATHSIG came first): say so all the same */
        if (watch_end && !host_gone &&
            !hal_pid_alive(watch_pid, watch_start)) {
            host_gone = watch_pid;
            say_host_ended();
        }
        uint64_t one = 1;
        ssize_t w = write(watch_wake, &one, sizeof(one));
        (void)w;
        if (!pthread_equal(pthread_self(), watch_thread))
            pthread_join(watch_thread, NULL);
        else
            pthread_detach(watch_thread);
        close(watch_wake);
        watch_wake = -1;
        watch_running = 0;
        watch_end = 0;
    }
    pthread_mutex_unlock(&watch_mx);
}

int hal_host_gone(void)
{
    return host_gone;
}

/* ---------------------------------------------------------------- */
/* the host marks the components of dead processes                  */

int hal_comp_mark_dead(int id)
{
    int r = hal_lock();
    if (r)
        return r;
    hal_header_t *h = hal_map.hdr;
    hal_comp_t *c = hal_comp_by_id(id);
    if (!c) {
        hal_unlock();
        return hal_fail(EINVAL, "no component with id %d", id);
    }
    if (c->kind != HALSDK_COMP_USER || c->pid == h->host_pid) {
        hal_unlock();
        return hal_fail(EINVAL, "component '%s' lives in the host",
                        c->o.name);
    }
    if (hal_pid_alive(c->pid, c->pid_start)) {
        hal_unlock();
        return hal_fail(EBUSY, "component '%s': its process (pid %d) is "
                        "alive", c->o.name, c->pid);
    }
    if (!(c->o.flags & HAL_COMP_DEAD)) {
        c->o.flags |= HAL_COMP_DEAD;
        c->ready = 0;
        /* its out pins go to zero (FALSE, 0, 0.0): through the signal
           when linked, their own value otherwise; one aligned 64-bit
           store each, which readers see whole */
        hoff_t co = SHMOFF(c);
        hoff_t o = h->list_head[K_PIN];
        while (o) {
            hal_pin_t *p = SHMPTR(o);
            if (p->comp == co && p->dir == HALSDK_OUT)
                __atomic_store_n(&hal_pin_value(p)->lu, 0,
                                 __ATOMIC_RELEASE);
            o = p->o.next;
        }
        h->serial++;
    }
    hal_unlock();
    return 0;
}
