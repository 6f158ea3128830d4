"""Stick figure of the robot from joint angles, as 2-D polylines for the panel's canvases.

Forward kinematics (robot.gait.ik; an imported robot's model: robot/panel/figure_body.py)
in the pelvis frame (REP-103: x forward, y left, z up) [m].
The side view looks at the robot's right side (screen x = x forward, screen y = z up);
the front view faces the robot (screen x = y, the robot's left on the viewer's right).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from robot.config.joint_names import ARM_JOINTS, LEG_JOINTS
from robot.config.robot import Geometry, RobotConfig
from robot.gait.ik import arm_fk_local, hip_centre, leg_fk_full, shoulder_centre
from robot.gait.xmath import Vec
from robot.panel.figure_body import body_figure

Point = tuple[float, float, float]


def _vec(v: Vec) -> Point:
    return (float(v[0]), float(v[1]), float(v[2]))


def _leg_points(g: Geometry, side: str, q: tuple[float, ...]) -> list[Point]:
    """Hip, knee, ankle, sole, toe, heel [m] of one leg."""
    knee, _ = leg_fk_full(dataclasses.replace(g, shin=0.0, ankle_height=0.0), side, q)
    ankle, _ = leg_fk_full(dataclasses.replace(g, ankle_height=0.0), side, q)
    sole, rot = leg_fk_full(g, side, q)
    s = _vec(sole)
    ends = []
    for dx in (g.foot_forward + g.foot_length / 2, g.foot_forward - g.foot_length / 2):
        ends.append((s[0] + float(rot[0]) * dx, s[1] + float(rot[3]) * dx,
                     s[2] + float(rot[6]) * dx))
    return [_vec(hip_centre(g, side)), _vec(knee), _vec(ankle), s, ends[0], ends[1], s]


def _arm_points(g: Geometry, side: str, q: tuple[float, float, float]) -> list[Point]:
    """Shoulder, elbow, hand [m] of one arm."""
    sx, sy, sz = shoulder_centre(g, side)
    elbow = arm_fk_local(dataclasses.replace(g, forearm=0.0), q)
    hand = arm_fk_local(g, q)
    return [(sx, sy, sz)] + [(sx + float(p[0]), sy + float(p[1]), sz + float(p[2]))
                             for p in (elbow, hand)]


def stick_figure(robot: RobotConfig, q: Sequence[float]) -> dict[str, list[Point]]:
    """Named 3-D polylines [m] for joint angles ``q`` [rad] in ``robot.joints`` order (an
    imported robot's from its model: robot/panel/figure_body.py)."""
    if robot.body is not None:
        return body_figure(robot, q)
    g = robot.geometry
    angles = dict(zip(robot.joint_names, (float(v) for v in q), strict=True))
    lines: dict[str, list[Point]] = {}
    for side in ("r", "l"):
        lines[f"{side}_leg"] = _leg_points(
            g, side, tuple(angles.get(f"{side}_{j}", 0.0) for j in LEG_JOINTS))  # 5-DoF: yaw 0
    hips = [_vec(hip_centre(g, "r")), _vec(hip_centre(g, "l"))]
    neck = (0.0, 0.0, g.torso_height)
    lines["torso"] = [hips[0], hips[1], (0.0, 0.0, 0.0), neck]
    if robot.has_arms:
        lines["torso"] += [_vec(shoulder_centre(g, "r")), neck, _vec(shoulder_centre(g, "l"))]
        for side in ("r", "l"):
            a = tuple(angles[f"{side}_{j}"] for j in ARM_JOINTS)
            lines[f"{side}_arm"] = _arm_points(g, side, (a[0], a[1], a[2]))
    lines["head"] = [neck, (0.0, 0.0, g.torso_height + 0.25 * g.thigh)]
    return lines


def views(robot: RobotConfig, q: Sequence[float]) -> dict[str, Any]:
    """Side and front views as ``{"side": {name: [[x, z], ...]}, "front": {...}}`` [m],
    shifted so the lowest foot point is at z = 0 (the ground line)."""
    lines = stick_figure(robot, q)
    ground = min(p[2] for name in ("r_leg", "l_leg") for p in lines[name])
    r3 = 4  # decimals: 0.1 mm is plenty for a canvas
    side = {n: [[round(p[0], r3), round(p[2] - ground, r3)] for p in pts]
            for n, pts in lines.items()}
    front = {n: [[round(p[1], r3), round(p[2] - ground, r3)] for p in pts]
             for n, pts in lines.items()}
    return {"side": side, "front": front}
