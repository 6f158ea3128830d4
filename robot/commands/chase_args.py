"""`biped play SHOW --chase ...`: the options that make a show follow an external timecode
and what it reports (robot/timecode/chased.py, robot/timecode/).

``--freewheel`` defaults to 15 frames (0.5-0.6 s): an audio cable's crackle, a DAW's loop
point or a MIDI interface's hiccup is shorter and the show rides through it; when the
operator stops the playback, the robot stops within that and its ramp (a longer default
would keep a performer moving after the show has stopped).
"""

from __future__ import annotations

import argparse
import re
from typing import Any

from robot.commands.common import bounded_float
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.loop.clock import Clock
from robot.loop.telemetry import Telemetry
from robot.motion.layered import LayeredEngine
from robot.timecode.chase import JUMP_FRAMES, LIVE_JUMP_FRAMES, ChaseClock
from robot.timecode.chased import ChasedShow
from robot.timecode.sources import LtcFile, source_of

FREEWHEEL_FRAMES = 15
_LABEL = re.compile(r"^(\d{1,2}):(\d{2}):(\d{2})[:;.](\d{2})$")


def add_chase_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--chase", default=None, metavar="ltc:DEVICE|ltc:FILE.wav|mtc:PORT",
                   help="follow an external timecode: LTC from an audio input (ALSA "
                        "device) or a WAV file, or MTC from a MIDI port (HOST:PORT: a mido "
                        "socket port); 24, 25, 29.97 drop-frame and 30 fps, found from the "
                        "signal")
    p.add_argument("--chase-start", default=None, metavar="HH:MM:SS:FF",
                   help="the timecode of show time 0 (default: 00:00:00:00)")
    p.add_argument("--freewheel", type=bounded_float(1, 300, "frames", what="a frame count"),
                   default=None, metavar="FRAMES",
                   help=f"frames to play on without timecode before the show stops "
                        f"(default: {FREEWHEEL_FRAMES})")


def start_label(value: str | None) -> tuple[int, int, int, int]:
    if value is None:
        return (0, 0, 0, 0)
    m = _LABEL.match(value.strip())
    if m is None:
        raise ConfigError(f"--chase-start {value!r}: expected HH:MM:SS:FF (e.g. 01:00:00:00)")
    h, mi, s, f = (int(g) for g in m.groups())
    if h > 23 or mi > 59 or s > 59 or f > 29:
        raise ConfigError(f"--chase-start {value}: out of range (hours 0-23, minutes and "
                          "seconds 0-59, frames 0-29)")
    return h, mi, s, f


def chased(args: argparse.Namespace, engine: GaitEngine, clock: Clock) -> ChasedShow | None:
    """The show wrapped to follow ``--chase``, or None without it (ConfigError: the
    options without --chase, or a file that cannot be chased)."""
    if args.chase is None:
        if args.chase_start is not None or args.freewheel is not None:
            raise ConfigError("--chase-start and --freewheel apply with --chase only")
        return None
    if not isinstance(engine, LayeredEngine) or engine.walk:
        raise ConfigError(f"--chase: {args.file} replays a walk's timeline, which cannot "
                          "follow a clock; chase a show (biped import) or a keyframe "
                          "sequence")
    label = start_label(args.chase_start)
    source = source_of(args.chase)
    freewheel = int(round(args.freewheel)) if args.freewheel is not None else FREEWHEEL_FRAMES
    jump = JUMP_FRAMES if isinstance(source, LtcFile) else LIVE_JUMP_FRAMES
    show = ChasedShow(engine, ChaseClock(label, freewheel=freewheel, jump_frames=jump), source,
                      clock)
    show.prepare()
    return show


def live(spec: str | None) -> bool:
    """``--chase spec`` is heard on the wall clock (a simulation must then run in real
    time): anything but a WAV file."""
    return spec is not None and not isinstance(source_of(spec), LtcFile)


def stop_when_lost(show: ChasedShow, stop: Any) -> Any:
    """A tick observer: ``stop(reason)`` once the timecode is lost (the way Stop does)."""
    told = False

    def watch(tel: Telemetry) -> None:
        nonlocal told
        if show.lost and not told:
            told = True
            frames = show.chase.freewheel
            show.ended = "timecode lost"
            stop(f"timecode lost: none for {frames} frames (--freewheel)")
    return watch


def chase_events(show: ChasedShow, log: Any) -> Any:
    """A tick observer: ``log(text)`` (an MCAP record's /events) at each timecode jump and
    dropout, and when the show ends by itself."""
    counts = [0, 0]
    said: list[str | None] = [None]

    def watch(tel: Telemetry) -> None:
        st = show.chase.stats
        for a, b in st.jumped[counts[0]:]:
            log(f"timecode jump: show time {a:.3f} s -> {b:.3f} s")
        if st.dropouts > counts[1]:
            log(f"timecode dropout (freewheel {show.chase.freewheel} frames)", level="warning")
        if show.ended and show.ended != said[0]:
            log(f"show: {show.ended}")
        counts[:], said[0] = [len(st.jumped), st.dropouts], show.ended
    return watch


def summary(show: ChasedShow) -> dict[str, Any]:
    """The ``"chase"`` object of `biped play --json`."""
    st = show.chase.stats
    rate = st.rate
    return {"source": show.source.name, "fps": rate.name if rate else None,
            "max_error_frames": round(st.max_error_frames, 4),
            "p95_error_frames": round(st.error_frames(95), 4), "dropouts": st.dropouts,
            "jumps": st.jumps, "jumped_s": [[round(a, 4), round(b, 4)] for a, b in st.jumped],
            "readings": st.readings, "stopped": show.ended}
