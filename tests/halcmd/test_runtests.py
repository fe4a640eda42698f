"""``halsdk runtests``: the runner of LinuxCNC-format test folders.

The unit tests build small test folders in ``tmp_path`` and run the
installed ``halsdk`` console script on them; the last test runs every
folder of ``tests/lcnc-format`` (the same folders give the same result
with the reference: ``tests/lcnc-format/run-reference.sh``).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import repo_path
from helpers.docblocks import code_blocks

HALSDK = os.path.join(os.path.dirname(sys.executable), "halsdk")
SUMMARY = re.compile(r"^Runtest: (\d+) tests run, (\d+) successful, "
                     r"(\d+) failed \+ (\d+) expected, (\d+) skipped$",
                     re.MULTILINE)


def runtests(*args: str, cwd: Path, timeout: float = 300
             ) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env["HALSDK_INSTANCE"] = f"rt-{os.getpid()}"
    return subprocess.run([HALSDK, "runtests", *args], cwd=cwd, env=env,
                          stdin=subprocess.DEVNULL, capture_output=True,
                          text=True, timeout=timeout)


def counts(proc: subprocess.CompletedProcess) -> tuple[int, ...]:
    m = SUMMARY.search(proc.stdout)
    assert m, proc.stdout + proc.stderr
    return tuple(int(g) for g in m.groups())


def folder(root: Path, name: str, files: dict[str, str],
           executable: tuple[str, ...] = ("checkresult", "skip", "test")
           ) -> Path:
    d = root / name
    d.mkdir(parents=True)
    for fname, text in files.items():
        (d / fname).write_text(text)
        if fname in executable:
            (d / fname).chmod(0o755)
    return d


PASSING_HAL = {"test.hal": "loadrt and2\nsetp and2.0.in0 1\n"
                           "getp and2.0.in0\n",
               "expected": "TRUE\n"}


def test_help_names_the_options(tmp_path: Path) -> None:
    proc = runtests("--help", cwd=tmp_path)
    assert proc.returncode == 0
    for opt in ("-c", "-n", "-s", "-u", "-v", "--timeout", "checkresult",
                "expected", "skip", "xfail"):
        assert opt in proc.stdout, opt
    top = subprocess.run([HALSDK, "--help"], capture_output=True, text=True,
                         cwd=tmp_path)
    assert "runtests" in top.stdout


def test_passing_tests_are_counted_and_cleaned(tmp_path: Path) -> None:
    a = folder(tmp_path, "a", PASSING_HAL)
    folder(tmp_path, "sub/b", {
        "test.sh": "echo hello\necho to-stderr >&2\n",
        "expected": "hello\n"})
    proc = runtests(".", cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert counts(proc) == (2, 2, 0, 0, 0)
    assert "Running test: ./a" in proc.stderr
    assert "Running test: ./sub/b" in proc.stderr
    assert not (a / "result").exists()      # cleaned after a pass
    # -n keeps result and stderr
    proc = runtests("-n", "sub", cwd=tmp_path)
    assert counts(proc) == (1, 1, 0, 0, 0)
    assert (tmp_path / "sub/b/result").read_text() == "hello\n"
    assert "to-stderr" in (tmp_path / "sub/b/stderr").read_text()
    # -c removes them
    assert runtests("-c", ".", cwd=tmp_path).returncode == 0
    assert not (tmp_path / "sub/b/result").exists()
    assert not (tmp_path / "sub/b/stderr").exists()


def test_failure_shows_the_diff_and_exits_1(tmp_path: Path) -> None:
    folder(tmp_path, "bad", {"test.hal": "loadrt and2\ngetp and2.0.in0\n",
                             "expected": "TRUE\n"})
    folder(tmp_path, "good", PASSING_HAL)
    proc = runtests(".", cwd=tmp_path)
    assert proc.returncode == 1
    assert counts(proc) == (2, 1, 1, 0, 0)
    out = proc.stdout
    assert "*** ./bad: FAIL: result differed from expected" in out
    assert "--- ./bad/expected" in out and "+++ ./bad/result" in out
    assert "-TRUE\n+FALSE\n" in out
    assert "Failed: ./bad" in out
    # a failed test keeps its files
    assert (tmp_path / "bad/result").read_text() == "FALSE\n"


def test_exit_status_of_the_run_fails_the_test(tmp_path: Path) -> None:
    folder(tmp_path, "err", {"test.hal": "loadrt nosuchcomp_rt\n",
                             "expected": ""})
    proc = runtests(".", cwd=tmp_path)
    assert proc.returncode == 1
    assert "*** ./err: FAIL: test run exited with 1" in proc.stdout
    assert "nosuchcomp_rt" in proc.stdout       # the stderr tail is shown


def test_checkresult_judges_instead_of_expected(tmp_path: Path) -> None:
    check = ('#!/bin/sh\n'
             'v=$(cat "$1")\n'
             'test "$v" -ge 3 && test "$v" -le 5\n')
    folder(tmp_path, "ok", {"test.sh": "echo 4\n", "checkresult": check,
                            "expected": "not used\n"})
    folder(tmp_path, "no", {"test.sh": "echo 9\n", "checkresult": check})
    folder(tmp_path, "neither", {"test.sh": "echo 9\n"})
    proc = runtests(".", cwd=tmp_path)
    assert counts(proc) == (3, 1, 2, 0, 0)
    assert "*** ./no: FAIL: checkresult exited with 1" in proc.stdout
    assert ("*** ./neither: FAIL: Neither expected nor checkresult existed"
            in proc.stdout)
    assert "./ok" not in proc.stdout


def test_skip_and_xfail(tmp_path: Path) -> None:
    folder(tmp_path, "off", {**PASSING_HAL, "skip": "not on this machine\n"},
           executable=())
    # an executable skip decides at run time: it fails to skip the test
    folder(tmp_path, "skipnow", {**PASSING_HAL,
                                 "skip": "#!/bin/sh\nexit 1\n"})
    folder(tmp_path, "runnow", {**PASSING_HAL,
                                "skip": "#!/bin/sh\nexit 0\n"})
    folder(tmp_path, "xf", {"test.sh": "echo no\n", "expected": "yes\n",
                            "xfail": ""})
    proc = runtests(".", cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout
    assert counts(proc) == (2, 1, 0, 1, 2)
    assert "Skipping disabled test: ./off" in proc.stderr
    assert "Skipping disabled test: ./skipnow" in proc.stderr
    assert "*** ./xf: XFAIL: result differed from expected" in proc.stdout
    # an expected failure that passes is a failure
    (tmp_path / "xf/expected").write_text("no\n")
    proc = runtests("xf", cwd=tmp_path)
    assert proc.returncode == 1
    assert "*** xf: XPASS: Passed, but was expected to fail" in proc.stdout
    assert counts(proc) == (1, 0, 1, 0, 0)


def test_nosudo_skips_tests_restricted_to_sudo(tmp_path: Path) -> None:
    folder(tmp_path, "root", {**PASSING_HAL,
                              "control": "Restrictions: sudo\n"})
    assert counts(runtests(".", cwd=tmp_path)) == (1, 1, 0, 0, 0)
    assert counts(runtests("-u", ".", cwd=tmp_path)) == (0, 0, 0, 0, 1)


def test_timeout_kills_a_hanging_test_and_the_next_runs(tmp_path: Path
                                                        ) -> None:
    # a halrun host that never ends: its instance is left for halrun -U
    folder(tmp_path, "a-hang", {"test.hal": "loadrt and2\n"
                                            "loadusr -w sleep 1000\n",
                                "expected": ""})
    folder(tmp_path, "b-next", PASSING_HAL)
    started = time.monotonic()
    proc = runtests("-t", "3", ".", cwd=tmp_path, timeout=120)
    assert time.monotonic() - started < 60
    assert proc.returncode == 1
    assert counts(proc) == (2, 1, 1, 0, 0)
    assert "*** ./a-hang: FAIL: test run timed out after 3 s" in proc.stdout
    left = [n for n in os.listdir("/dev/shm") if f"rt-{os.getpid()}-" in n]
    assert left == []


def test_stop_after_the_first_failure(tmp_path: Path) -> None:
    folder(tmp_path, "a", {"test.sh": "echo x\n", "expected": "y\n"})
    folder(tmp_path, "b", PASSING_HAL)
    proc = runtests("-s", ".", cwd=tmp_path)
    assert counts(proc) == (1, 0, 1, 0, 0)
    assert "./b" not in proc.stderr


def test_verbose_shows_the_output(tmp_path: Path) -> None:
    folder(tmp_path, "v", {"test.sh": "echo shown-out\necho shown-err >&2\n",
                           "expected": "shown-out\n"})
    proc = runtests("-v", ".", cwd=tmp_path)
    assert proc.returncode == 0
    assert "shown-out" in proc.stdout
    assert "shown-err" in proc.stderr


def test_environment_of_a_test(tmp_path: Path) -> None:
    """Our tools first on PATH, the compat hal module importable, and a
    private instance derived from HALSDK_INSTANCE."""
    script = ('command -v halrun\n'
              'echo "$HALSDK_INSTANCE"\n'
              'python3 -c "import hal; print(hal.__name__)"\n')
    folder(tmp_path, "env", {"test.sh": script, "checkresult": "#!/bin/sh\n"
                             "exit 0\n"})
    proc = runtests("-n", ".", cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    lines = (tmp_path / "env/result").read_text().splitlines()
    assert lines[0] == os.path.join(os.path.dirname(sys.executable),
                                    "halrun")
    assert lines[1] == f"rt-{os.getpid()}-t1"
    assert lines[2] == "halsdk.compat.hal"


def test_bad_usage(tmp_path: Path) -> None:
    assert runtests("no/such/dir", cwd=tmp_path).returncode == 2
    assert runtests("-t", "0", ".", cwd=tmp_path).returncode == 2
    proc = runtests(".", cwd=tmp_path)       # no tests: nothing failed
    assert proc.returncode == 0
    assert counts(proc) == (0, 0, 0, 0, 0)


def test_the_documented_example_runs(tmp_path: Path) -> None:
    """docs/runtests.rst: the folder it shows passes."""
    page = repo_path("docs", "runtests.rst")
    hal = code_blocks(page, "none")[0]
    expected = code_blocks(page, "text")[0]
    folder(tmp_path, "and2-truth", {"test.hal": hal, "expected": expected})
    proc = runtests(".", cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert counts(proc) == (1, 1, 0, 0, 0)


@pytest.mark.slow
def test_lcnc_format_folders_pass(tmp_path: Path) -> None:
    """Every folder of tests/lcnc-format passes (run on a copy, so that the
    checkout gets no result files; the copy keeps the checkout's layout
    for the example Modbus simulator the mb2hal tests start)."""
    import shutil
    shutil.copytree(repo_path("tests", "lcnc-format"),
                    tmp_path / "tests" / "lcnc-format", symlinks=True)
    shutil.copytree(repo_path("examples", "modbus"),
                    tmp_path / "examples" / "modbus", symlinks=True)
    # two runs side by side, half of the folders each (every test has
    # an instance of its own and the Modbus ones a free port): the
    # suite's longest test on a 2-core machine
    root = tmp_path / "tests"
    names = sorted(d.name for d in (root / "lcnc-format").iterdir()
                   if d.is_dir() and d.name != "lib")
    procs = []
    for k in range(2):
        env = dict(os.environ)
        env["HALSDK_INSTANCE"] = f"rt-{os.getpid()}-{k}"
        procs.append(subprocess.Popen(
            [HALSDK, "runtests",
             *(f"lcnc-format/{n}" for n in names[k::2])],
            cwd=root, env=env, stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))
    totals = [0] * 5
    for proc in procs:
        out, err = proc.communicate(timeout=1200)
        done = subprocess.CompletedProcess(proc.args, proc.returncode,
                                           out, err)
        assert proc.returncode == 0, out[-6000:]
        totals = [a + b for a, b in zip(totals, counts(done))]
    run, ok, failed, _xfailed, _skipped = totals
    assert failed == 0
    assert run == ok >= 40
