"""A damaged segment is reported, never a crash (issue 19, trust boundary).

Any process attached to an instance can write anywhere in its segment.
These tests do what a buggy component would: they write into the live
segment of a host (header fields, name-index buckets, block headers,
record heads and fields), then run every ``halcmd show``/``list``/
``save``/``status`` and the Python listings in attaching processes.
Those must end on their own, without a signal or a traceback; an error
says "instance NAME is damaged: ..." (or is an ordinary halcmd error).

The inputs and the host come from bench/segment_fuzz.py, whose
``--count N`` campaign runs many more of them (docs/reliability.md).
"""

from __future__ import annotations

import importlib.util
import os
import struct
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location(
    "segment_fuzz", ROOT / "bench" / "segment_fuzz.py")
assert _spec is not None and _spec.loader is not None
fuzz: Any = importlib.util.module_from_spec(_spec)
sys.modules["segment_fuzz"] = fuzz
_spec.loader.exec_module(fuzz)

HALCMD = str(Path(sys.executable).with_name("halcmd"))
TIMEOUT = 60
K_PIN, K_SIG, K_THREAD, K_STREAM = 3, 5, 7, 8

PY_LISTINGS = fuzz.LISTING + """
import sys
from halsdk import Hal
from halsdk.errors import HalError
try:
    with Hal(create=False) as hal:
        python_listings(hal)
except HalError as exc:
    print(f"python: {exc}", file=sys.stderr)
    sys.exit(1)
"""


@pytest.fixture(scope="module")
def host(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    tmp = tmp_path_factory.mktemp("segfuzz")
    (tmp / "listings.hal").write_text("\n".join(fuzz.COMMANDS) + "\n")
    name = f"{os.environ.get('HALSDK_INSTANCE', 't')}-segfuzz"[:40]
    h = fuzz.Host(name, str(tmp))
    h.tmp = tmp
    try:
        yield h
    finally:
        h.close()
        assert fuzz.leftovers(name) == 0, "a segment was left in /dev/shm"


def _run(host: Any, argv: list[str]) -> subprocess.CompletedProcess:
    env = dict(os.environ, HALSDK_INSTANCE=host.instance)
    try:
        return subprocess.run(argv, cwd=host.tmp, env=env, text=True,
                              capture_output=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired as exc:
        pytest.fail(f"{argv[:3]} hung on a damaged segment: {exc}")


def _ordinary(line: str) -> bool:
    """A line of an error halcmd prints on purpose."""
    return ("is damaged" in line or line.startswith(("halcmd:", "HAL:",
                                                     "python:"))
            or "listings.hal:" in line)


def _check_listings(host: Any) -> list[str]:
    """Every listing of halcmd and Python against the segment as it is;
    returns their error output."""
    errors = []
    for argv in ([HALCMD, "-k", "-f", "listings.hal"],
                 [sys.executable, "-c", PY_LISTINGS]):
        proc = _run(host, argv)
        what = f"{Path(argv[0]).name}: rc {proc.returncode}\n{proc.stderr}"
        assert proc.returncode >= 0, f"killed by a signal: {what}"
        assert "Traceback" not in proc.stderr, what
        bad = [ln for ln in proc.stderr.splitlines()
               if ln.strip() and not _ordinary(ln)]
        assert not bad, what
        if proc.returncode != 0:
            assert proc.stderr.strip(), what
        errors.append(proc.stderr)
    assert host.proc.poll() is None, "the host died"
    return errors


def _u32(host: Any, off: int) -> int:
    return int(struct.unpack_from("<I", host.mm, off)[0])


def _put(host: Any, off: int, value: int) -> None:
    struct.pack_into("<I", host.mm, off, value & 0xFFFFFFFF)


def _head(host: Any, kind: int) -> int:
    return _u32(host, host.layout.fields["list_head"] + 4 * kind)


def _record(host: Any, kind: int, name: str) -> int:
    """Offset of the record named name in the list of kind."""
    f = host.layout.fields
    off = _head(host, kind)
    for _ in range(100000):
        if not off:
            break
        raw = bytes(host.mm[off + f["obj_name"]:
                            off + f["obj_name"] + f["name_size"]])
        if raw.split(b"\0")[0].decode() == name:
            return off
        off = _u32(host, off)
    raise LookupError(name)


def _field(host: Any, rec: int, index: int) -> int:
    """Offset of the index-th 32-bit word after a record's name."""
    f = host.layout.fields
    return rec + f["obj_name"] + f["name_size"] + 4 * index


# Each case breaks one thing that crashed or hung halcmd before the
# checks.  The word index of fields after the name follows hal_core.h.
def _pin_list_out_of_segment(host: Any) -> None:
    _put(host, host.layout.fields["list_head"] + 4 * K_PIN, 0xFFFFFFF0)


def _pin_list_cycle(host: Any) -> None:
    rec = _record(host, K_PIN, "and2.0.out")
    _put(host, rec, rec)            # next: itself


def _pin_signal_wild(host: Any) -> None:
    rec = _record(host, K_PIN, "and2.0.out")
    _put(host, _field(host, rec, 5), 0x7FFFFFF0)    # pin->signal


def _pin_owner_wild(host: Any) -> None:
    rec = _record(host, K_PIN, "and2.0.in0")
    _put(host, _field(host, rec, 0), 0xFFFFFF00)    # comp


def _alias_name_wild(host: Any) -> None:
    rec = _record(host, K_PIN, "gate")
    _put(host, _field(host, rec, 2), 0xFFFFFFF0)    # oldname


def _thread_functs_cycle(host: Any) -> None:
    rec = _record(host, K_THREAD, "slow")
    # the functs field: after period (8), uses_fp, priority, running,
    # slot, timing_every, comp (6 words)
    functs = _field(host, rec, 8)
    first = _u32(host, functs)
    _put(host, first, first)        # the first entry's next: itself


def _thread_slot_wild(host: Any) -> None:
    rec = _record(host, K_THREAD, "slow")
    _put(host, _field(host, rec, 5), 0x7FFFFFFF)    # slot: the host's
    # executor index, used by delf/addf (the listings run both)


def _stream_huge(host: Any) -> None:
    rec = _record(host, K_STREAM, "sampler.0")
    _put(host, _field(host, rec, 2), 100000)        # nelem


def _bucket_wild(host: Any) -> None:
    for off in host.layout.buckets:
        _put(host, off, 0xFFFFFFF0)


def _heap_start_wild(host: Any) -> None:
    _put(host, host.layout.fields["heap_start"], 0xFFFFFF00)


def _pin_type_wild(host: Any) -> None:
    # the listings set it (setp pid.0.Igain): a type of -1 is damage,
    # not a value to coerce (a ValueError traceback before)
    rec = _record(host, K_PIN, "pid.0.Igain")
    word = _field(host, rec, 3)                     # type, dir (int16)
    _put(host, word, (_u32(host, word) & 0xFFFF0000) | 0xFFFF)


def _mutex_kind_wild(host: Any) -> None:
    # glibc took the mutex for a priority-protect one and aborted the
    # process inside pthread_mutex_lock (found by the campaign)
    moff, _size = host.layout.fields["mutex"]
    _put(host, moff + 16, 0x100EC0)                 # __data.__kind


CASES = [_pin_list_out_of_segment, _pin_list_cycle, _pin_signal_wild,
         _pin_owner_wild, _alias_name_wild, _thread_functs_cycle,
         _thread_slot_wild, _stream_huge, _bucket_wild, _heap_start_wild,
         _pin_type_wild, _mutex_kind_wild]


@pytest.mark.slow
@pytest.mark.parametrize("damage", CASES, ids=lambda f: f.__name__[1:])
def test_known_damage_is_reported(host: Any, damage: Any) -> None:
    damage(host)
    try:
        errors = _check_listings(host)
    finally:
        host.restore()
    assert any("is damaged" in e for e in errors), errors


def test_the_restored_segment_lists_cleanly(host: Any) -> None:
    errors = _check_listings(host)
    assert errors == ["", ""]


VICTIM = """\
import time
from halsdk.compat import hal
c = hal.component("victim")
c.newpin("out", hal.HAL_BIT, hal.HAL_OUT)
c["out"] = True
c.ready()
print("up", flush=True)
time.sleep(120)
"""


def test_host_marks_a_dead_component_on_a_damaged_list(
        tmp_path: Path) -> None:
    """The host's watch marks a SIGKILLed component dead by walking the
    pin list: on a damaged list it reports damage, it does not crash or
    loop for ever (an unchecked walk before)."""
    name = f"{os.environ.get('HALSDK_INSTANCE', 't')}-markdead"[:40]
    h = fuzz.Host(name, str(tmp_path))
    h.tmp = tmp_path
    env = dict(os.environ, HALSDK_INSTANCE=name)
    victim = subprocess.Popen([sys.executable, "-c", VICTIM], cwd=tmp_path,
                              env=env, stdout=subprocess.PIPE, text=True)
    try:
        assert victim.stdout is not None
        assert victim.stdout.readline().strip() == "up"
        rec = _record(h, K_PIN, "victim.out")
        keep = _u32(h, rec)
        _put(h, rec, rec)               # the pin list: a cycle
        victim.kill()
        victim.wait()
        time.sleep(1.0)                 # the watch runs within 0.1 s
        assert h.proc.poll() is None, h.host_log()
        _put(h, rec, keep)
        proc = _run(h, [HALCMD, "show", "comp", "victim"])
        assert proc.returncode == 0, proc.stderr
    finally:
        if victim.poll() is None:
            victim.kill()
            victim.wait()
        h.close()
    assert fuzz.leftovers(name) == 0


_inputs = st.lists(
    st.tuples(st.sampled_from(fuzz.TARGETS), st.integers(0, 2**31 - 1),
              st.sampled_from(fuzz.VALUES), st.integers(0, 2**32 - 1)),
    min_size=1, max_size=4)


@pytest.mark.slow
@settings(max_examples=12, derandomize=True, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture,
                                 HealthCheck.too_slow])
@given(inp=_inputs)
def test_random_damage_never_crashes(host: Any, inp: Any) -> None:
    fuzz.apply(host.mm, fuzz.resolve(host.layout, inp))
    try:
        _check_listings(host)
    finally:
        host.restore()


@pytest.mark.slow
def test_campaign_script_counts_no_failure(tmp_path: Path) -> None:
    env = dict(os.environ,
               HALSDK_INSTANCE=os.environ.get("HALSDK_INSTANCE", "t"))
    proc = subprocess.run(
        [sys.executable, str(ROOT / "bench" / "segment_fuzz.py"),
         "--count", "60", "--seed", "7"], cwd=tmp_path, env=env,
        text=True, capture_output=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "crashes 0, tracebacks 0, hangs 0, leftovers 0" in proc.stdout
    assert "60 inputs" in proc.stdout


HOLDER = """\
import sys
from halsdk import Hal
from halsdk.core import _core
hal = Hal(create=True)
print("up", flush=True)
from halsdk.errors import HalError
sys.stdin.readline()
try:
    _core.hold_lock_for_test(1.5)
    print("unlocked", flush=True)
except HalError as exc:
    print(f"unlocked: {exc}", flush=True)
hal.newsig("after", "float")
print(len(hal.signals()), flush=True)
sys.stdin.readline()
hal.close()
"""


def test_the_lock_holder_survives_a_write_into_the_held_mutex(
        tmp_path: Path) -> None:
    """glibc keeps a held robust mutex in the holder's robust list, with
    pointers inside the mutex; unlocking follows them.  Another process
    writing there while the host held the lock made the host die of
    SIGSEGV in pthread_mutex_unlock (found by the campaign): the holder
    puts back what is its own before unlocking."""
    import mmap

    from halsdk.core import _core
    from halsdk.core.instance import shm_name
    name = f"{os.environ.get('HALSDK_INSTANCE', 't')}-heldmutex"[:40]
    env = dict(os.environ, HALSDK_INSTANCE=name)
    holder = subprocess.Popen([sys.executable, "-c", HOLDER], cwd=tmp_path,
                              env=env, stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    assert holder.stdout is not None and holder.stdin is not None
    try:
        assert holder.stdout.readline().strip() == "up"
        fd = os.open("/dev/shm" + shm_name(name), os.O_RDWR)
        try:
            mm = mmap.mmap(fd, 0)
        finally:
            os.close(fd)
        moff, _size = _core.segment_layout()["mutex"]
        holder.stdin.write("\n")
        holder.stdin.flush()
        deadline = time.monotonic() + 10
        while struct.unpack_from("<I", mm, moff)[0] == 0:   # __lock
            assert time.monotonic() < deadline, "the lock was not taken"
            time.sleep(0.001)
        # __owner, then __list.__prev and __list.__next: small numbers
        struct.pack_into("<i", mm, moff + 8, 4242)
        struct.pack_into("<QQ", mm, moff + 24, 0x10, 0x18)
        said = holder.stdout.readline().strip()
        assert said.startswith("unlocked: instance ") and said.endswith(
            "is damaged: the instance mutex was written over while pid "
            f"{holder.pid} held it (repaired)"), said
        assert int(holder.stdout.readline()) == 1   # the lock works on
        proc = subprocess.run([HALCMD, "show", "comp"], cwd=tmp_path,
                              env=env, capture_output=True, text=True,
                              timeout=TIMEOUT)
        assert proc.returncode == 0, proc.stderr
        mm.close()
        holder.stdin.write("\n")
        holder.stdin.flush()
        assert holder.wait(TIMEOUT) == 0
    finally:
        if holder.poll() is None:
            holder.kill()
            holder.wait()
    assert fuzz.leftovers(name) == 0
