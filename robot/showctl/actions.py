"""What a show controller can ask of the robot, as typed actions, whatever carried it (an
OSC message, a MIDI control change or note, a MIDI Show Control GO, a cue of a cue list).

The OSC address space (docs/show-control.md):

    /biped/param/<name> <number>   a gait parameter by its preset name (robot.config.params)
    /biped/start | /biped/stop | /biped/estop
    /biped/preset <name>           blended in as a live switch
    /biped/take/play <name> | /biped/take/stop | /biped/take/record [<name>]
    /biped/cue <name or number>    a cue of the cue list (robot.showctl.cues)
    /biped/go                      the cue after the last one fired
    /biped/pose <name> [<layer>]   a saved keyframe sequence (a pose), on its own or layered

A command address takes no argument or one number: a button of a TouchOSC layout sends 1
when pressed and 0 when released, and a 0 (the release) does nothing. ``parse`` turns a
message into an action or an ``Ignored`` saying what was wrong with it (its ``kind`` is what
is logged once, robot.showctl.once).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from robot.config.params import canonical_name, check_value
from robot.errors import ConfigError

PREFIX = "/biped/"
PARAM = "/biped/param/"


@dataclass(frozen=True)
class SetParam:
    """One gait parameter ``name`` (canonical) to ``value`` (validated, in its unit)."""

    name: str
    value: float


@dataclass(frozen=True)
class Command:
    """A command without a name: ``what`` is one of ``COMMANDS``."""

    what: str


@dataclass(frozen=True)
class Named:
    """A command on something named: ``what`` is one of ``NAMED``; ``name`` the preset,
    take, cue or pose (None: a take recorded under a name of the time); ``layer``: a pose
    layered on the walk."""

    what: str
    name: str | None
    layer: bool = False


Action = SetParam | Command | Named

#: Commands without a name, by address.
COMMANDS = {"/biped/start": "start", "/biped/stop": "stop", "/biped/estop": "estop",
            "/biped/take/stop": "take stop", "/biped/go": "go"}
#: Commands on a name, by address.
NAMED = {"/biped/preset": "preset", "/biped/take/play": "take", "/biped/take/record":
         "record", "/biped/cue": "cue", "/biped/pose": "pose"}
ESTOP = Command("estop")


@dataclass(frozen=True)
class Ignored:
    """A message that does nothing: ``kind`` (logged once: unknown address, wrong type,
    value out of range...) and the one line that says why; ``quiet``: a button's release,
    not an error."""

    kind: str
    why: str
    quiet: bool = False


def _press(address: str, args: Sequence[object]) -> Ignored | None:
    """None for a press (no argument, or one number other than 0)."""
    if not args:
        return None
    v = _number(args[0]) if len(args) == 1 else None
    if v is not None:
        return None if v != 0.0 else Ignored("release", "", quiet=True)
    return Ignored(f"type {address}", f"{address}: expected no argument or one number "
                   f"(1 pressed, 0 released), got {_show(args)}")


def _number(v: object) -> float | None:
    """``v`` as a float if it is a number (not a boolean: OSC's T/F), else None."""
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def _show(args: Sequence[object]) -> str:
    text = ", ".join(repr(a) for a in args) or "nothing"
    return text if len(text) <= 60 else text[:60] + "..."


def _name_arg(v: object) -> str | None:
    """A name as OSC sends it: a string, or a cue number as a number (QLab's "1.5")."""
    if isinstance(v, str):
        return v
    f = _number(v)
    if f is not None and math.isfinite(f):
        return str(int(f)) if f.is_integer() else repr(f)
    return None


def parse(address: str, args: Sequence[object]) -> Action | Ignored:
    """The action an OSC message asks for, or why it is ignored."""
    if address.startswith(PARAM):
        where = f"OSC {address}"
        try:
            param = canonical_name(address[len(PARAM):], where=where)
        except ConfigError as e:
            return Ignored("param", str(e))
        if len(args) != 1 or _number(args[0]) is None:
            return Ignored(f"type {address}", f"{address}: expected one number, got "
                           f"{_show(args)}")
        try:
            return SetParam(param, check_value(param, args[0], where=where))
        except ConfigError as e:
            return Ignored(f"value {address}", str(e))
    if address in COMMANDS:
        return _press(address, args) or Command(COMMANDS[address])
    what = NAMED.get(address)
    if what is None:
        return Ignored("address", f"address {address!r} is not one of biped's: "
                       f"{PARAM}<name>, {', '.join([*COMMANDS, *NAMED])}")
    if what == "record" and not args:
        return Named(what, None)
    target = _name_arg(args[0]) if args else None
    extra = args[1:]
    layer = _number(extra[0]) if what == "pose" and len(extra) == 1 else None
    if target is None or (extra and layer is None):
        want = "a name and optionally 1 (layered on the walk)" if what == "pose" else "a name"
        return Ignored(f"type {address}", f"{address}: expected {want}, got {_show(args)}")
    return Named(what, target, layer=bool(layer))


