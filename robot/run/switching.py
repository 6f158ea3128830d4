"""Preset switches on a timeline: `biped walk --switch T:PRESET` and the robustness suite's
transition group.

``PresetSwitcher`` is a streamer observer (called in the loop's thread right after each
tick's write, like the simulated pushes): at the first tick at or after each switch's gait
time, counted from the first "walking" tick, it starts the engine's blend to that preset
(``GaitEngine.blend_to``: every shaping parameter over ``PRESET_BLEND_S``, steering at its
rate), so the next tick already moves towards it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from robot.config.params import GaitParams
from robot.errors import ConfigError
from robot.gait.blend import PRESET_BLEND_S
from robot.gait.engine import GaitEngine
from robot.loop.telemetry import GaitClock, Telemetry

_TIME_EPS = 1e-9  # [s]


@dataclass(frozen=True)
class PresetSwitch:
    """Switch to preset ``name`` (its ``params``, the robot's balance gains included) at
    gait time ``at_s`` [s] >= 0."""

    at_s: float
    name: str
    params: GaitParams

    def __post_init__(self) -> None:
        if not (math.isfinite(self.at_s) and self.at_s >= 0.0):
            raise ConfigError(f"switch to {self.name!r}: the gait time must be a time >= 0 "
                              f"[s], got {self.at_s!r}")


class PresetSwitcher:
    """Calls ``engine.blend_to`` at each switch's gait time (module docstring); ``applied``
    lists (switch, loop time [s]) as done."""

    def __init__(self, engine: GaitEngine, switches: Sequence[PresetSwitch], *,
                 blend_s: float = PRESET_BLEND_S) -> None:
        self.engine = engine
        self.switches = tuple(sorted(switches, key=lambda s: s.at_s))
        self.blend_s = blend_s
        self.applied: list[tuple[PresetSwitch, float]] = []
        self.clock = GaitClock()

    def __call__(self, tel: Telemetry) -> None:
        gait_t = self.clock(tel)
        if gait_t is None or tel.state != "walking":   # ramping out: not walked
            return
        while len(self.applied) < len(self.switches):
            s = self.switches[len(self.applied)]
            if s.at_s > gait_t + _TIME_EPS:
                break
            self.engine.blend_to(s.params, seconds=self.blend_s)
            self.applied.append((s, tel.t))

    def as_list(self) -> list[dict[str, float | str]]:
        """JSON-ready: each applied switch (gait time, preset) with its loop time."""
        return [{"at_s": s.at_s, "preset": s.name, "t_s": t} for s, t in self.applied]
