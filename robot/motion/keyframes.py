"""Keyframe sequences: poses with times, as TOML or JSON files a person edits by hand.

```toml
name = "wave"
interpolation = "min_jerk"   # or "smooth" (robot.motion.interp); default min_jerk
loop = false                 # true: repeat (the last keyframe must equal the first)
[[keyframe]]
t = 0.0                      # [s] from the start of the sequence
r_shoulder_pitch = 0.0       # [rad], every keyframe names the same joints
r_elbow = -0.3
[[keyframe]]
t = 1.5
r_shoulder_pitch = -1.2
r_elbow = -1.0
```

JSON has the same shape (``{"name": ..., "keyframe": [{"t": 0.0, ...}, ...]}``).
Checked against the robot before anything moves: known joints, angles inside the joint
limits, times increasing, and no segment faster than the joint's ``max_speed_rad_s``.
Every problem is one line naming the file, the keyframe and the joint.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TypeAlias

import numpy as np
import numpy.typing as npt

from robot.config.robot import RobotConfig
from robot.config.toml_io import JsonValue, TomlValue, number, parse_json, read_toml, show
from robot.errors import ConfigError
from robot.motion.interp import METHODS, interpolate

SUFFIXES = (".toml", ".json")
#: Sampling step [s] of the speed check.
SPEED_CHECK_S = 0.002
#: Longest sequence [s] (an all-day show loops a shorter one).
MAX_SECONDS = 3600.0
MAX_KEYFRAMES = 10_000
#: A value of a sequence file (TOML or JSON).
Value: TypeAlias = TomlValue | JsonValue


@dataclass(frozen=True)
class Sequence:
    """joints: the joints it drives; times: (k,) [s]; poses: (k, joints) [rad]."""

    name: str
    joints: tuple[str, ...]
    times: npt.NDArray[np.float64]
    poses: npt.NDArray[np.float64]
    interpolation: str = "min_jerk"
    loop: bool = False
    source: str = "<memory>"

    @property
    def duration(self) -> float:
        return float(self.times[-1])

    def at(self, t: float | npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """Joint angles [rad] at time(s) ``t`` [s]: (joints,) for a float, (n, joints)."""
        ts = np.atleast_1d(np.asarray(t, dtype=float))
        if self.loop and self.duration > 0:
            ts = np.mod(ts, self.duration)
        out = interpolate(self.interpolation, self.times, self.poses, ts)
        return out[0] if np.ndim(t) == 0 else out

    def as_json(self) -> dict[str, JsonValue]:
        return {"name": self.name, "interpolation": self.interpolation, "loop": self.loop,
                "keyframe": [{"t": float(t), **{j: float(v) for j, v in zip(
                    self.joints, pose, strict=True)}} for t, pose in zip(
                        self.times, self.poses, strict=True)]}


def parse_sequence(data: Mapping[str, Value], robot: RobotConfig, *,
                   source: str = "<memory>") -> Sequence:
    """A validated Sequence for ``robot`` (ConfigError, one line, on any problem)."""
    src = source
    unknown = sorted(set(data) - {"name", "interpolation", "loop", "keyframe", "description",
                                  "show"})
    if unknown:
        raise ConfigError(f"{src}: {unknown[0]}: unknown key; valid: name, interpolation, "
                          "loop, keyframe, description, show (robot.motion.show)")
    name = data.get("name", Path(src).stem.removesuffix(".keys"))
    if not isinstance(name, str) or not name:
        raise ConfigError(f"{src}: name: expected a non-empty string, got {show(name)}")
    method = data.get("interpolation", "min_jerk")
    if not isinstance(method, str) or method not in METHODS:
        raise ConfigError(f"{src}: interpolation: expected one of {', '.join(METHODS)}, "
                          f"got {show(method)}")
    loop = data.get("loop", False)
    if not isinstance(loop, bool):
        raise ConfigError(f"{src}: loop: expected true or false, got {show(loop)}")
    frames = data.get("keyframe")
    if not isinstance(frames, list) or not frames:
        raise ConfigError(f"{src}: keyframe: expected at least one [[keyframe]] with t and "
                          "joint angles")
    if len(frames) > MAX_KEYFRAMES:
        raise ConfigError(f"{src}: keyframe: {len(frames)} keyframes; at most {MAX_KEYFRAMES}")
    valid = {j.name: j for j in robot.joints}
    joints: tuple[str, ...] = ()
    times: list[float] = []
    poses: list[list[float]] = []
    for i, frame in enumerate(frames):
        where = f"{src}: keyframe[{i}]"
        if not isinstance(frame, dict):
            raise ConfigError(f"{where}: expected a table of t and joint angles")
        if "t" not in frame:
            raise ConfigError(f"{where}: t: missing (seconds from the start)")
        t = number(src, f"keyframe[{i}].t", frame["t"])
        if not 0.0 <= t <= MAX_SECONDS:
            raise ConfigError(f"{where}.t: {t:g} is outside [0, {MAX_SECONDS:g}] s")
        if times and t <= times[-1]:
            raise ConfigError(f"{where}.t: {t:g} s is not after keyframe[{i - 1}].t = "
                              f"{times[-1]:g} s")
        names = tuple(n for n in frame if n != "t")
        for n in names:
            if n not in valid:
                raise ConfigError(f"{where}.{n}: unknown joint of {robot.name}; valid: "
                                  f"{', '.join(valid)}")
        if not names:
            raise ConfigError(f"{where}: no joint angles")
        if i == 0:
            joints = names
        elif set(names) != set(joints):
            diff = sorted(set(joints) ^ set(names))[0]
            how = "missing" if diff in joints else "not in keyframe[0]"
            raise ConfigError(f"{where}: joint {diff!r} {how}; every keyframe gives the "
                              f"same joints ({', '.join(joints)})")
        pose = []
        for n in joints:
            q = number(src, f"keyframe[{i}].{n}", frame[n])
            j = valid[n]
            if not j.min_rad <= q <= j.max_rad:
                raise ConfigError(f"{where}.{n}: {q:g} rad is outside the joint limits "
                                  f"[{j.min_rad:g}, {j.max_rad:g}]")
            pose.append(q)
        times.append(t)
        poses.append(pose)
    seq = Sequence(name, joints, np.array(times), np.array(poses), method, loop, src)
    if loop and not np.array_equal(seq.poses[0], seq.poses[-1]):
        raise ConfigError(f"{src}: loop = true needs the last keyframe equal to the first "
                          "(repeat keyframe[0]'s angles at the end)")
    _check_speed(seq, robot)
    return seq


def _check_speed(seq: Sequence, robot: RobotConfig) -> None:
    """ConfigError if the interpolated motion is faster than a joint's max speed."""
    if len(seq.times) < 2:
        return
    n = int(math.ceil(seq.duration / SPEED_CHECK_S)) + 1
    ts = np.linspace(0.0, seq.duration, max(n, 2))
    q = seq.at(ts)
    speed = np.abs(np.diff(q, axis=0)) / np.diff(ts)[:, None]
    for col, name in enumerate(seq.joints):
        limit = robot.joint(name).max_speed_rad_s
        k = int(np.argmax(speed[:, col]))
        if speed[k, col] > limit * 1.001:
            seg = int(np.searchsorted(seq.times, ts[k], side="right")) - 1
            raise ConfigError(
                f"{seq.source}: keyframe[{seg}] -> keyframe[{seg + 1}]: {name} would move at "
                f"{speed[k, col]:.2f} rad/s, above its max_speed_rad_s {limit:g}; give the "
                "keyframes more time")


def load_sequence(path: str | Path, robot: RobotConfig) -> Sequence:
    """Read a .toml or .json sequence and validate it for ``robot``."""
    p = Path(path)
    if p.suffix not in SUFFIXES:
        raise ConfigError(f"{p}: unknown keyframe format {p.suffix!r}; valid: "
                          f"{', '.join(SUFFIXES)}")
    if p.suffix == ".toml":
        data: Mapping[str, Value] = read_toml(p)
    else:
        try:
            text = p.read_text()
        except FileNotFoundError:
            raise ConfigError(f"{p}: file not found") from None
        except (OSError, UnicodeDecodeError) as e:
            raise ConfigError(f"{p}: not a valid JSON keyframe file: {e}") from None
        value = parse_json(text, where=str(p))
        if not isinstance(value, dict):
            raise ConfigError(f"{p}: expected a JSON object with a keyframe list")
        data = value
    return parse_sequence(data, robot, source=str(p))


def sequence_to_toml(seq: Sequence) -> str:
    """TOML that ``load_sequence`` reads back to the same sequence."""
    lines = [f"name = {json.dumps(seq.name)}", f"interpolation = \"{seq.interpolation}\"",
             f"loop = {'true' if seq.loop else 'false'}"]
    for t, pose in zip(seq.times, seq.poses, strict=True):
        lines += ["", "[[keyframe]]", f"t = {float(t)!r}"]
        lines += [f"{j} = {float(v)!r}" for j, v in zip(seq.joints, pose, strict=True)]
    return "\n".join(lines) + "\n"
