"""ROBOTIS Dynamixel on Protocol 2.0 through ``dynamixel_sdk``: the X series (and the MX
series on 2.0 firmware) or the XL-320, by the robot file's servo model.

Control table: ``tables.DYNAMIXEL_X`` or ``tables.DYNAMIXEL_XL320``. ``read_state`` reads
one block per servo in one sync read: X present_load .. present_temperature (21 bytes; a
servo whose status packet carries the alert bit gets its Hardware Error Status read as
well), XL-320 present_position .. hardware_error_status (14 bytes, the errors inside).
"""

from __future__ import annotations

from typing import Any

import dynamixel_sdk

from robot.bus.base import ServoState
from robot.bus.sdk.bus import SdkBus
from robot.bus.sdk.port import TimedPort, error_names, sign_magnitude, twos_complement

#: XL-320 Present Load(41): bit 10 the direction, bits 0-9 the magnitude [0.1 %].
XL320_DIRECTION_BIT = 10


class _Port(TimedPort, dynamixel_sdk.PortHandler):
    """dynamixel_sdk's PortHandler with a configurable timeout (see TimedPort)."""


class DynamixelBus(SdkBus):
    """Dynamixel Protocol 2.0 chain. ``DynamixelBus(port, baud=..., robot=..., retries=...,
    timeout_ms=...)``.

    Load is Present Load [0.1 %] (current-based models report current there instead; the
    XL-320 signs it by bit 10), voltage [0.1 V], temperature [°C].
    """

    kind = "dynamixel"
    family = "dynamixel_x"
    families = ("dynamixel_x", "dynamixel_xl320")
    sdk = dynamixel_sdk
    port_class = _Port
    firmware_register = "firmware_version"

    def _make_packet_handler(self) -> Any:
        return dynamixel_sdk.PacketHandler(2.0)

    def _status_failed(self, error: int) -> bool:
        # Bits 0-6 are an instruction error code; bit 7 only flags a hardware error.
        return bool(error & ~dynamixel_sdk.ERRBIT_ALERT & 0xFF)

    def _decode_state(self, sid: int, block: bytes, status: int) -> ServoState:
        if self.family == "dynamixel_xl320":
            return ServoState(
                id=sid, position=self.field(block, "present_position"),
                load=sign_magnitude(self.field(block, "present_load"), XL320_DIRECTION_BIT) * 0.1,
                temperature=float(self.field(block, "present_temperature")),
                voltage=self.field(block, "present_voltage") * 0.1,
                errors=error_names(self.family, self.field(block, "hardware_error_status")))
        errors: frozenset[str] = frozenset()
        if status & dynamixel_sdk.ERRBIT_ALERT:
            errors = error_names(self.family, self.read_register(sid, "hardware_error_status"))
        return ServoState(
            id=sid,
            position=twos_complement(self.field(block, "present_position"), 32),
            load=twos_complement(self.field(block, "present_load"), 16) * 0.1,
            temperature=float(self.field(block, "present_temperature")),
            voltage=self.field(block, "present_input_voltage") * 0.1,
            errors=errors,
        )
