"""Bosch BNO055 over UART, through adafruit-circuitpython-bno055 (``BNO055_UART``) on a
pyserial port (a Raspberry Pi's serial pins, /dev/serial0, or a USB-serial adapter).

``open()`` opens the port at 115200 baud; the library checks the chip id, resets the chip
(~0.7 s) and configures it; the driver then selects the IMU fusion mode (accelerometer +
gyro fusion, relative heading: the servos' magnets and currents would disturb the
magnetometer that NDOF mode uses). Units are the chip's defaults after reset (UNIT_SEL 0:
m/s^2, dps which the library turns into rad/s). ``read()`` reads gyro, accelerometer and
quaternion (three register reads) and rotates them into the torso frame with the mount.

Every failure is one ImuError line naming the port and a fix; a read gives up after
``READ_GIVE_UP_S`` (the library's own per-reply timeouts), it never hangs.
"""

from __future__ import annotations

import math
import re
import struct
import time
from collections.abc import Callable
from typing import Any

from robot.config.imu_file import ImuConfig
from robot.imu.base import Imu, ImuError, ImuSample, Quat
from robot.imu.bno055_tables import (
    CHIP_ID,
    READ_GIVE_UP_S,
    UART_BAUD,
    UART_STATUS,
    UART_STATUS_FIX,
)
from robot.imu.frames import Mount

#: pyserial's own timeouts: the library reads only what has arrived, so these only bound
#: a write to a stuck adapter [s].
WRITE_TIMEOUT_S = 0.1
WIRING = ("check the wiring (its TX to the adapter's RX and back, GND), that PS1 is high "
          "and PS0 low (UART mode) and that it has 3.3 V")
INSTALL = "pip install 'biped[bno055]'"


class _Uart:
    """What ``BNO055_UART`` talks to (read/write/in_waiting/baudrate), on a pyserial port.

    Each transaction is one request and its reply, so a request first drops any bytes
    left from an earlier reply that came too late (otherwise they would be taken for the
    answer to this one)."""

    def __init__(self, port: Any) -> None:
        self._port = port

    @property
    def baudrate(self) -> int:
        return int(self._port.baudrate)

    @baudrate.setter
    def baudrate(self, value: int) -> None:
        self._port.baudrate = value

    @property
    def in_waiting(self) -> int:
        return int(self._port.in_waiting)

    def read(self, n: int) -> bytes:
        return bytes(self._port.read(n))

    def write(self, data: bytes) -> int | None:
        self._port.reset_input_buffer()
        written: int | None = self._port.write(data)
        return written


class Bno055Imu(Imu):
    """A BNO055 on serial port ``config.port``; ``clock`` stamps samples [s] (default
    time.monotonic, the streamer's wall clock)."""

    kind = "bno055"

    def __init__(self, config: ImuConfig, *,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.config = config
        self.port = config.port
        self._mount = Mount.from_rpy_deg(config.mount_rpy_deg)
        self._clock = clock
        self._serial: Any = None
        self._sensor: Any = None

    @property
    def is_open(self) -> bool:
        return self._sensor is not None

    def open(self) -> None:
        if self._sensor is not None:
            return
        try:
            import adafruit_bno055
            import serial
        except ImportError as e:
            raise ImuError(f"bno055: cannot import its library ({e}); {INSTALL}") from e
        try:
            port = serial.Serial(self.port, UART_BAUD, timeout=READ_GIVE_UP_S,
                                 write_timeout=WRITE_TIMEOUT_S)
        except (OSError, ValueError) as e:
            raise ImuError(f"bno055 on {self.port}: cannot open the port ({_reason(e)}); "
                           "check the path (`biped find-port`) and that you may use it "
                           "(group dialout)") from e
        try:
            sensor = adafruit_bno055.BNO055_UART(_Uart(port))
            sensor.mode = adafruit_bno055.IMUPLUS_MODE
        except BaseException as e:
            port.close()
            if isinstance(e, Exception):
                raise self._error(e, "opening") from e
            raise
        self._serial, self._sensor = port, sensor

    def close(self) -> None:
        if self._serial is not None:
            try:
                self._serial.close()
            except OSError:
                pass   # an unplugged adapter: nothing left to close
        self._serial = self._sensor = None

    def read(self) -> ImuSample:
        """Gyro [rad/s], specific force [m/s^2] and fused quaternion, in the torso frame
        (quat None until the chip's fusion has started: it reports all zeros)."""
        sensor = self._sensor
        if sensor is None:
            raise ImuError(f"bno055 on {self.port}: not open; call open() (or use `with`)")
        try:
            t = self._clock()
            # The UART class's own readers: the public properties re-read OPR_MODE before
            # every quantity, doubling the transactions (the mode was set in open()).
            gyro = sensor._gyro
            accel = sensor._acceleration
            quat = _unit(sensor._quaternion)
        except (OSError, RuntimeError, struct.error, IndexError) as e:
            raise self._error(e, "reading") from e
        sample = ImuSample(t, _vec(gyro), _vec(accel), quat)
        return self._mount.to_torso(sample)

    def _error(self, e: Exception, doing: str) -> ImuError:
        """One line for a library or serial failure while ``doing`` (opening/reading)."""
        text = str(e)
        where = f"bno055 on {self.port}: {doing}"
        if isinstance(e, RuntimeError) and "chip id" in text:
            return ImuError(f"{where}: not a BNO055 ({text}; expected 0x{CHIP_ID:02x}); is "
                            "another device on this port?")
        status = re.search(r"(?:read|write) error: (\d+)", text)
        if status:
            code = int(status.group(1))
            name = UART_STATUS.get(code, "unknown status")
            fix = UART_STATUS_FIX.get(code, WIRING)
            return ImuError(f"{where}: the chip answered error 0x{code:02x} {name}; {fix}")
        if isinstance(e, OSError) and "UART access error" in text:
            return ImuError(f"{where}: no reply within {READ_GIVE_UP_S:g} s at {UART_BAUD} "
                            f"baud; {WIRING}")
        return ImuError(f"{where}: {_reason(e)}; {WIRING}")


def _reason(e: BaseException) -> str:
    text = getattr(e, "strerror", None) or str(e) or type(e).__name__
    return " ".join(str(text).split())


def _vec(v: Any) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _unit(q: Any) -> Quat | None:
    w, x, y, z = (float(c) for c in q)
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if n < 0.5:   # all zeros: fusion not running yet
        return None
    return (w / n, x / n, y / n, z / n)
