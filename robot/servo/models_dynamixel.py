"""ROBOTIS Dynamixel models: datasheet facts, model numbers and factory gains.

Sources: the ROBOTIS e-Manual (its source repository ROBOTIS-GIT/emanual: the model pages
under docs/en/dxl/ for the control tables and their initial values, _data/dxl_x_info.yml and
_data/dxl_mx_info.yml for the specifications); model numbers as the pages' Model Number(0)
initial value and ROBOTIS-GIT/dynamixel-workbench's dynamixel_item.h. Stall torque and
no-load speed are given at the voltage the e-Manual prints in bold (its recommended one).
Where a number comes from elsewhere, or is assumed, the entry says so.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from robot.servo.model import RPM, ServoModel

X, XL320, P1 = "dynamixel_x", "dynamixel_xl320", "dynamixel_p1"


def _x(d: int, i: int, p: int) -> Mapping[str, int]:
    """Dynamixel X (and MX on Protocol 2.0) gains at the factory: Position D/I/P Gain
    (80/82/84, e-Manual "Initial Value" of the model's RAM table); Profile Acceleration /
    Velocity (108/112) 0 (no profile: the driver streams the trajectory itself)."""
    return MappingProxyType({"position_d_gain": d, "position_i_gain": i, "position_p_gain": p,
                             "profile_acceleration": 0, "profile_velocity": 0})


def _dip(d: int, i: int, p: int) -> Mapping[str, int]:
    """D/I/P Gain of the MX (Protocol 1.0) and XL-320 RAM tables, 0 ~ 254."""
    return MappingProxyType({"d_gain": d, "i_gain": i, "p_gain": p})


#: AX-12A / AX-18A e-Manual RAM table: CW/CCW Compliance Margin (26/27) 1, CW/CCW Compliance
#: Slope (28/29) 32.
_AX = MappingProxyType({"cw_compliance_margin": 1, "ccw_compliance_margin": 1,
                        "cw_compliance_slope": 32, "ccw_compliance_slope": 32})
#: MX-28 / MX-64 / MX-106 (Protocol 1.0) e-Manual RAM tables: D Gain(26) 0, I Gain(27) 0,
#: P Gain(28) 32.
_MX1 = _dip(0, 0, 32)
#: MX-28(2.0) and MX-64(2.0) e-Manual RAM tables: Position D 0 / I 0 / P 850.
_MX2 = _x(0, 0, 850)
#: XM430-W350 e-Manual RAM table: Position D 0 / I 0 / P 800.
_XM = _x(0, 0, 800)
#: XC330-M288 e-Manual RAM table: Position D 500 / I 0 / P 1,100.
_XC330 = _x(500, 0, 1100)
_XS, _MX1S, _AXS = "dynamixel_x", "dynamixel_mx1", "dynamixel_ax"


def _m(name: str, number: int, family: str, resolution: int, torque: float, rpm: float,
       mass: float, volts: float, **kw: object) -> ServoModel:
    return ServoModel(name, number, family, resolution, torque, rpm * RPM, mass, volts,
                      **kw)  # type: ignore[arg-type]


MODELS: dict[str, ServoModel] = {m.name: m for m in (
    # --- X series on Protocol 2.0 (e-Manual X pages), 4096 pulses/rev -------------------
    # XL430-W250-T: 1.4 N m, 57 rpm at 11.1 V; 57.2 g; 1060. Position D 4,000 / I 0 / P 640.
    _m("XL430-W250", 1060, X, 4096, 1.4, 57, 0.0572, 11.1, gain_set=_XS,
       factory_gains=_x(4000, 0, 640)),
    # 2XL430-W250-T: two axes in one case (98.2 g: 49.1 g an axis), each its own control
    # table and id, one shared baud rate; 1.4 N m, 57 rpm at 11.1 V; 1090. Position D 2,000
    # / I 0 / P 640 (2xl430-w250 page).
    _m("2XL430-W250", 1090, X, 4096, 1.4, 57, 0.0491, 11.1, gain_set=_XS,
       factory_gains=_x(2000, 0, 640), axes=2),
    # 2XC430-W250-T: two axes (102 g: 51 g an axis); 1.8 N m, 64 rpm at 12 V; 1160.
    # (gains: its page not read; taken as the 2XL430-W250's, the same dual case)
    _m("2XC430-W250", 1160, X, 4096, 1.8, 64, 0.051, 12.0, gain_set=_XS,
       factory_gains=_x(2000, 0, 640), axes=2),
    # XC430-W150-T: 1.6 N m, 106 rpm at 12 V (the e-Manual's XC430-W150 data; 70 rpm is the
    # XC430-W240's); 65 g; 1070. Position D 0 / I 0 / P 460.
    _m("XC430-W150", 1070, X, 4096, 1.6, 106, 0.065, 12.0, gain_set=_XS,
       factory_gains=_x(0, 0, 460)),
    # XM430-W350: 4.1 N m, 46 rpm at 12 V; 82 g; 1020. Position D 0 / I 0 / P 800.
    _m("XM430-W350", 1020, X, 4096, 4.1, 46, 0.082, 12.0, gain_set=_XS, factory_gains=_XM),
    # XM430-W210: 3.0 N m, 77 rpm at 12 V; 82 g; 1030. (gains: taken as the XM430-W350's)
    _m("XM430-W210", 1030, X, 4096, 3.0, 77, 0.082, 12.0, gain_set=_XS, factory_gains=_XM),
    # XH430-W350: 3.4 N m, 30 rpm at 12 V; 82 g; 1000. XH430-W210: 2.5 N m, 50 rpm at 12 V;
    # 1010. XH430-V350: 3.3 N m, 31 rpm at 24 V; 1040. XH430-V210: 2.6 N m, 52 rpm at 24 V;
    # 1050. (gains: taken as the XM430-W350's, the same 430 case and firmware)
    _m("XH430-W350", 1000, X, 4096, 3.4, 30, 0.082, 12.0, gain_set=_XS, factory_gains=_XM),
    _m("XH430-W210", 1010, X, 4096, 2.5, 50, 0.082, 12.0, gain_set=_XS, factory_gains=_XM),
    _m("XH430-V350", 1040, X, 4096, 3.3, 31, 0.082, 24.0, gain_set=_XS, factory_gains=_XM),
    _m("XH430-V210", 1050, X, 4096, 2.6, 52, 0.082, 24.0, gain_set=_XS, factory_gains=_XM),
    # XM540-W270: 10.6 N m, 30 rpm at 12 V; 165 g; 1120. XM540-W150: 7.3 N m, 53 rpm at
    # 12 V; 1130. (gains: taken as the XM430-W350's)
    _m("XM540-W270", 1120, X, 4096, 10.6, 30, 0.165, 12.0, gain_set=_XS, factory_gains=_XM),
    _m("XM540-W150", 1130, X, 4096, 7.3, 53, 0.165, 12.0, gain_set=_XS, factory_gains=_XM),
    # XL330-M288-T: 0.52 N m, 103 rpm at 5 V; 18 g; 1200. Position D 0 / I 0 / P 400.
    _m("XL330-M288", 1200, X, 4096, 0.52, 103, 0.018, 5.0, gain_set=_XS,
       factory_gains=_x(0, 0, 400)),
    # XL330-M077-T: 0.215 N m, 383 rpm at 5 V; 18 g; 1190. Position D 0 / I 400 / P 400.
    _m("XL330-M077", 1190, X, 4096, 0.215, 383, 0.018, 5.0, gain_set=_XS,
       factory_gains=_x(0, 400, 400)),
    # XC330-M288-T: 0.93 N m, 81 rpm at 5 V; 23 g; 1240. Position D 500 / I 0 / P 1,100.
    _m("XC330-M288", 1240, X, 4096, 0.93, 81, 0.023, 5.0, gain_set=_XS, factory_gains=_XC330),
    # XC330-M181-T: 0.60 N m, 129 rpm at 5 V; 1230. XC330-T288-T: 0.92 N m, 65 rpm at
    # 11.1 V; 1220. XC330-T181-T: 0.76 N m, 104 rpm at 11.1 V; 1210. All 23 g.
    # (gains: taken as the XC330-M288's)
    _m("XC330-M181", 1230, X, 4096, 0.60, 129, 0.023, 5.0, gain_set=_XS, factory_gains=_XC330),
    _m("XC330-T288", 1220, X, 4096, 0.92, 65, 0.023, 11.1, gain_set=_XS, factory_gains=_XC330),
    _m("XC330-T181", 1210, X, 4096, 0.76, 104, 0.023, 11.1, gain_set=_XS,
       factory_gains=_XC330),
    # --- MX series on Protocol 2.0 firmware: the X control table (mx-28-2, mx-64-2,
    # mx-106-2 pages), 4096 pulses/rev, factory baud 57600 (Baud Rate(8) 1) -------------
    # MX-28(2.0): 2.5 N m, 55 rpm at 12 V; 72 g (MX-28T/R); 30.
    _m("MX-28(2.0)", 30, X, 4096, 2.5, 55, 0.072, 12.0, gain_set=_XS, factory_gains=_MX2),
    # MX-64(2.0): 6.0 N m, 63 rpm at 12 V; 165 g (_data/dxl_mx_info.yml weight_mx64); 311.
    _m("MX-64(2.0)", 311, X, 4096, 6.0, 63, 0.165, 12.0, gain_set=_XS, factory_gains=_MX2),
    # MX-106(2.0): 8.4 N m, 45 rpm at 12 V; 165 g; 321. (gains: taken as the MX-64(2.0)'s)
    _m("MX-106(2.0)", 321, X, 4096, 8.4, 45, 0.165, 12.0, gain_set=_XS, factory_gains=_MX2),
    # --- XL-320 (ROBOTIS MINI): Protocol 2.0 with its own table (xl320 page) -------------
    # 0.39 N m at 7.4 V (1.1 A), 114 rpm at 7.4 V; 16.7 g; 350; 0..1023 over 0..300 deg;
    # Baud Rate(4) initial 3 = 1 Mbps; D Gain(27) 0, I Gain(28) 0, P Gain(29) 32.
    _m("XL-320", 350, XL320, 1024, 0.39, 114, 0.0167, 7.4, span_deg=300.0,
       gain_set="dynamixel_xl320", factory_gains=_dip(0, 0, 32), factory_baud=1_000_000),
    # --- Protocol 1.0 (e-Manual AX / MX pages) -------------------------------------------
    # AX-12A: 1.5 N m (12 V, 1.5 A), 59 rpm (12 V), 54.6 g; 0..300 deg in 1024 steps; 12.
    _m("AX-12A", 12, P1, 1024, 1.5, 59, 0.0546, 12.0, span_deg=300.0, gain_set=_AXS,
       factory_gains=_AX),
    # AX-18A: 1.8 N m (12 V, 2.2 A), 97 rpm (12 V), 55.9 g (54.5 g is the older AX-18F); 18.
    _m("AX-18A", 18, P1, 1024, 1.8, 97, 0.0559, 12.0, span_deg=300.0, gain_set=_AXS,
       factory_gains=_AX),
    # MX-28 (Protocol 1.0 firmware): 2.5 N m, 55 rpm at 12 V, 72 g; 4096 steps; 29; ships at
    # 57600 (Baud Rate(4) initial 34, unlike the AX's 1).
    _m("MX-28", 29, P1, 4096, 2.5, 55, 0.072, 12.0, gain_set=_MX1S, factory_gains=_MX1,
       factory_baud=57_600),
    # MX-64 (Protocol 1.0): 6.0 N m, 63 rpm at 12 V, 165 g; 310; 57600.
    _m("MX-64", 310, P1, 4096, 6.0, 63, 0.165, 12.0, gain_set=_MX1S, factory_gains=_MX1,
       factory_baud=57_600),
    # MX-106 (Protocol 1.0): 8.4 N m, 45 rpm at 12 V, 165 g; 320; 57600.
    _m("MX-106", 320, P1, 4096, 8.4, 45, 0.165, 12.0, gain_set=_MX1S, factory_gains=_MX1,
       factory_baud=57_600),
)}
