"""The streamer against the pty emulator with the real vendor SDKs (both protocols)."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from bus_harness import open_bus
from waiting import wait_for

from robot.bus.servo_map import ServoMap
from robot.bus.tables import TABLES
from robot.config.gait_file import load_gait
from robot.config.robot import RobotConfig
from robot.gait.engine import GaitEngine
from robot.loop.streamer import Streamer, Telemetry
from robot.loop.watchdog import WatchdogConfig
from sim.emulator.chain import Emulator, Packet

pytest_plugins = ("bus_harness",)

RATE = 200.0


def _streamer(bus: object, robot: RobotConfig, **kw: object) -> Streamer:
    engine = GaitEngine(robot, load_gait("walk").params)
    return Streamer(ServoMap(robot), bus, engine, rate_hz=RATE, **kw)  # type: ignore[arg-type]


def _goal_writes(log: list[Packet], robot: RobotConfig) -> list[Packet]:
    family = "dynamixel_x" if robot.bus.kind == "dynamixel" else "feetech_sts"
    addr = TABLES[family]["goal_position"].address
    return [p for p in log if p.instruction == "sync_write" and p.address == addr]


def _torque_writes(log: list[Packet], robot: RobotConfig) -> list[Packet]:
    family = "dynamixel_x" if robot.bus.kind == "dynamixel" else "feetech_sts"
    addr = TABLES[family]["torque_enable"].address
    return [p for p in log if p.instruction in ("write", "sync_write") and p.address == addr]


def test_one_sync_write_per_tick_within_limits_and_slew(emu: Emulator, robot: RobotConfig) -> None:
    bus = open_bus(emu, robot)
    emu.log(clear=True)
    try:
        stats = _streamer(bus, robot, read_every=10).run(seconds=0.4)
    finally:
        bus.close()
    log = emu.log()
    goals = _goal_writes(log, robot)
    assert stats.ticks > 50
    # goal := present before torque-on (no snap to a stale goal), then one packet per tick
    assert len(goals) == stats.ticks + 1
    hold, goals = goals[0], goals[1:]
    assert hold.values == {i: emu_zero for i, emu_zero in
                           zip(robot.ids, [j.zero_ticks for j in robot.joints], strict=True)}
    smap = ServoMap(robot)
    ticks = np.array([[p.values[i] for i in smap.ids] for p in goals])
    assert (ticks >= smap.tick_min).all() and (ticks <= smap.tick_max).all()
    max_step = smap.max_speed / RATE * smap.ticks_per_rad + 1.0   # +1 tick of rounding
    assert (np.abs(np.diff(ticks, axis=0)) <= max_step).all()
    torque = _torque_writes(log, robot)
    first_goal, last_goal = goals[0].t, goals[-1].t
    on = [p for p in torque if all(v == 1 for v in p.values.values())]
    off = [p for p in torque if all(v == 0 for v in p.values.values())]
    assert on and hold.t <= min(p.t for p in on)              # held goal before torque on
    assert max(p.t for p in on) <= first_goal                 # torque on before streaming
    assert off and min(p.t for p in off) >= last_goal         # torque off after the last
    assert {i for p in off for i in p.ids} == set(robot.ids)
    assert all(emu.registers(i)["torque_enable"] == 0 for i in robot.ids)


def test_exception_in_loop_leaves_torque_off(emu: Emulator, robot: RobotConfig) -> None:
    bus = open_bus(emu, robot)

    def explode(tel: Telemetry) -> None:
        if tel.tick == 30:
            raise RuntimeError("boom in the loop")

    try:
        stats = _streamer(bus, robot, observer=explode, hold_at_end=True).run(seconds=5)
        # An observer's exception ramps out to rest and ends torque off, even with hold.
        assert stats.fault and "boom in the loop" in stats.stop_reason
        assert not stats.holding
        assert stats.ticks < 5 * RATE
        assert all(emu.registers(i)["torque_enable"] == 0 for i in robot.ids)
        smap = ServoMap(robot)
        rest = smap.goals(smap.clamp(smap.vector(robot.rest)).tolist())
        assert {i: emu.registers(i)["goal_position"] for i in robot.ids} == rest
    finally:
        bus.close()


@pytest.mark.parametrize("fault", ["overheating", "overload", "vanish", "drop_all"])
def test_watchdog_stops_safely_on_injected_faults(emu: Emulator, robot: RobotConfig,
                                                  fault: str) -> None:
    bus = open_bus(emu, robot)
    victim = robot.joint("l_knee").servo_id
    injected = {"done": False}

    def inject(tel: Telemetry) -> None:
        if tel.tick == 40 and not injected["done"]:
            injected["done"] = True
            if fault in ("overheating", "overload"):
                emu.set_faults(hw_error={victim: fault})
            elif fault == "vanish":
                emu.set_faults(vanish={victim: 0.0})
            else:
                emu.set_faults(drop_rate=1.0)

    streamer = _streamer(bus, robot, read_every=5, observer=inject,
                         watchdog=WatchdogConfig(bus_error_streak=3))
    try:
        t0 = time.monotonic()
        stats = streamer.run(seconds=30)
        assert time.monotonic() - t0 < 20                # stopped long before the 30 s walk
    finally:
        emu.clear_faults()
        bus.close()
    assert stats.stop_reason.startswith("watchdog")
    if fault in ("overheating", "overload"):
        assert fault in stats.stop_reason and "l_knee" in stats.stop_reason
    else:
        assert "bus errors" in stats.stop_reason
    # Whatever answered is torque-off now (a vanished servo cannot be reached, by definition).
    reachable = [i for i in robot.ids if fault == "overheating" or i != victim]
    if fault != "drop_all":
        assert all(emu.registers(i)["torque_enable"] == 0 for i in reachable)


def test_sigint_ramps_out_and_leaves_torque_off(emu: Emulator, robot: RobotConfig,
                                               robot_toml: Path) -> None:
    # robot_toml: the reply timeout a loaded machine needs (with the bundled 20 ms, late
    # replies under load tripped the servos' own 0.1 s bus watchdog mid-walk: "stopped
    # following", exit 1).
    env = {**os.environ, "MUJOCO_GL": "egl"}
    cmd = [sys.executable, "-m", "robot.cli", "walk", "--bus", robot.bus.kind,
           "--robot", str(robot_toml), "--port", emu.port, "--seconds", "60", "--json"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env)
    try:
        # The gait streams (its handlers are installed) once 100 goals reached the servos.
        assert wait_for(lambda: len(_goal_writes(emu.log(), robot)) > 100, timeout_s=60,
                        every_s=0.1, stop=lambda: proc.poll() is not None), \
            f"the walk never streamed: {proc.poll() is not None and proc.communicate()[1]}"
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert "signal SIGINT" in out
    assert all(emu.registers(i)["torque_enable"] == 0 for i in robot.ids)
    goals = _goal_writes(emu.log(), robot)
    smap = ServoMap(robot)
    last = np.array([goals[-1].values[i] for i in smap.ids])
    rest = smap.to_ticks(smap.clamp(smap.vector(robot.rest)))
    assert np.abs(last - rest).max() <= 1                    # ramped back to the rest pose


def test_watchdog_follow_error_unit(robot: RobotConfig) -> None:
    from robot.bus.base import ServoState
    from robot.errors import SafetyStop
    from robot.loop.watchdog import Watchdog

    smap = ServoMap(robot)
    wd = Watchdog(WatchdogConfig(follow_reads=3), smap, robot=robot)
    q = np.zeros(len(smap.ids))
    stuck = {i: ServoState(i, int(smap.to_ticks(q)[k])) for k, i in enumerate(smap.ids)}
    q_cmd = q.copy()
    q_cmd[3] = 1.0                                           # r_knee commanded 1 rad away
    wd.check(stuck, q_cmd)
    wd.check(stuck, q_cmd)
    with pytest.raises(SafetyStop, match="r_knee.*stopped following"):
        wd.check(stuck, q_cmd)
    assert math.isfinite(float(q_cmd.sum()))
