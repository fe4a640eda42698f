"""Tests of the HAL language executor and the halcmd/halrun programs.

The differential corpus (``tests/data/halfiles``, the reference's
recorded outputs) is run by ``tests/golden/test_halcmd_golden.py``.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from helpers.halrun import halcmd_env as _env
from helpers.halrun import run_cli as _cli
from helpers.halrun import shm_left as _shm_left

from halsdk import halcmd
from halsdk.core import _core
from halsdk.halcmd import CommandRunner, logical_lines, parse_value, tokenize
from halsdk.halcmd.lexer import IniFile, SubstitutionError

# ---------------------------------------------------------------- lexer

def test_logical_lines_join_continuations_and_report_last_line():
    lines = ["a \\\n", "  b\n", "c\\\n", "d\n", "e"]
    assert list(logical_lines(lines)) == [(2, "a   b"), (4, "cd"), (5, "e")]


def test_tokenize_comments_quotes_and_substitution(monkeypatch, tmp_path):
    monkeypatch.setenv("HCT_X", "val")
    ini_path = tmp_path / "m.ini"
    ini_path.write_text("[AXIS_0]\nSCALE = 2.5\nSCALE = 9\n[E]\nK=v w\n")
    ini = IniFile(str(ini_path))
    assert tokenize('setp "a b" 1 # c "d"', ini) == ['setp', '"a b"', "1"]
    # substituted before the split, as in the reference: a value with a
    # blank makes two words unless the line quotes it
    assert tokenize("x$HCT_X $(HCT_X)y [AXIS_0]SCALE [E](K) '[E]K'",
                    ini) == ["xval", "valy", "2.5", "v", "w", "'v w'"]
    assert tokenize("a 'b # c' \"d\" e#f", ini) == ["a", "'b # c'", '"d"',
                                                    "e"]
    with pytest.raises(SubstitutionError, match="unterminated quoted"):
        tokenize("loadrt and2 names='a,b", ini)
    with pytest.raises(SubstitutionError, match="Environment variable "
                       "'HCT_NOPE' not found."):
        tokenize("a $HCT_NOPE", ini)
    with pytest.raises(SubstitutionError, match=r"Ini variable '\[E\]Z'"):
        tokenize("a [E]Z", ini)
    with pytest.raises(SubstitutionError):
        tokenize("a [E]K", None)        # no -i file given


@pytest.mark.parametrize("t, text, value", [
    (_core.BIT, "1", True), (_core.BIT, "true", True),
    (_core.BIT, "FALSE", False), (_core.S32, "0x10", 16),
    (_core.S32, "010", 8), (_core.S32, "-0x10", -16),
    (_core.S32, "4294967295", -1), (_core.U32, "-1", 0xFFFFFFFF),
    (_core.FLOAT, "1e3", 1000.0), (_core.FLOAT, "-.5", -0.5),
    (_core.FLOAT, "0x1p4", 16.0),
])
def test_parse_value_follows_c_rules(t, text, value):
    assert parse_value(t, text) == value


@pytest.mark.parametrize("t, text", [
    (_core.BIT, "2"), (_core.BIT, "yes"), (_core.S32, "1.5"),
    (_core.S32, "08"), (_core.FLOAT, "abc"), (_core.FLOAT, "1_0"),
    (_core.U32, ""),
])
def test_parse_value_rejects(t, text):
    with pytest.raises(ValueError):
        parse_value(t, text)


# ---------------------------------------------------------------- executor

class _Capture:
    def __init__(self):
        self.out: list[str] = []
        self.err: list[str] = []

    def executor(self, hal, **kw) -> CommandRunner:
        return CommandRunner(hal, out=self.out.append, err=self.err.append, **kw)


def test_executor_in_process(hal, tmp_path):
    cap = _Capture()
    ex = cap.executor(hal)
    assert _core.find("component", f"halcmd{os.getpid()}").ready
    f = tmp_path / "x.hal"
    f.write_text("newsig s s32\nsets s 0x20\ngets s\nnewsig s bit\n"
                 "gets s\n")
    assert ex.run_file(str(f)) == 1
    assert "".join(cap.out) == "32\n"           # stopped at line 4
    assert cap.err == ["HAL: ERROR: duplicate signal 's'\n",
                       f"{f}:4: newsig failed\n"]
    assert hal.gets("s") == 32
    ex.unregister()
    assert _core.find("component", f"halcmd{os.getpid()}") is None


def test_executor_keep_going_counts_failures(hal, tmp_path):
    cap = _Capture()
    ex = cap.executor(hal, keep_going=True, register=False)
    f = tmp_path / "k.hal"
    f.write_text("bogus\nnewsig a bit\nsets a 2\nsets a 1\ngets a\n")
    assert ex.run_file(str(f)) == 2
    assert cap.err == [f"{f}:1: Unknown command 'bogus'\n",
                       f"{f}:3: value '2' invalid for bit\n",
                       f"{f}:3: sets failed\n"]
    assert cap.out == ["TRUE\n"]


def test_net_is_not_half_applied(hal):
    """Unlike the reference, a failing net changes nothing."""
    hal.loadrt("and2", count=2)
    cap = _Capture()
    ex = cap.executor(hal, register=False)
    assert not ex.run_line("net x and2.0.out and2.1.out")
    assert cap.err[-1] == "link failed\n"
    assert _core.find("signal", "x") is None
    assert hal.pin("and2.0.out").signal is None


def test_python_helpers(hal, tmp_path):
    f = tmp_path / "p.hal"
    f.write_text("newsig a float\nsets a 1.25\n")
    assert halcmd.source(hal, str(f)) == 0
    assert hal.gets("a") == 1.25
    out: list[str] = []
    assert halcmd.command(hal, "gets a", out=out.append)
    assert out == ["1.25\n"]
    assert not halcmd.command(hal, "gets nosuch", err=out.append)
    assert out[-1] == "signal 'nosuch' not found\n"


def test_verbose_lines(hal):
    hal.loadrt("and2")
    cap = _Capture()
    ex = cap.executor(hal, register=False, verbose=1)
    assert ex.run_line("net a and2.0.out")
    assert ex.run_line("setp and2.0.in0 1")
    assert cap.out == ["Pin 'and2.0.out' linked to signal 'a'\n",
                       "setting parameter 'and2.0.in0' to '1'\n",
                       "Pin 'and2.0.in0' set to 1\n"]


# ---------------------------------------------------------------- programs

def test_halcmd_attaches_to_running_instance(hal, tmp_path):
    env = dict(os.environ)          # HALSDK_INSTANCE is the fixture's
    proc = _cli(["halcmd", "loadrt", "and2"], tmp_path, env)
    assert proc.returncode == 0, proc.stdout
    assert hal.component("and2").ready
    proc = _cli(["halcmd", "-s", "show", "pin", "and2.0.out"], tmp_path,
                env)
    assert proc.stdout == "and2 bit   OUT FALSE and2.0.out\n\n"
    f = tmp_path / "c.hal"
    f.write_text("setp and2.0.in0 1\ngetp and2.0.in0\nbogus\n")
    proc = _cli(["halcmd", "-f", "c.hal"], tmp_path, env)
    assert proc.returncode == 1
    assert proc.stdout == "TRUE\nc.hal:3: Unknown command 'bogus'\n"
    proc = _cli(["halcmd", "getp", "nosuch"], tmp_path, env)
    assert (proc.returncode, proc.stdout) == (
        1, "pin or parameter 'nosuch' not found\n")
    # the halcmd components of the finished processes are gone
    assert [c.name for c in hal.components("halcmd*")] == []


def test_halcmd_reads_stdin(hal, tmp_path):
    proc = _cli(["halcmd", "-f"], tmp_path, dict(os.environ),
                stdin="newsig a s32\nsets a 5\ngets a\nnewsig a s32\n")
    assert proc.returncode == 1
    assert proc.stdout == ("5\nHAL: ERROR: duplicate signal 'a'\n"
                           "<stdin>:4: newsig failed\n")


def test_halcmd_without_instance_fails(tmp_path):
    env = _env(tmp_path, "none")
    proc = _cli(["halcmd", "show"], tmp_path, env)
    assert proc.returncode != 0
    assert "halrun" in proc.stdout
    assert _shm_left(env) == []


def test_tcl_is_not_supported(tmp_path):
    env = _env(tmp_path, "tcl")
    for prog in ("halcmd", "halrun"):
        proc = _cli([prog, "-T"], tmp_path, env)
        assert proc.returncode != 0
        assert "not supported" in proc.stdout


def test_halrun_interactive_and_cleanup(tmp_path):
    env = _env(tmp_path, "inter")
    proc = _cli(["halrun"], tmp_path, env,
                stdin="newsig a bit\nbogus\nsets a 1\ngets a\nquit\n"
                      "gets a\n")
    # the prompt goes on after an error, as the reference's does
    assert proc.stdout == "<stdin>:2: Unknown command 'bogus'\nTRUE\n"
    assert _shm_left(env) == []
    (tmp_path / "i.hal").write_text("newsig b u32\nsets b 7\n")
    proc = _cli(["halrun", "-I", "-f", "i.hal"], tmp_path, env,
                stdin="gets b\n")
    assert (proc.returncode, proc.stdout) == (0, "7\n")
    proc = _cli(["halrun", "i.hal"], tmp_path, env)    # file without -f
    assert (proc.returncode, proc.stdout) == (0, "")
    proc = _cli(["halrun", "-U"], tmp_path, env)
    assert proc.returncode == 0
    assert _shm_left(env) == []


def test_halrun_refuses_a_second_instance(hal, tmp_path):
    proc = _cli(["halrun", "-f", "/dev/null"], tmp_path, dict(os.environ))
    assert proc.returncode != 0
    assert "halrun -U" in proc.stdout
    assert hal.info()       # the running instance is untouched


def test_halrun_takes_over_after_a_crashed_host(tmp_path):
    # a batch of HAL files run one after another: one host dies hard, the
    # next halrun says so in one line and goes on, no 'halrun -U' needed
    env = _env(tmp_path, "crash")
    crashed = subprocess.Popen([sys.executable, "-m", "halsdk.halcmd.cli",
                                "halrun"], cwd=tmp_path, env=env,
                               stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True)
    try:
        crashed.stdin.write("newsig a bit\nloadrt threads\nstart\n"
                            "sets a 1\ngets a\n")
        crashed.stdin.flush()
        assert crashed.stdout.readline() == "TRUE\n"
    finally:
        crashed.kill()
        crashed.wait(10)
        crashed.stdin.close()
        crashed.stdout.close()
    assert _shm_left(env) != []
    (tmp_path / "next.hal").write_text("newsig b u32\nsets b 7\ngets b\n"
                                       "list sig\n")
    proc = _cli(["halrun", "-f", "next.hal"], tmp_path, env)
    assert proc.returncode == 0, proc.stdout
    assert proc.stdout.splitlines()[0] == (
        f"halsdk: HAL instance '{env['HALSDK_INSTANCE']}': its host (pid "
        f"{crashed.pid}) is gone; taking the instance over")
    # a fresh instance: the dead host's signal 'a' is not there
    assert proc.stdout.splitlines()[1:] == ["7", "b "]
    assert _shm_left(env) == []


def test_missing_file_and_bad_option(tmp_path):
    env = _env(tmp_path, "opt")
    proc = _cli(["halrun", "-f", "nosuch.hal"], tmp_path, env)
    assert proc.returncode == 1
    assert proc.stdout == ("Could not open hal file 'nosuch.hal': "
                           "No such file or directory\n")
    proc = _cli(["halcmd", "-z"], tmp_path, env)
    assert proc.returncode != 0 and "unknown option -z" in proc.stdout
    assert _shm_left(env) == []


def test_loadusr_waits_for_ready_and_unloadusr(tmp_path):
    (tmp_path / "ucomp.py").write_text(
        "import time\nimport halsdk\n"
        "c = halsdk.component('ucomp')\nc.newpin('x', 's32', 'out')\n"
        "c['x'] = 42\nc.ready()\ntime.sleep(60)\n")
    (tmp_path / "u.hal").write_text(
        f"loadusr -Wn ucomp {sys.executable} ucomp.py\n"
        "list comp\ngetp ucomp.x\nunloadusr ucomp\nlist comp\n"
        f"loadusr -W {sys.executable} -c pass\n")
    env = _env(tmp_path, "usr")
    proc = _cli(["halrun", "-f", "u.hal"], tmp_path, env)
    lines = proc.stdout.splitlines()
    assert lines[0].startswith("ucomp halcmd")
    assert lines[1] == "42"
    assert lines[2] == f"halcmd{lines[2][6:-1]} "     # ucomp is gone
    assert lines[3] == (f"u.hal:6: {sys.executable} exited without "
                        "becoming ready")
    assert proc.returncode == 1
    assert _shm_left(env) == []


def test_loadusr_says_what_it_waits_for(tmp_path):
    """A -W wait for a component that never comes is not silent: after
    2 s it names the component and adds dots, as the reference does."""
    (tmp_path / "w.hal").write_text("loadusr -W sleep 3\n")
    env = _env(tmp_path, "wait")
    proc = _cli(["halrun", "-f", "w.hal"], tmp_path, env)
    first, second = proc.stdout.splitlines()[:2]
    assert first.startswith("Waiting for component 'sleep' to become "
                            "ready.")
    assert set(first.rpartition("ready")[2]) == {"."}
    assert second == "w.hal:1: sleep exited without becoming ready"
    assert proc.returncode == 1
    assert _shm_left(env) == []


def test_save_to_file_matches_stdout_and_reloads(hal, tmp_path):
    hal.loadrt("and2", count=2)
    cap = _Capture()
    ex = cap.executor(hal, register=False)
    for line in ("net a and2.0.out => and2.1.in0", "setp and2.0.tmax 3",
                 "alias pin and2.1.in1 b1", f"save all {tmp_path}/s.hal",
                 "save all"):
        assert ex.run_line(line), cap.err
    saved = (tmp_path / "s.hal").read_text()
    assert saved == "".join(cap.out)
    assert "net a and2.0.out => and2.1.in0\n" in saved
    assert "setp and2.0.tmax            3\n" in saved
    assert "alias pin and2.1.in1 b1\n" in saved
    # the saved nets and values rebuild the configuration elsewhere
    hal.delsig("a")
    hal.setp("and2.0.tmax", 0)
    tail = saved[saved.index("# signals"):]
    (tmp_path / "r.hal").write_text(tail)
    assert ex.run_file(str(tmp_path / "r.hal")) == 0, cap.err
    assert hal.pin("and2.1.in0").signal.name == "a"
    assert hal.getp("and2.0.tmax") == 3
    assert not ex.run_line("save all /nonexistent/dir/x.hal")
    assert cap.err[-1].startswith("Can't open 'save' destination")


def test_status_mem_counts(hal):
    hal.loadrt("and2")
    hal.newsig("s", "bit")
    cap = _Capture()
    ex = cap.executor(hal, register=False)
    assert ex.run_line("status mem")
    text = "".join(cap.out)
    assert text.startswith("HAL memory status\n  used/total shared memory:")
    assert "  active/recycled signals:    1/0\n" in text
    assert f"  active/recycled pins:       {len(hal.pins())}/0\n" in text


def test_completions(hal):
    from halsdk.halcmd.cli import _completions
    hal.loadrt("and2")
    assert _completions(hal, "ne", True) == ["net", "newinst", "newsig"]
    assert _completions(hal, "and2.0.i", False) == ["and2.0.in0", "and2.0.in1"]


def test_help_lists_every_command(hal):
    from halsdk.halcmd.commands import ARG_COUNTS
    cap = _Capture()
    ex = cap.executor(hal, register=False)
    assert ex.run_line("help")
    listed = "".join(cap.out).split()
    assert set(ARG_COUNTS) <= set(listed)
    cap.out.clear()
    assert ex.run_line("help net")
    assert cap.out[0].startswith("net SIGNAL PIN")
    assert not ex.run_line("help nosuch")
    assert cap.err[-1] == "No help for unknown command 'nosuch'\n"


def test_save_comp_has_load_args_of_another_process(hal, tmp_path):
    """The host keeps every load's parameters, so a halcmd that did not do
    the load still saves them."""
    hal.loadrt("and2", "count=2")
    assert hal.loadrt_args() == {"and2": "count=2 "}
    env = dict(os.environ)
    proc = subprocess.run([sys.executable, "-m", "halsdk.halcmd.cli",
                           "halcmd", "save", "comp"], env=env, cwd=tmp_path,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "loadrt and2 count=2" in proc.stdout
