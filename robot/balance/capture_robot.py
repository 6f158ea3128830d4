"""A robot's own numbers for its capture limit (robot.balance.capture_limit): where the
centre of pressure can go on a sole, how far a leg steps within its joint limits, and how
fast its servos swing it there.

- **Sole** (``sole``): the centre of pressure's region relative to the ankle point, the
  sole's toe (foot_forward + foot_length / 2 ahead), heel (foot_length / 2 -
  foot_forward behind) and edges (foot_width / 2 each side), each no further than the
  ankle servo can hold the whole robot's weight: stall torque / (m g), the ankle pitch
  servo's toward toe and heel, the ankle roll servo's toward the edges (a leg without
  ankle roll: the hip roll's), the stall from the servo law at the robot's gains and
  voltage (robot.servo.law.Law.stall), m the body tree's mass.
- **Reach** (``reach``): the legs (the IK's chains, robot.config.robot.RobotConfig.legs)
  straddle at the walk's hip height h = stance x (thigh + shin) over the ankles, each
  foot flat, the pelvis midway; a step of length l puts one sole l / 2 ahead of where it
  hangs at the zero pose and the other l / 2 behind, and the largest l forward and
  backward (and the widest step out, at no stride) are where the chain IK
  (robot.gait.ik_chain.chain_leg_ik) still reaches both feet with every joint inside its
  limits (bisection to 0.1 mm).
  Inward the soles keep FOOT_GAP_M between them (the legs do not collide and no foot
  crosses the other: the narrowest step is foot_width + FOOT_GAP_M, ankle to ankle).
- **Swing** (``swing``): the swinging leg is a rigid body (every link its hip joint moves,
  from the robot's body tree: the box model of its ``[geometry]`` and ``[mass]``, or an
  imported ``[model]``) in the walk's stance pose, about the hip pitch axis (steps
  forward and back) and the hip roll axis (steps sideways), its servo the hip
  pitch or roll joint's at the robot's gains and voltage, its goal slewed at the joint's
  ``max_speed_rad_s`` (what the driver and the simulated servo do); robot.servo.move_time
  integrates the motion of the leg's line from hip to ankle, and the foot's offset from
  its hip is h tan of that angle. The knee's and ankle's parts of a step (they keep the
  leg's length and the sole flat, moving with the hip) are taken to keep up.

Units: m, s, rad, kg.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robot.balance.capturability import Box, Interval
from robot.body.legs import fk
from robot.config.body_tree import robot_tree
from robot.config.robot import RobotConfig
from robot.gait.ik import leg_reach
from robot.gait.ik_chain import chain_leg_ik
from robot.servo.firmware import law_terms
from robot.servo.law import Law
from robot.servo.move_time import GRAVITY, Load, trajectory

#: The soles stay this far apart at least [m] (robot.balance.stage keeps the same gap).
FOOT_GAP_M = 0.005
#: The swing's trajectories are sampled on this time grid [s].
SWING_DT_S = 0.005
SWING_HORIZON_S = 1.0


def joint_law(robot: RobotConfig, name: str) -> Law:
    """The servo law of joint ``name`` at the robot's gains and voltage."""
    j = robot.joint(name)
    model, physics = robot.servo(j), robot.servo_physics(j)
    return Law.of(law_terms(model, physics, robot.gains(j)), physics, robot.voltage(j))


def _limits_ok(robot: RobotConfig, side: str, q: tuple[float, ...]) -> bool:
    names = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
    have = set(robot.joint_names)
    for name, v in zip(names, q, strict=True):
        joint = f"{side}_{name}"
        if joint in have:
            j = robot.joint(joint)
            if not j.min_rad - 1e-9 <= v <= j.max_rad + 1e-9:
                return False
    return True


def zero_width(robot: RobotConfig) -> float:
    """How far apart the soles stand at the zero pose, sideways [m] (the box model's:
    hip_width; an imported leg's chain may put them further out)."""
    (_, right, _), _ = fk(robot.legs[0], (0.0,) * 6)
    (_, left, _), _ = fk(robot.legs[1], (0.0,) * 6)
    return float(left - right)


def leg_length(robot: RobotConfig) -> float:
    """Hip pitch axis to ankle with the knee straight [m] (the IK's leg: robot.legs)."""
    leg = robot.legs[0]
    return leg.thigh + leg.shin


@dataclass(frozen=True)
class Leg:
    """One robot's legs (the IK's chains, robot.body.legs) at one hip height: the ankle
    ``h`` [m] below the hip pitch axis."""

    robot: RobotConfig
    h: float

    def solve(self, side: str, dx: float, dy: float) -> tuple[float, ...] | None:
        """The leg's angles with its sole flat, ``dx`` ahead of and ``dy`` outward from
        where it stands at the zero pose (straight below the hip), raised to the height
        ``h``; None if out of reach or of a joint's limits."""
        chain = self.robot.legs[0 if side == "r" else 1]
        (x0, y0, z0), _ = fk(chain, (0.0,) * 6)
        out = dy if side == "l" else -dy
        knee = self.robot.joint(f"{side}_knee")
        raise_by = chain.thigh + chain.shin - self.h
        ik = chain_leg_ik(chain, (float(x0) + dx, float(y0) + out, float(z0) + raise_by),
                          span=leg_reach(self.robot.geometry, knee.min_rad, knee.max_rad)
                          if chain.simple else None)
        q = tuple(float(v) for v in ik.q)
        return q if bool(ik.reachable) and _limits_ok(self.robot, side, q) else None

    def fits(self, dx: float, dy: float) -> bool:
        """Both legs straddle: one sole dx ahead of its hip, the other dx behind, both dy
        outward; every joint of both inside its limits."""
        return all(self.solve(side, sx * dx, dy) is not None
                   for side in ("r", "l") for sx in (1.0, -1.0))


def _largest(ok: object, hi: float, tol: float = 1e-4) -> float:
    """The largest x in [0, hi] with ok(x) (ok(0) assumed), by bisection."""
    assert callable(ok)
    lo = 0.0
    if ok(hi):
        return hi
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo


@dataclass(frozen=True)
class Reach:
    """How far a step lands [m], ankle to ankle: forward, back (step length), out: the
    widest step, inward: the narrowest (both lateral distances between the ankles)."""

    forward: float
    back: float
    out: float
    inward: float


def reach(robot: RobotConfig, stance: float, *, spread: float = 0.0) -> Reach:
    """The steps the legs reach at the walk's ``stance`` (its share of the leg length,
    robot.config.params) with the feet ``spread`` [m] outward of the hips."""
    g = robot.geometry
    length = leg_length(robot)
    leg = Leg(robot, stance * length)
    span = 2.0 * length
    fwd = 2.0 * _largest(lambda x: leg.solve("r", x, spread) is not None
                         and leg.solve("l", -x, spread) is not None, span)
    back = 2.0 * _largest(lambda x: leg.solve("r", -x, spread) is not None
                          and leg.solve("l", x, spread) is not None, span)
    base = zero_width(robot)
    out = base + 2.0 * _largest(lambda y: leg.fits(0.0, y), length)
    narrow = g.foot_width + FOOT_GAP_M
    inward = max(narrow, base - 2.0 * _largest(lambda y: leg.fits(0.0, -y),
                                                 max(0.0, 0.5 * (base - narrow))))
    return Reach(fwd, back, out, inward)


def sole(robot: RobotConfig) -> Box:
    """The centre of pressure's region relative to the ankle point [m] (module doc)."""
    g = robot.geometry
    weight = robot_tree(robot).mass * GRAVITY
    roll_joint = "ankle_roll" if robot.has_ankle_roll else "hip_roll"
    pitch = min(joint_law(robot, f"{s}_ankle_pitch").stall for s in "rl") / weight
    roll = min(joint_law(robot, f"{s}_{roll_joint}").stall for s in "rl") / weight
    toe = min(g.foot_forward + 0.5 * g.foot_length, pitch)
    heel = min(0.5 * g.foot_length - g.foot_forward, pitch)
    edge = min(0.5 * g.foot_width, roll)
    return Box(Interval(-heel, toe), Interval(-edge, edge))


def leg_load(robot: RobotConfig, h: float, axis: str) -> Load:
    """The swinging (right) leg as a rigid body about its hip ``axis`` ("pitch" or "roll")
    in the stance pose at hip height ``h``: every link the hip joint moves (the robot's
    body tree, robot.config.body_tree: the box model or an imported model), its inertia
    about the joint's axis, its mass and its centre of mass's distance from the axis."""
    q = Leg(robot, h).solve("r", 0.0, 0.0)
    if q is None:
        raise ValueError(f"{robot.name}: the leg does not reach its stance at h = {h:.3f} m")
    tree = robot_tree(robot)
    names = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
    pos, rot = tree.poses({f"r_{n}": v for n, v in zip(names, q, strict=True)})
    i = tree.joint_link[f"r_hip_{axis}"]
    hinge = tree.links[i].joint
    assert hinge is not None
    u = rot[i] @ np.asarray(hinge.axis, float)
    anchor = pos[i] + rot[i] @ np.asarray(hinge.pos, float)
    inertia = mass = 0.0
    moment = np.zeros(3)
    for k, link in enumerate(tree.links):
        if link.inertial is None or i not in tree.chain(k):
            continue
        m = link.inertial.mass
        c = pos[k] + rot[k] @ np.asarray(link.inertial.com, float) - anchor
        perp = c - float(c @ u) * u
        body = rot[k] @ link.inertial.matrix() @ rot[k].T
        inertia += m * float(perp @ perp) + float(u @ body @ u)
        mass += m
        moment += m * perp
    arm = float(np.linalg.norm(moment)) / mass if mass > 0 else 0.0
    return Load(inertia, mass, arm)


@dataclass(frozen=True)
class Swing:
    """How far the swinging foot's offset from its hip [m] has got by each of ``times``
    [s] when its hip servo drives it from ``start`` toward ``target`` (offsets forward or
    outward [m])."""

    times: npt.NDArray[np.float64]
    offset: npt.NDArray[np.float64]


def swing(robot: RobotConfig, stance: float, axis: str, start: float, target: float
          ) -> Swing:
    """The right leg's swing about its hip ``axis`` ("pitch": offsets forward, "roll":
    offsets outward) from ``start`` toward ``target`` [m] (module doc). The leg turns as
    one body about the hip: its line from hip to ankle at atan(offset / h), what the hip
    servo turns (the knee keeps the length)."""
    h = stance * leg_length(robot)
    load = leg_load(robot, h, axis)
    joint = robot.joint(f"r_hip_{axis}")
    law = joint_law(robot, f"r_hip_{axis}")
    times = np.arange(0.0, SWING_HORIZON_S + SWING_DT_S / 2, SWING_DT_S)
    q = trajectory(law, load, start=math.atan2(start, h), target=math.atan2(target, h),
                   slew=joint.max_speed_rad_s, times=times)
    # The furthest the foot has got toward the target by each time (where it could be
    # set down), no further than the target: an overshoot is beyond the legs' reach.
    d = h * np.tan(q)
    if target >= start:
        d = np.minimum(np.maximum.accumulate(d), target)
    else:
        d = np.maximum(np.minimum.accumulate(d), target)
    return Swing(times, d)
