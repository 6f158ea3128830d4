"""The driver's control tables (robot/bus/tables.py) against the emulator's own
transcription of the manuals (sim/emulator/control_tables.py): every register the driver uses has
the same address and size in both, and the manuals' initial values are served."""

from __future__ import annotations

import pytest

from robot.bus import tables as driver
from robot.servo import models as driver_models
from sim.emulator import control_tables as manual
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
