"""The emulator's child process: ``python -c "import sim.emulator.child as c; c.child_main(fd)"``.

Started by :class:`sim.emulator.chain.Emulator`. ``fd`` is a socketpair end carrying
``multiprocessing`` Connection messages: first the :class:`ChainSpec`, then the requests
``sim.emulator.server.ChainServer`` answers. The child exits on ``stop`` or when the parent
goes away.
"""

from __future__ import annotations

import signal
from multiprocessing.connection import Connection

from robot.loop.priority import loop_priority
from sim.emulator.server import ChainServer

__all__ = ["NICE", "child_main", "serve"]

#: The emulator's scheduling priority (nice) where the system allows it (root, or
#: CAP_SYS_NICE; elsewhere it keeps the parent's). Servos have processors of their own: on
#: a machine that other work loads, the host under test should be the one kept waiting, not
#: the servos' replies (a starved emulator answered pings and reads 100-750 ms late).
NICE = -10


def child_main(fd: int) -> None:
    """Child-process entry point: ``fd`` is the control socket; the spec comes first."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)   # the parent decides when to stop
    with loop_priority(NICE):    # this process's one thread: the servos' replies
        serve(Connection(fd))


def serve(conn: Connection) -> None:
    """Build the chain from the spec ``conn`` brings, then serve it until it ends."""
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
