"""Balance feedback: the streamer's stage between the gait engine and safety.

``Balance`` reads the IMU each tick (``attitude_reader``), runs the balance law
(robot.balance.law: gyro damping, learned lean, heading loop, capture-point stepping),
adds the joint corrections to the legs and hands the engine its posture trims (pelvis
lean, foot offsets, turn and tempo) for the next tick. Design.md, "balance feedback".
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from robot.balance.kinematic import (
    LegSlots,
    SoleMemo,
    leg_angles,
    over_support,
    support_weight,
    unplanned,
)
from robot.balance.law import (
    Attitude,
    BalanceState,
    Correction,
    GaitPhase,
    balance_step,
    commanded_yaw_rate,
)
from robot.config.params import GaitParams
from robot.gait.targets import NO_TRIM, BodyTrim
from robot.imu.base import Imu
from robot.imu.tilt import TiltEstimator, tilt_from_quat, wrap

if TYPE_CHECKING:
    from robot.gait.engine import GaitEngine

__all__ = ["Attitude", "Balance", "BalanceState", "Correction", "GaitPhase", "JointSlots",
           "apply", "attitude_reader", "balance_step", "commanded_yaw_rate", "wrap"]

#: The servos' lag behind their command (read back every few ticks) is followed with
#: this time constant [s]: about the loop's read-back period (10 ticks at 200 Hz).
LAG_TAU_S = 0.05
#: The kinematic estimate's support passes from one sole to the other over this time
#: constant [s] when a foot lifts or lands.
SUPPORT_TAU_S = 0.03
#: Feet stay this far apart at least [m] when a step moves one toward the other.
FOOT_GAP_M = 0.005


class JointSlots(NamedTuple):
    """Indices of the corrected joints (right, left) in a robot's joint vector; a joint
    the robot lacks is left out, except the ankle roll: on legs without one its
    correction goes to the hip roll. With the sole flat on the ground the torso's roll
    is -(hip_roll + ankle_roll) (robot.balance.law), so the hip roll turns the torso as
    the ankle roll would, and the leg below it, rigid about x down to the sole, presses
    the sole's edge down as the ankle's torque would: dropping the term would take the
    roll's proportional feedback (``bal_ankle_pp``) away altogether."""

    ankle_pitch: list[int]
    ankle_roll: list[int]
    hip_pitch: list[int]
    hip_roll: list[int]

    @classmethod
    def of(cls, joint_names: Sequence[str]) -> JointSlots:
        index = {n: i for i, n in enumerate(joint_names)}

        def both(joint: str) -> list[int]:
            return [index[f"{s}_{joint}"] for s in ("r", "l") if f"{s}_{joint}" in index]
        ankle_roll = both("ankle_roll") or both("hip_roll")
        return cls(both("ankle_pitch"), ankle_roll, both("hip_pitch"), both("hip_roll"))


def apply(q: np.ndarray, corr: Correction, slots: JointSlots) -> np.ndarray:
    """``q`` [rad] with ``corr`` added to both legs (a new array)."""
    out = q.tolist() if isinstance(q, np.ndarray) else [float(v) for v in q]
    for idx, dq in ((slots.ankle_pitch, corr.ankle_pitch), (slots.ankle_roll, corr.ankle_roll),
                    (slots.hip_pitch, corr.hip_pitch), (slots.hip_roll, corr.hip_roll)):
        for i in idx:
            out[i] += dq
    return np.array(out)


class Balance:
    """The streamer's feedback stage: per tick, read the tilt, step the loop, trim the
    engine's turn and return the corrected joints.

    read_tilt: returns the current ``Attitude`` (from an IMU; robot.imu); it may raise, and the
    streamer then ends the walk as a fault and drops the feedback. present: returns the
    joint angles [rad] the servos reported since the last tick (the loop's read-back) or
    None; between read-backs the legs are taken at the last command plus the lag the
    last read-back showed (``bal_kin_xi``: robot.balance.kinematic).
    """

    def __init__(self, engine: GaitEngine, read_tilt: Callable[[], Attitude],
                 present: Callable[[], Sequence[float] | None] | None = None) -> None:
        self.engine = engine
        self._read_tilt = read_tilt
        self._present = present
        self.slots = JointSlots.of(engine.robot.joint_names)
        self.legs = LegSlots.of(engine.robot.joint_names)
        self._soles = SoleMemo(engine.robot.geometry)
        self._sent: np.ndarray | None = None
        self._lag: np.ndarray | None = None
        self._lag_seen: np.ndarray | None = None
        self._before: tuple[tuple[float, ...], tuple[float, ...]] | None = None
        self._plan_before: tuple[tuple[float, ...], tuple[float, ...]] | None = None
        self._trim_before: BodyTrim | None = None
        self._w: float | None = None
        self._phase_p: GaitParams | None = None    # the parameters _height, _inward are for
        self._height = self._inward = 0.0
        self._by_stride = False
        self.state = BalanceState()
        self.last = Correction()
        self._theta = 0.0

    def start(self) -> None:
        """Forget the past (learned lean, heading, rhythm): called when the gait starts."""
        self.state = BalanceState()
        self.last = Correction()
        self._theta = float(self.engine.phase.theta)
        self._sent = self._lag = self._lag_seen = None
        self._before = self._plan_before = self._trim_before = self._w = None
        self.stop()

    def stop(self) -> None:
        self.engine.trim = NO_TRIM

    def gait_phase(self) -> GaitPhase:
        """What the law needs from the engine at this tick."""
        e = self.engine
        p = e.live_params
        if p is not self._phase_p:    # the pendulum's height and the feet's room, per set
            g = e.robot.geometry
            gap = g.hip_width + 2.0 * p.foot_spread - g.foot_width
            self._phase_p, self._height = p, p.stance * g.leg_length + g.ankle_height
            self._inward = max(0.0, 0.5 * (gap - FOOT_GAP_M))
            self._by_stride = not e.robot.has_hip_yaw and p.bal_stride_turn != 0.0
        theta = float(e.phase.theta)
        dtheta = theta - self._theta
        self._theta = theta
        lift = e.lift
        return GaitPhase(theta, dtheta if math.isfinite(dtheta) else 0.0, e.amplitude,
                         (lift[0] > 0.0, lift[1] > 0.0), self._height, self._inward,
                         not e.running, self._by_stride)

    def held(self, q: np.ndarray, dt: float) -> np.ndarray:
        """The joint angles [rad] the servos hold now, as known: the last command plus
        the lag the read-backs show (present - commanded), followed with the time
        constant ``LAG_TAU_S`` so that a read-back is no jump; ``q`` (this tick's
        target) before anything was sent."""
        got = self._present() if self._present is not None else None
        if self._sent is None:
            return q
        if got is not None and len(got) == len(self._sent):
            self._lag_seen = np.asarray(got, dtype=float) - self._sent
        if self._lag_seen is not None:
            lag = self._lag if self._lag is not None else self._lag_seen
            self._lag = lag + min(1.0, dt / LAG_TAU_S) * (self._lag_seen - lag)
        return self._sent if self._lag is None else self._sent + self._lag

    def kinematics(self, q: np.ndarray, tilt: Attitude, gait: GaitPhase, dt: float
                   ) -> tuple[float, float, float, float]:
        """What the legs' kinematics show that the gait did not plan: the pelvis over its
        support (x, y [m], vx, vy [m/s]) from the held joints and the IMU's tilt, less
        the same from this tick's gait joints ``q`` (level) and the step offsets the
        feedback put under the support (robot.balance.kinematic.unplanned)."""
        held = self.held(q, dt).tolist()
        legs = (leg_angles(held, self.legs.right), leg_angles(held, self.legs.left))
        q_list = q.tolist()
        plan = (leg_angles(q_list, self.legs.right), leg_angles(q_list, self.legs.left))
        # The support moves from foot to foot over SUPPORT_TAU_S, not in one tick: the two
        # feet's unplanned offsets differ by a few mm, and a jump by half of that at a
        # lift that the learned rhythm places a bin early or late reads as a push.
        want = support_weight((not gait.swinging[0], not gait.swinging[1]))
        w = self._w = (want if self._w is None
                       else self._w + min(1.0, dt / SUPPORT_TAU_S) * (want - self._w))
        g, soles = self.engine.robot.geometry, self._soles
        soles.tick()
        measured = over_support(g, legs, self._before,
                                (tilt.roll, tilt.pitch, tilt.roll_rate, tilt.pitch_rate), w, dt,
                                soles_of=soles)
        planned = over_support(g, plan, self._plan_before, (0.0, 0.0, 0.0, 0.0), w, dt,
                               soles_of=soles)
        t = self.engine.trim
        shift = (w * t.r_dx + (1.0 - w) * t.l_dx, w * t.r_dy + (1.0 - w) * t.l_dy)
        b = self._trim_before
        before = None if b is None else (w * b.r_dx + (1.0 - w) * b.l_dx,
                                         w * b.r_dy + (1.0 - w) * b.l_dy)
        self._before, self._plan_before, self._trim_before = legs, plan, t
        return unplanned(measured, planned, shift, before, dt)

    def __call__(self, q: np.ndarray, dt: float) -> np.ndarray:
        tilt = self._read_tilt()
        p = self.engine.live_params
        gait = self.gait_phase()
        kin = None
        if p.bal_kin_xi > 0.0:
            kin = self.kinematics(q, tilt, gait, dt)
        else:       # switched on later (the panel), it starts afresh: no stale last tick
            self._before = self._plan_before = self._trim_before = self._w = None
        self.state, corr = balance_step(self.state, tilt, p, dt, gait, kin)
        r_dx, r_dy, l_dx, l_dy = corr.feet
        r_roll, r_pitch, l_roll, l_pitch = corr.level
        self.engine.trim = BodyTrim(corr.pelvis_roll, corr.pelvis_pitch, r_dx, r_dy, l_dx, l_dy,
                                    corr.turn, corr.tempo, corr.land, r_roll, r_pitch, l_roll,
                                    l_pitch, p.bal_stop_close)
        self.last = corr
        out = apply(q, corr, self.slots)
        self._sent = out
        return out


def attitude_reader(imu: Imu, *, tau_s: float | None = None) -> Callable[[], Attitude]:
    """A function that reads ``imu`` and returns the torso's ``Attitude``: tilt and
    heading from the device's fused quaternion when it has one, else tilt from a
    complementary filter (robot.imu.tilt, time constant ``tau_s`` [s]) and no heading (the
    loop then integrates the yaw rate). Rates are the gyro's, torso frame."""
    estimator = TiltEstimator() if tau_s is None else TiltEstimator(tau_s=tau_s)

    def read() -> Attitude:
        s = imu.read()
        gx, gy, gz = s.gyro
        if s.quat is not None:
            roll, pitch = tilt_from_quat(s.quat)
            w, x, y, z = s.quat
            heading: float | None = math.atan2(2.0 * (w * z + x * y),
                                               1.0 - 2.0 * (y * y + z * z))
        else:
            roll, pitch = estimator.update(s)
            heading = None
        return Attitude(roll, pitch, gx, gy, gz, heading)
    return read
