"""Reading TOML files and checking their values: every problem is one ConfigError line
``<file>: <field path>: expected ..., got ...``, never a traceback.

Used by ``robot.config.robot_file`` (robot and gait files). Numeric fields carry their valid range as
dataclass field metadata (``spec(Range(...))``), so the range is declared next to the field
and named in the message.
"""

from __future__ import annotations

import json
import math
import stat
import sys
import tomllib
from collections.abc import Mapping
from dataclasses import MISSING, fields
from datetime import date, datetime, time
from pathlib import Path
from typing import TYPE_CHECKING, Literal, NamedTuple, TypeAlias, TypeVar, overload

from robot.errors import ConfigError

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

#: A value as ``tomllib`` returns it (offset-aware and local date-times, dates, times).
TomlValue: TypeAlias = (str | int | float | bool | datetime | date | time | list["TomlValue"]
                        | dict[str, "TomlValue"])
#: A TOML table (a whole file is one).
TomlTable: TypeAlias = dict[str, TomlValue]
#: A value as ``json.loads`` returns it.
JsonValue: TypeAlias = None | str | int | float | bool | list["JsonValue"] | dict[str, "JsonValue"]
#: A dataclass that ``build`` fills from a table.
D = TypeVar("D", bound="DataclassInstance")

#: Largest TOML file read [bytes]: a robot file is ~5 KiB; anything near this is not one.
MAX_TOML_BYTES = 1 << 20
#: Longest value representation quoted in a message [characters].
MAX_SHOWN = 40


class Range(NamedTuple):
    """Inclusive valid range of a numeric field: lo <= v <= hi, in ``unit``.

    label: how to print the range when ``[lo, hi]`` would be unreadable (e.g. "[-pi, pi]").
    """

    lo: float
    hi: float
    unit: str = ""
    label: str = ""

    def __str__(self) -> str:
        text = self.label or f"[{self.lo:g}, {self.hi:g}]"
        return f"{text} {self.unit}" if self.unit else text


def spec(valid: Range) -> dict[str, Range]:
    """Dataclass field metadata declaring a field's valid range."""
    return {"range": valid}


def show(value: object) -> str:
    """``repr(value)``, abbreviated when long (a 400-digit integer stays readable)."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10 ** MAX_SHOWN:
        digits = math.floor(math.log10(abs(value))) + 1
        return f"{'-' if value < 0 else ''}an integer of {digits} digits"
    text = repr(value)
    return text if len(text) <= MAX_SHOWN else text[:MAX_SHOWN] + "..."


def parse_json(text: str, *, where: str) -> JsonValue:
    """``text`` parsed as JSON; ConfigError naming ``where`` if it is not JSON, nests too
    deeply (RecursionError) or holds an integer past Python's digit limit (ValueError)."""
    try:
        value: JsonValue = json.loads(text)
    except RecursionError:
        raise ConfigError(f"{where}: not JSON: arrays or objects nested too deeply") \
            from None
    except json.JSONDecodeError as e:
        raise ConfigError(f"{where}: not JSON: {e.msg} (column {e.colno})") from None
    except ValueError:
        raise ConfigError(f"{where}: not JSON: an integer has more than "
                          f"{sys.get_int_max_str_digits()} digits") from None
    return value


def read_toml(path: Path) -> TomlTable:
    """Parse the TOML file ``path``; ConfigError (one line naming the file) if it is missing,
    not a regular file, unreadable, over MAX_TOML_BYTES, not UTF-8 or not valid TOML."""
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise ConfigError(f"{path}: file not found") from None
    except OSError as e:
        raise ConfigError(f"{path}: cannot read: {e.strerror or e}") from e
    if stat.S_ISDIR(mode):
        raise ConfigError(f"{path}: is a directory; expected a TOML file")
    if not stat.S_ISREG(mode):
        raise ConfigError(f"{path}: not a regular file (a device or pipe); expected a TOML file")
    try:
        with path.open("rb") as f:
            raw = f.read(MAX_TOML_BYTES + 1)
    except OSError as e:
        raise ConfigError(f"{path}: cannot read: {e.strerror or e}") from e
    if len(raw) > MAX_TOML_BYTES:
        raise ConfigError(f"{path}: larger than {MAX_TOML_BYTES // 1024} KiB; expected a TOML "
                          "file (a few KiB)")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ConfigError(f"{path}: not a UTF-8 text file (byte 0x{raw[e.start]:02x} at offset "
                          f"{e.start}); expected a TOML file") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"{path}: not valid TOML: {e}") from e
    except ValueError:  # tomllib: an integer beyond Python's digit limit
        raise ConfigError(f"{path}: not valid TOML: an integer has more than "
                          f"{sys.get_int_max_str_digits()} digits") from None
    except RecursionError:
        raise ConfigError(f"{path}: not valid TOML: arrays or tables nested too deeply") from None


@overload
def number(src: str, path: str, value: object, valid: Range | None = None, *,
           integer: Literal[False] = False) -> float: ...


@overload
def number(src: str, path: str, value: object, valid: Range | None = None, *,
           integer: Literal[True]) -> int: ...


def number(src: str, path: str, value: object, valid: Range | None = None, *,
           integer: bool = False) -> int | float:
    """``value`` checked to be a finite number (an integer if ``integer``) inside ``valid``;
    returned as int or float."""
    kind = "an integer" if integer else "a number"
    where = f" in {valid}" if valid else ""
    if isinstance(value, bool) or not isinstance(value, int | float) or (
            integer and isinstance(value, float)):
        raise ConfigError(f"{src}: {path}: expected {kind}{where}, got {show(value)}")
    if isinstance(value, float) and not math.isfinite(value):
        raise ConfigError(f"{src}: {path}: expected a finite number{where}, got {show(value)}")
    # Compare before any float(): float() of a 400-digit integer raises OverflowError.
    if valid is not None and not valid.lo <= value <= valid.hi:
        raise ConfigError(f"{src}: {path}: expected {kind}{where}, got {show(value)}")
    if integer:
        return value
    try:
        return float(value)
    except OverflowError:
        raise ConfigError(f"{src}: {path}: expected a finite number, got {show(value)}") from None


def table(src: str, path: str, value: TomlValue) -> TomlTable:
    """``value`` checked to be a table."""
    if not isinstance(value, dict):
        raise ConfigError(f"{src}: {path}: expected a table, got {show(value)}")
    return value


def build(cls: type[D], src: str, path: str, data: TomlValue, *,
          overrides: Mapping[str, object] | None = None) -> D:
    """Build a flat dataclass of numbers/strings from a TOML table, checking every field
    (numbers against the ``Range`` in the field's metadata, if any); ``overrides``: fields
    set by the caller, not the file."""
    overrides = overrides or {}
    tab = table(src, path, data)
    names = [f.name for f in fields(cls) if f.name not in overrides]
    unknown = sorted(set(tab) - set(names))
    if unknown:
        raise ConfigError(f"{src}: {path}.{unknown[0]}: unknown key; valid: {', '.join(names)}")
    kwargs: dict[str, object] = dict(overrides)
    for f in fields(cls):
        if f.name in overrides:
            continue
        fpath = f"{path}.{f.name}"
        if f.name not in tab:
            if f.default is not MISSING:
                continue
            raise ConfigError(f"{src}: {fpath}: missing (expected {f.type})")
        v = tab[f.name]
        kind = f.type.removesuffix(" | None") if isinstance(f.type, str) else f.type
        if kind in ("str", str):
            if not isinstance(v, str) or not v:
                raise ConfigError(f"{src}: {fpath}: expected a non-empty string, got {show(v)}")
            kwargs[f.name] = v
        elif kind in ("int", int):
            kwargs[f.name] = number(src, fpath, v, f.metadata.get("range"), integer=True)
        else:
            kwargs[f.name] = number(src, fpath, v, f.metadata.get("range"))
    return cls(**kwargs)
