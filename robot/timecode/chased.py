"""A show that follows an external timecode (``biped play SHOW --chase ...``): a motion
source around a show played on its own (robot.motion.layered.LayeredEngine with
``walk=False``: an imported stream, a keyframe sequence), whose time is the chased show
time (robot/timecode/chase.py) instead of the loop's ticks.

Before the timecode reaches the start (show time < 0) it holds the show's first pose
(state "waiting"); then it plays the show at the show time of each tick's deadline. A jump
in timecode (or a start found already past 0) is met by a ramp, never a snap: the
difference between the pose it was at and the pose at the new show time decays along a
minimum-jerk ramp (robot.motion.ramp.min_jerk) long enough that its own speed stays
within half each joint's slew limit and its acceleration within half the import's
acceleration limit (robot.previs.violations.accel_limits), while the show plays on under
it; the loop's slew limit bounds the sum on the wire. At the show's end it stops (the
loop ramps to rest); a stop from outside (the timecode lost, Ctrl-C) does the same.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import numpy.typing as npt

from robot.config.params import GaitParams
from robot.loop.clock import Clock
from robot.motion.layered import LayeredEngine
from robot.motion.ramp import min_jerk
from robot.previs.violations import accel_limits
from robot.timecode.chase import ChaseClock
from robot.timecode.sources import TimecodeSource

Array = npt.NDArray[np.float64]
#: Peak speed and acceleration of a min-jerk move, per unit distance and duration.
PEAK_SPEED, PEAK_ACCEL = 1.875, 5.7735
#: Share of the limits a jump's ramp may use (the show moves on under it).
SHARE = 0.5


class ChasedShow:
    """``show``: the show on its own; ``chase``: the clock; ``source``: where the
    timecode comes from (opened at ``entry``, closed by ``close``); ``clock``: the loop's."""

    def __init__(self, show: LayeredEngine, chase: ChaseClock, source: TimecodeSource,
                 clock: Clock) -> None:
        self.show, self.chase, self.source, self.clock = show, chase, source, clock
        self.robot = show.robot
        self.show_time: float | None = None      # at the last tick [s]
        self.ended: str | None = None             # why it stopped by itself
        self.lost = False
        self._on = False
        self._playing = False
        self._opened = False
        self._jumps = 0
        self._last: Array | None = None
        self._offset: Array | None = None
        self._ramp_t = 0.0
        self._ramp_s = 0.0
        seq = show.keyframes
        self._duration = seq.duration if seq is not None and not seq.loop else math.inf
        speed = np.array([j.max_speed_rad_s for j in self.robot.joints])
        self._speed, self._accel = SHARE * speed, SHARE * accel_limits(self.robot)

    # -- motion source ------------------------------------------------------------------
    @property
    def params(self) -> GaitParams:
        return self.show.params

    def set_params(self, changes: Mapping[str, float], *, where: str = "parameter"
                   ) -> GaitParams:
        return self.show.set_params(changes, where=where)

    def entry(self, present: Array, dt: float) -> list[float]:
        if not self._opened:
            self.source.open(self.clock.now())
            self._opened = True
        return self.show.entry(present, dt)

    def exit_pose(self) -> Array:
        return self.show.exit_pose()

    def start(self) -> None:
        self._on = True

    def stop(self) -> None:
        self._on = False
        self.show.stop()

    @property
    def stopped(self) -> bool:
        return not self._on

    @property
    def state(self) -> str:
        if not self._on:
            return "ramp_out"
        return "walking" if self._playing else "waiting"

    @property
    def amplitude(self) -> float:
        return self.show.amplitude

    def prepare(self) -> None:
        """What can fail before anything moves (robot.timecode.sources)."""
        self.source.prepare()

    def close(self) -> None:
        self.source.close()

    def tick(self, dt: float) -> list[float]:
        now = self.clock.now()
        for r in self.source.poll(now):
            self.chase.reading(r.at, r.frame, r.rate)
        self.lost = not self.chase.check(now)
        s = self.chase.show_time(now + dt)       # at this tick's deadline
        self.show_time = s
        jumped = self.chase.jumps != self._jumps
        self._jumps = self.chase.jumps
        first = s is not None and s >= 0.0 and not self._playing
        if first:
            self._playing = True
            self.show.start()
        self.show.time = min(max(s or 0.0, 0.0), self._duration)
        target = np.asarray(self.show.pose(), dtype=float)
        if self._last is not None and (jumped or (first and s is not None and s > dt)):
            self._begin_ramp(self._last - target)
        q = target + self._blend(dt)
        self._last = q
        if self._playing and self.show.finished and self._on:
            self.ended = "end of show"
            self.stop()
        return q.tolist()

    # -- a jump's ramp ------------------------------------------------------------------
    def _begin_ramp(self, offset: Array) -> None:
        d = np.abs(offset)
        need = np.maximum(PEAK_SPEED * d / self._speed, np.sqrt(PEAK_ACCEL * d / self._accel))
        self._offset, self._ramp_s, self._ramp_t = offset, max(float(need.max()), 0.05), 0.0

    def _blend(self, dt: float) -> Array:
        if self._offset is None:
            return np.zeros(len(self.robot.joints))
        self._ramp_t += dt
        left = 1.0 - float(min_jerk(min(self._ramp_t / self._ramp_s, 1.0)))
        out = self._offset * left
        if left <= 0.0:
            self._offset = None
        return np.asarray(out, dtype=float)
