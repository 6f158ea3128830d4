"""The panel's controller: the web side's handle on the control loop, which runs in a
process of its own (robot.panel.loop_process, robot.panel.loop_host) so that nothing the
web side does (threads, connections, JSON, the stick figure) competes with the loop for
one interpreter. Every HTTP request goes through it (thread-safe).

Ownership is decided where the bus is (the loop process's bus lease: a second mover gets
409 naming what runs). The order between a mover and an e-stop is decided here, by when
each request *arrived* (``received``: when the server accepted its connection): a mover
that arrived before an e-stop that has been handled is refused, however the threads that
serve the two were scheduled; and a mover sent to the loop before an e-stop is stopped
by it at the bus edge. So after an e-stop has answered, nothing sent before it moves.

No I/O in the constructor: ``open()`` (or the first request) starts the loop process.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Mapping
from typing import Any

from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.loop.telemetry import LoopStats
from robot.panel.loop_lost import take_over
from robot.panel.loop_process import LoopProcess, LoopUnavailable
from robot.panel.loop_state import LoopStateReader
from robot.panel.options import (
    DEFAULT_OPTIONS,
    BusSpec,
    HostSpec,
    LoopOptions,
    PanelStateError,
)
from robot.panel.presets import PresetStore
from robot.panel.runs import RunKind, Walk
from robot.panel.snapshot import describe_params, state_snapshot

log = logging.getLogger(__name__)

__all__ = ["BusSpec", "LoopOptions", "PanelController", "PanelStateError", "make_controller"]

#: How fresh a state must be for the panel (the live view pushes at 20 Hz) [s].
STATE_MAX_AGE_S = 0.02
STATE_TIMEOUT_S = 2.0   # the loop answers a state within a tick; beyond this it is stuck
MOVE_TIMEOUT_S = 30.0   # a start answers once its run has begun; a release once done
ESTOP_TIMEOUT_S = 5.0


class PanelController:
    """Start/stop/estop, live parameters, presets, posing and the loop's state."""

    def __init__(self, robot: RobotConfig, bus: BusSpec, params: GaitParams, *,
                 options: LoopOptions = DEFAULT_OPTIONS, presets: PresetStore | None = None,
                 preset: str | None = None) -> None:
        self.robot = robot
        self.bus = bus
        self.options = options
        self.presets = presets or PresetStore()
        self.preset = preset  # name of the last preset loaded (shown by the picker)
        self._params = params
        self._loop: LoopProcess | None = None
        self._lock = threading.Lock()         # movers and e-stops, in arrival order
        self._estop_at = -math.inf            # arrival of the last e-stop handled [s]
        self._closing = False
        self._reader = LoopStateReader(STATE_TIMEOUT_S)

    # -- the loop process ----------------------------------------------------------------
    def open(self) -> None:
        """Start the loop process and open the bus (errors as one line); idempotent."""
        with self._lock:
            if self._loop is None:
                loop = LoopProcess(HostSpec(self.robot, self.bus, self._params, self.options))
                loop.start()
                self._loop = loop

    @property
    def loop(self) -> LoopProcess:
        if self._loop is None:
            self.open()
        assert self._loop is not None
        return self._loop

    @property
    def pid(self) -> int | None:
        """The loop process's id (None before ``open``)."""
        return self._loop.pid if self._loop is not None else None

    # -- parameters ----------------------------------------------------------------------
    @property
    def params(self) -> GaitParams:
        return self._params

    def set_params(self, changes: Mapping[str, Any]) -> GaitParams:
        """Validate all of ``changes`` (ConfigError, nothing changes) and apply them: at the
        loop's next tick when running, else to the next run."""
        self._params.replace(changes, where="panel")   # refused here, before the loop
        new = self.loop.call("params", timeout=STATE_TIMEOUT_S, changes=dict(changes))
        self._params = new
        return new

    def load_preset(self, name: object) -> GaitParams:
        """Preset ``name``: blended in while walking (robot.gait.blend), else next run."""
        values = self.presets.load(name).for_robot(self.robot).as_dict()
        self._params = new = self.loop.call("preset", timeout=STATE_TIMEOUT_S, values=values)
        self.preset = str(name)
        return new

    def save_preset(self, name: object, *, overwrite: bool = False) -> str:
        return str(self.presets.save(name, self._params, overwrite=overwrite))

    # -- what moves ----------------------------------------------------------------------
    def _move(self, op: str, received: float | None, **args: Any) -> Any:
        """Send a mover in arrival order (refused if an e-stop arrived after it) and wait
        for its answer."""
        loop = self.loop                       # opened outside the lock (it takes it)
        with self._lock:
            if received is not None and received <= self._estop_at:
                raise PanelStateError("an emergency stop came after this request was sent: "
                                      "nothing moved; send it again")
            if self._closing:
                raise PanelStateError("the panel is shutting down")
            pending = loop.send(op, **args)
        try:
            return pending.wait(MOVE_TIMEOUT_S)
        finally:
            self._reader.expire()

    def start(self, *, run: RunKind | None = None, received: float | None = None) -> None:
        """Start a run (the gait, or ``run``: a recording, a take, a sequence) with the
        current parameters; PanelStateError (409) naming what holds the bus."""
        self._move("start", received, kind=run or Walk())

    def release(self, limb: object, *, received: float | None = None) -> dict[str, Any]:
        return dict(self._move("release", received, limb=limb))

    def capture(self, t: float | None, *, received: float | None = None) -> dict[str, Any]:
        return dict(self._move("capture", received, t=t))

    def reset_sim(self, *, received: float | None = None) -> None:
        """Simulation only, while stopped: the robot back on its feet, torque off."""
        self._move("reset", received)

    def clear_capture(self) -> None:
        self.loop.call("clear", timeout=STATE_TIMEOUT_S)

    def keyframes(self, name: str) -> Any:
        """The keyframes captured so far, as a sequence named ``name``."""
        return self.loop.call("keyframes", timeout=STATE_TIMEOUT_S, name=name)

    def stop(self) -> str:
        """Safe stop: ramp the gait out, go to rest, torque off (or hold). Idempotent:
        without a run it only answers the state."""
        state = self.loop.call("stop", timeout=STATE_TIMEOUT_S)["state"]
        self._reader.expire()
        return str(state)

    def emergency_stop(self, *, received: float | None = None) -> list[str]:
        """Latch at the bus edge and torque off at once (a run ends within one tick);
        answers once torque off has been sent: the failures, one line each."""
        loop = self.loop
        with self._lock:
            self._estop_at = max(self._estop_at, time.monotonic() if received is None
                                 else received)
            pending = loop.send("estop")
        try:
            return list(pending.wait(ESTOP_TIMEOUT_S)["failed"])
        finally:
            self._reader.expire()

    # -- the loop's state ----------------------------------------------------------------
    def loop_state(self, *, max_age: float = STATE_MAX_AGE_S) -> dict[str, Any]:
        """The loop's own report (robot.panel.loop_watch), at most ``max_age`` old [s]:
        one request to the loop however many callers ask. If the loop does not answer,
        the last report with a ``fault`` saying so (robot.panel.loop_state)."""
        return self._reader.read(self.loop, max_age)

    @property
    def running(self) -> bool:
        return bool(self.loop_state()["running"])

    @property
    def runs(self) -> int:
        return int(self.loop_state().get("runs", 0))

    @property
    def driver(self) -> str | None:
        return self.loop_state().get("driver")

    @property
    def holding(self) -> bool:
        """The last run ended with torque left on (``--hold``, no fault, no e-stop since)."""
        return bool(self.loop_state().get("holding"))

    @property
    def last_stats(self) -> LoopStats | None:
        stats = self.loop_state(max_age=0.0).get("last_stats")
        return LoopStats(**stats) if stats else None

    def live_params(self) -> GaitParams:
        """The parameters in effect in the loop (a take plays its own)."""
        return self.loop_state().get("params") or self._params

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for the current run to end; True if none is running afterwards."""
        end = time.monotonic() + (timeout if timeout is not None else 1e9)
        while self.loop_state(max_age=0.0)["running"]:
            if time.monotonic() >= end:
                return False
            time.sleep(0.02)
        return True

    def loop_rate_hz(self) -> float:
        return float(self.loop_state().get("loop_hz", 0.0))

    def state(self) -> dict[str, Any]:
        """A JSON-ready snapshot: loop state and timing, servos, sim metrics, stick figure,
        a fault (the loop is late, stopped on a fault, or not answering)."""
        s = self.loop_state()
        out = state_snapshot(self.robot, s.get("tel", {}), s.get("sim") or {},
                             running=bool(s["running"]), rate_hz=self.options.rate_hz,
                             loop_hz=float(s.get("loop_hz", 0.0)), show=s.get("show"))
        out["fault"] = s.get("fault")
        if out["fault"] and out["running"]:
            out["state"] = "late"                 # never a silent "walking"
        torque = s.get("torque") or {}
        out["torque"] = [torque.get(j.servo_id) for j in self.robot.joints]
        return out

    def describe(self) -> dict[str, Any]:
        """Parameters with their specs, grouped as the paper groups its sliders."""
        return describe_params(self._params, self.preset)

    def stop_budget_s(self) -> float:
        """How long a safe stop may take before it counts as stuck [s]: the gait's
        ramp-out plus 10 s for the move to rest."""
        p = self.live_params()
        ramp_s = p.ramp_cycles * p.cycle_s
        return (ramp_s if math.isfinite(ramp_s) else 0.0) + 10.0

    def shutdown(self, timeout: float | None = None, *,
                 abort: Callable[[], bool] = lambda: False) -> dict[str, Any]:
        """Refuse new runs; safe-stop a run (ramp out, rest) and wait for it, or stop it at
        once (e-stop) when ``abort()`` becomes true (e.g. a second signal) or after
        ``timeout`` [s] (default ``stop_budget_s()``); then the loop closes the bus,
        leaving torque on only if the last run ended holding and nothing aborted. Returns
        what the wire was told: ``holding``, ``torque`` {id: bool}, ``failed`` lines
        (empty dict when the loop never started); a loop process that died is taken over
        (torque off from here: robot.panel.loop_lost), its report says ``lost``."""
        with self._lock:
            self._closing = True
            loop = self._loop
        if loop is None:
            return {}
        if loop.gone is not None:        # killed: nobody holds the bus (robot.panel.loop_lost)
            loop.close()
            return take_over(self.robot, self.bus, why=loop.gone)
        budget = self.stop_budget_s() if timeout is None else timeout
        pending = loop.send("shutdown")
        end, stopped = time.monotonic() + budget, False
        result: dict[str, Any] = {}
        while True:
            try:
                result = dict(pending.wait(0.02))
                break
            except LoopUnavailable:
                pass
            except Exception as e:
                log.error("panel: the control loop failed to close: %s", e)
                break
            if not stopped and (abort() or time.monotonic() > end):
                stopped = True
                log.warning("emergency stop: %s", "aborted" if abort()
                            else f"the safe stop took longer than {budget:.1f} s")
                loop.send("estop")
            if time.monotonic() > end + 10.0:
                log.error("the control loop did not close; ending it")
                break
        loop.close()
        if not result and loop.gone is not None:    # it died while stopping
            return take_over(self.robot, self.bus, why=loop.gone)
        return result


def make_controller(robot: RobotConfig, bus: BusSpec, params: GaitParams, *,
                    options: LoopOptions = DEFAULT_OPTIONS,
                    presets: PresetStore | None = None,
                    preset: str | None = None) -> PanelController:
    """A controller for ``bus`` with its loop process started (the bus open)."""
    controller = PanelController(robot, bus, params, options=options, presets=presets,
                                 preset=preset)
    controller.open()
    return controller
