"""The joint table `biped monitor` shows: read-back servo states → rows → text or JSON.

Pure: no I/O. Angles come from ``ServoMap.from_positions`` (not clamped), so a joint moved
by hand past its limits shows where it is, with a marker.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from robot.bus.base import ServoState
from robot.bus.servo_map import ServoMap
from robot.config.robot import RobotConfig

#: Marker for a joint below its min_rad / above its max_rad.
BELOW, ABOVE = "<MIN", ">MAX"


@dataclass(frozen=True)
class JointRow:
    """One joint's read-back. q_rad: angle [rad]; min/max_rad: its limits [rad];
    outside: "" inside the limits, else BELOW or ABOVE."""

    name: str
    id: int
    q_rad: float
    ticks: int
    temperature: float | None
    load: float | None
    errors: tuple[str, ...]
    min_rad: float
    max_rad: float
    #: its gain registers as read at start (robot/servo/gains.py names), None: not read
    gains: Mapping[str, int] | None = None

    @property
    def q_deg(self) -> float:
        return math.degrees(self.q_rad)

    @property
    def outside(self) -> str:
        return BELOW if self.q_rad < self.min_rad else ABOVE if self.q_rad > self.max_rad else ""

    def as_dict(self) -> dict[str, Any]:
        return {"joint": self.name, "id": self.id, "rad": self.q_rad, "deg": self.q_deg,
                "ticks": self.ticks, "temperature": self.temperature, "load": self.load,
                "errors": list(self.errors), "min_rad": self.min_rad,
                "max_rad": self.max_rad, "outside": self.outside or None,
                "gains": None if self.gains is None else dict(self.gains)}


def rows(robot: RobotConfig, servo_map: ServoMap, states: Mapping[int, ServoState], *,
         gains: Mapping[int, Mapping[str, int] | None] | None = None) -> list[JointRow]:
    """One row per joint, in the robot's joint order (``states`` has every id; ``gains``:
    per id, as read once at start)."""
    gains = gains or {}
    q = servo_map.from_positions({sid: s.position for sid, s in states.items()})
    return [JointRow(name=j.name, id=j.servo_id, q_rad=float(qi) + 0.0,  # no -0.0
                     ticks=states[j.servo_id].position,
                     temperature=states[j.servo_id].temperature,
                     load=states[j.servo_id].load,
                     errors=tuple(sorted(states[j.servo_id].errors)),
                     min_rad=j.min_rad, max_rad=j.max_rad, gains=gains.get(j.servo_id))
            for j, qi in zip(robot.joints, q, strict=True)]


def _num(v: float | None, fmt: str) -> str:
    return "-" if v is None else format(v, fmt)


HEADER = (f"{'joint':<16} {'id':>3} {'rad':>8} {'deg':>8} {'ticks':>6} {'temp C':>6} "
          f"{'load %':>7}  {'limits [deg]':<17} {'':<4}  errors")


def format_row(r: JointRow) -> str:
    limits = f"{math.degrees(r.min_rad):+.1f}..{math.degrees(r.max_rad):+.1f}"
    return (f"{r.name:<16} {r.id:>3} {r.q_rad:>+8.3f} {r.q_deg:>+8.1f} {r.ticks:>6} "
            f"{_num(r.temperature, '.0f'):>6} {_num(r.load, '+.1f'):>7}  {limits:<17} "
            f"{r.outside:<4}  {','.join(r.errors) or '-'}")


def format_table(table: list[JointRow], *, title: str = "") -> list[str]:
    """The table as lines (no trailing newline): title, header, one line per joint, one
    line per distinct set of gains (``gains_lines``), and a summary line naming the joints
    outside their limits or with errors."""
    lines = ([title] if title else []) + [HEADER] + [format_row(r) for r in table]
    lines += gains_lines({r.name: r.gains for r in table if r.gains is not None})
    out = [f"{r.name} {r.outside}" for r in table if r.outside]
    bad = [f"{r.name}: {','.join(r.errors)}" for r in table if r.errors]
    lines.append("; ".join(
        ([f"outside limits: {', '.join(out)}"] if out else []) +
        ([f"errors: {'; '.join(bad)}"] if bad else [])) or "all joints inside their limits, "
        "no errors")
    return lines


def gains_lines(gains: Mapping[str, Mapping[str, int] | None]) -> list[str]:
    """One line per distinct set of gain register values: ``gains name=value ...: who,
    who`` (``who``: a joint or servo; "all" when they all agree; None: not readable, its
    model unknown)."""
    groups: dict[tuple[tuple[str, int], ...], list[str]] = {}
    for who, values in gains.items():
        groups.setdefault(tuple((values or {}).items()), []).append(who)
    return [f"gains {' '.join(f'{k}={v}' for k, v in key) or 'unknown'}: "
            f"{'all' if len(groups) == 1 else ', '.join(whos)}" for key, whos in groups.items()]
