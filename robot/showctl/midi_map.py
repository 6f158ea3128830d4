"""A MIDI mapping file (``--midi-map FILE``, TOML): which control change sets which gait
parameter over which range along which curve, what a note does, and the MIDI Show Control
device id this robot answers.

```toml
[[cc]]
channel = 1            # 1-16
cc = 7                 # 0-127
param = "speed"        # a gait parameter by its preset name (robot.config.params)
range = [0.0, 1.5]     # optional: the parameter's whole range; [hi, lo] turns it round
curve = "linear"       # linear | squared | sqrt | exponential (optional: linear)

[[note]]
channel = 10
note = 36              # 0-127; a note on (velocity > 0) fires it
take = "wave"          # one of do, preset, take, record, cue, pose (robot.showctl.entry)

[msc]
device = 1             # 0-126 (optional: 0); the all-call 127 is always answered
```

A control change value v of 0..127 is x = v / 127 along the curve: ``linear`` lo + x (hi -
lo); ``squared`` x^2 (fine near lo); ``sqrt`` x^0.5 (fine near hi); ``exponential``
lo (hi / lo)^x (equal ratios per step; lo and hi of one sign, neither 0). Every problem is
one line naming the file and the entry (``cc[2].param``).
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from robot.config.params import SPECS, canonical_name
from robot.config.toml_io import Range, number, read_toml, show
from robot.errors import ConfigError
from robot.files.atomic import write_text
from robot.showctl.actions import Command, Named
from robot.showctl.entry import KEYS, entry_action

CURVES = ("linear", "squared", "sqrt", "exponential")
CHANNEL, BYTE, DEVICE = Range(1, 16), Range(0, 127), Range(0, 126)
MAX_ENTRIES = 512


@dataclass(frozen=True)
class CcMap:
    """Control change ``cc`` on ``channel`` (1-16) → parameter ``param`` from ``lo`` (at
    0) to ``hi`` (at 127) along ``curve``."""

    channel: int
    cc: int
    param: str
    lo: float
    hi: float
    curve: str = "linear"

    def value(self, v: int) -> float:
        """The parameter's value for control value ``v`` (0..127), in its range."""
        x = min(max(v, 0), 127) / 127.0
        if self.curve == "exponential":
            y = self.lo * (self.hi / self.lo) ** x
        else:
            w = x * x if self.curve == "squared" else math.sqrt(x) if self.curve == "sqrt" else x
            y = self.lo + w * (self.hi - self.lo)
        spec = SPECS[self.param]
        return min(max(y, spec.lo), spec.hi)


@dataclass(frozen=True)
class NoteMap:
    channel: int
    note: int
    action: Command | Named


@dataclass(frozen=True)
class MidiMap:
    cc: tuple[CcMap, ...] = ()
    notes: tuple[NoteMap, ...] = ()
    msc_device: int = 0
    source: str = "(no mapping)"

    def cc_for(self, channel: int, cc: int) -> CcMap | None:
        return next((m for m in self.cc if (m.channel, m.cc) == (channel, cc)), None)

    def note_for(self, channel: int, note: int) -> NoteMap | None:
        return next((m for m in self.notes if (m.channel, m.note) == (channel, note)), None)

    def learned(self, channel: int, cc: int, param: str) -> MidiMap:
        """This mapping with ``cc`` on ``channel`` driving ``param`` over its whole range,
        linearly (replacing what that control did, and the control ``param`` had)."""
        spec = SPECS[param]
        kept = tuple(m for m in self.cc if (m.channel, m.cc) != (channel, cc)
                     and m.param != param)
        return dataclasses.replace(self, cc=(*kept, CcMap(channel, cc, param, spec.lo,
                                                          spec.hi)))


def _cc(src: str, i: int, tab: Mapping[str, object]) -> CcMap:
    where = f"cc[{i}]"
    extra = sorted(set(tab) - {"channel", "cc", "param", "range", "curve"})
    if extra:
        raise ConfigError(f"{src}: {where}.{extra[0]}: unknown key; valid: channel, cc, "
                          "param, range, curve")
    channel = number(src, f"{where}.channel", tab.get("channel"), CHANNEL, integer=True)
    cc = number(src, f"{where}.cc", tab.get("cc"), BYTE, integer=True)
    p = tab.get("param")
    if not isinstance(p, str):
        raise ConfigError(f"{src}: {where}.param: expected a gait parameter's name, got "
                          f"{show(p)}")
    param = canonical_name(p, where=f"{src}: {where}.param")
    spec = SPECS[param]
    lo, hi = spec.lo, spec.hi
    if "range" in tab:
        r = tab["range"]
        if not isinstance(r, list) or len(r) != 2:
            raise ConfigError(f"{src}: {where}.range: expected [low, high], got {show(r)}")
        valid = Range(spec.lo, spec.hi)
        lo, hi = (number(src, f"{where}.range[{k}]", r[k], valid) for k in (0, 1))
    curve = tab.get("curve", "linear")
    if curve not in CURVES:
        raise ConfigError(f"{src}: {where}.curve: expected one of {', '.join(CURVES)}, got "
                          f"{show(curve)}")
    if curve == "exponential" and not (lo * hi > 0):
        raise ConfigError(f"{src}: {where}.curve: exponential needs a range of one sign "
                          f"without 0, got [{lo:g}, {hi:g}]")
    return CcMap(channel, cc, param, lo, hi, str(curve))


def _note(src: str, i: int, tab: Mapping[str, object]) -> NoteMap:
    where = f"note[{i}]"
    extra = sorted(set(tab) - {"channel", "note", *KEYS})
    if extra:
        raise ConfigError(f"{src}: {where}.{extra[0]}: unknown key; valid: channel, note, "
                          f"{', '.join(KEYS)}")
    channel = number(src, f"{where}.channel", tab.get("channel"), CHANNEL, integer=True)
    note = number(src, f"{where}.note", tab.get("note"), BYTE, integer=True)
    return NoteMap(channel, note, entry_action(src, where, tab))


def parse_map(data: Mapping[str, object], *, source: str) -> MidiMap:
    unknown = sorted(set(data) - {"cc", "note", "msc"})
    if unknown:
        raise ConfigError(f"{source}: {unknown[0]}: unknown key; valid: cc, note, msc")
    entries: dict[str, list[Mapping[str, object]]] = {}
    for key in ("cc", "note"):
        raw = data.get(key, [])
        if not isinstance(raw, list) or len(raw) > MAX_ENTRIES or not all(
                isinstance(t, dict) for t in raw):
            raise ConfigError(f"{source}: {key}: expected [[{key}]] tables (at most "
                              f"{MAX_ENTRIES})")
        entries[key] = raw
    cc = tuple(_cc(source, i, t) for i, t in enumerate(entries["cc"]))
    notes = tuple(_note(source, i, t) for i, t in enumerate(entries["note"]))
    for kind, keys in (("cc", [(m.channel, m.cc) for m in cc]),
                       ("note", [(m.channel, m.note) for m in notes])):
        first: dict[tuple[int, int], int] = {}
        for i, k in enumerate(keys):
            if k in first:
                raise ConfigError(f"{source}: {kind}[{i}]: channel {k[0]} {kind} {k[1]} is "
                                  f"mapped by {kind}[{first[k]}] already")
            first[k] = i
    msc = data.get("msc", {})
    if not isinstance(msc, dict) or set(msc) - {"device"}:
        raise ConfigError(f"{source}: msc: expected a table with device = 0-126")
    device = number(source, "msc.device", msc.get("device", 0), DEVICE, integer=True)
    return MidiMap(cc, notes, device, source)


def load_map(path: Path) -> MidiMap:
    """The mapping in ``path`` (an empty one if it does not exist yet: learn writes it)."""
    if not path.exists():
        return MidiMap(source=str(path))
    return parse_map(read_toml(path), source=str(path))


def _text(v: str | float | bool) -> str:
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return ("true" if v else "false") if isinstance(v, bool) else repr(v)


def map_to_toml(m: MidiMap) -> str:
    lines = ["# biped MIDI mapping (docs/show-control.md); written by the panel's learn"]
    if m.msc_device:
        lines += ["", "[msc]", f"device = {m.msc_device}"]
    for c in m.cc:
        lines += ["", "[[cc]]", f"channel = {c.channel}", f"cc = {c.cc}",
                  f"param = {_text(c.param)}", f"range = [{c.lo!r}, {c.hi!r}]",
                  f"curve = {_text(c.curve)}"]
    for n in m.notes:
        a = n.action
        lines += ["", "[[note]]", f"channel = {n.channel}", f"note = {n.note}"]
        if isinstance(a, Command):
            lines.append(f"do = {_text(a.what)}")
        else:
            key = next(k for k, v in (("take", "take"), ("record", "record"),
                                      ("preset", "preset"), ("cue", "cue"), ("pose", "pose"))
                       if v == a.what)
            lines.append(f"{key} = {_text(a.name or '')}")
            if a.layer:
                lines.append("layer = true")
    return "\n".join(lines) + "\n"


def save_map(m: MidiMap, path: Path) -> None:
    """Write ``m`` to ``path`` whole (a temporary name, then renamed), checked first: it
    reads back as ``m``."""
    text = map_to_toml(m)
    if parse_map(tomllib.loads(text), source=str(path)) != dataclasses.replace(
            m, source=str(path)):
        raise ConfigError(f"{path}: the mapping would not read back as it is; not written")
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text(path, text)                # whole (robot/files/atomic.py)
