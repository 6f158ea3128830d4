"""Gait engines that record or replay the parameter timeline, for the one streaming loop.

Both are ``GaitEngine``s (with an optional keyframe layer, robot.motion.layered), so both
are motion sources (robot.loop.source) and a recorded or replayed run (the take player)
goes through ``robot.loop.streamer`` exactly like a walk: ramp in from the
present pose, balance, clamp, slew, watchdog, ramp out, rest, torque off. They only count
gait ticks (calls of ``tick``):

- ``RecordingEngine`` reports every parameter change, preset switch (a blend, robot.gait
  .blend) and the stop with the gait tick it takes effect at (the streamer applies pending
  changes and stops just before a tick);
- ``PlaybackEngine`` makes the same calls at the same ticks, so the gait (a pure function
  of that timeline) is the same, bit for bit.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from robot.config.params import GaitParams, canonical_name
from robot.config.robot import RobotConfig
from robot.gait.blend import PRESET_BLEND_S
from robot.motion.keyframes import Sequence
from robot.motion.layered import LayeredEngine

#: ``sink(gait_tick, **what)``: what = {"set": {...}}, {"blend": {...}} or {"stop": True}.
Sink = Callable[..., None]


class RecordingEngine(LayeredEngine):
    """A GaitEngine that reports its timeline to ``sink`` as it is driven."""

    def __init__(self, robot: RobotConfig, params: GaitParams, *, sink: Sink,
                 keyframes: Sequence | None = None) -> None:
        super().__init__(robot, params, keyframes=keyframes)
        self.gait_ticks = 0
        self._sink = sink

    def set_params(self, changes: Mapping[str, float], *, where: str = "parameter"
                   ) -> GaitParams:
        new = super().set_params(changes, where=where)  # raises (nothing recorded) if bad
        self._sink(self.gait_ticks, set={canonical_name(n): float(v)
                                         for n, v in changes.items()})
        return new

    def blend_to(self, params: GaitParams, *, seconds: float = PRESET_BLEND_S) -> None:
        super().blend_to(params, seconds=seconds)
        self._sink(self.gait_ticks, blend=params.as_dict())

    def stop(self) -> None:
        if self.running:
            self._sink(self.gait_ticks, stop=True)
        super().stop()

    def tick(self, dt: float) -> list[float]:
        q = super().tick(dt)
        self.gait_ticks += 1
        return q


class PlaybackEngine(LayeredEngine):
    """A GaitEngine that replays a timeline: ``changes`` (gait tick → parameters), preset
    switches ``blends`` (gait tick → every parameter of the preset, blended in) and a stop
    before gait tick ``stop_tick`` (None: it runs until the streamer stops it)."""

    def __init__(self, robot: RobotConfig, params: GaitParams, *,
                 changes: Mapping[int, Mapping[str, float]], stop_tick: int | None,
                 keyframes: Sequence | None = None,
                 blends: Mapping[int, Mapping[str, float]] | None = None) -> None:
        super().__init__(robot, params, keyframes=keyframes)
        self.gait_ticks = 0
        self._changes = changes
        self._blends = blends or {}
        self.stop_tick = stop_tick

    @property
    def progress(self) -> float:
        """Share of the timeline played, in [0, 1]."""
        if not self.stop_tick:
            return 0.0
        return min(1.0, self.gait_ticks / self.stop_tick)

    def tick(self, dt: float) -> list[float]:
        n = self.gait_ticks
        if n == self.stop_tick:
            self.stop()
        preset = self._blends.get(n)
        if preset:
            self.blend_to(self.params.replace(preset, where=f"take, gait tick {n}"))
        step = self._changes.get(n)
        if step:
            self.set_params(step, where=f"take, gait tick {n}")
        q = super().tick(dt)
        self.gait_ticks = n + 1
        return q
