"""The loop process's command thread: every command in the order the panel sent it, one
answer each (robot.panel.loop_process). Quick commands are answered here; those that use
the bus take the lease here (so a second mover is refused at once) and are answered by the
loop thread (robot.panel.loop_host)."""

from __future__ import annotations

import logging
import signal
import threading
from collections.abc import Callable, Mapping
from multiprocessing.connection import Connection
from typing import Any

from robot.errors import ConfigError
from robot.panel.loop_host import Done, LoopHost

log = logging.getLogger(__name__)

Encode = Callable[[object], tuple[str, Any]]
Args = Mapping[str, Any]


def _commands(host: LoopHost) -> tuple[dict[str, Callable[[Args], object]],
                                       dict[str, Callable[[Args, Done], None]]]:
    quick: dict[str, Callable[[Args], object]] = {
        "state": lambda a: host.state(),
        "params": lambda a: host.set_params(a["changes"]),
        "preset": lambda a: host.load_preset(a["values"]),
        "stop": lambda a: host.stop(),
        "estop": lambda a: host.emergency_stop(),
        "clear": lambda a: host.posing.clear(),
        "keyframes": lambda a: host.posing.keyframes(a["name"]),
    }
    later: dict[str, Callable[[Args, Done], None]] = {
        "start": lambda a, done: host.start(a["kind"], done),
        "release": lambda a, done: host.release(a["limb"], done),
        "capture": lambda a, done: host.capture(a.get("t"), done),
        "reset": lambda a, done: host.reset(done),
        "shutdown": lambda a, done: host.shutdown(done),
    }
    return quick, later


def serve(conn: Connection, host: LoopHost, encode: Encode) -> None:
    """Answer commands until the pipe ends; then, if the panel did not shut the loop
    down itself, do it (the run ramps out, torque off) and wait for the loop thread."""
    lock = threading.Lock()

    def answer(rid: int) -> Done:
        sent = [False]

        def done(result: object) -> None:
            if sent[0]:
                return
            sent[0] = True
            try:
                with lock:
                    conn.send((rid, encode(result)))
            except (OSError, ValueError):
                log.debug("panel loop: the panel went away before answer %d", rid)
        return done

    quick, later = _commands(host)
    signal.signal(signal.SIGTERM, lambda signum, frame: host.stop())
    while True:
        try:
            rid, op, args = conn.recv()
        except (EOFError, OSError):
            break
        done = answer(rid)
        try:
            if op in later:
                later[op](args, done)
            elif op in quick:
                done(quick[op](args))
            else:
                done(ConfigError(f"unknown command {op!r}"))
        except Exception as e:
            done(e)
    if not host.closing:
        log.warning("panel loop: the panel is gone; stopping the robot")
        host.shutdown(lambda result: None)
    host.join()
