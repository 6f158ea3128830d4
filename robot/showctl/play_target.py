"""Show control during `biped play` (``--osc PORT``): a play streams a file, so only what
ends it makes sense: ``/biped/stop`` and ``/biped/take/stop`` (a safe stop: ramp out,
rest, torque off or ``--hold``), ``/biped/estop`` (torque off now), and ``/biped/cue``,
``/biped/go`` and MIDI Show Control STOP for a cue list's cues that do one of those. Anything
else (parameters, start, presets, other takes, poses) is logged once per kind and ignored:
the play's file drives the robot. The status out carries the play's show clock (the
engine's time [s]) and the joints as commanded.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from typing import Any

from robot.loop.telemetry import Telemetry
from robot.run.run import Run
from robot.showctl.actions import Command, Named
from robot.showctl.cues import CueList
from robot.showctl.feed import Feed
from robot.showctl.once import OnceLog
from robot.showctl.options import ShowOptions
from robot.showctl.osc_in import OscListener
from robot.showctl.osc_out import Status, StatusSender

log = logging.getLogger(__name__)

STOPS = ("stop", "take stop", "estop")


class PlayTarget:
    """The feed's target on one play: ``run`` (open), its ``joints`` and ``show_time``
    (the show's time [s]: the engine's, or the chased timecode's; None before it starts);
    ``take``: what plays (the file's name)."""

    def __init__(self, run: Run[Any], *, joints: tuple[str, ...], take: str,
                 show_time: Callable[[], float | None], cues: CueList | None = None,
                 once: OnceLog | None = None) -> None:
        self.run = run
        self.joints = joints
        self.take = take
        self.show_time = show_time
        self.cues = cues or CueList()
        self.once = once or OnceLog(log)

    def params(self, changes: Mapping[str, float], received: float) -> None:
        self.once.note("play params", "show control: a play runs its file's parameters; "
                       "/biped/param/... is ignored during biped play")

    def estop(self, received: float) -> None:
        log.warning("emergency stop (show control)")
        self.run.emergency_stop("emergency stop (show control)")

    def act(self, action: Command | Named, received: float) -> None:
        if isinstance(action, Named) and action.what == "cue":
            cue = self.cues.find(action.name or "")
            if cue is None:
                self.once.note("cue unknown", f"cue {action.name!r}: not in the cue list; "
                               f"valid: {self.cues.names()}")
                return
            action = cue.action
        elif action == Command("go"):
            cue = self.cues.go()
            if cue is None:
                self.once.note("go past the end", "GO: no cue after the last one fired")
                return
            action = cue.action
        if not isinstance(action, Command) or action.what not in STOPS:
            what = action.what if isinstance(action, Command) else f"{action.what} {action.name}"
            self.once.note(f"play {action.what}", f"show control: {what!r} does nothing "
                           "during biped play (it accepts stop, take stop, estop and cues "
                           "that do one of those)")
            return
        if action.what == "estop":
            self.estop(received)
        else:
            log.info("safe stop (show control: %s)", action.what)
            self.run.request_stop(f"show control: {action.what}")

    def status(self) -> Status:
        tel: Telemetry = self.run.streamer.telemetry
        q = tel.q_cmd or []
        t = self.show_time()                # None: a chased show waiting for its start
        return Status(state=str(tel.state), fault=None, show_t=None if t is None else float(t),
                      take=self.take, joints=tuple(zip(self.joints, q, strict=False)))


@contextmanager
def play_show_control(options: ShowOptions, run: Run[Any], *, joints: tuple[str, ...],
                      take: str, show_time: Callable[[], float | None], rate_hz: float,
                      announce: Callable[[str], None]) -> Iterator[None]:
    """OSC in (and status out) for an open ``run`` while the block streams it; nothing
    without ``--osc``. The port opens before the play moves (ConfigError, one line);
    ``announce(line)`` tells where it listens."""
    osc = options.osc
    if osc is None:
        yield
        return
    once = OnceLog(logging.getLogger("robot.showctl"))
    target = PlayTarget(run, joints=joints, take=take, show_time=show_time,
                        cues=options.cues, once=once)
    feed = Feed(target, rate_hz=rate_hz, once=once)
    listener = OscListener(feed, port=osc.port, host=osc.host, sources=osc.sources)
    reply = (StatusSender(target.status, host=osc.reply[0], port=osc.reply[1],
                          hz=osc.reply_hz) if osc.reply else None)
    listener.open()
    try:
        feed.start()
        if reply is not None:
            reply.start()
        announce(f"OSC on {osc.host}:{listener.port} (stop, take stop, estop, cues)")
        yield
    finally:
        listener.close()
        if reply is not None:
            reply.close()
        feed.close()
