"""Balance feedback: an IMU sample → joint-angle corrections and a turn trim.

The stage between the gait engine and the streamer's safety stage (design.md, "balance
feedback"). Per control tick, from the torso's tilt (roll, pitch) [rad], tilt rate
(gyro x, y) [rad/s] and heading [rad]:

- gyro damping (OP3 style): ankle and hip pitch/roll move against the tilt rate;
- lean: the ankles learn (integrate) the lean that keeps the torso at the gait's own
  pitch (``torso_lean``) and upright in roll: on a slope the feet tilt with the ground
  while the body stays vertical; plus a proportional term on the tilt itself;
- heading: a PI loop trims ``turn`` so the heading follows the commanded turn rate.

Sign conventions (REP-103; robot/ik.py): every pitch joint turns about +y and every roll
joint about +x of its parent. With a foot flat on the ground, the torso's pitch is
-(hip_pitch + knee + ankle_pitch) and its roll -(hip_roll + ankle_roll). A torso tipping
forward (pitch rate > 0) is therefore corrected by *raising* ankle and hip pitch, which
pushes the toes down and moves the centre of pressure forward; a roll to the right
(roll rate > 0) by raising ankle and hip roll. The gains are gait parameters (group
``balance feedback`` of robot/params.py), so they are live-tunable and tuned per preset.

``balance_step`` is pure; ``Balance`` applies it to a joint vector.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from robot.imu.base import Imu
from robot.imu.tilt import TiltEstimator, tilt_from_quat, wrap
from robot.params import GaitParams
from robot.targets import NO_TRIM, BodyTrim

if TYPE_CHECKING:
    from robot.engine import GaitEngine


class Attitude(NamedTuple):
    """What the balance loop needs from an IMU, in the torso frame.

    roll, pitch: tilt from upright [rad] (+pitch = nose down, +roll = right side down);
    roll_rate, pitch_rate, yaw_rate: angular velocity [rad/s]; heading: yaw [rad] or None
    when the device has no absolute heading (then the yaw rate is integrated).
    """

    roll: float
    pitch: float
    roll_rate: float
    pitch_rate: float
    yaw_rate: float
    heading: float | None = None


class BalanceState(NamedTuple):
    """The loop's memory. lean_pitch, lean_roll: learned ankle lean [rad]; heading: the
    estimate [rad]; heading_ref: where the heading should be [rad]; heading_i: integral
    of the heading error [rad s]; turn: the turn trim [rad/step]; started: False until the
    first sample."""

    lean_pitch: float = 0.0
    lean_roll: float = 0.0
    heading: float = 0.0
    heading_ref: float = 0.0
    heading_i: float = 0.0
    turn: float = 0.0
    feet: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    started: bool = False


class Correction(NamedTuple):
    """Added to both legs [rad]: ankle/hip pitch and roll; turn trim [rad/step]; the
    pelvis's extra roll and pitch relative to the feet [rad] (the learned lean); both feet
    moved forward / left under the pelvis [m] (the step toward the fall)."""

    ankle_pitch: float = 0.0
    ankle_roll: float = 0.0
    hip_pitch: float = 0.0
    hip_roll: float = 0.0
    turn: float = 0.0
    pelvis_roll: float = 0.0
    pelvis_pitch: float = 0.0
    feet: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)


def _clip(x: float, limit: float) -> float:
    return -limit if x < -limit else limit if x > limit else x


def commanded_yaw_rate(p: GaitParams, amplitude: float) -> float:
    """Yaw rate [rad/s] that ``turn`` [rad/step] asks for: two steps per gait cycle."""
    cycle = p.cycle_s
    if not math.isfinite(cycle) or cycle <= 0.0:
        return 0.0
    return amplitude * p.turn * 2.0 / cycle


def balance_step(state: BalanceState, tilt: Attitude, p: GaitParams, dt: float, *,
                 amplitude: float = 1.0,
                 swinging: tuple[bool, bool] = (False, False)) -> tuple[BalanceState, Correction]:
    """One tick of the balance loop: the new state and the correction. dt: tick [s];
    amplitude: the gait envelope (the heading reference follows the commanded turn
    scaled by it)."""
    if not state.started:
        start = tilt.heading if tilt.heading is not None else 0.0
        state = BalanceState(heading=start, heading_ref=start, started=True)
    e_pitch = tilt.pitch - p.torso_lean
    e_roll = tilt.roll
    # The learned lean tilts the pelvis against the measured tilt (nose down when the
    # torso leans back), relative to the feet's plane.
    lean_pitch = _clip(state.lean_pitch - p.bal_lean_i * e_pitch * dt, p.bal_lean_max)
    lean_roll = _clip(state.lean_roll - p.bal_lean_i * e_roll * dt, p.bal_lean_max)
    heading = (tilt.heading if tilt.heading is not None
               else wrap(state.heading + tilt.yaw_rate * dt))
    heading_ref = wrap(state.heading_ref + commanded_yaw_rate(p, amplitude) * dt)
    error = wrap(heading_ref - heading)
    i_limit = p.bal_turn_max / p.bal_heading_i if p.bal_heading_i > 0 else 0.0
    heading_i = _clip(state.heading_i + error * dt, i_limit)
    # The trim follows the PI output with a time constant of one step: a stance foot yaws
    # with turn, so a trim that changed within a step would yaw the body one way in one
    # step and the other way in the next.
    want = _clip(p.bal_heading_p * error + p.bal_heading_i * heading_i, p.bal_turn_max)
    step_s = 0.5 * p.cycle_s if math.isfinite(p.cycle_s) else 0.0
    turn = want if step_s <= dt else state.turn + (want - state.turn) * dt / step_s
    # Stepping: a swinging foot moves (time constant: a quarter step) toward where the
    # body is falling; a standing foot stays put (moving it would push the body).
    want_x = _clip(p.bal_step_pd * tilt.pitch_rate, p.bal_step_max)
    want_y = _clip(-p.bal_step_pd * tilt.roll_rate, p.bal_step_max)
    a = min(1.0, dt / (0.125 * p.cycle_s)) if math.isfinite(p.cycle_s) else 1.0
    rx, ry, lx, ly = state.feet
    if swinging[0]:
        rx, ry = rx + a * (want_x - rx), ry + a * (want_y - ry)
    if swinging[1]:
        lx, ly = lx + a * (want_x - lx), ly + a * (want_y - ly)
    feet = (rx, ry, lx, ly)
    corr = Correction(
        ankle_pitch=p.bal_ankle_pd * tilt.pitch_rate + p.bal_ankle_pp * e_pitch,
        ankle_roll=p.bal_ankle_pd * tilt.roll_rate + p.bal_ankle_pp * e_roll,
        hip_pitch=p.bal_hip_pd * tilt.pitch_rate,
        hip_roll=p.bal_hip_pd * tilt.roll_rate,
        turn=amplitude * turn, pelvis_roll=lean_roll, pelvis_pitch=lean_pitch, feet=feet)
    return BalanceState(lean_pitch, lean_roll, heading, heading_ref, heading_i, turn, feet,
                        True), corr


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
    out = np.array(q, dtype=float)
    out[slots.ankle_pitch] += corr.ankle_pitch
    out[slots.ankle_roll] += corr.ankle_roll
    out[slots.hip_pitch] += corr.hip_pitch
    out[slots.hip_roll] += corr.hip_roll
    return out


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

    def start(self) -> None:
        """Forget the past (learned lean, heading): called when the gait starts."""
        self.state = BalanceState()
        self.last = Correction()
        self.stop()

    def stop(self) -> None:
        self.engine.trim = NO_TRIM

    def __call__(self, q: np.ndarray, dt: float) -> np.ndarray:
        tilt = self._read_tilt()
        lift = self.engine.lift
        self.state, corr = balance_step(self.state, tilt, self.engine.live_params, dt,
                                        amplitude=self.engine.amplitude,
                                        swinging=(lift[0] > 0.0, lift[1] > 0.0))
        self.engine.trim = BodyTrim(corr.pelvis_roll, corr.pelvis_pitch, *corr.feet,
                                    turn=corr.turn)
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
