"""Register access through one vendor SDK: the port, retries, the SDK's PORT_BUSY and
stale-data pitfalls, and error messages that name the servo and its joint.

``SdkBus`` (robot/bus/sdk/bus.py) builds the ``base.Bus`` API on it; the communication
watchdog (``failsafe``) and the health checks (``health``) need only this layer, so they
import it, not the bus. One lock serialises transactions, so a telemetry thread may share it.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable, Mapping
from types import ModuleType
from typing import Any, ClassVar

from robot.bus.sdk.port import PORT_ERRORS
from robot.bus.tables import BYTE_ORDER, TABLES, Register
from robot.config.robot import RobotConfig
from robot.errors import BusError
from robot.servo.models import BAUD_CODES

log = logging.getLogger(__name__)


class SdkRegisters:
    """Registers of a servo chain through a vendor SDK (``SdkBus`` is the whole bus).

    port: serial device; baud [bit/s]; robot: joints and ids, for messages; retries: extra
    attempts per transaction (default robot.bus.retries, else 2); timeout_ms: reply timeout
    [ms] per transaction (default robot.bus.timeout_ms, else 20).
    """

    kind: str
    #: The control-table family this bus drives: the robot's servo model's when it has one
    #: (a kind speaks several: Protocol 2.0 the X table and the XL-320's), else this default.
    family: str
    #: Every family this bus's protocol speaks (robot.servo.models.BUS_FAMILIES).
    families: ClassVar[tuple[str, ...]]
    sdk: ClassVar[ModuleType]
    #: The servos' longest return delay, as the health check read it on open [s].
    return_delay_s: float = 0.0

    def __init__(self, port: str, *, baud: int, robot: RobotConfig | None = None,
                 retries: int | None = None, timeout_ms: float | None = None,
                 family: str | None = None) -> None:
        self.port_name = port
        self.baud = int(baud)
        self.robot = robot
        self.retries = int(retries if retries is not None else
                           (robot.bus.retries if robot else 2))
        self.timeout_ms = float(timeout_ms if timeout_ms is not None else
                                (robot.bus.timeout_ms if robot else 20.0))
        if self.retries < 0 or not self.timeout_ms > 0:
            raise BusError(f"retries must be >= 0 and timeout_ms > 0, got {self.retries}, "
                           f"{self.timeout_ms}")
        self.family = self._pick_family(family, robot)
        self.table: dict[str, Register] = TABLES[self.family]
        self.byteorder = BYTE_ORDER[self.family]
        self._port: Any = None
        self._ph: Any = None
        self._torqued: set[int] = set()
        self.failsafe_armed: set[int] = set()   # ids whose communication watchdog we armed
        self._lock = threading.RLock()

    def _pick_family(self, family: str | None, robot: RobotConfig | None) -> str:
        """``family`` when given, else the robot's servo model's, else the class default."""
        chosen = family or (robot.bus.servo.family if robot is not None else self.family)
        if chosen not in self.families:
            raise BusError(f"a {self.kind} bus drives {', '.join(self.families)} servos, not "
                           f"{chosen}; use the bus kind of {chosen}")
        return chosen

    def _status_failed(self, error: int) -> bool:
        """Whether a status packet's error byte means the instruction failed (a hook)."""
        return False

    @property
    def port_handler(self) -> Any:
        """The SDK's PortHandler while open (for diagnostics and raw-SDK comparisons)."""
        return self._port

    @property
    def packet_handler(self) -> Any:
        """The SDK's packet handler while open."""
        return self._ph

    @property
    def is_open(self) -> bool:
        return self._port is not None and bool(self._port.is_open)

    @property
    def retry_span_s(self) -> float:
        return self.timeout_ms * 1e-3 * (self.retries + 1)

    def set_baud(self, baud: int) -> None:
        """(Re)open the port at ``baud`` [bit/s]; raises BusError naming the valid rates."""
        rates = sorted(BAUD_CODES[self.family].values())
        try:
            ok = self._port.setBaudRate(int(baud))
        except OSError as e:
            self._port = None
            raise BusError(f"cannot open {self.port_name}: {e}; is the adapter plugged in "
                           f"(ls /dev/serial/by-id/) and are you in the dialout group "
                           f"(sudo usermod -aG dialout $USER)?") from e
        if not ok:
            raise BusError(f"baud {baud} is not supported by the {self.kind} SDK; valid: "
                           f"{', '.join(map(str, rates))}")
        self.baud = int(baud)


    # ------------------------------------------------------------------ messages
    def who(self, sid: int) -> str:
        """``id 7 (l_hip_roll)``: the servo and its joint when the robot config knows it."""
        joint = self.robot.joint_by_id(sid) if self.robot else None
        return f"id {sid} ({joint.name})" if joint else f"id {sid}"

    def _fix(self, result: int | None, sid: int | None) -> str:
        scan = f"`biped scan --bus {self.kind} --port {self.port_name}`"
        if result == self.sdk.COMM_RX_CORRUPT:
            return ("replies are garbled: check cable and ground, lower the baud rate, or look "
                    f"for two servos sharing an id with {scan}")
        if result in (self.sdk.COMM_TX_FAIL, self.sdk.COMM_PORT_BUSY, None):
            return (f"is {self.port_name} still plugged in and not used by another program? "
                    "reconnect the adapter and retry")
        target = f"of {self.who(sid)}" if sid is not None else "of the servos"
        return f"check power and wiring {target}; is the baud rate right? try {scan}"

    def _error(self, sid: int | None, what: str, detail: str, result: int | None) -> BusError:
        where = f"{self.who(sid)}: " if sid is not None else ""
        return BusError(f"{self.kind} {self.port_name} @ {self.baud}: {where}{what} failed: "
                        f"{detail}; {self._fix(result, sid)}")

    # ------------------------------------------------------------------ transactions
    def _begin(self) -> Any:
        if not self.is_open:
            raise BusError(f"{self.kind} bus on {self.port_name} is not open; call open() or "
                           "use `with bus:`")
        self._port.is_using = False  # an earlier exception must not leave PORT_BUSY set
        return self._port

    def _transact(self, what: str, sid: int | None, fn: Callable[[], tuple[Any, int, int]],
                  *, missing_ok: bool = False,
                  blame: Callable[[], int | None] | None = None) -> tuple[Any, int]:
        """Run one SDK exchange ``fn() -> (value, comm result, status byte)`` with retries.

        Returns (value, status byte); (None, 0) for a silent servo when ``missing_ok``.
        ``blame()`` names the servo at fault after a failed group exchange.
        """
        result = self.sdk.COMM_SUCCESS
        with self._lock:
            for attempt in range(self.retries + 1):
                port = self._begin()
                try:
                    value, result, error = fn()
                except PORT_ERRORS as e:
                    port.is_using = False
                    raise self._error(sid, what, f"port error: {e}", None) from e
                except IndexError:
                    # scservo_sdk indexes a reply it misparsed (e.g. two servos answering
                    # one ping): a garbled reply, retried like a bad checksum.
                    port.is_using = False
                    value, result, error = None, self.sdk.COMM_RX_CORRUPT, 0
                if result == self.sdk.COMM_SUCCESS:
                    if self._status_failed(error):
                        raise self._error(sid, what, self._ph.getRxPacketError(error), result)
                    return value, error
                if missing_ok and result == self.sdk.COMM_RX_TIMEOUT:
                    return None, 0
                log.debug("%s %s attempt %d: %s", what, self.who(sid) if sid is not None else "",
                          attempt + 1, self._ph.getTxRxResult(result))
        detail = f"{self._ph.getTxRxResult(result)} (after {self.retries + 1} attempts)"
        if blame is not None:
            sid = blame()
            what = f"{what} (no valid reply from it)" if sid is not None else what
        raise self._error(sid, what, detail, result)

    def read_register(self, sid: int, name: str, *,
                      table: dict[str, Register] | None = None) -> int:
        """Unsigned value of register ``name`` of servo ``sid`` (in ``table``: another
        family's, for a scan that met one; default this bus's)."""
        reg = (table or self.table)[name]
        return int.from_bytes(self.read_bytes(sid, reg.address, reg.size, name), self.byteorder)

    def read_bytes(self, sid: int, address: int, length: int, what: str) -> bytes:
        """``length`` bytes of servo ``sid``'s control table from ``address`` (one read);
        ``what`` names them in errors."""
        data, _ = self._transact(f"read {what}", sid, lambda: self._ph.readTxRx(
            self._port, sid, address, length))
        if data is None or len(data) < length:
            raise self._error(sid, f"read {what}", f"short reply ({len(data or [])} of "
                              f"{length} bytes)", self.sdk.COMM_RX_CORRUPT)
        return bytes(data[:length])

    def write_register(self, sid: int, name: str, value: int) -> None:
        """Write register ``name`` of servo ``sid`` and wait for its status reply."""
        self.write_at(sid, self.table[name], value, name)

    def write_at(self, sid: int, reg: Register, value: int, what: str) -> None:
        """Write ``value`` to ``reg`` of servo ``sid`` and wait for its status reply."""
        data = list(int(value).to_bytes(reg.size, self.byteorder, signed=value < 0))
        self._transact(f"write {what}={value}", sid, lambda: (None, *self._ph.writeTxRx(
            self._port, sid, reg.address, reg.size, data)))

    def sync_write(self, reg: Register, values: Mapping[int, int], what: str) -> None:
        """One sync-write packet: ``values[id]`` (unsigned) to ``reg`` of every listed servo
        (no status reply: verify by reading back)."""
        if not values:
            return

        def send() -> tuple[None, int, int]:
            group = self.sdk.GroupSyncWrite(self._port, self._ph, reg.address, reg.size)
            for sid, v in values.items():
                group.addParam(sid, list(int(v).to_bytes(reg.size, self.byteorder)))
            return None, group.txPacket(), 0

        self._transact(f"sync write {what}", None, send)

    # ------------------------------------------------------------------ Bus API
    def ping(self, servo_id: int) -> int | None:
        model, _ = self._transact("ping", servo_id, lambda: self._ph.ping(self._port, servo_id),
                                  missing_ok=True)
        return None if model is None else int(model)

    @staticmethod
    def each(ids: Iterable[int], action: Callable[[int], None]) -> None:
        """``action(sid)`` for every id, in order, even after one fails; then raise the
        first failure (counting the others)."""
        failures: list[BusError] = []
        for sid in sorted(set(ids)):
            try:
                action(sid)
            except BusError as e:
                failures.append(e)
        if failures:
            more = f" (and {len(failures) - 1} more servos)" if len(failures) > 1 else ""
            raise BusError(f"{failures[0]}{more}") from failures[0]

    def set_torque(self, ids: Iterable[int], *, enabled: bool) -> None:
        def one(sid: int) -> None:
            self.write_register(sid, "torque_enable", int(enabled))
            (self._torqued.add if enabled else self._torqued.discard)(sid)

        self.each(ids, one)
