"""Feetech STS/SMS series through ``scservo_sdk`` (Protocol-1 style, little-endian).

Control table: ``tables.FEETECH_STS``. The SDK keeps its byte order in a module-wide
global; this bus sets it to little-endian (``PacketHandler(0)`` / ``SCS_SETEND(0)``) before
every transaction, so another user of the SDK cannot flip it under us. ``read_state``
reads present_position .. status (10 bytes) in one sync read.
"""

from __future__ import annotations

from typing import Any

import scservo_sdk

from robot.bus.base import ServoState
from robot.bus.sdk_bus import SdkBus
from robot.bus.sdk_port import TimedPort, error_names, sign_magnitude

LITTLE_ENDIAN = 0  # scservo_sdk's SCS_END value for STS/SMS


class _Port(TimedPort, scservo_sdk.PortHandler):
    """scservo_sdk's PortHandler with a configurable timeout and a real input flush."""


class FeetechBus(SdkBus):
    """Feetech STS chain. ``FeetechBus(port, baud=..., robot=..., retries=..., timeout_ms=...)``.

    Position and load are sign-magnitude (bits 15 and 10); load [0.1 %], voltage [0.1 V],
    temperature [°C]; errors from the status register and the status packet's error byte.
    """

    kind = "feetech"
    family = "feetech_sts"
    sdk = scservo_sdk
    port_class = _Port
    state_block = ("present_position", "status")
    firmware_register = "firmware_major"

    def _make_packet_handler(self) -> Any:
        return scservo_sdk.PacketHandler(LITTLE_ENDIAN)

    def _begin(self) -> Any:
        scservo_sdk.SCS_SETEND(LITTLE_ENDIAN)
        return super()._begin()

    def _decode_state(self, sid: int, block: bytes, status: int) -> ServoState:
        return ServoState(
            id=sid,
            position=sign_magnitude(self.field(block, "present_position"), 15),
            load=sign_magnitude(self.field(block, "present_load"), 10) * 0.1,
            temperature=float(self.field(block, "present_temperature")),
            voltage=self.field(block, "present_voltage") * 0.1,
            errors=error_names(self.family, self.field(block, "status") | status),
        )
