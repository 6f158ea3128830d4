"""Feetech STS/SMS and SCS series through ``scservo_sdk`` (a Protocol-1 style protocol).

Control table: ``tables.FEETECH_STS`` (little-endian) or ``tables.FEETECH_SCS`` (SCSCL,
big-endian), by the robot file's servo model. The SDK keeps its byte order in a module-wide
global (``PacketHandler(end)`` / ``SCS_SETEND``), which another user of the SDK in the same
process (a second bus of the other series, a library) can flip at any moment. This bus
never depends on it: it moves raw bytes only (readTxRx, writeTxRx, group packets it fills
itself) and converts them with its table's byte order, and its ping reads the model number
as raw bytes too (the SDK's ping converts them with the global). ``read_state`` reads
present_position .. status (10 bytes) in one sync read.
"""

from __future__ import annotations

from typing import Any

import scservo_sdk

from robot.bus.base import ServoState
from robot.bus.sdk.bus import SdkBus
from robot.bus.sdk.port import TimedPort, error_names, sign_magnitude
from robot.bus.tables import BYTE_ORDER, TABLES
from robot.servo.models import ServoModel, lookup

LITTLE_ENDIAN = 0  # scservo_sdk's SCS_END value for STS/SMS (SCS: 1)
#: Instruction packet of a ping, as scservo_sdk's own ping builds it (header, id and
#: checksum filled in by txPacket).
PING_LENGTH = 2


class _Port(TimedPort, scservo_sdk.PortHandler):
    """scservo_sdk's PortHandler with a configurable timeout and a real input flush."""


class FeetechBus(SdkBus):
    """Feetech chain. ``FeetechBus(port, baud=..., robot=..., retries=..., timeout_ms=...)``.

    Position and load are sign-magnitude (bits 15 and 10); load [0.1 %], voltage [0.1 V],
    temperature [°C]; errors from the status register and the status packet's error byte.
    """

    kind = "feetech"
    family = "feetech_sts"
    families = ("feetech_sts", "feetech_scs")
    sdk = scservo_sdk
    port_class = _Port
    firmware_register = "firmware_major"

    def __init__(self, port: str, **options: Any) -> None:
        super().__init__(port, **options)
        #: the raw Model Number bytes (3, 4) each servo answered its last ping with
        self.model_bytes: dict[int, bytes] = {}

    def _make_packet_handler(self) -> Any:
        return scservo_sdk.PacketHandler(LITTLE_ENDIAN)

    def ping(self, servo_id: int) -> int | None:
        """Model number of ``servo_id`` (its table's byte order), or None when silent. A
        ping instruction, then the two model bytes read raw (``model_bytes`` keeps them)."""
        reg = self.table["model_number"]

        def exchange() -> tuple[Any, int, int]:
            packet = [0] * (PING_LENGTH + 4)
            packet[2], packet[3], packet[4] = servo_id, PING_LENGTH, scservo_sdk.INST_PING
            _, result, error = self._ph.txRxPacket(self._port, packet)
            if result != scservo_sdk.COMM_SUCCESS:
                return None, result, error
            return self._ph.readTxRx(self._port, servo_id, reg.address, reg.size)  # type: ignore[no-any-return]

        data, _ = self._transact("ping", servo_id, exchange, missing_ok=True)
        if data is None or len(data) < reg.size:
            return None
        self.model_bytes[servo_id] = bytes(data[:reg.size])
        return int.from_bytes(self.model_bytes[servo_id], self.byteorder)

    def identify(self, sid: int, number: int) -> ServoModel | None:
        """As SdkBus.identify; a servo whose number is no model of this bus's family is
        tried in the other family's byte order (an SCS on an STS chain reads 0x0504 as
        1029, which is its 1284 read the wrong way round)."""
        found = super().identify(sid, number)
        raw = self.model_bytes.get(sid)
        if (found is not None and found.family == self.family) or raw is None:
            return found
        for family in self.families:
            other = lookup(family, int.from_bytes(raw, BYTE_ORDER[family]))
            if other is not None and TABLES[family]["model_number"] == self.table["model_number"]:
                return other
        return found

    def _decode_state(self, sid: int, block: bytes, status: int) -> ServoState:
        return ServoState(
            id=sid,
            position=sign_magnitude(self.field(block, "present_position"), 15),
            load=sign_magnitude(self.field(block, "present_load"), 10) * 0.1,
            temperature=float(self.field(block, "present_temperature")),
            voltage=self.field(block, "present_voltage") * 0.1,
            errors=error_names(self.family, self.field(block, "status") | status),
        )
