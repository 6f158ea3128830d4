"""The panel's studio: record takes, list and replay them, pose by hand and keyframe.

Takes live in ``takes_dir`` (NAME.take.jsonl, robot.motion.takes), keyframe sequences in
``keys_dir`` (NAME.toml, robot.motion.keyframes); by default under the user's data directory
(platformdirs: ``~/.local/share/biped``). Every run starts through the controller, so it
is the one streaming loop with its ramps and limits; a replayed take drives the run by
itself (the sliders are refused until it ends or is stopped).
"""

from __future__ import annotations

import dataclasses
import logging
import re
import threading
import time
import tomllib
from pathlib import Path
from typing import Any

import platformdirs

from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.loop.take_writer import TakeWriter
from robot.motion.keyframes import Sequence, load_sequence, parse_sequence, sequence_to_toml
from robot.motion.layered import LayeredEngine
from robot.motion.posing import Capture, limb_joints, limbs
from robot.motion.scripted import PlaybackEngine, RecordingEngine
from robot.motion.show import Show, show_of, stream_sequence
from robot.motion.takes import SUFFIX, TakeHeader, read_take
from robot.panel.controller import PanelController, PanelStateError
from robot.run.release import release

log = logging.getLogger(__name__)

NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,47}\Z")  # \Z: "$" lets a final newline in


def user_data_dir() -> Path:
    return Path(platformdirs.user_data_dir("biped", appauthor=False))


def _name(name: object, what: str) -> str:
    if not isinstance(name, str) or not NAME_RE.match(name):
        raise ConfigError(f"{what} name {name!r}: expected 1-48 letters, digits, '-' or '_'")
    return name


class Studio:
    """Takes and keyframes for one PanelController."""

    def __init__(self, controller: PanelController, *, takes_dir: Path | None = None,
                 keys_dir: Path | None = None) -> None:
        self.c = controller
        self.robot: RobotConfig = controller.robot
        self.takes_dir = takes_dir or user_data_dir() / "takes"
        self.keys_dir = keys_dir or user_data_dir() / "keyframes"
        self._lock = threading.Lock()
        self.recording: str | None = None
        self.playing: str | None = None
        self.released: str | None = None
        self.show: Show | None = None
        self._capture: Capture | None = None

    # -- takes -----------------------------------------------------------------------
    def takes(self) -> list[str]:
        if not self.takes_dir.is_dir():
            return []
        return sorted(p.name.removesuffix(SUFFIX) for p in self.takes_dir.glob(f"*{SUFFIX}"))

    def record(self, name: object = None) -> str:
        """Start a recorded run from rest with the current parameters; it ends (and the
        take is complete) with Stop."""
        take = _name(name, "take") if name else time.strftime("take-%Y%m%d-%H%M%S")
        self.takes_dir.mkdir(parents=True, exist_ok=True)
        o = self.c.options
        writer = TakeWriter(self.takes_dir / f"{take}{SUFFIX}", TakeHeader(
            robot=self.robot.name, robot_file=self.robot.source, joints=self.robot.joint_names,
            rate_hz=o.rate_hz, read_every=o.read_every, gait=self.c.preset or "panel",
            params=self.c.params, bus=self.c.bus.kind, balance=o.feedback is not None,
            note="recorded from the panel"))

        def engine(params: GaitParams) -> GaitEngine:
            writer.header = dataclasses.replace(writer.header, params=params)
            writer.open()
            return RecordingEngine(self.robot, params, sink=writer.event)

        def done() -> None:
            error = writer.close_quietly()
            self.recording = None
            if error:
                log.error("panel: take %s: %s", take, error)
        self.c.start(engine=engine, observer=writer, on_end=done)
        self.recording, self.released = take, None
        return take

    def play(self, name: object) -> dict[str, Any]:
        """Replay a take from the list (its recorded parameters, timeline and rate)."""
        take_name = _name(name, "take")
        path = self.takes_dir / f"{take_name}{SUFFIX}"
        if not path.is_file():
            raise ConfigError(f"take {take_name!r}: not found; valid: "
                              f"{', '.join(self.takes()) or '(none recorded yet)'}")
        take = read_take(path)
        h = take.header
        if h.joints != self.robot.joint_names:
            raise ConfigError(f"take {take_name!r} was recorded on {h.robot}, not "
                              f"{self.robot.name}")
        show = show_of(h.show, str(path))
        if show.stream:   # an imported show: its joints as they are, at any rate
            return self._play_show(take_name, stream_sequence(take), show)
        if h.rate_hz != self.c.options.rate_hz:
            raise ConfigError(f"take {take_name!r} was recorded at {h.rate_hz:g} Hz; the "
                              f"panel runs at {self.c.options.rate_hz:g} Hz (use biped play)")
        layer = (parse_sequence(h.keyframes, self.robot, source=f"{path}: keyframes")
                 if h.keyframes else None)
        stop = take.stop_tick if take.stop_tick is not None else len(take.t)

        def engine(_: GaitParams) -> GaitEngine:
            return PlaybackEngine(self.robot, h.params, changes=take.changes, stop_tick=stop,
                                  keyframes=layer)

        def done() -> None:
            self.playing = None
        self.c.start(engine=engine, driver=f"take {take_name}", on_end=done)
        self.playing, self.released = take_name, None
        return {"take": take_name, "seconds": take.gait_seconds}

    def _play_show(self, name: str, seq: Sequence, show: Show) -> dict[str, Any]:
        """A show take: its stream; the page plays its audio (``show_status``)."""
        def engine(params: GaitParams) -> GaitEngine:
            return LayeredEngine(self.robot, params, keyframes=seq, walk=False)

        def done() -> None:
            self.playing, self.show = None, None
        self.c.start(engine=engine, driver=f"take {name}", on_end=done)
        self.playing, self.released, self.show = name, None, show
        return {"take": name, "seconds": seq.duration}

    def show_status(self) -> dict[str, Any] | None:
        """The playing show's audio fields and its time [s] (the engine's: 0 at the first
        tick after the ramp in), for the page that plays the audio; None: no show."""
        show, streamer = self.show, self.c.streamer
        if show is None or self.playing is None:
            return None
        engine = streamer.engine if streamer is not None and self.c.running else None
        return {"take": self.playing, "t": engine.time if engine is not None else 0.0,
                "audio": f"/api/show/audio?take={self.playing}" if show.audio else None,
                "audio_offset_s": show.audio_offset_s,
                "cues": [{"t": c.t, "name": c.name} for c in show.cues]}

    def audio_file(self, name: object) -> Path:
        """The sound file a take's show names (ConfigError if it has none)."""
        take_name = _name(name, "take")
        path = self.takes_dir / f"{take_name}{SUFFIX}"
        if not path.is_file():
            raise ConfigError(f"take {take_name!r}: not found")
        audio = show_of(read_take(path).header.show, str(path)).audio_path()
        if audio is None or not audio.is_file():
            raise ConfigError(f"take {take_name!r}: no audio file")
        return audio

    # -- posing by hand and keyframes -------------------------------------------------
    def _idle(self) -> None:
        if self.c.running:
            raise PanelStateError("stop the gait before posing by hand")
        if not self.c.bus.is_open:
            self.c.bus.open()

    def release(self, limb: object) -> dict[str, Any]:
        """Torque off on ``limb`` (the others hold); a new limb starts a new capture."""
        joints = limb_joints(self.robot, limb)
        with self._lock:
            self._idle()
            release(self.robot, self.c.bus, str(limb))
            self.released = str(limb)
            if self._capture is None or self._capture.joints != joints:
                self._capture = Capture(self.robot, joints)
        return self.status()

    def capture(self, t: object = None) -> dict[str, Any]:
        with self._lock:
            self._idle()
            if self._capture is None:
                raise PanelStateError("release a limb first (torque off), then move it "
                                      "by hand and capture")
            when = None if t is None else float(t) if isinstance(t, (int, float)) \
                and not isinstance(t, bool) else None
            pose = self._capture.add(self.c.bus, t=when)
            return {"t": self._capture.times[-1],
                    "pose": dict(zip(self._capture.joints, pose, strict=True))}

    def clear(self) -> dict[str, Any]:
        """Forget the captured keyframes."""
        with self._lock:
            self._capture = None
        return {}

    def save(self, name: object) -> str:
        seq_name = _name(name, "sequence")
        with self._lock:
            if self._capture is None or not self._capture.times:
                raise ConfigError("no keyframes captured yet")
            seq = self._capture.sequence(seq_name)
        self.keys_dir.mkdir(parents=True, exist_ok=True)
        path = self.keys_dir / f"{seq_name}.toml"
        text = sequence_to_toml(seq)
        parse_sequence(tomllib.loads(text), self.robot, source=str(path))  # as it will load
        path.write_text(text)
        return str(path)

    def sequences(self) -> list[str]:
        if not self.keys_dir.is_dir():
            return []
        return sorted(p.stem for p in self.keys_dir.glob("*.toml"))

    def load(self, name: object) -> Sequence:
        seq_name = _name(name, "sequence")
        path = self.keys_dir / f"{seq_name}.toml"
        if not path.is_file():
            raise ConfigError(f"sequence {seq_name!r}: not found; valid: "
                              f"{', '.join(self.sequences()) or '(none saved yet)'}")
        return load_sequence(path, self.robot)

    def play_sequence(self, name: object, *, layer: bool) -> dict[str, Any]:
        """Play a saved sequence on its own, or layered on the walking gait."""
        seq = self.load(name)
        walk = bool(layer)

        def engine(params: GaitParams) -> GaitEngine:
            return LayeredEngine(self.robot, params, keyframes=seq, walk=walk)
        if walk:
            LayeredEngine(self.robot, self.c.params, keyframes=seq, walk=True)  # refuse legs
        self.c.start(engine=engine, driver=None if walk else f"sequence {seq.name}")
        self.released = None
        return {"sequence": seq.name, "seconds": seq.duration, "layered": walk}

    def status(self) -> dict[str, Any]:
        cap = self._capture
        return {"recording": self.recording, "playing": self.playing,
                "released": self.released, "limbs": list(limbs(self.robot)),
                "keyframes": len(cap.times) if cap else 0, "show": self.show_status(),
                "capture_joints": list(cap.joints) if cap else []}
