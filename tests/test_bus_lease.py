"""The bus lease on the pty emulator (the real SDKs), judged at the wire: one owner at a
time, refused at once naming the holder; after ``emergency_stop`` returns, no goal and no
torque-on of an earlier session reaches a servo, while a loop is streaming from another
thread; a session acquired afterwards drives again."""

from __future__ import annotations

import threading
import time

import pytest
from panel_wire import assert_estop_held

from robot.bus.lease import BusBusy, BusLease, Preempted, holding
from robot.bus.sdk.bus import SdkBus
from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)


def centre(robot: RobotConfig) -> dict[int, int]:
    return {j.servo_id: j.zero_ticks for j in robot.joints}


def test_one_owner_at_a_time(bus: SdkBus, robot: RobotConfig) -> None:
    lease = BusLease(bus, robot.ids)
    with holding(lease, "the gait") as first:
        with pytest.raises(BusBusy, match="the gait is running; stop it first"):
            lease.acquire("the release of legs")
        assert lease.owner == "the gait" and first.live
    with holding(lease, "the release of legs") as second:
        assert lease.owner == "the release of legs" and second.live
    assert lease.owner is None


def test_only_one_of_many_racing_acquires_wins(bus: SdkBus, robot: RobotConfig) -> None:
    lease = BusLease(bus, robot.ids)
    won: list[str] = []
    busy: list[str] = []
    gate = threading.Barrier(8)

    def claim(k: int) -> None:
        gate.wait()
        try:
            lease.acquire(f"mover {k}")
            won.append(f"mover {k}")
        except BusBusy as e:
            busy.append(e.owner)
    threads = [threading.Thread(target=claim, args=(k,)) for k in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(won) == 1 and busy == [won[0]] * 7


def test_estop_latches_a_streaming_session(emu: Emulator, bus: SdkBus,
                                           robot: RobotConfig) -> None:
    lease = BusLease(bus, robot.ids)
    session = lease.acquire("the gait")
    session.set_torque(robot.ids, enabled=True)
    refused: list[Exception] = []
    streaming = threading.Event()

    def stream() -> None:
        goals = centre(robot)
        while True:
            try:
                session.write_goals(goals)
                session.set_torque(robot.ids[:1], enabled=True)
            except Preempted as e:
                refused.append(e)
                return
            streaming.set()
    loop = threading.Thread(target=stream)
    loop.start()
    assert streaming.wait(10)
    emu.log(clear=True)
    sent = time.monotonic()
    assert lease.emergency_stop("emergency stop") == []
    loop.join(10)
    assert refused and "emergency stop" in str(refused[0])
    assert_estop_held(robot, emu.log(), emu.protocol, sent)   # in the wire's own order
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}
    assert not any(lease.torque.values())
    with pytest.raises(Preempted):         # still holding the bus, but latched
        session.write_goals(centre(robot))
    session.end()
    with holding(lease, "a new start") as fresh:  # a new owner after the e-stop drives
        fresh.set_torque(robot.ids, enabled=True)
        fresh.write_goals(centre(robot))
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {1}
    lease.close(torque_off=True)
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}
