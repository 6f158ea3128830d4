"""The driver's tables (robot/bus/tables.py) against the emulator's own transcription of
the manuals (sim/emulator/control_tables.py, servo_status.py, servo_models.py): every
register the driver uses has the same address and size in both, the manuals' initial
values are served, and error bits, Bus Watchdog, return-delay units and servo models agree
(the error bits also with the manuals' tables written out here and the vendor SDKs)."""

from __future__ import annotations

import math

import pytest

from robot.bus import tables as driver
from robot.servo import models as driver_models
from sim.emulator import control_tables as manual
from sim.emulator import servo_models as models
from sim.emulator import servo_status as status
from sim.emulator.servo import EmulatedServo, ServoSpec


@pytest.mark.parametrize("family", sorted(driver.TABLES))
def test_every_driver_register_matches_the_manual(family: str) -> None:
    ours, theirs = driver.TABLES[family], manual.TABLES[family]
    for name, reg in ours.items():
        assert name in theirs, f"{family}: {name} is not in the manual's table"
        assert (reg.address, reg.size) == theirs[name][:2], f"{family}: {name}"


@pytest.mark.parametrize("family", sorted(driver_models.BAUD_CODES))
def test_driver_baud_codes_are_the_manuals(family: str) -> None:
    for code, baud in driver_models.BAUD_CODES[family].items():
        assert manual.BAUD_CODES[family][code] == baud


@pytest.mark.parametrize("family", sorted(manual.TABLES))
def test_manual_tables_do_not_overlap(family: str) -> None:
    owner: dict[int, str] = {}
    for name, e in manual.TABLES[family].items():
        assert e.access in ("R", "RW") and e.size in (1, 2, 4)
        for a in range(e.address, e.address + e.size):
            assert a not in owner, f"{name} overlaps {owner.get(a)} at {a}"
            owner[a] = name


def test_xl430_has_the_registers_the_issue_named_with_the_manuals_values() -> None:
    x = manual.DYNAMIXEL_X
    assert x["return_delay_time"] == (9, 1, "RW", 250)
    assert x["position_p_gain"] == (84, 2, "RW", 640)
    assert x["position_i_gain"] == (82, 2, "RW", 0)
    assert x["position_d_gain"] == (80, 2, "RW", 4000)
    assert x["pwm_limit"] == (36, 2, "RW", 885)
    assert x["protocol_type"] == (13, 1, "RW", 2)
    assert x["shutdown"] == (63, 1, "RW", 52)
    assert x["goal_velocity"][:3] == (104, 4, "RW")
    assert x["present_velocity"][:3] == (128, 4, "R")
    assert x["moving_status"][:3] == (123, 1, "R")
    assert x["indirect_address_1"] == (168, 2, "RW", 224)
    assert x["indirect_address_28"] == (222, 2, "RW", 251)
    assert x["indirect_data_1"] == (224, 1, "RW", 0)
    assert x["indirect_address_29"] == (578, 2, "RW", 634)
    assert x["indirect_data_56"] == (661, 1, "RW", 0)


def test_a_new_servo_holds_the_manuals_initial_values() -> None:
    for family, model, baud in (("dynamixel_x", "XL430-W250", 57600),
                                ("feetech_sts", "STS3215", 1_000_000)):
        servo = EmulatedServo(ServoSpec(1, model, 2048, 0, 4095, baud,
                                        manual.TABLES[family]["return_delay_time"].initial
                                        or 0), 0.0)
        for name, e in manual.TABLES[family].items():
            if e.initial is not None and name not in ("min_position_limit",
                                                      "max_position_limit",
                                                      "min_angle_limit", "max_angle_limit"):
                assert servo.get(name) == e.initial, f"{family}: {name}"


# --------------------------------------------------------------------------------------
# Status bits, watchdog, return delay and models: the driver's facts against the
# emulator's transcription (sim/emulator/servo_status.py, servo_models.py), and the error
# bits against the manuals' tables written out here and the vendor SDKs' constants.

#: Fault name -> bit mask, as printed: ROBOTIS e-Manual XL430-W250 "Hardware Error
#: Status(70)"; e-Manual "Protocol 1.0" status packet error byte; Feetech STS memory table
#: "Servo status(65)"; e-Manual XL-320 "Shutdown(18)" (bit 0 Overload, 1 OverHeating,
#: 2 Input Voltage; Hardware Error Status(50) holds them); Feetech SCSCL memory table "Servo
#: Status" (BIT0 voltage, BIT2 temperature, BIT5 load; the SCS15 manual's status byte).
MANUAL_ERROR_MASKS: dict[str, dict[str, int]] = {
    "dynamixel_x": {"voltage": 0x01, "overheating": 0x04, "encoder": 0x08,
                    "electrical_shock": 0x10, "overload": 0x20},
    "dynamixel_p1": {"voltage": 0x01, "angle_limit": 0x02, "overheating": 0x04,
                     "range": 0x08, "checksum": 0x10, "overload": 0x20, "instruction": 0x40},
    "feetech_sts": {"voltage": 0x01, "encoder": 0x02, "overheating": 0x04,
                    "overcurrent": 0x08, "overload": 0x20},
    "dynamixel_xl320": {"overload": 0x01, "overheating": 0x02, "voltage": 0x04},
    "feetech_scs": {"voltage": 0x01, "overheating": 0x04, "overload": 0x20},
}


def masks(bits: dict[int, str]) -> dict[str, int]:
    return {name: 1 << b for b, name in bits.items()}


@pytest.mark.parametrize("family", sorted(MANUAL_ERROR_MASKS))
def test_emulator_error_bits_are_the_manuals(family: str) -> None:
    assert masks(status.ERROR_BITS[family]) == MANUAL_ERROR_MASKS[family]


@pytest.mark.parametrize("family", sorted(MANUAL_ERROR_MASKS))
def test_driver_error_bits_agree_with_the_emulators(family: str) -> None:
    assert driver.ERROR_BITS[family] == status.ERROR_BITS[family]
    assert set(driver.ERROR_BITS) == set(status.ERROR_BITS)


def test_error_bits_match_the_vendor_sdks() -> None:
    import dynamixel_sdk.protocol1_packet_handler as p1
    import scservo_sdk as sts  # re-exports protocol_packet_handler's ERRBIT_*

    assert MANUAL_ERROR_MASKS["dynamixel_p1"] == {
        "voltage": p1.ERRBIT_VOLTAGE, "angle_limit": p1.ERRBIT_ANGLE,
        "overheating": p1.ERRBIT_OVERHEAT, "range": p1.ERRBIT_RANGE,
        "checksum": p1.ERRBIT_CHECKSUM, "overload": p1.ERRBIT_OVERLOAD,
        "instruction": p1.ERRBIT_INSTRUCTION}
    assert MANUAL_ERROR_MASKS["feetech_sts"] == {
        "voltage": sts.ERRBIT_VOLTAGE, "encoder": sts.ERRBIT_ANGLE,
        "overheating": sts.ERRBIT_OVERHEAT, "overcurrent": sts.ERRBIT_OVERELE,
        "overload": sts.ERRBIT_OVERLOAD}


def test_bus_watchdog_is_the_manuals_and_the_drivers() -> None:
    # XL430-W250 "Bus Watchdog(98)": unit 20 ms, 1..127 arms, 0 clears, -1 error, fw v38.
    wd = status.BUS_WATCHDOG["dynamixel_x"]
    assert wd is not None
    assert (wd.register, wd.unit_s, wd.steps, wd.off, wd.tripped, wd.min_firmware) == (
        "bus_watchdog", 0.020, (1, 127), 0, -1, 38)
    assert wd.range_s == pytest.approx((0.020, 2.54))
    assert manual.TABLES["dynamixel_x"][wd.register][:3] == (98, 1, "RW")
    assert wd.register in manual.DXL_SIGNED   # -1 reads back as -1
    assert set(driver.COMM_WATCHDOG) == set(status.BUS_WATCHDOG)
    for family, ours in status.BUS_WATCHDOG.items():
        theirs = driver.COMM_WATCHDOG[family]
        if ours is None or theirs is None:
            assert ours is theirs, family
            continue
        assert (theirs.register, theirs.unit_s, theirs.steps, theirs.off, theirs.tripped,
                theirs.min_firmware) == (ours.register, ours.unit_s, ours.steps, ours.off,
                                         ours.tripped, ours.min_firmware), family


def test_bus_watchdog_arming_and_deadline() -> None:
    wd = status.BUS_WATCHDOG["dynamixel_x"]
    assert wd is not None
    assert [v for v in (-2, -1, 0, 1, 127, 128) if wd.accepts(v)] == [0, 1, 127]
    assert wd.deadline(5, torque_on=True, heard=10.0) == pytest.approx(10.1)
    assert wd.deadline(5, torque_on=False, heard=10.0) is None
    assert wd.deadline(-1, torque_on=True, heard=10.0) is None
    assert wd.deadline(0, torque_on=True, heard=10.0) is None


def test_return_delay_units_are_2_us_and_the_drivers() -> None:
    # XL430 Return Delay Time(9), AX-12A Return Delay Time(5), STS Return delay(7), XL-320
    # Return Delay Time(5), SCS15 Return delay time(7): 2 us.
    assert status.RETURN_DELAY_UNIT_S == {"dynamixel_x": 2e-6, "dynamixel_p1": 2e-6,
                                          "feetech_sts": 2e-6, "dynamixel_xl320": 2e-6,
                                          "feetech_scs": 2e-6}
    assert driver.RETURN_DELAY_UNIT_S == status.RETURN_DELAY_UNIT_S


def test_protocol_families_are_the_drivers() -> None:
    assert models.PROTOCOL_FAMILIES == driver_models.BUS_FAMILIES
    assert models.PROTOCOL_FAMILY == {k: f[0] for k, f in driver_models.BUS_FAMILIES.items()}


def test_servo_models_agree_with_the_drivers() -> None:
    assert set(models.MODELS) == set(driver_models.MODELS)
    for name, ours in models.MODELS.items():
        theirs = driver_models.MODELS[name]
        assert (theirs.name, theirs.number, theirs.family, theirs.resolution) == (
            ours.name, ours.number, ours.family, ours.resolution), name
        assert theirs.span_deg == ours.span_deg, name
        assert theirs.no_load_speed == pytest.approx(ours.no_load_speed, rel=1e-12), name
        assert theirs.ticks_per_rad == pytest.approx(ours.ticks_per_rad, rel=1e-12), name
        # LX servos have commands, no control table (tests/test_lx_tables.py)
        assert ours.family in {*manual.TABLES, "lx"}, name


@pytest.mark.parametrize(("name", "number", "resolution", "span_deg", "rpm"), [
    # e-Manual spec tables: model number, positions over the span, no-load rev/min.
    ("XL430-W250", 1060, 4096, 360.0, 57.0), ("AX-12A", 12, 1024, 300.0, 59.0),
    ("MX-28", 29, 4096, 360.0, 55.0),
    # Feetech STS3215 at 7.4 V: 0.222 s/60 deg = 60 / (6 * 0.222) rev/min.
    ("STS3215", 777, 4096, 360.0, 60.0 / (6 * 0.222)),
])
def test_servo_models_match_the_datasheets(name: str, number: int, resolution: int,
                                           span_deg: float, rpm: float) -> None:
    m = models.MODELS[name]
    assert (m.number, m.resolution, m.span_deg) == (number, resolution, span_deg)
    assert m.no_load_speed * 60 / (2 * math.pi) == pytest.approx(rpm, rel=1e-9)
    assert m.ticks_per_rad == pytest.approx(resolution / (span_deg * math.pi / 180))


# --------------------------------------------------------------------------------------
# Gain registers: the driver's (robot/bus/tables.py GAIN_REGISTERS, robot/servo/models.py
# factory values) against the emulator's transcription of each model's manual table.


#: The models with a control table (the LX servos have commands instead, and no gains).
TABLE_MODELS = sorted(n for n, m in driver_models.MODELS.items() if m.family in manual.TABLES)


@pytest.mark.parametrize("name", TABLE_MODELS)
def test_gain_registers_and_factory_values_match_the_models_manual_table(name: str) -> None:
    ours = driver_models.MODELS[name]
    emulated = models.MODELS[name]
    table = manual.TABLES[emulated.layout]
    for gain, reg in driver.GAIN_REGISTERS[ours.gain_set].items():
        assert gain in table, f"{name}: {gain} is not in its manual table"
        assert (reg.address, reg.size) == table[gain][:2], f"{name}: {gain}"
        assert table[gain].access == "RW", f"{name}: {gain}"
    servo = EmulatedServo(ServoSpec(1, name, 2048, 0, ours.resolution - 1, 1_000_000), 0.0)
    assert {g: servo.get(g) for g in ours.factory_gains} == dict(ours.factory_gains), name


def test_sts_gains_live_in_eeprom_and_x_ax_mx_gains_in_ram() -> None:
    from robot.servo.gains import GAIN_SETS

    for name in TABLE_MODELS:
        m = models.MODELS[name]
        end = manual.EEPROM_END[m.layout]
        gain_set = GAIN_SETS[driver_models.MODELS[name].gain_set]
        for gain, g in gain_set.gains.items():
            in_eeprom = manual.TABLES[m.layout][gain].address < end
            assert in_eeprom == (g.memory == "eeprom"), (name, gain)


def test_mx28_table_has_pid_where_the_ax_has_compliance() -> None:
    mx, ax = manual.TABLES["dynamixel_mx1"], manual.TABLES["dynamixel_p1"]
    assert [mx[n][:2] for n in ("d_gain", "i_gain", "p_gain")] == [(26, 1), (27, 1), (28, 1)]
    assert [ax[n][:2] for n in ("cw_compliance_margin", "ccw_compliance_margin",
                                "cw_compliance_slope", "ccw_compliance_slope")] == [
        (26, 1), (27, 1), (28, 1), (29, 1)]
    assert not {"cw_compliance_slope", "ccw_compliance_slope"} & set(mx)
    assert (mx["p_gain"].initial, mx["baud_rate"].initial) == (32, 34)   # 34 = 57600
