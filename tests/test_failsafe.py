"""The servos' own failsafe when the host vanishes, on the emulator with the REAL vendor SDKs.

Expected values come from the vendors' manuals, not from ``robot.bus.tables``:
ROBOTIS e-Manual, X series control table, "Bus Watchdog(98)": 1 byte, 1..127 in units of
20 ms, 0 disarms and clears, -1 after a trip, goals then answered with a Data Range Error
(Protocol 2.0 error 4) until 0 is written; torque is not dropped. The Feetech STS/SMS memory
table has no communication watchdog.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import NamedTuple

import pytest
from waiting import sleep_until, wait_for

from robot.bus.base import Bus
from robot.bus.sdk.bus import SdkBus
from robot.bus.servo_map import ServoMap
from robot.bus.tables import TABLES
from robot.config.gait_file import load_gait
from robot.config.robot import RobotConfig
from robot.errors import BusError, ConfigError
from robot.gait.engine import GaitEngine
from robot.loop.streamer import Streamer
from robot.loop.watchdog import FAILSAFE_MARGIN
from sim.emulator.chain import Emulator, Packet

pytest_plugins = ("bus_harness",)
Factory = Callable[..., SdkBus]
ROOT = Path(__file__).resolve().parent.parent


class Manual(NamedTuple):
    """The Bus Watchdog as the ROBOTIS e-Manual describes it (X series, address 98)."""

    address: int = 98
    size: int = 1
    unit_s: float = 0.020
    max_steps: int = 127
    tripped: int = -1


DXL = Manual()
#: What each family offers, from its manual; Feetech STS has nothing.
WATCHDOG: dict[str, Manual | None] = {"dynamixel": DXL, "feetech": None}
#: Protocol 2.0 status packet error number "Data Range Error".
DXL_DATA_RANGE_ERROR = "out of range"   # dynamixel_sdk's text for error number 4
KNEE = 4                # r_knee: limits 2048..3547 ticks in both bundled robots
FAR = 3547              # the knee's far limit: ~0.4 s of travel at no-load speed
TIMEOUT_S = 0.1
TICK_S = 0.005          # 200 Hz


def goals(robot: RobotConfig, knee: int) -> dict[int, int]:
    return {i: (knee if i == KNEE else 2048) for i in robot.ids}


def stream(bus: SdkBus, robot: RobotConfig, knee: int, seconds: float) -> None:
    """Goals at 200 Hz on absolute deadlines for ``seconds``."""
    start = time.monotonic()
    for k in range(round(seconds / TICK_S)):
        bus.write_goals(goals(robot, knee))
        sleep_until(start + (k + 1) * TICK_S)


def watchdog_writes(emu: Emulator) -> list[Packet]:
    return [p for p in emu.log() if p.instruction == "write" and p.address == DXL.address]


def max_gap(log: list[Packet]) -> float:
    times = [p.t for p in log]
    return max(b - a for a, b in zip(times, times[1:], strict=False))


# ---------------------------------------------------------------------- arming


def test_arm_writes_what_the_manual_says(bus: SdkBus, emu: Emulator, robot: RobotConfig,
                                         protocol: str) -> None:
    manual = WATCHDOG[protocol]
    emu.log(clear=True)
    armed = bus.arm_failsafe(robot.ids, timeout_s=TIMEOUT_S)
    if manual is None:
        assert armed is None and emu.log() == []    # nothing to arm, nothing written
        bus.disarm_failsafe(robot.ids)
        assert emu.log() == []
        return
    assert armed == pytest.approx(TIMEOUT_S)
    steps = round(TIMEOUT_S / manual.unit_s)
    assert TABLES["dynamixel_x"]["bus_watchdog"] == (manual.address, manual.size)
    # At the wire: each servo is cleared (0) then armed (5 x 20 ms), then read back.
    assert [(p.ids, p.values) for p in watchdog_writes(emu)] == [
        ((sid,), {sid: v}) for sid in sorted(robot.ids) for v in (0, steps)]
    reads = [p for p in emu.log() if p.instruction == "read"]
    assert [(p.ids, p.address, p.length) for p in reads] == [
        ((sid,), manual.address, manual.size) for sid in sorted(robot.ids)]
    assert {emu.registers(i)["bus_watchdog"] for i in robot.ids} == {steps}
    bus.disarm_failsafe(robot.ids)
    assert {emu.registers(i)["bus_watchdog"] for i in robot.ids} == {0}


@pytest.mark.parametrize("protocol", ["dynamixel"])
@pytest.mark.parametrize(("timeout_s", "armed"), [
    (0.02, 0.02), (0.03, 0.04), (0.1, 0.1), (0.5, 0.5), (2.54, 2.54)])
def test_timeouts_round_up_to_the_20_ms_unit(bus: SdkBus, emu: Emulator, timeout_s: float,
                                            armed: float) -> None:
    assert bus.arm_failsafe([KNEE], timeout_s=timeout_s) == pytest.approx(armed)
    assert emu.registers(KNEE)["bus_watchdog"] == round(armed / DXL.unit_s)


@pytest.mark.parametrize("protocol", ["dynamixel"])
@pytest.mark.parametrize("timeout_s", [0.0, 0.01, 2.6, 10.0, -0.1, math.nan, math.inf])
def test_invalid_timeouts_are_refused_before_anything_is_written(
        bus: SdkBus, emu: Emulator, robot: RobotConfig, timeout_s: float) -> None:
    emu.log(clear=True)
    with pytest.raises(ConfigError, match=r"outside the dynamixel bus_watchdog range "
                                          r"0\.02 to 2\.54 s \(steps of 20 ms\)") as info:
        bus.arm_failsafe(robot.ids, timeout_s=timeout_s)
    assert "\n" not in str(info.value)
    assert emu.log() == []


def test_sim_bus_has_no_failsafe(robot: RobotConfig) -> None:
    from sim.mujoco.bus import MujocoBus

    sim: Bus = MujocoBus(robot)
    assert sim.arm_failsafe(robot.ids, timeout_s=TIMEOUT_S) is None
    sim.disarm_failsafe(robot.ids)


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_close_disarms_what_it_armed_even_when_holding(bus_factory: Factory, emu: Emulator,
                                                        robot: RobotConfig) -> None:
    bus = bus_factory(emu, robot)
    bus.set_torque(robot.ids, enabled=True)
    bus.arm_failsafe(robot.ids, timeout_s=TIMEOUT_S)
    bus.close(torque_off=False)
    regs = [emu.registers(i) for i in robot.ids]
    assert {r["bus_watchdog"] for r in regs} == {0} and {r["torque_enable"] for r in regs} == {1}


# ---------------------------------------------------------------------- the host vanishes


class Child:
    """A driver in its own process: opens the bus, torque on, arms, streams until killed."""

    SCRIPT = """
import sys
from robot.bus.factory import make_bus
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot_file import load_robot
from robot.loop.clock import MonotonicClock
protocol, port, timeout_s, knee_id, knee = sys.argv[1:6]
robot = load_robot(ROBOTS_DIR / f"biped18-{protocol}.toml")
bus = make_bus(protocol, robot=robot, port=port, timeout_ms=50.0)
bus.open()
bus.set_torque(robot.ids, enabled=True)
bus.arm_failsafe(robot.ids, timeout_s=float(timeout_s))
goals = {i: (int(knee) if i == int(knee_id) else 2048) for i in robot.ids}
print("streaming", flush=True)
clock = MonotonicClock()
start = clock.now()
for k in range(1, 10**9):
    bus.write_goals(goals)
    clock.sleep_until(start + k * 0.005)   # absolute deadlines, as the streamer keeps them
"""

    def __init__(self, emu: Emulator) -> None:
        env = dict(os.environ, PYTHONPATH=str(ROOT))
        self.proc = subprocess.Popen(
            [sys.executable, "-c", self.SCRIPT, emu.protocol, emu.port, str(TIMEOUT_S),
             str(KNEE), str(FAR)], stdout=subprocess.PIPE, env=env)
        assert self.proc.stdout is not None
        assert self.proc.stdout.readline().strip() == b"streaming"

    def kill(self) -> None:
        self.proc.send_signal(signal.SIGKILL)    # no cleanup of any kind
        self.proc.wait(5.0)


@pytest.fixture(params=["silent", "unplugged", "sigkill"])
def vanish(request: pytest.FixtureRequest, bus: SdkBus, emu: Emulator,
           robot: RobotConfig) -> Iterator[Callable[[], None]]:
    """Start streaming goals that move the knee toward FAR, then make the host vanish.

    silent: the loop just stops; unplugged: the SDK's port is closed under the bus (no
    torque off, no disarm), like a USB cable pulled; sigkill: a driver process is killed.
    """
    how = str(request.param)

    def run() -> None:
        if how == "sigkill":
            bus.close(torque_off=False)       # the child owns the port from here
            child = Child(emu)
            assert wait_for(lambda: any(p.instruction == "sync_write" and p.values[KNEE] == FAR
                                        for p in emu.log())), "the child never streamed"
            child.kill()
            return
        bus.set_torque(robot.ids, enabled=True)
        bus.arm_failsafe(robot.ids, timeout_s=TIMEOUT_S)
        stream(bus, robot, FAR, 0.05)
        if how == "unplugged":
            bus.port_handler.closePort()

    yield run


def test_when_the_host_vanishes(vanish: Callable[[], None], bus_factory: Factory,
                                emu: Emulator, robot: RobotConfig, protocol: str) -> None:
    manual = WATCHDOG[protocol]
    emu.log(clear=True)
    vanish()
    last = [p for p in emu.log() if p.instruction == "sync_write"][-1]
    assert last.values[KNEE] == FAR
    # Stopped: tripped (Dynamixel X), or at the last goal (no watchdog); then still there.
    assert wait_for(lambda: emu.registers(KNEE)["present_position"] == FAR if manual is None
                    else emu.registers(KNEE)["bus_watchdog"] == manual.tripped)
    before = emu.registers(KNEE)
    sleep_until(time.monotonic() + 0.2)   # 0.2 s of servo time: ~750 ticks if it moved
    after = emu.registers(KNEE)
    assert after["present_position"] == before["present_position"]   # no longer moving
    assert after["torque_enable"] == 1                                # torque as it was
    if manual is None:
        # No watchdog (Feetech STS): the servo finishes the last goal and holds it.
        assert after["present_position"] == FAR and after["goal_position"] == FAR
        return
    # Dynamixel X: stopped short of the last goal, tripped, torque still on.
    assert 2048 < after["present_position"] < FAR - 200
    assert after["goal_position"] == after["present_position"] and after["moving"] == 0
    assert after["bus_watchdog"] == manual.tripped
    assert {emu.registers(i)["bus_watchdog"] for i in robot.ids} == {manual.tripped}

    # A new driver: goals are refused while tripped (sync write: silently; write: range error).
    again = bus_factory(emu, robot)
    try:
        again.write_goals(goals(robot, FAR))
        assert emu.registers(KNEE)["goal_position"] == after["present_position"]
        with pytest.raises(BusError, match=rf"id {KNEE} \(r_knee\): write goal_position="
                                           rf"{FAR} failed: .*{DXL_DATA_RANGE_ERROR}") as info:
            again.write_register(KNEE, "goal_position", FAR)
        assert "\n" not in str(info.value)
        # Disarm clears it: goals are accepted and the knee moves on, without a new torque on.
        again.disarm_failsafe(robot.ids)
        assert {emu.registers(i)["bus_watchdog"] for i in robot.ids} == {0}
        again.write_goals(goals(robot, FAR))
        assert wait_for(lambda: emu.registers(KNEE)["present_position"] == FAR)
    finally:
        again.close()


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_a_steady_200_hz_stream_never_trips_it(bus: SdkBus, emu: Emulator,
                                               robot: RobotConfig) -> None:
    bus.set_torque(robot.ids, enabled=True)
    # Armed as the streamer arms it: a read-back retried to its end never trips it.
    armed = bus.arm_failsafe(robot.ids,
                             timeout_s=FAILSAFE_MARGIN * bus.retry_span_s + 2 * TICK_S)
    assert armed is not None
    emu.log(clear=True)
    start = time.monotonic()
    for k in range(400):            # 2 s; a state read-back every 10th tick
        bus.write_goals(goals(robot, 2048 + (k % 100)))
        if k % 10 == 9:
            bus.read_state(robot.ids)
        sleep_until(start + (k + 1) * TICK_S)
    gap = max_gap(emu.log())
    regs = [emu.registers(i) for i in robot.ids]
    assert gap < armed, f"the host itself stalled {gap * 1e3:.0f} ms (machine overloaded?)"
    assert {r["bus_watchdog"] for r in regs} == {round(armed / DXL.unit_s)}
    assert emu.registers(KNEE)["goal_position"] == 2048 + 399 % 100


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_no_trip_while_torque_is_off(bus: SdkBus, emu: Emulator, robot: RobotConfig) -> None:
    bus.arm_failsafe([KNEE], timeout_s=0.02)
    sleep_until(emu.log()[-1].t + 0.1)        # five timeouts of silence, torque off
    assert emu.registers(KNEE)["bus_watchdog"] == 1
    bus.set_torque([KNEE], enabled=True)      # a packet: the watchdog starts counting now
    assert wait_for(lambda: emu.registers(KNEE)["bus_watchdog"] == DXL.tripped)
    assert emu.registers(KNEE)["torque_enable"] == 1
    assert bus.arm_failsafe([KNEE], timeout_s=TIMEOUT_S) == pytest.approx(TIMEOUT_S)
    assert emu.registers(KNEE)["bus_watchdog"] == 5   # re-arming clears the trip first


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_register_range_and_reboot_as_the_manual_says(bus: SdkBus, emu: Emulator) -> None:
    with pytest.raises(BusError, match=rf"id {KNEE} \(r_knee\): write bus_watchdog=128 "
                                       rf"failed: .*{DXL_DATA_RANGE_ERROR}"):
        bus.write_register(KNEE, "bus_watchdog", DXL.max_steps + 1)
    bus.set_torque([KNEE], enabled=True)
    bus.arm_failsafe([KNEE], timeout_s=0.02)
    assert wait_for(lambda: emu.registers(KNEE)["bus_watchdog"] == DXL.tripped)
    bus.packet_handler.reboot(bus.port_handler, KNEE)   # RAM back to its initial value 0
    regs = emu.registers(KNEE)
    assert regs["bus_watchdog"] == 0 and regs["torque_enable"] == 0


class StallingEngine(GaitEngine):
    """A gait engine whose host stalls once, ``STALL_S`` inside one tick after ``stall_at``
    ticks (swap, a full SD card, another process on the core): the injected fault."""

    stall_at = 400                      # 2 s of walking at 200 Hz

    def tick(self, dt: float) -> list[float]:
        self.stall_at -= 1
        if self.stall_at == 0:
            sleep_until(time.monotonic() + STALL_S)
        return super().tick(dt)


STALL_S = 0.5                           # 5 x the 100 ms the run arms


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_a_host_stall_that_trips_the_watchdog_is_named_as_such(
        bus: SdkBus, emu: Emulator, robot: RobotConfig) -> None:
    """The servos refuse goals after the trip, so the loop finds them not following; the
    stop reason names their tripped watchdog (not a jam), and the end leaves torque off and
    the watchdog cleared, judged at the emulator's registers."""
    engine = StallingEngine(robot, load_gait("walk").params)
    stats = Streamer(ServoMap(robot), bus, engine, rate_hz=200.0).run(seconds=20)
    assert stats.fault and "stopped following" in stats.stop_reason
    assert "bus watchdog tripped on servo" in stats.stop_reason, stats.stop_reason
    assert "the host stalled" in stats.stop_reason and "\n" not in stats.stop_reason
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}
    assert {emu.registers(i)["bus_watchdog"] for i in robot.ids} == {0}
