"""The control loop's thread asks the OS for a higher priority while it streams to servos.

A loop that another process keeps off the CPU for longer than the servos' own bus watchdog
(robot.loop.watchdog, ``failsafe_s``: 0.1 s) stops the robot: the servos refuse goals from
then on. On a Raspberry Pi that also runs a camera, a browser or a build, a loop at the
default priority loses those races. So while it streams to servos (a wall clock, not the
simulation's), the loop's own thread runs at nice ``LOOP_NICE``; the rest of the process
(the panel's web server, a recorder) keeps its priority, and the thread's priority is put
back when the run ends, however it ends.

Linux keeps a nice value per thread (setpriority(2) with a thread id). Raising it needs
root or CAP_SYS_NICE (or an RLIMIT_NICE that allows it); without them the loop runs as
before and says so once, in the log. A real-time policy (SCHED_FIFO) is not asked for: a
Python loop that spun at a real-time priority could lock a single-core board up.
"""

from __future__ import annotations

import logging
import os
import threading
from collections.abc import Iterator
from contextlib import contextmanager

log = logging.getLogger(__name__)

#: The loop thread's nice value while it streams (-20 highest .. 19 lowest; 0 default).
LOOP_NICE = -10


@contextmanager
def loop_priority(nice: int = LOOP_NICE, *, wall_clock: bool = True) -> Iterator[None]:
    """Run the calling thread at ``nice`` (never lower than it already is) for the block,
    where the OS allows it; put back on exit. Nothing changes on a simulation's clock
    (``wall_clock`` False: nothing waits on servos, and a loop that steps physics flat out
    would take the CPU from everything else) or where the OS keeps no per-thread nice."""
    if not wall_clock:
        yield
        return
    tid = threading.get_native_id()
    try:
        before = os.getpriority(os.PRIO_PROCESS, tid)
    except (AttributeError, OSError):         # no per-thread nice here
        yield
        return
    wanted = min(before, nice)
    raised = False
    if wanted < before:
        try:
            os.setpriority(os.PRIO_PROCESS, tid, wanted)
            raised = True
        except PermissionError:
            log.info("the control loop runs at nice %d: raising it to %d needs root or "
                     "CAP_SYS_NICE (a loop kept off the CPU for 0.1 s trips the servos' "
                     "bus watchdog)", before, wanted)
    try:
        yield
    finally:
        if raised:
            os.setpriority(os.PRIO_PROCESS, tid, before)
