"""Fault matrix (tests/test_fault_matrix.py), the ends a walk reaches from its servos and
its files: a joint jammed mid-walk, a hardware error flag per protocol (from the manuals),
a full disk under --record, the adapter's port closed mid-walk, with and without --hold; judged from the
emulated servos' registers, the exit code and the one-line cause, plus the goal stream."""

from __future__ import annotations

import io
import time
from contextlib import redirect_stdout
from pathlib import Path

import pytest
from fault_matrix import (
    VICTIM,
    assert_stream_safe,
    goal_writes,
    inject_when_streaming,
    last_goals,
    rest_ticks,
    run_walk,
    torque,
    victim_id,
    walk_args,
)
from waiting import sleep_until, wait_for

import robot.cli as cli
from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

#: Hardware-error flags per protocol, from the manuals (X-series Hardware Error Status 70;
#: STS status register 65), independent of robot/bus/tables.py.
HW_FLAGS = {"dynamixel": ("voltage", "overheating", "encoder", "electrical_shock", "overload"),
            "feetech": ("voltage", "encoder", "overheating", "overcurrent", "overload")}


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
@pytest.mark.parametrize(("protocol", "flag"), _hw_cases())
def test_hardware_error_flags(emu: Emulator, robot: RobotConfig, robot_toml: Path, flag: str,
                              hold: bool, capsys: pytest.CaptureFixture[str]) -> None:
    victim = victim_id(robot)
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
