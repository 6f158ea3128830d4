"""Root motion becomes the gait's travel: where an animation walks (robot/previs/
walk_spans.py), the paper's gait walks the legs (robot/motion/show_walk.py) with the speed,
turn and side step that make the robot travel as the animation's root does.

Per step (from one swing's lift-off to the next; the last to the walk's end) the root's
mean velocity over that step, in the heading frame of the root: forward v [m/s], left u
[m/s], yaw rate w [rad/s]. Step by step, so the steps' travel adds up to the root's (a
longer window, a stride, would average a limp but not add up at the walk's ends). The
gait's parameters follow from what one unit of each makes the robot travel
(robot/gait/targets.py, docs/gait.md), with n = 2 / cycle steps per second:

- ``speed`` scales the stride: the stance foot moves 2 A relative to the pelvis per step
  (A = the stride amplitude, ``Slgt`` x leg / ``rig_leg`` [m]), so the no-slip speed is
  2 A n per unit of ``speed``: speed = v / (2 A n e_f);
- ``side_step`` [m/step]: side_step = u / (n e_s); ``turn`` [rad/step]: turn = w / (n e_t);

e (``Efficiency``) is the share of that kinematic travel the robot realizes, measured in
MuJoCo with the ``walk`` preset over 20 s (``biped walk --set speed=... --json``; a show
plays without balance unless ``biped play --balance``): forward on biped18-dynamixel 0.66-
0.80 at speed 0.25-1 without balance (0.75-0.84 with), on biped18-feetech 0.29-0.72
without (0.58-0.76 with); side step 0.51-0.62 (dynamixel, 0.01-0.02 m/step; feetech 0.18
at 0.01 without balance); turn 0.96-1.02 on both (feetech without balance: 0.93 at speed
0.85). The defaults are the dynamixel robot's without balance. Where a robot's share
differs, or changes much with the speed (biped18-feetech without balance), ``MEASURED``
keeps its own, by speed; the speed asked is then the one whose share times speed walks
the root's speed over the walk, its ramps (a smaller stride, so a smaller share) counted
(``Efficiency.speed_for``). The values are kept inside what the gait
walks: ``speed`` in ``SPEED_RANGE`` (1.5 walked less far than 1.0 on both bundled robots:
it stumbles), turn and side step in their parameter ranges; each clamp is reported.

The gait starts half its ramp-in time (``ramp_cycles`` x cycle) before the walk's first
lift-off and is told to stop half its ramp-out time before the last touch-down, so its
amplitude's integral, the distance it walks, is the walk's length at full amplitude; for
that the ramp out keeps the speed of the step it starts in (steps that begin after the
gait's stop are not written). The legs are the gait's from the walk's first lift-off to its
last touch-down and blend over the half ramps outside it (robot/motion/show_walk.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from robot.config.params import SPECS, GaitParams
from robot.config.robot import RobotConfig
from robot.motion.show_walk import Travel
from robot.previs.feet import RigMotion
from robot.previs.walk_spans import Walk

#: The ``speed`` a show may ask (forward and backward).
SPEED_RANGE = (-1.0, 1.0)
#: Changes smaller than this (in every parameter) are not written.
CHANGE_EPS = 1e-3


@dataclass(frozen=True)
class Efficiency:
    """The share of the gait's kinematic travel the robot realizes (see the module)."""

    forward: float = 0.75
    side: float = 0.55
    turn: float = 1.0
    #: (speed, forward share) points, by speed; when given they replace ``forward``
    #: (interpolated; the end points' shares beyond them).
    forward_by_speed: tuple[tuple[float, float], ...] = ()

    def speed_for(self, no_slip: float, *, walk_s: float = math.inf,
                  ramp_s: float = 0.0) -> float:
        """The gait ``speed`` that walks ``no_slip`` units of the no-slip stride speed
        (the root's speed over what ``speed`` 1 would walk if no foot slipped) on average
        over a walk of ``walk_s`` [s] whose ramps take ``ramp_s`` [s] each. In a ramp the
        envelope A = smoothstep(r), r from 0 to 1, shrinks the stride as a speed x A
        would, at that speed's share; the ramps in and out together walk ``ramp_s`` at
        full amplitude's worth (the rest of the walk: ``walk_s - ramp_s``)."""
        if not self.forward_by_speed:
            return no_slip / self.forward
        grid = np.linspace(0.0, 2.0, 401)
        r = np.linspace(0.0, 1.0, 51)
        amp = r * r * (3.0 - 2.0 * r)
        pts = np.asarray(self.forward_by_speed)
        at = np.interp(np.outer(grid, amp), pts[:, 0], pts[:, 1])    # share (speed, r)
        ramp_share = (at * amp).mean(axis=1) / amp.mean()
        full = max(walk_s - ramp_s, 0.0) if math.isfinite(walk_s) else 1.0
        ramped = min(ramp_s, walk_s) if math.isfinite(walk_s) else 0.0
        share = np.interp(grid, pts[:, 0], pts[:, 1])
        walked = grid * (share * full + ramp_share * ramped) / (full + ramped)
        return math.copysign(float(np.interp(abs(no_slip), walked, grid)), no_slip)


#: What the bundled robots realize where it differs from ``Efficiency()``: MuJoCo, ``walk``
#: preset, no balance; forward from the difference of a 20 s and a 10 s walk (``biped walk
#: --robot R --no-balance --set speed=S --seconds 10|20 --json``, so the ramps cancel),
#: turn likewise at speed 0.85, turn 0.087 rad/step (106 of 114 deg per 10 s).
MEASURED = {
    "biped18-feetech": Efficiency(forward=0.65, side=0.18, turn=0.93, forward_by_speed=(
        (0.5, 0.48), (0.75, 0.65), (0.9, 0.71), (1.0, 0.75))),
}


def efficiency_for(robot: RobotConfig) -> Efficiency:
    """The measured shares for ``robot`` (the dynamixel robot's for any other)."""
    return MEASURED.get(robot.name, Efficiency())


@dataclass(frozen=True)
class WalkPlan:
    """One walk as the gait will walk it: gait start and stop [s of show time], the root's
    mean velocity over the walk (forward, left [m/s], yaw rate [rad/s]), the parameters
    per step (time [s], speed, turn, side_step) and what was clamped (lines)."""

    walk: Walk
    gait_start: float
    gait_stop: float
    velocity: tuple[float, float, float]
    steps: tuple[tuple[float, float, float, float], ...]
    clamped: tuple[str, ...]

    def line(self) -> str:
        v, u, w = self.velocity
        speeds = [s[1] for s in self.steps]
        return (f"walk t={self.walk.start:.2f}-{self.walk.end:.2f} s, "
                f"{len(self.walk.swings)} steps: root {v:+.3f} m/s forward, {u:+.3f} m/s "
                f"left, {math.degrees(w):+.1f} deg/s → gait t={self.gait_start:.2f}-"
                f"{self.gait_stop:.2f} s, speed {min(speeds):.2f}..{max(speeds):.2f}, turn "
                f"{np.mean([s[2] for s in self.steps]):+.3f} rad/step, side step "
                f"{np.mean([s[3] for s in self.steps]):+.4f} m/step")


def unit_travel(robot: RobotConfig, params: GaitParams, eff: Efficiency
                ) -> tuple[float, float, float]:
    """What one unit of speed [m/s], side step [m/s per m/step] and turn [rad/s per
    rad/step] make the robot travel with ``params`` (0 for a gait that does not step)."""
    cycle = params.cycle_s
    if not math.isfinite(cycle) or cycle <= 0:
        return 0.0, 0.0, 0.0
    n = 2.0 / cycle
    amp = robot.geometry.leg_length / params.rig_leg * (params.Slgt_R + params.Slgt_L) / 2
    return 2.0 * amp * n * eff.forward, n * eff.side, n * eff.turn


def _velocity(m: RigMotion, t0: float, t1: float) -> tuple[float, float, float]:
    """The root's mean velocity from ``t0`` to ``t1`` [s] in its heading frame."""
    p0, p1 = (np.array([np.interp(t, m.t, m.root[:, k]) for k in range(2)]) for t in (t0, t1))
    h0, h1 = (float(np.interp(t, m.t, m.heading)) for t in (t0, t1))
    dt = max(t1 - t0, 1e-9)
    d = (p1 - p0) / dt
    h = (h0 + h1) / 2
    return (math.cos(h) * d[0] + math.sin(h) * d[1], -math.sin(h) * d[0] + math.cos(h) * d[1],
            (h1 - h0) / dt)


def _clamp(name: str, v: float, lo: float, hi: float, t: float, out: list[str]) -> float:
    if lo <= v <= hi:
        return v
    kept = min(max(v, lo), hi)
    out.append(f"t={t:.2f} s: the root asks {name} {v:+.3f}; the gait walks {lo:g}..{hi:g}: "
               f"{kept:+.3f}")
    return kept


def plan_walk(walk: Walk, m: RigMotion, robot: RobotConfig, params: GaitParams,
              eff: Efficiency) -> WalkPlan:
    _, side, turn = unit_travel(robot, params, eff)
    no_slip = unit_travel(robot, params, replace(eff, forward=1.0))[0]
    ramp = params.ramp_cycles * params.cycle_s
    half = ramp / 2 if math.isfinite(ramp) else 0.0
    start = max(0.0, walk.start - half)
    stop = max(start, walk.end - half)
    bounds = [s.start for s in walk.swings] + [walk.end]
    clamped: list[str] = []
    steps = []
    for i in range(len(walk.swings)):
        t0, t1 = bounds[i], bounds[i + 1]
        v, u, w = _velocity(m, t0, t1)
        when = start if i == 0 else t0
        if i and when >= stop:
            break       # the ramp out keeps the last speed: its distance is the ramp in's
        asked = eff.speed_for(v / no_slip, walk_s=walk.end - walk.start, ramp_s=2 * half) \
            if no_slip else 0.0
        speed = _clamp("speed", asked,
                       *SPEED_RANGE, when, clamped)
        yaw = w / turn if turn and robot.has_hip_yaw else 0.0
        yaw = _clamp("turn", yaw, SPECS["turn"].lo, SPECS["turn"].hi, when, clamped)
        lat = _clamp("side_step", u / side if side else 0.0, SPECS["side_step"].lo,
                     SPECS["side_step"].hi, when, clamped)
        steps.append((when, round(speed, 4), round(yaw, 4), round(lat, 5)))
    if not robot.has_hip_yaw and abs(_velocity(m, walk.start, walk.end)[2]) > 1e-3:
        clamped.append(f"{robot.name} has no hip yaw: the root's turn is not walked")
    return WalkPlan(walk, start, stop, _velocity(m, walk.start, walk.end), tuple(steps),
                    tuple(clamped))


def travel(plans: tuple[WalkPlan, ...]) -> Travel:
    """The show's gait timeline for ``plans`` (a change only where a value changes)."""
    changes: list[tuple[float, dict[str, float]]] = []
    last: tuple[float, float, float] | None = None
    for p in plans:
        for when, speed, yaw, lat in p.steps:
            now = (speed, yaw, lat)
            if last is None or max(abs(a - b) for a, b in zip(now, last, strict=True)) \
                    > CHANGE_EPS:
                changes.append((when, {"speed": speed, "turn": yaw, "side_step": lat}))
                last = now
    return Travel(tuple((p.gait_start, p.gait_stop) for p in plans), tuple(changes))
