"""HiWonder/LewanSoul LX serial bus servos (LX-16A, LX-224, LX-224HV) on pyserial.

No vendor Python package is worth depending on (checked: ``pylx16a`` 1.1.1, last release
2022-04; ``lewansoul-lx16a`` 0.1, 2019; ``lx16a`` 0.0.2, 2020; ``lewanlib`` 0.1.1; HiWonder
ships its Python only as scripts inside its robots' images), and the protocol is small:
``robot.bus.lx.packet`` frames it, ``robot.bus.lx.tables.LX_COMMANDS`` holds the commands.

What the protocol makes different from the other buses (docs/hardware.md, "LX servos"):

- No sync write: ``write_goals`` sends one MOVE_TIME_WRITE per servo (in one write to
  the port) with move time = the time since the previous goals (the tick period while
  streaming; ``move_time_s`` for the first), so each servo arrives as the next goal comes.
  Write commands are never answered: a write cannot fail on the wire, a read shows it.
- No status read in one packet: ``read_state`` reads every position (POS_READ) and one
  more value of one servo in turn (``robot.bus.lx.status``).
- No model number and no baud register: ``ping`` (ID_READ) answers with the id only; the
  model reported is the robot file's. 115200 baud only.
- No communication watchdog: ``arm_failsafe`` returns None. A servo keeps its last goal
  when the host stalls; ``release`` unloads (LOAD_OR_UNLOAD_WRITE 0) by broadcast and
  servo by servo, needing no answer, so it works on a bus that stopped answering.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Iterable, Mapping

import serial

from robot.bus import health
from robot.bus.base import Bus, ServoInfo, ServoState
from robot.bus.limits import TickLimits
from robot.bus.lx.packet import encode, value, word
from robot.bus.lx.port import LX_VALUES, LxPort
from robot.bus.lx.status import LxStatus
from robot.bus.lx.tables import LX_BAUD, LX_BROADCAST_ID
from robot.bus.lx.wire import check_rate, max_rate_hz
from robot.bus.sdk.port import PORT_ERRORS, READ_BLOCK_S
from robot.config.robot import RobotConfig
from robot.errors import BusError
from robot.servo.models import MODELS

log = logging.getLogger(__name__)

#: The protocol's longest move time [s] (MOVE_TIME_WRITE: 0..30000 ms); a gap in the
#: stream longer than ``MAX_GAP_S`` moves at the pace of ``MAX_GAP_S`` instead.
MAX_MOVE_S = 30.0
MAX_GAP_S = 1.0
DEFAULT_MODEL = "LX-16A"


class LxBus(LxPort, Bus):
    """LX servo chain. ``LxBus(port, baud=115200, robot=..., retries=..., timeout_ms=...,
    move_time_s=..., model=..., check_health=...)``.

    retries: extra attempts per read (default robot.bus.retries, else 2); timeout_ms: wait
    for an answer [ms] (default robot.bus.timeout_ms, else 20); move_time_s: move time of
    the first goals [s] (later ones: the time since the previous goals); model: the model
    reported by ping without a robot config; check_health: ping the robot's servos on open.
    """

    kind = "lx"
    family = "lx"

    def __init__(self, port: str, *, baud: int = LX_BAUD, robot: RobotConfig | None = None,
                 retries: int | None = None, timeout_ms: float | None = None,
                 move_time_s: float = 0.02, model: str | None = None,
                 check_health: bool = True) -> None:
        if int(baud) != LX_BAUD:
            raise BusError(f"lx {port}: baud {baud} is not an LX rate; LX servos talk at "
                           f"{LX_BAUD} only")
        super().__init__(port, robot=robot,
                         retries=int(retries if retries is not None else
                                     (robot.bus.retries if robot else 2)),
                         timeout_ms=float(timeout_ms if timeout_ms is not None else
                                          (robot.bus.timeout_ms if robot else 20.0)))
        self.baud = LX_BAUD
        self.model = model or (robot.bus.model if robot else DEFAULT_MODEL)
        self.move_time_s = move_time_s
        self.check_health = check_health
        self.health: list[str] = []
        self.table = LX_VALUES
        self.limits = TickLimits(robot)
        self.status = LxStatus()
        self._torqued: set[int] = set()
        self._last_goals: float | None = None

    # ------------------------------------------------------------------ lifecycle
    @property
    def is_open(self) -> bool:
        return self._ser is not None and bool(self._ser.is_open)

    @property
    def retry_span_s(self) -> float:
        return self.timeout_ms * 1e-3 * (self.retries + 1)

    def open(self) -> None:
        if self.is_open:
            return
        try:
            self._ser = serial.Serial(self.port_name, LX_BAUD, timeout=READ_BLOCK_S)
        except (OSError, ValueError) as e:
            raise BusError(f"cannot open {self.port_name}: {e}; is the adapter plugged in "
                           "(ls /dev/serial/by-id/) and are you in the dialout group "
                           "(sudo usermod -aG dialout $USER)?") from e
        health.try_low_latency(self._ser)
        if self.check_health and self.robot is not None:
            try:
                self.health = self._check()
            except BaseException:
                self.close(torque_off=False)
                raise

    def _check(self) -> list[str]:
        warnings = [w for w in [health.latency_warning(self.port_name)] if w]
        ids = list(self.robot.ids) if self.robot else []
        missing = [i for i in ids if self.ping(i) is None]
        missing = [i for i in missing if self.ping(i) is None]   # one late reply is no loss
        if ids and len(missing) == len(ids):
            raise BusError(f"no servo answers on {self.port_name} at {LX_BAUD} baud (tried "
                           f"{', '.join(self.who(i) for i in ids[:4])}{' ...' * (len(ids) > 4)});"
                           " LX servos talk only at 115200: check their power (6-8.4 V; "
                           "LX-224HV 9-12.6 V), the half-duplex adapter and its wiring")
        if missing:
            warnings.append(f"configured servos not answering: "
                            f"{', '.join(self.who(i) for i in missing)}; check their power and "
                            "wiring (and ids with `biped scan --bus lx`)")
        for w in warnings:
            log.warning("%s", w)
        return warnings

    def close(self, *, torque_off: bool = True) -> None:
        ser, self._ser = self._ser, None
        if ser is None:
            return
        ids = sorted(set(self.robot.ids if self.robot else ()) | self._torqued)
        try:
            if torque_off and ids and ser.is_open:
                ser.write(self._unload_packets(ids))
                ser.flush()
        except PORT_ERRORS as e:
            log.warning("unload on close failed (port error: %s); servos %s may still hold "
                        "torque", e, ids)
        self._torqued.clear()
        try:
            ser.close()
        except PORT_ERRORS as e:
            log.debug("closing %s: %s", self.port_name, e)

    # ------------------------------------------------------------------ Bus API
    def _model_of(self, sid: int) -> str:
        joint = self.robot.joint_by_id(sid) if self.robot else None
        return (joint.model or self.model) if joint else self.model

    def ping(self, servo_id: int) -> int | None:
        """The (configured) model number if ``servo_id`` answers ID_READ, else None."""
        got = self._ask(servo_id, "id_read", attempts=1)
        return None if got is None else MODELS[self._model_of(servo_id)].number

    def broadcast_ping(self) -> dict[int, int]:
        """``{id: model}`` of a lone servo answering ID_READ at the broadcast id (the only
        read the servos answer there), ``{}`` when none does. Two servos garble it."""
        before = self.bad_checksum
        got = self._ask(LX_BROADCAST_ID, "id_read", attempts=1)
        if got is None:
            if self.bad_checksum > before:
                raise self._error(None, "broadcast id read", "garbled answers (two servos?)")
            return {}
        return {got[0]: MODELS[self.model].number}

    def set_baud(self, baud: int) -> None:
        """LX servos have one rate: anything but 115200 is a BusError."""
        if int(baud) != LX_BAUD:
            raise BusError(f"baud {baud} is not an LX rate; valid: {LX_BAUD}")

    def scan(self, ids: Iterable[int]) -> list[ServoInfo]:
        wanted = sorted(set(ids))
        models = {sid: self.ping(sid) for sid in wanted}
        models.update({sid: self.ping(sid) for sid in wanted if models[sid] is None})
        return [ServoInfo(id=sid, model=m, model_name=f"{self._model_of(sid)} (config)",
                          baud=LX_BAUD) for sid, m in models.items() if m is not None]

    def set_torque(self, ids: Iterable[int], *, enabled: bool) -> None:
        """Load (torque on) or unload every id, then read each load state back: BusError
        naming the servos that did not answer or did not take it."""
        ids = sorted(set(ids))
        self._send(b"".join(encode(sid, "load_or_unload_write", bytes([int(enabled)]))
                            for sid in ids))
        bad = []
        for sid in ids:
            got = self._ask(sid, "load_or_unload_read")
            if got is None or got[0] != int(enabled):
                bad.append(f"{self.who(sid)} ({'no answer' if got is None else got[0]})")
            else:
                (self._torqued.add if enabled else self._torqued.discard)(sid)
        if bad:
            raise self._error(None, f"{'load' if enabled else 'unload'} (torque "
                              f"{'on' if enabled else 'off'})", "not confirmed by "
                              + ", ".join(bad))

    def _unload_packets(self, ids: Iterable[int]) -> bytes:
        off = bytes([0])
        return encode(LX_BROADCAST_ID, "load_or_unload_write", off) + b"".join(
            encode(sid, "load_or_unload_write", off) for sid in ids)

    def release(self, ids: Iterable[int]) -> None:
        """Unload at once: one broadcast packet and one per id, no answer awaited."""
        ids = sorted(set(ids))
        self._send(self._unload_packets(ids))
        self._torqued.difference_update(ids)

    def write_goals(self, goals: Mapping[int, int]) -> None:
        if not goals:
            return
        now = time.monotonic()
        gap = self.move_time_s if self._last_goals is None else now - self._last_goals
        ms = word(round(min(max(gap, 0.0), MAX_GAP_S, MAX_MOVE_S) * 1000))
        check = self.limits.check
        data = b"".join(encode(sid, "move_time_write", word(check(sid, t)) + ms)
                        for sid, t in goals.items())
        self._send(data)
        self._last_goals = now

    def read_state(self, ids: Iterable[int]) -> dict[int, ServoState]:
        ids = tuple(dict.fromkeys(ids))
        query = self.status.next_query(ids)
        if query is not None:
            sid, name = query
            v = LX_VALUES[name]
            got = self._ask(sid, v.read)
            if got is not None:
                self.status.record(sid, name, [value(got, o, v.size) for o in
                                               range(v.offset, len(got), v.size)])
        out = {}
        for sid in ids:
            pos = self.read_register(sid, "present_position")
            out[sid] = self.status.state(sid, pos)
        return out

    def max_rate_hz(self, *, read_every: int) -> float | None:
        return max_rate_hz(len(self.robot.ids) if self.robot else 1, read_every=read_every)

    def check_rate(self, rate_hz: float, *, read_every: int) -> None:
        """ConfigError when the wire cannot carry ``rate_hz`` for this robot's servos."""
        check_rate(rate_hz, len(self.robot.ids) if self.robot else 1, read_every=read_every)
