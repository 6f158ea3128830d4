"""The emulator's child process: owns the pty, the servos, the fault state and the log.

Run by ``sim.emulator.child`` in the child process: ``conn`` carries ``multiprocessing``
Connection messages, requests ``(cmd, args)`` each answered ``("ok", payload)`` or
``("error", message)``. It serves until ``stop`` or until the parent goes away.
"""

from __future__ import annotations

import collections
import fcntl
import gc
import os
import random
import select
import struct
import termios
import time
import tty
from multiprocessing.connection import Connection
from types import ModuleType
from typing import Any

from sim.emulator import dxl1_protocol, dxl_protocol, lx_protocol, sts_protocol
from sim.emulator.dual_axis import case_mates, link_cases
from sim.emulator.line import Line, Outbox, pty_speed
from sim.emulator.records import ChainSpec, EmulatorError, Packet
from sim.emulator.servo import EmulatedServo
from sim.emulator.servo_dynamics import ServoDynamics

__all__ = ["ChainSpec", "EmulatorError", "Packet", "ChainServer"]

LOG_MAX = 200_000            # packets kept in the child
#: Packets between two ``gc.freeze()`` calls: the log's records are never garbage, and a
#: full collection that walks 200,000 of them stalls replies by tens of ms.
FREEZE_EVERY = 2000
QUIET_POLL_S = 0.005         # idle wake-up [s]: how fresh ``quiet_at`` stays (see serve)
DEFAULT_BAUD = 1_000_000     # [bit/s] when neither the pty nor the servos name a rate
PACKET_DATA = bytes([termios.TIOCPKT_DATA])   # a data read of the master in packet mode
COUNTER_KEYS = ("rx_bytes", "tx_bytes", "rx_packets", "tx_packets", "rx_bad_checksum",
                "dropped", "corrupted", "baud_mismatch", "tx_overflow", "cancelled",
                "late_max_us", "late_over_1ms", "host_output_flushes")


#: Wire protocol codec per bus kind.
CODECS: dict[str, ModuleType] = {"dynamixel": dxl_protocol, "dynamixel1": dxl1_protocol,
                                 "feetech": sts_protocol, "lx": lx_protocol}


class ChainServer:
    """Runs in the child: owns the pty, the servos and the fault state."""

    def __init__(self, spec: ChainSpec, conn: Connection) -> None:
        self.conn = conn
        self.codec: ModuleType = CODECS[spec.protocol]
        self.parser = self.codec.Parser()
        now = time.monotonic()
        servo_class = getattr(self.codec, "SERVO", EmulatedServo)  # LX: no control table
        self.servos = [servo_class(s, now) for s in spec.servos]
        for servo, model in zip(self.servos, spec.dynamics, strict=False):
            servo.dynamics = None if model is None else ServoDynamics(model)
        link_cases(self.servos)     # the two axes of a dual-axis case (2XL430-W250)
        self.plugged: set[int] = set(range(len(self.servos)) if spec.plugged is None
                                     else spec.plugged)
        self.rng = random.Random(spec.seed)
        self.log: collections.deque[Packet] = collections.deque(maxlen=LOG_MAX)
        self.counters: dict[str, int] = dict.fromkeys(
            [*COUNTER_KEYS, *self.codec.NAMES.values()], 0)
        self.drop_rate = self.corrupt_rate = 0.0
        self.missing: set[int] = set()
        self.vanish: dict[int, float] = {}
        self.quiet_at = now      # the last time the line was seen empty [s]
        self.line = Line()
        self.outbox = Outbox()
        self.frozen_at = 0       # rx_packets at the last gc.freeze()
        master, slave = os.openpty()
        tty.setraw(slave)
        os.set_blocking(master, False)
        # Packet mode: each read of the master is a data packet (a 0 byte first) or one
        # status byte, which tells when the host flushed its output (tcflush TCOFLUSH):
        # on a pty that discards what the kernel had not yet delivered (docs/third_party.md)
        fcntl.ioctl(master, termios.TIOCPKT, struct.pack("i", 1))
        self.master: int | None = master
        self.slave: int | None = slave
        self.path = os.ttyname(slave)

    def by_id(self, servo_id: int) -> EmulatedServo:
        """The servo with ``servo_id``, a plugged one first when several share it."""
        order = sorted(range(len(self.servos)), key=lambda i: i not in self.plugged)
        for i in order:
            if self.servos[i].servo_id == servo_id:
                return self.servos[i]
        raise EmulatorError(f"no emulated servo with id {servo_id}; ids: "
                            f"{sorted(s.servo_id for s in self.servos)}")

    def port_speed(self) -> int | None:
        """The baud rate [bit/s] the host configured on the slave, if readable."""
        return None if self.slave is None else pty_speed(self.slave)

    # ------------------------------------------------------------------ wire
    def on_bytes(self, data: bytes, now: float) -> None:
        """Bytes from the host, read at ``now`` [s]: execute each complete packet and
        schedule its replies after the wire time of the bytes and the return delays."""
        self.counters["rx_bytes"] += len(data)
        before = self.parser.bad_checksum
        frames = self.parser.feed(data)
        self.counters["rx_bad_checksum"] += self.parser.bad_checksum - before
        speed = self.port_speed()
        baud = float(speed or self.servos[0].baud or DEFAULT_BAUD)
        if self.outbox.next_at is not None:
            # The host talks before the replies it asked for are out: it gave up on them
            # (a timeout, a bad reply). The rest of the chain stays silent.
            self.counters["cancelled"] += self.outbox.clear()
            self.line.free_at = now
        self.line.instruction(now, len(data), baud)
        for servo_id, inst, params in frames:
            present = [s for i, s in enumerate(self.servos) if i in self.plugged
                       and s.servo_id not in self.missing
                       and self.vanish.get(s.servo_id, float("inf")) > now]
            listening = [s for s in present if speed is None or s.baud == speed]
            if present and not listening:
                self.counters["baud_mismatch"] += 1
                continue
            for s in listening:     # motion is lazy: bring the addressed servos to now
                if servo_id in (s.servo_id, self.codec.BROADCAST_ID):
                    s.update(now, quiet_until=self.quiet_at)
            # Servos sharing an id all execute the packet and all answer (on a real bus
            # their replies collide); each layer holds at most one servo per id.
            layers: list[dict[int, EmulatedServo]] = []
            for s in listening:
                layer = next((d for d in layers if s.servo_id not in d), None)
                if layer is None:
                    layer = {}
                    layers.append(layer)
                layer[s.servo_id] = s
            handled = [self.codec.handle(servo_id, inst, params, d)
                       for d in layers or [{}]]
            h = handled[0]
            for layer, hl in zip(layers, handled, strict=False):
                addressed = layer.values() if self.codec.BROADCAST_ID in hl.ids else (
                    layer[i] for i in hl.ids if i in layer)
                for s in addressed:
                    s.hear(now)
            self.counters["rx_packets"] += 1
            self.counters[h.instruction] = self.counters.get(h.instruction, 0) + 1
            self.log.append(Packet(now, h.instruction, h.ids, h.address, h.values, h.length))
            for r in (r for hl in handled for r in hl.replies):
                self.schedule(r.data, r.delay_s, baud)

    def schedule(self, data: bytes, delay_s: float, baud: float) -> None:
        """Queue one status packet: lost or garbled as the faults say, else released when
        its last byte would reach the host (``line.Line.reply``)."""
        if self.rng.random() < self.drop_rate:
            self.counters["dropped"] += 1
            return
        if self.rng.random() < self.corrupt_rate:
            self.counters["corrupted"] += 1
            data = data[:-1] + bytes([data[-1] ^ 0xFF])   # the checksum / CRC high byte
        self.outbox.put(self.line.reply(delay_s, len(data), baud), data)

    def release(self, now: float) -> None:
        """Write every reply due at ``now`` [s] to the host; count how late [µs]."""
        for at, data in self.outbox.due(now):
            if self.master is None:
                return
            late_us = round((time.monotonic() - at) * 1e6)
            self.counters["late_max_us"] = max(self.counters["late_max_us"], late_us)
            self.counters["late_over_1ms"] += late_us > 1000
            try:
                n = os.write(self.master, data)
            except (BlockingIOError, OSError):
                n = 0
            if n < len(data):
                self.counters["tx_overflow"] += 1
            self.counters["tx_bytes"] += n
            self.counters["tx_packets"] += 1

    def read_wire(self, now: float) -> bool:
        """Read and execute what the host sent (up to 4 kB); False when nothing was there."""
        assert self.master is not None
        try:
            data = os.read(self.master, 4097)
        except OSError:      # EAGAIN, EINTR; EIO: nobody has the slave open
            data = b""
        if data[:1] == PACKET_DATA:
            if len(data) > 1:
                self.on_bytes(data[1:], now)
        elif data:           # a status byte (packet mode)
            self.counters["host_output_flushes"] += bool(data[0] & termios.TIOCPKT_FLUSHWRITE)
        return bool(data)

    def close_port(self) -> None:
        self.outbox.clear()
        for fd in (self.master, self.slave):
            if fd is not None:
                os.close(fd)
        self.master = self.slave = None

    # ------------------------------------------------------------------ control
    def on_request(self, cmd: str, args: tuple[Any, ...]) -> Any:
        if cmd == "faults":
            return self.set_faults(args[0])
        if cmd == "clear":
            self.drop_rate = self.corrupt_rate = 0.0
            self.missing.clear()
            self.vanish.clear()
            for s in self.servos:
                s.conditions.clear()
                s.stuck = False
                s.frozen = set()
            return None
        if cmd == "log":
            out = list(self.log)
            if args[0]:
                self.log.clear()
            return out
        if cmd == "counters":
            return dict(self.counters)
        if cmd == "registers":
            return self.advance(self.by_id(args[0])).snapshot()
        if cmd == "plug":
            return self.plug(args[0])
        if cmd == "registers_of":
            return self.advance(self.servos[args[0]]).snapshot()
        if cmd == "set_register":
            s = self.advance(self.by_id(args[0]))
            return getattr(s, "pin", s.set)(args[1], args[2])   # LX servos compute none
        raise EmulatorError(f"unknown emulator request {cmd!r}")

    def advance(self, s: EmulatedServo) -> EmulatedServo:
        """``s`` updated to now. Its watchdog counts only the silence this process saw: a
        stall of the emulator itself (a loaded machine) is not a silent host."""
        s.update(time.monotonic(), quiet_until=self.quiet_at)
        return s

    def plug(self, indices: list[int] | None) -> None:
        """Connect exactly ``indices`` (None: every servo); a newly connected servo powers on."""
        wanted = set(range(len(self.servos))) if indices is None else set(indices)
        wanted |= {j for i in wanted for j in case_mates(self.servos, i)}   # a whole case
        now = time.monotonic()
        for i in self.plugged - wanted:
            self.servos[i].power_off(now)
        for i in wanted - self.plugged:
            self.servos[i].power_on(now)
        self.plugged = wanted

    def set_faults(self, f: dict[str, Any]) -> None:
        if f.get("drop_rate") is not None:
            self.drop_rate = f["drop_rate"]
        if f.get("corrupt_rate") is not None:
            self.corrupt_rate = f["corrupt_rate"]
        if f.get("missing_ids") is not None:
            self.missing = set(f["missing_ids"])
        self.vanish.update(f.get("vanish_at") or {})
        if f.get("stuck_ids") is not None:
            for s in self.servos:
                self.advance(s).stuck = s.servo_id in f["stuck_ids"]
        for sid, names in (f.get("frozen") or {}).items():
            self.by_id(sid).frozen = set(names)
        for sid, kind in (f.get("hw_error") or {}).items():
            s = self.by_id(sid)
            s.conditions = {kind} if kind else set()
            self.advance(s)
        if f.get("close_port"):
            self.close_port()

    def serve(self) -> None:
        self.conn.send(("ready", self.path))
        while True:
            fds: list[Any] = [self.conn] + ([self.master] if self.master is not None else [])
            due = self.outbox.next_at
            wait = QUIET_POLL_S if due is None else min(QUIET_POLL_S,
                                                        max(0.0, due - time.monotonic()))
            readable, _, _ = select.select(fds, [], [], wait)
            now = time.monotonic()
            if self.master not in readable:
                self.quiet_at = now
            if self.master is not None and self.master in readable:
                self.read_wire(now)
            self.release(time.monotonic())
            if self.counters["rx_packets"] >= self.frozen_at + FREEZE_EVERY:
                self.frozen_at = self.counters["rx_packets"]
                gc.freeze()
            if self.conn in readable:
                # Everything the host wrote before it asked is on the wire: a starved
                # emulator (a loaded machine) executes it before it answers, so a test
                # that reads registers after its command returned sees its last writes.
                while self.master is not None and self.read_wire(time.monotonic()):
                    self.release(time.monotonic())
                try:
                    cmd, args = self.conn.recv()
                except (EOFError, OSError):
                    return           # the parent is gone
                if cmd == "stop":
                    self.conn.send(("ok", None))
                    return
                try:
                    self.conn.send(("ok", self.on_request(cmd, args)))
                except Exception as e:  # noqa: BLE001 - report every failure to the parent
                    self.conn.send(("error", f"{type(e).__name__}: {e}"))
