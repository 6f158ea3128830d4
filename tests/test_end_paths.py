"""Start and end paths of the one streaming loop, read at the wire on the pty emulator:
a joint outside its limits refuses the start (nothing written), a failing gait engine
ramps straight to rest, pose shares the loop and its watchdog, statistics stay bounded;
a signal in each window around a run's end (issue 19: the command's latch, as robot.cli
installs it, with signals sent to this process at a known point)."""

from __future__ import annotations

import math
import os
import random
import signal
import threading
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np
import pytest
from bus_harness import PATIENT_TIMEOUT_MS, open_bus
from waiting import wait_for

import robot.cli as cli
from robot.bus.base import Bus
from robot.bus.dynamixel.protocol2 import DynamixelBus
from robot.bus.servo_map import ServoMap
from robot.config.gait_file import load_gait
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.loop.latency import SampleStats
from robot.loop.streamer import Streamer
from robot.loop.telemetry import Telemetry
from robot.motion.posing import PoseMove
from robot.run.run import Run
from robot.run.signals import Interrupted, SignalLatch
from robot.run.spec import RunOptions, RunSpec
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

#: Reply timeout [ms] of this module's buses and robot files (the harness reads it): no test
#: here makes a servo silent (a run's last read missed 100 ms at load: the end read as a fault).
REPLY_TIMEOUT_MS = PATIENT_TIMEOUT_MS

RESOLUTION = 4096
WRITES = ("write", "sync_write", "reg_write", "bulk_write", "action")


def ticks_of(robot: RobotConfig, name: str, q: float) -> int:
    j = robot.joint(name)
    return round(j.zero_ticks + j.sign * q * RESOLUTION / (2 * math.pi))


@pytest.mark.parametrize("command", [["walk", "--seconds", "1"], ["pose", "rest"]])
def test_joint_outside_limits_refuses_before_torque_on(
        emu: Emulator, robot: RobotConfig, robot_toml: Path, command: list[str],
        capsys: pytest.CaptureFixture[str]) -> None:
    knee = robot.joint("r_knee")
    beyond = knee.max_rad + 0.3                               # 0.3 rad past its max
    emu.set_register(knee.servo_id, "present_position", ticks_of(robot, "r_knee", beyond))
    emu.log(clear=True)
    code = cli.main([*command, "--bus", emu.protocol, "--port", emu.port,
                     "--robot", str(robot_toml)])
    err = capsys.readouterr().err.strip()
    assert code == 1
    assert len(err.splitlines()) == 1
    assert "refusing to start: r_knee" in err and "0.300 rad" in err and "max_rad" in err
    assert [p for p in emu.log() if p.instruction in WRITES] == []     # nothing written
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}


def test_joint_just_outside_is_taken_in_without_a_jump(emu: Emulator, robot: RobotConfig,
                                                       robot_toml: Path) -> None:
    knee = robot.joint("r_knee")
    step = knee.max_speed_rad_s / 50.0                        # one slew step at 50 Hz
    start = ticks_of(robot, "r_knee", knee.max_rad + 0.5 * step)
    emu.set_register(knee.servo_id, "present_position", start)
    emu.log(clear=True)
    assert cli.main(["pose", "zero", "--bus", emu.protocol, "--port", emu.port,
                     "--robot", str(robot_toml), "--rate", "50", "--speed", "2"]) == 0
    goals = [p.values[knee.servo_id] for p in emu.log()
             if p.instruction == "sync_write" and knee.servo_id in p.values
             and p.address in (116, 42)]
    assert abs(goals[0] - start) <= step * RESOLUTION / (2 * math.pi) + 1
    assert goals[-1] == knee.zero_ticks                       # then on to the zero pose


class BrokenEngine(GaitEngine):
    """A gait engine with a bug that shows after ``fail_at`` ticks."""

    fail_at = 120

    def tick(self, dt: float) -> list[float]:
        self.fail_at -= 1
        if self.fail_at <= 0:
            raise ZeroDivisionError("a bug in the gait")
        return super().tick(dt)


@pytest.mark.parametrize("hold", [False, True])
def test_gait_engine_exception_ramps_to_rest_then_torque_off(
        emu: Emulator, robot: RobotConfig, hold: bool) -> None:
    bus = open_bus(emu, robot)
    engine = BrokenEngine(robot, load_gait("walk").params)
    try:
        stats = Streamer(ServoMap(robot), bus, engine, rate_hz=200.0,
                         hold_at_end=hold).run(seconds=10)
    finally:
        bus.close(torque_off=False)
    assert stats.fault and not stats.holding
    assert stats.stop_reason == ("exception in the gait engine: ZeroDivisionError: "
                                 "a bug in the gait")
    rest = {j.servo_id: ticks_of(robot, j.name, min(max(robot.rest.get(j.name, 0.0),
                                                         j.min_rad), j.max_rad))
            for j in robot.joints}
    assert {i: emu.registers(i)["goal_position"] for i in robot.ids} == rest
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}


def test_sample_stats_exact_while_small_bounded_when_large() -> None:
    rng = random.Random(3)
    small = [rng.gauss(0.0, 1.0) for _ in range(5000)]
    s = SampleStats(capacity=8192)
    for x in small:
        s.add(x)
    for p in (1, 50, 99):
        assert s.percentile(p) == pytest.approx(float(np.percentile(small, p)), abs=1e-12)
    assert s.max == max(small)
    big = SampleStats(capacity=4096, seed=1)
    top = 0.0
    for _ in range(400_000):                                   # 33 min at 200 Hz
        x = rng.random()
        top = max(top, x)
        big.add(x)
    assert big.stored == 4096 and big.count == 400_000         # memory does not grow
    assert big.max == top
    assert big.percentile(50) == pytest.approx(0.5, abs=0.03)  # uniform: p50 = 0.5
    assert big.percentile(99) == pytest.approx(0.99, abs=0.01)


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_bus_watchdog_armed_past_the_longest_retried_transaction(
        emu: Emulator, robot: RobotConfig, robot_toml: Path) -> None:
    """Bus Watchdog (X-series address 98, 20 ms units) is armed while streaming, for longer
    than a transaction retried to its end (the harness file's reply timeout x 3 attempts),
    and disarmed after."""
    emu.log(clear=True)
    assert cli.main(["walk", "--bus", "dynamixel", "--port", emu.port, "--robot",
                     str(robot_toml), "--seconds", "0.3", "--set", "ramp_cycles=0.5"]) == 0
    writes = [p for p in emu.log() if p.instruction == "write" and p.address == 98]
    values = {i: [p.values[i] for p in writes if i in p.values] for i in robot.ids}
    bus = load_robot(robot_toml).bus                             # the file the walk ran
    span = bus.timeout_ms * 1e-3 * (bus.retries + 1)             # every attempt times out
    steps = math.ceil((1.5 * span + 2 / 200.0) / 0.020 - 1e-9)   # 1.5 x span + 2 ticks
    assert all(v == [0, steps, 0] for v in values.values()), values   # clear, arm, disarm
    assert {emu.registers(i)["bus_watchdog"] for i in robot.ids} == {0}


# ------------------------------------------------ issue 19: signals around a run's end
@pytest.fixture
def command_latch() -> Iterator[SignalLatch]:
    """SIGINT/SIGTERM handled in this process as robot.cli handles them for a command."""
    latch = SignalLatch()
    restore = latch.install()
    yield latch
    restore()


def posing(robot: RobotConfig, bus: Bus, *, first_signal_at: int | None = None) -> Run[PoseMove]:
    """A Run of `biped pose rest` (hold at the end, signals routed), slow enough to be
    stopped; ``first_signal_at``: SIGINT to this process at that tick."""
    sent: list[int] = []

    def observe(tel: Telemetry) -> None:
        if tel.tick == first_signal_at and not sent:     # once (the end notifies again)
            sent.append(tel.tick)
            os.kill(os.getpid(), signal.SIGINT)
    move = PoseMove(robot, ServoMap(robot).vector(robot.rest), max_speed=0.3)
    return Run(RunSpec(robot=robot, source=move, bus=bus, observer=observe,
                       options=RunOptions(rate_hz=50.0, hold=True, signals=True, watch=False)))


def wire_torque(emu: Emulator, robot: RobotConfig) -> set[int]:
    return {emu.registers(i)["torque_enable"] for i in robot.ids}


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_second_signal_while_the_hold_is_finished_turns_torque_off(
        emu: Emulator, robot: RobotConfig, command_latch: SignalLatch) -> None:
    """Item 4's first window: the second signal lands while the streamer finishes its hold
    (disarming the Bus Watchdog). It was counted and ignored: all 18 kept torque."""
    class SignalOnDisarm(DynamixelBus):
        signalled = False

        def disarm_failsafe(self, ids: Iterable[int]) -> None:
            if not self.signalled:                       # the operator's second Ctrl-C
                self.signalled = True
                os.kill(os.getpid(), signal.SIGINT)
            super().disarm_failsafe(ids)

    bus = SignalOnDisarm(emu.port, baud=robot.bus.baud, robot=robot,
                         timeout_ms=REPLY_TIMEOUT_MS)
    run = posing(robot, bus, first_signal_at=5)
    with run:
        run.stream()
    result = run.result
    assert command_latch.count == 2 and result.exit_code == 130
    assert result.stats.estop and not result.stats.holding and result.stats.torque == "off"
    assert wire_torque(emu, robot) == {0}
    assert {emu.registers(i)["bus_watchdog"] for i in robot.ids} == {0}


def test_second_signal_after_the_run_ended_holding_turns_torque_off(
        emu: Emulator, robot: RobotConfig, command_latch: SignalLatch) -> None:
    """Item 4's second window: the loop has returned holding, the command has not yet
    closed the bus (its handlers were restored there: -2/-15, or ignored)."""
    run = posing(robot, open_bus(emu, robot, timeout_ms=REPLY_TIMEOUT_MS),
                 first_signal_at=5)
    with run:
        assert run.stream().holding and wire_torque(emu, robot) == {1}
        os.kill(os.getpid(), signal.SIGTERM)
    result = run.result
    assert result.exit_code == 130                       # 128 + the first signal
    assert result.stats.torque == "off" and "after it ended holding" in result.stats.stop_reason
    assert "SIGTERM" in result.stats.stop_reason
    assert wire_torque(emu, robot) == {0}


def test_a_stop_before_the_stream_starts_writes_nothing(
        emu: Emulator, robot: RobotConfig, command_latch: SignalLatch) -> None:
    """A signal between opening the bus and the first tick: nothing is written (not a
    torque-on and a ramp to rest), exit 128 + signal."""
    run = posing(robot, open_bus(emu, robot))
    with run:
        emu.log(clear=True)
        os.kill(os.getpid(), signal.SIGTERM)
        stats = run.stream()
    assert stats.torque == "untouched" and stats.ticks == 0
    assert [p for p in emu.log() if p.instruction in WRITES] == []
    assert run.result.exit_code == 143 and wire_torque(emu, robot) == {0}


class Target:
    def __init__(self) -> None:
        self.calls: list[str] = []

    def request_stop(self, reason: str = "") -> None:
        self.calls.append(f"stop: {reason}")

    def emergency_stop(self, reason: str = "") -> None:
        self.calls.append(f"estop: {reason}")


def test_latch_regions() -> None:
    """The rules of robot.run.signals, by calling the handler as the interpreter would:
    outside any region the first signal raises (once), a shielded region defers it to
    its end, a routed one stops the target and never raises."""
    latch = SignalLatch()
    with pytest.raises(Interrupted) as first:
        latch.handle(signal.SIGTERM)
    assert first.value.signum == signal.SIGTERM
    latch.handle(signal.SIGINT)                           # the cleanup is not interrupted
    assert (latch.first, latch.count, latch.emergency) == (signal.SIGTERM, 2, True)
    assert latch.exit_code(None) == 143

    shielded = SignalLatch()
    with pytest.raises(Interrupted):
        with shielded.shielded():
            shielded.handle(signal.SIGINT)                # only counted here
            done = True
    assert done

    routed, target = SignalLatch(), Target()
    with routed.routed(target):
        routed.handle(signal.SIGINT)
        with routed.shielded():                           # routing wins: the loop is told
            routed.handle(signal.SIGTERM)
    assert target.calls == ["stop: signal SIGINT",
                            "estop: emergency stop (second signal, SIGTERM)"]
    assert routed.exit_code(None) == 130


def test_shield_in_another_thread_changes_nothing(command_latch: SignalLatch) -> None:
    """A run closing in a panel thread must not defer (and later raise) the main thread's
    signal there."""
    from robot.run.signals import shield

    def close() -> None:
        with shield():
            assert command_latch._shields == 0

    worker = threading.Thread(target=close)
    worker.start()
    worker.join()
    with shield():
        assert command_latch._shields == 1


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_second_signal_after_the_run_closed_turns_torque_off_at_the_end(
        emu: Emulator, robot: RobotConfig, command_latch: SignalLatch) -> None:
    """Item 4's last window: the run has closed holding, bus and all, and the command is
    still printing when the second signal lands (it raises there: the first was the
    loop's). At the command's end (``SignalLatch.settle``, which ``end`` runs before the
    exit) the bus opens again and torque goes off, and the operator is told."""
    run = posing(robot, open_bus(emu, robot, timeout_ms=REPLY_TIMEOUT_MS),
                 first_signal_at=5)
    with run:
        run.stream()
    assert run.result.stats.holding and wire_torque(emu, robot) == {1}
    with pytest.raises(Interrupted):
        os.kill(os.getpid(), signal.SIGTERM)
        wait_for(lambda: False, timeout_s=5)   # the handler raises at the next bytecode
    try:
        lines = command_latch.settle()
    finally:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, (signal.SIGINT, signal.SIGTERM))
    assert command_latch.emergency
    assert wire_torque(emu, robot) == {0}
    assert len(lines) == 1 and "second signal, SIGTERM" in lines[0] and "torque off" in lines[0]
    assert not run.result.stats.holding


def test_settle_without_a_second_signal_leaves_the_hold(command_latch: SignalLatch) -> None:
    """One signal only: what was registered for a second one is not run."""
    called: list[str] = []

    def late() -> str:
        called.append("late")
        return "late"
    command_latch.if_emergency_at_end(late)
    command_latch.record(signal.SIGINT)
    try:
        assert command_latch.settle() == [] and called == []
    finally:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, (signal.SIGINT, signal.SIGTERM))
