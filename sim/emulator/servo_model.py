"""What one emulated servo model is (``ServoModel``); the models are in
``sim.emulator.servo_models`` and ``servo_models_more``."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field


@dataclass(frozen=True)
class ServoModel:
    """name; number: Model Number register / ping; family: the protocol family (baud
    codes, error bits, watchdog); resolution: positions (0..resolution-1); span_deg: angle
    they cover [deg]; no_load_speed: at the nominal voltage [rad/s]; table: its control
    table's key in ``control_tables.TABLES`` when not the family's own; initial: the
    model's own initial values where its manual differs from the family's table; axes: ids
    one case answers at."""

    name: str
    number: int
    family: str
    resolution: int
    no_load_speed: float
    span_deg: float = 360.0
    table: str = ""
    initial: Mapping[str, int] = field(default_factory=dict)
    #: motors (ids) in one case: 2 for the 2XL430-W250 / 2XC430-W250 (sim/emulator/dual_axis.py)
    axes: int = 1

    @property
    def layout(self) -> str:
        """Key of its control table in ``control_tables.TABLES``."""
        return self.table or self.family

    @property
    def ticks_per_rad(self) -> float:
        return self.resolution / math.radians(self.span_deg)


def rpm(rev_per_min: float) -> float:
    """rev/min -> rad/s."""
    return rev_per_min * 2.0 * math.pi / 60.0


def per_60deg(seconds: float) -> float:
    """A hobby datasheet's "s/60 deg" -> rad/s."""
    return math.radians(60.0) / seconds
