"""Gait engine: params + phase + envelope → channels → targets → IK → joint angles.

Pure (no I/O). ``tick(dt)`` serves the control loop on floats (the engine is a motion
source, robot.loop.source); ``curves(times)`` serves previs on numpy arrays. Joint angles
come out in ``robot.joints`` order, clamped to the joint limits (each joint's clamped
poses counted: ``clamp_ticks``); unreachable targets are clamped by the IK and counted,
never NaN.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping

import numpy as np
import numpy.typing as npt

from robot.config.joint_names import JOINT_NAMES
from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.gait import expressions as gait
from robot.gait import vectorised
from robot.gait.blend import PARAM_TAU_S, PRESET_BLEND_S, STEER_RATE, Blend, follow
from robot.gait.stair_steps import StairPlan, StairSteps
from robot.gait.steering import STEER_BUDGET, within_steering_budget
from robot.gait.stop_close import ramp_out
from robot.gait.targets import NO_TRIM, BodyTrim, body_targets
from robot.gait.tick import TickKernel
from robot.gait.vectorised import solve
from robot.gait.xmath import Num
from robot.gait.xmath import plain as _plain
from robot.gait.xmath import smoothstep as _smoothstep

log = logging.getLogger(__name__)

__all__ = ["PARAM_TAU_S", "PRESET_BLEND_S", "STEER_BUDGET", "STEER_RATE", "GaitEngine",
           "within_steering_budget"]

#: The envelope's slowest rate [-] relative to its own while a feedback loop holds the
#: phase: a stop braced again and again still ends, in at most 1 / this the time.
ENVELOPE_MIN_RATE = 0.25


class GaitEngine:
    """Live gait state for one robot.

    The envelope ramps the gait amplitude in after ``start()`` and out after ``stop()``
    over ``ramp_cycles`` gait cycles (out within one swing when the trim's ``close`` asks:
    robot.gait.stop_close); the phase starts at 0 (start of the right swing).
    Parameter changes while the gait moves are followed smoothly (``PARAM_TAU_S``; a
    preset switch, ``blend_to``, over ``PRESET_BLEND_S``): ``params`` is what was set,
    ``live_params`` what the last tick used.
    """

    def __init__(self, robot: RobotConfig, params: GaitParams) -> None:
        driven = tuple(n for n in robot.joint_names if n in JOINT_NAMES)
        if driven != tuple(n for n in JOINT_NAMES if n in driven):
            raise ValueError("robot joints must be in canonical order")
        self.robot = robot
        self._leg_yaw = robot.has_hip_yaw
        self._params = params
        self._target = within_steering_budget(params)
        self._live = self._target
        self.phase = gait.Phase(0.0, 0.0, 0.0, 0.0, 0.0)
        self.time = 0.0
        self._ramp = 0.0          # linear ramp variable in [0, 1]
        self._stop: str | None = None   # a closing stop's stage (gait.stop_close)
        self._amplitude = 0.0     # _smoothstep(_ramp), set with it
        self._running = False
        self.unreachable_ticks = 0
        #: The heading change [rad] the gait's ``turn`` asked for so far: ``turn`` per step,
        #: two steps per cycle of the phase, times the envelope (a feedback loop's trim
        #: not included: it corrects, it does not ask).
        self.asked_yaw = 0.0
        #: Posture change relative to the feet, set by a feedback loop (robot.balance).
        self.trim = NO_TRIM
        #: Lift of the right and left foot [m] at the last ``pose`` (> 0: swinging).
        self.lift = (0.0, 0.0)
        self._lo = [j.min_rad for j in robot.joints]
        self._hi = [j.max_rad for j in robot.joints]
        self._limits = list(zip(self._lo, self._hi, strict=True))
        #: Poses in which each joint (robot order) was held at its limit, and the joints
        #: (indices) held there in the last pose.
        self.clamp_ticks = [0] * len(robot.joints)
        #: Ticks a feedback held the gait braced (trim.land > 0.5), all and after ``stop()``.
        self.braced_ticks = self.stop_braced_ticks = 0
        self.clamped: tuple[int, ...] = ()
        self._kernel = TickKernel(robot)
        self._plain_p: GaitParams | None = None   # the last parameters found _plain
        self._plain_trim: BodyTrim | None = None  # the last trim found _plain
        self._ramp_p: GaitParams | None = None    # the parameters _ramp_s is for
        self._ramp_s = 0.0
        self._blend: Blend | None = None  # a preset switch in progress (blend_to)
        self._blend_t = 0.0               # [s] since it began
        self.stairs: StairSteps | None = None  # footsteps on the stairs_* staircase
        self._ticking = False             # inside tick(): the pose is the walk's next

    # -- parameters -------------------------------------------------------------------
    @property
    def params(self) -> GaitParams:
        return self._params

    def set_params(self, changes: Mapping[str, float], *, where: str = "parameter"
                   ) -> GaitParams:
        """Validate and apply ``changes``; on error nothing changes (ConfigError)."""
        self.replace_params(self._params.replace(changes, where=where))
        return self._params

    def replace_params(self, params: GaitParams) -> None:
        """Set new parameters: at once while stopped, else followed smoothly by ``tick``
        (steering within ``STEER_BUDGET``)."""
        self._params = params
        self._target = within_steering_budget(params)
        if self.stopped:
            self._live = self._target

    @property
    def live_params(self) -> GaitParams:
        """The parameters in effect now (approaching ``params`` after a live change)."""
        return self._live

    def blend_to(self, params: GaitParams, *, seconds: float = PRESET_BLEND_S) -> None:
        """Switch to another preset's ``params``: at once while stopped, else every
        shaping parameter along one minimum-jerk blend over ``seconds`` [s] from the
        values live now (robot.gait.blend; steering at its rate). A later
        ``replace_params`` ends the blend (the rest followed as a slider change)."""
        self.replace_params(params)
        if not self.stopped:
            self._blend, self._blend_t = Blend(self._live, self._target, seconds), 0.0

    def _follow(self, dt: float) -> None:
        """Move the live parameters towards the set ones (robot.gait.blend.follow)."""
        blend = self._blend
        if blend is not None:
            self._blend_t += dt
            if blend.end is not self._target:      # replaced since: a slider's follow
                blend = self._blend = None
        self._live = follow(self._live, self._target, dt, blend=blend, blend_t=self._blend_t)
        if blend is not None and self._live is self._target:
            self._blend = None

    # -- envelope ---------------------------------------------------------------------
    def start(self) -> None:
        self._running = True
        self._stop = None

    def stop(self) -> None:
        self._running = False

    @property
    def amplitude(self) -> float:
        """Current envelope value in [0, 1]."""
        return self._amplitude

    @property
    def stopped(self) -> bool:
        """True once a stop has fully ramped out."""
        return not self._running and self._ramp <= 0.0

    @property
    def running(self) -> bool:
        return self._running

    # -- motion source (robot.loop.source) ----------------------------------------------
    def entry(self, present: npt.NDArray[np.float64], dt: float) -> list[float]:
        """Where a walk starts, whatever the present pose: ``start_pose()`` [rad]."""
        return self.start_pose()

    def exit_pose(self) -> npt.NDArray[np.float64]:
        """Where a walk ends: the robot's rest pose (a joint it does not name: 0) [rad]."""
        rest = self.robot.rest
        return np.array([rest.get(n, 0.0) for n in self.robot.joint_names], dtype=float)

    @property
    def state(self) -> str:
        """The loop's state while this engine drives it: "walking", or "ramp_out" after
        ``stop()``."""
        return "walking" if self._running else "ramp_out"

    # -- evaluation -------------------------------------------------------------------
    def pose(self, *, amplitude: float | None = None) -> list[float]:
        """Joint angles [rad] at the current phase (default: the current envelope)."""
        a = self.amplitude if amplitude is None else amplitude
        p, ph, trim = self._live, self.phase, self.trim
        q: list[Num]
        if self._ticking:       # a walk tick: the staircase's planner, while there is one
            plan = StairPlan.of(p) if p.stairs_count > 0 else None
            if plan is None:
                self.stairs = None
            elif self.stairs is None or self.stairs.plan != plan:
                self.stairs = StairSteps(plan, self.robot, self._leg_yaw, p.stairs_odometry)
        if self._ticking and self.stairs is not None:    # planned footsteps
            targets = self.stairs.targets(ph, p, a, trim)
            lift_r, lift_l = float(targets.lift_r), float(targets.lift_l)
            q, ok = solve(targets, self.robot)
        elif self._plain_inputs(p, ph, a, trim):
            # Python numbers throughout: the fused kernel, the same bits (robot.gait.tick).
            q, lift_r, lift_l, ok = self._kernel.pose(ph, p, a, trim)
        else:  # numpy scalars somewhere: the general functions, evaluated as they do
            ch = gait.channels(ph, p, amplitude=a)
            targets = body_targets(ch, p, self.robot.geometry, amplitude=a,
                                   leg_yaw=self._leg_yaw, trim=trim)
            lift_r, lift_l = float(targets.lift_r), float(targets.lift_l)
            q, ok = solve(targets, self.robot)
            q = [float(v) for v in q]
        self.lift = (lift_r, lift_l)
        if not ok:
            self.unreachable_ticks += 1
            if self.unreachable_ticks in (1, 10, 100) or self.unreachable_ticks % 1000 == 0:
                log.warning("gait target out of reach (%d ticks so far): clamped to the "
                            "nearest reachable pose; reduce stride, foot height or crouch",
                            self.unreachable_ticks)
        out = [lo if v < lo else hi if v > hi else v
               for v, (lo, hi) in zip(q, self._limits, strict=True)]
        if out != q:       # a joint held at its limit: counted per joint (clamp_ticks)
            self.clamped = tuple(i for i, (a, b) in enumerate(zip(out, q, strict=True))
                                 if a != b)
            for i in self.clamped:
                self.clamp_ticks[i] += 1
        elif self.clamped:
            self.clamped = ()
        return out

    def _plain_inputs(self, p: GaitParams, ph: gait.Phase, a: float, trim: BodyTrim) -> bool:
        """Every input a Python float or int, so the kernel's arithmetic is exactly the
        general functions' (checked once per parameter set and per trim)."""
        if p is not self._plain_p:
            self._plain_p = p if _plain(tuple(vars(p).values())) else None
        if trim is not self._plain_trim:
            self._plain_trim = trim if _plain(trim) else None
        return (p is self._plain_p and trim is self._plain_trim and _plain(ph)
                and (type(a) is float or type(a) is int))

    def start_pose(self) -> list[float]:
        """The pose at phase 0 with the envelope at 0 (where a walk starts and ends)."""
        saved = self.phase
        self.phase = gait.Phase(0.0, 0.0, 0.0, 0.0, 0.0)
        try:
            return self.pose(amplitude=0.0)
        finally:
            self.phase = saved

    def tick(self, dt: float) -> list[float]:
        """Advance by ``dt`` [s] (parameters, phase and envelope) and return the joint
        angles [rad]."""
        self._follow(dt)
        p = self._live
        if p is not self._ramp_p:
            self._ramp_p, self._ramp_s = p, p.ramp_cycles * p.cycle_s
        ramp_s = self._ramp_s
        # The envelope runs in gait time (ramp_cycles are cycles of the phase): while a
        # feedback loop holds the phase (a brace, tempo -1) it holds too, at least at
        # ENVELOPE_MIN_RATE, so the stride does not shrink under two planted feet.
        tempo = 1.0 + self.trim.tempo
        if self.trim.land > 0.5:
            self.braced_ticks += 1
            self.stop_braced_ticks += not self._running
        gait_dt = dt if tempo == 1.0 else dt * max(tempo, ENVELOPE_MIN_RATE)
        step = 1.0 if not math.isfinite(ramp_s) or ramp_s <= 0 else gait_dt / ramp_s
        if self._running:
            self._ramp = min(1.0, self._ramp + step)
        elif self.trim.close > 0.5:      # a stop that finishes its step (a feedback's)
            least = ENVELOPE_MIN_RATE * step * dt / gait_dt if gait_dt > 0 else step
            self._stop, self._ramp = ramp_out(self._stop, self._ramp, gait_dt,
                                              self.lift != (0.0, 0.0), p, least=least)
        else:
            self._ramp = max(0.0, self._ramp - step)
        self._amplitude = _smoothstep(self._ramp)
        if self._ramp > 0.0:
            theta = self.phase.theta
            rate = 1.0 if self.stairs is None else self.stairs.rate   # x 1.0: same bits
            self.phase = gait.advance(self.phase, p, dt * (tempo * rate))
            if p.turn != 0.0:
                self.asked_yaw += self.amplitude * p.turn * (self.phase.theta - theta) / math.pi
        else:
            # Fully ramped out: at zero amplitude the pose does not depend on the phase, so
            # resetting it is invisible and the next start begins a fresh stride.
            self.phase = gait.Phase(0.0, 0.0, 0.0, 0.0, 0.0)
        self.time += dt
        self._ticking = True
        try:
            return self.pose()
        finally:
            self._ticking = False

    def curves(self, times: npt.NDArray[np.float64], *, chunk: int = 16384,
               with_channels: bool = True
               ) -> tuple[dict[str, npt.NDArray[np.float64]], npt.NDArray[np.float64]]:
        """Channels and joint angles (n_joints, n) over ``times`` [s] at full amplitude and
        constant parameters (robot.gait.vectorised: in cache-sized chunks, over threads).
        ``with_channels=False`` returns an empty channel dict and only the joint angles."""
        return vectorised.curves(self.robot, self._target, times, chunk=chunk,
                                 with_channels=with_channels)

    def sole_targets(self, times: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """The sole targets (2, n, 3) [m, pelvis frame] that ``curves`` solves for."""
        return vectorised.sole_targets(self.robot, self._target, times)
