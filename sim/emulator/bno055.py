"""A fake Bosch BNO055 on a pseudo-terminal, speaking the chip's UART protocol, so the IMU
driver and the real adafruit library are tested at the wire (like sim/emulator/chain.py for the
servos). Written from the datasheet (BST-BNO055-DS000 rev 1.4), independently of
robot/imu/ and of the library:

- section 4.7, UART protocol: a write is ``0xAA 0x00 reg len data...`` answered by
  ``0xEE status`` (0x01 = WRITE_SUCCESS); a read is ``0xAA 0x01 reg len`` answered by
  ``0xBB len data...`` or ``0xEE status``;
- section 4.2 / 4.3, register map: page 0 (ids, data, status, UNIT_SEL, OPR_MODE, ...) and
  page 1 (sensor configuration, writable only in CONFIGMODE), selected by PAGE_ID 0x07;
- section 3.3 (Table 3-3): which outputs each operating mode produces; in CONFIGMODE the
  outputs read zero;
- section 3.6.4 / 3.6.5: data scales (accel 100 LSB per m/s^2 or 1 LSB per mg; gyro 16 LSB
  per dps or 900 LSB per rps, chosen by UNIT_SEL; quaternion 2^14 LSB per unit),
  little-endian signed 16-bit.

Tests set the motion in physical units (``set_motion``) and inject faults: ``silent`` (no
reply at all), ``read_status`` (answer every read with ``0xEE <status>``), ``chip_id``.
"""

from __future__ import annotations

import math
import os
import select
import struct
import threading
import tty
from types import TracebackType

# ---------------------------------------------------------------- datasheet data

START, READ, WRITE = 0xAA, 0x01, 0x00            # section 4.7 request bytes
READ_OK, STATUS = 0xBB, 0xEE                     # section 4.7 response headers
WRITE_SUCCESS, WRITE_FAIL, REGMAP_INVALID_ADDRESS = 0x01, 0x03, 0x04
REGMAP_WRITE_DISABLED, WRONG_START_BYTE, MAX_LENGTH_ERROR = 0x05, 0x06, 0x08
MIN_LENGTH_ERROR = 0x09
MAX_LENGTH = 128                                  # longest read/write the chip accepts

# Page 0 (section 4.2, Table 4-2): address of each register used here.
P0 = {"CHIP_ID": 0x00, "ACC_ID": 0x01, "MAG_ID": 0x02, "GYR_ID": 0x03, "SW_REV_ID_LSB": 0x04,
      "SW_REV_ID_MSB": 0x05, "BL_REV_ID": 0x06, "PAGE_ID": 0x07, "ACC_DATA": 0x08,
      "MAG_DATA": 0x0E, "GYR_DATA": 0x14, "EUL_DATA": 0x1A, "QUA_DATA": 0x20,
      "LIA_DATA": 0x28, "GRV_DATA": 0x2E, "TEMP": 0x34, "CALIB_STAT": 0x35,
      "ST_RESULT": 0x36, "SYS_STATUS": 0x39, "SYS_ERR": 0x3A, "UNIT_SEL": 0x3B,
      "OPR_MODE": 0x3D, "PWR_MODE": 0x3E, "SYS_TRIGGER": 0x3F, "AXIS_MAP_CONFIG": 0x41,
      "AXIS_MAP_SIGN": 0x42}
#: Page 0 registers only the chip writes (ids and outputs, 0x00-0x06 and 0x08-0x3A).
P0_READ_ONLY = (range(0x00, 0x07), range(0x08, 0x3B))
#: Reset values (section 4.3): ids, firmware 3.17 (0x0311), UNIT_SEL 0x80 (Android
#: orientation, m/s^2, dps, degrees, Celsius), CONFIGMODE, normal power, default axis map,
#: self test passed (ST_RESULT 0x0F).
P0_RESET = {"CHIP_ID": 0xA0, "ACC_ID": 0xFB, "MAG_ID": 0x32, "GYR_ID": 0x0F,
            "SW_REV_ID_LSB": 0x11, "SW_REV_ID_MSB": 0x03, "BL_REV_ID": 0x15,
            "ST_RESULT": 0x0F, "UNIT_SEL": 0x80, "OPR_MODE": 0x00, "AXIS_MAP_CONFIG": 0x24}
#: Page 1 sensor configuration (section 4.4) and its reset values.
P1_RESET = {0x08: 0x0D, 0x09: 0x6D, 0x0A: 0x38, 0x0B: 0x00}   # ACC/MAG/GYR_Config
P1_LAST = 0x7F
#: OPR_MODE values (section 3.3, Table 3-5) and which outputs each produces (Table 3-3).
CONFIGMODE = 0x00
FUSION_MODES = frozenset({0x08, 0x09, 0x0A, 0x0B, 0x0C})   # IMU, COMPASS, M4G, NDOF_FMC_OFF, NDOF
ACCEL_MODES = frozenset({0x01, 0x04, 0x05, 0x07}) | FUSION_MODES
GYRO_MODES = frozenset({0x03, 0x05, 0x06, 0x07, 0x08, 0x0B, 0x0C})
RST_SYS = 0x20                                   # SYS_TRIGGER bit 5 (section 4.3.63)
# UNIT_SEL bits (section 4.3.60) and the scales they select (Tables 3-17, 3-22, 3-31).
ACC_UNIT_MG, GYR_UNIT_RPS = 0x01, 0x02
LSB_PER_MS2, LSB_PER_MG = 100.0, 1.0
LSB_PER_DPS, LSB_PER_RPS = 16.0, 900.0
LSB_PER_QUAT = float(1 << 14)
G_MS2 = 9.80665


def _int16(value: float) -> bytes:
    return struct.pack("<h", max(-32768, min(32767, round(value))))


class FakeBno055:
    """A BNO055 on a pty (``path``), served by a thread while open (``with`` or start/stop).

    chip_id: what CHIP_ID reads; silent: never answer; read_status: answer every read with
    that 0xEE status (e.g. 0x07 BUS_OVER_RUN_ERROR). ``requests`` counts the frames seen.
    """

    def __init__(self, *, chip_id: int = 0xA0) -> None:
        self.chip_id = chip_id
        self.silent = False
        self._pending = bytearray()   # received, not yet a whole request
        self.read_status: int | None = None
        self.requests = 0
        self._lock = threading.Lock()
        self._gyro = (0.0, 0.0, 0.0)          # [rad/s]
        self._accel = (0.0, 0.0, G_MS2)       # [m/s^2]
        self._quat = (1.0, 0.0, 0.0, 0.0)
        self._page = [bytearray(0x80), bytearray(0x80)]
        self._reset()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._master = self._slave = -1
        self.path = ""

    # ------------------------------------------------------------ test side

    def set_motion(self, *, gyro: tuple[float, float, float] | None = None,
                   accel: tuple[float, float, float] | None = None,
                   quat: tuple[float, float, float, float] | None = None) -> None:
        """What the chip measures: gyro [rad/s], accel [m/s^2], quat (w, x, y, z)."""
        with self._lock:
            self._gyro = gyro if gyro is not None else self._gyro
            self._accel = accel if accel is not None else self._accel
            self._quat = quat if quat is not None else self._quat

    def register(self, name: str) -> int:
        """A page-0 register's present value."""
        with self._lock:
            return self._page[0][P0[name]]

    def start(self) -> None:
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)
        self.path = os.ttyname(self._slave)
        self._stop.clear()
        self._thread = threading.Thread(target=self._serve, name="fake-bno055", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
            self._thread = None
        for fd in (self._master, self._slave):
            if fd >= 0:
                os.close(fd)
        self._master = self._slave = -1

    def __enter__(self) -> FakeBno055:
        self.start()
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.stop()

    # ------------------------------------------------------------ chip side

    def _reset(self) -> None:
        self._page = [bytearray(0x80), bytearray(0x80)]
        for name, value in P0_RESET.items():
            self._page[0][P0[name]] = value
        self._page[0][P0["CHIP_ID"]] = self.chip_id
        for addr, value in P1_RESET.items():
            self._page[1][addr] = value

    def drained(self) -> bool:
        """Whether every byte the host sent has been taken and answered (or dropped, while
        ``silent``): a test that ends a fault waits for this, so a request sent during the
        fault is not answered after it (a busy machine may run this thread late)."""
        ready, _, _ = select.select([self._master], [], [], 0)
        return not ready and not self._pending

    def _serve(self) -> None:
        buf = self._pending
        while not self._stop.is_set():
            ready, _, _ = select.select([self._master], [], [], 0.05)
            if not ready:
                continue
            try:
                buf += os.read(self._master, 256)
            except OSError:
                continue
            while buf:
                reply, used = self._frame(buf)
                if used == 0:
                    break
                del buf[:used]
                if reply and not self.silent:
                    os.write(self._master, reply)

    def _frame(self, buf: bytearray) -> tuple[bytes, int]:
        """(reply, bytes consumed) for the request at the start of ``buf``; (b"", 0) if it
        is not complete yet."""
        if buf[0] != START:
            return bytes([STATUS, WRONG_START_BYTE]), 1
        if len(buf) < 4:
            return b"", 0
        op, reg, length = buf[1], buf[2], buf[3]
        if op == READ:
            self.requests += 1
            with self._lock:
                return self._read(reg, length), 4
        if op == WRITE:
            if len(buf) < 4 + length:
                return b"", 0
            self.requests += 1
            with self._lock:
                return self._write(reg, bytes(buf[4:4 + length])), 4 + length
        return bytes([STATUS, WRONG_START_BYTE]), 1

    def _read(self, reg: int, length: int) -> bytes:
        if self.read_status is not None:
            return bytes([STATUS, self.read_status])
        if length == 0:
            return bytes([STATUS, MIN_LENGTH_ERROR])
        if length > MAX_LENGTH:
            return bytes([STATUS, MAX_LENGTH_ERROR])
        if reg + length > 0x80:
            return bytes([STATUS, REGMAP_INVALID_ADDRESS])
        page = self._page[0][P0["PAGE_ID"]] & 1
        if page == 0:
            self._update_outputs()
        data = bytes(self._page[page][reg:reg + length])
        return bytes([READ_OK, length]) + data

    def _write(self, reg: int, data: bytes) -> bytes:
        if not data:
            return bytes([STATUS, MIN_LENGTH_ERROR])
        if reg + len(data) > 0x80:
            return bytes([STATUS, REGMAP_INVALID_ADDRESS])
        p0 = self._page[0]
        page = p0[P0["PAGE_ID"]] & 1
        addrs = range(reg, reg + len(data))
        if page == 0 and any(a in r for a in addrs for r in P0_READ_ONLY):
            return bytes([STATUS, REGMAP_WRITE_DISABLED])
        if page == 1 and addrs != range(P0["PAGE_ID"], P0["PAGE_ID"] + 1) \
                and (p0[P0["OPR_MODE"]] & 0x0F) != CONFIGMODE:
            return bytes([STATUS, WRITE_FAIL])   # configuration only in CONFIGMODE
        self._page[page][reg:reg + len(data)] = data
        if P0["PAGE_ID"] in addrs:   # PAGE_ID is 0x07 on both pages (section 4.2)
            p0[P0["PAGE_ID"]] = self._page[1][P0["PAGE_ID"]] = self._page[page][P0["PAGE_ID"]] & 1
        if page == 0 and P0["SYS_TRIGGER"] in addrs and p0[P0["SYS_TRIGGER"]] & RST_SYS:
            self._reset()
        return bytes([STATUS, WRITE_SUCCESS])

    def _update_outputs(self) -> None:
        """Fill the data registers from the motion, per OPR_MODE and UNIT_SEL."""
        p0 = self._page[0]
        mode = p0[P0["OPR_MODE"]] & 0x0F
        units = p0[P0["UNIT_SEL"]]
        zero3 = (0.0, 0.0, 0.0)
        accel = self._accel if mode in ACCEL_MODES else zero3
        acc_scale = LSB_PER_MG / (G_MS2 / 1000.0) if units & ACC_UNIT_MG else LSB_PER_MS2
        gyro = self._gyro if mode in GYRO_MODES else zero3
        gyr_scale = LSB_PER_RPS if units & GYR_UNIT_RPS else LSB_PER_DPS * 180.0 / math.pi
        quat = self._quat if mode in FUSION_MODES else (0.0, 0.0, 0.0, 0.0)
        for name, values, scale in (("ACC_DATA", accel, acc_scale),
                                    ("GYR_DATA", gyro, gyr_scale),
                                    ("QUA_DATA", quat, LSB_PER_QUAT)):
            addr = P0[name]
            p0[addr:addr + 2 * len(values)] = b"".join(_int16(v * scale) for v in values)
