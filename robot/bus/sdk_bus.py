"""What the Dynamixel and Feetech buses share: one vendor SDK behind ``base.Bus``.

Subclasses set the SDK module, the control-table family and the state block, and
implement three hooks (packet handler, status-byte failure, state decoding). Everything else
(retries, the SDK's PORT_BUSY and stale-data pitfalls, limit checks, error messages that
name the servo and its joint) lives here, once.

One lock serialises transactions, so a telemetry thread may share the bus.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Iterable, Mapping
from types import ModuleType
from typing import Any, ClassVar

from robot.bus import failsafe, health
from robot.bus.base import Bus, ServoInfo, ServoState
from robot.bus.limits import TickLimits
from robot.bus.sdk_port import PORT_ERRORS
from robot.bus.sync_read import BlockSyncRead, Reply
from robot.bus.tables import (
    BAUD_CODES,
    COMM_WATCHDOG,
    RETURN_DELAY_UNIT_S,
    TABLES,
    Register,
    model_name,
)
from robot.config.robot_file import RobotConfig
from robot.errors import BusError

log = logging.getLogger(__name__)


class SdkBus(Bus):
    """A servo chain driven through a vendor SDK. Subclasses: DynamixelBus, FeetechBus.

    port: serial device; baud [bit/s]; robot: joints, limits and ids (without it the bus
    can scan, ping and toggle torque but refuses goals); retries: extra attempts per
    transaction (default robot.bus.retries, else 2); timeout_ms: reply timeout [ms] per
    transaction (default robot.bus.timeout_ms, else 20); check_health: run the checks of
    ``robot.bus.health`` on open (results in ``self.health``).
    """

    family: ClassVar[str]
    sdk: ClassVar[ModuleType]
    port_class: ClassVar[type]
    state_block: ClassVar[tuple[str, str]]  # first and last register of the read_state block
    firmware_register: ClassVar[str]

    def __init__(self, port: str, *, baud: int, robot: RobotConfig | None = None,
                 retries: int | None = None, timeout_ms: float | None = None,
                 check_health: bool = True) -> None:
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
        self.check_health = check_health
        self.table: dict[str, Register] = TABLES[self.family]
        self.health: list[str] = []
        self.limits = TickLimits(robot)
        self._goal_size = self.table["goal_position"].size
        first, last = (self.table[n] for n in self.state_block)
        self._block_start = first.address
        self._reader = BlockSyncRead(self.sdk, first.address,
                                     last.address + last.size - first.address)
        self._port: Any = None
        self._ph: Any = None
        self._writer: Any = None
        self._torqued: set[int] = set()
        self.failsafe_armed: set[int] = set()   # ids whose communication watchdog we armed
        self._lock = threading.RLock()

    # ------------------------------------------------------------------ hooks
    def _make_packet_handler(self) -> Any:
        raise NotImplementedError

    def _status_failed(self, error: int) -> bool:
        """Whether a status packet's error byte means the instruction failed."""
        return False

    def _decode_state(self, sid: int, block: bytes, status: int) -> ServoState:
        raise NotImplementedError

    # ------------------------------------------------------------------ lifecycle
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

    def open(self) -> None:
        if self.is_open:
            return
        port = self.port_class(self.port_name)
        port.timeout_ms = self.timeout_ms
        self._port = port
        self._ph = self._make_packet_handler()
        self.set_baud(self.baud)
        self._reader.bind(port, self._ph)
        goal = self.table["goal_position"]
        self._writer = self.sdk.GroupSyncWrite(port, self._ph, goal.address, goal.size)
        health.try_low_latency(port.ser)
        if self.check_health:
            try:
                self.health = health.check(self)
            except BaseException:
                self.close(torque_off=False)
                raise

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

    def close(self, *, torque_off: bool = True) -> None:
        port, self._port = self._port, None
        if port is None:
            return
        wd = COMM_WATCHDOG[self.family]
        if wd is not None and self.failsafe_armed and port.is_open:
            self._close_write(port, wd.register, wd.off, sorted(self.failsafe_armed),
                              "the failsafe stays armed")
        self.failsafe_armed.clear()
        ids = sorted(set(self.robot.ids if self.robot else ()) | self._torqued)
        if torque_off and ids and port.is_open:
            self._close_write(port, "torque_enable", 0, ids, "they may still hold torque")
        try:
            if port.is_open:
                port.closePort()
        except PORT_ERRORS as e:
            log.debug("closing %s: %s", self.port_name, e)

    def _close_write(self, port: Any, name: str, value: int, ids: list[int],
                     consequence: str) -> None:
        """One sync write of ``name`` = ``value`` while closing; failures are only logged."""
        try:
            port.is_using = False
            reg = self.table[name]
            group = self.sdk.GroupSyncWrite(port, self._ph, reg.address, reg.size)
            for sid in ids:
                group.addParam(sid, list(value.to_bytes(reg.size, "little")))
            result = group.txPacket()
            if result != self.sdk.COMM_SUCCESS:
                log.warning("%s=%d on close failed: %s; servos %s: %s", name, value,
                            self._ph.getTxRxResult(result), ids, consequence)
        except PORT_ERRORS as e:
            log.warning("%s=%d on close failed (port error: %s); servos %s: %s", name, value,
                        e, ids, consequence)

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

    def read_register(self, sid: int, name: str) -> int:
        """Unsigned value of register ``name`` of servo ``sid``."""
        reg = self.table[name]
        data, _ = self._transact(f"read {name}", sid, lambda: self._ph.readTxRx(
            self._port, sid, reg.address, reg.size))
        return int.from_bytes(bytes(data[:reg.size]), "little")

    def write_register(self, sid: int, name: str, value: int) -> None:
        """Write register ``name`` of servo ``sid`` and wait for its status reply."""
        reg = self.table[name]
        data = list(int(value).to_bytes(reg.size, "little", signed=value < 0))
        self._transact(f"write {name}={value}", sid, lambda: (None, *self._ph.writeTxRx(
            self._port, sid, reg.address, reg.size, data)))

    # ------------------------------------------------------------------ Bus API
    def ping(self, servo_id: int) -> int | None:
        model, _ = self._transact("ping", servo_id, lambda: self._ph.ping(self._port, servo_id),
                                  missing_ok=True)
        return None if model is None else int(model)

    def broadcast_ping(self) -> dict[int, int] | None:
        """``{id: model number}`` of every servo that answers one broadcast ping at the
        current baud (``{}`` when none does), or None when the SDK has no broadcast ping
        (scservo_sdk). A garbled reply (two servos sharing an id) raises BusError."""
        fn = getattr(self._ph, "broadcastPing", None)
        if fn is None:
            return None
        with self._lock:
            port = self._begin()
            try:
                data, result = fn(port)
            except PORT_ERRORS as e:
                port.is_using = False
                raise self._error(None, "broadcast ping", f"port error: {e}", None) from e
        if result not in (self.sdk.COMM_SUCCESS, self.sdk.COMM_RX_TIMEOUT):
            raise self._error(None, "broadcast ping", self._ph.getTxRxResult(result), result)
        return {int(sid): int(v[0]) for sid, v in data.items()}

    def stray_bytes(self, *, wait_s: float = 0.02) -> int:
        """How many bytes arrive within ``wait_s`` [s] after the last reply (then dropped):
        more than 0 after a ping means a second servo answered with the same id (on a real
        bus the replies collide) or line noise."""
        with self._lock:
            port = self._begin()
            time.sleep(wait_s)
            try:
                n = int(port.ser.in_waiting)
                if n:
                    port.ser.reset_input_buffer()
            except PORT_ERRORS as e:
                raise self._error(None, "read stray bytes", f"port error: {e}", None) from e
        return n

    def scan(self, ids: Iterable[int]) -> list[ServoInfo]:
        """The servos among ``ids`` that answer a ping; a silent id gets a second ping after
        the others (one late reply must not read as a missing servo, as in health.check)."""
        found: list[ServoInfo] = []
        unit_us = RETURN_DELAY_UNIT_S[self.family] * 1e6
        wanted = sorted(set(ids))
        models = {sid: self.ping(sid) for sid in wanted}
        models.update({sid: self.ping(sid) for sid in wanted if models[sid] is None})
        for sid, model in models.items():
            if model is None:
                continue
            found.append(ServoInfo(
                id=sid, model=model, model_name=model_name(self.family, model),
                firmware=self.read_register(sid, self.firmware_register),
                return_delay_us=self.read_register(sid, "return_delay_time") * unit_us,
                baud=self.baud))
        return found

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

    def arm_failsafe(self, ids: Iterable[int], *, timeout_s: float) -> float | None:
        wd = COMM_WATCHDOG[self.family]
        return None if wd is None else failsafe.arm(self, wd, ids, timeout_s)

    def disarm_failsafe(self, ids: Iterable[int]) -> None:
        wd = COMM_WATCHDOG[self.family]
        if wd is not None:
            failsafe.disarm(self, wd, ids)

    def release(self, ids: Iterable[int]) -> None:
        """Torque off on ``ids`` in one sync write (no status reply to wait for)."""
        ids = sorted(set(ids))
        if not ids:
            return
        reg = self.table["torque_enable"]

        def send() -> tuple[None, int, int]:
            group = self.sdk.GroupSyncWrite(self._port, self._ph, reg.address, reg.size)
            for sid in ids:
                group.addParam(sid, [0])
            return None, group.txPacket(), 0

        self._transact("sync write torque_enable=0", None, send)
        self._torqued.difference_update(ids)

    def write_goals(self, goals: Mapping[int, int]) -> None:
        if not goals:
            return
        check, size, writer = self.limits.check, self._goal_size, self._writer
        params = [(sid, check(sid, t).to_bytes(size, "little"))
                  for sid, t in goals.items()]

        def send() -> tuple[None, int, int]:
            writer.clearParam()
            for sid, data in params:
                writer.addParam(sid, data)
            return None, writer.txPacket(), 0

        self._transact("sync write goal_position", None, send)

    def read_state(self, ids: Iterable[int]) -> dict[int, ServoState]:
        ids = tuple(dict.fromkeys(ids))
        if not ids:
            return {}
        got: dict[int, Reply] = {}
        self._transact("sync read state", None, lambda: self._reader.exchange(ids, got),
                       blame=lambda: self._reader.failed)
        return {sid: self._decode_state(sid, *got[sid]) for sid in ids}

    def field(self, block: bytes, name: str) -> int:
        """Unsigned little-endian value of register ``name`` inside a state block."""
        reg = self.table[name]
        start = reg.address - self._block_start
        return int.from_bytes(block[start:start + reg.size], "little")
