"""The fixed-rate control loop: absolute deadlines, ramps, safety, watchdog, telemetry.

One run: read the present pose → torque on → ramp (slew-limited) to the gait's start pose
→ ramp the gait amplitude in → stream → on stop ramp the gait out → ramp to the rest pose
→ torque off (or hold). Every tick: clamp to joint limits, limit the slew rate to each
servo's max speed, ONE sync write. Every ``read_every`` ticks: read back and feed the
watchdog. Parameter changes (``set_params``, thread-safe) are validated by the caller's
thread and applied at the start of the next tick.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robot.bus.base import Bus, ServoState
from robot.clock import Clock, MonotonicClock
from robot.engine import GaitEngine
from robot.errors import BusError, SafetyStop
from robot.params import GaitParams
from robot.ramp import ramp
from robot.servo_map import ServoMap
from robot.watchdog import Watchdog, WatchdogConfig

log = logging.getLogger(__name__)


@dataclass
class Telemetry:
    """A snapshot of the loop for the CLI, the panel and recorders (joint order).

    state: "idle" | "ramp_in" | "walking" | "ramp_out" | "rest" | "stopped" | "estop";
    period_error_ms: lateness of the last tick start [ms].
    """

    t: float = 0.0
    state: str = "idle"
    tick: int = 0
    q_cmd: list[float] = field(default_factory=list)
    q_present: list[float] | None = None
    servo: dict[int, ServoState] = field(default_factory=dict)
    period_error_ms: float = 0.0
    overruns: int = 0
    amplitude: float = 0.0
    stop_reason: str | None = None
    fresh: bool = False  # True on ticks that read the servos back


@dataclass
class LoopStats:
    """Loop statistics after a run. period errors are tick-start lateness [ms]."""

    ticks: int
    rate_hz: float
    duration_s: float
    achieved_hz: float
    period_error_p50_ms: float
    period_error_p99_ms: float
    period_error_max_ms: float
    overruns: int
    bus_errors: int
    wall_s: float
    stop_reason: str

    def as_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


TickObserver = Callable[[Telemetry], None]


class Streamer:
    """Streams an engine's joint angles to a bus at ``rate_hz`` [Hz]."""

    def __init__(self, robot_map: ServoMap, bus: Bus, engine: GaitEngine, *,
                 rate_hz: float = 200.0, read_every: int = 10, clock: Clock | None = None,
                 hold_at_end: bool = False, watchdog: WatchdogConfig | None = None,
                 observer: TickObserver | None = None) -> None:
        self.map = robot_map
        self.bus = bus
        self.engine = engine
        self.rate_hz = rate_hz
        self.dt = 1.0 / rate_hz
        self._step = robot_map.max_speed * self.dt  # slew limit per tick [rad]
        self.read_every = max(1, read_every)
        self.clock: Clock = clock or getattr(bus, "clock", None) or MonotonicClock()
        self.hold_at_end = hold_at_end
        self.watchdog = Watchdog(watchdog or WatchdogConfig(), robot_map, robot=engine.robot)
        self.observer = observer
        self.telemetry = Telemetry()
        self._lock = threading.Lock()
        self._pending: dict[str, float] = {}
        self._stop = threading.Event()
        self._estop = threading.Event()
        self._q_last: np.ndarray | None = None
        self._errors: list[float] = []
        self._overruns = 0
        self._bus_errors = 0
        self._next = 0.0
        self._ticks = 0

    # -- control from other threads ------------------------------------------------------
    def set_params(self, changes: Mapping[str, Any], *, where: str = "parameter") -> GaitParams:
        """Validate ``changes`` now (ConfigError, nothing changes) and apply them at the next
        tick. Returns the parameters as they will be."""
        with self._lock:
            merged = {**self._pending, **changes}
            new = self.engine.params.replace(merged, where=where)
            self._pending = {k: float(v) for k, v in merged.items()}
        return new

    def request_stop(self, reason: str = "stop requested") -> None:
        """Ramp the gait out, go to rest, then torque off (or hold)."""
        if not self._stop.is_set():
            self.telemetry.stop_reason = self.telemetry.stop_reason or reason
        self._stop.set()

    def emergency_stop(self) -> None:
        """Torque off at once (the loop ends within one tick)."""
        self.telemetry.stop_reason = "emergency stop"
        self._estop.set()
        self._stop.set()

    # -- the loop ------------------------------------------------------------------------
    def run(self, *, seconds: float | None = None) -> LoopStats:
        """Run until ``seconds`` of gait have passed or a stop is requested."""
        wall0 = time.perf_counter()
        ids = list(self.map.ids)
        t_start = self.clock.now()
        reason = "completed"
        try:
            present = self.map.from_positions(self.bus.read_positions(ids))
            self.bus.set_torque(ids, enabled=True)
            self._q_last = np.asarray(present, dtype=float)
            self._next = self.clock.now()
            self._ramp_to(self.engine.start_pose(), state="ramp_in")
            self.engine.start()
            t_gait = self.clock.now()
            while not self._estop.is_set():
                if self._stop.is_set() or (seconds is not None
                                           and self.clock.now() - t_gait >= seconds):
                    self.engine.stop()
                if self.engine.stopped:
                    break
                self._apply_pending()
                q = self.engine.tick(self.dt)
                state = "walking" if self.engine.running else "ramp_out"
                self._send(np.asarray(q), state=state)
            if not self._estop.is_set():
                self._ramp_to(self.map.clamp(self.map.vector(self.engine.robot.rest)),
                              state="rest")
            reason = self.telemetry.stop_reason or "completed"
        except SafetyStop as e:
            reason = f"watchdog: {e}"
            log.error("safe stop: %s", e)
            self.telemetry.stop_reason = reason
        except BaseException as e:
            reason = f"exception: {type(e).__name__}: {e}"
            self.telemetry.stop_reason = reason
            self._finish(torque_off=True)
            raise
        self._finish(torque_off=self._estop.is_set() or not self.hold_at_end)
        return self._stats(t_start, wall0, reason)

    def _finish(self, *, torque_off: bool) -> None:
        self.telemetry.state = "estop" if self._estop.is_set() else "stopped"
        if torque_off:
            try:
                self.bus.set_torque(list(self.map.ids), enabled=False)
            except BusError as e:
                log.error("could not disable torque: %s", e)
        else:
            log.info("holding the rest pose with torque on (hold_at_end)")
        self._notify()

    def _apply_pending(self) -> None:
        with self._lock:
            if not self._pending:
                return
            changes, self._pending = self._pending, {}
        self.engine.set_params(changes)

    def _ramp_to(self, q_goal: Any, *, state: str) -> None:
        assert self._q_last is not None
        path = ramp(self._q_last, self.map.clamp(q_goal), self.map.max_speed, self.rate_hz,
                    min_duration=0.3)
        for q in path[1:]:
            if self._estop.is_set():
                return
            self._send(q, state=state)

    def _send(self, q: np.ndarray, *, state: str) -> None:
        """Clamp, slew-limit, write; wait for the deadline; read back every Nth tick."""
        assert self._q_last is not None
        q = np.clip(self.map.clamp(q), self._q_last - self._step, self._q_last + self._step)
        q_list = q.tolist()
        self._wait_deadline()
        try:
            self.bus.write_goals(self.map.goals(q_list))
            self.watchdog.bus_ok("write")
        except BusError as e:
            self._bus_errors += 1
            self.watchdog.bus_failed("write", e)
        self._q_last = q
        self._ticks += 1
        tel = self.telemetry
        tel.tick, tel.state, tel.q_cmd = self._ticks, state, q_list
        tel.amplitude = self.engine.amplitude
        tel.fresh = False
        if self._ticks % self.read_every == 0:
            try:
                states = self.bus.read_state(self.map.ids)
                self.watchdog.bus_ok("read")
                tel.servo = states
                tel.q_present = self.map.from_positions(
                    {i: s.position for i, s in states.items()}).tolist()
                tel.fresh = True
                self.watchdog.check(states, q)
            except BusError as e:
                self._bus_errors += 1
                self.watchdog.bus_failed("read", e)
        self._notify()

    def _wait_deadline(self) -> None:
        self._next += self.dt
        self.clock.sleep_until(self._next)
        now = self.clock.now()
        late = now - self._next
        if late > self.dt:
            # Missed at least one whole slot: count it and realign, never burst to catch up.
            missed = int(late // self.dt)
            self._overruns += missed
            self._next += missed * self.dt
            self.watchdog.overrun()
        else:
            self.watchdog.on_time()
        self._errors.append(late)
        self.telemetry.t = now
        self.telemetry.period_error_ms = late * 1e3
        self.telemetry.overruns = self._overruns

    def _notify(self) -> None:
        if self.observer is not None:
            self.observer(self.telemetry)

    def _stats(self, t_start: float, wall0: float, reason: str) -> LoopStats:
        err = np.asarray(self._errors or [0.0]) * 1e3
        duration = max(self.clock.now() - t_start, 1e-9)
        return LoopStats(
            ticks=self._ticks, rate_hz=self.rate_hz, duration_s=duration,
            achieved_hz=self._ticks / duration,
            period_error_p50_ms=float(np.percentile(err, 50)),
            period_error_p99_ms=float(np.percentile(err, 99)),
            period_error_max_ms=float(err.max()), overruns=self._overruns,
            bus_errors=self._bus_errors, wall_s=time.perf_counter() - wall0,
            stop_reason=reason)
