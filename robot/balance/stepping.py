"""Stepping: what the balance law (robot.balance.law) does about a push, one tick at a time.

- The disturbance: the walk's own rocking in tilt and tilt rate is learned per phase
  (robot.balance.rhythm); what it does not explain (a residual tilt e and rate de/dt) puts
  the capture point dxi = h (e + de/dt / omega0) from where the walk expects it (a linear
  inverted pendulum of the hip height h pivoting on its feet, omega0 = sqrt(g / h)).
  With ``bal_kin_xi`` > 0 a share of dxi comes instead from the legs' kinematics
  (robot.balance.kinematic: the pelvis over its support from the held joint angles and the
  IMU's tilt, less the gait's plan and the feedback's own step offsets), its rhythm
  learned the same way: dxi = x + vx / omega0 of what the walk does not explain.
- The capture step (robot.balance.capture_step): the foot that swings (in double support,
  the one that lifts next) lands where dxi will have grown to by touchdown, within its
  reach, and the gait phase runs faster when that step would be out of reach
  (``bal_step_*``, ``bal_tempo_max``). A swinging foot follows its step target; a standing
  foot keeps its offset (moving it would push the body) until it swings again, when it
  goes back to the gait's own footstep unless a new step is needed.
- Level swing: the pelvis turns relative to the swinging foot with the residual tilt
  (``bal_swing_level``), so a foot swinging under a torso that rolls toward it keeps its
  height over the ground and its sole flat, and lands where the step was planned instead
  of early, on its edge; once it stands, that turn returns to 0 in ``LEVEL_OUT_S``.
- Hold: in double support the gait does not lift the foot the body leans onto
  (``bal_hold_xi``); brace: over ``bal_brace_xi`` both feet go down and the gait holds
  still for ``bal_brace_s``; a mostly forward error waits for a swinging foot to land
  first (a longer base to tip over; docs/robustness.md, issue 22).

Signs: REP-103, as robot.balance.law; dxi forward / left [m], tilts +roll right side down,
+pitch nose down [rad].
"""

from __future__ import annotations

import math
from typing import NamedTuple

from robot.balance.capture_step import Reach, StepPlan, plan_step, swing_phase_left, tempo_for
from robot.balance.rhythm import Rhythm
from robot.config.params import GaitParams

GRAVITY = 9.81  # [m/s^2]
#: Largest change one tick may make to the learned rhythm, per signal (roll, pitch [rad],
#: roll rate, pitch rate [rad/s]) x the learning rate: a push moves the table little.
LEARN_CLIP = (0.05, 0.05, 0.5, 0.5)
#: The same for the kinematic signals (the pelvis over its support: x, y [m], vx, vy
#: [m/s]): the tilt's clip x a 0.23 m pendulum.
KIN_CLIP = (0.012, 0.012, 0.12, 0.12)
#: The rhythm counts as learned (stepping and bracing act) after this many gait cycles
#: at full amplitude (robot.balance.rhythm learns a running mean over the first cycles).
LEARNED = 2.0
#: Swinging feet follow their step target with this time constant [gait cycles] (27 ms
#: for the walk preset: a hurried swing lasts about 0.15 s).
STEP_TAU_CYCLES = 1.0 / 32.0
#: The phase speed-up follows the capture step's with this time constant [s].
TEMPO_TAU_S = 0.02
#: A standing foot's level turn returns to 0 with this time constant [s].
LEVEL_OUT_S = 0.2
#: The brace and the hold come in and go out with these time constants [s]: in faster
#: than a foot falls, out over about a quarter of a step.
BRACE_IN_S = 0.02
BRACE_OUT_S = 0.1
#: While the gait stops, a brace needs this many times ``bal_brace_xi``.
STOP_BRACE = 2.0
Quad = tuple[float, float, float, float]


class GaitPhase(NamedTuple):
    """What the loop needs from the gait engine. theta: main phase [rad]; dtheta: its
    advance this tick [rad]; amplitude: the start/stop envelope [0, 1]; swinging: (right,
    left) foot lifted; height: pendulum length, the hip's height over the soles [m];
    inward: how far a foot may move toward the other one [m]; stopping: the gait was told
    to stop (its ramp-out); by_stride: the heading trim steers by step length (no hip
    yaw, ``bal_stride_turn`` set)."""

    theta: float = 0.0
    dtheta: float = 0.0
    amplitude: float = 1.0
    swinging: tuple[bool, bool] = (False, False)
    height: float = 0.23
    inward: float = 0.0
    stopping: bool = False
    by_stride: bool = False


class StepState(NamedTuple):
    """Stepping's memory. feet: (right dx, dy, left dx, dy) step offsets [m]; level:
    (right roll, pitch, left roll, pitch) the pelvis's turn relative to each foot [rad];
    tempo: phase speed-up [-]; brace: 0 walking .. 1 braced (feet down, gait still);
    brace_s: how much longer to stay braced [s]; hold: 0 .. 1 the gait holds in double
    support; next_lift: the foot the gait lifts next (0 right, 1 left); rhythm: the
    learned walk; latch: the largest capture step (forward, left) [m] planned during the
    current swing (a step once planned is not withdrawn before touchdown)."""

    feet: Quad = (0.0, 0.0, 0.0, 0.0)
    level: Quad = (0.0, 0.0, 0.0, 0.0)
    tempo: float = 0.0
    brace: float = 0.0
    brace_s: float = 0.0
    hold: float = 0.0
    next_lift: int = 0
    rhythm: Rhythm = Rhythm()
    latch: tuple[float, float] = (0.0, 0.0)
    kin_rhythm: Rhythm = Rhythm()
    braced_for: float = 0.0
    released: bool = False


def _clip(x: float, limit: float) -> float:
    return -limit if x < -limit else limit if x > limit else x


def _dead(x: float, band: float) -> float:
    """``x`` with ``band`` taken off its magnitude (0 inside the band)."""
    return x - band if x > band else x + band if x < -band else 0.0


def _further(old: float, new: float) -> float:
    """``new`` if it is further from 0 than ``old``, else ``old``."""
    return new if abs(new) > abs(old) else old


def _follow(x: float, want: float, dt: float, tau: float) -> float:
    return x + min(1.0, dt / tau) * (want - x) if tau > 0.0 else want


def used(p: GaitParams) -> bool:
    """Whether any stepping term is on (else the rhythm need not be learned)."""
    return (p.bal_step_gain != 0.0 or p.bal_brace_xi != 0.0 or p.bal_hold_xi != 0.0
            or p.bal_swing_level != 0.0)


def disturbance(rhythm: Rhythm, values: Quad, p: GaitParams, g: GaitPhase, moving: float,
                clip: Quad = LEARN_CLIP) -> tuple[Rhythm, Quad]:
    """The learned rhythm after this tick and the residual of ``values`` = the torso's
    (roll, pitch [rad], roll rate, pitch rate [rad/s]). The rhythm is expected in
    proportion to the envelope and to ``moving`` (1 - brace); it is learned only while the
    gait walks at full amplitude, each tick moving it by at most ``clip`` x the learning
    rate. Zeros until the rhythm is learned."""
    if not used(p):
        return rhythm, (0.0, 0.0, 0.0, 0.0)
    a = g.amplitude * moving
    learned = rhythm.at(g.theta)
    e_roll, e_pitch, r_roll, r_pitch = [v - a * m for v, m in zip(values, learned, strict=True)]
    if a >= 0.999 and p.bal_learn_cycles > 0.0:
        target = tuple([m + _clip(v - m, c)
                        for v, m, c in zip(values, learned, clip, strict=True)])
        rhythm = rhythm.learn(g.theta, target, g.dtheta, p.bal_learn_cycles)
    if p.bal_learn_cycles > 0.0 and rhythm.cycles < LEARNED:
        return rhythm, (0.0, 0.0, 0.0, 0.0)
    return rhythm, (e_roll, e_pitch, r_roll, r_pitch)


def capture_error(residual: Quad, height: float) -> tuple[float, float]:
    """The capture point's offset (forward, left) [m] from where the walk puts it, for a
    residual (roll, pitch [rad], roll rate, pitch rate [rad/s]) of the legs' tilt: the
    pendulum of length ``height`` [m] leans by the tilt, h (e + de/dt / omega0)."""
    h = max(height, 1e-3)
    w0 = math.sqrt(GRAVITY / h)
    e_roll, e_pitch, r_roll, r_pitch = residual
    return h * (e_pitch + r_pitch / w0), -h * (e_roll + r_roll / w0)


def kinematic_error(residual: Quad, height: float) -> tuple[float, float]:
    """The capture point's offset (forward, left) [m] from where the walk puts it, for a
    residual (x, y [m], vx, vy [m/s]) of the pelvis over its support: x + vx / omega0."""
    w0 = math.sqrt(GRAVITY / max(height, 1e-3))
    x, y, vx, vy = residual
    return x + vx / w0, y + vy / w0


def _standing_level(level: Quad, g: GaitPhase) -> tuple[float, float]:
    """The pelvis's level turn (roll, pitch) [rad] relative to the feet that stand (both:
    their mean): the torso tilts by it over the legs, which is not a fall."""
    if g.swinging[0] and not g.swinging[1]:
        return level[2], level[3]
    if g.swinging[1] and not g.swinging[0]:
        return level[0], level[1]
    return 0.5 * (level[0] + level[2]), 0.5 * (level[1] + level[3])


def capture_step(feet: Quad, xi: tuple[float, float], p: GaitParams, g: GaitPhase,
                 next_lift: int) -> tuple[StepPlan, float]:
    """The capture step of the foot that swings now, or of the one that lifts next in
    double support, and the phase speed-up it asks for."""
    rate = p.omega
    if not (math.isfinite(rate) and rate > 0.0) or all(g.swinging):
        return StepPlan(math.inf, 0.0, 0.0), 0.0
    foot = 0 if g.swinging[0] else 1 if g.swinging[1] else next_lift
    t_nom = swing_phase_left(g.theta, p.delta_f, foot) / rate
    _, ry, _, ly = feet
    out = p.bal_step_max
    # Inward, a foot may use its share of the gap, and what the other foot moved out.
    reach = (Reach(out, out, out, g.inward + max(0.0, ly)) if foot == 0
             else Reach(out, out, g.inward + max(0.0, -ry), out))
    gain = p.bal_step_gain
    dxi = (gain * _dead(xi[0], p.bal_step_dead), gain * _dead(xi[1], p.bal_step_dead))
    w0 = math.sqrt(GRAVITY / max(g.height, 1e-3))
    plan = plan_step(dxi, w0=w0, t_nominal=t_nom, t_min=t_nom / (1.0 + p.bal_tempo_max),
                     reach=reach, margin=p.bal_step_dead)
    return plan, tempo_for(t_nom, plan.t_s)


def _feet(feet: Quad, plan: StepPlan, p: GaitParams, g: GaitPhase, dt: float) -> Quad:
    """A swinging foot moves toward its capture step; a standing foot stays."""
    cycle = p.cycle_s
    tau = STEP_TAU_CYCLES * cycle if math.isfinite(cycle) else 0.0
    rx, ry, lx, ly = feet
    if g.swinging[0] and not g.swinging[1]:
        rx, ry = _follow(rx, plan.dx, dt, tau), _follow(ry, plan.dy, dt, tau)
    elif g.swinging[1] and not g.swinging[0]:
        lx, ly = _follow(lx, plan.dx, dt, tau), _follow(ly, plan.dy, dt, tau)
    return rx, ry, lx, ly


def _level(level: Quad, tilt: tuple[float, float], p: GaitParams, g: GaitPhase,
           dt: float) -> Quad:
    """A swinging foot's pelvis turn follows the residual tilt x ``bal_swing_level``; a
    standing foot's returns to 0."""
    want_roll, want_pitch = p.bal_swing_level * tilt[0], p.bal_swing_level * tilt[1]
    right, left = g.swinging
    r_roll, r_pitch, l_roll, l_pitch = level
    if right and not left:
        r_roll, r_pitch = want_roll, want_pitch
    else:
        r_roll, r_pitch = _follow(r_roll, 0.0, dt, LEVEL_OUT_S), _follow(r_pitch, 0.0, dt, LEVEL_OUT_S)
    if left and not right:
        l_roll, l_pitch = want_roll, want_pitch
    else:
        l_roll, l_pitch = _follow(l_roll, 0.0, dt, LEVEL_OUT_S), _follow(l_pitch, 0.0, dt, LEVEL_OUT_S)
    return r_roll, r_pitch, l_roll, l_pitch


def step(state: StepState, values: tuple[float, float, float, float], p: GaitParams,
         g: GaitPhase, dt: float, kin: Quad | None = None
         ) -> tuple[StepState, tuple[float, float]]:
    """One tick of stepping: the new state and the capture-point error (forward, left)
    [m] it acted on. ``values``: the torso's (roll, pitch, roll rate, pitch rate); ``kin``:
    the pelvis over its support (x, y [m], vx, vy [m/s]; robot.balance.kinematic), None
    when the legs' angles are not known (then the tilt alone says where the body is)."""
    rhythm, res = disturbance(state.rhythm, values, p, g, 1.0 - state.brace)
    kin_rhythm = state.kin_rhythm
    xi_kin = None
    if kin is not None and p.bal_kin_xi > 0.0:
        kin_rhythm, kres = disturbance(kin_rhythm, kin, p, g, 1.0 - state.brace, KIN_CLIP)
        xi_kin = kinematic_error(kres, g.height)
    # The legs' tilt: the torso's, less the turn the balance itself put over the standing
    # feet (and its rate this tick).
    old = _standing_level(state.level, g)
    level = _level(state.level, (res[0], res[1]), p, g, dt)
    new = _standing_level(level, g)
    legs = (res[0] - new[0], res[1] - new[1], res[2] - (new[0] - old[0]) / dt,
            res[3] - (new[1] - old[1]) / dt)
    xi = capture_error(legs, g.height)
    if xi_kin is not None:
        k = p.bal_kin_xi
        xi = ((1.0 - k) * xi[0] + k * xi_kin[0], (1.0 - k) * xi[1] + k * xi_kin[1])
    next_lift = 1 if g.swinging[0] else 0 if g.swinging[1] else state.next_lift
    plan, want_tempo = capture_step(state.feet, xi, p, g, next_lift)
    # Latch: late in a swing the torso's tilt no longer says where the body goes (the
    # swinging foot already takes weight, the ankles push); the foot keeps the furthest
    # step this swing planned. A new swing starts from its own plan.
    latch = (0.0, 0.0) if next_lift != state.next_lift else state.latch
    if any(g.swinging) and not all(g.swinging):
        latch = (_further(latch[0], plan.dx), _further(latch[1], plan.dy))
        plan = StepPlan(plan.t_s, latch[0], latch[1])
    feet = _feet(state.feet, plan, p, g, dt)
    tempo = _follow(state.tempo, want_tempo, dt, TEMPO_TAU_S)
    size = math.hypot(*xi)
    # A mostly forward error braces only once no foot swings: set down mid-swing beside
    # the stance foot, the swinging foot would shorten the base the body then tips over
    # (a forward push: it pivots on the toes of two feet side by side); landing where the
    # gait puts it, ahead, it lengthens that base. A backward or mostly lateral one braces
    # at once (waiting for those too cost a bump case on each robot's suite).
    may_brace = not any(g.swinging) or abs(xi[1]) > abs(xi[0]) or xi[0] < 0.0
    # A brace that has held bal_brace_max_s and still sees the error is given up: the
    # robot only tips slower over the edge of its feet while it stands (docs/robustness.md,
    # issue 22, third pass); the gait steps instead (the capture step, sooner), with no
    # brace or hold until the error is back under the brace's threshold.
    # A stop's closing swing moves the body as the learned rhythm does not (the sway goes
    # within one swing): while the gait stops, a brace needs STOP_BRACE x the error.
    large = 0.0 < p.bal_brace_xi * (STOP_BRACE if g.stopping else 1.0) < size
    released = state.released and large
    braced_for = state.braced_for + dt if state.brace_s > 0.0 else 0.0
    if 0.0 < p.bal_brace_max_s <= braced_for and large:
        released, braced_for = True, 0.0
    brace_s = (0.0 if released
               else p.bal_brace_s if large and may_brace else max(0.0, state.brace_s - dt))
    brace = _follow(state.brace, 1.0 if brace_s > 0.0 else 0.0, dt,
                    BRACE_IN_S if brace_s > 0.0 else BRACE_OUT_S)
    # Hold: in double support, do not lift the foot the body is leaning onto.
    toward = -xi[1] if next_lift == 0 else xi[1]       # the right foot is on the -y side
    holding = not any(g.swinging) and 0.0 < p.bal_hold_xi < toward and not released
    hold = _follow(state.hold, 1.0 if holding else 0.0, dt,
                   BRACE_IN_S if holding else BRACE_OUT_S)
    return StepState(feet, level, tempo, brace, brace_s, hold, next_lift, rhythm, latch,
                     kin_rhythm, braced_for, released), xi


def phase_rate(state: StepState, amplitude: float) -> float:
    """The gait phase's rate as a multiple of its own [-]: faster by the capture step's
    tempo, 0 while braced or held."""
    return (1.0 - state.brace) * (1.0 - state.hold) * (1.0 + amplitude * state.tempo)
