"""``halsdk runtests``: run test folders in LinuxCNC's regression-test format.

A test folder holds one test program and a way to judge its output:

``test.hal``
    run as ``halrun -f test.hal > result 2> stderr`` (re-run, up to ten
    times, while ``result`` holds a line ``overrun``: a sampler that lost
    records);
``test.sh``
    run as ``bash -x test.sh > result 2> stderr``;
``test``
    an executable, run as ``./test > result 2> stderr``;

then, when the run exited with status 0, ``checkresult`` (an executable,
run as ``checkresult result``, exit status 0 = pass) if the folder has one,
otherwise ``expected``, which must equal ``result`` byte for byte.  A file
``skip`` skips the folder (an executable ``skip`` skips it when it exits
with status 0: it decides at run time); a file ``xfail`` marks a test
that is expected to fail (counted apart; passing is then a failure,
"XPASS").

Each test runs in its folder, with the bin folder of the running Python
(its ``halrun``, ``halcmd``, ``halcompile``, ``python3``, ...) first on
``PATH``, the compat ``hal``/``linuxcnc`` modules on ``PYTHONPATH``, and a
HAL instance of its own (``HALSDK_INSTANCE``, derived from the caller's),
so that runs in parallel never collide.  A test that fails or times out
is followed by ``halrun -U``, so that an instance it left behind does not
make the next test fail.
"""

from __future__ import annotations

import argparse
import difflib
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Optional

#: the names of a test program, in the order they are looked for
TEST_NAMES = ("test.hal", "test.sh", "test")
#: what a run leaves in a test folder (removed before a run, and after a
#: test that passed, unless --noclean)
RUN_FILES = ("result", "stderr")
RUN_GLOBS = ("*.var", "*.var.bak")
#: a halrun test is run again while its result shows a sampler overrun
OVERRUN_TRIES = 10
DEFAULT_TIMEOUT = 120.0
#: how many lines of a failed test's stderr are shown
STDERR_TAIL = 20
#: instance names are at most 40 characters (halsdk.core.instance)
_INSTANCE_MAX = 40

_DESCRIPTION = """\
Run HAL regression tests written in LinuxCNC's format: every folder under
DIR holding test.hal, test.sh or an executable test is run in that folder
(halrun -f test.hal, bash -x test.sh or ./test, stdout to 'result' and
stderr to 'stderr'), then judged by its executable 'checkresult'
(checkresult result, exit 0 = pass) or by comparing 'expected' with
'result'.  A 'skip' file skips a folder (an executable one skips it when
it exits 0); an 'xfail' file marks an expected failure.  The tests run
this Python's halrun/halcmd/halcompile, each on a HAL instance of its own.
Prints 'Runtest: N tests run, N successful, N failed + N expected, N
skipped' and exits with status 1 when a test failed."""


@dataclass
class Summary:
    """What a run counted."""

    run: int = 0
    failed: list[str] = field(default_factory=list)
    xfailed: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)

    @property
    def successful(self) -> int:
        return self.run - len(self.failed) - len(self.xfailed)

    def line(self) -> str:
        return (f"Runtest: {self.run} tests run, {self.successful} "
                f"successful, {len(self.failed)} failed + "
                f"{len(self.xfailed)} expected, {len(self.skipped)} skipped")


@dataclass
class Options:
    noclean: bool = False
    stop: bool = False
    nosudo: bool = False
    verbose: bool = False
    timeout: float = DEFAULT_TIMEOUT


def find_tests(dirs: Sequence[str]) -> list[str]:
    """The test programs under ``dirs`` (each a folder or a test file),
    sorted as ``find DIR... | sort`` sorts them."""
    found: list[str] = []
    for d in dirs:
        top = Path(d)
        if top.is_file() and top.name in TEST_NAMES:
            found.append(str(top))
            continue
        for root, subdirs, files in os.walk(top):
            subdirs.sort()
            for name in TEST_NAMES:
                if name in files:
                    found.append(os.path.join(root, name))
    return sorted(set(found))


def clean(folders: Sequence[Path]) -> None:
    """Remove what earlier runs left in the test folders."""
    for folder in folders:
        for name in RUN_FILES:
            try:
                (folder / name).unlink()
            except FileNotFoundError:
                pass
        for pattern in RUN_GLOBS:
            for path in folder.glob(pattern):
                path.unlink()


def tools_folder() -> str:
    """The folder of the running Python's console scripts."""
    return os.path.dirname(sys.executable)


def _instance_base() -> str:
    base = os.environ.get("HALSDK_INSTANCE") or f"rt{os.getpid()}"
    return base[:_INSTANCE_MAX - 5]


def environment(number: int) -> dict[str, str]:
    """The environment of the ``number``-th test of this run."""
    from halsdk.compat import program_env
    env = program_env()
    env["PATH"] = tools_folder() + os.pathsep + env.get("PATH", "")
    env["HALSDK_INSTANCE"] = f"{_instance_base()}-t{number}"
    return env


def _skipped(folder: Path, env: dict[str, str], nosudo: bool,
             timeout: float) -> Optional[str]:
    """Why the test in ``folder`` is skipped, or None to run it."""
    skip = folder / "skip"
    if skip.exists():
        if not os.access(skip, os.X_OK):
            return "disabled"
        try:
            rc = subprocess.run([str(skip.resolve())], cwd=folder, env=env,
                                stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, timeout=timeout
                                ).returncode
        except subprocess.TimeoutExpired:
            rc = 1
        if rc != 0:             # LinuxCNC's rule: a skip that succeeds runs
            return "disabled"
    control = folder / "control"
    if nosudo and control.is_file():
        for line in control.read_text(errors="replace").splitlines():
            if line.startswith("Restrictions:") and "sudo" in line:
                return "sudo"
    return None


def _command(test: Path, env: dict[str, str]) -> list[str]:
    if test.name == "test.hal":
        halrun = shutil.which("halrun", path=env["PATH"]) or "halrun"
        return [halrun, "-f", "test.hal"]
    if test.name == "test.sh":
        return ["bash", "-x", "test.sh"]
    return ["./test"]


def _pump(src: IO[bytes], files: Sequence[IO[bytes]]) -> None:
    for chunk in iter(lambda: src.read1(65536), b""):  # type: ignore[attr-defined]
        for f in files:
            f.write(chunk)
            f.flush()


def _kill(proc: subprocess.Popen) -> None:
    """End the test's whole process group: TERM, then KILL."""
    for sig, wait in ((signal.SIGTERM, 3.0), (signal.SIGKILL, 5.0)):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=wait)
            # the group may outlive its leader: one more look
            os.killpg(proc.pid, 0)
        except (subprocess.TimeoutExpired, ProcessLookupError):
            pass
        except PermissionError:
            return


def run_program(test: Path, env: dict[str, str], verbose: bool,
                timeout: float) -> Optional[int]:
    """Run one test program in its folder; its exit status, or None when
    it was killed after ``timeout`` seconds."""
    folder = test.parent
    cmd = _command(test, env)
    with open(folder / "result", "wb") as out, \
            open(folder / "stderr", "wb") as err:
        try:
            return _run_program(cmd, folder, env, verbose, timeout, out, err)
        except OSError as exc:      # ./test not executable, no bash
            err.write(f"{cmd[0]}: {exc.strerror}\n".encode())
            return 126 if isinstance(exc, PermissionError) else 127


def _run_program(cmd: list[str], folder: Path, env: dict[str, str],
                 verbose: bool, timeout: float, out: IO[bytes],
                 err: IO[bytes]) -> Optional[int]:
    if not verbose:
        proc = subprocess.Popen(cmd, cwd=folder, env=env, stdout=out,
                                stderr=err, stdin=subprocess.DEVNULL,
                                start_new_session=True)
        pumps: list[threading.Thread] = []
    else:
        proc = subprocess.Popen(cmd, cwd=folder, env=env,
                                stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE,
                                stdin=subprocess.DEVNULL,
                                start_new_session=True)
        assert proc.stdout is not None and proc.stderr is not None
        pumps = [threading.Thread(target=_pump, daemon=True, args=a)
                 for a in ((proc.stdout, [out, sys.stdout.buffer]),
                           (proc.stderr, [err, sys.stderr.buffer]))]
        for t in pumps:
            t.start()
    try:
        rc: Optional[int] = proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        _kill(proc)
        rc = None
    else:
        # children the test left running (a background halrun) end too
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
    for t in pumps:
        t.join(timeout=5)
    return rc


def _overrun(result: Path) -> bool:
    try:
        text = result.read_text(errors="replace")
    except OSError:
        return False
    return re.search(r"^overrun$", text, re.MULTILINE) is not None


def _judge(folder: Path, shown: str, timeout: float, env: dict[str, str]
           ) -> tuple[bool, str, str]:
    """(passed, reason, details) of a test whose run exited with 0."""
    checkresult = folder / "checkresult"
    if checkresult.exists():
        if not os.access(checkresult, os.X_OK):
            return False, "checkresult is not executable", ""
        try:
            proc = subprocess.run(
                [str(checkresult.resolve()), str((folder / "result").resolve())],
                cwd=folder, env=env, stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                timeout=timeout)
        except subprocess.TimeoutExpired:
            return False, f"checkresult timed out after {timeout:g} s", ""
        out = proc.stdout.decode(errors="replace")
        return (proc.returncode == 0,
                f"checkresult exited with {proc.returncode}", out)
    expected = folder / "expected"
    if expected.is_file():
        want = expected.read_bytes()
        got = (folder / "result").read_bytes()
        if want == got:
            return True, "", ""
        diff = difflib.unified_diff(
            want.decode(errors="replace").splitlines(True),
            got.decode(errors="replace").splitlines(True),
            f"{shown}/expected", f"{shown}/result")
        text = "".join(line if line.endswith("\n")
                       else line + "\n\\ No newline at end of file\n"
                       for line in diff)
        return False, "result differed from expected", text
    return False, "Neither expected nor checkresult existed", ""


def _tail(path: Path, lines: int) -> str:
    try:
        text = path.read_text(errors="replace")
    except OSError:
        return ""
    return "".join(text.splitlines(True)[-lines:])


def _halrun_cleanup(env: dict[str, str]) -> None:
    """``halrun -U``: remove the instances whose host is gone."""
    halrun = shutil.which("halrun", path=env["PATH"])
    if halrun is None:
        return
    try:
        subprocess.run([halrun, "-U"], env=env, stdin=subprocess.DEVNULL,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       timeout=30)
    except subprocess.TimeoutExpired:
        pass


def run_tests(dirs: Sequence[str], opts: Options,
              out: Optional[IO[str]] = None,
              err: Optional[IO[str]] = None) -> Summary:
    """Run the tests under ``dirs``; report on ``out`` (results) and
    ``err`` (progress)."""
    out = sys.stdout if out is None else out
    err = sys.stderr if err is None else err
    tests = find_tests(dirs)
    if not opts.noclean:
        clean(sorted({Path(t).parent for t in tests}))
    summary = Summary()
    for number, path in enumerate(tests, 1):
        # shown as find shows it (./a for a test found under .)
        shown = os.path.dirname(path)
        test = Path(path)
        folder = test.parent
        env = environment(number)
        why = _skipped(folder, env, opts.nosudo, opts.timeout)
        if why is not None:
            print(f"Skipping {why} test: {shown}", file=err, flush=True)
            summary.skipped.append(shown)
            continue
        summary.run += 1
        print(f"Running test: {shown}", file=err, flush=True)
        out.flush()
        started = time.monotonic()
        rc: Optional[int] = 0
        for _ in range(OVERRUN_TRIES if test.name == "test.hal" else 1):
            if _ != 0:
                print(f"--- {shown}: overrun detected in sampler, "
                      "re-running test", file=err, flush=True)
            rc = run_program(test, env, opts.verbose, opts.timeout)
            if rc != 0 or not _overrun(folder / "result"):
                break
        details = ""
        if rc is None:
            passed, reason = False, \
                f"test run timed out after {opts.timeout:g} s and was killed"
        elif rc != 0:
            passed, reason = False, f"test run exited with {rc}"
        else:
            passed, reason, details = _judge(folder, shown, opts.timeout, env)
        if not passed:
            _halrun_cleanup(env)
        xfail = (folder / "xfail").exists()
        if passed and xfail:
            summary.failed.append(shown)
            print(f"*** {shown}: XPASS: Passed, but was expected to fail",
                  file=out, flush=True)
        elif passed:
            if not opts.noclean:
                clean([folder])
        elif xfail:
            summary.xfailed.append(shown)
            print(f"*** {shown}: XFAIL: {reason}", file=out, flush=True)
            if not opts.noclean:
                clean([folder])
        else:
            summary.failed.append(shown)
            print(f"*** {shown}: FAIL: {reason} "
                  f"({time.monotonic() - started:.1f} s)", file=out)
            if details:
                out.write(details if details.endswith("\n")
                          else details + "\n")
            if rc != 0 and not opts.verbose:
                tail = _tail(folder / "stderr", STDERR_TAIL)
                if tail:
                    out.write(f"--- last lines of {shown}/stderr:\n{tail}")
                    if not tail.endswith("\n"):
                        out.write("\n")
            out.flush()
            if opts.stop:
                break
    return summary


def parser(prog: str = "halsdk runtests") -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=prog, description=_DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dirs", nargs="*", metavar="DIR",
                   help="folders searched for tests (recursively), or test "
                        "files; default: the current folder")
    p.add_argument("-c", "--clean", action="store_true",
                   help="only remove the files earlier runs left in the "
                        "test folders (result, stderr, *.var, *.var.bak)")
    p.add_argument("-n", "--noclean", action="store_true",
                   help="keep result and stderr of the tests that passed "
                        "(and do not remove old ones before the run)")
    p.add_argument("-s", "--stop", action="store_true",
                   help="stop after the first failed test")
    p.add_argument("-u", "--nosudo", action="store_true",
                   help="skip the tests whose 'control' file has a "
                        "'Restrictions:' line naming sudo")
    p.add_argument("-v", "--verbose", action="store_true",
                   help="show each test's stdout and stderr as it runs "
                        "(normally only written to result and stderr)")
    p.add_argument("-t", "--timeout", type=float, default=DEFAULT_TIMEOUT,
                   metavar="SECONDS",
                   help="kill a test program still running after SECONDS "
                        "and count it failed (default: %(default)g)")
    return p


def main(argv: Optional[Sequence[str]] = None) -> int:
    a = parser().parse_args(sys.argv[1:] if argv is None else list(argv))
    dirs = a.dirs or ["."]
    for d in dirs:
        if not os.path.exists(d):
            print(f"halsdk runtests: {d}: no such file or folder",
                  file=sys.stderr)
            return 2
    if a.timeout <= 0:
        print("halsdk runtests: --timeout must be positive", file=sys.stderr)
        return 2
    if a.clean:
        clean(sorted({Path(t).parent for t in find_tests(dirs)}))
        return 0
    summary = run_tests(dirs, Options(noclean=a.noclean, stop=a.stop,
                                      nosudo=a.nosudo, verbose=a.verbose,
                                      timeout=a.timeout))
    print(summary.line(), flush=True)
    if summary.failed:
        print("Failed: " + " ".join(summary.failed), flush=True)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
