"""The balance law: one tick of feedback from the torso's attitude, as a pure function.

Per control tick, from the torso's tilt (roll, pitch) [rad], tilt rate [rad/s] and heading
[rad] (``Attitude``), the gait's phase and the feet's lift:

- gyro damping (OP3 style): ankle and hip pitch/roll move against the tilt rate;
- lean: the pelvis learns (integrates) the lean that keeps the torso at the gait's own
  pitch (``torso_lean``) and upright in roll: on a slope the feet tilt with the ground
  while the body stays vertical; plus a proportional ankle term on the tilt itself;
- heading: a PI loop trims ``turn`` so the heading follows the commanded turn rate;
- stepping (capture point): the walk's own rocking is learned per phase
  (``robot.balance.rhythm``); what it does not explain is a disturbance. Treating the robot as an
  inverted pendulum of the hip height h pivoting on its feet, a residual tilt e and rate
  de/dt put the capture point h * (e + de/dt / omega0) (omega0 = sqrt(g / h)) away from
  where the walk expects it. A swinging foot is placed ``bal_step_gain`` times that far
  toward the fall (never across the other foot), and the gait phase runs faster
  (``bal_tempo_*``) so the next step comes sooner.

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

from robot.balance.rhythm import Rhythm
from robot.config.params import GaitParams
from robot.imu.tilt import wrap

GRAVITY = 9.81  # [m/s^2]
#: Largest change one tick may make to the learned rhythm, per signal (roll, pitch [rad],
#: roll rate, pitch rate [rad/s]) x the learning rate: a push moves the table little.
LEARN_CLIP = (0.05, 0.05, 0.5, 0.5)
#: The rhythm counts as learned (stepping and bracing act) after this many gait cycles
#: at full amplitude (robot.balance.rhythm learns a running mean over the first cycles).
LEARNED = 2.0
#: Swinging feet follow their step target with this time constant [gait cycles].
STEP_TAU_CYCLES = 1.0 / 16.0
#: The brace (feet down, gait still) comes in and goes out with these time constants [s]:
#: in faster than a foot falls, out over about a quarter of a step.
BRACE_IN_S = 0.02
BRACE_OUT_S = 0.1


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


class GaitPhase(NamedTuple):
    """What the loop needs from the gait engine. theta: main phase [rad]; dtheta: its
    advance this tick [rad]; amplitude: the start/stop envelope [0, 1]; swinging: (right,
    left) foot lifted; height: pendulum length, the hip's height over the soles [m];
    inward: how far a foot may move toward the other one [m]."""

    theta: float = 0.0
    dtheta: float = 0.0
    amplitude: float = 1.0
    swinging: tuple[bool, bool] = (False, False)
    height: float = 0.23
    inward: float = 0.0


#: A gait phase for callers without an engine (full amplitude, no foot lifted).
NO_PHASE = GaitPhase()


class BalanceState(NamedTuple):
    """The loop's memory. lean_pitch, lean_roll: learned lean [rad]; heading: the estimate
    [rad]; heading_ref: where it should be [rad]; heading_i: integral of the heading error
    [rad s]; turn: the turn trim [rad/step]; feet: (right dx, dy, left dx, dy) step offsets
    [m]; tempo: extra phase rate [-]; brace: 0 walking .. 1 braced (feet down, gait
    still); brace_s: how much longer to stay braced [s]; hold: 0 .. 1 the gait holds in
    double support; next_lift: the foot the gait lifts next (0 right, 1 left); rhythm: the
    learned walk; started: False until the first sample."""

    lean_pitch: float = 0.0
    lean_roll: float = 0.0
    heading: float = 0.0
    heading_ref: float = 0.0
    heading_i: float = 0.0
    turn: float = 0.0
    feet: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    tempo: float = 0.0
    brace: float = 0.0
    brace_s: float = 0.0
    hold: float = 0.0
    next_lift: int = 0
    rhythm: Rhythm = Rhythm()
    started: bool = False


class Correction(NamedTuple):
    """Added to both legs [rad]: ankle/hip pitch and roll; turn trim [rad/step]; the
    pelvis's extra roll and pitch relative to the feet [rad] (the learned lean); the feet
    moved forward / left under the pelvis [m] (the step toward the fall); tempo: the gait
    phase runs (1 + tempo) times faster [-] (-1: it holds still); land: 0 walks, 1 keeps
    both feet down; capture: the capture-point error (forward, left) [m] (telemetry)."""

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


def _clip(x: float, limit: float) -> float:
    return -limit if x < -limit else limit if x > limit else x


def commanded_yaw_rate(p: GaitParams, amplitude: float) -> float:
    """Yaw rate [rad/s] that ``turn`` [rad/step] asks for: two steps per gait cycle."""
    cycle = p.cycle_s
    if not math.isfinite(cycle) or cycle <= 0.0:
        return 0.0
    return amplitude * p.turn * 2.0 / cycle


def _heading(state: BalanceState, tilt: Attitude, p: GaitParams, dt: float,
             amplitude: float) -> tuple[float, float, float, float]:
    """(heading, heading_ref, heading_i, turn trim) after one tick of the PI loop."""
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
    return heading, heading_ref, heading_i, turn


def _capture(rhythm: Rhythm, tilt: Attitude, p: GaitParams, g: GaitPhase, brace: float
             ) -> tuple[Rhythm, float, float]:
    """The learned rhythm after this tick and the capture-point error (forward, left) [m].
    The rhythm is expected in proportion to the envelope and to how much the gait moves
    (1 - brace); it is learned only while the gait walks at full amplitude."""
    if (p.bal_step_gain == 0.0 and p.bal_brace_xi == 0.0 and p.bal_tempo_gain == 0.0
            and p.bal_hold_xi == 0.0):
        return rhythm, 0.0, 0.0                   # nothing uses it: no need to learn
    values = (tilt.roll, tilt.pitch, tilt.roll_rate, tilt.pitch_rate)
    a = g.amplitude * (1.0 - brace)
    learned = rhythm.at(g.theta)
    e_roll, e_pitch, r_roll, r_pitch = (v - a * m for v, m in zip(values, learned, strict=True))
    if a >= 0.999 and p.bal_learn_cycles > 0.0:
        target = tuple(m + _clip(v - m, c)
                       for v, m, c in zip(values, learned, LEARN_CLIP, strict=True))
        rhythm = rhythm.learn(g.theta, target, g.dtheta, p.bal_learn_cycles)
    h = max(g.height, 1e-3)
    w0 = math.sqrt(GRAVITY / h)
    if p.bal_learn_cycles > 0.0 and rhythm.cycles < LEARNED:  # not learned: no stepping
        return rhythm, 0.0, 0.0
    return rhythm, h * (e_pitch + r_pitch / w0), -h * (e_roll + r_roll / w0)


def _dead(x: float, band: float) -> float:
    """``x`` with ``band`` taken off its magnitude (0 inside the band)."""
    return x - band if x > band else x + band if x < -band else 0.0


def _steps(feet: tuple[float, float, float, float], xi: tuple[float, float], p: GaitParams,
           g: GaitPhase, dt: float) -> tuple[float, float, float, float]:
    """Step offsets after one tick: a swinging foot moves toward the capture point (never
    more than ``inward`` toward the other foot); a standing foot stays (moving it would
    push the body)."""
    cycle = p.cycle_s
    k = min(1.0, dt / (STEP_TAU_CYCLES * cycle)) if math.isfinite(cycle) and cycle > 0 else 1.0
    want_x = _clip(p.bal_step_gain * _dead(xi[0], p.bal_step_dead), p.bal_step_max)
    want_y = _clip(p.bal_step_gain * _dead(xi[1], p.bal_step_dead), p.bal_step_max)
    rx, ry, lx, ly = feet
    if g.swinging[0]:
        ry_want = min(want_y, g.inward)           # the right foot moves left = inward
        rx, ry = rx + k * (want_x - rx), ry + k * (ry_want - ry)
    if g.swinging[1]:
        ly_want = max(want_y, -g.inward)
        lx, ly = lx + k * (want_x - lx), ly + k * (ly_want - ly)
    return rx, ry, lx, ly


def balance_step(state: BalanceState, tilt: Attitude, p: GaitParams, dt: float,
                 gait: GaitPhase = NO_PHASE) -> tuple[BalanceState, Correction]:
    """One tick of the balance loop: the new state and the correction. dt: tick [s]."""
    if not state.started:
        start = tilt.heading if tilt.heading is not None else 0.0
        state = BalanceState(heading=start, heading_ref=start, rhythm=state.rhythm,
                             started=True)
    a = gait.amplitude
    e_pitch = tilt.pitch - p.torso_lean
    e_roll = tilt.roll
    # The learned lean tilts the pelvis against the measured tilt (nose down when the
    # torso leans back), relative to the feet's plane.
    lean_pitch = _clip(state.lean_pitch - p.bal_lean_i * e_pitch * dt, p.bal_lean_max)
    lean_roll = _clip(state.lean_roll - p.bal_lean_i * e_roll * dt, p.bal_lean_max)
    heading, heading_ref, heading_i, turn = _heading(state, tilt, p, dt, a)
    rhythm, xi_x, xi_y = _capture(state.rhythm, tilt, p, gait, state.brace)
    feet = _steps(state.feet, (xi_x, xi_y), p, gait, dt)
    xi = math.hypot(xi_x, xi_y)
    excess = _dead(xi, p.bal_step_dead)
    want_tempo = min(p.bal_tempo_gain * excess, p.bal_tempo_max)
    cycle = p.cycle_s
    k = min(1.0, dt / (STEP_TAU_CYCLES * cycle)) if math.isfinite(cycle) and cycle > 0 else 1.0
    tempo = state.tempo + k * (want_tempo - state.tempo)
    brace_s = (p.bal_brace_s if 0.0 < p.bal_brace_xi < xi
               else max(0.0, state.brace_s - dt))
    up = brace_s > 0.0
    brace = state.brace + min(1.0, dt / (BRACE_IN_S if up else BRACE_OUT_S)) * (
        (1.0 if up else 0.0) - state.brace)
    # Hold: in double support, do not lift the foot the body is leaning onto.
    next_lift = 1 if gait.swinging[0] else 0 if gait.swinging[1] else state.next_lift
    toward = -xi_y if next_lift == 0 else xi_y       # the right foot is on the -y side
    holding = (not any(gait.swinging) and 0.0 < p.bal_hold_xi < toward)
    hold = state.hold + min(1.0, dt / (BRACE_IN_S if holding else BRACE_OUT_S)) * (
        (1.0 if holding else 0.0) - state.hold)
    corr = Correction(
        ankle_pitch=p.bal_ankle_pd * tilt.pitch_rate + p.bal_ankle_pp * e_pitch,
        ankle_roll=p.bal_ankle_pd * tilt.roll_rate + p.bal_ankle_pp * e_roll,
        hip_pitch=p.bal_hip_pd * tilt.pitch_rate,
        hip_roll=p.bal_hip_pd * tilt.roll_rate,
        turn=a * turn, pelvis_roll=lean_roll, pelvis_pitch=lean_pitch,
        feet=(a * feet[0], a * feet[1], a * feet[2], a * feet[3]),
        tempo=(1.0 - brace) * (1.0 - hold) * (1.0 + a * tempo) - 1.0, land=brace,
        capture=(xi_x, xi_y))
    return BalanceState(lean_pitch, lean_roll, heading, heading_ref, heading_i, turn, feet,
                        tempo, brace, brace_s, hold, next_lift, rhythm, True), corr
