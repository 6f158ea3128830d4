"""What the one loop streams: a motion source (joint targets over time) and the feedback
stage between it and safety.

A source is anything that gives the next joint targets for a tick: the gait engine
(robot.gait.engine) and the engines built on it (robot.motion.layered: a keyframe layer
or a keyframe sequence played on its own; robot.motion.scripted: a take recorded or
replayed), and a move to a pose (robot.motion.posing.PoseMove). The loop
(robot.loop.streamer) ramps from the present pose to ``entry``, ticks the source until it
has ``stopped``, then ramps to ``exit_pose``; it never asks what kind of source it has.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Protocol, TypeAlias, TypeVar, runtime_checkable

import numpy as np
import numpy.typing as npt

from robot.config.params import GaitParams
from robot.config.robot import RobotConfig

#: Joint angles [rad] in the robot's joint order (``robot.joints``).
JointVector: TypeAlias = npt.NDArray[np.float64]
#: What a source may return for a tick: joint angles [rad] in joint order, as an array or
#: as a list of floats (the gait engine's float path).
JointTargets: TypeAlias = npt.NDArray[np.float64] | Sequence[float]


@runtime_checkable
class MotionSource(Protocol):
    """Joint targets over time for the streaming loop.

    robot: whose joints (their order and limits); params: its live-settable parameters
    (None: it has none, ``set_params`` refuses); entry: where it starts, given the present
    pose [rad] and the tick [s] (the loop ramps there first; None: it starts from the
    present pose itself); exit_pose: where the loop ramps to after it has stopped (None:
    stay where it ended); start / stop: begin, and end as soon as it can (a gait ramps
    out); stopped: nothing more to stream; state: the telemetry state of its ticks
    ("walking", "ramp_out", "pose"); amplitude: its envelope in [0, 1] (telemetry);
    tick(dt): advance by ``dt`` [s] and return the joint targets.
    """

    robot: RobotConfig

    @property
    def params(self) -> GaitParams | None: ...

    def set_params(self, changes: Mapping[str, float], *,
                   where: str = "parameter") -> GaitParams: ...

    def entry(self, present: JointVector, dt: float) -> JointTargets | None: ...

    def exit_pose(self) -> JointTargets | None: ...

    def start(self) -> None: ...

    def stop(self) -> None: ...

    @property
    def stopped(self) -> bool: ...

    @property
    def state(self) -> str: ...

    @property
    def amplitude(self) -> float: ...

    def tick(self, dt: float) -> JointTargets: ...


@runtime_checkable
class ClampReporter(Protocol):
    """A source that says which joints (indices, robot order) its last ``tick`` held at
    a limit (the gait engine: ``clamped``); the loop puts them in its telemetry."""

    @property
    def clamped(self) -> tuple[int, ...]: ...


#: A run's or a streamer's source type (e.g. GaitEngine for the panel, which sets its
#: parameters live).
SourceT = TypeVar("SourceT", bound=MotionSource)


class Feedback(Protocol):
    """A stage between the source and safety (robot.balance.Balance): ``start`` when the
    source starts, then called every tick with the joints [rad] and the tick [s]."""

    def start(self) -> None: ...
    def stop(self) -> None: ...
    def __call__(self, q: JointVector, dt: float) -> JointVector: ...
