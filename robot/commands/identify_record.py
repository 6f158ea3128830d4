"""`biped identify record`: pendulum logs from a real servo, through this project's own bus.

A servo with a weight ``--mass`` [kg] on an arm ``--length`` [m] (the arm hanging down at
``--zero`` ticks) runs each trajectory of ``robot.servo.trajectories`` at each P gain of
``--kp``; one log per run is written to ``--out`` in the public pendulum-log JSON format
(``robot.servo.pendulum_log``), named ``<trajectory>_kp<kp>.json``, which ``identify
fit`` / ``check`` (and Rhoban/bam's tools) read.

Safety: the servo is a one-joint robot (limits ``--range`` around the zero; every goal is
clipped to them and refused outside); gains go through the driver's gain writer (RAM
every time, EEPROM only when the value changes, read back and verified) at the first
torque-on of each gain; torque on starts at goal := present, then a minimum-jerk ramp to
0 over ``RAMP_S`` before each run; torque off at the end, on any bus fault, and on the
first SIGINT / SIGTERM (the command's signal latch routes it here; exit 128 + signal).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from robot.bus.base import Bus
from robot.bus.factory import make_bus
from robot.bus.servo_map import ServoMap
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot import JointConfig, RobotConfig
from robot.config.robot_file import load_robot
from robot.config.servo_file import physics_for
from robot.errors import BusError, ConfigError, SafetyStop
from robot.run.signals import shield, stop_on_signals
from robot.servo.firmware import LOG_GAIN_REGISTERS
from robot.servo.models import MODELS
from robot.servo.pendulum_log import PendulumLog, write_log
from robot.servo.trajectories import Trajectory, min_jerk, trajectories

log = logging.getLogger(__name__)

PERIOD_S = 0.01           # one goal write and one read-back every 10 ms
RAMP_S = 1.5              # from where the arm is to 0 before each run
#: Read-backs in a row that may be lost (each already retried by the bus) before a run
#: stops: a real bus drops a reply now and then, and a lost sample is only a gap in the
#: log (every row carries its time); 5 in a row (50 ms) is a wiring or power fault.
LOST_READS_MAX = 5
BUNDLED = {"dynamixel": "biped18-dynamixel", "dynamixel1": "biped18-ax12",
           "feetech": "biped18-feetech"}
JOINT = "bench"


class _Stop:
    """The signal latch's target: the loop checks ``reason`` every tick."""

    def __init__(self) -> None:
        self.reason: str | None = None

    def request_stop(self, reason: str = "signal") -> None:
        self.reason = self.reason or reason

    def emergency_stop(self, reason: str = "signal") -> None:
        self.reason = self.reason or reason


def bench_robot(kind: str, motor: str, sid: int, zero: int, span: float,
                kp: int | None, *, timeout_ms: float | None = None) -> RobotConfig:
    """A one-joint robot: servo ``sid`` of model ``motor`` on a ``kind`` bus, limits
    ``zero`` ± ``span`` [rad], its P register at ``kp`` (None: factory); the reply timeout
    ``timeout_ms`` [ms] (None: the bundled robot's)."""
    if kind not in BUNDLED:
        raise ConfigError(f"--bus: expected one of {', '.join(BUNDLED)}, got {kind!r}")
    base = load_robot(ROBOTS_DIR / f"{BUNDLED[kind]}.toml")
    if motor not in MODELS or MODELS[motor].family != base.bus.servo.family:
        fits = [m for m, s in MODELS.items() if s.family == base.bus.servo.family]
        raise ConfigError(f"--motor: expected a {kind} servo ({', '.join(fits)}), got {motor!r}")
    registers = LOG_GAIN_REGISTERS[physics_for(motor).law]
    gains = dict.fromkeys(registers, kp) if kp is not None else {}
    joint = JointConfig(JOINT, sid, 1, zero, -span, span, 2 * math.pi)
    return replace(base, name=f"{motor} bench", joints=(joint,), rest={}, physics={},
                   bus=replace(base.bus, model=motor, gains=gains, servo_file=None,
                               timeout_ms=base.bus.timeout_ms if timeout_ms is None
                               else timeout_ms),
                   imu=None)


def record(bus: Bus, robot: RobotConfig, traj: Trajectory, *, seconds: float,
           mass: float, length: float, kp: int, stop: _Stop) -> PendulumLog:
    """Ramp to 0, run ``traj`` for ``seconds``; the log (torque left as the run ends)."""
    joint = robot.joints[0]
    sid, tpr = joint.servo_id, MODELS[robot.bus.model].ticks_per_rad
    servo_map = ServoMap(robot)
    clip = servo_map.clamp

    def angle(ticks: int) -> float:
        return (ticks - joint.zero_ticks) / tpr

    def goal(q: float) -> None:
        bus.write_goals({sid: int(servo_map.to_ticks(clip([q]))[0])})

    start = angle(bus.read_state([sid])[sid].position)
    if not -joint.max_rad <= start <= joint.max_rad:
        raise SafetyStop(f"id {sid}: at {start:+.2f} rad from --zero, outside --range "
                         f"{joint.max_rad:g}: turn the arm back by hand")
    goal(start)
    bus.set_torque([sid], enabled=True)
    _ticks(RAMP_S, stop, lambda t: goal(start * (1 - min_jerk(t / RAMP_S))))
    rows: list[tuple[float, ...]] = []
    on, lost, lost_all = True, 0, 0

    def tick(t: float) -> None:
        nonlocal on, lost, lost_all
        called = time.monotonic()
        g, want = traj.goal(t), traj.enable(t)
        if want != on:
            if want:
                goal(angle(bus.read_state([sid])[sid].position))
            bus.set_torque([sid], enabled=want)
            on = want
        if on:
            goal(g)
        # The sample's time: the goal has just reached the servo, the read-back goes out
        # now. Stamping the tick's start instead logs a goal and a position the late part
        # of a tick (a busy host, a slow adapter) put later than the log says.
        stamp = t + (time.monotonic() - called)
        try:
            s = bus.read_state([sid])[sid]
        except BusError:
            lost, lost_all = lost + 1, lost_all + 1
            if lost >= LOST_READS_MAX:
                raise
            return
        lost = 0
        rows.append((stamp, g, angle(s.position), s.load or 0.0,
                     s.voltage or 0.0, s.temperature or 0.0, float(on)))

    _ticks(seconds, stop, tick)
    if lost_all:
        log.warning("%s: %d read-backs lost (gaps in the log)", traj.name, lost_all)
    a = np.array(rows) if rows else np.zeros((0, 7))
    speed = np.gradient(a[:, 2], a[:, 0]) if len(a) > 1 else np.zeros(len(a))
    volts = float(np.median(a[:, 4])) if len(a) else 0.0
    return PendulumLog(source=f"{traj.name}_kp{kp}", mass=mass, length=length, kp=kp,
                       vin=volts or MODELS[robot.bus.model].nominal_voltage,
                       motor=robot.bus.model, trajectory=traj.name, t=a[:, 0], goal=a[:, 1],
                       position=a[:, 2], speed=speed, torque_enable=a[:, 6] > 0.5,
                       load=a[:, 3], input_volts=a[:, 4], temp=a[:, 5])


def _ticks(seconds: float, stop: _Stop, step: Callable[[float], None]) -> None:
    """Call ``step(t)`` every PERIOD_S on absolute deadlines for ``seconds`` [s]; ``t`` is
    the time since the first call when this one starts (a late tick carries its own time,
    and the ticks it overran are skipped)."""
    t0 = time.monotonic()
    n = 0
    while n * PERIOD_S <= seconds:
        if stop.reason is not None:
            raise _Stopped(stop.reason)
        step(time.monotonic() - t0)
        n += 1
        delay = t0 + n * PERIOD_S - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        else:
            n = max(n, math.ceil((time.monotonic() - t0) / PERIOD_S))   # late: skip ticks


class _Stopped(Exception):
    pass


def run_record(kind: str, port: str | None, *, motor: str, sid: int, zero: int | None,
               span: float, mass: float, length: float, kps: list[int], seconds: float,
               out: Path, amplitude: float, timeout_ms: float | None = None
               ) -> tuple[list[Path], str | None]:
    """Every trajectory at every gain; (logs written, the stop reason or None)."""
    zero = MODELS[motor].resolution // 2 if zero is None else zero
    if amplitude > span:
        raise ConfigError(f"--amplitude {amplitude:g}: more than --range {span:g} rad")
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    stop = _Stop()
    with stop_on_signals(stop):
        for kp in kps:
            robot = bench_robot(kind, motor, sid, zero, span, kp, timeout_ms=timeout_ms)
            bus = make_bus(kind, robot=robot, port=port)
            bus.open()
            try:
                for traj in trajectories(amplitude, seconds):
                    pl = record(bus, robot, traj, seconds=seconds, mass=mass,
                                length=length, kp=kp, stop=stop)
                    written.append(write_log(pl, out / f"{pl.source}.json"))
                    log.info("wrote %s", written[-1])
            except _Stopped as e:
                return written, str(e)
            finally:
                with shield():
                    bus.close()          # torque off
    return written, None
