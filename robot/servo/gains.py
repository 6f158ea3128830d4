"""Position-control gains as facts: per *gain set* (the registers a servo's firmware reads
its position law from), every gain's name, valid range, memory (EEPROM or RAM), meaning and
the manual section it comes from.

A servo model (``robot.servo.models.ServoModel``) names its gain set and its factory values;
a robot file sets values per bus and per joint (``[bus.gains]``, ``[joints.<name>.gains]``,
read by ``robot.config.gains_file``); the driver writes them before torque on. Names are the
manuals' register names in snake_case, so the robot file, ``robot/bus/tables.py`` (where
the addresses live: none here) and the manuals say the same word.

The gain sets differ *within* a family: on Protocol 1.0 an AX-12A keeps compliance
margins/slopes at 26-29 where an MX-28 keeps D/I/P gains at 26/27/28.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Literal, NamedTuple

Memory = Literal["eeprom", "ram"]


class Gain(NamedTuple):
    """One gain register.

    name: the manual's register name in snake_case; lo, hi: valid register values
    [inclusive]; memory: "eeprom" (kept over power-off, wears with writes) or "ram" (back to
    the factory value at power-on); meaning: unit and what the firmware does with it;
    source: the manual section it is transcribed from.
    """

    name: str
    lo: int
    hi: int
    memory: Memory
    meaning: str
    source: str

    def accepts(self, value: int) -> bool:
        return self.lo <= value <= self.hi


class GainSet(NamedTuple):
    """The gains one kind of servo firmware has. family: key of the control tables."""

    name: str
    family: str
    gains: Mapping[str, Gain]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.gains)

    @property
    def eeprom(self) -> tuple[str, ...]:
        """The gains kept in EEPROM (written only when they differ: EEPROM wears)."""
        return tuple(n for n, g in self.gains.items() if g.memory == "eeprom")


def _set(name: str, family: str, *gains: Gain) -> GainSet:
    return GainSet(name, family, {g.name: g for g in gains})


def _mx_pid(source: str) -> tuple[Gain, ...]:
    """The MX-style PID (RAM, 0 ~ 254: Kp = P / 8, Ki = I * 1000 / 2048, Kd = D * 4 / 1000)."""
    return (Gain("d_gain", 0, 254, "ram", "Kd = value * 4 / 1000", source),
            Gain("i_gain", 0, 254, "ram", "Ki = value * 1000 / 2048", source),
            Gain("p_gain", 0, 254, "ram", "Kp = value / 8", source))


def _feetech_pid(source: str, label: str) -> tuple[Gain, ...]:
    """Feetech's three position-loop coefficients at 21-23, in EEPROM, one byte each;
    ``label`` names a register in ``source`` given its letter (e.g. "{} coefficient")."""
    return tuple(Gain(f"{term}_coefficient", 0, 254, "eeprom",
                      f"position loop {word} coefficient",
                      f"{source}; {label.format(term.upper())}({address})")
                 for term, word, address in (("p", "proportional", 21),
                                             ("d", "derivative", 22),
                                             ("i", "integral", 23)))


_X = "ROBOTIS e-Manual, XL430-W250 / XM430-W350 / XC430-W150, Control Table of RAM Area"
_X_PID = f"{_X}; Position PID Gain(84, 82, 80)"
_AX = "ROBOTIS e-Manual, AX-12A, Control Table of RAM Area"
_MX = "ROBOTIS e-Manual, MX-28 (Protocol 1.0), Control Table of RAM Area; PID Gains(26, 27, 28)"
_XL320 = "ROBOTIS e-Manual, XL-320, Control Table of RAM Area; PID Gains(27, 28, 29)"
_SCS = ("Feetech SCSCL memory table (SCS15 manual v1.02), EEPROM, saved only with "
        "Lock(48) = 0")
_STS = ("Feetech STS/SMS memory table (FT-SMS-STS-emanual), EPROM area, saved only with "
        "Lock(55) = 0")

GAIN_SETS: dict[str, GainSet] = {
    # Dynamixel X series (Protocol 2.0): all RAM, 0 ~ 16,383 for the position gains,
    # 0 ~ 32,767 for the profile (velocity-based profile, Drive Mode bit 2 = 0).
    "dynamixel_x": _set(
        "dynamixel_x", "dynamixel_x",
        Gain("position_d_gain", 0, 16383, "ram", "KPD = value / 16", _X_PID),
        Gain("position_i_gain", 0, 16383, "ram", "KPI = value / 65536", _X_PID),
        Gain("position_p_gain", 0, 16383, "ram", "KPP = value / 128", _X_PID),
        Gain("profile_acceleration", 0, 32767, "ram",
             "214.577 rev/min^2 per unit; 0 = no acceleration limit",
             f"{_X}; Profile Acceleration(108)"),
        Gain("profile_velocity", 0, 32767, "ram",
             "0.229 rev/min per unit; 0 = no velocity limit", f"{_X}; Profile Velocity(112)"),
    ),
    # AX-12A / AX-18A (Protocol 1.0): compliance instead of PID, all RAM. Margin: the error
    # band [position units, 0.29 deg] inside which no torque is applied; slope: how far the
    # torque ramps down toward the goal, used in 7 steps (0-3 -> 2, 4-7 -> 4, 8-15 -> 8,
    # 16-31 -> 16, 32-63 -> 32, 64-127 -> 64, 128-254 -> 128), larger = softer.
    "dynamixel_ax": _set(
        "dynamixel_ax", "dynamixel_p1",
        Gain("cw_compliance_margin", 0, 255, "ram", "dead band, 0.29 deg per unit",
             f"{_AX}; Compliance Margin(26, 27)"),
        Gain("ccw_compliance_margin", 0, 255, "ram", "dead band, 0.29 deg per unit",
             f"{_AX}; Compliance Margin(26, 27)"),
        Gain("cw_compliance_slope", 0, 254, "ram",
             "torque ramp width, 7 steps 2..128; larger = softer",
             f"{_AX}; Compliance Slope(28, 29)"),
        Gain("ccw_compliance_slope", 0, 254, "ram",
             "torque ramp width, 7 steps 2..128; larger = softer",
             f"{_AX}; Compliance Slope(28, 29)"),
    ),
    # MX series on Protocol 1.0 firmware: PID, all RAM, 0 ~ 254.
    "dynamixel_mx1": _set(
        "dynamixel_mx1", "dynamixel_p1", *_mx_pid(_MX)),
    # Feetech STS/SMS: the position loop's coefficients live in EEPROM (one byte each; 255
    # is left out as on the table's other one-byte settings, e.g. Return delay 0 ~ 254).
    "feetech_sts": _set(
        "feetech_sts", "feetech_sts", *_feetech_pid(_STS, "{} coefficient")),
    # XL-320 (Protocol 2.0, its own table): the MX-style PID, RAM, 0 ~ 254 (the page's PID
    # section is the MX one: Kp = P / 8, Ki = I * 1000 / 2048, Kd = D * 4 / 1000).
    "dynamixel_xl320": _set(
        "dynamixel_xl320", "dynamixel_xl320", *_mx_pid(_XL320)),
    # Feetech SCS (SCSCL): the STS's three coefficients at the same addresses, in EEPROM.
    "feetech_scs": _set(
        "feetech_scs", "feetech_scs", *_feetech_pid(_SCS, "{}")),
    # HiWonder/LewanSoul LX: the Bus Servo Communication Protocol has no gain command (a
    # position, a move time, limits, offset, load/unload, LED): nothing to set.
    "lx": _set("lx", "lx"),
}


def describe(gain_set: str) -> str:
    """``name [lo..hi]`` for every gain of ``gain_set``, for messages."""
    return (", ".join(f"{g.name} [{g.lo}..{g.hi}]" for g in GAIN_SETS[gain_set].gains.values())
            or "none (its firmware takes no gains: remove the table)")
