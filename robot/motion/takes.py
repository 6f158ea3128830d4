"""Takes: a recorded performance, as a file ``NAME.take.jsonl`` that ``biped play`` replays.

JSON Lines, one object a line, written while the run goes (a crash or a full disk keeps
everything up to the last line written); plain text that ``jq`` or pandas read:

  {"take": 1, "robot": ..., "robot_file": ..., "joints": [...], "rate_hz": ..., ...}
      the header: robot, gait preset and every parameter at the start, loop rate,
      read-back interval, bus kind, balance feedback on or off
  {"gait_tick": k, "t": ..., "set": {"turn": 0.2, ...}}
      a parameter change, applied just before gait tick k (t = k / rate_hz [s] of gait
      time); every change made live (panel, gamepad, keyboard) is one such line
  {"gait_tick": k, "t": ..., "blend": {"vM": 0.34, ...}}
      a preset switch before gait tick k: every parameter of the preset, blended in over
      robot.gait.blend.PRESET_BLEND_S (the panel's preset picker, `biped walk --switch`)
  {"gait_tick": k, "t": ..., "stop": true}     the gait told to ramp out before tick k
  {"gait_tick": k, "t": ..., "start": true}    the gait told to start before tick k (a show
      whose legs walk in spans, robot/motion/show_walk.py; a recorded walk starts at 0)
  {"tick": n, "t": ..., "state": "walking", "q": [...], "present": [...]}
      one streamed tick: the commanded joint angles [rad] as they went to the bus (after
      balance, clamp and slew), ``t`` [s] on the loop's clock since the first tick;
      ``present``: on the ticks that read the servos back, the joint angles read [rad],
      ``present_t`` [s] when the reply was in (``biped sim-gap`` compares them with the
      commands and the simulation)

The gait is a pure function of the parameter timeline, so replaying the timeline on the
same robot and rate reproduces the stream (in the simulation with balance feedback too:
MuJoCo is deterministic from the same start). ``read_take`` validates a file completely
before anything moves; every problem is one line naming the file, the line and the field.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from robot.config.params import GaitParams, canonical_name, check_value
from robot.config.read_back import check_read_every, max_read_every
from robot.config.toml_io import JsonValue, number, parse_json
from robot.errors import ConfigError

SUFFIX = ".take.jsonl"
VERSION = 1
#: Largest take read [bytes]: an hour at 200 Hz of 18 joints is ~0.3 GB; refuse beyond.
MAX_BYTES = 1 << 30


def is_take(path: str | Path) -> bool:
    return str(path).endswith(SUFFIX)


@dataclass(frozen=True)
class TakeHeader:
    """What a replay needs to reproduce the run. rate_hz [Hz]; read_every: read-back
    interval [ticks]; params: every gait parameter at the start."""

    robot: str
    robot_file: str
    joints: tuple[str, ...]
    rate_hz: float
    read_every: int
    gait: str
    params: GaitParams
    bus: str = "sim"
    balance: bool = False
    note: str = ""
    #: A keyframe sequence layered on the gait (robot.motion.keyframes.Sequence.as_json()).
    keyframes: Mapping[str, JsonValue] | None = None
    #: The show: a joint stream to play as recorded, audio, cues (robot.motion.show).
    show: Mapping[str, JsonValue] | None = None

    def as_json(self) -> dict[str, Any]:
        return {"take": VERSION, "robot": self.robot, "robot_file": self.robot_file,
                "joints": list(self.joints), "rate_hz": self.rate_hz,
                "read_every": self.read_every, "gait": self.gait,
                "params": self.params.as_dict(), "bus": self.bus, "balance": self.balance,
                "note": self.note, "keyframes": self.keyframes, "show": self.show}


@dataclass(frozen=True)
class Take:
    """A take read back: header, timeline (gait tick → changes; the tick of the first
    stop, or None; every start and stop in order) and the joint stream (``q``: ticks x
    joints [rad]; ``t`` [s]; ``states``; ``present``: ticks x joints read back [rad], NaN
    on ticks without a read-back; ``present_t``: when each was read [s, the clock of
    ``t``; ``t`` if not recorded])."""

    header: TakeHeader
    changes: Mapping[int, Mapping[str, float]]
    stop_tick: int | None
    t: npt.NDArray[np.float64]
    q: npt.NDArray[np.float64]
    states: tuple[str, ...] = field(default=())
    source: str = "<memory>"
    starts: tuple[int, ...] = ()
    stops: tuple[int, ...] = ()
    present: npt.NDArray[np.float64] | None = None
    present_t: npt.NDArray[np.float64] | None = None
    blends: Mapping[int, Mapping[str, float]] = field(default_factory=dict)

    @property
    def gait_seconds(self) -> float:
        """Gait time until the stop [s] (the whole stream if it never stopped)."""
        if self.stop_tick is not None:
            return self.stop_tick / self.header.rate_hz
        return len(self.t) / self.header.rate_hz


# ------------------------------------------------------------------------------ reading


def _fail(where: str, what: str) -> ConfigError:
    return ConfigError(f"{where}: {what}")


def _int(where: str, v: JsonValue, name: str, lo: int = 0) -> int:
    if isinstance(v, bool) or not isinstance(v, int) or v < lo:
        raise _fail(where, f"{name}: expected an integer >= {lo}, got {v!r:.40}")
    return v


def _string(where: str, h: Mapping[str, JsonValue], name: str) -> str:
    v = h.get(name, "")
    if not isinstance(v, str):
        raise _fail(where, f"{name}: expected a string, got {v!r:.40}")
    return v


def _angles(where: str, qs: JsonValue, n: int) -> list[float]:
    """``qs`` checked to be ``n`` finite joint angles [rad]."""
    if isinstance(qs, list) and len(qs) == n:
        ok = [float(v) for v in qs if isinstance(v, int | float) and not isinstance(v, bool)
              and math.isfinite(v)]
        if len(ok) == n:
            return ok
    raise _fail(where, f"q: expected {n} finite joint angles [rad]")


def _header(where: str, h: JsonValue) -> TakeHeader:
    if not isinstance(h, dict) or h.get("take") != VERSION:
        raise _fail(where, f"not a take header (expected {{\"take\": {VERSION}, ...}}); "
                           f"record one with --record NAME{SUFFIX}")
    joints = h.get("joints")
    names = tuple(j for j in joints if isinstance(j, str)) if isinstance(joints, list) else ()
    if not (isinstance(joints, list) and names and len(names) == len(joints)):
        raise _fail(where, "joints: expected a list of joint names")
    rate = h.get("rate_hz")
    if isinstance(rate, bool) or not isinstance(rate, int | float) or not 1 <= rate <= 2000:
        raise _fail(where, f"rate_hz: expected a rate in [1, 2000] Hz, got {rate!r:.40}")
    params = h.get("params")
    if not isinstance(params, dict):
        raise _fail(where, "params: expected a table of gait parameters")
    strings = {k: _string(where, h, k) for k in ("robot", "robot_file", "gait", "bus", "note")}
    keys = h.get("keyframes")
    if keys is not None and not isinstance(keys, dict):
        raise _fail(where, "keyframes: expected a keyframe sequence object or null")
    show = h.get("show")
    if show is not None and not isinstance(show, dict):
        raise _fail(where, "show: expected a show object (robot.motion.show) or null")
    return TakeHeader(robot=strings["robot"], robot_file=strings["robot_file"],
                      joints=names, rate_hz=float(rate),
                      read_every=check_read_every(
                          h.get("read_every", min(10, max_read_every(rate))), float(rate),
                          where=f"{where}: read_every"),
                      gait=strings["gait"] or "take",
                      params=GaitParams().replace(params, where=f"{where}: params"),
                      bus=strings["bus"] or "sim", balance=h.get("balance") is True,
                      note=strings["note"], keyframes=keys, show=show)


def _lines(p: Path) -> list[tuple[str, JsonValue]]:
    """The take's non-blank lines as (where, parsed JSON)."""
    try:
        if p.stat().st_size > MAX_BYTES:
            raise ConfigError(f"{p}: larger than {MAX_BYTES >> 20} MiB; not a take")
        lines = p.read_text().splitlines()
    except FileNotFoundError:
        raise ConfigError(f"{p}: file not found") from None
    except (OSError, UnicodeDecodeError) as e:
        raise ConfigError(f"{p}: cannot read it: {e}") from None
    rows: list[tuple[str, JsonValue]] = []
    for i, text in enumerate(lines, 1):
        if not text.strip():
            continue
        rows.append((f"{p}: line {i}", parse_json(text, where=f"{p}: line {i}")))
    if not rows:
        raise ConfigError(f"{p}: empty; expected a take header line")
    return rows


def read_take(path: str | Path) -> Take:
    """Read and validate a take; ConfigError naming the file and line on any problem."""
    p = Path(path)
    rows = _lines(p)
    header = _header(*rows[0])
    n = len(header.joints)
    stop: int | None = None
    starts: list[int] = []
    stops: list[int] = []
    changes: dict[int, dict[str, float]] = {}
    blends: dict[int, dict[str, float]] = {}
    last_gait = -1
    t: list[float] = []
    q: list[list[float]] = []
    states: list[str] = []
    present: list[list[float]] = []
    read_t: list[float] = []
    nan = [math.nan] * n
    for where, row in rows[1:]:
        if not isinstance(row, dict):
            raise _fail(where, "expected a JSON object")
        if "gait_tick" in row:
            k = _int(where, row["gait_tick"], "gait_tick")
            if k < last_gait:
                raise _fail(where, f"gait_tick {k} is before the previous one ({last_gait})")
            last_gait = k
            new = row.get("set") or row.get("blend")
            into = blends if "blend" in row else changes
            if row.get("stop") is True:
                stop = k if stop is None else stop
                stops.append(k)
            elif row.get("start") is True:
                starts.append(k)
            elif isinstance(new, dict) and new:
                w = f"{where}: {'blend' if into is blends else 'set'}"
                step = {canonical_name(m, where=w): check_value(m, v, where=w)
                        for m, v in new.items()}
                into.setdefault(k, {}).update(step)
            else:
                raise _fail(where, "expected \"set\" or \"blend\": {name: value}, "
                                   "\"start\": true or \"stop\": true")
        elif "tick" in row:
            q.append(_angles(where, row.get("q"), n))
            t.append(number(where, "t", row.get("t", len(t) / header.rate_hz)))
            states.append(str(row.get("state", "")))
            seen = row.get("present")
            present.append(nan if seen is None else _angles(f"{where}: present", seen, n))
            read_t.append(number(where, "present_t", row.get("present_t", t[-1])))
        else:
            raise _fail(where, "expected a timeline line (gait_tick) or a stream line (tick)")
    if not q and not stop:
        raise ConfigError(f"{p}: a header only (no gait ticks, no stream lines): nothing to "
                          "replay; record a take with `biped walk --record NAME.take.jsonl`")
    q_arr = np.asarray(q, dtype=float).reshape(len(q), n)
    read = np.asarray(present, dtype=float).reshape(len(q), n)
    return Take(header, changes, stop, np.asarray(t, dtype=float), q_arr, tuple(states),
                source=str(p), starts=tuple(starts), stops=tuple(stops),
                present=read if np.isfinite(read).any() else None,
                present_t=np.asarray(read_t, dtype=float), blends=blends)


def header_of(where: str, data: JsonValue) -> TakeHeader:
    """A take header from its JSON object (as ``TakeHeader.as_json`` writes it), checked;
    ConfigError naming ``where`` and the field."""
    return _header(where, data)
