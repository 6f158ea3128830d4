"""What a panel run streams, as data the loop process can be sent: the gait the sliders
drive, a recording, a replayed take, a keyframe sequence. ``build`` makes its engine (and,
for a recording, the take writer that observes each tick) where the loop runs.

Every one of them is a ``GaitEngine`` streamed by the one loop (robot.run.run), with its
ramps, limits, slew limit and watchdog.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.loop.mcap_recorder import Alongside, McapRecorder
from robot.loop.take_writer import TakeWriter
from robot.motion.keyframes import Sequence, parse_sequence
from robot.motion.layered import LayeredEngine
from robot.motion.scripted import PlaybackEngine, RecordingEngine
from robot.motion.show import Cue
from robot.motion.show_walk import ShowEngine, Travel
from robot.motion.takes import TakeHeader, read_take


@dataclass(frozen=True)
class Walk:
    """The gait, driven by the sliders."""

    @property
    def owner(self) -> str:
        return "the gait"


@dataclass(frozen=True)
class Record:
    """The gait, recorded to the take file ``path`` (named ``take``) until it stops."""

    take: str
    path: str
    header: TakeHeader
    mcap: str | None = None      # the take as MCAP too, at this path

    @property
    def owner(self) -> str:
        return f"recording take {self.take}"


@dataclass(frozen=True)
class Play:
    """The take file ``path`` (named ``take``) replayed: its parameters and timeline."""

    take: str
    path: str

    @property
    def owner(self) -> str:
        return f"take {self.take}"


@dataclass(frozen=True)
class Keyframes:
    """A keyframe sequence on its own, or layered on the walking gait (``walk``)."""

    sequence: Sequence
    walk: bool = False

    @property
    def owner(self) -> str:
        return f"sequence {self.sequence.name}"


@dataclass(frozen=True)
class ShowTake:
    """A show take (an imported animation, robot.motion.show) streamed as recorded: its
    joint stream as a keyframe sequence, at any rate, the gait walking the legs where
    ``travel`` says (robot.motion.show_walk, with the take's ``params``); the panel plays
    its audio; ``cues`` say what comes next."""

    take: str
    sequence: Sequence
    travel: Travel = Travel()
    params: GaitParams | None = None
    cues: tuple[Cue, ...] = ()

    @property
    def owner(self) -> str:
        return f"take {self.take}"


RunKind = Walk | Record | Play | Keyframes | ShowTake


@dataclass
class Built:
    """A run's engine; ``recorder``: the take writer (opened by the run, before the bus
    moves); ``driver``: what drives the run instead of the sliders (None: the sliders)."""

    engine: GaitEngine
    recorder: TakeWriter | Alongside | None = None
    driver: str | None = None


def build(kind: RunKind, robot: RobotConfig, params: GaitParams) -> Built:
    """The engine of a run of ``kind`` from the current ``params`` (ConfigError if a take
    or sequence does not fit ``robot``)."""
    if isinstance(kind, Walk):
        return Built(GaitEngine(robot, params))
    if isinstance(kind, Record):
        header = dataclasses.replace(kind.header, params=params)
        writer = TakeWriter(kind.path, header)
        recording = RecordingEngine(robot, params, sink=writer.event)
        if kind.mcap is None:
            return Built(recording, recorder=writer)
        mcap = McapRecorder(kind.mcap, robot, header, params=lambda: recording.params)
        return Built(recording, recorder=Alongside(writer, mcap))
    if isinstance(kind, Play):
        take = read_take(kind.path)
        h = take.header
        if h.joints != robot.joint_names:
            raise ConfigError(f"take {kind.take!r} was recorded on {h.robot}, not {robot.name}")
        layer = (parse_sequence(h.keyframes, robot, source=f"{kind.path}: keyframes")
                 if h.keyframes else None)
        stop = take.stop_tick if take.stop_tick is not None else len(take.t)
        return Built(PlaybackEngine(robot, h.params, changes=take.changes, blends=take.blends, stop_tick=stop,
                                    keyframes=layer), driver=kind.owner)
    if isinstance(kind, ShowTake):
        if kind.travel.walks:
            return Built(ShowEngine(robot, kind.params or params, stream=kind.sequence,
                                    travel=kind.travel), driver=kind.owner)
        return Built(LayeredEngine(robot, params, keyframes=kind.sequence, walk=False),
                     driver=kind.owner)
    engine = LayeredEngine(robot, params, keyframes=kind.sequence, walk=kind.walk)
    return Built(engine, driver=None if kind.walk else kind.owner)
