"""Reading a BVH file into a Rig (robot/previs/rig.py): any writer's, ours or Blender's.

The hierarchy gives each joint's rest offset (an End Site is a chain end), its channels
and their order; the motion rows give per frame the root's position and every joint's
rotation, R = R_a R_b R_c in channel order (intrinsic: the BVH convention). Writers
differ and all are read: 3 or 6 channels per joint (Blender writes positions on every
joint: only the root's position is kept, as the skeleton's travel), any of the six Euler
orders per joint, any up axis, any length unit. Bad input is one ConfigError naming the
file and the line or joint.

Memory: the frames are parsed as a stream, ``CHUNK_BYTES`` of text at a time, into one
array of the frame count the header declares, so a long motion-capture take costs its
numbers (8 bytes each, then the rotations), never its text as Python words. What the
header declares is checked first, before a frame is read: at most ``MAX_SECONDS`` of
animation (an hour, what a take is sized for: robot.motion.takes.MAX_BYTES) and at most
``MAX_BONE_FRAMES`` bone-frames (the rotations' memory: 72 bytes each). ``progress``
shows a bar (tqdm, on stderr) while the frames of a file over ``PROGRESS_BYTES`` are read.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

import numpy as np
from tqdm import tqdm

from robot.errors import ConfigError
from robot.previs.rig import Array, Rig, nominal_frame_s
from robot.previs.rotations import compose

#: Largest BVH read [bytes].
MAX_BYTES = 1 << 29
#: Longest animation read [s]: an hour (a take of an hour at 200 Hz is ~0.3 GB).
MAX_SECONDS = 3600.0
#: Most frames x joints read: their rotations take 72 bytes each (720 MB at the limit).
MAX_BONE_FRAMES = 10_000_000
#: The hierarchy and the MOTION header must fit in this much of the file's start [bytes].
HEAD_BYTES = 1 << 22
#: Frame text parsed at a time [bytes].
CHUNK_BYTES = 1 << 20
#: Files whose frames take longer than a moment to read [bytes]: they show a progress bar.
PROGRESS_BYTES = 1 << 24
_FRAME_TIME = re.compile(rb"Frame\s+Time:\s*\S+", re.IGNORECASE)
_SPACES = (b" ", b"\n", b"\t", b"\r")


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


def read_bvh(path: str | Path, *, progress: bool = False) -> Rig:
    """The rig of the BVH file ``path`` (see the module docstring; ``progress``: a bar
    while the frames of a large file are read)."""
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > MAX_BYTES:
            raise ConfigError(f"{p}: larger than {MAX_BYTES >> 20} MiB; not an animation")
        with p.open("rb") as f:
            return _read(f, p, size, progress=progress)
    except FileNotFoundError:
        raise ConfigError(f"{p}: file not found") from None
    except (OSError, UnicodeDecodeError) as e:
        raise ConfigError(f"{p}: cannot read it as a BVH file: {e}") from None


def _read(f: BinaryIO, p: Path, size: int, *, progress: bool) -> Rig:
    head = f.read(HEAD_BYTES)
    m = _FRAME_TIME.search(head)
    cut = m.end() if m else len(head)
    text = head[:cut].decode()
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
    seconds = n * frame_s
    if seconds > MAX_SECONDS or n * len(names) > MAX_BONE_FRAMES:
        raise ConfigError(
            f"{p}: {n} frames of {len(names)} joints at {1 / nominal_frame_s(frame_s):g} fps "
            f"({seconds:.0f} s): "
            f"more than can be imported at once (at most {MAX_SECONDS:.0f} s and "
            f"{MAX_BONE_FRAMES:,} joint-frames); cut the animation into parts")
    width = sum(len(c) for c in channels)
    bar = tqdm(total=size, initial=cut, unit="B", unit_scale=True, leave=False,
               desc=f"reading {p.name}", disable=not progress or size < PROGRESS_BYTES)
    with bar:
        data = _frames(_chunks(f, head[cut:], bar), p, n, width)
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


def _chunks(f: BinaryIO, first: bytes, bar: tqdm) -> Iterator[bytes]:  # type: ignore[type-arg]
    """The frame text: what the head read held past the header, then the rest of the
    file ``CHUNK_BYTES`` at a time."""
    if first:
        yield first
    while chunk := f.read(CHUNK_BYTES):
        bar.update(len(chunk))
        yield chunk


def _frames(chunks: Iterator[bytes], p: Path, n: int, width: int) -> Array:
    """The ``n`` x ``width`` frame values from the text in ``chunks`` (a number may be cut
    between two chunks: the words after the last whitespace wait for the next one)."""
    out = np.empty(n * width)
    filled, carry, want = 0, b"", n * width
    for chunk in chunks:
        buf = carry + chunk
        last = max(buf.rfind(c) for c in _SPACES)
        words, carry = buf[:last + 1].split(), buf[last + 1:]
        filled = _store(out, filled, words, p, want, width)
    filled = _store(out, filled, carry.split(), p, want, width)
    if filled != want:
        raise ConfigError(f"{p}: MOTION has {filled} numbers; {n} frames of {width} "
                          f"channels need {want}")
    data = out.reshape(n, width)
    if not np.all(np.isfinite(data)):
        row = int(np.argwhere(~np.isfinite(data))[0, 0])
        raise ConfigError(f"{p}: MOTION frame {row}: a value is not finite")
    return data


def _store(out: Array, filled: int, words: list[bytes], p: Path, want: int,
           width: int) -> int:
    """Put ``words`` into ``out`` from ``filled`` on; the new fill."""
    if not words:
        return filled
    if filled + len(words) > want:
        raise ConfigError(f"{p}: MOTION has more than {want} numbers; "
                          f"{want // width} frames of {width} channels need {want}")
    try:
        out[filled:filled + len(words)] = np.array(words, dtype=np.float64)
    except ValueError:
        row = filled // width
        raise ConfigError(f"{p}: MOTION near frame {row}: a frame value is not a number") \
            from None
    return filled + len(words)
