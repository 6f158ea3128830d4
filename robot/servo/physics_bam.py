"""Servo models identified by Rhoban/bam on their own pendulum recordings (their "m1" model:
a DC motor through a Coulomb-viscous gearbox), carried over as facts: the XL-320, MX-64,
MX-106 and the 12 V STS3215 (``bam/params/<actuator>/m1.json``; the supply, the duty
limit and the register scale from ``bam/dynamixel/actuator.py`` / ``bam/feetech/
actuator.py``). robot/servo/physics_table.py lists them with the rest.

The MX-64 and MX-106 were recorded on Protocol 1.0 firmware (P Gain 32, 0.158 duty per P
unit and radian). The same motors on 2.0 firmware run the X law (KPP = P / 128 of PWM 885):
its factory P 850 gives 4.89 duty/rad where the 1.0 firmware's P 32 gives 5.06 (3 % apart),
so the 2.0 entries keep the identified motor with the manual's X scale.
"""

from __future__ import annotations

import math
from dataclasses import replace

from robot.servo.physics import ServoPhysics

_BAM = "Rhoban/bam {0} (identified m1 model)"


def _bam_m1(name: str, law: str, path: str, *, kt: float, r: float, armature: float,
            coulomb: float, viscous: float, vin: float, max_duty: float, duty_source: str,
            gain_scale: float = 1.0, gain_source: str = "the law's scale as measured",
            max_velocity: float = math.inf,
            max_velocity_source: str = "none: the firmware steps to the goal") -> ServoPhysics:
    src = _BAM.format(path)
    return ServoPhysics(
        name=name, law=law, kt=kt, resistance=r, armature=armature, coulomb=coulomb,
        viscous=viscous, nominal_voltage=vin, max_duty=max_duty, gain_scale=gain_scale,
        max_velocity=max_velocity,
        sources={"kt": src, "resistance": src, "armature": src, "coulomb": src,
                 "viscous": src, "nominal_voltage": f"{src}: the recordings' supply",
                 "max_duty": duty_source, "gain_scale": gain_source,
                 "kd_scale": "the law's ratio to P (no D in the recordings)",
                 "stribeck": "none (bam m1)", "stribeck_speed": "unused",
                 "load_friction": "none (bam m1)", "max_velocity": max_velocity_source})


_DXL = "Rhoban/bam bam/dynamixel/actuator.py"
#: XL-320: bam's XL320Actuator (vin 7.5 V, kp 32, error_gain 0.0505 = the law's scale,
#: max_pwm 1.0; robot/servo/firmware.py XL320_DUTY_PER_P).
XL320 = _bam_m1("XL-320", "dynamixel_xl320", "bam/params/xl320/m1.json", kt=0.9869471336819953,
                r=35.609097347319235, armature=0.0011189506223419352,
                coulomb=0.027514504332133573, viscous=0.003317607576942647, vin=7.5,
                max_duty=1.0, duty_source=f"{_DXL} XL320Actuator max_pwm (oscilloscope)")
#: MX-64 / MX-106: bam's MXActuator (vin 15 V, kp 32, error_gain 0.158, max_pwm 0.9625).
MX64 = _bam_m1("MX-64", "dynamixel_mx1", "bam/params/mx64/m1.json", kt=1.6224667906987444,
               r=3.949433673232461, armature=0.011951238325312509,
               coulomb=0.09038677246291783, viscous=0.011691602145974832, vin=15.0,
               max_duty=0.9625, duty_source=f"{_DXL} MXActuator max_pwm (oscilloscope)")
MX106 = _bam_m1("MX-106", "dynamixel_mx1", "bam/params/mx106/m1.json", kt=2.1913757006745245,
                r=2.9649903987776804, armature=0.026609234235148084,
                coulomb=0.10352026623606064, viscous=0.03520238029013507, vin=15.0,
                max_duty=0.9625, duty_source=f"{_DXL} MXActuator max_pwm (oscilloscope)")
_ON_2 = ("1: the e-Manual's X scale on the 2.0 firmware (the motor identified on 1.0 "
         "firmware; see robot/servo/physics_bam.py)")
MX64_2 = replace(MX64, name="MX-64(2.0)", law="dynamixel_x",
                 sources={**MX64.sources, "gain_scale": _ON_2})
MX106_2 = replace(MX106, name="MX-106(2.0)", law="dynamixel_x",
                  sources={**MX106.sources, "gain_scale": _ON_2})
#: STS3215 at 12 V: params/feetech_sts3215_12V/m1.json (its error_gain_ratio is the scale on
#: 0.166 duty per P unit and radian; max_velocity the firmware's goal slew); max_pwm 0.97 of
#: bam's STS3215Actuator.
STS3215_12V = _bam_m1(
    "STS3215-12V", "feetech_sts", "params/feetech_sts3215_12V/m1.json", kt=1.443985897804671,
    r=2.0295624974250366, armature=0.03245999409626578, coulomb=0.1958711784097532,
    viscous=0.03047350651248057, vin=12.0, max_duty=0.97,
    duty_source="Rhoban/bam bam/feetech/actuator.py STS3215Actuator max_pwm (oscilloscope)",
    gain_scale=0.9754522802666795,
    gain_source="Rhoban/bam params/feetech_sts3215_12V/m1.json error_gain_ratio (identified)",
    max_velocity=14.597462818084868,
    max_velocity_source="Rhoban/bam params/feetech_sts3215_12V/m1.json max_velocity")
