"""The `biped` process and the wire checks of the command end-path tests
(tests/test_command_ends*.py; issue 19, items 4, 5, 8): a real `biped` process whose output
is read as it comes, and what the pty emulator's registers show (torque per servo, the
Bus Watchdog of Dynamixel X, the goal stream inside the joint limits and the slew limit,
by the manual's tick formula)."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
from fault_matrix import goal_writes, tick_window
from waiting import sleep_until, wait_for

from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator

REPO = Path(__file__).resolve().parent.parent


class Biped:
    """A `biped` process (``python -m robot.cli``, as the console script runs it) whose
    stdout and stderr are read as they come, a prompt without its newline included."""

    def __init__(self, *argv: str, stdin: bool = False) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "robot.cli", *argv], cwd=REPO, text=True,
            stdin=subprocess.PIPE if stdin else subprocess.DEVNULL,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            env={**os.environ, "MUJOCO_GL": "egl"})
        self.out: list[str] = []
        self.err: list[str] = []
        self._readers = [threading.Thread(target=self._read, args=(s, lines), daemon=True)
                         for s, lines in ((self.proc.stdout, self.out),
                                          (self.proc.stderr, self.err))]
        for r in self._readers:
            r.start()

    @staticmethod
    def _read(stream: object, lines: list[str]) -> None:
        """Character by character: the last item grows until its newline."""
        lines.append("")
        for ch in iter(lambda: stream.read(1), ""):  # type: ignore[attr-defined]
            lines[-1] += ch
            if ch == "\n":
                lines.append("")

    def running(self) -> bool:
        return self.proc.poll() is None

    def said(self, text: str, *, where: str = "out") -> None:
        """Wait until a line containing ``text`` is printed (stdout or stderr). A process
        that ended is given up on once its output is read to the end (at load the readers
        lag the process: what it printed last can still be in the pipe when it exits)."""
        lines = self.out if where == "out" else self.err
        assert wait_for(lambda: any(text in line for line in lines),
                        stop=lambda: not self.running() and self._drained()), self.text()

    def _drained(self) -> bool:
        return not any(r.is_alive() for r in self._readers)

    def when(self, cond: object) -> None:
        assert wait_for(cond, stop=lambda: not self.running()), self.text()  # type: ignore[arg-type]

    def signals(self, sent: tuple[int, ...], *, gap_ms: float = 50.0) -> None:
        """The first signal; once the process said it is stopping, the others ``gap_ms``
        later (two same-number signals sent back to back may merge in the kernel)."""
        for k, sig in enumerate(sent):
            if k:
                self.said("stopping", where="err")
                sleep_until(time.monotonic() + gap_ms / 1e3)
            if self.running():
                self.proc.send_signal(sig)

    def send(self, text: str) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write(text)
        self.proc.stdin.flush()

    def finish(self, timeout: float = 30.0) -> tuple[int, str, str]:
        try:
            self.proc.wait(timeout)
        finally:
            if self.running():
                self.proc.kill()
                self.proc.wait()
        for r in self._readers:
            r.join(10)
        code, out, err = self.proc.returncode, "".join(self.out), "".join(self.err)
        assert code >= 0, f"killed by signal {-code}: {out}{err}"
        assert "Traceback" not in err, err
        return code, out, err

    def text(self) -> str:
        return "".join(self.out) + "".join(self.err)


def bus_args(emu: Emulator, robot_toml: Path) -> list[str]:
    return ["--bus", emu.protocol, "--port", emu.port, "--robot", str(robot_toml)]


def torque(emu: Emulator, robot: RobotConfig) -> set[int]:
    return {emu.registers(i)["torque_enable"] for i in robot.ids}


def watchdog(emu: Emulator, robot: RobotConfig) -> set[int]:
    """Dynamixel X Bus Watchdog (98) of every servo: 0 disarmed, -1 tripped, >0 armed;
    {0} for a Feetech, which has none."""
    return {emu.registers(i).get("bus_watchdog", 0) for i in robot.ids}


def goals_sent(emu: Emulator) -> int:
    return emu.counters().get("sync_write", 0)


def assert_goals_safe(emu: Emulator, robot: RobotConfig, rate_hz: float) -> None:
    """Every goal on the wire inside the joint limits, consecutive goals within the slew
    limit at ``rate_hz`` (the manual's tick formula, tests/fault_matrix.py)."""
    goals = goal_writes(emu)
    assert goals, "no goal reached the servos"
    ticks = np.array([[p.values[i] for i in robot.ids] for p in goals])
    window = tick_window(robot)
    assert all(window[i][0] <= t <= window[i][1] for row in ticks
               for i, t in zip(robot.ids, row, strict=True)), "a goal left the joint limits"
    step = np.array([j.max_speed_rad_s / rate_hz * 4096 / (2 * math.pi) for j in robot.joints])
    assert (np.abs(np.diff(ticks, axis=0)) <= step + 1.0).all(), "a goal broke the slew limit"


def assert_released(emu: Emulator, robot: RobotConfig) -> None:
    """Torque off on every servo and no Bus Watchdog left armed or tripped."""
    assert torque(emu, robot) == {0}
    assert watchdog(emu, robot) == {0}
