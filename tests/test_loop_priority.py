"""While it streams to servos the control loop's thread runs at a raised priority (nice),
and gets its own back however the run ends; on a simulation's clock it is left alone.

The expected nice is asked of the OS on a thread of the test's own (may this process lower
a nice value?), not taken from robot.loop.priority."""

from __future__ import annotations

import os
import threading

import pytest
from bus_harness import open_bus

from robot.bus.servo_map import ServoMap
from robot.config.gait_file import load_gait
from robot.config.robot import RobotConfig
from robot.gait.engine import GaitEngine
from robot.loop.streamer import Streamer, Telemetry
from sim.emulator.chain import Emulator
from sim.mujoco.bus import MujocoBus

pytest_plugins = ("bus_harness",)

RAISED = -10          # docs/hardware.md: the loop thread's nice while it drives servos


def nice_here() -> int:
    return os.getpriority(os.PRIO_PROCESS, threading.get_native_id())


def may_raise() -> bool:
    """Whether this process may lower a thread's nice value: tried on a thread of its own
    (a thread's nice ends with it)."""
    answer: list[bool] = []

    def probe() -> None:
        try:
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), nice_here() - 1)
            answer.append(True)
        except PermissionError:
            answer.append(False)

    t = threading.Thread(target=probe)
    t.start()
    t.join()
    return answer[0]


def streamer(bus: object, robot: RobotConfig, seen: list[int], *, stop_at: int = 0
             ) -> Streamer:
    def observe(tel: Telemetry) -> None:
        seen.append(nice_here())
        if stop_at and tel.tick == stop_at:
            raise KeyboardInterrupt            # as Ctrl-C does: through every handler

    engine = GaitEngine(robot, load_gait("walk").params)
    return Streamer(ServoMap(robot), bus, engine, observer=observe)  # type: ignore[arg-type]


@pytest.mark.parametrize("stop_at", [0, 30], ids=["completed", "ctrl_c"])
def test_the_loop_thread_is_raised_on_servos_and_put_back(emu: Emulator, robot: RobotConfig,
                                                          stop_at: int) -> None:
    before = nice_here()
    want = min(before, RAISED) if may_raise() else before
    seen: list[int] = []
    bus = open_bus(emu, robot)
    try:
        if stop_at:
            with pytest.raises(KeyboardInterrupt):
                streamer(bus, robot, seen, stop_at=stop_at).run(seconds=5.0)
        else:
            assert streamer(bus, robot, seen).run(seconds=0.3).stop_reason == "completed"
    finally:
        bus.close()
    assert len(seen) >= max(stop_at, 20) and set(seen) == {want}   # and the end's report
    assert nice_here() == before
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_a_simulated_run_keeps_the_thread_s_priority(robot: RobotConfig) -> None:
    before = nice_here()
    seen: list[int] = []
    bus = MujocoBus(robot)
    bus.open()
    try:
        streamer(bus, robot, seen).run(seconds=0.3)
    finally:
        bus.close()
    assert len(seen) > 20 and set(seen) == {before}
    assert nice_here() == before
