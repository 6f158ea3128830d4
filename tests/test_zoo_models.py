"""The servos of issue 21 against the vendors' pages, written out here (never read from the
driver's or the emulator's tables): model numbers, positions over their span, datasheet
torque, speed, mass and voltage; the XL-320 and SCSCL control tables, their error bits,
byte order and baud codes; and every model's emulated table holding every register the
driver uses, at the driver's address.

Sources per row: the ROBOTIS e-Manual (ROBOTIS-GIT/emanual, _data/dxl_x_info.yml,
_data/dxl_mx_info.yml and the model pages), Feetech's datasheets / memory tables and
SCSCL.h / SMS_STS.h (robot/servo/models_feetech.py names each), Waveshare's SC09 page for
the SCS0009.
"""

from __future__ import annotations

import math

import pytest

from robot.bus import tables as driver
from robot.servo import models as driver_models
from sim.emulator import control_tables as manual
from sim.emulator import servo_models as emulated
from sim.emulator.servo import EmulatedServo, ServoSpec

KGCM = 0.0980665

# name: (model number, positions, span deg, no-load rev/min, stall N m, mass g, volts)
DATASHEETS: dict[str, tuple[int, int, float, float, float, float, float]] = {
    "XL-320": (350, 1024, 300.0, 114, 0.39, 16.7, 7.4),
    "XL330-M077": (1190, 4096, 360.0, 383, 0.215, 18, 5.0),
    "XL330-M288": (1200, 4096, 360.0, 103, 0.52, 18, 5.0),
    "XC330-M181": (1230, 4096, 360.0, 129, 0.60, 23, 5.0),
    "XC330-M288": (1240, 4096, 360.0, 81, 0.93, 23, 5.0),
    "XC330-T181": (1210, 4096, 360.0, 104, 0.76, 23, 11.1),
    "XC330-T288": (1220, 4096, 360.0, 65, 0.92, 23, 11.1),
    "XC430-W150": (1070, 4096, 360.0, 106, 1.6, 65, 12.0),     # 106, not 70 (XC430-W240)
    "XM430-W210": (1030, 4096, 360.0, 77, 3.0, 82, 12.0),
    "XM430-W350": (1020, 4096, 360.0, 46, 4.1, 82, 12.0),
    "XH430-W210": (1010, 4096, 360.0, 50, 2.5, 82, 12.0),
    "XH430-W350": (1000, 4096, 360.0, 30, 3.4, 82, 12.0),
    "XH430-V210": (1050, 4096, 360.0, 52, 2.6, 82, 24.0),
    "XH430-V350": (1040, 4096, 360.0, 31, 3.3, 82, 24.0),
    "XM540-W150": (1130, 4096, 360.0, 53, 7.3, 165, 12.0),
    "XM540-W270": (1120, 4096, 360.0, 30, 10.6, 165, 12.0),
    "2XL430-W250": (1090, 4096, 360.0, 57, 1.4, 98.2 / 2, 11.1),   # per axis
    "2XC430-W250": (1160, 4096, 360.0, 64, 1.8, 102 / 2, 12.0),
    "MX-28": (29, 4096, 360.0, 55, 2.5, 72, 12.0),
    "MX-64": (310, 4096, 360.0, 63, 6.0, 165, 12.0),
    "MX-106": (320, 4096, 360.0, 45, 8.4, 165, 12.0),
    "MX-28(2.0)": (30, 4096, 360.0, 55, 2.5, 72, 12.0),
    "MX-64(2.0)": (311, 4096, 360.0, 63, 6.0, 165, 12.0),
    "MX-106(2.0)": (321, 4096, 360.0, 45, 8.4, 165, 12.0),
    "AX-18A": (18, 1024, 300.0, 97, 1.8, 55.9, 12.0),
    "STS3215-12V": (777, 4096, 360.0, 60 / (6 * 0.222), 30 * KGCM, 55, 12.0),
    "STS3250": (2825, 4096, 360.0, 60 / (6 * 0.133), 4.90, 60, 12.0),
    "SCS0009": (1284, 1024, 300.0, 100, 2.3 * KGCM, 14, 6.0),
    "SCS15": (1295, 1024, 215.0, 65, 16.5 * KGCM, 56, 7.4),
}


@pytest.mark.parametrize("name", sorted(DATASHEETS))
def test_models_are_their_datasheets(name: str) -> None:
    number, positions, span, rpm, torque, grams, volts = DATASHEETS[name]
    ours, emu = driver_models.MODELS[name], emulated.MODELS[name]
    for m in (ours, emu):
        assert (m.number, m.resolution, m.span_deg) == (number, positions, span), name
        assert m.no_load_speed * 60 / (2 * math.pi) == pytest.approx(rpm, rel=1e-9), name
    assert ours.stall_torque == pytest.approx(torque, rel=1e-9)
    assert ours.mass == pytest.approx(grams / 1000, rel=1e-9)
    assert ours.nominal_voltage == volts


def test_every_model_the_issue_names_is_known() -> None:
    named = {"XL-320", "XL330-M288", "XL330-M077", "XM430-W350", "XM430-W210", "XM540-W270",
             "XM540-W150", "MX-28", "MX-64", "MX-106", "MX-28(2.0)", "MX-64(2.0)",
             "MX-106(2.0)", "2XL430-W250", "2XC430-W250", "SCS0009", "SCS15", "SCS40",
             "STS3032", "STS3046", "STS3250", "STS3215", "STS3215-12V"}
    assert named <= set(driver_models.MODELS) and named <= set(emulated.MODELS)
    assert {n for n in driver_models.MODELS if n.startswith(("XH430", "XC330"))} == {
        "XH430-W210", "XH430-W350", "XH430-V210", "XH430-V350", "XC330-M181", "XC330-M288",
        "XC330-T181", "XC330-T288"}
    assert [n for n, m in driver_models.MODELS.items() if m.axes == 2] == [
        "2XL430-W250", "2XC430-W250"]


def test_families_the_issue_adds() -> None:
    fam = {n: m.family for n, m in driver_models.MODELS.items()}
    assert fam["XL-320"] == "dynamixel_xl320"
    assert {fam[n] for n in ("SCS0009", "SCS15", "SCS40")} == {"feetech_scs"}
    assert {fam[n] for n in ("MX-28", "MX-64", "MX-106")} == {"dynamixel_p1"}
    assert {fam[n] for n in ("MX-28(2.0)", "MX-64(2.0)", "MX-106(2.0)")} == {"dynamixel_x"}


# e-Manual XL-320 control table: (address, size, access, initial).
XL320_PAGE = {
    "model_number": (0, 2, "R", 350), "firmware_version": (2, 1, "R", None),
    "id": (3, 1, "RW", 1), "baud_rate": (4, 1, "RW", 3), "return_delay_time": (5, 1, "RW", 250),
    "cw_angle_limit": (6, 2, "RW", 0), "ccw_angle_limit": (8, 2, "RW", 1023),
    "control_mode": (11, 1, "RW", 2), "temperature_limit": (12, 1, "RW", 65),
    "min_voltage_limit": (13, 1, "RW", 60), "max_voltage_limit": (14, 1, "RW", 90),
    "max_torque": (15, 2, "RW", 1023), "status_return_level": (17, 1, "RW", 2),
    "shutdown": (18, 1, "RW", 3), "torque_enable": (24, 1, "RW", 0), "led": (25, 1, "RW", 0),
    "d_gain": (27, 1, "RW", 0), "i_gain": (28, 1, "RW", 0), "p_gain": (29, 1, "RW", 32),
    "goal_position": (30, 2, "RW", None), "moving_speed": (32, 2, "RW", None),
    "torque_limit": (35, 2, "RW", None), "present_position": (37, 2, "R", None),
    "present_speed": (39, 2, "R", None), "present_load": (41, 2, "R", None),
    "present_voltage": (45, 1, "R", None), "present_temperature": (46, 1, "R", None),
    "registered": (47, 1, "R", 0), "moving": (49, 1, "R", 0),
    "hardware_error_status": (50, 1, "R", 0), "punch": (51, 2, "RW", 32),
}


def test_xl320_table_is_the_e_manuals() -> None:
    assert {n: tuple(e) for n, e in manual.TABLES["dynamixel_xl320"].items()} == XL320_PAGE
    for name, reg in driver.TABLES["dynamixel_xl320"].items():
        assert (reg.address, reg.size) == XL320_PAGE[name][:2], name
    codes = {0: 9600, 1: 57600, 2: 115200, 3: 1_000_000}      # XL-320 "Baud Rate(4)"
    assert driver_models.BAUD_CODES["dynamixel_xl320"] == codes
    assert manual.BAUD_CODES["dynamixel_xl320"] == codes


# Feetech SCSCL: address and size as SCSCL.h / the SCS15 manual print them.
SCS_PAGE = {"id": (5, 1), "baud_rate": (6, 1), "min_angle_limit": (9, 2),
            "max_angle_limit": (11, 2), "p_coefficient": (21, 1), "torque_enable": (40, 1),
            "goal_position": (42, 2), "goal_time": (44, 2), "goal_speed": (46, 2),
            "lock": (48, 1), "present_position": (56, 2), "present_speed": (58, 2),
            "present_load": (60, 2), "present_voltage": (62, 1),
            "present_temperature": (63, 1), "moving": (66, 1)}


def test_scs_table_is_feetechs_and_big_endian() -> None:
    for table in (manual.TABLES["feetech_scs"], driver.TABLES["feetech_scs"]):
        assert {n: tuple(table[n][:2]) for n in SCS_PAGE} == SCS_PAGE
    assert manual.TABLES["feetech_scs"]["end"].initial == 1        # END(2): 1 = big-endian
    assert driver.BYTE_ORDER["feetech_scs"] == "big"
    servo = EmulatedServo(ServoSpec(1, "SCS15", 300, 0, 1023, 1_000_000), 0.0)
    a = manual.TABLES["feetech_scs"]["present_position"].address
    assert servo.read(a, 2) == bytes([300 >> 8, 300 & 0xFF])       # high byte first


def test_feetech_baud_codes_5_to_7_are_feetechs() -> None:
    """Feetech's SMS_STS.h / SCSCL.h (SMS_STS_76800 5, _57600 6, _38400 7) and the memory
    tables ("38400 ~ 1 Mbps"): not LeRobot's 57600 / 38400 / 19200."""
    for family in ("feetech_sts", "feetech_scs"):
        for codes in (driver_models.BAUD_CODES[family], manual.BAUD_CODES[family]):
            assert (codes[5], codes[6], codes[7]) == (76_800, 57_600, 38_400)
            assert 19_200 not in codes.values()


#: Register renamed on the current-sensing X tables: 126 is Present Current there.
ALIASES = {"present_load": "present_current"}


@pytest.mark.parametrize("name", sorted(n for n, m in driver_models.MODELS.items()
                                        if m.family in driver.TABLES))
def test_each_models_table_holds_every_register_the_driver_uses(name: str) -> None:
    ours = driver_models.MODELS[name]
    table = manual.TABLES[emulated.MODELS[name].layout]
    # The family's table also lists the other gain set's registers (the AX's compliance
    # where an MX has PID, 26-29): a model has only its own.
    others = {n for g, regs in driver.GAIN_REGISTERS.items() if g != ours.gain_set
              for n in regs} - set(driver.GAIN_REGISTERS[ours.gain_set])
    for reg_name, reg in driver.TABLES[ours.family].items():
        if reg_name in others:
            continue
        entry = table.get(reg_name) or table.get(ALIASES.get(reg_name, ""))
        assert entry is not None, f"{name}: {reg_name}"
        assert (entry.address, entry.size) == (reg.address, reg.size), f"{name}: {reg_name}"


def test_factory_baud_is_each_models_table() -> None:
    """The MX series on Protocol 1.0 ships at 57600 (Baud Rate(4) initial 34), the AX at
    1 Mbps, the XL-320 at 1 Mbps (initial 3), the X series and MX on 2.0 at 57600."""
    from sim.emulator.chain_specs import factory_baud

    expected = {"MX-28": 57_600, "MX-64": 57_600, "MX-106": 57_600, "AX-12A": 1_000_000,
                "XL-320": 1_000_000, "MX-64(2.0)": 57_600, "XM430-W350": 57_600,
                "STS3215": 1_000_000, "SCS15": 1_000_000}
    for name, baud in expected.items():
        assert driver_models.factory_baud(driver_models.MODELS[name]) == baud, name
        assert factory_baud(driver_models.kind_of(driver_models.MODELS[name].family),
                            name) == baud, name


def test_docs_robots_md_lists_every_servo_once() -> None:
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "robots.md").read_text()
    table = text.split("## Supported servos", 1)[1].split("\n\n", 3)[2]
    names = [row.split("|")[1].strip() for row in table.splitlines()
             if row.startswith("| ") and not row.startswith("| servo")]
    assert sorted(names) == sorted(driver_models.MODELS)
