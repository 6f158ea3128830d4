"""Servo models and families as data: every model the driver knows (``MODELS``, gathered
from ``models_dynamixel``, ``models_feetech`` and ``models_lx``), the bus kinds' families,
the baud rates each family's Baud Rate register encodes and the rate each ships at.

Sources are named per entry in those modules (ROBOTIS e-Manual, Feetech datasheets and
memory tables). This module sits below the robot config and the buses (it imports nothing
of the project outside robot/servo), so both can check a model or a baud rate against it.
"""

from __future__ import annotations

from collections.abc import Iterable

from robot.servo import models_dynamixel, models_feetech, models_lx
from robot.servo.model import ServoModel

__all__ = ["MODELS", "ServoModel"]

# Baud-rate register codes.
#: e-Manual X series "Baud Rate(8)" (XL430 / XM430 / XL330 / MX(2.0) pages; 7 = 4.5 Mbps
#: exists on some, not on the XL330: left out).
DYNAMIXEL_X_BAUD: dict[int, int] = {
    0: 9600, 1: 57600, 2: 115200, 3: 1000000, 4: 2000000, 5: 3000000, 6: 4000000,
}
#: e-Manual XL-320 "Baud Rate(4)": 0 9,600, 1 57,600, 2 115,200, 3 1 Mbps.
DYNAMIXEL_XL320_BAUD: dict[int, int] = {0: 9600, 1: 57600, 2: 115200, 3: 1000000}
#: Feetech STS/SMS memory table "Baud Rate(6)": 0-7 = 1000000, 500000, 250000, 128000,
#: 115200, 76800, 57600, 38400 ("configurable 38400 ~ 1 Mbps", the memory table as
#: translated on wiki.aifitlab.com "STS Servo - Memory Table Analysis", 2.2 EPROM); Feetech's
#: own SMS_STS.h names the same codes (SMS_STS_76800 5, SMS_STS_57600 6, SMS_STS_38400 7).
#: LeRobot's STS_SMS_SERIES_BAUDRATE_TABLE has 5-7 = 57600 / 38400 / 19200: one code off
#: (19200 is below the range Feetech states).
FEETECH_STS_BAUD: dict[int, int] = {
    0: 1000000, 1: 500000, 2: 250000, 3: 128000, 4: 115200, 5: 76800, 6: 57600, 7: 38400,
}
#: Feetech SCSCL memory table "Baud Rate(6)" (wiki.aifitlab.com "SCSCL Servo - Memory Table
#: Analysis", 2.2) and Feetech's SCSCL.h: the same eight codes as STS.
FEETECH_SCS_BAUD: dict[int, int] = dict(FEETECH_STS_BAUD)
# AX-12A "Baud Rate(4)": rate = 2000000 / (code + 1); the manual's table of the usual codes
# (1 Mbps is 1, the factory value; 57600 is 34, 3.5 % off but within tolerance).
DYNAMIXEL_P1_BAUD: dict[int, int] = {
    1: 1000000, 3: 500000, 4: 400000, 7: 250000, 9: 200000, 16: 115200, 34: 57600,
    103: 19200, 207: 9600,
}
BAUD_CODES: dict[str, dict[int, int]] = {
    "dynamixel_x": DYNAMIXEL_X_BAUD,
    "dynamixel_xl320": DYNAMIXEL_XL320_BAUD,
    "dynamixel_p1": DYNAMIXEL_P1_BAUD,
    "feetech_sts": FEETECH_STS_BAUD,
    "feetech_scs": FEETECH_SCS_BAUD,
}
#: Families with one fixed baud rate and no Baud Rate register [bit/s]: the LX servos talk
#: at 115200 only (LewanSoul "Bus Servo Communication Protocol", 2. UART interface).
FIXED_BAUD: dict[str, int] = {"lx": 115_200}
#: The rate a family's servos ship at [bit/s] (a model may differ: ServoModel.factory_baud):
#: ROBOTIS X series 57600 (Baud Rate(8) = 1), XL-320 1 Mbps (Baud Rate(4) = 3), AX-12A
#: 1 Mbps (Baud Rate(4) = 1), Feetech STS and SCS 1 Mbps (Baud Rate(6) = 0).
FACTORY_BAUD: dict[str, int] = {
    "dynamixel_x": 57_600, "dynamixel_xl320": 1_000_000, "dynamixel_p1": 1_000_000,
    "feetech_sts": 1_000_000, "feetech_scs": 1_000_000, **FIXED_BAUD,
}

MODELS: dict[str, ServoModel] = {**models_dynamixel.MODELS, **models_feetech.MODELS,
                                 **models_lx.MODELS}

#: family -> model number -> model; where two models report one number (the 7.4 V and
#: 12 V STS3215) the first listed names it.
MODELS_BY_NUMBER: dict[str, dict[int, ServoModel]] = {}
for _m in MODELS.values():
    MODELS_BY_NUMBER.setdefault(_m.family, {}).setdefault(_m.number, _m)

#: Bus kind -> the control-table families its protocol speaks (the first is the default):
#: Dynamixel Protocol 2.0 drives the X table and the XL-320's; Feetech's protocol the STS
#: (little-endian) and SCS (big-endian) tables.
BUS_FAMILIES: dict[str, tuple[str, ...]] = {
    "dynamixel": ("dynamixel_x", "dynamixel_xl320"), "dynamixel1": ("dynamixel_p1",),
    "feetech": ("feetech_sts", "feetech_scs"), "lx": ("lx",),
}


def kind_of(family: str) -> str:
    """The bus kind whose protocol speaks ``family``."""
    return next(k for k, fams in BUS_FAMILIES.items() if family in fams)


def lookup(families: str | Iterable[str], number: int) -> ServoModel | None:
    """The model reporting ``number`` within ``families`` (a family or several), or None."""
    for family in (families,) if isinstance(families, str) else families:
        model = MODELS_BY_NUMBER.get(family, {}).get(number)
        if model is not None:
            return model
    return None


def model_name(families: str | Iterable[str], number: int) -> str:
    """Human name of a model number within a family (or several), or ``"unknown(<n>)"``."""
    model = lookup(families, number)
    return model.name if model else f"unknown({number})"


def factory_baud(model: ServoModel) -> int:
    """The baud rate ``model`` ships at [bit/s]."""
    return model.factory_baud or FACTORY_BAUD[model.family]


def bauds(family: str) -> list[int]:
    """Every rate a family's servos can be set to [bit/s], slowest first."""
    if family in FIXED_BAUD:
        return [FIXED_BAUD[family]]
    return sorted(BAUD_CODES[family].values())
