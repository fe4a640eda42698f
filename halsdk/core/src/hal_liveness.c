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
 * A stopped host (SIGSTOP, a debugger) is no better than a dead one for
 * the programs that drive hardware from its pins: the watch of a process
 * that ends with the host also looks at the host's state in /proc every
 * 25 ms and ends the process ("is stopped") when two looks in a row find
 * it stopped.
 *
 * Kernels without pidfd_open (before 5.3) fall back to looking at the
 * host's pid every 25 ms.
 *
 * A program started by an attached process, or off the host's main
 * thread, that does not attach to HAL itself gets a guard process
 * (hal_guard_child) that ends it when the host ends.
 *
 * The host, for its part, marks a userspace component whose process has
 * ended: hal_comp_mark_dead (called by the host's watcher thread in
 * halsdk.core.instance, which waits on pidfds of the components' pids).
 */

#define _GNU_SOURCE
#include "hal_core.h"
#include <dirent.h>
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <fcntl.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
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
/* while this process ends itself with the host (and for ever once the host
   ended): a memfd named MARK_PREFIX<host pid>, which a halsdk-guard of
   this process sees in /proc/<pid>/fd and so sends no second SIGTERM */
static int watch_mark = -1;
#define MARK_PREFIX "halsdk-ends-with-host-"
/* how often a watch looks whether the host is stopped */
#define STOP_LOOK_MS 25

/* the line on stderr, once, whoever sees the end first */
static void say_host_ended(const char *what)
{
    if (__atomic_exchange_n(&said, 1, __ATOMIC_ACQ_REL))
        return;
    char line[256];
    int n = snprintf(line, sizeof(line), "%s: HAL instance '%s': its host "
                     "(pid %d) is %s; ending (pid %d)\n", watch_who,
                     watch_label, watch_pid, what, (int)getpid());
    if (n > 0) {
        ssize_t w = write(2, line, n < (int)sizeof(line) ? (size_t)n
                                                          : sizeof(line) - 1);
        (void)w;
    }
}

/* the host is stopped (SIGSTOP, a debugger) for two looks in a row,
   STOP_LOOK_MS apart: a process group continued together (Ctrl-Z, fg)
   is never taken for stopped */
static int host_stopped(int *looks)
{
    char st = hal_proc_state(watch_pid);
    *looks = (st == 'T' || st == 't') ? *looks + 1 : 0;
    return *looks >= 2;
}

static void host_ended(const char *what)
{
    host_gone = watch_pid;
    if (!watch_end)
        return;
    say_host_ended(what);
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
        host_ended("gone");
        return NULL;
    }
    struct pollfd fds[2] = {{watch_wake, POLLIN, 0}, {pfd, POLLIN, 0}};
    int looks = 0;
    for (;;) {
        /* the pidfd wakes us when the host ends; a stopped host is seen
           by a look at its state every STOP_LOOK_MS when this process
           ends with the host (without a pidfd, its death too) */
        int n = poll(fds, pfd >= 0 ? 2 : 1, STOP_LOOK_MS);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            break;
        }
        if (fds[0].revents)
            break;                      /* detached: stop watching */
        if (pfd >= 0 ? fds[1].revents != 0
                     : !hal_pid_alive(watch_pid, watch_start)) {
            host_ended("gone");
            break;
        }
        if (watch_end && host_stopped(&looks)) {
            host_ended("stopped");
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
    if (watch_mark >= 0)
        close(watch_mark);
    watch_mark = -1;
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
        if (watch_mark < 0) {
            char mark[64];
            snprintf(mark, sizeof(mark), MARK_PREFIX "%d", h->host_pid);
            watch_mark = memfd_create(mark, MFD_CLOEXEC);
        }
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
            say_host_ended("gone");
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
    if (watch_mark >= 0 && !host_gone) {
        close(watch_mark);              /* no longer ends with the host */
        watch_mark = -1;
    }
    pthread_mutex_unlock(&watch_mx);
}

int hal_host_gone(void)
{
    return host_gone;
}

/* ---------------------------------------------------------------- */
/* a program started off the host's main thread ends with the host  */

/* whether process pid ends itself when the host ends: it holds the mark
   of hal_watch_host(end_process) */
static int ends_by_itself(int pid, int host)
{
    char dir[64], want[64];
    snprintf(dir, sizeof(dir), "/proc/%d/fd", pid);
    int n = snprintf(want, sizeof(want), "/memfd:" MARK_PREFIX "%d", host);
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int found = 0;
    struct dirent *e;
    while (!found && (e = readdir(d)) != NULL) {
        char path[128], link[128];
        snprintf(path, sizeof(path), "%s/%s", dir, e->d_name);
        ssize_t len = readlink(path, link, sizeof(link) - 1);
        if (len < n)
            continue;
        link[len] = '\0';
        found = strncmp(link, want, n) == 0 &&
                (link[n] == '\0' || link[n] == ' ');
    }
    closedir(d);
    return found;
}

/* the guard process: its only open files are /dev/null on 0-2 and the
   two pidfds; it waits for either process to end */
static void guard_main(int hostfd, int childfd, int child, int host,
                       uint64_t host_start)
{
    signal(SIGINT, SIG_IGN);            /* the terminal's keys reach the */
    signal(SIGQUIT, SIG_IGN);           /* program; it ends, so do we */
    signal(SIGHUP, SIG_IGN);
    prctl(PR_SET_NAME, (unsigned long)"halsdk-guard", 0, 0, 0);
    int null = open("/dev/null", O_RDWR);
    if (null >= 0) {
        dup2(null, 0);
        dup2(null, 1);
        dup2(null, 2);
    }
    /* every other file of the starting process closed: a pipe of its
       output must not stay open for as long as the guard lives */
    for (int fd = 3; fd < 65536; fd++) {
        if (fd == hostfd || fd == childfd)
            continue;
#ifdef SYS_close_range
        if (fd > hostfd && fd > childfd) {
            if (syscall(SYS_close_range, fd, ~0U, 0) == 0)
                break;
        }
#endif
        close(fd);
    }
    int host_ends = 0;
    if (hostfd >= 0 && childfd >= 0) {
        struct pollfd fds[2] = {{hostfd, POLLIN, 0}, {childfd, POLLIN, 0}};
        for (;;) {
            int n = poll(fds, 2, -1);
            if (n < 0 && errno == EINTR)
                continue;
            host_ends = n > 0 && fds[0].revents && !fds[1].revents;
            break;
        }
    } else {                            /* no pidfds: look every 20 ms */
        for (;;) {
            if (kill(child, 0) != 0 && errno == ESRCH)
                break;
            if (!hal_pid_alive(host, host_start)) {
                host_ends = 1;
                break;
            }
            usleep(20000);
        }
    }
    if (host_ends && !ends_by_itself(child, host)) {
#ifdef SYS_pidfd_send_signal
        if (childfd < 0 ||
            syscall(SYS_pidfd_send_signal, childfd, SIGTERM, NULL, 0) != 0)
#endif
            kill(child, SIGTERM);
    }
    _exit(0);
}

int hal_guard_child(int child)
{
    hal_header_t *h = hal_map.hdr;
    if (!h)
        return hal_fail(ENODEV, "no HAL instance is attached");
    int host = h->host_pid;
    uint64_t host_start = h->host_start;
    int hostfd = hal_pidfd_open(host);
    int childfd = hal_pidfd_open(child);
    if ((hostfd < 0 && errno != ENOSYS) || (childfd < 0 && errno != ENOSYS)) {
        int e = errno;
        if (hostfd >= 0)
            close(hostfd);
        if (childfd >= 0)
            close(childfd);
        if (e == ESRCH)                 /* the program ended already */
            return 0;
        return hal_fail(e, "cannot watch program pid %d: %s", child,
                        strerror(e));
    }
    if (!hal_pid_alive(host, host_start)) {
        /* the host ended (or its pid was reused) before the pidfd */
        kill(child, SIGTERM);
        if (hostfd >= 0)
            close(hostfd);
        if (childfd >= 0)
            close(childfd);
        return 0;
    }
    /* two forks: the guard is nobody's child to reap but init's */
    pid_t mid = fork();
    if (mid == 0) {
        if (fork() == 0)
            guard_main(hostfd, childfd, child, host, host_start);
        _exit(0);
    }
    int e = errno;
    if (hostfd >= 0)
        close(hostfd);
    if (childfd >= 0)
        close(childfd);
    if (mid < 0)
        return hal_fail(e, "cannot watch program pid %d: fork: %s", child,
                        strerror(e));
    while (waitpid(mid, NULL, 0) < 0 && errno == EINTR)
        ;
    return 0;
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
        /* the checked walk: the host must not crash on a damaged list */
        FOR_EACH(K_PIN, hal_pin_t, p)
            if (p->comp == co && p->dir == HALSDK_OUT)
                __atomic_store_n(&hal_pin_value(p)->lu, 0,
                                 __ATOMIC_RELEASE);
        h->serial++;
    }
    hal_unlock();
    return 0;
}
