"""A chain of emulated servos on a pseudo-terminal, served from its own process.

The real vendor SDKs open the pty's slave path like a USB adapter and talk their protocol
to it; the test process drives faults and reads the log through a pipe while the child serves.
- Time: ``time.monotonic()`` [s] (system-wide on Linux); motion is lazy, at each packet.
- Baud: a pty carries no baud rate, but pyserial stores the requested speed in the slave's
  termios; the child holds the slave open and reads that speed (``TCGETS2``) at every
  packet. A servo whose ``baud_rate`` register names another rate does not hear the packet
  (counted as ``baud_mismatch``), so "wrong baud: nothing answers" is testable.
- Wire time (``sim.emulator.line``): a reply reaches the host when a real 8N1 line would
  have carried it: after the instruction's bytes, the servo's return delay and its own
  bytes at the baud rate, one talker at a time. A missing servo costs the SDK its timeout.
- Hardware faults: Dynamixel X latches ``hardware_error_status`` until reboot and drops
  torque (shutdown), every status packet then carries the alert bit 0x80; Feetech's
  ``status`` register follows the injected condition live and is the reply's error byte.
- Bus Watchdog (Dynamixel X): each servo keeps the time of the last instruction packet
  addressed to it; armed, torque on and silent for longer than the setting, it stops
  (goal := present), the register reads -1 and goal writes get a Data Range Error until
  0 is written; torque stays on. Evaluated lazily like motion, so ``registers()`` after a
  silent gap shows the trip. Feetech STS has no such register (see ``servo_status.BUS_WATCHDOG``).
- Log: one :class:`Packet` per heard instruction packet with a valid checksum (broadcast:
  id 254); values in the servo's byte order, signed per the X table; bulk reads: id → address.
- Servos travel at constant speed onto the goal, or move by the servo model
  (``motion="model"``: ``servo_dynamics``; ``loads``: id → a weight on its arm), from the
  joint's ``zero_ticks`` (2048 without a robot), limits: the joint's in ticks (outward).
  Sync/bulk reads answer in packet order; a missing servo silences the rest; a chain
  built from a robot is already set up (return delay 0).
- Factory-new servos (:meth:`Emulator.factory_new`): id 1, factory baud and return delay,
  unplugged until :meth:`Emulator.plug` / :meth:`Emulator.plug_all`. Unplugging powers a
  servo off: it keeps its EEPROM (on STS only what was written with Lock 0), RAM restarts.
  Servos sharing an id all execute a packet and all answer, one status each (a real bus
  would garble the overlapping replies; here the host sees both).
- Closing the port (``set_faults(close_port=True)``) makes the SDK's next call raise
  (``termios.error``/``SerialException``, EIO) and leaves ``PortHandler.is_using`` set.
- dynamixel_sdk 4.1 does not byte-stuff what it sends; the parser reads such packets by
  length. Replies are stuffed, and the SDK unstuffs them.
"""

from __future__ import annotations

import logging
import os
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import replace
from multiprocessing.connection import Connection
from pathlib import Path
from types import TracebackType
from typing import Any

from robot.config.robot import RobotConfig
from robot.servo.bench_load import BenchLoad
from sim.emulator.chain_specs import FACTORY_BAUD, FACTORY_ID, factory_baud, factory_servos, plan_chain
from sim.emulator.control_tables import BAUD_CODES, TABLES
from sim.emulator.records import ChainSpec, EmulatorError, Packet
from sim.emulator.servo_models import MODELS
from sim.emulator.servo_status import ERROR_BITS

__all__ = ["ChainSpec", "Emulator", "EmulatorError", "Packet"]

log = logging.getLogger(__name__)

ROOT = Path(__file__).resolve().parents[2]  # puts `sim` and `robot` on the child's path
REPLY_TIMEOUT_S = 5.0        # control-channel answer [s]
START_TIMEOUT_S = 20.0       # child start-up [s]


class Emulator:
    """A servo chain on a pty in a child process. No I/O until :meth:`start`."""

    def __init__(self, protocol: str, robot: RobotConfig | None = None, *,
                 ids: Sequence[int] | None = None, model: str | None = None, seed: int = 0,
                 baud: int | None = None, loads: Mapping[int, BenchLoad] | None = None,
                 motion: str = "travel") -> None:
        choice = plan_chain(protocol, robot, ids=ids, model=model, baud=baud, loads=loads,
                            motion=motion)
        self.protocol = protocol
        self.family = MODELS[choice.model].family     # the chain's table family
        self.model, self.baud, self.ids = choice.model, choice.baud, choice.ids
        self.spec = ChainSpec(protocol, choice.servos, seed, dynamics=choice.dynamics)
        self._proc: subprocess.Popen[bytes] | None = None
        self._conn: Connection | None = None
        self._port: str | None = None
        self._lock = threading.Lock()

    @classmethod
    def factory_new(cls, protocol: str, count: int, *, model: str | None = None) -> Emulator:
        """``count`` servos as they come out of the box, none plugged in yet.

        Each has id 1, the factory baud and return delay, torque off and its horn at
        mid-range; connect them with :meth:`plug` (one at a time) or :meth:`plug_all`.
        """
        if protocol not in FACTORY_BAUD:
            raise EmulatorError(f"protocol: expected one of {', '.join(FACTORY_BAUD)}, "
                                f"got {protocol!r}")
        if count < 1:
            raise EmulatorError(f"count: expected at least 1 servo, got {count}")
        emu = cls(protocol, ids=[FACTORY_ID] * count, model=model,
                  baud=factory_baud(protocol, model))
        emu.spec = replace(emu.spec, plugged=(), servos=factory_servos(protocol, emu.spec.servos))
        emu.ids = tuple(s.servo_id for s in emu.spec.servos)   # a dual-axis case: 1 and 2
        return emu

    # ------------------------------------------------------------------ lifecycle
    def start(self) -> str:
        """Start the child; return the pty slave path (e.g. ``/dev/pts/5``).

        A fresh interpreter (``python -c``, sim.emulator.child: callers need no ``__main__``
        guard) with a socketpair for a Connection, run in ``ROOT`` (``-c`` puts the working
        directory first on sys.path, where another checkout's ``sim`` may be)."""
        if self._port is not None:
            return self._port
        parent_sock, child_sock = socket.socketpair()
        fd = child_sock.fileno()
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(
            p for p in (str(ROOT), env.get("PYTHONPATH", "")) if p)
        self._proc = subprocess.Popen(
            [sys.executable, "-c", f"import sim.emulator.child as c; c.child_main({fd})"],
            pass_fds=[fd], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, env=env, cwd=ROOT)
        child_sock.close()
        self._conn = Connection(parent_sock.detach())
        try:
            self._conn.send(self.spec)
            if not self._conn.poll(START_TIMEOUT_S):
                raise EmulatorError(
                    f"the emulator process did not start within {START_TIMEOUT_S} s")
            tag, path = self._conn.recv()
        except (OSError, EOFError) as e:
            self.stop()
            raise EmulatorError("the emulator process died while starting (see its "
                                "stderr)") from e
        except EmulatorError:
            self.stop()
            raise
        if tag != "ready":
            self.stop()
            raise EmulatorError(f"the emulator failed to start: {path}")
        self._port = str(path)
        log.info("emulating %d %s servos (%s, %d bit/s) on %s", len(self.ids), self.model,
                 self.protocol, self.baud, self._port)
        return self._port

    def stop(self) -> None:
        """Stop the child and close the pty. Idempotent."""
        conn, proc = self._conn, self._proc
        self._conn, self._proc, self._port = None, None, None
        if conn is not None:
            try:
                conn.send(("stop", ()))
                if conn.poll(1.0):
                    conn.recv()
            except (OSError, EOFError):
                pass
            conn.close()
        if proc is not None:
            try:
                proc.wait(2.0)
            except subprocess.TimeoutExpired:
                proc.terminate()
                proc.wait(2.0)

    @property
    def port(self) -> str:
        if self._port is None:
            raise EmulatorError("the emulator is not running; call start() first")
        return self._port

    @property
    def pid(self) -> int | None:
        """The child's process id while it runs (a test may SIGSTOP it: a starved chain)."""
        return None if self._proc is None else self._proc.pid

    @property
    def alive(self) -> bool:
        return self._proc is not None and self._proc.poll() is None

    def __enter__(self) -> Emulator:
        self.start()
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.stop()

    # ------------------------------------------------------------------ control
    def _call(self, cmd: str, *args: Any) -> Any:
        with self._lock:
            if self._conn is None:
                raise EmulatorError("the emulator is not running; call start() first")
            try:
                self._conn.send((cmd, args))
                if not self._conn.poll(REPLY_TIMEOUT_S):
                    raise EmulatorError(f"the emulator did not answer {cmd!r} within "
                                        f"{REPLY_TIMEOUT_S} s")
                tag, payload = self._conn.recv()
            except (OSError, EOFError) as e:
                raise EmulatorError(f"the emulator process is gone ({e!r})") from e
        if tag == "error":
            raise EmulatorError(payload)
        return payload

    def set_faults(self, *, drop_rate: float | None = None, corrupt_rate: float | None = None,
                   missing_ids: Iterable[int] | None = None,
                   vanish: Mapping[int, float] | None = None,
                   hw_error: Mapping[int, str | None] | None = None,
                   stuck_ids: Iterable[int] | None = None,
                   frozen: Mapping[int, Iterable[str]] | None = None,
                   close_port: bool = False) -> None:
        """Change faults while serving; unspecified ones keep their setting.

        drop_rate / corrupt_rate: share of replies lost / sent with a bad checksum [0..1];
        missing_ids: ids that never answer (replaces the set); vanish: id → seconds from now
        after which it stops answering; hw_error: id → "overheating" | "overload" |
        "voltage" | ... (names in servo_status.ERROR_BITS) or None to end the condition;
        stuck_ids: ids whose horn is jammed from now on (they answer, take goals and
        report no error, but do not move; replaces the set);
        frozen: id → registers that acknowledge writes but keep their value ([]: ends it);
        close_port: close the pty (the SDK then gets an error; the log stays readable).
        """
        for name, rate in (("drop_rate", drop_rate), ("corrupt_rate", corrupt_rate)):
            if rate is not None and not 0.0 <= rate <= 1.0:
                raise EmulatorError(f"{name}: expected a share in [0, 1], got {rate}")
        kinds = set(ERROR_BITS[self.family].values())
        for sid, kind in (hw_error or {}).items():
            if kind is not None and kind not in kinds:
                raise EmulatorError(f"hw_error[{sid}]: unknown fault {kind!r}; valid: "
                                    f"{', '.join(sorted(kinds))}")
        now = time.monotonic()
        self._call("faults", {
            "drop_rate": drop_rate, "corrupt_rate": corrupt_rate,
            "missing_ids": None if missing_ids is None else list(missing_ids),
            "vanish_at": {sid: now + t for sid, t in (vanish or {}).items()},
            "hw_error": dict(hw_error or {}), "close_port": close_port,
            "stuck_ids": None if stuck_ids is None else list(stuck_ids),
            "frozen": {sid: self._check_names(names) for sid, names in (frozen or {}).items()},
        })

    def clear_faults(self) -> None:
        """End every injected fault (a latched Dynamixel hardware error needs a reboot)."""
        self._call("clear")

    def log(self, *, clear: bool = False) -> list[Packet]:
        """Every logged instruction packet, oldest first; ``clear`` empties the log."""
        return list(self._call("log", clear))

    def counters(self) -> dict[str, int]:
        """Packets per instruction name, plus rx/tx bytes and packets and fault counts."""
        return dict(self._call("counters"))

    def registers(self, servo_id: int) -> dict[str, int]:
        """Snapshot of one servo's control table by register name (motion brought to now)."""
        return dict(self._call("registers", servo_id))

    def registers_of(self, index: int) -> dict[str, int]:
        """Snapshot of servo number ``index`` (0-based, plugged or not; ids may repeat)."""
        self._check_index(index)
        return dict(self._call("registers_of", index))

    def plug(self, index: int | None) -> None:
        """Connect servo number ``index`` (0-based) alone, unplugging the others; None: none.
        A servo plugged in powers on: it keeps its EEPROM (id, baud, ...); RAM restarts."""
        if index is not None:
            self._check_index(index)
        self._call("plug", [] if index is None else [index])

    def plug_all(self) -> None:
        """Connect every servo (a chain after setup)."""
        self._call("plug", None)

    def _check_index(self, index: int) -> None:
        if not 0 <= index < len(self.ids):
            raise EmulatorError(f"servo index {index} is out of range; the chain has "
                                f"{len(self.ids)} servos (0..{len(self.ids) - 1})")

    def set_register(self, servo_id: int, name: str, value: int) -> None:
        """Store a register without the checks a host write gets (e.g. return_delay_time)."""
        self._check_names([name])
        self._call("set_register", servo_id, name, int(value))

    def _check_names(self, names: Iterable[str]) -> list[str]:
        """``names``, each in some servo's control table (LX: none, its servo checks)."""
        valid = {n for s in self.spec.servos for n in TABLES.get(MODELS[s.model].layout, ())}
        if self.family in TABLES and (bad := [n for n in names if n not in valid]):
            raise EmulatorError(f"register {bad[0]!r} is not in the {self.family} tables; "
                                f"valid: {', '.join(sorted(valid))}")
        return list(names)

    def set_baud(self, baud: int) -> None:
        """Make every servo listen at ``baud`` [bit/s] (writes their baud_rate register)."""
        codes = {b: c for c, b in BAUD_CODES[self.family].items()}
        if baud not in codes:
            raise EmulatorError(f"baud: {baud} is not a {self.protocol} rate; valid: "
                                f"{sorted(codes)}")
        for sid in self.ids:
            self.set_register(sid, "baud_rate", codes[baud])
