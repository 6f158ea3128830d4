"""Every servo model's physics (``robot.servo.physics``), with a source per number.

Three kinds of entry, best first:

1. identified from real recordings by this project (``biped identify fit`` on the public
   pendulum logs of Rhoban/bam, kept beside the repository in ../shared/servo_logs/bam/):
   XL330-M288, STS3250. Their fitted files ship as ``robot/configs/servos/<model>.toml``;
   ``robot.config.servo_file.physics_for`` prefers those files to this table.
2. identified by Rhoban/bam on their own recordings, numbers carried over as facts:
   STS3215 at 7.4 V (``bam/params/feetech_sts3215_7_4V/m1.json``).
3. datasheet stall torque and no-load speed at the nominal voltage (kt and R follow), the
   family's register scale from the manual (an assumption for the LX series, which
   publishes none), and the gearbox friction as shares of an identified servo of the same
   kind (named in each source).
"""

from __future__ import annotations

from typing import NamedTuple

from robot.servo import physics_bam
from robot.servo.models import MODELS
from robot.servo.physics import ServoPhysics, from_datasheet

_BAM_STS3215 = "Rhoban/bam bam/params/feetech_sts3215_7_4V/m1.json (identified, 7.4 V)"
_BAM_STS3215_12V = "Rhoban/bam params/feetech_sts3215_12V/m1.json (identified, 12 V)"
_BAM_MX64 = "Rhoban/bam bam/params/mx64/m1.json (identified MX-64)"
_BAM_XL330 = "Rhoban/bam bam/params/xl330/m1.json at 96001ff (identified, 7.4 V)"



class Shares(NamedTuple):
    """An identified servo's gearbox as shares, carried to same-kind datasheet models:
    Coulomb friction / stall torque, viscous friction / (kt^2/R), armature / (kt^2/R) as a
    time constant [s], the load term [-]; note: where they come from."""

    friction_share: float
    viscous_share: float
    tau_s: float
    note: str



#: XL330-M288, this project's fit (robot/configs/servos/XL330-M288.toml) at 7.4 V: static
#: friction (Coulomb + Stribeck) 0.0120 N m of 0.759 N m stall; viscous 0.0142 of kt^2/R
#: 0.0250; armature 0.00158 / 0.0250. Its load term is not carried (a datasheet model stays
#: Coulomb-viscous).
X_SHARES = Shares(0.016, 0.57, 0.063, "shares of the identified XL330-M288 (robot/configs/servos)")
#: MX-64 (bam): 0.0904 N m of 5.90 N m stall at 15 V; 0.0117 of 0.666; 0.01195 / 0.666.
MX_SHARES = Shares(0.0153, 0.0176, 0.018, "shares of " + _BAM_MX64)
#: STS3215 (bam, 7.4 V): 0.0524 N m of 3.25 N m stall; 0.0591 of 0.549; 0.0284 / 0.549.
STS_SHARES = Shares(0.0161, 0.108, 0.052, "shares of " + _BAM_STS3215)


def _sheet(name: str, shares: Shares, *, max_duty: float = 1.0) -> ServoPhysics:
    m = MODELS[name]
    return from_datasheet(name, m.gain_set, stall_torque=m.stall_torque,
                          no_load_speed=m.no_load_speed, voltage=m.nominal_voltage,
                          max_duty=max_duty, friction_share=shares.friction_share,
                          viscous_share=shares.viscous_share, tau_s=shares.tau_s,
                          note=shares.note)


_STS3215 = ServoPhysics(
    name="STS3215", law="feetech_sts", kt=1.21164135295077, resistance=2.6761663274455603,
    armature=0.02840336348682085, coulomb=0.05239296084748866, viscous=0.05908515565091076,
    nominal_voltage=7.4, max_duty=0.97, max_velocity=14.597462818084868,
    sources={"kt": _BAM_STS3215, "resistance": _BAM_STS3215, "armature": _BAM_STS3215,
             "coulomb": _BAM_STS3215, "viscous": _BAM_STS3215, "nominal_voltage": _BAM_STS3215,
             "max_duty": "Rhoban/bam bam/feetech/actuator.py max_pwm (oscilloscope)",
             "gain_scale": "Rhoban/bam error_gain 0.166 (oscilloscope, STS3215) as measured",
             "kd_scale": "assumed (robot/servo/firmware.py)",
             "max_velocity": _BAM_STS3215_12V + " max_velocity",
             "stribeck": "none (bam M1 model)", "stribeck_speed": "unused",
             "load_friction": "none (bam M1 model)"})

#: Rhoban/bam's XL330 M1 (Coulomb-viscous): the start of this project's fit, which ships as
#: robot/configs/servos/XL330-M288.toml and replaces it (robot.config.servo_file).
_XL330 = ServoPhysics(
    name="XL330-M288", law="dynamixel_x", kt=0.3866957639281311, resistance=4.017129222290597,
    armature=0.0018141672784458866, coulomb=0.01283272036582759, viscous=0.003661672282824312,
    nominal_voltage=7.4, gain_scale=0.5,
    sources={"kt": _BAM_XL330, "resistance": _BAM_XL330, "armature": _BAM_XL330,
             "coulomb": _BAM_XL330, "viscous": _BAM_XL330,
             "nominal_voltage": "the recordings' supply (7.4 V; the datasheet's is 5 V)",
             "max_duty": "e-Manual: PWM Limit 885 = 100 %",
             # Present PWM is P / 256 of the error in pulses: half the manual's P / 128
             "gain_scale": "the XL330 recordings' Present PWM: P / 256 "
                           "(tests/test_servo_model.py checks it on the logs)",
             "kd_scale": "the manual's register scale (no recordings)",
             "stribeck": "none (bam M1)", "stribeck_speed": "unused",
             "load_friction": "none (bam M1)", "max_velocity": "none: Profile Velocity 0"})

def _xl330_scale(physics: ServoPhysics) -> ServoPhysics:
    return physics.with_values(
        {"gain_scale": _XL330.gain_scale},
        source="the XL330-M288 recordings' Present PWM (P / 256), carried to the same firmware")


PHYSICS: dict[str, ServoPhysics] = {
    "XL430-W250": _sheet("XL430-W250", X_SHARES),
    "XM430-W350": _sheet("XM430-W350", X_SHARES),
    "XC430-W150": _sheet("XC430-W150", X_SHARES),
    "XL330-M288": _XL330,
    "AX-12A": _sheet("AX-12A", MX_SHARES),
    "AX-18A": _sheet("AX-18A", MX_SHARES),
    "MX-28": _sheet("MX-28", MX_SHARES),
    "STS3215": _STS3215,
    "STS3250": _sheet("STS3250", STS_SHARES, max_duty=0.97),
    "STS3032": _sheet("STS3032", STS_SHARES, max_duty=0.97),
    # HiWonder/LewanSoul LX: serial-bus hobby servos of the STS3215's class (17-20 kg cm,
    # metal gears): its gearbox shares.
    "LX-16A": _sheet("LX-16A", STS_SHARES),
    "LX-224": _sheet("LX-224", STS_SHARES),
    "LX-224HV": _sheet("LX-224HV", STS_SHARES),
    # --- issue 21's servos -------------------------------------------------------------
    # Identified by Rhoban/bam (robot/servo/physics_bam.py).
    "XL-320": physics_bam.XL320,
    "MX-64": physics_bam.MX64,
    "MX-106": physics_bam.MX106,
    "MX-64(2.0)": physics_bam.MX64_2,
    "MX-106(2.0)": physics_bam.MX106_2,
    "STS3215-12V": physics_bam.STS3215_12V,
    # Datasheet + register scale. The XL330-M077 shares the XL330-M288's firmware and its
    # recordings' scale (Present PWM = P / 256); the XC330s, of the same MCU and table
    # generation, are given it too (an assumption: no XC330 recordings).
    "XL330-M077": _xl330_scale(_sheet("XL330-M077", X_SHARES)),
    "XC330-M181": _xl330_scale(_sheet("XC330-M181", X_SHARES)),
    "XC330-M288": _xl330_scale(_sheet("XC330-M288", X_SHARES)),
    "XC330-T181": _xl330_scale(_sheet("XC330-T181", X_SHARES)),
    "XC330-T288": _xl330_scale(_sheet("XC330-T288", X_SHARES)),
    **{name: _sheet(name, X_SHARES) for name in (
        "XM430-W210", "XH430-W210", "XH430-W350", "XH430-V210", "XH430-V350", "XM540-W150",
        "XM540-W270", "2XL430-W250", "2XC430-W250")},
    "MX-28(2.0)": _sheet("MX-28(2.0)", MX_SHARES),
    "STS3046": _sheet("STS3046", STS_SHARES, max_duty=0.97),
    # Feetech SCS (potentiometer, carbon-brush motors): the STS3215's gearbox shares.
    **{name: _sheet(name, STS_SHARES) for name in ("SCS0009", "SCS15", "SCS40")},
}
