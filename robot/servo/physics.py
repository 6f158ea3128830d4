"""A servo's physics as data: the firmware's position law, a DC motor at the supply
voltage, gearbox friction and the rotor's reflected inertia.

The law (``robot.servo.firmware`` turns gain registers into these terms)::

    duty   = clip(kp * (goal - q) - kd * dq [+ the I term], -max_duty, max_duty)
    torque = kt * (V * duty - kt * dq) / R            (ke = kt in SI units)
           - sign(dq) * (coulomb + stribeck * exp(-(|dq| / stribeck_speed)^2)
                         + load_friction * |motor torque|)
           - viscous * dq

The load term is the gearbox's: the harder the motor pushes through it, the more it
rubs, so a servo holding a heavy arm sticks where it stands (the plateaus of the XL330
recordings) and lifts less than its stall torque.

so the stall torque ``kt V max_duty / R`` and the no-load speed follow from the supply
voltage. With the torque off the H-bridge is open: no motor torque, no back-EMF current,
only the gearbox friction. ``max_velocity`` is the firmware's own limit on how fast it moves
its internal goal (the STS series with Goal Speed 0), inf where the firmware steps to the
goal at once.

Every number carries its source in ``sources`` (field name → where it came from): the
fitted ones name the recordings, the datasheet ones the datasheet and what was derived.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace

#: Fields a fit may change (the motor, the gearbox, the firmware's scale), in file order.
FITTED = ("gain_scale", "kt", "resistance", "armature", "coulomb", "viscous", "stribeck",
          "stribeck_speed", "load_friction", "max_velocity", "kd_scale")


@dataclass(frozen=True)
class ServoPhysics:
    """One servo model's physics (see the module docstring for the law).

    law: the firmware's position law, a key of ``robot.servo.firmware.LAWS``;
    gain_scale: identified correction of the family's documented register scale (1 = the
    manual's scale); kd_scale: the same for the D term; max_duty: PWM limit (0..1);
    kt: torque constant [N m/A] (= back-EMF constant [V s/rad]); resistance: winding [ohm];
    armature: reflected rotor inertia [kg m^2]; coulomb: gearbox Coulomb friction [N m];
    viscous: gearbox viscous friction [N m s/rad]; stribeck: extra static friction at rest
    [N m], fading over stribeck_speed [rad/s]; load_friction: gearbox friction per N m of
    motor torque [-]; max_velocity: firmware goal slew [rad/s];
    nominal_voltage: the supply the datasheet and factory settings assume [V].
    """

    name: str
    law: str
    kt: float
    resistance: float
    armature: float
    coulomb: float
    viscous: float
    nominal_voltage: float
    max_duty: float = 1.0
    gain_scale: float = 1.0
    kd_scale: float = 1.0
    stribeck: float = 0.0
    stribeck_speed: float = 0.1
    load_friction: float = 0.0
    max_velocity: float = math.inf
    sources: Mapping[str, str] = field(default_factory=dict, compare=False)

    def stall_torque(self, voltage: float) -> float:
        """Torque at full duty and zero speed [N m] at ``voltage`` [V]."""
        return self.kt * voltage * self.max_duty / self.resistance

    @property
    def back_emf_damping(self) -> float:
        """kt^2 / R: the torque per speed the shorted winding brakes with [N m s/rad]."""
        return self.kt * self.kt / self.resistance

    def no_load_speed(self, voltage: float) -> float:
        """Speed at full duty with no load [rad/s] at ``voltage`` [V] (the gearbox's
        Coulomb and viscous friction included)."""
        drive = self.stall_torque(voltage) - self.coulomb
        return max(drive, 0.0) / (self.back_emf_damping + self.viscous)

    def with_values(self, values: Mapping[str, float], *, source: str) -> ServoPhysics:
        """A copy with ``values`` (names in FITTED) replaced, each sourced as ``source``."""
        unknown = sorted(set(values) - set(FITTED))
        if unknown:
            raise ValueError(f"not a fitted servo parameter: {unknown[0]}; valid: "
                             f"{', '.join(FITTED)}")
        sources = {**self.sources, **{k: source for k in values}}
        # mypy checks **values against every field's type, the str ones too
        return replace(self, **dict(values), sources=sources)  # type: ignore[arg-type]

    def unsourced(self) -> list[str]:
        """Numeric fields without a source (the table's test wants none)."""
        return [f.name for f in fields(self)
                if f.name not in ("name", "law", "sources") and f.name not in self.sources]


def from_datasheet(name: str, law: str, *, stall_torque: float, no_load_speed: float,
                   voltage: float, max_duty: float = 1.0, friction_share: float,
                   viscous_share: float, tau_s: float, note: str) -> ServoPhysics:
    """A model from a datasheet's stall torque [N m] and no-load speed [rad/s] at
    ``voltage`` [V]. Coulomb friction is ``friction_share`` of the stall torque and viscous
    friction ``viscous_share`` of b = kt^2/R (shares carried over from an identified servo,
    named in ``note``); the no-load speed is where the drive meets them,
    stall (1 - friction_share) = b (1 + viscous_share) speed, which gives b; stall =
    kt V d / R and b = kt^2 / R then give kt and R. The armature is b times a mechanical
    time constant ``tau_s`` [s]."""
    b = stall_torque * (1 - friction_share) / ((1 + viscous_share) * no_load_speed)
    kt = b * voltage * max_duty / stall_torque
    sheet = f"datasheet: {stall_torque:.3g} N m stall, {no_load_speed:.3g} rad/s at {voltage:g} V"
    return ServoPhysics(
        name=name, law=law, kt=kt, resistance=kt * kt / b, armature=b * tau_s,
        coulomb=friction_share * stall_torque, viscous=viscous_share * b,
        nominal_voltage=voltage, max_duty=max_duty,
        sources={"kt": f"{sheet} (kt = b V d / stall, b from the no-load speed)",
                 "resistance": f"{sheet} (R = kt^2 / b)",
                 "armature": f"estimate: b x {tau_s * 1000:g} ms mechanical time constant",
                 "coulomb": f"{friction_share:.3g} x stall torque, {note}",
                 "viscous": f"{viscous_share:.3g} x kt^2/R, {note}",
                 "nominal_voltage": "datasheet", "max_duty": "datasheet PWM limit",
                 "gain_scale": "1: the family's scale as robot/servo/firmware.py states it "
                               "(no recordings)",
                 "kd_scale": "1: the family's scale as robot/servo/firmware.py states it "
                             "(no recordings)",
                 "stribeck": "none (no recordings)", "stribeck_speed": "unused",
                 "load_friction": "none (no recordings)",
                 "max_velocity": "none: the firmware steps to the goal"})
