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

from robot.balance.law import (
    Attitude,
    BalanceState,
    Correction,
    GaitPhase,
    balance_step,
    commanded_yaw_rate,
)
from robot.gait.targets import NO_TRIM, BodyTrim
from robot.imu.base import Imu
from robot.imu.tilt import TiltEstimator, tilt_from_quat, wrap

if TYPE_CHECKING:
    from robot.gait.engine import GaitEngine

__all__ = ["Attitude", "Balance", "BalanceState", "Correction", "GaitPhase", "JointSlots",
           "apply", "attitude_reader", "balance_step", "commanded_yaw_rate", "wrap"]

#: Feet stay this far apart at least [m] when a step moves one toward the other.
FOOT_GAP_M = 0.005


class JointSlots(NamedTuple):
    """Indices of the corrected joints (right, left) in a robot's joint vector; a joint
    the robot lacks is left out."""

    ankle_pitch: list[int]
    ankle_roll: list[int]
    hip_pitch: list[int]
    hip_roll: list[int]

    @classmethod
    def of(cls, joint_names: Sequence[str]) -> JointSlots:
        index = {n: i for i, n in enumerate(joint_names)}

        def both(joint: str) -> list[int]:
            return [index[f"{s}_{joint}"] for s in ("r", "l") if f"{s}_{joint}" in index]
        return cls(both("ankle_pitch"), both("ankle_roll"), both("hip_pitch"),
                   both("hip_roll"))


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
    streamer then ends the walk as a fault and drops the feedback.
    """

    def __init__(self, engine: GaitEngine, read_tilt: Callable[[], Attitude]) -> None:
        self.engine = engine
        self._read_tilt = read_tilt
        self.slots = JointSlots.of(engine.robot.joint_names)
        self.state = BalanceState()
        self.last = Correction()
        self._theta = 0.0

    def start(self) -> None:
        """Forget the past (learned lean, heading, rhythm): called when the gait starts."""
        self.state = BalanceState()
        self.last = Correction()
        self._theta = float(self.engine.phase.theta)
        self.stop()

    def stop(self) -> None:
        self.engine.trim = NO_TRIM

    def gait_phase(self) -> GaitPhase:
        """What the law needs from the engine at this tick."""
        e = self.engine
        p, g = e.live_params, e.robot.geometry
        theta = float(e.phase.theta)
        dtheta = theta - self._theta
        self._theta = theta
        gap = g.hip_width + 2.0 * p.foot_spread - g.foot_width
        return GaitPhase(theta=theta, dtheta=dtheta if math.isfinite(dtheta) else 0.0,
                         amplitude=e.amplitude,
                         swinging=(e.lift[0] > 0.0, e.lift[1] > 0.0),
                         height=p.stance * g.leg_length + g.ankle_height,
                         inward=max(0.0, 0.5 * (gap - FOOT_GAP_M)))

    def __call__(self, q: np.ndarray, dt: float) -> np.ndarray:
        tilt = self._read_tilt()
        self.state, corr = balance_step(self.state, tilt, self.engine.live_params, dt,
                                        self.gait_phase())
        r_roll, r_pitch, l_roll, l_pitch = corr.level
        self.engine.trim = BodyTrim(corr.pelvis_roll, corr.pelvis_pitch, *corr.feet,
                                    turn=corr.turn, tempo=corr.tempo, land=corr.land,
                                    r_roll=r_roll, r_pitch=r_pitch, l_roll=l_roll,
                                    l_pitch=l_pitch)
        self.last = corr
        return apply(q, corr, self.slots)


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
        return Attitude(roll=roll, pitch=pitch, roll_rate=gx, pitch_rate=gy, yaw_rate=gz,
                        heading=heading)
    return read
