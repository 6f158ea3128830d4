"""A cue list (``--cues FILE``, TOML): what each cue of a show does, fired by name or
number (``/biped/cue <name>``, a MIDI Show Control GO with its cue number, a MIDI note), or
in order (a GO without a number fires the cue after the last one fired).

```toml
[[cue]]
number = "1"          # the show controller's cue number (QLab's, MSC's); optional
name = "walk in"      # optional; a cue needs a number or a name
preset = "walk"       # what it does: one of do, preset, take, record, cue, pose
                      # (robot.showctl.entry)
```
"""

from __future__ import annotations

import threading
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from robot.config.toml_io import read_toml, show
from robot.errors import ConfigError
from robot.showctl.actions import Command, Named
from robot.showctl.entry import KEYS, entry_action

MAX_CUES = 1000


@dataclass(frozen=True)
class Cue:
    number: str | None
    name: str | None
    action: Command | Named

    @property
    def label(self) -> str:
        return " ".join(x for x in (self.number and f"#{self.number}", self.name) if x)


def _label(src: str, where: str, tab: Mapping[str, object], key: str) -> str | None:
    v = tab.get(key)
    if v is None:
        return None
    if key == "number" and isinstance(v, (int, float)) and not isinstance(v, bool):
        v = str(v)
    if not isinstance(v, str) or not v or len(v) > 64:
        raise ConfigError(f"{src}: {where}.{key}: expected a string of 1-64 characters, got "
                          f"{show(v)}")
    return v


class CueList:
    """The cues in file order; ``fire``/``go`` pick one (thread-safe)."""

    def __init__(self, cues: tuple[Cue, ...] = (), *, source: str = "(none)") -> None:
        self.cues = cues
        self.source = source
        self._last: int | None = None
        self._lock = threading.Lock()

    @classmethod
    def load(cls, path: Path) -> CueList:
        src = str(path)
        data = read_toml(path)
        unknown = sorted(set(data) - {"cue"})
        if unknown:
            raise ConfigError(f"{src}: {unknown[0]}: unknown key; a cue list has [[cue]] "
                              "entries only")
        raw = data.get("cue", [])
        if not isinstance(raw, list) or len(raw) > MAX_CUES:
            raise ConfigError(f"{src}: cue: expected [[cue]] tables (at most {MAX_CUES})")
        cues: list[Cue] = []
        seen: set[str] = set()
        for i, tab in enumerate(raw):
            where = f"cue[{i}]"
            if not isinstance(tab, dict):
                raise ConfigError(f"{src}: {where}: expected a table")
            extra = sorted(set(tab) - {"number", "name", *KEYS})
            if extra:
                raise ConfigError(f"{src}: {where}.{extra[0]}: unknown key; valid: number, "
                                  f"name, {', '.join(KEYS)}")
            number, name = _label(src, where, tab, "number"), _label(src, where, tab, "name")
            if number is None and name is None:
                raise ConfigError(f"{src}: {where}: a cue needs a number or a name")
            for key in (k for k in (number, name) if k is not None):
                if key in seen:
                    raise ConfigError(f"{src}: {where}: {key!r} names another cue too")
                seen.add(key)
            action = entry_action(src, where, tab)
            if isinstance(action, Named) and action.what == "cue":
                raise ConfigError(f"{src}: {where}.cue: a cue cannot fire another cue")
            cues.append(Cue(number, name, action))
        return cls(tuple(cues), source=src)

    def find(self, key: str) -> Cue | None:
        """The cue numbered or named ``key`` (it becomes the last fired)."""
        with self._lock:
            for i, c in enumerate(self.cues):
                if key in (c.number, c.name):
                    self._last = i
                    return c
        return None

    def go(self) -> Cue | None:
        """The cue after the last one fired (the first at the start; None past the end)."""
        with self._lock:
            i = 0 if self._last is None else self._last + 1
            if i >= len(self.cues):
                return None
            self._last = i
            return self.cues[i]

    def names(self) -> str:
        return ", ".join(c.label for c in self.cues) or "(no cue list: --cues FILE)"
