"""What a servo on a test bench carries: a weight on an arm (a pendulum), or nothing.

The pendulum logs' rig (``robot.servo.pendulum_log``): q = 0 is the arm hanging down, a
point weight ``mass`` [kg] at ``length`` [m] from the shaft, optionally a uniform arm of
``arm_mass`` [kg]. With nothing on it a servo turns only its own rotor and horn.

``biped emulate --load`` gives an emulated servo such a load, ``biped sim-gap --load``
tells the simulation the same, and ``biped identify record --mass --length`` names the real
one; the text form is ``MASS@LENGTH`` (kg @ m), e.g. ``0.5@0.1``.
"""

from __future__ import annotations

from dataclasses import dataclass

from robot.errors import ConfigError

G = 9.81                 # [m/s^2]
#: The horn's own inertia about the shaft [kg m^2] (a small aluminium horn; the rotor's
#: reflected inertia, the model's armature, dominates it many times over).
HORN_INERTIA = 1e-6
MAX_MASS = 10.0          # [kg] what a hobby servo bench could hold, for input checks
MAX_LENGTH = 1.0         # [m]


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


def parse_load(text: str, *, where: str) -> BenchLoad:
    """``MASS@LENGTH`` [kg @ m] → a load; ConfigError naming ``where`` otherwise."""
    mass_s, sep, length_s = text.partition("@")
    try:
        mass, length = float(mass_s), float(length_s)
    except ValueError:
        mass = length = float("nan")
    if not sep or not (0 <= mass <= MAX_MASS and 0 <= length <= MAX_LENGTH):
        raise ConfigError(f"{where}: expected MASS@LENGTH with 0..{MAX_MASS:g} kg and "
                          f"0..{MAX_LENGTH:g} m (e.g. 0.5@0.1), got {text!r}")
    return BenchLoad(mass=mass, length=length)
