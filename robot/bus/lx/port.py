"""The wire under the LX bus: the serial port, one lock, requests and their answers, and
messages that name the servo and its joint (``LxBus`` in robot/bus/lx/bus.py builds the Bus
API on it, as ``SdkBus`` does on ``SdkRegisters``).

A write command is sent and never answered; a read command is retried (``retries``) until
a well-formed answer with the same id, command and parameter count arrives within
``timeout_ms``. The input is flushed before every request, so a late answer to an earlier
request is never taken for this one.
"""

from __future__ import annotations

import threading
import time
from typing import NamedTuple

import serial

from robot.bus.lx.packet import ReplyParser, encode, value
from robot.bus.lx.tables import LX_BAUD, LX_BROADCAST_ID, LX_COMMANDS
from robot.bus.sdk.port import PORT_ERRORS
from robot.config.robot import RobotConfig
from robot.errors import BusError


class LxValue(NamedTuple):
    """One value of an LX servo under a register-like name (for ``LxBus.read_register`` /
    ``write_register``, as the other families' registers): read: the command that answers
    it; write: the command that sets it alone (None: read-only or set in pairs); offset,
    size: where it sits in the read reply's parameters [bytes]; signed: two's complement."""

    read: str
    write: str | None
    offset: int
    size: int
    signed: bool = False


LX_VALUES: dict[str, LxValue] = {
    "id": LxValue("id_read", "id_write", 0, 1),
    "torque_enable": LxValue("load_or_unload_read", "load_or_unload_write", 0, 1),
    "present_position": LxValue("pos_read", None, 0, 2, signed=True),
    "present_temperature": LxValue("temp_read", None, 0, 1),
    "present_voltage_mv": LxValue("vin_read", None, 0, 2),
    "angle_offset": LxValue("angle_offset_read", "angle_offset_adjust", 0, 1, signed=True),
    "min_angle_limit": LxValue("angle_limit_read", None, 0, 2),
    "max_angle_limit": LxValue("angle_limit_read", None, 2, 2),
    "min_voltage_limit_mv": LxValue("vin_limit_read", None, 0, 2),
    "max_voltage_limit_mv": LxValue("vin_limit_read", None, 2, 2),
    "temperature_limit": LxValue("temp_max_limit_read", "temp_max_limit_write", 0, 1),
    "motor_mode": LxValue("or_motor_mode_read", None, 0, 1),
    "led_error": LxValue("led_error_read", "led_error_write", 0, 1),
}



class LxPort:
    """An LX servo chain's serial line. port: device; robot: joints, for messages;
    retries: extra attempts per read; timeout_ms: wait for an answer [ms]."""

    def __init__(self, port: str, *, robot: RobotConfig | None, retries: int,
                 timeout_ms: float) -> None:
        self.port_name, self.robot = port, robot
        self.retries, self.timeout_ms = retries, timeout_ms
        if self.retries < 0 or not self.timeout_ms > 0:
            raise BusError(f"retries must be >= 0 and timeout_ms > 0, got {self.retries}, "
                           f"{self.timeout_ms}")
        self.bad_checksum = 0
        self._ser: serial.Serial | None = None
        self._lock = threading.RLock()

    # ------------------------------------------------------------------ messages
    def who(self, sid: int) -> str:
        joint = self.robot.joint_by_id(sid) if self.robot else None
        return f"id {sid} ({joint.name})" if joint else f"id {sid}"

    def _error(self, sid: int | None, what: str, detail: str) -> BusError:
        where = f"{self.who(sid)}: " if sid is not None else ""
        return BusError(f"lx {self.port_name} @ {LX_BAUD}: {where}{what} failed: {detail}; "
                        f"check power and wiring of {self.who(sid) if sid is not None else 'the servos'}"
                        f" and its id with `biped scan --bus lx --port {self.port_name}`")

    # ------------------------------------------------------------------ wire
    def _port(self) -> serial.Serial:
        if self._ser is None or not self._ser.is_open:
            raise BusError(f"lx bus on {self.port_name} is not open; call open() or use "
                           "`with bus:`")
        return self._ser

    def _send(self, data: bytes) -> None:
        with self._lock:
            ser = self._port()
            try:
                ser.write(data)
            except PORT_ERRORS as e:
                raise self._error(None, "write", f"port error: {e}") from e

    def _ask(self, sid: int, name: str, *, attempts: int | None = None) -> bytes | None:
        """Send read command ``name`` to ``sid``; its answer's parameters, or None when no
        valid answer came within the timeout on any of ``attempts`` (default retries + 1)."""
        cmd = LX_COMMANDS[name]
        request = encode(sid, name)
        with self._lock:
            ser = self._port()
            for _ in range(attempts or self.retries + 1):
                parser = ReplyParser()
                try:
                    ser.reset_input_buffer()          # a late answer to an earlier request
                    ser.write(request)
                    deadline = time.monotonic() + self.timeout_ms * 1e-3
                    while time.monotonic() < deadline:
                        for f in parser.feed(ser.read(max(1, ser.in_waiting))):
                            if f.code == cmd.code and len(f.params) == cmd.reply and (
                                    f.servo_id == sid or sid == LX_BROADCAST_ID):
                                return bytes([f.servo_id]) + f.params \
                                    if sid == LX_BROADCAST_ID else f.params
                except PORT_ERRORS as e:
                    raise self._error(sid, f"read {name}", f"port error: {e}") from e
                finally:
                    self.bad_checksum += parser.bad_checksum
        return None

    def read_register(self, sid: int, name: str) -> int:
        """Value ``name`` (a key of LX_VALUES) of servo ``sid``; BusError if silent."""
        v = LX_VALUES[name]
        params = self._ask(sid, v.read)
        if params is None:
            raise self._error(sid, f"read {name}", f"no answer (after {self.retries + 1} "
                              "attempts)")
        return value(params, v.offset, v.size, signed=v.signed)

    def write_register(self, sid: int, name: str, val: int) -> None:
        """Set value ``name`` of ``sid`` (no answer comes: read it back to be sure)."""
        v = LX_VALUES[name]
        if v.write is None:
            raise BusError(f"lx: {name} cannot be written alone; valid: "
                           f"{', '.join(n for n, x in LX_VALUES.items() if x.write)}")
        size = LX_COMMANDS[v.write].params
        self._send(encode(sid, v.write, int(val).to_bytes(size, "little", signed=val < 0)))

    def stray_bytes(self, *, wait_s: float = 0.02) -> int:
        """Bytes arriving within ``wait_s`` [s] after the last answer (then dropped): a
        second servo with the same id, or noise."""
        with self._lock:
            ser = self._port()
            time.sleep(wait_s)
            n = int(ser.in_waiting)
            ser.reset_input_buffer()
        return n

