"""Without mosquitto, only the MQTT tests stop, and they are skipped with
the reason and the install command; in CI (``CI`` set) a missing broker
is a failure (issue 22: ``pytest`` gave 9 errors on a fresh machine)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import REPO, repo_path

PLUGIN = '''\
import halsdk.drivers.mqtt.broker as broker


def _missing():
    raise RuntimeError("mosquitto not found (install the Debian package "
                       "'mosquitto'): the MQTT tests and bench need a "
                       "local broker")


broker.find_mosquitto = _missing
'''

TESTS = ["tests/drivers/test_mqtt.py::test_publish_on_change",
         "tests/drivers/test_mqtt.py::test_subscribe_drives_pins",
         "tests/drivers/test_liveness_drivers.py::"
         "test_mqtt_bridge_publishes_offline_and_ends_when_host_is_sigkilled"]


def run_without_mosquitto(tmp_path: Path, ci: str | None
                          ) -> subprocess.CompletedProcess:
    (tmp_path / "no_mosquitto.py").write_text(PLUGIN)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(tmp_path), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env.pop("CI", None)
    if ci is not None:
        env["CI"] = ci
    # run from tmp_path: "python -m" puts its folder first on sys.path,
    # and the checkout's unbuilt halsdk must not hide the installed one
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no_mosquitto", "-rs",
         "-p", "no:cacheprovider", "-c", str(REPO / "pyproject.toml"),
         "--rootdir", str(REPO), *[str(REPO / t) for t in TESTS]],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)


def test_the_tests_named_here_exist() -> None:
    for test in TESTS:
        path, name = test.split("::")
        assert f"def {name}(" in repo_path(path).read_text(), test


@pytest.mark.slow
def test_without_mosquitto_the_mqtt_tests_are_skipped(tmp_path: Path
                                                      ) -> None:
    proc = run_without_mosquitto(tmp_path, None)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0, out
    assert f"{len(TESTS)} skipped" in out, out
    assert "error" not in out.lower().split("short test summary")[-1], out
    assert "apt-get install mosquitto" in out, out


@pytest.mark.slow
def test_in_ci_a_missing_broker_fails(tmp_path: Path) -> None:
    proc = run_without_mosquitto(tmp_path, "true")
    out = proc.stdout + proc.stderr
    assert proc.returncode == 1, out
    assert f"{len(TESTS)} errors" in out, out     # failed in a fixture
    assert "CI is set" in out, out
