"""The servo models the emulator can be, from the vendors' datasheets.

The emulator's own transcription (the driver's ``robot.servo.models.MODELS`` holds the same
facts; ``tests/test_emulator_tables.py`` makes the two agree). Only what the emulator uses:
the model number a ping reports, the family (which control table), the position
resolution and the angle it spans, and the no-load speed the horn travels at.
"""

from __future__ import annotations

from sim.emulator.servo_model import ServoModel, per_60deg, rpm
from sim.emulator.servo_models_more import MORE, XL330_INITIAL, XM_INITIAL

__all__ = ["MODELS", "ServoModel"]

#: ``Emulator(protocol)`` -> the control-table families its protocol speaks (the first is
#: the default chain's): Protocol 2.0 the X tables and the XL-320's, Feetech's the STS and
#: SCS tables.
PROTOCOL_FAMILIES: dict[str, tuple[str, ...]] = {
    "dynamixel": ("dynamixel_x", "dynamixel_xl320"), "dynamixel1": ("dynamixel_p1",),
    "feetech": ("feetech_sts", "feetech_scs"), "lx": ("lx",),
}
#: ``Emulator(protocol)`` -> its default control-table family.
PROTOCOL_FAMILY: dict[str, str] = {p: fams[0] for p, fams in PROTOCOL_FAMILIES.items()}

_rpm, _per_60deg = rpm, per_60deg

MODELS: dict[str, ServoModel] = {
    # ROBOTIS e-Manual XL430-W250: Model Number 1060; 4096 pulses/rev; no-load speed
    # 57 rev/min at 11.1 V.
    "XL430-W250": ServoModel("XL430-W250", 1060, "dynamixel_x", 4096, _rpm(57)),
    # ROBOTIS e-Manual XM430-W350: Model Number 1020; 4096 pulses/rev; 46 rev/min at 12 V;
    # RAM initial values Velocity I Gain(76) 1,920, Position D Gain(80) 0, Position P
    # Gain(84) 800 (the XL430 table's are 1,000 / 4,000 / 640).
    # Its table is the current-sensing X one (Current Limit(38) 1,193 [2.69 mA], Goal /
    # Present Current); Velocity Limit(44) 350, Temperature Limit 80, Max / Min Voltage
    # Limit 160 / 95.
    "XM430-W350": ServoModel("XM430-W350", 1020, "dynamixel_x", 4096, _rpm(46),
                             table="dynamixel_xm", initial=XM_INITIAL),
    # ROBOTIS e-Manual XC430-W150: Model Number 1070; 4096 pulses/rev; 106 rev/min at 12 V
    # (_data/dxl_x_info.yml; 70 is the XC430-W240's); RAM initial values Velocity I Gain
    # 1,920, Position D 0, Position P 460.
    "XC430-W150": ServoModel("XC430-W150", 1070, "dynamixel_x", 4096, _rpm(106), initial={
        "velocity_i_gain": 1920, "position_d_gain": 0, "position_p_gain": 460}),
    # ROBOTIS e-Manual XL330-M288-T: Model Number 1200; 4096 pulses/rev; 103 rev/min at 5 V;
    # its own table (control_tables_more: current sensing, PWM Slope, 20 indirect entries);
    # initial values Velocity I / P Gain 1,600 / 180, Position D 0 / I 0 / P 400, Current
    # Limit 1,750 [mA], Velocity Limit 445, Temperature Limit 70, Max / Min Voltage 70 / 35,
    # Shutdown 53.
    "XL330-M288": ServoModel("XL330-M288", 1200, "dynamixel_x", 4096, _rpm(103),
                             table="dynamixel_xl330", initial=XL330_INITIAL),
    # ROBOTIS e-Manual AX-12A: Model Number 12; 0..1023 over 0..300 deg (0.29 deg);
    # 59 rev/min at 12 V.
    "AX-12A": ServoModel("AX-12A", 12, "dynamixel_p1", 1024, _rpm(59), 300.0),
    # ROBOTIS e-Manual AX-18A: Model Number 18; 0..1023 over 300 deg; 97 rev/min at 12 V.
    "AX-18A": ServoModel("AX-18A", 18, "dynamixel_p1", 1024, _rpm(97), 300.0),
    # ROBOTIS e-Manual MX-28 (Protocol 1.0 firmware; the 2.0 firmware reports 30): Model
    # Number 29; 4096 steps/rev; 55 rev/min at 12 V.
    # Its own table (D/I/P Gain at 26/27/28: control_tables.DYNAMIXEL_MX1).
    "MX-28": ServoModel("MX-28", 29, "dynamixel_p1", 4096, _rpm(55), table="dynamixel_mx1"),
    # Feetech STS3215 (7.4 V): memory table Model(3-4) reads 777 (= 3 * 256 + 9); 4096
    # steps/rev (12-bit magnetic encoder, 0.088 deg/step); no-load 0.222 s/60 deg.
    "STS3215": ServoModel("STS3215", 777, "feetech_sts", 4096, _per_60deg(0.222)),
    # Feetech STS3250 (12 V) datasheet: 4096 steps/rev; no-load 0.133 s/60 deg. Model 2825
    # (= 11 * 256 + 9) as lerobot's Feetech table lists it.
    "STS3250": ServoModel("STS3250", 2825, "feetech_sts", 4096, _per_60deg(0.133)),
    # Feetech STS3032 (6 V): 4096 steps/rev; no-load 0.1 s/60 deg. Model 1288 (= 5 * 256 +
    # 8) is the value the driver lists; no Feetech page here prints it.
    "STS3032": ServoModel("STS3032", 1288, "feetech_sts", 4096, _per_60deg(0.1)),
    # HiWonder/LewanSoul LX (sim/emulator/lx_servo.py): positions 0..1000 over 0..240 deg,
    # 0.24 deg each (1001 positions spanning 240.24 deg at that pitch); no model number on
    # the wire (the number is the driver's label). No-load speed: LX-16A 0.16 s/60 deg at
    # 7.4 V (LewanSoul spec); LX-224 0.20 s/60 deg at 7.4 V and LX-224HV 0.18 s/60 deg at
    # 11.1 V (HiWonder listings).
    "LX-16A": ServoModel("LX-16A", 16, "lx", 1001, _per_60deg(0.16), 240.24),
    "LX-224": ServoModel("LX-224", 224, "lx", 1001, _per_60deg(0.20), 240.24),
    "LX-224HV": ServoModel("LX-224HV", 2240, "lx", 1001, _per_60deg(0.18), 240.24),
    **MORE,
}
