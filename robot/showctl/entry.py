"""What one entry of a cue list or a MIDI mapping does, as the file writes it: exactly one
of ``do = "start" | "stop" | "estop" | "take stop" | "go"``, ``preset``, ``take`` (play it),
``record``, ``cue``, ``pose`` (with ``layer = true``: on the walk). Checked with one line
naming the file and the entry."""

from __future__ import annotations

from collections.abc import Mapping

from robot.config.toml_io import show
from robot.errors import ConfigError
from robot.showctl.actions import Command, Named

DO = ("start", "stop", "estop", "take stop", "go")
#: Keys that name the thing acted on, and the action each is.
NAMES = {"preset": "preset", "take": "take", "record": "record", "cue": "cue", "pose": "pose"}
KEYS = ("do", *NAMES, "layer")


def entry_action(src: str, where: str, tab: Mapping[str, object], *,
                 allowed: tuple[str, ...] = KEYS) -> Command | Named:
    """The action of entry ``where`` (e.g. ``cue[2]``) of file ``src``."""
    chosen = [k for k in ("do", *NAMES) if k in tab and k in allowed]
    if len(chosen) != 1:
        keys = ", ".join(k for k in ("do", *NAMES) if k in allowed)
        has = f" (it has {', '.join(chosen)})" if chosen else ""
        raise ConfigError(f"{src}: {where}: expected exactly one of {keys}{has}")
    key = chosen[0]
    value = tab[key]
    if "layer" in tab and (key != "pose" or not isinstance(tab["layer"], bool)):
        raise ConfigError(f"{src}: {where}.layer: only a pose has layer = true/false")
    if key == "do":
        if value not in DO:
            raise ConfigError(f"{src}: {where}.do: expected one of {', '.join(DO)}, got "
                              f"{show(value)}")
        return Command(str(value))
    if not isinstance(value, str) or not value:
        raise ConfigError(f"{src}: {where}.{key}: expected a name (a string), got "
                          f"{show(value)}")
    return Named(NAMES[key], value, layer=tab.get("layer") is True)
