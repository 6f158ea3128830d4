"""Gait preset TOML files → a validated ``Gait`` (and back: ``gait_to_toml``).

Every error is one line: ``<file>: <field path>: <what is expected>, got <value>``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from robot.config.bundled import DEFAULT_GAIT, resolve_gait_path
from robot.config.params import SPECS, GaitParams, canonical_name, check_value
from robot.config.toml_io import TomlValue, read_toml, show, table
from robot.errors import ConfigError

if TYPE_CHECKING:
    from robot.config.robot import RobotConfig


@dataclass(frozen=True)
class Gait:
    """A named gait preset: parameters plus where it came from; given: the parameters
    the file names itself (the others are defaults); warning: what a user should know
    before walking it (a previs-only preset that falls), said when it is walked."""

    name: str
    params: GaitParams
    source: str = "<memory>"
    given: frozenset[str] = frozenset()
    warning: str = ""

    def for_robot(self, robot: RobotConfig) -> GaitParams:
        """The parameters on ``robot``: its ``[gait]`` over the preset's (what its body
        needs, whatever the preset), and its ``[balance]`` gains for those the preset does
        not name itself (docs/robots.md: preset < [gait] < --set; robot [balance] <
        preset < --set)."""
        params = self.params
        if robot.gait:
            params = params.replace(dict(robot.gait), where=f"{robot.source}: gait")
        own = {k: v for k, v in robot.balance.items() if k not in self.given}
        return params.replace(own, where=f"{robot.source}: balance") if own else params


def load_gait(name_or_path: str | Path | None = None) -> Gait:
    """Load and validate a gait preset by name or path (default: ``walk``)."""
    p = resolve_gait_path(name_or_path if name_or_path is not None else DEFAULT_GAIT)
    return parse_gait(read_toml(p), source=str(p))


def parse_gait(data: Mapping[str, TomlValue], *, source: str = "<memory>") -> Gait:
    """A validated gait preset from a gait file's table (ConfigError, one line, on any
    problem)."""
    src = source
    allowed = {"name", "fps", "description", "warning", "params", "mapping"}
    unknown = sorted(set(data) - allowed)
    if unknown:
        raise ConfigError(f"{src}: {unknown[0]}: unknown key; valid: {', '.join(sorted(allowed))}")
    name = data.get("name", Path(src).stem)
    if not isinstance(name, str) or not name:
        raise ConfigError(f"{src}: name: expected a non-empty string, got {show(name)}")
    warning = data.get("warning", "")
    if not isinstance(warning, str):
        raise ConfigError(f"{src}: warning: expected a string, got {show(warning)}")
    values: dict[str, float] = {}
    if "fps" in data:
        values["fps"] = check_value("fps", data["fps"], where=f"{src}: fps")
    for section, paper in (("params", True), ("mapping", False)):
        entries = table(src, section, data.get(section, {}))
        for key, v in entries.items():
            where = f"{src}: {section}.{key}"
            canon = canonical_name(key, where=where)
            if canon == "fps":
                raise ConfigError(f"{where}: fps belongs at the top level of the gait file")
            if SPECS[canon].paper != paper:
                right = "params" if SPECS[canon].paper else "mapping"
                raise ConfigError(f"{where}: {canon} belongs in [{right}]")
            if canon in values:
                raise ConfigError(f"{where}: {canon} given twice (alias of {canon})")
            values[canon] = check_value(canon, v, where=where)
    if not values:
        raise ConfigError(f"{src}: no parameters (fps, [params] or [mapping]); a preset "
                          "names at least one, or it would walk on the defaults unasked")
    return Gait(name=name, params=GaitParams().replace(values, where=src), source=src,
                given=frozenset(values), warning=warning)


def gait_to_toml(gait: Gait) -> str:
    """Serialise a gait so that ``parse_gait`` reads it back unchanged."""
    p = gait.params.as_dict()
    lines = [f"name = {_toml_string(gait.name)}", f"fps = {p['fps']!r}", "", "[params]"]
    lines += [f"{n} = {p[n]!r}" for n, s in SPECS.items() if s.paper and n != "fps"]
    lines += ["", "[mapping]"]
    lines += [f"{n} = {p[n]!r}" for n, s in SPECS.items() if not s.paper]
    return "\n".join(lines) + "\n"


def _toml_string(text: str) -> str:
    """A TOML basic string: quotes, backslashes and control characters escaped."""
    out = []
    for ch in text:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'
