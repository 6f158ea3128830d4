"""What the simulation does with a ``robot.config.world.World`` at run time: the pushes on
the torso (``PushScheduler``, ``TimedForces``). The world itself (units, signs, ranges)
is pure configuration in robot/config/world.py; ``World`` and ``Push`` are re-exported
here."""

from __future__ import annotations

import dataclasses
import heapq
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from robot.config.world import Push, World
from robot.loop.telemetry import GaitClock, Telemetry

__all__ = ["PUSH_WINDOW_S", "AppliedPush", "Push", "PushScheduler", "PushTarget", "TimedForces",
           "World"]

#: Duration of a push's constant force [s]: short next to a step (~0.4 s).
PUSH_WINDOW_S = 0.02
_TIME_EPS = 1e-9  # [s]


def heading_force(quat: Sequence[float], fx: float, fy: float) -> npt.NDArray[np.float64]:
    """(fx forward, fy left) in the heading frame (yaw only) of the body whose orientation
    is ``quat`` (w, x, y, z) → the world-frame vector (x, y, 0)."""
    w, x, y, z = quat
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([c * fx - s * fy, s * fx + c * fy, 0.0])


class PushTarget(Protocol):
    """What PushScheduler needs of the bus (``sim.mujoco.bus.MujocoBus``)."""

    def push(self, jx: float, jy: float, *, window_s: float = PUSH_WINDOW_S
             ) -> Mapping[str, Any] | None: ...


@dataclass(frozen=True)
class AppliedPush:
    """A push as applied: the request, the sim time it started [s] and the body's state
    just before it (sim.mujoco.push_state; None if the target gave none)."""

    push: Push
    sim_t_s: float
    state: Mapping[str, Any] | None = None


class PushScheduler:
    """A streamer observer (``__call__(tel)``) that pushes the torso at each ``Push``'s
    gait time: at the first control tick at or after it, counted from the first tick
    whose ``tel.state`` is "walking". ``applied`` lists what was done."""

    def __init__(self, bus: PushTarget, pushes: Sequence[Push], *,
                 window_s: float = PUSH_WINDOW_S) -> None:
        self.bus = bus
        self.pushes = tuple(sorted(pushes, key=lambda p: p.at_s))
        self.window_s = window_s
        self.applied: list[AppliedPush] = []
        self.clock = GaitClock()

    @property
    def gait_t0(self) -> float | None:
        """Sim time of the first walking tick [s]."""
        return self.clock.t0

    def __call__(self, tel: Telemetry) -> None:
        gait_t = self.clock(tel)
        if gait_t is None:
            return
        while len(self.applied) < len(self.pushes):
            p = self.pushes[len(self.applied)]
            if p.at_s > gait_t + _TIME_EPS:
                break
            state = self.bus.push(p.jx, p.jy, window_s=self.window_s)
            self.applied.append(AppliedPush(p, tel.t, state))

    def as_list(self) -> list[dict[str, Any]]:
        """JSON-ready: each applied push with its sim start time and, where the bus gave
        it, the body's state just before it (``state``)."""
        return [{**dataclasses.asdict(a.push), "sim_t_s": a.sim_t_s,
                 **({"state": dict(a.state)} if a.state is not None else {})}
                for a in self.applied]


class TimedForces:
    """Constant forces on one body, each until its end time: the bus adds a push's force
    to the body's ``xfrc_applied`` row at its start and takes it off at its end (the bus
    ends its physics steps exactly at ``next_end()``)."""

    def __init__(self) -> None:
        self._heap: list[tuple[float, int, npt.NDArray[np.float64]]] = []  # (end [s], n, F)
        self._count = 0

    def start(self, end_s: float, force: npt.NDArray[np.float64],
              xfrc: npt.NDArray[np.float64]) -> None:
        """Add ``force`` [N] (world frame) to ``xfrc`` (the body's row) until ``end_s``."""
        xfrc[:3] += force
        self._count += 1
        heapq.heappush(self._heap, (end_s, self._count, force))

    @property
    def active(self) -> bool:
        """A force is on (until ``next_end()``)."""
        return bool(self._heap)

    def next_end(self) -> float:
        """Sim time [s] at which the next force ends (inf if none)."""
        return self._heap[0][0] if self._heap else math.inf

    def end_due(self, now: float, xfrc: npt.NDArray[np.float64]) -> None:
        """Take every force that ends at or before ``now`` [s] off ``xfrc``."""
        while self._heap and self._heap[0][0] <= now + _TIME_EPS:
            _, _, force = heapq.heappop(self._heap)
            xfrc[:3] -= force
