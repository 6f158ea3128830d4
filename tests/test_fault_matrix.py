"""Fault matrix: every way a `biped walk` can end, on the pty emulator with the real vendor
SDKs (both protocols), with and without --hold. The verdict is the end state read back
from the emulated servos' registers (torque per servo, last goal), the exit code and the
one-line cause, plus the whole goal stream: never outside the joint limits, never faster
than the slew limit.

Expected tick limits and slew steps are computed here from the robot file by hand (the
manual's tick formula), not by ``ServoMap``.
"""

from __future__ import annotations

import io
import json
import math
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, redirect_stdout
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from waiting import sleep_until, wait_for

import robot.cli as cli
from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator, Packet

pytest_plugins = ("bus_harness",)

REPO = Path(__file__).resolve().parent.parent
RATE = 200.0
#: Goal packets before a fault is injected: well into the walk (ramp-in is ~0.3-1 s).
INJECT_AFTER_GOALS = 200
#: Hardware-error flags per protocol, from the manuals (X-series Hardware Error Status 70;
#: STS status register 65), independent of robot/bus/tables.py.
HW_FLAGS = {"dynamixel": ("voltage", "overheating", "encoder", "electrical_shock", "overload"),
            "feetech": ("voltage", "encoder", "overheating", "overcurrent", "overload")}
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


# ------------------------------------------------------------------------------ cases
@dataclass(frozen=True)
class Fault:
    """name; inject(emu, robot) or None; the end it must reach: "ok" (exit 0, rest, torque
    as --hold says), "ramp" (exit 1, ramped to rest, torque off), "off" (exit 1, torque off
    at once: goals stop soon after the fault), "either" (ok or off: a noisy bus that may or
    may not reach the error streak); cause: text the one-line stop reason must contain;
    after: goal packets before the fault is injected."""

    name: str
    inject: Callable[[Emulator, RobotConfig], None] | None
    end: str
    cause: str = ""
    after: int = INJECT_AFTER_GOALS


VICTIM = "l_knee"
#: The cause of a run that ended at rest but would not hold torque on servos that did
#: not answer its last read (robot.loop.ending.end).
UNHELD = "watchdog: not holding torque on servos that do not answer"


def _vid(robot: RobotConfig) -> int:
    return robot.joint(VICTIM).servo_id


FAULTS = [
    Fault("none", None, "ok", "completed"),
    Fault("drop10", lambda e, r: e.set_faults(drop_rate=0.1), "either"),
    Fault("drop50", lambda e, r: e.set_faults(drop_rate=0.5), "either"),
    Fault("drop100", lambda e, r: e.set_faults(drop_rate=1.0), "off", "bus errors"),
    Fault("corrupt30", lambda e, r: e.set_faults(corrupt_rate=0.3), "either"),
    Fault("corrupt100", lambda e, r: e.set_faults(corrupt_rate=1.0), "off", "bus errors"),
    Fault("vanish", lambda e, r: e.set_faults(vanish={_vid(r): 0.0}), "off", "bus errors"),
    # Jammed from the first goal: the ramp-in bends the knee ~1 rad; it stays straight.
    Fault("stuck", lambda e, r: e.set_faults(stuck_ids=[_vid(r)]), "off",
          f"servo {{}} ({VICTIM}) stopped following", after=1),
]


#: Issue 19 item 6: a knee that jammed 5 s into `walk --seconds 20` got 3739 more goals and
#: the walk ended "completed" (goal - present peaked at 0.36 rad, under the fixed 0.6 rad).
JAM_AFTER_GOALS = 600                                  # 3 s of walking at 200 Hz
#: The jam check judges 1 s of read-backs (robot.loop.following); the joint's goal must then
#: sweep its threshold (0.25 rad) once more: about a stride. Counted in goal packets (gait
#: ticks), not wall seconds: a loaded machine slows the loop, not the gait per tick.
#: 3 s of gait at 200 Hz; the measured figure was 190 (it was 3739).
JAM_MOST_GOALS = 600


@pytest.mark.parametrize("joint", ["l_knee", "r_hip_pitch"])
def test_jam_mid_walk_is_a_safety_stop(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                                       joint: str, capsys: pytest.CaptureFixture[str]) -> None:
    victim = robot.joint(joint).servo_id
    jam = lambda: emu.set_faults(stuck_ids=[victim])   # noqa: E731
    with inject_when_streaming(emu, jam, after=JAM_AFTER_GOALS) as info:
        code, result, err = run_walk(walk_args(emu, robot_toml, hold=False, seconds=20), capsys)
    emu.clear_faults()
    assert code == 1, err
    reason = result["stop_reason"]
    assert reason.startswith(f"watchdog: servo {victim} ({joint}) stopped following"), reason
    goals = goal_writes(emu)
    assert_stream_safe(robot, goals)
    assert info["at"] is not None
    assert len([p for p in goals if p.t > info["at"]]) <= JAM_MOST_GOALS   # not driven on
    assert torque(emu, robot.ids) == {0}


def _hw_cases() -> list[tuple[str, str]]:
    return [(p, f) for p, flags in HW_FLAGS.items() for f in flags]


@pytest.mark.parametrize("hold", [False, True], ids=["nohold", "hold"])
@pytest.mark.parametrize("fault", FAULTS, ids=[f.name for f in FAULTS])
def test_bus_faults(emu: Emulator, robot: RobotConfig, robot_toml: Path, fault: Fault,
                    hold: bool, capsys: pytest.CaptureFixture[str]) -> None:
    action = (lambda: fault.inject(emu, robot)) if fault.inject else None
    t0 = time.monotonic()
    with inject_when_streaming(emu, action, after=fault.after) as info:
        code, result, err = run_walk(walk_args(emu, robot_toml, hold=hold), capsys)
    emu.clear_faults()
    reason = result["stop_reason"]
    cause = fault.cause.format(_vid(robot))
    assert "\n" not in reason
    goals = goal_writes(emu)
    assert_stream_safe(robot, goals)
    assert time.monotonic() - t0 < 25
    reachable = tuple(i for i in robot.ids if fault.name != "vanish" or i != _vid(robot))
    end = fault.end
    if end == "either":   # a noisy bus: it completes, stops, or completes but cannot hold
        end = ("ok" if code == 0 else
               "unheld" if reason.startswith(UNHELD) else "off")
    if end == "unheld":   # ramped out to rest; the last read failed: no hold, torque off
        assert code == 1 and hold and result["fault"] and not result["holding"], err
        assert last_goals(emu, robot) == rest_ticks(robot)
        assert torque(emu, robot.ids) == {0}
    elif end == "ok":
        assert code == 0, err
        assert reason == "completed"
        assert last_goals(emu, robot) == rest_ticks(robot)
        assert torque(emu, robot.ids) == {1 if hold else 0}
        assert result["holding"] is hold
    else:
        assert code == 1, err
        assert result["fault"] and not result["holding"]
        assert cause in reason and reason.startswith("watchdog")
        assert torque(emu, reachable) == {0}                 # hold or not
        assert info["at"] is not None
        stopped = max(p.t for p in goals) - info["at"]
        assert stopped < 3.0                                  # no ramp-out: stopped at once


@pytest.mark.parametrize("hold", [False, True], ids=["nohold", "hold"])
@pytest.mark.parametrize(("protocol", "flag"), _hw_cases())
def test_hardware_error_flags(emu: Emulator, robot: RobotConfig, robot_toml: Path, flag: str,
                              hold: bool, capsys: pytest.CaptureFixture[str]) -> None:
    victim = _vid(robot)
    with inject_when_streaming(emu, lambda: emu.set_faults(hw_error={victim: flag})) as info:
        code, result, err = run_walk(walk_args(emu, robot_toml, hold=hold), capsys)
    goals = goal_writes(emu)
    assert_stream_safe(robot, goals)
    assert code == 1, err
    assert result["stop_reason"] == f"watchdog: servo {victim} ({VICTIM}) reports {flag}"
    assert torque(emu, robot.ids) == {0}                       # the faulty servo too
    assert max(p.t for p in goals) - info["at"] < 3.0          # not driven on
    emu.clear_faults()


@pytest.mark.parametrize("hold", [False, True], ids=["nohold", "hold"])
def test_full_disk_under_record_ramps_out(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                                          tmp_path: Path, hold: bool,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    record = tmp_path / "run.csv"
    record.symlink_to("/dev/full")                            # every flush: ENOSPC
    code, result, err = run_walk(walk_args(emu, robot_toml, hold=hold)
                                 + ["--record", str(record)], capsys)
    assert code == 1, err
    assert result["fault"] and "No space left on device" in result["stop_reason"]
    assert result["stop_reason"].startswith("exception in an observer: OSError")
    assert "No space left" in result["record_error"]
    assert_stream_safe(robot, goal_writes(emu))
    assert last_goals(emu, robot) == rest_ticks(robot)        # ramped out to rest
    assert torque(emu, robot.ids) == {0}                       # a fault: off, hold or not


@pytest.mark.parametrize("hold", [False, True], ids=["nohold", "hold"])
def test_port_closed_mid_walk(emu: Emulator, robot: RobotConfig, robot_toml: Path, hold: bool,
                              capsys: pytest.CaptureFixture[str]) -> None:
    """The adapter vanishes: nothing can reach the servos. They keep torque; Dynamixel X's
    Bus Watchdog (armed while streaming) stops them where they are."""
    with inject_when_streaming(emu, lambda: emu.set_faults(close_port=True)) as info:
        code, result, err = run_walk(walk_args(emu, robot_toml, hold=hold), capsys)
    assert code == 1, err
    reason = result["stop_reason"]
    assert reason.startswith("watchdog: 5 bus errors in a row") and "port error" in reason
    assert "\n" not in reason and not result["holding"]
    assert result["torque"] == "unknown"                      # not "off": nothing was sent
    goals = goal_writes(emu)
    assert_stream_safe(robot, goals)
    assert max(p.t for p in goals) <= info["at"] + 0.05       # nothing heard after it
    if emu.protocol == "dynamixel":                            # its failsafe trips
        assert wait_for(lambda: {emu.registers(i)["bus_watchdog"] for i in robot.ids} == {-1})
    regs = [emu.registers(i) for i in robot.ids]
    assert {r["torque_enable"] for r in regs} == {1}          # unreachable: still torqued
    if emu.protocol == "dynamixel":
        assert {r["bus_watchdog"] for r in regs} == {-1}      # tripped: stopped, holding
        assert all(r["goal_position"] == r["present_position"] for r in regs)
        sleep_until(time.monotonic() + 0.1)                   # 0.1 s of servo time: still
        assert [emu.registers(i)["present_position"] for i in robot.ids] == [
            r["present_position"] for r in regs]


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_port_closed_summary_says_what_is_known(emu: Emulator, robot: RobotConfig,
                                                robot_toml: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 19 item 8: after the port closed, the summary said "servos torque off" while
    all 18 held torque. It may only say what the bus confirmed."""
    args = [a for a in walk_args(emu, robot_toml, hold=False) if a != "--json"]
    with inject_when_streaming(emu, lambda: emu.set_faults(close_port=True)):
        out = io.StringIO()
        with redirect_stdout(out):
            code = cli.main(args)
    assert code == 1, capsys.readouterr().err
    servos = next(line for line in out.getvalue().splitlines()
                  if line.strip().startswith("servos"))
    assert "torque off" not in servos and "UNKNOWN" in servos, servos
    assert torque(emu, robot.ids) == {1}                       # what the wire shows


# ------------------------------------------------------------------------------ signals
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
