"""What a servo on a test bench carries: a weight on an arm (a pendulum), or nothing.

The pendulum logs' rig (``robot.servo.pendulum_log``): q = 0 is the arm hanging down, a
point weight ``mass`` [kg] at ``length`` [m] from the shaft, optionally a uniform arm of
``arm_mass`` [kg]. With nothing on it a servo turns only its own rotor and horn.

``biped emulate --load`` gives an emulated servo such a load, ``biped sim-gap --load``
tells the simulation the same, and ``biped identify record --mass --length`` names the real
one; the text form is ``MASS@LENGTH`` (kg @ m), e.g. ``0.5@0.1``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from robot.errors import ConfigError

G = 9.81                 # [m/s^2]
#: The horn's own inertia about the shaft [kg m^2] (a small aluminium horn; the rotor's
#: reflected inertia, the model's armature, dominates it many times over).
HORN_INERTIA = 1e-6
MAX_MASS = 10.0          # [kg] what a hobby servo bench could hold, for input checks
MAX_LENGTH = 1.0         # [m]
#: [kg], [m]: a lighter weight or a shorter arm is no pendulum (the horn outweighs it, and
#: MuJoCo refuses a moving body under 1e-15 kg).
MIN_MASS = 1e-3
MIN_LENGTH = 1e-3


@dataclass(frozen=True)
class BenchLoad:
    """mass [kg] at length [m]; arm_mass [kg]: a uniform arm from the shaft to the weight."""

    mass: float = 0.0
    length: float = 0.0
    arm_mass: float = 0.0

    @property
    def inertia(self) -> float:
        """About the shaft, the horn included [kg m^2]."""
        return self.mass * self.length ** 2 + self.arm_mass * self.length ** 2 / 3 + HORN_INERTIA

    @property
    def moment(self) -> float:
        """Gravity's torque on the arm held horizontal [N m]: the torque at q is
        -moment * sin(q)."""
        return (self.mass + self.arm_mass / 2) * self.length * G

    def text(self) -> str:
        return f"{self.mass:g}@{self.length:g}"


NONE = BenchLoad()


def got(value: float) -> str:
    return f"(got {value:g})"


def must(where: str, what: str, value: float) -> ConfigError:
    """The one-line refusal ``WHERE must be WHAT (got VALUE)``."""
    return ConfigError(f"{where} must be {what} {got(value)}")


def positive(where: str, value: float, *, least: float, most: float, unit: str) -> float:
    """``value`` if finite and within [least, most] [unit]; ConfigError otherwise."""
    if not (math.isfinite(value) and value > 0):
        raise must(where, "a finite number > 0", value)
    if value < least:
        raise must(where, f"at least {least:g} {unit}", value)
    if value > most:
        raise must(where, f"at most {most:g} {unit}", value)
    return value


def rig(where: str, *, mass: float, length: float, arm_mass: float = 0.0) -> None:
    """The rule for a weight on an arm: ``mass`` [kg] at ``length`` [m] within
    MIN..MAX_MASS and MIN..MAX_LENGTH, a uniform arm of ``arm_mass`` 0..MAX_MASS [kg];
    ``where``: the prefix of the fields' names (``"LOG: "``, ``"--"`` for options)."""
    positive(f"{where}mass", mass, least=MIN_MASS, most=MAX_MASS, unit="kg")
    positive(f"{where}length", length, least=MIN_LENGTH, most=MAX_LENGTH, unit="m")
    if not (math.isfinite(arm_mass) and 0 <= arm_mass):
        raise must(f"{where}arm_mass", "a finite number >= 0", arm_mass)
    if arm_mass > MAX_MASS:
        raise must(f"{where}arm_mass", f"at most {MAX_MASS:g} kg", arm_mass)


def parse_load(text: str, *, where: str) -> BenchLoad:
    """``MASS@LENGTH`` [kg @ m] → a load (mass 0: nothing on it; any other keeps ``rig``);
    ConfigError naming ``where`` otherwise."""
    mass_s, sep, length_s = text.partition("@")
    try:
        mass, length = float(mass_s), float(length_s)
    except ValueError:
        mass = length = float("nan")
    if not sep or not (0 <= mass <= MAX_MASS and 0 <= length <= MAX_LENGTH):
        raise ConfigError(f"{where}: expected MASS@LENGTH with 0..{MAX_MASS:g} kg and "
                          f"0..{MAX_LENGTH:g} m (e.g. 0.5@0.1), got {text!r}")
    if mass:
        rig(f"{where}: ", mass=mass, length=length)
    return BenchLoad(mass=mass, length=length)
