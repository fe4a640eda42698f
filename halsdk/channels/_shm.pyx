# cython: language_level=3, boundscheck=False, wraparound=False
"""Low-level access to the task controller's status and error channel
(:mod:`halsdk.channels.shmchannel`): atomic loads and stores, the seqlock
write and read of a region, one slot of the message ring, and a watch on
the task's process.

Addresses are plain integers (``Hal.new_shared_block`` and
``Hal.shared_block`` give the block's address in this process); the
layout belongs to :mod:`halsdk.channels.shmchannel`.  Memory ordering is
right on weakly ordered CPUs as well: acquire loads, release stores and
fences (``__atomic_*``), as the Linux seqcount does it.

Nothing here waits for the writer except :func:`seq_read` when the region
is being updated, and that wait runs without the GIL.
"""

from cpython.bytes cimport PyBytes_AS_STRING, PyBytes_FromStringAndSize
from libc.errno cimport ESRCH, errno
from libc.stdint cimport int32_t, uint32_t, uint64_t, uintptr_t
from libc.string cimport memcpy, memset
from posix.unistd cimport close

cdef extern from *:
    """
    #include <errno.h>
    #include <poll.h>
    #include <sched.h>
    #include <signal.h>
    #include <string.h>
    #include <sys/syscall.h>
    #include <time.h>
    #include <unistd.h>

    static inline uint64_t shm_load64(uintptr_t a)
    { return __atomic_load_n((uint64_t *)a, __ATOMIC_ACQUIRE); }
    static inline void shm_store64(uintptr_t a, uint64_t v)
    { __atomic_store_n((uint64_t *)a, v, __ATOMIC_RELEASE); }
    static inline uint32_t shm_load32(uintptr_t a)
    { return __atomic_load_n((uint32_t *)a, __ATOMIC_ACQUIRE); }
    static inline void shm_store32(uintptr_t a, uint32_t v)
    { __atomic_store_n((uint32_t *)a, v, __ATOMIC_RELEASE); }

    /* Raise *a to at least v (a shared high-water mark); returns the
       value it holds afterwards. */
    static inline uint64_t shm_max64(uintptr_t a, uint64_t v)
    {
        uint64_t *p = (uint64_t *)a;
        uint64_t cur = __atomic_load_n(p, __ATOMIC_ACQUIRE);
        while (cur < v) {
            if (__atomic_compare_exchange_n(p, &cur, v, 0, __ATOMIC_ACQ_REL,
                                            __ATOMIC_ACQUIRE))
                return v;
        }
        return cur;
    }

    /* Seqlock writer (one writer per sequence word): the word is odd
       while the data changes.  The release fence orders the odd store
       before the data stores, the release store of the even value orders
       the data before it. */
    static inline void shm_seq_write(uintptr_t seq, uintptr_t dst,
                                     const char *src, size_t n)
    {
        uint64_t *s = (uint64_t *)seq;
        uint64_t v = __atomic_load_n(s, __ATOMIC_RELAXED);
        v |= 1;                 /* now odd: being written */
        __atomic_store_n(s, v, __ATOMIC_RELAXED);
        __atomic_thread_fence(__ATOMIC_RELEASE);
        memcpy((void *)dst, src, n);
        __atomic_store_n(s, v + 1, __ATOMIC_RELEASE);
    }

    /* Seqlock reader: 1 when dst holds a copy no write overlapped.  The
       acquire fence orders the data loads before the second load of the
       sequence word. */
    static inline int shm_seq_read(uintptr_t seq, uintptr_t src, char *dst,
                                   size_t n)
    {
        uint64_t *s = (uint64_t *)seq;
        uint64_t s1 = __atomic_load_n(s, __ATOMIC_ACQUIRE);
        if (s1 & 1)
            return 0;
        memcpy(dst, (const void *)src, n);
        __atomic_thread_fence(__ATOMIC_ACQUIRE);
        return __atomic_load_n(s, __ATOMIC_RELAXED) == s1;
    }

    /* A slot of the message ring: u64 mark, i32 kind, u32 length, text.
       The mark is 2n+1 while message n is written, 2n+2 once it is
       complete. */
    typedef struct { uint64_t mark; int32_t kind; uint32_t len; } shm_slot;

    static inline void shm_slot_write(uintptr_t slot, uint64_t n,
                                      int32_t kind, const char *text,
                                      uint32_t len)
    {
        shm_slot *h = (shm_slot *)slot;
        __atomic_store_n(&h->mark, 2 * n + 1, __ATOMIC_RELAXED);
        __atomic_thread_fence(__ATOMIC_RELEASE);
        h->kind = kind;
        h->len = len;
        memcpy((char *)slot + sizeof(shm_slot), text, len);
        __atomic_store_n(&h->mark, 2 * n + 2, __ATOMIC_RELEASE);
    }

    /* Copy message n out of its slot: 1 done, -1 the slot holds a later
       message (n was overwritten, or is being overwritten), 0 the slot
       does not hold a complete message n yet. */
    static inline int shm_slot_read(uintptr_t slot, uint64_t n,
                                    int32_t *kind, uint32_t *len,
                                    char *text, size_t size)
    {
        shm_slot *h = (shm_slot *)slot;
        uint64_t want = 2 * n + 2;
        uint64_t m1 = __atomic_load_n(&h->mark, __ATOMIC_ACQUIRE);
        if (m1 != want)
            return m1 > want ? -1 : 0;
        *kind = h->kind;
        *len = h->len;
        memcpy(text, (const char *)slot + sizeof(shm_slot), size);
        __atomic_thread_fence(__ATOMIC_ACQUIRE);
        return __atomic_load_n(&h->mark, __ATOMIC_RELAXED) == want ? 1 : -1;
    }

    static inline int shm_pidfd_open(int pid)
    {
    #ifdef SYS_pidfd_open
        return (int)syscall(SYS_pidfd_open, pid, 0);
    #else
        errno = ENOSYS;
        return -1;
    #endif
    }

    /* A pidfd becomes readable when its process has ended (a zombie
       too). */
    static inline int shm_pidfd_ended(int fd)
    {
        struct pollfd p = { fd, POLLIN, 0 };
        return poll(&p, 1, 0) > 0 && (p.revents & (POLLIN | POLLHUP));
    }

    static inline int shm_pid_dead(int pid)
    { return kill(pid, 0) < 0 && errno == ESRCH; }

    static inline double shm_now(void)
    {
        struct timespec t;
        clock_gettime(CLOCK_MONOTONIC, &t);
        return t.tv_sec + 1e-9 * t.tv_nsec;
    }
    """
    uint64_t shm_load64(uintptr_t a) nogil
    void shm_store64(uintptr_t a, uint64_t v) nogil
    uint32_t shm_load32(uintptr_t a) nogil
    void shm_store32(uintptr_t a, uint32_t v) nogil
    uint64_t shm_max64(uintptr_t a, uint64_t v) nogil
    void shm_seq_write(uintptr_t seq, uintptr_t dst, const char *src,
                       size_t n) nogil
    int shm_seq_read(uintptr_t seq, uintptr_t src, char *dst,
                     size_t n) nogil
    void shm_slot_write(uintptr_t slot, uint64_t n, int32_t kind,
                        const char *text, uint32_t length) nogil
    int shm_slot_read(uintptr_t slot, uint64_t n, int32_t *kind,
                      uint32_t *length, char *text, size_t size) nogil
    int shm_pidfd_open(int pid) nogil
    bint shm_pidfd_ended(int fd) nogil
    bint shm_pid_dead(int pid) nogil
    double shm_now() nogil
    int sched_yield() nogil

#: bytes before the text in a ring slot (mark, kind, length)
SLOT_HEADER = 16


# ------------------------------------------------------------ words

def load64(uintptr_t addr) -> int:
    """The u64 at ``addr`` (acquire)."""
    return shm_load64(addr)


def store64(uintptr_t addr, uint64_t value) -> None:
    """Store a u64 at ``addr`` (release)."""
    shm_store64(addr, value)


def load32(uintptr_t addr) -> int:
    """The u32 at ``addr`` (acquire)."""
    return shm_load32(addr)


def store32(uintptr_t addr, uint32_t value) -> None:
    """Store a u32 at ``addr`` (release)."""
    shm_store32(addr, value)


def raise_to(uintptr_t addr, uint64_t value) -> int:
    """Raise the u64 at ``addr`` to at least ``value`` (compare and swap;
    it never goes down); returns what it holds afterwards."""
    return shm_max64(addr, value)


def fill(uintptr_t addr, const unsigned char[::1] data) -> None:
    """Copy ``data`` to ``addr`` (plain stores: for a block no reader
    trusts yet)."""
    if data.shape[0]:
        memcpy(<void *>addr, &data[0], data.shape[0])


def zero(uintptr_t addr, Py_ssize_t size) -> None:
    """Zero ``size`` bytes at ``addr`` (plain stores)."""
    if size > 0:
        memset(<void *>addr, 0, <size_t>size)


def peek(uintptr_t addr, Py_ssize_t size) -> bytes:
    """A plain copy of ``size`` bytes at ``addr`` (no ordering)."""
    return PyBytes_FromStringAndSize(<char *>addr, size)


# ------------------------------------------------------------ seqlock

def seq_write(uintptr_t seq, uintptr_t dst, const unsigned char[::1] data,
              Py_ssize_t size=-1) -> None:
    """Copy the first ``size`` bytes of ``data`` (all of it by default)
    to ``dst`` under the seqlock whose u64 sequence word is at ``seq``.
    The one writer of that region never waits."""
    cdef Py_ssize_t n = data.shape[0] if size < 0 else size
    if n > data.shape[0]:
        raise ValueError(f"seq_write: {n} bytes asked, {data.shape[0]} "
                         "given")
    if n:
        shm_seq_write(seq, dst, <const char *>&data[0], <size_t>n)


cdef class PidWatch:
    """Whether the process ``pid`` (the task's) has ended.

    A pidfd when the kernel has them: it cannot be fooled by the pid
    being reused by another process after the task ended, and it sees a
    zombie as ended.  Otherwise ``kill(pid, 0)`` failing with ESRCH.
    """

    cdef readonly int pid
    cdef int fd
    cdef bint gone

    def __cinit__(self, int pid):
        self.pid = pid
        self.fd = -1
        self.gone = pid <= 0
        if self.gone:
            return
        self.fd = shm_pidfd_open(pid)
        if self.fd < 0 and errno == ESRCH:
            self.gone = True

    def __dealloc__(self):
        if self.fd >= 0:
            close(self.fd)

    cdef bint ended(self) noexcept nogil:
        if self.gone:
            return True
        if self.fd >= 0:
            self.gone = shm_pidfd_ended(self.fd)
        else:
            self.gone = shm_pid_dead(self.pid)
        return self.gone

    def dead(self) -> bool:
        """True once the process has ended (it stays True)."""
        return self.ended()

    @property
    def uses_pidfd(self) -> bool:
        return self.fd >= 0


def seq_read(uintptr_t seq, uintptr_t src, Py_ssize_t size,
             double timeout, PidWatch watch=None):
    """A consistent copy of ``size`` bytes at ``src`` (seqlock at
    ``seq``), as bytes; or None when no copy was consistent within
    ``timeout`` s, or when ``watch``'s process ended while waiting.

    The first attempt keeps the GIL (a copy of a few kB takes well under
    a microsecond); only when the writer is in the middle of an update
    does the wait run without it: a short spin, then yielding the CPU
    (the writer may share it), checking the writer's process now and
    then.  The writer is never held up.
    """
    cdef bytes out = PyBytes_FromStringAndSize(NULL, size)
    cdef char *dst = PyBytes_AS_STRING(out)
    cdef long k = 0
    cdef double end = 0
    cdef bint ok = shm_seq_read(seq, src, dst, <size_t>size)
    if ok:
        return out
    with nogil:
        while True:
            if shm_seq_read(seq, src, dst, <size_t>size):
                ok = True
                break
            k += 1
            if k < 100:
                continue
            if end == 0:
                end = shm_now() + timeout
            elif shm_now() > end:
                break
            if watch is not None and k % 64 == 0 and watch.ended():
                break
            sched_yield()
    return out if ok else None


# ------------------------------------------------------------ message ring

def slot_write(uintptr_t slot, uint64_t n, int32_t kind,
               const unsigned char[::1] text) -> None:
    """Write message number ``n`` into its ring slot (the caller has cut
    the text to the slot's size)."""
    cdef const char *p = b""
    if text.shape[0]:
        p = <const char *>&text[0]
    shm_slot_write(slot, n, kind, p, <uint32_t>text.shape[0])


def slot_read(uintptr_t slot, uint64_t n, Py_ssize_t size):
    """Message ``n`` from its slot: ``(1, kind, text bytes)``; ``(-1, 0,
    b"")`` when the slot already holds a later message (n is lost);
    ``(0, 0, b"")`` when it holds no complete message n.  A length above
    ``size`` (garbage) reads as lost."""
    cdef bytes buf = PyBytes_FromStringAndSize(NULL, size)
    cdef int32_t kind = 0
    cdef uint32_t length = 0
    cdef int r = shm_slot_read(slot, n, &kind, &length,
                               PyBytes_AS_STRING(buf), <size_t>size)
    if r != 1:
        return r, 0, b""
    if length > <uint32_t>size:
        return -1, 0, b""
    return 1, kind, buf[:length]
