"""The fixed-rate control loop: absolute deadlines, ramps, safety, watchdog, telemetry.

There is one loop: ``_send`` (clamp to the joint limits, limit the slew rate to each
servo's max speed, wait for the next absolute deadline, ONE sync write, every
``read_every`` ticks a read-back for the watchdog). ``run`` streams any motion source
(robot.loop.source: a walk, a keyframe sequence, a take, a move to a pose) as a sequence
of ``_send``: ramp to the source's entry, its ticks, ramp to its exit pose; every run
starts and ends the same way:

start: read the present pose → refuse (nothing moves, torque untouched) if a joint is
  outside its limits by more than one slew step → goal := present → torque on → arm the
  servos' own bus watchdog where they have one; on servos the thread's priority is raised
  until the run has ended (robot.loop.priority).
end, by cause (docs/hardware.md, "What happens when"):
  completed / operator stop (``request_stop``, first Ctrl-C or SIGTERM): ramp the gait out,
    ramp to rest (a pose move: stop where it is), then torque off, or hold with
    ``hold_at_end``;
  emergency stop (second signal, panel E-stop): torque off at once;
  a fault the robot can still be driven through (an observer raised, e.g. a full disk
    under ``--record``; the loop cannot keep its rate): ramp out, rest, torque off;
  an exception in the gait engine (the source): ramp straight to rest, torque off;
  a fault that makes driving unsafe or impossible (hardware error flag, over-temperature,
    a servo not following, a dead bus, any other exception): torque off at once.
A fault always ends with torque off, ``hold_at_end`` or not (robot.loop.ending.end: a
hold needs servos that still answer); a stop before the start: nothing is written.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Mapping
from typing import Generic

import numpy as np

from robot.bus.base import Bus
from robot.bus.servo_map import ServoMap
from robot.config.params import GaitParams
from robot.config.read_back import max_read_every
from robot.errors import BusDead, BusError, SafetyStop
from robot.loop.clock import Clock, MonotonicClock, Pacer
from robot.loop.ending import arm_failsafe, end, explain_stop
from robot.loop.latency import SampleStats
from robot.loop.pending import PendingParams
from robot.loop.priority import loop_priority
from robot.loop.read_state import read_state
from robot.loop.source import ClampReporter, Feedback, JointTargets, JointVector, MotionSource, SourceT
from robot.loop.start_check import check_inside_limits
from robot.loop.telemetry import LoopStats, Telemetry, TickObserver, loop_stats
from robot.loop.watchdog import Watchdog, WatchdogConfig
from robot.motion.ramp import ramp

__all__ = ["Feedback", "LoopStats", "MotionSource", "Streamer", "Telemetry", "TickObserver"]

log = logging.getLogger(__name__)

class Streamer(Generic[SourceT]):
    """Streams a motion source's joint angles to a bus at ``rate_hz`` [Hz]."""

    def __init__(self, robot_map: ServoMap, bus: Bus, source: SourceT, *,
                 rate_hz: float = 200.0, read_every: int = 10, clock: Clock | None = None,
                 hold_at_end: bool = False, watchdog: WatchdogConfig | None = None,
                 observer: TickObserver | None = None,
                 feedback: Feedback | None = None) -> None:
        self.map = robot_map
        self.bus = bus
        self.source = source
        self.rate_hz, self.dt = rate_hz, 1.0 / rate_hz
        self._step = robot_map.max_speed * self.dt  # slew limit per tick [rad]
        self.read_every = min(max(1, read_every), max_read_every(rate_hz))  # inputs refuse more
        bus.check_rate(rate_hz, read_every=self.read_every)   # before anything moves
        self.clock: Clock = clock or getattr(bus, "clock", None) or MonotonicClock()
        self.hold_at_end = hold_at_end
        self.watchdog_config = watchdog or WatchdogConfig()
        self.watchdog = Watchdog(self.watchdog_config, robot_map, robot=source.robot,
                                 read_period_s=self.read_every * self.dt)
        self.observer, self.feedback = observer, feedback
        self._feedback_on = False
        self.telemetry = Telemetry()
        self._pending = PendingParams()
        self._stop = threading.Event()
        self._estop = threading.Event()
        self._fault: str | None = None
        self._bus_dead = False
        self._q_last: JointVector = np.zeros(len(robot_map.ids))
        self._lateness, self._slewed = SampleStats(), np.zeros(len(robot_map.ids), np.int64)
        self._overruns = self._bus_errors = self._ticks = 0
        self._pacer = Pacer(self.clock, self.dt)

    @property
    def engine(self) -> SourceT:
        """The source being streamed (the name from when it was always a gait engine)."""
        return self.source

    # -- control from other threads ------------------------------------------------------
    def set_params(self, changes: Mapping[str, float], *, where: str = "parameter") -> GaitParams:
        """Validate ``changes`` now (ConfigError, nothing changes) and apply them at the next
        tick. Returns the parameters as they will be."""
        return self._pending.add(self.source, changes, where=where)

    def blend_to(self, params: GaitParams) -> None:
        """Switch the source to another preset's ``params`` (validated) at the next tick,
        blended (robot.gait.blend; a source without blends takes them as a change)."""
        self._pending.blend(params)

    def request_stop(self, reason: str = "stop requested") -> None:
        """Ramp the gait out, go to rest, then torque off (or hold)."""
        if not self._stop.is_set():
            self.telemetry.stop_reason = self.telemetry.stop_reason or reason
        self._stop.set()

    def emergency_stop(self, reason: str = "emergency stop") -> None:
        """Torque off at once (the loop ends within one tick)."""
        self.telemetry.stop_reason = reason
        self._estop.set()
        self._stop.set()

    # -- runs ----------------------------------------------------------------------------
    def run(self, *, seconds: float | None = None) -> LoopStats:
        """Stream the source until it has stopped, ``seconds`` of it have passed (then it
        is stopped: a gait ramps out) or a stop is requested."""
        wall0 = time.perf_counter()
        t_start = self.clock.now()
        if self._stop.is_set():   # stopped before it started: nothing moves
            return self._stats(t_start, wall0, self.telemetry.stop_reason, torque="untouched")
        ids = list(self.map.ids)
        present = self.map.from_positions(self.bus.read_positions(ids))
        q0 = check_inside_limits(self.map, present, tolerance=self._step,  # StartRefused:
                                 source=self.source.robot.source)  # nothing moved or written
        with loop_priority(wall_clock=isinstance(self.clock, MonotonicClock)):
            torque = self._drive(ids, q0, seconds)    # servos (a wall clock): raised nice
        reason = self._fault or self.telemetry.stop_reason or "completed"
        self.telemetry.stop_reason = reason
        return self._stats(t_start, wall0, reason, torque=torque)

    def _drive(self, ids: list[int], q0: JointVector, seconds: float | None) -> str:
        """Torque on, stream, end (robot.loop.ending.end); what is known of the torque."""
        try:
            self.bus.write_goals(self.map.goals(q0.tolist()))  # no snap to a stale goal
            self.bus.set_torque(ids, enabled=True)
            self._q_last = q0
            arm_failsafe(self.bus, ids, self.watchdog_config.failsafe_s, dt=self.dt)
            self._pacer.start()               # after arming: its packets take wire time
            self._stream(seconds)
        except SafetyStop as e:                  # the watchdog: unsafe or impossible to drive
            self._bus_dead = isinstance(e, BusDead)
            self._set_fault(f"watchdog: {explain_stop(self.bus, ids, e, self.watchdog.name)}")
        except Exception as e:
            log.exception("the control loop failed")
            self._set_fault(f"exception: {type(e).__name__}: {e}")
        except BaseException:                    # KeyboardInterrupt, SystemExit: no ramp
            self._finish(hold=False)
            raise
        return self._finish(hold=self.hold_at_end and self._fault is None and not self._estop.is_set())

    def _stats(self, t_start: float, wall0: float, reason: str | None, *, torque: str) -> LoopStats:
        return loop_stats(self._lateness, ticks=self._ticks, rate_hz=self.rate_hz,
                          duration_s=max(self.clock.now() - t_start, 1e-9),
                          overruns=self._overruns, bus_errors=self._bus_errors,
                          wall_s=time.perf_counter() - wall0, stop_reason=reason or "stopped",
                          fault=self._fault is not None, holding=torque == "on",
                          estop=self._estop.is_set(), torque=torque,
                          slew_limited=tuple(self._slewed.tolist()))

    def _stream(self, seconds: float | None) -> None:
        src = self.source
        entry = src.entry(self._q_last.copy(), self.dt)
        if entry is not None:
            self._ramp_to(entry, state="ramp_in", interruptible=True)
        if not self._stop.is_set():
            src.start()
            if self.feedback is not None:
                self.feedback.start()
                self._feedback_on = True
            t_gait = self.clock.now()
            clamps = src if isinstance(src, ClampReporter) else None
            while not self._estop.is_set():
                if self._stop.is_set() or (seconds is not None
                                           and self.clock.now() - t_gait >= seconds):
                    src.stop()
                if src.stopped:
                    break
                self._apply_pending()
                try:
                    q = src.tick(self.dt)
                except Exception as e:           # the gait is unusable: straight to rest
                    log.exception("the gait engine failed")
                    self._set_fault(f"exception in the gait engine: {type(e).__name__}: {e}")
                    break
                self._send(np.asarray(q, dtype=float), state=src.state,
                           held=clamps.clamped if clamps is not None else ())
        if not self._estop.is_set():
            rest = src.exit_pose()
            if rest is not None:
                self._ramp_to(rest, state="rest")
        self._feedback_on = False

    def _set_fault(self, reason: str) -> None:
        """Record the first fault and request a stop (its ramp-out, if any, follows)."""
        if self._fault is None:
            self._fault = reason
            log.error("safe stop: %s", reason)
        self.request_stop(reason)

    def _finish(self, *, hold: bool) -> str:
        """Hold or torque off (robot.loop.ending.end); what is known of the torque."""
        torque, fault = end(self.bus, self.map.ids, hold=hold, estop=self._estop.is_set,
                            confirm=lambda: self.watchdog.faults(self.bus.read_state(self.map.ids)),
                            bus_dead=self._bus_dead, failsafe=bool(self.watchdog_config.failsafe_s))
        if fault is not None:
            self._set_fault(fault)
        self.telemetry.state = "estop" if self._estop.is_set() else "stopped"
        self._notify()
        return torque

    def _apply_pending(self) -> None:
        self._pending.apply(self.source)

    def _ramp_to(self, q_goal: JointTargets, *, state: str, interruptible: bool = False
                 ) -> None:
        path = ramp(self._q_last, self.map.clamp(q_goal), self.map.max_speed, self.rate_hz,
                    min_duration=0.3)
        for q in path[1:]:
            if self._estop.is_set() or (interruptible and self._stop.is_set()):
                return
            self._send(q, state=state)

    # -- the one loop --------------------------------------------------------------------
    def _send(self, q: JointVector, *, state: str, held: tuple[int, ...] = ()) -> None:
        """(Feedback,) clamp, slew-limit, wait for the deadline, write; every Nth: read.
        ``held``: the joints (indices) the source held at a limit this tick (telemetry)."""
        if self._feedback_on:
            q = self._feed_back(q)
        limited = self.map.clamp(q)
        own = limited != q
        clamped = (tuple(self.map.names[i] for i in sorted({*held, *np.flatnonzero(own).tolist()}))
                   if held or np.logical_or.reduce(own) else ())
        q = limited.clip(self._q_last - self._step, self._q_last + self._step)
        self._slewed += q != limited            # asked faster than the servo goes
        q_list = q.tolist()
        self._wait_deadline()
        try:
            self.bus.write_joint_goals(self.map, q)
            self.watchdog.bus_ok("write")
        except BusError as e:
            self._bus_errors += 1
            self.watchdog.bus_failed("write", e)
        self._q_last = q
        self._ticks += 1
        tel = self.telemetry
        tel.tick, tel.state, tel.q_cmd = self._ticks, state, q_list
        tel.amplitude = self.source.amplitude
        tel.fresh, tel.clamped = False, clamped
        if self._ticks % self.read_every == 0 and not read_state(
                self.bus, self.map, self.watchdog, tel, q, clock=self.clock):
            self._bus_errors += 1
        self._notify()

    def _feed_back(self, q: JointVector) -> JointVector:
        """``q`` corrected by feedback; if that fails: a fault, open loop from here (sensor)."""
        assert self.feedback is not None
        try:
            return self.feedback(q, self.dt)
        except Exception as e:
            self._feedback_on = False
            self.feedback.stop()
            log.exception("the balance feedback failed; open loop from here")
            self._set_fault(f"exception in the balance feedback: {type(e).__name__}: {e}")
            return q

    def _wait_deadline(self) -> None:
        now, late, missed = self._pacer.wait()
        if missed:                               # counted and realigned (loop.clock.Pacer)
            self._overruns += missed
            try:
                self.watchdog.overrun()
            except SafetyStop as e:              # the bus still works: ramp out and stop
                self._set_fault(f"watchdog: {e}")
        else:
            self.watchdog.on_time()
        self._lateness.add(late)
        tel = self.telemetry
        tel.t, tel.period_error_ms, tel.overruns = now, late * 1e3, self._overruns

    def _notify(self) -> None:
        if self.observer is None:
            return
        try:
            self.observer(self.telemetry)
        except Exception as e:                   # e.g. a full disk under --record
            self.observer = None
            log.exception("an observer of the loop failed; it is detached")
            self._set_fault(f"exception in an observer: {type(e).__name__}: {e}")
