"""A robot's capture limit at one moment of its walk: the largest push [N*s] in a
direction from which a perfect controller could still stop with 0, 1 or 2 steps
(robot.balance.capturability: Koolen et al. 2012's linear inverted pendulum with a finite
foot), from the body's state at that moment (sim.mujoco.push_state, the simulation's
``pushes_applied[].state``) and the robot's own numbers (robot.balance.capture_robot).

The model, every assumption named:

- the pendulum's height z0 is the centre of mass's over the ground at the moment, held
  constant (LIPM); omega0 = sqrt(g / z0);
- the push's impulse J changes the centre of mass's velocity by J / m at once (its 20 ms
  window and the angular momentum it gives are left out), so the capture point moves by
  J / (m omega0) along the push;
- 0 steps: the capture point must stay inside the support polygon at the moment (the
  hull of the soles on the ground, each corner no further from its ankle than the
  robot's sole region, i.e. the ankle servo's torque for the whole weight); none on the
  ground: 0;
- a limit is the largest J for which every push of J or less along the direction is
  capturable: 0 when the unpushed state is not (with 0 steps that is most of a walk: the
  capture point runs ahead of the standing foot toward the next footstep);
- 1 and 2 steps: the standing foot (in double support either foot may step: the better
  is taken) holds the centre of pressure in its sole (the sole's box in the heading
  frame, no further from the ankle than the robot's sole region: the ankle servo's
  torque); the first step lands where the swinging foot gets within its time t1 from
  where it is now (robot.balance.capture_robot.swing: the hip servo at the robot's gains,
  from rest, slewed at the joint's limit; the ankle-to-ankle distance at touchdown is
  twice the foot's offset from its hip, the legs straddling the pelvis), every later step
  in dt from the trailing position of a step of the same length (sideways: from the
  walk's own width), each within the legs' reach; the support passes to the landed foot
  at once; the last foot then holds the capture point in its sole region. t1 and dt
  (one for all later steps) are chosen to give the largest push, on a 10 ms grid up to
  1 s;
- a limit with more steps is at least the one with fewer (N or fewer steps).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from robot.balance.capturability import (
    Box,
    Interval,
    Step,
    hull,
    omega0,
    polygon_exit,
    ray_exit,
    region,
)
from robot.balance.capture_robot import Reach, reach, sole, swing, zero_width
from robot.config.robot import RobotConfig

#: The step-time grid's spacing [samples of the swing's 5 ms grid]: 10 ms.
GRID_EVERY = 2
#: Starts of the later steps' swings tabulated (fractions of half the longest step).
LATER_STARTS = 6
STEPS = (0, 1, 2)

Floats = npt.NDArray[np.float64]


class Foot(NamedTuple):
    """One foot at the moment [m, heading frame, from the centre of mass's ground
    point]: on the ground or not, its ankle, its hip, its sole's corners (n, 2)."""

    down: bool
    ankle: tuple[float, float]
    hip: tuple[float, float]
    sole: Floats


class PushState(NamedTuple):
    """The body at the moment of a push (sim.mujoco.push_state)."""

    height: float
    velocity: tuple[float, float]
    mass: float
    feet: tuple[Foot, Foot]       # right, left

    @classmethod
    def of(cls, d: Mapping[str, Any]) -> PushState:
        feet = tuple(Foot(bool(f["down"]), (float(f["ankle"][0]), float(f["ankle"][1])),
                          (float(f["hip"][0]), float(f["hip"][1])),
                          np.array(f["sole"], dtype=float)) for f in d["feet"])
        vx, vy = d["com_velocity_m_s"]
        return cls(float(d["com_height_m"]), (float(vx), float(vy)), float(d["mass_kg"]),
                   (feet[0], feet[1]))


@dataclass(frozen=True)
class Numbers:
    """The robot's numbers at one stance: its sole region, reach, the swing trajectories
    of the later steps (times [s]; x: forward and backward step lengths, y: widest and
    narrowest steps, ankle to ankle [m]) and the robot itself."""

    robot: RobotConfig
    stance: float
    sole: Box
    reach: Reach
    times: Floats
    later_fwd: Floats
    later_back: Floats
    later_out: Floats
    later_in: Floats


def _later(robot: RobotConfig, stance: float, half: float, sign: float) -> Floats:
    """The step length [m] a later step reaches within each grid time: a swing from the
    trailing position of a step of the length it reaches (a fixed point over tabulated
    starts) toward ``half`` [m] of the longest step, ``sign`` +1 forward, -1 back."""
    starts = np.linspace(0.0, half, LATER_STARTS)
    table = np.array([swing(robot, stance, "pitch", -sign * s, sign * half).offset
                      for s in starts]) * sign          # (starts, times)
    cols = np.arange(table.shape[1])
    spacing = starts[1] - starts[0] if half > 0.0 else 1.0

    def reached(s: Floats) -> Floats:
        """Per time, the offset reached from the trailing offset -s (linear in s between
        the tabulated starts)."""
        i = np.clip((s / spacing).astype(int), 0, LATER_STARTS - 2)
        w = s / spacing - i
        return (1.0 - w) * table[i, cols] + w * table[i + 1, cols]
    # x = reached(x): the further the foot landed, the further back it starts; reached(s)
    # falls as s grows, so reached(s) - s has one root in [0, half] (bisection).
    lo, hi = np.zeros(len(cols)), np.full(len(cols), half)
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        ahead = reached(mid) > mid
        lo, hi = np.where(ahead, mid, lo), np.where(ahead, hi, mid)
    return 2.0 * lo


def numbers(robot: RobotConfig, stance: float, spread: float = 0.0) -> Numbers:
    """The numbers for ``robot`` walking at ``stance`` with feet ``spread`` [m] outward."""
    r = reach(robot, stance, spread=spread)
    hw = zero_width(robot)
    sw = swing(robot, stance, "roll", spread, 0.5 * (r.out - hw))
    sw_in = swing(robot, stance, "roll", spread, 0.5 * (r.inward - hw))
    return Numbers(robot, stance, sole(robot), r, sw.times,
                   _later(robot, stance, 0.5 * r.forward, 1.0),
                   _later(robot, stance, 0.5 * r.back, -1.0),
                   hw + 2.0 * sw.offset, hw + 2.0 * sw_in.offset)


def _capped(n: Numbers, foot: Foot) -> Floats:
    """The foot's sole corners (n, 2) [m], each no further from the ankle than the
    robot's sole region (the ankle servo's torque)."""
    box, ankle = n.sole, np.asarray(foot.ankle)
    lo = ankle + [float(box.x.lo), float(box.y.lo)]
    hi = ankle + [float(box.x.hi), float(box.y.hi)]
    return np.clip(foot.sole, lo, hi)


def _support(n: Numbers, foot: Foot) -> Box:
    """The standing foot's centre-of-pressure region relative to its ankle: its sole's
    box in the heading frame, within the robot's sole region."""
    lo = foot.sole.min(axis=0) - foot.ankle
    hi = foot.sole.max(axis=0) - foot.ankle
    box = n.sole

    def cut(a: float, b: float, iv: Interval) -> Interval:
        lo_, hi_ = max(a, float(iv.lo)), min(b, float(iv.hi))
        return Interval(lo_, hi_) if lo_ < hi_ else iv
    return Box(cut(lo[0], hi[0], box.x), cut(lo[1], hi[1], box.y))


def _first_reach(n: Numbers, step_side: int, foot: Foot) -> tuple[Floats, Floats, Floats, Floats]:
    """Where the stepping foot (``step_side`` 0 right, 1 left) can land relative to the
    standing ankle within each grid time: x lo, x hi, y lo, y hi [m]."""
    r, hw = n.reach, zero_width(n.robot)
    dx = foot.ankle[0] - foot.hip[0]
    out_sign = 1.0 if step_side == 1 else -1.0
    # outward of where the ankle hangs at the zero pose (sim.mujoco.push_state's hip)
    dy = out_sign * (foot.ankle[1] - foot.hip[1])
    fx, bx = 0.5 * r.forward, 0.5 * r.back
    oy, iy = 0.5 * (r.out - hw), 0.5 * (r.inward - hw)
    dx, dy = min(max(dx, -bx), fx), min(max(dy, iy), oy)
    fwd = 2.0 * swing(n.robot, n.stance, "pitch", dx, fx).offset
    back = 2.0 * swing(n.robot, n.stance, "pitch", dx, -bx).offset
    wide = hw + 2.0 * swing(n.robot, n.stance, "roll", dy, oy).offset
    narrow = hw + 2.0 * swing(n.robot, n.stance, "roll", dy, iy).offset
    if step_side == 1:
        return back, fwd, narrow, wide
    return back, fwd, -wide, -narrow


def _grid(a: Floats) -> Floats:
    return a[::GRID_EVERY]


def limits(state: PushState, n: Numbers, direction_deg: float) -> dict[int, float]:
    """The 0-, 1- and 2-step limits [N*s] of a push ``direction_deg`` (0 forward, 90
    left) at ``state`` for the robot's numbers ``n`` (module doc)."""
    w0 = omega0(state.height)
    a = math.radians(direction_deg)
    k = 1.0 / (state.mass * w0)                      # capture point [m] per N*s
    u = (k * math.cos(a), k * math.sin(a))
    xi = (state.velocity[0] / w0, state.velocity[1] / w0)   # the centre of mass at 0
    down = [f for f in state.feet if f.down]
    out = dict.fromkeys(STEPS, 0.0)
    if not down:
        return out
    out[0] = float(polygon_exit(xi, u, hull(np.vstack([_capped(n, f) for f in down]))))
    times = _grid(n.times)
    later = Box(Interval(-_grid(n.later_back)[None, :], _grid(n.later_fwd)[None, :]),
                Interval(_grid(n.later_in)[None, :], _grid(n.later_out)[None, :]))
    for step_side in (0, 1):
        stand = state.feet[1 - step_side]
        if not stand.down:
            continue
        rel = (xi[0] - stand.ankle[0], xi[1] - stand.ankle[1])
        support = _support(n, stand)
        x_lo, x_hi, y_lo, y_hi = (_grid(v) for v in _first_reach(n, step_side,
                                                                  state.feet[step_side]))
        first = Step(support, Box(Interval(x_lo, x_hi), Interval(y_lo, y_hi)), times)
        one = ray_exit(rel, u, region([first], n.sole, w0))
        out[1] = max(out[1], float(np.max(one)))
        # The second step: the first standing foot swings; its lateral reach mirrors.
        mirror = (later.y if step_side == 0
                  else Interval(-later.y.hi, -later.y.lo))
        second = Step(n.sole, Box(later.x, mirror), times[None, :])
        first2 = first._replace(reach=Box(Interval(x_lo[:, None], x_hi[:, None]),
                                          Interval(y_lo[:, None], y_hi[:, None])),
                                t=times[:, None])
        two = ray_exit(rel, u, region([first2, second], n.sole, w0))
        out[2] = max(out[2], float(np.max(two)))
    out[1] = max(out[1], out[0])
    out[2] = max(out[2], out[1])
    return out
