"""Checks of a robot config that need more than one field: the bus settings of a servo
family, and joint limits that must map onto ticks the bus accepts.

The tick check computes with the tick arithmetic that ``ServoMap`` and ``TickLimits`` use
(robot/servo/ticks.py), so "the config loads" and "every goal the map can produce is one the
bus accepts" cannot drift apart.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from robot.config.joint_names import (
    ANKLE_ROLL_NAMES,
    ARM_NAMES,
    EXTRA_NAME,
    HIP_YAW_NAMES,
    JOINT_NAMES,
    LEG_NAMES,
)
from robot.config.toml_io import TomlValue, show
from robot.errors import ConfigError
from robot.servo import ticks as tick_math
from robot.servo.models import BUS_FAMILIES, MODELS, bauds

if TYPE_CHECKING:
    from robot.body.model import BodyModel
    from robot.config.robot import BusConfig, JointConfig, RobotConfig

#: Decimal places of the radian ranges printed in messages (rounded inward, so a value
#: copied from the message fits).
RAD_DIGITS = 4


def standard_bauds(kind: str) -> list[int]:
    """The baud rates [bit/s] the servos of bus ``kind`` ("dynamixel" | "feetech" | ...)
    offer, over every family the kind speaks (one, for a family without a Baud Rate
    register: FIXED_BAUD)."""
    return sorted({b for family in BUS_FAMILIES[kind] for b in bauds(family)})


def check_bus(src: str, bus: BusConfig) -> None:
    """kind, model and baud agree with each other (tables.py)."""
    if bus.kind not in BUS_FAMILIES:
        raise ConfigError(f"{src}: bus.kind: expected one of {', '.join(BUS_FAMILIES)}, "
                          f"got {bus.kind!r}")
    if bus.model not in MODELS:
        raise ConfigError(f"{src}: bus.model: unknown servo model {bus.model!r}; valid: "
                          f"{', '.join(MODELS)}")
    family = MODELS[bus.model].family
    if family not in BUS_FAMILIES[bus.kind]:
        raise ConfigError(f"{src}: bus.model: {bus.model} is not a {bus.kind} servo; valid: "
                          f"{', '.join(_models_of(BUS_FAMILIES[bus.kind]))}")
    rates = bauds(family)
    if bus.baud not in rates:
        raise ConfigError(f"{src}: bus.baud: expected a {bus.model} baud rate (one of "
                          f"{', '.join(map(str, rates))}), got {show(bus.baud)}")


def _models_of(families: tuple[str, ...] | str) -> list[str]:
    fams = (families,) if isinstance(families, str) else families
    return [m for m, s in MODELS.items() if s.family in fams]


def _inward(lo: float, hi: float) -> tuple[float, float]:
    k = 10 ** RAD_DIGITS
    return math.ceil(lo * k) / k, math.floor(hi * k) / k


def check_ticks(robot: RobotConfig) -> None:
    """Every joint's [min_rad, max_rad] maps (after the servo map's rounding,
    robot/servo/ticks.py) onto a non-empty tick range that the bus's limits accept whole;
    else ConfigError naming the joint's field and the radian range that fits its zero_ticks
    and sign."""
    joints = robot.joints
    servos = [robot.servo(j) for j in joints]
    resolution = np.array([m.resolution for m in servos], dtype=float)
    per_rad = np.array([m.ticks_per_rad for m in servos])
    sign = np.array([j.sign for j in joints], dtype=float)
    zero = np.array([j.zero_ticks for j in joints], dtype=float)
    tick_min, tick_max = tick_math.tick_range(zero, sign, per_rad,
                                              np.array([j.min_rad for j in joints]),
                                              np.array([j.max_rad for j in joints]))
    ok_min, ok_max = tick_math.accepted_range(tick_min, tick_max, resolution)
    q_at_0 = tick_math.to_rad(np.zeros(len(joints)), zero, sign, per_rad)
    q_at_top = tick_math.to_rad(resolution - 1.0, zero, sign, per_rad)
    for i, j in enumerate(robot.joints):
        res = int(resolution[i])
        lo, hi = int(tick_min[i]), int(tick_max[i])
        if lo <= hi and (int(ok_min[i]), int(ok_max[i])) == (lo, hi):
            continue
        jp = f"joints.{j.name}"
        if lo > hi:
            raise ConfigError(f"{robot.source}: {jp}.min_rad/max_rad: [{j.min_rad:g}, "
                              f"{j.max_rad:g}] rad holds no whole servo tick; expected limits "
                              f"at least one tick ({1 / per_rad[i]:.5f} rad) apart")
        ends = sorted((float(q_at_0[i]), float(q_at_top[i])))
        fit_lo, fit_hi = _inward(max(ends[0], -math.pi), min(ends[1], math.pi))
        # The low tick end is min_rad's for sign +1, max_rad's for sign -1.
        low_bad, high_bad = lo < 0, hi > res - 1
        if low_bad and high_bad:
            field = "min_rad/max_rad"
        else:
            field = "min_rad" if low_bad == (j.sign > 0) else "max_rad"
        q = j.min_rad if field == "min_rad" else j.max_rad
        tick = lo if low_bad else hi
        raise ConfigError(
            f"{robot.source}: {jp}.{field}: {q:g} rad is tick {tick}, outside the servo's "
            f"0..{res - 1} (zero_ticks {j.zero_ticks}, sign {j.sign:+d}); expected min_rad "
            f"and max_rad within [{fit_lo:.{RAD_DIGITS}f}, {fit_hi:.{RAD_DIGITS}f}] rad, "
            "or another zero_ticks")


def check_joint_set(src: str, jtab: Mapping[str, TomlValue]) -> None:
    """Every leg joint (hip yaw, ankle roll: on both sides or neither, not both left out),
    all arm joints or none; any other name is an extra joint and needs ``fixed_rad``."""
    for name, entry in jtab.items():
        if name in JOINT_NAMES:
            continue
        if not EXTRA_NAME.match(name):
            raise ConfigError(f"{src}: joints.{name}: not a joint name; use lowercase letters, "
                              "digits and '_' (an extra joint, e.g. head_pan)")
        if not isinstance(entry, Mapping) or "fixed_rad" not in entry:
            raise ConfigError(f"{src}: joints.{name}: unknown joint; the gait drives "
                              f"{', '.join(JOINT_NAMES)}; an extra joint (e.g. head_pan) "
                              "needs fixed_rad, the angle it is held at [rad]")
    legs = [n for n in LEG_NAMES if n not in HIP_YAW_NAMES + ANKLE_ROLL_NAMES]
    missing = [n for n in legs if n not in jtab]
    if missing:
        raise ConfigError(f"{src}: joints.{missing[0]}: missing (every leg joint is required; "
                          "only hip yaw or ankle roll may be left out, on both sides)")
    for pair, what in ((HIP_YAW_NAMES, "hip yaw"), (ANKLE_ROLL_NAMES, "ankle roll")):
        if sum(n in jtab for n in pair) == 1:
            absent = next(n for n in pair if n not in jtab)
            raise ConfigError(f"{src}: joints.{absent}: missing ({what} on both legs, or "
                              "neither for 5-DoF legs)")
    if not any(n in jtab for n in HIP_YAW_NAMES + ANKLE_ROLL_NAMES):
        raise ConfigError(f"{src}: joints.r_hip_yaw: missing (a leg needs hip yaw or ankle "
                          "roll: without both, 4 joints cannot place a foot and keep it level)")
    arms = [n for n in ARM_NAMES if n in jtab]
    if arms and len(arms) != len(ARM_NAMES):
        absent = next(n for n in ARM_NAMES if n not in jtab)
        raise ConfigError(f"{src}: joints.{absent}: missing (arms need all of "
                          f"{', '.join(ARM_NAMES)}, or none)")


def check_cases(src: str, joints: list[JointConfig], bus: BusConfig) -> None:
    """Dual-axis servos: every joint on one has a ``case``, each case holds exactly two
    joints, both on a dual-axis model; no other joint names a case."""
    members: dict[str, list[str]] = {}
    for j in joints:
        dual = MODELS[j.model or bus.model].axes == 2
        jp = f"joints.{j.name}.case"
        if dual and j.case is None:
            raise ConfigError(f"{src}: {jp}: missing ({j.model or bus.model} is a dual-axis "
                              "servo: name its case, the same word on the joint of its other "
                              "axis)")
        if j.case is not None and not dual:
            raise ConfigError(f"{src}: {jp}: {j.model or bus.model} has one axis; case is for "
                              "the dual-axis 2XL430-W250 / 2XC430-W250")
        if j.case is not None:
            members.setdefault(j.case, []).append(j.name)
    for case, names in members.items():
        if len(names) != 2:
            raise ConfigError(f"{src}: joints.{names[0]}.case: case {case!r} holds "
                              f"{len(names)} joint(s) ({', '.join(names)}); a dual-axis case "
                              "has two axes: name it on exactly two joints")


def check_joint_extras(src: str, jp: str, j: JointConfig, bus: BusConfig, *,
                       extra: bool) -> None:
    """``model`` is a servo of the bus's family; ``fixed_rad`` only on extra joints and
    inside the joint's limits."""
    if j.model is not None:
        # One control table per bus: a joint's model shares bus.model's family.
        valid = _models_of(MODELS[bus.model].family)
        if j.model not in valid:
            raise ConfigError(f"{src}: {jp}.model: {show(j.model)} is not a {bus.kind} servo "
                              f"model; valid: {', '.join(valid)} (one control table per "
                              f"bus: bus.model {bus.model}'s)")
    if j.fixed_rad is not None and not extra:
        raise ConfigError(f"{src}: {jp}.fixed_rad: the gait drives {j.name}; fixed_rad is for "
                          "extra joints only (e.g. head_pan)")
    if j.fixed_rad is not None and not j.min_rad <= j.fixed_rad <= j.max_rad:
        raise ConfigError(f"{src}: {jp}.fixed_rad: {j.fixed_rad:g} is outside the joint "
                          f"limits [{j.min_rad:g}, {j.max_rad:g}]")


def check_model_joints(src: str, body: BodyModel, joints: list[JointConfig]) -> None:
    """Every joint of an imported robot names one hinge of its model (``model_joint``,
    ``model_sign`` +-1), and every hinge of the model is a joint of the file."""
    hinges = body.tree.joint_link
    seen: dict[str, str] = {}
    for j in joints:
        where = f"{src}: joints.{j.name}"
        if j.model_joint is None:
            raise ConfigError(f"{where}.model_joint: missing (an imported robot names each "
                              "joint's hinge in [model.links])")
        if j.model_joint not in hinges:
            raise ConfigError(f"{where}.model_joint: the model has no joint {j.model_joint!r}; "
                              f"valid: {', '.join(hinges)}")
        if j.model_joint in seen:
            raise ConfigError(f"{where}.model_joint: {j.model_joint!r} is also "
                              f"joints.{seen[j.model_joint]}'s")
        seen[j.model_joint] = j.name
        if j.model_sign not in (1, -1):
            raise ConfigError(f"{where}.model_sign: expected +1 or -1, got {show(j.model_sign)}")
    missing = [h for h in hinges if h not in seen]
    if missing:
        raise ConfigError(f"{src}: model joint {missing[0]!r} is no joint of the file; add a "
                          "[joints.NAME] with model_joint = ... (an extra joint: fixed_rad)")
