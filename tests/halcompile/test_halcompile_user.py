"""halcompile: userspace components (``option userspace``) and userspace
C programs (``halcompile -u``), started with ``loadusr`` or as child
processes attached to the test's instance."""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time

import pytest
from helpers import data_path
from helpers.halcompile import child_env, halcompile, halrun_file

from halcompile import CompError, parse
from halcompile.gen_c import generate
from halsdk.build import extension_suffix
from halsdk.errors import LoadError

COMPS = str(data_path("comps"))


@pytest.fixture(scope="module")
def progs(tmp_path_factory: pytest.TempPathFactory) -> str:
    """hcuser.comp, hcuser2.comp and hcprog.c compiled into one folder."""
    folder = str(tmp_path_factory.mktemp("hc-user"))
    for args in (["--compile", os.path.join(COMPS, "hcuser.comp"),
                  os.path.join(COMPS, "hcuser2.comp")],
                 ["--compile", "-u", os.path.join(COMPS, "hcprog.c")]):
        proc = halcompile(*args, cwd=folder)
        assert proc.returncode == 0, proc.stderr
    return folder


def wait_for(cond, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


def start(folder: str, *args: str) -> subprocess.Popen:
    """Start a launcher as a child attached to the test's instance."""
    return subprocess.Popen([os.path.join(folder, args[0]), *args[1:]],
                            cwd=folder, env=child_env(),
                            stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def ready(hal, name: str) -> bool:
    return any(c.name == name and c.ready for c in hal.components())


# ------------------------------------------------------------ the files

def test_compile_writes_module_and_executable_launcher(progs):
    for name in ("hcuser", "hcuser2", "hcprog"):
        assert os.path.isfile(os.path.join(progs, name + extension_suffix()))
        launcher = os.path.join(progs, name)
        assert os.access(launcher, os.X_OK)
        with open(launcher, encoding="utf-8") as f:
            assert f.readline() == f"#!{sys.executable}\n"


def test_launcher_without_instance_fails_cleanly(progs, tmp_path):
    proc = subprocess.run([os.path.join(progs, "hcuser")], cwd=str(tmp_path),
                          env=child_env(HALSDK_INSTANCE=f"none{os.getpid()}"),
                          capture_output=True, text=True)
    assert proc.returncode == 1
    assert "no HAL instance" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_loadrt_of_a_userspace_module_is_refused(hal, progs, monkeypatch,
                                                 capfd):
    monkeypatch.setenv("HALSDK_PATH", progs)
    with pytest.raises(LoadError, match="^hcuser: this is a userspace "
                       "component: start it with 'loadusr hcuser'$"):
        hal.loadrt("hcuser")
    assert [c.name for c in hal.components()
            if c.name.startswith("hcuser")] == []


# ------------------------------------------------------------ running

def test_userspace_comp_runs_until_sigterm_unload(hal, progs):
    child = start(progs, "hcuser", "scale=3", "names=alpha,beta")
    try:
        wait_for(lambda: ready(hal, "hcuser"))
        comp = hal.component("hcuser")
        assert comp.pid == child.pid and not comp.realtime
        assert [p.name for p in hal.pins("alpha.*")] == [
            "alpha.in", "alpha.out", "alpha.passes", "alpha.quit"]
        assert [p.name for p in hal.params("beta.*")] == ["beta.offset"]
        assert hal.getp("alpha.offset") == 0.5          # the default
        hal.setp("alpha.in", 2.0)
        hal.setp("alpha.offset", 0.25)
        hal.setp("beta.in", -1.5)
        wait_for(lambda: hal.getp("alpha.out") == 6.25
                 and hal.getp("beta.out") == -4.0)
        before = hal.getp("alpha.passes")
        wait_for(lambda: hal.getp("alpha.passes") > before + 3)
        hal.unload("hcuser")
        assert child.wait(5) == -signal.SIGTERM
        assert [c.name for c in hal.components() if c.name == "hcuser"] == []
        assert hal.pins("alpha.*") == []
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def test_programs_run_without_halcompile(hal, progs, tmp_path):
    """The runtime of a userspace program is halsdk's (halsdk.userspace):
    the program starts and runs with the compiler made unimportable."""
    blocker = tmp_path / "halcompile"
    blocker.mkdir()
    (blocker / "__init__.py").write_text(
        'raise ImportError("halcompile is not installed here")\n')
    env = child_env()
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), env["PYTHONPATH"]])
    with open(os.path.join(progs, "hcuser"), encoding="utf-8") as f:
        assert "halcompile" not in f.read().split("\n", 2)[2]
    child = subprocess.Popen([os.path.join(progs, "hcuser"), "names=solo"],
                             cwd=progs, env=env, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    try:
        wait_for(lambda: ready(hal, "hcuser") or child.poll() is not None)
        assert child.poll() is None, child.communicate()
        hal.setp("solo.in", 2.0)
        wait_for(lambda: hal.getp("solo.out") == 2.5)        # scale 1
        hal.unload("hcuser")
        assert child.wait(5) == -signal.SIGTERM
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def test_mainloop_return_ends_program_and_removes_comp(hal, progs):
    child = start(progs, "hcuser", "count=2")
    try:
        wait_for(lambda: ready(hal, "hcuser"))
        assert [p.name for p in hal.pins("hcuser.1.*")] == [
            "hcuser.1.in", "hcuser.1.out", "hcuser.1.passes",
            "hcuser.1.quit"]
        hal.setp("hcuser.1.in", 4.0)
        wait_for(lambda: hal.getp("hcuser.1.out") == 4.5)   # scale 1
        hal.setp("hcuser.1.quit", True)
        assert child.wait(5) == 0
        assert hal.pins("hcuser.*") == []
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def test_count_and_names_together_fail(hal, progs):
    proc = subprocess.run([os.path.join(progs, "hcuser"), "count=2",
                           "names=a"], cwd=progs, env=child_env(),
                          capture_output=True, text=True, timeout=20)
    assert proc.returncode == 1
    assert "count= and names= are mutually exclusive" in proc.stderr
    assert "hcuser" not in [c.name for c in hal.components()]


def test_singleton_default_count_and_argv_without_userinit(hal, progs):
    # hcuser2: singleton, no userinit; its main loop reads argc/argv
    child = start(progs, "hcuser2", "a", "bb", "count=9")
    try:
        wait_for(lambda: ready(hal, "hcuser2"))
        # a singleton keeps count= in its command line (as the
        # reference's do): argv is ["hcuser2", "a", "bb", "count=9"]
        wait_for(lambda: hal.getp("hcuser2.nargs") == 4)
        assert hal.getp("hcuser2.arglen") == 1 + 2 + 7
        hal.setp("hcuser2.stop", True)
        assert child.wait(5) == 0
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def test_loadusr_from_halrun_file(progs, tmp_path):
    hal_file = tmp_path / "user.hal"
    hal_file.write_text(
        "loadusr -W hcuser scale=3 names=alpha\n"
        "setp alpha.in 2\n"
        "setp alpha.offset 0.25\n"
        "loadusr -w sleep 0.3\n"
        "getp alpha.out\n"
        "unload hcuser\n"
        "loadusr -Wn hcprog hcprog 2.5\n"
        "setp hcprog.in 4\n"
        "loadusr -w sleep 0.3\n"
        "getp hcprog.out\n"
        "unloadusr hcprog\n"
        "show comp\n")
    proc = halrun_file(hal_file, tmp_path,
                       PATH=progs + os.pathsep + os.environ["PATH"],
                       HALSDK_INSTANCE=f"hcuser{os.getpid()}")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0] == "6.25"
    assert lines[1] == "10"
    # only halcmd itself is left
    comps = [ln.split()[2] for ln in lines[2:]
             if ln.strip()[:1].isdigit()]
    assert len(comps) == 1 and comps[0].startswith("halcmd")


def test_loadusr_finds_launchers_on_halsdk_path(progs, tmp_path):
    """A compiled userspace component in a HALSDK_PATH folder starts by
    name, with no PATH set-up."""
    hal_file = tmp_path / "user.hal"
    hal_file.write_text("loadusr -W hcuser scale=2 names=beta\n"
                        "setp beta.in 1.5\n"
                        "loadusr -w sleep 0.3\n"
                        "getp beta.out\n"
                        "unload hcuser\n")
    assert progs not in os.environ["PATH"].split(os.pathsep)
    proc = halrun_file(hal_file, tmp_path, HALSDK_PATH=progs,
                       HALSDK_INSTANCE=f"hcpath{os.getpid()}")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines()[0] == "3.5"      # 1.5 * 2 + offset


def test_userspace_program_exit_status(hal, progs):
    proc = subprocess.run([os.path.join(progs, "hcprog"), "fail"],
                          cwd=progs, env=child_env(), capture_output=True,
                          text=True, timeout=20)
    assert proc.returncode == 3
    child = start(progs, "hcprog", "-2")
    try:
        wait_for(lambda: ready(hal, "hcprog"))
        hal.setp("hcprog.in", 1.25)
        wait_for(lambda: hal.getp("hcprog.out") == -2.5)
        # its own SIGTERM handler: leaves the loop, hal_exit, status 0
        hal.unload("hcprog")
        assert child.wait(5) == 0
        assert hal.pins("hcprog.*") == []
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def test_install_writes_launcher_to_user_bin(hal, tmp_path):
    data, bin_dir = tmp_path / "data", tmp_path / "bin"
    proc = halcompile("--install", os.path.join(COMPS, "hcuser.comp"),
                      cwd=str(tmp_path), XDG_DATA_HOME=str(data),
                      XDG_BIN_HOME=str(bin_dir))
    assert proc.returncode == 0, proc.stderr
    comp_dir = data / "halsdk" / "components"
    assert (comp_dir / ("hcuser" + extension_suffix())).is_file()
    assert os.access(comp_dir / "hcuser", os.X_OK)
    assert os.access(bin_dir / "hcuser", os.X_OK)
    # found by name on PATH, from anywhere
    child = subprocess.Popen(
        ["hcuser", "names=inst"], cwd=str(tmp_path),
        env=child_env(PATH=str(bin_dir) + os.pathsep + os.environ["PATH"]))
    try:
        wait_for(lambda: ready(hal, "hcuser"))
        assert hal.component("hcuser").pid == child.pid
        hal.setp("inst.quit", True)
        assert child.wait(5) == 0
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


# ------------------------------------------------------------ the language

HEAD = 'component x;\nlicense "GPL";\noption userspace yes;\npin out s32 c;\n'


def test_userspace_rules():
    with pytest.raises(CompError) as info:
        parse(HEAD + "function f;\n;;\nvoid user_mainloop(void) {}\n",
              "x.comp")
    assert str(info.value.loc) == "x.comp:3:8"
    assert "may not have functions" in info.value.message
    with pytest.raises(CompError) as info:
        parse(HEAD + ";;\nint main(void) { return 0; }\n", "x.comp")
    assert "user_mainloop" in info.value.message
    with pytest.raises(CompError) as info:
        parse(HEAD + "option userinit yes;\n;;\nvoid user_mainloop(void)"
              " {}\n", "x.comp")
    assert str(info.value.loc) == "x.comp:5:8"
    assert "userinit" in info.value.message
    # userinit without userspace: ignored (as the reference does)
    comp = parse('component y;\nlicense "GPL";\npin out s32 c;\n'
                 'option userinit yes;\n;;\nc = 1;\n', "y.comp")
    assert comp.option("userinit") is False
    assert "userinit" not in generate(comp)


def test_generated_userspace_c():
    comp = parse(HEAD + "option userinit yes;\n;;\nvoid userinit(int argc, "
                 "char **argv) {}\nvoid user_mainloop(void) {}\n", "x.comp")
    text = generate(comp)
    assert "user_mainloop();" in text and "userinit(argc, argv);" in text
    assert "hal_export_funct" not in text
    assert "RTAPI_MP_INT(count" not in text     # count comes from argv


def _normalize(text: str) -> str:
    """Component ids and process ids differ from run to run."""
    text = re.sub(r"halcmd\d+ +\d+", "halcmdPID PID", text)
    return re.sub(r"(?m)^( +)\d+(  )", lambda m: m.group(1) + "N" +
                  m.group(2), text)


def test_same_output_as_the_reference(progs, tmp_path):
    """hcuser_run.hal (the userspace comps and program, loaded, set,
    read and unloaded) prints what the reference's halrun printed with
    the same files built by its halcompile (hcuser_run.out)."""
    with open(os.path.join(COMPS, "hcuser_run.hal"), encoding="utf-8") as f:
        script = f.read()
    with open(os.path.join(COMPS, "hcuser_run.out"), encoding="utf-8") as f:
        golden = f.read()
    for name in ("hcuser", "hcuser2", "hcprog"):
        for file in (name, name + extension_suffix()):
            shutil.copy2(os.path.join(progs, file), tmp_path / file)
    (tmp_path / "run.hal").write_text(script)
    proc = halrun_file("run.hal", tmp_path,
                       HALSDK_INSTANCE=f"hcref{os.getpid()}")
    assert proc.returncode == 0, proc.stderr
    assert _normalize(proc.stdout) == _normalize(golden)
