"""What a run is made of (``RunSpec``: a robot, a motion source, a bus and options) and
what a bus may add to it (``WatchedBus``: the simulated bus watches its own runs).

The spec is frozen: it names the parts; ``robot.run.run.Run`` opens, drives and closes
them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Generic, Protocol, runtime_checkable

from robot.bus.base import Bus
from robot.config.robot import RobotConfig
from robot.imu import Imu
from robot.loop.source import Feedback, SourceT
from robot.loop.telemetry import Telemetry, TickObserver


class Recording(Protocol):
    """A recorder of the run's ticks (robot.loop.recorder.Recorder, robot.motion.takes
    .TakeWriter): ``open`` before the bus (an unwritable path fails first), called every
    tick, ``close_quietly`` → the first failed write as one line, or None."""

    def open(self) -> Recording: ...
    def __call__(self, tel: Telemetry) -> None: ...
    def close_quietly(self) -> str | None: ...


class RunWatch(Protocol):
    """What a bus watches during one run (the simulated bus: the torso's path and fall,
    the servos' effort, the world's pushes): called every tick after the physics;
    ``fell``: the robot has fallen; ``summary(seconds)``: JSON-ready metrics of the run
    (``seconds``: its gait time [s], for speeds)."""

    def __call__(self, tel: Telemetry) -> None: ...

    @property
    def fell(self) -> bool: ...

    def summary(self, seconds: float | None) -> Mapping[str, object]: ...


@runtime_checkable
class WatchedBus(Protocol):
    """A bus that offers a watch for each run (``sim.mujoco.bus.MujocoBus``); the Run asks
    the bus it was given, so robot/ never imports sim/."""

    def run_watch(self) -> RunWatch: ...


@dataclass(frozen=True)
class RunOptions:
    """rate_hz: control rate [Hz]; read_every: read the servos back every N ticks; hold:
    keep torque on at the end; seconds: of the source (None: until it stops or is
    stopped); stop_on_fall: emergency stop when the bus's watch sees a fall; signals:
    SIGINT/SIGTERM stop the run (first: safe stop, second: emergency stop; main thread
    only); close_bus: close the bus at the end (False: its owner keeps it open, e.g. the
    panel); watch: attach the bus's run watch if it has one."""

    rate_hz: float = 200.0
    read_every: int = 10
    hold: bool = False
    seconds: float | None = None
    stop_on_fall: bool = False
    signals: bool = False
    close_bus: bool = True
    watch: bool = True


@dataclass(frozen=True)
class RunSpec(Generic[SourceT]):
    """One run: ``source`` streamed to ``bus`` for ``robot``.

    imu: opened after the bus and closed by the run; the balance stage reads it (the
    source must then be a gait engine); feedback: a ready feedback stage instead (the
    panel's); recorder: records every tick; observer: also called every tick.
    """

    robot: RobotConfig
    source: SourceT
    bus: Bus
    options: RunOptions = field(default_factory=RunOptions)
    imu: Imu | None = None
    feedback: Feedback | None = None
    recorder: Recording | None = None
    observer: TickObserver | None = None
