"""Calibration arithmetic (``biped calibrate``): zero ticks, sign and limits from present
positions read while a human holds or moves the robot. Pure: ticks in, config values out.

Conventions (robot.bus.servo_map): ticks = zero_ticks + sign * q * resolution / (2 pi).
Positive q follows REP-103 (x forward, y left, z up; right-hand rule about the joint axis).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from robot.config.robot import ANGLE, RobotConfig

#: A hand move counts when the joint turned at least this far [rad] (about 6 degrees).
MOVE_THRESHOLD_RAD = 0.1
#: Prompt for the negative direction when the positive side has less room than this [rad]
#: (an elbow stops 0.1 rad past straight).
MIN_ROOM_RAD = 0.3
#: Recorded limits are pulled in by this much [rad], so a gait does not drive into the stop.
LIMIT_MARGIN_RAD = 0.02
#: Decimal places of the written limits (rounded inward).
LIMIT_DIGITS = 3

# What a positive / negative turn looks like, per joint type (REP-103, right-hand rule).
_WORDS: dict[str, tuple[str, str]] = {
    "hip_yaw": ("the toes turn to the robot's left", "the toes turn to the robot's right"),
    "hip_roll": ("the foot swings toward the robot's left", "the foot swings toward the "
                 "robot's right"),
    "hip_pitch": ("the leg swings backward", "the leg swings forward (knee up)"),
    "knee": ("the knee bends (the foot goes back and up)", "the knee straightens"),
    "ankle_pitch": ("the toes point down", "the toes lift up"),
    "ankle_roll": ("the sole's left edge goes up", "the sole's right edge goes up"),
    "shoulder_pitch": ("the arm swings backward", "the arm swings forward and up"),
    "shoulder_roll": ("the arm moves toward the robot's left", "the arm moves toward the "
                      "robot's right"),
    "elbow": ("the forearm swings backward", "the elbow bends (the forearm swings forward "
              "and up)"),
}


def joint_type(name: str) -> str:
    """``l_hip_roll`` → ``hip_roll``."""
    return name.split("_", 1)[1]


def probe_direction(robot: RobotConfig, name: str) -> int:
    """+1 to ask for a positive move, -1 when the positive side has too little room."""
    j = robot.joint(name)
    return 1 if j.max_rad >= MIN_ROOM_RAD or j.max_rad >= -j.min_rad else -1


def direction_words(name: str, direction: int) -> str:
    """What the move of ``name`` in ``direction`` (+1/-1) looks like, in words."""
    positive, negative = _WORDS[joint_type(name)]
    side = "left" if name.startswith("l_") else "right"
    text = positive if direction > 0 else negative
    if joint_type(name) in ("hip_roll", "shoulder_roll", "hip_yaw", "ankle_roll"):
        outward = (direction > 0) == (side == "left")
        if joint_type(name) != "ankle_roll":
            text += " (outward)" if outward else " (inward)"
    return text


def wrapped_delta(before: int, after: int, resolution: int) -> int:
    """Shortest signed tick change from ``before`` to ``after`` on a ``resolution`` circle."""
    half = resolution // 2
    return (after - before + half) % resolution - half


@dataclass(frozen=True)
class SignReading:
    """sign: +1/-1, or None when the joint did not move past the threshold; delta [ticks]."""

    sign: int | None
    delta: int


def detect_sign(before: int, after: int, *, direction: int, resolution: int,
                threshold_rad: float = MOVE_THRESHOLD_RAD,
                ticks_per_rad: float | None = None) -> SignReading:
    """The sign that makes a move of the joint in ``direction`` (+1/-1) a tick change of
    ``after - before``. ``ticks_per_rad``: default resolution / (2 pi) (a full-turn servo;
    pass ``ServoModel.ticks_per_rad`` for the AX's 1024 ticks over 300 deg)."""
    delta = wrapped_delta(before, after, resolution)
    if abs(delta) < threshold_rad * (ticks_per_rad or resolution / (2 * math.pi)):
        return SignReading(None, delta)
    return SignReading(1 if (delta > 0) == (direction > 0) else -1, delta)


def zero_ticks(positions: Mapping[int, int], robot: RobotConfig) -> dict[str, int]:
    """``{joint: zero_ticks}`` from present positions ``{servo id: ticks}`` in the zero pose."""
    res = robot.bus.servo.resolution
    return {j.name: int(positions[j.servo_id]) % res for j in robot.joints}


def hardware_range(zero: int, sign: int, resolution: int,
                   servo_limits: tuple[int, int] | None = None,
                   ticks_per_rad: float | None = None) -> tuple[float, float]:
    """The joint range [rad] the servo can reach: its tick range (its own position limit
    registers if given, else 0..resolution-1) seen from ``zero``/``sign``, inside [-pi, pi]."""
    lo_t, hi_t = servo_limits if servo_limits is not None else (0, resolution - 1)
    per_rad = ticks_per_rad or resolution / (2 * math.pi)
    ends = sorted(((lo_t - zero) * sign / per_rad, (hi_t - zero) * sign / per_rad))
    return max(ends[0], ANGLE.lo), min(ends[1], ANGLE.hi)


def limits_from_ends(a: int, b: int, *, zero: int, sign: int, resolution: int,
                     servo_limits: tuple[int, int] | None = None,
                     ticks_per_rad: float | None = None) -> tuple[float, float]:
    """(min_rad, max_rad) from the ticks read at the two ends of a joint's free range:
    pulled in by LIMIT_MARGIN_RAD, kept inside ``hardware_range``, rounded inward."""
    per_rad = ticks_per_rad or resolution / (2 * math.pi)
    qa = wrapped_delta(zero, a, resolution) * sign / per_rad
    qb = wrapped_delta(zero, b, resolution) * sign / per_rad
    lo, hi = sorted((qa, qb))
    hw_lo, hw_hi = hardware_range(zero, sign, resolution, servo_limits, per_rad)
    lo, hi = max(lo + LIMIT_MARGIN_RAD, hw_lo), min(hi - LIMIT_MARGIN_RAD, hw_hi)
    k = 10 ** LIMIT_DIGITS
    return math.ceil(lo * k) / k, math.floor(hi * k) / k


def fit_limits(min_rad: float, max_rad: float, *, zero: int, sign: int, resolution: int,
               servo_limits: tuple[int, int] | None = None,
               ticks_per_rad: float | None = None) -> tuple[float, float] | None:
    """[min_rad, max_rad] cut to ``hardware_range`` (what the servo reaches from ``zero`` and
    ``sign``), the cut ends rounded inward to LIMIT_DIGITS; the limits themselves when they
    fit. None when the servo reaches none of it (or under a thousandth of a radian)."""
    hw_lo, hw_hi = hardware_range(zero, sign, resolution, servo_limits, ticks_per_rad)
    k = 10 ** LIMIT_DIGITS
    lo = min_rad if min_rad >= hw_lo else math.ceil(hw_lo * k) / k
    hi = max_rad if max_rad <= hw_hi else math.floor(hw_hi * k) / k
    return (lo, hi) if lo < hi else None
