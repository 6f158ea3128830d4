"""The servo models of issue 21 the emulator can be (``servo_models`` gathers them), from
the vendors' pages; the driver's ``robot.servo.models`` holds the same facts and
``tests/test_emulator_tables.py`` makes the two agree.

ROBOTIS: the e-Manual pages (ROBOTIS-GIT/emanual docs/en/dxl/...; specifications in
_data/dxl_x_info.yml and dxl_mx_info.yml): model number, pulses per turn, the no-load
speed at the bold (recommended) voltage, the RAM / EEPROM initial values where the page's
differ from its table's base (``control_tables_more`` names which table each has). Where a
page was not read the entry says whose values it takes. Feetech: as the driver's entries
(robot/servo/models_feetech.py), the model numbers marked there as unverified included.
"""

from __future__ import annotations

from collections.abc import Mapping

from sim.emulator.servo_model import ServoModel, per_60deg, rpm

X, XL320, P1, STS, SCS = ("dynamixel_x", "dynamixel_xl320", "dynamixel_p1", "feetech_sts",
                          "feetech_scs")


def _x(d: int, i: int, p: int, **more: int) -> Mapping[str, int]:
    return {"position_d_gain": d, "position_i_gain": i, "position_p_gain": p, **more}


#: XM430-W350 page: Velocity I / P Gain 1,920 / 100, Position D 0 / P 800, Current Limit
#: 1,193, Velocity Limit 350, Temperature Limit 80, Max / Min Voltage Limit 160 / 95.
XM_INITIAL = _x(0, 0, 800, velocity_i_gain=1920, velocity_p_gain=100, current_limit=1193,
                velocity_limit=350, temperature_limit=80, max_voltage_limit=160,
                min_voltage_limit=95)
#: XL330-M288 page (see servo_models).
XL330_INITIAL = _x(0, 0, 400, velocity_i_gain=1600, velocity_p_gain=180, current_limit=1750,
                   velocity_limit=445, temperature_limit=70, max_voltage_limit=70,
                   min_voltage_limit=35, shutdown=53)
#: XL330-M077 page: Velocity I / P 400 / 40, Position I 400, P 400, Velocity Limit 1,620.
_XL330_M077 = {**XL330_INITIAL, **_x(0, 400, 400, velocity_i_gain=400, velocity_p_gain=40,
                                     velocity_limit=1620)}
#: XC330-M288 page: Velocity I / P 1,600 / 50, Position D 500 / P 1,100, Current Limit
#: 2,352, Velocity Limit 350, Shutdown 52 (the other XC330s: taken as these).
_XC330 = {**XL330_INITIAL, **_x(500, 0, 1100, velocity_p_gain=50, current_limit=2352,
                                velocity_limit=350, shutdown=52)}
#: MX-28(2.0) page: Velocity I / P 1,920 / 100, Position P 850, Velocity Limit 380,
#: Temperature Limit 80, Max / Min Voltage 160 / 95 (baud 57600 initial, as the X).
_MX28_2 = _x(0, 0, 850, velocity_i_gain=1920, velocity_p_gain=100, velocity_limit=380,
             temperature_limit=80, max_voltage_limit=160, min_voltage_limit=95)
#: MX-64(2.0) page: as the MX-28(2.0) with Current Limit 1,941 [3.36 mA], Velocity Limit
#: 435 (the MX-106(2.0) page was not read: taken as these).
_MX64_2 = {**_MX28_2, "current_limit": 1941, "velocity_limit": 435}
#: 2XL430-W250 page: Velocity I / P 1,800 / 100, Position D 2,000 / P 640, Velocity Limit
#: 250 (the 2XC430-W250 page was not read: taken as these).
_2XL = _x(2000, 0, 640, velocity_i_gain=1800, velocity_p_gain=100, velocity_limit=250)
#: MX-64 / MX-106 (Protocol 1.0) pages: Baud Rate(4) 34 = 57600 as the MX-28; Max Voltage
#: Limit 240 on the MX-64, 160 on the MX-106.
_MX64_1 = {"max_voltage_limit": 240}
_MX106_1 = {"max_voltage_limit": 160}


def _m(name: str, number: int, family: str, resolution: int, speed: float, *,
       span: float = 360.0, table: str = "", initial: Mapping[str, int] | None = None,
       axes: int = 1) -> ServoModel:
    return ServoModel(name, number, family, resolution, speed, span, table,
                      dict(initial or {}), axes)


MORE: dict[str, ServoModel] = {m.name: m for m in (
    _m("XL-320", 350, XL320, 1024, rpm(114), span=300.0),
    _m("XL330-M077", 1190, X, 4096, rpm(383), table="dynamixel_xl330", initial=_XL330_M077),
    _m("XC330-M288", 1240, X, 4096, rpm(81), table="dynamixel_xl330", initial=_XC330),
    _m("XC330-M181", 1230, X, 4096, rpm(129), table="dynamixel_xl330", initial=_XC330),
    _m("XC330-T288", 1220, X, 4096, rpm(65), table="dynamixel_xl330", initial=_XC330),
    _m("XC330-T181", 1210, X, 4096, rpm(104), table="dynamixel_xl330", initial=_XC330),
    # XM430-W210 (77 rpm), the XH430s (W350 30, W210 50, V350 31, V210 52 rpm), the XM540s
    # (W270 30, W150 53 rpm): the XM430-W350's table and initial values (pages not read).
    *(_m(n, num, X, 4096, rpm(r), table="dynamixel_xm", initial=XM_INITIAL)
      for n, num, r in (("XM430-W210", 1030, 77), ("XH430-W350", 1000, 30),
                        ("XH430-W210", 1010, 50), ("XH430-V350", 1040, 31),
                        ("XH430-V210", 1050, 52), ("XM540-W270", 1120, 30),
                        ("XM540-W150", 1130, 53))),
    # Two axes a case (2xl430-w250 page: "Each motor on 2XL430 has its own control table").
    _m("2XL430-W250", 1090, X, 4096, rpm(57), table="dynamixel_2xl", initial=_2XL, axes=2),
    _m("2XC430-W250", 1160, X, 4096, rpm(64), table="dynamixel_2xl", initial=_2XL, axes=2),
    _m("MX-28(2.0)", 30, X, 4096, rpm(55), table="dynamixel_mx2", initial=_MX28_2),
    _m("MX-64(2.0)", 311, X, 4096, rpm(63), table="dynamixel_xm", initial=_MX64_2),
    _m("MX-106(2.0)", 321, X, 4096, rpm(45), table="dynamixel_xm", initial=_MX64_2),
    _m("MX-64", 310, P1, 4096, rpm(63), table="dynamixel_mx64_1", initial=_MX64_1),
    _m("MX-106", 320, P1, 4096, rpm(45), table="dynamixel_mx106_1", initial=_MX106_1),
    # Feetech STS: the STS3215's table.
    _m("STS3215-12V", 777, STS, 4096, per_60deg(0.222)),
    _m("STS3046", 3046, STS, 4096, per_60deg(0.222)),
    # Feetech SCS (SCSCL table, big-endian): SCS0009 300 deg, SCS15 / SCS40 215 deg over
    # 1024 positions.
    _m("SCS0009", 1284, SCS, 1024, rpm(100), span=300.0),
    _m("SCS15", 1295, SCS, 1024, rpm(65), span=215.0),
    _m("SCS40", 1320, SCS, 1024, rpm(65), span=215.0),
)}
