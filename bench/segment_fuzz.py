"""Shared-memory corruption campaign: damage a live instance, then list it.

A buggy component can write anywhere in an instance's segment.  This
script does that on purpose: it starts a host with a few components (two
threads, and2, pid, siggen, a sampler stream, signals, aliases), then for
each input overwrites a few header fields, name-index buckets, block
headers, record heads or record fields of the live segment with values
chosen to hurt (0, all ones, offsets of other records, the record itself,
off-by-one offsets, random words), runs every ``halcmd show``/``list``/
``save``/``status`` and the Python listings in an attaching process, and
puts the bytes back.  It counts:

- **crashes**: the attaching process died of a signal;
- **tracebacks**: it raised something other than a ``HalError`` (or
  printed "Traceback");
- **hangs**: it did not end within the time limit;
- **leftovers**: ``/dev/shm`` segments of the campaign's instances left
  at the end.

All four must be 0.  ``damaged`` counts the inputs where the attaching
process reported "instance NAME is damaged"; the others found nothing
wrong (a value or a name changed) or failed with an ordinary error.

Usage::

    python bench/segment_fuzz.py --count 100000 [--jobs 2] [--seed 1]

Each input runs in a forked child of a worker (no interpreter start per
input); a worker owns one host and instance.  The suite's property test
(tests/core/test_segment_fuzz.py) runs the same inputs through the
installed ``halcmd`` and ``python`` instead.

The instance mutex (``pthread_mutex_t`` in the header) is left alone
unless ``--mutex``: a stray write there makes the lock look held, which
the lock timeout reports, not these checks.
"""

from __future__ import annotations

import argparse
import mmap
import os
import random
import select
import signal
import struct
import subprocess
import sys
import tempfile
import textwrap
import time
import traceback
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Optional

SETUP = """\
loadrt threads name1=fast period1=1000000 name2=slow period2=10000000
loadrt and2 count=2
loadrt pid num_chan=1
loadrt siggen
loadrt sampler depth=16 cfg=ffb
addf and2.0 fast
addf and2.1 fast
addf siggen.0.update slow
addf pid.0.do-pid-calcs slow
addf sampler.0 slow
net clock siggen.0.clock => and2.0.in0 sampler.0.pin.2
net chain and2.0.out => and2.1.in0
net wave siggen.0.sine => pid.0.command sampler.0.pin.0
net fb pid.0.output => pid.0.feedback sampler.0.pin.1
newsig spare float
newsig flag bit
sets spare 2.5
alias pin and2.1.in1 gate
alias pin pid.0.Pgain kp
setp kp 3.0
alias param and2.0.tmax gate-tmax
"""

# every listing of halcmd, each on its own (keep going after an error)
COMMANDS = [
    "show", "show all", "show comp", "show pin", "show pin and2.*",
    "show sig", "show param", "show funct", "show thread", "show alias",
    "list comp", "list pin", "list sig", "list param", "list funct",
    "list thread", "save", "save all", "save allu", "save comp",
    "save alias", "save sig", "save sigu", "save link", "save linka",
    "save net", "save neta", "save netl", "save netla", "save param",
    "save thread", "save unconnectedinpins", "status", "status lock",
    "status mem",
    # and changes, each undone (the walkers that change things)
    "newsig fz-s float", "sets fz-s 1.5", "linksp fz-s pid.0.Dgain",
    "gets fz-s", "unlinkp pid.0.Dgain", "delsig fz-s",
    "setp pid.0.Igain 0.5", "alias pin pid.0.Igain fz-ig", "getp fz-ig",
    "unalias pin fz-ig", "delf siggen.0.update slow",
    "addf siggen.0.update slow",
]

# what the Python listings touch of each object
LISTING = textwrap.dedent("""\
    def python_listings(hal):
        out = []
        for kind in ("component", "instance", "pin", "param", "signal",
                     "function", "thread", "stream"):
            for it in hal.items(kind):
                for attr in ("name", "type", "direction", "owner",
                             "owner_id", "alias_of", "value", "signal",
                             "linked", "writers", "readers", "bidirs",
                             "pins", "id", "realtime", "ready", "pid",
                             "alive", "uses_fp", "reentrant", "users",
                             "time", "tmax", "period", "running",
                             "functions", "nelem", "typestring", "types",
                             "maxdepth", "room", "depth", "overruns",
                             "sampleno"):
                    if hasattr(type(it), attr):
                        out.append(getattr(it, attr))
        out.append(hal.info())
        out.append(hal.counts())
        return len(out)
""")
exec(LISTING)   # defines python_listings (also sent to subprocesses)

# ---------------------------------------------------------------- inputs

TARGETS = ("header", "bucket", "block_head", "obj_head", "obj_fields",
           "anywhere")
VALUES = ("zero", "ones", "big", "other_record", "self", "near",
          "random", "flip", "small")


@dataclass
class Layout:
    """Where things are in the live segment (read once, before damage)."""
    size: int
    fields: dict[str, Any]
    header_words: list[int]         # offsets of header fields to damage
    buckets: list[int]              # offsets of non-empty bucket slots
    blocks: list[tuple[int, int]]   # (block offset, data size), used
    records: list[int]              # offsets of object records


def read_layout(mm: mmap.mmap, fields: dict[str, Any],
                include_mutex: bool = False) -> Layout:
    def u32(off: int) -> int:
        return int(struct.unpack_from("<I", mm, off)[0])

    heap_start = u32(fields["heap_start"])
    heap_top = u32(fields["heap_top"])
    nk = fields["nkinds"]
    words = [fields[k] for k in ("heap_start", "heap_top", "heap_end",
                                 "free_big", "buckets", "nbuckets")]
    words += [fields["free_class"] + 4 * i for i in range(64)]
    for arr in ("list_head", "list_tail", "count"):
        words += [fields[arr] + 4 * k for k in range(1, nk)]
    words += [8, 12, 16]            # abi, header_size, size
    if include_mutex:
        moff, msize = fields["mutex"]
        words += list(range(moff, moff + msize, 4))
    buckets = []
    b0 = u32(fields["buckets"])
    nb = u32(fields["nbuckets"])
    for i in range(nb):
        if u32(b0 + 4 * i):
            buckets.append(b0 + 4 * i)
    blocks, records = [], []
    off = heap_start
    while off + 16 <= heap_top:
        size, magic = struct.unpack_from("<II", mm, off)
        if magic == 0x55534544:
            blocks.append((off, size))
            kind = struct.unpack_from("<H", mm, off + 16 + 12)[0]
            if 0 < kind < nk and size >= fields["obj_name"] + 128:
                records.append(off + 16)
        off += 16 + size
    return Layout(len(mm), fields, words, buckets, blocks, records)


Input = Sequence[tuple[str, int, str, int]]


def random_input(rng: random.Random) -> list[tuple[str, int, str, int]]:
    """1 to 4 damages: (target, where, value kind, value word)."""
    return [(rng.choice(TARGETS), rng.getrandbits(31), rng.choice(VALUES),
             rng.getrandbits(32)) for _ in range(rng.randint(1, 4))]


def resolve(layout: Layout, inp: Input) -> list[tuple[int, bytes]]:
    """The (offset, bytes) writes of an input on this segment."""
    writes = []
    name_end = layout.fields["obj_name"] + layout.fields["name_size"]
    for target, where, vkind, word in inp:
        if target == "header":
            off = layout.header_words[where % len(layout.header_words)]
        elif target == "bucket" and layout.buckets:
            off = layout.buckets[where % len(layout.buckets)]
        elif target == "block_head" and layout.blocks:
            b, _ = layout.blocks[where % len(layout.blocks)]
            off = b + 4 * ((where >> 8) % 4)
        elif target == "obj_head" and layout.records:
            r = layout.records[where % len(layout.records)]
            off = r + 4 * ((where >> 8) % 7)       # next..gen
        elif target == "obj_fields" and layout.records:
            r = layout.records[where % len(layout.records)]
            off = r + name_end + 4 * ((where >> 8) % 24)
        else:
            off = 64 + where % (layout.size - 72)
        off &= ~3
        if vkind == "zero":
            val = 0
        elif vkind == "ones":
            val = 0xFFFFFFFF
        elif vkind == "big":
            val = 0x7FFFFFFF - (word & 0xFF)
        elif vkind == "other_record" and layout.records:
            val = layout.records[word % len(layout.records)]
        elif vkind == "self":
            val = off & ~15
        elif vkind == "near" and layout.records:
            val = layout.records[word % len(layout.records)] + \
                (word >> 16) % 33 - 16
        elif vkind == "small":
            val = word % 300
        elif vkind == "flip":
            val = -1                # filled in by apply: one bit flipped
        else:
            val = word
        if val == -1:
            writes.append((off, b"flip" + bytes([word % 32])))
        else:
            writes.append((off, struct.pack("<I", val & 0xFFFFFFFF)))
    return writes


def apply(mm: mmap.mmap, writes: list[tuple[int, bytes]]) -> None:
    for off, data in writes:
        if data[:4] == b"flip":
            cur = struct.unpack_from("<I", mm, off)[0]
            struct.pack_into("<I", mm, off, cur ^ (1 << data[4]))
        else:
            mm[off:off + 4] = data


# ---------------------------------------------------------------- host

HOST = textwrap.dedent("""\
    import sys
    from halsdk import Hal
    from halsdk.halcmd.commands import CommandRunner
    hal = Hal(create=True)
    ex = CommandRunner(hal, keep_going=False)
    rc = ex.run_lines(sys.argv[1].splitlines(), "setup")
    print("ready" if rc == 0 else f"setup failed {rc}", flush=True)
    sys.stdin.read()
    hal.close()
""")


class Host:
    """A host process with the SETUP instance, and the segment mapped."""

    def __init__(self, instance: str, cwd: str):
        from halsdk.core import _core
        from halsdk.core.instance import shm_name
        self.instance = instance
        self.path = "/dev/shm" + shm_name(instance)
        env = dict(os.environ, HALSDK_INSTANCE=instance,
                   PYTHONFAULTHANDLER="1")
        # the host's messages go to a file: a pipe nobody reads would
        # block it once full
        self.log = os.path.join(cwd, f"host-{instance}.log")
        with open(self.log, "w") as log:
            self.proc = subprocess.Popen(
                [sys.executable, "-c", HOST, SETUP], stdin=subprocess.PIPE,
                stdout=subprocess.PIPE, stderr=log, cwd=cwd, env=env,
                text=True)
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline().strip()
        if line != "ready":
            self.proc.kill()
            self._mapped = False
            self.close()
            raise RuntimeError(f"host did not start: {line!r}\n"
                               f"{self.host_log()}")
        fd = os.open(self.path, os.O_RDWR)
        try:
            self.mm = mmap.mmap(fd, 0)
            self._mapped = True
        finally:
            os.close(fd)
        self.layout = read_layout(self.mm, _core.segment_layout())
        heap_top = struct.unpack_from(
            "<I", self.mm, self.layout.fields["heap_top"])[0]
        self.keep = bytes(self.mm[:heap_top + 4096])

    def host_log(self) -> str:
        with open(self.log, errors="replace") as f:
            return f.read()[-3000:]

    def restore(self, writes: Sequence[tuple[int, bytes]] = ()) -> None:
        """Put the bytes back (header, index and every record).  The
        instance mutex is left as it is while a process holds it, unless
        ``writes`` (this input's) went into it: putting its free state
        back under a holder would be this script's own damage."""
        moff, msize = self.layout.fields["mutex"]
        ours = any(moff - 8 < off < moff + msize for off, _ in writes)
        held = struct.unpack_from("<I", self.mm, moff)[0] != 0
        if held and not ours:
            self.mm[:moff] = self.keep[:moff]
            self.mm[moff + msize:len(self.keep)] = \
                self.keep[moff + msize:]
        else:
            self.mm[:len(self.keep)] = self.keep

    def close(self) -> None:
        if getattr(self, "_mapped", False):
            self.restore()
            self.mm.close()
            self._mapped = False
        if self.proc.poll() is None:
            try:
                assert self.proc.stdin is not None
                self.proc.stdin.close()
                self.proc.wait(10)
            except (subprocess.TimeoutExpired, OSError):
                self.proc.kill()
                self.proc.wait()
        if self.proc.stdout is not None:
            self.proc.stdout.close()
        try:
            os.unlink(self.path)    # the host removes it; a damaged one
        except FileNotFoundError:   # may be left: not by this campaign
            pass


# ---------------------------------------------------------------- runs

@dataclass
class Counts:
    inputs: int = 0
    crashes: int = 0
    tracebacks: int = 0
    hangs: int = 0
    leftovers: int = 0
    damaged: int = 0
    errors: int = 0
    examples: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def add(self, other: Counts) -> None:
        for k in ("inputs", "crashes", "tracebacks", "hangs", "leftovers",
                  "damaged", "errors"):
            setattr(self, k, getattr(self, k) + getattr(other, k))
        self.examples += other.examples
        self.notes += other.notes


def child_main(cmd_file: str, instance: str) -> int:
    """In the forked child: attach, run every listing; exit code 0 ok,
    1 an ordinary HalError, 2 damage reported, 3 a traceback (stderr
    goes to the parent)."""
    from halsdk import Hal
    from halsdk.errors import HalError
    from halsdk.halcmd.commands import CommandRunner
    os.environ["HALSDK_INSTANCE"] = instance
    try:
        hal = Hal(instance, create=False)
    except HalError as exc:
        print(f"attach: {exc}", file=sys.stderr)
        return 2 if "is damaged" in str(exc) else 1
    code = 0
    try:
        ex = CommandRunner(hal, out=lambda text: None, keep_going=True)
        try:
            ex.run_file(cmd_file)
        finally:
            ex.unregister()
        python_listings(hal)    # type: ignore[name-defined]  # noqa: F821
    except HalError as exc:
        print(f"listing: {exc}", file=sys.stderr)
        code = 2 if "is damaged" in str(exc) else 1
    finally:
        hal.close()
    sys.stderr.flush()
    return code


def run_forked(host: Host, inp: Input, cmd_file: str, timeout: float,
               counts: Counts) -> None:
    writes = resolve(host.layout, inp)
    apply(host.mm, writes)
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(r)
        code = 3
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, 1)
            os.dup2(w, 2)
            import faulthandler
            faulthandler.register(signal.SIGUSR1, all_threads=True)
            code = child_main(cmd_file, host.instance)
        except BaseException:
            os.write(w, traceback.format_exc().encode())
            code = 3
        finally:
            os._exit(code)
    os.close(w)
    # the child's stderr ends when it does: read it until then
    deadline = time.monotonic() + timeout
    status = None
    err = b""
    hung = False
    while True:
        left = deadline - time.monotonic()
        ready = select.select([r], [], [], max(left, 0))[0] if left > 0 \
            else []
        if not ready:
            hung = True
            break
        chunk = os.read(r, 65536)
        if not chunk:
            break
        err += chunk
    if hung:
        # where it hangs: the Python stacks (faulthandler), then end it
        os.kill(pid, signal.SIGUSR1)
        if select.select([r], [], [], 2.0)[0]:
            err += os.read(r, 65536)
    os.close(r)
    if hung:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        counts.hangs += 1
        stacks = err.decode("utf-8", "replace")[-3000:]
        counts.examples.append(f"hang: {inp}\n{stacks}")
    else:
        status = os.waitpid(pid, 0)[1]
    counts.inputs += 1
    text = err.decode("utf-8", "replace")
    if status is not None:
        if os.WIFSIGNALED(status):
            counts.crashes += 1
            counts.examples.append(
                f"signal {os.WTERMSIG(status)}: {inp}")
        else:
            code = os.WEXITSTATUS(status)
            if code == 3 or "Traceback" in text:
                counts.tracebacks += 1
                counts.examples.append(f"traceback: {inp}\n{text[-2000:]}")
            elif code == 2 or "is damaged" in text:
                counts.damaged += 1
            elif code == 1:
                counts.errors += 1
                if counts.errors <= 3:
                    counts.notes.append(f"error: {inp}\n{text[-600:]}")
    host.restore(writes)


def worker(count: int, seed: int, timeout: float, include_mutex: bool,
           tag: str) -> Counts:
    counts = Counts()
    rng = random.Random(seed)
    # imported once here, not in every forked child
    import halsdk.halcmd.commands  # noqa: F401
    with tempfile.TemporaryDirectory() as tmp:
        cmd_file = os.path.join(tmp, "listings.hal")
        with open(cmd_file, "w") as f:
            f.write("\n".join(COMMANDS) + "\n")
        instance = f"fuzz-{tag}-{os.getpid()}"
        host = Host(instance, tmp)
        try:
            if include_mutex:
                from halsdk.core import _core
                host.layout = read_layout(host.mm, _core.segment_layout(),
                                          include_mutex=True)
            for _ in range(count):
                last = random_input(rng)
                run_forked(host, last, cmd_file, timeout, counts)
                if host.proc.poll() is not None:    # the host died
                    counts.crashes += 1
                    counts.examples.append(
                        f"the host died ({host.proc.returncode}) after "
                        f"{last}:\n{host.host_log()}")
                    break
        finally:
            host.close()
        counts.leftovers += leftovers(instance)
    return counts


def leftovers(instance_prefix: str) -> int:
    uid = os.getuid()
    return sum(1 for n in os.listdir("/dev/shm")
               if n.startswith(f"halsdk-{uid}-{instance_prefix}"))


def run_campaign(count: int, seed: int = 1, jobs: int = 1,
                 timeout: float = 20.0, mutex: bool = False) -> Counts:
    """``count`` inputs in ``jobs`` forked workers (each with its own
    host); their counts added up."""
    total = Counts()
    per = [count // jobs + (i < count % jobs) for i in range(jobs)]
    pids = []
    for i, n in enumerate(per):
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:
            os.close(r)
            c = Counts()
            try:
                c = worker(n, seed * 1000 + i, timeout, mutex,
                           f"{seed}-{i}")
            except BaseException:
                c.tracebacks += 1
                c.examples.append("worker: " + traceback.format_exc())
            os.write(w, repr(vars(c)).encode())
            os._exit(0)
        os.close(w)
        pids.append((pid, r))
    for pid, r in pids:
        data = b""
        while True:
            chunk = os.read(r, 1 << 20)
            if not chunk:
                break
            data += chunk
        os.close(r)
        os.waitpid(pid, 0)
        import ast
        d = ast.literal_eval(data.decode()) if data else {}
        total.add(Counts(**d) if d else Counts(tracebacks=1))
    return total


def campaign(count: int, seed: int = 1, jobs: int = 1,
             mutex: bool = True) -> dict[str, Any]:
    """The shared-memory kind of bench/reliability.py: its counts.  The
    mutex is damaged too, with a short lock timeout (a damaged mutex
    looks held: waits for it time out)."""
    if mutex:
        os.environ.setdefault("HALSDK_LOCK_TIMEOUT", "1")
    t0 = time.monotonic()
    total = run_campaign(count, seed, jobs, mutex=mutex)
    return {"inputs": total.inputs, "crashes": total.crashes,
            "tracebacks": total.tracebacks, "hangs": total.hangs,
            "leftovers": total.leftovers,
            "seconds": time.monotonic() - t0,
            "findings": [ex.splitlines()[0] for ex in total.examples],
            "damaged": total.damaged}


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--count", type=int, default=1000,
                    help="inputs in all (default 1000)")
    ap.add_argument("--jobs", type=int, default=1,
                    help="workers, each with its own host (default 1)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=20.0,
                    help="seconds an attaching process may take")
    ap.add_argument("--mutex", action="store_true",
                    help="damage the instance mutex too")
    ap.add_argument("--examples", type=int, default=5,
                    help="failures to print in full")
    ap.add_argument("--verbose", action="store_true",
                    help="also print a few ordinary errors")
    args = ap.parse_args(argv)
    t0 = time.monotonic()
    total = run_campaign(args.count, args.seed, args.jobs, args.timeout,
                         args.mutex)
    elapsed = time.monotonic() - t0
    print(f"shared-memory corruption: {total.inputs} inputs in "
          f"{elapsed:.0f} s ({args.jobs} jobs, seed {args.seed})")
    print(f"  crashes {total.crashes}, tracebacks {total.tracebacks}, "
          f"hangs {total.hangs}, leftovers {total.leftovers}")
    clean = total.inputs - total.damaged - total.errors - total.crashes \
        - total.tracebacks - total.hangs
    print(f"  reported damaged {total.damaged}, other errors "
          f"{total.errors}, clean {clean}")
    for ex in total.examples[:args.examples]:
        print("---\n" + ex)
    if args.verbose:
        for note in total.notes[:args.examples]:
            print("--- (ordinary)\n" + note)
    bad = total.crashes + total.tracebacks + total.hangs + total.leftovers
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
