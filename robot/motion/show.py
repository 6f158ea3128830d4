"""A show: what a take or a keyframe file adds to its motion for a performance: the joint
stream to play as it is (an imported animation), the soundtrack and when it starts, and
cue markers.

In a take it is the header's ``show`` object (robot/motion/takes.py); in a keyframe file
(robot/motion/keyframes.py) a ``[show]`` table of the same shape:

```toml
[show]
audio = "song.wav"        # relative to the file that names it
audio_offset_s = 0.5      # [s] of show time at which the audio's start plays (< 0: the
                          # audio starts that far in)
[[show.cue]]
t = 2.0                   # [s] of show time
name = "lights up"
```

``stream = true`` (written by `biped import`) makes `biped play` stream the take's joint
angles as recorded (through the same ramps, clamp and slew) instead of replaying a gait
timeline.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robot.config.toml_io import JsonValue, TomlValue, number, read_toml, show
from robot.errors import ConfigError
from robot.motion.keyframes import Sequence
from robot.motion.takes import Take

#: Most cues in one show.
MAX_CUES = 10_000
KEYS = ("stream", "audio", "audio_offset_s", "cue", "up", "travel_m")


@dataclass(frozen=True)
class Cue:
    """A marker at show time ``t`` [s]."""

    t: float
    name: str


@dataclass(frozen=True)
class Show:
    """stream: play the joint stream as recorded; audio: the sound file's path as written
    (None: silent); audio_offset_s [s]; cues by time; base: the directory ``audio`` is
    relative to; up, travel_m: what the import found (the rig's up axis, the root's travel
    [m] forward, left, up), for the record."""

    stream: bool = False
    audio: str | None = None
    audio_offset_s: float = 0.0
    cues: tuple[Cue, ...] = ()
    base: str = "."
    up: str = ""
    travel_m: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def audio_path(self) -> Path | None:
        if self.audio is None:
            return None
        p = Path(self.audio)
        return p if p.is_absolute() else Path(self.base) / p

    def as_json(self) -> dict[str, JsonValue]:
        out: dict[str, JsonValue] = {"stream": self.stream, "audio": self.audio,
                                     "audio_offset_s": self.audio_offset_s,
                                     "cue": [{"t": c.t, "name": c.name} for c in self.cues]}
        if self.up:
            out["up"] = self.up
            out["travel_m"] = list(self.travel_m)
        return out

    def audio_time(self, t: float) -> float:
        """Position in the audio [s] at show time ``t`` [s] (negative: not started)."""
        return t - self.audio_offset_s


def parse_show(data: Mapping[str, TomlValue] | Mapping[str, JsonValue], *, where: str,
               base: str | Path = ".") -> Show:
    """A checked Show (ConfigError naming ``where`` and the field on any problem)."""
    unknown = sorted(set(data) - set(KEYS))
    if unknown:
        raise ConfigError(f"{where}.{unknown[0]}: unknown key; valid: {', '.join(KEYS)}")
    stream = data.get("stream", False)
    if not isinstance(stream, bool):
        raise ConfigError(f"{where}.stream: expected true or false, got {show(stream)}")
    audio = data.get("audio")
    if audio is not None and (not isinstance(audio, str) or not audio):
        raise ConfigError(f"{where}.audio: expected the sound file's path, got {show(audio)}")
    offset = number(where, "audio_offset_s", data.get("audio_offset_s", 0.0))
    raw = data.get("cue", [])
    if not isinstance(raw, list) or len(raw) > MAX_CUES:
        raise ConfigError(f"{where}.cue: expected a list of at most {MAX_CUES} cues "
                          "({t, name})")
    cues = []
    for i, c in enumerate(raw):
        if not isinstance(c, dict) or set(c) - {"t", "name"} or not isinstance(
                c.get("name", ""), str):
            raise ConfigError(f"{where}.cue[{i}]: expected {{t = seconds, name = \"...\"}}")
        t = number(where, f"cue[{i}].t", c.get("t"))
        cues.append(Cue(t, str(c.get("name", f"cue {i + 1}"))))
    up = data.get("up", "")
    travel = data.get("travel_m", [0.0, 0.0, 0.0])
    if not isinstance(up, str) or not isinstance(travel, list) or len(travel) != 3:
        raise ConfigError(f"{where}: up / travel_m: expected a string and three numbers")
    moved = tuple(number(where, "travel_m", v) for v in travel)
    return Show(stream, audio, offset, tuple(sorted(cues, key=lambda c: c.t)), str(base),
                up, (moved[0], moved[1], moved[2]))


def show_of(header_show: Mapping[str, JsonValue] | None, source: str) -> Show:
    """The Show of a take's header (``source``: the take's path; audio is relative to it)."""
    if header_show is None:
        return Show(base=str(Path(source).parent))
    return parse_show(header_show, where=f"{source}: show", base=Path(source).parent)


def stream_sequence(take: Take) -> Sequence:
    """The take's joint stream as a sequence through every tick (``smooth``: at each tick
    time it gives that tick's angles; robot.motion.interp), to play with
    ``LayeredEngine(walk=False)``: ramp in to the first tick, then tick by tick."""
    if len(take.t) < 2:
        raise ConfigError(f"{take.source}: a show stream needs at least two ticks")
    times = np.arange(len(take.t)) / take.header.rate_hz
    return Sequence(name=Path(take.source).name, joints=take.header.joints, times=times,
                    poses=take.q, interpolation="smooth", source=take.source)


def show_of_sequence(path: str | Path) -> Show:
    """The ``[show]`` table of a keyframe file (robot/motion/keyframes.py), or no show."""
    p = Path(path)
    data: Mapping[str, TomlValue] | Mapping[str, JsonValue]
    if p.suffix == ".toml":
        data = read_toml(p)
    else:
        try:
            data = json.loads(p.read_text())
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
            raise ConfigError(f"{p}: not a valid JSON keyframe file: {e}") from None
    raw = data.get("show") if isinstance(data, dict) else None
    if raw is None:
        return Show(base=str(p.parent))
    if not isinstance(raw, dict):
        raise ConfigError(f"{p}: show: expected a table (audio, audio_offset_s, cue)")
    return parse_show(raw, where=f"{p}: show", base=p.parent)
