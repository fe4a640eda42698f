"""The pytest plugin halsdk.testing: fixture, recording, leak check."""

from __future__ import annotations

import os

import numpy as np
import pytest

import halsdk

pytest_plugins = ["pytester"]


def test_fixture_gives_a_private_stepped_instance(hal):
    assert hal.is_host
    assert hal.instance.startswith("pytest-")
    assert os.environ["HALSDK_INSTANCE"] == hal.instance
    hal.loadrt("tlowpass")
    hal.newthread("servo", 1_000_000)
    hal.addf("tlowpass.0", "servo")
    hal.setp("tlowpass.0.tau", 0)
    trace = hal.run(4, inputs={"tlowpass.0.in": np.array([1.0, 2.0, 3.0,
                                                          4.0])},
                    record=["tlowpass.0.out", "servo.time"])
    assert isinstance(trace["tlowpass.0.out"], np.ndarray)
    assert trace["tlowpass.0.out"].dtype == np.float64
    assert trace["servo.time"].dtype == np.int32
    assert list(trace["tlowpass.0.out"]) == [1.0, 2.0, 3.0, 4.0]
    assert list(trace.time) == [1_000_000, 2_000_000, 3_000_000, 4_000_000]


def test_run_checks_its_inputs(hal):
    hal.newthread("servo", 1_000_000)
    hal.newsig("s", "s32")
    with pytest.raises(halsdk.InvalidError, match="3 values for 2 cycles"):
        hal.run(2, inputs={"s": [1, 2, 3]})
    with pytest.raises(halsdk.NotFoundError, match="'nothing'"):
        hal.run(1, record=["nothing"])
    trace = hal.run(2, inputs={"s": [5, 6]}, record=["s"])
    assert list(trace["s"]) == [5, 6]


def test_instances_differ_between_tests(hal):
    # a fresh instance: nothing from the previous tests
    assert hal.components() == [] and hal.signals() == []


def test_plugin_in_another_project(pytester):
    """The plugin works for any project, and fails a session that leaks
    an instance."""
    pytester.makepyfile(test_mine="""
        import halsdk

        def test_uses_fixture(hal):
            c = halsdk.component("mine")
            c.newpin("x", "float", "in")
            c.ready()
            hal.newthread("t", 1_000_000)
            hal.set({"mine.x": 2.5})
            assert hal.run(3, record=["mine.x"])["mine.x"].tolist() == [2.5] * 3

        def test_leaks():
            import os, halsdk.testing
            name = halsdk.testing.private_instance_name()
            halsdk.testing._created.append(halsdk.core.instance.shm_name(name))
            # simulate an instance left behind
            fd = os.open("/dev/shm" + halsdk.core.instance.shm_name(name),
                         os.O_CREAT | os.O_WRONLY, 0o600)
            os.close(fd)
            open("leaked.txt", "w").write(name)
    """)
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider")
    result.assert_outcomes(passed=2)
    assert result.ret == 1
    result.stdout.fnmatch_lines(["*HAL instances left in /dev/shm*"])
    leaked = (pytester.path / "leaked.txt").read_text()
    os.unlink("/dev/shm" + halsdk.core.instance.shm_name(leaked))


STOPPABLE_PROJECT = """
import pathlib
import time

def test_first(hal):
    hal.loadrt("and2")
    hal.newthread("servo", 1_000_000)
    hal.addf("and2.0", "servo")
    hal.start()
    pathlib.Path("started").write_text(hal.instance)
    time.sleep(60)

def test_second(hal):
    pathlib.Path("second-ran").write_text("yes")

def test_third(hal):
    pass
"""


@pytest.mark.parametrize("signame", ["SIGTERM", "SIGHUP"])
def test_a_stopped_run_ends_cleanly(tmp_path, signame):
    """SIGTERM (or a closed terminal's SIGHUP) during a test that uses the
    hal fixture stops the run as Ctrl-C does: no further test starts, no
    failure is invented, no traceback, and the instance is removed."""
    import signal
    import subprocess
    import sys
    import time

    (tmp_path / "test_stoppable.py").write_text(STOPPABLE_PROJECT)
    env = {k: v for k, v in os.environ.items() if k != "HALSDK_INSTANCE"}
    sig = getattr(signal, signame)

    def default_disposition() -> None:
        # an ignored SIGHUP (this run started under nohup) is inherited,
        # and the plugin rightly leaves an ignored signal alone
        signal.signal(sig, signal.SIG_DFL)

    proc = subprocess.Popen(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
         "test_stoppable.py"], cwd=tmp_path, env=env,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        preexec_fn=default_disposition)
    started = tmp_path / "started"
    deadline = time.monotonic() + 60
    while not started.exists() and proc.poll() is None \
            and time.monotonic() < deadline:
        time.sleep(0.05)
    assert started.exists(), proc.communicate(timeout=30)[0]
    time.sleep(0.1)             # the instance name is written: in the test
    instance = started.read_text()
    proc.send_signal(getattr(signal, signame))
    out, _ = proc.communicate(timeout=30)
    assert proc.returncode == 128 + getattr(signal, signame), out
    assert f"stopped by {signame}" in out
    assert "Traceback" not in out and "SystemExit" not in out, out
    assert "failed" not in out, out
    assert not (tmp_path / "second-ran").exists()
    assert not any(instance in n for n in os.listdir("/dev/shm")), out
