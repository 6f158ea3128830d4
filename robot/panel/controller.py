"""The panel's controller: owns the bus, the current parameters and at most one Streamer
run in a worker thread; every HTTP request goes through it (thread-safe).

A run (robot.run.run.Run: its Streamer, observers and feedback) is one-shot, so "start"
after a stop starts a new run (a new GaitEngine with the current parameters) on the same
open bus, which the controller owns (its runs leave it open). The run's thread is not a
daemon: the process cannot end under it before ``shutdown`` has stopped it and closed
the bus.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Mapping
from typing import Any

from robot.bus.base import Bus
from robot.bus.servo_map import ServoMap
from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import BipedError
from robot.gait.engine import GaitEngine
from robot.loop.streamer import LoopStats, Streamer, Telemetry, TickObserver
from robot.panel.idle_pose import IdlePose
from robot.panel.options import DEFAULT_OPTIONS, EngineFactory, LoopOptions, PanelStateError
from robot.panel.presets import PresetStore
from robot.panel.sim_monitor import sim_monitor_factory
from robot.panel.sim_reset import reset_to_home
from robot.panel.snapshot import TickRate, describe_params, state_snapshot, telemetry_snapshot
from robot.run.run import Run
from robot.run.spec import RunOptions, RunSpec

log = logging.getLogger(__name__)

RATE_WINDOW = 50  # ticks over which the loop rate is measured


class PanelController:
    """Start/stop/estop, live parameters, presets and a telemetry snapshot for the panel.

    ``monitor_factory`` (sim only) returns a per-tick callback → dict of sim metrics
    (e.g. {"fell": bool, ...}); it runs in the loop's thread.
    """

    def __init__(self, robot: RobotConfig, bus: Bus, params: GaitParams, *,
                 options: LoopOptions = DEFAULT_OPTIONS, presets: PresetStore | None = None,
                 monitor_factory: Callable[[], Callable[[Telemetry], dict[str, Any]]] | None
                 = None, preset: str | None = None) -> None:
        self.robot = robot
        self.bus = bus
        self.options = options
        self.presets = presets or PresetStore()
        self._monitor_factory = monitor_factory
        self._map = ServoMap(robot)
        self._idle = IdlePose(bus, self._map)  # the read-back pose while no run is active
        self._params = params
        self.preset = preset  # name of the last preset loaded (shown by the picker)
        self._lock = threading.RLock()
        self._streamer: Streamer[GaitEngine] | None = None
        self._thread: threading.Thread | None = None
        self._tel: dict[str, Any] = {"state": "idle"}
        self._sim: dict[str, Any] = {}
        self._rate = TickRate(RATE_WINDOW)
        self.runs = 0
        self.last_stats: LoopStats | None = None  # of the last run that returned
        self._holding = False  # torque left on by the last run (hold, no fault or estop)
        self._estop_requested = False  # during the current run
        self._closing = False
        self.driver: str | None = None  # what drives the run instead of the sliders
        self._on_end: Callable[[], None] | None = None

    # -- parameters --------------------------------------------------------------------
    @property
    def params(self) -> GaitParams:
        return self._params

    @property
    def streamer(self) -> Streamer[GaitEngine] | None:
        return self._streamer

    def set_params(self, changes: Mapping[str, Any]) -> GaitParams:
        """Validate all of ``changes`` (ConfigError, nothing changes) and apply them: at the
        loop's next tick when running, else to the next run."""
        with self._lock:
            if self.running and self.driver is not None:
                raise PanelStateError(f"{self.driver} is playing; stop it to drive by hand")
            if self.running and self._streamer is not None:
                new = self._streamer.set_params(changes, where="panel")
            else:
                new = self._params.replace(changes, where="panel")
            self._params = new
            return new

    def load_preset(self, name: object) -> GaitParams:
        gait = self.presets.load(name)
        new = self.set_params(gait.for_robot(self.robot).as_dict())
        self.preset = str(name)
        return new

    def save_preset(self, name: object, *, overwrite: bool = False) -> str:
        return str(self.presets.save(name, self._params, overwrite=overwrite))

    # -- the loop ------------------------------------------------------------------------
    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def start(self, *, engine: EngineFactory | None = None,
              observer: TickObserver | None = None, driver: str | None = None,
              on_end: Callable[[], None] | None = None) -> None:
        """Start a new run with the current parameters (PanelStateError if one runs).

        engine: builds the run's engine (default: the plain gait); observer: also called
        every tick; driver: names what drives the run (a take): the sliders are refused
        meanwhile; on_end: called in the run's thread when it has ended."""
        with self._lock:
            if self._closing:
                raise PanelStateError("the panel is shutting down")
            if self.running:
                raise PanelStateError("the gait is already running; stop it first")
            if not self.bus.is_open:
                self.bus.open()
            gait = engine(self._params) if engine is not None else \
                GaitEngine(self.robot, self._params)
            monitor = self._monitor_factory() if self._monitor_factory else None
            self._rate.clear()
            self._sim = {}
            self._idle.forget()

            def observe(tel: Telemetry) -> None:
                self._observe(tel, monitor)
                if observer is not None:
                    observer(tel)
            o = self.options
            run = Run(RunSpec(robot=self.robot, source=gait, bus=self.bus, observer=observe,
                              feedback=o.feedback(gait) if o.feedback else None,
                              options=RunOptions(rate_hz=o.rate_hz, read_every=o.read_every,
                                                 hold=o.hold, close_bus=False, watch=False)))
            run.open()                 # the bus is open and stays so: builds the Streamer
            self._streamer = run.streamer
            self.driver, self._on_end = driver, on_end
            self._tel = {"state": "starting"}
            self.runs += 1
            self._holding = self._estop_requested = False
            self._thread = threading.Thread(target=self._run, args=(run,),
                                            name=f"gait-run-{self.runs}", daemon=False)
            self._thread.start()

    def _run(self, run: Run[GaitEngine]) -> None:
        streamer = run.streamer
        try:
            try:
                stats = run.stream()
            finally:
                run.close()            # opened by start(); leaves the bus open
            log.info("run ended: %s", stats.stop_reason)
            with self._lock:
                self.last_stats = stats
                self._holding = stats.holding and not self._estop_requested
            if stats.holding and not self._holding:  # an E-stop as the run ended holding
                self.bus.set_torque(list(self._map.ids), enabled=False)
        except BipedError as e:
            log.error("run failed: %s", e)
        except Exception:
            log.exception("run crashed")
        finally:
            self._observe(streamer.telemetry, None)
            end, self._on_end = self._on_end, None
            if end is not None:
                try:
                    end()
                except Exception:
                    log.exception("panel: ending the run's recording failed")

    def stop(self) -> None:
        """Safe stop: ramp the gait out, go to rest, torque off (or hold)."""
        with self._lock:
            if not self.running or self._streamer is None:
                raise PanelStateError("the gait is not running")
            self._streamer.request_stop("panel stop")

    def emergency_stop(self) -> None:
        """Torque off at once: ends a run within one tick; with no run, torque off now."""
        with self._lock:
            if self.running and self._streamer is not None:
                self._estop_requested = True
                self._streamer.emergency_stop()
                return
            self._holding = False
            if self.bus.is_open:
                self.bus.set_torque(list(self._map.ids), enabled=False)
            self._tel = {**self._tel, "state": "estop", "stop_reason": "emergency stop"}

    def reset_sim(self) -> None:
        """Simulation only, while stopped: put the robot back on its feet (the ``home``
        keyframe, torque off), keeping the simulation clock."""
        with self._lock:
            if self.running:
                raise PanelStateError("stop the gait before resetting the simulation")
            if getattr(self.bus, "kind", "") != "sim":
                raise PanelStateError("reset applies to the simulated bus only")
            reset_to_home(self.bus, list(self._map.ids))
            self._holding = False
            self._sim = {}
            self._tel = {"state": "idle", "stop_reason": "simulation reset"}

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for the current run to end; True if none is running afterwards."""
        t = self._thread
        if t is not None:
            t.join(timeout)
        return not self.running

    @property
    def holding(self) -> bool:
        """The last run ended with torque left on (``--hold``, no fault, no estop since)."""
        return self._holding

    def stop_budget_s(self) -> float:
        """How long a safe stop may take before it counts as stuck [s]: the gait's
        ramp-out plus 10 s for the move to rest."""
        p = self._streamer.engine.params if self._streamer is not None else self._params
        ramp_s = p.ramp_cycles * p.cycle_s
        return (ramp_s if math.isfinite(ramp_s) else 0.0) + 10.0

    def shutdown(self, timeout: float | None = None, *,
                 abort: Callable[[], bool] = lambda: False) -> None:
        """Refuse new runs; safe-stop a run (ramp out, rest) and wait for it, or stop it
        at once (emergency stop) when ``abort()`` becomes true (e.g. a second signal) or
        after ``timeout`` [s] (default ``stop_budget_s()``). Then close the bus, leaving
        torque on only if the last run ended holding and nothing aborted."""
        with self._lock:
            self._closing = True
            streamer = self._streamer if self.running else None
        if streamer is not None:
            streamer.request_stop("panel shutdown")
            budget = self.stop_budget_s() if timeout is None else timeout
            end = time.monotonic() + budget
            while not self.wait(0.05):
                if abort() or time.monotonic() > end:
                    log.warning("emergency stop: %s", "aborted" if abort()
                                else f"the safe stop took longer than {budget:.1f} s")
                    streamer.emergency_stop()
                    if not self.wait(2.0):
                        log.error("the gait thread did not end; closing the bus anyway")
                    break
        self.bus.close(torque_off=not (self._holding and not abort()))

    # -- telemetry -------------------------------------------------------------------
    def _observe(self, tel: Telemetry, monitor: Callable[[Telemetry], dict[str, Any]] | None
                 ) -> None:
        """Loop thread: copy what the panel shows (cheap; FK is done on request)."""
        snap = telemetry_snapshot(tel)
        self._rate.add(tel.tick, tel.t)
        sim = monitor(tel) if monitor is not None else None
        with self._lock:
            self._tel = snap
            if sim is not None:
                self._sim = sim

    def loop_rate_hz(self) -> float:
        """Measured ticks per second of the loop's clock over the last ticks [Hz]."""
        return self._rate.hz()

    def state(self) -> dict[str, Any]:
        """A JSON-ready snapshot: loop state and timing, servos, sim metrics, stick figure."""
        with self._lock:
            tel, sim, running = dict(self._tel), dict(self._sim), self.running
            if not running and not self._closing and self.bus.is_open:
                idle = self._idle.poll()  # reads (never writes), at most 5 times a second
                if idle is not None:
                    tel["q_present"], tel["servo"] = idle
        return state_snapshot(self.robot, tel, sim, running=running,
                              rate_hz=self.options.rate_hz, loop_hz=self.loop_rate_hz())

    def describe(self) -> dict[str, Any]:
        """Parameters with their specs, grouped as the paper groups its sliders."""
        return describe_params(self._params, self.preset)


def make_controller(robot: RobotConfig, bus: Bus, params: GaitParams, *,
                    options: LoopOptions = DEFAULT_OPTIONS,
                    presets: PresetStore | None = None,
                    preset: str | None = None) -> PanelController:
    """A controller for ``bus``, with fall detection when it is the simulated bus."""
    factory = sim_monitor_factory(bus) if bus.kind == "sim" else None
    return PanelController(robot, bus, params, options=options, presets=presets,
                           monitor_factory=factory, preset=preset)
