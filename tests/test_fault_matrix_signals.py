"""Fault matrix (tests/test_fault_matrix.py), signals: a `biped walk` process on the pty
emulator gets SIGINT, SIGTERM or two of them once its goals stream, with and without
--hold; the exit code, the one-line cause, the goal stream and the registers it leaves."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from fault_matrix import (
    REPO,
    assert_stream_safe,
    goal_writes,
    last_goals,
    rest_ticks,
    torque,
    walk_args,
)
from waiting import wait_for

from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)


SIGNAL_CASES = {  # name: (signals sent, exit code, ends at rest, torque with --hold)
    "sigint": ((signal.SIGINT,), 130, True, 1),
    "sigterm": ((signal.SIGTERM,), 143, True, 1),
    "double_sigint": ((signal.SIGINT, signal.SIGINT), 130, False, 0),
    "sigint_sigterm": ((signal.SIGINT, signal.SIGTERM), 130, False, 0),
}


@pytest.mark.parametrize("hold", [False, True], ids=["nohold", "hold"])
@pytest.mark.parametrize("case", sorted(SIGNAL_CASES))
def test_signals(emu: Emulator, robot: RobotConfig, robot_toml: Path, case: str,
                 hold: bool) -> None:
    sent, want_code, at_rest, hold_torque = SIGNAL_CASES[case]
    cmd = [sys.executable, "-m", "robot.cli",
           *walk_args(emu, robot_toml, hold=hold, seconds=60)]
    proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env={**os.environ, "MUJOCO_GL": "egl"})
    assert proc.stderr is not None and proc.stdout is not None
    err_lines: list[str] = []

    def read_stderr() -> None:
        for line in proc.stderr:     # line by line while the walk runs
            err_lines.append(line)

    reader = threading.Thread(target=read_stderr, daemon=True)
    reader.start()
    try:
        assert wait_for(lambda: emu.counters().get("sync_write", 0) >= 250, timeout_s=60,
                        stop=lambda: proc.poll() is not None), \
            f"the walk never streamed: {''.join(err_lines)}"
        for k, sig in enumerate(sent):
            if k:   # the first was handled (the walk says so): the second is its own signal
                assert wait_for(lambda: any("stopping" in line for line in err_lines),
                                stop=lambda: proc.poll() is not None), "".join(err_lines)
            proc.send_signal(sig)
        proc.wait(timeout=30)
        out = proc.stdout.read()
        reader.join(10)
        err = "".join(err_lines)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == want_code, err
    result = json.loads(out)
    assert "\n" not in result["stop_reason"]
    assert signal.Signals(sent[-1]).name in result["stop_reason"]
    assert_stream_safe(robot, goal_writes(emu))
    assert (last_goals(emu, robot) == rest_ticks(robot)) is at_rest
    assert torque(emu, robot.ids) == {hold_torque if hold else 0}
