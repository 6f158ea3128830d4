"""The BNO055 driver through the real adafruit library, at the wire: a fake BNO055 on a
pty (sim/emulator/bno055.py, written from the datasheet) holds values the tests set, the
driver must read them back within one LSB; faults end in one ImuError line naming the
port, never a hang."""

from __future__ import annotations

import math
import time
from collections.abc import Iterator

import pytest
from waiting import wait_for

from robot.imu import ImuConfig, ImuError, open_imu
from robot.imu.frames import quat_from_rpy
from sim.emulator.bno055 import P0, FakeBno055

GYRO_LSB = math.radians(1 / 16)   # 16 LSB per dps (datasheet Table 3-22)
ACCEL_LSB = 1 / 100               # 100 LSB per m/s^2 (Table 3-17)
QUAT_LSB = 2.0 ** -14             # Table 3-31
IMU_MODE = 0x08                   # OPR_MODE IMU fusion (Table 3-5)


@pytest.fixture
def dev() -> Iterator[FakeBno055]:
    with FakeBno055() as d:
        yield d


def config(dev: FakeBno055, **kw: object) -> ImuConfig:
    return ImuConfig(kind="bno055", port=dev.path, **kw)  # type: ignore[arg-type]


def test_reads_the_values_set_in_the_device(dev: FakeBno055) -> None:
    quat = quat_from_rpy(0.1, -0.25, 0.7)
    dev.set_motion(gyro=(0.1, -0.2, 0.3), accel=(0.5, -0.25, 9.81), quat=quat)
    with open_imu(config(dev)) as imu:
        assert dev.register("OPR_MODE") == IMU_MODE     # accel + gyro fusion, no magnetometer
        assert dev.register("UNIT_SEL") & 0x03 == 0     # m/s^2 and dps, as the library assumes
        t0 = time.monotonic()
        s = imu.read()
    assert t0 <= s.t <= time.monotonic()
    assert s.gyro == pytest.approx((0.1, -0.2, 0.3), abs=GYRO_LSB)
    assert s.accel == pytest.approx((0.5, -0.25, 9.81), abs=ACCEL_LSB)
    assert s.quat is not None
    # Normalising the quantised quaternion moves each part by at most ~one more LSB.
    assert s.quat == pytest.approx(quat, abs=2 * QUAT_LSB)
    assert not imu.is_open


def test_mounting_rotates_into_the_torso_frame(dev: FakeBno055) -> None:
    """A chip mounted upside down (roll 180): its z reads -g when the robot stands."""
    dev.set_motion(gyro=(0.1, 0.2, 0.3), accel=(0.0, 0.0, -9.81))
    with open_imu(config(dev, mount_rpy_deg=(180.0, 0.0, 0.0))) as imu:
        s = imu.read()
    assert s.accel == pytest.approx((0.0, 0.0, 9.81), abs=ACCEL_LSB)
    assert s.gyro == pytest.approx((0.1, -0.2, -0.3), abs=GYRO_LSB)


def test_no_fusion_output_yet_is_no_quaternion(dev: FakeBno055) -> None:
    dev.set_motion(quat=(0.0, 0.0, 0.0, 0.0))
    with open_imu(config(dev)) as imu:
        assert imu.read().quat is None


#: The library's tries per register read (adafruit_bno055 ``BNO055_UART._read_register``
#: gives up after three requests): a silent chip costs at most this many requests, so a
#: read gives up rather than hangs, judged by what reached the chip, not by the clock.
LIBRARY_TRIES = 3


def one_line_error(imu_config: ImuConfig) -> str:
    with pytest.raises(ImuError) as e:
        with open_imu(imu_config) as imu:
            imu.read()
    text = str(e.value)
    assert "\n" not in text and imu_config.port in text
    return text


def test_silent_device_is_a_timeout_naming_the_port(dev: FakeBno055) -> None:
    dev.silent = True
    text = one_line_error(config(dev))
    assert wait_for(dev.drained)
    assert 1 <= dev.requests <= LIBRARY_TRIES   # the chip-id read, tried and given up
    assert f"bno055 on {dev.path}: opening: no reply within 0.3 s at 115200 baud" in text
    assert "PS1 is high and PS0 low" in text


def test_bad_chip_id() -> None:
    with FakeBno055(chip_id=0x33) as other:
        text = one_line_error(config(other))
    assert "not a BNO055" in text and "0x33" in text and "0xa0" in text


def test_error_status_is_named(dev: FakeBno055) -> None:
    dev.read_status = 0x07
    text = one_line_error(config(dev))
    assert "answered error 0x07 BUS_OVER_RUN_ERROR" in text


def test_faults_after_open_fail_the_read_not_hang(dev: FakeBno055) -> None:
    with open_imu(config(dev)) as imu:
        dev.read_status = 0x02
        with pytest.raises(ImuError, match=r"reading: the chip answered error 0x02 READ_FAIL"):
            imu.read()
        dev.read_status = None
        imu.read()
        dev.silent = True
        assert wait_for(dev.drained)
        before = dev.requests
        with pytest.raises(ImuError, match="reading: no reply within 0.3 s"):
            imu.read()
        assert wait_for(dev.drained)   # the unanswered requests were taken while silent
        assert 1 <= dev.requests - before <= LIBRARY_TRIES   # gave up on the first register
        dev.silent = False
        assert imu.read().accel[2] == pytest.approx(9.81, abs=ACCEL_LSB)  # recovers


def test_missing_port_and_closed_reads() -> None:
    cfg = ImuConfig(kind="bno055", port="/dev/does-not-exist-imu")
    text = one_line_error(cfg)
    assert "cannot open the port" in text
    with pytest.raises(ImuError, match="not open"):
        open_imu(cfg).read()


def test_fake_follows_the_datasheet(dev: FakeBno055) -> None:
    """The fake itself: page 1 is configuration and writable only in CONFIGMODE; data
    registers read zero in CONFIGMODE; UNIT_SEL rps gives 900 LSB per rad/s."""
    import serial

    with serial.Serial(dev.path, 115200, timeout=0.5) as port:
        def ask(frame: bytes, n: int) -> bytes:
            port.write(frame)
            return bytes(port.read(n))

        dev.set_motion(gyro=(1.0, 0.0, 0.0))
        assert ask(bytes([0xAA, 0x01, P0["CHIP_ID"], 1]), 3) == bytes([0xBB, 1, 0xA0])
        assert ask(bytes([0xAA, 0x01, P0["GYR_DATA"], 2]), 4) == bytes([0xBB, 2, 0, 0])
        assert ask(bytes([0xAA, 0x00, P0["UNIT_SEL"], 1, 0x02]), 2) == bytes([0xEE, 0x01])
        assert ask(bytes([0xAA, 0x00, P0["OPR_MODE"], 1, IMU_MODE]), 2) == bytes([0xEE, 0x01])
        assert ask(bytes([0xAA, 0x01, P0["GYR_DATA"], 2]), 4) == bytes([0xBB, 2, 0x84, 0x03])
        assert ask(bytes([0xAA, 0x00, P0["PAGE_ID"], 1, 1]), 2) == bytes([0xEE, 0x01])
        assert ask(bytes([0xAA, 0x00, 0x08, 1, 0x0C]), 2) == bytes([0xEE, 0x03])
        assert ask(bytes([0xAA, 0x00, P0["PAGE_ID"], 1, 0]), 2) == bytes([0xEE, 0x01])
        assert ask(bytes([0xAA, 0x00, P0["CHIP_ID"], 1, 0]), 2) == bytes([0xEE, 0x05])
        assert ask(bytes([0x55]), 2) == bytes([0xEE, 0x06])
        assert ask(bytes([0xAA, 0x01, 0x7F, 2]), 2) == bytes([0xEE, 0x04])
