"""What the Dynamixel and Feetech buses share: one vendor SDK behind ``base.Bus``.

Subclasses set the SDK module and the control-table families their protocol speaks (the
bus drives one: its robot's servo model's), and implement three hooks (packet handler,
status-byte failure, state decoding). Register access, retries and messages live in
``SdkRegisters`` (robot/bus/sdk/registers.py); the bus adds opening and closing, scans,
goals, state reads and the failsafe, once.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Iterable, Mapping
from typing import Any, ClassVar

from robot.bus import health, rate_check
from robot.bus.base import Bus, ServoInfo, ServoState
from robot.bus.limits import TickLimits
from robot.bus.sdk import failsafe, gain_writer
from robot.bus.sdk.port import PORT_ERRORS
from robot.bus.sdk.registers import SdkRegisters
from robot.bus.sdk.sync_read import BlockSyncRead, Reply
from robot.bus.tables import COMM_WATCHDOG, RETURN_DELAY_UNIT_S, STATE_BLOCK, TABLES
from robot.bus.wire_time import TickWire, tick_wire
from robot.config.robot import RobotConfig
from robot.servo.models import ServoModel, lookup

log = logging.getLogger(__name__)


class SdkBus(SdkRegisters, Bus):
    """A servo chain driven through a vendor SDK. Subclasses: DynamixelBus, FeetechBus.

    port, baud, robot, retries, timeout_ms: as ``SdkRegisters`` (without a robot the bus
    can scan, ping and toggle torque but refuses goals); check_health: run the checks of
    ``robot.bus.health`` on open (results in ``self.health``).
    """

    port_class: ClassVar[type]
    firmware_register: ClassVar[str]

    def __init__(self, port: str, *, baud: int, robot: RobotConfig | None = None,
                 retries: int | None = None, timeout_ms: float | None = None,
                 check_health: bool = True, family: str | None = None) -> None:
        super().__init__(port, baud=baud, robot=robot, retries=retries, timeout_ms=timeout_ms,
                         family=family)
        #: first and last register of the read_state block (tables.STATE_BLOCK)
        self.state_block = STATE_BLOCK[self.family]
        self.check_health = check_health
        self.health: list[str] = []
        self.limits = TickLimits(robot)
        self._goal_size = self.table["goal_position"].size
        first, last = (self.table[n] for n in self.state_block)
        self._block_start = first.address
        self._reader = BlockSyncRead(self.sdk, first.address,
                                     last.address + last.size - first.address)
        self._writer: Any = None
        self._gains_done: set[int] = set()   # ids whose gains were written since open()

    # ------------------------------------------------------------------ hooks
    def _make_packet_handler(self) -> Any:
        raise NotImplementedError

    def _decode_state(self, sid: int, block: bytes, status: int) -> ServoState:
        raise NotImplementedError

    # ------------------------------------------------------------------ lifecycle
    def open(self) -> None:
        if self.is_open:
            return
        port = self.port_class(self.port_name)
        port.timeout_ms = self.timeout_ms
        self._gains_done.clear()
        self.return_delay_s = 0.0       # measured again by the health check
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
                group.addParam(sid, list(value.to_bytes(reg.size, self.byteorder)))
            result = group.txPacket()
            if result != self.sdk.COMM_SUCCESS:
                log.warning("%s=%d on close failed: %s; servos %s: %s", name, value,
                            self._ph.getTxRxResult(result), ids, consequence)
        except PORT_ERRORS as e:
            log.warning("%s=%d on close failed (port error: %s); servos %s: %s", name, value,
                        e, ids, consequence)

    # ------------------------------------------------------------------ Bus API
    def broadcast_ping(self) -> dict[int, int] | None:
        """``{id: model number}`` of every servo that answers one broadcast ping at the
        current baud (``{}`` when none does), or None when the protocol has no broadcast
        ping: scservo_sdk has none, and dynamixel_sdk's Protocol 1.0 handler returns
        COMM_NOT_AVAILABLE without sending anything (its API reference: "Available only in
        Protocol 2.0"). A garbled reply (two servos sharing an id) raises BusError."""
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
        if result == getattr(self.sdk, "COMM_NOT_AVAILABLE", None):
            return None
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
        for sid, number in models.items():
            if number is None:
                continue
            servo = self.identify(sid, number)
            # A servo of another family of this protocol (an XL-320 on an X chain) has its
            # firmware and return delay at its own table's addresses.
            table = TABLES[servo.family] if servo is not None else self.table
            found.append(ServoInfo(
                id=sid, model=servo.number if servo else number,
                model_name=servo.name if servo else f"unknown({number})",
                firmware=self.read_register(sid, self.firmware_register, table=table),
                return_delay_us=self.read_register(sid, "return_delay_time",
                                                   table=table) * unit_us,
                baud=self.baud))
        return found

    def identify(self, sid: int, number: int) -> ServoModel | None:
        """The model behind servo ``sid`` that reported ``number`` on a ping: the robot
        file's joint model when its number matches (two models may share one: the 7.4 V and
        12 V STS3215), else the model with that number among the protocol's families."""
        joint = self.robot.joint_by_id(sid) if self.robot else None
        if joint is not None and self.robot is not None:
            configured = self.robot.servo(joint)
            if configured.number == number:
                return configured
        return lookup((self.family, *self.families), number)

    def arm_failsafe(self, ids: Iterable[int], *, timeout_s: float) -> float | None:
        wd = COMM_WATCHDOG[self.family]
        return None if wd is None else failsafe.arm(self, wd, ids, timeout_s)

    def failsafe_tripped(self, ids: Iterable[int]) -> list[int]:
        wd = COMM_WATCHDOG[self.family]
        return [] if wd is None else failsafe.tripped(self, wd, ids)

    def disarm_failsafe(self, ids: Iterable[int]) -> None:
        wd = COMM_WATCHDOG[self.family]
        if wd is not None:
            failsafe.disarm(self, wd, ids)

    def release(self, ids: Iterable[int]) -> None:
        """Torque off on ``ids`` in one sync write (no status reply to wait for)."""
        ids = sorted(set(ids))
        self.sync_write(self.table["torque_enable"], dict.fromkeys(ids, 0), "torque_enable=0")
        self._torqued.difference_update(ids)

    def set_torque(self, ids: Iterable[int], *, enabled: bool) -> None:
        """Torque on or off; before the first torque-on of a servo since ``open()``, its
        gains from the robot file are written and verified (robot.bus.sdk.gain_writer)."""
        ids = sorted(set(ids))
        pending = [sid for sid in ids if sid not in self._gains_done] if enabled else []
        if pending:
            gain_writer.apply(self, pending)
            self._gains_done.update(pending)
        super().set_torque(ids, enabled=enabled)

    def max_rate_hz(self, *, read_every: int) -> float | None:
        wire = self.tick_wire(read_every)
        return None if wire is None else wire.max_rate_hz

    def check_rate(self, rate_hz: float, *, read_every: int) -> None:
        rate_check.check_rate(self, rate_hz, read_every)

    def tick_wire(self, read_every: int) -> TickWire | None:
        if self.robot is None:
            return None
        return tick_wire(self.family, servos=len(self.robot.ids), baud=self.baud,
                         goal_size=self._goal_size, block_size=self._reader.length,
                         read_every=read_every)

    def read_gains(self, servo_id: int, *, model: int | None = None) -> dict[str, int] | None:
        joint = self.robot.joint_by_id(servo_id) if self.robot else None
        servo = self.robot.servo(joint) if self.robot and joint else None
        if model is not None and (servo is None or servo.number != model):
            servo = self.identify(servo_id, model)   # the servo found is not the file's
        return None if servo is None else gain_writer.read(self, servo_id, servo.gain_set)

    def write_goals(self, goals: Mapping[int, int]) -> None:
        if not goals:
            return
        check, size, writer = self.limits.check, self._goal_size, self._writer
        order = self.byteorder
        params = [(sid, check(sid, t).to_bytes(size, order))
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
        """Unsigned value of register ``name`` inside a state block (the table's byte order)."""
        reg = self.table[name]
        start = reg.address - self._block_start
        return int.from_bytes(block[start:start + reg.size], self.byteorder)
