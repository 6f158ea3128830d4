"""The balance law: one tick of feedback from the torso's attitude, as a pure function.

Per control tick, from the torso's tilt (roll, pitch) [rad], tilt rate [rad/s] and heading
[rad] (``Attitude``), the gait's phase and the feet's lift:

- gyro damping (OP3 style): ankle and hip pitch/roll move against the tilt rate;
- lean: the pelvis learns (integrates) the lean that keeps the torso at the gait's own
  pitch (``torso_lean``) and upright in roll: on a slope the feet tilt with the ground
  while the body stays vertical; plus a proportional ankle term on the tilt itself;
- heading: a PI loop trims ``turn`` so the heading follows the commanded turn rate;
- stepping (robot.balance.stepping): a push is what the walk's learned rhythm does not
  explain (in the torso's tilt, and with ``bal_kin_xi`` in where the legs' kinematics put
  the body over its feet: robot.balance.kinematic); the swinging foot takes the capture
  step (robot.balance.capture_step: where the capture point will be at touchdown, sooner
  when that is out of reach), kept level with the ground; in double support the gait
  holds rather than lift a loaded foot.

Sign conventions (REP-103; robot/gait/ik.py): every pitch joint turns about +y and every roll
joint about +x of its parent. With a foot flat on the ground, the torso's pitch is
-(hip_pitch + knee + ankle_pitch) and its roll -(hip_roll + ankle_roll). A torso tipping
forward (pitch rate > 0) is therefore corrected by *raising* ankle and hip pitch, which
pushes the toes down and moves the centre of pressure forward, and by stepping forward
(+x); a roll to the right (roll rate > 0) by raising ankle and hip roll and by stepping
right (-y). The gains are gait parameters (group ``balance feedback`` of robot/config/params.py).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from robot.balance.heading_sign import SignCheck, look
from robot.balance.rhythm import Rhythm
from robot.balance.stepping import LEARN_CLIP, LEARNED, GaitPhase, StepState, phase_rate, step
from robot.config.params import GaitParams
from robot.imu.tilt import wrap

__all__ = ["LEARNED", "LEARN_CLIP", "Attitude", "BalanceState", "Correction", "GaitPhase",
           "balance_step", "commanded_yaw_rate"]


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


#: A gait phase for callers without an engine (full amplitude, no foot lifted).
NO_PHASE = GaitPhase()


class BalanceState(NamedTuple):
    """The loop's memory. lean_pitch, lean_roll: learned lean [rad]; heading: the estimate
    [rad]; heading_ref: where it should be [rad]; heading_i: integral of the heading error
    [rad s]; turn: the turn trim [rad/step]; stepping: its memory (step offsets, level
    turns, tempo, brace, hold, the learned rhythm; robot.balance.stepping); started: False
    until the first sample."""

    lean_pitch: float = 0.0
    lean_roll: float = 0.0
    heading: float = 0.0
    heading_ref: float = 0.0
    heading_i: float = 0.0
    turn: float = 0.0
    stepping: StepState = StepState()
    started: bool = False
    sign: SignCheck = SignCheck()

    @property
    def rhythm(self) -> Rhythm:
        return self.stepping.rhythm

    @property
    def next_lift(self) -> int:
        return self.stepping.next_lift


class Correction(NamedTuple):
    """Added to both legs [rad]: ankle/hip pitch and roll; turn trim [rad/step]; the
    pelvis's extra roll and pitch relative to the feet [rad] (the learned lean); the feet
    moved forward / left under the pelvis [m] (the capture step); level: the pelvis's
    further turn relative to each foot (right roll, pitch, left roll, pitch) [rad] (a
    swinging foot kept level); tempo: the gait phase runs (1 + tempo) times faster [-]
    (-1: it holds still); land: 0 walks, 1 keeps both feet down; capture: the
    capture-point error (forward, left) [m] (telemetry)."""

    ankle_pitch: float = 0.0
    ankle_roll: float = 0.0
    hip_pitch: float = 0.0
    hip_roll: float = 0.0
    turn: float = 0.0
    pelvis_roll: float = 0.0
    pelvis_pitch: float = 0.0
    feet: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    tempo: float = 0.0
    land: float = 0.0
    capture: tuple[float, float] = (0.0, 0.0)
    level: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)


def _clip(x: float, limit: float) -> float:
    return -limit if x < -limit else limit if x > limit else x


def commanded_yaw_rate(p: GaitParams, amplitude: float) -> float:
    """Yaw rate [rad/s] that ``turn`` [rad/step] asks for: two steps per gait cycle."""
    cycle = p.cycle_s
    if not math.isfinite(cycle) or cycle <= 0.0:
        return 0.0
    return amplitude * p.turn * 2.0 / cycle


def _heading(state: BalanceState, tilt: Attitude, p: GaitParams, dt: float,
             gait: GaitPhase) -> tuple[float, float, float, float, SignCheck]:
    """(heading, heading_ref, heading_i, turn trim, sign check) after one tick of the PI
    loop; on legs steered by stride length (``gait.by_stride``) the trim's sign is checked
    (robot.balance.heading_sign)."""
    amplitude = gait.amplitude
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
    cycle = p.cycle_s
    step_s = 0.5 * cycle if math.isfinite(cycle) else 0.0
    turn = want if step_s <= dt else state.turn + (want - state.turn) * dt / step_s
    sign = state.sign
    if gait.by_stride and amplitude >= 0.999:
        sign, flipped = look(sign, error, want, p.cycle_s, dt)
        if flipped:
            heading_i, turn = 0.0, 0.0
    return heading, heading_ref, heading_i, turn, sign


def balance_step(state: BalanceState, tilt: Attitude, p: GaitParams, dt: float,
                 gait: GaitPhase = NO_PHASE, kin: tuple[float, float, float, float] | None = None
                 ) -> tuple[BalanceState, Correction]:
    """One tick of the balance loop: the new state and the correction. dt: tick [s];
    kin: the pelvis over its support from the legs' angles (x, y [m], vx, vy [m/s];
    robot.balance.kinematic), None when unknown."""
    if not state.started:
        start = tilt.heading if tilt.heading is not None else 0.0
        state = BalanceState(heading=start, heading_ref=start,
                             stepping=StepState(rhythm=state.stepping.rhythm), started=True)
    a = gait.amplitude
    e_pitch = tilt.pitch - p.torso_lean
    e_roll = tilt.roll
    # The learned lean tilts the pelvis against the measured tilt (nose down when the
    # torso leans back), relative to the feet's plane.
    lean_pitch = _clip(state.lean_pitch - p.bal_lean_i * e_pitch * dt, p.bal_lean_max)
    lean_roll = _clip(state.lean_roll - p.bal_lean_i * e_roll * dt, p.bal_lean_max)
    heading, heading_ref, heading_i, turn, sign = _heading(state, tilt, p, dt, gait)
    values = (tilt.roll, tilt.pitch, tilt.roll_rate, tilt.pitch_rate)
    stepping, capture = step(state.stepping, values, p, gait, dt, kin)
    feet, level = stepping.feet, stepping.level
    corr = Correction(  # positional, in the order of the fields
        p.bal_ankle_pd * tilt.pitch_rate + p.bal_ankle_pp * e_pitch,       # ankle_pitch
        p.bal_ankle_pd * tilt.roll_rate + p.bal_ankle_pp * e_roll,         # ankle_roll
        p.bal_hip_pd * tilt.pitch_rate, p.bal_hip_pd * tilt.roll_rate,     # hip pitch, roll
        a * sign.sign * turn, lean_roll, lean_pitch,                # turn, pelvis roll, pitch
        (a * feet[0], a * feet[1], a * feet[2], a * feet[3]),       # feet
        phase_rate(stepping, a) - 1.0, stepping.brace, capture,     # tempo, land, capture
        (a * level[0], a * level[1], a * level[2], a * level[3]))   # level
    return BalanceState(lean_pitch, lean_roll, heading, heading_ref, heading_i, turn,
                        stepping, True, sign), corr
