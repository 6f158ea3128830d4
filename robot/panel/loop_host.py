"""The panel's control loop, inside its own process: the bus behind a lease, the one loop
on its own thread, and the commands the panel sends (robot.panel.loop_process carries
them).

Two threads. The *command* thread takes every command in the order the panel sent it and
answers the quick ones itself (the state, parameters, stop, the e-stop); anything that
uses the bus first takes the bus lease (robot.bus.lease: a second mover is refused at
once, naming the holder) and is then done by the *loop* thread, which answers when it has
begun (a run) or finished (a limb release, a capture, a reset). So the e-stop never waits
behind a command: it latches at the bus edge, torque goes off, and it answers.

Nothing here serves HTTP: the web side lives in another process, so however many
connections it has, it cannot take this interpreter's time from the loop.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable, Mapping
from typing import Any

from robot.balance.stage import Balance, attitude_reader
from robot.bus.lease import BusLease, Session
from robot.bus.servo_map import ServoMap
from robot.config.params import GaitParams
from robot.imu import Imu
from robot.loop.mcap_recorder import Alongside
from robot.loop.take_writer import TakeWriter
from robot.motion.posing import limb_joints
from robot.panel.idle_pose import IdlePose
from robot.panel.loop_posing import Posing
from robot.panel.loop_watch import LoopWatch
from robot.panel.options import HostSpec, PanelStateError
from robot.panel.rate_guard import stall_limit_s
from robot.panel.runs import RunKind, build
from robot.panel.sim_monitor import sim_monitor_factory
from robot.panel.sim_reset import reset_to_home
from robot.run.run import Run
from robot.run.spec import RunOptions, RunSpec
from robot.run.walk import walk_imu

log = logging.getLogger(__name__)

#: ``done(outcome)``: answer a command later; the outcome is a payload or an exception.
Done = Callable[[object], None]


class LoopHost:
    """The loop side of one panel (see the module docstring). No I/O before ``open``."""

    def __init__(self, spec: HostSpec) -> None:
        self.robot = spec.robot
        self.options = spec.options
        self.params = spec.params
        self.raw = spec.bus.build(self.robot)
        self.lease = BusLease(self.raw, self.robot.ids)
        self.watch = LoopWatch(self.robot, self.options.rate_hz,
                               stall_s=stall_limit_s(self.raw, self.options.rate_hz))
        self._idle = IdlePose(self.lease, ServoMap(self.robot))
        self._imu: Imu | None = None
        self._ops: queue.Queue[Callable[[], None] | None] = queue.Queue()
        self._thread = threading.Thread(target=self._work, name="panel-loop")
        self._lock = threading.Lock()
        self._run: Run[Any] | None = None
        self.posing = Posing(self.robot)
        self._polling = False
        self._guard_stop: str | None = None   # why the rate guard stopped the run
        self.closing = False

    def open(self) -> None:
        """Open the bus (a wrong port fails here, before anything is served) and the
        IMU's stand-in, and start the loop thread."""
        self.lease.open()
        self._imu = walk_imu(self.robot, self.raw, balance=self.options.balance,
                             noise=self.options.imu_noise)
        if self.raw.kind == "sim":
            self.watch.monitor_factory = sim_monitor_factory(self.raw)
        self._thread.start()

    def join(self) -> None:
        """Wait for the loop thread to end (after ``shutdown``)."""
        if self._thread.is_alive():
            self._thread.join()

    # -- the loop thread -----------------------------------------------------------------
    def _work(self) -> None:
        while (op := self._ops.get()) is not None:
            try:
                op()
            except Exception:
                log.exception("panel loop: a command failed")

    def _later(self, session: Session | None, done: Done, op: Callable[[], object]) -> None:
        """Run ``op`` on the loop thread, answer its result (or error), end ``session``."""
        def job() -> None:
            try:
                if session is not None and not session.live:
                    raise PanelStateError(f"an emergency stop came first: {session.owner} "
                                          "did not start (nothing moved)")
                result = op()
            except BaseException as e:
                result = e
            finally:
                if session is not None:
                    session.end()
            done(result)
        self._ops.put(job)

    # -- commands (the command thread) ---------------------------------------------------
    def state(self) -> dict[str, Any]:
        """The loop's state for the panel (robot.panel.loop_watch), plus the bus's."""
        running = self._run is not None
        if not running and not self.closing and self.raw.is_open and not self._polling:
            self._polling = True
            self._ops.put(self._poll)
        run = self._run
        return {**self.watch.snapshot(running=running), **self.posing.summary(),
                "params": self._params(), "owner": self.lease.owner,
                "engine_t": getattr(run.streamer.engine, "time", None) if run else None,
                "torque": dict(self.lease.torque)}

    def _params(self) -> GaitParams:
        run = self._run
        return run.streamer.engine.params if run is not None else self.params

    def _poll(self) -> None:
        try:
            self.watch.idle_pose(self._idle.poll())
        finally:
            self._polling = False

    def set_params(self, changes: Mapping[str, float]) -> GaitParams:
        with self._lock:
            run, driver = self._run, self.watch.driver
            if run is not None and driver is not None:
                raise PanelStateError(f"{driver} is playing; stop it to drive by hand")
            new = (run.streamer.set_params(changes, where="panel") if run is not None
                   else self.params.replace(changes, where="panel"))
            self.params = new
            return new

    def load_preset(self, values: Mapping[str, float]) -> GaitParams:
        """Another preset's parameters: blended in while a walk runs (robot.gait.blend),
        else for the next run."""
        with self._lock:
            run, driver = self._run, self.watch.driver
            if run is not None and driver is not None:
                raise PanelStateError(f"{driver} is playing; stop it to drive by hand")
            new = self.params.replace(values, where="preset")
            if run is not None:
                run.streamer.blend_to(new)
            self.params = new
            return new

    def _acquire(self, owner: str) -> Session:
        """The bus for ``owner`` (BusBusy naming the holder; refused while closing)."""
        if self.closing:
            raise PanelStateError("the panel is shutting down")
        return self.lease.acquire(owner)

    def start(self, kind: RunKind, done: Done) -> None:
        session = self._acquire(kind.owner)
        self._later(session, done, lambda: self._start(kind, session, done))

    def _start(self, kind: RunKind, session: Session, done: Done) -> object:
        built = build(kind, self.robot, self.params)
        feedback = None
        if self._imu is not None:
            if not self._imu.is_open:
                self._imu.open()
            feedback = Balance(built.engine, attitude_reader(self._imu))
        o = self.options
        run: Run[Any] = Run(RunSpec(
            robot=self.robot, source=built.engine, bus=session, feedback=feedback,
            recorder=built.recorder, observer=self.watch.observer(
                self._verdict, show_time=lambda: built.engine.time),
            options=RunOptions(rate_hz=o.rate_hz, read_every=o.read_every, hold=o.hold,
                               close_bus=False, watch=False)))
        run.open()                     # the take file first: unwritable, nothing moves
        with self._lock:
            self._run = run
        self.posing.clear()
        self.watch.begin(kind, built.driver)
        done({"state": "starting"})
        try:
            self._stream(kind, run, built.recorder, session)
        finally:
            session.end()              # free before "not running": a start may follow
            with self._lock:
                self._run = None
        return None

    def _stream(self, kind: RunKind, run: Run[Any], recorder: TakeWriter | Alongside | None,
                session: Session) -> None:
        """Stream the run, close it, and report how it ended."""
        stats = None
        try:
            stats = run.stream()
        except Exception as e:         # the streamer catches its own; this is a bug
            log.exception("panel loop: the run failed")
            self.watch.failed(f"{type(e).__name__}: {e}")
        finally:
            run.close()
        error = recorder.close_quietly() if recorder is not None else None
        if error:
            log.error("panel: %s: %s", kind.owner, error)
        guard, self._guard_stop = self._guard_stop, None
        holding = stats is not None and stats.holding and session.live and guard is None
        if stats is not None and stats.holding and not holding:
            self.lease.torque_off(self.robot.ids)     # an e-stop or a late loop: never hold
        self.watch.end(stats, holding=holding, record_error=error, fault=guard,
                       telemetry=run.streamer.telemetry)

    def _verdict(self, stop: str, at_once: bool) -> None:
        """The rate guard's stop: at once (the servos no longer listen) or a ramp out to
        rest; either way a fault, so the run never ends holding (``_stream``)."""
        self._guard_stop = stop
        run = self._run
        if run is not None:
            if at_once:
                run.streamer.emergency_stop(stop)
            else:
                run.streamer.request_stop(stop)

    def stop(self) -> dict[str, Any]:
        """Safe stop of the run (ramp out, rest, torque off or hold); without one, the
        state as it is (stop is idempotent)."""
        run = self._run
        if run is not None:
            run.request_stop("panel stop")
        return {"state": self.watch.state_name()}

    def emergency_stop(self) -> dict[str, Any]:
        """Latch at the bus edge and torque off now; the run (if any) ends within a tick."""
        run = self._run
        if run is not None:
            run.emergency_stop("emergency stop")
        failed = self.lease.emergency_stop("emergency stop", confirm=run is None)
        self.watch.estop(running=run is not None)
        return {"state": "estop", "failed": failed}

    def release(self, limb: object, done: Done) -> None:
        limb_joints(self.robot, limb)                # an unknown limb: refused now
        session = self._acquire(f"the release of {limb}")

        def op() -> object:
            result = self.posing.release(session, limb)
            self.watch.released = str(limb)
            return result
        self._later(session, done, op)

    def capture(self, t: float | None, done: Done) -> None:
        cap = self.posing.captured()
        session = self._acquire("a keyframe capture")
        self._later(session, done, lambda: self.posing.capture(session, cap, t))

    def reset(self, done: Done) -> None:
        if self.raw.kind != "sim":
            raise PanelStateError("reset applies to the simulated bus only")
        session = self._acquire("a simulation reset")

        def op() -> dict[str, Any]:
            with self.lease.io:
                reset_to_home(self.raw, list(self.robot.ids))
            self.lease.torque.update(dict.fromkeys(self.robot.ids, False))
            self.watch.reset()
            return {"state": "idle"}
        self._later(session, done, op)

    def shutdown(self, done: Done) -> None:
        """Refuse new runs, safe-stop the run, then (on the loop thread, after it) close
        the bus: torque off unless the last run ended holding; answer what the wire was
        told."""
        self.closing = True
        run = self._run
        if run is not None:
            run.request_stop("panel shutdown")

        def op() -> dict[str, Any]:
            holding = self.watch.holding
            failed = self.lease.close(torque_off=not holding)
            if self._imu is not None and self._imu.is_open:
                self._imu.close()
            return {"holding": holding, "failed": failed, "torque": dict(self.lease.torque)}
        self._later(None, done, op)
        self._ops.put(None)
