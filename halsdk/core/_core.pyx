# cython: language_level=3, boundscheck=False, wraparound=False
"""Low-level binding of the halsdk core (C).

This module maps the instance, exposes the object records as Python
handles and publishes the C API table as a capsule for compiled
components.  The public Python API is :mod:`halsdk` (``halsdk.Hal``);
this module is its engine and is not meant to be used directly.
"""

from libc.stdint cimport int16_t, int32_t, int64_t, uint8_t, uint16_t, \
    uint32_t, uint64_t
from libc.string cimport memset
from libc.errno cimport errno

from cpython.pycapsule cimport PyCapsule_New
from cpython.ref cimport PyObject, Py_INCREF, Py_DECREF
from cpython.mem cimport PyMem_Malloc, PyMem_Free


cdef extern from "sys/prctl.h" nogil:
    int prctl(int option, unsigned long a2, unsigned long a3,
              unsigned long a4, unsigned long a5)
    enum:
        PR_SET_PDEATHSIG

import os
import re
import sys

from halsdk.core import errors as _errors

# halsdk.core.records (and traceback) are imported where they are used:
# not at the start of every halcmd

cdef extern from "hal_core.h" nogil:
    ctypedef uint32_t hoff_t
    ctypedef union hal_value_t:
        uint8_t b
        int32_t s
        uint32_t u
        double f
        int64_t ls
        uint64_t lu

    enum:
        K_NONE, K_COMP, K_INST, K_PIN, K_PARAM, K_SIG, K_FUNCT, K_THREAD,
        K_STREAM, K_NKINDS, HAL_STREAM_MAX_ELEMS
        HALSDK_BIT, HALSDK_FLOAT, HALSDK_S32, HALSDK_U32, HALSDK_S64,
        HALSDK_U64, HALSDK_IN, HALSDK_OUT, HALSDK_IO, HALSDK_RO, HALSDK_RW
        HALSDK_COMP_USER, HALSDK_COMP_RT, HALSDK_NAME_LEN
        HAL_LOCK_PARAMS, HAL_DEFAULT_SIZE, HAL_ABI_VERSION
        HAL_SET_IGNORE_LOCK

    enum hal_rule:
        HAL_RULE_NONE, HAL_RULE_NOT_FOUND, HAL_RULE_EXISTS,
        HAL_RULE_BAD_NAME, HAL_RULE_LOCKED, HAL_RULE_PIN_LINKED,
        HAL_RULE_TYPE_MISMATCH, HAL_RULE_SECOND_WRITER,
        HAL_RULE_WRITER_AND_IO, HAL_RULE_NAME_IS_PIN, HAL_RULE_NO_PINS,
        HAL_RULE_SIG_HAS_WRITER, HAL_RULE_WRITE_OUTPUT,
        HAL_RULE_PIN_CONNECTED, HAL_RULE_RO_PARAM, HAL_RULE_NOT_REENTRANT,
        HAL_RULE_NEEDS_FP, HAL_RULE_BAD_POSITION, HAL_RULE_FUNCT_UNUSED,
        HAL_RULE_NOT_IN_THREAD, HAL_RULE_HOST_ONLY, HAL_RULE_NOT_OWNER,
        HAL_RULE_FULL, HAL_RULE_BAD_ARG, HAL_RULE_NRULES

    ctypedef struct hal_obj_t:
        hoff_t next, prev
        uint16_t kind
        uint16_t flags
        uint32_t gen
        char name[128]

    ctypedef struct hal_comp_t:
        hal_obj_t o
        int32_t id
        int32_t kind
        int32_t ready
        int32_t pid
        uint64_t pid_start
        int32_t ninst

    ctypedef struct hal_inst_t:
        hal_obj_t o
        int32_t id
        hoff_t comp

    ctypedef struct hal_item_t:
        hal_obj_t o
        hoff_t comp, inst, oldname
        int16_t type, dir

    ctypedef struct hal_pin_t:
        hal_obj_t o
        hoff_t comp, inst, oldname
        int16_t type, dir
        hoff_t ptr_cell, signal
        hal_value_t dummy

    ctypedef struct hal_param_t:
        hal_obj_t o
        hoff_t comp, inst, oldname
        int16_t type, dir
        hoff_t data

    ctypedef struct hal_sig_t:
        hal_obj_t o
        int16_t type
        int32_t readers, writers, bidirs
        hal_value_t value

    ctypedef struct hal_funct_t:
        hal_obj_t o
        hoff_t comp, inst
        int32_t uses_fp, reentrant, users, python
        hoff_t time_pin, tmax_param, tmax_inc_param

    ctypedef struct hal_fentry_t:
        hoff_t next
        hoff_t funct

    ctypedef struct hal_thread_t:
        hal_obj_t o
        int64_t period
        int32_t uses_fp, priority, running, slot
        uint32_t timing_every
        hoff_t comp, functs, time_pin, tmax_param
        int32_t nfuncts
        uint64_t cycles, overruns

    ctypedef union halsdk_value_t:
        uint8_t b
        int32_t s
        uint32_t u
        double f
        int64_t ls
        uint64_t lu

    ctypedef struct hal_stream_t:
        hal_obj_t o
        hoff_t comp, inst
        int32_t nelem, depth
        uint32_t stride
        uint8_t types[256]
        uint64_t num_overruns, num_underruns, sampleno

    ctypedef struct hal_header_t:
        uint64_t magic
        uint32_t abi
        uint32_t header_size
        uint64_t size
        char instance[64]
        char mutex[1]               # pthread_mutex_t: only its place
        int32_t host_pid
        uint64_t host_start
        uint32_t serial
        uint32_t lock
        int32_t msg_level
        hoff_t heap_start, heap_top, heap_end
        hoff_t free_class[64]
        hoff_t free_big
        uint64_t bytes_used
        hoff_t list_head[10]
        hoff_t list_tail[10]
        int32_t count[10]
        hoff_t buckets
        uint32_t nbuckets
        int32_t sim_clock
        int64_t sim_time
        int32_t threads_running
        int32_t recovered
        int32_t lock_holder

    ctypedef struct hal_map_t:
        char *base
        hal_header_t *hdr
        long size
        int is_host
        char name[64]

    hal_map_t hal_map
    int hal_loading_rt
    ctypedef void (*halsdk_funct_t)(void *, long)
    ctypedef struct halsdk_api:
        int version
    const halsdk_api halsdk_api_table

    enum:
        HAL_NAME_SIZE, HAL_ALIGN
    long HAL_WALK_MAX
    void *hal_obj_at(uint64_t off, int kind)
    void *hal_block_at(uint64_t off, uint64_t size)
    int hal_damage_seen()
    int hal_damage_take()
    int hal_check_header()
    void *hal_walk_first(int kind)
    void *hal_walk_next(int kind, const hal_obj_t *o, long *steps)
    const char *hal_last_error()
    int hal_last_rule()
    int hal_last_kind()
    const char *hal_last_name(int index)
    int hal_check_settable(const hal_obj_t *o, int flags)
    int hal_net(const char *sig, const char *const *pins, int npins)
    int hal_fail(int err, const char *fmt, ...)
    int hal_instance_create(const char *shm, const char *inst, long size)
    int hal_instance_attach(const char *shm)
    void hal_instance_detach(int unlink_shm, const char *shm)
    int hal_instance_probe(const char *shm, int *pid, uint64_t *start,
                           int *abi)
    uint64_t hal_proc_start_time(int pid)
    int hal_pid_alive(int pid, uint64_t start)
    int hal_watch_host(int end_process, const char *who)
    int hal_host_gone()
    int hal_guard_child(int child)
    int hal_comp_mark_dead(int id)
    enum:
        HAL_COMP_DEAD
    int hal_lock()
    void hal_unlock()
    double hal_lock_timeout()
    int hal_set_lock_timeout(double seconds)
    ctypedef struct hal_snap_t:
        hoff_t off
        uint32_t gen
        uint32_t name, owner, link, alias
        int32_t id, type, dir, flags
        int32_t ready, pid, users, time, tmax
        int32_t readers, writers, bidirs
        uint32_t sub, nsub
        int64_t period
        uint64_t pid_start, cycles, overruns
        uint64_t value
    ctypedef struct hal_snap_sub_t:
        uint32_t name
        int32_t dir
    ctypedef struct hal_snapshot_t:
        hal_snap_t *recs
        long nrecs
        hal_snap_sub_t *subs
        long nsubs
        char *pool
        long npool
    int hal_snapshot(int kind, hal_snapshot_t *snap)
    void hal_snapshot_free(hal_snapshot_t *snap)
    int hal_hold_lock_for_test(double seconds)
    void *hal_find(int kind, const char *name)
    hal_comp_t *hal_comp_by_id(int id)
    int hal_check_name(const char *name, const char *what)
    int hal_comp_new(const char *name, int kind)
    int hal_comp_exit(int id)
    int hal_comp_set_ready(int id, int ready)
    int hal_inst_new(const char *name, int comp_id)
    int hal_inst_delete(const char *name)
    void *hal_malloc_owned(long size, int owner_id)
    int hal_pin_new(const char *name, int type, int dir, void **cell,
                    int owner_id)
    int hal_param_new(const char *name, int type, int dir, void *data,
                      int owner_id)
    int hal_alias(int kind, const char *name, const char *alias)
    int hal_unalias(int kind, const char *alias)
    int hal_signal_new(const char *name, int type)
    int hal_signal_delete(const char *name)
    int hal_link(const char *pin, const char *sig)
    int hal_unlink(const char *pin)
    int hal_export_funct(const char *name, halsdk_funct_t fn, void *arg,
                         int uses_fp, int reentrant, int owner_id,
                         int python)
    int hal_thread_new(const char *name, long period, int uses_fp,
                       unsigned every)
    int hal_thread_delete(const char *name)
    int hal_addf(const char *f, const char *t, int pos)
    int hal_delf(const char *f, const char *t)
    int hal_stop_threads()
    int exec_start_all(int want_rt, char *note, int notelen)
    int exec_run_cycles(int slot, long n)
    int exec_step_all(long n)
    int hal_set_lock(unsigned char lock)
    int hal_check_consistency(char *rep, int len)
    hal_value_t *hal_pin_value(hal_pin_t *pin)
    void *hal_param_value(hal_param_t *param)
    long long hal_stream_create(const char *name, int owner_id, int depth,
                                const char *typestring)
    long long hal_stream_attach(const char *name)
    long long hal_shmem_new(const char *name, int owner_id, long size)
    long long hal_shmem_attach(const char *name)
    void *hal_shmem_ptr(long long handle)
    long hal_shmem_size(long long handle)
    void *hal_symbol_find(const char *name, const char *user)
    const char *hal_symbol_user(const char *module)
    hal_stream_t *hal_stream_get(long long handle)
    int hal_stream_write(long long handle, const halsdk_value_t *rec)
    int hal_stream_read(long long handle, halsdk_value_t *rec,
                        uint64_t *sampleno)
    int hal_stream_depth(long long handle)
    int hal_stream_room(long long handle)
    int hal_stream_parse_types(const char *typestring, uint8_t *types,
                               const char *what)
    long long hal_get_time()
    void *(*hal_gil_release)() noexcept nogil
    void (*hal_gil_restore)(void *) noexcept nogil

cdef extern from "<string.h>" nogil:
    size_t strnlen(const char *s, size_t maxlen)


cdef extern from "Python.h":
    ctypedef struct PyThreadState
    int PyGILState_Check() noexcept nogil
    PyThreadState *PyEval_SaveThread() noexcept nogil
    void PyEval_RestoreThread(PyThreadState *) noexcept nogil


cdef void *gil_release() noexcept nogil:
    if PyGILState_Check():
        return <void *>PyEval_SaveThread()
    return NULL


cdef void gil_restore(void *state) noexcept nogil:
    PyEval_RestoreThread(<PyThreadState *>state)


hal_gil_release = gil_release
hal_gil_restore = gil_restore

cdef inline void *SHMPTR(hoff_t off) noexcept nogil:
    return <void *>(hal_map.base + off)

cdef inline hoff_t SHMOFF(void *p) noexcept nogil:
    return <hoff_t>(<char *>p - hal_map.base)

BIT = HALSDK_BIT
FLOAT = HALSDK_FLOAT
S32 = HALSDK_S32
U32 = HALSDK_U32
S64 = HALSDK_S64
U64 = HALSDK_U64
IN = HALSDK_IN
OUT = HALSDK_OUT
IO = HALSDK_IO
RO = HALSDK_RO
RW = HALSDK_RW
COMP_USER = HALSDK_COMP_USER
COMP_RT = HALSDK_COMP_RT
NAME_LEN = HALSDK_NAME_LEN
DEFAULT_SIZE = HAL_DEFAULT_SIZE
ABI_VERSION = HAL_ABI_VERSION

TYPE_NAMES = {BIT: "bit", FLOAT: "float", S32: "s32", U32: "u32",
              S64: "s64", U64: "u64"}
DIR_NAMES = {IN: "IN", OUT: "OUT", IO: "I/O", RO: "RO", RW: "RW"}

_C_API = PyCapsule_New(<void *>&halsdk_api_table,
                       b"halsdk.core._core._C_API", NULL)



# the C enum hal_rule -> halsdk.errors.Rule (a test checks they agree)
RULES = {
    HAL_RULE_NONE: "NONE", HAL_RULE_NOT_FOUND: "NOT_FOUND",
    HAL_RULE_EXISTS: "EXISTS", HAL_RULE_BAD_NAME: "BAD_NAME",
    HAL_RULE_LOCKED: "LOCKED", HAL_RULE_PIN_LINKED: "PIN_LINKED",
    HAL_RULE_TYPE_MISMATCH: "TYPE_MISMATCH",
    HAL_RULE_SECOND_WRITER: "SECOND_WRITER",
    HAL_RULE_WRITER_AND_IO: "WRITER_AND_IO",
    HAL_RULE_NAME_IS_PIN: "NAME_IS_PIN", HAL_RULE_NO_PINS: "NO_PINS",
    HAL_RULE_SIG_HAS_WRITER: "SIG_HAS_WRITER",
    HAL_RULE_WRITE_OUTPUT: "WRITE_OUTPUT",
    HAL_RULE_PIN_CONNECTED: "PIN_CONNECTED",
    HAL_RULE_RO_PARAM: "RO_PARAM", HAL_RULE_NOT_REENTRANT: "NOT_REENTRANT",
    HAL_RULE_NEEDS_FP: "NEEDS_FP", HAL_RULE_BAD_POSITION: "BAD_POSITION",
    HAL_RULE_FUNCT_UNUSED: "FUNCT_UNUSED",
    HAL_RULE_NOT_IN_THREAD: "NOT_IN_THREAD",
    HAL_RULE_HOST_ONLY: "HOST_ONLY", HAL_RULE_NOT_OWNER: "NOT_OWNER",
    HAL_RULE_FULL: "FULL", HAL_RULE_BAD_ARG: "BAD_ARG",
}
assert len(RULES) == HAL_RULE_NRULES


def error_of(int r):
    """The exception of a negative core return: its class by errno, its
    rule, kind and names from the core's last failure."""
    msg = hal_last_error().decode("utf-8", "replace")
    cdef int kind = hal_last_kind()
    names = []
    for i in range(3):
        n = hal_last_name(i).decode("utf-8", "replace")
        if n:
            names.append(n)
    return _errors.error_for_errno(
        r, msg, rule=_errors.Rule(RULES.get(hal_last_rule(), "NONE")),
        kind=KIND_WORDS.get(kind), names=tuple(names))


cdef int check(int r) except -1:
    """Raise the exception of a negative core return, or
    :class:`DamagedError` when the core found the instance damaged on the
    way (whatever it returned)."""
    if hal_damage_take():
        raise error_of(-117)        # EUCLEAN
    if r >= 0:
        return r
    raise error_of(r)


# ---------------------------------------------------------------- damage
#
# What this module reads from the segment is checked as the core checks
# it (hal_core.h: hal_obj_at, hal_block_at): an offset that is not what
# it should be raises DamagedError, never a crash.

cdef str name_of(const hal_obj_t *o):
    """A record's name, never read past its field."""
    return o.name[:strnlen(o.name, HAL_NAME_SIZE)].decode("utf-8",
                                                          "replace")


cdef object damaged(str what):
    inst = hal_map.name[:strnlen(hal_map.name, 64)].decode("ascii",
                                                           "replace")
    return _errors.DamagedError(f"instance {inst} is damaged: {what}")


cdef void *obj_at(hoff_t off, int kind, str what,
                  Item holder=None) except NULL:
    """The record of that kind at off, or DamagedError naming what.

    ``holder``: the object off was read from without the lock; if it was
    deleted meanwhile (with what off leads to), that is a StaleError."""
    cdef void *p = hal_obj_at(off, kind)
    if p == NULL:
        if holder is not None:
            holder.rec()
        raise damaged(f"{what}: offset {off} is not a "
                      f"{KIND_WORDS.get(kind, 'object')} record")
    return p


cdef object _values = None


cdef object coerce(int type, value, str what, bint wrap=False):
    """halsdk.values.coerce (imported on first use: it imports us)."""
    global _values
    if _values is None:
        from halsdk.core import values
        _values = values
    return _values.coerce(type, value, what, wrap)


cdef int lock() except -1:
    """Take the instance mutex without holding the GIL while waiting.

    A core operation may hold the mutex while it waits for a thread cycle
    to end, and a cycle may run a Python function that needs the GIL: so
    no thread may wait for the mutex with the GIL held.
    """
    cdef int r
    with nogil:
        r = hal_lock()
    return check(r)


cdef bytes enc(name):
    if not isinstance(name, str):
        raise _errors.InvalidError(
            f"HAL names are strings, not {type(name).__name__}: {name!r}")
    b = name.encode("utf-8")
    if b"\0" in b:
        raise _errors.InvalidError(f"name {name!r} contains a NUL byte")
    return b


cdef int need_instance() except -1:
    if hal_map.hdr == NULL:
        raise _errors.InstanceError("no HAL instance is attached "
                                    "in this process")
    return 0


# ---------------------------------------------------------------- values

cdef object get_raw(int type, void *p):
    if type == HALSDK_BIT:
        return (<uint8_t *>p)[0] != 0
    if type == HALSDK_FLOAT:
        return (<double *>p)[0]
    if type == HALSDK_S32:
        return (<int32_t *>p)[0]
    if type == HALSDK_U32:
        return (<uint32_t *>p)[0]
    if type == HALSDK_S64:
        return (<int64_t *>p)[0]
    return (<uint64_t *>p)[0]


_C_INTEGER = re.compile(r"\s*([+-]?)(0[xX][0-9a-fA-F]+|0[0-7]*|[1-9][0-9]*)\s*$")

_INT_RANGE = {
    HALSDK_S32: (-(1 << 31), (1 << 31) - 1),
    HALSDK_U32: (0, (1 << 32) - 1),
    HALSDK_S64: (-(1 << 63), (1 << 63) - 1),
    HALSDK_U64: (0, (1 << 64) - 1),
}


def c_integer(str text):
    """An integer written as C's strtol(..., 0) reads it: ``0x`` hex, a
    leading ``0`` octal, else decimal; no digit separators."""
    m = _C_INTEGER.match(text)
    if m is None:
        raise ValueError(text)
    sign, body = m.groups()
    if body[:2].lower() == "0x":
        v = int(body[2:], 16)
    elif len(body) > 1 and body[0] == "0":
        v = int(body[1:], 8)
    else:
        v = int(body, 10)
    return -v if sign == "-" else v


cdef int put_raw(int type, void *p, object v) except -1:
    if type == HALSDK_BIT:
        (<uint8_t *>p)[0] = 1 if v else 0
    elif type == HALSDK_FLOAT:
        (<double *>p)[0] = v
    elif type == HALSDK_S32:
        (<int32_t *>p)[0] = v
    elif type == HALSDK_U32:
        (<uint32_t *>p)[0] = v
    elif type == HALSDK_S64:
        (<int64_t *>p)[0] = v
    else:
        (<uint64_t *>p)[0] = v
    return 0


# ---------------------------------------------------------------- handles

cdef class Item:
    """A handle on a named object of the instance.

    Handles stay valid while their object exists; using one after the
    object was deleted raises :class:`halsdk.StaleError`.
    """
    cdef readonly int kind
    cdef hoff_t off
    cdef uint32_t gen
    cdef str _name

    cdef void *rec(self) except NULL:
        need_instance()
        cdef hal_obj_t *o = <hal_obj_t *>SHMPTR(self.off)
        if o.kind != self.kind or o.gen != self.gen:
            raise _errors.StaleError(
                f"{KIND_WORDS[self.kind]} '{self._name}' no longer exists")
        return o

    @property
    def name(self) -> str:
        """The object's current name (its alias, if it has one)."""
        cdef hal_obj_t *o = <hal_obj_t *>self.rec()
        return name_of(o)

    @property
    def exists(self) -> bool:
        """False once the object has been deleted."""
        if hal_map.hdr == NULL:
            return False
        cdef hal_obj_t *o = <hal_obj_t *>SHMPTR(self.off)
        return o.kind == self.kind and o.gen == self.gen

    def __eq__(self, other):
        return (isinstance(other, Item) and (<Item>other).off == self.off
                and (<Item>other).gen == self.gen)

    def __hash__(self):
        return hash((self.off, self.gen))

    def __repr__(self):
        return f"<{type(self).__name__} {self._name!r}>"


KIND_WORDS = {K_COMP: "component", K_INST: "instance", K_PIN: "pin",
              K_PARAM: "param", K_SIG: "signal", K_FUNCT: "function",
              K_THREAD: "thread", K_STREAM: "stream"}


cdef Item make(int kind, void *p):
    cdef Item it
    cls = _KIND_CLASS[kind]
    it = cls.__new__(cls)
    it.kind = kind
    it.off = SHMOFF(p)
    it.gen = (<hal_obj_t *>p).gen
    it._name = name_of(<hal_obj_t *>p)
    return it


cdef str comp_name(hoff_t off, Item owned):
    return name_of(<hal_obj_t *>obj_at(
        off, K_COMP, f"the owner of {KIND_WORDS[owned.kind]} "
        f"'{owned._name}'", owned))


_ITEM_DIRS = {K_PIN: (HALSDK_IN, HALSDK_OUT, HALSDK_IO),
              K_PARAM: (HALSDK_RO, HALSDK_RW)}


cdef int valid_type(int type, Item it) except -1:
    if type not in TYPE_NAMES:
        raise damaged(f"{KIND_WORDS[it.kind]} '{it._name}' has type "
                      f"{type}")
    return type


cdef class ValueItem(Item):
    """What pins and params share: owner, type, direction, alias, value."""

    cdef void *data(self) except NULL:
        raise NotImplementedError

    @property
    def type(self) -> int:
        """HAL type number (see :class:`halsdk.HalType`)."""
        return valid_type((<hal_item_t *>self.rec()).type, self)

    @property
    def direction(self) -> int:
        """Direction number (see :class:`halsdk.Direction`)."""
        d = (<hal_item_t *>self.rec()).dir
        if d not in _ITEM_DIRS[self.kind]:
            raise damaged(f"{KIND_WORDS[self.kind]} '{self._name}' has "
                          f"direction {d}")
        return d

    @property
    def owner(self) -> str:
        """Name of the owning component."""
        return comp_name((<hal_item_t *>self.rec()).comp, self)

    @property
    def owner_id(self) -> int:
        """Id of the owning component."""
        return (<hal_comp_t *>obj_at(
            (<hal_item_t *>self.rec()).comp, K_COMP,
            f"the owner of {KIND_WORDS[self.kind]} '{self._name}'",
            self)).id

    @property
    def alias_of(self):
        """The original name while the item has an alias, else None."""
        cdef hal_item_t *it = <hal_item_t *>self.rec()
        cdef hoff_t off = it.oldname
        if off == 0:
            return None
        cdef char *n = <char *>hal_block_at(off, HAL_NAME_SIZE)
        if n == NULL or n[HAL_NAME_SIZE - 1] != 0:
            if (<hal_item_t *>self.rec()).oldname != off:
                return self.alias_of    # unaliased meanwhile (no lock)
            raise damaged(f"{KIND_WORDS[self.kind]} '{self._name}': its "
                          f"original name at offset {off} is not a name")
        return n[:strnlen(n, HAL_NAME_SIZE)].decode("utf-8", "replace")

    @property
    def value(self):
        return get_raw((<hal_item_t *>self.rec()).type, self.data())

    @value.setter
    def value(self, v):
        self.setp(v)

    def setp(self, v, *, bint ignore_lock=False, bint wrap=False):
        """Set the value as ``halcmd setp`` does: the core refuses out
        pins, linked pins, read-only params and (unless ``ignore_lock``)
        an instance locked against setting values.  ``wrap``: read a
        word exactly as halcmd does (see :func:`halsdk.values.coerce`)."""
        cdef hal_item_t *it = <hal_item_t *>self.rec()
        check(hal_check_settable(<hal_obj_t *>it,
                                 HAL_SET_IGNORE_LOCK if ignore_lock else 0))
        v = coerce(it.type, v, f"{KIND_WORDS[self.kind]} '{self._name}'",
                   wrap)
        put_raw(it.type, self.data(), v)

    def write(self, v):
        """Write the value as the owning component does (any direction)."""
        cdef hal_item_t *it = <hal_item_t *>self.rec()
        v = coerce(it.type, v, f"{KIND_WORDS[self.kind]} '{self._name}'")
        put_raw(it.type, self.data(), v)


cdef class Pin(ValueItem):
    """A pin: a typed endpoint of a component."""

    cdef void *data(self) except NULL:
        cdef void *v = hal_pin_value(<hal_pin_t *>self.rec())
        check(0)                    # a bad signal offset: DamagedError
        return v

    @property
    def signal(self):
        """The signal this pin is linked to, or None."""
        cdef hal_pin_t *p = <hal_pin_t *>self.rec()
        cdef hoff_t so = p.signal
        cdef void *s
        if so == 0:
            return None
        s = hal_obj_at(so, K_SIG)
        if s == NULL:
            # unlinked and deleted meanwhile (no lock here), or damage
            self.rec()
            if p.signal != so:
                return self.signal
            obj_at(so, K_SIG, f"the signal of pin '{self._name}'")
        return make(K_SIG, s)

    @property
    def linked(self) -> bool:
        """True while linked to a signal."""
        return (<hal_pin_t *>self.rec()).signal != 0


cdef class Param(ValueItem):
    """A parameter of a component."""

    cdef void *data(self) except NULL:
        cdef void *v = hal_param_value(<hal_param_t *>self.rec())
        check(0)                    # a bad value offset: DamagedError
        return v


cdef class Signal(Item):
    """A signal: a typed wire between pins."""

    @property
    def type(self) -> int:
        """HAL type number (see :class:`halsdk.HalType`)."""
        return valid_type((<hal_sig_t *>self.rec()).type, self)

    @property
    def value(self):
        cdef hal_sig_t *s = <hal_sig_t *>self.rec()
        return get_raw(s.type, &s.value)

    @value.setter
    def value(self, v):
        self.sets(v)

    def sets(self, v, *, bint ignore_lock=False, bint wrap=False):
        """Set the signal as ``halcmd sets`` does: the core refuses a
        signal with a writer and (unless ``ignore_lock``: halcmd's
        ``sets``, as the reference's) an instance locked against setting
        values."""
        cdef hal_sig_t *s = <hal_sig_t *>self.rec()
        check(hal_check_settable(<hal_obj_t *>s,
                                 HAL_SET_IGNORE_LOCK if ignore_lock else 0))
        v = coerce(s.type, v, f"signal '{self._name}'", wrap)
        put_raw(s.type, &s.value, v)

    def write(self, v):
        """Write the value whatever its writers and the lock (what the
        signal's writer does)."""
        cdef hal_sig_t *s = <hal_sig_t *>self.rec()
        v = coerce(s.type, v, f"signal '{self._name}'")
        put_raw(s.type, &s.value, v)

    @property
    def writers(self) -> int:
        """Number of out pins linked (0 or 1)."""
        return (<hal_sig_t *>self.rec()).writers

    @property
    def readers(self) -> int:
        """Number of in pins linked."""
        return (<hal_sig_t *>self.rec()).readers

    @property
    def bidirs(self) -> int:
        """Number of io pins linked."""
        return (<hal_sig_t *>self.rec()).bidirs

    @property
    def pins(self) -> list:
        """The pins linked to this signal, in creation order."""
        cdef hal_sig_t *s = <hal_sig_t *>self.rec()
        cdef hoff_t so = SHMOFF(s)
        cdef hal_pin_t *p
        cdef long steps = 0
        out = []
        lock()
        try:
            p = <hal_pin_t *>hal_walk_first(K_PIN)
            while p != NULL:
                if p.signal == so:
                    out.append(make(K_PIN, p))
                p = <hal_pin_t *>hal_walk_next(K_PIN, &p.o, &steps)
            check(0)                # a damaged list: DamagedError
        finally:
            hal_unlock()
        return out


cdef class Component(Item):
    """A component: the owner of pins, params and functions."""

    @property
    def id(self) -> int:
        """Component (or instance) id."""
        return (<hal_comp_t *>self.rec()).id

    @property
    def realtime(self) -> bool:
        return (<hal_comp_t *>self.rec()).kind == HALSDK_COMP_RT

    @property
    def ready(self) -> bool:
        """True once the component called hal_ready()."""
        return (<hal_comp_t *>self.rec()).ready != 0

    @property
    def pid(self) -> int:
        """Process that owns the component."""
        return (<hal_comp_t *>self.rec()).pid

    @property
    def alive(self) -> bool:
        """False when the process that owns the component is gone."""
        cdef hal_comp_t *c = <hal_comp_t *>self.rec()
        return hal_pid_alive(c.pid, c.pid_start) != 0

    @property
    def dead(self) -> bool:
        """True once the host marked the component dead: its process
        ended without removing it (its out pins were set to zero)."""
        return ((<hal_comp_t *>self.rec()).o.flags & HAL_COMP_DEAD) != 0


cdef class Instance(Item):
    """An instance added to a component at run time (newinst)."""

    @property
    def id(self) -> int:
        """Component (or instance) id."""
        return (<hal_inst_t *>self.rec()).id

    @property
    def owner(self) -> str:
        """Name of the owning component."""
        return comp_name((<hal_inst_t *>self.rec()).comp, self)


cdef class Function(Item):
    """A function exported by a realtime component."""

    @property
    def owner(self) -> str:
        """Name of the owning component."""
        return comp_name((<hal_funct_t *>self.rec()).comp, self)

    @property
    def owner_id(self) -> int:
        """Id of the owning component."""
        return (<hal_comp_t *>obj_at(
            (<hal_funct_t *>self.rec()).comp, K_COMP,
            f"the owner of function '{self._name}'", self)).id

    @property
    def uses_fp(self) -> bool:
        """True if it uses floating point."""
        return (<hal_funct_t *>self.rec()).uses_fp != 0

    @property
    def reentrant(self) -> bool:
        """True if it may be in several threads."""
        return (<hal_funct_t *>self.rec()).reentrant != 0

    @property
    def users(self) -> int:
        """Number of thread entries that call it."""
        return (<hal_funct_t *>self.rec()).users

    @property
    def realtime(self) -> bool:
        """False for a Python function: it takes the GIL."""
        return (<hal_funct_t *>self.rec()).python == 0

    @property
    def time(self) -> int:
        """Last measured run time in ns (the ``.time`` pin)."""
        cdef hal_funct_t *f = <hal_funct_t *>self.rec()
        return timing_pin(f.time_pin, self)

    @property
    def tmax(self) -> int:
        """Largest measured run time in ns (the ``.tmax`` param)."""
        cdef hal_funct_t *f = <hal_funct_t *>self.rec()
        return timing_param(f.tmax_param, self)


cdef int32_t timing_pin(hoff_t off, Item owner) except? -1:
    """The value of a function's or thread's ``.time`` pin."""
    cdef hal_pin_t *p = <hal_pin_t *>obj_at(
        off, K_PIN, f"the .time pin of {KIND_WORDS[owner.kind]} "
        f"'{owner._name}'", owner)
    cdef hal_value_t *v = hal_pin_value(p)
    check(0)
    return v.s


cdef int32_t timing_param(hoff_t off, Item owner) except? -1:
    """The value of a function's or thread's ``.tmax`` param."""
    cdef hal_param_t *p = <hal_param_t *>obj_at(
        off, K_PARAM, f"the .tmax param of {KIND_WORDS[owner.kind]} "
        f"'{owner._name}'", owner)
    cdef int32_t *v = <int32_t *>hal_param_value(p)
    check(0)
    return v[0]


cdef class Thread(Item):
    """A realtime thread and the functions it calls."""

    @property
    def period(self) -> int:
        """Period in ns."""
        return (<hal_thread_t *>self.rec()).period

    @property
    def uses_fp(self) -> bool:
        """True if it uses floating point."""
        return (<hal_thread_t *>self.rec()).uses_fp != 0

    @property
    def running(self) -> bool:
        """True while its pthread runs (start .. stop)."""
        return (<hal_thread_t *>self.rec()).running != 0

    @property
    def timing_every(self) -> int:
        """Functions are timed every this many cycles."""
        return (<hal_thread_t *>self.rec()).timing_every

    @property
    def cycles(self) -> int:
        """Cycles run so far (realtime and stepped)."""
        return (<hal_thread_t *>self.rec()).cycles

    @property
    def overruns(self) -> int:
        """Cycles that ended after the next one was due."""
        return (<hal_thread_t *>self.rec()).overruns

    @property
    def time(self) -> int:
        """Last measured run time in ns (the ``.time`` pin)."""
        cdef hal_thread_t *t = <hal_thread_t *>self.rec()
        return timing_pin(t.time_pin, self)

    @property
    def tmax(self) -> int:
        """Largest measured run time in ns (the ``.tmax`` param)."""
        cdef hal_thread_t *t = <hal_thread_t *>self.rec()
        return timing_param(t.tmax_param, self)

    @property
    def functions(self) -> list:
        """Names of the functions in call order."""
        cdef hal_thread_t *t = <hal_thread_t *>self.rec()
        cdef hoff_t e
        cdef hal_fentry_t *fe
        out = []
        lock()
        try:
            e = t.functs
            while e:
                fe = <hal_fentry_t *>hal_block_at(e, sizeof(hal_fentry_t))
                if fe == NULL or len(out) >= t.nfuncts:
                    raise damaged(
                        f"thread '{self._name}': function list entry at "
                        f"offset {e} is not an entry (or the list is "
                        f"longer than its count {t.nfuncts})")
                out.append(name_of(<hal_obj_t *>obj_at(
                    fe.funct, K_FUNCT, f"a function of thread "
                    f"'{self._name}'")))
                e = fe.next
        finally:
            hal_unlock()
        return out


_STREAM_LETTER = {HALSDK_FLOAT: "f", HALSDK_BIT: "b", HALSDK_S32: "s",
                  HALSDK_U32: "u", HALSDK_S64: "l", HALSDK_U64: "k"}
_STREAM_DTYPE = {HALSDK_FLOAT: "<f8", HALSDK_BIT: "?", HALSDK_S32: "<i4",
                 HALSDK_U32: "<u4", HALSDK_S64: "<i8", HALSDK_U64: "<u8"}


cdef class Stream(Item):
    """A stream: a realtime-safe FIFO of records in the instance.

    One process writes (normally a realtime function), one reads.  Each
    record holds one value per letter of the type string (f float, b bit,
    s s32, u u32, l s64, k u64) and the number of the sample (records
    written before it).  A stream of ``maxdepth`` D holds D - 1 records,
    as the reference's do.  ``write``/``read`` never block.
    """

    cdef long long handle(self) except -1:
        self.rec()
        return (<long long>self.gen << 32) | <long long>self.off

    @property
    def owner(self) -> str:
        """Name of the owning component."""
        return comp_name((<hal_stream_t *>self.rec()).comp, self)

    cdef hal_stream_t *checked(self) except NULL:
        """The record, its value count and types checked."""
        cdef hal_stream_t *st = <hal_stream_t *>self.rec()
        cdef int n = st.nelem
        if not 1 <= n <= HAL_STREAM_MAX_ELEMS:
            raise damaged(f"stream '{self._name}' has {n} values")
        for i in range(n):
            if st.types[i] not in _STREAM_LETTER:
                raise damaged(f"stream '{self._name}': value {i} has type "
                              f"{st.types[i]}")
        return st

    @property
    def nelem(self) -> int:
        """Values per record."""
        return self.checked().nelem

    @property
    def typestring(self) -> str:
        """One letter per value: f b s u l k."""
        cdef hal_stream_t *st = self.checked()
        return "".join(_STREAM_LETTER[st.types[i]] for i in range(st.nelem))

    @property
    def types(self) -> list:
        """Type numbers of the values (BIT, FLOAT, ...)."""
        cdef hal_stream_t *st = self.checked()
        return [st.types[i] for i in range(st.nelem)]

    @property
    def maxdepth(self) -> int:
        """The depth it was made with (it holds one record less)."""
        return (<hal_stream_t *>self.rec()).depth

    @property
    def room(self) -> int:
        """Records that can be written before it is full."""
        return check(hal_stream_room(self.handle()))

    @property
    def depth(self) -> int:
        """Records written and not read yet."""
        return check(hal_stream_depth(self.handle()))

    @property
    def overruns(self) -> int:
        """Writes that found the FIFO full (the record was dropped)."""
        return (<hal_stream_t *>self.rec()).num_overruns

    @property
    def underruns(self) -> int:
        """Reads that found the FIFO empty."""
        return (<hal_stream_t *>self.rec()).num_underruns

    @property
    def sampleno(self) -> int:
        """Records written so far (the number of the next one)."""
        return (<hal_stream_t *>self.rec()).sampleno

    def write(self, values) -> bool:
        """Append one record; False (and one more overrun) when full."""
        cdef hal_stream_t *st = self.checked()
        cdef int n = st.nelem
        cdef halsdk_value_t rec[256]
        vals = list(values)
        if len(vals) != n:
            raise _errors.InvalidError(
                f"stream '{self._name}' takes {n} values per record, "
                f"not {len(vals)}")
        memset(rec, 0, sizeof(rec))
        for i in range(n):
            t = st.types[i]
            v = coerce(t, vals[i], f"value {i} of stream '{self._name}'")
            put_raw(t, &rec[i], v)
        cdef int r = hal_stream_write(self.handle(), rec)
        if r == -28:        # ENOSPC
            return False
        check(r)
        return True

    def read(self):
        """(sample number, tuple of values) of the oldest record, or None
        (and one more underrun) when the FIFO is empty."""
        cdef hal_stream_t *st = self.checked()
        cdef halsdk_value_t rec[256]
        cdef uint64_t sn = 0
        cdef int r = hal_stream_read(self.handle(), rec, &sn)
        if r == -11:        # EAGAIN
            return None
        check(r)
        return sn, tuple(get_raw(st.types[i], &rec[i])
                         for i in range(st.nelem))

    def dtype(self, names=None):
        """NumPy dtype of a record: field ``sample`` then one per value
        (named by ``names``, default ``v0``, ``v1``, ...)."""
        import numpy as np
        cdef hal_stream_t *st = self.checked()
        n = st.nelem
        if names is None:
            names = [f"v{i}" for i in range(n)]
        names = list(names)
        if len(names) != n:
            raise _errors.InvalidError(
                f"stream '{self._name}' has {n} values, got {len(names)} "
                "names")
        return np.dtype({
            "names": ["sample"] + names,
            "formats": ["<u8"] + [_STREAM_DTYPE[st.types[i]]
                                  for i in range(n)],
            "offsets": [8 * i for i in range(n + 1)],
            "itemsize": 8 * (n + 1)})

    def read_many(self, long max=-1, names=None):
        """Read up to ``max`` records (all available when negative) into a
        NumPy structured array (see :meth:`dtype`), without counting an
        underrun.  ``arr["v0"]`` is the first column."""
        import numpy as np
        dt = self.dtype(names)
        cdef long long h = self.handle()
        cdef long avail = check(hal_stream_depth(h))
        cdef long n = avail if max < 0 or max > avail else max
        cdef long stride = dt.itemsize
        raw = np.empty(n * stride, dtype=np.uint8)
        cdef unsigned char[::1] mv = raw
        cdef long k = 0
        cdef int r = 0
        if n > 0:
            with nogil:
                while k < n:
                    r = hal_stream_read(
                        h, <halsdk_value_t *>&mv[k * stride + 8],
                        <uint64_t *>&mv[k * stride])
                    if r < 0:
                        break
                    k += 1
        if r < 0 and r != -11:
            check(r)
        return raw[:k * stride].view(dt)


_KIND_CLASS = {K_COMP: Component, K_INST: Instance, K_PIN: Pin,
               K_PARAM: Param, K_SIG: Signal, K_FUNCT: Function,
               K_THREAD: Thread, K_STREAM: Stream}


# ---------------------------------------------------------------- instance

def create(str shm_name, str instance, long size=0):
    """Create the instance and become its host."""
    cdef bytes a = enc(shm_name), b = enc(instance)
    cdef const char *ca = a
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_instance_create(ca, cb, size)
    check(r)


def attach(str shm_name):
    """Map an existing instance."""
    check(hal_instance_attach(enc(shm_name)))


def detach(bint unlink=False, shm_name=None):
    """Unmap the instance; the host also removes it."""
    cdef bytes b
    _python_functs.clear()
    if shm_name:
        b = enc(shm_name)
        hal_instance_detach(unlink, b)
    else:
        hal_instance_detach(0, NULL)


def probe(str shm_name):
    """What is at a shared-memory name, as ``(state, host_pid, host_start,
    abi)``; state is ``"absent"``, ``"creating"`` (being created),
    ``"junk"`` (not a halsdk instance), ``"abi"`` (an instance of another
    ABI version) or ``"ok"``.  A segment that fails the trust checks (not
    owned by the effective user, not mode 0600, more than one link, a
    symbolic link or not a regular file) raises TrustError."""
    cdef int pid = 0, abi = 0
    cdef uint64_t start = 0
    r = hal_instance_probe(enc(shm_name), &pid, &start, &abi)
    if r == -13:
        raise error_of(r)
    state = {0: "ok", -2: "absent", -11: "creating", -71: "junk",
             -93: "abi"}.get(r, "junk")
    return state, pid, start, abi


def pid_alive(int pid, uint64_t start=0) -> bool:
    return hal_pid_alive(pid, start) != 0


def watch_host(bint end_process=False, str who="halsdk"):
    """Watch the host of the attached instance from a thread of the core
    (a pidfd, no GIL needed); with ``end_process``, when the host ends,
    write a line naming it to stderr and SIGTERM this process."""
    need_instance()
    check(hal_watch_host(end_process, enc(who)))


def host_gone() -> int:
    """The pid of the host once its end was seen by :func:`watch_host`,
    else 0."""
    return hal_host_gone()


def guard_child(int pid):
    """A program this process started (``pid``) gets SIGTERM when the
    host ends, however it ends: a small guard process (named
    ``halsdk-guard``) waits on pidfds of the host and the program and ends
    with whichever ends first."""
    need_instance()
    check(hal_guard_child(pid))


def comp_mark_dead(int comp_id):
    """Host: mark the userspace component of an ended process dead and
    set its out pins to zero."""
    need_instance()
    cdef int r
    with nogil:
        r = hal_comp_mark_dead(comp_id)
    check(r)


def set_parent_death_signal(int signum):
    """prctl(PR_SET_PDEATHSIG): this process gets ``signum`` when the
    thread that started it ends (for a child between fork and exec)."""
    if prctl(PR_SET_PDEATHSIG, <unsigned long>signum, 0, 0, 0) != 0:
        raise OSError(errno, "prctl(PR_SET_PDEATHSIG) failed")


def proc_start_time(int pid) -> int:
    return hal_proc_start_time(pid)


def attached() -> bool:
    return hal_map.hdr != NULL


def is_host() -> bool:
    return hal_map.hdr != NULL and hal_map.is_host != 0


def info() -> dict:
    """Facts about the attached instance."""
    need_instance()
    cdef hal_header_t *h = hal_map.hdr
    return {
        "instance": hal_map.name[:strnlen(hal_map.name, 64)].decode(
            "ascii", "replace"),
        "size": h.size,
        "abi": h.abi,
        "host_pid": h.host_pid,
        "host_start": h.host_start,
        "serial": h.serial,
        "lock": h.lock,
        "bytes_used": h.bytes_used,
        "heap_top": h.heap_top,
        "heap_end": h.heap_end,
        "counts": {KIND_WORDS[k]: h.count[k] for k in KIND_WORDS},
        "sim_time": h.sim_time,
        "simulated_clock": h.sim_clock != 0,
        "threads_running": h.threads_running != 0,
        "recovered": h.recovered,
        "msg_level": h.msg_level,
        "lock_holder": h.lock_holder,
    }


def segment_layout() -> dict:
    """Where the header fields and the record heads lie in a segment of
    this ABI (byte offsets and sizes), for tools and tests that look at
    or damage a segment on purpose (tests/core/test_segment_fuzz.py)."""
    cdef hal_header_t h
    cdef hal_obj_t o
    cdef char *b = <char *>&h
    cdef char *ob = <char *>&o

    return {
        "header_size": sizeof(hal_header_t),
        "mutex": (<char *>&h.mutex - b, sizeof(h.mutex)),
        "instance": (<char *>&h.instance - b, 64),
        "heap_start": <char *>&h.heap_start - b,
        "heap_top": <char *>&h.heap_top - b,
        "heap_end": <char *>&h.heap_end - b,
        "free_class": <char *>&h.free_class - b,
        "free_big": <char *>&h.free_big - b,
        "list_head": <char *>&h.list_head - b,
        "list_tail": <char *>&h.list_tail - b,
        "count": <char *>&h.count - b,
        "buckets": <char *>&h.buckets - b,
        "nbuckets": <char *>&h.nbuckets - b,
        "nkinds": K_NKINDS,
        "block_header": 16,
        "obj_name": <char *>&o.name - ob,
        "name_size": HAL_NAME_SIZE,
    }


def set_msg_level(int level):
    need_instance()
    if not 0 <= level <= 5:
        raise _errors.InvalidError(f"message level {level} is not 0..5")
    hal_map.hdr.msg_level = level


def serial() -> int:
    need_instance()
    return hal_map.hdr.serial


def get_time() -> int:
    """rtapi_get_time(): ns; simulated time while stepping."""
    return hal_get_time()


def hold_lock_for_test(double seconds):
    """Hold the instance mutex (tests kill a holder to check recovery)."""
    need_instance()
    cdef int r
    with nogil:
        r = hal_hold_lock_for_test(seconds)
    check(r)


def check_consistency():
    """(number of problems, the problems) of the instance invariants."""
    need_instance()
    cdef char rep[512]
    cdef int n
    with nogil:
        n = hal_check_consistency(rep, sizeof(rep))
    check(n)
    return n, rep.decode("utf-8", "replace")


# ---------------------------------------------------------------- lookup

_KIND_BY_WORD = {v: k for k, v in KIND_WORDS.items()}


def find(str kind, name):
    """The handle of a named object, or None."""
    need_instance()
    cdef int k = _KIND_BY_WORD[kind]
    cdef bytes b = enc(name)
    cdef void *p
    lock()
    try:
        p = hal_find(k, b)
        check(0)                    # a damaged index: DamagedError
        return make(k, p) if p != NULL else None
    finally:
        hal_unlock()


def items(str kind):
    """Handles of every object of a kind, in creation order."""
    need_instance()
    cdef int k = _KIND_BY_WORD[kind]
    cdef hal_obj_t *obj
    cdef long steps = 0
    out = []
    lock()
    try:
        check(hal_check_header())
        obj = <hal_obj_t *>hal_walk_first(k)
        while obj != NULL:
            if len(out) >= hal_map.hdr.count[k]:
                raise damaged(f"the {kind} list is longer than its count "
                              f"{hal_map.hdr.count[k]}")
            out.append(make(k, obj))
            obj = <hal_obj_t *>hal_walk_next(k, obj, &steps)
        check(0)                    # a damaged list: DamagedError
    finally:
        hal_unlock()
    return out


def named_items(str kind):
    """``(name, handle)`` of every object of a kind, in creation order;
    the names are taken under the lock with the handles, so sorting or
    filtering by them never fails when an object goes meanwhile."""
    return [((<Item>it)._name, it) for it in items(kind)]


cdef str _pool_str(hal_snapshot_t *s, uint32_t at):
    return (s.pool + at).decode("utf-8", "replace")


cdef object _pool_opt(hal_snapshot_t *s, uint32_t at):
    return (s.pool + at).decode("utf-8", "replace") if at else None


cdef list _records_of(int k, hal_snapshot_t *s):
    cdef long i
    cdef uint32_t j
    cdef hal_snap_t *r
    cdef hal_snap_sub_t *sub
    from halsdk.core import records as _records
    out = []
    for i in range(s.nrecs):
        r = &s.recs[i]
        name = _pool_str(s, r.name)
        if k == K_PIN:
            out.append(_records.PinInfo(
                name, r.type, r.dir, get_raw(r.type, &r.value),
                _pool_str(s, r.owner), r.id, _pool_opt(s, r.link),
                _pool_opt(s, r.alias)))
        elif k == K_PARAM:
            out.append(_records.ParamInfo(
                name, r.type, r.dir, get_raw(r.type, &r.value),
                _pool_str(s, r.owner), r.id, _pool_opt(s, r.alias)))
        elif k == K_SIG:
            pins = []
            for j in range(r.nsub):
                sub = &s.subs[r.sub + j]
                pins.append(_records.LinkedPin(_pool_str(s, sub.name),
                                               sub.dir))
            out.append(_records.SignalInfo(
                name, r.type, get_raw(r.type, &r.value), tuple(pins),
                r.readers, r.writers, r.bidirs))
        elif k == K_COMP:
            out.append(_records.ComponentInfo(
                name, r.id, r.flags & 1 != 0, r.ready != 0, r.pid,
                hal_pid_alive(r.pid, r.pid_start) != 0, r.flags & 2 != 0))
        elif k == K_INST:
            out.append(_records.InstanceInfo(name, r.id,
                                             _pool_str(s, r.owner)))
        elif k == K_FUNCT:
            out.append(_records.FunctionInfo(
                name, _pool_str(s, r.owner), r.id, r.flags & 1 != 0,
                r.flags & 2 != 0, r.users, r.flags & 4 == 0, r.time,
                r.tmax))
        elif k == K_THREAD:
            out.append(_records.ThreadInfo(
                name, r.period, r.flags & 1 != 0, r.flags & 2 != 0,
                tuple(_pool_str(s, s.subs[r.sub + j].name)
                      for j in range(r.nsub)),
                r.time, r.tmax, r.cycles, r.overruns))
        else:
            out.append(_records.StreamInfo(name, _pool_str(s, r.owner)))
    return out


def snapshot(str kind):
    """Records (:mod:`halsdk.core.records`) of every object of a kind, in
    creation order: names, metadata and values copied by the core in one
    pass under the lock, so a listing never fails or mixes states when
    another process changes the instance meanwhile."""
    need_instance()
    cdef int k = _KIND_BY_WORD[kind]
    cdef hal_snapshot_t s
    cdef int r
    with nogil:
        r = hal_snapshot(k, &s)
    check(r)
    try:
        return _records_of(k, &s)
    finally:
        hal_snapshot_free(&s)


def lock_timeout() -> float:
    """Seconds a wait for the instance lock lasts before it fails."""
    return hal_lock_timeout()


def set_lock_timeout(double seconds):
    """Set this process's lock timeout (more than 0, at most 86400 s)."""
    check(hal_set_lock_timeout(seconds))


def lock_holder() -> int:
    """The pid holding the instance lock now, 0 when none."""
    need_instance()
    return hal_map.hdr.lock_holder


def _test_offset(str kind, name) -> int:
    """Test hook: the segment offset of a named object (0: none)."""
    need_instance()
    cdef int k = _KIND_BY_WORD[kind]
    cdef bytes b = enc(name)
    cdef void *p
    lock()
    try:
        p = hal_find(k, b)
        return SHMOFF(p) if p != NULL else 0
    finally:
        hal_unlock()


def _test_poke(hoff_t off, str field, long long value) -> int:
    """Test hook: write one field of the record at ``off`` (or of the
    header, ``count.<kind>``) to break an invariant on purpose; returns
    the old value so that the test can put it back."""
    need_instance()
    cdef void *p = SHMPTR(off)
    cdef long long old
    if field.startswith("count."):
        old = hal_map.hdr.count[_KIND_BY_WORD[field[6:]]]
        hal_map.hdr.count[_KIND_BY_WORD[field[6:]]] = <int32_t>value
    elif field == "obj.prev":
        old = (<hal_obj_t *>p).prev
        (<hal_obj_t *>p).prev = <hoff_t>value
    elif field == "obj.name0":
        old = (<hal_obj_t *>p).name[0]
        (<hal_obj_t *>p).name[0] = <char>value
    elif field == "item.comp":
        old = (<hal_item_t *>p).comp
        (<hal_item_t *>p).comp = <hoff_t>value
    elif field == "pin.signal":
        old = (<hal_pin_t *>p).signal
        (<hal_pin_t *>p).signal = <hoff_t>value
    elif field == "sig.readers":
        old = (<hal_sig_t *>p).readers
        (<hal_sig_t *>p).readers = <int32_t>value
    elif field == "funct.users":
        old = (<hal_funct_t *>p).users
        (<hal_funct_t *>p).users = <int32_t>value
    else:
        raise ValueError(f"unknown field {field!r}")
    return old


def comp_by_id(int id):
    need_instance()
    cdef hal_comp_t *c
    lock()
    try:
        c = hal_comp_by_id(id)
        check(0)
        return make(K_COMP, c) if c != NULL else None
    finally:
        hal_unlock()


def check_name(name, str what="object"):
    check(hal_check_name(enc(name), enc(what)))


# ---------------------------------------------------------------- changes

def comp_new(name, int kind):
    need_instance()
    cdef bytes b = enc(name)
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_comp_new(cb, kind)
    return check(r)


def comp_exit(int comp_id):
    need_instance()
    _drop_python_functs(comp_id)
    cdef int r
    with nogil:
        r = hal_comp_exit(comp_id)
    check(r)


def comp_ready(int comp_id, bint ready=True):
    need_instance()
    cdef int r
    with nogil:
        r = hal_comp_set_ready(comp_id, ready)
    check(r)


def inst_new(name, int comp_id):
    need_instance()
    cdef bytes b = enc(name)
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_inst_new(cb, comp_id)
    return check(r)


def inst_delete(name):
    need_instance()
    cdef bytes b = enc(name)
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_inst_delete(cb)
    check(r)


def pin_new(name, int type, int dir, int owner_id):
    """Create a pin whose pointer cell is allocated for the owner."""
    need_instance()
    cdef bytes b = enc(name)
    check(hal_check_name(b, b"pin"))
    cdef const char *cb = b
    cdef void **cell
    cdef int r
    with nogil:
        cell = <void **>hal_malloc_owned(sizeof(void *), owner_id)
    if cell == NULL:
        check(-12)
    with nogil:
        r = hal_pin_new(cb, type, dir, cell, owner_id)
    check(r)
    return find("pin", name)


def param_new(name, int type, int dir, int owner_id):
    """Create a param whose value is allocated for the owner."""
    need_instance()
    cdef bytes b = enc(name)
    check(hal_check_name(b, b"param"))
    cdef const char *cb = b
    cdef void *data
    cdef int r
    with nogil:
        data = hal_malloc_owned(8, owner_id)
    if data == NULL:
        check(-12)
    with nogil:
        r = hal_param_new(cb, type, dir, data, owner_id)
    check(r)
    return find("param", name)


def alias(str kind, name, alias_name):
    need_instance()
    cdef int k = _KIND_BY_WORD[kind]
    cdef bytes a = enc(name), b = enc(alias_name)
    cdef const char *ca = a
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_alias(k, ca, cb)
    check(r)


def unalias(str kind, alias_name):
    need_instance()
    cdef int k = _KIND_BY_WORD[kind]
    cdef bytes b = enc(alias_name)
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_unalias(k, cb)
    check(r)


def signal_new(name, int type):
    need_instance()
    cdef bytes b = enc(name)
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_signal_new(cb, type)
    check(r)
    return find("signal", name)


def signal_delete(name):
    need_instance()
    cdef bytes b = enc(name)
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_signal_delete(cb)
    check(r)


def link(pin, sig):
    need_instance()
    cdef bytes a = enc(pin), b = enc(sig)
    cdef const char *ca = a
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_link(ca, cb)
    check(r)


def net(sig, pins):
    """Link pins to a signal atomically, creating it with the first
    pin's type (hal_net)."""
    need_instance()
    cdef bytes s = enc(sig)
    encoded = [enc(p) for p in pins]
    cdef int n = len(encoded)
    cdef const char **arr = <const char **>PyMem_Malloc(
        (n if n else 1) * sizeof(const char *))
    if arr == NULL:
        raise MemoryError()
    cdef const char *cs = s
    cdef int r
    try:
        for i in range(n):
            arr[i] = <const char *>encoded[i]
        with nogil:
            r = hal_net(cs, arr, n)
    finally:
        PyMem_Free(arr)
    check(r)


def unlink(pin):
    need_instance()
    cdef bytes b = enc(pin)
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_unlink(cb)
    check(r)


def set_lock(int level):
    need_instance()
    if not 0 <= level <= 255:
        raise _errors.InvalidError(f"lock level {level} is not 0..255")
    cdef unsigned char lv = level
    cdef int r
    with nogil:
        r = hal_set_lock(lv)
    check(r)


def get_lock() -> int:
    need_instance()
    return hal_map.hdr.lock


def set_loading_rt(bint on):
    """Mark hal_init() calls of a module being loaded as realtime."""
    global hal_loading_rt
    hal_loading_rt = on


# ---------------------------------------------------------------- threads

_python_functs = {}     # funct name -> (owner id, callable state)


cdef class _PyFunct:
    cdef object fn
    cdef str name
    cdef bint reported
    cdef public long errors


cdef void py_trampoline(void *arg, long period) noexcept nogil:
    with gil:
        pf = <_PyFunct>arg
        try:
            pf.fn(period)
        except BaseException:
            pf.errors += 1
            if not pf.reported:
                pf.reported = True
                sys.stderr.write(f"halsdk: Python function '{pf.name}' "
                                 "raised (reported once):\n")
                import traceback
                traceback.print_exc()


def export_python(name, fn, int owner_id, bint uses_fp=True):
    """Export a Python callable ``fn(period_ns)`` as a (non-realtime)
    function; it takes the GIL on every call."""
    need_instance()
    if not callable(fn):
        raise _errors.InvalidError(f"function '{name}': {fn!r} is not "
                                   "callable")
    pf = _PyFunct()
    pf.fn = fn
    pf.name = name
    cdef bytes b = enc(name)
    cdef const char *cb = b
    cdef void *arg = <void *>pf
    cdef int r
    with nogil:
        r = hal_export_funct(cb, py_trampoline, arg, uses_fp, 0, owner_id,
                             1)
    check(r)
    _python_functs[name] = (owner_id, pf)


def python_funct_errors(name) -> int:
    entry = _python_functs.get(name)
    return entry[1].errors if entry else 0


def _drop_python_functs(int comp_id):
    for n in [n for n, (o, _) in _python_functs.items() if o == comp_id]:
        del _python_functs[n]


def thread_new(name, long period, bint uses_fp=True,
               unsigned int timing_every=1):
    need_instance()
    cdef bytes b = enc(name)
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_thread_new(cb, period, uses_fp, timing_every)
    check(r)
    return find("thread", name)


def thread_delete(name):
    need_instance()
    cdef bytes b = enc(name)
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_thread_delete(cb)
    check(r)


def addf(funct, thread, position=-1):
    need_instance()
    if not -2**31 <= position < 2**31:
        raise _errors.InvalidError(f"addf '{funct}': position {position} "
                                   "is out of range")
    cdef int pos = position
    cdef bytes f = enc(funct), t = enc(thread)
    cdef const char *cf = f
    cdef const char *ct = t
    cdef int r
    with nogil:
        r = hal_addf(cf, ct, pos)
    check(r)


def delf(funct, thread):
    need_instance()
    cdef bytes f = enc(funct), t = enc(thread)
    cdef const char *cf = f
    cdef const char *ct = t
    cdef int r
    with nogil:
        r = hal_delf(cf, ct)
    check(r)


def start(bint realtime=True):
    """Start every thread; returns a note when realtime was not granted."""
    need_instance()
    cdef char note[256]
    cdef int r
    note[0] = 0
    with nogil:
        r = exec_start_all(realtime, note, sizeof(note))
    check(r)
    return note.decode() or None


def stop():
    need_instance()
    cdef int r
    with nogil:
        r = hal_stop_threads()
    check(r)


def step(long n=1, thread=None):
    """Run threads for n cycles with simulated time, without sleeping."""
    need_instance()
    if n < 0:
        raise _errors.InvalidError(f"cannot step {n} cycles")
    cdef int r
    cdef int slot
    cdef long cycles = n
    if thread is None:
        with nogil:
            r = exec_step_all(cycles)
    else:
        t = find("thread", thread)
        if t is None:
            raise _errors.NotFoundError(f"thread '{thread}' not found")
        slot = (<hal_thread_t *>(<Item>t).rec()).slot
        with nogil:
            r = exec_run_cycles(slot, cycles)
    check(r)


# ---------------------------------------------------------------- streams

def stream_parse_types(typestring, str what="stream") -> list:
    """Type numbers of a stream type string; InvalidError names ``what``."""
    cdef uint8_t types[256]
    cdef bytes b = enc(typestring)
    cdef bytes w = enc(what)
    cdef int n = check(hal_stream_parse_types(b, types, w))
    return [types[i] for i in range(n)]


def stream_create(name, int owner_id, int depth, typestring) -> Stream:
    """Create a stream owned by a component or instance of this process;
    it is deleted with its owner."""
    need_instance()
    cdef bytes b = enc(name), t = enc(typestring)
    cdef long long h = hal_stream_create(b, owner_id, depth, t)
    if h < 0:
        check(<int>h)
    return stream_attach(name)


def shmem_new(name, int owner_id, long size) -> tuple:
    """Create a named shared block of ``size`` zeroed bytes owned by a
    component of this process (deleted with its owner); returns
    ``(address, size)`` in this process."""
    need_instance()
    cdef bytes b = enc(name)
    cdef long long h = hal_shmem_new(b, owner_id, size)
    if h < 0:
        check(<int>h)
    return shmem_place(h, name)


cdef tuple shmem_place(long long h, name):
    """(address, size) of a shared block's data, checked."""
    cdef void *p = hal_shmem_ptr(h)
    cdef long n = hal_shmem_size(h)
    check(0)                        # data outside the heap: DamagedError
    if p == NULL or n < 0:
        raise _errors.NotFoundError(f"shared block '{name}' no longer "
                                    "exists")
    return <size_t>p, n


def shmem_attach(name) -> tuple:
    """``(address, size)`` in this process of the named shared block a
    realtime module made (NotFoundError if there is none).  The address
    stays valid while the block's owner is loaded."""
    need_instance()
    cdef bytes b = enc(name)
    cdef long long h = hal_shmem_attach(b)
    if h < 0:
        check(<int>h)
    return shmem_place(h, name)


def symbol_address(name) -> int:
    """Address of a symbol a loaded realtime module exported
    (EXPORT_SYMBOL), or 0.  For tests that call it with ctypes."""
    cdef bytes b = enc(name)
    return <size_t>hal_symbol_find(b, NULL)


def symbol_user(module):
    """A loaded module that uses symbols of ``module``, or None."""
    cdef bytes b = enc(module)
    cdef const char *u = hal_symbol_user(b)
    return None if u == NULL else u.decode()


def stream_attach(name) -> Stream:
    """The handle of an existing stream (NotFoundError if there is none)."""
    need_instance()
    cdef bytes b = enc(name)
    cdef long long h = hal_stream_attach(b)
    if h < 0:
        check(<int>h)
    s = find("stream", name)
    if s is None:
        raise _errors.NotFoundError(f"stream '{name}' not found")
    return s


# capture: a realtime function that copies pins, signals or params into a
# stream once per call

ctypedef struct capture_t:
    long long handle
    int n
    int overruns
    hoff_t offs[256]
    uint8_t kinds[256]
    halsdk_value_t rec[256]


cdef void capture_fn(void *arg, long period) noexcept nogil:
    cdef capture_t *c = <capture_t *>arg
    cdef int i
    cdef hal_value_t *v
    for i in range(c.n):
        if c.kinds[i] == K_PIN:
            v = hal_pin_value(<hal_pin_t *>SHMPTR(c.offs[i]))
        elif c.kinds[i] == K_SIG:
            v = &(<hal_sig_t *>SHMPTR(c.offs[i])).value
        else:
            v = <hal_value_t *>hal_param_value(
                <hal_param_t *>SHMPTR(c.offs[i]))
        c.rec[i].lu = v.lu
    if hal_stream_write(c.handle, c.rec) < 0:
        c.overruns += 1


def capture_new(int comp_id, funct_name, stream_name, items, long depth,
                bint uses_fp=True) -> Stream:
    """Make the stream and the capture function of a capture: ``items`` are
    Pin, Signal or Param handles, one value each per call."""
    need_instance()
    cdef Item it
    n = len(items)
    if not 1 <= n <= HAL_STREAM_MAX_ELEMS:
        raise _errors.InvalidError(
            f"capture of {n} values: 1 to {HAL_STREAM_MAX_ELEMS} allowed")
    letters = []
    for obj in items:
        if not isinstance(obj, (Pin, Param, Signal)):
            raise _errors.InvalidError(f"cannot capture {obj!r}")
        letters.append(_STREAM_LETTER[obj.type])
    if depth < 1 or depth >= 0x7fffffff:
        raise _errors.InvalidError(f"capture of {depth} cycles: 1 to "
                                   f"{0x7fffffff - 1} allowed")
    # room for depth records (a stream holds one less than its depth)
    st = stream_create(stream_name, comp_id, depth + 1, "".join(letters))
    cdef capture_t *c = <capture_t *>hal_malloc_owned(sizeof(capture_t),
                                                      comp_id)
    if c == NULL:
        check(-12)
    c.handle = (<Stream>st).handle()
    c.n = n
    for i, obj in enumerate(items):
        it = <Item>obj
        it.rec()
        c.offs[i] = it.off
        c.kinds[i] = it.kind
    cdef bytes b = enc(funct_name)
    cdef const char *cb = b
    cdef int r
    with nogil:
        r = hal_export_funct(cb, capture_fn, c, uses_fp, 0, comp_id, 0)
    check(r)
    return st
