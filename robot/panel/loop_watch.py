"""What the panel's loop process reports: the loop's telemetry as the panel shows it, its
measured rate and rate alarms (robot.panel.rate_guard), the simulation's metrics, who is
driving, how the last run ended. Written by the loop thread every tick (cheap copies, no
forward kinematics: the panel's process draws the stick figure), read by the command
thread under one lock.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from robot.bus.base import ServoState
from robot.config.robot import RobotConfig
from robot.loop.telemetry import LoopStats, Telemetry, TickObserver
from robot.panel.rate_guard import RateGuard
from robot.panel.runs import Play, Record, RunKind, ShowTake
from robot.panel.show_clock import ShowClock
from robot.panel.snapshot import TickRate, telemetry_snapshot

RATE_WINDOW = 50  # ticks over which the loop rate is measured
#: A per-run callback → the simulation's metrics (robot.panel.sim_monitor).
MonitorFactory = Callable[[], Callable[[Telemetry], dict[str, Any]]]
#: ``verdict(reason, at_once)``: the rate guard wants the run stopped.
OnVerdict = Callable[[str, bool], None]


class LoopWatch:
    """The loop's state for the panel (see the module docstring)."""

    def __init__(self, robot: RobotConfig, rate_hz: float, *, stall_s: float = 0.1) -> None:
        self.robot = robot
        self.rate_hz = rate_hz
        self.stall_s = stall_s
        self.monitor_factory: MonitorFactory | None = None
        self._lock = threading.Lock()
        self._tel: dict[str, Any] = {"state": "idle"}
        self._sim: dict[str, Any] = {}
        self._rate = TickRate(RATE_WINDOW)
        self._idle: tuple[list[float], dict[int, ServoState]] | None = None
        self.runs = 0
        self.kind: RunKind | None = None
        self.driver: str | None = None
        self.released: str | None = None
        self.fault: str | None = None
        self.last_stats: LoopStats | None = None
        self.record_error: str | None = None
        self.holding = False
        self._clock: ShowClock | None = None

    # -- the loop thread -----------------------------------------------------------------
    def observer(self, verdict: OnVerdict, *, show_time: Callable[[], float] | None = None
                 ) -> TickObserver:
        """The tick observer of one run: copy the telemetry, measure the rate, watch it
        (``verdict`` when the guard wants a stop), the sim's metrics, a show's clock
        (``show_time``: the engine's time [s])."""
        monitor = self.monitor_factory() if self.monitor_factory is not None else None
        guard = RateGuard(self.rate_hz, stall_s=self.stall_s)
        stopped = [False]

        def observe(tel: Telemetry) -> None:
            snap = telemetry_snapshot(tel)
            self._rate.add(tel.tick, tel.t)
            v = guard.update(tel.t, tel.overruns)
            sim = monitor(tel) if monitor is not None else None
            with self._lock:
                self._tel = snap
                if self._clock is None and isinstance(self.kind, ShowTake) and show_time:
                    self._clock = ShowClock(self.kind, show_time)
                if self._clock is not None:
                    self._clock.tick(tel.state)
                self.fault = v.alarm or (self.fault if stopped[0] else None)
                if sim is not None:
                    self._sim = sim
            if v.stop and not stopped[0]:
                stopped[0] = True
                verdict(v.alarm or "the loop is late", v.at_once)
        return observe

    def begin(self, kind: RunKind, driver: str | None) -> None:
        with self._lock:
            self._rate.clear()
            self._sim, self._idle = {}, None
            self._tel = {"state": "starting"}
            self.runs += 1
            self.kind, self.driver, self.released = kind, driver, None
            self._clock = None
            self.fault, self.record_error, self.holding = None, None, False

    def end(self, stats: LoopStats | None, *, holding: bool, record_error: str | None,
            fault: str | None = None, telemetry: Telemetry | None = None) -> None:
        """The run has ended: ``fault`` the rate guard's stop, if it stopped it."""
        with self._lock:
            if telemetry is not None:
                self._tel = telemetry_snapshot(telemetry)
            self.last_stats, self.holding = stats, holding
            self.kind = self.driver = None
            self._clock = None
            self.record_error = record_error
            if stats is None:
                return
            if fault:                  # the rate guard stopped it
                self.fault = fault
            elif stats.estop:          # the operator's: not a fault, even if a write
                self.fault = None      # was refused at the latch on its way out
                self._tel["stop_reason"] = "emergency stop"
            else:                      # how it ended, not a late alarm from before
                self.fault = stats.stop_reason if stats.fault else None

    def failed(self, reason: str) -> None:
        with self._lock:
            self.fault = reason

    def idle_pose(self, pose: tuple[list[float], dict[int, ServoState]] | None) -> None:
        with self._lock:
            self._idle = pose

    # -- the command thread ---------------------------------------------------------------
    def estop(self, *, running: bool) -> None:
        with self._lock:
            self.holding = False
            if not running:
                self._tel = {**self._tel, "state": "estop", "stop_reason": "emergency stop"}

    def reset(self) -> None:
        with self._lock:
            self.holding, self._sim, self.fault = False, {}, None
            self._tel = {"state": "idle", "stop_reason": "simulation reset"}

    def state_name(self) -> str:
        with self._lock:
            return str(self._tel.get("state", "idle"))

    def snapshot(self, *, running: bool) -> dict[str, Any]:
        with self._lock:
            tel, kind = dict(self._tel), self.kind
            if not running and self._idle is not None:
                tel["q_present"], tel["servo"] = self._idle
            stats = self.last_stats
            return {"running": running, "tel": tel, "sim": dict(self._sim),
                    "loop_hz": self._rate.hz(), "runs": self.runs, "driver": self.driver,
                    "recording": kind.take if isinstance(kind, Record) else None,
                    "playing": kind.take if isinstance(kind, (Play, ShowTake)) else None,
                    "show": self._clock.progress() if self._clock is not None else None,
                    "released": self.released, "holding": self.holding,
                    "fault": self.fault, "record_error": self.record_error,
                    "last_stats": stats.as_dict() if stats is not None else None}
