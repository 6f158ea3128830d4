"""The panel's control-loop process killed under a walking panel (SIGKILL: the OOM killer,
a crash in C code), and the emulator killed under it, judged at the wire.

Nothing of a SIGKILLed loop runs any more, and the servos keep their last goal with torque
on: the panel (its web side) must notice at once, open the port itself and turn torque off,
and exit non-zero; in the sim there is nothing left to turn off, and it exits non-zero too.
A dead emulator (the adapter gone) leaves nothing the panel can reach: it says torque is
not confirmed off and exits 1. Oracles: the emulator's Torque Enable registers and its
packet log (Torque Enable is address 64 on the XL430, from its e-Manual).
"""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import pytest
from panel_wire import TORQUE_ADDRESS, Panel, children, launched, torque_now
from waiting import wait_for

from robot.config.bundled import DEFAULT_ROBOT
from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

RATE = 100.0  # [Hz]


@pytest.fixture
def protocol() -> str:
    return "dynamixel"


def walking(panel: Panel) -> None:
    assert wait_for(lambda: panel.state()["state"] == "walking", timeout_s=30), panel.state()


def kill_loop(panel: Panel) -> float:
    (loop,) = children(panel.proc.pid)
    killed = time.monotonic()
    os.kill(loop, signal.SIGKILL)
    return killed


def test_loop_killed_the_panel_turns_torque_off_itself(
        emu: Emulator, robot: RobotConfig, robot_toml: Path, tmp_path: Path) -> None:
    with launched(emu, robot_toml, tmp_path, start=True, rate=RATE) as panel:
        walking(panel)
        assert set(torque_now(emu, robot).values()) == {1}
        emu.log(clear=True)
        killed = kill_loop(panel)
        out, rest = panel.proc.communicate(timeout=30)  # it ends by itself: no signal sent
        code = panel.proc.returncode
    last = out.splitlines()[-1]
    assert code == 1, out + "".join(panel.err)
    assert "torque off" in last and "control loop process had ended" in last, last
    # stderr is read by the harness's thread and by communicate(): a line is in either
    assert wait_for(lambda: "exit code -9" in "".join(panel.err) + (rest or ""),
                    timeout_s=10), (panel.err, rest)
    assert set(torque_now(emu, robot).values()) == {0}
    offs = [p for p in emu.log() if p.address == TORQUE_ADDRESS["dynamixel"]
            and p.t > killed and set(p.values.values()) == {0}]
    assert {i for p in offs for i in p.ids} >= set(robot.ids)        # written after the kill


def test_loop_killed_in_the_sim_exits_non_zero(tmp_path: Path) -> None:
    with launched(None, DEFAULT_ROBOT, tmp_path, start=True, rate=RATE) as panel:
        walking(panel)
        kill_loop(panel)
        out, _ = panel.proc.communicate(timeout=30)
        code = panel.proc.returncode
    assert code == 1, out + "".join(panel.err)
    assert "the simulation ended with the control loop process" in out.splitlines()[-1], out


def test_emulator_killed_under_a_walking_panel(
        emu: Emulator, robot: RobotConfig, robot_toml: Path, tmp_path: Path) -> None:
    """Held before: the bus is gone, so torque cannot be confirmed off: it says so, exit 1."""
    with launched(emu, robot_toml, tmp_path, start=True, rate=RATE) as panel:
        walking(panel)
        assert emu.pid is not None
        os.kill(emu.pid, signal.SIGKILL)
        assert wait_for(lambda: not panel.state()["running"], timeout_s=30), panel.state()
        panel.proc.send_signal(signal.SIGTERM)
        out, _ = panel.proc.communicate(timeout=30)
        code = panel.proc.returncode
    last = out.splitlines()[-1]
    assert code == 1, out
    assert "torque NOT confirmed off" in last and "bus watchdog" in last, last
