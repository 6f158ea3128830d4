"""The firmware's position law per family: gain registers → the terms of

    duty = clip(kp * (setpoint - q) - kd * dq + ki * integral(setpoint - q) dt, +-max_duty)

with the register-to-duty scale each family's manual (or a measurement) gives, times the
model's identified ``gain_scale`` (``robot.servo.physics``). Register names are those of
``robot.servo.gains``. A register missing from ``gains`` counts as 0, except the position P
gain, which every law needs.

Scales and where they come from:

- Dynamixel X (e-Manual, "Position PID Gain"): KPP = P / 128, KPI = I / 65536,
  KPD = D / 16 on the error in pulses, PWM 885 = full duty (PWM Limit 36, factory 885).
  The D and I terms are taken per 1 ms control cycle (an assumption: the manual gives no
  unit). Profile Velocity (0.229 rev/min a unit, 0 = none) slews the goal.
- Dynamixel MX, Protocol 1.0 (e-Manual MX-28): KP = P / 8, KI = I * 1000 / 2048,
  KD = D * 4 / 1000; the duty per P unit and radian, 0.158, was measured with an
  oscilloscope on MX-64 / MX-106 by Rhoban/bam (``bam/dynamixel/actuator.py``,
  ``error_gain``); I and D keep the manual's ratios to P (per 1 ms, as for X).
- Feetech STS: duty = 0.166 per P unit and radian, measured with an oscilloscope on an
  STS3215 by Rhoban/bam (``bam/feetech/actuator.py``, ``error_gain``); D and I on the same
  scale per 1 ms (an assumption; Feetech documents neither).
- Dynamixel XL-320 (e-Manual XL-320: the MX PID registers at 27/28/29): duty = 0.0505 per
  P unit and radian, measured with an oscilloscope on XL-320s by Rhoban/bam
  (``bam/dynamixel/actuator.py``, ``XL320Actuator.error_gain``); I and D as for the MX.
- Feetech SCS (SCSCL): the STS's coefficients (21/22/23); no measured scale: the STS3215's
  is assumed.
- Dynamixel AX (e-Manual AX-12A, "Compliance"): no torque within the compliance margin,
  then the output rises to full over the compliance slope [pulses]; cw and ccw averaged.
- HiWonder/LewanSoul LX: no gain registers and no published position law; assumed is what
  the simulation ran for every servo before it had a model: full duty at 0.05 rad of
  error (times the model's ``gain_scale``) and a D term of 0.03 s (kd / kp, times
  ``kd_scale``), which critically damped the old simulated LX-16A.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import NamedTuple

from robot.servo.models import ServoModel
from robot.servo.physics import ServoPhysics

X_PWM_FULL = 885.0          # e-Manual: PWM Limit factory value = 100 % duty
X_KPP_DIVISOR = 128.0       # e-Manual: KPP = P / 128
X_KPI_DIVISOR = 65536.0     # e-Manual: KPI = I / 65536
X_KPD_DIVISOR = 16.0        # e-Manual: KPD = D / 16
X_PROFILE_RPM = 0.229       # e-Manual: Profile Velocity unit [rev/min]
MX_DUTY_PER_P = 0.158       # Rhoban/bam oscilloscope, MX-64/106 [duty / (P unit rad)]
STS_DUTY_PER_P = 0.166      # Rhoban/bam oscilloscope, STS3215 [duty / (P unit rad)]
XL320_DUTY_PER_P = 0.05048199   # Rhoban/bam oscilloscope, XL-320 [duty / (P unit rad)]
CYCLE_S = 0.001             # assumed firmware cycle of the D and I terms [s]
LX_FULL_DUTY_RAD = 0.05     # assumed error at full duty of the LX firmware [rad]
LX_D_S = 0.03               # assumed kd / kp of the LX firmware [s]


class LawTerms(NamedTuple):
    """kp [duty/rad], kd [duty s/rad], ki [duty/(rad s)], margin: dead band around the
    goal [rad], max_velocity: the firmware's goal slew [rad/s] (inf: none)."""

    kp: float
    kd: float
    ki: float
    margin: float
    max_velocity: float


def _p(gains: Mapping[str, int], name: str, model: ServoModel) -> float:
    if name not in gains:
        raise KeyError(f"{model.name}: the position law needs the {name} register; "
                       f"got {', '.join(sorted(gains)) or 'none'}")
    return float(gains[name])


def _x(model: ServoModel, physics: ServoPhysics, gains: Mapping[str, int]) -> LawTerms:
    per_tick = model.ticks_per_rad / X_PWM_FULL * physics.gain_scale
    kp = _p(gains, "position_p_gain", model) / X_KPP_DIVISOR * per_tick
    kd = gains.get("position_d_gain", 0) / X_KPD_DIVISOR * per_tick * CYCLE_S * physics.kd_scale
    ki = gains.get("position_i_gain", 0) / X_KPI_DIVISOR * per_tick / CYCLE_S
    profile = gains.get("profile_velocity", 0) * X_PROFILE_RPM * 2 * math.pi / 60
    return LawTerms(kp, kd, ki, 0.0, profile if profile > 0 else physics.max_velocity)


def _mx(model: ServoModel, physics: ServoPhysics, gains: Mapping[str, int]) -> LawTerms:
    return _byte_pid(MX_DUTY_PER_P, model, physics, gains)


def _xl320(model: ServoModel, physics: ServoPhysics, gains: Mapping[str, int]) -> LawTerms:
    return _byte_pid(XL320_DUTY_PER_P, model, physics, gains)


def _byte_pid(duty_per_p: float, model: ServoModel, physics: ServoPhysics,
              gains: Mapping[str, int]) -> LawTerms:
    """The MX (Protocol 1.0) and XL-320 PID: one-byte D/I/P Gain registers, KP = P / 8,
    KI = I * 1000 / 2048, KD = D * 4 / 1000, ``duty_per_p`` duty per P unit and radian."""
    p = _p(gains, "p_gain", model)
    per_kp = duty_per_p * physics.gain_scale * 8.0   # duty per (KP unit rad)
    kd = gains.get("d_gain", 0) * 4 / 1000 * per_kp * CYCLE_S * physics.kd_scale
    ki = gains.get("i_gain", 0) * 1000 / 2048 * per_kp / CYCLE_S
    return LawTerms(p / 8 * per_kp, kd, ki, 0.0, physics.max_velocity)


def _sts(model: ServoModel, physics: ServoPhysics, gains: Mapping[str, int]) -> LawTerms:
    per = STS_DUTY_PER_P * physics.gain_scale
    kp = _p(gains, "p_coefficient", model) * per
    kd = gains.get("d_coefficient", 0) * per * CYCLE_S * physics.kd_scale
    ki = gains.get("i_coefficient", 0) * per / CYCLE_S
    return LawTerms(kp, kd, ki, 0.0, physics.max_velocity)


def _ax(model: ServoModel, physics: ServoPhysics, gains: Mapping[str, int]) -> LawTerms:
    slope = (gains.get("cw_compliance_slope", 32) + gains.get("ccw_compliance_slope", 32)) / 2
    margin = (gains.get("cw_compliance_margin", 1) + gains.get("ccw_compliance_margin", 1)) / 2
    tpr = model.ticks_per_rad
    kp = tpr / max(slope, 1.0) * physics.gain_scale
    return LawTerms(kp, 0.0, 0.0, margin / tpr, physics.max_velocity)


def _lx(model: ServoModel, physics: ServoPhysics, gains: Mapping[str, int]) -> LawTerms:
    kp = physics.gain_scale / LX_FULL_DUTY_RAD
    return LawTerms(kp, kp * LX_D_S * physics.kd_scale, 0.0, 0.0, physics.max_velocity)


LAWS: dict[str, Callable[[ServoModel, ServoPhysics, Mapping[str, int]], LawTerms]] = {
    "dynamixel_x": _x, "dynamixel_mx1": _mx, "feetech_sts": _sts, "dynamixel_ax": _ax,
    "lx": _lx, "dynamixel_xl320": _xl320,
    # Feetech SCS: the STS coefficients at the same addresses; no oscilloscope figure for
    # an SCS: the STS3215's scale is assumed (its source says so).
    "feetech_scs": _sts,
}


def law_terms(model: ServoModel, physics: ServoPhysics, gains: Mapping[str, int]) -> LawTerms:
    """The law's terms for ``model`` with ``physics`` at the gain registers ``gains``."""
    return LAWS[physics.law](model, physics, gains)


def stiffness(model: ServoModel, physics: ServoPhysics, gains: Mapping[str, int],
              voltage: float) -> float:
    """Output stiffness at small error [N m/rad]: kp * kt * V / R."""
    return law_terms(model, physics, gains).kp * physics.kt * voltage / physics.resistance

#: The register a pendulum log's ``kp`` names, per law (the AX series: its compliance slope).
LOG_GAIN_REGISTERS: dict[str, tuple[str, ...]] = {
    "dynamixel_x": ("position_p_gain",), "dynamixel_mx1": ("p_gain",),
    "feetech_sts": ("p_coefficient",),
    "dynamixel_ax": ("cw_compliance_slope", "ccw_compliance_slope"), "lx": (),
    "dynamixel_xl320": ("p_gain",), "feetech_scs": ("p_coefficient",),
}


def log_gains(model: ServoModel, physics: ServoPhysics, kp: int) -> dict[str, int]:
    """The gain registers during a pendulum log: the model's factory values with the
    register the log's ``kp`` names set to it."""
    return {**model.factory_gains, **dict.fromkeys(LOG_GAIN_REGISTERS[physics.law], kp)}
