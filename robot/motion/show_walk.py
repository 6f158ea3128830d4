"""A show whose legs walk where the animation walks: the imported joint stream plays as
authored (arms, head, extra joints always; legs outside the walks), and in each walk the
paper's gait drives the legs with travel parameters (speed, turn, side step) that
``biped import`` took from the root's motion (robot/previs/travel.py).

The gait's part is a ``Travel``: the walks as (start, stop) pairs of show time [s] (the
gait starts its ramp in at ``start`` and is told to stop at ``stop``, then ramps out over
the same ``ramp_cycles`` of the gait), the steering changes at their times and the preset
switches (each a blend over robot.gait.blend.PRESET_BLEND_S, as ``biped walk --switch`` and
the panel's preset picker record them). In a take it is the parameter timeline
(robot/motion/takes.py: ``start``, ``set``, ``blend`` and ``stop`` lines at gait ticks of
the take's rate), so it plays at any loop rate.

The legs blend between authored and gait angles without a snap, by the gait's own
envelope: the gait's share of the legs is smoothstep(2 r), r the envelope's linear ramp
variable in [0, 1] (robot/gait/engine.py): the legs become the gait's over the first half
of its ramp in (while its amplitude is still below one half) and the authored ones again
over the last half of its ramp out; at the edges the gait stands at its start pose, so
what blends is two standing poses. A show stopped during a walk ramps the gait out too.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from robot.config.joint_names import LEG_NAMES
from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.motion.keyframes import Sequence
from robot.motion.takes import Take


@dataclass(frozen=True)
class Travel:
    """walks: (start, stop) [s of show time], in order, not overlapping; changes: (t [s],
    {parameter: value}) steering changes in time order; blends: (t [s], {parameter:
    value}) preset switches in time order, each blended in from t (a blend and a change at
    the same tick: the blend first, as robot.motion.scripted.PlaybackEngine does)."""

    walks: tuple[tuple[float, float], ...] = ()
    changes: tuple[tuple[float, Mapping[str, float]], ...] = ()
    blends: tuple[tuple[float, Mapping[str, float]], ...] = ()

    def timeline(self, rate_hz: float) -> list[dict[str, Any]]:
        """The take's timeline lines for it, at gait ticks of ``rate_hz`` [Hz]."""
        events: list[tuple[int, int, dict[str, Any]]] = []
        for start, stop in self.walks:
            events.append((round(start * rate_hz), 1, {"start": True}))
            events.append((round(stop * rate_hz), 2, {"stop": True}))
        for t, step in self.changes:
            events.append((round(t * rate_hz), 0, {"set": dict(step)}))
        for t, preset in self.blends:
            events.append((round(t * rate_hz), -1, {"blend": dict(preset)}))
        events.sort(key=lambda e: (e[0], e[1]))
        return [{"gait_tick": k, "t": k / rate_hz, **what} for k, _, what in events]

    @staticmethod
    def of_take(take: Take) -> Travel:
        """The take's timeline as a Travel (ConfigError if its starts and stops do not
        alternate start, stop, start, ...; a last start without a stop walks to the end)."""
        rate = take.header.rate_hz
        marks = sorted([(k, 1) for k in take.starts] + [(k, 0) for k in take.stops])
        walks: list[tuple[float, float]] = []
        start: int | None = None
        for k, is_start in marks:
            if (start is None) != bool(is_start):
                raise ConfigError(f"{take.source}: gait_tick {k}: a walk's start and stop do "
                                  "not alternate (start, stop, start, ...)")
            if is_start:
                start = k
            else:
                assert start is not None
                walks.append((start / rate, k / rate))
                start = None
        if start is not None:
            walks.append((start / rate, math.inf))
        changes = tuple((k / rate, dict(step)) for k, step in sorted(take.changes.items()))
        blends = tuple((k / rate, dict(preset)) for k, preset in sorted(take.blends.items()))
        return Travel(tuple(walks), changes, blends)


def _smoothstep(x: float) -> float:
    x = min(max(x, 0.0), 1.0)
    return x * x * (3.0 - 2.0 * x)


class ShowEngine(GaitEngine):
    """``stream``: every authored joint over show time (robot.motion.show.stream_sequence);
    ``travel``: when the gait walks and how. A motion source: ``start`` / ``stop`` begin
    and end the show (a stop during a walk ramps the gait's legs out first); the gait's
    own start and stop follow ``travel``."""

    def __init__(self, robot: RobotConfig, params: GaitParams, *, stream: Sequence,
                 travel: Travel) -> None:
        super().__init__(robot, params)
        self.stream = stream
        self.travel = travel
        names = robot.joint_names
        self._index = [names.index(j) for j in stream.joints]
        self._legs = [i for i, n in enumerate(names) if n in LEG_NAMES]
        events: list[tuple[float, int, Mapping[str, float] | None]] = []
        for start, stop in travel.walks:
            events += [(start, 1, None), (stop, 2, None)]
        events += [(t, 0, step) for t, step in travel.changes]
        events += [(t, -1, preset) for t, preset in travel.blends]
        self._events = sorted(events, key=lambda e: (e[0], e[1]))
        self._next = 0
        self._on = False

    @property
    def duration(self) -> float:
        return self.stream.duration

    @property
    def gait_share(self) -> float:
        """The gait's share of the legs now, in [0, 1]."""
        return _smoothstep(2.0 * self._ramp)

    def pose(self, *, amplitude: float | None = None) -> list[float]:
        gait = super().pose(amplitude=amplitude)
        q = list(gait)
        for i, v in zip(self._index, self.stream.at(self.time).tolist(), strict=True):
            q[i] = min(max(v, self._lo[i]), self._hi[i])
        w = self.gait_share
        if w > 0.0:
            for i in self._legs:
                q[i] = w * gait[i] + (1.0 - w) * q[i]
        return q

    # -- motion source: the show's start and stop; the gait's follow the travel ---------
    def start(self) -> None:
        self._on = True

    def stop(self) -> None:
        self._on = False
        super().stop()

    @property
    def stopped(self) -> bool:
        return not self._on and super().stopped

    @property
    def state(self) -> str:
        """"walking" while the show streams (the loop's word for a source that plays),
        "ramp_out" after its stop."""
        return "walking" if self._on else "ramp_out"

    @property
    def finished(self) -> bool:
        """The stream has played to its end."""
        return self.time >= self.duration - 1e-12

    def tick(self, dt: float) -> list[float]:
        if self.finished and self._on:
            self.stop()
        while self._next < len(self._events) and self._events[self._next][0] <= self.time + 1e-9:
            t, kind, step = self._events[self._next]
            self._next += 1
            if kind == -1 and step:
                self.blend_to(self.params.replace(step, where=f"show blend at t={t:.3f} s"))
            elif kind == 0 and step:
                self.set_params(step, where=f"show travel at t={t:.3f} s")
            elif kind == 1 and self._on:
                super().start()
            elif kind == 2:
                super().stop()
        return super().tick(dt)
