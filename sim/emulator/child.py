"""The emulator's child process: ``python -c "import sim.emulator.child as c; c.child_main(fd)"``.

Started by :class:`sim.emulator.chain.Emulator`. ``fd`` is a socketpair end carrying
``multiprocessing`` Connection messages: first the :class:`ChainSpec`, then the requests
``sim.emulator.server.ChainServer`` answers. The child exits on ``stop`` or when the parent
goes away.
"""

from __future__ import annotations

import os
import signal
from multiprocessing.connection import Connection

from sim.emulator.server import ChainServer

__all__ = ["NICE", "child_main"]

#: The emulator's scheduling priority (nice) where the system allows it (root, or
#: CAP_SYS_NICE; elsewhere it keeps the parent's). Servos have processors of their own: on
#: a machine that other work loads, the host under test should be the one kept waiting, not
#: the servos' replies (a starved emulator answered pings and reads 100-750 ms late).
NICE = -10


def child_main(fd: int) -> None:
    """Child-process entry point: ``fd`` is the control socket; the spec comes first."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)   # the parent decides when to stop
    try:
        os.setpriority(os.PRIO_PROCESS, 0, NICE)
    except PermissionError:
        pass
    conn = Connection(fd)
    try:
        spec = conn.recv()
        server = ChainServer(spec, conn)
    except Exception as e:  # noqa: BLE001 - tell the parent why we could not start
        conn.send(("error", f"{type(e).__name__}: {e}"))
        conn.close()
        return
    try:
        server.serve()
    finally:
        server.close_port()
        conn.close()
