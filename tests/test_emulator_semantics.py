"""Register semantics other servo libraries depend on, through the real vendor SDKs.

Homing offset, operating modes (velocity, extended position, PWM, wheel, step), STS
re-centring with Torque Enable = 128, and present load / PWM from the motor state. Every
address, unit and formula is written out here from the manuals (ROBOTIS e-Manual
XL430-W250 and AX-12A control tables, Feetech STS memory table), not taken from the
emulator's tables; the expected values are computed here from the manuals' relations.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest
import sdk_link
from sdk_link import ok
from sdk_timeouts import allow_slow_replies
from waiting import wait_for

from sim.emulator.chain import Emulator

BAUD = 1_000_000
# XL430-W250 (e-Manual): addresses
X_MODE, X_HOMING, X_VEL_LIMIT, X_PWM_LIMIT, X_TORQUE = 11, 20, 44, 36, 64
X_P_GAIN, X_GOAL_PWM, X_GOAL_VEL, X_PROFILE_VEL, X_GOAL = 84, 100, 104, 112, 116
X_MOVING = 122
X_PRESENT_PWM, X_LOAD, X_PRESENT_VEL, X_PRESENT = 124, 126, 128, 132
X_ERR_RANGE, X_ERR_LIMIT = 4, 6
X_VEL_UNIT_TPS = 0.229 * 4096 / 60          # 0.229 rev/min in ticks/s
# STS3215 (Feetech memory table)
S_PHASE, S_OFFSET, S_MODE, S_TORQUE, S_GOAL, S_GOAL_TIME, S_SPEED = 18, 31, 33, 40, 42, 44, 46
S_LOCK, S_PRESENT, S_PRESENT_SPEED, S_LOAD = 55, 56, 58, 60
S_MAX_ACC = 85


@pytest.fixture(autouse=True)
def patient_sdks(monkeypatch: pytest.MonkeyPatch) -> None:
    allow_slow_replies(monkeypatch)


def served(protocol: str) -> Iterator[tuple[Emulator, Any, Any]]:
    yield from sdk_link.served(protocol, [1], BAUD)


@pytest.fixture
def dx() -> Iterator[tuple[Emulator, Any, Any]]:
    yield from served("dynamixel")


@pytest.fixture
def st() -> Iterator[tuple[Emulator, Any, Any]]:
    yield from served("feetech")


def s32(v: int) -> int:
    return v - (1 << 32) if v >= 1 << 31 else v


def s16(v: int) -> int:
    return v - (1 << 16) if v >= 1 << 15 else v


def sign_magnitude(value: int, bit: int) -> int:
    return abs(value) | (1 << bit if value < 0 else 0)


def from_sign_magnitude(raw: int, bit: int) -> int:
    magnitude = raw & ((1 << bit) - 1)
    return -magnitude if raw >> bit & 1 else magnitude


# ------------------------------------------------------------------ Dynamixel X
def test_x_homing_offset_shifts_present_and_goal(dx: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = dx
    assert s32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT))) == 2048
    assert ph.write4ByteTxRx(port, 1, X_HOMING, 1000) == (0, 0)
    assert s32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT))) == 2048 + 1000   # actual + offset
    assert ph.write4ByteTxRx(port, 1, X_HOMING, (-500) & 0xFFFFFFFF) == (0, 0)
    assert s32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT))) == 2048 - 500
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 1) == (0, 0)
    assert ph.write4ByteTxRx(port, 1, X_HOMING, 0) == (0, 7)      # EEPROM: torque on
    assert ph.write4ByteTxRx(port, 1, X_GOAL, 1748) == (0, 0)     # the goal's frame too
    assert wait_for(lambda: s32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT))) == 1748)
    assert emu.registers(1)["moving"] == 0


def test_x_velocity_mode_turns_past_one_turn(dx: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = dx
    assert ph.write1ByteTxRx(port, 1, X_MODE, 1) == (0, 0)             # velocity control
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 1) == (0, 0)
    limit = ok(ph.read4ByteTxRx(port, 1, X_VEL_LIMIT))
    assert ph.write4ByteTxRx(port, 1, X_GOAL_VEL, limit + 1) == (0, X_ERR_LIMIT)
    assert ph.write4ByteTxRx(port, 1, X_GOAL_VEL, 200) == (0, 0)
    t0 = time.monotonic()
    assert wait_for(lambda: s32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT))) > 4096 + 2048)
    elapsed = time.monotonic() - t0
    assert s32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT_VEL))) == 200
    assert elapsed >= 4096 / (200 * X_VEL_UNIT_TPS) * 0.9          # not faster than asked
    assert ph.write4ByteTxRx(port, 1, X_GOAL_VEL, (-200) & 0xFFFFFFFF) == (0, 0)
    assert s32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT_VEL))) == -200


def test_x_extended_position_and_pwm_modes(dx: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = dx
    assert ph.write1ByteTxRx(port, 1, X_MODE, 0) == (0, X_ERR_RANGE)   # XL430: no current
    assert ph.write1ByteTxRx(port, 1, X_MODE, 4) == (0, 0)             # extended position
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 1) == (0, 0)
    assert ph.write4ByteTxRx(port, 1, X_GOAL, (-3000) & 0xFFFFFFFF) == (0, 0)
    assert wait_for(lambda: s32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT))) == -3000)
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 0) == (0, 0)
    assert ph.write1ByteTxRx(port, 1, X_MODE, 16) == (0, 0)            # PWM control
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 1) == (0, 0)
    limit = ok(ph.read2ByteTxRx(port, 1, X_PWM_LIMIT))
    assert ph.write2ByteTxRx(port, 1, X_GOAL_PWM, limit + 1) == (0, X_ERR_LIMIT)
    assert ph.write2ByteTxRx(port, 1, X_GOAL_PWM, 442) == (0, 0)       # 50 % of 885
    assert wait_for(lambda: s32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT))) > -3000 + 100)
    assert s16(ok(ph.read2ByteTxRx(port, 1, X_PRESENT_PWM))) == 442
    # Duty 442/885 on a free horn: that share of the no-load speed (XL430: 57 rev/min).
    assert s32(ok(ph.read4ByteTxRx(port, 1, X_PRESENT_VEL))) == round(442 / 885 * 57 / 0.229)


def test_x_present_load_and_pwm_follow_the_motor(dx: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = dx
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 1) == (0, 0)
    assert ok(ph.read2ByteTxRx(port, 1, X_LOAD)) == 0                  # holding, free
    assert ph.write4ByteTxRx(port, 1, X_PROFILE_VEL, 100) == (0, 0)    # 100 x 0.229 rev/min
    assert ph.write4ByteTxRx(port, 1, X_GOAL, 2048 + 1500) == (0, 0)
    # Moving(122), Moving Status(123), Present PWM(124) in one read: the duty that holds
    # 22.9 rev/min on a free horn is that share of the no-load 57 rev/min.
    snapshot = ok(ph.read4ByteTxRx(port, 1, X_MOVING))
    assert snapshot & 0xFF == 1 and s16(snapshot >> 16) == round(100 * 0.229 / 57 * 885)
    # Arrived and at rest: Present Position can read the goal (rounded) one emulator step
    # before the horn stops, so wait for both rather than read the duty on arrival.
    assert wait_for(lambda: ok(ph.read4ByteTxRx(port, 1, X_PRESENT)) == 3548
                    and ok(ph.read2ByteTxRx(port, 1, X_PRESENT_PWM)) == 0)
    emu.set_faults(stuck_ids=[1])                                      # a jammed horn
    assert ph.write4ByteTxRx(port, 1, X_GOAL, 3548 - 20) == (0, 0)
    p = ok(ph.read2ByteTxRx(port, 1, X_P_GAIN))
    duty = p / 128 * -20 / 885                 # e-Manual: KPP = P / 128 of PWM 885
    assert s16(ok(ph.read2ByteTxRx(port, 1, X_PRESENT_PWM))) == round(duty * 885)
    assert s16(ok(ph.read2ByteTxRx(port, 1, X_LOAD))) == round(duty * 1000)   # 0.1 %


# ------------------------------------------------------------------ Feetech STS
def test_sts_offset_shifts_present_and_goal(st: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = st
    assert ph.write2ByteTxRx(port, 1, S_OFFSET, 1000) == (0, 0)
    assert ok(ph.read2ByteTxRx(port, 1, S_PRESENT)) == 2048 - 1000       # raw - offset
    assert ph.write2ByteTxRx(port, 1, S_OFFSET, sign_magnitude(-100, 11)) == (0, 0)
    assert ok(ph.read2ByteTxRx(port, 1, S_PRESENT)) == 2148
    assert ph.write2ByteTxRx(port, 1, S_OFFSET, 2047) == (0, 0)
    assert ok(ph.read2ByteTxRx(port, 1, S_PRESENT)) == 1               # 2048 - 2047
    assert ph.write2ByteTxRx(port, 1, S_OFFSET, sign_magnitude(-2047, 11)) == (0, 0)
    assert ok(ph.read2ByteTxRx(port, 1, S_PRESENT)) == (2048 + 2047) % 4096
    assert ph.write2ByteTxRx(port, 1, S_OFFSET, 1000) == (0, 0)
    assert ph.write2ByteTxRx(port, 1, S_GOAL, 1148) == (0, 0)          # horn to 2148
    assert wait_for(lambda: ok(ph.read2ByteTxRx(port, 1, S_PRESENT)) == 1148)


def test_sts_torque_128_centres_and_the_offset_survives_power(
        st: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = st
    emu.set_register(1, "present_position", 3000)          # turned by hand to raw 3000
    assert ph.write1ByteTxRx(port, 1, S_TORQUE, 128) == (0, 0)
    assert ok(ph.read2ByteTxRx(port, 1, S_PRESENT)) == 2048
    assert ok(ph.read2ByteTxRx(port, 1, S_OFFSET)) == 3000 - 2048      # present = raw - ofs
    emu.set_register(1, "present_position", 2048 - 1000)  # horn by hand to raw 2000
    assert ok(ph.read2ByteTxRx(port, 1, S_PRESENT)) == 1048
    assert ph.write1ByteTxRx(port, 1, S_TORQUE, 128) == (0, 0)
    assert ok(ph.read2ByteTxRx(port, 1, S_OFFSET)) == sign_magnitude(2000 - 2048, 11)
    assert ok(ph.read1ByteTxRx(port, 1, S_LOCK)) == 1                  # EEPROM locked
    emu.plug(None)
    emu.plug_all()                                                      # a power cycle
    assert ok(ph.read2ByteTxRx(port, 1, S_OFFSET)) == sign_magnitude(-48, 11)
    assert ok(ph.read2ByteTxRx(port, 1, S_PRESENT)) == 2048
    assert ph.write1ByteTxRx(port, 1, S_TORQUE, 2) == (0, 0)            # ignored: no such
    assert ok(ph.read1ByteTxRx(port, 1, S_TORQUE)) == 0


def test_sts_wheel_mode_spins_by_goal_speed(st: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = st
    assert ph.write1ByteTxRx(port, 1, S_MODE, 1) == (0, 0)              # constant speed
    assert ph.write2ByteTxRx(port, 1, S_SPEED, sign_magnitude(-700, 15)) == (0, 0)
    assert ok(ph.read1ByteTxRx(port, 1, S_TORQUE)) == 1                 # the speed drives
    assert ok(ph.read2ByteTxRx(port, 1, S_PRESENT_SPEED)) == sign_magnitude(-700, 15)
    seen: set[int] = set()

    def wrapped() -> bool:            # single-turn feedback: 0..4095 while it turns
        seen.add(ok(ph.read2ByteTxRx(port, 1, S_PRESENT)))
        return any(p > 3500 for p in seen) and any(p < 2000 for p in seen)
    assert wait_for(wrapped)
    assert all(0 <= p < 4096 for p in seen)
    assert ok(ph.read2ByteTxRx(port, 1, S_LOAD)) > 0                    # duty reported
    assert ph.write1ByteTxRx(port, 1, S_TORQUE, 0) == (0, 0)
    assert ok(ph.read2ByteTxRx(port, 1, S_PRESENT_SPEED)) == 0


def test_sts_pwm_and_step_modes(st: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = st
    assert ph.write1ByteTxRx(port, 1, S_MODE, 2) == (0, 0)              # PWM open loop
    assert ph.write2ByteTxRx(port, 1, S_GOAL_TIME, 500) == (0, 0)       # 50 % duty
    assert ok(ph.read2ByteTxRx(port, 1, S_LOAD)) == 500                 # 0.1 % of duty
    no_load = 4096 / (6 * 0.222)     # STS3215: 0.222 s per 60 deg [ticks/s]
    assert ok(ph.read2ByteTxRx(port, 1, S_PRESENT_SPEED)) == round(0.5 * no_load)
    assert ph.write1ByteTxRx(port, 1, S_TORQUE, 0) == (0, 0)
    assert ph.write1ByteTxRx(port, 1, S_MODE, 3) == (0, 0)              # step mode
    assert ph.write1ByteTxRx(port, 1, S_PHASE, 0x10) == (0, 0)          # full-angle feedback
    start = from_sign_magnitude(ok(ph.read2ByteTxRx(port, 1, S_PRESENT)), 15)

    def present(steps: int) -> bool:
        return from_sign_magnitude(ok(ph.read2ByteTxRx(port, 1, S_PRESENT)), 15) == (
            start + steps)
    assert ph.write2ByteTxRx(port, 1, S_GOAL, 3000) == (0, 0)           # 3000 steps more
    assert wait_for(lambda: present(3000))
    assert ph.write2ByteTxRx(port, 1, S_GOAL, 3000) == (0, 0)           # and again
    assert wait_for(lambda: present(6000))
    assert ph.write2ByteTxRx(port, 1, S_GOAL, sign_magnitude(-6000, 15)) == (0, 0)
    assert wait_for(lambda: present(0))
    assert emu.registers(1)["moving"] == 0


def test_sts_factory_registers_read_back(st: tuple[Emulator, Any, Any]) -> None:
    _, port, ph = st
    for address, value in zip(range(80, 87), (3, 20, 1, 0, 200, 254, 5), strict=True):
        assert ph.write1ByteTxRx(port, 1, address, value) == (0, 0)
        assert ok(ph.read1ByteTxRx(port, 1, address)) == value, address
    assert ok(ph.read1ByteTxRx(port, 1, S_MAX_ACC)) == 254


# ------------------------------------------------------------------ Dynamixel AX (1.0)
@pytest.fixture
def ax() -> Iterator[tuple[Emulator, Any, Any]]:
    yield from served("dynamixel1")


def test_ax_wheel_mode_by_angle_limits(ax: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = ax
    assert ph.write2ByteTxRx(port, 1, 6, 0) == (0, 0)     # CW Angle Limit
    assert ph.write2ByteTxRx(port, 1, 8, 0) == (0, 0)     # CCW Angle Limit: wheel
    assert ph.write1ByteTxRx(port, 1, 24, 1) == (0, 0)    # Torque Enable
    assert ph.write2ByteTxRx(port, 1, 32, 1024 + 512) == (0, 0)   # CW, 512 of 1023
    # Present Speed(38) in wheel mode: the output share (0-1023), bit 10 = CW.
    assert ok(ph.read2ByteTxRx(port, 1, 38)) == 1024 + 512
    start = ok(ph.read2ByteTxRx(port, 1, 36))
    assert wait_for(lambda: ok(ph.read2ByteTxRx(port, 1, 36)) != start)
    assert emu.registers(1)["moving"] == 1


def test_x_bus_watchdog_stops_a_velocity_mode_servo(dx: tuple[Emulator, Any, Any]) -> None:
    emu, port, ph = dx
    assert ph.write1ByteTxRx(port, 1, X_MODE, 1) == (0, 0)
    assert ph.write1ByteTxRx(port, 1, X_TORQUE, 1) == (0, 0)
    assert ph.write4ByteTxRx(port, 1, X_GOAL_VEL, 100) == (0, 0)
    assert ph.write1ByteTxRx(port, 1, 98, 1) == (0, 0)     # Bus Watchdog(98): 20 ms
    # e-Manual: silent past the setting, the servo stops and the register reads -1.
    assert wait_for(lambda: emu.registers(1)["bus_watchdog"] == -1)
    regs = emu.registers(1)
    assert regs["present_velocity"] == 0 and regs["moving"] == 0
