"""ROBOTIS Dynamixel X series on Protocol 2.0 through ``dynamixel_sdk``.

Control table: ``tables.DYNAMIXEL_X``. ``read_state`` reads the contiguous block from
present_load to present_temperature (21 bytes) in one sync read; a servo whose status
packet carries the alert bit gets its Hardware Error Status register read as well.
"""

from __future__ import annotations

from typing import Any

import dynamixel_sdk

from robot.bus.base import ServoState
from robot.bus.sdk_bus import SdkBus
from robot.bus.sdk_port import TimedPort, error_names, twos_complement


class _Port(TimedPort, dynamixel_sdk.PortHandler):
    """dynamixel_sdk's PortHandler with a configurable timeout (see TimedPort)."""


class DynamixelBus(SdkBus):
    """Dynamixel X chain. ``DynamixelBus(port, baud=..., robot=..., retries=..., timeout_ms=...)``.

    Load is Present Load [0.1 %] (current-based models report current there instead),
    voltage Present Input Voltage [0.1 V], temperature [°C].
    """

    kind = "dynamixel"
    family = "dynamixel_x"
    sdk = dynamixel_sdk
    port_class = _Port
    state_block = ("present_load", "present_temperature")
    firmware_register = "firmware_version"

    def _make_packet_handler(self) -> Any:
        return dynamixel_sdk.PacketHandler(2.0)

    def _status_failed(self, error: int) -> bool:
        # Bits 0-6 are an instruction error code; bit 7 only flags a hardware error.
        return bool(error & ~dynamixel_sdk.ERRBIT_ALERT & 0xFF)

    def _decode_state(self, sid: int, block: bytes, status: int) -> ServoState:
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
