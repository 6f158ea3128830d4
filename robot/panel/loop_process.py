"""The panel's control loop in a process of its own, and the pipe to it.

``LoopProcess`` (the panel's side) starts a fresh interpreter (``python -c``, like the
servo emulator: no ``__main__`` guard needed anywhere) that runs ``child_main``: it builds
the bus and the loop (robot.panel.loop_host) from a ``HostSpec`` and serves commands sent
over a socketpair, one Connection, in the order they were sent. Each command gets exactly
one answer (a payload, or an error by kind), so the pipe never holds more than the
commands in flight: the loop never blocks on the panel's side reading.

The child has its own session (a Ctrl-C at the terminal reaches only the panel, which
decides how the loop stops); SIGTERM sent to it directly asks for a safe stop of the run.
When the panel's side goes away (a crash, SIGKILL) the pipe ends: the loop stops the way
``shutdown`` does (ramp out, rest, torque off) and the process exits.
"""

from __future__ import annotations

import itertools
import logging
import os
import signal
import socket
import subprocess
import sys
import threading
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

from robot.bus.lease import BusBusy
from robot.errors import BipedError, BusError, ConfigError
from robot.panel.options import HostSpec, PanelStateError

log = logging.getLogger(__name__)

ROOT = Path(__file__).resolve().parents[2]  # puts `robot` (and `sim`) on the child's path
START_TIMEOUT_S = 60.0  # the child's imports and the bus's opening (health checks) [s]


class LoopUnavailable(BipedError):
    """The loop process does not answer (busy beyond the timeout, or gone): 503."""


def _encode(result: object) -> tuple[str, Any]:
    if not isinstance(result, BaseException):
        return "ok", result
    kind = ("conflict" if isinstance(result, (BusBusy, PanelStateError)) else
            "config" if isinstance(result, ConfigError) else
            "bus" if isinstance(result, BusError) else
            "biped" if isinstance(result, BipedError) else "internal")
    return kind, str(result) if kind != "internal" else f"{type(result).__name__}: {result}"


def _decode(kind: str, payload: Any) -> Any:
    if kind == "ok":
        return payload
    if kind == "conflict":
        raise PanelStateError(payload)
    if kind == "config":
        raise ConfigError(payload)
    if kind == "bus":
        raise BusError(payload)
    if kind == "biped":
        raise BipedError(payload)
    raise RuntimeError(f"the control loop failed: {payload}")


class Pending:
    """An answer on its way (``wait``)."""

    def __init__(self, op: str, rid: int = 0) -> None:
        self.op = op
        self.rid = rid
        self._event = threading.Event()
        self._answer: tuple[str, Any] = ("internal", "no answer")

    @property
    def answered(self) -> bool:
        return self._event.is_set()

    def set(self, answer: tuple[str, Any]) -> None:
        self._answer = answer
        self._event.set()

    def wait(self, timeout: float) -> Any:
        if not self._event.wait(timeout):
            raise LoopUnavailable(f"the control loop did not answer {self.op!r} within "
                                  f"{timeout:g} s")
        return _decode(*self._answer)


class LoopProcess:
    """The panel's side of the pipe. ``start()`` spawns the loop process and waits until
    its bus is open (raising its error as one line if it could not open)."""

    def __init__(self, spec: HostSpec) -> None:
        self.spec = spec
        self._proc: subprocess.Popen[bytes] | None = None
        self._conn: Connection | None = None
        self._send_lock = threading.Lock()
        self._pending: dict[int, Pending] = {}
        self._ids = itertools.count(1)
        self.gone: str | None = None  # why the pipe ended

    @property
    def pid(self) -> int | None:
        return self._proc.pid if self._proc is not None else None

    def in_flight(self, op: str) -> int:
        """How many ``op`` commands sent are still unanswered."""
        return sum(1 for slot in list(self._pending.values()) if slot.op == op)

    def start(self) -> None:
        parent_sock, child_sock = socket.socketpair()
        fd = child_sock.fileno()
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH", ""))
                                            if p)
        self._proc = subprocess.Popen(
            [sys.executable, "-c", f"import robot.panel.loop_process as m; m.child_main({fd})"],
            pass_fds=[fd], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, env=env,
            start_new_session=True)
        child_sock.close()
        conn = Connection(parent_sock.detach())
        level = logging.getLogger().getEffectiveLevel()
        try:
            conn.send((self.spec, level))
            if not conn.poll(START_TIMEOUT_S):
                raise LoopUnavailable(f"the control loop did not start within "
                                      f"{START_TIMEOUT_S:g} s")
            kind, payload = conn.recv()
        except (OSError, EOFError) as e:
            self._reap()
            raise LoopUnavailable(f"the control loop process died while starting (exit "
                                  f"code {self._proc.returncode}); see its messages above") \
                from e
        except BaseException:
            self._reap()
            raise
        if kind != "ok":
            self._reap()
            _decode(kind, payload)
        self._conn = conn
        threading.Thread(target=self._read, name="panel-loop-pipe", daemon=True).start()

    def _read(self) -> None:
        conn = self._conn
        assert conn is not None
        try:
            while True:
                rid, answer = conn.recv()
                slot = self._pending.pop(rid, None)
                if slot is not None:
                    slot.set(answer)
        except (OSError, EOFError):
            pass
        code = self._proc.wait() if self._proc is not None else None
        self.gone = f"the control loop process has ended (exit code {code})"
        for slot in list(self._pending.values()):
            slot.set(("biped", self.gone))
        self._pending.clear()

    def send(self, op: str, **args: Any) -> Pending:
        """Send ``op`` now (in the caller's order); its answer comes to the Pending."""
        rid = next(self._ids)
        slot = Pending(op, rid)
        if self.gone is not None or self._conn is None:
            slot.set(("biped", self.gone or "the control loop is not running"))
            return slot
        self._pending[rid] = slot
        try:
            with self._send_lock:
                self._conn.send((rid, op, args))
        except (OSError, ValueError) as e:
            self._pending.pop(rid, None)
            slot.set(("biped", f"the control loop is gone: {e}"))
        return slot

    def call(self, op: str, *, timeout: float = 10.0, **args: Any) -> Any:
        """Send ``op`` and wait for its answer (LoopUnavailable after ``timeout`` [s]; a
        late answer is then dropped)."""
        slot = self.send(op, **args)
        try:
            return slot.wait(timeout)
        except LoopUnavailable:
            self._pending.pop(slot.rid, None)
            raise

    def close(self, timeout: float = 5.0) -> int | None:
        """End the pipe (the loop process ends as after ``shutdown``) and reap it. Shut
        down, not only closed: the reader thread is inside a read on it."""
        if self._conn is not None:
            try:
                sock = socket.socket(fileno=self._conn.fileno())
                sock.shutdown(socket.SHUT_RDWR)
                sock.detach()
            except OSError:
                pass
            self._conn.close()
        return self._reap(timeout)

    def _reap(self, timeout: float = 5.0) -> int | None:
        proc = self._proc
        if proc is None:
            return None
        try:
            return proc.wait(timeout)
        except subprocess.TimeoutExpired:
            log.error("the control loop process did not end; killing it")
            proc.kill()
            return proc.wait()


# ------------------------------------------------------------------------------ child
def child_main(fd: int) -> None:
    """The loop process: build the host from the spec, then serve commands until the
    panel says shutdown or its side of the pipe ends."""
    from robot.panel.loop_host import LoopHost
    from robot.panel.loop_serve import serve

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    conn = Connection(fd)
    spec, level = conn.recv()
    logging.basicConfig(level=level, stream=sys.stderr,  # as robot.cli writes its own
                        format=("%(levelname)s %(name)s: %(message)s"
                                if level <= logging.DEBUG else "%(levelname)s: %(message)s"))
    sys.setswitchinterval(0.0005)  # the loop thread gets the interpreter back quickly
    host = LoopHost(spec)
    try:
        host.open()
    except BaseException as e:
        conn.send(_encode(e if isinstance(e, BipedError) else
                          BipedError(f"{type(e).__name__}: {e}")))
        conn.close()
        raise SystemExit(2) from None
    conn.send(("ok", None))
    serve(conn, host, _encode)
    logging.shutdown()
    os._exit(0)       # the bus is closed, the loop thread joined: no teardown to wait for
