"""Reading a BVH file into a Rig (robot/previs/rig.py): any writer's, ours or Blender's.

The hierarchy gives each joint's rest offset (an End Site is a chain end), its channels
and their order; the motion rows give per frame the root's position and every joint's
rotation, R = R_a R_b R_c in channel order (intrinsic: the BVH convention). Writers
differ and all are read: 3 or 6 channels per joint (Blender writes positions on every
joint: only the root's position is kept, as the skeleton's travel), any of the six Euler
orders per joint, any up axis, any length unit. Bad input is one ConfigError naming the
file and the line or joint.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from robot.errors import ConfigError
from robot.previs.rig import Array, Rig, nominal_frame_s
from robot.previs.rotations import compose

#: Largest BVH read [bytes].
MAX_BYTES = 1 << 29


class _Tokens:
    def __init__(self, text: str, source: str) -> None:
        self.words = text.split()
        self.i = 0
        self.source = source

    def next(self, what: str) -> str:
        if self.i >= len(self.words):
            raise ConfigError(f"{self.source}: ended early; expected {what}")
        w = self.words[self.i]
        self.i += 1
        return w

    def expect(self, word: str) -> None:
        got = self.next(word)
        if got.upper() != word.upper():
            raise ConfigError(f"{self.source}: expected {word!r}, got {got!r:.40} "
                              f"(word {self.i})")

    def number(self, what: str) -> float:
        w = self.next(what)
        try:
            v = float(w)
        except ValueError:
            raise ConfigError(f"{self.source}: {what}: expected a number, got "
                              f"{w!r:.40}") from None
        if not math.isfinite(v):
            raise ConfigError(f"{self.source}: {what}: {w} is not a finite number")
        return v


def read_bvh(path: str | Path) -> Rig:
    p = Path(path)
    try:
        if p.stat().st_size > MAX_BYTES:
            raise ConfigError(f"{p}: larger than {MAX_BYTES >> 20} MiB; not an animation")
        text = p.read_text()
    except FileNotFoundError:
        raise ConfigError(f"{p}: file not found") from None
    except (OSError, UnicodeDecodeError) as e:
        raise ConfigError(f"{p}: cannot read it as a BVH file: {e}") from None
    tok = _Tokens(text, str(p))
    tok.expect("HIERARCHY")
    names: list[str] = []
    parents: list[int] = []
    offsets: list[list[float]] = []
    channels: list[list[str]] = []
    ends: list[tuple[int, tuple[float, float, float]]] = []
    stack: list[int] = []
    kind = tok.next("ROOT")
    if kind.upper() != "ROOT":
        raise ConfigError(f"{p}: expected ROOT after HIERARCHY, got {kind!r:.40}")
    while True:
        if kind.upper() in ("ROOT", "JOINT"):
            name = tok.next("a joint name")
            tok.expect("{")
            tok.expect("OFFSET")
            off = [tok.number(f"{name}: OFFSET") for _ in range(3)]
            tok.expect("CHANNELS")
            count = int(tok.number(f"{name}: CHANNELS"))
            chans = [tok.next(f"{name}: channel").lower() for _ in range(count)]
            bad = [c for c in chans if c[:1] not in "xyz" or c[1:] not in ("position",
                                                                            "rotation")]
            if count not in (3, 6) or bad:
                raise ConfigError(f"{p}: joint {name}: channels {' '.join(chans)}: expected "
                                  "3 rotations, or 3 positions and 3 rotations")
            parents.append(stack[-1] if stack else -1)
            stack.append(len(names))
            names.append(name)
            offsets.append(off)
            channels.append(chans)
        elif kind.upper() == "END":
            tok.expect("Site")
            tok.expect("{")
            tok.expect("OFFSET")
            where = f"{names[stack[-1]]}: End Site OFFSET"
            o = (tok.number(where), tok.number(where), tok.number(where))
            tok.expect("}")
            ends.append((stack[-1], o))
        elif kind == "}":
            stack.pop()
        else:
            raise ConfigError(f"{p}: unexpected {kind!r:.40} in the hierarchy (word {tok.i})")
        if not stack:
            break
        kind = tok.next("JOINT, End Site or }")
    tok.expect("MOTION")
    tok.expect("Frames:")
    n = int(tok.number("Frames"))
    tok.expect("Frame")
    tok.expect("Time:")
    frame_s = tok.number("Frame Time")
    if n < 1 or not frame_s > 0:
        raise ConfigError(f"{p}: Frames {n}, Frame Time {frame_s:g}: expected at least one "
                          "frame and a positive frame time [s]")
    width = sum(len(c) for c in channels)
    values = tok.words[tok.i:]
    if len(values) != n * width:
        raise ConfigError(f"{p}: MOTION has {len(values)} numbers; {n} frames of {width} "
                          f"channels need {n * width}")
    try:
        data: Array = np.array(values, dtype=float).reshape(n, width)
    except ValueError:
        raise ConfigError(f"{p}: MOTION: a frame value is not a number") from None
    if not np.all(np.isfinite(data)):
        row = int(np.argwhere(~np.isfinite(data))[0, 0])
        raise ConfigError(f"{p}: MOTION frame {row}: a value is not finite")
    pose = np.empty((n, len(names), 3, 3))
    root = np.zeros((n, 3))
    col = 0
    for b, chans in enumerate(channels):
        rot = [i for i, c in enumerate(chans) if c.endswith("rotation")]
        order = "".join(chans[i][0] for i in rot)
        if len(set(order)) != 3:
            raise ConfigError(f"{p}: joint {names[b]}: rotation channels {order!r}: expected "
                              "one each of X, Y and Z")
        pose[:, b] = compose(order, np.radians(data[:, [col + i for i in rot]]))
        if b == 0:
            pos = [i for i, c in enumerate(chans) if c.endswith("position")]
            for i in pos:
                root[:, "xyz".index(chans[i][0])] = data[:, col + i]
        col += len(chans)
    return Rig(tuple(names), tuple(parents), np.array(offsets), pose, root,
               nominal_frame_s(frame_s),
               tuple(ends), str(p))
