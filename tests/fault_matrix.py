"""The fault matrix's oracles and runner (tests/test_fault_matrix*.py): expected tick
limits and slew steps computed here from the robot file by hand (the manual's tick formula),
not by ``ServoMap``; the goal stream and the registers read back from the pty emulator; a
`biped walk` run in-process with a fault injected once enough goals reached the servos.

The matrix is split over three files so that pytest's file-per-worker split runs them side
by side (each walk runs in real time on the pty: 198 s wall for one file, 47 CPU-s):
bus faults (test_fault_matrix.py), a jam, hardware error flags, a full disk and a closed
port (test_fault_matrix_ends.py), signals (test_fault_matrix_signals.py).
"""

from __future__ import annotations

import io
import json
import math
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, redirect_stdout
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import robot.cli as cli
from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator, Packet

REPO = Path(__file__).resolve().parent.parent
RATE = 200.0
#: Goal packets before a fault is injected: well into the walk (ramp-in is ~0.3-1 s).
INJECT_AFTER_GOALS = 200
GOAL_ADDRESS = {"dynamixel": 116, "feetech": 42}      # Goal Position, from the manuals
RESOLUTION = 4096                                      # ticks per turn (XL430, STS3215)


# ------------------------------------------------------------------------------ oracles
def tick_window(robot: RobotConfig) -> dict[int, tuple[int, int]]:
    """Allowed goal ticks per id: the joint limits through ticks = zero + sign*q*4096/2pi,
    rounded inward."""
    out = {}
    for j in robot.joints:
        ends = sorted(j.zero_ticks + j.sign * q * RESOLUTION / (2 * math.pi)
                      for q in (j.min_rad, j.max_rad))
        out[j.servo_id] = (math.ceil(ends[0] - 1e-9), math.floor(ends[1] + 1e-9))
    return out


def rest_ticks(robot: RobotConfig) -> dict[int, int]:
    out = {}
    for j in robot.joints:
        q = min(max(robot.rest.get(j.name, 0.0), j.min_rad), j.max_rad)
        out[j.servo_id] = round(j.zero_ticks + j.sign * q * RESOLUTION / (2 * math.pi))
    return out


def goal_writes(emu: Emulator) -> list[Packet]:
    addr = GOAL_ADDRESS[emu.protocol]
    return [p for p in emu.log() if p.instruction == "sync_write" and p.address == addr]


def assert_stream_safe(robot: RobotConfig, goals: list[Packet]) -> None:
    """Every goal inside the joint limits; consecutive goals within the slew limit."""
    window = tick_window(robot)
    ids = robot.ids
    ticks = np.array([[p.values[i] for i in ids] for p in goals])
    lo = np.array([window[i][0] for i in ids])
    hi = np.array([window[i][1] for i in ids])
    assert (ticks >= lo).all() and (ticks <= hi).all(), "a goal left the joint limits"
    step = np.array([j.max_speed_rad_s / RATE * RESOLUTION / (2 * math.pi) for j in robot.joints])
    assert (np.abs(np.diff(ticks, axis=0)) <= step + 1.0).all(), "a goal exceeded the slew limit"


def torque(emu: Emulator, ids: tuple[int, ...]) -> set[int]:
    return {emu.registers(i)["torque_enable"] for i in ids}


def last_goals(emu: Emulator, robot: RobotConfig) -> dict[int, int]:
    return {i: emu.registers(i)["goal_position"] for i in robot.ids}


# ------------------------------------------------------------------------------ running
def walk_args(emu: Emulator, robot_toml: Path, *, hold: bool, seconds: float = 2.0) -> list[str]:
    args = ["walk", "--bus", emu.protocol, "--port", emu.port, "--robot", str(robot_toml),
            "--seconds", str(seconds), "--rate", str(RATE), "--json", "--set",
            "ramp_cycles=0.5"]
    return args + (["--hold"] if hold else [])


@contextmanager
def inject_when_streaming(emu: Emulator, action: Callable[[], None] | None, *,
                          after: int = INJECT_AFTER_GOALS) -> Iterator[dict]:
    """Run ``action`` once ``after`` goal packets have reached the servos."""
    info: dict[str, Any] = {"at": None}
    stop = threading.Event()

    def worker() -> None:
        while not stop.is_set():
            if emu.counters().get("sync_write", 0) >= after:
                assert action is not None
                action()
                info["at"] = time.monotonic()
                return
            stop.wait(0.01)

    thread = threading.Thread(target=worker, daemon=True)
    if action is not None:
        thread.start()
    try:
        yield info
    finally:
        stop.set()
        if action is not None:
            thread.join(5)


def run_walk(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, dict, str]:
    out = io.StringIO()
    with redirect_stdout(out):
        code = cli.main(args)
    err = capsys.readouterr().err
    return code, json.loads(out.getvalue()), err


VICTIM = "l_knee"
#: The cause of a run that ended at rest but would not hold torque on servos that did
#: not answer its last read (robot.loop.ending.end).
UNHELD = "watchdog: not holding torque on servos that do not answer"


def victim_id(robot: RobotConfig) -> int:
    return robot.joint(VICTIM).servo_id
