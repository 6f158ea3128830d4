"""One way to assemble a run: ``Run(spec)`` opens the recorder, the bus and the IMU, builds
the balance stage and the Streamer with every observer (the bus's own watch, the fall
stop, the recorder, the caller's), routes the signals, streams, and closes everything
the way the end requires; ``result`` is typed (robot.run.result.RunResult).

    with Run(spec) as run:      # opens (a refused start or an error still closes)
        run.stream()
    run.result

``execute(spec)`` does exactly that. `biped walk`, `biped play`, the panel, the
robustness suite and the tuner all run through here.
"""

from __future__ import annotations

import contextlib
import logging
import signal
import time
from collections.abc import Callable
from types import TracebackType
from typing import Generic

from robot.balance.stage import Balance, attitude_reader
from robot.bus.servo_map import ServoMap
from robot.errors import BusError, ConfigError
from robot.gait.engine import GaitEngine
from robot.imu.last import LastSample
from robot.loop.ending import finish
from robot.loop.source import Feedback, SourceT
from robot.loop.streamer import Streamer
from robot.loop.telemetry import LoopStats, Telemetry
from robot.run.result import RunResult, torque_words
from robot.run.signals import SignalLatch, installed, shield, stop_on_signals
from robot.run.spec import RunSpec, RunWatch, WatchedBus

log = logging.getLogger(__name__)


class Run(Generic[SourceT]):
    """The object that owns one run's recorder, bus (unless ``options.close_bus`` is
    False), IMU, observers, Streamer and signals. No I/O before ``__enter__``."""

    def __init__(self, spec: RunSpec[SourceT]) -> None:
        self.spec = spec
        # Under a command its latch (signals before and after the stream count too).
        outer = installed() if spec.options.signals else None
        self.latch = outer or SignalLatch()
        self.watch: RunWatch | None = None
        self._streamer: Streamer[SourceT] | None = None
        self._stats: LoopStats | None = None
        self._result: RunResult | None = None
        self._wall0 = 0.0
        self._imu_opened = False
        self._imu_last: LastSample | None = None
        self._signals = contextlib.ExitStack()

    @property
    def streamer(self) -> Streamer[SourceT]:
        if self._streamer is None:
            raise ConfigError("run: not open; use `with Run(spec) as run:` first")
        return self._streamer

    @property
    def result(self) -> RunResult:
        if self._result is None:
            raise ConfigError("run: no result before it has streamed and closed")
        return self._result

    # -- opening -------------------------------------------------------------------------
    def __enter__(self) -> Run[SourceT]:
        self.open()
        return self

    def open(self) -> None:
        """Open the recorder, then the bus (unless open), the IMU, and build the Streamer;
        on an error, close what was opened."""
        spec = self.spec
        self._wall0 = time.perf_counter()
        if spec.recorder is not None:
            spec.recorder.open()          # an unwritable path fails before the bus opens
        try:
            self._open()
            if spec.options.signals:      # routed from here until closed (robot.run.signals)
                self._signals.enter_context(stop_on_signals(self.streamer, self.latch))
        except BaseException:
            self._close()
            raise

    def _open(self) -> None:
        spec, o = self.spec, self.spec.options
        if not spec.bus.is_open:
            spec.bus.open()
        if o.watch and isinstance(spec.bus, WatchedBus):
            self.watch = spec.bus.run_watch()
        if spec.imu is not None:
            spec.imu.open()
            self._imu_opened = True
        feedback = self._feedback()       # first: the observers see what its IMU read
        self._streamer = Streamer(ServoMap(spec.robot), spec.bus, spec.source,
                                  rate_hz=o.rate_hz, read_every=o.read_every,
                                  hold_at_end=o.hold, observer=self._observer(),
                                  feedback=feedback)

    def _feedback(self) -> Feedback | None:
        spec = self.spec
        if spec.imu is None:
            return spec.feedback
        if not isinstance(spec.source, GaitEngine):
            raise ConfigError(f"run: balance needs a gait engine, not a "
                              f"{type(spec.source).__name__}")
        self._imu_last = LastSample(spec.imu)          # what it read, for the recorders
        return Balance(spec.source, attitude_reader(self._imu_last), present=self._read_back)

    def _read_back(self) -> list[float] | None:
        """The joint angles [rad] the loop read back on its last tick, else None."""
        tel = self._streamer.telemetry if self._streamer is not None else None
        return tel.q_present if tel is not None and tel.fresh else None

    def _observer(self) -> Callable[[Telemetry], None]:
        spec = self.spec
        observers: list[Callable[[Telemetry], None]] = []
        if self._imu_last is not None:
            imu = self._imu_last

            def imu_sample(tel: Telemetry) -> None:
                tel.imu = imu.last
            observers.append(imu_sample)
        watch = self.watch
        if watch is not None:
            observers.append(watch)
            if spec.options.stop_on_fall:
                def stop_on_fall(tel: Telemetry) -> None:
                    if watch.fell:
                        self.streamer.emergency_stop("fell")
                observers.append(stop_on_fall)
        observers += [o for o in (spec.recorder, spec.observer) if o is not None]
        source = spec.source
        if isinstance(source, GaitEngine):          # leg odometry on stairs (read-backs)
            def read_back(tel: Telemetry) -> None:
                if tel.fresh and tel.q_present is not None and source.stairs is not None:
                    source.stairs.measure(tel.q_present)
            observers.append(read_back)

        def observe(tel: Telemetry) -> None:
            for o in observers:
                o(tel)
        return observe

    # -- streaming -----------------------------------------------------------------------
    def stream(self) -> LoopStats:
        """Stream the source (once): until it stops, ``options.seconds`` pass, or a stop."""
        self._stats = self.streamer.run(seconds=self.spec.options.seconds)
        return self._stats

    def request_stop(self, reason: str = "stop requested") -> None:
        self.streamer.request_stop(reason)

    def emergency_stop(self, reason: str = "emergency stop") -> None:
        self.streamer.emergency_stop(reason)

    # -- closing -------------------------------------------------------------------------
    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()

    def close(self) -> None:
        """Close what the run opened; then ``result`` holds the outcome (if it streamed).
        Signals still go to the streamer until the end (a second one: torque off)."""
        with self._signals, shield():
            self._close_all()

    def _close_all(self) -> None:
        self._end_hold()
        record_error = self._close()
        if self._stats is None:
            return
        if self._stats.holding and self.spec.options.close_bus and self.latch is installed():
            self.latch.if_emergency_at_end(self._release_late)
        metrics = (dict(self.watch.summary(self.spec.options.seconds))
                   if self.watch is not None else None)
        code = self.latch.exit_code(self._stats) or (1 if record_error else 0)
        self._result = RunResult(stats=self._stats, wall_s=time.perf_counter() - self._wall0,
                                 seconds=self.spec.options.seconds, metrics=metrics,
                                 record_error=record_error, exit_code=code)

    def _end_hold(self) -> None:
        """A second signal after the loop ended holding (while it finished or since): it
        asked for torque off, so torque goes off (robot.loop.ending.finish)."""
        stats = self._stats
        if stats is None or not stats.holding or not self.latch.emergency:
            return
        assert self.latch.last is not None
        stats.torque = finish(self.spec.bus, self.spec.robot.ids, torque_off=True,
                              bus_dead=False, failsafe=False)
        stats.holding, stats.estop = False, True
        stats.stop_reason = (f"emergency stop (second signal, "
                             f"{signal.Signals(self.latch.last).name}) after it ended holding")
        log.warning("torque off: a second signal came after the run ended holding")

    def _release_late(self) -> str | None:
        """A second signal came after the run closed holding (the command was still
        finishing): open the bus again and turn torque off; what to tell the operator."""
        stats = self._stats
        if stats is None or not stats.holding:
            return None
        assert self.latch.last is not None
        bus, name = self.spec.bus, signal.Signals(self.latch.last).name
        try:
            bus.open()
            stats.torque = finish(bus, self.spec.robot.ids, torque_off=True, bus_dead=False,
                                  failsafe=False)
        except BusError as e:
            log.error("a second signal after the run ended holding: %s", e)
            stats.torque = "unknown"
        finally:
            bus.close(torque_off=True)
        stats.holding, stats.estop = False, True
        return f"emergency stop (second signal, {name}) after the run ended: {torque_words(stats)}"

    def _close(self) -> str | None:
        """Close what the run opened. The streamer has already left the servos as its end
        requires (holding, or torque off); a refused start left them untouched: closing
        must not undo either."""
        spec = self.spec
        try:
            if spec.options.close_bus:
                spec.bus.close(torque_off=False)
        finally:
            if self._imu_opened and spec.imu is not None:
                spec.imu.close()
                self._imu_opened = False
        return spec.recorder.close_quietly() if spec.recorder is not None else None


def execute(spec: RunSpec[SourceT]) -> RunResult:
    """Open, stream and close ``spec``'s run; its result."""
    run = Run(spec)
    with run:
        run.stream()
    return run.result
