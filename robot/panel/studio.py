"""The panel's studio: record takes, list and replay them, pose by hand and keyframe.

Takes live in ``takes_dir`` (NAME.take.jsonl, robot.motion.takes), keyframe sequences in
``keys_dir`` (NAME.toml, robot.motion.keyframes); by default under the user's data directory
(platformdirs: ``~/.local/share/biped``). Files are listed, checked and saved here; every
run, release and capture goes to the loop process through the controller (so it is the
one streaming loop with its ramps and limits, and one owner of the bus at a time); a
replayed take drives the run by itself (the sliders are refused until it ends or is
stopped). What is recording, playing or released is the loop's own report.
"""

from __future__ import annotations

import logging
import re
import time
import tomllib
from pathlib import Path
from typing import Any

import platformdirs

from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.files.atomic import write_text
from robot.motion.keyframes import Sequence, load_sequence, parse_sequence, sequence_to_toml
from robot.motion.layered import LayeredEngine
from robot.motion.posing import limb_joints, limbs
from robot.motion.show import Show, show_of, stream_sequence
from robot.motion.show_walk import Travel
from robot.motion.takes import SUFFIX, TakeHeader, read_take
from robot.panel.controller import PanelController
from robot.panel.runs import Keyframes, Play, Record, ShowTake

log = logging.getLogger(__name__)

NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,47}\Z")  # \Z: "$" lets a final newline in


def user_data_dir() -> Path:
    return Path(platformdirs.user_data_dir("biped", appauthor=False))


def _name(name: object, what: str) -> str:
    if not isinstance(name, str) or not NAME_RE.fullmatch(name):
        raise ConfigError(f"{what} name {name!r}: expected 1-48 letters, digits, '-' or '_'")
    return name


class Studio:
    """Takes and keyframes for one PanelController. ``received``: when the request
    arrived (robot.panel.controller: the order against an e-stop)."""

    def __init__(self, controller: PanelController, *, takes_dir: Path | None = None,
                 keys_dir: Path | None = None) -> None:
        self.c = controller
        self.robot: RobotConfig = controller.robot
        self.takes_dir = takes_dir or user_data_dir() / "takes"
        self.keys_dir = keys_dir or user_data_dir() / "keyframes"
        self.show: Show | None = None  # the show take last played (its audio, cues)

    @property
    def recording(self) -> str | None:
        return self.c.loop_state().get("recording")

    @property
    def playing(self) -> str | None:
        return self.c.loop_state().get("playing")

    # -- takes -----------------------------------------------------------------------
    def takes(self) -> list[str]:
        if not self.takes_dir.is_dir():
            return []
        return sorted(p.name.removesuffix(SUFFIX) for p in self.takes_dir.glob(f"*{SUFFIX}"))

    def record(self, name: object = None, *, received: float | None = None) -> str:
        """Start a recorded run from rest with the current parameters; it ends (and the
        take is complete) with Stop."""
        take = _name(name, "take") if name else time.strftime("take-%Y%m%d-%H%M%S")
        _writable(self.takes_dir, "takes")
        o = self.c.options
        header = TakeHeader(
            robot=self.robot.name, robot_file=self.robot.source, joints=self.robot.joint_names,
            rate_hz=o.rate_hz, read_every=o.read_every, gait=self.c.preset or "panel",
            params=self.c.params, bus=self.c.bus.kind, balance=o.balance,
            note="recorded from the panel")
        path = self.takes_dir / f"{take}{SUFFIX}"
        mcap = str(path.with_name(f"{take}.mcap")) if o.mcap else None
        self.c.start(run=Record(take, str(path), header, mcap=mcap), received=received)
        return take

    def play(self, name: object, *, received: float | None = None) -> dict[str, Any]:
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
            seq = stream_sequence(take)
            self.c.start(run=ShowTake(take_name, seq, Travel.of_take(take), h.params,
                                      show.cues), received=received)
            self.show = show
            return {"take": take_name, "seconds": seq.duration}
        if h.rate_hz != self.c.options.rate_hz:
            raise ConfigError(f"take {take_name!r} was recorded at {h.rate_hz:g} Hz; the "
                              f"panel runs at {self.c.options.rate_hz:g} Hz (use biped play)")
        self.c.start(run=Play(take_name, str(path)), received=received)
        return {"take": take_name, "seconds": take.gait_seconds}

    def show_status(self) -> dict[str, Any] | None:
        """The playing show's audio fields and its time ``t`` [s] (the engine's: 0 at the
        first tick after the ramp in) at the loop process's wall time ``at`` [s] of that
        tick, and the show's measured ``rate`` (show seconds per wall second), for the
        page that plays the audio; None: no show playing."""
        show, s = self.show, self.c.loop_state()
        playing, now = s.get("playing"), s.get("show")
        if show is None or playing is None or not now:
            return None
        return {"take": playing, "t": now["t"], "at": now["at"], "rate": now["rate"],
                "playing": now["playing"],
                "audio": f"/api/show/audio?take={playing}" if show.audio else None,
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
    def release(self, limb: object, *, received: float | None = None) -> dict[str, Any]:
        """Torque off on ``limb`` (the others hold); a new limb starts a new capture."""
        limb_joints(self.robot, limb)          # an unknown limb: 400, before the loop
        self.c.release(limb, received=received)
        return self.status()

    def capture(self, t: object = None, *, received: float | None = None) -> dict[str, Any]:
        when = float(t) if isinstance(t, (int, float)) and not isinstance(t, bool) else None
        return self.c.capture(when, received=received)

    def clear(self) -> dict[str, Any]:
        """Forget the captured keyframes."""
        self.c.clear_capture()
        return {}

    def save(self, name: object) -> str:
        seq_name = _name(name, "sequence")
        seq = self.c.keyframes(seq_name)
        path = self.keys_dir / f"{seq_name}.toml"
        text = sequence_to_toml(seq)
        parse_sequence(tomllib.loads(text), self.robot, source=str(path))  # as it will load
        _writable(self.keys_dir, "keyframes")
        try:
            write_text(path, text)
        except OSError as e:
            raise ConfigError(f"sequence {seq_name!r}: cannot write {path}: "
                              f"{e.strerror or e}") from None
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

    def play_sequence(self, name: object, *, layer: bool,
                      received: float | None = None) -> dict[str, Any]:
        """Play a saved sequence on its own, or layered on the walking gait."""
        seq = self.load(name)
        walk = bool(layer)
        if walk:
            LayeredEngine(self.robot, self.c.params, keyframes=seq, walk=True)  # refuse legs
        self.c.start(run=Keyframes(seq, walk), received=received)
        return {"sequence": seq.name, "seconds": seq.duration, "layered": walk}

    def status(self) -> dict[str, Any]:
        s = self.c.loop_state()
        return {"recording": s.get("recording"), "playing": s.get("playing"),
                "released": s.get("released"), "limbs": list(limbs(self.robot)),
                "keyframes": s.get("keyframes", 0), "show": self.show_status(),
                "capture_joints": list(s.get("capture_joints", []))}


def _writable(directory: Path, what: str) -> None:
    """Create ``directory``; ConfigError in one line if it cannot be."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise ConfigError(f"{what} directory {directory}: cannot create it: "
                          f"{e.strerror or e}") from None
