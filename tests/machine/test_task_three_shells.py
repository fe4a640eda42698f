"""The machine operated from other processes, as a user does it with three
shells (issue 17's acceptance test, and docs/remote.rst):

1. ``halsdk run examples/mill/mill.ini`` (real time, the example as
   shipped);
2. a script written against the reference's documented ``linuxcnc``
   module only: E-stop reset, on, home, MDI, a program run while reading
   the status, the error channel, E-stop;
3. ``halsdk ctl status --follow --json`` watching the whole session.
"""

from __future__ import annotations

import ast
import json
import signal
import subprocess
import sys
import time

import pytest
from helpers import data_path, repo_path
from helpers.running_machine import halsdk_command, running_machine

pytestmark = pytest.mark.slow


def test_three_shells_operate_the_example_mill(tmp_path):
    ini = repo_path("examples", "mill", "mill.ini")
    with running_machine(tmp_path, ini=ini) as machine, \
            open(tmp_path / "follow.jsonl", "w") as sink:
        # into a file: a pipe nobody reads during the session would fill
        # and hold the follower up
        follow = subprocess.Popen(
            halsdk_command() + ["ctl", "status", "--follow", "--json",
                                "--interval", "0.05"],
            env=machine.env, stdout=sink, stderr=subprocess.PIPE,
            text=True)
        try:
            # the third shell follows before the session starts
            for _ in range(1200):
                if (tmp_path / "follow.jsonl").read_text() or \
                        follow.poll() is not None:
                    break
                time.sleep(0.05)
            script = subprocess.run(
                [sys.executable, str(data_path("task", "operate_mill.py")),
                 str(data_path("task", "square.ngc"))],
                env=machine.env, capture_output=True, text=True,
                timeout=300, cwd=str(tmp_path))
        finally:
            follow.send_signal(signal.SIGINT)
            try:
                _, err = follow.communicate(timeout=20)
            except subprocess.TimeoutExpired:
                follow.kill()
                _, err = follow.communicate()
            out = (tmp_path / "follow.jsonl").read_text()
        assert script.returncode == 0, script.stdout + script.stderr
        lines = dict(line.split(":", 1) for line in
                     script.stdout.splitlines() if ":" in line)
        assert lines["start in estop"].strip() == "True"
        assert lines["homed"].strip() == "(1, 1, 1)"
        assert lines["after mdi"].strip() == "(100.0, 50.0, -10.0)"
        assert lines["file"].strip() == "True"
        # the outline's feed moves (lines 6 to 9) were seen while running
        seen = ast.literal_eval(lines["lines seen"].strip())
        assert {6, 7, 8, 9} <= set(seen)
        assert lines["after program"].strip() == "(20.0, 20.0, 1.0)"
        assert lines["mdi in auto"].strip() == "True"
        assert lines["refusal reported"].strip() == "True"
        assert lines["end in estop"].strip() == "True enabled: False"
        # the third shell saw the session go by
        snapshots = [json.loads(line) for line in out.splitlines()
                     if line.startswith("{")]
        assert snapshots, err
        states = [snap["task_state"] for snap in snapshots]
        assert states[0] == 1 and 4 in states and states[-1] == 1
        assert any(snap["interp_state"] == 2 for snap in snapshots)
        assert "Traceback" not in err
    assert "Traceback" not in "".join(machine.output)
