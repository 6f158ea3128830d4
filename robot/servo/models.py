"""Servo models and families as data: datasheet facts per model, the bus kinds' families,
and the baud rates each family's Baud Rate register encodes.

Sources are named per entry (ROBOTIS e-Manual, Feetech datasheets and memory table). This
module sits below the robot config and the buses (it imports nothing of the project), so
both can check a model or a baud rate against it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType
from typing import NamedTuple

# Baud-rate register codes.
DYNAMIXEL_X_BAUD: dict[int, int] = {
    0: 9600, 1: 57600, 2: 115200, 3: 1000000, 4: 2000000, 5: 3000000, 6: 4000000,
}
FEETECH_STS_BAUD: dict[int, int] = {
    0: 1000000, 1: 500000, 2: 250000, 3: 128000, 4: 115200, 5: 76800, 6: 57600, 7: 38400,
}
# AX-12A "Baud Rate(4)": rate = 2000000 / (code + 1); the manual's table of the usual codes
# (1 Mbps is 1, the factory value; 57600 is 34, 3.5 % off but within tolerance).
DYNAMIXEL_P1_BAUD: dict[int, int] = {
    1: 1000000, 3: 500000, 4: 400000, 7: 250000, 9: 200000, 16: 115200, 34: 57600,
    103: 19200, 207: 9600,
}
BAUD_CODES: dict[str, dict[int, int]] = {
    "dynamixel_x": DYNAMIXEL_X_BAUD,
    "dynamixel_p1": DYNAMIXEL_P1_BAUD,
    "feetech_sts": FEETECH_STS_BAUD,
}
#: Families with one fixed baud rate and no Baud Rate register [bit/s]: the LX servos talk
#: at 115200 only (LewanSoul "Bus Servo Communication Protocol", 2. UART interface).
FIXED_BAUD: dict[str, int] = {"lx": 115_200}


class ServoModel(NamedTuple):
    """Datasheet facts about one servo model.

    number: model number as reported by ping / the model_number register
    family: key into TABLES
    resolution: number of positions (goal/present ticks run 0..resolution-1)
    stall_torque: stall torque at the nominal voltage [N m]
    no_load_speed: no-load speed at the nominal voltage [rad/s]
    mass: [kg]
    nominal_voltage: [V]
    """

    name: str
    number: int
    family: str
    resolution: int
    stall_torque: float
    no_load_speed: float
    mass: float
    nominal_voltage: float
    #: angle the ``resolution`` positions span [deg]: 360 for a full turn, 300 for the AX
    #: series (1024 ticks over 300 deg, i.e. an effective 1228.8 ticks per turn)
    span_deg: float = 360.0
    #: key of ``robot.servo.gains.GAIN_SETS``: the gain registers this servo's firmware has
    gain_set: str = ""
    #: the gains as the servo leaves the factory (register values; every gain of the set)
    factory_gains: Mapping[str, int] = MappingProxyType({})

    @property
    def ticks_per_rad(self) -> float:
        """Ticks per radian of output shaft."""
        return self.resolution / math.radians(self.span_deg)


_RPM = 2.0 * math.pi / 60.0


def _x(d: int, i: int, p: int) -> Mapping[str, int]:
    """Dynamixel X gains at the factory: Position D/I/P Gain (80/82/84, e-Manual "Initial
    Value" of the model's RAM table); Profile Acceleration/Velocity (108/112) 0 (no profile:
    the driver streams the trajectory itself)."""
    return MappingProxyType({"position_d_gain": d, "position_i_gain": i, "position_p_gain": p,
                             "profile_acceleration": 0, "profile_velocity": 0})


#: AX-12A / AX-18A e-Manual RAM table: CW/CCW Compliance Margin (26/27) 1, CW/CCW Compliance
#: Slope (28/29) 32.
_AX_FACTORY = MappingProxyType({"cw_compliance_margin": 1, "ccw_compliance_margin": 1,
                                "cw_compliance_slope": 32, "ccw_compliance_slope": 32})
#: MX-28 (Protocol 1.0) e-Manual RAM table: D Gain (26) 0, I Gain (27) 0, P Gain (28) 32.
_MX1_FACTORY = MappingProxyType({"d_gain": 0, "i_gain": 0, "p_gain": 32})
#: Feetech STS3215: P coefficient (21) 32, D coefficient (22) 32, I coefficient (23) 0 (the
#: servo's EPROM as shipped; LeRobot's Feetech bus notes "Default is 32" when it lowers P).
_STS_FACTORY = MappingProxyType({"p_coefficient": 32, "d_coefficient": 32, "i_coefficient": 0})
_X_SET, _AX_SET, _MX1_SET, _STS_SET = "dynamixel_x", "dynamixel_ax", "dynamixel_mx1", "feetech_sts"
#: LX positions 0..1000 cover 0..240 deg (0.24 deg a step): 1001 positions, each 0.24 deg
#: wide, so ``span_deg`` 240.24 gives exactly 1000 steps per 240 deg.
_LX_RES, _LX_SPAN = 1001, 240.24
_KGCM = 9.80665e-2  # N m per kg cm

MODELS: dict[str, ServoModel] = {
    # ROBOTIS XL430-W250-T: 1.4 N m, 57 rpm at 11.1 V; 57.2 g.
    # Gains: e-Manual XL430-W250 RAM table, Position D 4,000 / I 0 / P 640.
    "XL430-W250": ServoModel("XL430-W250", 1060, "dynamixel_x", 4096, 1.4, 57 * _RPM, 0.0572, 11.1,
                             gain_set=_X_SET, factory_gains=_x(4000, 0, 640)),
    # ROBOTIS XM430-W350: 4.1 N m, 46 rpm at 12 V; 82 g.
    # Gains: e-Manual XM430-W350 RAM table, Position D 0 / I 0 / P 800.
    "XM430-W350": ServoModel("XM430-W350", 1020, "dynamixel_x", 4096, 4.1, 46 * _RPM, 0.082, 12.0,
                             gain_set=_X_SET, factory_gains=_x(0, 0, 800)),
    # ROBOTIS XC430-W150: 1.6 N m (12 V stall), 70 rpm; 65 g.
    # Gains: e-Manual XC430-W150 RAM table, Position D 0 / I 0 / P 460.
    "XC430-W150": ServoModel("XC430-W150", 1070, "dynamixel_x", 4096, 1.6, 70 * _RPM, 0.065, 12.0,
                             gain_set=_X_SET, factory_gains=_x(0, 0, 460)),
    # ROBOTIS e-Manual XL330-M288-T: 0.52 N m (5.0 V, 1.47 A), 103 rpm (5.0 V), 18 g; model
    # number 1200. Gains: e-Manual XL330-M288 RAM table, Position D 0 / I 0 / P 400.
    "XL330-M288": ServoModel("XL330-M288", 1200, "dynamixel_x", 4096, 0.52, 103 * _RPM, 0.018, 5.0,
                             gain_set=_X_SET, factory_gains=_x(0, 0, 400)),
    # ROBOTIS e-Manual AX-12A: 1.5 N m (12 V, 1.5 A), 59 rpm (12 V), 54.6 g; 0..300 deg in
    # 1024 steps (0.29 deg); model number 12.
    "AX-12A": ServoModel("AX-12A", 12, "dynamixel_p1", 1024, 1.5, 59 * _RPM, 0.0546, 12.0, 300.0,
                         gain_set=_AX_SET, factory_gains=_AX_FACTORY),
    # ROBOTIS e-Manual AX-18A: 1.8 N m (12 V, 2.2 A), 97 rpm (12 V), 54.5 g; model 18.
    "AX-18A": ServoModel("AX-18A", 18, "dynamixel_p1", 1024, 1.8, 97 * _RPM, 0.0545, 12.0, 300.0,
                         gain_set=_AX_SET, factory_gains=_AX_FACTORY),
    # ROBOTIS e-Manual MX-28 (Protocol 1.0 firmware): 2.5 N m, 55 rpm at 12 V, 72 g;
    # 4096 steps per turn; model number 29.
    "MX-28": ServoModel("MX-28", 29, "dynamixel_p1", 4096, 2.5, 55 * _RPM, 0.072, 12.0,
                        gain_set=_MX1_SET, factory_gains=_MX1_FACTORY),
    # Feetech STS3215 (7.4 V): 19.5 kg cm = 1.91 N m, 0.222 s/60 deg; 55 g.
    "STS3215": ServoModel("STS3215", 777, "feetech_sts", 4096, 1.91, (math.pi / 3) / 0.222, 0.055, 7.4,
                          gain_set=_STS_SET, factory_gains=_STS_FACTORY),
    # Feetech STS3250 (12 V): 50 kg cm = 4.90 N m, 0.133 s/60 deg (Feetech datasheet, doc.
    # 6384135881578380868917773 A/0); model number 2825 (lerobot's Feetech table); mass not
    # in that datasheet: 60 g estimated (the STS3215's 55 g case with a metal shell).
    # Gains: taken as the STS3215's (same STS firmware; the public STS3250 recordings ran at
    # P 32).
    "STS3250": ServoModel("STS3250", 2825, "feetech_sts", 4096, 4.90, (math.pi / 3) / 0.133, 0.060,
                          12.0, gain_set=_STS_SET, factory_gains=_STS_FACTORY),
    # Feetech STS3032: 4.5 kg cm = 0.44 N m, 0.1 s/60 deg at 6 V; 17 g.
    # Gains: no STS3032 memory table at hand; taken as the STS3215's (same STS firmware).
    "STS3032": ServoModel("STS3032", 1288, "feetech_sts", 4096, 0.44, (math.pi / 3) / 0.1, 0.017, 6.0,
                          gain_set=_STS_SET, factory_gains=_STS_FACTORY),
    # HiWonder/LewanSoul LX serial bus servos. The protocol has no model number: ``number``
    # is biped's own label (scan reports the robot file's model). No gains: the firmware
    # takes a position and a move time, nothing else (gain set "lx" is empty).
    # LX-16A (LewanSoul spec sheet): 17 kg cm at 7.4 V (15 at 6.6 V), 0.16 s/60 deg at
    # 7.4 V (0.18 at 6 V), 52 g, 6-8.4 V.
    "LX-16A": ServoModel("LX-16A", 16, "lx", _LX_RES, 17 * _KGCM, (math.pi / 3) / 0.16, 0.052, 7.4,
                         _LX_SPAN, gain_set="lx"),
    # LX-224 / LX-224HV (HiWonder listings, not a datasheet page: an assumption until one is
    # at hand): 20 kg cm, 0.20 s/60 deg at 7.4 V (LX-224, 6-8.4 V) and 0.18 s/60 deg at
    # 11.1 V (LX-224HV, 9-12.6 V); about 60 g.
    "LX-224": ServoModel("LX-224", 224, "lx", _LX_RES, 20 * _KGCM, (math.pi / 3) / 0.20, 0.060, 7.4,
                         _LX_SPAN, gain_set="lx"),
    "LX-224HV": ServoModel("LX-224HV", 2240, "lx", _LX_RES, 20 * _KGCM, (math.pi / 3) / 0.18, 0.060,
                           11.1, _LX_SPAN, gain_set="lx"),
}

MODELS_BY_NUMBER: dict[str, dict[int, ServoModel]] = {}
for _m in MODELS.values():
    MODELS_BY_NUMBER.setdefault(_m.family, {})[_m.number] = _m

BUS_FAMILIES: dict[str, str] = {
    "dynamixel": "dynamixel_x", "dynamixel1": "dynamixel_p1", "feetech": "feetech_sts",
    "lx": "lx",
}


def model_name(family: str, number: int) -> str:
    """Human name of a model number within a family, or ``"unknown(<number>)"``."""
    model = MODELS_BY_NUMBER.get(family, {}).get(number)
    return model.name if model else f"unknown({number})"
