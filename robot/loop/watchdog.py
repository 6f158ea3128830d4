"""Watchdog: turns bus errors, overruns and servo faults into a safe stop with a reason.

A servo not following is judged two ways: relative to how its goal moves (a jam or a block:
robot.loop.following), and, as a backstop, far from its goal for several read-backs. Both
need read-backs often enough: robot.config.read_back bounds the period everywhere it can be
set (``--read-every``, a take's header), so no input switches the watchdog off.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robot.bus.base import ServoState
from robot.bus.servo_map import ServoMap
from robot.config.robot import RobotConfig
from robot.errors import BusDead, BusError, SafetyStop
from robot.loop.following import FollowCheck

#: How many times the longest retried transaction the servos' bus watchdog must allow.
FAILSAFE_MARGIN = 1.5

FAULTS = frozenset({"overheating", "overload", "voltage", "electrical_shock", "encoder",
                    "overcurrent"})


@dataclass(frozen=True)
class WatchdogConfig:
    """Thresholds.

    bus_error_streak: consecutive failed bus transactions before a stop;
    overrun_streak: consecutive overrunning ticks before a stop;
    max_temperature_c: [°C]; follow_error_rad: commanded - present beyond which a servo
    is "not following" whatever its goal does [rad] (the backstop; the jam check is
    robot.loop.following); follow_reads: consecutive read-backs it must persist;
    failsafe_s: the servos' own bus watchdog, armed while streaming: with no packet for
    this long [s] they stop by themselves (None: leave it off). It is armed at least
    ``FAILSAFE_MARGIN`` times the bus's ``retry_span_s`` plus two ticks, so a transaction
    that is retried to its end never trips it.
    """

    bus_error_streak: int = 5
    overrun_streak: int = 50
    max_temperature_c: float = 70.0
    follow_error_rad: float = 0.6
    follow_reads: int = 5
    failsafe_s: float | None = 0.1


class Watchdog:
    """The checks of one run; ``read_period_s``: time between read-backs [s]."""

    def __init__(self, cfg: WatchdogConfig, servo_map: ServoMap, *,
                 robot: RobotConfig | None = None, read_period_s: float = 0.05) -> None:
        self.cfg = cfg
        self.map = servo_map
        self.robot = robot
        self._bus_streak = {"write": 0, "read": 0}
        self._overrun_streak = 0
        self._follow_streak = np.zeros(len(servo_map.ids), dtype=int)
        self._follow = FollowCheck(servo_map, read_period_s=read_period_s)

    def name(self, servo_id: int) -> str:
        """'servo 4 (r_knee)': a servo as messages name it."""
        j = self.robot.joint_by_id(servo_id) if self.robot else None
        return f"servo {servo_id}" + (f" ({j.name})" if j else "")

    def bus_ok(self, kind: str) -> None:
        """A ``kind`` ("write" or "read") transaction succeeded."""
        self._bus_streak[kind] = 0

    def bus_failed(self, kind: str, error: BusError) -> None:
        """Writes and read-backs keep separate streaks: goals that still go out do not
        excuse a robot that can no longer be monitored."""
        self._bus_streak[kind] += 1
        n = self._bus_streak[kind]
        if n >= self.cfg.bus_error_streak:
            raise BusDead(f"{n} bus errors in a row ({kind}); last: {error}") from error

    def on_time(self) -> None:
        self._overrun_streak = 0

    def overrun(self) -> None:
        self._overrun_streak += 1
        if self._overrun_streak >= self.cfg.overrun_streak:
            raise SafetyStop(f"{self._overrun_streak} loop overruns in a row: the loop cannot "
                             f"keep its rate; lower --rate or the read-back frequency")

    def check(self, states: Mapping[int, ServoState], q_cmd: npt.NDArray[np.float64], *,
              present: npt.NDArray[np.float64] | None = None) -> None:
        """Raise SafetyStop on a hardware fault, overheating, or a servo not following.
        ``present``: the positions of ``states`` in radians, joint order, if known."""
        self.faults(states)
        self._following(states, q_cmd, present)

    def faults(self, states: Mapping[int, ServoState]) -> None:
        """Raise SafetyStop on a hardware fault or overheating."""
        hot = self.cfg.max_temperature_c
        for sid, s in states.items():
            if s.errors and s.errors & FAULTS:
                raise SafetyStop(f"{self.name(sid)} reports {', '.join(sorted(s.errors & FAULTS))}")
            if s.temperature is not None and s.temperature > hot:
                raise SafetyStop(f"{self.name(sid)} at {s.temperature:.0f} °C "
                                 f"(limit {hot:.0f} °C)")

    def _following(self, states: Mapping[int, ServoState], q_cmd: npt.NDArray[np.float64],
                   present: npt.NDArray[np.float64] | None) -> None:
        if present is None:
            present = self.map.from_positions({i: s.position for i, s in states.items()})
        stuck = self._follow.add(q_cmd, present)
        if stuck is not None:
            i, r_goal, r_present = stuck
            raise SafetyStop(f"{self.name(self.map.ids[i])} stopped following: its goal "
                             f"moved over {r_goal:.2f} rad in {self._follow.window_s:.2g} s, "
                             f"it moved {r_present:.3f} rad (jammed or blocked)")
        err = np.abs(present - q_cmd)
        lagging = err > self.cfg.follow_error_rad
        self._follow_streak = np.where(lagging, self._follow_streak + 1, 0)
        worst = int(np.argmax(self._follow_streak))
        if self._follow_streak[worst] >= self.cfg.follow_reads:
            sid = self.map.ids[worst]
            raise SafetyStop(f"{self.name(sid)} stopped following: {err[worst]:.2f} rad "
                             f"from its goal for {self._follow_streak[worst]} read-backs")
